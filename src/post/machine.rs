//! Moves in the machine's own frame: a return to a reference position (`G28`, `G30`, Siemens
//! `G74`) and a move in machine coordinates (`G53`, `SUPA`, `M91`). The analysis knows neither
//! the reference positions nor the work offsets, so the positions its moves reach there are
//! not positions in the work offset's frame: written as ordinary moves they would send the
//! tool somewhere else (a `G91 G28 Z0` written as `Z0.` is a rapid down to the part's top).
//! They are written by the target's `home-1`, `home-2` and `machine-rapid` templates, or
//! refused with an error and not written at all.
//!
//! The door: [`Post::machine_op`] for the marker, [`Post::machine_step`] for each of the
//! moves it governs.

use super::{Post, Vals};
use crate::canon::{Canon, MachineMove, MachineTarget};
use crate::diag::{Code, Diagnostic};
use crate::dialect::output::MACHINE_AXES;

/// A machine-frame move under way: its marker, the event that writes it, how many of its
/// moves are still to come, and whether the target can write it.
pub(super) struct PendingMachine {
    marker: MachineMove,
    event: &'static str,
    left: usize,
    writable: bool,
}

impl PendingMachine {
    /// Whether the next move is the marker's last: the one to the machine's position.
    pub(super) fn last_step(&self) -> bool {
        self.left <= 1
    }
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// A machine-frame move begins: the moves that follow are its own.
    pub(super) fn machine_op(&mut self, canon: &Canon, m: &MachineMove) {
        self.cancel_cycle();
        // A straight approach of the reference position is the target's return with the
        // current position as its intermediate point (`G91 G28 Z0`), as its template writes it.
        // Fixed points and reference positions 3 and 4 have no template: refused.
        let event = match m.target {
            MachineTarget::Reference(1) | MachineTarget::Direct(1) => "home-1",
            MachineTarget::Reference(2) | MachineTarget::Direct(2) => "home-2",
            MachineTarget::Reference(_) | MachineTarget::Direct(_) => "home-n",
            MachineTarget::Fixed(_) => "fixed-point",
            MachineTarget::Machine => "machine-rapid",
            MachineTarget::Builder => "machine-builder-rapid",
            MachineTarget::Limit => "travel-limit",
        };
        let writable = self.out.template(event).is_some_and(|(t, _)| !t.0.is_empty());
        if !writable {
            self.diags.push(Diagnostic::new(
                Code::PostUnwritable,
                canon.origin,
                format!(
                    "the {} is not written: the target's output rules have no `{event}` template, and written as a move in the work offset's frame it would go elsewhere; nothing that follows can be trusted to start from where the source's does",
                    m.describe()
                ),
            ));
        }
        self.machine = Some(PendingMachine { marker: m.clone(), event, left: m.moves(), writable });
    }

    /// A straight move of the machine-frame move under way: a reference return's move to its
    /// intermediate point is an ordinary rapid; its last move is written by the target's
    /// template (the positions it reaches are the machine's, so each axis it moved is stated
    /// again by the next move that names it).
    pub(super) fn machine_step(&mut self, canon: &Canon, p: &[f64; 6], rapid: bool) {
        let Some(mut pending) = self.machine.take() else { return };
        pending.left = pending.left.saturating_sub(1);
        if pending.left > 0 {
            let writable = pending.writable;
            self.machine = Some(pending);
            if writable {
                self.straight(canon, p, rapid);
            }
            return;
        }
        let q = self.point(p);
        if pending.writable && !rapid {
            // The target's machine-coordinate block moves at rapid (G53 on Fanuc and Haas).
            self.note(
                Code::PostUnwritable,
                canon,
                "machine-feed",
                "a feed in machine coordinates is not written: the target's `machine-rapid` moves at rapid",
            );
        } else if pending.writable {
            let mut vals = Vals::new();
            for (k, v) in pending.marker.axes.iter().enumerate() {
                if let Some(v) = v {
                    let x = match pending.marker.target {
                        MachineTarget::Reference(_) | MachineTarget::Direct(_) | MachineTarget::Fixed(_) | MachineTarget::Limit => 0.0,
                        MachineTarget::Machine | MachineTarget::Builder if k < 3 => self.to_out(*v),
                        MachineTarget::Machine | MachineTarget::Builder => *v,
                    };
                    vals.set(MACHINE_AXES[k], x);
                }
            }
            self.event(pending.event, &mut vals);
        }
        // The axes it moved are where only the machine knows: unknown until a block states
        // them absolutely (`CanonOp::Known`), never written meanwhile (not as the 0 the
        // analysis gives them).
        for (k, v) in pending.marker.axes.iter().enumerate() {
            if v.is_some() {
                self.known &= !(1 << k);
            }
        }
        self.moved(q);
    }
}
