"""Program skeletons per post style. An op is a dict:
  {'name': 'POCKET1', 'tool': tool, 'S': 6000, 'moves': [...]}  milling
  {'name': 'DRILL1', 'tool': tool, 'S': 2000, 'holes': {...}}    hole cycle
A tool is a dict: t, d, cr, kind ('FLAT END MILL', 'SPOT DRILL', 'DRILL', 'REAMER', 'RIGHT TAP',
'FACE MILL'), taper (point angle for drills), zmin, pitch (taps).
holes = {'cycle': 'drill'|'spot'|'peck'|'ream'|'tap', 'pts': [(x,y)], 'top': 0, 'tip': -z,
         'r': 3 (R-plane above top), 'clear': 15, 'f': feed, 'q': peck, 'pitch': p}
"""
import math
from emit import GCode, Klartext, Apt, num


def ffmt(v):
    return num(v, 'fanuc')


def sfmt(v):
    return num(v, 'plain')


def tool_comment_fusion(t, style):
    d = t['d']
    if style == 'siemens' or style == 'tnc':
        f = sfmt
    else:
        f = ffmt
    s = 'T%d D=%s CR=%s' % (t['t'], f(d), f(t.get('cr', 0)))
    if t.get('taper'):
        s += ' TAPER=%sDEG' % sfmt(t['taper'])
    s += ' - ZMIN=%s - %s' % (f(t['zmin']), t['kind'])
    return s


# ---------------------------------------------------------------- Fanuc-family hole cycles
def fanuc_holes(g, h, spindle, lcnc=False, haas=False):
    top = h.get('top', 0.0)
    R = top + h.get('r', 3.0)
    z = h['tip']
    c = h['cycle']
    pts = h['pts']
    first = pts[0]
    if c in ('drill', 'spot'):
        head = 'G98 G81' if not h.get('dwell') else 'G98 G82'
        extra = '' if not h.get('dwell') else (' P%d' % h['dwell'] if not lcnc else ' P%s' % sfmt(h['dwell'] / 1000))
    elif c == 'peck':
        head = 'G98 G83'
        extra = ' Q' + g.numfmt(h['q'])
    elif c == 'chip':
        head = 'G98 G73'
        extra = ' Q' + g.numfmt(h['q'])
    elif c == 'ream':
        head = 'G98 G85'
        extra = ''
    elif c == 'tap':
        head = 'G98 G84'
        extra = ''
    if c == 'tap' and not lcnc and not haas:
        g.block('M29 S%d' % spindle)
    f = h['f']
    words = '%s X%s Y%s Z%s R%s%s F%s' % (head, g.numfmt(first[0]), g.numfmt(first[1]),
                                          g.numfmt(z), g.numfmt(R), extra,
                                          g.numfmt(f) if g.style != 'ngc' else sfmt(f))
    g.block(words)
    g.pos[0], g.pos[1] = first
    for p in pts[1:]:
        w = g.xyz(p[0], p[1], None)
        g.block(' '.join(w))
    g.block('G80')
    g.motion = None


# ---------------------------------------------------------------- Fusion Fanuc / Haas
def fusion_fanuc(prog, title, ops, haas=False):
    g = GCode('fanuc', numbering='N', start=10, step=5, comp_d=None)
    g.raw('%')
    g.raw(('O%05d' if haas else 'O%d') % prog + ' (%s)' % title)
    seen = []
    for op in ops:
        t = op['tool']
        if t['t'] not in seen:
            seen.append(t['t'])
            g.comment(tool_comment_fusion(t, 'fanuc'))
    if haas:
        g.block('G90 G17')
        g.block('G21')
        g.block('G53 G0 Z0.')
    else:
        g.block('G90 G94 G17 G49 G40 G80')
        g.block('G21')
        g.block('G28 G91 Z0.')
        g.block('G90')
    last_t = None
    for i, op in enumerate(ops):
        t = op['tool']
        g.raw('')
        g.comment(op['name'])
        g.reset_modal()
        g.comp_d = t['t']
        newtool = t['t'] != last_t
        if newtool:
            if i > 0:
                g.block('M9')
                if haas:
                    g.block('G53 G0 Z0.')
                else:
                    g.block('G28 G91 Z0.')
                    g.block('G90')
            g.block('T%d M6' % t['t'])
            if haas and i + 1 < len(ops) and ops[i + 1]['tool']['t'] != t['t']:
                g.block('T%d' % ops[i + 1]['tool']['t'])
            g.comment(t['kind'])
            g.block('S%d M3' % op['S'])
            g.block('G54')
            g.block('M8')
        last_t = t['t']
        if 'moves' in op:
            ms = op['moves']
            # first rapid XY, then G43 at clearance
            m0 = ms[0]
            g.block('G0 X%s Y%s' % (g.numfmt(m0[1]), g.numfmt(m0[2])))
            g.pos[0], g.pos[1] = m0[1], m0[2]
            g.motion = 0
            clear = ms[1][3]
            g.block('G43 Z%s H%d' % (g.numfmt(clear), t['t']))
            g.pos[2] = clear
            g.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            g.block('G0 X%s Y%s' % (g.numfmt(p[0]), g.numfmt(p[1])))
            g.block('G43 Z%s H%d' % (g.numfmt(h.get('clear', 15)), t['t']))
            g.pos = [p[0], p[1], h.get('clear', 15)]
            g.motion = 0
            if h['cycle'] == 'tap':
                pass
            fanuc_holes(g, h, op['S'], haas=haas)
            g.block('G0 Z%s' % g.numfmt(h.get('clear', 15)))
    g.block('M9')
    g.block('M5')
    if haas:
        g.block('G53 G0 Z0.')
        g.block('G53 G0 X0. Y0.')
    else:
        g.block('G28 G91 Z0.')
        g.block('G28 X0. Y0.')
        g.block('G90')
    g.block('M30')
    g.raw('%')
    return g.text()


# ---------------------------------------------------------------- Fusion Siemens 840D
def siemens_holes(g, h, spindle, nx=False):
    top = h.get('top', 0.0)
    rtp = top + h.get('clear', 15)
    rfp = top
    sdis = h.get('r', 3.0)
    dp = h['tip']
    c = h['cycle']
    if c in ('drill', 'spot'):
        if h.get('dwell'):
            call = 'CYCLE82(%s,%s,%s,%s,,%s)' % (sfmt(rtp), sfmt(rfp), sfmt(sdis), sfmt(dp),
                                                  sfmt(h['dwell'] / 1000))
        else:
            call = 'CYCLE81(%s,%s,%s,%s,)' % (sfmt(rtp), sfmt(rfp), sfmt(sdis), sfmt(dp))
    elif c in ('peck', 'chip'):
        vari = 1 if c == 'peck' else 0
        # FDEP = first depth (absolute), DAM = 0: no degression, every peck as deep as the first
        call = 'CYCLE83(%s,%s,%s,%s,,%s,,0,0,0,1,%d,,,,,)' % (
            sfmt(rtp), sfmt(rfp), sfmt(sdis), sfmt(dp), sfmt(rfp - h['q']), vari)
    elif c == 'ream':
        call = 'CYCLE85(%s,%s,%s,%s,,0,%s,%s)' % (sfmt(rtp), sfmt(rfp), sfmt(sdis), sfmt(dp),
                                                  sfmt(h['f']), sfmt(h['f'] * 2))
    elif c == 'tap':
        call = 'CYCLE84(%s,%s,%s,%s,,0,3,,%s,0,%d,%d)' % (sfmt(rtp), sfmt(rfp), sfmt(sdis),
                                                            sfmt(dp), sfmt(h['pitch']), spindle,
                                                            spindle)
    if c != 'tap':
        g.block('F%s' % sfmt(h['f']))
    g.block('MCALL ' + call)
    for p in h['pts']:
        g.block('X%s Y%s' % (sfmt(p[0]), sfmt(p[1])))
    g.block('MCALL')


def fusion_siemens(name, ops, stock=None):
    g = GCode('siemens', numbering='N', start=10, step=10)
    g.raw('; %%_N_%s_MPF' % name.upper())
    g.raw('; $PATH=/_N_MPF_DIR')
    seen = []
    for op in ops:
        t = op['tool']
        if t['t'] not in seen:
            seen.append(t['t'])
            g.comment(tool_comment_fusion(t, 'siemens'))
    g.block('G90 G94 G17 G710')
    g.block('G64')
    if stock:
        (x0, x1), (y0, y1), (z0, z1) = stock
        g.block('WORKPIECE(,"",,"BOX",112,%s,%s,-80,%s,%s,%s,%s)' % (
            sfmt(z1), sfmt(z0), sfmt(x0), sfmt(y0), sfmt(x1), sfmt(y1)))
    g.block('G0 SUPA D0 Z0')
    last_t = None
    for i, op in enumerate(ops):
        t = op['tool']
        g.raw('')
        g.comment(op['name'])
        g.reset_modal()
        if t['t'] != last_t:
            if i > 0:
                g.block('M9')
                g.block('G0 SUPA D0 Z0')
            g.block('T%d D1' % t['t'])
            g.block('M6')
            g.comment(t['kind'])
            g.block('S%d M3' % op['S'])
            g.block('G54')
            g.block('M8')
        last_t = t['t']
        if 'moves' in op:
            ms = op['moves']
            m0 = ms[0]
            g.block('G0 X%s Y%s' % (sfmt(m0[1]), sfmt(m0[2])))
            g.pos[0], g.pos[1] = m0[1], m0[2]
            g.motion = 0
            g.moves(ms[1:])
        else:
            h = op['holes']
            p = h['pts'][0]
            g.block('G0 X%s Y%s' % (sfmt(p[0]), sfmt(p[1])))
            g.block('G0 Z%s' % sfmt(h.get('top', 0) + h.get('clear', 15)))
            siemens_holes(g, h, op['S'])
    g.block('M9')
    g.block('M5')
    g.block('G0 SUPA D0 Z0')
    g.block('G0 SUPA X0 Y0')
    g.block('M30')
    return g.text()


# ---------------------------------------------------------------- Heidenhain Klartext
def tnc_holes(k, h, spindle):
    top = h.get('top', 0.0)
    q200 = h.get('r', 3.0)
    q201 = h['tip'] - top
    q204 = h.get('clear', 15)
    c = h['cycle']
    f = h['f']
    if c in ('drill', 'spot', 'peck') :
        q202 = h['q'] if c == 'peck' else -q201
        k.block('CYCL DEF 200 DRILLING ~')
        rows = [('Q200', q200, 'SET-UP CLEARANCE'), ('Q201', q201, 'DEPTH'),
                ('Q206', f, 'FEED RATE FOR PLNGNG'), ('Q202', q202, 'PLUNGING DEPTH'),
                ('Q210', 0, 'DWELL TIME AT TOP'), ('Q203', top, 'SURFACE COORDINATE'),
                ('Q204', q204, '2ND SET-UP CLEARANCE'),
                ('Q211', h.get('dwell', 0) / 1000, 'DWELL TIME AT DEPTH')]
    elif c == 'chip':
        k.block('CYCL DEF 203 UNIVERSAL DRILLING ~')
        rows = [('Q200', q200, 'SET-UP CLEARANCE'), ('Q201', q201, 'DEPTH'),
                ('Q206', f, 'FEED RATE FOR PLNGNG'), ('Q202', h['q'], 'PLUNGING DEPTH'),
                ('Q210', 0, 'DWELL TIME AT TOP'), ('Q203', top, 'SURFACE COORDINATE'),
                ('Q204', q204, '2ND SET-UP CLEARANCE'), ('Q212', 0, 'DECREMENT'),
                ('Q213', 3, 'BREAKS'), ('Q205', h['q'], 'MIN. PLUNGING DEPTH'),
                ('Q211', 0, 'DWELL TIME AT DEPTH'), ('Q208', 3000, 'RETRACTION FEED RATE'),
                ('Q256', 0.2, 'DIST. FOR CHIP BRKNG')]
    elif c == 'ream':
        k.block('CYCL DEF 201 REAMING ~')
        rows = [('Q200', q200, 'SET-UP CLEARANCE'), ('Q201', q201, 'DEPTH'),
                ('Q206', f, 'FEED RATE FOR PLNGNG'), ('Q211', 0, 'DWELL TIME AT DEPTH'),
                ('Q208', f * 2, 'RETRACTION FEED RATE'), ('Q203', top, 'SURFACE COORDINATE'),
                ('Q204', q204, '2ND SET-UP CLEARANCE')]
    elif c == 'tap':
        k.block('CYCL DEF 207 RIGID TAPPING NEW ~')
        rows = [('Q200', q200, 'SET-UP CLEARANCE'), ('Q201', q201, 'DEPTH OF THREAD'),
                ('Q239', h['pitch'], 'THREAD PITCH'), ('Q203', top, 'SURFACE COORDINATE'),
                ('Q204', q204, '2ND SET-UP CLEARANCE')]
    for i, (q, v, c_) in enumerate(rows):
        end = ' ~' if i + 1 < len(rows) else ''
        k.raw('    %s=%s    ;%s%s' % (q, num(v, 'tnc'), c_, end))
    for i, p in enumerate(h['pts']):
        if i == 0:
            k.block('L X%s Y%s R0 FMAX M99' % (k.nf(p[0]), k.nf(p[1])))
        else:
            k.block('L X%s Y%s R0 FMAX M99' % (k.nf(p[0]), k.nf(p[1])))


def fusion_tnc(name, ops, stock):
    k = Klartext(name)
    k.block('BEGIN PGM %s MM' % name)
    (x0, x1), (y0, y1), (z0, z1) = stock
    k.block('BLK FORM 0.1 Z X%s Y%s Z%s' % (k.nf(x0), k.nf(y0), k.nf(z0)))
    k.block('BLK FORM 0.2 X%s Y%s Z%s' % (k.nf(x1), k.nf(y1), k.nf(z1)))
    # newer Fusion heidenhain.cps: a framed tool list, '#n D=.. - ZMIN=.. - ZMAX=.. - type'
    k.block(';-------------------------------------')
    k.block(';Tools')
    seen = []
    for op in ops:
        t = op['tool']
        if t['t'] not in seen:
            seen.append(t['t'])
            s = '#%d D=%s' % (t['t'], sfmt(t['d']))
            if t.get('cr'):
                s += ' CR=%s' % sfmt(t['cr'])
            if t.get('taper'):
                s += ' TAPER=%sdeg' % sfmt(t['taper'])
            s += ' - ZMIN=%s - ZMAX=+15 - %s' % (num(t['zmin'], 'tnc'), t['kind'].lower())
            k.block(';  ' + s)
    k.block(';-------------------------------------')
    k.block(';')
    last_t = None
    for i, op in enumerate(ops):
        t = op['tool']
        k.block('* - ' + op['name'])
        k.reset_modal()
        if t['t'] != last_t:
            if i > 0:
                k.block('M9')
            k.block('M5')
            k.block('TOOL CALL %d Z S%d' % (t['t'], op['S']))
            k.block('L M140 MB MAX')
            k.block('M3')
        last_t = t['t']
        if 'moves' in op:
            ms = op['moves']
            m0 = ms[0]
            k.block('L X%s Y%s R0 FMAX' % (k.nf(m0[1]), k.nf(m0[2])))
            k.pos[0], k.pos[1] = m0[1], m0[2]
            k.block('L Z%s R0 FMAX' % k.nf(ms[1][3]))
            k.pos[2] = ms[1][3]
            k.block('M8')
            k.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            k.block('L X%s Y%s R0 FMAX' % (k.nf(p[0]), k.nf(p[1])))
            k.block('L Z%s R0 FMAX' % k.nf(h.get('top', 0) + h.get('clear', 15)))
            k.block('M8')
            tnc_holes(k, h, op['S'])
            k.block('L Z%s R0 FMAX' % k.nf(h.get('top', 0) + h.get('clear', 15)))
    k.block('M9')
    k.block('M5')
    k.block('L M140 MB MAX')
    k.block('M30')
    k.block('END PGM %s MM' % name)
    return k.text()


# ---------------------------------------------------------------- Fusion LinuxCNC
def fusion_lcnc(title, ops):
    g = GCode('ngc', numbering='N', start=10, step=5)
    g.raw('%')
    g.comment(title)
    seen = []
    for op in ops:
        t = op['tool']
        if t['t'] not in seen:
            seen.append(t['t'])
            g.comment(tool_comment_fusion(t, 'ngc'))
    g.block('G90 G94 G40 G17 G91.1')
    g.block('G21')
    g.block('G53 G0 Z0')
    last_t = None
    for i, op in enumerate(ops):
        t = op['tool']
        g.raw('')
        g.comment(op['name'])
        g.reset_modal()
        g.comp_d = t['t']
        if t['t'] != last_t:
            if i > 0:
                g.block('M9')
                g.block('G53 G0 Z0')
            g.block('T%d M6' % t['t'])
            g.block('S%d M3' % op['S'])
            g.block('G54')
            g.block('M8')
        last_t = t['t']
        if 'moves' in op:
            ms = op['moves']
            m0 = ms[0]
            g.block('G0 X%s Y%s' % (sfmt(m0[1]), sfmt(m0[2])))
            g.pos[0], g.pos[1] = m0[1], m0[2]
            g.motion = 0
            g.block('G43 Z%s H%d' % (sfmt(ms[1][3]), t['t']))
            g.pos[2] = ms[1][3]
            g.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            g.block('G0 X%s Y%s' % (sfmt(p[0]), sfmt(p[1])))
            g.block('G43 Z%s H%d' % (sfmt(h.get('clear', 15)), t['t']))
            g.pos = [p[0], p[1], h.get('clear', 15)]
            fanuc_holes(g, h, op['S'], lcnc=True)
            g.block('G0 Z%s' % sfmt(h.get('clear', 15)))
    g.block('M9')
    g.block('M5')
    g.block('G53 G0 Z0')
    g.block('M30')
    g.raw('%')
    return g.text()


# ---------------------------------------------------------------- Mastercam (MPFAN / Haas)
def mcam(prog, name, ops, stock_comment=None, material='ALUMINUM MM - 6061', haas=False,
         date='03-12-26', time='09:41'):
    g = GCode('mcam', numbering='N', start=100, step=2, comp_d=None)
    g.raw('%')
    g.raw('O%04d(%s)' % (prog, name.upper()))
    g.raw('(DATE=DD-MM-YY - %s TIME=HH:MM - %s)' % (date, time))
    g.raw('(MCX FILE - C:\\USERS\\PROG\\DOCUMENTS\\MY MCAM2022\\%s.MCAM)' % name.upper())
    g.raw('(NC FILE - C:\\USERS\\PROG\\DOCUMENTS\\MY MCAM2022\\MILL\\NC\\%s.NC)' % name.upper())
    g.raw('(MATERIAL - %s)' % material)
    if stock_comment:
        for s in stock_comment:
            g.raw(s)
    seen = []
    for op in ops:
        t = op['tool']
        if t['t'] not in seen:
            seen.append(t['t'])
            g.raw('( T%d | %s | H%d | D%d | TOOL DIA. - %s )' % (
                t['t'], t['mcam'], t['t'], t['t'], num(t['d'], 'mcam')))
    g.block('G21')
    g.block('G0 G17 G40 G49 G80 G90')
    last_t = None
    for i, op in enumerate(ops):
        t = op['tool']
        g.reset_modal()
        g.comp_d = t['t']
        if t['t'] != last_t:
            if i > 0:
                g.block('M5')
                g.block('G91 G28 Z0.')
                g.block('M01')
            g.comment(op['name'])
            g.block('T%d M6' % t['t'])
        else:
            g.comment(op['name'])
        last_t = t['t']
        if 'moves' in op:
            ms = op['moves']
            m0 = ms[0]
            g.block('G0 G90 G54 X%s Y%s S%d M3' % (g.numfmt(m0[1]), g.numfmt(m0[2]), op['S']))
            g.pos[0], g.pos[1] = m0[1], m0[2]
            g.motion = 0
            g.block('G43 H%d Z%s' % (t['t'], g.numfmt(ms[1][3])))
            g.pos[2] = ms[1][3]
            g.block('M8')
            g.moves(ms[2:])
        else:
            h = op['holes']
            p = h['pts'][0]
            g.block('G0 G90 G54 X%s Y%s S%d M3' % (g.numfmt(p[0]), g.numfmt(p[1]), op['S']))
            g.block('G43 H%d Z%s' % (t['t'], g.numfmt(h.get('clear', 15))))
            g.block('M8')
            g.pos = [p[0], p[1], h.get('clear', 15)]
            fanuc_holes(g, h, op['S'], haas=haas)
        g.block('M9')
    g.block('M5')
    g.block('G91 G28 Z0.')
    g.block('G28 X0. Y0.')
    g.block('M30')
    g.raw('%')
    return g.text()
