%
O2310 (G74 FACE GROOVE)
(An annular groove in the face between Ø60 and Ø80, 6 deep: G74 pecks along Z by Q,
shifting in X by P, as the Fanuc 0i-TF manual's face grooving cycle.)
G21 G18 G40 G99
T0303 (FACE GROOVE W3)
G50 S1500
G96 S120 M03
G00 X60. Z2. M08
G74 R0.5
G74 X80. Z-6. P2500 Q3000 F0.05
G00 X150. Z100. M09
M30
%
