//! The read phase of a block: its codes looked up and checked against their groups, its
//! words evaluated and put in their slots (scaled for least-increment input, halved for
//! diameters), and the parameters its codes need checked. Nothing runs yet: the execute
//! phase (`exec/`) reads what this phase left.
//!
//! Doors: [`Interpreter::read`], and for the execute phase
//! [`Interpreter::active_motion_code`], [`Interpreter::claims_axes`],
//! [`Interpreter::value`].

use crate::canon::{DistanceMode, Units};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{CodeDef, DecimalInput, Dialect, DwellPoint, Meaning, Role, Step, TimeUnit};
use crate::syntax::{Block, Value, Word, WordMode};
use crate::text::TextRange;

use super::{Interpreter, Slot, eval};

/// How the block's words read, from its codes and the modes in force.
#[derive(Clone, Copy)]
struct WordReading {
    /// The units of its lengths (G20 or G21 in the block counts already).
    units: Units,
    /// Whether X gives a diameter (G7 in the block counts already).
    diameter: bool,
    /// Whether only an absolute X gives one (`DIAM90`; in the block counts already).
    diameter_absolute: bool,
    /// Whether K counts a drilling cycle's repeats, no length.
    k_counts: bool,
    /// The role of the sequence number a subprogram call starts at (`M98 Q2100`), read as a
    /// number, no length, in a block with such a call.
    call_start: Option<Role>,
    /// The role of a tilted-plane code's form selector (`G68.2 P2 Q1`, `P1 Q321`: its
    /// `tilt-mode`), or of a count a code's args name (`G73 U14 W4 R3`: R the `passes`), read
    /// as a number, no length.
    selector: Option<Role>,
}

impl Interpreter<'_> {
    /// Forgets the previous block's words and codes.
    pub(super) fn clear_block(&mut self) {
        let mut filled = std::mem::take(&mut self.filled);
        while filled != 0 {
            self.slots[filled.trailing_zeros() as usize] = None;
            filled &= filled - 1;
        }
        self.code_steps = 0;
        self.unknown_roles = 0;
        self.codes.clear();
        self.block_cycle = None;
        self.cycle_args.clear();
        self.intent_words = false;
        self.remap_call = None;
        self.cycle_text = None;
    }

    /// Read phase: values, codes, groups and parameter checks. False when the block must be skipped.
    pub(super) fn read(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        self.clear_block();
        self.block_read = true;
        self.misread_before = self.misread;
        self.block_misread = false;
        // Codes first: a unit change in this block affects how its numbers scale.
        self.numbered_spindles = block.spindle.is_some();
        let mut ok = self.read_codes(block, diags);
        let how = self.word_reading();
        for (k, w) in block.words.iter().enumerate() {
            if matches!(w.role, Role::G | Role::M | Role::Keyword | Role::Cycle) {
                continue;
            }
            ok &= self.read_word(block, k, *w, how, diags);
        }
        self.polar_roles();
        if let Some(cylinder) = self.st.cylinder {
            self.cylinder_words(cylinder);
        } else if self.st.face_plane.is_some() {
            self.face_words();
        }
        // Where I J K are the circle centre and the pole (Heidenhain ISO), a block that
        // writes them sets the pole, with or without an arc.
        if self.dialect.behaviour.arc_centres_pole {
            let (a0, a1, _) = self.st.plane.axes();
            if let Some(c) = self.centre_words(a0, a1, self.st.pos) {
                self.st.pole = c;
            }
        }
        // Polar words (`PA+90`) name an end point as axis words do.
        const POSITION: u128 = {
            // A line's angle alone (Fanuc lathe direct drawing `G01 ,A150.`) says where the move goes too.
            let mut m = 1 << Role::PolarRadius as u32 | 1 << Role::PolarAngle as u32 | 1 << Role::LineAngle as u32;
            let mut k = 0;
            while k < Role::AXES.len() {
                m |= 1 << Role::AXES[k] as u32;
                k += 1;
            }
            m
        };
        // A mill's W (its quill) moves the tool as X, Y and Z do (`quill_word`).
        self.has_axes = self.filled & POSITION != 0 || (self.filled & 1 << Role::W as u32 != 0 && self.quill_moves_tool());
        // The motion code is known now, the modal one too (`has_axes`).
        self.polar_command_words(block, diags);
        self.fixed_point_number(diags);
        if ok {
            ok = self.check_params(block, diags);
        }
        ok
    }

    /// Whether `block` is one inert keyword code and the word of its value, and nothing else
    /// to read (Heidenhain's `FN 3:` before its assignment, `FN 12:` before its jump): a code
    /// that means nothing to execute (`other`), takes no other word and moves nothing. Then
    /// what [`Interpreter::read_inert_code`] reads: the code, the word of its value.
    pub(super) fn inert_code_words(&self, block: &Block) -> Option<(usize, Word)> {
        let [a, b] = block.words.as_slice() else { return None };
        let (code, word) = match (a.role, b.role) {
            (Role::Keyword, Role::Extra) => (a, b),
            (Role::Extra, Role::Keyword) => (b, a),
            _ => return None,
        };
        let (Value::Number { value: c, .. }, Value::Number { .. }) = (code.value, word.value) else { return None };
        let c = c as usize;
        // What the dictionary says of the code, asked once (`inert_keyword`; none past the
        // codes).
        if !self.inert_keywords.get(c).is_some_and(|&inert| inert)
            || word.cycle_arg
            || code.cycle_arg
            || !block.axis_refs.is_empty()
            || self.st.face_plane.is_some()
        {
            return None;
        }
        // A motion mode that would read the value as a polar word (`polar_roles`): the
        // general way.
        let polar = self.st.motion_code.is_some_and(|m| self.extra_polar.get(m).is_none_or(|&p| p));
        (!polar).then_some((c, *word))
    }

    /// The read phase of a block [`Interpreter::inert_code_words`] found inert, code `c`
    /// written at `at` and `word`: exactly what [`Interpreter::read`] does for it (the code in
    /// the block's codes, alone in its group; the value in its slot; no word `check_params`
    /// looks at).
    pub(super) fn read_inert_code(&mut self, c: usize, at: TextRange, word: Word) {
        self.clear_block();
        self.block_read = true;
        self.misread_before = self.misread;
        self.block_misread = false;
        self.codes.push((c, at));
        self.code_steps |= 1 << self.dialect.groups[self.code(c).group].step as u32;
        let Value::Number { value, .. } = word.value else { return };
        self.slots[Role::Extra as usize] = Some(Slot { value, range: word.range, mode: word.mode });
        self.filled |= 1 << Role::Extra as u32;
        // No axis, polar or centre word: `polar_roles` finds none to turn into one.
        self.has_axes = false;
    }

    /// The block's codes (G, M and keyword codes) and its named cycle, in the block's codes;
    /// false when one cannot be read, is unknown, or shares its group with another.
    fn read_codes(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        let mut ok = true;
        for w in &block.words {
            if !matches!(w.role, Role::G | Role::M | Role::Keyword | Role::Cycle) {
                continue;
            }
            if w.role == Role::Cycle {
                if let Value::Number { value, .. } = w.value {
                    self.block_cycle = Some(value as usize);
                }
                continue;
            }
            if w.role == Role::Keyword {
                let Value::Number { value, .. } = w.value else { continue };
                ok &= self.push_code(value as usize, w.range, diags);
                continue;
            }
            if !matches!(w.role, Role::G | Role::M) {
                continue;
            }
            ok &= self.letter_code(block, w, diags);
        }
        ok
    }

    /// A G or M word: the code its value names, added to the block's codes. A word whose
    /// value is unknown or vacant is left out; an M code the dialect does not list is the
    /// machine builder's where the dialect says so. False when the block must be skipped.
    fn letter_code(&mut self, block: &Block, w: &Word, diags: &mut Vec<Diagnostic>) -> bool {
        let Some(v) = self.value(block, w.value, w.range, diags) else {
            return false;
        };
        if eval::is_unknown(v) {
            let _ = self.unknown_word(block, w.range, diags);
            return true;
        }
        if eval::is_null(v) {
            return true; // a word whose value is vacant is omitted
        }
        let x10 = (v * 10.0).round();
        let letter = w.letter as char;
        let found =
            if (v * 10.0 - x10).abs() < 1e-3 && (0.0..10_000.0).contains(&x10) { self.dialect.code_id(letter, x10 as u32) } else { None };
        let Some(idx) = found else {
            let shown = block.text(w.range);
            // A code the machine's configuration remaps (LinuxCNC `REMAP=M428 ngc=428remap`):
            // a call of that subroutine after the block.
            if let Some(sub) = (0.0..100_000.0).contains(&x10).then(|| self.profile.machine.remap(letter, x10 as u32)).flatten() {
                self.remap_call = Some(sub.to_owned());
                self.intent_words = true;
                return true;
            }
            if letter == 'M' && self.dialect.behaviour.machine_m_codes && (0.0..10_000.0).contains(&x10) {
                let d = Diagnostic::new(
                    Code::MachineCode,
                    w.range,
                    format!("`{shown}` is a machine-builder M code; recorded, with no effect on the toolpath"),
                );
                self.limited(diags, "machine-m-code", d);
                return true;
            }
            if let Some(e) = (0.0..100_000.0).contains(&x10).then(|| self.dialect.vocabulary.code(letter, x10 as u32)).flatten() {
                let d = Diagnostic::new(
                    Code::Unmodelled,
                    w.range,
                    format!(
                        "`{shown}` ({}, {}) is in the control's vocabulary but not modelled: kept as intent, its effect on the toolpath unknown",
                        e.what, e.manual
                    ),
                );
                let moves = e.moves.then(|| motion_unknown(shown, &e.what, w.range));
                self.limited(diags, "unmodelled-code", d);
                if let Some(m) = moves {
                    self.limited(diags, "motion-unknown", m);
                    self.position_lost();
                }
                self.intent_words = true;
                return true;
            }
            diags.push(Diagnostic::new(
                Code::UnknownCode,
                w.range,
                format!("`{shown}` is not a code of the {} dialect", self.dialect.name),
            ));
            return false;
        };
        self.push_code(idx, w.range, diags)
    }

    /// How the block's words read: in the units and the diameter mode the block's own codes
    /// set, else those in force; and whether K counts the repeats of a drilling cycle (the
    /// block's own or the one in force), no length.
    fn word_reading(&self) -> WordReading {
        let units = self.codes.iter().rev().find_map(|(c, _)| match self.code(*c).meaning {
            Meaning::UnitsInch => Some(Units::Inch),
            Meaning::UnitsMm => Some(Units::Mm),
            _ => None,
        });
        let units = units.unwrap_or(self.st.units);
        // G7 in this block already reads its X words as diameters.
        let diameter = self.codes.iter().rev().find_map(|(c, _)| match self.code(*c).meaning {
            Meaning::DiameterMode => Some((true, false)),
            Meaning::RadiusMode => Some((false, false)),
            Meaning::DiameterAbsolute => Some((true, true)),
            _ => None,
        });
        let (diameter, diameter_absolute) = diameter.unwrap_or((self.st.diameter, self.st.diameter_absolute));
        // In a drilling cycle's block (its own or the one in force) K counts repeats: no length.
        let is_hole_cycle = |m: Meaning| {
            matches!(
                m,
                Meaning::CycleDrill
                    | Meaning::CycleDrillDwell
                    | Meaning::CyclePeckDrill
                    | Meaning::CycleChipBreak
                    | Meaning::CycleBore
                    | Meaning::CycleBoreDwell
                    | Meaning::CycleBoreStop
                    | Meaning::CycleTap
                    | Meaning::CycleTapLeft
                    | Meaning::CycleFineBore
                    | Meaning::CycleBackBore
                    | Meaning::CycleBoreManual
            )
        };
        let k_counts = self.codes.iter().any(|&(c, _)| is_hole_cycle(self.code(c).meaning))
            || self.st.motion_code.is_some_and(|c| is_hole_cycle(self.code(c).meaning));
        let calls = self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::SubprogramCall);
        let call_start = self.dialect.macros.call_start.filter(|_| calls).and_then(|l| self.dialect.letter_role(l));
        let selector = self.codes.iter().find_map(|&(c, _)| {
            let def = self.code(c);
            let tilt = !def.tilt_forms.is_empty();
            def.args.iter().find(|&&(_, to)| (tilt && to == Role::TiltMode) || to == Role::Passes).map(|&(from, _)| from)
        });
        WordReading { units, diameter, diameter_absolute, k_counts, call_start, selector }
    }

    /// Word `k` of the block, not a code: into its slot, or the named cycle's arguments. An
    /// axis named by a variable (`AX[_X]=10`) is looked up first; a value that is unknown or
    /// vacant leaves the word out. False when the block must be skipped.
    fn read_word(&mut self, block: &Block, k: usize, mut w: Word, how: WordReading, diags: &mut Vec<Diagnostic>) -> bool {
        if let Some(&(_, index)) = block.axis_refs.iter().find(|&&(i, _)| i == k) {
            match self.axis_by_variable(block, index, w.range, diags) {
                Some(letter) => {
                    w.letter = letter;
                    w.role = self.dialect.letter_role(letter).unwrap_or(Role::Extra);
                }
                None => return true,
            }
        }
        let w = &w;
        if w.cycle_arg {
            if let (Value::Text(r), Role::ContourName) = (w.value, w.role) {
                // A second name is the end of a label range (`CYCLE62(,2,"START","END")`).
                let text = block.text(r);
                self.cycle_text = Some(match self.cycle_text.take() {
                    Some(first) if !first.is_empty() && !text.is_empty() => format!("{first}:{text}"),
                    Some(first) if text.is_empty() => first,
                    _ => text.to_owned(),
                });
                return true;
            }
            match self.value(block, w.value, w.range, diags) {
                Some(v) if eval::is_unknown(v) => {
                    let _ = self.unknown_word(block, w.range, diags);
                }
                Some(v) if !eval::is_null(v) => self.cycle_args.push((w.role, v)),
                Some(_) => {}
                None => return false,
            }
            return true;
        }
        let Some(role) = self.free_role(block, w, diags) else { return false };
        self.machine_axis_name(block, role, w.range, diags);
        let mut v = match w.value {
            Value::Number { value, .. } => value,
            Value::Text(r) => match self.text_value(block, role, r, w.range, diags) {
                Some(v) => v,
                None => return false,
            },
            Value::Expr(_) => match self.value(block, w.value, w.range, diags) {
                Some(v) if eval::is_unknown(v) => {
                    if role == Role::F {
                        // Not zero: the feed the control has, which this file does not know.
                        self.st.feed_unknown = true;
                        self.st.feed_outside = true;
                        self.st.feed = self.st.feed.max(0.0);
                    }
                    self.unknown_roles |= 1 << role as u32;
                    let what = self.unknown_word(block, w.range, diags);
                    if role.is_axis() || matches!(role, Role::I | Role::J | Role::K | Role::R | Role::PolarRadius | Role::PolarAngle) {
                        // Where the tool goes is not known here (a Q after `FN 18: SYSREAD`, a
                        // global variable): a translation refuses rather than drop the word
                        // or write a made-up value.
                        let shown = block.text(w.range).to_owned();
                        let msg =
                            format!("`{shown}` reads {what}: where this move goes is not known here, so a translation cannot write it");
                        self.limited(diags, "motion-unknown", Diagnostic::new(Code::MotionUnknown, w.range, msg));
                    }
                    return true;
                }
                Some(v) if eval::is_null(v) => return true,
                Some(v) => v,
                None => return false,
            },
        };
        if role == Role::P && matches!(w.value, Value::Number { decimal: true, .. }) && self.dwell_block(block) {
            v = self.dwell_p_point(block, w.range, v, diags);
        }
        v = self.least_increment(block, w, role, v, how, diags);
        // Under `DIAM90` an incremental X (G91, in this block or in force, or `X=IC()`) is a radius.
        let incremental = match w.mode {
            WordMode::Modal => self
                .codes
                .iter()
                .rev()
                .find_map(|&(c, _)| match self.code(c).meaning {
                    Meaning::DistanceIncremental => Some(true),
                    Meaning::DistanceAbsolute => Some(false),
                    _ => None,
                })
                .unwrap_or(self.st.distance == DistanceMode::Incremental),
            mode => mode == WordMode::Incremental,
        };
        if how.diameter && role == Role::X && !(how.diameter_absolute && incremental) {
            v /= 2.0;
        }
        self.slots[role as usize] = Some(Slot { value: v, range: w.range, mode: w.mode });
        self.filled |= 1 << role as u32;
        true
    }

    /// Whether the block's P is a dwell time: a dwell (`G04`) or a canned drilling or boring
    /// cycle (`G82 ... P`, `G89 ... P`) among its codes, or a repeat line of the canned cycle in
    /// force (`X2. P1.` under a modal `G82`: the cycle runs again at the new position with the
    /// new dwell; Fanuc and Haas operator's manuals, canned cycles: the cycle's data stay modal
    /// and a block of them alone repeats it). A repeat line has a position word (an axis or R:
    /// Fanuc 0i-F/30i operator's manuals, canned cycles: a block with no axis word does not run
    /// the cycle, so `M06 P3.` under `G81` is no repeat), the cycle in force takes a P (its
    /// dwell; the P is then used, not an unused word), and no code of the block takes a P of
    /// its own (`M98 P`, `G10 P`) or sets another motion.
    fn dwell_block(&self, block: &Block) -> bool {
        let own = self.codes.iter().any(|&(c, _)| {
            let m = self.code(c).meaning;
            m == Meaning::Dwell || m.is_cycle()
        });
        own || (self.st.motion_code.is_some_and(|c| self.code(c).meaning.is_cycle() && self.code(c).params.takes(Role::P))
            && block.words.iter().any(|w| w.role.is_axis() || w.role == Role::R)
            && !self.codes.iter().any(|&(c, _)| {
                let def = self.code(c);
                def.params.takes(Role::P) || !def.args.is_empty() || self.dialect.groups[def.group].step == Step::Motion
            }))
    }

    /// A dwell's P written with a decimal point (`G04 P2.`, `G89 ... P2.`), as the dialect
    /// reads it: Fanuc takes P only as a whole number of milliseconds and stops with an alarm
    /// (0i-F/30i operator's manuals, Dwell and canned cycles: "a decimal point cannot be used"
    /// in P; alarm PS0007), the error is at the word and the value read as written; Haas
    /// reads the point as seconds (mill and lathe operator's manuals, G04), given here in the
    /// dwell unit; elsewhere P stays in the dwell unit.
    fn dwell_p_point(&self, block: &Block, range: TextRange, v: f64, diags: &mut Vec<Diagnostic>) -> f64 {
        match self.dialect.behaviour.dwell_point {
            DwellPoint::Unit => v,
            DwellPoint::Seconds => match self.dialect.behaviour.dwell_unit {
                TimeUnit::Milliseconds => v * 1000.0,
                TimeUnit::Seconds => v,
            },
            DwellPoint::Alarm => {
                let shown = block.text(range).trim();
                let msg = format!(
                    "`{shown}`: a dwell's P takes no decimal point on this control (a whole number of milliseconds); it stops with an alarm"
                );
                diags.push(Diagnostic::new(Code::DwellPointAlarm, range, msg));
                v
            }
        }
    }

    /// The role word `w` fills: its own, or, for an address that may appear twice, the
    /// second one's. `None`, with the finding, when the block has that address already.
    fn free_role(&self, block: &Block, w: &Word, diags: &mut Vec<Diagnostic>) -> Option<Role> {
        let mut role = w.role;
        // Words kept but not interpreted (`DISR=1 DISCL=2`): two addresses of that role are two
        // addresses; only the same one written twice is a duplicate.
        // Every earlier such word of the block counts, not only the last in the slot
        // (`DISR=1 DISCL=2 DISR=3` writes DISR twice).
        if role == Role::Extra && self.slots[role as usize].is_some() {
            let name = |r: TextRange| {
                block.text(r).trim().chars().take_while(|c| c.is_ascii_alphabetic() || *c == '_').collect::<String>().to_ascii_uppercase()
            };
            let own = name(w.range);
            let again =
                block.words.iter().any(|o| o.role == Role::Extra && !o.cycle_arg && o.range.start < w.range.start && name(o.range) == own);
            if !again {
                return Some(role);
            }
        }
        if self.slots[role as usize].is_some() {
            // An address that may appear twice gives its second occurrence another role.
            let again = self.dialect.addresses.iter().find(|a| a.role == role).and_then(|a| a.again);
            if let Some(r) = again.filter(|r| self.slots[*r as usize].is_none()) {
                role = r;
            }
        }
        if self.slots[role as usize].is_some() {
            let shown = block.text(w.range);
            // A kept address is named whole (`DISR`), the others by their letter.
            let address = match role {
                Role::Extra => {
                    shown.trim().chars().take_while(|c| c.is_ascii_alphabetic() || *c == '_').collect::<String>().to_ascii_uppercase()
                }
                _ => (w.letter as char).to_string(),
            };
            diags.push(Diagnostic::new(
                Code::DuplicateWord,
                w.range,
                format!("`{shown}`: the address {address} appears twice in this block"),
            ));
            return None;
        }
        Some(role)
    }

    /// Value `v` of length word `w` (in `role`) under least-increment input (the dialect's
    /// `decimal-input`): without a decimal point it counts increments (`X10` is 0.01 mm) and
    /// is scaled so. Such a word in a program that writes its other lengths with points is
    /// suspect, and said so; each axis remembers whether its position was read so.
    fn least_increment(&mut self, block: &Block, w: &Word, role: Role, mut v: f64, how: WordReading, diags: &mut Vec<Diagnostic>) -> f64 {
        let units = how.units;
        if let (Value::Number { decimal, .. }, DecimalInput::LeastIncrement { mm, inch, scaled }) =
            (w.value, &self.dialect.behaviour.decimal_input)
            && scaled.contains(&role)
            && !(how.k_counts && role == Role::K)
            && how.call_start != Some(role)
            && how.selector != Some(role)
            && !self.profile.calculator_input
            && !self.taken_as_angle(role)
        {
            let axis = Role::AXES.iter().position(|&a| a == role);
            let absolute = match w.mode {
                WordMode::Modal => self.st.distance == DistanceMode::Absolute,
                WordMode::Absolute => true,
                WordMode::Incremental => false,
            };
            self.point_habit[if !decimal {
                2
            } else if v.fract() == 0.0 {
                0
            } else {
                1
            }] += u32::from(decimal || v != 0.0);
            // Where the finding points: the word, or while a subprogram from another file runs
            // the main program's call of it (the finding is told against the main program).
            if !decimal && v != 0.0 && self.first_bare.is_none() {
                self.first_bare = Some(self.origin_override.map_or(w.range, |(call, _)| call));
            }
            if decimal {
                self.st.length_points = true;
                if let Some(i) = axis.filter(|_| absolute) {
                    self.misread[i] = false;
                }
            } else {
                if v != 0.0 && self.st.length_points {
                    let shown = block.text(w.range);
                    let unit = if units == Units::Mm { "mm" } else { "inch" };
                    let scaled_to = (v * if units == Units::Mm { *mm } else { *inch } * 1e9).round() / 1e9;
                    let msg = format!(
                        "`{shown}` has no decimal point: least-increment input reads it as {scaled_to} {unit}, while this program writes its other lengths with points; if {v} {unit} was meant, write `{shown}.` (or, if the machine reads whole numbers as units, set its decimal_input to calculator in the config)"
                    );
                    let mut d = Diagnostic::new(Code::NoDecimalPoint, w.range, msg);
                    // The first such word is the finding; the others repeat it.
                    if self.misread_word.is_some() {
                        d.severity = Severity::Note;
                    }
                    self.limited(diags, "no-decimal-point", d);
                    match axis {
                        Some(i) => self.misread[i] = true,
                        None => self.block_misread = true,
                    }
                    self.misread_word = Some(format!("`{shown}` read as {scaled_to} {unit}"));
                } else if let Some(i) = axis.filter(|_| absolute) {
                    self.misread[i] = false;
                }
                v *= if units == Units::Mm { *mm } else { *inch };
            }
        }
        v
    }

    /// A motion code may give a word the role of a polar coordinate (Heidenhain ISO's
    /// `G11 R+20 H+30`: R is the polar radius there, an arc's radius elsewhere).
    fn polar_roles(&mut self) {
        if let Some(c) = self.active_motion_code() {
            let def = self.code(c);
            for &(from, to) in &def.args {
                if matches!(to, Role::PolarRadius | Role::PolarAngle) && self.slots[to as usize].is_none() {
                    if let Some(s) = self.slots[from as usize].take() {
                        self.slots[to as usize] = Some(s);
                        self.filled |= 1 << to as u32;
                    }
                }
            }
        }
    }

    /// `X1=10`: a linear axis or A/B named by its machine axis name (SINUMERIK: X1, Y1, Z1 by
    /// default), read as that axis. G74 and G75 name axes so (their values ignored); in any
    /// other block, whether the value is in the machine's frame or the work's is the
    /// machine's configuration (channel and machine axis names), so the move is said to be
    /// unknown and a translation refuses. C's numbered names (`C4=120`, a spindle as an axis)
    /// are channel axes, read as ever.
    fn machine_axis_name(&mut self, block: &Block, role: Role, range: TextRange, diags: &mut Vec<Diagnostic>) {
        if !matches!(role, Role::X | Role::Y | Role::Z | Role::A | Role::B) {
            return;
        }
        let t = block.text(range).as_bytes();
        let digits = t.iter().skip(1).take_while(|c| c.is_ascii_digit()).count();
        if digits == 0 || t.get(1 + digits) != Some(&b'=') {
            return;
        }
        if self.codes.iter().any(|&(c, _)| matches!(self.code(c).meaning, Meaning::ReferenceApproach | Meaning::FixedPointApproach)) {
            return;
        }
        let shown = block.text(range).to_owned();
        let d = motion_unknown(&shown, "an axis by its machine axis name, whose frame the machine's configuration sets", range);
        self.limited(diags, "motion-unknown", d);
    }

    /// Fanuc `G16` (polar coordinate command) in force, or set by this block, and not ended by
    /// its `G15`: the move's or hole's first axis word of the plane is the radius, the second
    /// the angle (in G17, X the radius and Y the angle), about the work origin (Fanuc 0i-MF
    /// operator's manual, "Polar coordinate command (G15, G16)"). The block's own G90 / G91
    /// decides: an incremental angle with the radius omitted adds to the angle of the current
    /// position about the work origin (the manual's bolt circle `G91 Y120.`); an incremental
    /// radius makes the current position the pole, which is not modelled and is said so (a
    /// translation refuses). The axis words of a code that takes them itself (`G04`, `G10`,
    /// `G52`, `G92`, `G68`, `G51`: the dictionary's parameters) and of a block in machine
    /// coordinates (`G53`) are not polar (the manual's limitations); a reference return's
    /// intermediate point (`G28`, `G30`) under G16 the manual does not settle, so it is said
    /// and refused rather than guessed.
    fn polar_command_words(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) {
        let has = |s: &Self, m: Meaning| s.codes.iter().any(|&(k, _)| s.code(k).meaning == m);
        if !(has(self, Meaning::Polar) || (self.st.polar_command && !has(self, Meaning::PolarOff))) {
            return;
        }
        let (a0, a1, _) = self.st.plane.axes();
        let (r, a) = (Role::AXES[a0], Role::AXES[a1]);
        let given = |s: &Self, role: Role| s.slots[role as usize].is_some();
        if !given(self, r) && !given(self, a) {
            return;
        }
        let refuse = |s: &mut Self, diags: &mut Vec<Diagnostic>, why: &str| {
            let d = motion_unknown(block.text(block.range).trim(), why, block.range);
            s.limited(diags, "motion-unknown", d);
        };
        if has(self, Meaning::Home1) || has(self, Meaning::Home2) {
            refuse(
                self,
                diags,
                "a reference return's intermediate point under the polar coordinate command, which the manual does not say is polar or not",
            );
            return;
        }
        if has(self, Meaning::MachineCoords) || has(self, Meaning::MachineBuilderCoords) {
            return;
        }
        let Some(c) = self.active_motion_code() else { return };
        let m = self.code(c).meaning;
        if !(matches!(m, Meaning::Rapid | Meaning::Linear | Meaning::ArcCw | Meaning::ArcCcw) || m.is_cycle()) {
            return;
        }
        // The distance mode this block moves in: the word's own, else the block's G90 / G91,
        // else the one in force.
        let block_mode = self.codes.iter().rev().find_map(|&(k, _)| match self.code(k).meaning {
            Meaning::DistanceAbsolute => Some(false),
            Meaning::DistanceIncremental => Some(true),
            _ => None,
        });
        let incremental = |s: &Self, role: Role| match s.slots[role as usize].map(|w| w.mode) {
            Some(WordMode::Absolute) => false,
            Some(WordMode::Incremental) => true,
            _ => block_mode.unwrap_or(s.st.distance == DistanceMode::Incremental),
        };
        if given(self, r) && incremental(self, r) {
            refuse(self, diags, "an incremental polar radius: the pole at the current position, the angle from the previous one");
            return;
        }
        for (from, to) in [(r, Role::PolarRadius), (a, Role::PolarAngle)] {
            if let Some(s) = self.slots[from as usize].take() {
                self.slots[to as usize] = Some(s);
                self.filled |= 1 << to as u32;
            }
        }
    }

    /// SINUMERIK `G75 FP=n`: the fixed point is 1 to 4 (840D sl programming manual, "Fixed
    /// point approach"); another number the control alarms on, so it is an error at the word,
    /// not a guess at fixed point 1.
    fn fixed_point_number(&mut self, diags: &mut Vec<Diagnostic>) {
        if !self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::FixedPointApproach) {
            return;
        }
        let Some(s) = self.slots[Role::P as usize] else { return };
        if s.value.fract() == 0.0 && (1.0..=4.0).contains(&s.value) {
            return;
        }
        let msg = format!("fixed point {}: the fixed point approach takes 1 to 4; the control alarms on another number", s.value);
        self.limited(diags, "bad-value", Diagnostic::new(Code::BadValue, s.range, msg));
    }

    /// Adds code `idx` to the block's codes; false (with a diagnostic) when its group already has one.
    fn push_code(&mut self, idx: usize, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        let def = self.code(idx);
        // A bare axis letter in a cycle's definition (TNC `CYCL DEF 8.1 X Y`, the axes cycle 8
        // mirrors) names an axis of the cycle, which reads it from the block: not the tool
        // axis the letter gives after `TOOL CALL 1 Z`.
        if def.keyword.is_some()
            && matches!(def.meaning, Meaning::PlaneXy | Meaning::PlaneXz | Meaning::PlaneYz)
            && self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::CycleDefine)
        {
            return true;
        }
        if let Some(k) = self.codes.iter().position(|(c, _)| self.code(*c).group == def.group) {
            let other = self.codes[k].0;
            if def.gives_way {
                return true;
            }
            if self.code(other).gives_way {
                self.codes[k] = (idx, range);
                return true;
            }
            // `M2=5 M3=5 M5`: each spindle's code, where a block addresses spindles by number
            // (Siemens 840D: stop spindles 2, 3 and the master together). The analysis follows
            // one spindle a block: the first is read, the others kept as intent.
            if self.numbered_spindles && def.letter == 'M' && self.code(other).letter == 'M' {
                diags.push(Diagnostic::new(
                    Code::Unmodelled,
                    range,
                    format!(
                        "{} beside {}: this block addresses several spindles by number, each its own code; ncplan follows the first spindle of a block, so {} is kept as intent",
                        def.label(),
                        self.code(other).label(),
                        def.label()
                    ),
                ));
                return true;
            }
            // `G91 G28 X0 Y0 Z100. G90`: where the control's manual says the last G code of a
            // group in a block is the one in effect, it is, with a note.
            if self.dialect.behaviour.same_group_last_wins && def.letter == 'G' && self.code(other).letter == 'G' {
                diags.push(Diagnostic::new(
                    Code::ModalGroupLastWins,
                    range,
                    format!(
                        "{} and {} are both in modal group `{}`: the control takes the last, {}",
                        self.code(other).label(),
                        def.label(),
                        self.dialect.groups[def.group].id,
                        def.label()
                    ),
                ));
                self.codes[k] = (idx, range);
                return true;
            }
            diags.push(Diagnostic::new(
                Code::ModalGroupConflict,
                range,
                format!(
                    "{} and {} are both in modal group `{}`; a block may hold only one",
                    self.code(other).label(),
                    def.label(),
                    self.dialect.groups[def.group].id
                ),
            ));
            return false;
        }
        self.codes.push((idx, range));
        self.code_steps |= 1 << self.dialect.groups[def.group].step as u32;
        true
    }

    /// A quoted value: a tool name (`T="DRILL_8"`) becomes the number the tool table gives
    /// it, or a number from 10001 on in the order names first appear.
    fn text_value(&mut self, block: &Block, role: Role, r: TextRange, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<f64> {
        let name = block.text(r);
        if role == Role::Extra {
            return Some(0.0); // a name the engine only records (`LBL "NAME"`)
        }
        if role != Role::T {
            diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("\"{name}\" is text; this address takes a number")));
            return None;
        }
        if let Some((&n, _)) = self.profile.tools.iter().find(|(_, t)| t.name.as_deref().is_some_and(|t| t.eq_ignore_ascii_case(name))) {
            return Some(f64::from(n));
        }
        let k = match self.tool_names.iter().position(|t| t.eq_ignore_ascii_case(name)) {
            Some(k) => k,
            None => {
                self.tool_names.push(name.to_owned());
                self.tool_names.len() - 1
            }
        };
        Some(10_001.0 + k as f64)
    }

    /// A word's value: its number, or its expression evaluated; `None`, with the finding,
    /// for text or an expression without a finite value.
    pub(super) fn value(&mut self, block: &Block, v: Value, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<f64> {
        match v {
            Value::Number { value, .. } => Some(value),
            Value::Text(_) => {
                diags.push(Diagnostic::new(Code::MalformedNumber, range, "text where a number is needed"));
                None
            }
            Value::Expr(e) => match self.eval(block, e, range, diags) {
                Ok(x) if x.is_finite() || (eval::is_null(x) && self.dialect.macros.null_value) || eval::is_unknown(x) => Some(x),
                Ok(_) => {
                    diags.push(Diagnostic::new(Code::ArithmeticError, range, "the expression has no finite value"));
                    None
                }
                Err(err) => {
                    diags.push(self.eval_diag(err, range));
                    None
                }
            },
        }
    }

    /// Checks that the block's codes have the words they need and no others they exclude,
    /// and says which words no command of the block takes. False when one is missing.
    fn check_params(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        let mut ok = true;
        // A word whose value is unknown is there on the machine: it meets the requirement.
        let present = |s: &Self, r: Role| s.slots[r as usize].is_some() || s.word_unknown(r);
        let has_axes = self.has_axes;
        for &(c, range) in &self.codes {
            let def = self.code(c);
            let is_motion = self.dialect.groups[def.group].step == Step::Motion;
            for &r in &def.params.required {
                if !present(self, r) {
                    diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs {}", def.label(), self.address_name(r))));
                    ok = false;
                }
            }
            for set in &def.params.any_of {
                if !set.iter().any(|&r| present(self, r)) && (!is_motion || has_axes) {
                    let names: Vec<_> = set.iter().map(|&r| self.address_name(r)).collect();
                    diags.push(Diagnostic::new(
                        Code::MissingParameter,
                        range,
                        format!("{} needs one of {}", def.label(), names.join(", ")),
                    ));
                    ok = false;
                }
            }
            for (a, b) in &def.params.exclusive {
                if a.iter().any(|&r| present(self, r)) && b.iter().any(|&r| present(self, r)) {
                    let an: Vec<_> = a.iter().map(|&r| self.address_name(r)).collect();
                    let bn: Vec<_> = b.iter().map(|&r| self.address_name(r)).collect();
                    diags.push(Diagnostic::new(
                        Code::MissingParameter,
                        range,
                        format!("{} mixes {} with {}", def.label(), an.join(" "), bn.join(" ")),
                    ));
                    ok = false;
                }
            }
        }
        // Words that no command in this block takes.
        let mut motion = None;
        for w in &block.words {
            if !matches!(w.role, Role::P | Role::Q | Role::L | Role::R | Role::I | Role::J | Role::K | Role::H | Role::D | Role::E) {
                continue;
            }
            // The centre words set the pole in any block.
            if self.dialect.behaviour.arc_centres_pole && matches!(w.role, Role::I | Role::J | Role::K) {
                continue;
            }
            let motion = *motion.get_or_insert_with(|| self.active_motion_code());
            // A keyword code takes the value it is written with (`SPOS=90`).
            let takes = |c: &CodeDef, r: Role| c.params.takes(r) || c.keyword.as_ref().is_some_and(|k| k.value_role == Some(r));
            let taken = self.codes.iter().any(|&(c, _)| takes(self.code(c), w.role)) || motion.is_some_and(|c| takes(self.code(c), w.role));
            // A code kept as intent takes the words no modelled command does (`M101 P1 Q2`).
            if !taken && !self.intent_words {
                let shown = block.text(w.range);
                let d =
                    Diagnostic::new(Code::UnusedWord, w.range, format!("`{shown}`: no command in this block takes {}", w.letter as char));
                diags.push(self.unused(d));
            }
        }
        ok
    }

    fn address_name(&self, role: Role) -> String {
        self.dialect.addresses.iter().find(|a| a.role == role).map_or_else(|| role.as_str().to_owned(), |a| a.name.clone())
    }

    /// The motion code this block executes: explicit, or the modal one when axes are given
    /// and no other code claims them: one whose meaning uses axis words, or whose parameters
    /// list an axis word the block has (`G4 X1.5`, `G51 A45 E0.002`).
    pub(super) fn active_motion_code(&self) -> Option<usize> {
        if let Some(&(c, _)) = self.codes.iter().find(|(c, _)| self.dialect.groups[self.code(*c).group].step == Step::Motion) {
            return Some(c);
        }
        let claimed = self.codes.iter().any(|&(c, _)| {
            matches!(
                self.code(c).meaning,
                Meaning::SetData
                    | Meaning::ModalMacroCall
                    | Meaning::LengthCompDynamic
                    | Meaning::Home1
                    | Meaning::Home2
                    | Meaning::ReferenceApproach
                    | Meaning::FixedPointApproach
                    | Meaning::OriginShift
                    | Meaning::LocalOffset
                    | Meaning::Scaling
                    | Meaning::Rotation
                    | Meaning::Pole
                    | Meaning::PoleKeeping
                    | Meaning::CycleDefine
                    | Meaning::FrameTrans
                    | Meaning::FrameTransAdd
                    | Meaning::FrameRot
                    | Meaning::FrameRotAdd
                    | Meaning::FrameScale
                    | Meaning::FrameScaleAdd
                    | Meaning::FrameMirror
                    | Meaning::FrameMirrorAdd
                    | Meaning::Mirror
                    | Meaning::MirrorAboutZero
                    | Meaning::MirrorCancel
                    | Meaning::Stock
                    | Meaning::CycleIntent
                    | Meaning::CycleTurnIntent
            ) || (self.dialect.groups[self.code(c).group].step != Step::Motion && self.claims_axes(c))
        });
        if self.has_axes && !claimed { self.st.motion_code } else { None }
    }

    /// Whether code `c` takes one of the axis words the block has, a mill's quill `W` among
    /// them (`G28 W0`, `G92 W2`, `G10 L20 P1 W5`: the dictionary lists W for those codes).
    pub(super) fn claims_axes(&self, c: usize) -> bool {
        Role::AXES.iter().chain(&[Role::W]).any(|&r| self.slots[r as usize].is_some() && self.code(c).params.takes(r))
    }

    /// A word whose value is unknown: omitted, as a vacant one is, so that a move keeps its
    /// known axes; said once per block.
    fn unknown_word(&mut self, block: &Block, range: TextRange, diags: &mut Vec<Diagnostic>) -> String {
        self.unknown_words += 1;
        let shown = block.text(range).to_owned();
        let what = self.unknown_what();
        let msg = format!("`{shown}` reads {what}; the word is left out and the block keeps its known words");
        let mut d = Diagnostic::new(Code::UnknownValue, range, msg);
        if !self.is_called() {
            d.severity = Severity::Warning;
        }
        self.limited(diags, "unknown-value", d);
        what
    }

    /// The axis an axis variable names (`AX[_X]=10` after `DEF AXIS _X=X`); none, with a
    /// note, when its value comes from outside the file (a `PROC`'s `AXIS` argument) or is
    /// no axis.
    fn axis_by_variable(
        &mut self,
        block: &Block,
        index: crate::syntax::ExprId,
        range: TextRange,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<u8> {
        // An undeclared name is said once, by the note below.
        let mut read = Vec::new();
        let v = match self.eval(block, index, range, &mut read) {
            Ok(v) => v,
            Err(e) => {
                diags.append(&mut read);
                diags.push(self.eval_diag(e, range));
                return None;
            }
        };
        if !eval::is_unknown(v) {
            diags.append(&mut read);
        }
        if let Some(letter) = crate::syntax::axis_of(v).filter(|&c| self.dialect.letter_role(c).is_some_and(|r| r.is_axis())) {
            return Some(letter);
        }
        let shown = block.text(range).trim();
        // The name with its index (`AX[_X]`), without the value.
        let shown = shown.find(']').map_or(shown, |i| &shown[..=i]).to_owned();
        if eval::is_unknown(v) {
            let what = self.unknown_what();
            let msg = format!("`{shown}` names its axis by {what}: the move along it is left out");
            self.limited(diags, "unknown-value", Diagnostic::new(Code::UnknownValue, range, msg));
        } else {
            let msg = format!("`{shown}`: the variable holds no axis here; the word is left out");
            let mut d = Diagnostic::new(Code::BadValue, range, msg);
            d.severity = Severity::Warning;
            self.limited(diags, "axis-variable", d);
        }
        None
    }
}

/// Whether a keyword word naming code `c` of `d` (`c` < the number of codes), with its value
/// as the extra word, is an inert code ([`Interpreter::inert_code_words`]): a code that means
/// nothing to execute (Heidenhain's `FN`, whose arithmetic or jump the block's assignment or
/// statement carries), takes its value as the extra word, needs no other word, and is not a
/// motion mode; and the extra word is not scaled as a least increment (that goes the general
/// way). Asked once for each code of the dictionary.
pub(super) fn inert_keyword(d: &Dialect, profile: &super::Profile, c: usize) -> bool {
    let def = &d.codes[c];
    let inert = def.meaning == Meaning::Other
        && def.keyword.as_ref().is_some_and(|k| k.value_role == Some(Role::Extra))
        && def.args.is_empty()
        && def.params.required.is_empty()
        && def.params.any_of.is_empty()
        && def.params.exclusive.is_empty()
        && d.groups[def.group].step != Step::Motion;
    // A value scaled as a least increment goes the general way.
    let scaled = !profile.calculator_input
        && matches!(&d.behaviour.decimal_input, DecimalInput::LeastIncrement { scaled, .. } if scaled.contains(&Role::Extra));
    inert && !scaled
}

/// The finding of code `shown`, whose documented effect (`what`) moves the machine in a way
/// ncplan does not model (`moves="true"` in the dictionary): the toolpath after it is not
/// known, and a translation refuses rather than drop the motion.
pub(super) fn motion_unknown(shown: &str, what: &str, range: TextRange) -> Diagnostic {
    Diagnostic::new(
        Code::MotionUnknown,
        range,
        format!("`{shown}` ({what}) moves the machine, and ncplan does not model that motion: the toolpath after it is not known"),
    )
}
