($SetPartSize(100, 100, 20, 1) )
($Message("Load the Fanuc machine settings (Files -> Load machine settings) before running."))
(Fanuc sample for the class)
%
O0123 (SAMPLE)
G21 G40 G54 G80 G90
T06 M06
S1500 F300 M03
G00 G43 H06 Z50.
G00 X0 Y0 Z2.
G01 Z-1. F100
X90.
G03 X100. Y10. R10.
G01 Y100.
X0.
Y0.
G00 Z50.
M30
%
