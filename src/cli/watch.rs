//! `ncplan watch`: watch the configured folders and store every revision and its changes.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result};

use super::common::{demo_config_here, dialect, load_config, registry_for, this_binary};
use crate::config;

/// The arguments of `ncplan watch`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Configuration file; without it, the built-in demo configuration.
    #[arg(long)]
    config: Option<PathBuf>,
}

/// Runs `ncplan watch`.
pub(super) fn run(args: Args) -> Result<ExitCode> {
    let Args { config: given } = args;
    let demo = given.is_none();
    let config = if demo { demo_config_here()? } else { load_config(given.as_deref())? };
    config.check_watchable()?;
    let registry = registry_for(Some(&config))?;
    for f in config.folders.iter().filter(|f| f.dialect != config::AUTO_DIALECT) {
        dialect(&registry, &f.dialect).with_context(|| format!("folder {}", crate::sharefile::path_text(&f.path)))?;
    }
    init_tracing();
    println!(
        "ncplan watch: database {}{}",
        config.database,
        if config.site.is_empty() { String::new() } else { format!(", site {}", config.site) }
    );
    for f in &config.folders {
        println!(
            "  {:<8} {:<10} {:<9} {}{}",
            f.role.as_str(),
            f.name,
            f.dialect,
            crate::sharefile::path_text(&f.path),
            if f.poll { " (polled)" } else { "" }
        );
    }
    if demo {
        println!("Try, in another terminal: cp demo/examples/O1234_edited.nc demo/shares/DMU50/O1234.nc");
        println!("then: {} report --wait", this_binary());
    }
    crate::daemon::run(config, registry, Arc::new(crate::daemon::SystemClock))?;
    Ok(ExitCode::SUCCESS)
}

/// Logs to stderr: coloured only on a terminal; under systemd, to the journal with its fields.
fn init_tracing() {
    use std::io::IsTerminal;
    use tracing_subscriber::layer::SubscriberExt;
    use tracing_subscriber::util::SubscriberInitExt;
    let filter = tracing_subscriber::EnvFilter::try_from_env("NCPLAN_LOG").unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    if std::env::var_os("JOURNAL_STREAM").is_some()
        && let Ok(journal) = tracing_journald::layer()
    {
        let _ = tracing_subscriber::registry().with(filter).with(journal.with_syslog_identifier("ncplan".into())).try_init();
        return;
    }
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(std::io::stderr().is_terminal())
        .with_writer(std::io::stderr)
        .try_init();
}
