//! Studies and grids in a real PostgreSQL server (Debian's `postgresql`): each test starts its
//! own server (`initdb` + `pg_ctl` into a folder of its own under the target folder, as
//! `nobody` when run as root, password authentication, a free port on 127.0.0.1) and stops it
//! when the test ends, passes or panics (a drop guard); a server left running by a test run
//! that was killed is stopped by the next run of that test. Where PostgreSQL is not installed,
//! the tests say so and pass: `.ci/run` installs it when `CI` is set.

use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

mod common;

use common::{
    CDBO, create_study, driven, every_trial_told_once_and_distinct, fresh_dir, fresh_dir_with_demo,
    history, kill_first_and_reap, ok, optimize, refused, rewards_table, spawn, wait_until,
};

/// The password of the test server's superuser `cdbo`.
const PASSWORD: &str = "lap-secret";

/// A PostgreSQL server of its own, stopped and removed on drop (also when the test panics).
struct Server {
    bin: PathBuf,
    dir: PathBuf,
    port: u16,
    /// Whether it runs as `nobody` (we are root).
    as_nobody: bool,
}

/// The folder holding `initdb` and `pg_ctl`: on PATH, or Debian's newest version.
fn postgres_bin() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .find(|p| p.join("initdb").is_file() && p.join("pg_ctl").is_file())
    });
    on_path.or_else(|| {
        let mut versions: Vec<PathBuf> = std::fs::read_dir("/usr/lib/postgresql")
            .ok()?
            .flatten()
            .map(|e| e.path().join("bin"))
            .filter(|b| b.join("initdb").is_file())
            .collect();
        versions.sort();
        versions.pop()
    })
}

impl Server {
    /// Starts a server, or `None` (with a message) where PostgreSQL is not installed.
    fn start(name: &str) -> Option<Server> {
        let Some(bin) = postgres_bin() else {
            eprintln!(
                "skipped: PostgreSQL is not installed (apt-get install postgresql; initdb and pg_ctl not found)"
            );
            return None;
        };
        // A fixed folder per test: a server that a killed run of this test left running is
        // found there and stopped before the folder is made afresh.
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pg-{name}"));
        let as_nobody = unsafe { libc::geteuid() } == 0;
        let stale = Server {
            bin: bin.clone(),
            dir: dir.clone(),
            port: 0,
            as_nobody,
        };
        if dir.join("data").join("postmaster.pid").exists() {
            eprintln!("stopping the server a killed run left in {}", dir.display());
        }
        drop(stale);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("pw"), PASSWORD).unwrap();
        if as_nobody {
            let ok = Command::new("chown")
                .args(["-R", "nobody", dir.to_str().unwrap()])
                .status()
                .unwrap()
                .success();
            assert!(ok, "chown {}", dir.display());
        }
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let server = Server {
            bin,
            dir,
            port,
            as_nobody,
        };
        let data = server.dir.join("data");
        server.run(
            "initdb",
            &[
                "-D",
                data.to_str().unwrap(),
                "-U",
                "cdbo",
                "-A",
                "scram-sha-256",
                &format!("--pwfile={}", server.dir.join("pw").display()),
                "--no-sync",
                "-E",
                "UTF8",
                "--locale=C",
            ],
        );
        let options = format!(
            "-k {} -p {port} -c listen_addresses=127.0.0.1 -c fsync=off",
            server.dir.display()
        );
        server.run(
            "pg_ctl",
            &[
                "-D",
                data.to_str().unwrap(),
                "-l",
                server.dir.join("log").to_str().unwrap(),
                "-w",
                "-o",
                &options,
                "start",
            ],
        );
        Some(server)
    }

    fn command(&self, program: &str) -> Command {
        let program = self.bin.join(program);
        if self.as_nobody {
            let mut c = Command::new("runuser");
            c.args(["-u", "nobody", "--"]).arg(program);
            c
        } else {
            Command::new(program)
        }
    }

    fn run(&self, program: &str, args: &[&str]) {
        let out = self
            .command(program)
            .args(args)
            .current_dir(&self.dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{program} {args:?}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }

    /// The URL of database `postgres` as user `cdbo` with `password`.
    fn url_with(&self, password: &str) -> String {
        format!(
            "postgresql://cdbo:{password}@127.0.0.1:{}/postgres",
            self.port
        )
    }

    fn url(&self) -> String {
        self.url_with(PASSWORD)
    }

    fn client(&self) -> postgres::Client {
        postgres::Client::connect(&self.url(), postgres::NoTls).unwrap()
    }
}

impl Drop for Server {
    /// Stops the server (if one runs in its folder) and removes the folder.
    fn drop(&mut self) {
        let data = self.dir.join("data");
        if !data.join("postmaster.pid").exists() {
            let _ = std::fs::remove_dir_all(&self.dir);
            return;
        }
        let _ = self
            .command("pg_ctl")
            .args([
                "-D",
                data.to_str().unwrap(),
                "-m",
                "immediate",
                "-w",
                "stop",
            ])
            .current_dir(&self.dir)
            .output();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A worker of `method` (seed 3) on `storage` to `laps` told trials ([`optimize`]).
fn worker(storage: &str, laps: usize, method: &str) -> Command {
    let mut c = optimize(storage, laps, 0.0);
    c.args(["--seed", "3", "--method", method]);
    c
}

/// Three workers of `method` on one PostgreSQL study, started at once before it exists; one
/// is killed with SIGKILL half-way. Every trial is told once with weights of its own, and the
/// laps driven are the trials told plus at most the killed worker's lap in flight (and one
/// per worker whose lease ran out while it drove).
fn three_workers(trials: usize, method: &str) {
    let Some(server) = Server::start(&format!("workers{trials}")) else {
        return;
    };
    let dir = fresh_dir_with_demo(&format!("workers{trials}"));
    let storage = format!("{}#workers", server.url());
    let start = Instant::now();
    let workers: Vec<Child> = (0..3)
        .map(|_| spawn(worker(&storage, trials, method), &dir))
        .collect();
    wait_until("half the laps driven", Duration::from_secs(600), || {
        driven(&dir) >= trials / 2
    });
    kill_first_and_reap(workers);
    let h = history(&dir, "workers", &server.url());
    every_trial_told_once_and_distinct(&h, trials);
    let laps = driven(&dir);
    eprintln!(
        "3 {method} workers, one killed at {}: {laps} laps driven, {} trials told, {:.1} s",
        trials / 2,
        h.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(
        (trials..=trials + 3).contains(&laps),
        "{laps} laps driven for {trials} trials"
    );
}

#[test]
#[ignore = "slow: three GP workers on PostgreSQL, one killed (tests/reliability.rs kills one on SQLite by default)"]
fn three_workers_one_killed_tell_each_trial_once() {
    three_workers(24, "cdbo");
}

/// The full-size run: 300 laps, of random search so that the laps (a process each) and the
/// database, not the GP, take the time.
#[test]
#[ignore = "slow: 300 laps of three workers (run by .ci/run)"]
fn three_workers_one_killed_300_laps() {
    three_workers(300, "random");
}

/// One worker on SQLite and one on PostgreSQL, the same seed: the same trials bit for bit
/// (the best reward with them); and `study copy` both ways gives the same exports.
#[test]
#[ignore = "slow: the same race on SQLite and PostgreSQL, then study copy both ways"]
fn sqlite_and_postgres_agree_bit_for_bit() {
    let Some(server) = Server::start("same") else {
        return;
    };
    let dir = fresh_dir_with_demo("same");
    let pg = format!("{}#same", server.url());
    let laps = 12;
    for storage in ["a.db", pg.as_str()] {
        let out = worker(storage, laps, "cdbo")
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{storage}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (a, b) = (
        history(&dir, "a", "a.db"),
        history(&dir, "same", &server.url()),
    );
    assert_eq!(a.len(), laps);
    assert_eq!(a, b);
    let best = |h: &[serde_json::Value]| {
        h.iter()
            .map(|t| t["reward"].as_f64().unwrap())
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert_eq!(best(&a).to_bits(), best(&b).to_bits());

    // SQLite → PostgreSQL → SQLite: every export the same, byte for byte.
    ok(
        &dir,
        &["study", "copy", "a.db", &format!("{}#copied", server.url())],
    );
    ok(
        &dir,
        &[
            "study",
            "copy",
            &format!("{}#copied", server.url()),
            "back.db",
        ],
    );
    refused(
        &dir,
        &["study", "copy", "a.db", &format!("{}#copied", server.url())],
        &["already exists"],
    );
    for (name, storage, out) in [
        ("a", "a.db".to_owned(), "ex-a"),
        ("copied", server.url(), "ex-pg"),
        ("back", "back.db".to_owned(), "ex-back"),
    ] {
        ok(
            &dir,
            &["study", "export", name, "--storage", &storage, "--out", out],
        );
    }
    for file in [
        "history.csv",
        "history.json",
        "best_policy.json",
        "best_policy.csv",
    ] {
        let a = std::fs::read(dir.join("ex-a").join(file)).unwrap();
        assert_eq!(
            a,
            std::fs::read(dir.join("ex-pg").join(file)).unwrap(),
            "{file}"
        );
        assert_eq!(
            a,
            std::fs::read(dir.join("ex-back").join(file)).unwrap(),
            "{file}"
        );
    }
    // The copy goes on as the original would: one more lap each, the same trial.
    for storage in ["a.db".to_owned(), format!("{}#copied", server.url())] {
        let out = worker(&storage, laps + 1, "cdbo")
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    assert_eq!(
        history(&dir, "a", "a.db"),
        history(&dir, "copied", &server.url())
    );
}

/// Asking and telling by hand: a tell of a trial already told is refused as a conflict.
#[test]
fn a_trial_told_twice_is_refused() {
    let Some(server) = Server::start("twice") else {
        return;
    };
    let dir = fresh_dir_with_demo("twice");
    let url = server.url();
    let study = ["--storage", url.as_str()];
    ok(&dir, &create_study("hand", &study));
    let asked: serde_json::Value =
        serde_json::from_str(&ok(&dir, &[&["study", "ask", "hand"][..], &study].concat())).unwrap();
    let trial = asked["trial"].to_string();
    let tell = [
        &[
            "study", "tell", "hand", "--trial", &trial, "--reward", "12.5",
        ][..],
        &study,
    ]
    .concat();
    ok(&dir, &tell);
    refused(
        &dir,
        &tell,
        &["trial 1 was already told (reward 12.5)", "#hand"],
    );
    let status = ok(
        &dir,
        &[&["study", "status", "hand", "--json"][..], &study].concat(),
    );
    let status: serde_json::Value = serde_json::from_str(&status).unwrap();
    assert_eq!(status["told"], 1);
    assert_eq!(status["best_reward"], 12.5);
}

/// Bad input — an unreachable database, wrong credentials, a schema from a newer version, an
/// unknown scheme, a study or grid that does not exist — is one clear line each, for studies,
/// grid workers and reports, and nothing is written.
#[test]
fn bad_databases_are_one_line_and_write_nothing() {
    let Some(server) = Server::start("bad") else {
        return;
    };
    let dir = fresh_dir_with_demo("bad");
    let create = |storage: &str| -> Vec<String> {
        create_study("s", &["--storage", storage])
            .into_iter()
            .map(String::from)
            .collect()
    };
    let run = |args: Vec<String>, needles: &[&str]| refused(&dir, &args, needles);
    // Nothing listens on a port just freed.
    let closed = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let unreachable = format!("postgresql://cdbo:{PASSWORD}@127.0.0.1:{closed}/postgres");
    run(
        create(&unreachable),
        &["error connecting to server", "#s", "cdbo:***@"],
    );
    run(
        create(&server.url_with("wrong")),
        &[
            "password authentication failed for user \"cdbo\"",
            "cdbo:***@",
        ],
    );
    run(
        create("mysql://cdbo@127.0.0.1/db"),
        &["mysql://", "postgresql://"],
    );
    // The same for a grid's workers and its report.
    let worker = |storage: &str| -> Vec<String> {
        ["experiment", "quick", "--storage", storage, "--worker"]
            .map(String::from)
            .to_vec()
    };
    let report = |storage: &str| -> Vec<String> {
        ["report", "--storage", storage].map(String::from).to_vec()
    };
    run(
        worker(&unreachable),
        &["error connecting to server", "#quick", "cdbo:***@"],
    );
    run(
        report(&format!("{unreachable}#quick")),
        &["error connecting to server", "#quick", "cdbo:***@"],
    );
    run(
        worker(&server.url_with("wrong")),
        &["password authentication failed", "cdbo:***@"],
    );
    run(
        worker("mysql://cdbo@127.0.0.1/db"),
        &["mysql://", "postgresql://"],
    );
    run(report(&server.url()), &["study or grid name", "#NAME"]);
    assert!(
        !dir.join("runs").exists(),
        "a refused report wrote its folder"
    );
    // A database without any study: reading is "no such study", and creates no table.
    run(
        ["study", "status", "s", "--storage", &server.url()]
            .map(String::from)
            .to_vec(),
        &["no such study"],
    );
    run(
        report(&format!("{}#quick", server.url())),
        &["no such grid", "#quick"],
    );
    let mut client = server.client();
    let tables = |client: &mut postgres::Client| -> i64 {
        client
            .query_one(
                "SELECT COUNT(*) FROM information_schema.tables WHERE table_name LIKE 'cdbo_%'",
                &[],
            )
            .unwrap()
            .get(0)
    };
    assert_eq!(tables(&mut client), 0);
    // A newer cdbo's schema: refused, the database left as it was.
    ok(&dir, &create(&server.url()));
    client
        .execute(
            "UPDATE cdbo_meta SET value = '99' WHERE key = 'schema_version'",
            &[],
        )
        .unwrap();
    let dump = |client: &mut postgres::Client| -> String {
        let rows = client
            .query(
                "SELECT name, config, optimizer_state FROM cdbo_studies ORDER BY name",
                &[],
            )
            .unwrap();
        let trials: i64 = client
            .query_one(
                "SELECT (SELECT COUNT(*) FROM cdbo_trials) + (SELECT COUNT(*) FROM cdbo_grids)",
                &[],
            )
            .unwrap()
            .get(0);
        format!(
            "{:?} {trials}",
            rows.iter()
                .map(|r| (
                    r.get::<_, String>(0),
                    r.get::<_, String>(1),
                    r.get::<_, String>(2)
                ))
                .collect::<Vec<_>>()
        )
    };
    let before = dump(&mut client);
    for args in [
        ["study", "ask", "s", "--storage", &server.url()]
            .map(String::from)
            .to_vec(),
        ["study", "status", "s", "--storage", &server.url()]
            .map(String::from)
            .to_vec(),
        create(&format!("{}#other", server.url())),
        worker(&server.url()),
        report(&format!("{}#quick", server.url())),
    ] {
        run(args, &["newer cdbo (study schema 99, this version reads"]);
    }
    assert_eq!(dump(&mut client), before);
}

/// Two workers fill the quick grid in PostgreSQL, one killed with SIGKILL while it runs a
/// cell: every cell is finished once (the killed worker's cell is run again by the other, at
/// once, its owner being a dead process of this host), a worker started on the finished grid
/// runs nothing, and the report from the database equals the report of the grid run on one
/// machine into a folder.
#[test]
#[ignore = "slow: the quick grid by two workers on PostgreSQL, one killed"]
fn two_workers_fill_the_quick_grid_one_killed() {
    let Some(server) = Server::start("grid") else {
        return;
    };
    let dir = fresh_dir("grid");
    ok(
        &dir,
        &["experiment", "quick", "--out", "one", "--jobs", "2"],
    );
    ok(&dir, &["report", "one", "--out", "report-one"]);
    let storage = format!("{}#quick", server.url());
    let worker = || {
        let mut c = Command::new(CDBO);
        c.args([
            "experiment",
            "quick",
            "--storage",
            &storage,
            "--worker",
            "--jobs",
            "1",
        ]);
        spawn(c, &dir)
    };
    let workers: Vec<Child> = (0..2).map(|_| worker()).collect();
    let victim = workers[0].id();
    let mut client = server.client();
    // Kill the first worker while it holds an unfinished cell, once a few cells are done.
    let start = Instant::now();
    loop {
        assert!(start.elapsed() < Duration::from_secs(300), "no cell held");
        let row = client
            .query_opt(
                "SELECT (SELECT COUNT(*) FROM cdbo_grid_runs WHERE record IS NOT NULL),
                        (SELECT COUNT(*) FROM cdbo_grid_runs WHERE record IS NULL AND split_part(owner, '/', 2) = $1)",
                &[&victim.to_string()],
            )
            .ok()
            .flatten();
        if let Some(row) = row
            && row.get::<_, i64>(0) >= 4
            && row.get::<_, i64>(1) == 1
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut workers = workers.into_iter();
    let mut killed = workers.next().unwrap();
    killed.kill().unwrap();
    let killed = killed.wait_with_output().unwrap();
    let survivor = workers.next().unwrap().wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&survivor.stderr);
    assert!(survivor.status.success(), "{err}");
    // Every cell run to the end once, by one worker or the other.
    let mut ran: Vec<String> = [&killed.stdout, &survivor.stdout]
        .iter()
        .flat_map(|out| {
            String::from_utf8_lossy(out)
                .lines()
                .filter_map(|l| l.strip_prefix("ran ")?.split(':').next().map(String::from))
                .collect::<Vec<_>>()
        })
        .collect();
    ran.sort();
    let mut cells: Vec<String> = client
        .query(
            "SELECT run FROM cdbo_grid_runs WHERE record IS NOT NULL",
            &[],
        )
        .unwrap()
        .iter()
        .map(|r| r.get(0))
        .collect();
    cells.sort();
    assert_eq!(cells.len(), 16);
    assert_eq!(ran, cells, "each cell run once");
    eprintln!(
        "2 workers, one killed mid-cell: {} + {} cells ran",
        String::from_utf8_lossy(&killed.stdout)
            .matches("\nran ")
            .count(),
        String::from_utf8_lossy(&survivor.stdout)
            .matches("\nran ")
            .count()
    );
    // The finished grid: a new worker runs nothing.
    let again = ok(
        &dir,
        &["experiment", "quick", "--storage", &storage, "--worker"],
    );
    assert!(
        again.contains("16 finished") && again.contains("0 runs done"),
        "{again}"
    );
    ok(
        &dir,
        &[
            "report",
            "--storage",
            &storage,
            "--out",
            "report-pg",
            "--export",
            "exported",
        ],
    );
    assert_eq!(
        rewards_table(&dir.join("report-pg")),
        rewards_table(&dir.join("report-one"))
    );
    // The exported folder reports the same as the database.
    ok(&dir, &["report", "exported", "--out", "report-exported"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("report-exported/results.md")).unwrap(),
        std::fs::read_to_string(dir.join("report-pg/results.md")).unwrap()
    );
}
