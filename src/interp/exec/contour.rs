//! The contour languages' helpers that move nothing themselves: the pole (Heidenhain `CC`,
//! its ISO forms) that polar words and arcs turn about, and corners rounded or chamfered
//! between two moves, by a block of their own (`RND R5`, `CHF 2`) or by the words of a move
//! (Siemens `RND=`, `CHF=`). The corner geometry is worked out by `interp/corner.rs`.
//!
//! Doors: [`Interpreter::pole_code`], [`Interpreter::corner_code`],
//! [`Interpreter::corner_words`].

use crate::canon::Plane;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::{Interpreter, corner};
use crate::text::TextRange;

impl Interpreter<'_> {
    /// `CC X Y` and its forms: the pole at the block's point (the plane's axes not given stay
    /// as they were, for the keeping form), or that far from the current point or the pole; and
    /// Fanuc `G16` / `G15`, the polar coordinate command on or off.
    pub(super) fn pole_code(&mut self, def: &CodeDef) {
        match def.meaning {
            // Fanuc G16 / G15: the moves that follow read polar words about the work origin
            // (`polar_command_words`).
            Meaning::Polar | Meaning::PolarOff => self.st.polar_command = def.meaning == Meaning::Polar,
            Meaning::Pole => {
                self.st.pole_plane = None;
                let t = self.target();
                let (a0, a1, _) = self.st.plane.axes();
                self.st.pole = (t[a0], t[a1]);
            }
            Meaning::PoleKeeping => {
                let t = self.target();
                let given = |axis: usize| self.slots[Role::AXES[axis] as usize].is_some();
                // The two axes of another plane (`CC Y Z` while the tool is along Z): the circle
                // about it lies in their plane (the TNC takes the plane of a circle from its
                // centre's axes).
                let other = match (given(0), given(1), given(2)) {
                    (true, true, false) => Some(Plane::Xy),
                    (true, false, true) => Some(Plane::Xz),
                    (false, true, true) => Some(Plane::Yz),
                    _ => None,
                }
                .filter(|p| *p != self.st.plane);
                if let Some(p) = other {
                    let (a0, a1, _) = p.axes();
                    self.st.pole = (t[a0], t[a1]);
                    self.st.pole_plane = Some(p);
                    return;
                }
                self.st.pole_plane = None;
                let (a0, a1, _) = self.st.plane.axes();
                self.st.pole = match (given(a0), given(a1)) {
                    (false, false) => (t[a0], t[a1]),
                    (g0, g1) => (if g0 { t[a0] } else { self.st.pole.0 }, if g1 { t[a1] } else { self.st.pole.1 }),
                };
            }
            _ => {
                self.st.pole_plane = None;
                let (a0, a1, _) = self.st.plane.axes();
                let (b0, b1) = if def.meaning == Meaning::PoleIncremental { (self.st.pos[a0], self.st.pos[a1]) } else { self.st.pole };
                let word = |axis: usize| self.slot(Role::AXES[axis]).unwrap_or(0.0);
                self.st.pole = (b0 + word(a0), b1 + word(a1));
            }
        }
    }

    /// A corner block (`RND R5`, `CHF 2`): the corner between the move before it and the next.
    pub(super) fn corner_code(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let size = if def.meaning == Meaning::CornerRound { self.slot(Role::R) } else { self.slot(Role::Geometry) };
        match size {
            Some(v) if v > 0.0 => self.mark_corner(
                if def.meaning == Meaning::CornerRound { corner::Corner::Round(v) } else { corner::Corner::Chamfer(v) },
                false,
            ),
            // An unknown size (the tool radius, `RND RQ108`): the word was left out
            // and said so; the corner stays sharp.
            None if self.word_unknown(if def.meaning == Meaning::CornerRound { Role::R } else { Role::Geometry }) => {}
            _ => diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs a size above zero", def.label()))),
        }
    }

    /// A corner the block's own words round or chamfer (Siemens `X65 RND=5`, Fanuc `X65 ,R5`):
    /// marked after the block's move, between it and the next, as a corner block between them
    /// would be.
    ///
    /// `RNDM=r` rounds every corner from the end of its own block's move on with radius r,
    /// until `RNDM=0`; a block's own `RND=`, `CHR=` or `CHF=` takes its corner instead
    /// (840D sl programming manual, fundamentals, "Chamfer, rounding": "RNDM: modal
    /// rounding", "RNDM=0: deactivates modal rounding").
    pub(in crate::interp) fn corner_words(&mut self, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let mut words = [Role::CornerRadius, Role::CornerChamfer, Role::CornerChamferLength].map(|r| self.slot(r));
        // `RNDM=r`: its value stands in the corner radius's slot.
        // A block without a move (`RNDM=2` alone) has no corner of its own: the rounding
        // starts at the next move's end.
        let rndm = self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::RoundModal);
        if rndm {
            let r = words[0].unwrap_or(0.0);
            if r < 0.0 {
                diags.push(Diagnostic::new(Code::MissingParameter, range, "a modal rounding (RNDM) needs a radius of zero (off) or above"));
            }
            self.st.round_modal = (r > 0.0).then_some(r);
            if r <= 0.0 || !self.has_axes {
                words[0] = None;
            }
        }
        // A modal rounding's corner, left out where it is none (`Corners::mark`).
        let modal = rndm || words == [None, None, None];
        let (size, corner) = match (words, self.st.round_modal) {
            ([Some(r), ..], _) => (r, corner::Corner::Round(r)),
            ([None, Some(c), _], _) => (c, corner::Corner::Chamfer(c)),
            ([None, None, Some(c)], _) => (c, corner::Corner::ChamferLength(c)),
            ([None, None, None], Some(r)) if self.has_axes => (r, corner::Corner::Round(r)),
            ([None, None, None], _) => return,
        };
        if size > 0.0 {
            self.mark_corner(corner, modal);
        } else {
            diags.push(Diagnostic::new(Code::MissingParameter, range, "a corner rounding or chamfer needs a size above zero"));
        }
    }

    /// Marks the corner between the move the corner stage holds and the next.
    /// `modal`: a modal rounding's corner (`RNDM`).
    fn mark_corner(&mut self, corner: corner::Corner, modal: bool) {
        if let Some(k) = self.corners.get_mut().as_mut() {
            k.mark(corner, self.origin, self.line, modal);
        }
    }
}
