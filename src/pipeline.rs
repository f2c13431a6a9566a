//! The pure composition of the core: bytes → text → canon → plan, with all diagnostics,
//! and the door the commands use to reach the core. The CLI, the daemon and the tests all
//! analyse programs through [`analyze`]; a command module names no core module, only this
//! one (and `store`): what it prints, writes or compares goes through the functions and the
//! vocabulary below.

use crate::interp;
use crate::plan;
use crate::text::{self, DecodeNote};

// The vocabulary the commands speak: diagnostics and how they are shown, dialects, positions
// in a text, plans, the options of a translation, changes. What they ask of the core is one
// function each, below.
pub use crate::canon::{CallWriter, Canon, CanonOp, CanonSink, MOVE_LINE, Units, write_call_bytes};
pub use crate::diag::{Code, Diagnostic, DiagnosticJson, Severity, render_human, render_short, render_short_at};
pub use crate::dialect::sniff::Sniffed;
pub use crate::dialect::{Dialect, Registry};
pub use crate::diff::{Change, render_plain};
pub use crate::interp::{Profile, ProgramRole, role_for};
pub use crate::part21::stepnc::Class as StepNcClass;
pub use crate::plan::ProcessPlan;
pub use crate::post::{Limits, Options as TranslateOptions};
pub use crate::text::{LineIndex, SourceText, Text, TextRange, locate};

/// Everything known about one program.
#[derive(Debug)]
pub struct Analysis {
    /// The decoded text.
    pub source: SourceText,
    /// Canonical ops (empty from [`analyze_plan`]).
    pub canon: Vec<Canon>,
    /// The recovered plan.
    pub plan: ProcessPlan,
    /// Findings of every phase, in source order.
    pub diagnostics: Vec<Diagnostic>,
}

impl Analysis {
    /// Whether any finding is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// Analyses raw program bytes. Never fails.
pub fn analyze(bytes: &[u8], dialect: &Dialect, profile: &Profile) -> Analysis {
    let (source, notes) = text::decode(bytes);
    let mut diagnostics = crate::diag::decoding(notes);
    let mut canon = Vec::new();
    let mut found = interp::interpret(&source.text, dialect, profile, &mut canon);
    let mut votes = interp::shown::RadiusVotes::default();
    canon.iter().for_each(|c| votes.see(c));
    found.extend(moves_show(&votes, &found, profile));
    if let Some((machine, evidence)) = lathe_machine(&found, profile) {
        canon.clear();
        found = interp::interpret(&source.text, dialect, &machine, &mut canon);
        found.extend(evidence);
    }
    diagnostics.extend(found);
    let (plan, plan_diags) = plan::recover(&canon, profile, name_of(Text::Whole(&source.text), dialect));
    diagnostics.extend(plan_diags);
    diagnostics.sort_by_key(|d| (d.range.start, d.range.end));
    Analysis { source, canon, plan, diagnostics }
}

/// Analyses raw program bytes as [`analyze`] does, without keeping the canonical ops: plan
/// recovery takes them as the interpreter emits them, so memory holds the plan, not the ops.
/// Never fails.
pub fn analyze_plan(bytes: &[u8], dialect: &Dialect, profile: &Profile) -> Analysis {
    plan_of(text::decode(bytes), dialect, profile)
}

/// Plan facts the post-processor writes from (`ncplan translate`, the web download): hole tops
/// and tool facts from the shop's tool table. Only a tool table with diameters needs the plan
/// first; otherwise the writer asks for hole tops itself when a cycle needs them.
fn translation_facts<'t>(text: impl Into<Text<'t>>, dialect: &Dialect, profile: &Profile) -> (Vec<[f64; 3]>, Vec<crate::post::ToolFact>) {
    if profile.tools.values().any(|t| t.diameter.is_some()) {
        let plan = plan_of_text(text.into(), dialect, profile).0;
        (crate::post::hole_tops(&plan), crate::post::tool_facts(&plan))
    } else {
        (Vec::new(), Vec::new())
    }
}

/// [`analyze_plan`] of bytes it may take: decoding reuses them, so the text is not a copy.
pub fn analyze_plan_owned(bytes: Vec<u8>, dialect: &Dialect, profile: &Profile) -> Analysis {
    plan_of(text::decode_owned(bytes), dialect, profile)
}

fn plan_of((source, notes): (SourceText, Vec<DecodeNote>), dialect: &Dialect, profile: &Profile) -> Analysis {
    let mut diagnostics = crate::diag::decoding(notes);
    let (plan, found) = plan_of_text(Text::Whole(&source.text), dialect, profile);
    diagnostics.extend(found);
    diagnostics.sort_by_key(|d| (d.range.start, d.range.end));
    Analysis { source, canon: Vec::new(), plan, diagnostics }
}

/// The plan of a decoded text (whole or read piece by piece) and the findings of the run and
/// of plan recovery, as [`analyze_plan`] makes them: the ops go into plan recovery as they
/// come.
pub fn plan_of_text(text: Text<'_>, dialect: &Dialect, profile: &Profile) -> (ProcessPlan, Vec<Diagnostic>) {
    let mut recoverer = plan::Recoverer::new(profile);
    let mut votes = interp::shown::RadiusVotes::default();
    let mut diagnostics = interp::interpret(text, dialect, profile, &mut interp::shown::Tee { sink: &mut recoverer, votes: &mut votes });
    diagnostics.extend(moves_show(&votes, &diagnostics, profile));
    let machine = lathe_machine(&diagnostics, profile);
    // A program found to turn only after its first moves (or by its moves all lying in the
    // ZX plane) is read again as a lathe's from its start.
    let turns = recoverer.turns_throughout();
    let (plan, plan_diags) = if machine.is_some() || turns {
        let (mut machine, evidence) = machine.unwrap_or_else(|| (profile.clone(), Vec::new()));
        machine.turns |= turns;
        let mut again = plan::Recoverer::new(&machine);
        diagnostics = interp::interpret(text, dialect, &machine, &mut again);
        diagnostics.extend(evidence);
        again.finish(name_of(text, dialect))
    } else {
        recoverer.finish(name_of(text, dialect))
    };
    diagnostics.extend(plan_diags);
    (plan, diagnostics)
}

/// What the moves show where the interpreter's evidence did not: X words as radii by the
/// slope of 45° moves, where no arc tells (`interp::shown`).
fn moves_show(votes: &interp::shown::RadiusVotes, found: &[Diagnostic], profile: &Profile) -> Option<Diagnostic> {
    let known = profile.x_radius || found.iter().any(|d| d.code == Code::XWordsRadius);
    votes.finding(known)
}

/// The machine a program's own words show (X words as radii, inch at power-on, whole numbers
/// in units: calculator-type decimal input, a lathe whose reset state reads X as a diameter) where
/// the first reading found the evidence: the profile so set, and the findings that say why.
/// The program is then read again on it.
fn lathe_machine(found: &[Diagnostic], profile: &Profile) -> Option<(Profile, Vec<Diagnostic>)> {
    let evidence: Vec<Diagnostic> = found.iter().filter(|d| MachineShown::is_evidence(d.code)).cloned().collect();
    if evidence.is_empty() {
        return None;
    }
    let machine = MachineShown::from_codes(evidence.iter().map(|d| d.code.as_str())).on(profile);
    Some((machine, evidence))
}

/// What a program's own words showed of the machine it runs on, beyond what its
/// configuration says: X words as radii, inch at power-on, whole numbers in units
/// (calculator-type decimal input). The machine does not change with
/// an edit, so when two revisions are compared, what either shows holds for both
/// ([`analyze_pair`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MachineShown {
    x_radius: bool,
    inch: bool,
    calculator: bool,
    /// A lathe of a control whose turning machines read X as a diameter in G18 from reset.
    lathe: bool,
    /// Such a lathe that changes the tool with the T word.
    turret: bool,
}

impl MachineShown {
    /// Whether a finding tells what the machine is.
    fn is_evidence(code: Code) -> bool {
        matches!(code, Code::XWordsRadius | Code::XWordsDiameter | Code::ToolWordChanges | Code::UnitsInferred | Code::DecimalInputInferred)
    }

    /// What a revision's findings (their codes, as `interp::units-inferred`) show.
    pub fn from_codes<'c>(codes: impl IntoIterator<Item = &'c str>) -> MachineShown {
        let mut shown = MachineShown::default();
        for code in codes {
            shown.x_radius |= code == Code::XWordsRadius.as_str();
            shown.inch |= code == Code::UnitsInferred.as_str();
            shown.calculator |= code == Code::DecimalInputInferred.as_str();
            shown.lathe |= code == Code::XWordsDiameter.as_str();
            shown.turret |= code == Code::ToolWordChanges.as_str();
        }
        shown
    }

    /// What an analysis's findings show.
    pub fn of(a: &Analysis) -> MachineShown {
        MachineShown::from_codes(a.diagnostics.iter().map(|d| d.code.as_str()))
    }

    /// What either shows.
    pub fn union(self, other: MachineShown) -> MachineShown {
        MachineShown {
            x_radius: self.x_radius || other.x_radius,
            inch: self.inch || other.inch,
            calculator: self.calculator || other.calculator,
            lathe: self.lathe || other.lathe,
            turret: self.turret || other.turret,
        }
    }

    /// `dialect` as this machine reads a program's words: a length without a point in whole
    /// units where it showed calculator-type input.
    pub fn reads(self, dialect: &Dialect) -> std::borrow::Cow<'_, Dialect> {
        use crate::dialect::DecimalInput;
        if self.calculator && matches!(dialect.behaviour.decimal_input, DecimalInput::LeastIncrement { .. }) {
            let mut d = dialect.clone();
            d.behaviour.decimal_input = DecimalInput::Calculator;
            std::borrow::Cow::Owned(d)
        } else {
            std::borrow::Cow::Borrowed(dialect)
        }
    }

    /// `profile` on this machine.
    pub fn on(self, profile: &Profile) -> Profile {
        let mut machine = profile.clone();
        machine.x_radius |= self.x_radius;
        machine.inch |= self.inch;
        machine.calculator_input |= self.calculator;
        machine.lathe_reset |= self.lathe;
        machine.tool_word_changes |= self.turret;
        machine
    }
}

/// The machine a revision's analysis showed.
fn shown(a: &Analysis) -> MachineShown {
    MachineShown::of(a)
}

/// Two revisions of a program analysed to be compared ([`analyze_plan_owned`] each), read on
/// one machine: where one revision's words show what the machine is (X words as radii, inch
/// at power-on, calculator-type input) and the other's do not, the other is read again on that machine. An edit that
/// only tips the evidence (a feed rewritten, a point added to one number) then changes no
/// length of the program; the revision read again says why, with the other's findings.
pub fn analyze_pair(original: (Vec<u8>, &Dialect, &Profile), edited: (Vec<u8>, &Dialect, &Profile)) -> (Analysis, Analysis) {
    let a = analyze_plan_owned(original.0, original.1, original.2);
    let b = analyze_plan_owned(edited.0, edited.1, edited.2);
    let (in_a, in_b) = (shown(&a), shown(&b));
    let both = in_a.union(in_b);
    if in_a == in_b {
        return (a, b);
    }
    let evidence =
        |x: &Analysis| -> Vec<Diagnostic> { x.diagnostics.iter().filter(|d| MachineShown::is_evidence(d.code)).cloned().collect() };
    let (of_a, of_b) = (evidence(&a), evidence(&b));
    let a = if in_a == both { a } else { read_on(a, original.1, &both.on(original.2), &of_b) };
    let b = if in_b == both { b } else { read_on(b, edited.1, &both.on(edited.2), &of_a) };
    (a, b)
}

/// `a` read again on `machine`, which `other`'s words showed: its decoding findings and its
/// own evidence kept (a reading on a machine already so set finds none again), the other's
/// evidence added to say why.
fn read_on(a: Analysis, dialect: &Dialect, machine: &Profile, other: &[Diagnostic]) -> Analysis {
    let Analysis { source, canon, diagnostics, .. } = a;
    let mut kept: Vec<Diagnostic> =
        diagnostics.into_iter().filter(|d| d.code.as_str().starts_with("text::") || MachineShown::is_evidence(d.code)).collect();
    let (plan, found) = plan_of_text(Text::Whole(&source.text), dialect, machine);
    kept.extend(found);
    kept.extend(
        other
            .iter()
            .map(|d| Diagnostic::new(d.code, TextRange::default(), format!("read as the other revision shows the machine: {}", d.message))),
    );
    kept.sort_by_key(|d| (d.range.start, d.range.end));
    Analysis { source, canon, plan, diagnostics: kept }
}

/// The program's name: the record the dictionary names it by (CLDATA `PARTNO`), or the header's.
fn name_of(text: Text<'_>, dialect: &Dialect) -> Option<String> {
    crate::syntax::record_program_name(text, dialect).or_else(|| program_name(&text.head()))
}

/// A diagnostic for input over the size limit, for callers that refuse to read it whole.
pub fn too_large(size: u64, limit: u64) -> Diagnostic {
    Diagnostic::new(
        Code::TooLarge,
        TextRange::default(),
        format!("the file has {size} bytes, over the limit of {limit}; it was stored but not analysed"),
    )
}

/// The program's own name or number, as its header states it: `O1234`, `%_N_NAME_MPF`,
/// `BEGIN PGM NAME MM`. Looks at the first non-blank lines only (of a long text, within its
/// head: [`Text::head`]).
pub fn program_name(text: &str) -> Option<String> {
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()).take(5) {
        let up = line.to_ascii_uppercase();
        if let Some(rest) = up.strip_prefix("%_N_") {
            // A whole name: `%_N_DRILL_REAM_MPF` is DRILL_REAM, with only the type suffix off.
            let word = rest.split_whitespace().next().unwrap_or("");
            let name = word.strip_suffix("_MPF").or_else(|| word.strip_suffix("_SPF")).unwrap_or(word);
            if !name.is_empty() {
                return Some(name.to_owned());
            }
        }
        let numbered = up.trim_start_matches(|c: char| c.is_ascii_digit()).trim_start();
        if let Some(rest) = numbered.strip_prefix("BEGIN PGM ") {
            if let Some(name) = rest.split_whitespace().next() {
                return Some(name.to_owned());
            }
        }
        let mut chars = up.chars();
        if matches!(chars.next(), Some('O' | ':')) {
            let digits: String = chars.take_while(char::is_ascii_digit).collect();
            if !digits.is_empty() {
                let n: u64 = digits.parse().unwrap_or(0);
                return Some(format!("O{n}"));
            }
        }
    }
    None
}

/// The dialect taken when nothing in a program tells its dialect: RS274NGC, the ISO baseline.
pub const DEFAULT_DIALECT: &str = "linuxcnc";

/// Tells the dialect of the program `bytes` (named `path`) from its start and its file name.
///
/// When the evidence does not set one dialect apart (the sniff's candidates: a single code of
/// one maker among Fanuc-like families), the program is read in the evidence's choice, and
/// if that reading has errors, in the other candidates in the evidence's order: the first
/// that reads it without an error is taken. A weak guess never turns the program's other
/// codes into errors; a program that no candidate reads cleanly keeps the evidence's choice
/// (between two readings that both stop, a count of errors tells no maker). The programs it
/// calls are not read: [`sniff_in`] reads them from where a profile says.
pub fn sniff(registry: &crate::dialect::Registry, bytes: &[u8], path: &std::path::Path) -> crate::dialect::sniff::Sniffed {
    sniff_in(registry, bytes, path, &Profile::default())
}

/// [`sniff`], with the programs the program calls read from `profile`'s program source (a
/// shop's subprogram shows its maker's codes in what it calls too: `check` passes the
/// folder beside the file).
pub fn sniff_in(
    registry: &crate::dialect::Registry,
    bytes: &[u8],
    path: &std::path::Path,
    profile: &Profile,
) -> crate::dialect::sniff::Sniffed {
    let (source, _) = text::decode(&bytes[..bytes.len().min(64 * 1024)]);
    // A longer file's end is read too: how a program ends tells its control (`/M99`, `M30`).
    let tail = (bytes.len() > 68 * 1024).then(|| text::decode(&bytes[bytes.len() - 4 * 1024..]).0);
    let sniffed_text = match &tail {
        Some(t) => std::borrow::Cow::Owned(format!("{}\n{}", source.text, t.text)),
        None => std::borrow::Cow::Borrowed(&*source.text),
    };
    let mut s = registry.sniff(&sniffed_text, path.file_name().and_then(|n| n.to_str()), DEFAULT_DIALECT);
    if s.candidates.len() < 2 {
        return s;
    }
    struct Discard;
    impl CanonSink for Discard {
        fn emit(&mut self, _: Canon) {}
        fn kept_bytes(&self, _: u64) -> u64 {
            0
        }
    }
    let errors = |name: &str| {
        registry
            .get(name)
            .map(|d| interp::interpret(Text::from(&*source.text), &d, profile, &mut Discard).iter().filter(|x| x.is_error()).count())
    };
    let mut read = Vec::new();
    for name in s.candidates.clone() {
        let Some(n) = errors(&name) else { continue };
        read.push(format!("{name} {n}"));
        if n == 0 {
            if name != s.dialect {
                let before = std::mem::replace(&mut s.dialect, name);
                s.runner_up = Some((before, s.score));
                s.evidence.push(format!("weak evidence: the first reading without an error ({})", read.join(", ")));
            }
            break;
        }
    }
    s
}

/// The plan in words: a line per stock, tool, feature and workingstep (`ncplan plan`).
pub fn describe_plan(plan: &ProcessPlan) -> String {
    plan::describe(plan)
}

/// Runs the program through the interpreter, handing each canonical op to `sink` as it is
/// made (`ncplan canon`): memory does not grow with the program. Returns the findings.
pub fn canon<'t>(text: impl Into<Text<'t>>, dialect: &Dialect, profile: &Profile, sink: &mut dyn CanonSink) -> Vec<Diagnostic> {
    interp::interpret(text, dialect, profile, sink)
}

/// Writes the plan as STEP-NC (ISO 14649 Part 21) of `class` to `out` as it is made, with the
/// header's `timestamp`; returns `out` and the findings of the export.
pub fn write_stepnc<W: std::io::Write>(
    plan: &ProcessPlan,
    class: StepNcClass,
    timestamp: &str,
    out: W,
) -> std::io::Result<(W, Vec<Diagnostic>)> {
    crate::part21::stepnc::write(plan, class, timestamp, out)
}

/// Translates program `text`, read in `from`, into `to`'s dialect, handing the text to `sink`
/// as it is written; returns the findings of reading and writing. The plan facts the writer
/// needs (the tool table's tools; where each hole's top is, for a cycle that states only its
/// R level) are taken from the program: the tools first when the table has any, the hole tops
/// only when the first such cycle asks. The program is first read once into nothing, for the
/// machine its words show ([`machine_of`]), then translated on it: twice in all when it needs
/// no plan facts, in constant memory. `opts`' hole tops and tools are filled in here.
pub fn translate<'t>(
    text: impl Into<Text<'t>>,
    from: &Dialect,
    to: &Dialect,
    profile: &Profile,
    opts: TranslateOptions,
    sink: impl FnMut(&[u8]),
) -> Vec<Diagnostic> {
    let text = text.into();
    // The machine the program's words show (X as radii, inch at power-on) is found only by
    // reading the program to its end, and the writer streams: so it is found first, and the
    // program translated as it is planned, never at 2× its diameters or 25.4× its size.
    let (machine, evidence) = machine_of(text, from, profile);
    let profile = machine.as_ref().unwrap_or(profile);
    let (hole_tops, tools) = translation_facts(text, from, profile);
    let opts = TranslateOptions { hole_tops, tools, ..opts };
    let mut tops = || crate::post::hole_tops(&plan_of_text(text, from, profile).0);
    let mut diags = crate::post::translate_with_facts(text, from, to, profile, opts, &mut tops, sink);
    diags.extend(evidence);
    diags
}

/// The machine settings a program's own words show that its dialect cannot know (X words as
/// radii, inch at power-on: see [`lathe_machine`]), found by reading it once into nothing:
/// the profile so set and the findings that say why, or `None` and no findings when the
/// program shows none. Streams: memory does not grow with the program.
pub fn machine_of(text: Text<'_>, dialect: &Dialect, profile: &Profile) -> (Option<Profile>, Vec<Diagnostic>) {
    let mut votes = interp::shown::RadiusVotes::default();
    let mut found = interp::interpret(text, dialect, profile, &mut votes);
    found.extend(moves_show(&votes, &found, profile));
    match lathe_machine(&found, profile) {
        Some((machine, evidence)) => (Some(machine), evidence),
        None => (None, Vec::new()),
    }
}

/// The proof of a translation by its motion (`translate --check`): `translated`, the text the
/// target's writer made of `source`, read back in `to`, must run as `source` read in `from`
/// does: every move in the same frame (the work offset stated, a reference return, a move in
/// machine coordinates), with the same tool, feed, spindle and coolant, positions within
/// 0.001 mm, or within the target's resolution where the writer said it rounded (`written`
/// holds the writer's findings). Returns the findings: none when the motion is the same; an
/// error of the read-back, or [`Code::PostMotionDiffers`] at the source's block where the two
/// part. A translation the writer refused (an error of `post::`) is not proven: it is not
/// given out, and a difference would say nothing the refusal does not.
///
/// The two are read at once, each on a thread of its own, and compared as their moves come
/// ([`crate::proof::Comparison`]): memory holds a few batches of moves, not the motions, and
/// `translated` may be read piece by piece (a file written beside the output).
pub fn check_translation<'t>(
    source: Text<'_>,
    from: &Dialect,
    translated: impl Into<Text<'t>>,
    to: &Dialect,
    profile: &Profile,
    written: &[Diagnostic],
) -> Vec<Diagnostic> {
    use crate::proof::{Comparison, Trace};
    const TOL: f64 = PROOF_TOL;
    if written.iter().any(|d| d.is_error() && d.code.as_str().starts_with("post::")) {
        return Vec::new();
    }
    let translated = translated.into();
    // The source runs on the machine its words show, as it was translated ([`translate`]);
    // the translation states what it needs, and is read back on the machine as configured.
    let machine = machine_of(source, from, profile).0;
    let machine = machine.as_ref().unwrap_or(profile);
    let said = |code: Code| written.iter().any(|d| d.code == code);
    // Arcs whose centres the writer moved: within the largest radius difference of the
    // source's arcs, known only at its end, so read for first.
    let slack = if said(Code::PostArcCentre) {
        let mut t = Trace::streaming(TOL, |mut v| {
            v.clear();
            v
        });
        interp::interpret(source, from, machine, &mut t);
        t.slack()
    } else {
        0.0
    };
    // Rounded: within the target's resolution in the units the translation ends in, known
    // only at its end: where inches and millimetres differ, both are compared, and the one
    // of the units it ended in kept.
    let rounded = said(Code::PostRounded) || said(Code::PostArcCentre);
    let within = |inch: bool| if rounded { TOL.max(crate::post::resolution(to, inch)) + slack } else { TOL + slack };
    let mut candidates = vec![(Some(false), Comparison::new(within(false)))];
    if within(true) == within(false) {
        candidates[0].0 = None;
    } else {
        candidates.push((Some(true), Comparison::new(within(true))));
    }
    let (back, inches) = prove_beside((source, from, machine), (translated, to, profile), &mut candidates);
    if let Some(e) = back.iter().find(|d| d.is_error()) {
        let at = text::locate(translated, &[e.range.start]).first().map_or(0, |l| l.line);
        return vec![Diagnostic::new(
            Code::PostMotionDiffers,
            TextRange::default(),
            format!("the translation, read back as {}, has an error at its line {at}: {}: {}", to.name, e.code.as_str(), e.message),
        )];
    }
    let verdict = candidates.into_iter().find(|(inch, _)| inch.is_none_or(|i| i == inches)).and_then(|(_, c)| c.verdict());
    let difference = verdict.unwrap_or_else(|| {
        // Not reached: both streams end, and a comparison of two ended streams is decided.
        Some(crate::proof::Difference {
            line: 0,
            origin: TextRange::default(),
            other_line: None,
            what: "the comparison did not finish".into(),
        })
    });
    match difference {
        None => Vec::new(),
        Some(d) => {
            let back_line = d.other_line.map(|l| format!(" (the translation's line {l})")).unwrap_or_default();
            vec![Diagnostic::new(
                Code::PostMotionDiffers,
                d.origin,
                format!("the translation does not run as the program does{back_line}: {}", d.what),
            )]
        }
    }
}

/// How close two points of a proof are at least to count as one (mm).
const PROOF_TOL: f64 = 0.001;

/// Batches of moves under way from each reading thread at once: how far it may run ahead
/// of the comparison.
const PROOF_BATCHES: usize = 4;

/// A batch of a stream's moves, or its end with the seconds dwelt after its last move.
enum Proved {
    Moves(Vec<crate::proof::Move>),
    End(f64),
}

/// Reads the program and its translation each on a thread of its own into a streaming
/// [`crate::proof::Trace`], and feeds every undecided comparison of `candidates` the moves
/// the first of them waits for, until all are decided. Returns the findings of reading the
/// translation back and whether it ended in inches.
fn prove_beside(
    (source, from, machine): (Text<'_>, &Dialect, &Profile),
    (translated, to, profile): (Text<'_>, &Dialect, &Profile),
    candidates: &mut [(Option<bool>, crate::proof::Comparison)],
) -> (Vec<Diagnostic>, bool) {
    use crate::proof::{Side, Trace};
    use std::sync::mpsc;
    let (a_full, a_filled) = mpsc::sync_channel::<Proved>(PROOF_BATCHES);
    let (b_full, b_filled) = mpsc::sync_channel::<Proved>(PROOF_BATCHES);
    let (a_empty, a_emptied) = mpsc::channel::<Vec<crate::proof::Move>>();
    let (b_empty, b_emptied) = mpsc::channel::<Vec<crate::proof::Move>>();
    // A trace whose batches go down `full`, taking emptied ones back; once the comparison
    // is decided (the channel closed) they are dropped.
    let trace = |full: mpsc::SyncSender<Proved>, emptied: mpsc::Receiver<Vec<crate::proof::Move>>| {
        let sent = full.clone();
        let t = Trace::streaming(PROOF_TOL, move |moves| {
            let mut next = emptied.try_recv().unwrap_or_else(|_| Vec::with_capacity(crate::proof::BATCH));
            if let Err(mpsc::SendError(Proved::Moves(mut v))) = sent.send(Proved::Moves(moves)) {
                v.clear();
                next = v;
            }
            next
        });
        (t, full)
    };
    std::thread::scope(|scope| {
        let ours = scope.spawn(move || {
            let (mut t, full) = trace(a_full, a_emptied);
            interp::interpret(source, from, machine, &mut t);
            let _ = full.send(Proved::End(t.finish()));
        });
        let theirs = scope.spawn(move || {
            let (mut t, full) = trace(b_full, b_emptied);
            let back = interp::interpret(translated, to, profile, &mut t);
            let _ = full.send(Proved::End(t.finish()));
            (back, t.in_inches())
        });
        while let Some(side) = candidates.iter().find_map(|(_, c)| c.wants()) {
            let (filled, empty) = match side {
                Side::Program => (&a_filled, &a_empty),
                Side::Translation => (&b_filled, &b_empty),
            };
            // A reading thread gone (it panicked): the panic comes out of the join.
            let Ok(batch) = filled.recv() else { break };
            match batch {
                Proved::Moves(mut moves) => {
                    // Each undecided comparison a copy, the last the moves themselves.
                    let live = candidates.iter().filter(|(_, c)| !c.decided()).count();
                    for (k, (_, c)) in candidates.iter_mut().filter(|(_, c)| !c.decided()).enumerate() {
                        if k + 1 == live {
                            c.take(side, moves.drain(..));
                        } else {
                            c.take(side, moves.iter().cloned());
                        }
                    }
                    moves.clear();
                    let _ = empty.send(moves);
                }
                Proved::End(dwell) => candidates.iter_mut().for_each(|(_, c)| c.end(side, dwell)),
            }
        }
        // Decided: the rest of each reading goes nowhere.
        drop((a_filled, b_filled));
        ours.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        theirs.join().unwrap_or_else(|e| std::panic::resume_unwind(e))
    })
}

/// The changes from the `original` program's plan to the `edited` one's, each analysed in its
/// dialect, in the order of the edited program (`ncplan diff`).
pub fn diff(original: &Analysis, original_dialect: &Dialect, edited: &Analysis, edited_dialect: &Dialect) -> Vec<Change> {
    let faults = |a: &Analysis| crate::diff::verdict::faults(&a.source.text, &a.diagnostics);
    // The statements compared as the machine both were read on reads their words.
    let machine = shown(original).union(shown(edited));
    let (original_dialect, edited_dialect) = (machine.reads(original_dialect), machine.reads(edited_dialect));
    crate::diff::compare_with_findings(
        crate::diff::Program { plan: &original.plan, text: &original.source.text, dialect: &original_dialect },
        crate::diff::Program { plan: &edited.plan, text: &edited.source.text, dialect: &edited_dialect },
        (&faults(original), &faults(edited)),
    )
}

/// [`diff`], with the edited program's call arguments followed into the subroutines its
/// profile finds (`edited_profile.programs`: those beside it for `ncplan diff`), and a call
/// whose argument count changed compared with the subroutine as each version finds it
/// (`original_profile.programs` beside the original).
pub fn diff_beside(
    original: &Analysis,
    original_dialect: &Dialect,
    edited: &Analysis,
    edited_dialect: &Dialect,
    (original_profile, edited_profile): (&Profile, &Profile),
) -> Vec<Change> {
    let mut changes = diff(original, original_dialect, edited, edited_dialect);
    let machine = shown(original).union(shown(edited));
    let (original_dialect, edited_dialect) = (&*machine.reads(original_dialect), &*machine.reads(edited_dialect));
    if let Some(programs) = &edited_profile.programs {
        let program = crate::diff::Program { plan: &edited.plan, text: &edited.source.text, dialect: edited_dialect };
        if let Some(before) = &original_profile.programs {
            let old = crate::diff::Program { plan: &original.plan, text: &original.source.text, dialect: original_dialect };
            crate::diff::follow_rebound_calls(&mut changes, (old, before.as_ref()), (program, programs.as_ref()));
        }
        crate::diff::follow_calls(&mut changes, program, programs.as_ref());
    }
    changes
}

#[cfg(test)]
mod tests {
    use super::program_name;

    #[test]
    fn program_names() {
        assert_eq!(program_name("%\nO1234 (FACE)\nG0 X0"), Some("O1234".into()));
        assert_eq!(program_name("%_N_PART1_MPF\n;$PATH=/_N_WKS_DIR\n"), Some("PART1".into()));
        assert_eq!(program_name("%_N_DRILL_REAM_MPF\n"), Some("DRILL_REAM".into()));
        assert_eq!(program_name("%_N_CYCLE_POCKET_SPF\n"), Some("CYCLE_POCKET".into()));
        assert_eq!(program_name("0 BEGIN PGM FLANGE MM\n"), Some("FLANGE".into()));
        assert_eq!(program_name("BEGIN PGM FLANGE MM\n"), Some("FLANGE".into()));
        assert_eq!(program_name(":0100\n"), Some("O100".into()));
        assert_eq!(program_name("G0 X0\n"), None);
    }
}
