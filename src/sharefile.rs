//! A file of a watched share, as the daemon, `import` and called-program lookups meet it:
//! opened only when it is a regular file, and never in a way that can block; and its name as
//! text that loses nothing and holds no control character.
//!
//! Shell code (it opens files). **Opening.** [`open`] looks at the path first (`stat`) and
//! refuses anything but a regular file (a FIFO, a socket, a device, a folder) without opening
//! it; a regular file is then opened with `O_NONBLOCK` (a FIFO put in its place in between
//! cannot hold the open) and the opened handle is looked at again (`fstat`), so what is read
//! is the regular file that was judged. **Names.** [`path_text`] is the text a path is stored
//! and shown as: its bytes where they are UTF-8 and printable; a byte that is not UTF-8 (a
//! Latin-1 name from a Windows DNC share) or a control character (a newline that would forge a
//! log line) as `\xNN`, and a backslash that would read as such an escape as `\\`. The escape
//! is reversible ([`text_path`]): a stored path names its file again. A name that is plain
//! UTF-8 without control characters is its own text, as it always was.

use std::ffi::OsStr;
use std::fs::{File, Metadata};
use std::io::Read as _;
use std::os::unix::ffi::{OsStrExt as _, OsStringExt as _};
use std::os::unix::fs::{FileTypeExt as _, OpenOptionsExt as _};
use std::path::{Path, PathBuf};

/// A file of a share, opened.
#[derive(Debug)]
pub enum Opened {
    /// A regular file, and its metadata taken on the opened handle.
    File(File, Metadata),
    /// Not a regular file: what it is (`a FIFO`, `a socket`, `a device`, `a folder`); not read.
    NotRegular(&'static str),
}

/// What a file type is, in words, for a file that is not regular.
pub fn kind(t: std::fs::FileType) -> &'static str {
    if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else if t.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// Opens `path` (links followed) for reading if it is a regular file, without blocking: see
/// the module comment. A path that vanished is the `NotFound` error.
pub fn open(path: &Path) -> std::io::Result<Opened> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Ok(Opened::NotRegular(kind(meta.file_type())));
    }
    let file = std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY).open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Ok(Opened::NotRegular(kind(meta.file_type())));
    }
    Ok(Opened::File(file, meta))
}

/// The bytes of `path` when it is a regular file of at most `limit` bytes; `None` otherwise
/// (not regular, too large, unreadable).
pub fn read_regular(path: &Path, limit: u64) -> Option<Vec<u8>> {
    let Ok(Opened::File(file, meta)) = open(path) else { return None };
    if meta.len() > limit {
        return None;
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes).ok()?;
    (bytes.len() as u64 <= limit).then_some(bytes)
}

/// The text a path is stored, logged and shown as (see the module comment): reversible by
/// [`text_path`], without control characters.
pub fn path_text(path: &Path) -> String {
    os_text(path.as_os_str())
}

/// [`path_text`] of any name (a file name alone).
pub fn os_text(name: &OsStr) -> String {
    let bytes = name.as_bytes();
    let mut out = String::with_capacity(bytes.len());
    for chunk in bytes.utf8_chunks() {
        let valid = chunk.valid();
        for (i, c) in valid.char_indices() {
            if c.is_control() {
                let mut buf = [0; 4];
                for b in c.encode_utf8(&mut buf).bytes() {
                    out.push_str(&format!("\\x{b:02x}"));
                }
            } else if c == '\\' && escapes_next(&valid[i + 1..], !chunk.invalid().is_empty()) {
                out.push_str("\\\\");
            } else {
                out.push(c);
            }
        }
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02x}"));
        }
    }
    out
}

/// Whether a backslash followed by `rest` (and, when `rest` is empty, by an escaped byte if
/// `before_escape`) would read as an escape, so that it must be written `\\`: before a
/// backslash, an `x`, or anything written as `\xNN`.
fn escapes_next(rest: &str, before_escape: bool) -> bool {
    match rest.chars().next() {
        Some(n) => n == '\\' || n == 'x' || n.is_control(),
        None => before_escape,
    }
}

/// The path a stored text names: [`path_text`] undone. A backslash not followed by `\` or
/// `xNN` is itself (paths stored before the escape existed read as they were).
pub fn text_path(text: &str) -> PathBuf {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'\\' {
            if b.get(i + 1) == Some(&b'\\') {
                out.push(b'\\');
                i += 2;
                continue;
            }
            if b.get(i + 1) == Some(&b'x')
                && let Some(v) = text.get(i + 2..i + 4).and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(v);
                i += 4;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    PathBuf::from(std::ffi::OsString::from_vec(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(bytes: &[u8]) -> PathBuf {
        PathBuf::from(std::ffi::OsString::from_vec(bytes.to_vec()))
    }

    #[test]
    fn names_are_text_without_control_characters_and_come_back_whole() {
        let cases: [(&[u8], &str); 9] = [
            (b"/srv/share/a\\\n", "/srv/share/a\\\\\\x0a"),
            (b"/srv/share/O1234.nc", "/srv/share/O1234.nc"),
            ("/srv/share/Pièce.nc".as_bytes(), "/srv/share/Pièce.nc"),
            (b"/srv/share/PI\xc8CE.nc", "/srv/share/PI\\xc8CE.nc"),
            (b"/srv/share/a\nWARN forged.nc", "/srv/share/a\\x0aWARN forged.nc"),
            (b"/srv/share/a\\b.nc", "/srv/share/a\\b.nc"),
            (b"/srv/share/a\\xc8.nc", "/srv/share/a\\\\xc8.nc"),
            (b"/srv/share/a\\\\b", "/srv/share/a\\\\\\b"),
            (b"/srv/share/a\\\xff", "/srv/share/a\\\\\\xff"),
        ];
        for (bytes, text) in cases {
            let path = p(bytes);
            assert_eq!(path_text(&path), text, "{bytes:?}");
            assert!(!path_text(&path).chars().any(char::is_control));
            assert_eq!(text_path(text), path, "{text}");
        }
        // Every byte string survives the round trip.
        let mut all: Vec<u8> = (0..=255u8).collect();
        all.extend_from_slice(b"\\\\x\\x4\\");
        assert_eq!(text_path(&path_text(&p(&all))), p(&all));
    }

    #[test]
    fn only_regular_files_are_opened() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        assert!(matches!(open(&fifo).unwrap(), Opened::NotRegular("a FIFO")));
        assert!(matches!(open(dir.path()).unwrap(), Opened::NotRegular("a folder")));
        assert!(matches!(open(Path::new("/dev/null")).unwrap(), Opened::NotRegular("a device")));
        let file = dir.path().join("O1.nc");
        std::fs::write(&file, "G0 X1\n").unwrap();
        assert!(matches!(open(&file).unwrap(), Opened::File(_, m) if m.len() == 6));
        assert_eq!(read_regular(&file, 6).as_deref(), Some(&b"G0 X1\n"[..]));
        assert_eq!(read_regular(&file, 5), None);
        assert_eq!(read_regular(&file, u64::MAX).map(|b| b.len()), Some(6));
        assert_eq!(read_regular(&fifo, 100), None);
    }
}
