#!/usr/bin/env python3
"""Second batch: NX, hyperMILL and CL-data programs (see DESIGN.md P25..P31).
Run: python3 tests/posts_gen/make2.py"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from geom import pocket, profile, face, lines_at, step_passes, slot, tip_depth  # noqa: E402
from styles2 import nx_siemens, nx_fanuc, hm_tnc, hm_siemens, nx_clsf  # noqa: E402
from emit import num  # noqa: E402

OUT = os.path.join(os.path.dirname(__file__), '..', 'programs', 'posts')
PROGRAMS = {}


def prog(fn):
    PROGRAMS[fn.__name__] = fn
    return fn


def r3(v):
    return round(v, 3)


# ------------------------------------------------------------------ P25
@prog
def nx_840d_pocket_holes():
    em = dict(t=1, d=12, name='EM_D12_R0')
    sp = dict(t=2, d=10, name='SPOT_D10_90DEG')
    dr = dict(t=3, d=9.8, name='DRILL_D9.8_118DEG')
    rm = dict(t=4, d=10, name='REAMER_D10_H7')
    pts = [(90, 15), (90, 35), (90, 55)]
    tip = r3(-(25 + tip_depth(0, 9.8, 118) + 1.5))
    ops = [dict(name='CAVITY_MILL_POCKET', tool=em, S=6000,
                moves=pocket(40, 35, 50, 40, 10, 12, [-4, -8, -12], 7, 'helix', 1100, 300,
                             clear=50.0, safe=3.0)),
           dict(name='SPOT_DRILLING', tool=sp, S=3000,
                holes=dict(cycle='spot', pts=pts, tip=-2.5, r=3, f=150, clear=50)),
           dict(name='PECK_DRILLING', tool=dr, S=1800,
                holes=dict(cycle='peck', pts=pts, tip=tip, r=3, q=5, f=200, clear=50)),
           dict(name='REAMING', tool=rm, S=350,
                holes=dict(cycle='ream', pts=pts, tip=-26.5, r=3, f=70, clear=50))]
    return 'mpf', nx_siemens('HOUSING_17', ops)


# ------------------------------------------------------------------ P26
@prog
def nx_fanuc_profile():
    t1 = dict(t=1, d=20, name='MILL_D20')
    ops = [dict(name='PLANAR_PROFILE', tool=t1, S=3500,
                moves=profile(60, 40, 100, 60, 10, 20, [-5, -10, -15, -20], 700, 250,
                              comp='control', lead=15, clear=50.0, safe=3.0))]
    return 'nc', nx_fanuc(ops)


# ------------------------------------------------------------------ P27
@prog
def hypermill_tnc_pocket_drill():
    t1 = dict(t=1, d=10, desc='T1 SCHAFTFRAESER D10 Z3 HM')
    t2 = dict(t=2, d=10, desc='T2 NC-ANBOHRER D10 90GRAD')
    t3 = dict(t=3, d=6.8, desc='T3 VHM-BOHRER D6.8 140GRAD')
    pts = [(100, 15), (100, 40), (100, 65)]
    tip = r3(-tip_depth(20, 6.8, 140))
    ops = [dict(name='1: T1 2D-TASCHE', tool=t1, S=8000,
                moves=pocket(50, 40, 60, 40, 5, 10, [-5, -10, -15], 6, 'ramp', 1200, 300,
                             clear=50.0, safe=2.0)),
           dict(name='2: T2 ZENTRIEREN', tool=t2, S=3000,
                holes=dict(cycle='spot', pts=pts, tip=-2, r=2, f=150, clear=50)),
           dict(name='3: T3 TIEFBOHREN', tool=t3, S=2600,
                holes=dict(cycle='chip', pts=pts, tip=tip, r=2, q=4, f=250, clear=50))]
    return 'h', hm_tnc('HOUSING_COVER', ops, ((0, 120), (0, 80), (-30, 0)))


# ------------------------------------------------------------------ P28
@prog
def hypermill_840d_face_openpocket():
    t1 = dict(t=1, d=50, desc='T1 PLANFRAESER D50')
    t2 = dict(t=2, d=10, desc='T2 SCHAFTFRAESER D10')
    fm, _ = face(0, 100, 0, 60, 50, 0, 35, 1500, 500, clear=50.0, safe=2.0)
    ms = [('rapid', 50, -8, None), ('rapid', None, None, 50.0), ('rapid', None, None, 2.0)]
    for i, z in enumerate([-5, -10]):
        if i:
            ms += [('rapid', None, None, 2.0), ('rapid', 50, -8, None)]
        ms += [('line', None, None, z, 300), ('line', 50, 20, z, 1000), ('line', 50, -8, z, 1000),
               ('rapid', None, None, 2.0), ('rapid', 40, -8, None), ('line', None, None, z, 300),
               ('line', 40, 20, z, 1000), ('line', 60, 20, z, 1000), ('line', 60, -8, z, 1000)]
    ms.append(('rapid', None, None, 50.0))
    sl = slot(20, 45, 80, 45, 14, 10, [-3, -6], 800, 250, clear=50.0, safe=2.0)
    ops = [dict(name='1: T1 PLANEN', tool=t1, S=3000, moves=fm),
           dict(name='2: T2 TASCHE OFFEN', tool=t2, S=8000, moves=ms),
           dict(name='3: T2 NUT', tool=t2, S=8000, moves=sl)]
    return 'mpf', hm_siemens('GABEL_12', ops, ((0, 100), (0, 60), (-20, 1)))


# ------------------------------------------------------------------ P29
@prog
def nx_clsf_pocket_drill():
    em = dict(t=1, d=8, name='MILL_D8', len=75)
    dr = dict(t=2, d=5, name='STD_DRILL_D5', len=60, taper=118, flute=30)
    tip = r3(-tip_depth(10, 5, 118))
    ops = [dict(name='CAVITY_MILL', tool=em, S=9000,
                moves=pocket(50, 30, 40, 30, 6, 8, [-4, -8], 5, 'plunge', 800, 250,
                             clear=50.0, safe=3.0)),
           dict(name='DRILLING', tool=dr, S=3500,
                holes=dict(cycle='drill', pts=[(85, 15), (85, 45)], tip=tip, r=3, f=200,
                           clear=50))]
    return 'cls', nx_clsf(ops)


# ------------------------------------------------------------------ P30 Autodesk ISO 4343 APT
@prog
def iso4343_profile_face():
    """Shape of the Autodesk 'Common ISO 4343 APT' post (2021): MODE, PARTNO, PPRINT, UNITS,
    MULTAX/OFF, per section PPRINT + CUTTER (7 parameters) + LOADTL/t, 0, l, o + SPINDL, COOLNT/ON +
    COOLNT/flood, RAPID + GOTO, FEDRAT/f, MMPM, MOVARC/centre, normal (reversed for CW), r, ANGLE,
    sweep + GOTO; CYCLE/DRILL, depth, MMPM, feed, clearance, RAPTO, r with a FEDRAT and a GOTO at the
    hole bottom (Fusion's cycle point) per hole; CYCLE/OFF; END; FINI."""
    L = []
    F6 = lambda v: '%.6f' % (round(v, 6) + 0.0)
    L.append('MODE/MILL')
    L.append("PARTNO/'1042'")
    L.append("PPRINT/'1042'")
    L.append("PPRINT/'LOCATOR PLATE'")
    L.append('UNITS/MM')
    pos = [0, 0, 15]
    feed = [None]

    def goto(x, y, z):
        x = pos[0] if x is None else x
        y = pos[1] if y is None else y
        z = pos[2] if z is None else z
        pos[:] = [x, y, z]
        L.append('GOTO/%s, %s, %s' % (F6(x), F6(y), F6(z)))

    def setfeed(f):
        if f != feed[0]:
            L.append('FEDRAT/%s, MMPM' % F6(f))
            feed[0] = f

    def run(ms):
        for mv in ms:
            if mv[0] == 'rapid':
                L.append('RAPID')
                goto(*mv[1:4])
            elif mv[0] == 'line':
                setfeed(mv[4])
                goto(*mv[1:4])
            elif mv[0] == 'arc':
                _, d, x, y, z, cx, cy, f = mv
                setfeed(f)
                r = math.hypot(pos[0] - cx, pos[1] - cy)
                a0 = math.degrees(math.atan2(pos[1] - cy, pos[0] - cx))
                a1 = math.degrees(math.atan2(y - cy, x - cx))
                sweep = (a1 - a0) % 360 if d == 'ccw' else (a0 - a1) % 360
                nz = 1.0 if d == 'ccw' else -1.0
                L.append('MOVARC/%s, %s, %s, %s, %s, %s, %s, ANGLE, %s' % (
                    F6(cx), F6(cy), F6(pos[2]), F6(0), F6(0), F6(nz), F6(r), F6(sweep)))
                goto(x, y, z)

    first = [True]

    def section(comment, d, cr, b, h, t, body, s):
        if first[0]:
            L.append('MULTAX/OFF')
            first[0] = False
        L.append("PPRINT/'%s'" % comment)
        L.append('CUTTER/%s, %s, %s, %s, %s, %s, %s' % (F6(d), F6(cr), F6(0), F6(cr), F6(0),
                                                        F6(b), F6(h)))
        L.append('LOADTL/%d, 0, %s, %d' % (t, F6(body), t))
        L.append('SPINDL/%s, RPM, CLW' % F6(s))
        if t == 1:
            L.append('COOLNT/ON')
            L.append('COOLNT/flood')

    section('Face1', 50, 0, 0, 10, 1, 45, 3000)
    fm, _ = face(0, 80, 0, 60, 50, 0, 35, 1500, 500)
    run(fm)
    section('2D Contour1', 10, 0, 0, 22, 2, 50, 8000)
    run(profile(40, 30, 60, 40, 8, 10, [-3, -6], 800, 250, lead=6, allowance=8))
    run(profile(40, 30, 60, 40, 8, 10, [-6], 800, 250, lead=6))
    # drill: the post halves the full point angle (b = 118/2 = 59)
    section('Drill1', 6, 0, 59, 40, 3, 65, 3200)
    tip = r3(15 + tip_depth(0, 6, 118) + 1.0)
    pts = [(25, 20), (55, 20), (55, 40), (25, 40)]
    L.append('RAPID')
    goto(pts[0][0], pts[0][1], 15)
    L.append('RAPID')
    goto(None, None, 5)
    L.append('CYCLE/DRILL, %s, MMPM, %s, %s, RAPTO, %s' % (F6(tip), F6(300), F6(15), F6(12)))
    for p in pts:
        L.append('FEDRAT/%s, MMPM' % F6(300))
        goto(p[0], p[1], -tip)
    L.append('CYCLE/OFF')
    L.append('RAPID')
    goto(None, None, 15)
    L.append('COOLNT/OFF')
    L.append('END')
    L.append('FINI')
    return 'apt', '\n'.join(L) + '\n'


# ------------------------------------------------------------------ P31 Creo Pro/CLfile
@prog
def creo_slot_step():
    L = []
    L.append('$$*          Pro/CLfile  Version 8.0 - 8.0.3.0')
    L.append('$$-> MFGNO / SLIDE_BASE')
    L.append('PARTNO / SLIDE_BASE')
    L.append('$$-> FEATNO / 41')
    L.append('MACHIN / UNCX01, 1')
    L.append('$$-> CUTCOM_GEOMETRY_TYPE / OUTPUT_ON_CENTER')
    L.append('UNITS / MM')
    L.append('LOADTL / 1')
    L.append('$$-> CUTTER / 20.000000')
    L.append('SPINDL / RPM, 4000.000000,  CLW')
    L.append('COOLNT / FLOOD')

    def g(x, y, z):
        L.append('GOTO / %.10f, %.10f, %.10f' % (x + 0.0, y + 0.0, z + 0.0))

    # step along the X+ edge: band X65..80, D20 centre X75, Y-15..65
    L.append('RAPID')
    g(75, -15, 50)
    L.append('RAPID')
    g(75, -15, 3)
    for i, z in enumerate([-3, -6]):
        L.append('FEDRAT / 300.000000,  MMPM')
        g(75, -15 if i == 0 else 65, z)
        L.append('FEDRAT / 900.000000,  MMPM')
        g(75, 65 if i == 0 else -15, z)
    L.append('RAPID')
    g(75, -15, 50)
    L.append('$$-> FEATNO / 42')
    L.append('LOADTL / 2')
    L.append('$$-> CUTTER / 12.000000')
    L.append('SPINDL / RPM, 6500.000000,  CLW')
    # slot along Y: width 12 = tool, centre line (10,12)..(10,38)
    L.append('RAPID')
    g(10, 12, 50)
    L.append('RAPID')
    g(10, 12, 3)
    for i, z in enumerate([-2.5, -5]):
        L.append('FEDRAT / 150.000000,  MMPM')
        g(10, 12 if i == 0 else 38, z)
        L.append('FEDRAT / 600.000000,  MMPM')
        g(10, 38 if i == 0 else 12, z)
    L.append('RAPID')
    g(10, 12, 50)

    def circle(cx, cy, z, ccw, r):
        # Creo: right-hand rule about the axis vector, record continued with '$'
        L.append('CIRCLE / %.10f, %.10f, %.10f,  $' % (cx, cy, z))
        L.append('         0.0000000000, 0.0000000000, %s, %.10f' % (
            '1.0000000000' if ccw else '-1.0000000000', r))

    # wide slot along X: width 18, centre line X28..52 at Y25, D12 centre pass + loop +-3
    L.append('RAPID')
    g(28, 25, 50)
    L.append('RAPID')
    g(28, 25, 3)
    for i, z in enumerate([-3, -6]):
        if i:
            L.append('RAPID')
            g(28, 25, 3)
        L.append('FEDRAT / 150.000000,  MMPM')
        g(28, 25, z)
        L.append('FEDRAT / 600.000000,  MMPM')
        g(52, 25, z)
        g(52, 22, z)
        circle(52, 25, z, True, 3)
        g(52, 28, z)
        g(28, 28, z)
        circle(28, 25, z, True, 3)
        g(28, 22, z)
        g(52, 22, z)
        g(52, 25, z)
        L.append('RAPID')
        g(52, 25, 3)
    L.append('RAPID')
    g(52, 25, 50)
    L.append('SPINDL / OFF')
    L.append('COOLNT / OFF')
    L.append('$$-> END /')
    L.append('FINI')
    return 'ncl', '\n'.join(L) + '\n'


# ------------------------------------------------------------------ P43 SolidWorks CAM .apt
def swnum(v):
    v = round(v + 0.0, 6)
    if abs(v) < 5e-7:
        return '0'
    t = ('%.6f' % v).rstrip('0')
    if t.startswith('0.'):
        t = t[1:]
    elif t.startswith('-0.'):
        t = '-' + t[2:]
    return t


@prog
def swcam_pocket_drill():
    """SolidWorks CAM / CAMWorks .apt shape (cldata.md C-SW): PARTNO/1, UNIT/MM, INSERT/Stock Size,
    TRNTYP + CSYS, INSERT tool text, CUTTER 7 parameters, LOAD/TOOL, SELECT/TOOL, RAPID/ with a slash,
    CIRCLE/centre,axis with no radius (counter-clockwise about the axis), CYCLE/INIT +
    CYCLE/DRILL,FEDTO,..,MMPM,..,RAPTO,..,RTRCTO,..,DWELL,0 with hole-top GOTOs, FINI."""
    L = ['PARTNO/1', 'UNIT/MM', 'INSERT/Stock Size X100. Y60. Z20.', 'TRNTYP/WORLD,0,0,0',
         'CSYS/1.,0,0,0,0,1.,0,0,0,0,1.,0', 'SETUP/START,1']
    pos = [0.0, 0.0, 25.0]
    feed = [None]

    def goto(x, y, z):
        x = pos[0] if x is None else x
        y = pos[1] if y is None else y
        z = pos[2] if z is None else z
        pos[:] = [x, y, z]
        L.append('GOTO/%s,%s,%s' % (swnum(x), swnum(y), swnum(z)))

    L += ['INSERT/T01 8mm CRB 3FL 19 LOC', 'CUTTER/8.,0,4.,0,0,0,19.', 'LOAD/TOOL,1', 'SELECT/TOOL,2',
          'SPINDL/9000,RPM,CLW', 'COOLNT/FLOOD']
    for mv in pocket(30, 30, 30, 20, 5, 8, [-2.5, -5], 5, 'plunge', 900, 250, clear=25.0, safe=3.0):
        if mv[0] == 'rapid':
            L.append('RAPID/')
            goto(*mv[1:4])
        elif mv[0] == 'line':
            if mv[4] != feed[0]:
                L.append('FEDRAT/%s,MMPM' % swnum(mv[4]))
                feed[0] = mv[4]
            goto(*mv[1:4])
        elif mv[0] == 'arc':
            _, d, x, y, z, cx, cy, f = mv
            L.append('CIRCLE/%s,%s,%s,0,0,%s' % (swnum(cx), swnum(cy), swnum(pos[2]),
                                                 '1.' if d == 'ccw' else '-1.'))
            goto(x, y, z)
    L += ['INSERT/T02 6.6mm JOBBER DRILL', 'CUTTER/6.6,0,3.3,1.982912,31.,0,60.', 'LOAD/TOOL,2',
          'SPINDL/3000,RPM,CLW', 'COOLNT/FLOOD']
    pts = [(70, 15), (90, 15), (90, 45), (70, 45)]
    L.append('RAPID/')
    goto(pts[0][0], pts[0][1], 25)
    L.append('CYCLE/INIT')
    tip = r3(tip_depth(12, 6.6, 118))
    L.append('CYCLE/DRILL,FEDTO,%s,MMPM,250.,RAPTO,3.,RTRCTO,25.,DWELL,0' % swnum(tip))
    for p_ in pts:
        goto(p_[0], p_[1], 0)
    L.append('CYCLE/OFF')
    L.append('RAPID/')
    goto(None, None, 25)
    L += ['COOLNT/OFF', 'SPINDL/OFF', 'SETUP/END,1', 'FINI']
    return 'apt', '\n'.join(L) + '\n'


def main(names):
    for n, fn in PROGRAMS.items():
        if names and n not in names:
            continue
        ext, text = fn()
        with open(os.path.join(OUT, n + '.' + ext), 'w') as f:
            f.write(text)
        print('wrote', n + '.' + ext)


if __name__ == '__main__':
    main(sys.argv[1:])
