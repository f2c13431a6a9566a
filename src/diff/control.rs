//! Control-flow statements told as what they change: which blocks run, and how often.
//!
//! A statement is a control-flow statement when it begins with one of the dictionary's
//! statement keywords that decide what runs next (`IF`, `WHILE`, `GOTO`, `o100 repeat`,
//! `CALL LBL`, `REPEAT`, `break`), after the O-word that labels it in LinuxCNC (`o100 if`),
//! when one of its codes calls or returns (`M98`, `G65`, `M99`), or when it calls a program by
//! its name (Siemens `WARMUP_CYCLE(7200, 5)`). Its differing words become a
//! [`ChangeKind::FlowChanged`](super::ChangeKind::FlowChanged) named by what they are: the
//! condition of a branch or a loop, a jump's target, a repeat count (the dictionary's repeat
//! word: `L`, `P`, `REP`), a call added or removed. The arguments a call passes are not flow:
//! they stay the statement changes that name them unless what they feed is followed.

use super::statement::{Sort, Token};
use crate::dialect::{Dialect, Meaning, Role, Statement};

/// The meaning of a G or M code token (`M98`), by the dictionary.
fn code_meaning(tok: &Token, d: &Dialect) -> Option<Meaning> {
    let letter @ ('G' | 'M') = tok.key.chars().next()? else { return None };
    let n = tok.key[1..].parse::<f64>().ok()?;
    d.code(letter, (n * 10.0).round().max(0.0) as u32).map(|c| c.meaning)
}

/// What a control-flow statement decides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Flow {
    /// A branch on a condition (`IF`, `ELSE`, `CASE`).
    Branch,
    /// A loop: its bound, its end (`WHILE`, `DO`, `REPEAT`, `FOR`, `LOOP`).
    Loop,
    /// Leaving or restarting a loop (`BREAK`, `CONTINUE`).
    Exit,
    /// A jump to a label or block (`GOTO`, `GOTOF`, `FN 9: … GOTO LBL`).
    Jump,
    /// A return from a subprogram (`RETURN`, `M99`, `RET`).
    Return,
    /// A call of a subprogram or label (`o<name> call`, `M98`, `CALL LBL`, `G65`).
    Call,
}

impl Flow {
    /// What its condition or value is called in a change.
    pub(super) fn field(self) -> &'static str {
        match self {
            Flow::Branch => "condition",
            Flow::Loop => "loop",
            Flow::Exit => "loop exit",
            Flow::Jump => "jump",
            Flow::Return => "return",
            Flow::Call => "call",
        }
    }
}

/// What a dictionary statement keyword decides, if it decides what runs.
fn of_statement(s: Statement) -> Option<Flow> {
    use Statement as S;
    Some(match s {
        S::If | S::ElseIf | S::Else | S::EndIf | S::Case | S::Then => Flow::Branch,
        S::While
        | S::EndWhile
        | S::Do
        | S::EndDo
        | S::For
        | S::EndFor
        | S::RepeatUntil
        | S::Until
        | S::Loop
        | S::EndLoop
        | S::Repeat
        | S::EndRepeat
        | S::RepeatSection
        | S::RepeatBlock => Flow::Loop,
        S::Break | S::Continue => Flow::Exit,
        S::Goto | S::GotoForward | S::GotoBack | S::GotoQuiet | S::GotoLabel => Flow::Jump,
        S::Return => Flow::Return,
        S::Call | S::CallLabel | S::CallProgram => Flow::Call,
        _ => return None,
    })
}

/// A token's key without the O-word that labels a LinuxCNC flow statement (`O100WHILE`,
/// `O<L1>IF`): the keyword, or the key itself.
pub(super) fn keyword(key: &str) -> &str {
    let Some(rest) = key.strip_prefix('O') else { return key };
    if let Some(named) = rest.strip_prefix('<') {
        return named.find('>').map_or(key, |e| &named[e + 1..]);
    }
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    if digits > 0 { &rest[digits..] } else { key }
}

/// The variable a subroutine's end or return sets for its caller, and the value it gives,
/// where `tok` is such a statement (LinuxCNC `O100ENDSUB[#<EDGE>]` sets `#<_value>` to
/// `#<EDGE>`; the value is empty where it gives none): the dictionary's return-value
/// parameter as a statement writes it (`#<_VALUE>`).
pub(super) fn return_value(tok: &Token, d: &Dialect) -> Option<(String, String)> {
    let name = d.macros.return_value.as_deref()?;
    let (sigil, named) = d.lexical.parameter?;
    let k = keyword(&tok.key);
    let kw = d.macros.statements.iter().find_map(|(kw, s)| {
        (matches!(s, Statement::EndSub | Statement::Return)
            && k.starts_with(kw.as_str())
            && k[kw.len()..].chars().next().is_none_or(|c| !c.is_ascii_alphabetic()))
        .then_some(kw.as_str())
    })?;
    let upper = tok.text.to_ascii_uppercase();
    let from = upper.rfind(kw).map_or(upper.len(), |i| i + kw.len());
    let rest = tok.text[from..].trim();
    let value = rest.strip_prefix('[').and_then(|r| r.strip_suffix(']')).unwrap_or(rest).to_owned();
    let name = name.to_ascii_uppercase();
    Some((if named { format!("{sigil}<{name}>") } else { format!("{sigil}{name}") }, value))
}

/// What the statement of `tokens` decides, by its first keyword or its codes; `None` for a
/// statement that runs no other blocks.
pub(super) fn flow_of(tokens: &[Token], d: &Dialect) -> Option<Flow> {
    let first = tokens.first()?;
    // `O<NAME>CALL[…]` and `O<NAME>CALL`: a call whatever its arguments.
    let k = keyword(&first.key);
    let starts = |text: &str| {
        d.macros
            .statements
            .iter()
            .filter(|(kw, _)| text.starts_with(kw.as_str()) && text[kw.len()..].chars().next().is_none_or(|c| !c.is_ascii_alphabetic()))
            .find_map(|(_, s)| of_statement(*s))
    };
    if k.len() < first.key.len() {
        if let Some(f) = starts(k) {
            return Some(f);
        }
    } else {
        // The keyword may follow a function number (Heidenhain `FN 11: IF … GOTO LBL 1`).
        for i in 0..tokens.len() {
            let rest = tokens[i..].iter().map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ");
            if let Some(f) = starts(&rest) {
                return Some(f);
            }
        }
    }
    if k.len() < first.key.len() && (k.is_empty() && first.sort == Sort::Call || k == "CALL") {
        return Some(Flow::Call);
    }
    if called_by_name(first, d) {
        return Some(Flow::Call);
    }
    tokens.iter().filter(|t| t.sort == Sort::Word).find_map(|t| match code_meaning(t, d)? {
        // A cycle called at a position (Heidenhain `M99`) machines there: the plan tells it.
        Meaning::SubprogramCall | Meaning::LocalSubprogramCall | Meaning::MacroCall | Meaning::ModalMacroCall => Some(Flow::Call),
        Meaning::SubprogramReturn => Some(Flow::Return),
        _ => None,
    })
}

/// Whether a statement's first token calls a program by its name, as the parser reads it where
/// the dialect calls programs by name (Siemens `WARMUP_CYCLE(7200, 5)`): a name with its
/// arguments that is no cycle, keyword code or statement of the dictionary.
pub(super) fn called_by_name(first: &Token, d: &Dialect) -> bool {
    let key = first.key.as_str();
    d.macros.call_by_name
        && first.sort == Sort::Call
        && key.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && d.cycle(key).is_none()
        && d.macros.statement(key).is_none()
        && !d.keyword_codes().any(|(_, k)| k.text.eq_ignore_ascii_case(key))
}

/// Whether a word of a call statement is its repeat count, by the dictionary's repeat word
/// (`CALL LBL 1 REP 5`, Siemens `P=5`). The `L` of a call code (`M98 P100 L5`, `G65 P9000 L2`)
/// is its repeat count too, as the interpreter reads it.
pub(super) fn repeat_word(tok: &Token, d: &Dialect) -> bool {
    d.macros.call_repeat.as_deref().is_some_and(|w| tok.key.eq_ignore_ascii_case(w))
        || (tok.sort == Sort::Word && d.addresses.iter().any(|a| a.name == tok.key && a.role == Role::L))
}

/// The passes a call's repeat words give: `L3` three, `REP 2` three where the count is the
/// passes after the first, none written one; `None` for anything else (an expression, other
/// words with it).
pub(super) fn passes(words: &str, d: &Dialect) -> Option<u64> {
    if words.is_empty() {
        return Some(1);
    }
    let at = words.find(|c: char| c.is_ascii_digit())?;
    let key = words[..at].trim_end_matches(['=', ' ']);
    let n: u64 = words[at..].trim().parse().ok()?;
    let word = d.macros.call_repeat.as_deref().is_some_and(|w| key.eq_ignore_ascii_case(w));
    let l = d.addresses.iter().any(|a| a.name == key && a.role == Role::L);
    (word || l).then(|| n + u64::from(word && !l && d.macros.call_repeat_additional))
}

/// What differs in a conditional jump (`IF R1<3 GOTOB MARKE1`): its condition where the
/// jump's target stays, else the target.
pub(super) fn jump_part(before: &str, after: &str) -> &'static str {
    let split = |s: &str| s.find("GOTO").map(|i| (s[..i].to_owned(), s[i..].to_owned()));
    match (split(before), split(after)) {
        (Some((_, tb)), Some((_, ta))) if tb == ta => "condition",
        (Some(_), _) | (_, Some(_)) => "jump target",
        _ => "condition",
    }
}

/// Whether a differing word of a jump statement names where it jumps: one side's word holds a
/// jump keyword or the label keyword of the dictionary (`GOTO`, `GOTOF`, `LBL`: `GOTO LBL 5`
/// → `GOTO LBL 6`). Any other word of a jump statement is its condition (`FN 9: IF +Q1 EQU
/// +0` → `EQU +1`, or `FN 9` → `FN 10`, the comparison).
pub(super) fn jump_target_word(diff: &(Option<Token>, Option<Token>), d: &Dialect) -> bool {
    let keywords: Vec<&str> = d
        .macros
        .statements
        .iter()
        .filter(|(_, s)| {
            matches!(
                s,
                Statement::Goto
                    | Statement::GotoForward
                    | Statement::GotoBack
                    | Statement::GotoQuiet
                    | Statement::GotoLabel
                    | Statement::Label
            )
        })
        .filter_map(|(k, _)| k.split(' ').next())
        .collect();
    [&diff.0, &diff.1].into_iter().flatten().any(|t| {
        let up = t.text.to_ascii_uppercase();
        keywords.iter().any(|k| up.contains(&k.to_ascii_uppercase()))
    })
}

/// How a branch statement nests (`IF` opens, `ENDIF` closes, `ELSE` neither); `None` for any
/// other statement.
pub(super) fn branch_depth(tokens: &[Token], d: &Dialect) -> Option<i32> {
    let first = tokens.first()?;
    let k = keyword(&first.key);
    let text = if k.len() < first.key.len() { k.to_owned() } else { tokens.iter().map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ") };
    let s = d
        .macros
        .statements
        .iter()
        .find(|(kw, _)| text.starts_with(kw.as_str()) && text[kw.len()..].chars().next().is_none_or(|c| !c.is_ascii_alphabetic()))?;
    match s.1 {
        Statement::If | Statement::Case => Some(1),
        Statement::EndIf => Some(-1),
        Statement::ElseIf | Statement::Else => Some(0),
        _ => None,
    }
}

/// Whether a statement's key (`O100REPEAT`) is the dictionary's count loop, which runs its body
/// the number its argument says (LinuxCNC `o100 repeat [5]`).
pub(super) fn count_loop_key(key: &str, d: &Dialect) -> bool {
    let word = key.strip_prefix(['O', 'o']).map_or(key, |r| r.trim_start_matches(|c: char| c.is_ascii_digit()));
    d.macros.statement(word) == Some(Statement::Repeat)
}

/// The tokens of a jump statement that name where it jumps: the jump keyword's token and those
/// after it (`GOTOF MARKE1`, `IF R1<3 GOTOB N100`, `FN 9: IF +Q1 EQU +0 GOTO LBL 5`,
/// `IF [#1 EQ 0] GOTO 100`); empty where the statement holds no jump keyword of the dictionary.
/// A jump names its target right after its keyword (SINUMERIK Fundamentals, program jumps:
/// `GOTOF <label>`, a label `MARKE1:` or a block number `N100`; TNC `FN 9: IF … GOTO LBL n`;
/// Fanuc `IF [<condition>] GOTO n`); what stands before the keyword is the condition (`IF …`,
/// the function `FN 9` that names the comparison). So a label's own name (`MARKE1`, which holds
/// no keyword) is the target by where it stands, not by what it spells.
pub(super) fn jump_target_tokens<'t>(tokens: &'t [Token], d: &Dialect) -> &'t [Token] {
    let keywords: Vec<String> = d
        .macros
        .statements
        .iter()
        .filter(|(_, s)| {
            matches!(s, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
        })
        .filter_map(|(k, _)| k.split(' ').next().map(str::to_ascii_uppercase))
        .collect();
    let is_jump = |t: &Token| {
        let up = t.text.trim().to_ascii_uppercase();
        keywords
            .iter()
            .any(|k| up.strip_prefix(k.as_str()).is_some_and(|rest| rest.chars().next().is_none_or(|c| !c.is_ascii_alphabetic())))
    };
    tokens.iter().position(is_jump).map_or(&tokens[tokens.len()..], |i| &tokens[i..])
}
