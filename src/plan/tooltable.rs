//! Tool tables as shops keep them, read into the tool data an analysis uses: the plan takes
//! a milled feature's size from the tool-centre path and the tool's radius, and a drilled
//! hole's depth from the drill's diameter and point angle, so a table is where sizes come
//! from when the program does not say them.
//!
//! Formats, told from the text:
//! - **LinuxCNC** (`tool.tbl`): one tool per line, `T1 P1 D10.0 Z+25.0 ;comment`; `D` is
//!   the diameter, `Z` the length offset, the comment names the tool (its kind is read from
//!   it, as from a CAM tool comment).
//! - **Heidenhain** (`TOOL.T`): `BEGIN TOOL.T MM`, a header line naming fixed-width columns
//!   (`T NAME L R R2 … T-ANGLE … TYP`), one row per tool, `[END]`. `R` is the radius, `R2`
//!   the corner radius, `T-ANGLE` a drill's point angle, `TYP` the kind (`MILL`, `DRILL`,
//!   `TAP`, `REAM`, `CENT`…).
//! - **Fanuc offsets** (the `G10` blocks a control punches): `G10 L12 P1 R5.` sets the radius
//!   geometry of offset 1 (`L13` its wear), `G10 L10 P1 R100.` its length (`L11` wear), as in
//!   offset memory C; an offset number is taken as the tool number, as posts write `D1` for
//!   `T1`. `G20` in the file means inches.
//!
//! - **Siemens** tool offsets (a `TO_INI` archive, `$TC_…` assignments): `$TC_DP6[t,d]` the
//!   radius, `$TC_DP7[t,d]` the corner radius, `$TC_DP3[t,d]` the length, `$TC_DP1[t,d]` the
//!   tool type (1xx milling tools: 110/111 ball, 120 end mill, 121 with corner rounding, 140
//!   face mill; 2xx drilling tools: 200 twist drill, 220 centre drill, 240 tap, 250 reamer),
//!   `$TC_TP2[t]` the name; cutting edge 1 of tool `t` is tool `t`'s geometry.
//!
//! Wear (Fanuc `L11`/`L13`, Heidenhain `DL`/`DR`) is left out: the drawing's sizes follow the
//! tool's nominal geometry, which the CAM system's path was computed with.
//!
//! Every number is returned in millimetres.

use std::collections::BTreeMap;

use crate::interp::ToolData;

/// The tools of a table, by number.
pub type Tools = BTreeMap<u32, ToolData>;

/// Which format a table was read as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// LinuxCNC `tool.tbl`.
    LinuxCnc,
    /// Heidenhain `TOOL.T`.
    Heidenhain,
    /// Fanuc `G10` offset blocks.
    FanucOffsets,
    /// Siemens `$TC_…` tool offset data.
    Siemens,
}

/// Reads a tool table; `inch` says the table's numbers are inches where the format does not
/// say (LinuxCNC's follow the machine's units). An error names the line it could not read.
pub fn read(text: &str, inch: bool) -> Result<(Format, Tools), String> {
    let first = text.lines().map(str::trim).find(|l| !l.is_empty()).unwrap_or("");
    let up = first.to_ascii_uppercase();
    let (format, tools) = if up.starts_with("BEGIN") && up.contains(".T") {
        (Format::Heidenhain, heidenhain(text)?)
    } else if text.lines().any(|l| l.trim_start().starts_with("$TC_DP")) {
        (Format::Siemens, siemens(text))
    } else if text.lines().any(|l| g10_block(l).is_some()) {
        (Format::FanucOffsets, fanuc(text))
    } else {
        (Format::LinuxCnc, linuxcnc(text, if inch { 25.4 } else { 1.0 })?)
    };
    if tools.is_empty() {
        return Err(
            "no tools in it: a tool table is a LinuxCNC tool.tbl, a Heidenhain TOOL.T, Fanuc G10 offset blocks or Siemens $TC_DP data"
                .into(),
        );
    }
    Ok((format, tools))
}

/// A `G10 L1x` block of an offset listing, blanks and a block number left out: its words
/// after `G10`.
fn g10_block(line: &str) -> Option<String> {
    let compact: String = line.chars().filter(|c| !c.is_whitespace()).collect::<String>().to_ascii_uppercase();
    let rest = compact.strip_prefix('N').map_or(compact.as_str(), |r| r.trim_start_matches(|c: char| c.is_ascii_digit()));
    rest.strip_prefix("G10").filter(|r| r.starts_with("L1")).map(str::to_owned)
}

fn blank_tool() -> ToolData {
    ToolData { diameter: None, length: 0.0, name: None, kind: None, corner_radius: None, flutes: None, point_angle: None }
}

/// The kind a tool's name or comment states, as a CAM tool comment would.
fn kind_named(name: &str) -> Option<String> {
    super::parse_tool_comment(name).kind.map(|k| k.as_str().to_owned())
}

/// The letter-number words of a line (`T1`, `D+10.0`, `L12P1R5.` without blanks too), up
/// to its `;` comment: a letter, then the number right after it.
fn words(line: &str) -> Vec<(char, f64)> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if !b[i].is_ascii_alphabetic() {
            i += 1;
            continue;
        }
        let start = i + 1;
        let mut j = start;
        while j < b.len() && (b[j].is_ascii_digit() || matches!(b[j], b'.' | b'-' | b'+')) {
            j += 1;
        }
        if let Ok(v) = line[start..j].parse::<f64>() {
            out.push(((b[i] as char).to_ascii_uppercase(), v));
        }
        i = j;
    }
    out
}

fn linuxcnc(text: &str, k: f64) -> Result<Tools, String> {
    let mut tools = Tools::new();
    for (i, line) in text.lines().enumerate() {
        let (data, comment) = line.split_once(';').unwrap_or((line, ""));
        if data.trim().is_empty() {
            continue;
        }
        let ws = words(data);
        let Some(number) = ws.iter().find(|(l, _)| *l == 'T').map(|(_, v)| *v) else {
            return Err(format!("line {}: a LinuxCNC tool table row starts with T<number>: `{}`", i + 1, line.trim()));
        };
        if number < 0.0 || number.fract() != 0.0 || number > f64::from(u32::MAX) {
            return Err(format!("line {}: `T{number}` is not a tool number", i + 1));
        }
        let get = |l: char| ws.iter().find(|(c, _)| *c == l).map(|(_, v)| *v);
        let name = Some(comment.trim().to_owned()).filter(|c| !c.is_empty());
        let mut t = blank_tool();
        t.diameter = get('D').filter(|d| *d > 0.0).map(|d| d * k);
        t.length = get('Z').unwrap_or(0.0) * k;
        t.kind = name.as_deref().and_then(kind_named);
        t.corner_radius = name.as_deref().and_then(|n| super::parse_tool_comment(n).corner_radius);
        t.name = name;
        tools.insert(number as u32, t);
    }
    Ok(tools)
}

fn heidenhain(text: &str) -> Result<Tools, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, begin) = lines.next().ok_or("an empty TOOL.T")?;
    let k = if begin.to_ascii_uppercase().contains("INCH") { 25.4 } else { 1.0 };
    let (_, header) = lines.next().ok_or("TOOL.T: no header line after BEGIN")?;
    // Each column runs from its name's first character to the next name's.
    let mut starts: Vec<(usize, String)> = Vec::new();
    let mut prev_blank = true;
    for (i, c) in header.char_indices() {
        if !c.is_whitespace() && prev_blank {
            let name: String = header[i..].split_whitespace().next().unwrap_or("").to_ascii_uppercase();
            starts.push((i, name));
        }
        prev_blank = c.is_whitespace();
    }
    let column = |row: &str, name: &str| -> Option<String> {
        let k = starts.iter().position(|(_, n)| n == name)?;
        let from = starts[k].0;
        let to = starts.get(k + 1).map_or(row.len(), |s| s.0);
        row.get(from.min(row.len())..to.min(row.len())).map(|s| s.trim().to_owned()).filter(|s| !s.is_empty())
    };
    if !starts.iter().any(|(_, n)| n == "T") || !starts.iter().any(|(_, n)| n == "R") {
        return Err(format!("TOOL.T: the header line names no T and R columns: `{}`", header.trim()));
    }
    let mut tools = Tools::new();
    for (i, row) in lines {
        if row.trim_start().starts_with('[') {
            break;
        }
        let num = |name: &str| column(row, name).and_then(|v| v.parse::<f64>().ok());
        let Some(number) = num("T").filter(|n| *n >= 0.0 && n.fract() == 0.0) else {
            return Err(format!("line {}: a TOOL.T row without a tool number in its T column: `{}`", i + 1, row.trim()));
        };
        let mut t = blank_tool();
        t.diameter = num("R").filter(|r| *r > 0.0).map(|r| 2.0 * r * k);
        t.corner_radius = num("R2").filter(|r| *r > 0.0).map(|r| r * k);
        t.length = num("L").unwrap_or(0.0) * k;
        t.point_angle = num("T-ANGLE").filter(|a| *a > 0.0 && *a < 180.0);
        t.flutes = num("CUT").filter(|n| *n > 0.0 && n.fract() == 0.0).map(|n| n as u32);
        t.name = column(row, "NAME");
        let doc = column(row, "DOC");
        t.kind = column(row, "TYP")
            .and_then(|typ| match typ.to_ascii_uppercase().as_str() {
                "DRILL" => Some("twist_drill".to_owned()),
                "TAP" => Some("tap".to_owned()),
                "REAM" => Some("reamer".to_owned()),
                "CENT" | "NC-DRILL" => Some("center_drill".to_owned()),
                "CSINK" => Some("countersink".to_owned()),
                "BOR" | "BORE" => Some("boring_tool".to_owned()),
                "FACE" => Some("face_mill".to_owned()),
                "BALL" => Some("ball_end_mill".to_owned()),
                "TORUS" => Some("bullnose_end_mill".to_owned()),
                "MILL" if t.corner_radius.is_some() => Some("bullnose_end_mill".to_owned()),
                "MILL" => Some("end_mill".to_owned()),
                _ => None,
            })
            .or_else(|| t.name.as_deref().and_then(kind_named))
            .or_else(|| doc.as_deref().and_then(kind_named))
            .or_else(|| t.point_angle.map(|_| "twist_drill".to_owned()));
        tools.insert(number as u32, t);
    }
    Ok(tools)
}

fn fanuc(text: &str) -> Tools {
    let up = text.to_ascii_uppercase();
    let k = if up.contains("G20") { 25.4 } else { 1.0 };
    // Offset number → (radius geometry, length geometry).
    let mut offsets: BTreeMap<u32, [f64; 2]> = BTreeMap::new();
    for line in up.lines() {
        let Some(rest) = g10_block(line) else { continue };
        let ws = words(&rest);
        let get = |l: char| ws.iter().find(|(c, _)| *c == l).map(|(_, v)| *v);
        let (Some(l), Some(p), Some(r)) = (get('L'), get('P'), get('R')) else { continue };
        if p < 1.0 || p.fract() != 0.0 {
            continue;
        }
        let slot = match l as i64 {
            12 => 0,
            10 => 1,
            _ => continue,
        };
        offsets.entry(p as u32).or_default()[slot] = r * k;
    }
    offsets
        .into_iter()
        .map(|(n, [radius, length])| {
            let mut t = blank_tool();
            t.diameter = (radius > 0.0).then_some(2.0 * radius);
            t.length = length;
            (n, t)
        })
        .collect()
}

fn siemens(text: &str) -> Tools {
    let mut tools = Tools::new();
    for line in text.lines() {
        let line = line.split(';').next().unwrap_or("").trim();
        let Some(rest) = line.strip_prefix("$TC_") else { continue };
        let Some((lhs, value)) = rest.split_once('=') else { continue };
        let Some((name, index)) = lhs.split_once('[') else { continue };
        let index: Vec<&str> = index.trim_end_matches(']').split(',').map(str::trim).collect();
        let Some(number) = index.first().and_then(|t| t.parse::<u32>().ok()) else { continue };
        // Only cutting edge 1 (D1) is the tool's own geometry.
        if name.starts_with("DP") && index.get(1).is_some_and(|d| *d != "1") {
            continue;
        }
        let value = value.trim();
        let num = value.parse::<f64>().ok();
        let t = tools.entry(number).or_insert_with(blank_tool);
        match name.trim().to_ascii_uppercase().as_str() {
            "TP2" => t.name = Some(value.trim_matches('"').to_owned()).filter(|n| !n.is_empty()),
            "DP3" => t.length = num.unwrap_or(0.0),
            "DP6" => t.diameter = num.filter(|r| *r > 0.0).map(|r| 2.0 * r),
            "DP7" => t.corner_radius = num.filter(|r| *r > 0.0),
            "DP1" => {
                t.kind = num
                    .and_then(|v| match v as u32 {
                        110 | 111 => Some("ball_end_mill"),
                        121 => Some("bullnose_end_mill"),
                        140 => Some("face_mill"),
                        100..=199 => Some("end_mill"),
                        200 => Some("twist_drill"),
                        220 => Some("center_drill"),
                        230 => Some("countersink"),
                        240 => Some("tap"),
                        250 => Some("reamer"),
                        _ => None,
                    })
                    .map(str::to_owned)
            }
            _ => {}
        }
    }
    tools.retain(|_, t| t.diameter.is_some() || t.kind.is_some());
    tools
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linuxcnc_rows_with_comments() {
        let (f, t) = read("T1 P1 D10.0 Z+25.0 ;10mm 3FL flat end mill\nT7 P7 D6.8 Z0 ;6.8 drill\n\n", false).unwrap();
        assert_eq!(f, Format::LinuxCnc);
        assert_eq!(t[&1].diameter, Some(10.0));
        assert_eq!(t[&1].length, 25.0);
        assert_eq!(t[&1].kind.as_deref(), Some("end_mill"));
        assert_eq!(t[&7].kind.as_deref(), Some("twist_drill"));
        let (_, t) = read("T2 P2 D0.25 ;quarter inch\n", true).unwrap();
        assert!((t[&2].diameter.unwrap() - 6.35).abs() < 1e-9);
        assert!(read("P1 D10\n", false).unwrap_err().contains("line 1"));
    }

    #[test]
    fn heidenhain_columns() {
        let text = "BEGIN TOOL.T MM\n\
                    T    NAME             L         R        R2       T-ANGLE  TYP\n\
                    0    NULLTOOL         0         0        0        0        MILL\n\
                    1    EM12             50.5      6        0        0        MILL\n\
                    5    DRILL_6_8        80        3.4      0        140      DRILL\n\
                    [END]\n";
        let (f, t) = read(text, false).unwrap();
        assert_eq!(f, Format::Heidenhain);
        assert_eq!(t[&1].diameter, Some(12.0));
        assert_eq!(t[&1].kind.as_deref(), Some("end_mill"));
        assert_eq!(t[&5].point_angle, Some(140.0));
        assert_eq!(t[&5].kind.as_deref(), Some("twist_drill"));
        assert_eq!(t[&0].diameter, None);
    }

    proptest::proptest! {
        /// Any text, however broken, is a table or a clear error: never a panic.
        #[test]
        fn any_text_is_read_or_refused(text in "(BEGIN TOOL\\.T MM\n|T[0-9]{0,3} |G10 L1[0-3] P[0-9] R[-0-9.]{0,4}\n|\\$TC_DP[0-9]\\[[0-9,]{0,3}\\]=[0-9.]{0,3}\n|[ -~\n]{0,12}|;.{0,5}){0,24}") {
            let _ = read(&text, false);
            let _ = read(&text, true);
        }
    }

    #[test]
    fn siemens_tool_offsets() {
        let text = "CHANDATA(1)\n$TC_TP1[2]=2\n$TC_TP2[2]=\"SCHAFTFRAESER_D20\"\n$TC_DP1[2,1]=120\n$TC_DP3[2,1]=92.415\n\
                    $TC_DP6[2,1]=10.\n$TC_DP6[2,2]=9.9\n$TC_DP1[5,1]=200\n$TC_DP6[5,1]=3.4\nM17\n";
        let (f, t) = read(text, false).unwrap();
        assert_eq!(f, Format::Siemens);
        assert_eq!(t[&2].diameter, Some(20.0));
        assert_eq!(t[&2].kind.as_deref(), Some("end_mill"));
        assert_eq!(t[&2].name.as_deref(), Some("SCHAFTFRAESER_D20"));
        assert_eq!(t[&5].kind.as_deref(), Some("twist_drill"));
        assert_eq!(t[&5].diameter, Some(6.8));
    }

    #[test]
    fn fanuc_offset_blocks() {
        let text = "%\nG10 L12 P1 R5.\nG10 L13 P1 R-0.02\nG10L10P1R123.4\nG10 L12 P3 R3.4\n%\n";
        let (f, t) = read(text, false).unwrap();
        assert_eq!(f, Format::FanucOffsets);
        // The nominal radius: wear is left out.
        assert_eq!(t[&1].diameter, Some(10.0));
        assert!((t[&1].length - 123.4).abs() < 1e-9);
        assert_eq!(t[&3].diameter, Some(6.8));
    }
}
