//! Where the database is: a SQLite file, or a PostgreSQL server named by a URL whose
//! password comes from a file readable only by the service user, or from the environment.

use std::path::{Path, PathBuf};

/// The environment variable a PostgreSQL password may come from.
pub const PASSWORD_ENV: &str = "NCPLAN_DB_PASSWORD";
/// The environment variable naming a file the PostgreSQL password may come from.
pub const PASSWORD_FILE_ENV: &str = "NCPLAN_DB_PASSWORD_FILE";

/// A database.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// A SQLite file.
    Sqlite(PathBuf),
    /// A PostgreSQL database.
    Postgres(PgTarget),
}

/// A PostgreSQL database: its URL (`postgresql://user@host:port/db?sslmode=require`) and
/// where its password is kept.
#[derive(Clone, PartialEq, Eq)]
pub struct PgTarget {
    /// The URL as given; shown only with its password blanked ([`PgTarget::shown`]).
    pub(super) url: String,
    /// A file holding the password, readable by its owner alone.
    pub(super) password_file: Option<PathBuf>,
}

impl std::fmt::Debug for PgTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PgTarget").field("url", &self.shown()).field("password_file", &self.password_file).finish()
    }
}

impl PgTarget {
    /// The URL as given, to write into a generated configuration (benchmarks); may hold a password.
    pub fn url_for_config(&self) -> &str {
        &self.url
    }

    /// The URL with any password in it blanked, for messages and logs.
    pub fn shown(&self) -> String {
        redact(&self.url)
    }
}

impl Location {
    /// A `--db` argument: a `postgresql://` (or `postgres://`) URL, else a SQLite file.
    pub fn parse(text: &str) -> Location {
        if is_url(text) {
            Location::Postgres(PgTarget { url: text.to_owned(), password_file: None })
        } else {
            Location::Sqlite(PathBuf::from(text))
        }
    }

    /// A PostgreSQL URL with the file its password is kept in.
    pub fn postgres(url: &str, password_file: Option<PathBuf>) -> Location {
        Location::Postgres(PgTarget { url: url.to_owned(), password_file })
    }

    /// The SQLite file, if it is one.
    pub fn file(&self) -> Option<&Path> {
        match self {
            Location::Sqlite(p) => Some(p),
            Location::Postgres(_) => None,
        }
    }

    /// Whether the database is there to be read: a SQLite file that exists, or any server
    /// (whether it answers shows when it is opened).
    pub fn exists(&self) -> bool {
        match self {
            Location::Sqlite(p) => p.exists(),
            Location::Postgres(_) => true,
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Sqlite(p) => write!(f, "{}", p.display()),
            Location::Postgres(t) => f.write_str(&t.shown()),
        }
    }
}

/// Whether `text` is a PostgreSQL URL.
pub fn is_url(text: &str) -> bool {
    text.starts_with("postgresql://") || text.starts_with("postgres://")
}

/// The URL with the password of its user part (`user:secret@`) and any `password=`
/// parameter blanked.
fn redact(url: &str) -> String {
    let (scheme, rest) = url.split_once("://").unwrap_or(("", url));
    let (authority, tail) = match rest.find(['/', '?']) {
        Some(i) => rest.split_at(i),
        None => (rest, ""),
    };
    let authority = match authority.rsplit_once('@') {
        Some((user, host)) => match user.split_once(':') {
            Some((name, _)) => format!("{name}:***@{host}"),
            None => format!("{user}@{host}"),
        },
        None => authority.to_owned(),
    };
    let tail = match tail.split_once('?') {
        Some((path, query)) => {
            let params: Vec<String> = query
                .split('&')
                .map(|p| if p.to_ascii_lowercase().starts_with("password=") { "password=***".to_owned() } else { p.to_owned() })
                .collect();
            format!("{path}?{}", params.join("&"))
        }
        None => tail.to_owned(),
    };
    format!("{scheme}://{authority}{tail}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passwords_are_never_shown() {
        let l = Location::parse("postgresql://ncplan:s3cret@db.plant:5433/ncplan?sslmode=require&password=other");
        let shown = l.to_string();
        assert_eq!(shown, "postgresql://ncplan:***@db.plant:5433/ncplan?sslmode=require&password=***");
        assert!(!format!("{l:?}").contains("s3cret"));
        assert_eq!(Location::parse("postgres://u@h/db").to_string(), "postgres://u@h/db");
        assert_eq!(Location::parse("var/ncplan.db"), Location::Sqlite(PathBuf::from("var/ncplan.db")));
    }
}
