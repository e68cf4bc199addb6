//! The reliability suite: what docs/reliability.md promises, tried on the real binary — bad
//! input on every command, read-only and foreign study files, kill -9 of workers, several
//! workers on one study, cut run records. Each case gives one clear error line (exit 2) or the
//! documented behaviour, and never a panic (exit 101).

use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

mod common;

use common::{
    CDBO, cdbo, create_study, demo, driven, every_trial_told_once_and_distinct, fresh_dir,
    fresh_dir_with_demo, history, kill_first_and_reap, ok, optimize, optimize_args, refused, spawn,
    wait_until,
};

#[test]
fn every_size_has_a_bound_and_every_number_a_domain() {
    let dir = fresh_dir("flags");
    let big = "100000";
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["race", "--kernels", big],
            &["--kernels", big, "at most 1000"],
        ),
        (
            &["race", "--laps", "99999999"],
            &["--laps", "99999999", "at most 10000"],
        ),
        (&["race", "--laps", "0"], &["--laps", "at least 1"]),
        (
            &["race", "--demo-speed", "0"],
            &["--demo-speed", "'0'", "above 0"],
        ),
        (&["race", "--demo-speed=-3"], &["--demo-speed", "'-3'"]),
        (
            &["race", "--demo-speed", "NaN"],
            &["--demo-speed", "finite"],
        ),
        (&["race", "--beta", "inf"], &["--beta", "finite"]),
        (&["race", "--beta=-1"], &["--beta", "at least 0"]),
        (&["serve-sim", "--kernels", big], &["--kernels", big]),
        (
            &["serve-sim", "--kernels", "5", "--demo-speed=-3"],
            &["--demo-speed", "'-3'"],
        ),
        (
            &["policy", "table", "w.json", "--points", "2000000"],
            &["--points", "at most 1000000"],
        ),
        (
            &[
                "policy",
                "fit",
                "--demo",
                "d.csv",
                "--kernels",
                big,
                "-o",
                "w.json",
            ],
            &["--kernels", big],
        ),
        (
            &[
                "policy",
                "fit",
                "--demo",
                "d.csv",
                "--kernels",
                "5",
                "--ridge",
                "nan",
                "-o",
                "w.json",
            ],
            &["--ridge"],
        ),
        (
            &["study", "create", "s", "--kernels", big, "--demo", "d.csv"],
            &["--kernels", big],
        ),
        (
            &["study", "tell", "s", "--trial", "1", "--reward", "nan"],
            &["--reward", "finite"],
        ),
        (
            &[
                "study", "tell", "s", "--trial", "1", "--failed", "--at", "1.5",
            ],
            &["--at", "[0, 1]"],
        ),
        (
            &[
                "optimize",
                "--evaluator",
                "true",
                "--laps",
                "5",
                "--db",
                "s.db",
                "--kernels",
                big,
                "--demo",
                "d.csv",
            ],
            &["--kernels", big],
        ),
        (
            &[
                "optimize",
                "--evaluator",
                "true",
                "--laps",
                "5",
                "--db",
                "s.db",
                "--kernels",
                "5",
                "--timeout",
                "0",
            ],
            &["--timeout", "above 0"],
        ),
        (
            &["experiment", "quick", "--jobs", "0"],
            &["--jobs", "at least 1"],
        ),
        (
            &["experiment", "quick", "--jobs", big],
            &["--jobs", "at most 1024"],
        ),
        (&["bench", "optimizers", "--dims", big], &["--dims", big]),
        (
            &["bench", "suggest", "--observations", big],
            &["--observations", big],
        ),
        (&["bench", "sim", "--laps", "0"], &["--laps"]),
        (&["lap", "--throttle", "3"], &["--throttle", "[-1, 1]"]),
        (&["lap", "--demo", "0"], &["--demo", "above 0"]),
        (&["race", "--kernels"], &["--kernels"]),
    ];
    for (args, needles) in cases {
        refused(&dir, args, needles);
    }
    // The same bounds hold in an experiment's TOML, checked before any run starts.
    std::fs::write(
        dir.join("big.toml"),
        "laps = 5\nrepeats = 1\nmethods = [\"cdbo\"]\n[[tracks]]\ntrack = \"ridgeway\"\nkernels = [100000]\n",
    )
    .unwrap();
    refused(
        &dir,
        &["experiment", "big.toml", "--out", "big"],
        &["big.toml", "kernels 100000", "at most 1000"],
    );
    std::fs::write(
        dir.join("laps.toml"),
        "laps = 1000000\nrepeats = 1\nmethods = [\"cdbo\"]\n[[tracks]]\ntrack = \"ridgeway\"\nkernels = [10]\n",
    )
    .unwrap();
    // A legal but slow grid says so before its first run (here the unknown track then ends it).
    std::fs::write(
        dir.join("slow.toml"),
        "laps = 5000\nrepeats = 1\nmethods = [\"cdbo\"]\n[[tracks]]\ntrack = \"nowhere\"\nkernels = [10, 100]\n",
    )
    .unwrap();
    let out = cdbo(&dir, &["experiment", "slow.toml", "--out", "slow"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with(
            "warning: slow: each of its largest runs: 100 kernels and 5000 laps: expect about"
        ),
        "{err}"
    );
    refused(
        &dir,
        &["experiment", "laps.toml", "--out", "laps"],
        &["laps.toml", "laps 1000000", "at most 10000"],
    );
}

#[test]
fn a_legal_but_slow_race_says_so_first() {
    let dir = fresh_dir("slow");
    // 5000 laps would take hours: the warning comes before the first lap; --laps 0 would be
    // refused, so a bad --demo-speed ends the run at once after the warning.
    let out = cdbo(
        &dir,
        &[
            "race",
            "--laps",
            "5000",
            "--kernels",
            "100",
            "--demo-speed",
            "90",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let warning = err.lines().next().unwrap_or_default();
    assert!(
        warning.starts_with("warning: 100 kernels and 5000 laps: expect about")
            && warning.contains(" h "),
        "{err}"
    );
}

/// `optimize` and `study create` warn of a study whose optimiser will be slow, before anything
/// is read or written (here a missing demonstration then ends each, and no study is created).
#[test]
fn a_legal_but_slow_study_says_so_first() {
    let dir = fresh_dir("slow-study");
    let cases: [(&[&str], &str); 2] = [
        (
            &[
                "optimize",
                "--laps",
                "4000",
                "--kernels",
                "100",
                "--db",
                "s.db",
                "--demo",
                "gone.csv",
                "--evaluator",
                "echo 1",
            ],
            "warning: 100 kernels and 4000 laps: expect the optimiser to take about 1.5 h",
        ),
        (
            &[
                "study",
                "create",
                "s",
                "--db",
                "s.db",
                "--kernels",
                "100",
                "--method",
                "bo-cmaes",
                "--demo",
                "gone.csv",
            ],
            "warning: 100 kernels and 300 laps: expect the optimiser to take about 3 min",
        ),
    ];
    for (args, first) in cases {
        let out = cdbo(&dir, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        let mut lines = err.lines();
        assert!(
            lines.next().unwrap_or_default().starts_with(first),
            "{args:?}: {err}"
        );
        assert!(
            lines.next().unwrap_or_default().contains("gone.csv"),
            "{err}"
        );
        assert!(!dir.join("s.db").exists());
    }
    // The paper's sizes say nothing, nor do methods without a GP at the largest sizes.
    let mut quiet = vec![vec!["study", "create", "s", "--kernels", "30"]];
    for method in ["random", "pattern-search"] {
        quiet.push(vec![
            "optimize",
            "--kernels",
            "1000",
            "--laps",
            "10000",
            "--method",
            method,
        ]);
    }
    for args in quiet {
        let more = [
            "--db",
            "s.db",
            "--demo",
            "gone.csv",
            "--evaluator",
            "echo 1",
        ];
        let more = if args[0] == "study" {
            &more[..4]
        } else {
            &more[..]
        };
        let out = cdbo(&dir, &[&args[..], more].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("warning"), "{args:?}: {err}");
        assert!(err.contains("gone.csv"), "{args:?}: {err}");
    }
}

/// Three workers started at once on a study that does not exist yet all join it; one is
/// killed (SIGKILL) mid-way; the others finish. Every trial is told once, with distinct
/// weights, and at most trials + 3 laps are driven in all.
#[test]
fn three_workers_one_killed_drive_each_trial_once() {
    let dir = fresh_dir_with_demo("workers");
    let trials = 24;
    let workers: Vec<Child> = (0..3)
        .map(|_| spawn(optimize("w.db", trials, 0.1), &dir))
        .collect();
    // Kill the first once a few trials are told.
    wait_until("6 laps driven", Duration::from_secs(60), || {
        driven(&dir) >= 6
    });
    kill_first_and_reap(workers);
    every_trial_told_once_and_distinct(&history(&dir, "s", "w.db"), trials);
    let laps = driven(&dir);
    assert!(
        (trials..=trials + 3).contains(&laps),
        "{laps} laps driven for {trials} trials"
    );
}

/// One worker alone gives the same trials as a run without claims: the sequence of a single
/// uninterrupted run, whatever the lease.
#[test]
fn a_single_worker_is_unchanged_by_claims() {
    let dir = fresh_dir_with_demo("single");
    let out = optimize("a.db", 8, 0.0).current_dir(&dir).output().unwrap();
    assert!(out.status.success());
    ok(&dir, &create_study("s", &["--db", "b.db"]));
    for _ in 0..8 {
        let asked: serde_json::Value =
            serde_json::from_str(&ok(&dir, &["study", "ask", "s", "--db", "b.db"])).unwrap();
        let policy = dir.join("p.json");
        std::fs::write(&policy, asked.to_string()).unwrap();
        let lap: serde_json::Value = serde_json::from_str(&ok(
            &dir,
            &[
                "lap",
                "--track",
                "oval.xml",
                "--policy",
                policy.to_str().unwrap(),
                "--json",
            ],
        ))
        .unwrap();
        let trial = asked["trial"].to_string();
        let mut tell = vec!["study", "tell", "s", "--db", "b.db", "--trial", &trial];
        // A failed lap is told with its place and reason, as the evaluator reads them from
        // `cdbo lap --json`.
        let (reward, at, reason);
        if lap["completed"].as_bool().unwrap() {
            reward = lap["reward_mps"].as_f64().unwrap().to_string();
            tell.extend(["--reward", &reward]);
        } else {
            at = lap["failure"]["x"].as_f64().unwrap().to_string();
            reason = lap["failure"]["reason"].as_str().unwrap().to_owned();
            tell.extend(["--failed", "--at", &at, "--reason", &reason]);
        }
        ok(&dir, &tell);
    }
    let (a, b) = (history(&dir, "s", "a.db"), history(&dir, "s", "b.db"));
    assert_eq!(a, b);
}

/// Resuming with other settings than the study's is refused, naming the stored value;
/// `--laps` is a total.
#[test]
fn resuming_with_other_settings_is_refused() {
    let dir = fresh_dir_with_demo("resume");
    let out = optimize("r.db", 3, 0.1).current_dir(&dir).output().unwrap();
    assert!(out.status.success());
    let base = |extra: &[&str]| -> Vec<String> {
        let mut v = optimize_args("true", "r.db", 5);
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    for (extra, needle) in [
        (
            &["--method", "turbo"][..],
            "created with --method cdbo, not turbo",
        ),
        (&["--seed", "3"][..], "created with --seed 0, not 3"),
        (&["--beta", "2"][..], "created with --beta 1, not 2"),
    ] {
        refused(&dir, &base(extra), &["r.db", needle]);
    }
    let mut args = base(&[]);
    args[4] = "7".into();
    refused(&dir, &args, &["created with --kernels 6, not 7"]);
    let out = optimize("r.db", 2, 0.1).current_dir(&dir).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("3 trials told already, --laps 2 is the total to reach: nothing to drive"),
        "{text}"
    );
}

/// Reading commands open a study read-only: they work for a user who cannot write the file
/// or its folder. Empty and foreign files are refused and left byte for byte.
#[test]
fn read_only_and_foreign_studies() {
    let dir = fresh_dir_with_demo("readonly");
    let out = optimize("ro.db", 3, 0.1)
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let locked = dir.join("locked");
    std::fs::create_dir_all(&locked).unwrap();
    std::fs::copy(dir.join("ro.db"), locked.join("ro.db")).unwrap();
    let before = std::fs::read(locked.join("ro.db")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(locked.join("ro.db"), std::fs::Permissions::from_mode(0o444)).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root may write anything: read as another user where we are root.
    let as_reader = |args: &[&str]| -> Output {
        let mut c = if unsafe { libc::geteuid() } == 0 {
            let mut c = Command::new("setpriv");
            c.args(["--reuid=65534", "--regid=65534", "--clear-groups", CDBO]);
            c
        } else {
            Command::new(CDBO)
        };
        c.args(args).current_dir(&locked).output().expect("runs")
    };
    if unsafe { libc::geteuid() } == 0 && as_reader(&["--version"]).status.code() != Some(0) {
        eprintln!("skipped: root, and setpriv cannot run the binary as nobody");
        return;
    }
    for cmd in [
        &["study", "status", "s", "--db", "ro.db"][..],
        &["study", "history", "s", "--db", "ro.db"],
        &["study", "best", "s", "--db", "ro.db"],
    ] {
        let out = as_reader(cmd);
        assert!(
            out.status.success(),
            "{cmd:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let export = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-rel-{}-export", std::process::id()));
    let _ = std::fs::remove_dir_all(&export);
    std::fs::create_dir_all(&export).unwrap();
    std::fs::set_permissions(&export, std::fs::Permissions::from_mode(0o777)).unwrap();
    let out = as_reader(&[
        "study",
        "export",
        "s",
        "--db",
        "ro.db",
        "--out",
        export.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(export.join("history.csv").exists());
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(std::fs::read(locked.join("ro.db")).unwrap(), before);

    std::fs::write(dir.join("empty.db"), "").unwrap();
    std::fs::write(dir.join("notes.db"), "x,a\n0,1\n").unwrap();
    // An SQLite database that is not a study: a study's file with user_version (bytes 60..64
    // of the header) zeroed.
    let mut foreign = std::fs::read(dir.join("ro.db")).unwrap();
    foreign[60..64].fill(0);
    std::fs::write(dir.join("foreign.db"), foreign).unwrap();
    for (file, needle) in [
        ("empty.db", "the file is empty"),
        ("notes.db", "not an SQLite database"),
        ("foreign.db", "without a study"),
    ] {
        let before = std::fs::read(dir.join(file)).unwrap();
        for cmd in ["status", "ask", "history"] {
            refused(
                &dir,
                &["study", cmd, "s", "--db", file],
                &[file, "not a cdbo study", needle],
            );
        }
        refused(
            &dir,
            &[
                "optimize",
                "--evaluator",
                "true",
                "--kernels",
                "6",
                "--laps",
                "5",
                "--db",
                file,
            ],
            &["not a cdbo study"],
        );
        assert_eq!(
            std::fs::read(dir.join(file)).unwrap(),
            before,
            "{file} was changed"
        );
    }
}

/// A failure reason of megabytes is kept as a bounded tail.
#[test]
fn evaluator_output_is_bounded_in_the_study() {
    let dir = fresh_dir_with_demo("output");
    let evaluator = r#"printf '{"failed": true, "reason": "'; head -c 3000000 /dev/zero | tr '\0' x; printf 'the end"}'"#;
    let out = cdbo(&dir, &optimize_args(evaluator, "o.db", 1));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let h = history(&dir, "s", "o.db");
    let reason = h[0]["failure"].as_str().unwrap();
    assert!(reason.len() <= 4096, "{}", reason.len());
    assert!(
        reason.starts_with("[3000007 bytes of output") && reason.ends_with("xthe end"),
        "{reason:.200}"
    );
    assert!(std::fs::metadata(dir.join("o.db")).unwrap().len() < 1_000_000);
}

/// A run record cut short is run again on resume, with a warning naming it, and the report
/// then passes; leftover policy files of killed workers go when the study next runs.
#[test]
fn cut_run_records_and_leftover_files() {
    let dir = fresh_dir("cut");
    std::fs::write(
        dir.join("tiny.toml"),
        "laps = 3\nrepeats = 1\nmethods = [\"random\"]\n[[tracks]]\ntrack = \"ridgeway\"\nkernels = [5]\n",
    )
    .unwrap();
    ok(
        &dir,
        &["experiment", "tiny.toml", "--out", "e", "--jobs", "1"],
    );
    let record = dir.join("e/runs/ridgeway-m5-random-r0.json");
    let text = std::fs::read(&record).unwrap();
    std::fs::write(&record, &text[..text.len() / 2]).unwrap();
    let out = cdbo(
        &dir,
        &["experiment", "tiny.toml", "--out", "e", "--jobs", "1"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: ")
            && err.contains("ridgeway-m5-random-r0.json")
            && err.contains("running ridgeway-m5-random-r0 again"),
        "{err}"
    );
    let again = std::fs::read(&record).unwrap();
    assert!(serde_json::from_slice::<serde_json::Value>(&again).is_ok());
    ok(&dir, &["report", "e"]);

    demo(&dir);
    let leftover = dir.join("l.db.trial-1.pid-999999999.json");
    std::fs::write(&leftover, "{}").unwrap();
    let out = optimize("l.db", 1, 0.1).current_dir(&dir).output().unwrap();
    assert!(out.status.success());
    assert!(!leftover.exists());
}

/// `serve-sim` answers every malformed line with a JSON error naming it, and keeps answering.
#[test]
fn serve_sim_survives_bad_lines() {
    use std::io::{BufRead, BufReader, Write};
    let dir = fresh_dir("serve");
    let mut child = Command::new(CDBO)
        .args(["serve-sim", "--kernels", "5"])
        .current_dir(&dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    let mut replies = BufReader::new(child.stdout.take().unwrap()).lines();
    let long = format!("{{\"weights\": [{}]}}", "0.1, ".repeat(300_000));
    let bad: &[(&[u8], &str)] = &[
        (b"\xff\xfe{\"info\": true}", "not UTF-8"),
        (long.as_bytes(), "longer than 1048576 bytes"),
        (b"{\"weights\": \"fast\"}", "expected"),
        (
            b"{\"weights\": [1, 2, \"x\", 4, 5]}",
            "weight 2 is not a number",
        ),
        (b"{\"weights\": [1e999, 0, 0, 0, 0]}", "not JSON"),
        (b"{\"weights\": [NaN, 0, 0, 0, 0]}", "not JSON"),
        (b"{\"weights\": [0.1, 0.2]}", "expected 5 weights, got 2"),
        (b"[1, 2", "not JSON"),
    ];
    for (k, (line, needle)) in bad.iter().enumerate() {
        input.write_all(line).unwrap();
        input.write_all(b"\n").unwrap();
        input.flush().unwrap();
        let reply: serde_json::Value =
            serde_json::from_str(&replies.next().unwrap().unwrap()).unwrap();
        let e = reply["error"].as_str().unwrap_or_else(|| panic!("{reply}"));
        assert!(e.starts_with(&format!("line {}: ", k + 1)), "{e}");
        assert!(e.contains(needle), "{e:.300} lacks {needle:?}");
    }
    writeln!(input, "{{\"info\": true}}").unwrap();
    let info: serde_json::Value = serde_json::from_str(&replies.next().unwrap().unwrap()).unwrap();
    assert_eq!(info["dim"], 5);
    drop(input);
    assert!(child.wait().unwrap().success());
}
