BEGIN PGM RESET MM
FN 18: SYSREAD Q5 = ID50 NR1 IDXQ1 ; tool length L
; reset the wear of tools 10 to 20
FN 0: Q1 = +10
FN 0: Q2 = +20
LBL 1
FN 17: SYSWRITE ID50 NR4 IDXQ1 = +0 ; DL length oversize
FN 17: SYSWRITE ID50 NR5 IDXQ1 = +0 ; DR radius oversize
FN 1: Q1 = +Q1 + +1
FN 12: IF +Q1 LT +Q2 GOTO LBL 1
M30
END PGM RESET MM
