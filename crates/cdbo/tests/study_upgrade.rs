//! A study of schema 1 (written before the claims) is read as it is and upgraded to schema 2
//! when opened to ask and tell, keeping every trial bit for bit; a read-only open writes
//! nothing.

use std::path::{Path, PathBuf};

use cdbo::study::{Outcome, SCHEMA_VERSION, Study, StudyConfig};
use rusqlite::Connection;
use rusqlite::types::Value;

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-upgrade-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn config() -> StudyConfig {
    StudyConfig {
        method: cdbo::method::Method::Cdbo,
        kernels: 4,
        lengthscale: 1.0 / 3.0,
        seed: 7,
        beta: 1.0,
        w0: vec![0.1, -0.2, 0.3, 0.05],
        track: None,
        track_length: None,
        knob: None,
        max_failed_laps: None,
        box_radius: None,
        warm_start: None,
        line_kernels: None,
        base_line: Default::default(),
        steering: Default::default(),
    }
}

/// Every column of every row, exactly: reals as their bits.
fn rows(path: &Path, table: &str) -> Vec<Vec<String>> {
    let conn = Connection::open(path).unwrap();
    let mut stmt = conn
        .prepare(&format!("SELECT * FROM {table} ORDER BY 1"))
        .unwrap();
    let n = stmt.column_count();
    stmt.query_map([], |r| {
        (0..n)
            .map(|i| {
                Ok(match r.get::<_, Value>(i)? {
                    Value::Real(x) => format!("real {:016x}", x.to_bits()),
                    other => format!("{other:?}"),
                })
            })
            .collect()
    })
    .unwrap()
    .collect::<rusqlite::Result<_>>()
    .unwrap()
}

fn user_version(path: &Path) -> i64 {
    Connection::open(path)
        .unwrap()
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .unwrap()
}

/// A study with four told trials (a lap, a failed lap with its place, a bare reward) and one
/// pending, written by today's code.
fn reference(dir: &Path) -> PathBuf {
    let path = dir.join("reference.db");
    let mut s = Study::create(&path, config()).unwrap();
    let outcomes = [
        Outcome::Lap {
            time_s: 61.37,
            length_m: 1234.5,
        },
        Outcome::Failed {
            at: Some(0.4321),
            reason: Some("off_track".into()),
        },
        Outcome::Reward(19.999_999_999_999_996),
        Outcome::Failed {
            at: None,
            reason: None,
        },
    ];
    for outcome in &outcomes {
        let t = s.ask().unwrap();
        s.tell(t.id, outcome).unwrap();
    }
    s.ask().unwrap();
    path
}

/// The same study as the version-1 code wrote it: its schema (no claim columns), WAL, and
/// `user_version` 1, with the reference's rows copied value for value.
fn as_version_1(reference: &Path, path: &Path) {
    let mut conn = Connection::open(path).unwrap();
    conn.pragma_update(None, "journal_mode", "WAL").unwrap();
    conn.pragma_update(None, "synchronous", "FULL").unwrap();
    let tx = conn.transaction().unwrap();
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
             told_unix_s REAL);
         CREATE TABLE optimizer (id INTEGER PRIMARY KEY CHECK (id = 1), state TEXT NOT NULL);",
    )
    .unwrap();
    tx.execute("ATTACH DATABASE ?1 AS v2", [reference.to_str().unwrap()])
        .unwrap();
    tx.execute_batch(
        "INSERT INTO meta SELECT * FROM v2.meta;
         INSERT INTO trials SELECT id, weights, reward, lap_time_s, failure, x_fail,
             asked_unix_s, told_unix_s FROM v2.trials;
         INSERT INTO optimizer SELECT * FROM v2.optimizer;",
    )
    .unwrap();
    tx.pragma_update(None, "user_version", 1).unwrap();
    tx.commit().unwrap();
    conn.execute("DETACH DATABASE v2", []).unwrap();
    conn.close().unwrap();
}

#[test]
fn a_version_1_study_is_read_as_it_is_and_upgraded_bit_for_bit() {
    assert_eq!(SCHEMA_VERSION, 2);
    let dir = scratch("v1");
    let reference = reference(&dir);
    let v1 = dir.join("v1.db");
    as_version_1(&reference, &v1);
    assert_eq!(user_version(&v1), 1);
    let v1_trials = rows(&v1, "trials");
    assert_eq!(v1_trials.len(), 5);
    assert_eq!(
        v1_trials[0].len(),
        8,
        "the version-1 schema has no claim columns"
    );

    // Read-only: the same trials as the reference, and not a byte of the file written.
    let before = std::fs::read(&v1).unwrap();
    let mut perms = std::fs::metadata(&v1).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&v1, perms.clone()).unwrap();
    {
        let s = Study::open_read_only(&v1).unwrap();
        assert_eq!(s.config(), &config());
        let expected = Study::open_read_only(&reference)
            .unwrap()
            .history()
            .unwrap();
        let history = s.history().unwrap();
        assert_eq!(history, expected);
        for (a, b) in history.iter().zip(&expected) {
            let bits = |t: &cdbo::study::Trial| -> Vec<u64> {
                t.weights.iter().map(|w| w.to_bits()).collect()
            };
            assert_eq!(bits(a), bits(b));
            assert_eq!(a.reward.map(f64::to_bits), b.reward.map(f64::to_bits));
        }
        assert_eq!(s.told().unwrap(), 4);
        assert_eq!(
            s.best().unwrap(),
            Study::open_read_only(&reference).unwrap().best().unwrap()
        );
    }
    assert_eq!(
        std::fs::read(&v1).unwrap(),
        before,
        "a read-only open wrote the file"
    );
    assert_eq!(user_version(&v1), 1);
    #[allow(clippy::permissions_set_readonly_false)]
    perms.set_readonly(false);
    std::fs::set_permissions(&v1, perms).unwrap();

    // Opened to ask and tell: upgraded, every version-1 column of every row kept exactly, the
    // claim columns empty, and the study goes on exactly as the reference does.
    let mut upgraded = Study::open(&v1).unwrap();
    assert_eq!(user_version(&v1), SCHEMA_VERSION);
    let after = rows(&v1, "trials");
    for (old, new) in v1_trials.iter().zip(&after) {
        assert_eq!(new[..8], old[..], "a version-1 column changed");
        assert_eq!(new[8..], ["Null", "Null"]);
    }
    assert_eq!(rows(&v1, "meta"), rows(&reference, "meta"));
    assert_eq!(rows(&v1, "optimizer"), rows(&reference, "optimizer"));
    let mut same = Study::open(&reference).unwrap();
    for reward in [21.5, 18.25] {
        let (a, b) = (upgraded.ask().unwrap(), same.ask().unwrap());
        assert_eq!(a, b);
        upgraded.tell(a.id, &Outcome::Reward(reward)).unwrap();
        same.tell(b.id, &Outcome::Reward(reward)).unwrap();
    }
    assert_eq!(upgraded.ask().unwrap(), same.ask().unwrap());
    drop(upgraded);
    // Opened again: nothing more to upgrade.
    assert_eq!(Study::open(&v1).unwrap().history().unwrap().len(), 7);
    let _ = std::fs::remove_dir_all(&dir);
}
