//! The SQLite back end: one study per file (WAL journal, synchronous commits), so that a told
//! result is on disk before `tell` returns. Writers take SQLite's write lock for the whole
//! transaction (`BEGIN IMMEDIATE`); a second process waits up to [`BUSY_TIMEOUT`] and then
//! gets a clear "busy" error. The schema version is SQLite's `user_version`.

use std::path::Path;
use std::time::Duration;

use rusqlite::{Connection, OpenFlags, OptionalExtension, params};

use super::SCHEMA_VERSION;
use super::Trial;
use super::claim::Claim;
use super::rows::TRIALS;
use super::rows::sqlite::{SqliteRows, SqliteRowsTransaction};
use super::storage::{Dump, Row, Storage, Told, Transaction};
use crate::error::{Error, Result};

/// How long a process waits for another one's transaction before reporting "busy".
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// The first 16 bytes of every SQLite database file.
const SQLITE_HEADER: &[u8; 16] = b"SQLite format 3\0";

/// The trial columns [`row_to_trial`] reads, in its order.
const TRIAL_COLUMNS: &str = "id, weights, reward, lap_time_s, failure, x_fail";

/// A study in an SQLite file.
pub struct Sqlite {
    rows: SqliteRows,
}

/// Sorts an SQLite error by its code: busy or locked, not a database, or another failure.
pub(crate) fn sql_error(path: &Path, source: rusqlite::Error) -> Error {
    use rusqlite::ErrorCode;
    let path = path.to_owned();
    match source.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy | ErrorCode::DatabaseLocked) => Error::Busy { path },
        Some(ErrorCode::NotADatabase) => Error::NotAStudy {
            path,
            reason: "the file is not an SQLite database".into(),
        },
        _ => Error::Sql { path, source },
    }
}

impl Sqlite {
    /// Creates the study file holding `dump`; refuses to overwrite one. The file is built
    /// under a temporary name and linked into place once complete, so that a create killed
    /// half-way leaves no half-made study behind.
    pub fn create(path: &Path, dump: &Dump) -> Result<()> {
        if path.exists() {
            return Err(Error::AlreadyExists {
                path: path.to_owned(),
            });
        }
        let building = path.with_file_name(format!(
            ".{}.creating-{}",
            path.file_name()
                .map_or("study".into(), |n| n.to_string_lossy()),
            std::process::id()
        ));
        let err = |e| sql_error(path, e);
        let mut conn = Connection::open(&building).map_err(err)?;
        configure(&conn).map_err(err)?;
        let tx = conn.transaction().map_err(err)?;
        tx.execute_batch(
            "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
             CREATE TABLE trials (
                 id INTEGER PRIMARY KEY,
                 weights TEXT NOT NULL,
                 reward REAL,
                 lap_time_s REAL,
                 failure TEXT,
                 x_fail REAL,
                 asked_unix_s REAL NOT NULL,
                 told_unix_s REAL,
                 owner TEXT,
                 lease_until_unix_s REAL);
             CREATE TABLE optimizer (id INTEGER PRIMARY KEY CHECK (id = 1), state TEXT NOT NULL);",
        )
        .map_err(err)?;
        tx.execute(
            "INSERT INTO meta (key, value) VALUES ('config', ?1)",
            params![dump.config],
        )
        .map_err(err)?;
        tx.execute(
            "INSERT INTO optimizer (id, state) VALUES (1, ?1)",
            params![dump.optimizer],
        )
        .map_err(err)?;
        for row in &dump.trials {
            let t = &row.trial;
            let weights = super::weights_json(&t.weights)?;
            tx.execute(
                "INSERT INTO trials (id, weights, reward, lap_time_s, failure, x_fail, asked_unix_s, told_unix_s, owner, lease_until_unix_s)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                params![
                    t.id,
                    weights,
                    t.reward,
                    t.lap_time_s,
                    t.failure,
                    t.x_fail,
                    row.asked_unix_s,
                    row.told_unix_s,
                    row.owner,
                    row.lease_until_unix_s
                ],
            )
            .map_err(err)?;
        }
        tx.pragma_update(None, "user_version", SCHEMA_VERSION)
            .map_err(err)?;
        tx.commit().map_err(err)?;
        // Closing the only connection checkpoints the WAL into the file.
        conn.close().map_err(|(_, e)| err(e))?;
        // A hard link never replaces a study another process created meanwhile.
        let placed = match std::fs::hard_link(&building, path) {
            Ok(()) => std::fs::remove_file(&building),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let _ = std::fs::remove_file(&building);
                return Err(Error::AlreadyExists {
                    path: path.to_owned(),
                });
            }
            Err(_) => std::fs::rename(&building, path),
        };
        placed.map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })
    }

    /// Opens the study file at `path` and reads its settings (JSON). Writable, a study of an
    /// older schema is upgraded; read-only, nothing is written, and a file or folder that is
    /// read-only works (then as an immutable file, if SQLite cannot share it).
    pub fn open(path: &Path, writable: bool) -> Result<(Sqlite, String)> {
        if !path.is_file() {
            return Err(Error::NoStudy {
                path: path.to_owned(),
            });
        }
        check_header(path)?;
        let err = |e| sql_error(path, e);
        let (conn, version) = if writable {
            let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE)
                .map_err(err)?;
            conn.busy_timeout(BUSY_TIMEOUT).map_err(err)?;
            let version = user_version(&conn).map_err(err)?;
            (conn, version)
        } else {
            read_only_connection(path)?
        };
        super::check_version(path, version)?;
        // Read before anything is written: a foreign database is left as it was.
        let config: Option<String> = if version >= 1 {
            conn.query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
                r.get(0)
            })
            .optional()
            .map_err(err)?
        } else {
            None
        };
        let config = config.ok_or_else(|| Error::NotAStudy {
            path: path.to_owned(),
            reason: "an SQLite database without a study in it".into(),
        })?;
        if writable {
            configure(&conn).map_err(err)?;
            if version < SCHEMA_VERSION {
                upgrade(&conn).map_err(err)?;
            }
        }
        Ok((
            Sqlite {
                rows: SqliteRows::new(path, conn, &TRIALS),
            },
            config,
        ))
    }
}

impl Storage for Sqlite {
    fn label(&self) -> &Path {
        self.rows.path()
    }

    fn begin(&mut self) -> Result<Box<dyn Transaction + '_>> {
        Ok(Box::new(SqliteTransaction {
            rows: self.rows.begin()?,
        }))
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        self.rows.heartbeat(id, owner, until)
    }

    fn told(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn history(&mut self) -> Result<Vec<Trial>> {
        Ok(self.dump_rows()?.into_iter().map(|r| r.trial).collect())
    }

    fn dump(&mut self) -> Result<Dump> {
        let err = self.rows.err();
        let config = self
            .rows
            .conn()
            .query_row("SELECT value FROM meta WHERE key = 'config'", [], |r| {
                r.get(0)
            })
            .map_err(&err)?;
        let optimizer = optimizer_state(self.rows.conn()).map_err(err)?;
        Ok(Dump {
            config,
            optimizer,
            trials: self.dump_rows()?,
        })
    }
}

impl Sqlite {
    fn dump_rows(&self) -> Result<Vec<Row>> {
        let err = self.rows.err();
        let conn = self.rows.conn();
        // A schema-1 study opened read-only is read as it is: it has no claim columns.
        let claims = if user_version(conn).map_err(&err)? >= 2 {
            "owner, lease_until_unix_s"
        } else {
            "NULL, NULL"
        };
        let mut stmt = conn
            .prepare(&format!(
                "SELECT {TRIAL_COLUMNS}, asked_unix_s, told_unix_s, {claims} FROM trials ORDER BY id"
            ))
            .map_err(&err)?;
        let rows = stmt
            .query_map([], |r| {
                Ok(Row {
                    trial: row_to_trial(r)?,
                    asked_unix_s: r.get(6)?,
                    told_unix_s: r.get(7)?,
                    owner: r.get(8)?,
                    lease_until_unix_s: r.get(9)?,
                })
            })
            .map_err(&err)?;
        rows.collect::<rusqlite::Result<Vec<_>>>().map_err(err)
    }
}

/// A write transaction on an SQLite study.
struct SqliteTransaction<'a> {
    rows: SqliteRowsTransaction<'a>,
}

impl<'a> SqliteTransaction<'a> {
    fn tx(&self) -> &rusqlite::Transaction<'a> {
        self.rows.tx()
    }

    fn err(&self) -> impl Fn(rusqlite::Error) -> Error + 'a {
        self.rows.err()
    }
}

impl Transaction for SqliteTransaction<'_> {
    fn pending(&mut self) -> Result<Vec<(Trial, Claim)>> {
        let mut stmt = self
            .tx()
            .prepare(&format!(
                "SELECT {TRIAL_COLUMNS}, owner, lease_until_unix_s FROM trials WHERE reward IS NULL ORDER BY id"
            ))
            .map_err(self.err())?;
        let rows = stmt
            .query_map([], |r| {
                let t = row_to_trial(r)?;
                let c = Claim {
                    trial: t.id,
                    owner: r.get(6)?,
                    lease_until: r.get(7)?,
                };
                Ok((t, c))
            })
            .map_err(self.err())?;
        rows.collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.err())
    }

    fn told(&mut self) -> Result<usize> {
        self.rows.count(true)
    }

    fn told_rewards(&mut self) -> Result<Vec<f64>> {
        let mut stmt = self
            .tx()
            .prepare("SELECT reward FROM trials WHERE reward IS NOT NULL")
            .map_err(self.err())?;
        let rows = stmt.query_map([], |r| r.get(0)).map_err(self.err())?;
        rows.collect::<rusqlite::Result<Vec<_>>>()
            .map_err(self.err())
    }

    fn trial(&mut self, id: i64) -> Result<Option<Trial>> {
        self.tx()
            .query_row(
                &format!("SELECT {TRIAL_COLUMNS} FROM trials WHERE id = ?1"),
                params![id],
                row_to_trial,
            )
            .optional()
            .map_err(self.err())
    }

    fn optimizer_state(&mut self) -> Result<String> {
        optimizer_state(self.tx()).map_err(self.err())
    }

    fn add_trial(
        &mut self,
        weights: &str,
        asked_unix_s: f64,
        claim: Option<(&str, f64)>,
    ) -> Result<i64> {
        let (owner, until) = claim.unzip();
        self.tx()
            .execute(
                "INSERT INTO trials (weights, asked_unix_s, owner, lease_until_unix_s) VALUES (?1, ?2, ?3, ?4)",
                params![weights, asked_unix_s, owner, until],
            )
            .map_err(self.err())?;
        Ok(self.tx().last_insert_rowid())
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.rows.set_claim(id, owner, until)
    }

    fn record(&mut self, id: i64, told: &Told, optimizer_state: &str) -> Result<()> {
        self.tx()
            .execute(
                "UPDATE trials SET reward = ?1, lap_time_s = ?2, failure = ?3, x_fail = ?4, told_unix_s = ?5 WHERE id = ?6",
                params![
                    told.reward,
                    told.lap_time_s,
                    told.failure,
                    told.x_fail,
                    told.told_unix_s,
                    id
                ],
            )
            .map_err(self.err())?;
        self.tx()
            .execute(
                "UPDATE optimizer SET state = ?1 WHERE id = 1",
                params![optimizer_state],
            )
            .map_err(self.err())?;
        Ok(())
    }

    fn commit(self: Box<Self>) -> Result<()> {
        self.rows.commit()
    }
}

/// WAL journal, full synchronous commits, a busy timeout.
pub(crate) fn configure(conn: &Connection) -> rusqlite::Result<()> {
    conn.busy_timeout(BUSY_TIMEOUT)?;
    conn.pragma_update(None, "journal_mode", "WAL")?;
    conn.pragma_update(None, "synchronous", "FULL")?;
    Ok(())
}

/// Refuses a file that is not an SQLite database before SQLite touches it (opened read-write,
/// SQLite would write its header into an empty file).
pub(crate) fn check_header(path: &Path) -> Result<()> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16);
    std::fs::File::open(path)
        .and_then(|f| f.take(16).read_to_end(&mut head))
        .map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })?;
    if head.is_empty() {
        return Err(Error::NotAStudy {
            path: path.to_owned(),
            reason: "the file is empty".into(),
        });
    }
    if head != SQLITE_HEADER {
        return Err(Error::NotAStudy {
            path: path.to_owned(),
            reason: "the file is not an SQLite database".into(),
        });
    }
    Ok(())
}

pub(crate) fn user_version(conn: &Connection) -> rusqlite::Result<i64> {
    conn.pragma_query_value(None, "user_version", |r| r.get(0))
}

/// A read-only connection and the schema version. SQLite shares a WAL database through a
/// `-shm` file beside it; where that cannot be made (a read-only folder), the file is opened
/// as immutable, which is right while no writer has the study open.
pub(crate) fn read_only_connection(path: &Path) -> Result<(Connection, i64)> {
    let err = |e| sql_error(path, e);
    let shared =
        Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY).and_then(|c| {
            c.busy_timeout(BUSY_TIMEOUT)?;
            let v = user_version(&c)?;
            Ok((c, v))
        });
    if let Ok(opened) = shared {
        return Ok(opened);
    }
    let uri = format!("file:{}?immutable=1", uri_path(path));
    let conn = Connection::open_with_flags(
        uri,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_URI,
    )
    .map_err(err)?;
    let v = user_version(&conn).map_err(err)?;
    Ok((conn, v))
}

/// A path as the path of an SQLite `file:` URI.
fn uri_path(path: &Path) -> String {
    let text = path.to_string_lossy();
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '%' => out.push_str("%25"),
            '?' => out.push_str("%3f"),
            '#' => out.push_str("%23"),
            c => out.push(c),
        }
    }
    out
}

/// Schema 1 → 2: the claims' columns.
fn upgrade(conn: &Connection) -> rusqlite::Result<()> {
    conn.execute_batch(&format!(
        "BEGIN IMMEDIATE;
         ALTER TABLE trials ADD COLUMN owner TEXT;
         ALTER TABLE trials ADD COLUMN lease_until_unix_s REAL;
         PRAGMA user_version = {SCHEMA_VERSION};
         COMMIT;"
    ))
}

fn row_to_trial(r: &rusqlite::Row<'_>) -> rusqlite::Result<Trial> {
    let json: String = r.get(1)?;
    let weights: Vec<f64> = serde_json::from_str(&json).map_err(|e| {
        rusqlite::Error::FromSqlConversionFailure(1, rusqlite::types::Type::Text, Box::new(e))
    })?;
    Ok(Trial {
        id: r.get(0)?,
        weights,
        reward: r.get(2)?,
        lap_time_s: r.get(3)?,
        failure: r.get(4)?,
        x_fail: r.get(5)?,
    })
}

fn optimizer_state(conn: &Connection) -> rusqlite::Result<String> {
    conn.query_row("SELECT state FROM optimizer WHERE id = 1", [], |r| r.get(0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::tests::{config, temp};
    use crate::study::{Location, Study};

    #[test]
    fn foreign_and_newer_files_are_refused() {
        let path = temp("foreign");
        std::fs::write(&path, "x,a\n0,1\n").unwrap();
        let e = Study::open(&path).err().unwrap().to_string();
        assert!(e.contains("not an SQLite database"), "{e}");
        let path = temp("newer");
        drop(Study::create(&path, config()).unwrap());
        let conn = Connection::open(&path).unwrap();
        conn.pragma_update(None, "user_version", 99).unwrap();
        drop(conn);
        let e = Study::open(&path).err().unwrap().to_string();
        assert!(e.contains("newer cdbo"), "{e}");
        let e = Study::open(&path.with_extension("missing"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("no such study"), "{e}");
        let e = Study::open_at(&Location::Sqlite(path.with_extension("missing")))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("no such study"), "{e}");
    }
}
