//! Schema migrations, applied in order; `PRAGMA user_version` holds how many have run.
//! Never edit a shipped migration: append a new one.

/// Rows of `workingsteps` from the stored plan JSON (SQLite's JSON functions), so that the
/// tables follow the plan without the store knowing the plan's types.
macro_rules! fill_workingsteps {
    () => {
        "INSERT INTO workingsteps(revision_id, idx, operation, tool, feature, strategy, feed, spindle_speed, spindle, coolant,
                          depth, security_plane, cutting_length, axial_depth, radial_depth, allowance_side, allowance_bottom,
                          first_line, last_line)
SELECT p.revision_id, json_extract(w.value, '$.index'), json_extract(w.value, '$.operation'), json_extract(w.value, '$.tool'),
       json_extract(w.value, '$.feature'), json_extract(w.value, '$.strategy.kind'), json_extract(w.value, '$.technology.feed'),
       json_extract(w.value, '$.technology.spindle_speed'), json_extract(w.value, '$.technology.spindle'),
       json_extract(w.value, '$.technology.coolant'), json_extract(w.value, '$.depth'), json_extract(w.value, '$.security_plane'),
       json_extract(w.value, '$.cutting_length'), json_extract(w.value, '$.axial_depth'), json_extract(w.value, '$.radial_depth'),
       json_extract(w.value, '$.allowance_side'), json_extract(w.value, '$.allowance_bottom'),
       json_extract(w.value, '$.lines[0]'), json_extract(w.value, '$.lines[1]')
FROM plans p, json_each(p.plan_json, '$.workingsteps') w"
    };
}

/// Rows of `features` from the stored plan JSON.
macro_rules! fill_features {
    () => {
        "INSERT INTO features(revision_id, id, kind, x, y, z, depth, diameter, width, length, positions, top_inferred, workingsteps,
                      first_line, last_line)
SELECT p.revision_id, json_extract(f.value, '$.id'), json_extract(f.value, '$.kind.type'), json_extract(f.value, '$.placement[0]'),
       json_extract(f.value, '$.placement[1]'), json_extract(f.value, '$.placement[2]'), json_extract(f.value, '$.depth'),
       json_extract(f.value, '$.kind.diameter'),
       COALESCE(json_extract(f.value, '$.kind.width'), json_extract(f.value, '$.kind.rectangle[0]')),
       COALESCE(json_extract(f.value, '$.kind.length'), json_extract(f.value, '$.kind.rectangle[1]')),
       json_array_length(f.value, '$.kind.positions'), json_extract(f.value, '$.top_inferred'),
       json_extract(f.value, '$.workingsteps'), json_extract(f.value, '$.lines[0]'), json_extract(f.value, '$.lines[1]')
FROM plans p, json_each(p.plan_json, '$.features') f"
    };
}

/// Fills `workingsteps` for one revision (`?1`).
pub(super) const FILL_WORKINGSTEPS: &str = concat!(fill_workingsteps!(), " WHERE p.revision_id = ?1");
/// Fills `features` for one revision (`?1`).
pub(super) const FILL_FEATURES: &str = concat!(fill_features!(), " WHERE p.revision_id = ?1");

/// The migrations.
pub const MIGRATIONS: &[&str] = &[
    r#"
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
"#,
    // 2: workingsteps and features as tables, filled from the plans already stored.
    concat!(
        "
CREATE TABLE workingsteps (
    revision_id      INTEGER NOT NULL REFERENCES revisions(id),
    idx              INTEGER NOT NULL,
    operation        TEXT NOT NULL,
    tool             INTEGER NOT NULL,
    feature          INTEGER,
    strategy         TEXT,
    feed             REAL,
    spindle_speed    REAL,
    spindle          TEXT,
    coolant          TEXT,
    depth            REAL,
    security_plane   REAL,
    cutting_length   REAL,
    axial_depth      REAL,
    radial_depth     REAL,
    allowance_side   REAL,
    allowance_bottom REAL,
    first_line       INTEGER,
    last_line        INTEGER,
    PRIMARY KEY (revision_id, idx)
);
CREATE TABLE features (
    revision_id  INTEGER NOT NULL REFERENCES revisions(id),
    id           INTEGER NOT NULL,
    kind         TEXT NOT NULL,
    x            REAL,
    y            REAL,
    z            REAL,
    depth        REAL,
    diameter     REAL,
    width        REAL,
    length       REAL,
    positions    INTEGER,
    top_inferred INTEGER,
    workingsteps TEXT,
    first_line   INTEGER,
    last_line    INTEGER,
    PRIMARY KEY (revision_id, id)
);
",
        fill_workingsteps!(),
        ";\n",
        fill_features!(),
        ";\n"
    ),
    // 3: pairing by whole names, rule by rule, with the rule stored; the name each revision
    // stated; partial writes; plans as summaries (toolpaths are rebuilt from the immutable
    // blob); a journal of analyses in progress, so that content whose analysis killed the
    // process is recorded once; where a change is (its line in the original, and for a
    // toolpath change the region and the largest deviation, mm).
    r#"
CREATE TABLE program_keys (
    program_id INTEGER NOT NULL REFERENCES programs(id),
    rule       TEXT NOT NULL CHECK (rule IN ('pattern', 'program-name', 'file-name')),
    key        TEXT NOT NULL,
    PRIMARY KEY (program_id, rule)
);
CREATE INDEX program_keys_key ON program_keys(key);
INSERT INTO program_keys(program_id, rule, key) SELECT id, 'file-name', stem FROM programs;
INSERT OR IGNORE INTO program_keys(program_id, rule, key) SELECT id, 'program-name', program_key FROM programs WHERE program_key <> stem;
ALTER TABLE comparisons ADD COLUMN rule TEXT;
ALTER TABLE revisions ADD COLUMN name TEXT;
CREATE TABLE revision_marks (
    revision_id   INTEGER PRIMARY KEY REFERENCES revisions(id),
    mark          TEXT NOT NULL CHECK (mark IN ('partial')),
    superseded_by INTEGER NOT NULL REFERENCES revisions(id),
    noted_at      TEXT NOT NULL
);
ALTER TABLE plans ADD COLUMN complete INTEGER NOT NULL DEFAULT 1;
CREATE TABLE attempts (
    hash       TEXT NOT NULL,
    path       TEXT NOT NULL,
    started_at TEXT NOT NULL,
    tries      INTEGER NOT NULL,
    PRIMARY KEY (hash, path)
);
ALTER TABLE changes ADD COLUMN original_line INTEGER;
ALTER TABLE changes ADD COLUMN region_min_x REAL;
ALTER TABLE changes ADD COLUMN region_min_y REAL;
ALTER TABLE changes ADD COLUMN region_min_z REAL;
ALTER TABLE changes ADD COLUMN region_max_x REAL;
ALTER TABLE changes ADD COLUMN region_max_y REAL;
ALTER TABLE changes ADD COLUMN region_max_z REAL;
ALTER TABLE changes ADD COLUMN deviation REAL;
DROP VIEW shopfloor_changes;
CREATE VIEW shopfloor_changes AS
SELECT m.name                    AS machine,
       COALESCE(r.name, p.name)  AS program,
       op.path                   AS original_path,
       p.path                    AS edited_path,
       c.revision_id             AS revision_id,
       c.workingstep             AS workingstep,
       c.kind                    AS kind,
       c.field                   AS field,
       c.before                  AS before,
       c.after                   AS after,
       c.detected_at             AS detected_at,
       c.operation               AS operation,
       c.id                      AS change_id,
       c.line                    AS line,
       c.original_line           AS original_line,
       c.region_min_x            AS region_min_x,
       c.region_min_y            AS region_min_y,
       c.region_min_z            AS region_min_z,
       c.region_max_x            AS region_max_x,
       c.region_max_y            AS region_max_y,
       c.region_max_z            AS region_max_z,
       c.deviation               AS deviation
FROM changes c
JOIN revisions r   ON r.id = c.revision_id
JOIN programs p    ON p.id = r.program_id
LEFT JOIN machines m ON m.id = p.machine_id
JOIN revisions orv ON orv.id = c.original_revision_id
JOIN programs op   ON op.id = orv.program_id
WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial');
"#,
    // 4: the planners' review marks (`ncplan serve`): adopt, reject or a note on a change, with
    // who and when. Their own table: analysis data is never modified. A change is named by its
    // id and, since a comparison made again replaces its change rows, by what it said, so a
    // mark never blocks a comparison and outlives it as a record.
    r#"
CREATE TABLE review_marks (
    id          INTEGER PRIMARY KEY,
    change_id   INTEGER NOT NULL,
    revision_id INTEGER NOT NULL REFERENCES revisions(id),
    kind        TEXT NOT NULL,
    before      TEXT NOT NULL,
    after       TEXT NOT NULL,
    mark        TEXT NOT NULL CHECK (mark IN ('adopt', 'reject', 'note')),
    note        TEXT NOT NULL DEFAULT '',
    marked_by   TEXT NOT NULL,
    marked_at   TEXT NOT NULL
);
CREATE INDEX review_marks_change ON review_marks(change_id);
CREATE INDEX review_marks_revision ON review_marks(revision_id);
CREATE INDEX changes_detected ON changes(detected_at);
CREATE INDEX programs_machine ON programs(machine_id);
CREATE TRIGGER review_marks_immutable BEFORE UPDATE ON review_marks BEGIN SELECT RAISE(ABORT, 'review marks are a record: add a new one'); END;
"#,
    // 5: the site each program and machine belongs
    // to (`site = "HALL2"` in the config), so that many DNC servers share one PostgreSQL
    // database. A SQLite file is one server's: its names and paths stay unique as they were.
    r#"
ALTER TABLE machines ADD COLUMN site TEXT NOT NULL DEFAULT '';
ALTER TABLE programs ADD COLUMN site TEXT NOT NULL DEFAULT '';
ALTER TABLE attempts ADD COLUMN site TEXT NOT NULL DEFAULT '';
DROP VIEW shopfloor_changes;
CREATE VIEW shopfloor_changes AS
SELECT m.name                    AS machine,
       COALESCE(r.name, p.name)  AS program,
       op.path                   AS original_path,
       p.path                    AS edited_path,
       c.revision_id             AS revision_id,
       c.workingstep             AS workingstep,
       c.kind                    AS kind,
       c.field                   AS field,
       c.before                  AS before,
       c.after                   AS after,
       c.detected_at             AS detected_at,
       c.operation               AS operation,
       c.id                      AS change_id,
       c.line                    AS line,
       c.original_line           AS original_line,
       c.region_min_x            AS region_min_x,
       c.region_min_y            AS region_min_y,
       c.region_min_z            AS region_min_z,
       c.region_max_x            AS region_max_x,
       c.region_max_y            AS region_max_y,
       c.region_max_z            AS region_max_z,
       c.deviation               AS deviation,
       p.site                    AS site
FROM changes c
JOIN revisions r   ON r.id = c.revision_id
JOIN programs p    ON p.id = r.program_id
LEFT JOIN machines m ON m.id = p.machine_id
JOIN revisions orv ON orv.id = c.original_revision_id
JOIN programs op   ON op.id = orv.program_id
WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial');
"#,
    // 6: re-analysis of the archive (`ncplan reanalyze`, `ncplan worker`): each revision's
    // plan says which analysis version made it ('' for the one at ingest); `analyses` records
    // each re-analysis once per version, with the plan and findings it replaced; the queue
    // holds what is left, with the lease of the worker that claimed it.
    r#"
CREATE TABLE analyses (
    revision_id       INTEGER NOT NULL REFERENCES revisions(id),
    version           TEXT NOT NULL,
    analysed_at       TEXT NOT NULL,
    worker            TEXT NOT NULL,
    previous          TEXT NOT NULL,
    previous_plan     TEXT,
    previous_findings TEXT NOT NULL,
    plan_changed      INTEGER NOT NULL,
    new_findings      INTEGER NOT NULL,
    vanished_findings INTEGER NOT NULL,
    PRIMARY KEY (revision_id, version)
);
CREATE TABLE reanalysis_queue (
    revision_id INTEGER NOT NULL REFERENCES revisions(id),
    version     TEXT NOT NULL,
    worker      TEXT,
    lease_until TEXT,
    PRIMARY KEY (revision_id, version)
);
ALTER TABLE plans ADD COLUMN analysis TEXT NOT NULL DEFAULT '';
"#,
    // 7: old analyses' changes kept (`old_changes`: the rows a comparison made again
    // replaced, with the analysis version that made them and the one that replaced them; a
    // change found again keeps its id, so its review marks stay on it), each change row names
    // the analysis that made it, and the SQL console's saved queries (who saved which, when).
    r#"
ALTER TABLE changes ADD COLUMN analysis TEXT NOT NULL DEFAULT '';
CREATE TABLE old_changes (
    change_id            INTEGER NOT NULL,
    revision_id          INTEGER NOT NULL REFERENCES revisions(id),
    original_revision_id INTEGER NOT NULL REFERENCES revisions(id),
    analysis             TEXT NOT NULL,
    replaced_by          TEXT NOT NULL,
    replaced_at          TEXT NOT NULL,
    workingstep          INTEGER NOT NULL,
    operation            TEXT NOT NULL,
    kind                 TEXT NOT NULL,
    field                TEXT NOT NULL,
    before               TEXT NOT NULL,
    after                TEXT NOT NULL,
    line                 INTEGER,
    detected_at          TEXT NOT NULL,
    original_line        INTEGER,
    region_min_x         REAL,
    region_min_y         REAL,
    region_min_z         REAL,
    region_max_x         REAL,
    region_max_y         REAL,
    region_max_z         REAL,
    deviation            REAL
);
CREATE INDEX old_changes_revision ON old_changes(revision_id);
CREATE INDEX old_changes_change ON old_changes(change_id);
CREATE TABLE saved_queries (
    id       INTEGER PRIMARY KEY,
    name     TEXT NOT NULL,
    sql      TEXT NOT NULL,
    saved_by TEXT NOT NULL,
    saved_at TEXT NOT NULL
);
"#,
    // 8: the planners' sign-in sessions (`ncplan serve` with `[[web.user]]`), so that a restart
    // of the server signs no one out. A session is named by the SHA-256 of its cookie's token:
    // the database (which the SQL console reads) never holds a cookie that works. It ends at
    // `expires_at`, or when its planner signs out.
    r#"
CREATE TABLE web_sessions (
    token_hash TEXT PRIMARY KEY,
    user_name  TEXT NOT NULL,
    created_at TEXT NOT NULL,
    expires_at TEXT NOT NULL
);
CREATE INDEX web_sessions_expiry ON web_sessions(expires_at);
"#,
    // 9: where a change is seen beyond its first line, and what a statement change causes
    // (issue 32): JSON of `diff::Detail`, empty when it has none.
    r#"
ALTER TABLE changes ADD COLUMN detail TEXT NOT NULL DEFAULT '';
"#,
    // 10: the programs each revision called from outside its text (lower-case file stems), so
    // that when a called program changes, the programs that call it are compared again.
    r#"
CREATE TABLE calls (
    revision_id INTEGER NOT NULL REFERENCES revisions(id),
    name        TEXT NOT NULL
);
CREATE INDEX calls_name ON calls(name);
"#,
    // 11: knowledge back to CAM (issue 42): every step of a suggestion's review (proposed,
    // accepted, rejected with its reason, snoozed, exported, adopted, reopened), who and when,
    // with the value and the evidence at that step; rows never updated. The suggestions
    // themselves are derived from the accepted changes (`suggestion_edits`, the view the
    // rules read) each time; `suggestion_states` is each one's last step.
    r#"
CREATE TABLE suggestion_events (
    suggestion TEXT NOT NULL,
    step       INTEGER NOT NULL,
    group_key  TEXT NOT NULL,
    state      TEXT NOT NULL CHECK (state IN ('proposed', 'accepted', 'rejected', 'snoozed', 'exported', 'adopted', 'reopened')),
    reason     TEXT NOT NULL DEFAULT '',
    value      REAL NOT NULL,
    evidence   INTEGER NOT NULL,
    decided_by TEXT NOT NULL,
    decided_at TEXT NOT NULL,
    PRIMARY KEY (suggestion, step)
);
CREATE TRIGGER suggestion_events_immutable BEFORE UPDATE ON suggestion_events BEGIN SELECT RAISE(ABORT, 'suggestion events are a record: add a new one'); END;
CREATE VIEW suggestion_edits AS
SELECT c.id                     AS change_id,
       c.revision_id            AS revision_id,
       c.original_revision_id   AS original_revision_id,
       COALESCE(r.name, p.name) AS program,
       op.path                  AS original_path,
       c.workingstep            AS workingstep,
       c.operation              AS operation,
       c.kind                   AS kind,
       c.field                  AS field,
       c.before                 AS before,
       c.after                  AS after,
       COALESCE(m.name, '')     AS machine,
       r.seen_at                AS seen_at,
       w.tool                   AS tool,
       w.spindle_speed          AS spindle_speed,
       (SELECT k.mark FROM review_marks k WHERE k.change_id = c.id AND k.mark <> 'note' ORDER BY k.id DESC LIMIT 1) AS review,
       (SELECT k.marked_by FROM review_marks k WHERE k.change_id = c.id AND k.mark <> 'note' ORDER BY k.id DESC LIMIT 1) AS reviewed_by
FROM changes c
JOIN revisions r   ON r.id = c.revision_id
JOIN programs p    ON p.id = r.program_id
LEFT JOIN machines m ON m.id = p.machine_id
JOIN revisions orv ON orv.id = c.original_revision_id
JOIN programs op   ON op.id = orv.program_id
LEFT JOIN workingsteps w ON w.revision_id = c.original_revision_id AND w.idx = c.workingstep
WHERE c.kind IN ('feed_changed', 'plunge_feed_changed', 'spindle_speed_changed', 'axial_depth_changed', 'stepover_changed',
                 'cycle_parameter_changed', 'clearance_changed')
  AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial');
CREATE VIEW suggestion_states AS
SELECT e.suggestion, e.group_key, e.state, e.reason, e.value, e.evidence, e.decided_by, e.decided_at, e.step AS steps
FROM suggestion_events e
WHERE e.step = (SELECT MAX(x.step) FROM suggestion_events x WHERE x.suggestion = e.suggestion);
"#,
];

#[cfg(test)]
mod tests {
    #[test]
    fn the_second_migration_fills_tables_from_stored_plans() {
        let conn = rusqlite::Connection::open_in_memory().unwrap();
        conn.execute_batch(super::MIGRATIONS[0]).unwrap();
        conn.execute_batch(
            "INSERT INTO programs VALUES (1, 'p', 'cam', NULL, 'p', 'p', 'p', 'fanuc');
             INSERT INTO blobs VALUES ('h', 1, x'00');
             INSERT INTO revisions VALUES (7, 1, 'h', 1, NULL, 't', 'utf-8', 'ok');",
        )
        .unwrap();
        let plan = r#"{"workingsteps":[{"index":1,"operation":"drilling","tool":2,"feature":1,"technology":{"feed":120.0,"spindle_speed":1500.0,"spindle":"cw","coolant":"flood"},"security_plane":50.0,"cutting_length":34.0,"lines":[4,9]}],
                       "features":[{"id":1,"kind":{"type":"round_hole","diameter":8.0,"positions":[[0,0],[40,0]]},"placement":[20,20,2],"depth":17.0,"top_inferred":true,"workingsteps":[1],"lines":[4,9]}]}"#;
        conn.execute("INSERT INTO plans VALUES (7, ?1, 1, 1)", [plan]).unwrap();
        conn.execute_batch(super::MIGRATIONS[1]).unwrap();
        let ws: (i64, String, f64, i64) = conn
            .query_row("SELECT idx, operation, feed, last_line FROM workingsteps WHERE revision_id = 7", [], |r| {
                Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?))
            })
            .unwrap();
        assert_eq!(ws, (1, "drilling".into(), 120.0, 9));
        let f: (String, f64, i64, f64) = conn
            .query_row("SELECT kind, diameter, positions, depth FROM features WHERE revision_id = 7", [], |r| {
                Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?))
            })
            .unwrap();
        assert_eq!(f, ("round_hole".into(), 8.0, 2, 17.0));
    }
}
