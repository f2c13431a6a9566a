%
O01050 (UMC PART)
(Using G0 which travels along dogleg path.)
(T2 D=8. CR=1. - ZMIN=-12. - bull nose end mill)
G90 G94 G17
G21
G53 G0 Z0.
(2D Contour1)
T2 M6
S10000 M3
G54
M8
G0 A0. B0.
G254
G0 X-30. Y-25.
G43 Z20. H2
G0 Z5.
G1 Z-12. F500.
G1 X30. F1500.
Y25.
X-30.
Y-25.
G0 Z20.
G255
M9
G103 P0 (LOOKAHEAD ON)
G53 G0 Z0.
M30
%
