//! LinuxCNC's lathe profile cycles (G70 finishing, G71/G72 roughing and their `.1`/`.2`
//! variants), whose contour is the O-word subroutine named by Q. The passes are worked out
//! as rs274 works them out, so that the canon agrees with it: the profile is offset by the
//! finishing distance, turned so that it runs with Z and X falling, shifted by the
//! allowances U and W, and cut level by level, with pockets (G71, G72), without them (`.1`)
//! or only from the first pocket on (`.2`).
//!
//! Points are complex numbers, Z the real part and X the imaginary one.

use nalgebra::Complex;

use super::Interpreter;
use crate::canon::{Canon, CanonOp, CanonSink, DistanceMode, Plane};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::text::TextRange;

type C = Complex<f64>;

/// Where the cycle's moves go, in the program's (Z, X) frame.
pub(super) trait Out {
    /// A straight move, at rapid or at feed.
    fn line(&mut self, to: C, rapid: bool);
    /// An arc about `centre` (counter-clockwise in the Z-X frame when `ccw`: G3).
    fn arc(&mut self, ccw: bool, centre: C, to: C);
}

/// Within this, two points or levels are the same.
const TOL: f64 = 1e-6;

/// One element of a profile.
#[derive(Clone, Copy, Debug)]
pub(super) enum Seg {
    /// A straight line.
    Line { s: C, e: C },
    /// An arc about `c`.
    Arc { ccw: bool, s: C, e: C, c: C },
    /// A corner finish at `at` (the A word rounds with a radius, the C word chamfers),
    /// made into an arc or a line between its neighbours before the cut.
    Corner { round: bool, size: f64, at: C },
}

fn i() -> C {
    C::new(0.0, 1.0)
}

impl Seg {
    fn sp(&self) -> C {
        match *self {
            Seg::Line { s, .. } | Seg::Arc { s, .. } => s,
            Seg::Corner { at, .. } => at,
        }
    }

    fn ep(&self) -> C {
        match *self {
            Seg::Line { e, .. } | Seg::Arc { e, .. } => e,
            Seg::Corner { at, .. } => at,
        }
    }

    fn set_sp(&mut self, p: C) {
        match self {
            Seg::Line { s, .. } | Seg::Arc { s, .. } => *s = p,
            Seg::Corner { at, .. } => *at = p,
        }
    }

    fn set_ep(&mut self, p: C) {
        match self {
            Seg::Line { e, .. } | Seg::Arc { e, .. } => *e = p,
            Seg::Corner { at, .. } => *at = p,
        }
    }

    /// The points at which the element is at level `x`, as Z values.
    fn at_level(&self, x: f64) -> Vec<f64> {
        let mut out = Vec::new();
        match *self {
            Seg::Line { s, e } => {
                if s.im.min(e.im) > x + TOL || s.im.max(e.im) < x - TOL {
                    return out;
                }
                if (s.im - e.im).abs() < TOL {
                    out.push(s.re);
                    out.push(e.re);
                } else {
                    out.push((x - s.im) / (e.im - s.im) * (e.re - s.re) + s.re);
                }
            }
            Seg::Arc { c, s, .. } => {
                let r = (s - c).norm();
                let mut q = -(x - r - c.im) * (x + r - c.im);
                if q < -TOL {
                    return out;
                }
                if q < 0.0 {
                    q = 0.0;
                }
                let q = q.sqrt();
                for z in [c.re + q, c.re - q] {
                    if self.on_arc(C::new(z, x)) {
                        out.push(z);
                    }
                }
            }
            Seg::Corner { .. } => {}
        }
        out
    }

    /// Whether `p` (on the arc's circle) lies between its start and end.
    fn on_arc(&self, p: C) -> bool {
        let Seg::Arc { ccw, s, e, c } = *self else { return true };
        let a = ((s - c).conj() * (p - c)).im;
        let b = ((e - c).conj() * (p - c)).im;
        if ccw { a >= -TOL && b <= TOL } else { a <= TOL && b >= -TOL }
    }

    /// Follows the element while it climbs (X rising); true when it does not.
    fn climb(&self, at: &mut C, out: &mut dyn Out) -> Result<bool, String> {
        match *self {
            Seg::Line { s, e } => {
                if e.im + TOL < s.im {
                    return Ok(true);
                }
                if (*at - s).norm() > TOL {
                    return Err("the profile is followed from a point off it".into());
                }
                out.line(e, false);
                *at = e;
                Ok(false)
            }
            Seg::Arc { ccw: false, c, e, .. } => {
                if at.re > c.re {
                    return Ok(true);
                }
                if (*at - e).norm() > 1e-3 {
                    out.arc(false, c, e);
                }
                *at = e;
                Ok(false)
            }
            Seg::Arc { ccw: true, c, e, s } => {
                if at.re < c.re {
                    return Ok(true);
                }
                let mut to = e;
                if e.re < c.re {
                    to = C::new(c.re, c.im + (s - c).norm());
                }
                if (*at - to).norm() > 1e-3 {
                    out.arc(true, c, to);
                }
                *at = to;
                Ok(true)
            }
            Seg::Corner { .. } => Ok(false),
        }
    }

    /// Moves onto the element at `at`'s level and follows it up while it climbs.
    fn climb_only(&self, at: &mut C, out: &mut dyn Out) {
        match *self {
            Seg::Line { s, e } => {
                if e.im < s.im {
                    return;
                }
                let Some(&z) = self.at_level(at.im).first() else { return };
                at.re = z;
                out.line(*at, false);
                out.line(e, false);
                *at = e;
            }
            Seg::Arc { ccw, c, e, s } => {
                let zs = self.at_level(at.im);
                let (Some(&first), Some(&last)) = (zs.first(), zs.last()) else { return };
                if !ccw {
                    if last > c.re {
                        return;
                    }
                    at.re = last;
                    out.line(*at, false);
                    if (*at - e).norm() > 1e-3 {
                        out.arc(false, c, e);
                    }
                    *at = e;
                } else {
                    if first < c.re {
                        return;
                    }
                    at.re = first;
                    out.line(*at, false);
                    let mut to = e;
                    if e.re < c.re {
                        to = C::new(c.re, c.im + (s - c).norm());
                    }
                    if (*at - to).norm() > 1e-3 {
                        out.arc(true, c, to);
                    }
                    *at = to;
                }
            }
            Seg::Corner { .. } => {}
        }
    }

    /// Follows the element down to level `x` (or its end); true when it does not dive.
    fn dive(&self, at: &mut C, x: f64, out: &mut dyn Out, fast: bool) -> Result<bool, String> {
        match *self {
            Seg::Line { s, e } => {
                if s.im <= e.im + TOL {
                    return Ok(true);
                }
                if x < e.im {
                    out.line(e, fast);
                    *at = e;
                    return Ok(false);
                }
                let Some(&z) = self.at_level(x).first() else {
                    return Err("a pass level lies beyond the profile's descent".into());
                };
                let to = C::new(z, x);
                out.line(to, fast);
                *at = to;
                Ok(false)
            }
            Seg::Arc { ccw, c, e, .. } => {
                if (*at - e).norm() < TOL || (*at - e).re <= TOL {
                    *at = e;
                    return Ok(false);
                }
                let mut zs = self.at_level(x);
                if zs.is_empty() {
                    zs = self.at_level(x - TOL);
                }
                if ccw {
                    if at.re - TOL > c.re {
                        return Ok(true);
                    }
                    match zs.last().copied().filter(|&z| z <= c.re) {
                        None => {
                            out.arc(true, c, e);
                            *at = e;
                        }
                        Some(z) => {
                            let to = C::new(z, x);
                            out.arc(true, c, to);
                            *at = to;
                        }
                    }
                } else {
                    if at.re <= c.re {
                        return Ok(true);
                    }
                    match zs.first().copied() {
                        None => {
                            out.arc(false, c, e);
                            *at = e;
                        }
                        // Met only on the far side: the pass level goes down first.
                        Some(z) if z < c.re => {}
                        Some(z) => {
                            let to = C::new(z, x);
                            out.arc(false, c, to);
                            *at = to;
                        }
                    }
                }
                Ok(false)
            }
            Seg::Corner { .. } => Ok(false),
        }
    }

    fn draw(&self, out: &mut dyn Out) {
        match *self {
            Seg::Line { e, .. } => out.line(e, false),
            Seg::Arc { ccw, c, e, .. } => out.arc(ccw, c, e),
            Seg::Corner { .. } => {}
        }
    }

    /// Moves the element `d` to its side (left of its direction for a line; away from the
    /// centre of a counter-clockwise arc).
    fn offset(&mut self, d: f64) {
        match self {
            Seg::Line { s, e } => {
                let shift = i() * d * (*s - *e) / (*s - *e).norm();
                *s += shift;
                *e += shift;
            }
            Seg::Arc { ccw, s, e, c } => {
                let r = (*s - *c).norm();
                let k = (r + if *ccw { d } else { -d }) / r;
                *s = (*s - *c) * k + *c;
                *e = (*e - *c) * k + *c;
            }
            Seg::Corner { .. } => {}
        }
    }

    fn radius(&self) -> f64 {
        match *self {
            Seg::Line { s, e } => (s - e).norm(),
            Seg::Arc { s, e, c, .. } => (s - e).norm().min((s - c).norm()),
            Seg::Corner { .. } => 0.0,
        }
    }

    /// Whether the element runs with Z falling (the form roughing needs).
    fn monotonic(&self) -> bool {
        match *self {
            Seg::Line { s, e } => (e - s).re <= 1e-3,
            Seg::Arc { ccw, s, e, c } => {
                let (entry, exit, dz) = ((s - c).im, (e - c).im, (e - s).re);
                if ccw { entry >= -1e-3 && exit >= -1e-3 && dz <= -1e-3 } else { entry <= 1e-3 && exit <= 1e-3 && dz <= -1e-3 }
            }
            Seg::Corner { .. } => true,
        }
    }

    fn map(&mut self, f: impl Fn(C) -> C, mirror: bool) {
        match self {
            Seg::Line { s, e } => (*s, *e) = (f(*s), f(*e)),
            Seg::Arc { ccw, s, e, c } => {
                (*s, *e, *c) = (f(*s), f(*e), f(*c));
                if mirror {
                    *ccw = !*ccw;
                }
            }
            Seg::Corner { at, .. } => *at = f(*at),
        }
    }
}

/// Makes `prev`'s end and `next`'s start one point again after both were offset.
fn join(prev: &mut Seg, next: &mut Seg) -> Result<(), String> {
    // The point where the line through `a`–`b` meets the circle about `centre` through
    // `through`, nearest `near`.
    let on_circle = |a: C, b: C, centre: C, through: C, near: C| {
        let rot = (a - b).conj() / (a - b).norm();
        let pe = (through - b) * rot;
        let pc = (centre - b) * rot;
        let q = (pc - pe).norm_sqr() - pc.im * pc.im;
        let q = if q < 0.0 { 0.0 } else { q.sqrt() };
        let s1 = C::new(pc.re + q, 0.0) / rot + b;
        let s2 = C::new(pc.re - q, 0.0) / rot + b;
        if (near - s1).norm() < (near - s2).norm() { s1 } else { s2 }
    };
    let p = match (*prev, *next) {
        (Seg::Line { s: ps, e: pe }, Seg::Line { s: ns, e: ne }) => {
            let rot = (ns - ne).conj() / (ns - ne).norm();
            let (a, b) = ((ps - ne) * rot, (pe - ne) * rot);
            if (a - b).im == 0.0 {
                return Err("two parallel lines of the profile cannot be joined".into());
            }
            let f = a.im / (a - b).im;
            (a + (b - a) * f) / rot + ne
        }
        (Seg::Arc { e: pe, c, .. }, Seg::Line { s: ns, e: ne }) => {
            if (ns - pe).norm() < TOL {
                return Ok(());
            }
            on_circle(ns, ne, c, pe, ns)
        }
        (Seg::Line { s: ps, e: pe }, Seg::Arc { s: ns, e: ne, c, .. }) => {
            if (ns - pe).norm() < TOL {
                return Ok(());
            }
            on_circle(ps, pe, c, ne, ns)
        }
        (Seg::Arc { s: ps, c: pc, .. }, Seg::Arc { s: ns, c: nc, .. }) => {
            let a = (ns - nc).norm();
            let b = (ps - pc).norm();
            let c = (nc - pc).norm();
            let cos = (c * c + a * a - b * b) / 2.0 / a / c;
            let cos2 = (cos * cos).min(1.0);
            let rot = C::new(cos, (1.0 - cos2).sqrt());
            rot * (pc - nc) / c * a + nc
        }
        _ => return Ok(()),
    };
    prev.set_ep(p);
    next.set_sp(p);
    Ok(())
}

/// A profile with the state of its roughing.
#[derive(Clone, Debug)]
pub(super) struct Profile {
    segs: Vec<Seg>,
    delta: f64,
    escape: C,
    /// How the profile was turned to run with Z and X falling: bit 0 Z mirrored, bit 1 X
    /// mirrored, bit 2 rotated by 90°.
    flip: u8,
    /// Where the pockets being cut began (their first levels count from there).
    pocket_starts: Vec<C>,
}

/// Steps a cycle may take at most: beyond, the profile is taken to be one it cannot cut.
const MAX_STEPS: usize = 100_000;

/// Undoes the profile's turning on the moves it makes.
struct Unflip<'o> {
    out: &'o mut dyn Out,
    flip: u8,
}

impl Unflip<'_> {
    fn point(&self, p: C) -> C {
        match self.flip {
            0 => p,
            1 => -p.conj(),
            2 => p.conj(),
            3 => -p,
            4 => i() * p,
            5 => (i() * p).conj(),
            6 => -(i() * p).conj(),
            _ => -i() * p,
        }
    }
}

impl Out for Unflip<'_> {
    fn line(&mut self, to: C, rapid: bool) {
        let to = self.point(to);
        self.out.line(to, rapid);
    }

    fn arc(&mut self, ccw: bool, centre: C, to: C) {
        let mirrored = matches!(self.flip, 1 | 2 | 5 | 6);
        let (centre, to) = (self.point(centre), self.point(to));
        self.out.arc(ccw != mirrored, centre, to);
    }
}

impl Profile {
    pub(super) fn new(segs: Vec<Seg>) -> Profile {
        Profile { segs, delta: 0.5, escape: C::new(0.3, 0.3), flip: 0, pocket_starts: Vec::new() }
    }

    fn rotate(&mut self) {
        for s in &mut self.segs {
            s.map(|p| -p * i(), false);
        }
        self.flip ^= 4;
    }

    /// Turns the profile so that it runs with Z and X falling.
    fn swap(&mut self) {
        let (Some(first), Some(last)) = (self.segs.first(), self.segs.last()) else { return };
        let d = first.ep() - last.ep();
        if d.im > 0.0 {
            for s in &mut self.segs {
                s.map(|p| p.conj(), true);
            }
            self.flip ^= 2;
        }
        if d.re < 0.0 {
            for s in &mut self.segs {
                s.map(|p| -p.conj(), true);
            }
            self.flip ^= 1;
        }
    }

    fn monotonic(&mut self) -> Result<(), String> {
        if let Some(first) = self.segs.first_mut()
            && (first.ep() - first.sp()).re > 0.0
        {
            let mut s = first.sp();
            s.re = first.ep().re;
            first.set_sp(s);
        }
        if self.segs.iter().any(|s| !s.monotonic()) {
            return Err("the profile is not monotonic: it turns back along the cutting direction".into());
        }
        Ok(())
    }

    /// Whether the profile, its approach aside, needs turning by 90° to be monotonic.
    fn should_rotate(&self) -> bool {
        let mut rest = self.clone();
        if !rest.segs.is_empty() {
            rest.segs.remove(0);
        }
        rest.swap();
        rest.segs.iter().any(|s| !s.monotonic())
    }

    /// Makes each corner finish an arc or a chamfer between its neighbours.
    fn do_finish(&mut self) -> Result<(), String> {
        for h in 1..self.segs.len().saturating_sub(1) {
            let Seg::Corner { round, size, .. } = self.segs[h] else { continue };
            let (prev, next) = (self.segs[h - 1], self.segs[h + 1]);
            let (mut p, mut n) = (prev, next);
            let mut finish = size;
            p.offset(finish);
            n.offset(finish);
            if (p.ep() - n.sp()).re > 1e-2 {
                finish = -finish;
                (p, n) = (prev, next);
                p.offset(finish);
                n.offset(finish);
            }
            if (p.ep() - n.sp()).re > 1e-2 {
                return Err(format!("the corner finish at Z{:.4} X{:.4} cannot be made", prev.ep().re, prev.ep().im));
            }
            join(&mut p, &mut n)?;
            let centre = (p.ep() + n.sp()) / 2.0;
            p.offset(-finish);
            n.offset(-finish);
            let (s, e) = (p.ep(), n.sp());
            self.segs[h - 1].set_ep(s);
            self.segs[h + 1].set_sp(e);
            self.segs[h] =
                if round { Seg::Arc { ccw: (s - centre).im > 0.0 || (e - centre).im > 0.0, s, e, c: centre } } else { Seg::Line { s, e } };
        }
        self.segs.retain(|s| s.radius() >= 1e-3);
        Ok(())
    }

    /// Offsets the profile (all but its approach) by `distance` towards the stock.
    fn add_distance(&mut self, distance: f64) -> Result<(), String> {
        if self.segs.len() < 2 {
            return Err("the profile needs at least one element after its approach".into());
        }
        let first = self.segs[0];
        let last = self.segs[self.segs.len() - 1];
        let angle = (first.ep() - first.sp()) / (last.sp() - first.sp());
        let distance = if angle.im < 0.0 { -distance } else { distance };
        let approach = self.segs.remove(0);
        let mut done = 0.0;
        let mut steps = 0;
        while done != distance {
            steps += 1;
            if steps > MAX_STEPS || self.segs.is_empty() || !distance.is_finite() {
                return Err("the profile cannot be offset by the distance asked".into());
            }
            let mut step = self.segs.iter().map(|s| s.radius() / 2.0).fold(1e9, f64::min);
            step = step.min((distance - done).abs());
            if distance < 0.0 {
                step = -step;
            }
            let before = self.segs.clone();
            let mut kept = Vec::with_capacity(self.segs.len());
            for (k, s) in self.segs.iter_mut().enumerate() {
                s.offset(step);
                if s.radius() >= 1e-3 {
                    kept.push((*s, before[k]));
                }
            }
            // Between elements that moved apart, an arc about their old meeting point.
            let mut segs: Vec<Seg> = Vec::with_capacity(kept.len() * 2);
            for k in 0..kept.len() {
                segs.push(kept[k].0);
                if let Some(&(next, next_before)) = kept.get(k + 1)
                    && (kept[k].0.ep() - next.sp()).re > 1e-2
                {
                    let centre = (kept[k].1.ep() + next_before.sp()) / 2.0;
                    segs.push(Seg::Arc { ccw: distance > 0.0, s: kept[k].0.ep(), e: next.sp(), c: centre });
                }
            }
            self.segs = segs;
            let mut k = 0;
            while k + 1 < self.segs.len() {
                if !self.segs[k].monotonic() {
                    if k == 0 || self.segs[k].radius() < self.segs[k - 1].radius() {
                        self.segs.remove(k);
                    } else {
                        self.segs.remove(k - 1);
                    }
                    k = 0;
                    if self.segs.len() < 2 {
                        break;
                    }
                }
                if self.segs[k].radius() < 1e-3 {
                    self.segs.remove(k);
                    k = 0;
                } else {
                    let (a, b) = self.segs.split_at_mut(k + 1);
                    join(&mut a[k], &mut b[0])?;
                }
                k += 1;
            }
            done += step;
        }
        for k in 0..self.segs.len().saturating_sub(1) {
            let mid = (self.segs[k].ep() + self.segs[k + 1].sp()) / 2.0;
            self.segs[k].set_ep(mid);
            self.segs[k + 1].set_sp(mid);
        }
        let mut approach = approach;
        if let Some(f) = self.segs.first() {
            approach.set_ep(f.sp());
        }
        self.segs.insert(0, approach);
        Ok(())
    }

    /// G70: `passes` passes from distance `d` to `e` from the profile, from (`x`, `z`).
    pub(super) fn finish(mut self, out: &mut dyn Out, x: f64, z: f64, d: f64, e: f64, passes: i64) -> Result<(), String> {
        let Some(first) = self.segs.first_mut() else { return Err("the profile has no moves".into()) };
        first.set_sp(C::new(z, x));
        if self.should_rotate() {
            self.rotate();
        }
        self.swap();
        self.do_finish()?;
        self.monotonic()?;
        let flip = self.flip;
        let mut out = Unflip { out, flip };
        if passes > MAX_STEPS as i64 {
            return Err("too many finishing passes".into());
        }
        let mut pass = passes;
        while pass > 0 {
            let distance = (pass - 1) as f64 * (d - e) / passes as f64 + e;
            let mut path = self.clone();
            path.add_distance(distance)?;
            out.line(path.segs[0].sp(), true);
            out.line(path.segs[0].ep(), true);
            for s in &path.segs[1..] {
                s.draw(&mut out);
            }
            pass -= 1;
        }
        Ok(())
    }

    /// G71 (`facing` false) or G72: roughing from (`x`, `z`), leaving `d` to the profile and
    /// the allowances `u` (X) and `w` (Z), `depth` per pass, retracting `retract` at 45°.
    /// `pockets`: 0 all, 1 none, 2 only from the first pocket on.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn rough(
        mut self,
        out: &mut dyn Out,
        pockets: u8,
        (x, z): (f64, f64),
        (u, w): (f64, f64),
        d: f64,
        depth: f64,
        retract: f64,
        facing: bool,
    ) -> Result<(), String> {
        let Some(first) = self.segs.first_mut() else { return Err("the profile has no moves".into()) };
        first.set_sp(C::new(z, x));
        if facing {
            self.rotate();
        }
        self.swap();
        self.do_finish()?;
        self.monotonic()?;
        self.add_distance(d)?;
        let shift = C::new(w, u);
        for s in &mut self.segs {
            s.map(|p| p + shift, false);
        }
        let flip = self.flip;
        self.delta = depth.max(2.0 * TOL);
        self.escape = C::new(retract, retract);
        let mut out = Unflip { out, flip };
        let start = self.segs[0].sp();
        out.line(start, true);
        if let Some(last) = self.segs.last().copied()
            && last.ep().im < start.im
        {
            let mut to = last.ep();
            to.im = start.im;
            self.segs.push(Seg::Line { s: last.ep(), e: to });
        }
        self.pocket_starts.push(start);
        let mut steps = 0;
        self.pocket(pockets, start, 0, &mut out, &mut steps)
    }

    fn pocket(&mut self, mut pockets: u8, mut at: C, mut k: usize, out: &mut dyn Out, steps: &mut usize) -> Result<(), String> {
        let mut x = self.pocket_starts.last().map_or(at.im, |p| p.im);
        if pockets == 2 {
            while k < self.segs.len() {
                if self.segs[k].dive(&mut at, -1e9, out, k == 0)? {
                    break;
                }
                k += 1;
            }
            pockets = 3;
        }
        while k < self.segs.len() {
            *steps += 1;
            if *steps > MAX_STEPS {
                return Err("the roughing takes more passes than any profile needs".into());
            }
            while x - TOL > at.im {
                x -= self.delta;
            }
            let before = (k, at, x);
            if self.segs[k].dive(&mut at, x, out, k == 0)? {
                if pockets == 1 {
                    for s in &self.segs[k..] {
                        s.climb_only(&mut at, out);
                    }
                } else {
                    while k < self.segs.len() {
                        if self.segs[k].climb(&mut at, out)? {
                            if pockets == 3 {
                                let top = self.pocket_starts.last().map_or(f64::INFINITY, |p| p.im);
                                if at.im > top && self.pocket_starts.len() > 1 {
                                    self.pocket_starts.pop();
                                }
                                if self.pocket_starts.len() == 1 {
                                    self.pocket_starts.push(at);
                                }
                            }
                            return self.pocket(pockets, at, k, out, steps);
                        }
                        k += 1;
                    }
                }
                return Ok(());
            }
            if k + 1 == self.segs.len() {
                return Ok(());
            }
            if (at.im - x).abs() > TOL || self.segs[k].ep() == at {
                k += 1;
                continue;
            }
            let from = k;
            for j in from..self.segs.len() {
                let zs = self.segs[j].at_level(at.im);
                let (Some(&front), Some(&back)) = (zs.first(), zs.last()) else { continue };
                let to_z = if j != from { front } else { back };
                let distance = (to_z - at.re).abs();
                if to_z - TOL > at.re {
                    continue;
                }
                if distance < TOL {
                    if j == from {
                        continue;
                    }
                    if (at - self.segs[j].sp()).norm() < TOL {
                        k = j;
                    } else {
                        x -= self.delta;
                    }
                    break;
                }
                let mut to = at;
                to.re = to_z;
                out.line(to, false);
                let scale = (distance / 2.0 / self.escape.re).min(1.0);
                to += self.escape * scale;
                out.line(to, true);
                out.line(at - (self.escape * scale).conj(), true);
                out.line(at, from == 0);
                x -= self.delta;
                break;
            }
            // A step that changed nothing (a level met only where the pass starts) goes on
            // at the next level rather than round again.
            if before == (k, at, x) {
                x -= self.delta;
            }
        }
        Ok(())
    }
}

/// A profile cycle as its block gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cycle {
    kind: Meaning,
    /// 0 all pockets, 1 none, 2 from the first pocket on.
    pockets: u8,
    /// The start point: the block's X and Z, or the current point's.
    pub(super) x: f64,
    pub(super) z: f64,
    /// The axes the block states the start point in absolutely (`CanonOp::Known`).
    stated: u8,
    d: f64,
    e: f64,
    i: f64,
    p: f64,
    r: f64,
    u: f64,
    w: f64,
    label: &'static str,
}

/// The interpreter's side of the cycle's moves: each a canonical move in the ZX plane.
struct Emit<'i, 'a, 's> {
    interp: &'i mut Interpreter<'a>,
    sink: &'s mut dyn CanonSink,
    /// Whether the last move was a feed (the motion mode the cycle leaves), and its kind.
    last: Meaning,
}

impl Out for Emit<'_, '_, '_> {
    fn line(&mut self, to: C, rapid: bool) {
        let mut p = self.interp.st.pos;
        (p[0], p[2]) = (to.im, to.re);
        self.interp.emit(self.sink, if rapid { CanonOp::StraightTraverse(p) } else { CanonOp::StraightFeed(p) });
        self.interp.st.pos = p;
        self.last = if rapid { Meaning::Rapid } else { Meaning::Linear };
    }

    fn arc(&mut self, ccw: bool, centre: C, to: C) {
        let mut p = self.interp.st.pos;
        // rs274 makes no arc to where the tool already is.
        if (p[0] - to.im).abs() < 1e-4 && (p[2] - to.re).abs() < 1e-4 {
            return;
        }
        (p[0], p[2]) = (to.im, to.re);
        let op = CanonOp::ArcFeed {
            first_end: to.re,
            second_end: to.im,
            first_axis: centre.re,
            second_axis: centre.im,
            rotation: if ccw { 1 } else { -1 },
            axis_end: p[1],
            abc: [p[3], p[4], p[5]],
        };
        self.interp.emit(self.sink, op);
        self.interp.st.pos = p;
        self.last = if ccw { Meaning::ArcCcw } else { Meaning::ArcCw };
    }
}

impl Interpreter<'_> {
    /// G70, G71, G72 (LinuxCNC): checks the block and asks the flow driver for the
    /// profile subroutine named by Q.
    pub(super) fn profile_cycle(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let bad = |msg: String| Diagnostic::new(Code::BadValue, range, format!("{}: {msg}; the cycle is skipped", def.label()));
        let Some(q) = self.slot(Role::Q).filter(|q| q.is_finite() && *q >= 0.0 && *q < 1e9) else {
            return diags.push(bad("Q must name the profile's subroutine by its number".into()));
        };
        if def.meaning != Meaning::ProfileFinish && self.comp.borrow().is_some() {
            return diags.push(bad("the cycle cannot run with cutter compensation on".into()));
        }
        if self.st.plane != Plane::Xz {
            return diags.push(bad("the cycle turns in the ZX plane (G18)".into()));
        }
        let v = |s: &Self, r: Role, default: f64| s.slot(r).unwrap_or(default);
        let incremental = self.st.distance == DistanceMode::Incremental;
        let cycle = Cycle {
            kind: def.meaning,
            pockets: def.index.min(2),
            x: if incremental { self.st.pos[0] + v(self, Role::X, 0.0) } else { v(self, Role::X, self.st.pos[0]) },
            z: if incremental { self.st.pos[2] + v(self, Role::Z, 0.0) } else { v(self, Role::Z, self.st.pos[2]) },
            stated: if incremental { 0 } else { u8::from(self.slot(Role::X).is_some()) | u8::from(self.slot(Role::Z).is_some()) << 2 },
            d: v(self, Role::D, 0.0),
            e: v(self, Role::E, 0.0),
            i: v(self, Role::I, 1.0),
            p: v(self, Role::P, 1.0),
            r: v(self, Role::R, 0.5),
            u: v(self, Role::U, 0.0),
            w: v(self, Role::W, 0.0),
            label: match def.meaning {
                Meaning::ProfileFinish => "the finishing cycle",
                _ => "the roughing cycle",
            },
        };
        self.request = Some(super::Request::Profile { name: format!("{}", q.round() as u64), cycle });
    }

    /// Cuts `cycle` over the profile that `shape` (the subroutine's canon, run from the
    /// cycle's start point) draws; `corners` are the corner finishes its blocks ask for
    /// (A rounds, C chamfers), each after the canon op it follows.
    pub(super) fn profile_run(
        &mut self,
        cycle: Cycle,
        shape: &[Canon],
        corners: &[(usize, bool, f64)],
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let range = self.origin;
        // The cycle first goes to its start point.
        let mut p = self.st.pos;
        (p[0], p[2]) = (cycle.x, cycle.z);
        self.stated.set(cycle.stated);
        self.emit(sink, CanonOp::StraightTraverse(p));
        self.st.pos = p;
        let mut segs = Vec::new();
        let mut at = C::new(cycle.z, cycle.x);
        let mut corner = corners.iter().peekable();
        for (k, c) in shape.iter().enumerate() {
            let seg = match &c.op {
                CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => Seg::Line { s: at, e: C::new(p[2], p[0]) },
                CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, .. } => {
                    Seg::Arc { ccw: *rotation > 0, s: at, e: C::new(*first_end, *second_end), c: C::new(*first_axis, *second_axis) }
                }
                _ => continue,
            };
            // A block that does not move in Z or X is not part of the profile.
            if (seg.ep() - at).norm() == 0.0 {
                continue;
            }
            at = seg.ep();
            segs.push(seg);
            while let Some(&&(after, round, size)) = corner.peek() {
                if after > k + 1 {
                    break;
                }
                corner.next();
                if after == k + 1 {
                    segs.push(Seg::Corner { round, size, at });
                }
            }
        }
        if segs.len() <= 1 {
            return;
        }
        if cycle.i.is_nan() || cycle.i <= 0.0 {
            let msg = format!("{}: the depth of cut I must be greater than zero; the cycle is skipped", cycle.label);
            return diags.push(Diagnostic::new(Code::BadValue, range, msg));
        }
        let profile = Profile::new(segs);
        let mut out = Emit { interp: self, sink, last: Meaning::Linear };
        let done = match cycle.kind {
            Meaning::ProfileFinish => profile.finish(&mut out, cycle.x, cycle.z, cycle.d, cycle.e, cycle.p.trunc() as i64),
            kind => profile.rough(
                &mut out,
                cycle.pockets,
                (cycle.x, cycle.z),
                (cycle.u, cycle.w),
                cycle.d,
                cycle.i,
                cycle.r,
                kind == Meaning::ProfileRoughFace,
            ),
        };
        let last = out.last;
        // The cycle leaves the motion mode of its last move in force, as rs274's does.
        self.st.motion_code = self.dialect.codes.iter().position(|c| c.letter == 'G' && c.meaning == last);
        if let Err(why) = done {
            diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: {why}; the cycle stops here", cycle.label)));
        }
    }
}
