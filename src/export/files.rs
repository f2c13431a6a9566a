//! The outbox: the files `ncplan export-suggestions` writes.
//!
//! - `fusion`: `ncplan-suggestions.json`, an Autodesk Fusion / Inventor CAM / HSM tool library
//!   of the accepted tool suggestions (`suggest::library::export`), and the same JSON zipped as
//!   `ncplan-suggestions.tools` (one entry, `tools.json`, stored: a plain zip any reader takes);
//! - `csv`: `ncplan-suggestions.csv`, one row per accepted suggestion (operation notes too);
//! - `nx`: `ncplan-tool_machining_data.dat`, a fragment of NX's machining data library
//!   (`FORMAT`/`DATA` lines, as the file in `MACH/resource/library/feeds_speeds/ascii` has
//!   them) for an administrator to merge;
//! - `html`: `ncplan-suggestions.html`, the evidence report of every suggestion.
//!
//! The folder is refused when it lies in or around a watched folder, and a file is refused
//! where it would be the shop's own tool library: the CAM side's files are only read.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use super::Knowledge;
use crate::config::Config;
use crate::suggest::review::State;
use crate::suggest::{library, render};

/// What to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// The Fusion tool library, JSON and `.tools`.
    Fusion,
    /// The neutral CSV.
    Csv,
    /// A fragment of NX's `tool_machining_data.dat`.
    Nx,
    /// The evidence report.
    Html,
}

impl Format {
    /// The format of its name.
    pub fn parse(s: &str) -> Option<Format> {
        match s {
            "fusion" => Some(Format::Fusion),
            "csv" => Some(Format::Csv),
            "nx" => Some(Format::Nx),
            "html" => Some(Format::Html),
            _ => None,
        }
    }

    /// Whether writing it hands the suggestions to the CAM side (they are then exported).
    pub fn hands_over(self) -> bool {
        self != Format::Html
    }
}

/// Refuses an outbox in or around a watched folder.
pub fn check_outbox(dir: &Path, config: &Config) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot make the outbox {}", dir.display()))?;
    let real = std::fs::canonicalize(dir).with_context(|| format!("cannot read the outbox {}", dir.display()))?;
    for f in &config.folders {
        let watched = std::fs::canonicalize(&f.path).unwrap_or_else(|_| f.path.clone());
        if real.starts_with(&watched) || watched.starts_with(&real) {
            bail!("the outbox {} meets the watched folder {}; ncplan never writes into a watched folder", dir.display(), f.path.display());
        }
    }
    Ok(real)
}

/// Writes `bytes` to `dir/name`, refusing the shop's tool library; returns the path.
fn put(dir: &Path, name: &str, bytes: &[u8], config: &Config) -> Result<PathBuf> {
    let path = dir.join(name);
    if config.suggest.tool_libraries.iter().any(|l| std::fs::canonicalize(l).is_ok_and(|l| l == path)) {
        bail!("{} is the shop's tool library; ncplan never writes the CAM side's files", path.display());
    }
    let tmp = dir.join(format!(".{name}.part"));
    std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, &path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}

/// Writes `format` into `dir` (checked): the accepted suggestions and the exported ones not
/// adopted yet; returns the files and the ids of those it handed over now (the accepted ones).
pub fn write(
    k: &Knowledge,
    format: Format,
    dir: &Path,
    config: &Config,
    html: impl FnOnce(&Knowledge) -> String,
) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let dir = check_outbox(dir, config)?;
    // Accepted ones, and exported ones the CAM side has not adopted yet (an export written
    // again holds them still); only the accepted ones are handed over now.
    let accepted: Vec<_> = k.entries.iter().filter(|e| matches!(e.state, State::Accepted | State::Exported) && e.s.passed()).collect();
    let ids: Vec<String> = accepted.iter().filter(|e| e.state == State::Accepted).map(|e| e.s.id.clone()).collect();
    let mut files = Vec::new();
    match format {
        Format::Fusion => {
            let s: Vec<_> = accepted.iter().map(|e| &e.s).collect();
            let json = serde_json::to_string_pretty(&library::export(k.library.as_ref(), &s))?;
            files.push(put(&dir, "ncplan-suggestions.json", json.as_bytes(), config)?);
            files.push(put(&dir, "ncplan-suggestions.tools", &zip_one("tools.json", json.as_bytes()), config)?);
        }
        Format::Csv => {
            let rows: Vec<_> = accepted.iter().map(|e| (&e.s, e.state.name())).collect();
            files.push(put(&dir, "ncplan-suggestions.csv", render::csv(&rows).as_bytes(), config)?);
        }
        Format::Nx => {
            let s: Vec<_> = accepted.iter().map(|e| &e.s).collect();
            files.push(put(&dir, "ncplan-tool_machining_data.dat", render::nx_fragment(&s).as_bytes(), config)?);
        }
        Format::Html => files.push(put(&dir, "ncplan-suggestions.html", html(k).as_bytes(), config)?),
    }
    Ok((files, if format.hands_over() { ids } else { Vec::new() }))
}

/// A zip archive of one stored (uncompressed) file, dated 1980-01-01 so that the same
/// content gives the same bytes. The `.tools` file Fusion imports is such a zip of the JSON.
pub fn zip_one(name: &str, data: &[u8]) -> Vec<u8> {
    let (crc, size, n) = (crc32fast::hash(data), data.len() as u32, name.len() as u16);
    let mut out = Vec::with_capacity(data.len() + 2 * name.len() + 100);
    let le16 = |v: u16, o: &mut Vec<u8>| o.extend_from_slice(&v.to_le_bytes());
    let le32 = |v: u32, o: &mut Vec<u8>| o.extend_from_slice(&v.to_le_bytes());
    // Local file header: version 2.0, no flags, stored, time 0, date 1980-01-01.
    le32(0x0403_4b50, &mut out);
    for v in [20u16, 0, 0, 0, 0x21] {
        le16(v, &mut out);
    }
    for v in [crc, size, size] {
        le32(v, &mut out);
    }
    le16(n, &mut out);
    le16(0, &mut out);
    out.extend_from_slice(name.as_bytes());
    out.extend_from_slice(data);
    let central = out.len() as u32;
    le32(0x0201_4b50, &mut out);
    for v in [20u16, 20, 0, 0, 0, 0x21] {
        le16(v, &mut out);
    }
    for v in [crc, size, size] {
        le32(v, &mut out);
    }
    for v in [n, 0, 0, 0, 0] {
        le16(v, &mut out);
    }
    le32(0, &mut out);
    le32(0, &mut out);
    out.extend_from_slice(name.as_bytes());
    let central_size = out.len() as u32 - central;
    le32(0x0605_4b50, &mut out);
    for v in [0u16, 0, 1, 1] {
        le16(v, &mut out);
    }
    le32(central_size, &mut out);
    le32(central, &mut out);
    le16(0, &mut out);
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_zip_carries_the_ieee_crc32() {
        // The check value of CRC-32/ISO-HDLC, the one zip uses, at its place in the header.
        let z = super::zip_one("a", b"123456789");
        assert_eq!(&z[14..18], &0xCBF4_3926u32.to_le_bytes());
    }

    #[test]
    fn a_zip_of_one_file_has_its_headers_in_place() {
        let z = super::zip_one("tools.json", b"{}");
        assert_eq!(&z[..4], b"PK\x03\x04");
        assert_eq!(&z[30..40], b"tools.json");
        assert_eq!(&z[40..42], b"{}");
        let end = z.len() - 22;
        assert_eq!(&z[end..end + 4], b"PK\x05\x06");
        // The central directory starts where the end record says.
        let at = u32::from_le_bytes(z[end + 16..end + 20].try_into().unwrap()) as usize;
        assert_eq!(&z[at..at + 4], b"PK\x01\x02");
    }
}
