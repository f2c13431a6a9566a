//! Expression trees, stored in a per-block arena.

use crate::text::TextRange;

/// Index of an expression in [`super::Block::exprs`].
pub type ExprId = u32;

/// A unary function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    /// Sine of degrees.
    Sin,
    /// Cosine of degrees.
    Cos,
    /// Tangent of degrees.
    Tan,
    /// Arc sine, degrees.
    Asin,
    /// Arc cosine, degrees.
    Acos,
    /// Arc tangent, degrees (one-argument form).
    Atan,
    /// Square root.
    Sqrt,
    /// Absolute value.
    Abs,
    /// Round half away from zero.
    Round,
    /// Round down (floor in LinuxCNC).
    Fix,
    /// Round up (ceiling in LinuxCNC).
    Fup,
    /// Natural logarithm.
    Ln,
    /// e to the power.
    Exp,
    /// Whether a named parameter exists, or whether a numbered one's index is in range.
    Exists,
    /// Power, two arguments (`POW[a,b]`); parsed into a binary `**`.
    Pow,
    /// BCD to binary (Fanuc `BIN`).
    Bin,
    /// Binary to BCD (Fanuc `BCD`).
    Bcd,
    /// Negation.
    Neg,
    /// Integer part, toward zero in every dialect (Siemens `TRUNC`, Heidenhain `INT`).
    Trunc,
    /// Sign: -1, 0 or 1.
    Sgn,
    /// Fractional part.
    Frac,
    /// Square.
    Sq,
    /// Base-10 logarithm.
    Log,
    /// Logical not.
    Not,
}

impl Func {
    /// The function called `name` (upper case), if any.
    pub fn named(name: &str) -> Option<Func> {
        Some(match name {
            "SIN" => Func::Sin,
            "COS" => Func::Cos,
            "TAN" => Func::Tan,
            "ASIN" => Func::Asin,
            "ACOS" => Func::Acos,
            "ATAN" | "ATAN2" => Func::Atan,
            "SQRT" => Func::Sqrt,
            "ABS" => Func::Abs,
            "ROUND" => Func::Round,
            "FIX" => Func::Fix,
            "TRUNC" | "INT" => Func::Trunc,
            "SGN" => Func::Sgn,
            "FRAC" => Func::Frac,
            "SQ" | "POT" => Func::Sq,
            "LOG" => Func::Log,
            "NEG" => Func::Neg,
            // Siemens ROUNDUP: the next integer up (840D sl job planning, "ROUNDUP: Round up":
            // ROUNDUP(3.1) is 4, ROUNDUP(-3.1) is -3), as FUP where no magnitude rounding is set.
            "FUP" | "ROUNDUP" => Func::Fup,
            "LN" => Func::Ln,
            "EXP" => Func::Exp,
            "EXISTS" => Func::Exists,
            "POW" => Func::Pow,
            "BIN" => Func::Bin,
            "BCD" => Func::Bcd,
            "NOT" => Func::Not,
            _ => return None,
        })
    }
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `**`
    Pow,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `MOD`
    Mod,
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `EQ`
    Eq,
    /// `NE`
    Ne,
    /// `GT`
    Gt,
    /// `GE`
    Ge,
    /// `LT`
    Lt,
    /// `LE`
    Le,
    /// `AND`
    And,
    /// `OR`
    Or,
    /// `XOR`
    Xor,
    /// `<<`: joins two values as text (Siemens `"PART "<<N`); text is not evaluated.
    Concat,
}

impl BinOp {
    /// Binding strength; higher binds tighter.
    pub fn precedence(self) -> u8 {
        match self {
            BinOp::Pow => 5,
            BinOp::Mul | BinOp::Div | BinOp::Mod => 4,
            BinOp::Add | BinOp::Sub | BinOp::Concat => 3,
            BinOp::Eq | BinOp::Ne | BinOp::Gt | BinOp::Ge | BinOp::Lt | BinOp::Le => 2,
            BinOp::And | BinOp::Or | BinOp::Xor => 1,
        }
    }

    /// The word operator called `name` (upper case), if any.
    pub fn named(name: &str) -> Option<BinOp> {
        Some(match name {
            "MOD" => BinOp::Mod,
            "DIV" => BinOp::Div,
            "EQU" => BinOp::Eq,
            "EQ" => BinOp::Eq,
            "NE" => BinOp::Ne,
            "GT" => BinOp::Gt,
            "GE" => BinOp::Ge,
            "LT" => BinOp::Lt,
            "LE" => BinOp::Le,
            "AND" => BinOp::And,
            "OR" => BinOp::Or,
            "XOR" => BinOp::Xor,
            _ => return None,
        })
    }
}

/// An expression node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// A numbered parameter whose number is the inner expression (`#1`, `#[#2+1]`).
    Param(ExprId),
    /// A named parameter (`#<depth>`); the range covers the name.
    Named(TextRange),
    /// A text literal in an expression (Siemens `IF MSG=="DONE"`, `$MN_HW_SERIAL_NUMBER <>
    /// "X1"`); the range covers the text inside the quotes. Text values are not evaluated:
    /// it reads as a value the analysis does not know.
    Text(TextRange),
    /// An element of a named array (`VTOFD[1]`); the range covers the name.
    NamedIndex(TextRange, ExprId),
    /// A function of one argument.
    Unary(Func, ExprId),
    /// Two-argument arc tangent `ATAN[y]/[x]`, degrees.
    Atan2(ExprId, ExprId),
    /// A binary operation.
    Binary(BinOp, ExprId, ExprId),
}

/// One step of an expression written in postfix order ([`super::Block::flat`]): the form in
/// which the interpreter evaluates a block it runs again, once its names are resolved to
/// slots, without a walk of the tree or an allocation. A step takes its operands from the
/// top of a stack of values and leaves its result there; an operation with a number or a
/// parameter for an operand takes that operand with it, so that a value read and used at
/// once is never put on the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FlatOp {
    /// A number.
    Num(f64),
    /// The numbered parameter of this whole number (`#5`, `Q3`, `R1`).
    Param(u32),
    /// The numbered parameter whose number is the value on top (`#[#2+1]`).
    ParamAt,
    /// The named parameter in this slot.
    Slot(u32),
    /// A function of the value on top.
    Unary(Func),
    /// The two-argument arc tangent of the two values on top (y below x).
    Atan2,
    /// A binary operation on the two values on top (the left operand below).
    Binary(BinOp),
    /// A binary operation on the value on top and this number (`#1 * 0.1`), which is the
    /// right operand, or the left one of an operation whose operands may change places
    /// (`0.5 * SIN[..]`: addition and multiplication give the same bits either way).
    BinaryNum(BinOp, f64),
    /// As [`FlatOp::BinaryNum`], the operand the numbered parameter of this whole number.
    BinaryParam(BinOp, u32),
    /// As [`FlatOp::BinaryNum`], the operand the named parameter in this slot.
    BinarySlot(BinOp, u32),
    /// A step the flat form does not take (a text, an array element, `EXISTS`, a name
    /// without a slot): the expression goes the general way.
    Fail,
}
