#!/usr/bin/env python3
"""Writes the CL test parts of tests/it/cldata.rs: each part as NX (CLSF, `.cls`), Creo
(Pro/CLfile, `.ncl`) and CATIA V5 (`.aptsource`) would export it, in the record forms of
../shared/reference/cldata.md, and the Fanuc program a correct post makes of it (`.nc`).
Run it from this folder; the files are committed, so the tests do not need Python."""

PARTS = {
    # name: (program number, title, operations)
    "face": (1001, "FACE TOP", [
        ("tool", 1, "FACEMILL_D50", 50.0), ("spindle", 1200),
        ("rapid", -30, 0, 50), ("rapid", -30, 0, 5), ("feed", 300), ("line", -30, 0, -0.5),
        ("feed", 800), ("line", 130, 0, -0.5), ("line", 130, 40, -0.5), ("line", -30, 40, -0.5),
        ("line", -30, 80, -0.5), ("line", 130, 80, -0.5), ("rapid", 130, 80, 50), ("spindle_off",),
    ]),
    "drill_ream": (1002, "DRILL AND REAM 4X D8H7", [
        ("tool", 2, "DRILL_D7.8", 7.8), ("spindle", 1500), ("rapid", 20, 20, 50), ("coolant", True),
        ("cycle", "drill", -15, 2, 150, None), ("hole", 20, 20), ("hole", 80, 20), ("hole", 80, 60), ("hole", 20, 60),
        ("cycle_off",), ("coolant", False), ("spindle_off",),
        ("tool", 3, "REAMER_D8H7", 8.0), ("spindle", 400), ("rapid", 20, 20, 50), ("coolant", True),
        ("cycle", "ream", -12, 2, 80, None), ("hole", 20, 20), ("hole", 80, 20), ("hole", 80, 60), ("hole", 20, 60),
        ("cycle_off",), ("coolant", False), ("spindle_off",),
    ]),
    "peck": (1003, "PECK DRILL 3X D6 DEPTH 18", [
        ("tool", 5, "DRILL_D6", 6.0), ("spindle", 2000), ("rapid", 30, 40, 50), ("coolant", True),
        ("cycle", "peck", -18, 0, 100, 5), ("hole", 30, 40), ("hole", 50, 40), ("hole", 70, 40),
        ("cycle_off",), ("coolant", False), ("spindle_off",),
    ]),
    "pocket": (1004, "POCKET 60X40 R3 DEPTH 5", [
        ("tool", 4, "ENDMILL_D10", 10.0), ("spindle", 3000), ("rapid", 50, 40, 50), ("rapid", 50, 40, 5),
        ("feed", 200), ("line", 50, 40, -5), ("feed", 600), ("line", 50, 25, -5), ("line", 72, 25, -5),
        ("arc", 72, 28, 75, 28, -5, True), ("line", 75, 52, -5), ("arc", 72, 52, 72, 55, -5, True),
        ("line", 28, 55, -5), ("arc", 28, 52, 25, 52, -5, True), ("line", 25, 28, -5),
        ("arc", 28, 28, 28, 25, -5, True), ("line", 50, 25, -5), ("rapid", 50, 25, 50), ("spindle_off",),
    ]),
    # An outside profile with cutter compensation (left, climb), its corners rounded clockwise.
    "profile": (1005, "PROFILE 80X60 R5 WITH G41", [
        ("tool", 4, "ENDMILL_D10", 10.0), ("spindle", 3000), ("coolant", True), ("rapid", -20, -20, 50),
        ("rapid", -20, -20, 5), ("feed", 200), ("line", -20, -20, -3), ("comp", "LEFT", 4), ("feed", 500),
        ("line", 10, 0, -3), ("line", 10, 55, -3), ("arc", 15, 55, 15, 60, -3, False), ("line", 85, 60, -3),
        ("arc", 85, 55, 90, 55, -3, False), ("line", 90, 5, -3), ("arc", 85, 5, 85, 0, -3, False),
        ("line", 15, 0, -3), ("arc", 15, 5, 10, 5, -3, False), ("comp_off",), ("line", -20, -20, -3),
        ("rapid", -20, -20, 50), ("coolant", False), ("spindle_off",),
    ]),
}

STOCK = "STOCK X0 Y0 Z-20 X100 Y80 Z0"


def n(v, d=4):
    s = f"{v:.{d}f}"
    return s


def fanuc_num(v):
    s = f"{v:.3f}".rstrip("0")
    return s if not s.endswith("-0.") else "0."


def fanuc(number, title, ops):
    out = ["%", f"O{number} ({title})", f"({STOCK})", "G21 G17 G40 G49 G80 G90"]
    cycle = None
    code = {"drill": "G81", "ream": "G85", "peck": "G83"}
    for op in ops:
        k = op[0]
        if k == "tool":
            out += [f"T{op[1]} M6", f"G43 H{op[1]}"]
        elif k == "spindle":
            out.append(f"S{op[1]} M3")
        elif k == "spindle_off":
            out.append("M5")
        elif k == "coolant":
            out.append("M8" if op[1] else "M9")
        elif k == "rapid":
            out.append(f"G0 X{fanuc_num(op[1])} Y{fanuc_num(op[2])} Z{fanuc_num(op[3])}")
        elif k == "feed":
            out.append(f"F{fanuc_num(op[1])}")
        elif k == "line":
            out.append(f"G1 X{fanuc_num(op[1])} Y{fanuc_num(op[2])} Z{fanuc_num(op[3])}")
        elif k == "arc":
            cx, cy, x, y, z, ccw = op[1:]
            sx, sy = last
            out.append(f"{'G3' if ccw else 'G2'} X{fanuc_num(x)} Y{fanuc_num(y)} I{fanuc_num(cx - sx)} J{fanuc_num(cy - sy)}")
            op = ("line", x, y, z)
        elif k == "cycle":
            cycle = op
        elif k == "hole":
            _, kind, z, r, f, q = cycle
            qw = f" Q{fanuc_num(q)}" if q else ""
            out.append(f"G98 {code[kind]} X{fanuc_num(op[1])} Y{fanuc_num(op[2])} Z{fanuc_num(z)} R{fanuc_num(r)}{qw} F{fanuc_num(f)}")
        elif k == "cycle_off":
            out.append("G80")
        elif k == "comp":
            out.append(f"G{41 if op[1] == 'LEFT' else 42} D{op[2]}")
        elif k == "comp_off":
            out.append("G40")
        if op[0] in ("rapid", "line"):
            last = (op[1], op[2])
    out += ["M30", "%"]
    return "\n".join(out) + "\n"


def nx(name, number, title, ops):
    out = []
    first_point = True
    cycle = None
    for op in ops:
        k = op[0]
        if k == "tool":
            if out:
                out.append("END-OF-PATH")
            out += [f"TOOL PATH/{name.upper()}_{op[1]},TOOL,{op[2]}",
                    f"TLDATA/MILL,{n(op[3])},0.0000,75.0000,0.0000,0.0000",
                    "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
                    "$$ centerline data", f"PPRINT/{STOCK}", "PAINT/PATH", "PAINT/SPEED,10",
                    f"LOAD/TOOL,{op[1]},ADJUST,{op[1]}"]
            first_point = True
        elif k == "spindle":
            out.append(f"SPINDL/RPM,{n(op[1])},CLW")
        elif k == "spindle_off":
            out.append("SPINDL/OFF")
        elif k == "coolant":
            out.append("COOLNT/FLOOD" if op[1] else "COOLNT/OFF")
        elif k in ("rapid", "line"):
            if k == "rapid":
                out += ["PAINT/COLOR,186", "RAPID"]
            axis = ",0.0000000,0.0000000,1.0000000" if first_point else ""
            out.append(f"GOTO/{n(op[1])},{n(op[2])},{n(op[3])}{axis}")
            first_point = False
        elif k == "feed":
            out += ["PAINT/COLOR,31", f"FEDRAT/MMPM,{n(op[1])}"]
        elif k == "arc":
            cx, cy, x, y, z, ccw = op[1:]
            # NX: clockwise about the axis; a counter-clockwise arc in XY has the axis -Z.
            k_axis = "-1.0000000" if ccw else "1.0000000"
            r = ((x - cx) ** 2 + (y - cy) ** 2) ** 0.5
            out.append(f"CIRCLE/{n(cx)},{n(cy)},{n(z)},0.0000000,0.0000000,{k_axis},{n(r)},0.0600,0.5000,10.0000,0.0000")
            out.append(f"GOTO/{n(x)},{n(y)},{n(z)}")
        elif k == "cycle":
            _, kind, z, r, f, q = op
            head = {"drill": "DRILL", "ream": "BORE", "peck": "DRILL,DEEP"}[kind]
            step = f",STEP,{n(q)}" if q else ""
            # Distances along the tool axis from the hole's top (z 0): FEDTO negative.
            out.append(f"CYCLE/{head}{step},RAPTO,{n(r)},FEDTO,{n(z)},RTRCTO,AUTO,MMPM,{n(f)}")
        elif k == "hole":
            out.append(f"GOTO/{n(op[1])},{n(op[2])},0.0000")
        elif k == "cycle_off":
            out.append("CYCLE/OFF")
        elif k == "comp":
            out.append(f"CUTCOM/{op[1]},{op[2]}")
        elif k == "comp_off":
            out.append("CUTCOM/OFF")
    out.append("END-OF-PATH")
    out.append(f"FINI")
    return "\n".join(out) + "\n"


def creo(name, number, title, ops):
    out = ["$$*          Pro/CLfile  Version 8.0 - 8.0.3.0", f"$$-> MFGNO / {name.upper()}", f"PARTNO / {name.upper()}",
           "$$-> FEATNO / 32", "MACHIN / UNCX01, 1", "$$-> CUTCOM_GEOMETRY_TYPE / OUTPUT_ON_CENTER", "UNITS / MM",
           f"PPRINT / {STOCK}"]
    cycle = None
    for op in ops:
        k = op[0]
        if k == "tool":
            out += [f"LOADTL / {op[1]}", f"$$-> CUTTER / {op[3]:.6f}",
                    "$$-> CSYS / 1.0000000000, 0.0000000000, 0.0000000000, 0.0000000000,  $",
                    "            0.0000000000, 1.0000000000, 0.0000000000, 0.0000000000,  $",
                    "            0.0000000000, 0.0000000000, 1.0000000000, 0.0000000000"]
        elif k == "spindle":
            out.append(f"SPINDL / RPM, {op[1]:.6f},  CLW")
        elif k == "spindle_off":
            out.append("SPINDL / OFF")
        elif k == "coolant":
            out.append("COOLNT / FLOOD" if op[1] else "COOLNT / OFF")
        elif k in ("rapid", "line"):
            if k == "rapid":
                out.append("RAPID ")
            out.append(f"GOTO / {op[1]:.10f}, {op[2]:.10f}, {op[3]:.10f}")
        elif k == "feed":
            out.append(f"FEDRAT / {op[1]:.6f},  MMPM")
        elif k == "arc":
            cx, cy, x, y, z, ccw = op[1:]
            r = ((x - cx) ** 2 + (y - cy) ** 2) ** 0.5
            # Right-hand rule: counter-clockwise in XY about +Z. Continued over two lines.
            out.append(f"CIRCLE / {cx:.10f}, {cy:.10f}, {z:.10f},  $")
            out.append(f"         0.0000000000, 0.0000000000, {1.0 if ccw else -1.0:.10f}, {r:.10f}")
            out.append(f"GOTO / {x:.10f}, {y:.10f}, {z:.10f}")
        elif k == "cycle":
            _, kind, z, r, f, q = op
            head = {"drill": "DRILL", "ream": "REAM", "peck": "DEEP"}[kind]
            step = f" STEP, {q:.6f}," if q else ""
            out.append(f"CYCLE / {head}, DEPTH, {-z:.6f},{step} MMPM, {f:.6f}, CLEAR,$")
            out.append(f" {r:.6f}")
        elif k == "hole":
            out.append(f"GOTO / {op[1]:.10f}, {op[2]:.10f}, 0.0000000000")
        elif k == "cycle_off":
            out.append("CYCLE / OFF")
        elif k == "comp":
            out.append(f"CUTCOM / {op[1]}, {op[2]}")
        elif k == "comp_off":
            out.append("CUTCOM / OFF")
    out += ["$$-> END / ", "FINI "]
    return "\n".join(out) + "\n"


def fold72(line):
    """CATIA folds records at column 72, wherever that falls (inside a number too)."""
    parts = []
    while len(line) > 72:
        parts.append(line[:71] + "$")
        line = line[71:]
    parts.append(line)
    return parts


def catia(name, number, title, ops):
    out = ["$$ -----------------------------------------------------------------", "$$ Generated on Wednesday, December 02, 2026",
           "$$ CATIA APT VERSION 1.0", "$$ -----------------------------------------------------------------",
           "$$ Manufacturing Program.1", "$$*CATIA0", "$$ Manufacturing Program.1",
           "$$    1.00000   0.00000   0.00000   0.00000", "$$    0.00000   1.00000   0.00000   0.00000",
           "$$    0.00000   0.00000   1.00000   0.00000", f"PARTNO {title}", f"PPRINT/{STOCK}"]
    cycle = None
    for op in ops:
        k = op[0]
        if k == "tool":
            out += ["$$ OPERATION NAME : Tool Change.1", f"TPRINT/{op[2]}"]
            out += fold72(f"CUTTER/ {op[3]:.6f},  0.000000,  {op[3] / 2:.6f},  0.000000,  0.000000,  0.000000,  50.000000")
            out += [f"TOOLNO/{op[1]},   {op[3]:.6f}", f"LOADTL/{op[1]}", "$$ OPERATION NAME : Machining.1", "MULTAX"]
        elif k == "spindle":
            out.append(f"SPINDL/ {op[1]:.4f},RPM,CLW")
        elif k == "spindle_off":
            out.append("SPINDL/OFF")
        elif k == "coolant":
            out.append("COOLNT/ON" if op[1] else "COOLNT/OFF")
        elif k in ("rapid", "line"):
            if k == "rapid":
                out.append("RAPID")
            out += fold72(f"GOTO  /  {op[1]:.5f},  {op[2]:.5f},  {op[3]:.5f},  0.000000,  0.000000,  1.000000")
        elif k == "feed":
            out.append(f"FEDRAT/ {op[1]:.4f},MMPM")
        elif k == "arc":
            cx, cy, x, y, z, ccw = op[1:]
            r = ((x - cx) ** 2 + (y - cy) ** 2) ** 0.5
            out += fold72(f"CIRCLE/ {cx:.6f},  {cy:.6f},  {z:.6f},  0.000000,  0.000000,  {1.0 if ccw else -1.0:.6f},  {r:.6f}")
            out += fold72(f"GOTO  /  {x:.5f},  {y:.5f},  {z:.5f},  0.000000,  0.000000,  1.000000")
        elif k == "cycle":
            _, kind, z, r, f, q = op
            head = {"drill": "DRILL", "ream": "REAM", "peck": "DEEP"}[kind]
            step = f",INCR,{q:.4f}" if q else ""
            out.append(f"CYCLE/{head},FEDTO,{-z:.4f}{step},MMPM,{f:.4f},RAPTO,{r:.4f},RTRCTO,50.0000")
        elif k == "hole":
            out += fold72(f"GOTO  /  {op[1]:.5f},  {op[2]:.5f},  0.00000,  0.000000,  0.000000,  1.000000")
        elif k == "cycle_off":
            out.append("CYCLE/OFF")
        elif k == "comp":
            out.append(f"CUTCOM/{op[1]},{op[2]}")
        elif k == "comp_off":
            out.append("CUTCOM/OFF")
    out += ["REWIND/0", "END"]
    return "\r\n".join(out) + "\r\n"


for name, (number, title, ops) in PARTS.items():
    open(f"{name}.nc", "w").write(fanuc(number, title, ops))
    open(f"{name}_nx.cls", "w").write(nx(name, number, title, ops))
    open(f"{name}_creo.ncl", "w").write(creo(name, number, title, ops))
    open(f"{name}_catia.aptsource", "w", newline="").write(catia(name, number, title, ops))
