"""Writers that turn geom.py moves into the text of one post style (modal: only changed words)."""
import math


def num(v, style):
    v = round(v + 0.0, 3)
    if abs(v) < 5e-4:
        v = 0.0
    s = ('%.3f' % v).rstrip('0')
    if style == 'fanuc':        # Fusion Fanuc/Haas: 10.  -6.5  0.5
        return s
    if style == 'mcam':         # Mastercam: 10.  -6.5  .5
        if s.startswith('0.') and s != '0.':
            s = s[1:]
        elif s.startswith('-0.'):
            s = '-' + s[2:]
        return s
    s = s.rstrip('.')
    if s in ('-0', ''):
        s = '0'
    if style == 'tnc':          # Klartext: +10  -6.5
        return s if s.startswith('-') else '+' + s
    return s                    # siemens, linuxcnc, nx: 10  -6.5


class GCode:
    """Fanuc-family / Siemens / LinuxCNC word writer. style: fanuc | mcam | siemens | ngc."""

    def __init__(self, style, numbering=None, start=10, step=5, arc='ij', feed_fmt=None,
                 comp_d=None, gcode_pad=False):
        self.style = style
        self.lines = []
        self.numbering = numbering      # None | 'N' | 'N4' (N0010 as NX Fanuc)
        self.n = start
        self.step = step
        self.arc = arc                  # 'ij' incremental | 'ac' Siemens I=AC() | 'cr' radius
        self.pos = [None, None, None]
        self.motion = None
        self.feed = None
        self.comp_d = comp_d
        self.pending_comp = None
        self.gpad = gcode_pad           # G00/G01 (NX Fanuc, Mastercam writes G0/G1)

    def numfmt(self, v):
        return num(v, 'fanuc' if self.style == 'fanuc' else
                   'mcam' if self.style == 'mcam' else 'plain')

    def raw(self, text):
        self.lines.append(text)

    def block(self, text):
        if self.numbering == 'N':
            text = 'N%d %s' % (self.n, text)
            self.n += self.step
        elif self.numbering == 'N4':
            text = 'N%04d %s' % (self.n, text)
            self.n += self.step
        self.lines.append(text)

    def comment(self, text):
        if self.style == 'siemens':
            self.lines.append('; ' + text)
        else:
            self.lines.append('(' + text + ')')

    def g(self, n):
        return ('G%02d' % n) if self.gpad else ('G%d' % n)

    def reset_modal(self):
        self.pos = [None, None, None]
        self.motion = None
        self.feed = None

    def xyz(self, x, y, z, force=False):
        words = []
        for i, (a, v) in enumerate(zip('XYZ', (x, y, z))):
            if v is None:
                continue
            if force or self.pos[i] is None or abs(self.pos[i] - v) > 5e-4:
                words.append(a + self.numfmt(v))
            self.pos[i] = v
        return words

    def fword(self, f):
        if f is None or f == self.feed:
            return []
        self.feed = f
        if self.style in ('fanuc', 'mcam'):
            return ['F' + num(f, 'fanuc' if self.style == 'fanuc' else 'mcam')]
        return ['F' + num(f, 'plain')]

    def move(self, mv):
        k = mv[0]
        if k == 'note':
            self.comment(mv[1])
            return
        if k == 'comp':
            if mv[1] == 'off':
                self.pending_comp = 'G40'
            else:
                code = 'G41' if mv[1] == 'left' else 'G42'
                if self.style == 'siemens':
                    self.pending_comp = code
                else:
                    self.pending_comp = code + ' D%d' % self.comp_d
            return
        words = []
        if k == 'rapid':
            _, x, y, z = mv
            w = self.xyz(x, y, z)
            if not w:
                return
            if self.motion != 0:
                words.append(self.g(0))
                self.motion = 0
            words += w
        elif k == 'line':
            _, x, y, z, f = mv
            w = self.xyz(x, y, z)
            if not w:
                return
            if self.motion != 1:
                words.append(self.g(1))
                self.motion = 1
            words += w + self.fword(f)
        elif k == 'arc':
            _, d, x, y, z, cx, cy, f = mv
            sx, sy = self.pos[0], self.pos[1]
            code = 2 if d == 'cw' else 3
            if self.motion != code:
                words.append(self.g(code))
                self.motion = code
            helix = self.pos[2] is not None and abs(self.pos[2] - z) > 5e-4
            full = abs(sx - x) < 5e-4 and abs(sy - y) < 5e-4
            xy = self.xyz(x, y, z, force=False)
            if full:
                xy = ['X' + self.numfmt(x), 'Y' + self.numfmt(y)] + [w for w in xy if w[0] == 'Z']
            if not [w for w in xy if w[0] in 'XY']:
                xy = ['X' + self.numfmt(x)] + xy
            words += xy
            if self.arc == 'ac':
                words += ['I=AC(%s)' % num(cx, 'plain'), 'J=AC(%s)' % num(cy, 'plain')]
            elif self.arc == 'cr' and not full:
                r = math.hypot(sx - cx, sy - cy)
                words += ['CR=%s' % num(r, 'plain')] if self.style == 'siemens' else \
                         ['R' + self.numfmt(r)]
            else:
                words += ['I' + self.numfmt(cx - sx), 'J' + self.numfmt(cy - sy)]
            words += self.fword(f)
        if self.pending_comp:
            words.insert(1 if words and words[0].startswith('G') else 0, self.pending_comp)
            # keep G40/G41 before the motion word as posts write "G1 G41 D1 X.."
            if words[0] in ('G41 D%s' % self.comp_d, 'G42 D%s' % self.comp_d, 'G40', 'G41', 'G42'):
                pass
            self.pending_comp = None
        self.block(' '.join(words))

    def moves(self, ms):
        for mv in ms:
            self.move(mv)

    def text(self):
        return '\n'.join(self.lines) + '\n'


class Klartext:
    """Heidenhain TNC conversational writer (block numbers, L / CC / C, FMAX, RL/RR/R0)."""

    def __init__(self, name, signs=True, fmax='FMAX'):
        self.name = name
        self.lines = []
        self.n = 0
        self.pos = [None, None, None]
        self.feed = None
        self.comp = 'R0'
        self.cc = None
        self.signs = signs
        self.fmax = fmax

    def nf(self, v):
        s = num(v, 'tnc')
        if not self.signs and s.startswith('+'):
            s = s[1:]
        return s

    def block(self, text):
        self.lines.append('%d %s' % (self.n, text))
        self.n += 1

    def raw(self, text):
        self.lines.append(text)

    def comment(self, text):
        self.block('; ' + text)

    def reset_modal(self):
        self.pos = [None, None, None]
        self.feed = None
        self.cc = None

    def xyz(self, x, y, z):
        w = []
        for i, (a, v) in enumerate(zip('XYZ', (x, y, z))):
            if v is None:
                continue
            if self.pos[i] is None or abs(self.pos[i] - v) > 5e-4:
                w.append(a + self.nf(v))
            self.pos[i] = v
        return w

    def move(self, mv):
        k = mv[0]
        if k == 'note':
            self.comment(mv[1])
            return
        if k == 'comp':
            self.comp = {'left': 'RL', 'right': 'RR', 'off': 'R0'}[mv[1]]
            self.comp_changed = True
            return
        if k == 'rapid':
            w = self.xyz(*mv[1:4])
            if not w:
                return
            self.block('L ' + ' '.join(w) + ' R0 ' + self.fmax)
            self.comp = 'R0'
        elif k == 'line':
            _, x, y, z, f = mv
            w = self.xyz(x, y, z)
            if not w:
                return
            fw = ''
            if f != self.feed:
                fw = ' F%d' % round(f)
                self.feed = f
            self.block('L ' + ' '.join(w) + ' ' + self.comp + fw)
        elif k == 'arc':
            _, d, x, y, z, cx, cy, f = mv
            if self.cc is None or abs(self.cc[0] - cx) > 5e-4 or abs(self.cc[1] - cy) > 5e-4:
                self.block('CC X%s Y%s' % (self.nf(cx), self.nf(cy)))
                self.cc = (cx, cy)
            if self.pos[2] is not None and abs(self.pos[2] - z) > 5e-4:
                # helix: polar arc about the pole, incremental angle and depth (Fusion heidenhain.cps)
                a0 = math.degrees(math.atan2(self.pos[1] - cy, self.pos[0] - cx))
                a1 = math.degrees(math.atan2(y - cy, x - cx))
                sw = (a1 - a0) % 360 if d == 'ccw' else -((a0 - a1) % 360)
                if abs(sw) < 1e-6:
                    sw = 360 if d == 'ccw' else -360
                dz = z - self.pos[2]
                self.pos = [x, y, z]
                fw = ''
                if f != self.feed:
                    fw = ' F%d' % round(f)
                    self.feed = f
                self.block('CP IPA%s IZ%s DR%s %s%s' % (num(sw, 'tnc'), num(dz, 'tnc'),
                                                      '+' if d == 'ccw' else '-', self.comp, fw))
                return
            self.pos[0] = x
            self.pos[1] = y
            w = ['X' + self.nf(x), 'Y' + self.nf(y)]
            if self.pos[2] is None or abs(self.pos[2] - z) > 5e-4:
                w.append('Z' + self.nf(z))
                self.pos[2] = z
            fw = ''
            if f != self.feed:
                fw = ' F%d' % round(f)
                self.feed = f
            self.block('C ' + ' '.join(w) + (' DR+' if d == 'ccw' else ' DR-') + ' ' + self.comp + fw)

    def moves(self, ms):
        for mv in ms:
            self.move(mv)

    def text(self):
        return '\n'.join(self.lines) + '\n'


class Apt:
    """CLDATA writer (NX CLSF listing style or ISO 4343 style)."""

    def __init__(self, flavour='nx'):
        self.flavour = flavour
        self.lines = []
        self.pos = [0.0, 0.0, 50.0]
        self.feed = None

    def raw(self, text):
        self.lines.append(text)

    def f(self, v):
        if self.flavour == 'nx':
            return '%.4f' % (round(v, 4) + 0.0)
        return '%.3f' % (round(v, 3) + 0.0)

    def goto(self, x, y, z):
        x = self.pos[0] if x is None else x
        y = self.pos[1] if y is None else y
        z = self.pos[2] if z is None else z
        self.pos = [x, y, z]
        self.lines.append('GOTO/%s,%s,%s' % (self.f(x), self.f(y), self.f(z)))

    def fedrat(self, v):
        if v is None or v == self.feed:
            return
        self.feed = v
        if self.flavour == 'nx':
            self.lines.append('FEDRAT/MMPM,%s' % self.f(v))
        else:
            self.lines.append('FEDRAT/%s,MMPM' % self.f(v))

    def move(self, mv):
        k = mv[0]
        if k == 'note':
            self.lines.append('PPRINT/' + mv[1])
        elif k == 'comp':
            self.lines.append({'left': 'CUTCOM/LEFT', 'right': 'CUTCOM/RIGHT',
                               'off': 'CUTCOM/OFF'}[mv[1]])
        elif k == 'rapid':
            self.lines.append('RAPID')
            self.goto(*mv[1:4])
        elif k == 'line':
            self.fedrat(mv[4])
            self.goto(*mv[1:4])
        elif k == 'arc':
            _, d, x, y, z, cx, cy, f = mv
            self.fedrat(f)
            r = math.hypot(self.pos[0] - cx, self.pos[1] - cy)
            if self.flavour == 'nx':
                # NX: motion is clockwise about the CIRCLE axis (cldata.md 4.2)
                k_ = '0.0000000,0.0000000,1.0000000' if d == 'cw' else '0.0000000,0.0000000,-1.0000000'
                self.lines.append('CIRCLE/%s,%s,%s,%s,%s,0.0100,0.5000,%s,0.0000' % (
                    self.f(cx), self.f(cy), self.f(self.pos[2]), k_, self.f(r), self.f(self.tool_d)))
            else:
                kk = '0,0,1' if d == 'ccw' else '0,0,-1'
                self.lines.append('CIRCLE/%s,%s,%s,%s,%s' % (
                    self.f(cx), self.f(cy), self.f(self.pos[2]), kk, self.f(r)))
            self.goto(x, y, z)

    def moves(self, ms):
        for mv in ms:
            self.move(mv)

    def text(self):
        return '\n'.join(self.lines) + '\n'
