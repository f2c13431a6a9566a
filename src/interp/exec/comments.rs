//! The comment step: a block's comments go into the canon, as comments or as the
//! directives some carry (`(MSG, ...)`, `(ABORT, ...)`, the log file ones).
//!
//! Door: [`Interpreter::comments`].

use crate::canon::{CanonOp, CanonSink};
use crate::diag::{Code, Diagnostic};
use crate::dialect::Directive;
use crate::interp::{Interpreter, eval};
use crate::syntax::Block;

impl Interpreter<'_> {
    /// The block's comments, in order; an abort ends the program there.
    pub(super) fn comments(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        for r in &block.comments {
            let text = block.text(*r);
            if !self.inch_tool_comment && inch_tool_size(text) {
                self.inch_tool_comment = true;
            }
            let op = match self.dialect.lexical.directive(text) {
                Some((Directive::Message, m)) => CanonOp::Message(m.to_owned()),
                Some((Directive::Abort, m)) => {
                    let msg = format!("the program aborts: {}; execution stops here", m.trim());
                    diags.push(Diagnostic::new(Code::ProgramAlarm, *r, msg));
                    self.st.ended = true;
                    return;
                }
                // `(LOGCLOSE)` only: with more after it, rs274 takes it for a comment.
                Some((Directive::LogFile(crate::dialect::LogFile::Close), rest)) if !rest.trim().is_empty() => {
                    CanonOp::Comment(text.to_owned())
                }
                Some((Directive::LogFile(kind), rest)) => CanonOp::Log(kind, self.log_text(kind, rest)),
                Some((Directive::Log | Directive::Simulator, _)) | None => CanonOp::Comment(text.to_owned()),
            };
            self.emit(sink, op);
        }
    }

    /// What a log-file directive writes: the file's name as written, nothing for a close, or
    /// the line with each parameter (`#1`, `#<depth>`) replaced by its value with six
    /// decimals, as rs274 writes it (`######` for one it cannot read; a `#` ending the text
    /// goes).
    fn log_text(&self, kind: crate::dialect::LogFile, rest: &str) -> String {
        use crate::dialect::LogFile;
        match kind {
            LogFile::Close => return String::new(),
            LogFile::Open | LogFile::Append => return rest.trim().to_owned(),
            LogFile::Line => {}
        }
        let mut out = String::with_capacity(rest.len());
        let mut rest = rest;
        while let Some(at) = rest.find('#') {
            out.push_str(&rest[..at]);
            let after = &rest[at + 1..];
            let digits = after.bytes().take_while(u8::is_ascii_digit).count();
            let (value, used) = if digits > 0 {
                // A system parameter reads the state now, as in an expression.
                let n = after[..digits].parse::<u32>().ok();
                let system = n.and_then(|n| self.system_value(self.dialect.macros.system_var(n)?, 0.0));
                (system.or_else(|| n.and_then(|n| self.params.get(f64::from(n)).ok())), digits)
            } else if let Some(raw) = after.strip_prefix('<').and_then(|a| a.find('>').map(|e| &a[..e])) {
                let name = eval::normalise_name(raw);
                // A system parameter reads the state now, as in an expression.
                let system = self.dialect.macros.system_named.iter().find(|(n, ..)| *n == name);
                let value = match system {
                    Some(&(_, var, constant)) => self.system_value(var, constant),
                    None => self.params.get_named(&name).ok(),
                };
                (value, raw.len() + 2)
            } else {
                (None, 0)
            };
            match value {
                Some(v) => out.push_str(&format!("{v:.6}")),
                None if used > 0 => out.push_str("######"),
                None if after.is_empty() => {}
                None => out.push('#'),
            }
            rest = &after[used..];
        }
        out.push_str(rest);
        out
    }
}

/// Whether a comment names a tool by an inch size: a fraction or a decimal followed by `"`
/// or `IN`/`INCH` (`3/4" BORING BAR`, `1/2 IN DRILL`, `.500" END MILL`) in a comment that
/// names a tool (`T04`, a bar, drill, mill, insert). Shops that work in inches label their
/// tools so. Pipe and screw threads keep inch names in metric shops too (`1/2" NPT`, `G 1/4
/// BSP`, `3/8-16 UNC`): a comment naming a thread tells nothing.
fn inch_tool_size(text: &str) -> bool {
    let up = text.to_ascii_uppercase();
    let words = ["NPT", "BSP", "UNC", "UNF", "THREAD", "PIPE", "TAP"];
    if words.iter().any(|w| up.contains(w)) {
        return false;
    }
    let tools = ["BAR", "DRILL", "MILL", "INSERT", "TOOL", "BORE", "BORING", "REAMER", "GROOV", "CUTOFF", "CUT OFF"];
    let tool_number = up.as_bytes().windows(2).any(|w| w[0] == b'T' && w[1].is_ascii_digit());
    if !tool_number && !tools.iter().any(|w| up.contains(w)) {
        return false;
    }
    let b = up.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if !(b[i].is_ascii_digit() || b[i] == b'.') || (i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'.')) {
            i += 1;
            continue;
        }
        // A number: digits with at most one point or one slash between digits.
        let start = i;
        let (mut slash, mut point, mut digits) = (false, false, 0);
        while i < b.len() {
            match b[i] {
                c if c.is_ascii_digit() => digits += 1,
                b'.' if !point && !slash => point = true,
                b'/' if !slash && !point && digits > 0 && b.get(i + 1).is_some_and(u8::is_ascii_digit) => slash = true,
                _ => break,
            }
            i += 1;
        }
        if digits == 0 || !(slash || point) || i == start {
            continue;
        }
        let rest = up[i..].trim_start();
        let unit = rest.starts_with('"')
            || rest
                .strip_prefix("INCH")
                .or_else(|| rest.strip_prefix("IN"))
                .is_some_and(|r| !r.starts_with(|c: char| c.is_ascii_alphanumeric()));
        if unit {
            return true;
        }
    }
    false
}
