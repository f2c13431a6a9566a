"""Second batch of skeletons: NX Post Builder (Sinumerik, Fanuc), hyperMILL (TNC, Sinumerik),
and CL data (NX CLSF listing, Autodesk ISO 4343 APT, Creo Pro/CLfile)."""
import math
from emit import GCode, Klartext, Apt, num
from styles import siemens_holes, fanuc_holes, tnc_holes, sfmt


# ---------------------------------------------------------------- NX -> Sinumerik 840D
def nx_siemens(name, ops):
    g = GCode('siemens', numbering='N', start=10, step=10, arc='ac')
    g.raw('%%_N_%s_MPF' % name.upper())
    g.raw(';$PATH=/_N_MPF_DIR')
    g.block('G40 G17 G710 G94 G90 G60 G601 FNORM')
    last = None
    for op in ops:
        t = op['tool']
        g.reset_modal()
        g.block(';Operation : %s' % op['name'])
        if t['t'] != last:
            g.block(';Tool : %s' % t['name'])
            g.block('G0 SUPA Z0 D0')
            g.block('T="%s"' % t['name'])
            g.block('M6')
            g.block('D1')
        last = t['t']
        g.block('CYCLE832(0.01,_ORI_FINISH,1)' if 'moves' in op else 'CYCLE832()')
        g.block('G54')
        if 'moves' in op:
            ms = op['moves']
            g.block('G0 G90 X%s Y%s S%d M3' % (sfmt(ms[0][1]), sfmt(ms[0][2]), op['S']))
            g.pos[0], g.pos[1] = ms[0][1], ms[0][2]
            g.motion = 0
            g.block('Z%s M8' % sfmt(ms[1][3]))
            g.pos[2] = ms[1][3]
            g.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            g.block('G0 G90 X%s Y%s S%d M3' % (sfmt(p[0]), sfmt(p[1]), op['S']))
            g.block('Z%s M8' % sfmt(h.get('top', 0) + h.get('clear', 15)))
            siemens_holes(g, h, op['S'], nx=True)
    g.block('M9')
    g.block('G0 SUPA Z0 D0')
    g.block('M5')
    g.block('M30')
    return g.text()


# ---------------------------------------------------------------- NX -> Fanuc (MILL_3_AXIS)
def nx_fanuc(ops):
    g = GCode('fanuc', numbering='N4', start=10, step=10, comp_d=1, gcode_pad=True)
    g.raw('%')
    g.block('G40 G17 G90 G21')
    g.block('G91 G28 Z0.0')
    for op in ops:
        t = op['tool']
        g.reset_modal()
        g.comp_d = t['t']
        # NX writes the tool-change block as an alignment block ':'
        g.lines.append(':%04d T%02d M06' % (g.n, t['t']))
        g.n += g.step
        ms = op['moves']
        g.block('G00 G90 X%s Y%s S%d M03' % (g.numfmt(ms[0][1]), g.numfmt(ms[0][2]), op['S']))
        g.pos[0], g.pos[1] = ms[0][1], ms[0][2]
        g.motion = 0
        g.block('G43 Z%s H%02d' % (g.numfmt(ms[1][3]), t['t']))
        g.pos[2] = ms[1][3]
        g.moves(ms[2:3])
        first_feed = True
        for mv in ms[3:]:
            if first_feed and mv[0] == 'line':
                first_feed = False
                w = g.xyz(mv[1], mv[2], mv[3])
                g.block(' '.join(['G01'] + w + ['F%s' % g.numfmt(mv[4]), 'M08']))
                g.motion = 1
                g.feed = mv[4]
                continue
            g.move(mv)
    g.block('M05')
    g.block('G91 G28 Z0.0')
    g.block('M02')
    g.raw('%')
    return g.text()


# ---------------------------------------------------------------- hyperMILL -> TNC
def hm_tnc(name, ops, stock):
    k = Klartext(name, signs=False, fmax='F MAX')
    k.block('BEGIN PGM %s MM' % name)
    k.block(';hyperMILL 2022.1  OPEN MIND Technologies AG')
    (x0, x1), (y0, y1), (z0, z1) = stock
    k.block('BLK FORM 0.1 Z X%s Y%s Z%s' % (k.nf(x0), k.nf(y0), k.nf(z0)))
    k.block('BLK FORM 0.2 X%s Y%s Z%s' % (k.nf(x1), k.nf(y1), k.nf(z1)))
    last = None
    for op in ops:
        t = op['tool']
        k.reset_modal()
        k.block('* - %s' % op['name'])
        if t['t'] != last:
            k.block(';%s' % t['desc'])
            k.block('TOOL CALL %d Z S%d DL+0 DR+0' % (t['t'], op['S']))
            k.block('L Z+0 R0 F MAX M91')
        last = t['t']
        k.block('CYCL DEF 32.0 TOLERANCE')
        k.block('CYCL DEF 32.1 T0.01')
        if 'moves' in op:
            ms = op['moves']
            k.block('L X%s Y%s R0 F MAX M3' % (k.nf(ms[0][1]), k.nf(ms[0][2])))
            k.pos[0], k.pos[1] = ms[0][1], ms[0][2]
            k.block('L Z%s R0 F MAX M8' % k.nf(ms[1][3]))
            k.pos[2] = ms[1][3]
            k.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            k.block('L X%s Y%s R0 F MAX M3' % (k.nf(p[0]), k.nf(p[1])))
            k.block('L Z%s R0 F MAX M8' % k.nf(h.get('top', 0) + h.get('clear', 15)))
            tnc_holes(k, h, op['S'])
        k.block('M9')
        k.block('L Z+0 R0 F MAX M91')
    k.block('M5')
    k.block('M30')
    k.block('END PGM %s MM' % name)
    return k.text()


# ---------------------------------------------------------------- hyperMILL -> Sinumerik
def hm_siemens(name, ops, stock):
    g = GCode('siemens', numbering='N', start=1, step=1, arc='cr')
    g.raw('; hyperMILL 2022.1  OPEN MIND')
    g.raw('; PROGRAM %s' % name)
    (x0, x1), (y0, y1), (z0, z1) = stock
    g.block('G17 G90 G71 G40 G64')
    g.block('WORKPIECE(,"",,"BOX",112,%s,%s,-80,%s,%s,%s,%s)' % (
        sfmt(z1), sfmt(z0), sfmt(x0), sfmt(y0), sfmt(x1), sfmt(y1)))
    last = None
    for op in ops:
        t = op['tool']
        g.reset_modal()
        g.comment('JOB %s' % op['name'])
        if t['t'] != last:
            g.comment(t['desc'])
            g.block('T%d' % t['t'])
            g.block('M6')
            g.block('D1')
        last = t['t']
        ms = op['moves']
        g.block('G0 X%s Y%s S%d M3' % (sfmt(ms[0][1]), sfmt(ms[0][2]), op['S']))
        g.pos[0], g.pos[1] = ms[0][1], ms[0][2]
        g.motion = 0
        g.block('G0 Z%s M8' % sfmt(ms[1][3]))
        g.pos[2] = ms[1][3]
        g.moves(ms[2:])
        g.block('M9')
    g.block('G0 G53 Z0 D0')
    g.block('M5')
    g.block('M30')
    return g.text()


# ---------------------------------------------------------------- CL data
def nx_clsf(ops):
    a = Apt('nx')
    for op in ops:
        t = op['tool']
        a.raw('TOOL PATH/%s,TOOL,%s' % (op['name'], t['name']))
        if t.get('taper'):
            a.raw('TLDATA/DRILL,MILL,%.4f,0.0000,%.4f,%.4f,%.4f' % (t['d'], t['len'], t['taper'],
                                                                  t['flute']))
        else:
            a.raw('TLDATA/MILL,%.4f,%.4f,%.4f,0.0000,0.0000' % (t['d'], t.get('cr', 0), t['len']))
        a.raw('MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000')
        a.raw('$$ centerline data')
        a.raw('PAINT/PATH')
        a.raw('PAINT/SPEED,10')
        if op.get('load', True):
            a.raw('LOAD/TOOL,%d,ADJUST,%d' % (t['t'], t['t']))
        a.raw('SPINDL/RPM,%.4f,CLW' % op['S'])
        a.tool_d = t['d']
        a.feed = None
        if 'moves' in op:
            ms = op['moves']
            a.raw('PAINT/COLOR,186')
            a.raw('RAPID')
            a.raw('GOTO/%s,%s,%s,0.0000000,0.0000000,1.0000000' % (
                a.f(ms[0][1]), a.f(ms[0][2]), a.f(ms[1][3])))
            a.pos = [ms[0][1], ms[0][2], ms[1][3]]
            a.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            clear = h.get('top', 0) + h.get('clear', 15)
            a.raw('PAINT/COLOR,186')
            a.raw('RAPID')
            a.raw('GOTO/%s,%s,%s,0.0000000,0.0000000,1.0000000' % (a.f(p[0]), a.f(p[1]),
                                                                   a.f(clear)))
            a.raw('CYCLE/DRILL,RAPTO,%s,FEDTO,%s,RTRCTO,AUTO,MMPM,%s' % (
                a.f(h.get('r', 3)), a.f(h['tip'] - h.get('top', 0)), a.f(h['f'])))
            a.raw('PAINT/COLOR,31')
            for q in h['pts']:
                a.raw('GOTO/%s,%s,%s' % (a.f(q[0]), a.f(q[1]), a.f(h.get('top', 0))))
            a.raw('CYCLE/OFF')
            a.raw('PAINT/COLOR,186')
            a.raw('RAPID')
            a.raw('GOTO/%s,%s,%s' % (a.f(h['pts'][-1][0]), a.f(h['pts'][-1][1]), a.f(clear)))
        a.raw('PAINT/SPEED,10')
        a.raw('PAINT/TOOL,NOMORE')
        a.raw('END-OF-PATH')
    return a.text()
