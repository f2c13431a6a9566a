#!/usr/bin/env python3
"""Independent cross-check of tests/programs/posts: reads each program with a small reader of its own
(the subset of each dialect these programs use), sweeps the tool over check points taken from the
sidecar's features, and reports where the material a program removes disagrees with the sidecar.
It does not use ncplan. Run: python3 tests/posts_gen/verify.py [name ...]"""
import glob
import json
import math
import os
import re
import sys

HERE = os.path.join(os.path.dirname(__file__), '..', 'programs', 'posts')

# design stock for programs whose stock is not stated (from DESIGN.md)
DESIGN_STOCK = {
    'f360_fanuc_pocket_helix': ((0, 100), (0, 80), (-20, 0)),
    'f360_haas_profile_holes': ((-45, 45), (-30, 30), (-20, 0)),
    'f360_fanuc_face_slots': ((0, 120), (0, 60), (-25, 1)),
    'f360_fanuc_bracket': ((0, 100), (0, 60), (-20, 1)),
    'f360_haas_drill_ream_tap': ((0, 80), (0, 50), (-15, 0)),
    'f360_fanuc_pocket_ctrlcomp': ((0, 120), (0, 80), (-30, 0)),
    'f360_lcnc_pocket_holes': ((0, 100), (0, 60), (-20, 0)),
    'f360_lcnc_profile_face': ((-40, 40), (-30, 30), (-20, 1)),
    'nx_840d_pocket_holes': ((0, 110), (0, 70), (-25, 0)),
    'nx_fanuc_profile': ((0, 120), (0, 80), (-30, 0)),
    'nx_clsf_pocket_drill': ((0, 100), (0, 60), (-20, 0)),
    'iso4343_profile_face': ((0, 80), (0, 60), (-15, 1)),
    'creo_slot_step': ((0, 80), (0, 50), (-20, 0)),
    'shop_lcnc_plate': ((0, 100), (0, 60), (-12, 0.5)),
    'shop_lcnc_profile': ((-28, 28), (-18, 18), (-10, 0)),
    'shop_fanuc_pocket': ((0, 120), (0, 70), (-20, 0)),
    'shop_haas_slot_holes': ((0, 100), (0, 70), (-15, 0)),
    'shop_840d_step': ((0, 90), (0, 60), (-20, 0)),
    'f360_lcnc_step_slot': ((0, 90), (0, 50), (-20, 0)),
    'f360_haas_open_pocket': ((0, 100), (0, 60), (-20, 0)),
    'shop_fanuc_boltcircle': ((0, 100), (0, 100), (-10, 0)),
}
NX_FANUC_TOOLS = {1: 20.0}


# ------------------------------------------------------------------ tool sizes
def tool_sizes(name, text, sidecar):
    d = {}
    for m in re.finditer(r'T(\d+)\s+D=([\d.]+)', text):
        d[int(m.group(1))] = float(m.group(2))
    for m in re.finditer(r'#(\d+) D=([\d.]+)', text):
        d[int(m.group(1))] = float(m.group(2))
    for m in re.finditer(r'T(\d+) \|[^|]*\|[^|]*\|[^|]*\| TOOL DIA\. - ([\d.]+)', text):
        d[int(m.group(1))] = float(m.group(2))
    for m in re.finditer(r';\s?T(\d+) \S+ D([\d.]+)', text):
        d[int(m.group(1))] = float(m.group(2))
    tt = sidecar.get('tool_table')
    if tt:
        tx = open(os.path.join(HERE, tt)).read()
        for m in re.finditer(r'^T(\d+) P\d+ .*?D([\d.]+)', tx, re.M):
            d[int(m.group(1))] = float(m.group(2))
        for m in re.finditer(r'G10 L12 P(\d+) R([\d.]+)', tx):
            d[int(m.group(1))] = 2 * float(m.group(2))
        for m in re.finditer(r'\$TC_DP6\[(\d+),1\]=([\d.]+)', tx):
            d[int(m.group(1))] = 2 * float(m.group(2))
        for m in re.finditer(r'^(\d+)\s+\S+\s+[+-][\d.]+\s+\+([\d.]+)', tx, re.M):
            d[int(m.group(1))] = 2 * float(m.group(2))
    if name == 'nx_fanuc_profile':
        d.update(NX_FANUC_TOOLS)
    return d


# ------------------------------------------------------------------ path model
class Path:
    def __init__(self):
        self.segs = []      # dict(kind, p0, p1, c, ccw, R, comp, rnd)
        self.holes = []     # (x, y, tip_z, dia)
        self.pos = [0.0, 0.0, 100.0]
        self.R = 0.0
        self.dia = 0.0
        self.comp = 'off'

    def line(self, x, y, z, feed):
        p0 = tuple(self.pos)
        p1 = (p0[0] if x is None else x, p0[1] if y is None else y, p0[2] if z is None else z)
        if p1 != p0:
            self.segs.append(dict(kind='line', p0=p0, p1=p1, R=self.R, feed=feed, comp=self.comp))
        self.pos = list(p1)

    def arc(self, x, y, z, cx, cy, ccw):
        p0 = tuple(self.pos)
        p1 = (p0[0] if x is None else x, p0[1] if y is None else y, p0[2] if z is None else z)
        self.segs.append(dict(kind='arc', p0=p0, p1=p1, c=(cx, cy), ccw=ccw, R=self.R, feed=True,
                              comp=self.comp))
        self.pos = list(p1)

    def hole(self, x, y, tip):
        self.holes.append((x, y, tip, self.dia))

    def tool(self, dia):
        self.dia = dia or 0.0
        self.R = self.dia / 2


def arc_from_radius(p0, p1, r, ccw):
    """Centre of an arc from p0 to p1 with radius r (r < 0: the longer arc)."""
    x0, y0 = p0[0], p0[1]
    x1, y1 = p1[0], p1[1]
    mx, my = (x0 + x1) / 2, (y0 + y1) / 2
    dx, dy = x1 - x0, y1 - y0
    q = math.hypot(dx, dy)
    h = math.sqrt(max(abs(r) ** 2 - (q / 2) ** 2, 0))
    # centre to the left of the chord for a CCW arc of <= 180 degrees
    nx, ny = -dy / q, dx / q
    s = 1 if ccw else -1
    if r < 0:
        s = -s
    return mx + s * h * nx, my + s * h * ny


# ------------------------------------------------------------------ readers
def read_gcode(text, tools, siemens=False):
    P = Path()
    # A router's program: no tool change, the one tool of the header is in the spindle.
    if len(tools) == 1 and not re.search(r'\bM0?6\b', text):
        P.tool(next(iter(tools.values())))
    motion = 0
    cycle = None
    mcall = None
    names = {}
    pend_t = None
    for raw in expand_osub(text).splitlines():
        line = raw.strip()
        if not line or line.startswith('%') or re.match(r'^O\d', line):
            continue
        if siemens:
            line = line.split(';', 1)[0]
        else:
            line = re.sub(r'\([^)]*\)', '', line)
        line = re.sub(r'^[N:]\d+\s*', '', line).strip()
        if not line:
            continue
        if re.search(r'\bG28\b|\bG53\b|SUPA|M140|\bG10\b|\bo\d+\b', line):
            if 'o100 call' in line:
                pass
            else:
                P.pos[2] = 100.0
                continue
        m = re.match(r'MCALL\s*(CYCLE\d+)\((.*)\)', line)
        if m:
            args = m.group(2).split(',')
            mcall = float(args[3])
            continue
        if line == 'MCALL':
            mcall = None
            continue
        m = re.search(r'T="([^"]+)"', line)
        if m:
            dm = re.search(r'_D([\d.]+?)(_|$)', m.group(1))
            pend_t = float(dm.group(1)) if dm else 0
            continue
        words = re.findall(r'([A-Z]+)\s*(=\s*AC\(([^)]*)\)|=\s*[-+]?[\d.]+|[-+]?[\d.]+)', line)
        w = {}
        gs = []
        for k, v, ac in words:
            if ac:
                val = float(ac)
            else:
                val = float(v.lstrip('=').strip())
            if k == 'G':
                gs.append(int(round(val)))
            else:
                w[k] = val
        if 'T' in w:
            pend_t = tools.get(int(w['T']), 0)
        if re.search(r'\bM0?6\b', line) and pend_t is not None:
            P.tool(pend_t)
        for g in gs:
            if g in (0, 1, 2, 3):
                motion = g
                cycle = None if cycle and g in (0, 1, 2, 3) else cycle
            elif g == 40:
                P.comp = 'off'
            elif g == 41:
                P.comp = 'left'
            elif g == 42:
                P.comp = 'right'
            elif g == 80:
                cycle = None
            elif g in (73, 81, 82, 83, 84, 85, 86, 89):
                cycle = dict(z=w.get('Z'), r=w.get('R'))
        x, y, z = w.get('X'), w.get('Y'), w.get('Z')
        if cycle is not None and (x is not None or y is not None or any(g in (81, 83, 84, 85, 73, 82) for g in gs)):
            if 'Z' in w:
                cycle['z'] = w['Z']
            hx = P.pos[0] if x is None else x
            hy = P.pos[1] if y is None else y
            P.pos[0], P.pos[1] = hx, hy
            P.hole(hx, hy, cycle['z'])
            continue
        if mcall is not None and (x is not None or y is not None):
            P.pos[0] = P.pos[0] if x is None else x
            P.pos[1] = P.pos[1] if y is None else y
            P.hole(P.pos[0], P.pos[1], mcall)
            continue
        if x is None and y is None and z is None:
            continue
        if motion in (0, 1):
            P.line(x, y, z, motion == 1)
            if 'RND' in w:
                P.segs[-1]['rnd'] = w['RND']
        else:
            p1 = (P.pos[0] if x is None else x, P.pos[1] if y is None else y)
            if 'CR' in w or 'R' in w:
                cx, cy = arc_from_radius(P.pos, p1, w.get('CR', w.get('R')), motion == 3)
            elif siemens and re.search(r'I\s*=\s*AC', line):
                cx, cy = w['I'], w['J']
            else:
                cx, cy = P.pos[0] + w.get('I', 0), P.pos[1] + w.get('J', 0)
            P.arc(x, y, z, cx, cy, motion == 3)
    return P


def expand_osub(text):
    """LinuxCNC: inline `oN call` with the body of `oN sub` .. `oN endsub`."""
    subs = {}
    out = []
    cur = None
    for ln in text.splitlines():
        m = re.match(r'\s*o(\d+)\s+(sub|endsub|call)', ln)
        if m and m.group(2) == 'sub':
            cur = m.group(1)
            subs[cur] = []
            continue
        if m and m.group(2) == 'endsub':
            cur = None
            continue
        if cur is not None:
            subs[cur].append(ln)
            continue
        if m and m.group(2) == 'call':
            out.extend(subs[m.group(1)])
            continue
        out.append(ln)
    return '\n'.join(out)


def expand_lbl(lines):
    """Klartext: inline CALL LBL n (subprogram bodies after the main program's end)."""
    body = {}
    main = []
    cur = None
    ended = False
    for ln in lines:
        t = ln['text']
        m = re.match(r'LBL (\d+)$', t)
        if m:
            n = int(m.group(1))
            if n == 0:
                cur = None
            else:
                cur = n
                body[n] = []
            continue
        if cur is not None:
            body[cur].append(ln)
        elif not ended:
            main.append(ln)
        if re.match(r'(M30|M2|M02)\b', t) or t.startswith('END PGM'):
            ended = True
    out = []
    for ln in main:
        m = re.match(r'CALL LBL (\d+)', ln['text'])
        if m:
            out.extend(body[int(m.group(1))])
        else:
            out.append(ln)
    return out


def read_tnc(text, tools):
    P = Path()
    blocks = []
    for raw in text.splitlines():
        if re.match(r'^\s+Q\d+=', raw):
            blocks[-1]['q'].update({m.group(1): float(m.group(2)) for m in
                                    re.finditer(r'(Q\d+)=([-+]?[\d.]+)', raw)})
            continue
        m = re.match(r'^(\d+)\s+(.*)$', raw)
        if not m:
            continue
        t = m.group(2).split(';', 1)[0].strip()
        blocks.append(dict(text=t, q={}))
    blocks = expand_lbl(blocks)
    cc = None
    cyc = None
    for b in blocks:
        t = b['text']
        if not t:
            continue
        if t.startswith('TOOL CALL'):
            n = int(t.split()[2])
            P.tool(tools.get(n, 0))
            continue
        if t.startswith('CYCL DEF 200') or t.startswith('CYCL DEF 203'):
            cyc = b['q']
            continue
        if 'M140' in t or 'M91' in t:
            P.pos[2] = 100.0
            continue
        m = re.match(r'CC X([-+]?[\d.]+) Y([-+]?[\d.]+)', t)
        if m:
            cc = (float(m.group(1)), float(m.group(2)))
            continue
        m = re.match(r'RND R([\d.]+)', t)
        if m:
            P.segs[-1]['rnd'] = float(m.group(1))
            continue
        m = re.match(r'CP IPA([-+]?[\d.]+) IZ([-+]?[\d.]+) DR([-+])', t)
        if m:
            sw, dz = float(m.group(1)), float(m.group(2))
            a0 = math.atan2(P.pos[1] - cc[1], P.pos[0] - cc[0]) + math.radians(sw)
            r = math.hypot(P.pos[0] - cc[0], P.pos[1] - cc[1])
            P.arc(cc[0] + r * math.cos(a0), cc[1] + r * math.sin(a0), P.pos[2] + dz, cc[0], cc[1],
                  m.group(3) == '+')
            continue
        m = re.match(r'CR X([-+]?[\d.]+) Y([-+]?[\d.]+) R([-+]?[\d.]+) DR([-+])', t)
        if m:
            x, y, r = float(m.group(1)), float(m.group(2)), float(m.group(3))
            ccw = m.group(4) == '+'
            cx, cy = arc_from_radius(P.pos, (x, y), r, ccw)
            P.arc(x, y, None, cx, cy, ccw)
            continue
        if re.match(r'^(L|C) ', t):
            w = {k: float(v) for k, v in re.findall(r'\b([XYZ])([-+]?[\d.]+)', t)}
            if ' RL' in t:
                P.comp = 'left'
            elif ' RR' in t:
                P.comp = 'right'
            elif ' R0' in t:
                P.comp = 'off'
            if t.startswith('L'):
                rapid = 'FMAX' in t or 'F MAX' in t
                if 'M99' in t:
                    P.pos[0] = w.get('X', P.pos[0])
                    P.pos[1] = w.get('Y', P.pos[1])
                    P.hole(P.pos[0], P.pos[1], cyc['Q203'] + cyc['Q201'])
                    continue
                P.line(w.get('X'), w.get('Y'), w.get('Z'), not rapid)
            else:
                P.arc(w.get('X'), w.get('Y'), w.get('Z'), cc[0], cc[1], 'DR+' in t)
    return P


def read_cl(text, tools):
    P = Path()
    nx = 'TOOL PATH/' in text
    lines = []
    buf = ''
    for raw in text.splitlines():
        m = re.match(r'\$\$-> CUTTER / ([\d.]+)', raw.strip())
        if m:
            lines.append('CUTTERC/' + m.group(1))
            continue
        s = raw.split('$$', 1)[0].rstrip()
        if s.endswith('$'):
            buf += s[:-1]
            continue
        s = buf + s
        buf = ''
        if s.strip():
            lines.append(s.strip())
    rapid = False
    pend = None
    cyc = None
    for s in lines:
        major, _, rest = s.partition('/')
        major = major.strip()
        args = [a.strip() for a in rest.split(',')] if rest else []
        if major == 'RAPID' and rest.strip() == '':
            rapid = True
            continue
        if major in ('TLDATA',):
            v = [a for a in args if re.match(r'^[-\d.]+$', a)]
            P.tool(float(v[0]))
        elif major in ('CUTTER', 'CUTTERC'):
            P.tool(float(args[0]))
        elif major == 'CIRCLE' and len(args) == 6:
            v = [float(a) for a in args]
            pend = ('noradius', v[0], v[1], v[5] > 0)
        elif major == 'RAPID':
            rapid = True
        elif major == 'CIRCLE' and len(args) > 6:
            v = [float(a) for a in args[:7]]
            if nx:
                ccw = v[5] < 0
            else:
                ccw = v[5] > 0
            pend = (v[0], v[1], ccw)
        elif major == 'MOVARC':
            v = [float(a) for a in args[:7]]
            pend = (v[0], v[1], v[5] > 0)
        elif major == 'CYCLE':
            if args[0] == 'OFF':
                cyc = None
            elif 'FEDTO' in args:
                v = float(args[args.index('FEDTO') + 1])
                cyc = ('rel', v if nx else -v)
            else:
                cyc = ('bottom', None)
        elif major == 'GOTO':
            x, y, z = (float(a) for a in args[:3])
            if cyc is not None and not rapid:
                P.hole(x, y, z + cyc[1] if cyc[0] == 'rel' else z)
                P.pos = [x, y, z]
            elif pend and pend[0] == 'noradius':
                P.arc(x, y, z, pend[1], pend[2], pend[3])
                pend = None
            elif pend:
                P.arc(x, y, z, pend[0], pend[1], pend[2])
                pend = None
            else:
                P.line(x, y, z, not rapid)
            rapid = False
    return P


# ------------------------------------------------------------------ compensation and rounding
def seg_dir(s, at_end):
    if s['kind'] == 'line':
        dx, dy = s['p1'][0] - s['p0'][0], s['p1'][1] - s['p0'][1]
        q = math.hypot(dx, dy) or 1
        return dx / q, dy / q
    cx, cy = s['c']
    p = s['p1'] if at_end else s['p0']
    rx, ry = p[0] - cx, p[1] - cy
    q = math.hypot(rx, ry) or 1
    return (-ry / q, rx / q) if s['ccw'] else (ry / q, -rx / q)


def apply_rnd(segs):
    out = []
    i = 0
    while i < len(segs):
        s = dict(segs[i])
        if s.get('rnd') and i + 1 < len(segs) and s['kind'] == 'line' and segs[i + 1]['kind'] == 'line':
            r = s['rnd']
            n = dict(segs[i + 1])
            d0 = seg_dir(s, True)
            d1 = seg_dir(n, False)
            corner = s['p1']
            a = (corner[0] - d0[0] * r, corner[1] - d0[1] * r, corner[2])
            b = (corner[0] + d1[0] * r, corner[1] + d1[1] * r, corner[2])
            cross = d0[0] * d1[1] - d0[1] * d1[0]
            ccw = cross > 0
            nl = (-d0[1], d0[0]) if ccw else (d0[1], -d0[0])
            c = (a[0] + nl[0] * r, a[1] + nl[1] * r)
            s['p1'] = a
            out.append(s)
            out.append(dict(kind='arc', p0=a, p1=b, c=c, ccw=ccw, R=s['R'], feed=True, comp=s['comp']))
            n['p0'] = b
            segs = segs[:i + 1] + [n] + segs[i + 2:]
            i += 1
            continue
        out.append(s)
        i += 1
    return out


def apply_comp(segs):
    out = []
    for i, s in enumerate(segs):
        if s['comp'] == 'off' or s['R'] == 0:
            out.append(s)
            continue
        side = 1 if s['comp'] == 'left' else -1
        R = s['R'] * side
        prev_on = i > 0 and segs[i - 1]['comp'] != 'off'
        next_on = i + 1 < len(segs) and segs[i + 1]['comp'] != 'off'

        def off(p, d):
            return (p[0] - d[1] * R, p[1] + d[0] * R, p[2])

        t = dict(s)
        if s['kind'] == 'line':
            d = seg_dir(s, False)
            if not prev_on:       # lead-in: start uncompensated, end on the next element's normal
                nd = seg_dir(segs[i + 1], False) if next_on else d
                t['p1'] = off(s['p1'], nd)
            else:
                t['p0'] = off(s['p0'], d)
                t['p1'] = off(s['p1'], d)
        else:
            t['p0'] = off(s['p0'], seg_dir(s, False))
            t['p1'] = off(s['p1'], seg_dir(s, True))
        out.append(t)
    # lead-out line (first element with comp off after a comp chain): start from the offset end
    for i in range(1, len(out)):
        if out[i]['comp'] == 'off' and segs[i - 1]['comp'] != 'off' and out[i]['kind'] == 'line':
            out[i] = dict(out[i], p0=out[i - 1]['p1'])
    return out


# ------------------------------------------------------------------ sweep
def min_z_at(segs, px, py, skip_tool_below=0.0):
    best = None
    for s in segs:
        if not s['feed'] or s['R'] <= skip_tool_below:
            continue
        R = s['R'] + 1e-6
        z0, z1 = s['p0'][2], s['p1'][2]
        if s['kind'] == 'line':
            ax, ay = s['p0'][0], s['p0'][1]
            bx, by = s['p1'][0], s['p1'][1]
            dx, dy = bx - ax, by - ay
            L2 = dx * dx + dy * dy
            if abs(z0 - z1) < 1e-9:
                t = 0 if L2 == 0 else max(0, min(1, ((px - ax) * dx + (py - ay) * dy) / L2))
                if math.hypot(ax + t * dx - px, ay + t * dy - py) <= R:
                    best = z0 if best is None else min(best, z0)
            else:
                n = max(2, int(math.sqrt(L2) / 0.25) + 1)
                for k in range(n + 1):
                    t = k / n
                    if math.hypot(ax + t * dx - px, ay + t * dy - py) <= R:
                        z = z0 + t * (z1 - z0)
                        best = z if best is None else min(best, z)
        else:
            cx, cy = s['c']
            r = math.hypot(s['p0'][0] - cx, s['p0'][1] - cy)
            a0 = math.atan2(s['p0'][1] - cy, s['p0'][0] - cx)
            a1 = math.atan2(s['p1'][1] - cy, s['p1'][0] - cx)
            if s['ccw']:
                sw = (a1 - a0) % (2 * math.pi)
            else:
                sw = -((a0 - a1) % (2 * math.pi))
            if abs(sw) < 1e-9:
                sw = 2 * math.pi if s['ccw'] else -2 * math.pi
            n = max(4, int(abs(sw) * r / 0.25) + 1)
            for k in range(n + 1):
                t = k / n
                a = a0 + sw * t
                if math.hypot(cx + r * math.cos(a) - px, cy + r * math.sin(a) - py) <= R:
                    z = z0 + t * (z1 - z0)
                    best = z if best is None else min(best, z)
    return best


def rrect_samples(cx, cy, w, l, r, off, step=2.0):
    """Points on the rounded rectangle offset by `off` (negative = inside)."""
    pts = []
    x0, x1, y0, y1 = cx - w / 2 + r, cx + w / 2 - r, cy - l / 2 + r, cy + l / 2 - r
    R = r + off
    for (ax, ay, bx, by, nx, ny) in [(x0, cy - l / 2, x1, cy - l / 2, 0, -1), (cx + w / 2, y0, cx + w / 2, y1, 1, 0),
                                     (x1, cy + l / 2, x0, cy + l / 2, 0, 1), (cx - w / 2, y1, cx - w / 2, y0, -1, 0)]:
        n = max(1, int(math.hypot(bx - ax, by - ay) / step))
        for k in range(n + 1):
            t = k / n
            pts.append((ax + t * (bx - ax) + nx * off, ay + t * (by - ay) + ny * off))
    if R > 0:
        for (ccx, ccy, a) in [(x1, y0, -90), (x1, y1, 0), (x0, y1, 90), (x0, y0, 180)]:
            for k in range(5):
                aa = math.radians(a + 22.5 * k)
                pts.append((ccx + R * math.cos(aa), ccy + R * math.sin(aa)))
    return pts


def check(name):
    sc = json.load(open(os.path.join(HERE, name + '.json')))
    prog = [f for f in glob.glob(os.path.join(HERE, name + '.*'))
            if not re.search(r'\.(json|tbl|ofs|T|ini)$', f)][0]
    text = open(prog).read()
    tools = tool_sizes(name, text, sc)
    dia = sc['dialect']
    if dia == 'heidenhain':
        P = read_tnc(text, tools)
    elif dia == 'cldata':
        P = read_cl(text, tools)
    else:
        P = read_gcode(text, tools, siemens=(dia == 'siemens'))
    segs = apply_comp(apply_rnd(P.segs))
    stock = sc.get('stock')
    if stock:
        st = (tuple(stock['x']), tuple(stock['y']), tuple(stock['z']))
    else:
        st = DESIGN_STOCK.get(name)
    errs = []

    def inside_stock(p):
        return st is None or (st[0][0] + 0.2 <= p[0] <= st[0][1] - 0.2 and st[1][0] + 0.2 <= p[1] <= st[1][1] - 0.2)

    def expect_cut(pts, zexp, what):
        bad = 0
        for p in pts:
            if not inside_stock(p):
                continue
            z = min_z_at(segs, *p)
            if z is None or abs(z - zexp) > 0.06:
                bad += 1
                if bad <= 3:
                    errs.append('%s: at (%.2f, %.2f) min z %s, expected %.3f' % (what, p[0], p[1], z, zexp))
        return bad

    def expect_uncut(pts, ztop, what):
        bad = 0
        for p in pts:
            if not inside_stock(p):
                continue
            z = min_z_at(segs, *p)
            if z is not None and z < ztop - 0.03:
                bad += 1
                if bad <= 3:
                    errs.append('%s: at (%.2f, %.2f) cut to %.3f, should stay at %.3f' % (what, p[0], p[1], z, ztop))
        return bad

    for f in sc['features']:
        k = f['kind']
        top = f.get('top', 0)
        if k in ('closed_pocket', 'open_pocket'):
            w, l, r = f['width'], f['length'], f['corner_radius']
            cx, cy = f['x'], f['y']
            if k == 'open_pocket':
                ext = 20
                side = f['open_side']
                if side == 'y-':
                    cy, l = cy - ext / 2, l + ext
                elif side == 'y+':
                    cy, l = cy + ext / 2, l + ext
                elif side == 'x-':
                    cx, w = cx - ext / 2, w + ext
                else:
                    cx, w = cx + ext / 2, w + ext
            inner = rrect_samples(cx, cy, w, l, r, -0.3)
            grid = [(cx + dx, cy + dy) for dx in frange(-w / 2 + 1, w / 2 - 1, 4) for dy in frange(-l / 2 + 1, l / 2 - 1, 4)
                    if in_rrect(dx, dy, w, l, r, 0.3)]
            expect_cut(inner + grid, top - f['depth'], name + ' ' + k + ' floor')
            expect_uncut(rrect_samples(cx, cy, w, l, r, 0.3), top, name + ' ' + k + ' wall')
        elif k == 'general_outside_profile':
            w, l, r = f['width'], f['length'], f['corner_radius']
            expect_uncut(rrect_samples(f['x'], f['y'], w, l, r, -0.3), top, name + ' boss')
            expect_cut(rrect_samples(f['x'], f['y'], w, l, r, 0.3), top - f['depth'], name + ' profile floor')
        elif k == 'slot':
            wd = f['width']
            L = f['length_end_to_end']
            if f['orientation'] == 'x':
                cx, cy, w, l = f['x'], f['y'], L, wd
            else:
                cx, cy, w, l = f['x'], f['y'], wd, L
            expect_cut(rrect_samples(cx, cy, w, l, wd / 2, -0.3), top - f['depth'], name + ' slot floor')
            expect_uncut(rrect_samples(cx, cy, w, l, wd / 2, 0.3), top, name + ' slot wall')
        elif k == 'step':
            (x0, x1), (y0, y1) = st[0], st[1]
            e, wd, z = f['edge'], f['width'], f['floor_z']
            if e in ('y+', 'y-'):
                yb = y1 - wd if e == 'y+' else y0 + wd
                band = [(x, yy) for x in frange(x0 + 0.3, x1 - 0.3, 3) for yy in
                        ((yb + 0.3, y1 - 0.3) if e == 'y+' else (y0 + 0.3, yb - 0.3))]
                wall = [(x, yb - 0.3 if e == 'y+' else yb + 0.3) for x in frange(x0 + 0.3, x1 - 0.3, 3)]
            else:
                xb = x1 - wd if e == 'x+' else x0 + wd
                band = [(xx, y) for y in frange(y0 + 0.3, y1 - 0.3, 3) for xx in
                        ((xb + 0.3, x1 - 0.3) if e == 'x+' else (x0 + 0.3, xb - 0.3))]
                wall = [(xb - 0.3 if e == 'x+' else xb + 0.3, y) for y in frange(y0 + 0.3, y1 - 0.3, 3)]
            expect_cut(band, z, name + ' step floor')
            expect_uncut(wall, 0, name + ' step wall')
            if abs(f['depth'] + z) > 1e-6:
                errs.append('%s step: depth %s vs floor %s' % (name, f['depth'], z))
        elif k == 'planar_face':
            (x0, x1), (y0, y1) = st[0], st[1]
            pts = [(x, y) for x in frange(x0 + 0.5, x1 - 0.5, 5) for y in frange(y0 + 0.5, y1 - 0.5, 5)]
            bad = 0
            for p in pts:
                z = min_z_at(segs, *p)
                if z is None or z > f['z'] + 0.01:
                    bad += 1
                    if bad <= 3:
                        errs.append('%s face: (%.1f, %.1f) not faced (%s)' % (name, p[0], p[1], z))
            if st and abs(st[2][1] - f['z'] - f['depth']) > 1e-6:
                errs.append('%s face: depth %s but stock top %s' % (name, f['depth'], st[2][1]))
        elif k == 'round_hole':
            for (x, y) in f['positions']:
                hs = [h for h in P.holes if abs(h[0] - x) < 1e-3 and abs(h[1] - y) < 1e-3]
                plunge = min_z_at(segs, x, y)
                if not hs and plunge is None:
                    errs.append('%s hole (%s, %s): no cycle and no cut' % (name, x, y))
                    continue
                deepest = min([h[2] for h in hs] + ([plunge] if plunge is not None and f['bottom'] != 'conical' else []) +
                              ([plunge] if not hs and plunge is not None else []))
                dd = f.get('drilled', {}).get('diameter')
                fd = f.get('drilled', {}).get('depth', f['depth'])
                if f['bottom'] == 'through':
                    if deepest > st[2][0] - 0.3 and deepest > -f['depth'] - 0.5:
                        errs.append('%s hole (%s, %s): deepest %.3f is not through %s' % (name, x, y, deepest, f['depth']))
                    if st and abs((st[2][1] if st[2][1] <= 0 else 0) - st[2][0] - f['depth']) > 1e-6:
                        errs.append('%s hole: through depth %s vs stock %s' % (name, f['depth'], st[2]))
                elif f['bottom'] == 'conical':
                    d = dd or f['diameter']
                    exp = top - (fd + (d / 2) / math.tan(math.radians(f.get('point_angle', 118) / 2)))
                    drills = [h for h in hs if abs(h[3] - d) < 1e-6 or h[3] == 0]
                    got = min([h[2] for h in drills]) if drills else deepest
                    if abs(got - exp) > 0.03:
                        errs.append('%s hole (%s, %s): tip %.3f, expected %.3f' % (name, x, y, got, exp))
                else:
                    if abs(deepest - (top - f['depth'])) > 0.03:
                        errs.append('%s flat hole (%s, %s): bottom %.3f' % (name, x, y, deepest))
                if not hs and f['bottom'] == 'flat':
                    # A hole milled round: cut inside its wall, at its floor; the wall stays.
                    rad = f['diameter'] / 2
                    ring = lambda q: [(x + q * math.cos(a * math.pi / 8), y + q * math.sin(a * math.pi / 8)) for a in range(16)]
                    expect_cut(ring(rad - 0.3) + [(x, y)], top - f['depth'], name + ' milled hole floor')
                    expect_uncut(ring(rad + 0.3), top, name + ' milled hole wall')
                sizes = sorted({h[3] for h in hs})
                want = dd or f['diameter']
                if hs and not any(abs(s - want) < 1e-6 for s in sizes) and not f.get('thread'):
                    errs.append('%s hole (%s, %s): tools %s, expected a %s' % (name, x, y, sizes, want))
    return errs


def in_rrect(dx, dy, w, l, r, inset):
    ax, ay = abs(dx), abs(dy)
    hx, hy = w / 2 - inset, l / 2 - inset
    if ax > hx or ay > hy:
        return False
    rr = max(r - inset, 0)
    cx, cy = hx - rr, hy - rr
    if ax > cx and ay > cy:
        return math.hypot(ax - cx, ay - cy) <= rr
    return True


def frange(a, b, step):
    n = max(1, int((b - a) / step))
    return [a + (b - a) * k / n for k in range(n + 1)]


if __name__ == '__main__':
    names = sys.argv[1:] or sorted(os.path.basename(f)[:-5] for f in glob.glob(os.path.join(HERE, '*.json')))
    total = 0
    for n in names:
        e = check(n)
        total += len(e)
        print('%-36s %s' % (n, 'ok' if not e else '%d problem(s)' % len(e)))
        for x in e:
            print('    ' + x)
    sys.exit(1 if total else 0)
