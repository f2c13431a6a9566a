//! `ncplan query`: run one read-only SQL statement against the database.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;

use super::common::{Format, StoreArgs, db_path};
use crate::store::Store;

/// The arguments of `ncplan query`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// SQL: one SELECT, WITH, VALUES or EXPLAIN statement.
    sql: String,
    #[command(flatten)]
    store: StoreArgs,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
}

/// Runs `ncplan query`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { sql, store, format } = args;
    let db = db_path(&store)?;
    let store = Store::open_read_only(&db)?;
    let (cols, rows) = match store.query_read_only(&sql) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return Ok(ExitCode::from(2));
        }
    };
    match format {
        Format::Json => {
            let objs: Vec<serde_json::Map<String, serde_json::Value>> =
                rows.iter().map(|r| cols.iter().cloned().zip(r.iter().map(|v| serde_json::Value::String(v.clone()))).collect()).collect();
            serde_json::to_writer_pretty(&mut out, &objs)?;
            writeln!(out)?;
        }
        Format::Text => {
            writeln!(out, "{}", cols.join("\t"))?;
            for r in rows {
                writeln!(out, "{}", r.join("\t"))?;
            }
        }
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
