//! Parameters and expression evaluation.
//!
//! Numbered parameters live in a dense table; named ones in slots, a name given its slot the
//! first time it is met (the dialect's named system variables take the first ones). A block
//! the driver keeps to run again (a loop's, a subroutine's) has its names resolved to slots
//! once (`resolve`, into `Block::resolved`): its passes read and write by index, without a
//! name compared or an allocation; its expressions are then written once in postfix order with
//! the slots in them (`Block::flat`), which `eval_fast` runs as a short list of steps rather
//! than a walk of the tree. Other expressions are evaluated in place, over the block's arena.

use std::collections::BTreeMap;

use crate::syntax::{BinOp, Block, Expr, ExprId, FlatOp, Func};

/// Parameters below this number live in a dense table (LinuxCNC has #1 to #5602; Fanuc
/// permanent variables reach #999 and system variables beyond).
pub const MAX_PARAM: usize = 10_000;

pub use crate::dialect::MAX_HIGH_PARAM;

/// The vacant value of Fanuc Macro B (`#0`): a NaN that arithmetic treats as zero and
/// `EQ`/`NE` tell apart from zero.
pub const NULL: f64 = f64::NAN;

/// A value that comes from outside the file: the caller's arguments, retained common
/// variables, machine data, global user data. A NaN with its own payload, so that it travels
/// through the parameter table like any value; arithmetic on it stays unknown (see [`eval`]),
/// and a word whose value is unknown is omitted, as a vacant one is, with a note.
pub const UNKNOWN: f64 = f64::from_bits(0x7FF8_0000_0BAD_F00D);

/// Whether `v` is [`UNKNOWN`] (whatever its sign: negation flips only the sign bit).
pub fn is_unknown(v: f64) -> bool {
    v.to_bits() & !(1 << 63) == UNKNOWN.to_bits()
}

/// Where the first unknown value an evaluation read came from.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum UnknownSource {
    /// A numbered parameter (`#101`, `R5`).
    Numbered(u32),
    /// A named parameter (`_X_HOME`, a `PROC` argument).
    Named(String),
    /// A text literal (`"X1"`): text values are not evaluated.
    Text,
}

/// Numbered and named parameters.
#[derive(Clone, Debug)]
pub struct Params {
    numbered: Dense,
    /// Parameters from [`MAX_PARAM`] on that were written; the others read as `fill`, or as
    /// [`UNKNOWN`] inside one of `high_unknown`'s ranges.
    high: BTreeMap<u32, f64>,
    high_unknown: Vec<(u32, u32)>,
    fill: f64,
    /// The highest parameter number the control has.
    highest: usize,
    /// Named parameters by slot: a name is given its slot once ([`Params::slot`]), and its
    /// value is then read and written by index. Slots are never given back: their number is
    /// that of the names the program writes or reads.
    named: Named,
    /// FIX and FUP round toward and away from zero (Fanuc family) instead of down and up.
    pub magnitude_rounding: bool,
    /// The first unknown value read since [`Params::take_unknown_read`] (the interpreter
    /// names it in its notes).
    unknown_read: std::cell::RefCell<Option<UnknownSource>>,
    /// Where the unknown value a parameter holds came from, when the program set it from
    /// one (`Q1930 = Q1900 - Q108`: from Q108), so that a message names the outside value.
    origins: BTreeMap<UnknownSource, UnknownSource>,
    /// `#<_hal[pin]>` reads a pin of the running machine (LinuxCNC `HAL_PIN_VARS=1` in the
    /// machine's configuration): unknown, and the pin exists.
    pub hal_pins: bool,
}

/// Whether a named parameter (normalised) reads a HAL pin: `_hal[pin]`.
fn is_hal_pin(name: &str) -> bool {
    name.get(..5).is_some_and(|p| p.eq_ignore_ascii_case("_hal["))
}

impl Default for Params {
    fn default() -> Params {
        Params::new(false)
    }
}

impl PartialEq for Params {
    /// Equal values in every parameter (a vacant or NaN value equals only itself).
    fn eq(&self, other: &Params) -> bool {
        let bits = |a: &f64, b: &f64| a.to_bits() == b.to_bits();
        self.numbered.same(&other.numbered)
            && self.high.len() == other.high.len()
            && self.high.iter().zip(&other.high).all(|((ka, a), (kb, b))| ka == kb && bits(a, b))
            && self.named.same_values(&other.named)
    }
}

/// Values in a page of the numbered table.
const PAGE: usize = 256;

/// The numbered parameters below [`MAX_PARAM`], in pages shared between copies until one is
/// written: a loop's state is kept at some of its passes to compare with later ones, and
/// such a copy costs a few pages, not the table.
#[derive(Clone, Debug)]
struct Dense {
    pages: Vec<std::sync::Arc<[f64; PAGE]>>,
}

impl Dense {
    fn new(fill: f64) -> Dense {
        // One page shared by all until written: copies of it are what a write makes.
        let page = std::sync::Arc::new([fill; PAGE]);
        Dense { pages: (0..MAX_PARAM.div_ceil(PAGE)).map(|_| std::sync::Arc::clone(&page)).collect() }
    }

    #[inline]
    fn get(&self, i: usize) -> f64 {
        self.pages[i / PAGE][i % PAGE]
    }

    #[inline]
    fn set(&mut self, i: usize, v: f64) {
        std::sync::Arc::make_mut(&mut self.pages[i / PAGE])[i % PAGE] = v;
    }

    fn fill(&mut self, range: std::ops::RangeInclusive<usize>, v: f64) {
        for i in range {
            self.set(i, v);
        }
    }

    /// Equal values everywhere (a vacant or NaN value equals only itself).
    fn same(&self, other: &Dense) -> bool {
        self.pages.len() == other.pages.len()
            && self
                .pages
                .iter()
                .zip(&other.pages)
                .all(|(a, b)| std::sync::Arc::ptr_eq(a, b) || a.iter().zip(b.iter()).all(|(x, y)| x.to_bits() == y.to_bits()))
    }
}

/// The named parameters: each name's slot, and the slots' values (`None` while unset).
#[derive(Clone, Debug, Default)]
struct Named {
    /// The names and their slots, shared between copies (names are added, never changed).
    index: std::sync::Arc<NameIndex>,
    values: Vec<Option<f64>>,
}

#[derive(Clone, Debug, Default)]
struct NameIndex {
    slots: BTreeMap<Box<str>, u32>,
    /// By slot: the name, and whether it is local to a subroutine (no leading `_`).
    names: Vec<Box<str>>,
    local: Vec<bool>,
}

/// Whether a named parameter is global to every program the control runs (a leading `_`:
/// LinuxCNC `#<_td>`), not local to a subroutine.
pub(crate) fn is_global(name: &str) -> bool {
    name.starts_with('_')
}

impl Named {
    fn slot(&mut self, name: &str) -> u32 {
        if let Some(&s) = self.index.slots.get(name) {
            return s;
        }
        let index = std::sync::Arc::make_mut(&mut self.index);
        let s = index.names.len() as u32;
        index.slots.insert(name.into(), s);
        index.names.push(name.into());
        index.local.push(!is_global(name));
        self.values.push(None);
        s
    }

    /// Whether both hold the same names with the same values (slots given in the same order,
    /// as two states of one run have them; a slot one has not given yet is unset).
    fn same_values(&self, other: &Named) -> bool {
        let n = self.values.len().max(other.values.len());
        (0..n).all(|k| match (self.values.get(k).copied().flatten(), other.values.get(k).copied().flatten()) {
            (None, None) => true,
            (Some(a), Some(b)) => a.to_bits() == b.to_bits() && self.index.names[k] == other.index.names[k],
            _ => false,
        })
    }
}

/// No slot: the expression or assignment names no parameter ([`Block::resolved`]).
pub const NO_SLOT: u32 = u32::MAX;

/// Resolves the parameter names of `block` to their slots in `params`, once, for a block
/// kept to run again ([`Block::resolved`]): by expression, then by assignment.
pub fn resolve(block: &mut Block, params: &mut Params) {
    let mut resolved = std::mem::take(&mut block.resolved);
    resolved.clear();
    for e in &block.exprs {
        resolved.push(match *e {
            Expr::Named(r) => params.slot(&normalised(block.text(r))),
            _ => NO_SLOT,
        });
    }
    for a in &block.assigns {
        resolved.push(match a.target {
            crate::syntax::ParamTarget::Named(r) => params.slot(&normalised(block.text(r))),
            _ => NO_SLOT,
        });
    }
    block.resolved = resolved;
    flatten(block);
}

/// Resolves the numbered parameters `block`'s assignments set by a number written out (`Q3 =
/// ..`, `#101 = ..`, `R1=..`) to their index in the table ([`resolved_assign`]), where
/// `ordinary` says the control keeps an ordinary value there (no system variable, not the
/// vacant `#0`): the block's passes then write them without a look at the number. After
/// [`resolve`], for a block kept to run again.
pub fn resolve_numbered(block: &mut Block, ordinary: impl Fn(u32) -> bool) {
    for (k, a) in block.assigns.iter().enumerate() {
        if let crate::syntax::ParamTarget::Numbered(e) = a.target
            && let Some(&Expr::Num(n)) = block.exprs.get(e as usize)
            && (0.0..MAX_PARAM as f64).contains(&n)
            && (n as usize) as f64 == n
            && ordinary(n as u32)
            && let Some(r) = block.resolved.get_mut(block.exprs.len() + k)
        {
            *r = n as u32;
        }
    }
}

/// The deepest stack of values a flat expression may need ([`FlatOp`]); a deeper one is
/// left to the tree.
const FLAT_STACK: usize = 8;

/// Writes the expressions of `block`, its names resolved, in postfix order
/// ([`Block::flat`]): each tree from its root, so that every expression in it is computed
/// by a span of its own. A step [`eval_fast`] would turn down becomes [`FlatOp::Fail`].
fn flatten(block: &mut Block) {
    let mut flat = std::mem::take(&mut block.flat);
    let mut spans = std::mem::take(&mut block.flat_spans);
    flat.clear();
    spans.clear();
    spans.resize(block.exprs.len(), (0, 0));
    let mut inner = vec![false; block.exprs.len()];
    for e in &block.exprs {
        let mut mark = |id: ExprId| {
            if let Some(m) = inner.get_mut(id as usize) {
                *m = true;
            }
        };
        match *e {
            Expr::Param(a) | Expr::Unary(_, a) | Expr::NamedIndex(_, a) => mark(a),
            Expr::Atan2(a, b) | Expr::Binary(_, a, b) => {
                mark(a);
                mark(b);
            }
            Expr::Num(_) | Expr::Named(_) | Expr::Text(_) => {}
        }
    }
    for (root, _) in inner.iter().enumerate().filter(|(_, inner)| !**inner) {
        flatten_expr(block, root as ExprId, &mut flat, &mut spans, 0);
    }
    // An operand that went with its operation has no step of its own: one of its own, for
    // whoever evaluates it alone (a word's parameter number).
    for (id, span) in spans.iter_mut().enumerate().filter(|(_, span)| span.1 == 0) {
        let step = match operand(block, BinOp::Add, id as ExprId) {
            Some(FlatOp::BinaryNum(_, v)) => FlatOp::Num(v),
            Some(FlatOp::BinaryParam(_, i)) => FlatOp::Param(i),
            Some(FlatOp::BinarySlot(_, s)) => FlatOp::Slot(s),
            _ => continue,
        };
        *span = (flat.len() as u32, flat.len() as u32 + 1);
        flat.push(step);
    }
    block.flat = flat;
    block.flat_spans = spans;
}

/// Writes expression `id` in postfix order and records its span; returns the depth of stack
/// it needs. `level` is how deep the tree is here (a tree deeper than it could ever need is
/// not written further).
fn flatten_expr(block: &Block, id: ExprId, flat: &mut Vec<FlatOp>, spans: &mut [(u32, u32)], level: usize) -> usize {
    let start = flat.len() as u32;
    let Some(&e) = block.exprs.get(id as usize) else {
        flat.push(FlatOp::Fail);
        return 1;
    };
    let mut sub = |id: ExprId, flat: &mut Vec<FlatOp>| {
        if level > 4 * FLAT_STACK {
            flat.push(FlatOp::Fail);
            return FLAT_STACK + 1;
        }
        flatten_expr(block, id, flat, spans, level + 1)
    };
    let depth = match e {
        Expr::Num(v) if v.is_nan() => {
            flat.push(FlatOp::Fail);
            1
        }
        Expr::Num(v) => {
            flat.push(FlatOp::Num(v));
            1
        }
        Expr::Param(inner) => match block.exprs.get(inner as usize) {
            // As `eval_fast` reads a parameter named by a number.
            Some(&Expr::Num(n)) => {
                let whole = (0.0..MAX_PARAM as f64).contains(&n) && (n as usize) as f64 == n;
                flat.push(if whole { FlatOp::Param(n as u32) } else { FlatOp::Fail });
                1
            }
            _ => {
                let d = sub(inner, flat);
                flat.push(FlatOp::ParamAt);
                d
            }
        },
        Expr::Named(_) => {
            flat.push(resolved(block, id).map_or(FlatOp::Fail, FlatOp::Slot));
            1
        }
        Expr::Unary(Func::Exists, _) | Expr::Binary(BinOp::Concat, ..) | Expr::Text(_) | Expr::NamedIndex(..) => {
            flat.push(FlatOp::Fail);
            1
        }
        Expr::Unary(f, inner) => {
            let d = sub(inner, flat);
            flat.push(FlatOp::Unary(f));
            d
        }
        Expr::Atan2(a, b) => {
            let d = sub(a, flat).max(1 + sub(b, flat));
            flat.push(FlatOp::Atan2);
            d
        }
        // An operand read and used at once goes with its operation: the right one, or the
        // left one where the operands may change places (IEEE 754 addition and
        // multiplication give the same bits either way).
        Expr::Binary(op, a, b) => match (operand(block, op, b), operand(block, op, a)) {
            (Some(with), _) => {
                let d = sub(a, flat);
                flat.push(with);
                d
            }
            (None, Some(with)) if matches!(op, BinOp::Add | BinOp::Mul) => {
                let d = sub(b, flat);
                flat.push(with);
                d
            }
            _ => {
                let d = sub(a, flat).max(1 + sub(b, flat));
                flat.push(FlatOp::Binary(op));
                d
            }
        },
    };
    // A span only where the stack it needs is at hand (an expression written twice keeps
    // its first).
    if depth <= FLAT_STACK && spans.get(id as usize).is_some_and(|s| s.1 == 0) {
        spans[id as usize] = (start, flat.len() as u32);
    }
    depth
}

/// The step that applies `op` with expression `id` of `block` for its operand, where that is
/// one `flatten_expr` writes in a single step: a number, a numbered parameter of a whole
/// number in the table, a name resolved to its slot.
fn operand(block: &Block, op: BinOp, id: ExprId) -> Option<FlatOp> {
    match *block.exprs.get(id as usize)? {
        Expr::Num(v) if !v.is_nan() => Some(FlatOp::BinaryNum(op, v)),
        Expr::Param(inner) => match *block.exprs.get(inner as usize)? {
            Expr::Num(n) if (0.0..MAX_PARAM as f64).contains(&n) && (n as usize) as f64 == n => Some(FlatOp::BinaryParam(op, n as u32)),
            _ => None,
        },
        Expr::Named(_) => resolved(block, id).map(|s| FlatOp::BinarySlot(op, s)),
        _ => None,
    }
}

/// Evaluates the flat steps `ops` ([`flatten`]) as [`eval_tree`] evaluates their tree: `None`
/// where it gives none (a step turned down, a value it cannot use, a vacant or unknown
/// value read or made anywhere in the tree).
///
/// The value on top is kept apart (`acc`), the values below it on a stack whose depth
/// [`flatten`] has checked, so that an index into it is taken modulo its size and needs no
/// bounds check.
fn eval_flat(ops: &[FlatOp], params: &Params) -> Option<f64> {
    const MASK: usize = FLAT_STACK - 1;
    let mut stack = [0.0f64; FLAT_STACK];
    // Values below `acc`, the first of them the empty value `acc` starts with.
    let mut below = 0usize;
    let mut acc = 0.0f64;
    // A NaN met anywhere: the tree would have stopped there.
    let mut nan = false;
    for &op in ops {
        acc = match op {
            FlatOp::Num(v) => {
                stack[below & MASK] = acc;
                below += 1;
                v
            }
            FlatOp::Param(i) => {
                stack[below & MASK] = acc;
                below += 1;
                params.numbered.get(i as usize)
            }
            FlatOp::Slot(s) => {
                stack[below & MASK] = acc;
                below += 1;
                (*params.named.values.get(s as usize)?)?
            }
            FlatOp::ParamAt => {
                if !(0.0..MAX_PARAM as f64).contains(&acc) || (acc as usize) as f64 != acc {
                    return None;
                }
                params.numbered.get(acc as usize)
            }
            FlatOp::Unary(f) => match f {
                Func::Fix if params.magnitude_rounding => acc.trunc(),
                Func::Fup if params.magnitude_rounding => {
                    if acc < 0.0 {
                        acc.floor()
                    } else {
                        acc.ceil()
                    }
                }
                _ => unary(f, acc).ok()?,
            },
            FlatOp::Atan2 => {
                below = below.wrapping_sub(1);
                stack[below & MASK].atan2(acc).to_degrees()
            }
            FlatOp::Binary(op) => {
                below = below.wrapping_sub(1);
                operate(op, stack[below & MASK], acc)?
            }
            // The operand goes right: where it was the left one, the operation is one whose
            // operands may change places (`flatten_expr`).
            FlatOp::BinaryNum(op, v) => operate(op, acc, v)?,
            FlatOp::BinaryParam(op, i) => {
                let v = params.numbered.get(i as usize);
                nan |= v.is_nan();
                operate(op, acc, v)?
            }
            FlatOp::BinarySlot(op, s) => {
                let v = (*params.named.values.get(s as usize)?)?;
                nan |= v.is_nan();
                operate(op, acc, v)?
            }
            FlatOp::Fail => return None,
        };
        nan |= acc.is_nan();
    }
    (!nan && below == 1).then_some(acc)
}

/// `a op b` as [`eval_tree`] computes it for ordinary numbers; `None` where it gives none.
#[inline(always)]
fn operate(op: BinOp, a: f64, b: f64) -> Option<f64> {
    match op {
        BinOp::Add => Some(a + b),
        BinOp::Sub => Some(a - b),
        BinOp::Mul => Some(a * b),
        _ => binary_value(op, a, b, |c: bool| f64::from(u8::from(c))).ok(),
    }
}

/// The slot expression `id` of `block` names, where the block has its names resolved.
#[inline]
pub fn resolved(block: &Block, id: ExprId) -> Option<u32> {
    block.resolved.get(id as usize).copied().filter(|&s| s != NO_SLOT)
}

/// The slot assignment `k` of `block` sets, where the block has its names resolved, or the
/// index of the numbered parameter it sets, where [`resolve_numbered`] resolved it.
#[inline]
pub fn resolved_assign(block: &Block, k: usize) -> Option<u32> {
    block.resolved.get(block.exprs.len() + k).copied().filter(|&s| s != NO_SLOT)
}

/// A subroutine's caller's local named parameters, saved by [`Params::take_local_names`].
#[derive(Clone, Debug, Default)]
pub struct SavedNames(Vec<(u32, f64)>);

/// Why an expression has no value.
#[derive(Clone, Debug, PartialEq)]
pub enum EvalError {
    /// A named parameter that was never set.
    Undefined(String),
    /// A parameter number outside the table.
    BadIndex(f64),
    /// Division by zero or a function outside its domain.
    Domain(&'static str),
}

impl Params {
    /// A table whose variables start vacant (`null`) or at zero. `#0` is always vacant in
    /// the first case.
    pub fn new(null: bool) -> Params {
        Params {
            numbered: Dense::new(if null { NULL } else { 0.0 }),
            high: BTreeMap::new(),
            high_unknown: Vec::new(),
            fill: if null { NULL } else { 0.0 },
            highest: MAX_PARAM - 1,
            named: Named::default(),
            magnitude_rounding: false,
            unknown_read: std::cell::RefCell::new(None),
            origins: BTreeMap::new(),
            hal_pins: false,
        }
    }

    /// An unset named parameter read: a HAL pin where the machine's configuration lets the
    /// program read them (unknown), else undefined.
    fn unset_named(&self, name: &str) -> Result<f64, EvalError> {
        if self.hal_pins && is_hal_pin(name) {
            self.note_unknown(|| UnknownSource::Named(name.to_owned()));
            return Ok(UNKNOWN);
        }
        Err(EvalError::Undefined(name.to_owned()))
    }

    /// Lets the table reach parameter `n` (at most [`MAX_HIGH_PARAM`] - 1): the control's
    /// highest variable.
    pub fn set_highest(&mut self, n: u32) {
        self.highest = (n as usize).clamp(MAX_PARAM - 1, MAX_HIGH_PARAM - 1);
    }

    /// Sets the numbered range `first..=last` to [`UNKNOWN`]: values the program finds set.
    pub fn mark_unknown(&mut self, first: u32, last: u32) {
        if last as usize >= MAX_PARAM {
            self.high_unknown.push((first.max(MAX_PARAM as u32), last));
        }
        let last = (last as usize).min(MAX_PARAM - 1);
        if (first as usize) <= last {
            self.numbered.fill(first as usize..=last, UNKNOWN);
        }
    }

    /// The first unknown value read since [`Params::take_unknown_read`].
    pub fn unknown_read_peek(&self) -> Option<UnknownSource> {
        self.unknown_read.borrow().clone()
    }

    /// The first unknown value read since the last call, and forgets it.
    pub fn take_unknown_read(&self) -> Option<UnknownSource> {
        self.unknown_read.borrow_mut().take()
    }

    /// The outside value the unknown value of `key` came from: `key` itself unless the
    /// program set it from another ([`Params::derive`]).
    fn origin(&self, key: UnknownSource) -> UnknownSource {
        self.origins.get(&key).cloned().unwrap_or(key)
    }

    /// Records that parameter `target` was just set from the unknown value `from` came from
    /// (`None`: from none, or a known value).
    pub fn derive(&mut self, target: UnknownSource, from: Option<UnknownSource>) {
        match from {
            Some(from) if from != target => {
                self.origins.insert(target, from);
            }
            _ if !self.origins.is_empty() => {
                self.origins.remove(&target);
            }
            _ => {}
        }
    }

    /// Whether [`Params::derive`] has anything to do for a value set from `from`: a value
    /// from outside the file, or an origin to forget (the usual case has neither).
    #[inline]
    pub fn derives(&self, from: &Option<UnknownSource>) -> bool {
        from.is_some() || !self.origins.is_empty()
    }

    fn note_unknown(&self, source: impl FnOnce() -> UnknownSource) {
        let mut r = self.unknown_read.borrow_mut();
        if r.is_none() {
            *r = Some(source());
        }
    }

    /// Saves and resets the numbered range `first..=last` (a call's locals); returns the
    /// saved values for [`Params::restore`].
    pub fn push_locals(&mut self, first: u16, last: u16, reset: f64) -> Vec<f64> {
        let r = first as usize..=(last as usize).min(MAX_PARAM - 1);
        let saved = r.clone().map(|i| self.numbered.get(i)).collect();
        self.numbered.fill(r, reset);
        saved
    }

    /// Puts back the values of `saved`, an earlier copy of this table, keeping the slots
    /// given since (unset again), so that blocks resolved to them stay right.
    pub fn restore_values(&mut self, saved: Params) {
        let named = std::mem::take(&mut self.named);
        *self = saved;
        let values = std::mem::replace(&mut self.named, named).values;
        for (k, v) in self.named.values.iter_mut().enumerate() {
            *v = values.get(k).copied().flatten();
        }
    }

    /// Restores locals saved by [`Params::push_locals`].
    pub fn restore(&mut self, first: u16, saved: &[f64]) {
        let f = first as usize;
        for (k, &v) in saved.iter().enumerate() {
            self.numbered.set(f + k, v);
        }
    }

    /// Named parameters that are local to a subroutine (no leading `_`), unset and returned
    /// for [`Params::restore_named`].
    pub fn take_local_names(&mut self) -> SavedNames {
        let n = &mut self.named;
        let mut saved = Vec::new();
        for (k, v) in n.values.iter_mut().enumerate() {
            if n.index.local[k]
                && let Some(v) = v.take()
            {
                saved.push((k as u32, v));
            }
        }
        SavedNames(saved)
    }

    /// Puts back the caller's local names, dropping the callee's.
    pub fn restore_named(&mut self, saved: SavedNames) {
        let n = &mut self.named;
        for (k, v) in n.values.iter_mut().enumerate() {
            if n.index.local[k] {
                *v = None;
            }
        }
        for (k, v) in saved.0 {
            n.values[k as usize] = Some(v);
        }
    }

    /// The value of numbered parameter `n`.
    pub fn get(&self, n: f64) -> Result<f64, EvalError> {
        let i = match index(n, self.highest) {
            Ok(i) => i,
            Err(e) => return self.field(n).ok_or(e),
        };
        let v = if i < MAX_PARAM {
            self.numbered.get(i)
        } else {
            let k = i as u32;
            match self.high.get(&k) {
                Some(&v) => v,
                None if self.high_unknown.iter().any(|&(a, b)| (a..=b).contains(&k)) => UNKNOWN,
                None => self.fill,
            }
        };
        if is_unknown(v) {
            self.note_unknown(|| self.origin(UnknownSource::Numbered(i as u32)));
        }
        Ok(v)
    }

    /// A field of the control's own data read with a fraction (`#30057.25`, a part of
    /// parameter 30057): unknown, as the whole value is; `None` where the whole is not
    /// data from outside the file (a fraction then names no variable).
    fn field(&self, n: f64) -> Option<f64> {
        if !n.is_finite() || n < 0.0 || n.fract() == 0.0 {
            return None;
        }
        let whole = self.get(n.trunc()).ok()?;
        is_unknown(whole).then_some(UNKNOWN)
    }

    /// Sets numbered parameter `n`.
    pub fn set(&mut self, n: f64, v: f64) -> Result<(), EvalError> {
        let i = index(n, self.highest)?;
        if i < MAX_PARAM {
            self.numbered.set(i, v);
        } else {
            self.high.insert(i as u32, v);
        }
        Ok(())
    }

    /// Sets numbered parameter `n`, a whole number: as [`Params::set`] does, without the
    /// look at a fraction.
    #[inline]
    pub fn set_whole(&mut self, n: u32, v: f64) -> Result<(), EvalError> {
        let i = n as usize;
        if i > self.highest {
            return Err(EvalError::BadIndex(f64::from(n)));
        }
        if i < MAX_PARAM {
            self.numbered.set(i, v);
        } else {
            self.high.insert(n, v);
        }
        Ok(())
    }

    /// The value of a named parameter.
    pub fn get_named(&self, name: &str) -> Result<f64, EvalError> {
        match self.named.index.slots.get(name) {
            Some(&s) => self.get_slot(s),
            None => self.unset_named(name),
        }
    }

    /// Sets a named parameter.
    pub fn set_named(&mut self, name: &str, v: f64) {
        let s = self.named.slot(name);
        self.named.values[s as usize] = Some(v);
    }

    /// Whether a named parameter exists.
    pub fn has_named(&self, name: &str) -> bool {
        (self.hal_pins && is_hal_pin(name)) || self.named.index.slots.get(name).is_some_and(|&s| self.named.values[s as usize].is_some())
    }

    /// The slot of named parameter `name` (normalised), given now if it has none: what a
    /// read or write by [`Params::get_slot`] and [`Params::set_slot`] names.
    pub fn slot(&mut self, name: &str) -> u32 {
        self.named.slot(name)
    }

    /// The slot `name` has, if any (none: it was never read nor written).
    pub fn slot_of(&self, name: &str) -> Option<u32> {
        self.named.index.slots.get(name).copied()
    }

    /// The name of slot `s`.
    pub fn slot_name(&self, s: u32) -> &str {
        &self.named.index.names[s as usize]
    }

    /// The value of the named parameter in slot `s`.
    #[inline]
    pub fn get_slot(&self, s: u32) -> Result<f64, EvalError> {
        match self.named.values[s as usize] {
            Some(v) => {
                if is_unknown(v) {
                    self.note_unknown(|| self.origin(UnknownSource::Named(self.slot_name(s).to_owned())));
                }
                Ok(v)
            }
            None => self.unset_named(self.slot_name(s)),
        }
    }

    /// Sets numbered parameter `i`, an index [`resolve_numbered`] gave (in the table).
    #[inline]
    pub fn set_resolved(&mut self, i: u32, v: f64) {
        self.numbered.set(i as usize, v);
    }

    /// Sets the named parameter in slot `s`.
    #[inline]
    pub fn set_slot(&mut self, s: u32, v: f64) {
        self.named.values[s as usize] = Some(v);
    }
}

fn index(n: f64, highest: usize) -> Result<usize, EvalError> {
    // A whole number in range, the usual case, needs no rounding.
    if n >= 0.0 && n <= highest as f64 && (n as usize) as f64 == n {
        return Ok(n as usize);
    }
    let r = n.round();
    if (n - r).abs() > 1e-4 || r < 0.0 || r > highest as f64 {
        return Err(EvalError::BadIndex(n));
    }
    Ok(r as usize)
}

pub use crate::dialect::normalise_name;
pub(crate) use crate::dialect::normalised;

/// Evaluates expression `id` of `block` against `params`.
pub fn eval(block: &Block, id: ExprId, params: &Params) -> Result<f64, EvalError> {
    let Some(e) = block.exprs.get(id as usize) else { return Err(EvalError::Domain("invalid expression")) };
    Ok(match *e {
        Expr::Num(v) => v,
        Expr::Param(inner) => {
            let n = eval(block, inner, params)?;
            // `#[#1]` with #1 unknown: which parameter is read is unknown, and so is its value.
            if is_unknown(n) { UNKNOWN } else { params.get(n)? }
        }
        Expr::Named(r) => match resolved(block, id) {
            Some(s) => params.get_slot(s)?,
            None => params.get_named(&normalised(block.text(r)))?,
        },
        Expr::Text(_) => {
            params.note_unknown(|| UnknownSource::Text);
            UNKNOWN
        }
        Expr::NamedIndex(r, index) => {
            let i = eval(block, index, params)?;
            // `WERT[R1]` with R1 unknown: which element is read is unknown, and so is its value.
            if is_unknown(i) { UNKNOWN } else { params.get_named(&format!("{}[{}]", normalised(block.text(r)), i))? }
        }
        Expr::Unary(Func::Exists, inner) => match block.exprs.get(inner as usize) {
            Some(Expr::Named(r)) => f64::from(u8::from(match resolved(block, inner) {
                Some(s) => params.named.values[s as usize].is_some() || (params.hal_pins && is_hal_pin(params.slot_name(s))),
                None => params.has_named(&normalised(block.text(*r))),
            })),
            // The parameter number itself must evaluate (`EXISTS[###2]` reads `##2`).
            Some(&Expr::Param(i)) => f64::from(u8::from(index(eval(block, i, params)?, params.highest).is_ok_and(|i| i >= 1))),
            _ => 0.0,
        },
        Expr::Unary(f, inner) if f != Func::Exists && is_unknown(eval(block, inner, params)?) => UNKNOWN,
        Expr::Unary(Func::Fix, inner) if params.magnitude_rounding => zero_if_null(eval(block, inner, params)?).trunc(),
        Expr::Unary(Func::Fup, inner) if params.magnitude_rounding => {
            let x = zero_if_null(eval(block, inner, params)?);
            if x < 0.0 { x.floor() } else { x.ceil() }
        }
        Expr::Unary(f, inner) => unary(f, zero_if_null(eval(block, inner, params)?))?,
        Expr::Atan2(y, x) => {
            let (y, x) = (eval(block, y, params)?, eval(block, x, params)?);
            if is_unknown(y) || is_unknown(x) {
                return Ok(UNKNOWN);
            }
            zero_if_null(y).atan2(zero_if_null(x)).to_degrees()
        }
        // Text joined with text: not evaluated (its operands are read, for their own notes).
        Expr::Binary(BinOp::Concat, a, b) => {
            let _ = (eval(block, a, params)?, eval(block, b, params)?);
            params.note_unknown(|| UnknownSource::Text);
            UNKNOWN
        }
        Expr::Binary(op, a, b) => binary(op, eval(block, a, params)?, eval(block, b, params)?)?,
    })
}

/// Evaluates expression `id` of `block` as [`eval`] does, where every value it meets is an
/// ordinary number: no vacant or unknown value, no name the block has not resolved to a slot
/// ([`resolve`]), no parameter number other than a whole one below [`MAX_PARAM`], no error.
/// That is the common case of a loop's blocks, and it needs neither a `Result` nor a look at
/// unknown values. `None` otherwise (and where the result is not a number): [`eval`] then
/// gives the value, or says why there is none, as it would have.
#[inline]
pub fn eval_fast(block: &Block, id: ExprId, params: &Params) -> Option<f64> {
    // A block kept to run again has its expressions flat ([`resolve`]).
    if let Some(&(start, end)) = block.flat_spans.get(id as usize)
        && end > start
    {
        let ops = block.flat.get(start as usize..end as usize)?;
        // One step, the most common (an assignment's target, a word's parameter): no stack.
        let v = match *ops {
            [FlatOp::Num(v)] => v,
            [FlatOp::Param(i)] => params.numbered.get(i as usize),
            [FlatOp::Slot(s)] => (*params.named.values.get(s as usize)?)?,
            _ => return eval_flat(ops, params),
        };
        return (!v.is_nan()).then_some(v);
    }
    eval_tree(block, id, params)
}

/// [`eval_fast`] by a walk of the tree.
fn eval_tree(block: &Block, id: ExprId, params: &Params) -> Option<f64> {
    let v = match *block.exprs.get(id as usize)? {
        Expr::Num(v) => v,
        Expr::Param(inner) => {
            // Most parameters are named by a number (`Q3`, `#5`, `R1`): read without a call.
            let n = match *block.exprs.get(inner as usize)? {
                Expr::Num(n) => n,
                _ => eval_tree(block, inner, params)?,
            };
            // A whole number in the dense table reads as `index` rounds it.
            if !(0.0..MAX_PARAM as f64).contains(&n) || (n as usize) as f64 != n {
                return None;
            }
            params.numbered.get(n as usize)
        }
        Expr::Named(_) => (*params.named.values.get(resolved(block, id)? as usize)?)?,
        Expr::Unary(Func::Exists, _) => return None,
        Expr::Unary(Func::Fix, inner) if params.magnitude_rounding => eval_tree(block, inner, params)?.trunc(),
        Expr::Unary(Func::Fup, inner) if params.magnitude_rounding => {
            let x = eval_tree(block, inner, params)?;
            if x < 0.0 { x.floor() } else { x.ceil() }
        }
        Expr::Unary(f, inner) => unary(f, eval_tree(block, inner, params)?).ok()?,
        Expr::Atan2(y, x) => eval_tree(block, y, params)?.atan2(eval_tree(block, x, params)?).to_degrees(),
        Expr::Binary(BinOp::Concat, ..) => return None,
        Expr::Binary(op, a, b) => {
            let (a, b) = (eval_tree(block, a, params)?, eval_tree(block, b, params)?);
            binary_value(op, a, b, |c: bool| f64::from(u8::from(c))).ok()?
        }
        Expr::Text(_) | Expr::NamedIndex(..) => return None,
    };
    // A vacant or unknown value (both NaN) read or made: the general way.
    (!v.is_nan()).then_some(v)
}

/// Whether `v` is the vacant value.
pub fn is_null(v: f64) -> bool {
    v.is_nan()
}

fn zero_if_null(v: f64) -> f64 {
    if v.is_nan() { 0.0 } else { v }
}

fn unary(f: Func, x: f64) -> Result<f64, EvalError> {
    Ok(match f {
        Func::Sin => x.to_radians().sin(),
        Func::Cos => x.to_radians().cos(),
        Func::Tan => x.to_radians().tan(),
        Func::Asin if x.abs() > 1.0 => return Err(EvalError::Domain("ASIN of a value outside -1..1")),
        Func::Asin => x.asin().to_degrees(),
        Func::Acos if x.abs() > 1.0 => return Err(EvalError::Domain("ACOS of a value outside -1..1")),
        Func::Acos => x.acos().to_degrees(),
        Func::Atan => x.atan().to_degrees(),
        Func::Sqrt if x < 0.0 => return Err(EvalError::Domain("SQRT of a negative value")),
        Func::Sqrt => x.sqrt(),
        Func::Abs => x.abs(),
        Func::Round => x.round(),
        Func::Fix => x.floor(),
        Func::Fup => x.ceil(),
        Func::Ln if x <= 0.0 => return Err(EvalError::Domain("LN of a non-positive value")),
        Func::Ln => x.ln(),
        Func::Exp => x.exp(),
        Func::Exists | Func::Pow => 0.0,
        Func::Bin | Func::Bcd if x < 0.0 || x.fract() != 0.0 || x > 4_294_967_295.0 => {
            return Err(EvalError::Domain("BIN and BCD take a whole number from 0 to 2^32-1"));
        }
        // BIN: each 4-bit nibble is one decimal digit; BCD: the reverse.
        Func::Bin => {
            let (mut v, mut out, mut scale) = (x as u64, 0u64, 1u64);
            while v > 0 {
                let digit = v & 0xF;
                if digit > 9 {
                    return Err(EvalError::Domain("BIN of a value that is not BCD"));
                }
                out += digit * scale;
                scale *= 10;
                v >>= 4;
            }
            out as f64
        }
        Func::Bcd => {
            let (mut v, mut out, mut shift) = (x as u64, 0u64, 0u32);
            while v > 0 && shift < 64 {
                out |= (v % 10) << shift;
                shift += 4;
                v /= 10;
            }
            out as f64
        }
        Func::Neg => -x,
        Func::Trunc => x.trunc(),
        Func::Sgn => {
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
        Func::Frac => x.fract(),
        Func::Sq => x * x,
        Func::Log => {
            if x <= 0.0 {
                return Err(EvalError::Domain("LOG of a value that is not positive"));
            }
            x.log10()
        }
        Func::Not => f64::from(u8::from(x == 0.0)),
    })
}

fn binary(op: BinOp, a: f64, b: f64) -> Result<f64, EvalError> {
    let truth = |c: bool| f64::from(u8::from(c));
    // Unknown values: whatever the operation, the result is unknown too.
    if is_unknown(a) || is_unknown(b) {
        return Ok(UNKNOWN);
    }
    // Vacant values: EQ and NE tell them from zero; everything else reads them as zero.
    match (op, a.is_nan(), b.is_nan()) {
        (BinOp::Eq, true, _) | (BinOp::Eq, _, true) => return Ok(truth(a.is_nan() && b.is_nan())),
        (BinOp::Ne, true, _) | (BinOp::Ne, _, true) => return Ok(truth(a.is_nan() != b.is_nan())),
        _ => {}
    }
    let (a, b) = (zero_if_null(a), zero_if_null(b));
    let v = binary_value(op, a, b, truth)?;
    if v.is_nan() {
        return Err(EvalError::Domain("the operation has no real value"));
    }
    Ok(v)
}

fn binary_value(op: BinOp, a: f64, b: f64, truth: impl Fn(bool) -> f64) -> Result<f64, EvalError> {
    const EQ_TOL: f64 = 1e-6;
    Ok(match op {
        BinOp::Pow => a.powf(b),
        BinOp::Mul => a * b,
        BinOp::Div if b == 0.0 => return Err(EvalError::Domain("division by zero")),
        BinOp::Div => a / b,
        BinOp::Mod if b == 0.0 => return Err(EvalError::Domain("MOD by zero")),
        BinOp::Mod => a.rem_euclid(b.abs()),
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Eq => truth((a - b).abs() < EQ_TOL),
        BinOp::Ne => truth((a - b).abs() >= EQ_TOL),
        BinOp::Gt => truth(a > b),
        BinOp::Ge => truth(a >= b),
        BinOp::Lt => truth(a < b),
        BinOp::Le => truth(a <= b),
        BinOp::And => truth(a != 0.0 && b != 0.0),
        BinOp::Or => truth(a != 0.0 || b != 0.0),
        BinOp::Xor => truth((a != 0.0) != (b != 0.0)),
        // Text is not evaluated (see `eval`).
        BinOp::Concat => UNKNOWN,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;
    use crate::syntax::Parser;

    /// Every expression of every block, evaluated from the flat form and by the tree walk,
    /// gives the same value, bit for bit, or none in both: numbers, parameters by number and
    /// by a computed number, names, functions, comparisons, a division by zero, a vacant and
    /// an unknown value, `EXISTS`, and a tree too deep for the flat form's stack.
    #[test]
    fn the_flat_form_evaluates_as_the_tree_does() {
        let registry = Registry::shipped();
        let d = registry.get("linuxcnc").unwrap();
        let deep = format!("#<deep> = [{}1{}]", "[1 + ".repeat(12), "]".repeat(12));
        let text = [
            "#<a> = [#1 * 0.1 + SIN[#2] / [#3 - 3]]",
            "#<b> = [#1 * 0.1 + SIN[#2 * 3.6] * COS[#<x> * 3.6] - 1]",
            "#<c> = [#[#4 + 1] * 2 + #[#4 + 0.5]]",
            "#<d> = [ATAN[#1]/[#2] ** 2 + ABS[-#1] + FIX[-2.5] + FUP[2.5] + ROUND[#1]]",
            "#<e> = [[#1 LT 3] AND [#2 GT 1] OR [#1 EQ #2] + [5 MOD 3]]",
            "#<f> = [EXISTS[#<x>] + #<nowhere> + 1]",
            "#<g> = [#6 + 1] #<h> = [SQRT[-#2]] #<i> = [#7 * 2]",
            "G1 X[#<x> * 2] Y#<x> Z-#1",
            deep.as_str(),
            // An operand taken with its operation: right or (added, multiplied) left, a
            // vacant, unknown or unset one, an operation on it without a value.
            "#<j> = [2 - #1 / #<x> + [#1 - #3] * #2 MOD 7] #<k> = [0.5 * [#1 + #2] + #6] #<l> = [#7 + [1 - #1]]",
            "#<m> = [#<nowhere> * [#1 + 1]] #<n> = [[#1 + 1] / 0] #<o> = [[#1 * #2] LT 1000 AND [#3 EQ 3]]",
        ]
        .join("\n");
        let mut params = Params::new(false);
        for (n, v) in [(1.0, 2.5), (2.0, 30.0), (3.0, 3.0), (4.0, 4.0), (5.0, 7.0), (6.0, UNKNOWN), (7.0, NULL)] {
            params.set(n, v).unwrap();
        }
        params.set_named("x", 1.25);
        let mut parser = Parser::new(text.as_str(), &d);
        let (mut block, mut diags, mut blocks) = (Block::default(), Vec::new(), 0);
        let mut flat_ones = 0;
        while parser.next_block(&mut block, &mut diags) {
            blocks += 1;
            resolve(&mut block, &mut params);
            assert_eq!(block.flat_spans.len(), block.exprs.len());
            for id in 0..block.exprs.len() as ExprId {
                let (fast, tree) = (eval_fast(&block, id, &params), eval_tree(&block, id, &params));
                assert_eq!(fast.map(f64::to_bits), tree.map(f64::to_bits), "{} expression {id}", block.source());
                flat_ones += usize::from(block.flat_spans[id as usize].1 > block.flat_spans[id as usize].0);
            }
        }
        assert_eq!(blocks, 11);
        assert!(flat_ones > 40, "{flat_ones}");
        // Values: the second block's, and the deep one's by the tree.
        let b = {
            let mut p = Parser::new("#<b> = [#1 * 0.1 + SIN[#2 * 3.6] * COS[#<x> * 3.6] - 1]", &d);
            let mut b = Block::default();
            assert!(p.next_block(&mut b, &mut diags));
            resolve(&mut b, &mut params);
            b
        };
        let want = 2.5 * 0.1 + (30.0f64 * 3.6).to_radians().sin() * (1.25f64 * 3.6).to_radians().cos() - 1.0;
        assert_eq!(eval_fast(&b, b.assigns[0].value, &params), Some(want));
        // Its numbers and names go with their operations (`* 0.1`, `* 3.6` twice, `- 1`):
        // eleven steps, not fifteen.
        let (start, end) = b.flat_spans[b.assigns[0].value as usize];
        assert_eq!(end - start, 11, "{:?}", &b.flat[start as usize..end as usize]);
    }
}
