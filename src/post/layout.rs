//! Templates sorted once into the parts the writer walks for every block it renders.
//!
//! A template is a list of blocks of words, each word a list of pieces; most words are a
//! single number placeholder (`{x}`), and a move's template is rendered for nearly every
//! block of a program. [`Layout::of`] looks at each word once: the motion code that is left
//! out while in force, a number with its format, its modal slot and whether it is left out
//! when unchanged, the words put off to a move, or any other word, rendered piece by piece.
//! A number placeholder without a format writes nothing and has no part.

use crate::dialect::output::{Output, Piece, Template, Value};

/// How one word of a template is rendered.
#[derive(Debug)]
pub(super) enum Part {
    /// A motion block's first word, its G code: left out while the same code is in force.
    Code(String),
    /// A word of one number placeholder.
    Num(Num),
    /// The words put off to a move, alone in their word (`{mods}`); the word's index.
    Mods(usize),
    /// Any other word, by its index in the block.
    Word(usize),
}

/// A number placeholder, sorted.
#[derive(Clone, Copy, Debug)]
pub(super) struct Num {
    /// The value.
    pub value: Value,
    /// Its number format.
    pub fi: u32,
    /// The modal slot ([`super::modal_slot`]), or [`NO_SLOT`].
    pub slot: u8,
    /// Whether it is left out when its text is unchanged: a modal format, not forced.
    pub modal: bool,
    /// What its rounding counts towards.
    pub class: Class,
}

/// What a number's rounding counts towards: the largest rounding of positions (a centre's
/// by 2√2 times its own, as it moves the arc through the start that stays by up to that),
/// of feeds, or neither.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Class {
    Other,
    Position,
    Centre,
    Feed,
}

impl Class {
    fn of(value: Value) -> Class {
        match value {
            Value::I | Value::J | Value::K | Value::Cx | Value::Cy | Value::Cz => Class::Centre,
            // A cycle's levels are positions too.
            Value::X
            | Value::Y
            | Value::Z
            | Value::R
            | Value::Bottom
            | Value::RPlane
            | Value::Clear
            | Value::Surface
            | Value::Sdis
            | Value::Depth
            | Value::ClearDist
            | Value::Peck => Class::Position,
            Value::F | Value::Pitch => Class::Feed,
            _ => Class::Other,
        }
    }
}

impl Num {
    /// Placeholder `value` in format `fi` of `out`, forced (`{x!}`) or not.
    pub(super) fn new(value: Value, fi: usize, force: bool, out: &Output) -> Num {
        let slot = super::modal_slot(value).map_or(NO_SLOT, |k| k as u8);
        let index = u32::try_from(fi).expect("a dictionary has fewer than 2^32 number formats");
        Num { value, fi: index, slot, modal: out.formats[fi].modal && !force, class: Class::of(value) }
    }
}

/// No modal slot.
pub(super) const NO_SLOT: u8 = 8;

/// One block of a [`Layout`].
#[derive(Debug)]
pub(super) struct LayoutBlock {
    /// Written without block number.
    pub raw: bool,
    /// Whether a placeholder of the block is X, Y or Z: a motion block that moves none of
    /// them is left out.
    pub moves: bool,
    /// Its words' parts.
    pub parts: Vec<Part>,
    /// The same parts when they are the common move's: perhaps its motion code, perhaps the
    /// words put off to a move, then numbers only (`G1 {mods} {x} {y} {z} {f}`).
    pub simple: Option<Simple>,
}

/// A block of [`Part`]s in the common move's order, for a loop without the general cases.
#[derive(Debug)]
pub(super) struct Simple {
    /// The motion code, when the block starts with one ([`Part::Code`]).
    pub code: Option<String>,
    /// Whether the words put off to a move come next ([`Part::Mods`]).
    pub mods: bool,
    /// The numbers, in order.
    pub nums: Vec<Num>,
}

impl Simple {
    fn of(parts: &[Part]) -> Option<Simple> {
        let mut rest = parts;
        let code = match rest.first() {
            Some(Part::Code(c)) => {
                rest = &rest[1..];
                Some(c.clone())
            }
            _ => None,
        };
        let mods = matches!(rest.first(), Some(Part::Mods(_)));
        if mods {
            rest = &rest[1..];
        }
        let nums = rest.iter().map(|p| if let Part::Num(n) = p { Some(*n) } else { None }).collect::<Option<Vec<Num>>>()?;
        Some(Simple { code, mods, nums })
    }
}

/// A template's blocks, sorted into parts.
#[derive(Debug)]
pub(super) struct Layout(pub Vec<LayoutBlock>);

impl Layout {
    /// The layout of `t` under the rules `out`; `motion` for a move's template, whose first
    /// word may be its motion code.
    pub(super) fn of(t: &Template, out: &Output, motion: bool) -> Layout {
        let blocks =
            t.0.iter()
                .map(|b| {
                    let mut parts = Vec::with_capacity(b.words.len());
                    for (wi, w) in b.words.iter().enumerate() {
                        let part = match w.0.as_slice() {
                            [Piece::Lit(l)] if motion && wi == 0 && out.modal_motion => Part::Code(l.clone()),
                            [Piece::Var { value: Value::Mods, .. }] => Part::Mods(wi),
                            [Piece::Var { value, format, force }] if !value.is_text() => {
                                // Without a format, the word writes nothing.
                                let Some(fi) = *format else { continue };
                                Part::Num(Num::new(*value, fi, *force, out))
                            }
                            _ => Part::Word(wi),
                        };
                        parts.push(part);
                    }
                    let moves =
                        b.words.iter().flat_map(|w| &w.0).any(|p| matches!(p, Piece::Var { value: Value::X | Value::Y | Value::Z, .. }));
                    let simple = Simple::of(&parts);
                    LayoutBlock { raw: b.raw, moves, parts, simple }
                })
                .collect();
        Layout(blocks)
    }
}
