//! `ncplan serve`: serve the planners' workspace.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Result, bail};

use super::common::{load_config, registry_for};
use crate::store::Location;

/// The arguments of `ncplan serve`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Configuration (database, folders, [[web.user]]); without it, the built-in demo's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Address to listen on (default 127.0.0.1:8480, or the configuration's [web] listen);
    /// another than loopback needs users configured.
    #[arg(long, value_name = "ADDR")]
    listen: Option<String>,
    /// The database instead of the configuration's: a SQLite file or a `postgresql://` URL.
    #[arg(long, value_name = "FILE|URL")]
    db: Option<String>,
}

/// Runs `ncplan serve`.
pub(super) fn run(args: Args) -> Result<ExitCode> {
    let Args { config: given, listen, db } = args;
    let mut config = load_config(given.as_deref())?;
    if let Some(db) = db {
        config.database = Location::parse(&db);
    }
    if !config.database.exists() {
        bail!("no database at {} (has `ncplan watch` run?)", config.database);
    }
    let registry = registry_for(Some(&config))?;
    let db = config.database.clone();
    let options = crate::web::Options { config, registry, listen, clock: Arc::new(crate::daemon::SystemClock) };
    crate::web::serve(options, |addr| {
        println!("ncplan serve: http://{addr}/ (database {db})");
        let _ = std::io::stdout().flush();
    })?;
    Ok(ExitCode::SUCCESS)
}
