//! Typed statement changes: a differing statement told by what its words do, where the plan
//! does not show it (a subprogram run with unknown parameters, an empty plan, a change the
//! plan's comparison folds away).
//!
//! Each differing word is looked up in the dictionary: its code's meaning (`M8`:
//! coolant-flood, `G4`: dwell, `G18`: plane-xz) or its address's role (`F`: feed, `H`:
//! length offset). The statement's other codes give the words their sense: after a dwell code
//! the `F`, `P` or `X` word is the dwell's time, not a feed or a position; in a canned cycle's
//! block `R`, `Q`, `P` are its parameters and `Z` its depth. A named cycle's arguments (`CYCLE81`)
//! and the parameters a cycle reads by number (Heidenhain `Q200`) are its parameters, named as
//! the dictionary names them. The words of one kind in one statement make one change of that
//! kind (`G4 F0.1` added is one dwell added); what the dictionary says nothing about (axis
//! words the plan tells, variables, jumps) is left to the statement change. A move whose axis
//! words read variables is the moves, the plan not seeing where they go; an axis word is also
//! one written with `=` (`Z=INI[108]`) or a name the dictionary indexes by the axis it moves
//! (`AX[AXIVER]=…`). A machine function the plan has no kind for is named by the dictionary:
//! a G or M code (`M66`), a keyword code (`DRFOF`), a procedure (`FGROUP(…)`) of such a
//! meaning, or a code the dictionary does not model but its vocabulary documents (`G112`).

use super::ChangeKind;
use super::statement::{Sort, Token};
use crate::dialect::{DataForm, Dialect, Meaning, Role};

/// What a token is about, by the dictionary: its code's meaning (`M8`: coolant-flood, `RL`:
/// comp-left) or its address's role (`F`: feed).
#[derive(Clone, Copy, PartialEq)]
pub(super) enum About {
    Code(Meaning),
    Address(Role),
    Unknown,
}

pub(super) fn about(tok: &Token, d: &Dialect) -> About {
    let k = tok.key.as_str();
    // A word alone without a value is a keyword before an address of the same letter
    // (Heidenhain `L X+10`: the straight line, not the length `L+0` of `TOOL DEF`).
    if tok.value.is_empty()
        && tok.sort == Sort::Other
        && let Some((i, _)) = d.keyword_codes().find(|(_, spec)| spec.text == k)
    {
        return About::Code(d.codes[i].meaning);
    }
    // A G or M code: the token's key is the code (`G43`, `M8`).
    if let Some(letter @ ('G' | 'M')) = k.chars().next()
        && let Ok(n) = k[1..].parse::<f64>()
    {
        return d.code(letter, (n * 10.0).round().max(0.0) as u32).map_or(About::Unknown, |c| About::Code(c.meaning));
    }
    if let Some(a) = d.addresses.iter().find(|a| a.name == k) {
        return About::Address(a.role);
    }
    // A keyword code (`FMAX`, `RL`, `TOOL CALL`), by its first word.
    d.keyword_codes()
        .find(|(_, spec)| spec.text.split(' ').next() == Some(k))
        .map_or(About::Unknown, |(i, _)| About::Code(d.codes[i].meaning))
}

/// Whether an assignment sets a variable, not an address written with `=`: a key shaped
/// like an address (`CR=5`, `RND=2`: up to three letters) that the dictionary names no
/// address or code is the program's own variable (Siemens `DEF REAL WR` … `WR=286.43`).
pub(super) fn sets_variable(tok: &Token, d: &Dialect) -> bool {
    tok.sort == Sort::Assign && (!tok.is_address() || (tok.key.len() >= 2 && about(tok, d) == About::Unknown)) && !axis_indexed_move(tok, d)
}

/// The codes a statement's tokens name that give its other words their sense.
#[derive(Clone, Copy, Default, PartialEq)]
pub(super) struct Context {
    /// A dwell code (`G4`): its time word is the dwell.
    pub dwell: bool,
    /// A canned cycle's code (`G81`): `R`, `Q`, `P` are its parameters, `Z` its depth.
    pub cycle: bool,
    /// Another cycle's code (`G76` threading, a lathe's `G71`): its words but the end point
    /// and feed are its parameters.
    pub other_cycle: bool,
    /// Constant surface speed (`G96 D2500 S200`): its other word is the speed limit.
    pub css: bool,
    /// An override switch (`M50 P0`): its `P` is the switch.
    pub switch: bool,
    /// A shift of the origin (`CYCL DEF 7.1 X+10`, `G52`): its axis words are the shift.
    pub shift: bool,
    /// A dynamic length offset (`G43.1 Z…`): its axis words are the offset.
    pub length: bool,
    /// A data-setting code (`G10 L2`) and what its `L` value sets, by the dictionary.
    pub data: Option<DataForm>,
    /// A legacy cycle's sub-block (`CYCL DEF 1.2 DEPTH -15`): its value is that argument.
    pub legacy: bool,
    /// Moves whose axis words read variables (`G0 Z#7`): what the plan may not see.
    pub moves_by_variables: bool,
    /// A machine function the plan has no kind for (`M66 P1 L3`, `G64 P0.01`, a builder's
    /// `M88`): its other words are that function's.
    pub function: bool,
    /// That function's code: its letter and number × 10 (`M66`: `('M', 660)`).
    pub function_code: Option<(char, u32)>,
    /// What the statement decides about which blocks run, if it is a control-flow statement.
    pub flow: Option<super::control::Flow>,
    /// A macro call (`G65 P9810 F200.`, `G66`): its letters are the macro's arguments (locals
    /// of the macro), never the modal feed, speed, tool or axes, whether the macro is found or not.
    pub macro_call: bool,
    /// A rapid (`G0`) on a mill, with no plane code in the statement: its `Z` is the height the
    /// tool goes to between cuts or before the first (clearance, approach).
    pub rapid: bool,
    /// A probing move (`G38.2`, `G31`): its axis words are where the probe goes until it
    /// touches, its `F` the probing feed.
    pub probe: bool,
    /// A lathe cycle's code whose words the dictionary gives roles (`args`, Haas `G71 … D`):
    /// its letter and number × 10 (`diff::turning::cycle_role`).
    pub turn_cycle: Option<(char, u32)>,
    /// What the blocks around the statement make of it (`diff::around`): the move before a
    /// lathe cycle (its start point), a block of the contour a cycle names by `P` and `Q`.
    pub around: Option<super::around::Around>,
    /// A touch probe's measuring cycle, by the dictionary (`probe="true"`, `probe-programs`):
    /// Renishaw's `G65 P9810 Z-5. F3000.`, Heidenhain `TCH PROBE 430` with its Q parameters,
    /// Siemens `CYCLE977(…)`: its words and parameters are the probing's.
    pub probe_cycle: bool,
    /// A parameter function's keyword code (`FN 17: SYSWRITE`): the statement is that function.
    pub function_keyword: Option<usize>,
}

/// Whether a token names a touch probe's measuring cycle by the dictionary: a cycle called by
/// name (`CYCLE977(…)`) or a keyword code (`TCH PROBE`) it marks `probe="true"`, or, in a macro
/// call, the number of a program it lists in `probe-programs` (`G65 P9810`).
pub(super) fn probing(t: &Token, macro_call: bool, d: &Dialect) -> bool {
    match t.sort {
        Sort::Call => d.cycles.iter().any(|c| c.probe && c.name.eq_ignore_ascii_case(&t.key)),
        Sort::Word if macro_call && t.key == "P" => {
            t.value.parse::<u32>().is_ok_and(|n| d.macros.probe_programs.iter().any(|&(a, b)| (a..=b).contains(&n)))
        }
        Sort::Other => d
            .keyword_codes()
            .any(|(i, spec)| d.codes[i].probe && (spec.text == t.key || spec.text.split(' ').next() == Some(t.key.as_str()))),
        _ => false,
    }
}

/// Whether a code shifts the origin of the program's coordinates.
fn shifts(m: Meaning) -> bool {
    matches!(m, Meaning::LocalOffset | Meaning::OriginShift | Meaning::FrameTrans | Meaning::FrameTransAdd)
}

/// Whether a code is a cycle other than a drilling one, whose words are its parameters: the
/// lathe cycles that start where they are called ([`super::around::starts_where_called`]) but
/// the multiple-pass thread and the peck cycles (`G76`, `G74`/`G75` of system A, which count
/// only as lathe cycles below), and the profile, synchronised-spindle and rigid tapping codes.
fn other_cycle(m: Meaning) -> bool {
    use Meaning as M;
    (super::around::starts_where_called(m) && !matches!(m, M::CycleThreadMultiple | M::CycleGroove | M::CycleFacePeck))
        || matches!(m, M::ProfileFinish | M::ProfileRoughTurn | M::ProfileRoughFace | M::SpindleSync | M::RigidTap)
}

/// Whether a token is an axis or arc-centre word: an address and its value (`X10`), an axis
/// address given an expression with `=` (Siemens `Z=INI[108]`, `V=$AA_SOFTENDP[V]-1`: the 840D
/// sl programming manual, fundamentals, "axis address = expression"), or a name the dictionary
/// indexes by the axis it moves (`AX[AXIVER]=…`, `POS[X]=…`: `<axis-indexed meaning="axis-word">`).
pub(super) fn axis_word(tok: &Token, d: &Dialect) -> bool {
    use Role as R;
    let addressed = matches!(tok.sort, Sort::Word | Sort::Assign)
        && matches!(about(tok, d), About::Address(R::X | R::Y | R::Z | R::A | R::B | R::C | R::U | R::V | R::W | R::I | R::J | R::K));
    addressed || axis_indexed_move(tok, d)
}

/// Whether an assignment moves the axis a dictionary name is indexed by (Siemens `AX[X]=10`,
/// `AX[AXNAME(AXIS_EW)]=PROCESS[20]+2`, `POS[X]=0.2`), the parser's axis-indexed word, not a
/// variable of the program.
pub(super) fn axis_indexed_move(tok: &Token, d: &Dialect) -> bool {
    let Some((open, close)) = d.lexical.array_brackets else { return false };
    let name = tok.key.strip_suffix(char::from(close)).and_then(|k| k.split_once(char::from(open))).map(|(name, _)| name);
    tok.sort == Sort::Assign && name.is_some_and(|n| d.lexical.axis_indexed.iter().any(|a| a.moves && a.name.eq_ignore_ascii_case(n)))
}

/// Whether an axis word's value reads a variable: its expression names a parameter (`Z#7`,
/// `X=R1`, `Q5`), a user or system variable (`Z=INI[108]`, `V=$AA_SOFTENDP[V]-1`). A number
/// is none, nor is one inside a dimension function (Siemens `X=IC(10)`, `AC(…)`, `C=DC(90)`,
/// `ACP`/`ACN`: the 840D sl programming manual, fundamentals, "Absolute and incremental
/// dimensions" and "Absolute dimension for rotary axes": the number, absolute or incremental
/// for that word alone) or a function of numbers (`SIN(30)`): the plan reads those values.
fn by_variable(tok: &Token, d: &Dialect) -> bool {
    let v = tok.value.as_bytes();
    let sigil = d.lexical.parameter.map(|(s, _)| s);
    let mut i = 0;
    while i < v.len() {
        let c = v[i];
        if c == b'$' || sigil.is_some_and(|s| s.is_ascii() && !s.is_ascii_alphabetic() && c == s as u8) {
            return true;
        }
        let start = i;
        // A quoted constant (`'H1F'`, `'B1011'`): a number.
        if c == b'\'' {
            i += 1 + v[i + 1..].iter().position(|&b| b == b'\'').map_or(v.len() - i - 1, |k| k + 1);
            continue;
        }
        if c.is_ascii_digit() || c == b'.' {
            // A number, with its exponent if any (`1.5E3`, `10EX3`).
            while i < v.len() && (v[i].is_ascii_alphanumeric() || v[i] == b'.') {
                i += 1;
            }
            continue;
        }
        if !(c.is_ascii_alphabetic() || c == b'_') {
            i += 1;
            continue;
        }
        while i < v.len() && (v[i].is_ascii_alphanumeric() || v[i] == b'_') {
            i += 1;
        }
        let name = tok.value[start..i].to_ascii_uppercase();
        let wrapper =
            d.lexical.axis_modes.as_ref().is_some_and(|(abs, inc)| name.eq_ignore_ascii_case(abs) || name.eq_ignore_ascii_case(inc))
                || d.lexical.rotary_absolute.iter().any(|r| r.eq_ignore_ascii_case(&name));
        let function = crate::syntax::Func::named(&name).is_some() || crate::syntax::BinOp::named(&name).is_some();
        if !wrapper && !function {
            return true;
        }
    }
    false
}

/// The legacy cycle a `DEF n.m` token defines a sub-block of (`CYCL DEF 9.1`), by the
/// dictionary's cycle-define keyword and cycle numbers.
fn legacy_cycle<'d>(t: &Token, d: &'d Dialect) -> Option<&'d crate::dialect::CycleDef> {
    let (n, sub) = t.value.split_once('.')?;
    if sub.is_empty() || !sub.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let defines = d
        .keyword_codes()
        .any(|(i, spec)| d.codes[i].meaning == Meaning::CycleDefine && spec.text.split(' ').next_back() == Some(t.key.as_str()));
    defines.then(|| d.cycles.iter().find(|c| c.name == n)).flatten()
}

impl Context {
    /// The context of a statement's tokens.
    pub(super) fn of(tokens: &[Token], d: &Dialect) -> Context {
        let mut c = Context::default();
        if let Some(cycle) = tokens.iter().find_map(|t| legacy_cycle(t, d)) {
            c.dwell |= cycle.meaning == Meaning::Dwell;
            c.shift |= shifts(cycle.meaning);
            c.legacy = !c.dwell && !c.shift;
        }
        c.macro_call =
            tokens.iter().any(|t| t.sort == Sort::Word && matches!(about(t, d), About::Code(Meaning::MacroCall | Meaning::ModalMacroCall)));
        // A frame's or an origin shift's axis words are its values, no move (`AROT Z=ANGLE`).
        let no_motion = tokens.iter().any(|t| matches!(about(t, d), About::Code(m) if super::statement::words_are_no_motion(m)));
        c.moves_by_variables = !c.macro_call && !no_motion && tokens.iter().any(|t| axis_word(t, d) && by_variable(t, d));
        c.probe_cycle = tokens.iter().any(|t| probing(t, c.macro_call, d));
        c.function_keyword = tokens.iter().find_map(|t| super::function::code_after_number(t, d));
        c.flow = super::control::flow_of(tokens, d);
        let mill = !d.behaviour.x_diameter && d.behaviour.initial_plane == crate::canon::Plane::Xy;
        let codes = || tokens.iter().filter(|t| t.sort == Sort::Word).map(|t| about(t, d));
        c.rapid = mill
            && codes().any(|a| a == About::Code(Meaning::Rapid))
            && !codes().any(|a| matches!(a, About::Code(Meaning::PlaneXy | Meaning::PlaneXz | Meaning::PlaneYz)));
        // A keyword code that shifts the origin (Siemens `TRANS`, `ATRANS`): its axis words are the shift.
        c.shift |= tokens.iter().any(|t| t.sort == Sort::Other && matches!(about(t, d), About::Code(m) if shifts(m)));
        for t in tokens.iter().filter(|t| t.sort == Sort::Word) {
            let code = || t.key[1..].parse::<f64>().ok().map(|n| (t.key.chars().next().unwrap_or('M'), (n * 10.0).round() as u32));
            if about(t, d) == About::Unknown && (unknown_code(t) || documented_code(t, d).is_some()) {
                c.function = true;
                c.function_code = c.function_code.or_else(code);
            }
            if let About::Code(m) = about(t, d) {
                c.dwell |= m == Meaning::Dwell;
                c.probe |= matches!(m, Meaning::Probe | Meaning::ProbeQuiet);
                c.cycle |= m.is_cycle();
                c.other_cycle |= other_cycle(m);
                let lathe = other_cycle(m)
                    || super::around::starts_where_called(m)
                    || matches!(m, Meaning::CycleStockCorner | Meaning::CycleContourTurn | Meaning::CyclePartOff);
                if lathe && c.turn_cycle.is_none() {
                    c.turn_cycle = code().filter(|&(l, n)| d.code(l, n).is_some_and(|def| !def.args.is_empty()));
                }
                c.css |= m == Meaning::SpindleCss;
                c.switch |= matches!(m, Meaning::FeedOverrideSwitch | Meaning::SpeedOverrideSwitch);
                c.shift |= shifts(m);
                c.length |= m == Meaning::LengthCompDynamic;
                if machine_function(m) && numbered_code(t) {
                    c.function = true;
                    c.function_code = c.function_code.or_else(code);
                }
                if m == Meaning::SetData {
                    let l = tokens.iter().find(|t| t.key == "L").and_then(|t| t.value.parse::<f64>().ok());
                    let code = t.key[1..].parse::<f64>().ok().and_then(|n| d.code('G', (n * 10.0).round() as u32));
                    c.data = code.zip(l).and_then(|(code, l)| code.forms.iter().find(|f| f64::from(f.0) == l)).map(|f| f.1);
                }
            }
        }
        c
    }

    /// Whether the statement's codes give some of its words another sense than their letters'.
    pub(super) fn special(self) -> bool {
        self.dwell
            || self.cycle
            || self.other_cycle
            || self.css
            || self.switch
            || self.shift
            || self.length
            || self.legacy
            || self.function
            || self.data.is_some()
    }

    /// Both statements' contexts: a word removed from one and added to the other has either.
    pub(super) fn or(self, o: Context) -> Context {
        Context {
            dwell: self.dwell || o.dwell,
            cycle: self.cycle || o.cycle,
            other_cycle: self.other_cycle || o.other_cycle,
            css: self.css || o.css,
            switch: self.switch || o.switch,
            shift: self.shift || o.shift,
            length: self.length || o.length,
            data: self.data.or(o.data),
            legacy: self.legacy || o.legacy,
            moves_by_variables: self.moves_by_variables || o.moves_by_variables,
            function: self.function || o.function,
            function_code: self.function_code.or(o.function_code),
            flow: self.flow.or(o.flow),
            macro_call: self.macro_call || o.macro_call,
            rapid: self.rapid && o.rapid,
            probe: self.probe || o.probe,
            turn_cycle: self.turn_cycle.or(o.turn_cycle),
            around: self.around.or(o.around),
            probe_cycle: self.probe_cycle || o.probe_cycle,
            function_keyword: self.function_keyword.or(o.function_keyword),
        }
    }
}

/// A statement difference told by its kind: the kind, the field, and the words before and
/// after (empty where added or removed).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Typed {
    pub kind: ChangeKind,
    pub field: String,
    pub before: String,
    pub after: String,
}

/// The kind and field a differing word is about, in its statement's context; `None` for a
/// word the dictionary gives no machining sense to (an axis, a variable, a label).
pub(super) fn kind_of(tok: &Token, ctx: Context, d: &Dialect) -> Option<(ChangeKind, &'static str)> {
    use ChangeKind as K;
    use Meaning as M;
    use Role as R;
    if (!tok.is_address() && !axis_indexed_move(tok, d)) || tok.sort == Sort::Call {
        return None;
    }
    // A comment the control stops at (LinuxCNC `(abort, …)`): the program ends there.
    if tok.sort == Sort::Other && abort_comment(&tok.text, d) {
        return Some((K::StopAdded, "abort"));
    }
    // A legacy cycle's value, a number alone after its sub-block.
    if tok.sort == Sort::Other && tok.key.parse::<f64>().is_ok() && (ctx.dwell || ctx.legacy) {
        return Some(if ctx.dwell { (K::DwellChanged, "dwell") } else { (K::CycleParameterChanged, "cycle parameter") });
    }
    let a = about(tok, d);
    if let Some(k) = probe_cycle_kind(tok, a, ctx, d) {
        return Some(k);
    }
    // A macro call's letters (`G65 P9810 F200.`): arguments, told as the call's (and followed
    // into the macro where it is found), not as what the letter means outside a call.
    if ctx.macro_call && matches!(a, About::Address(_)) {
        return None;
    }
    // Moves the plan may not see, where their axis words read variables: the whole move.
    let motion = matches!(a, About::Code(M::Rapid | M::Linear | M::ArcCw | M::ArcCcw | M::Probe | M::ProbeQuiet));
    if let About::Address(r) = a
        && ctx.other_cycle
        && !matches!(r, R::X | R::Y | R::Z | R::U | R::W | R::F | R::S | R::T | R::G | R::M | R::N)
    {
        return Some((K::CycleParameterChanged, "cycle parameter"));
    }
    // A machine function's own words (`M66 P1 E0 L3`, `G64 P0.01`): that function's. An arc's
    // centre or radius words (`G91 G03 X… Y… I… J…`) are the arc's, not the distance mode's:
    // they are the function's only where the dictionary says its code takes them.
    if let About::Address(r) = a
        && ctx.function
        && !ctx.cycle
        && !ctx.other_cycle
        && !matches!(r, R::X | R::Y | R::Z | R::A | R::B | R::C | R::U | R::V | R::W | R::F | R::S | R::T | R::G | R::M | R::N)
        && (!matches!(r, R::I | R::J | R::K | R::R) || function_takes(ctx, r, d))
    {
        return Some((K::MachineFunctionChanged, "machine function"));
    }
    // The axis words of a shift, also written as assignments (Siemens `TRANS X=gX B=gB`).
    let assigned_axis = tok.sort == Sort::Assign && axis_word(&Token { sort: Sort::Word, ..tok.clone() }, d);
    if ctx.shift && (axis_word(tok, d) || assigned_axis) {
        return Some((K::WorkOffsetChanged, "origin shift"));
    }
    if ctx.switch && matches!(a, About::Address(R::P)) {
        return Some((K::FeedOverrideChanged, "feed override"));
    }
    if ctx.css && matches!(a, About::Address(R::D)) {
        return Some((K::SpindleSpeedChanged, "spindle speed limit"));
    }
    // A probing move's target, feed or code (`G38.2 Z-10 F100` → `G38.2 Z-15 F50`, `G38.2` →
    // `G38.3`): where the probe goes until it touches, and how fast (LinuxCNC G38.x, Fanuc
    // G31 skip function), told as the probing it is, not as a cut's feed or a toolpath.
    if ctx.probe && !ctx.cycle && !ctx.other_cycle && !ctx.macro_call {
        match a {
            About::Code(M::Probe | M::ProbeQuiet) => return Some((K::ProbingChanged, "probe move")),
            About::Address(R::F) => return Some((K::ProbingChanged, "probe feed")),
            _ if axis_word(tok, d) => return Some((K::ProbingChanged, "probe target")),
            _ => {}
        }
    }
    if let Some(k) = around_kind(tok, a, motion, ctx, d) {
        return Some(k);
    }
    if ctx.moves_by_variables && !ctx.cycle && !ctx.other_cycle && ctx.data.is_none() && !ctx.length && (motion || axis_word(tok, d)) {
        return Some((K::ToolpathChanged, "moves"));
    }
    Some(match a {
        About::Code(m) => match m {
            M::FeedInverseTime | M::FeedPerMinute | M::FeedPerRev => (K::FeedChanged, "feed mode"),
            M::SpindleCss | M::SpindleRpm | M::SpindleLimit => (K::SpindleModeChanged, "spindle mode"),
            M::SpindleCw | M::SpindleCcw | M::SpindleStop | M::SpindleOrient => (K::SpindleDirectionChanged, "spindle"),
            M::CoolantMist | M::CoolantFlood | M::CoolantOff => (K::CoolantChanged, "coolant"),
            M::LengthCompPlus | M::LengthCompDynamic | M::LengthCompMinus | M::LengthCompCancel => {
                (K::LengthOffsetChanged, "length offset")
            }
            M::CompOff | M::CompLeft | M::CompRight | M::CompLeftDiameter | M::CompRightDiameter => {
                (K::CutterCompChanged, "cutter compensation")
            }
            M::Wcs | M::WcsExtended => (K::WorkOffsetChanged, "work offset"),
            M::ProgramStop | M::OptionalStop => (K::StopAdded, "stop"),
            M::ProgramEnd | M::ProgramEndRewind => (K::StopAdded, "program end"),
            M::Dwell => (K::DwellChanged, "dwell"),
            M::OverridesOn | M::OverridesOff | M::FeedOverrideSwitch => (K::FeedOverrideChanged, "feed override"),
            M::ToolChange => (K::ToolRenamed, "tool"),
            M::PlaneXy | M::PlaneXz | M::PlaneYz => (K::PlaneChanged, "plane"),
            // A tilted working plane set or reset (`PLANE SPATIAL …`, `G68.2`, `PLANE RESET`),
            // where no plan row names it (no cut follows).
            M::TiltSpatial
            | M::TiltEuler
            | M::TiltEulerIncremental
            | M::TiltRollPitchYaw
            | M::TiltThreePoints
            | M::TiltTwoVectors
            | M::TiltProjectionAngles
            | M::TiltVector
            | M::TiltPoints
            | M::TiltProjected
            | M::TiltAxial
            | M::TiltToolAxis
            | M::TiltRelative
            | M::TiltReset => (K::WorkPlaneChanged, "work plane"),
            M::UnitsInch | M::UnitsMm => (K::UnitsChanged, "units"),
            M::RetractInitial | M::RetractR => (K::CycleParameterChanged, "cycle retract"),
            // A keyword frame (`TRANS`, `ATRANS`) with the shift its words state: one change.
            m if shifts(m) && tok.sort == Sort::Other => (K::WorkOffsetChanged, "origin shift"),
            // A G or M code, not a keyword's option (Heidenhain `PLANE … TURN MB MAX`).
            m if machine_function(m) && numbered_code(tok) => (K::MachineFunctionChanged, "machine function"),
            _ => return None,
        },
        About::Address(r) if ctx.dwell && matches!(r, R::F | R::P | R::X | R::U | R::DwellTime) => (K::DwellChanged, "dwell"),
        About::Address(r) if ctx.length && matches!(r, R::X | R::Y | R::Z | R::I | R::J | R::K) => {
            (K::LengthOffsetChanged, "length offset")
        }
        About::Address(r) if ctx.data.is_some() && !matches!(r, R::L | R::G) => data_kind(ctx.data?, r),
        About::Address(r) if ctx.cycle && matches!(r, R::R | R::Q | R::P | R::K) => (K::CycleParameterChanged, "cycle parameter"),
        About::Address(R::Z) if ctx.cycle => (K::DepthChanged, "hole depth"),
        // A rapid's height (`G0 G54 X0 Y0 Z0`): where the tool goes before or between cuts.
        About::Address(R::Z) if ctx.rapid && !ctx.special() && tok.sort == Sort::Word && !by_variable(tok, d) => {
            (K::ClearanceChanged, "rapid height")
        }
        About::Address(r) => match r {
            R::F => (K::FeedChanged, "feed"),
            R::PlungeFeed => (K::PlungeFeedChanged, "plunge feed"),
            R::S | R::SpindleLimit => (K::SpindleSpeedChanged, "spindle speed"),
            R::T | R::NextTool => (K::ToolRenamed, "tool"),
            R::H => (K::LengthOffsetChanged, "length offset"),
            R::D => (K::CutterCompChanged, "radius offset"),
            R::ToolEdge => (K::LengthOffsetChanged, "cutting edge (tool length and radius offsets)"),
            R::DwellTime => (K::DwellChanged, "dwell"),
            _ => return None,
        },
        About::Unknown if unknown_code(tok) || documented_code(tok, d).is_some() => (K::MachineFunctionChanged, "machine function"),
        About::Unknown => return None,
    })
}

/// A touch probe's measuring cycle (`G65 P9810 Z-5. F3000.`, `TCH PROBE 0.1 X+10`): its
/// target, feed, the cycle it runs and its other words (Renishaw Inspection Plus letters,
/// Heidenhain's cycle number), told as the probing they set.
fn probe_cycle_kind(tok: &Token, a: About, ctx: Context, d: &Dialect) -> Option<(ChangeKind, &'static str)> {
    use ChangeKind as K;
    if !ctx.probe_cycle {
        return None;
    }
    Some(match a {
        About::Address(Role::F) => (K::ProbingChanged, "probe feed"),
        _ if axis_word(tok, d) => (K::ProbingChanged, "probe target"),
        About::Address(_) if ctx.macro_call && tok.key == "P" => (K::ProbingChanged, "probing cycle"),
        About::Address(_) => (K::ProbingChanged, "probing parameter"),
        About::Unknown if tok.sort == Sort::Other && tok.key.parse::<f64>().is_ok() => (K::ProbingChanged, "probing cycle"),
        About::Code(Meaning::MacroCall | Meaning::ModalMacroCall) => (K::ProbingChanged, "probing cycle"),
        About::Code(_) if probing(tok, false, d) => (K::ProbingChanged, "probing cycle"),
        _ => return None,
    })
}

/// A lathe cycle's start point or contour, where the statement's own words do not say it
/// (`diff::around`: Fanuc/Haas G70–G76 start where the tool stands; P and Q name the contour).
fn around_kind(tok: &Token, a: About, motion: bool, ctx: Context, d: &Dialect) -> Option<(ChangeKind, &'static str)> {
    use super::around::Around;
    if ctx.special() || ctx.probe || ctx.macro_call {
        return None;
    }
    let position = axis_word(tok, d) && matches!(a, About::Address(Role::X | Role::Z | Role::U | Role::W));
    match ctx.around {
        Some(Around::ContourOf(_)) if motion || axis_word(tok, d) => Some((ChangeKind::ToolpathChanged, "contour")),
        Some(Around::StartOf(_)) if position => Some((ChangeKind::CycleParameterChanged, "start point")),
        _ => None,
    }
}

/// A machine function as a change names it: its code and the dictionary's name for it
/// (`machine function M66: wait on input`), or that the dictionary does not know it.
pub(super) fn function_field(ctx: Context, d: &Dialect) -> String {
    let Some((letter, n)) = ctx.function_code else { return "machine function".into() };
    let code = format!("{letter}{}", crate::diff::num(f64::from(n) / 10.0));
    match d.code(letter, n) {
        Some(def) if !def.name.is_empty() && def.name != def.meaning.as_str() => format!("machine function {code}: {}", def.name),
        Some(def) => format!("machine function {code}: {}", def.meaning.as_str().replace('-', " ")),
        // A code the control's manual documents that the engine does not model (Mazak `G112`):
        // what the vocabulary says it does.
        None => match d.vocabulary.code(letter, n) {
            Some(e) if !e.what.is_empty() => format!("machine function {code}: {}", e.what),
            _ => format!("machine function {code}: not in the dictionary"),
        },
    }
}

/// The vocabulary's entry for a numbered G or M code the dictionary does not model but the
/// control's manual documents (`<vocabulary>`: Mazak Integrex `G112`, the block's S and M words
/// on the milling spindle): a machine function the plan has no kind for.
fn documented_code<'d>(tok: &Token, d: &'d Dialect) -> Option<&'d crate::dialect::vocabulary::Entry> {
    if !numbered_code(tok) {
        return None;
    }
    let letter = tok.key.chars().next()?;
    let n = (tok.key[1..].parse::<f64>().ok()? * 10.0).round();
    if !(0.0..1e6).contains(&n) || d.code(letter, n as u32).is_some() {
        return None;
    }
    d.vocabulary.code(letter, n as u32)
}

/// A statement added or removed whole that calls a procedure the dictionary lists as a machine
/// function the plan has no kind for (Siemens `FGROUP(AX_HORI,AX_VER)`, `<cycle meaning="other">`:
/// the axes the path feed refers to): that function, named.
fn function_call(tok: &Token, d: &Dialect) -> Option<String> {
    let c = d.cycles.iter().find(|c| tok.sort == Sort::Call && c.name.eq_ignore_ascii_case(&tok.key))?;
    (machine_function(c.meaning) && !c.probe).then(|| format!("machine function {}", c.name.to_ascii_uppercase()))
}

/// A keyword code the dictionary gives a machine function the plan has no kind for (Siemens
/// `DRFOF`, handwheel offsets cleared): that function, by the dictionary's name for it.
fn keyword_function(tok: &Token, d: &Dialect) -> Option<String> {
    if tok.sort != Sort::Other || !tok.value.is_empty() {
        return None;
    }
    let (i, spec) = d.keyword_codes().find(|(_, spec)| spec.text == tok.key)?;
    let def = &d.codes[i];
    machine_function(def.meaning).then(|| {
        let name = if def.name.is_empty() { def.meaning.as_str().replace('-', " ") } else { def.name.clone() };
        format!("machine function {}: {name}", spec.text)
    })
}

/// Whether the statement's machine function takes words of `role` by the dictionary (LinuxCNC
/// `M66 P E L Q`): a code the dictionary does not know (a builder's `M88`) may take any.
fn function_takes(ctx: Context, role: Role, d: &Dialect) -> bool {
    ctx.function_code
        .and_then(|(l, n)| d.code(l, n))
        .is_none_or(|def| def.params.takes(role) || def.args.iter().any(|(from, _)| *from == role))
}

/// Whether a code's meaning is a machine function the plan has no kind for: what the
/// dictionary names but the plan does not model (an output, a wait on an input, the path
/// mode, the distance mode, the modal state saved or restored).
fn machine_function(m: Meaning) -> bool {
    use Meaning as M;
    matches!(
        m,
        M::Other
            | M::PathMode
            | M::DistanceAbsolute
            | M::DistanceIncremental
            | M::ArcDistanceAbsolute
            | M::ArcDistanceIncremental
            | M::DiameterMode
            | M::RadiusMode
            | M::StateSave
            | M::StateSaveAutorestore
            | M::StateInvalidate
            | M::StateRestore
    )
}

/// Whether a token is a numbered G or M code (`M66`, `G64`).
fn numbered_code(tok: &Token) -> bool {
    tok.sort == Sort::Word && matches!(tok.key.chars().next(), Some('G' | 'M')) && tok.key[1..].parse::<f64>().is_ok()
}

/// Whether a token is an M-code the dictionary does not know (a machine builder's `M88`).
fn unknown_code(tok: &Token) -> bool {
    tok.sort == Sort::Word && tok.key.starts_with('M') && tok.key.len() > 1 && tok.key[1..].bytes().all(|b| b.is_ascii_digit() || b == b'.')
}

/// The kind of a word of a data-setting statement: a work offset's values, a tool's length
/// or radius.
fn data_kind(form: DataForm, r: Role) -> (ChangeKind, &'static str) {
    use DataForm as F;
    match form {
        F::Wcs | F::WcsHere | F::WcsExtended => (ChangeKind::WorkOffsetChanged, "work offset data"),
        F::ToolRadius | F::ToolRadiusWear => (ChangeKind::CutterCompChanged, "tool radius data"),
        _ if r == Role::R => (ChangeKind::CutterCompChanged, "tool radius data"),
        _ => (ChangeKind::LengthOffsetChanged, "tool length data"),
    }
}

/// A write to a cutting edge's offset data through a system variable array the dictionary
/// names (`tool-data`: Siemens `$TC_DP4[t,d]=…`, length 2): the tool's length or radius
/// changed, naming the tool and edge its indices give (`tool BRSONDE, edge IVICA`), with the
/// variable it came through as written. Not such an array, or not indexed by exactly two
/// non-empty indices, tool and edge (`$TC_DP4[]`, `$TC_DP6[1,2,3]`): none, and the write is
/// told as the variable it is.
pub(super) fn tool_data(key: &str, d: &Dialect) -> Option<(ChangeKind, String)> {
    let (name, rest) = key.split_once('[')?;
    let name = name.trim().to_ascii_uppercase();
    let &(_, form) = d.macros.tool_data.iter().find(|(n, _)| *n == name)?;
    let index = rest.trim_end().strip_suffix(']')?;
    let indices: Vec<&str> = index.split(',').map(str::trim).collect();
    if indices.len() != 2 || indices.iter().any(|i| i.is_empty()) {
        return None;
    }
    let (kind, what) = match form {
        DataForm::ToolRadius => (ChangeKind::CutterCompChanged, "radius"),
        DataForm::ToolRadiusWear => (ChangeKind::CutterCompChanged, "radius wear"),
        DataForm::ToolLengthWear => (ChangeKind::LengthOffsetChanged, "length wear"),
        _ => (ChangeKind::LengthOffsetChanged, "length"),
    };
    let whose = format!("tool {}, edge {}", indices[0], indices[1]);
    // (The names after ` (via ` are kept as written: `ME_TOOL_NUMBER`.)
    Some((kind, format!("tool {what} (via {name}[{}]: {whose})", index.trim())))
}

/// The typed changes of one statement's token differences, and which differences they tell.
/// Words of one kind make one change: their texts joined, before and after.
pub(super) fn typed(diffs: &[(Option<Token>, Option<Token>)], ctx: Context, d: &Dialect) -> (Vec<Typed>, Vec<bool>) {
    use ChangeKind as K;
    if let Some(whole) = parameter_function(diffs, ctx.function_keyword, d) {
        return (vec![whole], vec![true; diffs.len()]);
    }
    if let Some(whole) = whole_statement(diffs, ctx, d) {
        return (vec![whole], vec![true; diffs.len()]);
    }
    // A probing cycle's statement added or removed whole (`G65 P9811 Z-5.`, `TCH PROBE 430 …`):
    // one change, with its words.
    let one_side = diffs.iter().all(|(x, _)| x.is_none()) || diffs.iter().all(|(_, y)| y.is_none());
    if ctx.probe_cycle && one_side && diffs.iter().any(|(x, y)| y.as_ref().or(x.as_ref()).is_some_and(|t| probing(t, ctx.macro_call, d))) {
        let text = |after: bool| {
            let side = |(x, y): &(Option<Token>, Option<Token>)| if after { y.clone() } else { x.clone() };
            diffs.iter().filter_map(side).map(|t| t.text).collect::<Vec<_>>().join(" ")
        };
        let t = Typed { kind: ChangeKind::ProbingChanged, field: "probing cycle".into(), before: text(false), after: text(true) };
        return (vec![t], vec![true; diffs.len()]);
    }
    let mut out: Vec<Typed> = Vec::new();
    let mut told = vec![false; diffs.len()];
    for (n, (x, y)) in diffs.iter().enumerate() {
        let tok = y.as_ref().or(x.as_ref()).expect("a difference has a side");
        // A turret's T word with the same tool and another offset (`T0101` → `T0111`).
        if let Some(t) = turret_offset(x.as_ref(), y.as_ref(), d) {
            told[n] = true;
            out.push(t);
            continue;
        }
        let (kind, field) = match (kind_of(tok, ctx, d), function_call(tok, d)) {
            (Some((kind, field)), _) => (kind, field.to_owned()),
            // (Its arguments changed in place are the call's own rows.)
            (None, Some(f)) if x.is_none() || y.is_none() => (ChangeKind::MachineFunctionChanged, f),
            _ => continue,
        };
        told[n] = true;
        // (A probe's target and its feed are told apart: `probe target`, `probe feed`.)
        let k = match out
            .iter()
            .position(|t| t.kind == kind && (!matches!(kind, K::ProbingChanged | K::MachineFunctionChanged) || t.field == field))
        {
            Some(k) => k,
            None => {
                out.push(Typed { kind, field, before: String::new(), after: String::new() });
                out.len() - 1
            }
        };
        let t = &mut out[k];
        for (side, tok) in [(&mut t.before, x), (&mut t.after, y)] {
            if let Some(tok) = tok {
                if !side.is_empty() {
                    side.push(' ');
                }
                side.push_str(&tok.text);
            }
        }
    }
    for t in &mut out {
        if t.kind == ChangeKind::MachineFunctionChanged && t.field == "machine function" {
            t.field = function_field(ctx, d);
        }
        // The cycle whose start point or contour it is (`start point of G76`).
        if let Some(super::around::Around::StartOf((l, n)) | super::around::Around::ContourOf((l, n))) = ctx.around
            && matches!(t.field.as_str(), "contour" | "start point")
        {
            t.field = format!("{} of {l}{}", t.field, crate::diff::num(f64::from(n) / 10.0));
        }
        // A stop added or removed is its own kind; one replaced by another stays `stop_added`
        // with both sides.
        if t.kind == ChangeKind::StopAdded && t.after.is_empty() {
            t.kind = ChangeKind::StopRemoved;
        }
    }
    (out, told)
}

/// The statement's change as its function's, where the function is a machine function the
/// plan has no kind for (a system datum or a table row written), or a read of data only the
/// machine has into a parameter (`FN 18: SYSREAD Q1600 = ID50 NR0 IDXQ1`, told whole as a
/// statement, not as the parameter set to `ID50`): the words that differ on each side.
fn parameter_function(diffs: &[(Option<Token>, Option<Token>)], code: Option<usize>, d: &Dialect) -> Option<Typed> {
    let (i, spec) = d.keyword_codes().find(|&(i, _)| Some(i) == code)?;
    let head = Token { key: spec.text.clone(), value: String::new(), text: spec.text.clone(), sort: Sort::Other };
    let (kind, field) = match keyword_function(&head, d) {
        Some(field) => (ChangeKind::MachineFunctionChanged, field),
        None if d.codes[i].meaning == crate::dialect::Meaning::MachineDataRead => (ChangeKind::StatementChanged, "statement".into()),
        None => return None,
    };
    let side = |after: bool| {
        let words = diffs.iter().filter_map(|(x, y)| if after { y.as_ref() } else { x.as_ref() });
        words.map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ")
    };
    Some(Typed { kind, field, before: side(false), after: side(true) })
}

/// A parameter function that writes or reads a tool table's column as system data by number
/// (Heidenhain `FN 17: SYSWRITE ID50 NR1 IDXQ2 = +0`, `FN 18: SYSREAD Q1601 = ID50 NR1 IDXQ1`:
/// group 50, the tool table, column NR of tool IDX; the dictionary's `tool-column`), told as
/// that column's change from the statements whole (`a`, `b`: each side's tokens, empty where
/// the statement is only on the other side): a write of a length or radius is the tool's
/// length offset or cutter compensation changed, any other column's the tool data changed,
/// with the column, the tool and the values; a read is the parameter it sets, named by what
/// it reads (a statement change: reading changes nothing on the machine).
pub(super) fn tool_column(a: &[Token], b: &[Token], code: Option<usize>, d: &Dialect) -> Option<Typed> {
    let (_, spec) = d.keyword_codes().find(|&(i, _)| Some(i) == code)?;
    if d.macros.tool_columns.is_empty() {
        return None;
    }
    let read = d.codes[code?].meaning == crate::dialect::Meaning::MachineDataRead;
    let keyword = spec.text.split(' ').next()?.to_ascii_uppercase();
    // `ID50 NR1 IDXQ2 = 0` (a write) or `Q1601 = ID50 NR1 IDXQ1` (a read): the group, the
    // column, the tool and the value written or the parameter read into.
    let parse = |t: &[Token]| -> Option<(u32, u32, String, String)> {
        let text: String = t.iter().map(|t| t.text.as_str()).collect::<String>().split_whitespace().collect();
        let at = text.to_ascii_uppercase().find(&keyword)? + keyword.len();
        let rest = &text[at..];
        let (target, other) = if read {
            let (param, target) = rest.split_once('=')?;
            (target, param)
        } else {
            rest.split_once('=')?
        };
        let up = target.to_ascii_uppercase();
        let digits = |s: &str| -> Option<(u32, usize)> {
            let n = s.bytes().take_while(u8::is_ascii_digit).count();
            Some((s[..n].parse().ok()?, n))
        };
        let after_id = up.strip_prefix("ID")?;
        let (group, n) = digits(after_id)?;
        let after_nr = after_id[n..].strip_prefix("NR")?;
        let (nr, n) = digits(after_nr)?;
        let idx_at = target.len() - after_nr[n..].len();
        let idx = match up[idx_at..].strip_prefix("IDX") {
            Some(_) => target[idx_at + 3..].to_owned(),
            None if idx_at == target.len() => String::new(),
            None => return None,
        };
        Some((group, nr, idx, other.to_owned()))
    };
    let (pa, pb) = (if a.is_empty() { None } else { Some(parse(a)?) }, if b.is_empty() { None } else { Some(parse(b)?) });
    let (group, nr, idx, _) = pb.clone().or(pa.clone())?;
    let column = |g: u32, nr: u32| d.macros.tool_columns.iter().find(|c| c.id == g && c.nr == nr);
    if !d.macros.tool_columns.iter().any(|c| c.id == group) {
        return None;
    }
    let col = column(group, nr);
    let of_tool = if idx.is_empty() { String::new() } else { format!(" of tool {idx}") };
    let named = col.map_or_else(
        || format!("tool table column NR{nr} (ID{group}){of_tool}"),
        |c| format!("tool table {} ({}, ID{group} NR{nr}){of_tool}", c.name, c.what),
    );
    // Both sides write the same entry: its values; else each side's entry and value.
    let same = pa.as_ref().zip(pb.as_ref()).is_none_or(|(x, y)| (x.0, x.1, &x.2) == (y.0, y.1, &y.2));
    let side = |p: &Option<(u32, u32, String, String)>| {
        p.as_ref().map_or_else(String::new, |(g, nr, idx, v)| {
            if same {
                v.clone()
            } else if read {
                format!("{v} = ID{g} NR{nr} IDX{idx}")
            } else {
                format!("ID{g} NR{nr} IDX{idx} = {v}")
            }
        })
    };
    let (before, after) = (side(&pa), side(&pb));
    if read {
        // `Q1600 read from tool table column NR0 (ID50) of tool Q1`, added or removed.
        let (field, before, after) = if same {
            let param = &pb.as_ref().or(pa.as_ref())?.3;
            let mark = |p: &Option<(u32, u32, String, String)>| p.as_ref().map_or_else(String::new, |_| "read".to_owned());
            (format!("{param} read from {named}"), mark(&pa), mark(&pb))
        } else {
            (format!("read from {named}"), before, after)
        };
        return Some(Typed { kind: ChangeKind::StatementChanged, field, before, after });
    }
    let kind = match col.and_then(|c| c.form) {
        Some(DataForm::ToolLength | DataForm::ToolLengthWear) => ChangeKind::LengthOffsetChanged,
        Some(DataForm::ToolRadius | DataForm::ToolRadiusWear) => ChangeKind::CutterCompChanged,
        _ => ChangeKind::ToolDataChanged,
    };
    Some(Typed { kind, field: named, before, after })
}

/// A write of a table's row by column names (the dictionary's `tool-table` write keyword:
/// Heidenhain `FN 27: TABWRITE 5/"L,R" = Q2`, row 5's columns L and R from Q2 on), told
/// whole from each side's statement (`a`, `b`: empty where the statement is only on the other
/// side) and the table each side opened last before it (`tables`, `FN 26: TABOPEN
/// TNC:\TOOL.T`). In the tool table (the dictionary's file, by name whatever the path) row n
/// is tool n, and its columns are the `tool-column`s of its group by name: a length written
/// is the tool's length offset changed, a radius its cutter compensation, any other column
/// the tool data. In another table, or where no table is opened before it, the write is told
/// as the machine function it is, naming the table, the row and the columns.
pub(super) fn table_write((a, b): (&[Token], &[Token]), tables: (Option<&str>, Option<&str>), d: &Dialect) -> Option<Typed> {
    let tt = d.macros.tool_table.as_ref()?;
    // `5/"L,R"=Q2`: the row, the columns and the values.
    let parse = |t: &[Token]| -> Option<(String, Vec<String>, String)> {
        let text: String = t.iter().map(|t| t.text.as_str()).collect::<String>().split_whitespace().collect();
        let at = text.to_ascii_uppercase().find(&tt.write)? + tt.write.len();
        let (target, value) = text[at..].split_once('=')?;
        let (row, cols) = target.split_once('/')?;
        let cols: Vec<String> =
            cols.trim_matches('"').split(',').map(|c| c.trim().to_ascii_uppercase()).filter(|c| !c.is_empty()).collect();
        Some((row.to_owned(), cols, value.to_owned()))
    };
    let (pa, pb) = (if a.is_empty() { None } else { Some(parse(a)?) }, if b.is_empty() { None } else { Some(parse(b)?) });
    let (row, cols, _) = pb.clone().or(pa.clone())?;
    let table = if pb.is_some() { tables.1 } else { tables.0 };
    // The file's name without its path (`TNC:\table\TOOL.T`).
    let name = |t: &str| t.rsplit(['\\', '/', ':']).next().unwrap_or(t).trim_matches('"').to_owned();
    let tool_table = table.is_some_and(|t| name(t).eq_ignore_ascii_case(&tt.file));
    let same = pa.as_ref().zip(pb.as_ref()).is_none_or(|(x, y)| (&x.0, &x.1) == (&y.0, &y.1));
    let side = |p: &Option<(String, Vec<String>, String)>| {
        p.as_ref().map_or_else(String::new, |(r, c, v)| if same { v.clone() } else { format!("{r}/\"{}\" = {v}", c.join(",")) })
    };
    let (before, after) = (side(&pa), side(&pb));
    if tool_table {
        let column = |c: &str| d.macros.tool_columns.iter().find(|k| k.id == tt.group && k.name.eq_ignore_ascii_case(c));
        let forms: Vec<Option<DataForm>> = cols.iter().map(|c| column(c).and_then(|k| k.form)).collect();
        let kind = if forms.iter().any(|f| matches!(f, Some(DataForm::ToolLength | DataForm::ToolLengthWear))) {
            ChangeKind::LengthOffsetChanged
        } else if forms.iter().any(|f| matches!(f, Some(DataForm::ToolRadius | DataForm::ToolRadiusWear))) {
            ChangeKind::CutterCompChanged
        } else {
            ChangeKind::ToolDataChanged
        };
        let named: Vec<String> = cols.iter().map(|c| column(c).map_or_else(|| c.clone(), |k| format!("{} ({})", k.name, k.what))).collect();
        let field = format!("tool table {} of tool {row}", named.join(", "));
        return Some(Typed { kind, field, before, after });
    }
    // Added or removed whole: the row and columns with the value.
    let whole = |p: &Option<(String, Vec<String>, String)>| {
        p.as_ref().map_or_else(String::new, |(r, c, v)| format!("{r}/\"{}\" = {v}", c.join(",")))
    };
    let (before, after) = if pa.is_some() && pb.is_some() { (before, after) } else { (whole(&pa), whole(&pb)) };
    let table = table.map_or_else(|| "a table not opened before it".to_owned(), |t| format!("table {}", name(t)));
    let code = d
        .keyword_codes()
        .find(|(_, spec)| spec.text.eq_ignore_ascii_case(&tt.write))
        .map_or(tt.write.as_str(), |(_, spec)| spec.text.as_str());
    let field = format!(
        "machine function {code}: write to {table}, row {row}, column{} {}",
        if cols.len() == 1 { "" } else { "s" },
        cols.join(",")
    );
    Some(Typed { kind: ChangeKind::MachineFunctionChanged, field, before, after })
}

/// A statement added or removed whole that a keyword code begins (`TOOL CALL 5 Z S3000`):
/// one change of that code's kind, with the statement's words.
fn whole_statement(diffs: &[(Option<Token>, Option<Token>)], ctx: Context, d: &Dialect) -> Option<Typed> {
    let added = diffs.iter().all(|(x, y)| x.is_none() && y.is_some());
    let removed = diffs.iter().all(|(x, y)| x.is_some() && y.is_none());
    let first = diffs.first().and_then(|(x, y)| y.as_ref().or(x.as_ref()))?;
    let keyword = first.sort == Sort::Other
        && first.value.is_empty()
        && d.keyword_codes().any(|(_, spec)| spec.text.split(' ').next() == Some(first.key.as_str()));
    if !(added || removed) || !keyword {
        return None;
    }
    // The longest keyword code the statement opens with: `PLANE SPATIAL …` is the spatial
    // tilt, not the bare `PLANE` the dictionary keeps for the other forms.
    let words: Vec<&Token> = diffs.iter().filter_map(|(x, y)| y.as_ref().or(x.as_ref())).collect();
    let opens = |spec: &crate::dialect::KeywordSpec| {
        let n = spec.text.split(' ').count();
        n <= words.len() && spec.text.split(' ').zip(&words).all(|(w, t)| t.sort == Sort::Other && t.value.is_empty() && t.key == w)
    };
    let longest = d.keyword_codes().filter(|(_, spec)| opens(spec)).max_by_key(|(_, spec)| spec.text.len());
    let head = longest.map(|(_, spec)| Token { key: spec.text.clone(), value: String::new(), text: spec.text.clone(), sort: Sort::Other });
    let head = head.as_ref().unwrap_or(first);
    let (kind, field) = match kind_of(head, ctx, d) {
        Some((kind, field)) => (kind, field.to_owned()),
        None => (ChangeKind::MachineFunctionChanged, keyword_function(head, d)?),
    };
    let text = diffs.iter().filter_map(|(x, y)| y.as_ref().or(x.as_ref())).map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ");
    let kind = if kind == ChangeKind::StopAdded && removed { ChangeKind::StopRemoved } else { kind };
    let (before, after) = if added { (String::new(), text) } else { (text, String::new()) };
    Some(Typed { kind, field, before, after })
}

/// The cycle a call token names (`CYCLE81(…)`) and its arguments' names, by the dictionary.
pub(super) fn cycle_args<'d>(name: &str, d: &'d Dialect) -> Option<&'d [crate::dialect::CycleArg]> {
    d.cycles.iter().find(|c| c.name.eq_ignore_ascii_case(name) && !c.args.is_empty()).map(|c| c.args.as_slice())
}

/// The cycle argument a numbered parameter feeds (Heidenhain `Q200`: the set-up clearance
/// of the 200 cycles), by the dictionary's `param=`; `None` for any other variable.
pub(super) fn cycle_param<'d>(key: &str, in_cycle: bool, d: &'d Dialect) -> Option<&'d crate::dialect::CycleArg> {
    let digits = key.trim_start_matches(|c: char| c.is_ascii_alphabetic());
    if digits.len() == key.len() || digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let n: u32 = digits.parse().ok()?;
    // Only a parameter spelt with the dictionary's parameter letter is one (`Q200`, not `R200`).
    let letter = &key[..key.len() - digits.len()];
    if !d.lexical.parameter.is_some_and(|(sigil, _)| letter.len() == 1 && letter.starts_with(sigil.to_ascii_uppercase())) {
        return None;
    }
    // A parameter in the ranges the dictionary leaves to the user and to other programs
    // (Heidenhain Q0-Q199, Q1400-Q1999: "free for users"; the cycles' transfer parameters are
    // Q200 and up) is a variable of the program's own: a legacy cycle that names a low number
    // (cycle 27's `Q1` depth) reads it only in its own definition's block (`in_cycle`).
    if !in_cycle && d.macros.outside.iter().any(|&(lo, hi)| (lo..=hi).contains(&n)) {
        return None;
    }
    d.cycles.iter().flat_map(|c| c.args.iter()).find(|a| a.param == Some(n))
}

/// The kind of change a named cycle's argument makes, by its role in the dictionary: a feed
/// (`FFP1` of `POCKET3`, `Q207` of cycle 251) is a feed change and a depth (`DP`, `Q201`) a
/// depth change, as the plan names them where it sees them; any other is a cycle parameter.
pub(super) fn arg_kind(role: Role) -> ChangeKind {
    match role {
        Role::F | Role::FinishFeed => ChangeKind::FeedChanged,
        Role::PlungeFeed => ChangeKind::PlungeFeedChanged,
        Role::Depth | Role::DepthRelative => ChangeKind::DepthChanged,
        _ => ChangeKind::CycleParameterChanged,
    }
}

/// A cycle argument's name as a planner reads it: `Q200 (safety distance)`.
pub(super) fn arg_name(arg: &crate::dialect::CycleArg) -> String {
    // The manuals' leading `_` of Siemens names (`_FFP1`) is no part of the name a planner reads.
    format!("{} ({})", arg.name.trim_start_matches('_'), arg.role.as_str().replace('-', " "))
}

/// The alignment of two argument lists: pairs of positions, one side `None` for an argument
/// inserted or removed. A plain position-by-position pairing unless an insertion or removal
/// explains more of the list (a longest common subsequence of the values).
pub(super) fn align_args(a: &[String], b: &[String]) -> Vec<(Option<usize>, Option<usize>)> {
    let positional: Vec<(Option<usize>, Option<usize>)> =
        (0..a.len().max(b.len())).map(|k| ((k < a.len()).then_some(k), (k < b.len()).then_some(k))).collect();
    if a.len() == b.len() {
        return positional;
    }
    let mut anchors = Vec::new();
    super::statement::lcs(a, b, 0, 0, &mut anchors);
    let same_in_place = (0..a.len().min(b.len())).filter(|&k| a[k] == b[k]).count();
    if anchors.len() <= same_in_place {
        return positional;
    }
    super::statement::pairs_along(anchors, a.len(), b.len())
}

/// Whether a token is a comment whose directive stops the program (`(abort, probe failed)`).
fn abort_comment(text: &str, d: &Dialect) -> bool {
    let t = text.trim();
    let Some(open) = d.lexical.comments.iter().find(|k| k.opens(t.as_bytes())) else { return false };
    let inner = &t[open.open_len()..];
    let inner = match open.close {
        crate::dialect::CommentClose::Char(c) => inner.strip_suffix(c).unwrap_or(inner),
        crate::dialect::CommentClose::Pair(a, b) => inner.strip_suffix(&format!("{a}{b}")[..]).unwrap_or(inner),
        _ => inner,
    };
    matches!(d.lexical.directive(inner.trim_start()), Some((crate::dialect::Directive::Abort, _)))
}

/// A lathe turret's T word whose last digits name the offset (Fanuc T-series `T0202`, the
/// dictionary's `offset-digits`), or, where the dictionary's tool address has `offset-suffix`
/// (Fagor `T2.2`), whose digits after the point name it: the same tool with another offset
/// (`T0101` → `T0111`, a wear offset of its own; `T1.1` → `T1.2`) is the tool's offset
/// changed, not the tool renamed. A word with the point and no digits after it (`T2.`) names
/// no offset: the tool's own is taken, as the interpreter reads it (interp/exec/tool.rs).
fn turret_offset(x: Option<&Token>, y: Option<&Token>, d: &Dialect) -> Option<Typed> {
    let address = d.addresses.iter().find(|a| a.role == Role::T)?;
    let (digits, suffix) = (address.offset_digits, address.offset_suffix);
    if digits.is_none() && !suffix {
        return None;
    }
    let split = |t: &Token| -> Option<(u64, Option<u64>)> {
        if about(t, d) != About::Address(Role::T) {
            return None;
        }
        let v = t.value.trim();
        if suffix && let Some((tool, offset)) = v.split_once('.') {
            let number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
            if !number(tool) || !(offset.is_empty() || number(offset)) {
                return None;
            }
            return Some((tool.parse().ok()?, if offset.is_empty() { None } else { Some(offset.parse().ok()?) }));
        }
        let v = v.parse::<u64>().ok()?;
        // Without the point, where no digits split the word (Fagor `T2`): the tool alone, with
        // its own offset, as `T2.` (interp/exec/tool.rs).
        if suffix && digits.is_none() {
            return Some((v, None));
        }
        let base = 10u64.pow(u32::from(digits?));
        Some((v / base, Some(v % base)))
    };
    let ((ta, oa), (tb, ob)) = (split(x?)?, split(y?)?);
    let text = |o: Option<u64>| o.map_or_else(|| "the tool's own".to_owned(), |o| o.to_string());
    (ta == tb && oa != ob).then(|| Typed {
        kind: ChangeKind::LengthOffsetChanged,
        field: format!("offset of tool {ta}"),
        before: text(oa),
        after: text(ob),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;

    fn word(key: &str, value: &str) -> Token {
        Token { key: key.into(), value: value.into(), text: format!("{key}={value}"), sort: Sort::Assign }
    }

    #[test]
    fn a_dimension_function_around_a_number_is_that_number() {
        let d = Registry::shipped().get("siemens").unwrap();
        for v in ["IC(10)", "AC(-5.5)", "DC(90)", "ACP(90)", "ACN(270)", "ic(10)", "10", "-2.5", "SIN(30)*10", "1.5EX3", "'H1F'"] {
            assert!(!by_variable(&word("X", v), &d), "{v}");
        }
        for v in ["IC(R1)", "R1", "INI[108]", "$AA_SOFTENDP[V]-1", "PROCESS[20]+2", "AC(_Z_SAFE)"] {
            assert!(by_variable(&word("X", v), &d), "{v}");
        }
        let fanuc = Registry::shipped().get("fanuc").unwrap();
        let z = |v: &str| Token { key: "Z".into(), value: v.into(), text: format!("Z{v}"), sort: Sort::Word };
        assert!(by_variable(&z("#7"), &fanuc) && by_variable(&z("[#1+2.]"), &fanuc));
        assert!(!by_variable(&z("-2."), &fanuc) && !by_variable(&z("[1.+2.]"), &fanuc));
    }

    #[test]
    fn tool_data_takes_a_tool_and_an_edge_and_nothing_else() {
        let d = Registry::shipped().get("siemens").unwrap();
        let (kind, field) = tool_data("$TC_DP3[5,1]", &d).unwrap();
        assert_eq!((kind, field.as_str()), (ChangeKind::LengthOffsetChanged, "tool length (via $TC_DP3[5,1]: tool 5, edge 1)"));
        assert_eq!(tool_data("$TC_DP6[ T , 2 ]", &d).unwrap().1, "tool radius (via $TC_DP6[T , 2]: tool T, edge 2)");
        // Not a tool and an edge: the variable row.
        for key in ["$TC_DP4[]", "$TC_DP6[1,2,3]", "$TC_DP4[1]", "$TC_DP4[,1]", "$TC_DP4[1,]", "$TC_DP4"] {
            assert_eq!(tool_data(key, &d), None, "{key}");
        }
    }
}
