//! The tilted working plane: Heidenhain `PLANE SPATIAL`/`EULER`/`VECTOR`/`RELATIV`/`RESET`,
//! Siemens `CYCLE800`, Fanuc `G68.2` (cancelled by G69). The control turns its coordinate
//! system; the program's coordinates after it are in the tilted plane, which is how the canon
//! keeps them. What the plan needs to place them on the part is the [`Frame`] in force,
//! passed on as a `WorkPlane` marker whenever it changes; the interpreter's position is
//! carried over into the new plane's coordinates (the tool stays where it is on the part).
//!
//! How the angles turn the plane, as the controls document it:
//! - spatial angles (`tilt-spatial`): about the fixed X by A, then the fixed Y by B, then the
//!   fixed Z by C: `Rz(C)·Ry(B)·Rx(A)`;
//! - Euler angles (`tilt-euler`): about Z by A, then the turned X by B, then the turned Z by
//!   C: `Rz(A)·Rx(B)·Rz(C)` (Fanuc `G68.2 I J K`, Heidenhain `EULPR EULNU EULROT`);
//! - a base and a normal vector (`tilt-vector`): the new X and the new Z (the tool axis);
//! - a relative angle (`tilt-relative`): about the tilted plane's own X, Y or Z;
//! - Siemens `ROT`/`AROT` about X or Y (`frame-rot`, `frame-rot-add`): the programmable frame
//!   turned in space, about Z, the turned Y and the turned X ([`Interpreter::frame_rotation_in_space`]);
//! - a swivel cycle (`tilt-cycle`, `CYCLE800`): axis by axis in the mode's order, each
//!   about the turned axes, about the reference point `_X0 _Y0 _Z0`, the zero point then
//!   shifted to `_X1 _Y1 _Z1` on the tilted plane; on the plane in force where `_ST`'s units
//!   digit is 1 (additive) [from the cycle's documented `_ST` coding, unconfirmed on a control]; in solid-angle mode (bits 7-6 01) about Z
//!   by `_A`, then about the turned Y by `_B` [the order from public CYCLE800 descriptions,
//!   unconfirmed on a control]; in projection-angle mode (bits 7-6 10) with the axes X and Y
//!   in either order (`_MODE` 185: X, Y, Z), the angles about X and Y projected as `PLANE
//!   PROJECTED` reads them (the new X in the old ZX plane, as the SINUMERIK Operate manual
//!   says of the XY and YX positions), then a turn about the new Z by the third angle. Its
//!   other modes (projection angles about Z, rotary axes direct without the machine's
//!   `swivel_axes`) need what the analysis does not have: said, and the plane stays as it was;
//! - three points (`tilt-points`, `PLANE POINTS`): the first to the second is the new X, the
//!   third on the new +Y side;
//! - projection angles (`tilt-projected`, `PLANE PROJECTED`): the plane's traces in the ZX
//!   and YZ planes, each angle the right-hand turn about the axis square to its plane;
//! - the rotary axes' positions (`tilt-axial` `PLANE AXIAL`, `tilt-tool-axis` `G68.3`): read
//!   as tool centre point control reads them, said in a note;
//! - Euler angles on the plane in force (`tilt-euler-incremental`, `G68.4`);
//! - roll-pitch-yaw (`tilt-roll-pitch-yaw`, `G68.2 P1`, the code's form chosen by its `P`
//!   word, the dictionary's `tilt-forms`): about X by A, then the turned Y by B, then the turned
//!   Z by C: `Rx(A)·Ry(B)·Rz(C)` [LinuxCNC's G68.2 remap's reading of the default order Q123;
//!   unconfirmed against Fanuc's manual]; its `Q` word the order (`Q321`), I J K staying the
//!   angles about X, Y and Z as Mazak's G68.2 P1 page documents them;
//! - three points block by block (`tilt-three-points`, `G68.2 P2 Q0..Q3`) and two vectors
//!   (`tilt-two-vectors`, `G68.2 P3 Q1 Q2`): the blocks' words kept ([`TiltSteps`]) until the
//!   one completing the plane, which puts it in force;
//! - projection angles named by their axes (`tilt-projection-angles`, `G68.2 P4 I J K`): as
//!   `tilt-projected` with the angles about X and Y swapped into its order.
//!
//! Tool centre point control switched off leaves the tool where the rotary axes stand: on a
//! mill without a tilted plane its axis is the one they index it to.
//!
//! Tool centre point control (`M128`, `TRAORI`, `G43.4`) is here too: under it, the rotary
//! axes' positions turn the tool axis, sent as `ToolAxis` markers.
//!
//! Doors: [`Interpreter::tilt_code`], [`Interpreter::tilt_cycle`], [`Interpreter::tilt_by_axis_words`]
//! (legacy cycle 19), [`Interpreter::untilt`], [`Interpreter::tcp`], [`Interpreter::rotary_tool_axis`].

use crate::canon::{CanonOp, CanonSink, Frame};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::Interpreter;
use crate::syntax::Block;
use crate::text::TextRange;

/// A rotation by `deg` degrees about axis `axis` (0 X, 1 Y, 2 Z).
fn rot(axis: usize, deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    let (s, c) = (snap(s), snap(c));
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// `v` with the float noise of a right angle's sine or cosine taken off.
fn snap(v: f64) -> f64 {
    if v.abs() < 1e-15 { 0.0 } else { v }
}

fn mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Rotations about axes `axes` by `deg`, each about the axes the ones before turned.
fn chain(axes: [usize; 3], deg: [f64; 3]) -> [[f64; 3]; 3] {
    mul(mul(rot(axes[0], deg[0]), rot(axes[1], deg[1])), rot(axes[2], deg[2]))
}

fn norm(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (l > 1e-9 && l.is_finite()).then(|| v.map(|x| x / l))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The rotation whose X is `base` (made square to `normal`) and whose Z is `normal`.
fn by_vectors(base: [f64; 3], normal: [f64; 3]) -> Option<[[f64; 3]; 3]> {
    let z = norm(normal)?;
    let d = base[0] * z[0] + base[1] * z[1] + base[2] * z[2];
    let x = norm([base[0] - d * z[0], base[1] - d * z[1], base[2] - d * z[2]])?;
    let y = cross(z, x);
    Some(std::array::from_fn(|i| [x[i], y[i], z[i]]))
}

/// The plane of projection angles `a` (its trace in the ZX plane, from X) and `b` (its trace
/// in the YZ plane, from Y), each the right-hand turn about the axis square to its plane (so
/// that one alone tilts as the spatial angle about that axis): its X along the first trace.
fn projected(a: f64, b: f64) -> Option<[[f64; 3]; 3]> {
    let (sa, ca) = a.to_radians().sin_cos();
    let (sb, cb) = b.to_radians().sin_cos();
    let u = [ca, 0.0, -sa];
    let v = [0.0, cb, sb];
    by_vectors(u, cross(u, v))
}

/// The `NAME±number` words of a keyword's unread rest of line (`SPA+30 SPB+0 TURN FMAX`):
/// each name with its number; words without a number (`TURN`, `SEQ+`) are passed over.
fn line_numbers(rest: &str) -> Vec<(&str, Option<f64>)> {
    let mut out = Vec::new();
    let b = rest.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if !b[i].is_ascii_alphabetic() {
            i += 1;
            continue;
        }
        let start = i;
        loop {
            while i < b.len() && b[i].is_ascii_alphabetic() {
                i += 1;
            }
            // Digits followed by a letter belong to the name (`P1X+0` of PLANE POINTS).
            let mut j = i;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if j == i || j >= b.len() || !b[j].is_ascii_alphabetic() {
                break;
            }
            i = j;
        }
        let name = &rest[start..i];
        let num_start = i;
        while i < b.len() && (b[i].is_ascii_digit() || matches!(b[i], b'+' | b'-' | b'.')) {
            i += 1;
        }
        let text = &rest[num_start..i];
        if text.bytes().any(|c| c.is_ascii_digit()) {
            out.push((name, text.parse::<f64>().ok()));
        } else if i < b.len() && b[i].is_ascii_alphabetic() && !text.is_empty() {
            // A parameter or expression in place of the number (`SPA+Q1`): no value.
            out.push((name, None));
            while i < b.len() && b[i].is_ascii_alphanumeric() {
                i += 1;
            }
        }
    }
    out
}

/// The rotation order word of roll-pitch-yaw angles (Fanuc `G68.2 P1 Q123`, default 123): the
/// axes (0 X, 1 Y, 2 Z) in the order turned, each once; `None` for another number.
fn rotation_order(q: Option<f64>) -> Option<[usize; 3]> {
    let q = q.unwrap_or(123.0);
    if q.fract() != 0.0 || !(123.0..=321.0).contains(&q) {
        return None;
    }
    let q = q as usize;
    let axes = [q / 100, q / 10 % 10, q % 10];
    let mut seen = [false; 3];
    for &a in &axes {
        if !(1..=3).contains(&a) || std::mem::replace(&mut seen[a - 1], true) {
            return None;
        }
    }
    Some(axes.map(|a| a - 1))
}

/// What the blocks of a tilted plane stated over several have given so far: by its `Q`
/// number, a point (`X Y Z`) and a direction (`I J K`).
#[derive(Clone, Debug, PartialEq)]
pub(in crate::interp) struct TiltSteps {
    form: Meaning,
    given: [Option<([f64; 3], [f64; 3])>; 4],
    /// The turn about the plane's Z (`R`).
    turn: f64,
}

impl Interpreter<'_> {
    /// The value the code gives role `role`: a word of its unread rest of line
    /// (`line-words`), a word its `args` map to the role, or the block's word of that role.
    fn tilt_value(&self, def: &CodeDef, rest: &[(&str, Option<f64>)], role: Role) -> Option<f64> {
        if !def.line_words.is_empty() {
            return rest.iter().find(|(n, _)| def.line_word(n) == Some(role)).and_then(|&(_, v)| v);
        }
        match def.args.iter().find(|(_, to)| *to == role) {
            Some(&(from, _)) => self.slot(from),
            None => self.slot(role),
        }
    }

    /// A tilted-plane code (`PLANE …`, `G68.2`): the frame it states, put in force.
    pub(super) fn tilt_code(
        &mut self,
        def: &CodeDef,
        range: TextRange,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let rest_text = block.text(TextRange { start: range.end, end: block.range.end });
        let rest = line_numbers(rest_text);
        if let Some((name, _)) = rest.iter().find(|(n, v)| v.is_none() && def.line_word(n).is_some()) {
            let msg = format!("{}: the value of {name} is not a number the analysis can read; the plane in force stays", def.label());
            diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
            return;
        }
        let Some(meaning) = self.tilt_form(def, range, diags) else { return };
        let get = |s: &Self, r: Role| s.tilt_value(def, &rest, r);
        let angles = |s: &Self| [Role::TiltA, Role::TiltB, Role::TiltC].map(|r| get(s, r).unwrap_or(0.0));
        let origin = |s: &Self| [Role::TiltOriginX, Role::TiltOriginY, Role::TiltOriginZ].map(|r| get(s, r).unwrap_or(0.0));
        let frame = match meaning {
            Meaning::TiltReset => None,
            Meaning::TiltSpatial => {
                let [a, b, c] = angles(self);
                Some(Frame { origin: origin(self), rotation: chain([2, 1, 0], [c, b, a]) })
            }
            Meaning::TiltEuler => Some(Frame { origin: origin(self), rotation: chain([2, 0, 2], angles(self)) }),
            Meaning::TiltRollPitchYaw => {
                let Some(axes) = rotation_order(get(self, Role::TiltMode)) else {
                    let msg =
                        format!("{}: a rotation order the analysis does not know (Q123 to Q321); the plane in force stays", def.label());
                    diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                    return;
                };
                let by_axis = angles(self);
                Some(Frame { origin: origin(self), rotation: chain(axes, axes.map(|a| by_axis[a])) })
            }
            Meaning::TiltProjectionAngles => {
                let [about_x, about_y, turn] = angles(self);
                let Some(rotation) = projected(about_y, about_x) else {
                    let msg = format!("{}: the projection angles give no plane; the plane in force stays", def.label());
                    diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                    return;
                };
                Some(Frame { origin: origin(self), rotation: mul(rotation, rot(2, turn)) })
            }
            Meaning::TiltThreePoints | Meaning::TiltTwoVectors => {
                let given = |s: &Self, rs: [Role; 3]| {
                    let v = rs.map(|r| get(s, r));
                    v.iter().any(Option::is_some).then(|| v.map(|x| x.unwrap_or(0.0)))
                };
                let step = get(self, Role::TiltMode).unwrap_or(0.0);
                let at = given(self, [Role::TiltOriginX, Role::TiltOriginY, Role::TiltOriginZ]);
                let dir = given(self, [Role::TiltA, Role::TiltB, Role::TiltC]);
                let turn = get(self, Role::TiltTurn);
                match self.tilt_step(meaning, step, at, dir, turn) {
                    Ok(Some(frame)) => Some(frame),
                    Ok(None) => return,
                    Err(why) => {
                        let msg = format!("{} Q{step}: {why}; the plane in force stays", def.label());
                        diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                        return;
                    }
                }
            }
            Meaning::TiltVector => {
                let base = [Role::TiltBaseX, Role::TiltBaseY, Role::TiltBaseZ].map(|r| get(self, r).unwrap_or(0.0));
                let normal = [Role::ToolAxisI, Role::ToolAxisJ, Role::ToolAxisK].map(|r| get(self, r).unwrap_or(0.0));
                match by_vectors(base, normal) {
                    Some(rotation) => Some(Frame { origin: origin(self), rotation }),
                    None => {
                        let msg = format!("{}: the base and normal vectors are zero or parallel; the plane in force stays", def.label());
                        diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                        return;
                    }
                }
            }
            Meaning::TiltRelative => {
                let now = self.st.frame.unwrap_or(Frame::IDENTITY);
                let turn = [Role::TiltA, Role::TiltB, Role::TiltC].iter().enumerate().find_map(|(k, &r)| get(self, r).map(|v| (k, v)));
                let Some((axis, deg)) = turn else { return };
                Some(now.then(&Frame { origin: [0.0; 3], rotation: rot(axis, deg) }))
            }
            Meaning::TiltEulerIncremental => {
                let now = self.st.frame.unwrap_or(Frame::IDENTITY);
                Some(now.then(&Frame { origin: origin(self), rotation: chain([2, 0, 2], angles(self)) }))
            }
            Meaning::TiltPoints | Meaning::TiltProjected => {
                let v = |s: &Self, rs: [Role; 3]| rs.map(|r| get(s, r).unwrap_or(0.0));
                let vectors = if def.meaning == Meaning::TiltPoints {
                    let p1 = v(self, [Role::TiltP1X, Role::TiltP1Y, Role::TiltP1Z]);
                    let p2 = v(self, [Role::TiltP2X, Role::TiltP2Y, Role::TiltP2Z]);
                    let p3 = v(self, [Role::TiltP3X, Role::TiltP3Y, Role::TiltP3Z]);
                    let x = std::array::from_fn(|i| p2[i] - p1[i]);
                    let y = std::array::from_fn(|i| p3[i] - p1[i]);
                    by_vectors(x, cross(x, y)).map(|r| (r, 0.0))
                } else {
                    let [a, b, c] = angles(self);
                    projected(a, b).map(|r| (r, c))
                };
                let Some((rotation, turn)) = vectors else {
                    let msg = format!("{}: the points or angles give no plane; the plane in force stays", def.label());
                    diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                    return;
                };
                Some(Frame { origin: [0.0; 3], rotation: mul(rotation, rot(2, turn)) })
            }
            Meaning::TiltAxial | Meaning::TiltToolAxis => {
                let axes = self.rotary_rotation();
                self.kinematics_note(diags, "the tilted working plane", "plane-kinematics");
                if def.meaning == Meaning::TiltAxial {
                    let [a, b, c] = angles(self);
                    Some(Frame { origin: [0.0; 3], rotation: chain([2, 1, 0], [c, b, a]) })
                } else {
                    let turn = get(self, Role::TiltC).unwrap_or(0.0);
                    Some(Frame { origin: origin(self), rotation: mul(axes, rot(2, turn)) })
                }
            }
            _ => return,
        };
        // A plane from the one in force (relative angles, G68.4) already stands on its datum.
        let frame = if matches!(meaning, Meaning::TiltRelative | Meaning::TiltEulerIncremental) { frame } else { self.on_datum(frame) };
        self.plane_retract(rest_text, range, sink, diags);
        self.set_frame(frame, sink);
    }

    /// Heidenhain `PLANE … TURN MB …` (TNC 640 user's manual, "Tilting the working plane",
    /// retraction MB): before the rotary axes turn, the tool retracts along the tool axis in
    /// force, `MB MAX` to just before its travel limit (as `M140 MB MAX`: a move in the
    /// machine's frame, the axis unknown after it), `MB n` by n (incremental, away from the
    /// part). An `MB n` from a tool-axis position the program does not know goes where the
    /// analysis cannot say: a motion it does not know.
    fn plane_retract(&mut self, rest: &str, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let words: Vec<&str> = rest.split_whitespace().collect();
        let Some(at) = words.iter().position(|w| w.starts_with("MB")) else { return };
        let value = match &words[at][2..] {
            "" => words.get(at + 1).copied().unwrap_or(""),
            v => v,
        };
        if value == "MAX" {
            self.travel_limit(sink);
            return;
        }
        let Ok(by) = value.parse::<f64>() else {
            let msg = format!(
                "the retract `MB {value}` before the plane turns is not a number the analysis can read: where it goes is not known"
            );
            return diags.push(Diagnostic::new(Code::MotionUnknown, range, msg));
        };
        let (_, _, n) = self.st.plane.axes();
        if by == 0.0 {
            return;
        }
        if !self.knows(n) {
            let msg = format!("the retract `MB {value}` before the plane turns goes from a tool-axis position the program does not know");
            return diags.push(Diagnostic::new(Code::MotionUnknown, range, msg));
        }
        let mut p = self.st.pos;
        p[n] += by;
        self.emit(sink, CanonOp::StraightTraverse(p));
        self.st.pos = p;
    }

    /// A plane stated in the coordinates in force: turned about the datum a local shift moved
    /// the program zero to (Heidenhain `CYCL DEF 7`, `TRANS DATUM`, G52), as the TNC tilts
    /// about the active datum (a datum shift first, then the plane: the TNC 640 manual's
    /// order); its origin is then that datum's and the program's coordinates on it are the
    /// plane's. An untilted plane stays untilted.
    fn on_datum(&self, frame: Option<Frame>) -> Option<Frame> {
        let shift = [self.st.g92[0], self.st.g92[1], self.st.g92[2]];
        frame.filter(|f| !f.is_identity()).map(|f| Frame { origin: std::array::from_fn(|i| f.origin[i] + shift[i]), rotation: f.rotation })
    }

    /// One block of a tilted plane stated over several (Fanuc `G68.2 P2 Q0..Q3`, `G68.2 P3
    /// Q1 Q2`): its words kept; the frame once the block completing it comes, `None` before.
    /// A block out of the form's order, or of another form, starts it again (said).
    fn tilt_step(
        &mut self,
        form: Meaning,
        step: f64,
        at: Option<[f64; 3]>,
        dir: Option<[f64; 3]>,
        turn: Option<f64>,
    ) -> Result<Option<Frame>, String> {
        let three = form == Meaning::TiltThreePoints;
        let last: u8 = if three { 3 } else { 2 };
        let first: u8 = if three { 0 } else { 1 };
        if step.fract() != 0.0 || step < f64::from(first) || step > f64::from(last) {
            self.st.tilt_steps = None;
            return Err(format!("not a block of this form (Q{first} to Q{last})"));
        }
        let step = step as usize;
        let steps = self.st.tilt_steps.get_or_insert_with(|| Box::new(TiltSteps { form, given: [None; 4], turn: 0.0 }));
        if steps.form != form {
            **steps = TiltSteps { form, given: [None; 4], turn: 0.0 };
        }
        steps.given[step] = Some((at.unwrap_or([0.0; 3]), dir.unwrap_or([0.0; 3])));
        if let Some(turn) = turn {
            steps.turn = turn;
        }
        if step != usize::from(last) {
            return Ok(None);
        }
        let steps = self.st.tilt_steps.take().expect("kept above");
        let g = steps.given;
        if three {
            let (Some((p1, _)), Some((p2, _)), Some((p3, _))) = (g[1], g[2], g[3]) else {
                return Err("the first or second point was not given before the third".into());
            };
            let x = std::array::from_fn(|i| p2[i] - p1[i]);
            let y = std::array::from_fn(|i| p3[i] - p1[i]);
            let rotation = by_vectors(x, cross(x, y)).ok_or("the three points lie on a line")?;
            // The origin: Q0's where given, else the first point.
            let origin = g[0].map_or(p1, |(o, _)| o);
            Ok(Some(Frame { origin, rotation: mul(rotation, rot(2, steps.turn)) }))
        } else {
            let Some((origin, x)) = g[1] else { return Err("the X direction (Q1) was not given before the Z direction".into()) };
            let (_, z) = g[2].expect("this block");
            let rotation = by_vectors(x, z).ok_or("the X and Z directions are zero or parallel")?;
            Ok(Some(Frame { origin, rotation }))
        }
    }

    /// The meaning the block's form word gives a tilted-plane code (`G68.2 P1`: roll-pitch-yaw,
    /// the dictionary's `tilt-forms`): the code's own without the word or with 0; `None`, said,
    /// for a form the dictionary does not list (`G68.2 P2` three points over several blocks),
    /// the plane in force staying.
    fn tilt_form(&self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<Meaning> {
        let Some(&(letter, _, _)) = def.tilt_forms.first() else { return Some(def.meaning) };
        let name = letter.to_string();
        let role = self.dialect.addresses.iter().find(|a| a.name == name).map(|a| a.role);
        let Some(v) = role.and_then(|r| self.slot(r)) else { return Some(def.meaning) };
        match def.tilt_forms.iter().find(|&&(l, n, _)| l == letter && f64::from(n) == v) {
            Some(&(_, _, m)) => Some(m),
            None if v == 0.0 => Some(def.meaning),
            None => {
                let msg = format!(
                    "{} {letter}{v}: a form of the tilted plane the analysis does not model; the plane in force stays",
                    def.label()
                );
                diags.push(Diagnostic::new(Code::TiltUnknown, range, msg));
                None
            }
        }
    }

    /// A legacy tilting cycle's block with angles (`CYCL DEF 19.1 A+0 B+45 C+0`): spatial
    /// angles about X, Y and Z from its A, B and C words; all zero untilts. A block without
    /// them (`CYCL DEF 19.0 WORKING PLANE`) changes nothing.
    pub(in crate::interp) fn tilt_by_axis_words(&mut self, sink: &mut dyn CanonSink) {
        let given = [Role::A, Role::B, Role::C].map(|r| self.slot(r));
        if given.iter().all(Option::is_none) {
            return;
        }
        let [a, b, c] = given.map(|v| v.unwrap_or(0.0));
        let frame = self.on_datum(Some(Frame { origin: [0.0; 3], rotation: chain([2, 1, 0], [c, b, a]) }));
        self.set_frame(frame, sink);
    }

    /// A swivel cycle (`CYCLE800(_FR, _TC, _ST, _MODE, _X0, …)`) with its arguments; without
    /// any, it cancels the swivelled plane.
    pub(in crate::interp) fn tilt_cycle(
        &mut self,
        args: &[(Role, f64)],
        range: TextRange,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let get = |r: Role| args.iter().find(|(a, _)| *a == r).map(|(_, v)| *v);
        // `_FR` other than 0: the control retracts (along Z, then X/Y, or along the tool axis
        // by `_FR_I` or to the travel limit) before it swivels. Not modelled: the toolpath
        // after it is not known, and a translation refuses rather than swivel without it.
        if let Some(fr) = get(Role::RetractDistance).filter(|&fr| fr != 0.0) {
            let msg = format!(
                "`CYCLE800` with retract mode _FR={fr} (a retract before the swivel, to the machine's retract position or along the tool axis) moves the machine, and ncplan does not model that retract: the toolpath after it is not known"
            );
            self.limited(diags, "motion-unknown", Diagnostic::new(Code::MotionUnknown, range, msg));
        }
        let angles = [Role::TiltA, Role::TiltB, Role::TiltC].map(|r| get(r).unwrap_or(0.0));
        let Some(mode) = get(Role::TiltMode) else {
            if angles.iter().all(|&a| a == 0.0) {
                self.set_frame(None, sink);
            }
            return;
        };
        let mode = mode as u32;
        let axes = [mode & 3, (mode >> 2) & 3, (mode >> 4) & 3];
        // Rotary axes direct (mode bits 7-6 = 11): `_A` and `_B` position the machine's first
        // and second swivel axes, which its configuration names (`swivel_axes`); the plane is
        // where they turn the tool, read as tool centre point control reads the rotary axes.
        let direct = self.dialect.behaviour.swivel_axes.filter(|_| mode >> 6 == 3).map(|named| {
            let mut abc = [0.0; 3];
            for (k, letter) in named.iter().enumerate() {
                abc[usize::from(letter - b'A')] = angles[k];
            }
            chain([2, 1, 0], [abc[2], abc[1], abc[0]])
        });
        let rotation = match (mode >> 6, direct) {
            (_, Some(r)) => {
                self.kinematics_note(diags, "CYCLE800's plane in rotary axes direct mode", "tilt-direct");
                r
            }
            // Solid angle: about Z by the first angle, then about the turned Y by the second.
            (1, None) => chain([2, 1, 2], [angles[0], angles[1], 0.0]),
            // Projection angles about X and Y (either order), then a turn about the new Z.
            (2, None) if matches!(axes, [1, 2, 3 | 0] | [2, 1, 3 | 0]) => {
                let about = |axis: u32| angles[if axes[0] == axis { 0 } else { 1 }];
                match projected(about(2), about(1)) {
                    Some(r) => mul(r, rot(2, angles[2])),
                    None => {
                        let msg = format!("swivel mode {mode}: the projection angles give no plane; the plane in force stays");
                        self.limited(diags, "tilt-mode", Diagnostic::new(Code::TiltUnknown, range, msg));
                        return;
                    }
                }
            }
            (0, None) if !axes.contains(&0) => chain(axes.map(|a| a as usize - 1), angles),
            _ => {
                let msg = match mode >> 6 {
                    2 => format!(
                        "swivel mode {mode}: projection angles about other axes than X and Y (the G18 and G19 positions) are not modelled; the plane in force stays, so what is cut after it is placed on that plane, which may not be the face the machine turns to"
                    ),
                    _ => format!(
                        "swivel mode {mode} (rotary axes direct, or no axes named) needs the machine's kinematics (rotary axes direct: the machine's `swivel_axes` in its configuration); the plane in force stays, so what is cut after it is placed on that plane, which may not be the face the machine turns to"
                    ),
                };
                self.limited(diags, "tilt-mode", Diagnostic::new(Code::TiltUnknown, range, msg));
                return;
            }
        };
        let pivot = [Role::TiltOriginX, Role::TiltOriginY, Role::TiltOriginZ].map(|r| get(r).unwrap_or(0.0));
        let shift = [Role::TiltShiftX, Role::TiltShiftY, Role::TiltShiftZ].map(|r| get(r).unwrap_or(0.0));
        let turned = Frame { origin: pivot, rotation };
        let frame = Frame { origin: turned.to_base(shift), rotation };
        // `_ST` units digit 1: additive, on the swivelled plane in force.
        let additive = get(Role::TiltSwivel).is_some_and(|st| (st.abs() as u64) % 10 == 1);
        let frame = match self.st.frame {
            Some(now) if additive => now.then(&frame),
            _ => frame,
        };
        self.set_frame(Some(frame), sink);
    }

    /// Tool centre point control on or off. On, the rotary axes' positions give the tool axis
    /// (see [`Interpreter::rotary_tool_axis`]). Off, the rotary axes stay where they stand and
    /// the tool with them: on a mill without a tilted plane, the axis they index the tool to
    /// (as [`Interpreter::rotary_turns_tool`] reads them without the control); else the plane's
    /// Z (a tilted plane gives the axis, a lathe's C is its spindle).
    pub(in crate::interp) fn tcp(&mut self, on: bool, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if on == self.st.tcp {
            return;
        }
        self.st.tcp = on;
        self.emit(sink, CanonOp::Setting(crate::canon::Setting::ToolCentrePoint(on)));
        if on || self.rotary_indexes_tool() {
            self.rotary_tool_axis(sink, diags);
        } else {
            self.set_tool_axis([0.0, 0.0, 1.0], sink);
        }
    }

    /// An analog output the machine's configuration wires to its kinematics type (LinuxCNC
    /// switchkins, `M68 E3 Q1` in a remapped `M428`): a 5-axis type turns tool centre point
    /// control on, identity or another model off. Any other output is only recorded.
    pub(in crate::interp) fn kinematics_output(&mut self, def: &CodeDef, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let profile = self.profile;
        let Some(switch) = profile.machine.kinematics.as_ref() else { return };
        let word = |me: &Self, letter: u8| me.dialect.letter_role(letter).and_then(|r| me.slot(r));
        let (Some(output), Some(value)) = (word(self, b'E'), word(self, b'Q')) else { return };
        let Some(kinematics) = switch.selects(def.letter, u32::from(def.number), output, value) else { return };
        let on = kinematics == crate::interp::machine::Kinematics::ToolCentrePoint;
        self.tcp(on, sink, diags);
        self.st.tcp_machine = on;
    }

    /// Whether the rotary axes a block moves turn the tool axis on the part: under tool centre
    /// point control; and without it, where the axes index the part or the head (3+2 by rotary
    /// positioning: an SH8000's B, a 4-axis mill's A) with no tilted working plane in force
    /// (the plane then gives the axis) on a mill. On a lathe's dictionary (X in diameters or
    /// a ZX start plane) C is the spindle's position, and under polar interpolation (`G12.1`,
    /// `TRANSMIT`) the face's plane: the tool axis stays.
    pub(in crate::interp) fn rotary_turns_tool(&self) -> bool {
        // Only where the rotary words are the move's destination: a reference return's
        // (`G28 A0`) are its intermediate point, a `G92 A0`'s or a `G10`'s no move at all.
        self.st.tcp || (self.rotary_indexes_tool() && self.active_motion_code().is_some())
    }

    /// Whether rotary axes standing without tool centre point control index the tool on the
    /// part: a mill's dictionary, no tilted working plane, no polar interpolation.
    fn rotary_indexes_tool(&self) -> bool {
        let b = &self.dialect.behaviour;
        let lathe = b.x_diameter || b.initial_plane != crate::canon::Plane::Xy;
        self.st.frame.is_none() && self.st.face_plane.is_none() && !lathe
    }

    /// The tool axis the block's rotary axes turn the tool to (under tool centre point
    /// control, or indexing without it: [`Interpreter::rotary_turns_tool`]): `Rz(C)·Ry(B)·Rx(A)`
    /// applied to Z, the rotary axes where the block takes them.
    ///
    /// Which rotary axes turn the table and which the head: neither the dictionary nor the
    /// machine's configuration says, so the ISO 841 reading holds. ISO 841 names the senses
    /// of A, B and C as the tool's turn relative to the part; a rotary table turns the part the
    /// other way (its axis is A', B', C' on the machine), so in the part's frame, where the plan
    /// places features, the tool axis is the same turn for a table axis as for a head axis. A
    /// machine whose kinematics differ tilts it otherwise: that assumption is said once, where
    /// it tilts.
    pub(in crate::interp) fn rotary_tool_axis(&mut self, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        // The block's own G90 or G91 is in force for its words, though it is executed after
        // this reading.
        let stated = self.codes.iter().find_map(|&(c, _)| match self.code(c).meaning {
            Meaning::DistanceAbsolute => Some(false),
            Meaning::DistanceIncremental => Some(true),
            _ => None,
        });
        let incremental = |me: &Self, r: Role| match (me.slots[r as usize].map(|s| s.mode), stated) {
            (Some(crate::syntax::WordMode::Absolute | crate::syntax::WordMode::Incremental), _) | (_, None) => me.incremental(r),
            (_, Some(inc)) => inc,
        };
        let at = [Role::A, Role::B, Role::C].map(|r| {
            let i = r as usize;
            match self.slots[i] {
                Some(_) if incremental(self, r) => self.st.pos[i] + self.slot(r).unwrap_or(0.0),
                Some(slot) => slot.value,
                None => self.st.pos[i],
            }
        });
        let at = self.machine_senses(at);
        let r = chain([2, 1, 0], [at[2], at[1], at[0]]);
        let axis = [0, 1, 2].map(|i| if r[i][2].abs() < 1e-12 { 0.0 } else { r[i][2] });
        if axis != [0.0, 0.0, 1.0] {
            if self.st.tcp {
                self.kinematics_note(diags, "under tool centre point control the tool axis", "tcp-kinematics");
            } else {
                self.kinematics_note(diags, "the tool axis the rotary axes index to (no tool centre point control)", "index-kinematics");
            }
        }
        self.set_tool_axis(axis, sink);
    }

    /// The turn the rotary axes A, B and C give at their positions in force: `Rz(C)·Ry(B)·Rx(A)`.
    fn rotary_rotation(&self) -> [[f64; 3]; 3] {
        let at = self.machine_senses([Role::A, Role::B, Role::C].map(|r| self.st.pos[r as usize]));
        chain([2, 1, 0], [at[2], at[1], at[0]])
    }

    /// The rotary axes' positions as ISO 841 turns: negated for an axis the machine's
    /// kinematics turn the other way (`MachineSetup::reversed_rotary`: LinuxCNC `5axiskins`'s B).
    fn machine_senses(&self, at: [f64; 3]) -> [f64; 3] {
        let reversed = self.profile.machine.reversed_rotary;
        [0, 1, 2].map(|i| if reversed[i] { -at[i] } else { at[i] })
    }

    /// Says once (per `key`) that `what` is read from the rotary axes as turns about the part's axes.
    fn kinematics_note(&mut self, diags: &mut Vec<Diagnostic>, what: &str, key: &'static str) {
        if self.notes.contains_key(key) {
            return;
        }
        let machine = &self.profile.machine;
        let reversed: Vec<&str> = ["A", "B", "C"].into_iter().zip(machine.reversed_rotary).filter(|r| r.1).map(|r| r.0).collect();
        let msg = if reversed.is_empty() {
            format!(
                "{what} is taken from the rotary axes A, B and C as turns of the tool about the part's X, Y and Z (ISO 841 senses; A, then B, then C about the fixed axes); a machine whose kinematics differ tilts it otherwise"
            )
        } else {
            format!(
                "{what} is taken from the rotary axes A, B and C as turns of the tool about the part's X, Y and Z (A, then B, then C about the fixed axes), {} turning the other way from ISO 841 as the kinematics of {} turn it",
                reversed.join(", "),
                machine.source
            )
        };
        let mut d = Diagnostic::new(Code::TiltUnknown, self.origin, msg);
        d.severity = crate::diag::Severity::Note;
        self.limited(diags, key, d);
    }

    /// Sends the tool axis marker where the axis changes.
    fn set_tool_axis(&mut self, axis: [f64; 3], sink: &mut dyn CanonSink) {
        if (0..3).all(|i| (axis[i] - self.tool_axis[i]).abs() < 1e-12) {
            return;
        }
        self.tool_axis = axis;
        self.emit(sink, CanonOp::ToolAxis(axis));
    }

    /// G69 and the like: the tilted plane is cancelled with the rotation.
    pub(in crate::interp) fn untilt(&mut self, sink: &mut dyn CanonSink) {
        // A plane stated over several blocks and not completed is dropped with it.
        self.st.tilt_steps = None;
        self.set_frame(None, sink);
    }

    /// Siemens `ROT`/`AROT` with an angle about X or Y (840D frames: programmable rotations in
    /// space): the coordinate system turned in space, a tilted working plane as `CYCLE800`'s,
    /// about the program zero in force. The angles in the RPY order (machine data 10600
    /// `FRAME_ANGLE_INPUT_MODE` = 1, the default): about Z, then the turned Y, then the turned
    /// X [from the programming manual's frame chapter, recalled; one angle per block, as posts
    /// write them, needs no order]. `AROT` turns the plane in force about its own axes (a
    /// rotation in the plane kept so far, `AROT RPL=`, folded in first); `ROT` turns the plane
    /// that was in force before any programmable rotation.
    pub(in crate::interp) fn frame_rotation_in_space(&mut self, deg: [f64; 3], additive: bool, sink: &mut dyn CanonSink) {
        let datum = Frame { origin: [self.st.g92[0], self.st.g92[1], self.st.g92[2]], ..Frame::IDENTITY };
        let before = self.st.frame_before_rot.unwrap_or(self.st.frame);
        let (start, planar) = if additive {
            let planar = self.st.rotation.map_or(rot(2, 0.0), |(_, _, c, s)| rot(2, s.atan2(c).to_degrees()));
            (self.st.frame.unwrap_or(datum), planar)
        } else {
            (before.unwrap_or(datum), rot(2, 0.0))
        };
        self.st.rotation = None;
        let rotation = mul(mul(start.rotation, planar), chain([2, 1, 0], [deg[2], deg[1], deg[0]]));
        self.set_frame(Some(Frame { origin: start.origin, rotation }), sink);
        self.st.frame_before_rot = Some(before);
    }

    /// A replacing `TRANS` or `ROT`: the plane a programmable rotation in space turned is put
    /// back as it was before it.
    pub(in crate::interp) fn programmable_rotation_cleared(&mut self, sink: &mut dyn CanonSink) {
        if let Some(before) = self.st.frame_before_rot.take() {
            self.set_frame(before, sink);
        }
    }

    /// Puts `frame` in force (`None`: untilted): the position carried over into its
    /// coordinates, and the marker sent when the frame changes.
    pub(in crate::interp) fn set_frame(&mut self, frame: Option<Frame>, sink: &mut dyn CanonSink) {
        let frame = frame.filter(|f| !f.is_identity());
        // Another plane put in force ends what a programmable rotation turned.
        self.st.frame_before_rot = None;
        if frame == self.st.frame {
            return;
        }
        // The untilted plane's coordinates stand on the datum a local shift moved (as a
        // plane's origin does: [`Interpreter::on_datum`]).
        let datum = Frame { origin: [self.st.g92[0], self.st.g92[1], self.st.g92[2]], ..Frame::IDENTITY };
        let old = self.st.frame.unwrap_or(datum);
        let new = frame.unwrap_or(datum);
        let at = new.from_base(old.to_base([self.st.pos[0], self.st.pos[1], self.st.pos[2]]));
        self.st.pos[..3].copy_from_slice(&at);
        self.st.frame = frame;
        self.st.frame_set = frame.map(|f| (f, self.st.pos[5]));
        self.emit(sink, CanonOp::WorkPlane(frame.map(Box::new)));
    }

    /// A C move under a tilted working plane, without tool centre point control: the C axis
    /// (a mill-turn's work spindle positioned as an axis, `SPOS` then `C4=120`; a rotary
    /// table) turns the part about its Z under the plane, which the control does not follow
    /// (the plane's frame stays where it was set on the machine). The features cut next lie
    /// on the part turned by C from where it stood when the plane was set: the plane turned
    /// about the part's Z by that angle, C positive from +X towards +Y (the C-axis lathe's
    /// reading, `interp::live`). The program's coordinates stay; only the plane on the part
    /// turns.
    pub(in crate::interp) fn turn_part_under_plane(&mut self, sink: &mut dyn CanonSink) {
        let Some((set, c0)) = self.st.frame_set else { return };
        if self.active_motion_code().is_none() {
            return;
        }
        let i = Role::C as usize;
        let c = match self.slots[i] {
            Some(_) if self.incremental(Role::C) => self.st.pos[i] + self.slot(Role::C).unwrap_or(0.0),
            Some(slot) => slot.value,
            None => return,
        };
        let turn = rot(2, c - c0);
        let turned = Frame { origin: mul_v(turn, set.origin), rotation: mul(turn, set.rotation) };
        let frame = Some(turned).filter(|f| !f.is_identity());
        if frame == self.st.frame {
            return;
        }
        self.st.frame = frame;
        self.emit(sink, CanonOp::WorkPlane(frame.map(Box::new)));
    }
}

fn mul_v(a: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn spatial_a_tilts_the_tool_axis_towards_minus_y() {
        // SPA+30: about X by 30°; the tool axis (Z) turns towards -Y.
        let f = Frame { origin: [0.0; 3], rotation: chain([2, 1, 0], [0.0, 0.0, 30.0]) };
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!(close(f.axis(), [0.0, -s, c]));
    }

    #[test]
    fn spatial_b90_puts_the_tool_axis_along_x() {
        let f = Frame { origin: [0.0; 3], rotation: chain([2, 1, 0], [0.0, 90.0, 0.0]) };
        assert!(close(f.axis(), [1.0, 0.0, 0.0]));
        // The tilted X points down.
        assert!(close(f.dir_to_base([1.0, 0.0, 0.0]), [0.0, 0.0, -1.0]));
    }

    #[test]
    fn euler_nutation_turns_about_the_precessed_x() {
        // Precession 90° about Z, then nutation 90° about the new X (the old Y).
        let f = Frame { origin: [0.0; 3], rotation: chain([2, 0, 2], [90.0, 90.0, 0.0]) };
        assert!(close(f.axis(), [1.0, 0.0, 0.0]));
    }

    #[test]
    fn roll_pitch_yaw_turns_about_the_turned_axes() {
        // Rx(90)·Ry(90): the turn about Y is about the Y the first turn moved onto Z, so the
        // plane's Z lies along X (about the fixed axes it would lie along -Y).
        let r = chain([0, 1, 2], [90.0, 90.0, 0.0]);
        assert!(close([r[0][2], r[1][2], r[2][2]], [1.0, 0.0, 0.0]), "{r:?}");
        let fixed = chain([2, 1, 0], [0.0, 90.0, 90.0]);
        assert!(close([fixed[0][2], fixed[1][2], fixed[2][2]], [0.0, -1.0, 0.0]), "{fixed:?}");
    }

    #[test]
    fn vectors_give_x_and_z() {
        let r = by_vectors([1.0, 0.0, 0.1], [0.0, 0.0, 2.0]).unwrap();
        let f = Frame { origin: [0.0; 3], rotation: r };
        assert!(close(f.axis(), [0.0, 0.0, 1.0]));
        assert!(close(f.dir_to_base([1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]));
        assert!(by_vectors([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]).is_none());
    }

    #[test]
    fn frames_round_trip_points() {
        let f = Frame { origin: [10.0, -5.0, 3.0], rotation: chain([0, 1, 2], [20.0, -35.0, 70.0]) };
        let p = [1.5, 2.5, -4.0];
        assert!(close(f.from_base(f.to_base(p)), p));
    }

    #[test]
    fn one_projection_angle_tilts_as_the_spatial_angle_about_its_axis() {
        let spatial = |a: f64, b: f64| Frame { origin: [0.0; 3], rotation: chain([2, 1, 0], [0.0, b, a]) };
        let proj = |a: f64, b: f64| Frame { origin: [0.0; 3], rotation: projected(a, b).unwrap() };
        // PROMIN alone: SPA; PROPR alone: SPB.
        assert!(close(proj(0.0, 30.0).axis(), spatial(30.0, 0.0).axis()));
        assert!(close(proj(25.0, 0.0).axis(), spatial(0.0, 25.0).axis()));
        assert!(close(proj(25.0, 0.0).dir_to_base([1.0, 0.0, 0.0]), spatial(0.0, 25.0).dir_to_base([1.0, 0.0, 0.0])));
        // Both: the plane holds both traces.
        let f = proj(20.0, 35.0);
        let (s, c) = 35f64.to_radians().sin_cos();
        let n = f.axis();
        assert!((n[1] * c + n[2] * s).abs() < 1e-12);
    }

    #[test]
    fn solid_angle_tilts_towards_its_direction_in_xy() {
        // About Z by 90°, then about the turned Y by 30°: the tool leans 30° towards +Y.
        let f = Frame { origin: [0.0; 3], rotation: chain([2, 1, 2], [90.0, 30.0, 0.0]) };
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!(close(f.axis(), [0.0, s, c]));
    }

    #[test]
    fn the_writer_reads_the_rotary_axes_as_the_interpreter_does() {
        for abc in [[0.0, 15.0, 0.0], [30.0, -20.0, 75.0], [-90.0, 0.0, 285.0], [12.5, 81.101, 103.826]] {
            let r = chain([2, 1, 0], [abc[2], abc[1], abc[0]]);
            assert!(close(crate::canon::rotary_tool_axis(abc), [r[0][2], r[1][2], r[2][2]]), "{abc:?}");
        }
    }

    #[test]
    fn rotation_orders_name_each_axis_once() {
        assert_eq!(rotation_order(None), Some([0, 1, 2]));
        assert_eq!(rotation_order(Some(321.0)), Some([2, 1, 0]));
        assert_eq!(rotation_order(Some(132.0)), Some([0, 2, 1]));
        for bad in [313.0, 122.0, 124.0, 0.123, 1230.0] {
            assert_eq!(rotation_order(Some(bad)), None, "{bad}");
        }
    }

    #[test]
    fn projection_angles_named_by_their_axes() {
        // Fanuc P4 I (about X) and J (about Y) are Heidenhain's PROMIN and PROPR: one alone
        // tilts as the turn about its axis.
        let f = Frame { origin: [0.0; 3], rotation: projected(0.0, -30.0).unwrap() };
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!(close(f.axis(), [0.0, s, c]));
    }

    #[test]
    fn rest_of_line_words() {
        let w = line_numbers(" SPATIAL SPA+30 SPB-12.5 SPC+0 TURN MB MAX FMAX SEQ+ TABLE ROT");
        assert_eq!(w, vec![("SPA", Some(30.0)), ("SPB", Some(-12.5)), ("SPC", Some(0.0))]);
        let w = line_numbers(" SPA+Q1 SPB+0");
        assert_eq!(w, vec![("SPA", None), ("SPB", Some(0.0))]);
        let w = line_numbers(" POINTS P1X+0 P2Y-12.5 P3Z+7 MOVE DIST50 F900");
        assert_eq!(w, vec![("P1X", Some(0.0)), ("P2Y", Some(-12.5)), ("P3Z", Some(7.0)), ("DIST", Some(50.0)), ("F", Some(900.0))]);
    }
}
