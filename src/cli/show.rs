//! `ncplan show`: print one stored revision: what it is, its findings and its changes; with
//! flags, its source or its plan.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{Result, bail};

use super::common::{StoreArgs, db_path, load_config, registry_for};
use crate::pipeline;
use crate::store::Store;

/// The arguments of `ncplan show`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// A revision id, or a program's path (whole, or its end such as `DMU50/O1234.nc`).
    revision: String,
    /// With a path: the newest revision seen at or before this time (RFC 3339, or a date).
    #[arg(long, value_name = "TIME")]
    at: Option<String>,
    /// Print the stored program bytes as they were, and nothing else.
    #[arg(long, conflicts_with = "plan")]
    source: bool,
    /// Print the stored plan as JSON, and nothing else.
    #[arg(long)]
    plan: bool,
    #[command(flatten)]
    store: StoreArgs,
}

/// Runs `ncplan show`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { revision, at, source, plan, store: store_args } = args;
    let db = db_path(&store_args)?;
    let store = Store::open_read_only(&db)?;
    let id = match revision.parse::<i64>() {
        Ok(id) if at.is_none() => id,
        _ => match store.revision_of_path(&revision, at.as_deref())? {
            Ok(Some(id)) => id,
            Ok(None) => bail!("no stored revision of `{revision}`{}", at.map(|a| format!(" at or before {a}")).unwrap_or_default()),
            Err(paths) => bail!("`{revision}` names several programs; give more of the path:\n  {}", paths.join("\n  ")),
        },
    };
    let Some(info) = store.revision(id)? else { bail!("no revision {id}") };
    if source {
        out.write_all(&store.content(id)?.unwrap_or_default())?;
    } else if plan {
        // The stored plan is a summary; the whole plan is rebuilt from the stored bytes.
        let config = match &store_args.config {
            Some(p) => load_config(Some(p))?,
            None => load_config(None)?,
        };
        let registry = registry_for(Some(&config))?;
        let reader = crate::daemon::ingest::Reader { config: &config, registry: &registry };
        match store.source(id)?.map(|src| reader.rebuild(src)).transpose()?.flatten() {
            Some(plan) => {
                serde_json::to_writer_pretty(&mut out, &plan)?;
                writeln!(out)?;
            }
            None => bail!("revision {id} has no plan (status {})", info.status),
        }
    } else {
        write_revision(&mut out, &store, &info)?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn write_revision(out: &mut impl Write, store: &Store, r: &crate::store::RevisionInfo) -> Result<()> {
    let place = r.machine.as_deref().map_or_else(|| "CAM original".to_owned(), |m| format!("machine {m}"));
    writeln!(out, "revision {}: {place}, program {} ({})", r.id, r.name, r.dialect)?;
    writeln!(out, "  path     {}", r.path)?;
    writeln!(out, "  seen     {}", r.seen_at)?;
    writeln!(out, "  content  {} bytes, {}, sha256 {}", r.size, r.encoding, r.hash)?;
    let status = match (r.status.as_str(), r.partial_of) {
        (_, Some(by)) => format!("a partial write of revision {by}; kept out of the change report"),
        ("too_large", _) => "too large; stored, not analysed".into(),
        ("empty", _) => "holds no program; stored, never compared".into(),
        _ => "analysed".into(),
    };
    writeln!(out, "  status   {status}")?;
    match &r.original {
        Some((id, path, rule, n)) => writeln!(out, "  compared with revision {id} ({path}), paired by {rule}: {n} changes")?,
        None if r.role == "machine" => writeln!(out, "  not compared (no CAM original paired)")?,
        None => {}
    }
    let findings = store.findings(r.id)?;
    writeln!(out, "\nfindings ({}):", findings.len())?;
    for f in &findings {
        writeln!(out, "  {}:{}: {}[{}]: {}", f.line, f.col, f.severity, f.code, f.message)?;
    }
    let changes = store.changes(r.id)?;
    if r.original.is_some() {
        writeln!(out, "\nchanges ({}):", changes.len())?;
        for line in pipeline::render_plain(&changes) {
            writeln!(out, "  - {line}")?;
        }
    }
    writeln!(out, "\n(--source prints the program, --plan its plan)")?;
    Ok(())
}
