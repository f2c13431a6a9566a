//! Setups: the tilted working plane a workingstep runs on (`PLANE SPATIAL`, `CYCLE800`,
//! `G68.2`), as ISO 14649 places things, an `axis2_placement_3d`: an origin, an axis (the
//! tilted Z, the tool axis) and a reference direction (the tilted X), in the part's frame
//! (the untilted program coordinates, mm).
//!
//! A workingstep's toolpath, start point, depths and holes stay in its setup's coordinates,
//! as the program states them; its features are placed in the part's frame with their own
//! axis (`feature::place_on_setups`), so that holes drilled on two faces are two features and a
//! changed tilt moves them. [`Setup::angles`] tells the plane as spatial angles (about X, Y
//! and Z, the rotary axes A, B and C turn about), the terms a planner reads a tilt in.
//!
//! Door: [`Setup`].

use serde::{Deserialize, Serialize};

use crate::canon::Frame;
use crate::text::num;

/// A point in millimetres.
type P3 = [f64; 3];

/// A tilted working plane in the part's frame, mm.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    /// Origin of the plane.
    pub origin: P3,
    /// The plane's Z axis: the tool axis, unit.
    pub axis: P3,
    /// The plane's X axis, unit, square to `axis`.
    pub ref_direction: P3,
}

fn cross(a: P3, b: P3) -> P3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// A value with float noise below a nanometre taken off (and no negative zero).
fn clean(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 { 0.0 } else { r }
}

impl Setup {
    /// The setup of canon frame `f`, its origin scaled by `k` (mm per program unit).
    pub fn of_frame(f: &Frame, k: f64) -> Setup {
        let col = |j: usize| [0, 1, 2].map(|i| clean(f.rotation[i][j]));
        Setup { origin: f.origin.map(|v| clean(v * k)), axis: col(2), ref_direction: col(0) }
    }

    /// The plane's Y axis.
    pub fn y(&self) -> P3 {
        cross(self.axis, self.ref_direction)
    }

    /// Point `p` of the plane (its own coordinates) in the part's frame.
    pub fn to_part(&self, p: P3) -> P3 {
        let (x, y, z) = (self.ref_direction, self.y(), self.axis);
        [0, 1, 2].map(|i| clean(self.origin[i] + x[i] * p[0] + y[i] * p[1] + z[i] * p[2]))
    }

    /// Point `q` of the part's frame in the plane's own coordinates.
    pub fn from_part(&self, q: P3) -> P3 {
        let d = [q[0] - self.origin[0], q[1] - self.origin[1], q[2] - self.origin[2]];
        let dot = |v: P3| clean(v[0] * d[0] + v[1] * d[1] + v[2] * d[2]);
        [dot(self.ref_direction), dot(self.y()), dot(self.axis)]
    }

    /// Point `p` in the coordinates of setup `from` (none: the part's frame) carried into
    /// those of setup `to`.
    pub fn carry(p: P3, from: Option<&Setup>, to: Option<&Setup>) -> P3 {
        let q = from.map_or(p, |s| s.to_part(p));
        to.map_or(q, |s| s.from_part(q))
    }

    /// The tilt in words: `30° about A` where it turns about one axis, else each angle
    /// (`A20° B35° C-70°`); `untilted` for none.
    pub fn tilt_words(setup: Option<&Setup>) -> String {
        let Some(s) = setup else { return "untilted".to_owned() };
        let a = s.angles();
        let turned: Vec<usize> = (0..3).filter(|&i| a[i] != 0.0).collect();
        match turned.as_slice() {
            [] => "untilted".to_owned(),
            [i] => format!("tilted {}° about {}", num(a[*i]), ["A", "B", "C"][*i]),
            _ => format!("tilted A{}° B{}° C{}°", num(a[0]), num(a[1]), num(a[2])),
        }
    }

    /// The plane in words: its tilt, origin and tool axis.
    pub fn words(&self) -> String {
        let (o, z) = (self.origin, self.axis);
        format!(
            "work plane {}, origin X{} Y{} Z{}, tool axis I{} J{} K{}",
            Setup::tilt_words(Some(self)),
            num(o[0]),
            num(o[1]),
            num(o[2]),
            num(z[0]),
            num(z[1]),
            num(z[2])
        )
    }

    /// The plane as spatial angles, degrees: about X (A), then Y (B), then Z (C), each about
    /// the part's fixed axes, each in (-180, 180]; B in [-90, 90], and A 0 where B is ±90°.
    pub fn angles(&self) -> [f64; 3] {
        let (x, y, z) = (self.ref_direction, self.y(), self.axis);
        // Rows of R = [x y z] (columns): r[i][j].
        let r = |i: usize, j: usize| [x, y, z][j][i];
        let b = (-r(2, 0)).clamp(-1.0, 1.0).asin();
        let (a, c) = if b.cos().abs() > 1e-9 {
            (r(2, 1).atan2(r(2, 2)), r(1, 0).atan2(r(0, 0)))
        } else {
            // Square to Z (B ±90°) only C - A or C + A shows: told as C, the turn about the
            // spindle or table axis (a mill-turn's B head at 90°, its C at the hole).
            (0.0, (-r(0, 1)).atan2(r(1, 1)))
        };
        [a, b, c].map(|v| {
            let d = clean((v.to_degrees() * 1e6).round() / 1e6);
            if d <= -180.0 { d + 360.0 } else { d }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spatial(a: f64, b: f64, c: f64) -> Setup {
        let rot = |axis: usize, deg: f64| {
            let (s, co) = f64::to_radians(deg).sin_cos();
            match axis {
                0 => [[1.0, 0.0, 0.0], [0.0, co, -s], [0.0, s, co]],
                1 => [[co, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, co]],
                _ => [[co, -s, 0.0], [s, co, 0.0], [0.0, 0.0, 1.0]],
            }
        };
        let f0 = Frame { origin: [0.0; 3], rotation: rot(2, c) };
        let f = f0.then(&Frame { origin: [0.0; 3], rotation: rot(1, b) }).then(&Frame { origin: [0.0; 3], rotation: rot(0, a) });
        Setup::of_frame(&f, 1.0)
    }

    #[test]
    fn spatial_angles_come_back() {
        for (a, b, c) in [
            (30.0, 0.0, 0.0),
            (0.0, -45.0, 0.0),
            (-90.0, 0.0, 75.0),
            (20.0, 35.0, -70.0),
            (0.0, 90.0, 0.0),
            (0.0, 90.0, 180.0),
            (0.0, -90.0, 30.0),
        ] {
            let got = spatial(a, b, c).angles();
            assert!((got[0] - a).abs() < 1e-6 && (got[1] - b).abs() < 1e-6 && (got[2] - c).abs() < 1e-6, "{a} {b} {c}: {got:?}");
        }
    }

    #[test]
    fn points_go_onto_the_plane() {
        // Tilted 90° about Y: the plane's X points down, its Z along +X.
        let s = Setup { origin: [100.0, 0.0, -20.0], axis: [1.0, 0.0, 0.0], ref_direction: [0.0, 0.0, -1.0] };
        assert_eq!(s.to_part([5.0, 10.0, 0.0]), [100.0, 10.0, -25.0]);
        assert_eq!(s.to_part([0.0, 0.0, -8.0]), [92.0, 0.0, -20.0]);
    }
}
