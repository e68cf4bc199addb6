//! The SQLite back end: one study or grid per file (WAL journal, synchronous commits), so that
//! what is written is on disk before the call returns. Writers take SQLite's write lock for
//! the whole transaction (`BEGIN IMMEDIATE`); another process waits up to [`BUSY_TIMEOUT`],
//! then gets a clear "busy" error. The schema version is SQLite's `user_version`.

use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use rusqlite::{Connection, OpenFlags, TransactionBehavior, params};

use super::claim::Claim;
use super::{BUSY_TIMEOUT, Kind, Rows, RowsTransaction, SCHEMA_VERSION, Table, check_version};
use crate::error::{Error, Result};

/// The first 16 bytes of every SQLite database file.
const SQLITE_HEADER: &[u8; 16] = b"SQLite format 3\0";

/// The claimed rows of kind `K` in an SQLite file, and the connection to it.
pub(crate) struct SqliteRows<K> {
    path: PathBuf,
    conn: Connection,
    kind: PhantomData<K>,
}

impl<K: Kind> SqliteRows<K> {
    /// Opens the file at `path`, refusing one that is not SQLite or of a newer schema, then
    /// lets `read` check what it holds (given the schema version) before anything is written.
    /// Writable, the file is brought to [`SCHEMA_VERSION`] ([`Table::sqlite_upgrade`]), and a
    /// missing or empty file is made where the kind is made on open
    /// ([`super::Parent::made_on_open`]). Read-only, nothing is written, and a file or folder
    /// that is read-only works (then as an immutable file, if SQLite cannot share it).
    pub(crate) fn open<T>(
        path: &Path,
        writable: bool,
        read: impl FnOnce(&Connection, i64) -> Result<T>,
    ) -> Result<(SqliteRows<K>, T)> {
        let table = &K::TABLE;
        let parent = table.parent;
        let make = writable && parent.made_on_open();
        let absent = if parent.made_on_open() {
            std::fs::metadata(path).map_or(true, |m| m.len() == 0)
        } else {
            !path.is_file()
        };
        if !absent {
            check_header(path, table)?;
        } else if !make {
            return Err(parent.missing(path.to_owned()));
        }
        let err = |e| sql_error::<K>(path, e);
        let conn = if writable {
            let create = if make {
                OpenFlags::SQLITE_OPEN_CREATE
            } else {
                OpenFlags::empty()
            };
            Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE | create)
                .map_err(err)?
        } else {
            read_only_connection::<K>(path)?
        };
        conn.busy_timeout(BUSY_TIMEOUT).map_err(err)?;
        let version = user_version(&conn).map_err(err)?;
        check_version(path, version, parent)?;
        // Read before anything is written: a foreign database is left as it was.
        let read = read(&conn, version)?;
        if writable {
            configure(&conn).map_err(err)?;
            if version < SCHEMA_VERSION {
                conn.execute_batch(&format!(
                    "BEGIN IMMEDIATE; {} PRAGMA user_version = {SCHEMA_VERSION}; COMMIT;",
                    table.sqlite_upgrade
                ))
                .map_err(err)?;
            }
        }
        let rows = SqliteRows {
            path: path.to_owned(),
            conn,
            kind: PhantomData,
        };
        Ok((rows, read))
    }

    /// Creates the file at `path` holding what `fill` writes, at [`SCHEMA_VERSION`]; refuses to
    /// overwrite one. The file is built under a temporary name and linked into place once
    /// complete, so that a create killed half-way leaves nothing half-made behind.
    pub(crate) fn create(
        path: &Path,
        fill: impl FnOnce(&rusqlite::Transaction<'_>) -> Result<()>,
    ) -> Result<()> {
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
        let err = |e| sql_error::<K>(path, e);
        let mut conn = Connection::open(&building).map_err(err)?;
        configure(&conn).map_err(err)?;
        let tx = conn.transaction().map_err(err)?;
        fill(&tx)?;
        tx.pragma_update(None, "user_version", SCHEMA_VERSION)
            .map_err(err)?;
        tx.commit().map_err(err)?;
        // Closing the only connection checkpoints the WAL into the file.
        conn.close().map_err(|(_, e)| err(e))?;
        // A hard link never replaces a file another process created meanwhile.
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

    /// The connection, to read without the write lock.
    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }

    /// An SQLite error as this file's [`Error`].
    pub(crate) fn err(&self) -> impl Fn(rusqlite::Error) -> Error + '_ {
        |e| sql_error::<K>(&self.path, e)
    }

    /// Starts a transaction holding the file's write lock until it commits or is dropped.
    pub(crate) fn begin(&mut self) -> Result<SqliteTransaction<'_, K>> {
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| sql_error::<K>(&self.path, e))?;
        Ok(SqliteTransaction {
            path: &self.path,
            tx,
            kind: PhantomData,
        })
    }
}

impl<K: Kind> Rows for SqliteRows<K> {
    fn label(&self) -> &Path {
        &self.path
    }

    fn heartbeat(&mut self, id: i64, owner: &str, until: f64) -> Result<bool> {
        let sql = format!(
            "UPDATE {} SET lease_until_unix_s = ?1 WHERE id = ?2 AND owner = ?3 AND {}",
            K::TABLE.sqlite,
            rows_of::<K>(false),
        );
        let n = self
            .conn
            .execute(&sql, params![until, id, owner])
            .map_err(self.err())?;
        Ok(n == 1)
    }

    fn count(&mut self, done: bool) -> Result<usize> {
        count::<K>(&self.conn, done).map_err(self.err())
    }
}

/// A write transaction on the claimed rows of kind `K`, under the file's write lock.
pub(crate) struct SqliteTransaction<'a, K> {
    path: &'a Path,
    tx: rusqlite::Transaction<'a>,
    kind: PhantomData<K>,
}

impl<'a, K: Kind> SqliteTransaction<'a, K> {
    /// The transaction, for what the kind stores beside the claims.
    pub(crate) fn tx(&self) -> &rusqlite::Transaction<'a> {
        &self.tx
    }

    /// An SQLite error as this file's [`Error`].
    pub(crate) fn err(&self) -> impl Fn(rusqlite::Error) -> Error + 'a {
        let path = self.path;
        move |e| sql_error::<K>(path, e)
    }
}

impl<K: Kind> RowsTransaction for SqliteTransaction<'_, K> {
    fn count(&mut self, done: bool) -> Result<usize> {
        count::<K>(&self.tx, done).map_err(self.err())
    }

    fn claims(&mut self) -> Result<Vec<Claim>> {
        let sql = format!(
            "SELECT id, owner, lease_until_unix_s FROM {} WHERE {} ORDER BY id",
            K::TABLE.sqlite,
            rows_of::<K>(false),
        );
        let err = self.err();
        let mut stmt = self.tx.prepare(&sql).map_err(&err)?;
        let rows = stmt
            .query_map([], |r| {
                Ok(Claim {
                    trial: r.get(0)?,
                    owner: r.get(1)?,
                    lease_until: r.get(2)?,
                })
            })
            .map_err(&err)?;
        rows.collect::<rusqlite::Result<Vec<_>>>().map_err(err)
    }

    fn set_claim(&mut self, id: i64, owner: &str, until: f64) -> Result<()> {
        self.tx
            .execute(
                &format!(
                    "UPDATE {} SET owner = ?1, lease_until_unix_s = ?2 WHERE id = ?3",
                    K::TABLE.sqlite
                ),
                params![owner, until, id],
            )
            .map_err(self.err())?;
        Ok(())
    }

    fn commit(self: Box<Self>) -> Result<()> {
        let err = self.err();
        self.tx.commit().map_err(err)
    }
}

/// Sorts an SQLite error by its code: busy or locked, not a database, or another failure.
pub(crate) fn sql_error<K: Kind>(path: &Path, source: rusqlite::Error) -> Error {
    use rusqlite::ErrorCode;
    let path = path.to_owned();
    match source.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy | ErrorCode::DatabaseLocked) => Error::Busy { path },
        Some(ErrorCode::NotADatabase) => K::TABLE
            .parent
            .foreign(path, "the file is not an SQLite database".into()),
        _ => Error::Sql { path, source },
    }
}

/// Number of rows done (or, `done` false, not done yet).
fn count<K: Kind>(conn: &Connection, done: bool) -> rusqlite::Result<usize> {
    let sql = format!(
        "SELECT COUNT(*) FROM {} WHERE {}",
        K::TABLE.sqlite,
        rows_of::<K>(done)
    );
    conn.query_row(&sql, [], |r| r.get::<_, i64>(0))
        .map(|n| n as usize)
}

/// The condition that picks the rows done (or, `done` false, not done yet).
fn rows_of<K: Kind>(done: bool) -> String {
    let is = if done { "IS NOT NULL" } else { "IS NULL" };
    format!("{} {is}", K::TABLE.done)
}

/// WAL journal, full synchronous commits, a busy timeout.
fn configure(conn: &Connection) -> rusqlite::Result<()> {
    conn.busy_timeout(BUSY_TIMEOUT)?;
    conn.pragma_update(None, "journal_mode", "WAL")?;
    conn.pragma_update(None, "synchronous", "FULL")?;
    Ok(())
}

/// Refuses a file that is not an SQLite database before SQLite touches it (opened read-write,
/// SQLite would write its header into an empty file).
fn check_header(path: &Path, table: &Table) -> Result<()> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16);
    std::fs::File::open(path)
        .and_then(|f| f.take(16).read_to_end(&mut head))
        .map_err(|e| Error::Io {
            path: path.to_owned(),
            source: e,
        })?;
    if head.is_empty() {
        return Err(table
            .parent
            .foreign(path.to_owned(), "the file is empty".into()));
    }
    if head != SQLITE_HEADER {
        return Err(table
            .parent
            .foreign(path.to_owned(), "the file is not an SQLite database".into()));
    }
    Ok(())
}

/// The file's schema version (SQLite's `user_version`).
pub(crate) fn user_version(conn: &Connection) -> rusqlite::Result<i64> {
    conn.pragma_query_value(None, "user_version", |r| r.get(0))
}

/// A read-only connection. SQLite shares a WAL database through a `-shm` file beside it;
/// where that cannot be made (a read-only folder), the file is opened as immutable, which is
/// right while no writer has it open.
fn read_only_connection<K: Kind>(path: &Path) -> Result<Connection> {
    let shared =
        Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY).and_then(|c| {
            c.busy_timeout(BUSY_TIMEOUT)?;
            user_version(&c)?;
            Ok(c)
        });
    if let Ok(conn) = shared {
        return Ok(conn);
    }
    let uri = format!("file:{}?immutable=1", uri_path(path));
    Connection::open_with_flags(
        uri,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_URI,
    )
    .map_err(|e| sql_error::<K>(path, e))
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
