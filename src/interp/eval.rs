//! Parameters and expression evaluation.

use std::collections::BTreeMap;

use crate::syntax::{BinOp, Block, Expr, ExprId, Func};

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
    numbered: Vec<f64>,
    /// Parameters from [`MAX_PARAM`] on that were written; the others read as `fill`, or as
    /// [`UNKNOWN`] inside one of `high_unknown`'s ranges.
    high: BTreeMap<u32, f64>,
    high_unknown: Vec<(u32, u32)>,
    fill: f64,
    /// The highest parameter number the control has.
    highest: usize,
    named: BTreeMap<String, f64>,
    /// FIX and FUP round toward and away from zero (Fanuc family) instead of down and up.
    pub magnitude_rounding: bool,
    /// The first unknown value read since [`Params::take_unknown_read`] (the interpreter
    /// names it in its notes).
    unknown_read: std::cell::RefCell<Option<UnknownSource>>,
    /// Where the unknown value a parameter holds came from, when the program set it from
    /// one (`Q1930 = Q1900 - Q108`: from Q108), so that a message names the outside value.
    origins: BTreeMap<UnknownSource, UnknownSource>,
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
        self.numbered.len() == other.numbered.len()
            && self.numbered.iter().zip(&other.numbered).all(|(a, b)| bits(a, b))
            && self.high.len() == other.high.len()
            && self.high.iter().zip(&other.high).all(|((ka, a), (kb, b))| ka == kb && bits(a, b))
            && self.named.len() == other.named.len()
            && self.named.iter().zip(&other.named).all(|((ka, a), (kb, b))| ka == kb && bits(a, b))
    }
}

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
            numbered: vec![if null { NULL } else { 0.0 }; MAX_PARAM],
            high: BTreeMap::new(),
            high_unknown: Vec::new(),
            fill: if null { NULL } else { 0.0 },
            highest: MAX_PARAM - 1,
            named: BTreeMap::new(),
            magnitude_rounding: false,
            unknown_read: std::cell::RefCell::new(None),
            origins: BTreeMap::new(),
        }
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
            self.numbered[first as usize..=last].fill(UNKNOWN);
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
        let saved = self.numbered[r.clone()].to_vec();
        self.numbered[r].fill(reset);
        saved
    }

    /// Restores locals saved by [`Params::push_locals`].
    pub fn restore(&mut self, first: u16, saved: &[f64]) {
        let f = first as usize;
        self.numbered[f..f + saved.len()].copy_from_slice(saved);
    }

    /// Named parameters that are local to a subroutine (no leading `_`), removed and
    /// returned for [`Params::restore_named`].
    pub fn take_local_names(&mut self) -> BTreeMap<String, f64> {
        let (globals, locals) = std::mem::take(&mut self.named).into_iter().partition(|(k, _)| k.starts_with('_'));
        self.named = globals;
        locals
    }

    /// Puts back the caller's local names, dropping the callee's.
    pub fn restore_named(&mut self, locals: BTreeMap<String, f64>) {
        self.named.retain(|k, _| k.starts_with('_'));
        self.named.extend(locals);
    }

    /// The value of numbered parameter `n`.
    pub fn get(&self, n: f64) -> Result<f64, EvalError> {
        let i = match index(n, self.highest) {
            Ok(i) => i,
            Err(e) => return self.field(n).ok_or(e),
        };
        let v = if i < MAX_PARAM {
            self.numbered[i]
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
            self.numbered[i] = v;
        } else {
            self.high.insert(i as u32, v);
        }
        Ok(())
    }

    /// The value of a named parameter.
    pub fn get_named(&self, name: &str) -> Result<f64, EvalError> {
        let v = self.named.get(name).copied().ok_or_else(|| EvalError::Undefined(name.to_owned()))?;
        if is_unknown(v) {
            self.note_unknown(|| self.origin(UnknownSource::Named(name.to_owned())));
        }
        Ok(v)
    }

    /// Sets a named parameter.
    // Inlined: `refresh_system_vars` sets a few named values on every block.
    #[inline]
    pub fn set_named(&mut self, name: &str, v: f64) {
        match self.named.get_mut(name) {
            Some(slot) => *slot = v,
            None => {
                self.named.insert(name.to_owned(), v);
            }
        }
    }

    /// Whether a named parameter exists.
    pub fn has_named(&self, name: &str) -> bool {
        self.named.contains_key(name)
    }
}

fn index(n: f64, highest: usize) -> Result<usize, EvalError> {
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
        Expr::Named(r) => params.get_named(&normalised(block.text(r)))?,
        Expr::Text(_) => {
            params.note_unknown(|| UnknownSource::Text);
            UNKNOWN
        }
        Expr::NamedIndex(r, index) => {
            let i = eval(block, index, params)?;
            params.get_named(&format!("{}[{}]", normalised(block.text(r)), i))?
        }
        Expr::Unary(Func::Exists, inner) => match block.exprs.get(inner as usize) {
            Some(Expr::Named(r)) => f64::from(u8::from(params.has_named(&normalised(block.text(*r))))),
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
