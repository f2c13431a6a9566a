//! The issue-43 sweep: real programs from public repositories that neither the corpus nor an
//! earlier sweep used, as pointers with verdicts written before ncplan read them
//! (`tests/sweeps/issue43/material.tsv`; the texts are not committed: `extract.sh` rebuilds
//! them from repository mirrors). With `NCPLAN_SWEEP43` naming the extracted folder, each
//! program is checked as a new user would (`ncplan check FILE`, the dialect told from the
//! file), and scored per half: of the valid programs, those read without an error and those
//! whose family (and lathe or mill) is told right (of all counted programs too); of the
//! invalid ones, those still rejected (the third sweep's rows are the halves `build-s3` and
//! `holdout-s3`). Without it the test says so and passes; `NCPLAN_SWEEP43_HALF`
//! names one half to score.
//!
//! Sweep 5 (rows v001-, halves `build-s5` / `holdout-s5`, split by repository): the holdout
//! (norn93/gcode, 22 programs of a LinuxCNC generator and Mastercam posts) measured once, at
//! commit 030433f: 0/14 valid programs without an error (0.0%), family right for 0/14 valid
//! and 0/22 of all; invalid still rejected 8/8. Every program was read as Fanuc (`%`, `O0000`,
//! `X10.`), whose `;` ends a block, so each `; comment` after a block became an error.
//!
//! Sweep 6 (rows w001-, halves `build-s6` / `holdout-s6`, split by repository; 51 programs of
//! 18 repositories): the holdout (13 repositories, 35 counted programs) measured once, on
//! 2026-12-06 at commit c6027b6 (the rules of integrate b5a700c): 23/32 valid programs without
//! an error (71.9%), family right for 24/32 valid (75.0%) and 27/35 of all (77.1%); invalid
//! still rejected 3/3. The misses: six Tormach PathPilot posts read as Fanuc (`G91.1`, `G41.2`
//! unknown there, and arcs misread after them), two Mori Seiki NT mill-turn programs (G361/G419, T2002) with 36 and 65
//! errors, a Fusion lathe post read as Okuma and a mill post read as Centroid (no error), and a
//! main program whose errors are in the O9100 it calls (a file the verdicts skip). Build-s6
//! after the run: 14/14 valid without an error, family 14/14 valid and 15/15 of all, invalid
//! 1/1, once w014's verdict was corrected to skip (see its row: G32 in a system-B program).
//!
//! After the round that built from every half (branch vocab6; all halves seen, so these are
//! no held-out figures): holdout-s6 29/32 valid without an error, family 31/32 valid (the
//! PathPilot posts read as `pathpilot`, the Mori Seiki NT programs' builder G codes kept as
//! intent, the Fusion posts no longer Okuma or Centroid by one weighty code); left: w033/w034
//! (G41.2, which PathPilot v2.3.6's interpreter does not name, a nested comment rs274 stops
//! at, a G84 at F0), w035 (no evidence of its maker: read as Fanuc), w025 (a `)` after a
//! nested comment).
//!
//! Sweep 7 (rows x001-, halves `build-s7` / `holdout-s7`, split by repository; 86 programs of
//! 16 repositories, 80 counted, 6 skipped): Fanuc 0i-MD macros and a Robodrill's own macros
//! (G10 L52 parameter input, G54.1 P, #3000 alarms), Robodrill and Makino CAM output, a
//! Nakamura-Tome mill-turn shop (G112/G107, five-digit T words), a Haas flycutting set,
//! Centroid CNC12 macros (DEFINE, quoted prompts), LinuxCNC and PathPilot subroutine files, a
//! Sinumerik 840D grinder's PROC library, old-TNC Klartext (CYCL DEF 1 PECKING), and student
//! programs that the control rejects. The build half (7 repositories, 19 valid and 5 invalid
//! programs) and the holdout (9 repositories, 47 valid and 9 invalid) are to be measured by
//! the lead after the merge. Measured once each, 2026-12-06, on integrate e229d11 (the
//! rules of vocab6, diff6, tilt5 and lathe5 merged; neither half seen by anyone building
//! rules): holdout-s7 30/47 valid without an error (63.8%), family right for 45/47 valid
//! (95.7%) and 54/56 of all, invalid still rejected 8/9; build-s7 9/19 valid without an error
//! (47.4%), family 13/19 valid (68.4%) and 17/24 of all, invalid 5/5. The misses: Centroid
//! CNC12 macro files read as LinuxCNC, a Turkish shop's lathe programs with five errors each,
//! Renishaw and Robodrill macros with one, an M600 that the repository's INI remaps, an old
//! TNC's Klartext, a Sinumerik grinder's calls, a 1354-error `.TAP`.
//!
//! After branch vocab7 built from both halves (all seen, so no held-out figures; extracted
//! with the LinuxCNC INI above a program's folder and its SUBROUTINE_PATH folders kept):
//! holdout-s7 38/47 valid without an error, family 46/47 valid; build-s7 9/19, family 19/19
//! (the Centroid CNC12 macros now read as Centroid, their macro language still unmodelled);
//! holdout-s6 29/32, family 31/32.
//!
//! Sweep 8 (rows y001-y089, half `holdout-s8`: held out whole, no build half; 89 programs of
//! 20 repositories, 83 valid and 6 invalid, none skipped): one job shop's Doosan Lynx 300
//! lathe and DNM 5700 mill programs (Fanuc: two-block G71, G32, M165 P98xx probe calls, M98 Q
//! local subprograms, files without extension), a Fanuc screw-thread grinder's builder
//! macros (M444, G31 C skip, #3000 alarms, a V dresser axis), Centroid Intercon output and
//! Centroid's own CNC11 system-test macro, Sinumerik shop programs and PROCs (R parameters
//! with labels, WHILE/REPEAT, ROUNDUP, T="name"), student Fanuc/Mazak/Haas programs, a Fusion
//! post, and LinuxCNC machine configurations' subroutine files (M6 remaps, carousel ATCs,
//! tool setters, probing; named o-words, HAL/INI reads), about half of the set. Measured once
//! by the lead after the merge, on 6 December 2026 (integrate 7be615f): holdout-s8 77/83
//! valid without an error (92.8%), family right for 80/83 valid (96.4%) and 86/89 of all,
//! invalid still rejected 5/6. Missed: a Centroid CNC11 system-test macro (34 errors), two
//! Doosan lathe programs and two grinder macros with 1-5 errors each, a Haas job-shop program
//! (1 error); the Sinumerik lathe PROC and its main program read as the mill dictionary, a
//! grinder macro read as Haas; the invalid LinuxCNC `m199.ngc` read without an error.
//!
//! After branch vocab10 built from all four seen halves (none held out): Centroid's macro
//! language as its M-Series operator's manual gives it (DEFINE names, quoted text arguments,
//! `/` arguments, letter variables, the file's end a return) and G32's modal lead:
//! holdout-s8 79/83 valid without an error, family 80/83; holdout-s7 45/47, family 46/47;
//! build-s7 15/19, family 19/19; holdout-s6 29/32, family 31/32. Left: the Sinumerik lathe
//! PROC and its main program (no Sinumerik lathe dictionary), the grinder's O8000 IF with no
//! THEN, the Doosan G71 contour that runs on past Q, the Haas job shop's nested comment.
//!
//! Sweep 9 (rows z001-z032, half `holdout-s9`: held out whole, no build half; 32 programs of
//! 12 repositories, 29 valid and 3 invalid, none skipped), meant to spread wider than sweep 8
//! (half LinuxCNC): 21 Sinumerik programs of grinder builders and their shops (CMA cycles with
//! typed and VAR parameters, GUD arrays, CASE .. OF, WHILE, oscillation OSP1/OSCTRL, SETINT,
//! FXS fixed stop, `$AA_ENC_COMP` writes, HMI `;NCG#` comment blocks, a probe log saved as
//! `.MPF` that is no program), 8 Fanuc (an Indonesian mould shop's CAM output with `/M99` then
//! `M30`, G10 L10-L13 offset input, an `M198` main program with a placeholder word the control
//! rejects; a 2011 drilling program with G8 P1; Fusion output without an O word) and 3 LinuxCNC
//! (a tuning loop, a stray `%` that LinuxCNC rejects, a one-subroutine file). No Heidenhain,
//! Haas, Okuma, Mazak or Fagor program was found in a repository not used before. Verdicts
//! written by reading each file before anyone ran ncplan on it (LinuxCNC files also through
//! rs274). Measured once on 6 December 2026 (integrate 4d5e17b, after every merge of the
//! stop): 24/29 valid without an error (82.8%), family right for 27/29 valid (93.1%) and
//! 30/32 of all, invalid still rejected 3/3. The misses: a grinder builder's cycle with
//! two-dimensional array indices (`R[1,2]`, 63 errors), Siemens `RND` after an arc as the
//! first move of a contour subprogram (12), `/3` skip levels in a block (4), `M2=5 M3=5 M5`
//! (several numbered spindles in a block, 2: fixed after the measurement), two Fanuc `.NT`
//! mould programs read as LinuxCNC (one with 1 error: `P0` no command takes).
//!
//! After branch vocab11 built from all five seen halves (none held out): Siemens arrays of up
//! to three dimensions and `OSCTRL[Z]=(set,reset)`, a rounding beside an arc a warning (the
//! control makes it; not computed here), skip levels `/0`-`/9`, `S2=90000/3` (the `/3` the
//! note above took for a skip level is a division in an addressed spindle word), Haas's `IF
//! [..]` with a statement and no THEN, `/M99` closing a main program as Fanuc's evidence, and
//! the machine scored by what the reading concludes (a plan that turns), not by the
//! dictionary's name alone. The figures are in the branch's report.
//!
//! Sweep 10 (rows a001-a029, half `holdout-s10`: held out whole, no build half; 29 programs of
//! 15 repositories, 25 valid, 3 invalid, 1 skipped; the prefix `a` since `v` was sweep 5's),
//! spread over families rather than owners (at most 3 programs a repository): LinuxCNC 10
//! (machine configurations' M6 remaps and probing subroutines with `_ini`/`_hal` reads, a
//! woodworking magazine remap, a lathe turret M6, a Fusion `.tap` kept in a configuration),
//! Fanuc 9 (two job shops' lathes: `,A` direct-drawing chamfers, two-block G71/G76, a Doosan
//! Lynx 2100's sub-spindle B pickoff with `P11`/`P13` spindle select and `/2` skip levels; a
//! thread grinder's Macro B main program with its G65 macros beside it and G31 skip probing),
//! Siemens 7 (an aerospace shop's 5-axis 840D CAM output with shop cycles `RAPORT`/`TOL`,
//! `TRAORI`, `T="name"`, its `EXTCALL` main program, a drilling program saved as `.nc`; a programmer's own PROC cycle and the GROB main program calling it with
//! builder cycles and GUDs) and Haas 3 (a college class's mill programs). The invalid: a `YY=`
//! address, a line of minus signs between blocks, LinuxCNC o-words closing an `if` that was never
//! opened. No Heidenhain, Okuma, Mazak, Fagor or Mitsubishi program could be found in a
//! repository not used before. Verdicts written by reading each file before anyone ran ncplan on
//! it (LinuxCNC files also through rs274). Measured once by the lead after the merges (integrate
//! 9a7411f, 6 December 2026): 22/25 valid without an error (88.0%), family right for 22/25 valid
//! (88.0%), invalid still rejected 1/3. Errors on valid programs: a Sinumerik PROC cycle (5: `ROUNDUP (…)`,
//! a function with a space before its bracket), two Fanuc lathe programs of one shop (4 and 5:
//! the direct-drawing angle `G1X51.0,A-45.0`, not in the Fanuc lathe dictionary).
//! Family: a LinuxCNC probing subroutine read as Centroid, a Fusion `.tap` read as Fanuc. Invalid
//! programs read without an error: the `YY=R101` address and the o-words closing an `if` that was
//! never opened.
//!
//! After that measurement (vocab12, from the controls' documentation, not from one file): Siemens
//! `ROUNDUP` (840D sl job planning, a blank before its bracket as any function), the LinuxCNC
//! probing sub's `o <zprobe> sub` (blanks do not count in RS274NGC) no longer read as Centroid,
//! `G91.1` in a Fusion/Mach safe start evidence of RS274NGC, a bare o-word inside a sub body and
//! an `endif` no `if` of its label opened stopping the program as rs274 does. Seen halves then:
//! holdout-s10 25/25 valid without an error, family 24/25 valid, invalid 2/3; holdout-s9 29/29;
//! holdout-s8 79/83; holdout-s7 45/47; build-s7 15/19; holdout-s6 29/32 (the last four as
//! before). Left: `YY=R101` (a GUD of that name cannot be ruled out from the file alone), the
//! LinuxCNC lathe's M6 remap read as a mill.
//!
//! Sweep 11 (rows b001-b018, half `holdout-s11`: held out whole, no build half; 18 programs of 9
//! repositories, 14 valid, 3 invalid, 1 skipped), fewer than the 40 asked: the index and the
//! unused local mirrors gave nothing else that no earlier sweep, test or corpus file had used.
//! LinuxCNC 8 (configuration subroutines: polar `@`/`^` bolt holes, M6 remaps with `M70`/`M72`,
//! `_ini`/`_hal` reads, `#<_task>` guards and an `endsub [1]` inside an `if`, an `else if` chain
//! written with a space, `G38.2`/`G38.3` probing, a surface map written through `#[#<_pidx>]`;
//! an F-Engrave splash with `G64 P`), Siemens 4 (NX output for an 840D 5-axis mill calling shop
//! cycles by name, `BLUM9902` laser measuring, `TRAORI`; a Polish aerospace shop's Hamuel main
//! program and two subprograms kept as a checker's test input: `EXTCALL`, `$AA_IW[U]`,
//! `T="7757453"`, `MSG("E_STR1: "<<E_STR1)`, `CYCLE60` engraving), Fanuc 4 (an aerospace
//! horizontal machining centre's CATIA output, old post, new post and the program merged from
//! two: `G10 L2`/`L20`, `G54.1 P`, `/G05.1Q1`, B indexing; a CAM lathe job), Heidenhain 1. The
//! invalid: a TNC post's broken second `TOOL CALL` and parenthesised comments, a `GOTOB` to a
//! label that is not there, an `O` word carrying a name. Verdicts written by reading each file
//! before anyone ran ncplan on it (LinuxCNC files also through rs274). Measured once by the lead
//! after the merges (integrate 12e72bb, 6 December 2026): 13/14 valid without an error (92.9%),
//! family right for 14/14 valid (100.0%) and 16/17 of all, invalid still rejected 1/3. The error:
//! b016, flexgui's M6 remap `toolchange.ngc` (19 errors: its `endsub [1]` inside an `if` ends the
//! definition for ncplan as for rs274 run on it as a main program; the verdict "valid" rests on
//! the remap calling it, which the sweep does not model). Invalid read without an error: b002 (a
//! TNC post's broken second `TOOL CALL` and `( )` comments) and b014 (`Osample(…)`, read as an
//! Okuma lathe program, where a named program is allowed). Three of the 18 rows (b004-b006) are
//! of an owner whose other repositories sweep 10 used (MariuszMalec).
//!
//! After branch vocab13 (all halves seen, so no held-out figures): a subroutine file's `endsub`
//! inside one of its `if`s returns early (RS274NGC "Calling Files": the file runs from its
//! `sub` line when called, b016), and Fanuc's `WH` abbreviation of `WHILE` (x003, x004; x001
//! keeps its R-arc shorter than half its chord): holdout-s11 14/14 valid without an error,
//! family 14/14, invalid 1/3; build-s7 17/19; the other seen halves as before (holdout-s10
//! 25/25, s9 29/29, s8 79/83, s7 45/47, s6 29/32). Left: b002 (a Klartext block that starts
//! with an axis, `80 Z DR+0.0`, is read as a modal `L`; the TNC takes no block without its
//! function), b014 (`Osample(..)`: Okuma's named program takes it, and the reading without an
//! error wins on weak evidence), a003 (`YY=R101`).
//!
//! Sweep 12 (rows c001-c030, half `holdout-s12`: held out whole, no build half; 30 programs of 15
//! repositories, 28 valid, 2 invalid), fewer than the 40 asked: the index and the fetchable store
//! gave nothing else unused, and no Okuma, Fagor, Mitsubishi or Centroid program. Under this
//! round's rule a repository another issue's tests used may give files those tests did not use
//! (each row says so). Fanuc 6 (a Dutch shop's Fanuc 18T lathe programs with `:0115 ;` program
//! numbers after a `&HE:%` DNC header, two-block `G71`/`G76`; NX samples for a Mori Seiki CL-203B
//! lathe and a LeBlond Makino with a Fanuc 0M; a student's Fusion output), Siemens 6 (SinuTrain
//! 840D sl lathe programs with `WORKPIECE`, `CYCLE62`/`CYCLE952`/`CYCLE940` and `;NCG#` shop-cycle
//! comment blocks; a published data set's NX output for a Spinner U5 with `DEF REAL`, `SUPA`,
//! `CYCLE832`, `MCALL CYCLE81`; a SYIL X7 run-in routine calling `EXTERN WARMUP_CYCLE`), LinuxCNC 6
//! (engrave-12.py output, a multi-head demo with REMAP'd `M428`-`M430`, a probing library's bore
//! subs, Probe Screen NG's tool-setter macro), Mazak 4 (Integrex 300SY user macros with
//! `G122.1`/`G123.1`, `WHILE .. DO1`, `#3000=70(..)`, `G112 M200`; an eight-digit `O00000001`
//! Nexus output), Heidenhain 3 (a Hungarian shop's hyperMILL 2025 output for a DMU 85: `PLANE
//! SPATIAL .. STAY SEQ- TABLE ROT`, `F MAX`, `/103 M30`, `FN 9: IF .. GOTO LBL "CuttingEdges1"`),
//! Haas 2, Mach3 2, LNC 1 (`MSG_OK[..]`, `#100 = INPUT[..]`). The invalid: Probe Screen NG's
//! `O1 if [<#_value> EQ -1]` (rs274 stops: bad number format) and a class program's `X-9.5.` with
//! two decimal points. Verdicts written by reading each file before anyone ran ncplan on it
//! (LinuxCNC files also through rs274). Measured once on 7 December 2026 (integrate 9165117):
//! 20/28 valid programs without an error (71.4%), family right for 25/28 valid (89.3%), invalid
//! still rejected 1/2. The errors: three SinuTrain 840D sl lathe programs whose `CYCLE62` names
//! its contour by its first argument (a contour program beside them; "none is named", 4, 1 and 2
//! errors), the Dutch shop's three Fanuc 18T programs (a DC2 and `&HE:%` DNC header before the
//! first end of block, which the control's label skip ignores: 3 errors each), two of the
//! Integrex macros (2 and 7 errors); the family: the three Integrex files read as the Mazak mill
//! (`mazak`) where the machine is a mill-turn lathe. Invalid read without an error: Probe Screen
//! NG's `<#_value>`. After the measurement (seen): `CYCLE62`'s first argument names the contour
//! (the ShopTurn `E_LAB_A_name` labels or a program of that name), the three SinuTrain
//! programs read without an error.
//!
//! After branch vocab14 (all halves seen, so no held-out figures): the Integrex mill-turn's
//! own dictionary `mazak_millturn` (G-code type C, told by INTEGREX, G122.1/G123.1 and
//! `G112 M/S`; `T6400.1102` a tool with its ID code), a LinuxCNC subroutine file's unreadable
//! block an error (it runs when called: c018's `[<#_value> EQ -1]`), and a Klartext block with
//! no function an error (b002): holdout-s12 27/28 valid without an error, family 28/28, invalid
//! 2/2; holdout-s11 14/14, invalid 2/3; the other halves as before. Left: c024's first `G1`
//! with no F before it (F200 comes a block later: whether the Mazak keeps a feed from before
//! is not known), b014 (`Osample(..)`), a003 (`YY=R101`).
//!
//! Sweep 13 (rows d001-d022, half `holdout-s13`: held out whole, no build half; 22 programs of 2
//! repositories, all valid), from files no set used of repositories other sets used in part (each
//! row says so). Heidenhain 12 (a Hungarian job shop's hyperMILL 2025 output for a DMG DMU 85
//! monoBLOCK, two sister parts' jobs: `PLANE SPATIAL` on up to five table orientations followed by
//! `L A+Q120 C+Q122`, cycles 200/203/207/208/241 defined with `~` continuation lines and called by
//! `M99`, `CYCL DEF 32` tolerance set and reset, `M110`/`M111`, a 30 000-line 3+2 ball-nose
//! finish, an engraving job, Latin-1 job comments, `/NN M30` then `FN 9` label blocks), Haas 10 (a
//! machining student's hand-written lathe programs with one-block `G71`/`G76`/`G75`, `M23`, and
//! mill programs; three Fusion 360 personal-use outputs with feed moves in place of rapids, merged
//! by hand with `M00` between setups). No Siemens, Fanuc-only, LinuxCNC, Okuma or Mazak program
//! in a repository not mined before was found. Verdicts written by reading each file before
//! anyone ran ncplan on it. Measured once on 7 December 2026 (integrate 0d8fb95): 21/22 valid
//! programs without an error (95.5%), family right for 20/22 (90.9%), no invalid program in it.
//! Missed: two of the Haas lathe programs (`weld_pin_02`, `_03`: one-block `G76 X Z K D F` and
//! Haas chip-conveyor `M31`/`M33`, no code only Haas has) read as the Fanuc lathe, where the
//! one-block `G76` then gives an error in `_02` (Fanuc's two-block form wants P and Q).
//!
//! After branch vocab15 (all halves seen, so no held-out figures): the one-block `G76 X Z K D F`
//! read without an error on the Fanuc lathe too (its FS15 tape format; the block that gives K
//! reads so) and, with `G75 I/K`, counted as the Haas lathe's evidence (the Haas manual's only
//! forms, weight 10 as G71's one block with D); the Fagor lathe reads the 8055's own language
//! (P parameters, bracketed statements, G70/G71 units) rather than Macro B: holdout-s13 22/22
//! valid without an error, family 22/22 (d015/d016 read as `haas_lathe`); every other half as
//! before (build 28/29, build-s3 24/24, build-s4 22/22, build-s5 4/4, build-s6 14/14, build-s7
//! 17/19, holdout 27/27, s4 43/44, s5 14/14, s6 29/32, s7 45/47, s8 79/83, s9 29/29, s10 25/25,
//! s11 14/14, s12 27/28; holdout-s3 not scored: its heidenhain-simulator mirror cannot be
//! fetched). Left: c024 (a first `G1` whose F comes a block later), b014 (`Osample(..)`), a003
//! (`YY=R101`), the Fanuc label skip beyond a sender's header line.
//!
//! Sweep 14 (rows e001-e023, half `holdout-s14`: held out whole, no build half; 23 programs of 5
//! repositories, files no set used of repositories other sets used in part, each row says so, and
//! none whose history is this round's revision pairs r506-r608). Haas 14 (a college class's
//! hand-written mill programs: facing, spot-and-drill sequences as `G01` plunges, `G84` tapping
//! with its R plane below the start, `G41`/`G40` around corner arcs, pen-plotter exercises at
//! F900 with the spindle off, T words with no `M06`, a CAM helical bore pasted into a hand
//! program; two Haas lathe programs with `G50`/`G96`/`T0101`), Siemens 7 (a thread grinder's
//! workpiece programs of HMI shop-form calls, a ShopTurn-style contour, a leadscrew-error
//! compensation table with `CHANDATA`/`$AN_CEC`/`NEWCONF`, grinder cycles with condition-less
//! `DO MOV[C]` synchronized actions and a loading robot's handshake), Mazak 2 (Integrex 300SY
//! side milling with `G112`); no invalid program (e012's `Z-0560` with no decimal point is read in
//! least increments with Haas Setting 162 off, its default: a pass 0.5 in. too high, no stop). Verdicts written by reading each file before anyone ran ncplan on
//! it. Measured once on 7 December 2026 (integrate a74fb77): 21/23 valid without an error
//! (91.3%), family right 22/23 (95.7%). e003 and e007 (Haas class programs) write a parenthesis
//! inside a comment (`(... F900 (IPM) based ...)`), which this reading ends at the first `)`, so
//! the rest of the line is read as words (e007 then as the Fanuc mill); e010 is read as the Fanuc
//! mill, with no error, having no code only Haas has.
//!
//! After the round vocab16 (all halves seen): e010 is read as Haas by its `G04 P1.0` (seconds on
//! a Haas, no Fanuc form): holdout-s14 family 23/23. e003/e007 keep their errors: no Fanuc, Haas
//! or Mitsubishi manual found documents a nested comment (fanuc.xml says so). build-s7 is 17/19
//! on integrate 6068106 already (x001: an `R0.2` arc the macro's `#621=#610+#18` sends 104 mm;
//! x027: G2/G3 with no I, J, K or R, its verdict not settled).
//!
//! Sweep 15 (rows f001-f023, half `holdout-s15`: held out whole, no build half; 23 programs of 4
//! repositories, files no set used of repositories other sets used in part, each row says so, and
//! none whose text is a side of this round's revision pairs r609-r674). Fanuc 11 (a job shop's
//! Doosan DNM 5700 hand-written mill programs backed up from the machine: tooling clamps with an
//! empty comment before code, soft-jaw spiral pockets of `G03` quarter arcs, clamp plates, a
//! double-vise band anchor with `G81` drilling and `I`/`J` chamfer contours, a `G83` peck, radial
//! T-cutter slots; three small programs of an SK7420 thread grinder: an endless `GOTO` C run-in, a
//! `WHILE` touch-step macro with a repeated sequence number, a C run with no motion G code), Haas
//! 10 (the college class's programs not used before: a face finish, S-clamp arms' drilling and
//! `G41` peripheries, a small jaw, T words with no `M06`, four lathe programs with
//! `G50`/`G96`/`G97` and R-corner finishing), Siemens 2 (a thread grinder's dressing-profile
//! cycles: `G451`, `G42` switched to `G41` without `G40`, `RND`, GUD thread data); 1 invalid (f010:
//! a `G02` with neither R nor I/J). Verdicts written by reading each file before anyone ran ncplan
//! on it. Measured once on 7 December 2026 (integrate 2a0a436): 22/22 valid programs without an
//! error, family right 23/23, the invalid one still rejected.
//!
//! Sweep 16 (rows g001-g033, half `holdout-s16`: held out whole, no build half; 33 programs of 2
//! repositories, files no set used of repositories other sets used in part, each row says so).
//! Siemens 30 (a German mill-turn course's SinuTrain 840D sl programs for a turning centre with a
//! B axis, a counter-spindle and driven tools: `CYCLE951`/`CYCLE952`/`CYCLE930` turning with
//! `CYCLE62` contour calls by name or by labels, the contour editor's subprograms with `DIAM90`,
//! `CHR`/`RND`/`RNDM`, `ANG`, `I=AC()`/`K=AC()` and `CR=` arcs and undercuts, a cone by
//! hand-written passes with `G42 G147`/`G40 G148 DISR`, two ShopTurn work-step programs,
//! `TRANSMIT` face milling, `TRACYL` peripheral drilling and tapping under `CYCLE800` with
//! `MCALL` and `REPEATB` of labelled position patterns, a counter-spindle handover with
//! `COUPDEF`/`COUPON`, an `EXTERN`-declared slotting `PROC` with a `REPEAT`/`UNTIL` loop),
//! LinuxCNC 3 (a cylindrical grinder's generated flute subroutines of `G93` X/Z/C moves with
//! depth-fraction `if`/`elseif` chains, and its W-axis loading subroutine); 1
//! invalid (g021: a teaching skeleton with `. . .` placeholders for values). Verdicts written by
//! reading each file before anyone ran ncplan on it. Measured once on 7 December 2026 (integrate
//! a89f1ba): 26/32 valid without an error (81.2%), family right for 15/32 valid (46.9%), the
//! invalid one still rejected. The Sinumerik turning programs are read with the one Siemens
//! dictionary and most of their plans turn nothing: `CYCLE951`, `CYCLE930`, `CYCLE952` and the
//! ShopTurn `F_ROUGH` steps are intent only, so the machine is taken for a mill (17 of 30); six
//! give errors: `G147`/`G148` (soft approach and retract) unknown codes (g006), arcs and
//! rounded corners of the contour editor's subprograms that do not close (g010), a `CYCLE952`
//! contour named by a subprogram beside the file (g011: "no label starts the contour"), and
//! `S2=100` beside an `S` taken for the same address twice (g017).
//! After branch sinuturn (integrate bc9f9f2; seen, built from): the machine judged also by the
//! reading's own lathe findings (a lathe's reset state, a lathe's tool change by T), with
//! `CYCLE930`/`CYCLE940`/ShopTurn `F_ROUGH` kept as intent but read as a lathe's words:
//! holdout-s16 26/32 valid without an error (unchanged), family right 25/32 valid (was 15) and
//! 26/33 of all. Still taken for mills: contour subprograms alone (g009, g010: no turning word,
//! their arcs the errors they were; g020: `G17 DIAMOF` for `TRANSMIT`), the slotting `PROC` with
//! `DIAMOF`/`DIAMON` and no T word (g028), and the LinuxCNC grinder's three files.
//!
//! Sweep 16's build half (rows h001-h030, half `build-s16`, gathered by vocab17 to build from;
//! 30 programs of 6 repositories, all valid): Fanuc 19 (a Robodrill's 2025 Renishaw GoProbe
//! macros, a Fanuc SK7620A thread grinder's builder macros, two Doosan DNM 5700 job-shop
//! programs), Heidenhain 5 (hyperMILL 2025 output for a DMG DMU 100P duoBLOCK), Haas 6 (mill and
//! lathe class programs). On integrate 4215ce6, before any rule was built from it: 28/30 valid
//! without an error, family 29/30. h005: Renishaw's `#[#111+5]=1280` with #111 the caller's wrote
//! #0 (the unknown index rounded to 0), after which O9700's `IF[#8EQ#0]` read as unknown and its
//! `GOTO#149` jumped to the vacant value; h021: `CYCL DEF9.1 V.IDO2` (cycle 9's DWELL 2 in the
//! Hungarian dialogue, name run into value); h003 read as the Fanuc lathe by `G65 P9732 S1. W2.`,
//! a macro argument. After branch vocab17: 30/30, family 30/30; every seen half as before.
//!
//! Sweep 17's build half (rows j001-j018, half `build-s17`, gathered by vocab18 to build from;
//! 18 programs of 4 repositories, all valid; fewer than asked and no Fanuc, Haas, Heidenhain,
//! Okuma, Mazak or Fagor program could be found unused): Centroid 7 (an Acroloc router's CNC12
//! M-function macros), LinuxCNC 11 (Machinekit probing and manual tool-change remaps, a touch-plate
//! sub, Pocket NC's builder subs). On integrate 6910503, before any rule was built from it:
//! 16/18 valid without an error, family 18/18. j003: Centroid's template `IF #50001 ;Prevent
//! lookahead` read as a block IF looking for its ENDIF; j018: a subroutine file closed by the
//! `endsub` of another name (copied from tool-change.ngc). After branch vocab18: 18/18, family
//! 18/18; holdout-s13 to s16 (whose mirrors were fetched) as before.
//!
//! Sweep 17's held-back half (rows i001-i063, half `holdout-s17`, gathered by gather17b and
//! gather17c; 63 programs). Measured once on 6 December 2026 (integrate eedc724): 51/54 valid
//! without an error (94.4%), family 53/54, invalid rejected 8/9. Seen since; after branch tnc18
//! (Heidenhain `~` formula continuation, contour label lists, calls of unmodelled cycles as
//! intent, old cycle sub-blocks with glued values, the Fanuc dwell's P with a decimal point an
//! alarm, a Siemens `DEF` of an address name an error): 53/54, family 53/54, invalid 9/9; i057
//! (an NX Haas VF-3 sample with no code of Haas's own) now reads as Fanuc with two errors, its
//! cycle dwells `P.5`.
//!
//! Sweep 18 (rows k001-k031, half `holdout-s18`, gathered by gather18b: held out whole; 31
//! programs of 6 repositories, files no set used of repositories other sets used in part):
//! Siemens 14, Haas 7, Fanuc 4, LinuxCNC 4, Fagor 1, Mazak 1; 4 invalid. Measured once on
//! 7 December 2026 (integrate c2111971): 25/27 valid without an error (92.6%), family right
//! 27/27 valid and 31/31 of all, invalid rejected 4/4. The misses: k007 (an NX Haas VF-3 test
//! part with no code of Haas's own, guessed Fanuc with low confidence) gets the Fanuc dwell
//! alarm at `P.01` (a Haas reads it as 0.01 s: a finding that holds for one maker of a weakly
//! guessed family is no error); k019 (a Haas dispatcher) raises its own `#3000` alarm on the
//! branch the analysis takes, which a control takes only when cycle start is pushed by hand.
//!
//! Sweep 19 (rows l001-l032, half `holdout-s19`, gathered by gather19b: held out whole; 32
//! programs of 6 repositories, files no set used of repositories other sets used in part):
//! Mitsubishi 11 (a horizontal machining centre's bundled pallet, tool-change, measuring and
//! parameter-check macros), Siemens 8 (the FB422 grinder's entry and setup cycles), Haas 7,
//! Heidenhain 4 (hyperMILL drilling and tapping jobs), Fanuc 1, Mazak 1; 1 invalid. Measured once
//! (session 19, integrate 8357e035): 26/31 valid without an error (83.9%), family 28/31 valid and
//! 29/32 of all, invalid rejected 0/1. The misses: three Haas pen-plotter programs with a
//! parenthesis nested in a comment, a Sinumerik grinder cycle, two Mitsubishi machine-bundle macros
//! read as Haas and Fanuc, and the invalid l017 (a misspelt name in both branches) not rejected.

use std::path::PathBuf;

use ncplan::dialect::Registry;

struct Row {
    id: String,
    half: String,
    repo: String,
    path: String,
    valid: String,
    families: Vec<String>,
    lathe: bool,
}

fn rows() -> Vec<Row> {
    let text = std::fs::read_to_string(crate::root().join("tests/sweeps/issue43/material.tsv")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split('\t').collect();
            assert!(c.len() >= 11, "material.tsv: a row has 11 columns: {l:?}");
            let mut families = vec![c[7].to_owned()];
            families.extend(c[8].split_whitespace().map(str::to_owned));
            Row {
                id: c[0].to_owned(),
                half: c[1].to_owned(),
                repo: c[2].to_owned(),
                path: c[4].to_owned(),
                valid: c[6].to_owned(),
                families,
                lathe: c[9] == "lathe",
            }
        })
        .collect()
}

/// What `ncplan check` says of a file: the dialect it told, the number of errors, and whether
/// the reading concluded a turning machine from the program's own words: a lathe's reset state
/// (`interp::x-words-diameter`: turning cycles, kept as intent or not, a speed limit, constant
/// cutting rate) or a lathe's tool change by the T word (`interp::tool-word-changes`: a program
/// that says `DIAMON`, or such words, with T words and no M6). A lathe program that mills with
/// driven tools (`TRANSMIT`, `TRACYL`) or only keeps its turning as intent turns nothing in its
/// plan, yet the reading knows the machine.
fn check(file: &std::path::Path) -> (String, usize, bool) {
    let out = std::process::Command::new(crate::bin()).arg("check").arg(file).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let dialect = stderr.split("dialect ").nth(1).and_then(|s| s.split_whitespace().next()).unwrap_or("?").to_owned();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let errors = stdout.lines().filter(|l| l.starts_with("error[")).count();
    let lathe = stdout.lines().any(|l| l.contains("[interp::x-words-diameter]") || l.contains("[interp::tool-word-changes]"));
    (dialect, errors, lathe)
}

/// Whether the reading concludes the program turns: a workingstep of its plan is a turning one
/// (the lathe evidence recovery uses: diameter mode, a lathe cycle, synchronised moves or a
/// constant surface speed in the ZX plane, every move in the ZX plane through the axis),
/// whatever the dictionary's name.
fn turns(file: &std::path::Path) -> bool {
    let out = std::process::Command::new(crate::bin()).args(["plan", "--format", "json"]).arg(file).output().unwrap();
    let Ok(plan) = serde_json::from_slice::<serde_json::Value>(&out.stdout) else { return false };
    plan["workingsteps"].as_array().is_some_and(|w| w.iter().any(|w| !w["turning"].is_null()))
}

#[derive(Default, Debug)]
struct Score {
    valid: usize,
    clean: usize,
    counted: usize,
    family_right: usize,
    invalid: usize,
    rejected: usize,
    valid_family_right: usize,
    misses: Vec<String>,
}

#[test]
fn the_sweep_reads_what_its_controls_run() {
    let Some(dir) = std::env::var_os("NCPLAN_SWEEP43").map(PathBuf::from) else {
        crate::skip("sweep43", "NCPLAN_SWEEP43 is not set (tests/sweeps/issue43/extract.sh OUT, then NCPLAN_SWEEP43=OUT): not scored");
        return;
    };
    // `NCPLAN_SWEEP43_HALF=build` scores one half only (the holdout is measured once, at the end).
    let only = std::env::var("NCPLAN_SWEEP43_HALF").ok();
    let registry = Registry::shipped();
    let mut scores: std::collections::BTreeMap<String, Score> = Default::default();
    let file_of = |r: &Row| dir.join(r.repo.replacen('/', "+", 1)).join(&r.path);
    let chosen: Vec<Row> = rows().into_iter().filter(|r| r.valid != "skip" && only.as_ref().is_none_or(|h| *h == r.half)).collect();
    // A half whose texts are not all extracted (its repository mirror was missing when
    // extract.sh ran) is skipped with a message, not scored on part of its rows.
    let mut incomplete: std::collections::BTreeMap<&str, (usize, PathBuf)> = Default::default();
    for r in &chosen {
        let file = file_of(r);
        if !file.is_file() {
            incomplete.entry(r.half.as_str()).or_insert((0, file)).0 += 1;
        }
    }
    for (half, (n, first)) in &incomplete {
        crate::skip(
            "sweep43",
            &format!(
                "half {half}: {n} program(s) missing (first {}): fetch its mirrors and extract the sweep again; not scored",
                first.display()
            ),
        );
    }
    for r in chosen.iter().filter(|r| !incomplete.contains_key(r.half.as_str())) {
        let file = file_of(r);
        let (dialect, errors, lathe_read) = check(&file);
        let d = registry.get(&dialect);
        let family = d.as_ref().map_or("?".to_owned(), |d| if d.family == "rs274ngc" { "linuxcnc".to_owned() } else { d.family.clone() });
        // The machine by what the reading concludes: a lathe dictionary, a lathe the reading
        // found from the program's words, or a plan that turns (a Sinumerik lathe program read
        // with the one Siemens dictionary).
        let lathe = d.as_ref().is_some_and(|d| d.behaviour.x_diameter) || dialect.contains("lathe") || lathe_read || turns(&file);
        let s = scores.entry(r.half.clone()).or_default();
        s.counted += 1;
        let family_ok = r.families.iter().any(|f| *f == family || f == "any") && lathe == r.lathe;
        s.family_right += usize::from(family_ok);
        if r.valid == "yes" {
            s.valid += 1;
            s.clean += usize::from(errors == 0);
            s.valid_family_right += usize::from(family_ok);
        } else {
            s.invalid += 1;
            s.rejected += usize::from(errors > 0);
        }
        if !family_ok || (r.valid == "yes") != (errors == 0) {
            s.misses.push(format!("{} {} ({}): read as {dialect}, {errors} errors", r.id, r.path, r.valid));
        }
    }
    // The figures go past the harness's capture, as a skip does.
    use std::io::Write as _;
    let mut err = std::io::stderr();
    for (half, s) in &scores {
        let pct = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
        let _ = writeln!(
            err,
            "sweep43 {half}: {}/{} valid programs without an error ({:.1}%), family right for {}/{} valid ({:.1}%) and {}/{} of all ({:.1}%), invalid still rejected {}/{}",
            s.clean,
            s.valid,
            pct(s.clean, s.valid),
            s.valid_family_right,
            s.valid,
            pct(s.valid_family_right, s.valid),
            s.family_right,
            s.counted,
            pct(s.family_right, s.counted),
            s.rejected,
            s.invalid
        );
        for m in &s.misses {
            let _ = writeln!(err, "  {m}");
        }
    }
    // The half the rules were built from holds the targets; the holdout half is
    // measured, and its figures reported, not tuned against.
    // Each sweep's build half (`build`, `build-s3`) holds them.
    for (half, s) in scores.iter().filter(|(h, _)| h.starts_with("build")) {
        assert!(s.clean * 100 >= s.valid * 95, "{half}: {} of {} valid programs without an error", s.clean, s.valid);
        assert!(
            s.valid_family_right * 100 >= s.valid * 98,
            "{half}: family right for {} of {} valid programs",
            s.valid_family_right,
            s.valid
        );
        assert_eq!(s.rejected, s.invalid, "{half}: an invalid program reads without an error");
    }
}
