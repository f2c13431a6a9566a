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
    /// Where the plane is the developed surface of a cylinder (cylindrical interpolation:
    /// Fanuc `G07.1`, Siemens `TRACYL`), the cylinder's diameter, mm: the plane is laid
    /// tangent to it where `axis` points, its X along the cylinder's axis, and its Y is the
    /// length round the cylinder at that diameter (`Setup::wrapped_at`).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub cylinder: Option<f64>,
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
        Setup { origin: f.origin.map(|v| clean(v * k)), axis: col(2), ref_direction: col(0), cylinder: None }
    }

    /// On the developed surface of a cylinder (`cylinder`), the plane laid tangent where the
    /// length `along` its Y (from where it is laid now) wraps to: turned about the cylinder's
    /// axis (the plane's X) by `along` over the radius, as the control maps the developed
    /// length to the angle of C (Fanuc 0i-TF / 30i operator's manual, cylindrical
    /// interpolation: the length round the cylinder is the radius times the angle; SINUMERIK
    /// 840D sl job planning, `TRACYL`: Y on the developed surface). The plane itself where it
    /// is no cylinder's.
    pub fn wrapped_at(&self, along: f64) -> Setup {
        let Some(d) = self.cylinder.filter(|d| *d > 1e-9) else { return *self };
        let (s, c) = (2.0 * along / d).sin_cos();
        let (z, y) = (self.axis, self.y());
        Setup { axis: [0, 1, 2].map(|i| clean(z[i] * c + y[i] * s)), ..*self }
    }

    /// On the developed surface of a cylinder, the angle (degrees, about the cylinder's axis,
    /// as C turns) the plane's radial axis stands at, `along` its Y from where it is laid:
    /// about the part's Z, the C axis of a lathe whose spindle is Z; to 0.0001°.
    pub fn wrap_angle(&self, along: f64) -> f64 {
        let a = self.wrapped_at(along).axis;
        // To 0.0001°: the plan's lengths are kept to a micrometre.
        let d = clean((a[1].atan2(a[0]).to_degrees().rem_euclid(360.0) * 1e4).round() / 1e4);
        if d >= 360.0 { 0.0 } else { d }
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
        let wrap = self.cylinder.map_or_else(String::new, |d| format!(", the developed surface of the Ø{} cylinder", num(d)));
        format!(
            "work plane {}, origin X{} Y{} Z{}, tool axis I{} J{} K{}{wrap}",
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
        let s = Setup { origin: [100.0, 0.0, -20.0], axis: [1.0, 0.0, 0.0], ref_direction: [0.0, 0.0, -1.0], cylinder: None };
        assert_eq!(s.to_part([5.0, 10.0, 0.0]), [100.0, 10.0, -25.0]);
        assert_eq!(s.to_part([0.0, 0.0, -8.0]), [92.0, 0.0, -20.0]);
    }

    /// The developed surface of the Ø50 cylinder laid tangent at C0 (radial axis +X, its X
    /// along -Z, its Y the way C turns): a quarter of the circumference, 25·π/2 along Y,
    /// wraps to C90, where the radial axis is +Y; half of it to C180 (-X). Written before the
    /// run (the developed length is the radius times the angle).
    #[test]
    fn the_developed_surface_wraps_round_its_cylinder() {
        let s = Setup { origin: [0.0; 3], axis: [1.0, 0.0, 0.0], ref_direction: [0.0, 0.0, -1.0], cylinder: Some(50.0) };
        let quarter = 25.0 * std::f64::consts::FRAC_PI_2;
        let q = s.wrapped_at(quarter);
        assert_eq!((q.axis, q.ref_direction, q.cylinder), ([0.0, 1.0, 0.0], [0.0, 0.0, -1.0], Some(50.0)));
        assert_eq!(q.to_part([10.0, 0.0, 23.0]), [0.0, 23.0, -10.0]);
        assert_eq!(s.wrapped_at(2.0 * quarter).axis, [-1.0, 0.0, 0.0]);
        assert_eq!((s.wrap_angle(quarter), s.wrap_angle(-quarter), s.wrap_angle(0.0)), (90.0, 270.0, 0.0));
        // A plane of no cylinder does not turn.
        let flat = Setup { cylinder: None, ..s };
        assert_eq!(flat.wrapped_at(quarter), flat);
    }
}
