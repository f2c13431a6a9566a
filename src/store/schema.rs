//! Schema migrations, applied in order; `PRAGMA user_version` holds how many have run.
//! Never edit a shipped migration: append a new one.

/// The migrations.
pub const MIGRATIONS: &[&str] = &[r#"
CREATE TABLE machines (
    id      INTEGER PRIMARY KEY,
    name    TEXT NOT NULL UNIQUE,
    dialect TEXT NOT NULL,
    folder  TEXT NOT NULL
);
CREATE TABLE programs (
    id          INTEGER PRIMARY KEY,
    path        TEXT NOT NULL UNIQUE,
    role        TEXT NOT NULL CHECK (role IN ('cam', 'machine')),
    machine_id  INTEGER REFERENCES machines(id),
    name        TEXT NOT NULL,
    program_key TEXT NOT NULL,
    stem        TEXT NOT NULL,
    dialect     TEXT NOT NULL
);
CREATE INDEX programs_key ON programs(role, program_key);
CREATE INDEX programs_stem ON programs(role, stem);
CREATE TABLE blobs (
    hash    TEXT PRIMARY KEY,
    size    INTEGER NOT NULL,
    content BLOB NOT NULL
);
CREATE TABLE revisions (
    id         INTEGER PRIMARY KEY,
    program_id INTEGER NOT NULL REFERENCES programs(id),
    hash       TEXT NOT NULL REFERENCES blobs(hash),
    size       INTEGER NOT NULL,
    mtime_ns   INTEGER,
    seen_at    TEXT NOT NULL,
    encoding   TEXT NOT NULL,
    status     TEXT NOT NULL
);
CREATE INDEX revisions_program ON revisions(program_id, id);
CREATE TABLE plans (
    revision_id  INTEGER PRIMARY KEY REFERENCES revisions(id),
    plan_json    TEXT NOT NULL,
    workingsteps INTEGER NOT NULL,
    tools        INTEGER NOT NULL
);
CREATE TABLE diagnostics (
    id          INTEGER PRIMARY KEY,
    revision_id INTEGER NOT NULL REFERENCES revisions(id),
    code        TEXT NOT NULL,
    severity    TEXT NOT NULL,
    line        INTEGER NOT NULL,
    col         INTEGER NOT NULL,
    byte_start  INTEGER NOT NULL,
    byte_end    INTEGER NOT NULL,
    message     TEXT NOT NULL
);
CREATE INDEX diagnostics_revision ON diagnostics(revision_id);
CREATE TABLE comparisons (
    revision_id          INTEGER PRIMARY KEY REFERENCES revisions(id),
    original_revision_id INTEGER NOT NULL REFERENCES revisions(id),
    compared_at          TEXT NOT NULL,
    changes              INTEGER NOT NULL
);
CREATE TABLE changes (
    id                   INTEGER PRIMARY KEY,
    revision_id          INTEGER NOT NULL REFERENCES revisions(id),
    original_revision_id INTEGER NOT NULL REFERENCES revisions(id),
    workingstep          INTEGER NOT NULL,
    operation            TEXT NOT NULL,
    kind                 TEXT NOT NULL,
    field                TEXT NOT NULL,
    before               TEXT NOT NULL,
    after                TEXT NOT NULL,
    line                 INTEGER,
    detected_at          TEXT NOT NULL
);
CREATE INDEX changes_revision ON changes(revision_id);
CREATE TRIGGER blobs_immutable BEFORE UPDATE ON blobs BEGIN SELECT RAISE(ABORT, 'blobs are immutable'); END;
CREATE TRIGGER blobs_permanent BEFORE DELETE ON blobs BEGIN SELECT RAISE(ABORT, 'blobs are never deleted'); END;
CREATE TRIGGER revisions_immutable BEFORE UPDATE ON revisions BEGIN SELECT RAISE(ABORT, 'revisions are immutable'); END;
CREATE TRIGGER revisions_permanent BEFORE DELETE ON revisions BEGIN SELECT RAISE(ABORT, 'revisions are never deleted'); END;
CREATE VIEW shopfloor_changes AS
SELECT m.name        AS machine,
       p.name        AS program,
       op.path       AS original_path,
       p.path        AS edited_path,
       c.revision_id AS revision_id,
       c.workingstep AS workingstep,
       c.kind        AS kind,
       c.field       AS field,
       c.before      AS before,
       c.after       AS after,
       c.detected_at AS detected_at,
       c.operation   AS operation,
       c.id          AS change_id
FROM changes c
JOIN revisions r   ON r.id = c.revision_id
JOIN programs p    ON p.id = r.program_id
LEFT JOIN machines m ON m.id = p.machine_id
JOIN revisions orv ON orv.id = c.original_revision_id
JOIN programs op   ON op.id = orv.program_id;
"#];

#[cfg(test)]
mod tests {
    use crate::store::Store;

    #[test]
    fn migrations_apply_and_protect_revisions() {
        let s = Store::open_in_memory().unwrap();
        assert_eq!(s.version().unwrap(), super::MIGRATIONS.len());
        let (cols, _) = s.query("SELECT * FROM shopfloor_changes").unwrap();
        let want =
            "machine program original_path edited_path revision_id workingstep kind field before after detected_at operation change_id";
        assert_eq!(cols.join(" "), want);
        s.conn.execute_batch("INSERT INTO blobs VALUES ('h', 1, x'00')").unwrap();
        assert!(s.conn.execute_batch("UPDATE blobs SET size = 2").is_err());
        assert!(s.conn.execute_batch("DELETE FROM blobs").is_err());
    }
}
