//! A program file read piece by piece: the shell's [`TextReader`], so that `canon` and
//! `translate` run in memory that does not grow with the file.
//!
//! Opening surveys the file once as its bytes go by ([`Survey`]: encoding, byte-order mark,
//! lone carriage returns, decoded length); the parser then reads the decoded text where it
//! needs it, by offset ([`Layout::read`]), and reads it again after a jump back. A file that
//! changes while it is read (cut short, rewritten) cannot give the text its survey saw: the
//! reads that fail say so ([`FileText::trouble`]), and so does a size or modification time
//! other than the survey's, checked after the run.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::SystemTime;

use crate::diag::Diagnostic;
use crate::text::{Encoding, HEAD, Layout, Survey, Text, TextReader};

/// A surveyed program file, read where the parser needs it.
pub struct FileText {
    file: File,
    path: PathBuf,
    layout: Layout,
    /// The file's size and modification time when it was surveyed.
    seen: (u64, Option<SystemTime>),
    /// Why the file could not be read as surveyed (the first reason).
    trouble: Mutex<Option<String>>,
    /// Held while the file's position is set and bytes read from it.
    reading: Mutex<()>,
}

/// A program's text: a regular file read piece by piece, or bytes read whole (a pipe, a
/// stored revision); with its first bytes as they are, to tell its dialect from.
pub struct Program {
    text: Whole,
    head: Vec<u8>,
}

enum Whole {
    /// A file read piece by piece.
    File(FileText),
    /// The whole decoded text.
    Whole(String),
}

impl Program {
    /// Opens `path`: a regular file is surveyed and read piece by piece; anything else (a
    /// pipe, a device) is read whole. With the findings of decoding it.
    pub fn open(path: &Path) -> std::io::Result<(Program, Vec<Diagnostic>)> {
        let mut file = File::open(path)?;
        if !file.metadata()?.is_file() {
            let mut bytes = Vec::new();
            file.read_to_end(&mut bytes)?;
            return Ok(Program::from_bytes(bytes));
        }
        let mut head = Vec::new();
        let (text, diags) = FileText::survey(file, path, &mut head)?;
        Ok((Program { text: Whole::File(text), head }, diags))
    }

    /// A program whose bytes are in memory (a stored revision), decoded whole.
    pub fn from_bytes(bytes: Vec<u8>) -> (Program, Vec<Diagnostic>) {
        let head = bytes[..bytes.len().min(HEAD)].to_vec();
        let (source, notes) = crate::text::decode_owned(bytes);
        (Program { text: Whole::Whole(source.text), head }, crate::diag::decoding(notes))
    }

    /// The text, for the core.
    pub fn text(&self) -> Text<'_> {
        match &self.text {
            Whole::File(f) => Text::Read(f),
            Whole::Whole(s) => Text::Whole(s),
        }
    }

    /// The file's first [`HEAD`] bytes, undecoded (what sniffing reads).
    pub fn head_bytes(&self) -> &[u8] {
        &self.head
    }

    /// Why the text read is not the file's as surveyed, if it is not: to be checked after a run.
    pub fn trouble(&self) -> Option<String> {
        match &self.text {
            Whole::File(f) => f.trouble(),
            Whole::Whole(_) => None,
        }
    }
}

impl FileText {
    /// Surveys `file` in one pass over its bytes, keeping its first [`HEAD`] in `head`.
    fn survey(mut file: File, path: &Path, head: &mut Vec<u8>) -> std::io::Result<(FileText, Vec<Diagnostic>)> {
        let meta = file.metadata()?;
        let seen = (meta.len(), meta.modified().ok());
        let mut survey = Survey::new();
        let mut buf = vec![0u8; 1 << 20];
        loop {
            let n = match file.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if head.len() < HEAD {
                head.extend_from_slice(&buf[..n.min(HEAD - head.len())]);
            }
            survey.feed(&buf[..n]);
        }
        let (layout, notes) = survey.finish();
        let text = FileText { file, path: path.to_path_buf(), layout, seen, trouble: Mutex::new(None), reading: Mutex::new(()) };
        Ok((text, crate::diag::decoding(notes)))
    }

    /// How the file decodes.
    pub fn encoding(&self) -> Encoding {
        self.layout.encoding
    }

    /// Why the file could not be read as it was surveyed, if so: a read that failed or found
    /// other bytes, or a size or modification time that changed since.
    pub fn trouble(&self) -> Option<String> {
        if let Some(t) = self.trouble.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone() {
            return Some(t);
        }
        let now = self.file.metadata().ok().map(|m| (m.len(), m.modified().ok()));
        (now != Some(self.seen))
            .then(|| format!("{} changed while it was read: the result is not that of one version of it", self.path.display()))
    }

    fn note(&self, why: String) {
        let mut t = self.trouble.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        t.get_or_insert(why);
    }
}

impl TextReader for FileText {
    fn len(&self) -> usize {
        self.layout.text_len()
    }

    fn read(&self, at: usize, want: usize, buf: &mut String) -> usize {
        let mut failed = None;
        // Appended where the buffer's room lies, not read into room cleared for it first:
        // the position set and the bytes read under one lock, since the position is the
        // file's own.
        let mut read_at = |offset: u64, most: usize, b: &mut Vec<u8>| {
            let _reading = self.reading.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            let mut file = &self.file;
            let read = file.seek(SeekFrom::Start(offset)).and_then(|_| file.take(most as u64).read_to_end(b));
            match read {
                Ok(n) => n,
                Err(e) => {
                    failed = Some(e);
                    0
                }
            }
        };
        match self.layout.read(at, want, &mut read_at, buf) {
            Ok(start) => start,
            Err(_) => {
                let why = match failed {
                    Some(e) => format!("{} could not be read on: {e}", self.path.display()),
                    None => format!("{} changed while it was read (it no longer holds the text first read)", self.path.display()),
                };
                self.note(why);
                at
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(t: Text<'_>) -> String {
        t.piece(0, t.len()).into_owned()
    }

    #[test]
    fn a_file_reads_as_its_decoded_text() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.nc");
        let bytes = b"\xEF\xBB\xBFG0 X1\r\n(caf\xe9 \x80)\rG1 X2\nM2\n".to_vec();
        std::fs::write(&path, &bytes).unwrap();
        let (program, diags) = Program::open(&path).unwrap();
        let (whole, want) = crate::text::decode(&bytes);
        assert_eq!((read_all(program.text()), diags), (whole.text, crate::diag::decoding(want)));
        assert_eq!(program.head_bytes(), &bytes[..]);
        assert_eq!(program.trouble(), None);
    }

    #[test]
    fn a_file_cut_short_or_grown_while_it_is_read_is_trouble() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.nc");
        let text: String = (0..2000).map(|i| format!("N{i} X{i}.5 Y-2\n")).collect();
        std::fs::write(&path, &text).unwrap();
        let (program, _) = Program::open(&path).unwrap();
        assert_eq!(read_all(program.text()), text);
        // Cut short by a writer: reading past its new end fails, and says why.
        std::fs::OpenOptions::new().write(true).open(&path).unwrap().set_len(100).unwrap();
        let t = program.text();
        let tail = t.piece(text.len() - 50, 50);
        assert!(tail.is_empty(), "{tail:?}");
        assert!(program.trouble().is_some_and(|w| w.contains("p.nc")), "{:?}", program.trouble());
        // Grown after the survey: its size is not the one surveyed.
        std::fs::write(&path, &text).unwrap();
        let (program, _) = Program::open(&path).unwrap();
        let file = std::fs::OpenOptions::new().append(true).open(&path).unwrap();
        std::os::unix::fs::FileExt::write_all_at(&file, b"M30\n", text.len() as u64).unwrap();
        assert!(program.trouble().is_some_and(|w| w.contains("changed while it was read")), "{:?}", program.trouble());
    }
}
