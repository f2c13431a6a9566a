%
O2311 (FACE GROOVE PLUNGED AND FINISHED)
(A face grooving tool as posts write it: plunges along -Z stepping inward across X, each
turned across at its floor, then the outer and the inner wall finished down to one floor.)
G21 G18 G40 G99
T0808 (FACE GROOVE W3)
G50 S1800
G96 S150 M03
G00 X110. Z1. M08
G01 Z-3. F0.05
X96.
Z-2.8
G00 Z1.
X110.
Z-2.5
G01 Z-5.6
X96.
Z-5.4
G00 Z1.
X112.
G01 Z-6. F0.03
X100.
Z-5.8
G00 Z1.
X92.
G01 Z-6.
X100.2
Z-5.8
G00 Z1.
X150. Z100. M09
M30
%
