%
O0125 (LATHE-STYLE MILL DEMO)
($SetPartSize(60, 40, 15, 1) )
($Message("Set the tool (T01) before you start") )
($Millimeters)
G21 G90 G40 G54
T01 M06
S2000 M03
G00 G43 H01 Z25.
X-5. Y-5.
Z2.
G01 Z-2. F150.
X65. F400.
Y45.
X-5.
Y-5.
G00 Z25.
M05
M30
%
