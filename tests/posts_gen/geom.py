"""Tool-path geometry for the post-style test programs in tests/programs/posts/.

Each function takes the PART geometry from the design (DESIGN.md) and the tool, and returns a list
of moves in tool-centre coordinates (computer compensation) or in part-contour coordinates with a
compensation marker (control compensation). The emitters in emit.py turn the moves into the text a
post processor of one style writes. The expectations (the .json sidecars) are written by hand from
DESIGN.md, not from this file.

Move tuples:
  ('rapid', x, y, z)            any of x y z may be None (axis not moved)
  ('line', x, y, z, f)
  ('arc', 'cw'|'ccw', x, y, z, cx, cy, f)   centre absolute; z != start z => helix
  ('comp', 'left'|'right'|'off')  radius compensation switched on the NEXT move
  ('note', text)
"""
import math

F = None


def rrect_loop(cx, cy, w, l, r, z, direction, f):
    """Closed loop around a rounded rectangle, starting and ending at the middle of the bottom edge
    (cx, cy - l/2). direction 'ccw' (pocket climb with M3) or 'cw' (outside climb with M3)."""
    x0, x1 = cx - w / 2, cx + w / 2
    y0, y1 = cy - l / 2, cy + l / 2
    r = max(r, 0.0)
    m = []
    if direction == 'ccw':
        pts = [
            ('line', x1 - r, y0), ('arc', x1, y0 + r, x1 - r, y0 + r),
            ('line', x1, y1 - r), ('arc', x1 - r, y1, x1 - r, y1 - r),
            ('line', x0 + r, y1), ('arc', x0, y1 - r, x0 + r, y1 - r),
            ('line', x0, y0 + r), ('arc', x0 + r, y0, x0 + r, y0 + r),
            ('line', cx, y0),
        ]
        d = 'ccw'
    else:
        pts = [
            ('line', x0 + r, y0), ('arc', x0, y0 + r, x0 + r, y0 + r),
            ('line', x0, y1 - r), ('arc', x0 + r, y1, x0 + r, y1 - r),
            ('line', x1 - r, y1), ('arc', x1, y1 - r, x1 - r, y1 - r),
            ('line', x1, y0 + r), ('arc', x1 - r, y0, x1 - r, y0 + r),
            ('line', cx, y0),
        ]
        d = 'cw'
    for p in pts:
        if p[0] == 'line':
            m.append(('line', p[1], p[2], z, f))
        elif r > 0:
            m.append(('arc', d, p[1], p[2], z, p[3], p[4], f))
    return m


def pocket(cx, cy, w, l, r, tool_d, depths, stepover, entry, f_cut, f_plunge,
           top=0.0, clear=15.0, safe=5.0, allowance=0.0, finish_comp=None, lead=None):
    """Closed rectangular pocket. Computer comp: loops of the contour offset inward by the tool
    radius (+allowance) and by multiples of stepover, innermost first, joined by straight moves
    along the X = cx line. entry: 'helix' (at the centre), 'ramp' (along X through the centre) or
    'plunge' (at the centre). finish_comp 'left': a last pass on the part contour with G41 at the
    final depth (control compensation), entered by a quarter-arc lead of radius `lead`."""
    rt = tool_d / 2
    m = [('rapid', cx, cy, None), ('rapid', None, None, clear), ('rapid', None, None, safe)]
    prev_z = top
    for z in depths:
        # entry
        if entry == 'helix':
            hr = round(min(rt * 0.6, 3.0), 3)
            m.append(('line', cx + hr, cy, prev_z + 1.0, f_plunge))
            zz = prev_z + 1.0
            while zz > z + 1e-9:
                z_half = max(zz - 0.5, z)
                z_end = max(zz - 1.0, z)
                m.append(('arc', 'ccw', cx - hr, cy, z_half, cx, cy, f_plunge))
                m.append(('arc', 'ccw', cx + hr, cy, z_end, cx, cy, f_plunge))
                zz = z_end
            m.append(('arc', 'ccw', cx - hr, cy, z, cx, cy, f_cut))
            m.append(('arc', 'ccw', cx + hr, cy, z, cx, cy, f_cut))
            m.append(('line', cx, cy, z, f_cut))
        elif entry == 'ramp':
            a = min(w / 2 - rt - 1, 12.0)
            m.append(('line', cx, cy, prev_z + 0.5, f_plunge))
            zz = prev_z + 0.5
            side = 1
            while zz > z + 1e-9:
                zz = max(zz - 1.0, z)
                m.append(('line', cx + side * a, cy, zz, f_plunge))
                side = -side
            m.append(('line', cx + side * a, cy, z, f_cut))
            m.append(('line', cx, cy, z, f_cut))
        else:
            m.append(('line', cx, cy, prev_z + 1.0, f_plunge))
            m.append(('line', cx, cy, z, f_plunge))
        # loops, innermost first
        o0 = rt + allowance
        offs = [o0]
        while True:
            nxt = offs[-1] + stepover
            if min(w, l) - 2 * nxt < 2.0:
                break
            offs.append(nxt)
        # keep only loops that still have a positive size
        for o in reversed(offs):
            wl, ll = w - 2 * o, l - 2 * o
            m.append(('line', cx, cy - ll / 2, z, f_cut))
            m.extend(rrect_loop(cx, cy, wl, ll, r - o, z, 'ccw', f_cut))
        m.append(('line', cx, cy - (l - 2 * offs[0]) / 2 + stepover / 2, z, f_cut))
        m.append(('rapid', None, None, safe))
        m.append(('rapid', cx, cy, None))
        prev_z = z
    if finish_comp:
        z = depths[-1]
        a = lead
        y0 = cy - l / 2
        m.append(('rapid', cx - a, y0 + 2 * a, None))
        m.append(('line', cx - a, y0 + 2 * a, z, f_plunge))
        m.append(('comp', finish_comp))
        m.append(('line', cx - a, y0 + a, z, f_cut))
        m.append(('arc', 'ccw', cx, y0, z, cx, y0 + a, f_cut))
        m.extend(rrect_loop(cx, cy, w, l, r, z, 'ccw', f_cut))
        m.append(('arc', 'ccw', cx + a, y0 + a, z, cx, y0 + a, f_cut))
        m.append(('comp', 'off'))
        m.append(('line', cx + a, y0 + 2 * a, z, f_cut))
    m.append(('rapid', None, None, clear))
    return m


def profile(cx, cy, w, l, r, tool_d, depths, f_cut, f_plunge, comp='computer', lead=8.0,
            clear=15.0, safe=5.0, allowance=0.0):
    """Outside profile of a rounded rectangle (boss / part outline), climb (CW with M3), entered
    from outside below the bottom edge by a line and a quarter arc of radius `lead` (tool-centre
    lead radius in computer comp; programmed radius in control comp)."""
    rt = tool_d / 2
    o = rt + allowance if comp == 'computer' else 0.0
    wl, ll, rl = w + 2 * o, l + 2 * o, r + o
    y0 = cy - ll / 2
    a = lead
    m = [('rapid', cx + a, y0 - 2 * a, None), ('rapid', None, None, clear),
         ('rapid', None, None, safe)]
    for i, z in enumerate(depths):
        if i > 0:
            m.append(('rapid', None, None, safe))
            m.append(('rapid', cx + a, y0 - 2 * a, None))
        m.append(('line', None, None, z, f_plunge))
        if comp == 'control':
            m.append(('comp', 'left'))
        m.append(('line', cx + a, y0 - a, z, f_cut))
        m.append(('arc', 'ccw', cx, y0, z, cx, y0 - a, f_cut))
        m.extend(rrect_loop(cx, cy, wl, ll, rl, z, 'cw', f_cut))
        m.append(('arc', 'ccw', cx - a, y0 - a, z, cx, y0 - a, f_cut))
        if comp == 'control':
            m.append(('comp', 'off'))
        m.append(('line', cx - a, y0 - 2 * a, z, f_cut))
    m.append(('rapid', None, None, clear))
    return m


def face(xmin, xmax, ymin, ymax, tool_d, z, stepover, f_cut, f_plunge, clear=15.0, safe=5.0,
         axis='x'):
    """Zig-zag facing across the whole top: lines along X from outside to outside, stepping in Y."""
    rt = tool_d / 2
    xs, xe = xmin - rt - 5, xmax + rt + 5
    # first centre line: the tool overhangs the near edge by 20 % of its diameter
    y = round(ymin + rt - 0.2 * tool_d, 3)
    ys = []
    while True:
        ys.append(y)
        if y + rt >= ymax + 0.1 * tool_d - 1e-6:
            break
        y = round(y + stepover, 3)
    m = [('rapid', xs, ys[0], None), ('rapid', None, None, clear), ('rapid', None, None, safe),
         ('line', None, None, z, f_plunge)]
    left = True
    for i, y in enumerate(ys):
        if i > 0:
            m.append(('line', None, y, z, f_cut))
        m.append(('line', xe if left else xs, y, z, f_cut))
        left = not left
    m.append(('rapid', None, None, clear))
    return m, ys


def lines_at(pts, depths, f_cut, f_plunge, clear=15.0, safe=5.0, start_outside=True):
    """Straight passes through a list of XY points at each depth (steps, slots). Each depth starts
    at pts[0] (outside the stock for steps: plunged in air), goes through the points."""
    m = [('rapid', pts[0][0], pts[0][1], None), ('rapid', None, None, clear),
         ('rapid', None, None, safe)]
    for i, z in enumerate(depths):
        if i > 0:
            m.append(('rapid', None, None, safe))
            m.append(('rapid', pts[0][0], pts[0][1], None))
        m.append(('line', None, None, z, f_plunge))
        for p in pts[1:]:
            m.append(('line', p[0], p[1], z, f_cut))
    m.append(('rapid', None, None, clear))
    return m


def step_passes(x_from, x_to, ys, depths, f_cut, f_plunge, clear=15.0, safe=5.0):
    """A step along an edge: at each depth, straight passes along X at every Y in ys (outer first),
    zig-zag, from outside the stock to outside."""
    m = [('rapid', x_from, ys[0], None), ('rapid', None, None, clear),
         ('rapid', None, None, safe)]
    for i, z in enumerate(depths):
        if i > 0:
            m.append(('rapid', None, None, safe))
            m.append(('rapid', x_from, ys[0], None))
        m.append(('line', None, None, z, f_plunge))
        fwd = True
        for j, y in enumerate(ys):
            if j > 0:
                m.append(('line', None, y, z, f_cut))
            m.append(('line', x_to if fwd else x_from, y, z, f_cut))
            fwd = not fwd
        if not fwd:
            pass
    m.append(('rapid', None, None, clear))
    return m


def slot(x1, y1, x2, y2, width, tool_d, depths, f_cut, f_plunge, clear=15.0, safe=5.0):
    """Straight slot along X (y1 == y2) with round ends. width == tool_d: one pass on the centre
    line per depth. width > tool_d: centre pass, then a loop offset by (width-tool_d)/2 with
    half circles at the ends."""
    assert abs(y1 - y2) < 1e-9
    y = y1
    off = (width - tool_d) / 2
    m = [('rapid', x1, y, None), ('rapid', None, None, clear), ('rapid', None, None, safe)]
    at_start = True
    for i, z in enumerate(depths):
        if i > 0 and off > 0:
            m.append(('rapid', None, None, safe))
            m.append(('rapid', x1, y, None))
            at_start = True
        m.append(('line', None, None, z, f_plunge))
        if off <= 1e-9:
            m.append(('line', x2 if at_start else x1, y, z, f_cut))
            at_start = not at_start
        else:
            m.append(('line', x2, y, z, f_cut))
            m.append(('line', x2, y - off, z, f_cut))
            # loop: along bottom to x1? climb inside a slot = CCW: bottom edge +X, right end up
            m.append(('arc', 'ccw', x2, y + off, z, x2, y, f_cut))
            m.append(('line', x1, y + off, z, f_cut))
            m.append(('arc', 'ccw', x1, y - off, z, x1, y, f_cut))
            m.append(('line', x2, y - off, z, f_cut))
            m.append(('line', x2, y, z, f_cut))
            m.append(('rapid', None, None, safe))
    m.append(('rapid', None, None, clear))
    return m


def tip_depth(full_depth, d, angle):
    return full_depth + (d / 2) / math.tan(math.radians(angle / 2))
