#!/usr/bin/env python3
"""Writes the CAM-style suite: each part posted the way Fusion 360 / Mastercam / NX (Fanuc,
Haas), Siemens 840D and Heidenhain TNC posts write programs (header tool lists, safe-start
blocks, 3-4 decimals, realistic feeds), and a sidecar `<name>.json` naming the workingsteps
and features each one contains.

Run from this folder: `python3 generate.py`. The programs are kept in the repository; the
generator documents how they were made and makes new parts cheap to add."""

import json
import math

# ---------------------------------------------------------------- toolpaths, abstractly
# A toolpath is a list of ("rapid", x, y, z) / ("feed", x, y, z, f) / ("arc", x, y, z, cx, cy,
# ccw, f) / ("drill", cycle, positions, top, bottom, r, peck, f, dwell) / ("dwell", s)
# records; an operation is (tool, toolpath).


def face(tool_d, x0, x1, y0, y1, levels, f, stepover_share=0.7):
    r = tool_d / 2
    step = tool_d * stepover_share
    out = []
    for z in levels:
        ys = []
        y = y0 + r * 0.3
        while y < y1 - r * 0.3 + 1e-9:
            ys.append(round(y, 4))
            y += step
        if ys[-1] < y1 - r * 0.3 - 1e-6:
            ys.append(round(y1 - r * 0.3, 4))
        xa, xb = x0 - r - 5, x1 + r + 5
        out.append(("rapid", xa, ys[0], None))
        out.append(("rapid", xa, ys[0], z + 5))
        out.append(("feed", xa, ys[0], z, f / 2))
        for i, yy in enumerate(ys):
            a, b = (xa, xb) if i % 2 == 0 else (xb, xa)
            if i > 0:
                out.append(("feed", a, yy, z, f))
            out.append(("feed", b, yy, z, f))
        out.append(("rapid", None, None, z + 15))
    return out


def rounded_rect(cx, cy, w, l, rc, z, f, start_mid=True):
    """The loop of a w x l rectangle with corner radius rc (tool-centre path), CCW, from the
    middle of the bottom edge."""
    hw, hl = w / 2, l / 2
    out = [("feed", cx + hw - rc, cy - hl, z, f)]
    if rc > 0:
        out.append(("arc", cx + hw, cy - hl + rc, z, cx + hw - rc, cy - hl + rc, True, f))
    out.append(("feed", cx + hw, cy + hl - rc, z, f))
    if rc > 0:
        out.append(("arc", cx + hw - rc, cy + hl, z, cx + hw - rc, cy + hl - rc, True, f))
    out.append(("feed", cx - hw + rc, cy + hl, z, f))
    if rc > 0:
        out.append(("arc", cx - hw, cy + hl - rc, z, cx - hw + rc, cy + hl - rc, True, f))
    out.append(("feed", cx - hw, cy - hl + rc, z, f))
    if rc > 0:
        out.append(("arc", cx - hw + rc, cy - hl, z, cx - hw + rc, cy - hl + rc, True, f))
    out.append(("feed", cx, cy - hl, z, f))
    return out


def pocket_rough(tool_d, cx, cy, w, l, rc, levels, f, allowance=0.3, step_share=0.5, ramp=None):
    """Contour-parallel loops inward from the wall less the allowance, at each level; the tool
    plunges at the centre, or ramps down along X over `ramp` mm at half the feed."""
    r = tool_d / 2
    out = []
    prev = 0.0
    for z in levels:
        if ramp:
            out.append(("rapid", cx - ramp / 2, cy, None))
            out.append(("rapid", cx - ramp / 2, cy, prev + 1))
            out.append(("feed", cx + ramp / 2, cy, z, f / 2))
            out.append(("feed", cx, cy, z, f))
        else:
            out.append(("rapid", cx, cy, None))
            out.append(("rapid", cx, cy, z + 5))
            out.append(("feed", cx, cy, z, f / 3))
        prev = z
        ow, ol = w - 2 * (r + allowance), l - 2 * (r + allowance)
        loops = []
        k = 0
        while True:
            ww, ll = ow - 2 * k * tool_d * step_share, ol - 2 * k * tool_d * step_share
            if ww <= 0.5 or ll <= 0.5:
                break
            loops.append((ww, ll))
            k += 1
        for ww, ll in reversed(loops):
            out.append(("feed", cx, cy - ll / 2, z, f))
            out.extend(rounded_rect(cx, cy, ww, ll, 0, z, f))
        out.append(("rapid", None, None, z + 5))
    out.append(("rapid", None, None, 15))
    return out


def pocket_finish(tool_d, cx, cy, w, l, rc, z, f):
    r = tool_d / 2
    out = [("rapid", cx, cy, None), ("rapid", cx, cy, z + 5), ("feed", cx, cy, z, f / 3), ("feed", cx, cy - l / 2 + r, z, f)]
    out.extend(rounded_rect(cx, cy, w - 2 * r, l - 2 * r, max(rc - r, 0), z, f))
    out.append(("rapid", None, None, 15))
    return out


def profile(tool_d, cx, cy, w, l, rc, levels, f, allowance):
    """A boss w x l with corner radius rc, cut from outside: the tool enters beside the part."""
    r = tool_d / 2 + allowance
    out = []
    for z in levels:
        sx, sy = cx, cy - l / 2 - r - tool_d
        out.append(("rapid", sx, sy, None))
        out.append(("rapid", sx, sy, z + 5))
        out.append(("feed", sx, sy, z, f / 3))
        out.append(("feed", cx, cy - l / 2 - r, z, f))
        # Clockwise around the boss (climb with M3): mirror of the CCW loop.
        hw, hl, rr = w / 2 + r, l / 2 + r, rc + r
        out += [
            ("feed", cx - hw + rr, cy - hl, z, f),
            ("arc", cx - hw, cy - hl + rr, z, cx - hw + rr, cy - hl + rr, False, f),
            ("feed", cx - hw, cy + hl - rr, z, f),
            ("arc", cx - hw + rr, cy + hl, z, cx - hw + rr, cy + hl - rr, False, f),
            ("feed", cx + hw - rr, cy + hl, z, f),
            ("arc", cx + hw, cy + hl - rr, z, cx + hw - rr, cy + hl - rr, False, f),
            ("feed", cx + hw, cy - hl + rr, z, f),
            ("arc", cx + hw - rr, cy - hl, z, cx + hw - rr, cy - hl + rr, False, f),
            ("feed", cx, cy - hl, z, f),
        ]
        out.append(("rapid", None, None, z + 5))
    out.append(("rapid", None, None, 15))
    return out


def drill(cycle, positions, top, bottom, f, peck=None, dwell=None, clearance=3.0):
    return [("drill", cycle, positions, top, bottom, top + clearance, peck, f, dwell)]


def expanded(cycle, positions, top, bottom, f, peck=None, clearance=3.0):
    """Drilling written out as G0/G1 moves, the way expanded-cycle posts write it."""
    out = []
    r = top + clearance
    for x, y in positions:
        out.append(("rapid", x, y, None))
        out.append(("rapid", x, y, r))
        if peck:
            z = top
            while z > bottom + 1e-9:
                nz = max(z - peck, bottom)
                if z < top:
                    out.append(("rapid", x, y, z + 0.3))
                out.append(("feed", x, y, nz, f))
                out.append(("rapid", x, y, r))
                z = nz
        else:
            out.append(("feed", x, y, bottom, f))
            out.append(("feed" if cycle == "ream" else "rapid", x, y, r, f))
    out.append(("rapid", None, None, 15))
    return out


# ---------------------------------------------------------------- posts

def fmt(v, d=3):
    s = f"{v:.{d}f}".rstrip("0")
    return s if not s.endswith(".") else s


def fanuc(name, number, tools, ops, stock, haas=False):
    """Fusion 360 / Mastercam style: header tool list, safe start, N numbers, G43 H."""
    L = ["%", f"O{number} ({name.upper()})"]
    if stock:
        L.append(f"(STOCK X{fmt(stock[0])} Y{fmt(stock[1])} Z{fmt(stock[2])} X{fmt(stock[3])} Y{fmt(stock[4])} Z{fmt(stock[5])})")
    for t, (kind, d) in tools.items():
        L.append(f"(T{t} {kind}_{d:g}MM D={fmt(d)} CR=0.)" if "MILL" in kind else f"(T{t} {kind} D={fmt(d)})")
    L.append("G90 G94 G17 G49 G40 G80")
    L.append("G21")
    L.append("G28 G91 Z0.")
    L.append("G90")
    n = [10]

    def out(s):
        L.append(f"N{n[0]} {s}")
        n[0] += 5

    for t, speed, path in ops:
        kind = tools[t][0]
        out(f"T{t} M06")
        out(f"S{speed} M03")
        out("G54")
        first = True
        cur = [None, None, None]
        for m in path:
            if m[0] == "drill":
                _, cyc, pos, top, bottom, r, peck, f, dwell = m
                code = {"drill": "G81", "peck": "G83", "ream": "G85", "tap": "G84", "spot": "G82"}[cyc]
                x, y = pos[0]
                if first:
                    out(f"G00 X{fmt(x)} Y{fmt(y)}")
                    out(f"G43 Z15. H{t:02d}")
                    out("M08")
                    first = False
                extra = f" Q{fmt(peck)}" if peck else ""
                extra += f" P{int(dwell * 1000)}" if dwell else ""
                out(f"G98 {code} X{fmt(x)} Y{fmt(y)} Z{fmt(bottom)} R{fmt(r)}{extra} F{fmt(f, 1)}")
                for x, y in pos[1:]:
                    out(f"X{fmt(x)} Y{fmt(y)}")
                out("G80")
                continue
            kindm = m[0]
            x, y, z = m[1], m[2], m[3]
            if first and kindm == "rapid":
                out(f"G00 X{fmt(x)} Y{fmt(y)}")
                out(f"G43 Z15. H{t:02d}")
                out("M08")
                cur = [x, y, 15.0]
                first = False
                continue
            words = []
            for a, v, c in (("X", x, cur[0]), ("Y", y, cur[1]), ("Z", z, cur[2])):
                if v is not None and (c is None or abs(v - c) > 1e-9):
                    words.append(f"{a}{fmt(v, 4)}")
            if kindm == "rapid":
                if words:
                    out("G00 " + " ".join(words))
            elif kindm == "feed":
                out("G01 " + " ".join(words) + f" F{fmt(m[4], 1)}")
            elif kindm == "arc":
                cx, cy, ccw, f = m[4], m[5], m[6], m[7]
                i, j = cx - cur[0], cy - cur[1]
                out(("G03 " if ccw else "G02 ") + " ".join(w for w in words if not w.startswith("Z")) + f" I{fmt(i, 4)} J{fmt(j, 4)} F{fmt(f, 1)}")
            for k, v in enumerate((x, y, z)):
                if v is not None:
                    cur[k] = v
        out("M09")
        out("G28 G91 Z0.")
        out("G90")
        if haas:
            out("M01")
    out("M30")
    L.append("%")
    return "\n".join(L) + "\n"


def siemens(name, number, tools, ops, stock):
    """NX / Siemens 840D: `;` comments, T="name" D1, CYCLE8x with MCALL."""
    L = [f"%_N_{name.upper()}_MPF", ";$PATH=/_N_MPF_DIR"]
    if stock:
        L.append(f"; STOCK X{fmt(stock[0])} Y{fmt(stock[1])} Z{fmt(stock[2])} X{fmt(stock[3])} Y{fmt(stock[4])} Z{fmt(stock[5])}")
    for t, (kind, d) in tools.items():
        L.append(f';T="{kind}_D{d:g}" D={fmt(d)}')
    n = [10]

    def out(s):
        L.append(f"N{n[0]} {s}")
        n[0] += 10

    out("G17 G710 G40 G90 G94")
    out("G54")
    for t, speed, path in ops:
        kind, d = tools[t]
        out(f'T="{kind}_D{d:g}" D1')
        out("M6")
        out(f"S{speed} M3")
        first = True
        cur = [None, None, None]
        for m in path:
            if m[0] == "drill":
                _, cyc, pos, top, bottom, r, peck, f, dwell = m
                x, y = pos[0]
                if first:
                    out(f"G0 X{fmt(x)} Y{fmt(y)}")
                    out("Z50")
                    out("M8")
                    first = False
                out(f"F{fmt(f, 1)}")
                sd = fmt(r - top)
                if cyc == "peck":
                    call = f"CYCLE83(50,{fmt(top)},{sd},{fmt(bottom)},,{fmt(top - peck)},,{fmt(peck)},0,0,1,1)"
                elif cyc == "ream":
                    call = f"CYCLE85(50,{fmt(top)},{sd},{fmt(bottom)},,0,{fmt(f, 1)},{fmt(f, 1)})"
                elif cyc == "spot":
                    call = f"CYCLE82(50,{fmt(top)},{sd},{fmt(bottom)},,{fmt(dwell or 0.5)})"
                else:
                    call = f"CYCLE81(50,{fmt(top)},{sd},{fmt(bottom)})"
                out(f"MCALL {call}")
                for x, y in pos:
                    out(f"X{fmt(x)} Y{fmt(y)}")
                out("MCALL")
                continue
            kindm = m[0]
            x, y, z = m[1], m[2], m[3]
            if first and kindm == "rapid":
                out(f"G0 X{fmt(x)} Y{fmt(y)}")
                out("Z50")
                out("M8")
                cur = [x, y, 50.0]
                first = False
                continue
            words = []
            for a, v, c in (("X", x, cur[0]), ("Y", y, cur[1]), ("Z", z, cur[2])):
                if v is not None and (c is None or abs(v - c) > 1e-9):
                    words.append(f"{a}{fmt(v, 4)}")
            if kindm == "rapid":
                if words:
                    out("G0 " + " ".join(words))
            elif kindm == "feed":
                out("G1 " + " ".join(words) + f" F{fmt(m[4], 1)}")
            elif kindm == "arc":
                cx, cy, ccw, f = m[4], m[5], m[6], m[7]
                i, j = cx - cur[0], cy - cur[1]
                out(("G3 " if ccw else "G2 ") + " ".join(w for w in words if not w.startswith("Z")) + f" I={fmt(i, 4)} J={fmt(j, 4)} F{fmt(f, 1)}")
            for k, v in enumerate((x, y, z)):
                if v is not None:
                    cur[k] = v
        out("M9")
        out("M5")
    out("M30")
    return "\n".join(L) + "\n"


def heidenhain(name, number, tools, ops, stock):
    """TNC Klartext: BLK FORM, TOOL CALL, CYCL DEF 200/201/203 with Q203, L/CC/C."""
    L = []
    n = [0]

    def out(s):
        L.append(f"{n[0]} {s}")
        n[0] += 1

    out(f"BEGIN PGM {name.upper()} MM")
    if stock:
        out(f"BLK FORM 0.1 Z X{stock[0]:+g} Y{stock[1]:+g} Z{stock[2]:+g}")
        out(f"BLK FORM 0.2 X{stock[3]:+g} Y{stock[4]:+g} Z{stock[5]:+g}")
    for t, (kind, d) in tools.items():
        out(f"; T{t} {kind} D={fmt(d)}")
    q = lambda v: f"{v:+.3f}".rstrip("0").rstrip(".")
    for t, speed, path in ops:
        kind, d = tools[t]
        out(f"; {kind}")
        out(f"TOOL CALL {t} Z S{speed}")
        out("M3")
        first = True
        cur = [None, None, None]
        for m in path:
            if m[0] == "drill":
                _, cyc, pos, top, bottom, r, peck, f, dwell = m
                x, y = pos[0]
                if first:
                    out(f"L X{q(x)} Y{q(y)} R0 FMAX")
                    out("L Z+50 FMAX M8")
                    first = False
                depth = bottom - top
                if cyc == "ream":
                    out("CYCL DEF 201 REAMING ~")
                    body = [("Q200", r - top, "SET-UP CLEARANCE"), ("Q201", depth, "DEPTH"), ("Q206", f, "FEED RATE FOR PLNGNG"), ("Q211", 0, "DWELL TIME AT DEPTH"), ("Q208", f, "RETRACTION FEED RATE"), ("Q203", top, "SURFACE COORDINATE"), ("Q204", 50, "2ND SET-UP CLEARANCE")]
                else:
                    out("CYCL DEF 200 DRILLING ~")
                    pk = peck if peck else -depth
                    body = [("Q200", r - top, "SET-UP CLEARANCE"), ("Q201", depth, "DEPTH"), ("Q206", f, "FEED RATE FOR PLNGNG"), ("Q202", pk, "PLUNGING DEPTH"), ("Q210", 0, "DWELL TIME AT TOP"), ("Q203", top, "SURFACE COORDINATE"), ("Q204", 50, "2ND SET-UP CLEARANCE"), ("Q211", dwell or 0, "DWELL TIME AT DEPTH")]
                for i, (k, v, c) in enumerate(body):
                    L.append(f"  {k}={q(v)} ;{c}" + (" ~" if i + 1 < len(body) else ""))
                for x, y in pos:
                    out(f"L X{q(x)} Y{q(y)} FMAX M99")
                continue
            kindm = m[0]
            x, y, z = m[1], m[2], m[3]
            if first and kindm == "rapid":
                out(f"L X{q(x)} Y{q(y)} R0 FMAX")
                out("L Z+50 FMAX M8")
                cur = [x, y, 50.0]
                first = False
                continue
            words = []
            for a, v, c in (("X", x, cur[0]), ("Y", y, cur[1]), ("Z", z, cur[2])):
                if v is not None and (c is None or abs(v - c) > 1e-9):
                    words.append(f"{a}{q(v)}")
            if kindm == "rapid":
                if words:
                    out("L " + " ".join(words) + " FMAX")
            elif kindm == "feed":
                out("L " + " ".join(words) + f" F{int(round(m[4]))}")
            elif kindm == "arc":
                cx, cy, ccw, f = m[4], m[5], m[6], m[7]
                out(f"CC X{q(cx)} Y{q(cy)}")
                out("C " + " ".join(w for w in words if not w.startswith("Z")) + (" DR+" if ccw else " DR-") + f" F{int(round(f))}")
            for k, v in enumerate((x, y, z)):
                if v is not None:
                    cur[k] = v
        out("L Z+50 FMAX M9")
        out("M5")
    out("M30")
    out(f"END PGM {name.upper()} MM")
    return "\n".join(L) + "\n"


# ---------------------------------------------------------------- parts

STOCK = (0, 0, -25, 120, 80, 0)
FACE_MILL = ("FACE_MILL", 50.0)
EM10 = ("FLAT_END_MILL", 10.0)
EM8 = ("FLAT_END_MILL", 8.0)


def part(name, tools, ops, features, workingsteps, stock=STOCK):
    return dict(name=name, tools=tools, ops=ops, features=features, workingsteps=workingsteps, stock=stock)


# The sidecars' hole depths were then converted to the convention a drawing uses: the depth
# where the full diameter ends (a drill's tip lies (d/2)/tan(59 deg) below it), the deepest
# such section of the tools that made the hole. `depth` here is the tip; convert on a rerun.
def hole_f(positions, d, depth):
    return dict(kind="round_hole", x=positions[0][0], y=positions[0][1], count=len(positions), diameter=d, depth=depth)


def pocket_f(cx, cy, w, l, rc, depth):
    return dict(kind="closed_pocket", x=cx, y=cy, width=w, length=l, corner_radius=rc, depth=depth)


def face_f(depth):
    # Trimmed to the stock (120 x 80, passes along X).
    return dict(kind="planar_face", depth=depth, length=120.0, width=80.0)


def profile_f(depth):
    return dict(kind="general_outside_profile", depth=depth)


P4 = [(20.0, 20.0), (100.0, 20.0), (100.0, 60.0), (20.0, 60.0)]
P3 = [(30.0, 40.0), (60.0, 40.0), (90.0, 40.0)]

PARTS = [
    part("face_drill", {1: FACE_MILL, 2: ("DRILL", 8.5)},
         [(1, 1200, face(50, 0, 120, 0, 80, [-0.5, -1.0], 900)), (2, 2200, drill("drill", P4, -1.0, -16.0, 220))],
         [face_f(1.0), hole_f(P4, 8.5, 15.0)], ["plane_finish_milling", "drilling"]),
    part("peck_ream", {3: ("DRILL", 9.8), 4: ("REAMER", 10.0)},
         [(3, 2000, drill("peck", P3, 0.0, -22.0, 200, peck=4.0)), (4, 400, drill("ream", P3, 0.0, -20.0, 80))],
         [hole_f(P3, 10.0, 22.0)], ["multistep_drilling", "reaming"]),
    part("pocket_rough_finish", {5: EM10},
         [(5, 8000, pocket_rough(10, 60, 40, 50, 30, 6, [-3.0, -6.0], 1500) + pocket_finish(10, 60, 40, 50, 30, 6, -6.0, 1500))],
         [pocket_f(60, 40, 50, 30, 6, 6.0)], ["bottom_and_side_rough_milling", "side_finish_milling"]),
    part("boss_profile", {6: ("FLAT_END_MILL", 12.0)},
         [(6, 6000, profile(12, 60, 40, 70, 40, 5, [-4.0, -8.0], 1200, 0.3) + profile(12, 60, 40, 70, 40, 5, [-8.0], 900, 0.0))],
         [profile_f(8.0)], ["side_rough_milling", "side_finish_milling"]),
    part("two_pockets_one_tool", {7: EM8},
         [(7, 9000, pocket_finish(8, 30, 40, 30, 24, 4, -5.0, 1000) + pocket_finish(8, 90, 40, 30, 24, 4, -5.0, 1000))],
         [pocket_f(30, 40, 30, 24, 4, 5.0), pocket_f(90, 40, 30, 24, 4, 5.0)], ["side_finish_milling", "side_finish_milling"]),
    part("spot_drill_ream", {8: ("SPOT_DRILL", 10.0), 9: ("DRILL", 7.8), 10: ("REAMER", 8.0)},
         [(8, 3000, drill("spot", P4, 0.0, -2.0, 150, dwell=0.3)), (9, 2400, drill("drill", P4, 0.0, -18.0, 240)), (10, 500, drill("ream", P4, 0.0, -16.0, 90))],
         [hole_f(P4, 8.0, 18.0)], ["center_drilling", "drilling", "reaming"]),
    part("two_hole_sizes", {11: ("DRILL", 6.0), 12: ("DRILL", 12.0)},
         [(11, 3000, drill("drill", P3, 0.0, -12.0, 250)), (12, 1500, drill("peck", [(30.0, 15.0), (90.0, 15.0)], 0.0, -24.0, 180, peck=6.0))],
         [hole_f(P3, 6.0, 12.0), hole_f([(30.0, 15.0), (90.0, 15.0)], 12.0, 24.0)], ["drilling", "multistep_drilling"]),
    part("face_pocket_holes", {1: FACE_MILL, 5: EM10, 2: ("DRILL", 8.5)},
         [(1, 1200, face(50, 0, 120, 0, 80, [-1.0], 900)),
          (5, 8000, pocket_finish(10, 60, 40, 40, 30, 8, -8.0, 1200)),
          (2, 2200, drill("drill", [(15.0, 15.0), (105.0, 65.0)], -1.0, -11.0, 220))],
         [face_f(1.0), pocket_f(60, 40, 40, 30, 8, 7.0), hole_f([(15.0, 15.0), (105.0, 65.0)], 8.5, 10.0)],
         ["plane_finish_milling", "side_finish_milling", "drilling"]),
    part("profile_and_holes", {6: ("FLAT_END_MILL", 12.0), 3: ("DRILL", 6.6)},
         [(6, 6000, profile(12, 60, 40, 80, 50, 8, [-6.0], 1100, 0.0)),
          (3, 2600, drill("peck", [(35.0, 30.0), (85.0, 30.0), (85.0, 50.0), (35.0, 50.0)], 0.0, -15.0, 220, peck=5.0))],
         [profile_f(6.0), hole_f([(35.0, 30.0), (85.0, 30.0), (85.0, 50.0), (35.0, 50.0)], 6.6, 15.0)], ["side_finish_milling", "multistep_drilling"]),
    part("deep_pocket_levels", {13: EM10},
         [(13, 7500, pocket_rough(10, 60, 40, 60, 40, 5, [-2.5, -5.0, -7.5, -10.0], 1400, allowance=0.2) + pocket_finish(10, 60, 40, 60, 40, 5, -10.0, 1400))],
         [pocket_f(60, 40, 60, 40, 5, 10.0)], ["bottom_and_side_rough_milling", "side_finish_milling"]),
]

# The NIST-style case: a faced top in two layers, a hole drilled by explicit moves and
# reamed, a rectangular pocket roughed and finished with one tool at one feed.
NIST = part(
    "nist_style",
    {1: FACE_MILL, 2: ("SPIRAL_DRILL", 9.8), 4: ("REAMER", 10.0), 5: EM10},
    [(1, 1200, face(50, 0, 120, 0, 80, [-0.5, -1.0], 900)),
     (2, 2000, expanded("peck", [(25.0, 40.0)], -1.0, -21.0, 200, peck=5.0)),
     (4, 400, drill("ream", [(25.0, 40.0)], -1.0, -19.0, 80)),
     (5, 8000, pocket_rough(10, 75, 40, 40, 30, 6, [-4.0, -7.0], 1200) + pocket_finish(10, 75, 40, 40, 30, 6, -7.0, 1200))],
    [face_f(1.0), hole_f([(25.0, 40.0)], 10.0, 20.0), pocket_f(75, 40, 40, 30, 6, 6.0)],
    ["plane_finish_milling", "multistep_drilling", "reaming", "bottom_and_side_rough_milling", "side_finish_milling"],
)

EXPANDED = part(
    "expanded_drilling", {2: ("DRILL", 8.5), 4: ("REAMER", 9.0)},
    [(2, 2200, expanded("peck", P4, 0.0, -18.0, 220, peck=6.0)), (4, 450, expanded("ream", P4, 0.0, -15.0, 90))],
    [hole_f(P4, 9.0, 18.0)], ["multistep_drilling", "reaming"],
)


# Roughing that ramps into each level at half the feed: the ramps are entries, not cuts.
RAMP = part(
    "pocket_ramp_entry", {14: ("FLAT_END_MILL", 12.0)},
    [(14, 7000, pocket_rough(12, 60, 40, 60, 44, 8, [-3.0, -6.0, -9.0], 1600, ramp=16.0) + pocket_finish(12, 60, 40, 60, 44, 8, -9.0, 1600))],
    [pocket_f(60, 40, 60, 44, 8, 9.0)], ["bottom_and_side_rough_milling", "side_finish_milling"],
)


def main():
    posts = [("fanuc", "nc", fanuc), ("siemens", "mpf", siemens), ("heidenhain", "h", heidenhain)]
    count = 0
    for k, p in enumerate(PARTS + [NIST, EXPANDED, RAMP]):
        for d, (dialect, ext, post) in enumerate(posts):
            # Explicit moves are what Fanuc-family posts expand; the others keep cycles.
            if p["name"] in ("nist_style", "expanded_drilling") and dialect != "fanuc":
                continue
            haas = dialect == "fanuc" and k % 2 == 1
            name = f"{p['name']}_{'haas' if haas else dialect}"
            stock = p["stock"] if k % 3 != 2 else None
            if dialect == "fanuc":
                text = post(name, 5000 + k, p["tools"], p["ops"], stock, haas=haas)
            else:
                text = post(name, 5000 + k, p["tools"], p["ops"], stock)
            with open(f"{name}.{ext}", "w") as f:
                f.write(text)
            side = dict(dialect="haas" if haas else dialect, workingsteps=p["workingsteps"], features=p["features"], stock=stock is not None)
            with open(f"{name}.json", "w") as f:
                json.dump(side, f, indent=1)
                f.write("\n")
            count += 1
    # Edited variants of one part for the diff tests (tests/it/edits.rs): what an operator or
    # a CAM re-post changes in the roughing.
    import os
    os.makedirs("edits", exist_ok=True)
    tools = {5: EM10}
    variants = {
        "original": pocket_rough(10, 60, 40, 50, 30, 6, [-3.0, -6.0], 1500),
        "stepover": pocket_rough(10, 60, 40, 50, 30, 6, [-3.0, -6.0], 1500, step_share=0.4),
        "allowance": pocket_rough(10, 60, 40, 50, 30, 6, [-3.0, -6.0], 1500, allowance=0.5),
        "axial_depth": pocket_rough(10, 60, 40, 50, 30, 6, [-2.0, -4.0, -6.0], 1500),
    }
    for key, rough in variants.items():
        ops = [(5, 8000, rough + pocket_finish(10, 60, 40, 50, 30, 6, -6.0, 1500))]
        with open(f"edits/pocket_{key}.nc", "w") as f:
            f.write(fanuc(f"pocket_{key}", 6000, tools, ops, STOCK))
    print(count, "programs")


if __name__ == "__main__":
    main()
