//! Variables followed to their uses: a variable, R or Q parameter set to another value is
//! told as what the words it feeds do.
//!
//! The statements of the edited program (the original's, for a variable only it sets) that
//! read the variable are found by name, and their words read by the dictionary as a differing
//! statement's are ([`super::typed`]): an `F` is the feed, an `S` the spindle speed, a
//! cycle's parameter (`Q201=-Q5`) that parameter, a `Z` the clearance height where the move
//! is a rapid and the cut depth where it feeds (the motion in force, from the statement or
//! the ones before it). A variable that only feeds another (`#<depth>=#<top>-#<cut>`) is
//! followed through it, five levels deep ([`FED_LEVELS`]). A loop's bound or a branch's condition that reads it
//! decides which blocks run, or how often: a flow change (`loop bound (via CYCLES)`). Each
//! use kind becomes a change of that kind at the variable's statement, naming the variable
//! (`clearance height (via #<_z_clearance>)`); a variable whose uses say nothing the
//! dictionary knows (an axis position) stays the statement change that names it. One this
//! program passes to a subroutine in another file (`o<nozzle> call [#<len>]`, `G65 P9810
//! Z#100`) is followed there, through the parameter its argument binds ([`calls`]); where
//! the subroutine is not found, is called by name (Siemens `GRIND(WR, 2)`), or its parameter
//! feeds nothing the dictionary knows, the value is still that parameter's: told as its change
//! (`parameter 1 of GRIND (via WR)`), unless an argument inserted or removed before it shifts
//! the binding.

use super::control;
use super::statement::{self, Sort, Stmt, Token};
use super::typed::{self, About, Context, about};
use super::{Change, ChangeKind, Program};
use crate::dialect::{Dialect, Meaning, Role};

/// How far back the motion in force is looked for, in statements.
const MOTION_LOOKBACK: usize = 64;

/// How many statements that read a variable are looked at.
const MAX_USES: usize = 256;

/// How many variables one level feeds that are followed to the next.
const MAX_FED: usize = 8;

/// How many assignments added or removed are followed to their uses (each reads both
/// programs' statements once more).
const MAX_WHOLE: usize = 64;

/// How many levels of variables fed by a parameter are followed (`#4` → `#<length>` →
/// `#<tip>` → `#<angle>` → `#<final>` → `M68 … Q[#<final>]`).
const FED_LEVELS: usize = 5;

/// Whether `value` reads the variable `name` (upper case, as statements are written): the
/// name not followed by more of a name or number (`#1` is not read by `#10`).
fn reads(value: &str, name: &str) -> bool {
    value.match_indices(name).any(|(i, _)| {
        let before_ok = !name.starts_with(|c: char| c.is_ascii_alphabetic())
            || value[..i].chars().next_back().is_none_or(|c| !c.is_ascii_alphanumeric() && c != '_');
        // A name closed by its own bracket (`#<use_g43>`) ends there, in statements written
        // without blanks too (`[#<USE_G43>NE0]`).
        let after = value[i + name.len()..].chars().next();
        before_ok && (name.ends_with('>') || after.is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_' || c == '.')))
    })
}

/// Whether a condition's token reads a parameter named by a letter and a number (Heidenhain
/// `Q31`), written against the words around it in one spelling (`FN11:IF+Q11GTQ31GOTOLBL2`
/// splits into `GTQ31`): the name's number not continued by more digits.
fn reads_glued(t: &Token, name: &str) -> bool {
    let letters = name.bytes().take_while(u8::is_ascii_alphabetic).count();
    if letters == 0 || letters == name.len() || !name[letters..].bytes().all(|c| c.is_ascii_digit()) {
        return false;
    }
    t.text.match_indices(name).any(|(i, _)| !t.text[i + name.len()..].starts_with(|c: char| c.is_ascii_digit() || c == '.' || c == '_'))
}

/// The motion in force at statement `k` (rapid or not), from its own codes or the ones before.
fn rapid_at(p: Program<'_>, stmts: &[Stmt], k: usize, own: &[Token]) -> Option<bool> {
    // A rapid word anywhere in the statement makes it a rapid (`L Z+Q1 R0 FMAX`: the line
    // keyword comes first, its rapid feed word after).
    let motion = |toks: &[Token]| {
        let kinds: Vec<Meaning> =
            toks.iter().filter_map(|t| if let About::Code(m) = about(t, p.dialect) { Some(m) } else { None }).collect();
        if kinds.iter().any(|m| matches!(m, Meaning::Rapid | Meaning::RapidBlock)) {
            Some(true)
        } else if kinds.iter().any(|m| matches!(m, Meaning::Linear | Meaning::ArcCw | Meaning::ArcCcw)) {
            Some(false)
        } else {
            None
        }
    };
    if let Some(m) = motion(own) {
        return Some(m);
    }
    // A Heidenhain-style line with its feed word: FMAX is the rapid, else it feeds.
    (0..k)
        .rev()
        .take(MOTION_LOOKBACK)
        .find_map(|j| motion(&statement::tokens_in(&statement::text_of(p.text, p.dialect, &stmts[j]), p.dialect)))
}

/// What a word reading a variable does: its kind and field, in its statement's context.
fn use_kind(tok: &Token, ctx: Context, rapid: impl FnOnce() -> Option<bool>, d: &Dialect) -> Option<(ChangeKind, String)> {
    if typed::sets_variable(tok, d) {
        return typed::cycle_param(&tok.key, ctx.cycle, d)
            .map(|a| (typed::arg_kind(a.role), format!("cycle parameter {}", typed::arg_name(a))));
    }
    if matches!(about(tok, d), About::Address(Role::Z)) && !ctx.cycle && !ctx.probe && ctx.data.is_none() && !ctx.length {
        return rapid().map(|r| {
            if r { (ChangeKind::ClearanceChanged, "clearance height".into()) } else { (ChangeKind::DepthChanged, "cut depth".into()) }
        });
    }
    // A machine function's word named with its code (`machine function M68: analog output`).
    typed::kind_of(tok, ctx, d)
        .map(|(k, f)| (k, if k == ChangeKind::MachineFunctionChanged { typed::function_field(ctx, d) } else { f.to_owned() }))
}

/// The text of statement `s` as written, over its lines.
fn raw<'t>(text: &'t str, s: &Stmt) -> &'t str {
    let from = (s.offset as usize).min(text.len());
    let lines = (s.last.saturating_sub(s.line) + 1) as usize;
    let end = text[from..].match_indices('\n').nth(lines - 1).map_or(text.len(), |(e, _)| from + e);
    &text[from..end]
}

/// The kinds of the uses of `name` in `p`, the variables it feeds (for the next level), and
/// whether any statement reads it.
fn uses(p: Program<'_>, stmts: &[Stmt], name: &str) -> (Vec<(ChangeKind, String)>, Vec<String>, bool) {
    let mut kinds: Vec<(ChangeKind, String)> = Vec::new();
    let mut feeds = Vec::new();
    let mut seen = 0;
    let mut any = false;
    for (k, s) in stmts.iter().enumerate() {
        // The raw line first: most statements do not name the variable.
        if !raw(p.text, s).to_ascii_uppercase().contains(name) {
            continue;
        }
        let toks = statement::tokens_in(&statement::text_of(p.text, p.dialect, s), p.dialect);
        let ctx = Context::of(&toks, p.dialect);
        let flow = control::flow_of(&toks, p.dialect);
        for t in &toks {
            // A loop's or branch's bound may stand as a token of its own (`TO CYCLES`).
            let read = reads(&t.value, name) || (flow.is_some() && (t.sort == Sort::Other && reads(&t.text, name) || reads_glued(t, name)));
            if !read || (t.sort == Sort::Assign && t.key == name) {
                continue;
            }
            any = true;
            // A loop's bound or a branch's condition that reads it: which blocks run, or how
            // often (`FOR COUNT = 1 TO CYCLES`).
            // A count loop whose count is the variable itself (`o100 repeat [#<n>]`): its passes.
            let count = t.sort == Sort::Call
                && control::count_loop_key(&t.key, p.dialect)
                && statement::arguments(&t.value).first().is_some_and(|a| a.trim() == name);
            let decides = match flow {
                Some(control::Flow::Loop) if count => Some((ChangeKind::FlowChanged, "loop passes".to_owned())),
                Some(control::Flow::Loop) => Some((ChangeKind::FlowChanged, "loop bound".to_owned())),
                Some(control::Flow::Branch) => Some((ChangeKind::FlowChanged, "condition".to_owned())),
                // A jump the variable decides: read before its target, in its condition
                // (Heidenhain `FN 11: IF +Q11 GT Q31 GOTO LBL 2`), or as the target itself.
                Some(control::Flow::Jump) => {
                    let target = toks.last().is_some_and(|l| std::ptr::eq(l, t));
                    Some((ChangeKind::FlowChanged, if target { "jump" } else { "condition" }.to_owned()))
                }
                _ => None,
            };
            // A named cycle's argument (Siemens `CYCLE81(10,0,1,-DEPTH)`): the parameter its
            // position names in the dictionary, each argument that reads it.
            if decides.is_none()
                && t.sort == Sort::Call
                && let Some(args) = typed::cycle_args(&t.key, p.dialect)
            {
                for (i, a) in statement::arguments(&t.value).iter().enumerate() {
                    let kf = match args.get(i) {
                        Some(arg) => (typed::arg_kind(arg.role), format!("{} {}", t.key, typed::arg_name(arg))),
                        None => (ChangeKind::CycleParameterChanged, format!("{} argument {}", t.key, i + 1)),
                    };
                    if reads(a, name) && !kinds.contains(&kf) {
                        kinds.push(kf);
                    }
                }
                continue;
            }
            // An axis word of a return or machine-coordinate move (`G53 G0 X#<setter_x>`,
            // `G28 Z#1`): where that move goes, told as that move's change.
            // Where its words say no more than that the move changed.
            let returns = s.moves & statement::RETURN_MOVE != 0 && typed::axis_word(t, p.dialect);
            let kind = decides.or_else(|| use_kind(t, ctx, || rapid_at(p, stmts, k, &toks), p.dialect));
            let kind = match kind {
                None | Some((ChangeKind::ToolpathChanged, _)) if returns => {
                    Some((ChangeKind::ReturnMoveChanged, "return or machine-coordinate move".to_owned()))
                }
                k => k,
            };
            match kind {
                Some(kf) if !kinds.contains(&kf) => kinds.push(kf),
                Some(_) => {}
                None if typed::sets_variable(t, p.dialect) && !feeds.contains(&t.key) => feeds.push(t.key.clone()),
                None => {}
            }
        }
        seen += 1;
        if seen >= MAX_USES {
            break;
        }
    }
    (kinds, feeds, any)
}

/// Whether `var` (a statement's variable key, upper case) is global by the dictionary's
/// parameters, which the subroutines and programs that run after it read: a named parameter
/// whose name starts with `_` (LinuxCNC `#<_paranoid>`), or a numbered one in the
/// dictionary's `global-variables` (Fanuc's common `#100`-`#999`, LinuxCNC's `#31`-`#5000`).
/// So is a user variable a program neither declares nor takes as a parameter, where the
/// dialect's programs declare theirs (`shared_name`).
/// Its callers ask it of both programs: a name one of them declares, or sets in a statement
/// with a keyword of the language, is no global there.
fn global(var: &str, (p, stmts): (Program<'_>, &[Stmt])) -> bool {
    let d = p.dialect;
    if shared_name(var, p, stmts) {
        return true;
    }
    let Some((sigil, named)) = d.lexical.parameter else { return false };
    let Some(rest) = var.strip_prefix(sigil) else { return false };
    (named && rest.starts_with("<_")) || rest.parse::<u32>().is_ok_and(|n| d.macros.globals.iter().any(|&(lo, hi)| (lo..=hi).contains(&n)))
}

/// Whether `var` is a user variable named by an identifier (`PROCESS[50]`, `COMMON_RND[2]`) that
/// the program neither declares (the dictionary's declare statement, `DEF REAL …`) nor takes as
/// a parameter of its procedure header, where identifiers name variables, each program declares
/// its own and one read before it is set is the caller's or global data (`identifier-variables`,
/// a `declare` statement, `unset-variables="unknown"`): then it is global user data, defined for
/// every program outside this file (Sinumerik: a program's own variables are defined with `DEF`
/// and seen only in it; the GUD, defined in the definition files, are seen by every program —
/// 840D sl programming manual, job planning, "Definition of user variables (DEF)").
fn shared_name(var: &str, p: Program<'_>, stmts: &[Stmt]) -> bool {
    let d = p.dialect;
    let declares = d.macros.statements.iter().any(|&(_, s)| s == crate::dialect::Statement::Declare);
    if !d.lexical.identifier_variables || !d.macros.unset_unknown || !declares {
        return false;
    }
    let name = var.split('[').next().unwrap_or(var);
    let identifier = name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && name.len() >= 2;
    // (An address written with `=`, `F=…`, is no variable; a parameter by its sigil and number
    // is one of the dictionary's numbered ranges.)
    let parameter = d
        .lexical
        .parameter
        .is_some_and(|(sigil, _)| name.strip_prefix(sigil).is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())));
    if !identifier || parameter || known_name(name, d) {
        return false;
    }
    if stmts.first().and_then(|s| header_parameters(p.text, d, s, 0)).is_some_and(|f| f.contains_key(name)) {
        return false;
    }
    !stmts.iter().any(|s| {
        // The raw text first: most statements do not name the variable.
        if !raw(p.text, s).to_ascii_uppercase().contains(name) {
            return false;
        }
        let tokens = statement::tokens_in(&statement::text_of(p.text, d, s), d);
        let declare = tokens.first().is_some_and(|t| d.macros.statement(&t.key) == Some(crate::dialect::Statement::Declare));
        // Set in a statement with a keyword of the language (`IDS=10 EVERY … DO …`: a
        // synchronized action's number; `IF INI[109]=0`: a condition written with `=`): not
        // a plain assignment of a variable.
        let keyword = tokens.iter().any(|t| t.sort == Sort::Assign && t.key.eq_ignore_ascii_case(var))
            && tokens.iter().any(|t| t.sort == Sort::Other && d.macros.statement(&t.key).is_some());
        keyword || (declare && tokens.iter().skip(1).any(|t| reads(&t.text, name)))
    })
}

/// Whether the dictionary knows `name` (upper case, without an index) as a word of the language,
/// so that no program can name its own or global user data so: the 840D sl programming manual,
/// fundamentals, "Identifiers" — reserved words must not be used as identifiers, and a user
/// identifier's first two characters are letters or underscores. Known are: an address (`F=…`)
/// or its extended form, the address and a number (`S1=2000`, `M1=3`: spindle 1's speed and
/// direction; `X1=10`, `Y2=5`: numbered axes); a G or M code, a keyword code (`SPOS=0`,
/// `SPOSA=90`) or a statement keyword; a name indexed by an axis (`FA[X]=100`, `OVRA[X]=50`);
/// a cycle or procedure (`CYCLE81`); a statement or cycle keyword the vocabulary documents.
fn known_name(name: &str, d: &Dialect) -> bool {
    let word = Token { key: name.to_owned(), value: String::new(), text: name.to_owned(), sort: Sort::Word };
    let address = |a: &str| d.addresses.iter().any(|x| x.name.eq_ignore_ascii_case(a));
    let letters = name.trim_end_matches(|c: char| c.is_ascii_digit());
    about(&word, d) != About::Unknown
        || address(name)
        || (letters.len() < name.len() && address(letters))
        || d.keyword_codes().any(|(_, spec)| spec.text.split(' ').next().is_some_and(|w| w.eq_ignore_ascii_case(name)))
        || d.macros.statement(name).is_some()
        || d.lexical.axis_indexed.iter().any(|a| a.name.eq_ignore_ascii_case(name))
        || d.cycles.iter().any(|c| c.name.eq_ignore_ascii_case(name))
        || d.vocabulary.keyword(name).is_some()
}

/// Statement changes of variables set to other values become the changes of what the
/// variables feed, where their uses say it; the rest stay as they are.
pub(super) fn follow(changes: &mut Vec<Change>, a: Program<'_>, b: Program<'_>, (sa, sb): (&[Stmt], &[Stmt])) {
    moved(changes, (a, sa), (b, sb));
    let mut k = 0;
    // Each assignment added or removed reads both programs once more: so many at most.
    let mut whole_left = MAX_WHOLE;
    while k < changes.len() {
        let c = &changes[k];
        let var = c.field.strip_prefix("variable ").map(str::to_owned);
        let Some(var) = var.filter(|_| c.kind == ChangeKind::StatementChanged) else {
            k += 1;
            continue;
        };
        let (p, stmts) = if c.line.is_some() { (b, sb) } else { (a, sa) };
        let whole = c.before.is_empty() || c.after.is_empty();
        if whole {
            // A global set or no longer set, that the file does not read: for what runs after.
            if global(&var, (a, sa)) && global(&var, (b, sb)) && !uses(a, sa, &var).2 && !uses(b, sb, &var).2 {
                changes[k].kind = ChangeKind::GlobalVariableChanged;
                k += 1;
                continue;
            }
            if whole_left == 0 || !sole_assignment(changes, k, &var, (a, sa), (b, sb)) {
                k += 1;
                continue;
            }
            whole_left -= 1;
        }
        // An assignment added or removed is followed to the uses both programs have (the
        // statements that now read another value); new or changed statements tell themselves.
        // Only those after it: the added one in the edited program, the removed one in the
        // original.
        let kept: Vec<Stmt>;
        let (p, stmts) = if whole {
            let (p, own, other, after) = match (c.line, c.original_line) {
                (Some(l), _) => (b, sb, sa, l),
                (None, Some(l)) => (a, sa, sb, l),
                (None, None) => (b, sb, sa, u32::MAX),
            };
            let hashes: std::collections::BTreeSet<u64> = other.iter().map(|s| s.hash).collect();
            kept = own.iter().filter(|s| s.line > after && hashes.contains(&s.hash)).cloned().collect();
            (p, kept.as_slice())
        } else {
            (p, stmts)
        };
        let found: Vec<(ChangeKind, String)> =
            fed_kinds(p, stmts, &var).into_iter().filter(|(kind, _)| !(whole && *kind == ChangeKind::ToolRenamed)).collect();
        if found.is_empty() {
            // A global the file does not read: told as such, for what runs after it.
            if global(&var, (a, sa)) && global(&var, (b, sb)) && !uses(a, sa, &var).2 && !uses(b, sb, &var).2 {
                changes[k].kind = ChangeKind::GlobalVariableChanged;
            }
            k += 1;
            continue;
        }
        let template = changes.remove(k);
        for (kind, field) in found {
            let mut t = template.clone();
            t.kind = kind;
            let note = if kind == ChangeKind::ClearanceChanged { below_top(p, &t.before, &t.after) } else { None };
            t.field = format!("{field} (via {var}{})", note.unwrap_or_default());
            t.detail.effect = None;
            if whole && t.before.is_empty() {
                t.before = "not set".into();
            }
            if whole && t.after.is_empty() {
                t.after = "no longer set".into();
            }
            changes.insert(k, t);
            k += 1;
        }
    }
}

/// An assignment written elsewhere with another value (`#<tool_touch_x_coords> = 52` removed
/// at line 12, `= 17.4` added at line 13): where each program assigns the variable once, its
/// removal and its addition are one change of the value, from the original's to the edited
/// one's, at both lines, followed to its uses as a value changed in place is. Only a value
/// that differs comes here: an assignment moved with its value is no change where every use
/// reads it after it in both programs (`super::account`'s `moved_same`).
fn moved(changes: &mut Vec<Change>, (a, sa): (Program<'_>, &[Stmt]), (b, sb): (Program<'_>, &[Stmt])) {
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let removed = c.kind == ChangeKind::StatementChanged
            && c.field.starts_with("variable ")
            && !c.before.is_empty()
            && c.after.is_empty()
            && c.line.is_none()
            && c.original_line.is_some();
        let added = |o: &Change| {
            o.kind == ChangeKind::StatementChanged && o.field == c.field && o.before.is_empty() && !o.after.is_empty() && o.line.is_some()
        };
        // The same text written elsewhere (`#<feed> = #<_feed>` three lines lower) may read
        // another value there, or the same: not told as a change of its value.
        let found = if removed { changes.iter().position(|o| added(o) && o.after != c.before) } else { None };
        let Some(j) = found else {
            k += 1;
            continue;
        };
        let var = c.field["variable ".len()..].to_owned();
        if assignments(a, sa, &var) != 1 || assignments(b, sb, &var) != 1 {
            k += 1;
            continue;
        }
        let new = changes.remove(j);
        if j < k {
            k -= 1;
        }
        let c = &mut changes[k];
        c.after = new.after;
        c.line = new.line;
        c.detail.at.extend(new.detail.at);
        k += 1;
    }
}

/// How far apart (in statements) an assignment moved with its value may lie for
/// [`moved_same`], and how many statements around it are read.
const MOVED_WITHIN: usize = 32;

/// Assignments moved with their value (`#<tool_setter_height> = 23.8836` written two lines
/// lower, `Q1 = 5` above another): no change where the value is a number, each program
/// assigns the variable once, and no statement between the two places (in each program,
/// between it and where the other program's lies) reads the variable, calls, jumps, is
/// numbered (a jump's target) or opens or closes a block. Then every use
/// reads the same value in both: those after both places the number, those before both the
/// value before it. Each as (original line, None) and (None, edited line).
pub(super) fn moved_same(
    hunks: &[statement::Hunk],
    a: Program<'_>,
    b: Program<'_>,
    sa: &[Stmt],
    sb: &[Stmt],
) -> Vec<(Option<u32>, Option<u32>)> {
    let mut out = Vec::new();
    let removed: Vec<usize> = hunks.iter().flat_map(|h| h.original.clone()).take(MAX_WHOLE).collect();
    let added: Vec<usize> = hunks.iter().flat_map(|h| h.edited.clone()).take(MAX_WHOLE).collect();
    for &i in &removed {
        let Some(&j) = added.iter().find(|&&j| sb[j].hash == sa[i].hash && i.abs_diff(j) <= MOVED_WITHIN) else { continue };
        let toks = statement::tokens_in(&statement::text_of(a.text, a.dialect, &sa[i]), a.dialect);
        let [t] = toks.as_slice() else { continue };
        let number = t.value.trim().trim_start_matches(['[']).trim_end_matches([']']).parse::<f64>().is_ok();
        if t.sort != Sort::Assign || !typed::sets_variable(t, a.dialect) || !number {
            continue;
        }
        let var = t.key.as_str();
        if assignments(a, sa, var) != 1 || assignments(b, sb, var) != 1 {
            continue;
        }
        // Where each lies in the other program: the start of its hunk's other side.
        let place = |k: usize, original: bool| {
            hunks
                .iter()
                .find(|h| if original { h.original.contains(&k) } else { h.edited.contains(&k) })
                .map(|h| if original { h.edited.start } else { h.original.start })
        };
        let (Some(pi), Some(pj)) = (place(i, true), place(j, false)) else { continue };
        let quiet = |p: Program<'_>, stmts: &[Stmt], own: usize, other: usize| {
            let (lo, hi) = (own.min(other), (own + 1).max(other));
            hi - lo <= MOVED_WITHIN
                && stmts.iter().enumerate().take(hi).skip(lo).all(|(k, s)| {
                    k == own || {
                        let toks = statement::tokens_in(&statement::text_of(p.text, p.dialect, s), p.dialect);
                        // A numbered block may be a jump's target (Fanuc `GOTO 100` to `N100`).
                        let raw = p.text.get(s.offset as usize..).unwrap_or_default().trim_start();
                        let numbered = raw.len() > 1 && raw.as_bytes()[0].eq_ignore_ascii_case(&b'N') && raw.as_bytes()[1].is_ascii_digit();
                        s.moves & statement::CALL == 0
                            && !numbered
                            && control::flow_of(&toks, p.dialect).is_none()
                            && toks
                                .iter()
                                .all(|t| matches!(t.sort, Sort::Word | Sort::Assign) && !reads(&t.value, var) && !reads(&t.text, var))
                    }
                })
        };
        if quiet(a, sa, i, pj) && quiet(b, sb, j, pi) {
            out.push((Some(sa[i].line), None));
            out.push((None, Some(sb[j].line)));
        }
    }
    out
}

/// Whether the assignment of `var` that change `k` adds (or removes) is the only one: the
/// other program assigns `var` nowhere, and no other change sets a variable to the value it
/// gave or took (a rename, `#<x>=#5421` → `#<y>=#5421`, or an assignment moved). Only then do
/// the statements that read `var` after it read another value than before.
fn sole_assignment(changes: &[Change], k: usize, var: &str, (a, sa): (Program<'_>, &[Stmt]), (b, sb): (Program<'_>, &[Stmt])) -> bool {
    let c = &changes[k];
    let (other, stmts) = if c.before.is_empty() { (a, sa) } else { (b, sb) };
    !paired(changes, k) && !assigns(other, stmts, var)
}

/// Whether another change sets or takes away a variable with the value change `k`'s
/// assignment gave or took, or the same variable the other way (a rename, a move).
fn paired(changes: &[Change], k: usize) -> bool {
    let c = &changes[k];
    let value = if c.before.is_empty() { &c.after } else { &c.before };
    changes.iter().enumerate().any(|(j, o)| {
        j != k
            && o.field.starts_with("variable ")
            && (o.before.is_empty() != c.before.is_empty())
            && (o.before == *value || o.after == *value || o.field == c.field)
    })
}

/// Whether a statement of `p` assigns `var`.
fn assigns(p: Program<'_>, stmts: &[Stmt], var: &str) -> bool {
    assignments(p, stmts, var) > 0
}

/// How many statements of `p` assign `var`.
fn assignments(p: Program<'_>, stmts: &[Stmt], var: &str) -> usize {
    stmts
        .iter()
        .filter(|s| {
            let from = s.offset as usize;
            let lines = (s.last - s.line + 1) as usize;
            let end = p.text[from..].match_indices('\n').nth(lines - 1).map_or(p.text.len(), |(e, _)| from + e);
            p.text[from..end].to_ascii_uppercase().contains(var)
                && statement::tokens_in(&statement::text_of(p.text, p.dialect, s), p.dialect)
                    .iter()
                    .any(|t| t.sort == Sort::Assign && t.key == var)
        })
        .count()
}

/// Where a clearance set through a variable now lies below the part's top (the stock the
/// program or configuration states): that, naming the reference. Only plain numbers are
/// compared, in the program's units.
fn below_top(p: Program<'_>, before: &str, after: &str) -> Option<String> {
    let (x, y) = (before.trim().parse::<f64>().ok()?, after.trim().parse::<f64>().ok()?);
    let inch = p.plan.units == Some(crate::canon::Units::Inch);
    let mm = |v: f64| if inch { v * 25.4 } else { v };
    let note = super::part_top(p.plan)?.crossed(mm(x), mm(y), super::Fmt { inch })?;
    Some(format!(",{}", note.trim_start().trim_start_matches('(').trim_end_matches(')')).replace(",now", ", now"))
}

/// The callee a call statement's key names, as a program source is asked for it: the label of
/// an O-word subroutine (`O<LOADTOOL>` is `loadtool`).
fn callee_name(key: &str) -> Option<String> {
    let label = key.strip_prefix(['O', 'o'])?.strip_prefix('<')?.strip_suffix('>')?;
    (!label.is_empty()).then(|| label.to_ascii_lowercase())
}

/// The kinds the parameter `param` feeds in `p` (its statements `stmts`), followed through the
/// variables it sets, [`FED_LEVELS`] deep, as [`follow`] does for a variable.
fn fed_kinds(p: Program<'_>, stmts: &[Stmt], param: &str) -> Vec<(ChangeKind, String)> {
    let mut found: Vec<(ChangeKind, String)> = Vec::new();
    let mut level = vec![param.to_owned()];
    for _ in 0..FED_LEVELS {
        let mut next = Vec::new();
        for v in &level {
            let (kinds, feeds, _) = uses(p, stmts, v);
            for kf in kinds {
                if !found.contains(&kf) {
                    found.push(kf);
                }
            }
            next.extend(feeds.into_iter().filter(|f| f != param));
            next.truncate(MAX_FED);
        }
        if next.is_empty() {
            break;
        }
        level = next;
    }
    found
}

/// A subroutine from another file: its text and its statements.
type Callee = (String, Vec<Stmt>);

/// A call's argument changed in place, passed to a subroutine in another file
/// (`programs`: the subprograms beside the program, as the analysis finds them), becomes the
/// change of what the parameter it binds does in that subroutine: positional argument `k`
/// binds the dictionary's local parameter `k` (`#2` for LinuxCNC's second), followed there to
/// the words it feeds (`feed (via O<PROBE_X_PLUS> argument 4, #4 in probe_x_plus)`). A call
/// whose argument count changed (every later argument binds another parameter), a subroutine
/// not found, or a parameter whose uses say nothing the dictionary knows, leaves the
/// statement change as it is.
pub(super) fn calls(changes: &mut Vec<Change>, edited: Program<'_>, programs: &dyn crate::interp::ProgramSource) {
    let dialect = edited.dialect;
    let Some((sigil, _)) = dialect.lexical.parameter else { return };
    let mut edited_stmts: Option<Vec<Stmt>> = None;
    let (first, last) = dialect.macros.locals;
    let mut texts: Vec<(String, Option<Callee>)> = Vec::new();
    let plan = crate::plan::ProcessPlan::default();
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let target = c.field.strip_prefix("call ").and_then(|r| r.rsplit_once(" argument ")).and_then(|(key, n)| {
            let n = n.parse::<u16>().ok().filter(|&n| n >= 1 && u32::from(first) + u32::from(n) - 1 <= u32::from(last))?;
            Some((key.to_owned(), callee_name(key)?, first + n - 1))
        });
        let target = target.filter(|_| c.kind == ChangeKind::StatementChanged).or_else(|| macro_argument(c, edited, &mut edited_stmts));
        let Some((key, name, n)) = target else {
            // A call by name the analysis cannot follow (Siemens `F_TP_GRINDING_PARAMETERS(…)`,
            // no such file beside it): its argument is that parameter's value.
            if let Some(label) = by_name_argument(changes, k, edited) {
                let c = &mut changes[k];
                c.kind = ChangeKind::CycleParameterChanged;
                c.field = label;
            }
            k += 1;
            continue;
        };
        // Arguments bind by position: where one was inserted or removed, every later one binds
        // another parameter than the alignment pairs it with, so that call is left as it is.
        let prefix = format!("call {key} argument ");
        let (line, original_line) = (c.line, c.original_line);
        let shifted = changes.iter().any(|o| {
            o.line == line && o.original_line == original_line && o.field.starts_with(&prefix) && (o.before == "none" || o.after == "none")
        });
        // Arguments only appended at the end shift nothing: every earlier one binds the
        // parameter it bound, and each new one binds its own (`o<loadtool> call [#<toolno>]`
        // → `… [#<toolno>][#<use_g43>]`: `#2` now passed).
        let appended = shifted && only_appended(changes, (line, original_line), &key, edited, &mut edited_stmts);
        if shifted && !appended {
            k += 1;
            continue;
        }
        if !texts.iter().any(|(t, _)| *t == name) {
            let loaded = programs.load(&name).map(|text| {
                let stmts = statement::statements(&text, dialect);
                (text, stmts)
            });
            texts.push((name.clone(), loaded));
        }
        let param = format!("{sigil}{n}");
        let found = match texts.iter().find(|(t, _)| *t == name) {
            Some((_, Some((text, stmts)))) => fed_kinds(Program { plan: &plan, text, dialect }, stmts, &param),
            _ => Vec::new(),
        };
        if found.is_empty() {
            // The subroutine not found, or its parameter's uses say nothing the dictionary
            // knows: the argument is still that parameter's value, told as its change (a
            // probing macro's as the probing's, as the dictionary says).
            let c = &mut changes[k];
            if c.kind == ChangeKind::ProbingChanged {
                k += 1;
                continue;
            }
            c.kind = ChangeKind::CycleParameterChanged;
            c.field = format!("parameter {} of {}", arg_label(&key, n, first, dialect), callee_label(&key, &name));
            k += 1;
            continue;
        }
        let template = changes.remove(k);
        for (kind, field) in found {
            let mut t = template.clone();
            t.kind = kind;
            t.field = format!("{field} (via {key} argument {}, {param} in {name})", arg_label(&key, n, first, dialect));
            t.detail.effect = None;
            if key.starts_with('G') {
                // A macro call's word (`B-0.75`): its value, the letter being named.
                for v in [&mut t.before, &mut t.after] {
                    if v.starts_with(|c: char| c.is_ascii_alphabetic()) {
                        v.remove(0);
                    }
                }
            }
            changes.insert(k, t);
            k += 1;
        }
    }
    variables_into_calls(changes, edited, programs, &mut texts);
}

/// The calls in `p` that pass `var` (read in an argument): each call's key, the program it
/// calls and the local the argument binds there (`o<coolant> call [#<len>]`: `#1` of
/// `coolant`; `G65 P9810 Z#100`: `#26` of `O9810`).
fn passed_to(p: Program<'_>, stmts: &[Stmt], var: &str) -> Vec<(String, String, u16, u32)> {
    let d = p.dialect;
    let (first, last) = d.macros.locals;
    let mut out: Vec<(String, String, u16, u32)> = Vec::new();
    let mut push = |x: (String, String, u16, u32)| {
        if !out.contains(&x) {
            out.push(x);
        }
    };
    for s in stmts {
        let from = s.offset as usize;
        let lines = (s.last - s.line + 1) as usize;
        let end = p.text[from..].match_indices('\n').nth(lines - 1).map_or(p.text.len(), |(e, _)| from + e);
        if !p.text[from..end].to_ascii_uppercase().contains(var) {
            continue;
        }
        let toks = statement::tokens_in(&statement::text_of(p.text, d, s), d);
        for t in toks.iter().filter(|t| t.sort == Sort::Call) {
            // A program called by its name (Siemens `WARMUP_CYCLE(7200, 5)`): its parameters
            // bind by position to the names its own definition declares; told by position
            // (the local `0`, the name carrying the position).
            if callee_name(&t.key).is_none() && control::called_by_name(t, d) {
                for (i, a) in statement::arguments(&t.value).iter().enumerate() {
                    if reads(a, var) {
                        push((t.key.clone(), format!("{}#{}", t.key, i + 1), 0, s.line));
                    }
                }
                continue;
            }
            let Some(name) = callee_name(&t.key) else { continue };
            for (i, a) in statement::arguments(&t.value).iter().enumerate() {
                let n = u32::from(first) + i as u32;
                if reads(a, var) && n <= u32::from(last) {
                    push((t.key.clone(), name.clone(), n as u16, s.line));
                }
            }
        }
        // A macro call's letters (`G65 P9810 Z#100`): the local each letter sets.
        let code = toks.iter().find(|t| t.sort == Sort::Word && matches!(about(t, d), About::Code(Meaning::MacroCall)));
        let program = toks.iter().find_map(|t| if t.key == "P" { t.value.parse::<u32>().ok() } else { None });
        if let (Some(code), Some(program)) = (code, program) {
            for t in toks.iter().filter(|t| t.sort == Sort::Word && t.key.len() == 1 && t.key != "P" && reads(&t.value, var)) {
                let letter = t.key.as_bytes()[0];
                if let Some(n) = if letter.is_ascii_uppercase() { d.macros.arguments[usize::from(letter - b'A')] } else { None } {
                    push((code.key.clone(), format!("O{program:04}"), n, s.line));
                }
            }
        }
    }
    out
}

/// A variable set to another value (or newly set) that no word of this program tells, passed
/// to a subroutine in another file: told as what the parameter it binds does there
/// (`machine function M68 (via #<len>, O<COOLANT> argument 1, #1 in coolant)`).
fn variables_into_calls(
    changes: &mut Vec<Change>,
    edited: Program<'_>,
    programs: &dyn crate::interp::ProgramSource,
    texts: &mut Vec<(String, Option<Callee>)>,
) {
    let Some((sigil, _)) = edited.dialect.lexical.parameter else { return };
    let mut stmts: Option<Vec<Stmt>> = None;
    let plan = crate::plan::ProcessPlan::default();
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let var = c
            .field
            .strip_prefix("variable ")
            .filter(|_| c.kind == ChangeKind::StatementChanged && c.line.is_some() && !c.after.is_empty())
            .map(str::to_owned);
        let Some(var) = var else {
            k += 1;
            continue;
        };
        let stmts = stmts.get_or_insert_with(|| statement::statements(edited.text, edited.dialect));
        // A newly set variable: only where it is the one assignment, and no rename or move.
        if c.before.is_empty() && (paired(changes, k) || assignments(edited, stmts, &var) != 1) {
            k += 1;
            continue;
        }
        let mut found: Vec<(ChangeKind, String)> = Vec::new();
        let added = c.before.is_empty();
        let changed_at = |line: u32| changes.iter().any(|o| o.line == Some(line) || o.detail.at.iter().any(|&(_, e)| e == Some(line)));
        let mut passed: Vec<String> = Vec::new();
        for (key, name, n, line) in passed_to(edited, stmts, &var) {
            // A newly set variable: told through the calls that were there before it.
            if added && changed_at(line) {
                continue;
            }
            let field = match name.rsplit_once('#').filter(|_| n == 0) {
                // Called by name: its parameters are named in its own file, not numbered.
                Some((_, position)) => format!("parameter {position} of {key} (via {var})"),
                None => {
                    let label = arg_label(&key, n, edited.dialect.macros.locals.0, edited.dialect);
                    format!("parameter {label} of {} (via {var})", callee_label(&key, &name))
                }
            };
            if !passed.contains(&field) {
                passed.push(field);
            }
            if n == 0 {
                continue;
            }
            if !texts.iter().any(|(t, _)| *t == name) {
                let loaded = programs.load(&name).map(|text| {
                    let stmts = statement::statements(&text, edited.dialect);
                    (text, stmts)
                });
                texts.push((name.clone(), loaded));
            }
            let Some((_, Some((text, callee)))) = texts.iter().find(|(t, _)| *t == name) else { continue };
            let param = format!("{sigil}{n}");
            let p = Program { plan: &plan, text, dialect: edited.dialect };
            for (kind, field) in fed_kinds(p, callee, &param) {
                if !found.iter().any(|(k2, _)| *k2 == kind) {
                    let label = arg_label(&key, n, edited.dialect.macros.locals.0, edited.dialect);
                    found.push((kind, format!("{field} (via {var}, {key} argument {label}, {param} in {name})")));
                }
            }
        }
        if found.is_empty() {
            // Passed to subroutines whose parameters' uses the analysis cannot follow (not
            // found beside the program, or used for what no dictionary word tells): the value
            // is still those parameters' value, told as their change.
            found = passed.into_iter().map(|f| (ChangeKind::CycleParameterChanged, f)).collect();
        }
        if found.is_empty() {
            k += 1;
            continue;
        }
        let template = changes.remove(k);
        for (kind, field) in found {
            let mut t = template.clone();
            (t.kind, t.field) = (kind, field);
            t.detail.effect = None;
            if t.before.is_empty() {
                // A variable newly set: the parameter it binds had no value from it before.
                t.before = "not set".into();
            }
            changes.insert(k, t);
            k += 1;
        }
    }
}

/// Whether the argument changes of the call `key` at `lines` only append arguments at the end
/// of the list or only take the last ones off (`[1][2]` → `[1]`: `#2` no longer passed).
fn only_appended(
    changes: &[Change],
    lines: (Option<u32>, Option<u32>),
    key: &str,
    edited: Program<'_>,
    stmts: &mut Option<Vec<Stmt>>,
) -> bool {
    let prefix = format!("call {key} argument ");
    let (mut inserted, mut removed) = (Vec::new(), Vec::new());
    for o in changes.iter().filter(|o| (o.line, o.original_line) == lines) {
        let Some(n) = o.field.strip_prefix(&prefix).and_then(|n| n.parse::<usize>().ok()) else { continue };
        if o.after == "none" {
            removed.push(n);
        }
        if o.before == "none" {
            inserted.push(n);
        }
    }
    if !inserted.is_empty() && !removed.is_empty() {
        return false;
    }
    let Some(line) = lines.0 else { return false };
    let d = edited.dialect;
    let stmts = stmts.get_or_insert_with(|| statement::statements(edited.text, d));
    let Some(s) = stmts.iter().find(|s| s.line <= line && line <= s.last) else { return false };
    let toks = statement::tokens_in(&statement::text_of(edited.text, d, s), d);
    let Some(count) = toks.iter().find(|t| t.key == key && t.sort == Sort::Call).map(|t| statement::arguments(&t.value).len()) else {
        return false;
    };
    inserted.sort_unstable();
    removed.sort_unstable();
    // Appended: the edited list's last ones; taken off: the ones after the edited list's end.
    (!inserted.is_empty() && count >= inserted.len() && inserted.iter().copied().eq(count - inserted.len() + 1..=count))
        || (!removed.is_empty() && removed.iter().copied().eq(count + 1..=count + removed.len()))
}

/// How a change names the program a call runs: an O-word call by its key (`O<COOLANT>`), a
/// macro call by the program it names (`O9810`), a call by name by its name.
fn callee_label(key: &str, name: &str) -> String {
    if key.starts_with('G') { name.to_owned() } else { key.to_owned() }
}

/// A call's argument changed in place where the call names its program (Siemens
/// `F_TP_GRINDING_PARAMETERS(…)`) and no argument was inserted or removed before it: the field
/// that tells it as that parameter's change (`parameter 1 of F_TP_GRINDING_PARAMETERS`).
fn by_name_argument(changes: &[Change], k: usize, edited: Program<'_>) -> Option<String> {
    let c = &changes[k];
    if c.kind != ChangeKind::StatementChanged || c.before == "none" || c.after == "none" {
        return None;
    }
    let (key, n) = c.field.strip_prefix("call ")?.rsplit_once(" argument ")?;
    let n = n.parse::<usize>().ok()?;
    let call = Token { key: key.to_owned(), value: "()".into(), text: format!("{key}()"), sort: Sort::Call };
    if !control::called_by_name(&call, edited.dialect) {
        return None;
    }
    let prefix = format!("call {key} argument ");
    let shifted = changes.iter().any(|o| {
        o.line == c.line && o.original_line == c.original_line && o.field.starts_with(&prefix) && (o.before == "none" || o.after == "none")
    });
    (!shifted).then(|| format!("parameter {n} of {key}"))
}

/// How a change names the argument that binds local `n`: its position in an O-word call's
/// list, its letter in a macro call (`G65 … B-0.75`: `B`).
fn arg_label(key: &str, n: u16, first: u16, d: &Dialect) -> String {
    if key.starts_with('G') {
        if let Some(i) = d.macros.arguments.iter().position(|a| *a == Some(n)) {
            return char::from(b'A' + i as u8).to_string();
        }
    }
    position(n, first).to_string()
}

/// The position, counted from 1, of local `n` among the locals from `first`, in `usize`: a
/// header's parameters are counted with `saturating_add` and may stand at `u16::MAX` (a PROC
/// header of some 65,000 parameters), where `n + 1` overflows a `u16`.
fn position(n: u16, first: u16) -> usize {
    (usize::from(n) + 1).saturating_sub(usize::from(first))
}

/// A word of a macro call (`G65 P9810 B2`, LNC `G65 "PROBEY" B-0.5`) changed in place: the
/// call's code, the program it calls (`O9810`, `PROBEY`) and the local its letter sets by
/// the dictionary's argument letters (`B` is `#2`).
fn macro_argument(c: &Change, edited: Program<'_>, stmts: &mut Option<Vec<Stmt>>) -> Option<(String, String, u16)> {
    let d = edited.dialect;
    let line = c.line?;
    let letter_of = |w: &str| {
        let l = w.chars().next().filter(char::is_ascii_alphabetic)?.to_ascii_uppercase();
        w[1..].trim().parse::<f64>().ok().map(|_| l)
    };
    let (lb, la) = (letter_of(&c.before)?, letter_of(&c.after)?);
    // A word of the call statement, told as a statement or as the call's change.
    // (A probing macro's word, told as the probing's where the macro is not found beside the
    // program, is followed into it where it is.)
    let probing = c.kind == ChangeKind::ProbingChanged && matches!(c.field.as_str(), "probing parameter" | "probe target" | "probe feed");
    let word = (c.kind == ChangeKind::StatementChanged && c.field == "statement")
        || (c.kind == ChangeKind::FlowChanged && c.field == "call")
        || probing;
    if lb != la || !word {
        return None;
    }
    let n = d.macros.arguments[usize::from(la as u8 - b'A')]?;
    let stmts = stmts.get_or_insert_with(|| statement::statements(edited.text, d));
    let s = stmts.iter().find(|s| s.line <= line && line <= s.last)?;
    let toks = statement::tokens_in(&statement::text_of(edited.text, d, s), d);
    // The call's code, and the name written against it (LNC `G65"PROBEY"` reads as one token).
    let (code, quoted) = toks.iter().find_map(|t| {
        let (code, rest) = t.key.split_once('"').map_or((t.key.as_str(), None), |(c, r)| (c, Some(r)));
        let word = Token { key: code.to_owned(), value: String::new(), text: code.to_owned(), sort: Sort::Word };
        matches!(about(&word, d), About::Code(Meaning::MacroCall))
            .then(|| (code.to_owned(), rest.map(|r| r.trim_end_matches('"').to_owned()).filter(|r| !r.is_empty())))
    })?;
    let name = quoted.or_else(|| {
        toks.iter().find_map(|t| {
            if t.key == "P" {
                t.value.parse::<u32>().ok().map(|p| format!("O{p:04}"))
            } else {
                let q = t.text.trim();
                (q.len() > 2 && q.starts_with('"') && q.ends_with('"')).then(|| q[1..q.len() - 1].to_owned())
            }
        })
    })?;
    Some((code, name, n))
}

/// The arguments of the call `key` in the statement at `line` of `p`, as written.
fn call_args(p: Program<'_>, stmts: &[Stmt], line: u32, key: &str) -> Option<Vec<String>> {
    let s = stmts.iter().find(|s| s.line == line)?;
    let tokens = statement::tokens_in(&statement::text_of(p.text, p.dialect, s), p.dialect);
    let call = tokens.iter().find(|t| t.sort == Sort::Call && t.key == key)?;
    Some(statement::arguments(&call.value))
}

/// How a subroutine takes its parameters: each variable it sets from a positional parameter
/// at the top of its body (`#<z_clearance> = #3`), by that variable, and each positional
/// parameter it reads otherwise, by itself (`#3`); with the parameter's number. `None` where a
/// variable is set from two parameters.
fn binding(text: &str, d: &Dialect, sigil: char, (first, last): (u16, u16)) -> Option<std::collections::BTreeMap<String, u16>> {
    let positional = |v: &str| {
        let n = v.strip_prefix(sigil)?.parse::<u16>().ok()?;
        (first..=last).contains(&n).then_some(n)
    };
    let mut out = std::collections::BTreeMap::new();
    let mut named = std::collections::BTreeSet::new();
    for s in statement::statements(text, d) {
        for t in statement::tokens_in(&statement::text_of(text, d, &s), d) {
            if t.sort == Sort::Assign
                && let Some(n) = positional(&t.value)
                && positional(&t.key).is_none()
            {
                if out.insert(t.key.clone(), n).is_some_and(|m| m != n) {
                    return None;
                }
                named.insert(n);
            }
        }
    }
    // Positional parameters read elsewhere, by themselves.
    let up = text.to_ascii_uppercase();
    for n in first..=last {
        let p = format!("{sigil}{n}");
        let read = up.match_indices(&p).any(|(i, _)| !up[i + p.len()..].starts_with(|c: char| c.is_ascii_digit()));
        if read && !named.contains(&n) {
            out.insert(p, n);
        }
    }
    Some(out)
}

/// Calls whose argument count changed together with the subroutine they call (in another
/// file, `before` the edit and `after` it): the old call with the old subroutine and the new
/// call with the new one bind each of its parameters (by the variable the subroutine sets
/// from it, `#<z_clearance> = #3`) to an argument; a parameter bound to the same argument
/// before and after is no change, whatever its position, so a list shortened with the
/// subroutine's parameters renumbered alike is told as one statement change that says so. A
/// parameter bound to another value is told once, as what it feeds in the new subroutine (or
/// as that parameter's change), in place of a row for every argument the shift moved.
pub(super) fn rebound(
    changes: &mut Vec<Change>,
    (a, before): (Program<'_>, &dyn crate::interp::ProgramSource),
    (b, after): (Program<'_>, &dyn crate::interp::ProgramSource),
) {
    let d = b.dialect;
    let Some((sigil, _)) = d.lexical.parameter else { return };
    if a.dialect.name != d.name {
        return;
    }
    let mut calls: Vec<(String, u32, u32)> = Vec::new();
    for c in changes.iter() {
        let Some((key, _)) = c.field.strip_prefix("call ").and_then(|r| r.rsplit_once(" argument ")) else { continue };
        if c.kind == ChangeKind::StatementChanged
            && (c.before == "none" || c.after == "none")
            && let (Some(lo), Some(le)) = (c.original_line, c.line)
            && !calls.contains(&(key.to_owned(), lo, le))
        {
            calls.push((key.to_owned(), lo, le));
        }
    }
    if calls.is_empty() {
        return;
    }
    let (sa, sb) = (statement::statements(a.text, a.dialect), statement::statements(b.text, d));
    let plan = crate::plan::ProcessPlan::default();
    for (key, lo, le) in calls {
        let Some(name) = callee_name(&key).or_else(|| by_name_callee(&key, d)) else { continue };
        let (Some(old_text), Some(new_text)) = (before.load(&name), after.load(&name)) else { continue };
        let (Some(old_args), Some(new_args)) = (call_args(a, &sa, lo, &key), call_args(b, &sb, le, &key)) else { continue };
        let locals = d.macros.locals;
        // A procedure's parameters by the names its header gives them (Siemens `PROC
        // F_ZC_START(REAL Z_START_POSITION, …)`), else by the variables it sets from them.
        let formal = (formal_parameters(&old_text, d, locals.0), formal_parameters(&new_text, d, locals.0));
        let by_name = formal.0.is_some() && formal.1.is_some();
        let bound = |text: &str, f: Option<std::collections::BTreeMap<String, u16>>| f.or_else(|| binding(text, d, sigil, locals));
        let (Some(old_bind), Some(new_bind)) = (bound(&old_text, formal.0), bound(&new_text, formal.1)) else {
            continue;
        };
        // The subroutine unchanged and arguments only appended or taken off at the end: every
        // earlier one binds what it bound, which [`calls`] tells.
        let prefix = |x: &[String], y: &[String]| x.len() <= y.len() && x.iter().zip(y).all(|(p, q)| p == q);
        if old_text == new_text && (prefix(&old_args, &new_args) || prefix(&new_args, &old_args)) {
            continue;
        }
        let arg = |args: &[String], n: u16| args.get(usize::from(n).checked_sub(usize::from(locals.0))?).filter(|v| !v.is_empty()).cloned();
        let new_stmts = statement::statements(&new_text, d);
        let callee = Program { plan: &plan, text: &new_text, dialect: d };
        let at = |c: &mut Change| {
            (c.original_line, c.line) = (Some(lo), Some(le));
            c.detail.at = vec![(Some(lo), Some(le))];
        };
        let template = changes
            .iter()
            .find(|c| c.original_line == Some(lo) && c.line == Some(le) && c.field.starts_with(&format!("call {key} argument ")))
            .cloned();
        let Some(template) = template else { continue };
        let mut told = Vec::new();
        let vars: std::collections::BTreeSet<&String> = old_bind.keys().chain(new_bind.keys()).collect();
        for var in vars {
            let was = old_bind.get(var).and_then(|&n| arg(&old_args, n));
            let now = new_bind.get(var).and_then(|&n| arg(&new_args, n));
            // A parameter the new subroutine no longer takes, nor reads: nothing of this call.
            if !new_bind.contains_key(var) && !reads(&new_text.to_ascii_uppercase(), var) {
                continue;
            }
            if was == now {
                continue;
            }
            let n = new_bind.get(var).or_else(|| old_bind.get(var)).copied().unwrap_or(locals.0);
            let param = if by_name { var.clone() } else { format!("{sigil}{n}") };
            let label = if var.starts_with(sigil) && positional_name(var, sigil) {
                format!("parameter {}", position(n, locals.0))
            } else {
                var.clone()
            };
            let kinds = if new_bind.contains_key(var) { fed_kinds(callee, &new_stmts, &param) } else { Vec::new() };
            let mut t = template.clone();
            t.detail.effect = None;
            at(&mut t);
            t.before = was.unwrap_or_else(|| "not passed".into());
            t.after = now.unwrap_or_else(|| {
                if new_bind.contains_key(var) { "not passed".into() } else { format!("not passed (set in {name} itself)") }
            });
            if kinds.is_empty() {
                t.kind = ChangeKind::CycleParameterChanged;
                t.field = if label.starts_with("parameter ") { format!("{label} of {key}") } else { format!("parameter {label} of {key}") };
                told.push(t);
                continue;
            }
            for (kind, field) in kinds {
                let mut u = t.clone();
                u.kind = kind;
                u.field = if by_name {
                    format!("{field} (via {key} parameter {label})")
                } else {
                    format!("{field} (via {key} {label}, {param} in {name})")
                };
                told.push(u);
            }
        }
        if told.is_empty() {
            let mut t = template.clone();
            t.kind = ChangeKind::StatementChanged;
            t.field = format!("call {key} rebound");
            t.before = format!("[{}]", old_args.join("]["));
            t.after = format!("[{}]", new_args.join("]["));
            t.detail.effect = None;
            at(&mut t);
            told.push(t);
        }
        let k = changes
            .iter()
            .position(|c| c.original_line == Some(lo) && c.line == Some(le) && c.field.starts_with(&format!("call {key} argument ")));
        changes.retain(|c| !(c.original_line == Some(lo) && c.line == Some(le) && c.field.starts_with(&format!("call {key} argument "))));
        let k = k.unwrap_or(changes.len()).min(changes.len());
        for (i, t) in told.into_iter().enumerate() {
            changes.insert(k + i, t);
        }
    }
}

/// The program a call by name calls, as a program source is asked for it, where the dialect
/// calls programs by their names (Siemens `F_ZC_START(INI[7],INI[6],INI[5],50*INI[5],0)`: the
/// program `F_ZC_START`).
fn by_name_callee(key: &str, d: &Dialect) -> Option<String> {
    let t = Token { key: key.to_owned(), value: "()".into(), text: format!("{key}()"), sort: Sort::Call };
    control::called_by_name(&t, d).then(|| key.to_owned())
}

/// The parameters a procedure's header names, in order (Siemens `PROC F_ZC_START(REAL
/// Z_START_POSITION, REAL Z_END_POSITION, VAR REAL SPEED)`: the 840D sl programming manual, job
/// planning, "Subprogram with parameter transfer", the formal parameters bound to the call's
/// actual parameters by position), each by its name with its position counted from `first`;
/// `None` where the program opens with no such header.
fn formal_parameters(text: &str, d: &Dialect, first: u16) -> Option<std::collections::BTreeMap<String, u16>> {
    let s = statement::statements(text, d).into_iter().next()?;
    header_parameters(text, d, &s, first)
}

/// [`formal_parameters`] of a program whose first statement is `s`.
fn header_parameters(text: &str, d: &Dialect, s: &Stmt, first: u16) -> Option<std::collections::BTreeMap<String, u16>> {
    let tokens = statement::tokens_in(&statement::text_of(text, d, s), d);
    let (head, call) = (tokens.first()?, tokens.get(1)?);
    if d.macros.statement(&head.key) != Some(crate::dialect::Statement::Procedure) || call.sort != Sort::Call {
        return None;
    }
    let mut out = std::collections::BTreeMap::new();
    for (k, p) in statement::arguments(&call.value).iter().enumerate() {
        // `REAL SPEED`, `VAR REAL POS[3]`, `REAL F=100`: the last word before a default or an index.
        let decl = p.split('=').next().unwrap_or(p);
        let name = decl.split_whitespace().last().map(|w| w.split('[').next().unwrap_or(w));
        let Some(name) = name.filter(|n| !n.is_empty()) else { continue };
        out.insert(name.to_ascii_uppercase(), first.saturating_add(u16::try_from(k).ok()?));
    }
    (!out.is_empty()).then_some(out)
}

/// Whether a variable is a positional parameter itself (`#3`), not a name the subroutine gives it.
fn positional_name(var: &str, sigil: char) -> bool {
    var.strip_prefix(sigil).is_some_and(|n| !n.is_empty() && n.bytes().all(|c| c.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;

    #[test]
    fn names_the_dictionary_knows_are_no_global_user_data() {
        // Extended addresses (spindle 1's speed and direction), keyword codes written with `=`,
        // names indexed by an axis, numbered axes: the language's, never a user's GUD.
        let d = Registry::shipped().get("siemens").unwrap();
        for name in ["S1", "M1", "SPOS", "SPOSA", "FA", "OVRA", "X1", "Y2", "F", "CYCLE81", "H2", "T1"] {
            assert!(known_name(name, &d), "{name}");
        }
        // Names only a program or the definition files give.
        for name in ["PROCESS", "INI", "COMMON_RND", "WR", "_Z_SAFE", "UX1"] {
            assert!(!known_name(name, &d), "{name}");
        }
    }

    #[test]
    fn a_parameter_position_at_the_end_of_u16_does_not_overflow() {
        assert_eq!(position(u16::MAX, 0), 65536);
        assert_eq!(position(u16::MAX, 1), 65535);
        assert_eq!(position(0, 1), 0);
        let d = Registry::shipped().get("siemens").unwrap();
        assert_eq!(arg_label("F_ZC_START", u16::MAX, 1, &d), "65535");
    }
}
