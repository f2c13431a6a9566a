%
O2312 (FACE GROOVE PLUNGED)
(Plunges along -Z at three diameters, stepping in by less than the tool's width: the
groove a face grooving tool leaves between Ø88 and Ø100 plunged, floor Z-4.)
G21 G18 G40 G99
T0808 (FACE GROOVE W4)
G97 S800 M03
G00 X100. Z2. M08
G01 Z-4. F0.05
G00 Z2.
X94.
G01 Z-4.
G00 Z2.
X88.
G01 Z-4.
G00 Z2.
X150. Z100. M09
M30
%
