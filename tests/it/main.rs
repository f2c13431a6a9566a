//! Integration tests: one binary (matklad's advice), one module per area.

mod arch;
mod cli;
mod cycles;
mod daemon;
mod derived;
mod dialects;
mod encodings;
mod equivalence;
mod flow;
mod macros;
mod plan;
mod robustness;
mod shop;
mod stepnc;

use std::path::{Path, PathBuf};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shared corpus beside the checkout, if present.
pub fn shared() -> PathBuf {
    root().join("../shared")
}

/// The built `ncplan` binary.
pub fn bin() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_ncplan"))
}
