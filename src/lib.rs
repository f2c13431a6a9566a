//! ncplan: recover process plans from CNC part programs, diff them against the CAM original,
//! and keep the shopfloor's changes.
//!
//! The pure core (`text`, `diag`, `dialect`, `syntax`, `interp`, `canon`, `meta`, `plan`, `part21`,
//! `diff`, `pipeline`, `view`, `suggest`) does no IO. The shell around it (`config`, `store`, `daemon`, `web`, `export`, `cli`, `bench`,
//! `textfile`, `sharefile`) reads files, talks SQL and watches folders. See `ARCHITECTURE.md`.

#![warn(missing_docs)]

pub mod bench;
pub mod canon;
pub mod cli;
pub mod config;
pub mod daemon;
pub mod diag;
pub mod dialect;
pub mod diff;
pub mod export;
pub mod import;
pub mod interp;
pub mod machine_config;
pub mod pairing;
pub mod part21;
pub mod pipeline;
pub mod plan;
pub mod post;
pub mod proof;
pub mod reanalyze;
pub mod sharefile;
pub mod store;
pub mod suggest;
pub mod syntax;
pub mod text;
pub mod textfile;
pub mod view;
pub mod web;
