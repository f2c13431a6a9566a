//! Record form: programs written as `MAJOR/minor,value,...` records (APT CLDATA, ISO 4343),
//! not as words. The dictionary's `<records>` says what each major word does (one of the
//! engine's [`RecordAction`]s), which codes it puts in force, what its positional numbers
//! are, and what its minor words mean (a code, or the role of the number after them).
//! `syntax::records` reads such text into ordinary blocks, so the interpreter runs them as
//! it runs G-code.

use super::{Pattern, Role};

/// The engine's record capabilities: what a record does with its arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordAction {
    /// The record's codes and words make a block (`SPINDL/RPM,1200,CLW`, `LOADTL/2`).
    Words,
    /// The text after the major word is raw text, kept as a comment (`PPRINT/...`,
    /// `PARTNO name`): never split at commas.
    Text,
    /// The program's name in raw text (`PARTNO/MFG0004`): a comment, and the name pairing uses.
    Name,
    /// The whole record, major word included, is kept as a comment (`TLDATA/MILL,10,0.5,75,0,0`,
    /// `CUTTER/10,0.5`): a statement about the tool the comment reader reads as it reads a
    /// tool comment, its numbers in the order the statement defines.
    Statement,
    /// Read and ignored: display or post-processor selection only (`PAINT/COLOR,42`).
    Ignore,
    /// A move to the point `x,y,z`, with the tool axis `i,j,k` where six numbers are given:
    /// a feed move, the rapid a preceding [`RecordAction::Rapid`] asked for, the arc a
    /// preceding [`RecordAction::Circle`] described, or a hole of the cycle in force.
    Goto,
    /// A move by increments `dx,dy,dz` from the last point, or by one distance along the
    /// tool axis (`GODLTA/d`).
    Delta,
    /// The next motion record only is a rapid (one-shot); the feed stays.
    Rapid,
    /// A circle `xc,yc,zc,i,j,k[,r,...]` (centre, axis vector, radius) the next motion record
    /// ends an arc on. Which way the arc turns about the axis is the producer's
    /// [`CircleSense`], unless the record's minor words give a direction code.
    Circle,
    /// A canned cycle: a minor word with a cycle code starts one, with the cycle-cancel code
    /// ends it, with neither changes the parameters of the one in force; every motion record
    /// in between is one hole, its point the hole's control point (its top).
    Cycle,
    /// The start point, without motion (`FROM/x,y,z`).
    From,
}

impl RecordAction {
    /// Every action with its dictionary spelling.
    pub const ALL: &'static [(&'static str, RecordAction)] = &[
        ("words", RecordAction::Words),
        ("text", RecordAction::Text),
        ("name", RecordAction::Name),
        ("statement", RecordAction::Statement),
        ("ignore", RecordAction::Ignore),
        ("goto", RecordAction::Goto),
        ("delta", RecordAction::Delta),
        ("rapid", RecordAction::Rapid),
        ("circle", RecordAction::Circle),
        ("cycle", RecordAction::Cycle),
        ("from", RecordAction::From),
    ];

    /// Parses the dictionary spelling.
    pub fn parse(s: &str) -> Option<RecordAction> {
        Self::ALL.iter().find(|(n, _)| *n == s).map(|(_, a)| *a)
    }
}

/// Which way a `CIRCLE` record's arc turns about its axis vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CircleSense {
    /// Clockwise looking along the vector from its tip (NX).
    Clockwise,
    /// Counter-clockwise about the vector, the right-hand rule (Creo, SolidWorks, ISO 4343).
    CounterClockwise,
}

/// A minor word of a record.
#[derive(Clone, Debug)]
pub struct MinorDef {
    /// The word, upper case (`CLW`, `MMPM`, `1STPECK`).
    pub word: String,
    /// The codes it puts in force, indices into [`super::Dialect::codes`] (`MMPM`: feed per
    /// minute and millimetres).
    pub codes: Vec<usize>,
    /// The role of the number after it (a couplet: `RPM,1200`), if one follows; `extra`
    /// reads the number and keeps nothing.
    pub role: Option<Role>,
    /// For a cycle's couplet: the value is a distance along the tool axis from the hole's
    /// control point, multiplied by this sign (SolidWorks `FEDTO,5` is 5 below: -1).
    pub from_point: Option<f64>,
}

/// One major word and what it does.
#[derive(Clone, Debug)]
pub struct RecordDef {
    /// The major word, upper case, blanks single (`GOTO`, `TOOL PATH`, `END-OF-PATH`).
    pub major: String,
    /// What it does.
    pub action: RecordAction,
    /// Codes every such record puts in force (indices into [`super::Dialect::codes`]).
    pub codes: Vec<usize>,
    /// Roles of the numbers not taken by a minor word, in order, each perhaps measured from
    /// a hole's point as [`MinorDef::from_point`] (`radius@up`).
    pub args: Vec<(Role, Option<f64>)>,
    /// Minor words.
    pub minors: Vec<MinorDef>,
    /// A role whose value also gives another (`LOADTL/2`: tool 2 and length offset 2), when
    /// the record does not give that one.
    pub also: Vec<(Role, Role)>,
}

impl RecordDef {
    /// The minor word `word` (upper case).
    pub fn minor(&self, word: &str) -> Option<&MinorDef> {
        self.minors.iter().find(|m| m.word == word)
    }
}

/// A CAM system whose CL files differ from the common form: found by evidence in the file's
/// start, with its own circle sense and its own definitions of some records.
#[derive(Clone, Debug)]
pub struct Producer {
    /// Name, for messages (`nx`, `creo`).
    pub name: String,
    /// Patterns any of which, found in the file's first 64 KiB, says the file is this
    /// producer's; none: the default producer, taken when no other matches.
    pub evidence: Vec<(String, Pattern)>,
    /// Which way its circles turn about their axis.
    pub circle: CircleSense,
    /// Records defined differently from the common ones.
    pub records: Vec<RecordDef>,
}

/// The record form of a dialect.
#[derive(Clone, Debug)]
pub struct Records {
    /// The character that continues a record on the next line (`$`), joined without a separator.
    pub continuation: char,
    /// The comment opener, to the end of the line (`$$`).
    pub comment: String,
    /// The opener of a comment that is a command for the CAM system (Creo `$$-> CSYS / ...`,
    /// `$$-> CUTTER / 3.0`), not a note for the operator: read over, not kept as a comment.
    pub command: Option<String>,
    /// Records common to every producer.
    pub records: Vec<RecordDef>,
    /// Producers, tried in order; the first without evidence is the default.
    pub producers: Vec<Producer>,
    /// Tolerance for a circle's start and end radii and its tangency checks, in the program's units.
    pub tolerance: f64,
}

impl Records {
    /// The definition of `major` for producer `producer` (an index into `producers`).
    pub fn record(&self, producer: Option<usize>, major: &str) -> Option<&RecordDef> {
        producer
            .and_then(|p| self.producers.get(p))
            .and_then(|p| p.records.iter().find(|r| r.major == major))
            .or_else(|| self.records.iter().find(|r| r.major == major))
    }

    /// The producer of a file whose start is `head`, and the evidence that told it.
    pub fn producer(&self, head: &[u8]) -> Option<(usize, Option<&str>)> {
        for (i, p) in self.producers.iter().enumerate() {
            if let Some((label, _)) = p.evidence.iter().find(|(_, re)| re.regex().is_match(head)) {
                return Some((i, Some(label.as_str())));
            }
        }
        self.producers.iter().position(|p| p.evidence.is_empty()).map(|i| (i, None))
    }
}
