#!/usr/bin/env python3
"""Writes the programs of tests/programs/posts/ from the part designs in DESIGN.md.
Run: python3 tests/posts_gen/make.py  (writes into tests/programs/posts/).
The sidecars (.json) are NOT written here: they are written by hand from DESIGN.md."""
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from geom import pocket, profile, face, lines_at, step_passes, slot, tip_depth  # noqa: E402
from styles import fusion_fanuc, fusion_siemens, fusion_tnc, fusion_lcnc, mcam  # noqa: E402

OUT = os.path.join(os.path.dirname(__file__), '..', 'programs', 'posts')
PROGRAMS = {}


def prog(fn):
    PROGRAMS[fn.__name__] = fn
    return fn


def T(t, d, kind, zmin, cr=0.0, taper=None, mcam_desc=None, pitch=None):
    return dict(t=t, d=d, kind=kind, zmin=zmin, cr=cr, taper=taper, pitch=pitch,
                mcam=mcam_desc or ('%s. %s' % (('%g' % d), kind)))


def r3(v):
    return round(v, 3)


# ------------------------------------------------------------------ P1
@prog
def f360_fanuc_pocket_helix():
    t1 = T(1, 10, 'FLAT END MILL', -8)
    ops = [dict(name='POCKET1', tool=t1, S=8000,
                moves=pocket(50, 40, 60, 40, 8, 10, [-4, -8], 6, 'helix', 1200, 400))]
    return 'nc', fusion_fanuc(1001, 'POCKET PLATE', ops)


# ------------------------------------------------------------------ P2
@prog
def f360_haas_profile_holes():
    t1 = T(1, 12, 'FLAT END MILL', -12)
    t2 = T(2, 10, 'SPOT DRILL', -2, taper=90)
    tip = r3(-tip_depth(15, 6.6, 118))
    t3 = T(3, 6.6, 'DRILL', tip, taper=118)
    pts = [(-30, -15), (30, -15), (30, 15), (-30, 15)]
    ops = [dict(name='2D CONTOUR1', tool=t1, S=6000,
                moves=profile(0, 0, 80, 50, 5, 12, [-6, -12], 1000, 300, lead=8)),
           dict(name='SPOT DRILL1', tool=t2, S=3000,
                holes=dict(cycle='spot', pts=pts, tip=-2, r=3, f=200)),
           dict(name='DRILL1', tool=t3, S=2500,
                holes=dict(cycle='peck', pts=pts, tip=tip, r=3, q=3, f=250))]
    return 'nc', fusion_fanuc(1002, 'BOSS PLATE', ops, haas=True)


# ------------------------------------------------------------------ P3
@prog
def f360_fanuc_face_slots():
    t1 = T(1, 50, 'FACE MILL', 0)
    t2 = T(2, 8, 'FLAT END MILL', -5)
    t3 = T(3, 10, 'FLAT END MILL', -6)
    fm, _ = face(0, 120, 0, 60, 50, 0, 35, 1500, 500)
    ops = [dict(name='FACE1', tool=t1, S=3000, moves=fm),
           dict(name='SLOT1', tool=t2, S=9000,
                moves=slot(20, 20, 60, 20, 8, 8, [-2.5, -5], 600, 200)),
           dict(name='SLOT2', tool=t3, S=8000,
                moves=slot(30, 42, 90, 42, 14, 10, [-3, -6], 800, 250))]
    return 'nc', fusion_fanuc(1003, 'SLOT BAR', ops)


# ------------------------------------------------------------------ bracket (P4, P7, P12)
BRACKET_STOCK = ((0, 100), (0, 60), (-20, 1))


def bracket_ops(post):
    t1 = T(1, 50, 'FACE MILL', 0)
    t2 = T(2, 16, 'FLAT END MILL', -8)
    t3 = T(3, 10, 'FLAT END MILL', -6)
    t4 = T(4, 10, 'SPOT DRILL', -1.5, taper=90)
    tip = r3(-(20 + tip_depth(0, 8.5, 118) + 1.0))
    t5 = T(5, 8.5, 'DRILL', tip, taper=118)
    fm, _ = face(0, 100, 0, 60, 50, 0, 35, 1500, 500)
    pts = [(80, 15), (80, 35)]
    return [dict(name='FACE1', tool=t1, S=3000, moves=fm),
            dict(name='STEP1', tool=t2, S=5000,
                 moves=step_passes(-15, 115, [53], [-4, -8], 900, 300)),
            dict(name='POCKET1', tool=t3, S=8000,
                 moves=pocket(35, 22, 40, 20, 6, 10, [-3, -6], 6, 'ramp', 1000, 300)),
            dict(name='SPOT DRILL1', tool=t4, S=3000,
                 holes=dict(cycle='spot', pts=pts, tip=-1.5, r=3, f=200)),
            dict(name='DRILL1', tool=t5, S=2200,
                 holes=dict(cycle='peck', pts=pts, tip=tip, r=3, q=4, f=250))]


@prog
def f360_fanuc_bracket():
    return 'nc', fusion_fanuc(1004, 'BRACKET', bracket_ops('fanuc'))


@prog
def f360_840d_bracket():
    return 'mpf', fusion_siemens('BRACKET', bracket_ops('siemens'), stock=BRACKET_STOCK)


@prog
def f360_tnc_bracket():
    return 'h', fusion_tnc('BRACKET', bracket_ops('tnc'), BRACKET_STOCK)


# ------------------------------------------------------------------ P5
@prog
def f360_haas_drill_ream_tap():
    t1 = T(1, 10, 'SPOT DRILL', -2, taper=90)
    tip_a = r3(-(15 + tip_depth(0, 9.8, 118) + 1.0))
    t2 = T(2, 9.8, 'DRILL', tip_a, taper=118)
    t3 = T(3, 10, 'REAMER', -16)
    tip_b = r3(-tip_depth(13, 5.0, 118))
    t4 = T(4, 5, 'DRILL', tip_b, taper=118)
    t5 = T(5, 6, 'RIGHT TAP', -10, pitch=1)
    a = [(20, 25), (60, 25)]
    b = [(10, 10), (70, 10), (70, 40), (10, 40)]
    ops = [dict(name='SPOT DRILL1', tool=t1, S=3000,
                holes=dict(cycle='spot', pts=a + b, tip=-2, r=3, f=200)),
           dict(name='DRILL1', tool=t2, S=1800,
                holes=dict(cycle='peck', pts=a, tip=tip_a, r=3, q=4, f=220)),
           dict(name='BORE1', tool=t3, S=400,
                holes=dict(cycle='ream', pts=a, tip=-16, r=3, f=80)),
           dict(name='DRILL2', tool=t4, S=3000,
                holes=dict(cycle='peck', pts=b, tip=tip_b, r=3, q=3, f=300)),
           dict(name='TAP1', tool=t5, S=500,
                holes=dict(cycle='tap', pts=b, tip=-10, r=5, f=500, pitch=1))]
    return 'nc', fusion_fanuc(1005, 'VALVE PLATE', ops, haas=True)


# ------------------------------------------------------------------ P6
@prog
def f360_fanuc_pocket_ctrlcomp():
    t1 = T(1, 12, 'FLAT END MILL', -12)
    t2 = T(2, 10, 'FLAT END MILL', -12)
    rough = pocket(60, 40, 70, 45, 10, 12, [-4, -8, -12], 7, 'ramp', 1200, 350, allowance=0.3)
    fin = pocket(60, 40, 70, 45, 10, 10, [-12], 100, 'plunge', 900, 300,
                 finish_comp='left', lead=8)
    # finishing op: only the compensated contour pass (drop the roughing loop of the helper)
    fin = fin_only(fin)
    ops = [dict(name='POCKET1 ROUGH', tool=t1, S=7000, moves=rough),
           dict(name='POCKET1 FINISH', tool=t2, S=8000, moves=fin)]
    return 'nc', fusion_fanuc(1006, 'COVER', ops)


def fin_only(ms):
    """From a pocket(..., finish_comp=...) move list keep the start rapids and the comp pass."""
    i = max(k for k, m in enumerate(ms) if m[0] == 'rapid' and m[3] is None and m[1] is not None
            and k > 2 and ms[k + 1][0] == 'line' and ms[k + 2][0] == 'comp')
    head = [('rapid', ms[i][1], ms[i][2], None), ms[1], ms[2]]
    return head + ms[i + 1:]


# ------------------------------------------------------------------ P8
@prog
def f360_840d_pocket_ramp():
    t1 = T(1, 16, 'FLAT END MILL', -10)
    ops = [dict(name='POCKET1', tool=t1, S=6000,
                moves=pocket(60, 40, 80, 50, 8, 16, [-5, -10], 9, 'ramp', 1400, 400))]
    return 'mpf', fusion_siemens('HOUSING_LID', ops, stock=((0, 120), (0, 80), (-25, 0)))


# ------------------------------------------------------------------ P9
@prog
def f360_840d_face_step():
    t1 = T(1, 63, 'FACE MILL', 0)
    t2 = T(2, 20, 'FLAT END MILL', -10)
    fm, _ = face(-50, 50, -30, 30, 63, 0, 45, 1800, 600)
    s1 = lines_at([(-40, -45), (-40, 45)], [-5, -10], 1000, 300)
    s2 = []
    # second step on X+ edge: two passes per depth (outer x=45, inner x=35)
    s2 = [('rapid', 45, -45, None), ('rapid', None, None, 15.0), ('rapid', None, None, 5.0)]
    for i, z in enumerate([-3, -6]):
        if i:
            s2 += [('rapid', None, None, 5.0), ('rapid', 45, -45, None)]
        s2 += [('line', None, None, z, 300), ('line', 45, 45, z, 1000), ('line', 35, 45, z, 1000),
               ('line', 35, -45, z, 1000)]
    s2.append(('rapid', None, None, 15.0))
    ops = [dict(name='FACE1', tool=t1, S=2500, moves=fm),
           dict(name='STEP LEFT', tool=t2, S=4500, moves=s1),
           dict(name='STEP RIGHT', tool=t2, S=4500, moves=s2)]
    return 'mpf', fusion_siemens('SLIDE_BLOCK', ops, stock=((-50, 50), (-30, 30), (-30, 1)))


# ------------------------------------------------------------------ P10
@prog
def f360_840d_holes():
    t1 = T(1, 10, 'SPOT DRILL', -2, taper=90)
    tip_a = r3(-(20 + tip_depth(0, 8, 118) + 1.5))
    t2 = T(2, 8, 'DRILL', tip_a, taper=118)
    tip_b = r3(-tip_depth(15, 8.5, 140))
    t3 = T(3, 8.5, 'DRILL', tip_b, taper=140)
    t4 = T(4, 10, 'RIGHT TAP', -12, pitch=1.5)
    a = [(20, 20), (50, 20), (80, 20), (80, 50), (50, 50), (20, 50)]
    b = [(35, 35), (65, 35)]
    ops = [dict(name='SPOT DRILL1', tool=t1, S=3000,
                holes=dict(cycle='spot', pts=a + b, tip=-2, r=3, f=200)),
           dict(name='DRILL1', tool=t2, S=2500,
                holes=dict(cycle='peck', pts=a, tip=tip_a, r=3, q=3, f=250)),
           dict(name='DRILL2', tool=t3, S=2200,
                holes=dict(cycle='peck', pts=b, tip=tip_b, r=3, q=3, f=240)),
           dict(name='TAP1', tool=t4, S=400,
                holes=dict(cycle='tap', pts=b, tip=-12, r=5, f=600, pitch=1.5))]
    return 'mpf', fusion_siemens('FLANGE_PLATE', ops, stock=((0, 100), (0, 70), (-20, 0)))


# ------------------------------------------------------------------ P11
@prog
def f360_840d_profile_ctrl():
    t1 = T(1, 16, 'FLAT END MILL', -15)
    ops = [dict(name='2D CONTOUR1', tool=t1, S=5000,
                moves=profile(0, 0, 80, 50, 5, 16, [-5, -10, -15], 900, 300, comp='control',
                              lead=12))]
    return 'mpf', fusion_siemens('COVER_BOSS', ops, stock=((-48, 48), (-33, 33), (-20, 0)))


# ------------------------------------------------------------------ P13
@prog
def f360_tnc_pocket():
    t1 = T(1, 8, 'FLAT END MILL', -9)
    ops = [dict(name='POCKET1', tool=t1, S=9000,
                moves=pocket(50, 40, 50, 30, 6, 8, [-3, -6, -9], 5, 'ramp', 900, 300))]
    return 'h', fusion_tnc('TRAY', ops, ((0, 100), (0, 80), (-20, 0)))


# ------------------------------------------------------------------ P14
@prog
def f360_tnc_face_holes():
    t1 = T(1, 40, 'FACE MILL', 0)
    t2 = T(2, 10, 'SPOT DRILL', -2, taper=90)
    tip = r3(-tip_depth(12, 6.8, 118))
    t3 = T(3, 6.8, 'DRILL', tip, taper=118)
    fm, _ = face(0, 120, 0, 60, 40, 0, 30, 1500, 500)
    pts = [(20, 15), (100, 15), (100, 45), (20, 45)]
    ops = [dict(name='FACE1', tool=t1, S=3500, moves=fm),
           dict(name='SPOT DRILL1', tool=t2, S=3000,
                holes=dict(cycle='spot', pts=pts, tip=-2, r=3, f=200)),
           dict(name='DRILL1', tool=t3, S=2600,
                holes=dict(cycle='chip', pts=pts, tip=tip, r=3, q=3, f=260))]
    return 'h', fusion_tnc('BASE_PLATE', ops, ((0, 120), (0, 60), (-15, 1)))


# ------------------------------------------------------------------ P15
@prog
def f360_tnc_profile_rl():
    t1 = T(1, 12, 'FLAT END MILL', -8)
    ops = [dict(name='2D CONTOUR1', tool=t1, S=6000,
                moves=profile(0, 0, 70, 40, 8, 12, [-4, -8], 900, 300, comp='control', lead=10))]
    return 'h', fusion_tnc('SPACER', ops, ((-40, 40), (-25, 25), (-20, 0)))


# ------------------------------------------------------------------ P16
@prog
def f360_tnc_slot_step():
    t1 = T(1, 16, 'FLAT END MILL', -5)
    t2 = T(2, 10, 'FLAT END MILL', -4)
    ops = [dict(name='STEP1', tool=t1, S=5000,
                moves=step_passes(-12, 112, [2], [-2.5, -5], 900, 300)),
           dict(name='SLOT1', tool=t2, S=7000,
                moves=slot(25, 30, 75, 30, 10, 10, [-2, -4], 700, 200))]
    return 'h', fusion_tnc('GUIDE_RAIL', ops, ((0, 100), (0, 50), (-20, 0)))


# ------------------------------------------------------------------ P17
@prog
def f360_lcnc_pocket_holes():
    t1 = T(1, 6, 'FLAT END MILL', -6)
    tip = r3(-tip_depth(10, 5, 118))
    t2 = T(2, 5, 'DRILL', tip, taper=118)
    ops = [dict(name='POCKET1', tool=t1, S=12000,
                moves=pocket(35, 30, 40, 30, 5, 6, [-3, -6], 3.5, 'helix', 900, 250)),
           dict(name='DRILL1', tool=t2, S=3500,
                holes=dict(cycle='drill', pts=[(80, 15), (80, 45)], tip=tip, r=3, f=300))]
    return 'ngc', fusion_lcnc('ENCLOSURE_SIDE', ops)


# ------------------------------------------------------------------ P18
@prog
def f360_lcnc_profile_face():
    t1 = T(1, 50, 'FACE MILL', 0)
    t2 = T(2, 10, 'FLAT END MILL', -10)
    fm, _ = face(-40, 40, -30, 30, 50, 0, 35, 1500, 500)  # stock top Z+1
    ops = [dict(name='FACE1', tool=t1, S=3000, moves=fm),
           dict(name='2D CONTOUR1', tool=t2, S=8000,
                moves=profile(0, 0, 60, 40, 6, 10, [-5, -10], 800, 250, lead=6, allowance=8)
                + profile(0, 0, 60, 40, 6, 10, [-10], 800, 250, lead=6))]
    return 'ngc', fusion_lcnc('PAD', ops)


# ------------------------------------------------------------------ Mastercam P19-P24
@prog
def mcam_fanuc_pocket_computer():
    t1 = T(1, 12, 'FLAT ENDMILL', -10, mcam_desc='12. FLAT ENDMILL')
    ops = [dict(name='POCKET - STANDARD', tool=t1, S=6500,
                moves=pocket(50, 40, 60, 50, 10, 12, [-5, -10], 7, 'helix', 1100, 350))]
    stock = ['(STOCK: X100. Y80. Z25.)']
    return 'nc', mcam(2001, 'pocket_block', ops, stock_comment=stock)


@prog
def mcam_haas_pocket_control():
    t1 = T(1, 10, 'FLAT ENDMILL', -8, mcam_desc='10. FLAT ENDMILL')
    rough = pocket(40, 40, 50, 50, 8, 10, [-4, -8], 6, 'ramp', 1000, 300, allowance=0.2)
    fin = fin_only(pocket(40, 40, 50, 50, 8, 10, [-8], 100, 'plunge', 800, 300,
                          finish_comp='left', lead=6))
    ops = [dict(name='POCKET - ROUGH', tool=t1, S=7500, moves=rough),
           dict(name='CONTOUR 2D - FINISH WALL', tool=t1, S=7500, moves=fin)]
    stock = ['(STOCK: X80. Y80. Z20.)']
    return 'nc', mcam(2002, 'square_cup', ops, stock_comment=stock, haas=True)


@prog
def mcam_fanuc_profile_holes():
    t1 = T(1, 16, 'FLAT ENDMILL', -10, mcam_desc='16. FLAT ENDMILL')
    t2 = T(2, 12, 'SPOT DRILL', -2.5, mcam_desc='12. SPOTDRILL')
    tip = r3(-(15 + tip_depth(0, 8, 118) + 1.0))
    t3 = T(3, 8, 'DRILL', tip, mcam_desc='8. DRILL')
    pts = [(-30, -15), (30, -15), (30, 15), (-30, 15)]
    ops = [dict(name='CONTOUR 2D', tool=t1, S=5000,
                moves=profile(0, 0, 80, 50, 5, 16, [-5, -10], 900, 300, comp='control',
                              lead=10)),
           dict(name='DRILL/CBORE', tool=t2, S=2500,
                holes=dict(cycle='spot', pts=pts, tip=-2.5, r=2, f=150)),
           dict(name='DRILL/CBORE', tool=t3, S=2000,
                holes=dict(cycle='drill', pts=pts, tip=tip, r=2, f=200))]
    stock = ['(STOCK: X90. Y60. Z15.)', '(STOCK ORIGIN: X0. Y0. Z0. - TOP CENTRE)']
    return 'nc', mcam(2003, 'boss_plate', ops, stock_comment=stock)


@prog
def mcam_haas_face_step():
    t1 = T(1, 63, 'FACE MILL', 0, mcam_desc='63. FACE MILL')
    t2 = T(2, 20, 'FLAT ENDMILL', -12, mcam_desc='20. FLAT ENDMILL')
    fm, _ = face(0, 120, 0, 70, 63, 0, 45, 1800, 600)
    ops = [dict(name='FACE', tool=t1, S=2500, moves=fm),
           dict(name='CONTOUR 2D', tool=t2, S=4500,
                moves=step_passes(-15, 135, [62], [-4, -8, -12], 1000, 300))]
    stock = ['(STOCK: X120. Y70. Z31.)', '(STOCK ORIGIN: X0. Y0. Z1. - LOWER LEFT TOP)']
    return 'nc', mcam(2004, 'clamp_jaw', ops, stock_comment=stock, haas=True)


@prog
def mcam_fanuc_slots():
    t1 = T(1, 10, 'FLAT ENDMILL', -5, mcam_desc='10. FLAT ENDMILL')
    t2 = T(2, 12, 'FLAT ENDMILL', -6, mcam_desc='12. FLAT ENDMILL')
    ops = [dict(name='SLOT MILL', tool=t1, S=7000,
                moves=slot(20, 15, 80, 15, 10, 10, [-2.5, -5], 600, 200)),
           dict(name='SLOT MILL', tool=t2, S=6000,
                moves=slot(25, 42, 75, 42, 16, 12, [-3, -6], 700, 220))]
    stock = ['(STOCK: X100. Y60. Z20.)']
    return 'nc', mcam(2005, 'slide_plate', ops, stock_comment=stock)


@prog
def mcam_fanuc_open_pocket():
    t1 = T(1, 12, 'FLAT ENDMILL', -8, mcam_desc='12. FLAT ENDMILL')
    # open pocket X30..70, Y30..60(open, stock edge), corner r6 at the closed corners
    ms = [('rapid', 36, 68, None), ('rapid', None, None, 25.0), ('rapid', None, None, 2.0)]
    for i, z in enumerate([-4, -8]):
        if i:
            ms += [('rapid', None, None, 2.0), ('rapid', 46, 68, None)]
        else:
            ms += [('rapid', 46, 68, None)]
        ms += [('line', None, None, z, 300),
               ('line', 46, 40, z, 1000), ('line', 54, 40, z, 1000), ('line', 54, 68, z, 1000),
               ('rapid', None, None, 2.0), ('rapid', 36, 68, None), ('line', None, None, z, 300),
               ('line', 36, 36, z, 1000), ('line', 64, 36, z, 1000), ('line', 64, 68, z, 1000)]
    ms.append(('rapid', None, None, 25.0))
    ops = [dict(name='POCKET - OPEN', tool=t1, S=6500, moves=ms)]
    stock = ['(STOCK: X100. Y60. Z20.)']
    return 'nc', mcam(2006, 'fork_end', ops, stock_comment=stock)


# ------------------------------------------------------------------ P39
@prog
def f360_840d_pocket_slot_ctrl():
    t1 = T(1, 12, 'FLAT END MILL', -7)
    t2 = T(2, 10, 'FLAT END MILL', -7)
    t3 = T(3, 10, 'FLAT END MILL', -5)
    rough = pocket(40, 35, 50, 36, 8, 12, [-3.5, -7], 7, 'ramp', 1200, 350, allowance=0.25)
    fin = fin_only(pocket(40, 35, 50, 36, 8, 10, [-7], 100, 'plunge', 900, 300,
                          finish_comp='left', lead=6))
    ops = [dict(name='POCKET1 ROUGH', tool=t1, S=7000, moves=rough),
           dict(name='POCKET1 FINISH', tool=t2, S=8000, moves=fin),
           dict(name='SLOT1', tool=t3, S=8000,
                moves=slot(80, 35, 105, 35, 10, 10, [-2.5, -5], 700, 200))]
    return 'mpf', fusion_siemens('GUIDE_BLOCK', ops, stock=((0, 120), (0, 70), (-20, 0)))


# ------------------------------------------------------------------ P40
@prog
def f360_lcnc_step_slot():
    t1 = T(1, 16, 'FLAT END MILL', -10)
    t2 = T(2, 8, 'FLAT END MILL', -4)
    ops = [dict(name='STEP1', tool=t1, S=6000,
                moves=lines_at([(83, -12), (83, 62)], [-5, -10], 900, 300)),
           dict(name='SLOT1', tool=t2, S=10000,
                moves=slot(15, 25, 55, 25, 12, 8, [-2, -4], 700, 200))]
    return 'ngc', fusion_lcnc('RAIL_END', ops)


# ------------------------------------------------------------------ P41
@prog
def f360_haas_open_pocket():
    t1 = T(1, 10, 'FLAT END MILL', -6)
    ms = [('rapid', -8, 30, None), ('rapid', None, None, 15.0), ('rapid', None, None, 5.0)]
    for i, z in enumerate([-3, -6]):
        if i:
            ms += [('rapid', None, None, 5.0), ('rapid', -8, 30, None)]
        ms += [('line', None, None, z, 300), ('line', 30, 30, z, 1000), ('line', -8, 30, z, 1000),
               ('line', -8, 20, z, 1000), ('line', 30, 20, z, 1000), ('line', 30, 40, z, 1000),
               ('line', -8, 40, z, 1000)]
    ms.append(('rapid', None, None, 15.0))
    ops = [dict(name='POCKET2', tool=t1, S=8000, moves=ms)]
    return 'nc', fusion_fanuc(1041, 'LEVER', ops, haas=True)


# ------------------------------------------------------------------ P44
@prog
def f360_tnc_pocket_helix():
    t1 = T(1, 10, 'FLAT END MILL', -6)
    ops = [dict(name='POCKET2', tool=t1, S=8000,
                moves=pocket(45, 35, 50, 36, 6, 10, [-3, -6], 6, 'helix', 1000, 300))]
    return 'h', fusion_tnc('CLAMP_BASE', ops, ((0, 90), (0, 70), (-20, 0)))


def main(names):
    os.makedirs(OUT, exist_ok=True)
    for n, fn in PROGRAMS.items():
        if names and n not in names:
            continue
        ext, text = fn()
        with open(os.path.join(OUT, n + '.' + ext), 'w') as f:
            f.write(text)
        print('wrote', n + '.' + ext)


if __name__ == '__main__':
    main(sys.argv[1:])
