//! Studies for a real car: the ask/tell workflow, bad input, external evaluators, crash
//! safety under SIGKILL, and the simulator as a JSON-lines service.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

mod common;

use common::{CDBO, Service, cdbo, fresh_dir_with_demo, history, ok};

/// Expects failure with one clear error line containing `needle`.
fn fails(dir: &Path, args: &[&str], needle: &str) {
    let out = cdbo(dir, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains(needle), "{:?} lacks {needle:?}", lines[0]);
}

const EVALUATOR: &str = "{cdbo} lap --policy {policy} --json";

/// [`common::optimize_args`] of seed 4 on the SQLite file `db`.
fn optimize_args(db: &str, laps: usize, evaluator: &str) -> Vec<String> {
    let mut args = common::optimize_args(evaluator, db, laps);
    args.extend(["--seed".into(), "4".into()]);
    args
}

#[test]
fn ask_tell_workflow_and_bad_input() {
    let dir = fresh_dir_with_demo("workflow");
    let create = [
        "study",
        "create",
        "car",
        "--kernels",
        "8",
        "--demo",
        "demo.csv",
    ];
    ok(&dir, &create);
    fails(&dir, &create, "already exists");
    let ask: serde_json::Value = serde_json::from_str(&ok(&dir, &["study", "ask", "car"])).unwrap();
    assert_eq!(ask["trial"], 1);
    assert_eq!(ask["weights"].as_array().unwrap().len(), 8);
    assert_eq!(ask["table"].as_array().unwrap().len(), 1001);
    // Asking again returns the same pending trial.
    let again: serde_json::Value =
        serde_json::from_str(&ok(&dir, &["study", "ask", "car"])).unwrap();
    assert_eq!(ask, again);
    let csv = ok(&dir, &["study", "ask", "car", "--format", "csv"]);
    assert!(csv.starts_with("# trial 1\nx,a\n"));
    fails(
        &dir,
        &["study", "tell", "car", "--trial", "7", "--reward", "1"],
        "no trial 7",
    );
    fails(
        &dir,
        &["study", "tell", "car", "--trial", "1", "--reward", "NaN"],
        "finite",
    );
    fails(
        &dir,
        &["study", "tell", "car", "--trial", "1", "--reward", "inf"],
        "finite",
    );
    fails(
        &dir,
        &[
            "study",
            "tell",
            "car",
            "--trial",
            "1",
            "--lap-time",
            "-3",
            "--length",
            "100",
        ],
        "--lap-time",
    );
    ok(
        &dir,
        &[
            "study",
            "tell",
            "car",
            "--trial",
            "1",
            "--lap-time",
            "200",
            "--length",
            "3000",
        ],
    );
    fails(
        &dir,
        &["study", "tell", "car", "--trial", "1", "--reward", "3"],
        "already told",
    );
    let t2: serde_json::Value = serde_json::from_str(&ok(&dir, &["study", "ask", "car"])).unwrap();
    assert_eq!(t2["trial"], 2);
    ok(
        &dir,
        &[
            "study", "tell", "car", "--trial", "2", "--failed", "--at", "0.25", "--reason",
            "stalled",
        ],
    );
    let status: serde_json::Value =
        serde_json::from_str(&ok(&dir, &["study", "status", "car", "--json"])).unwrap();
    assert_eq!(status["told"], 2);
    assert_eq!(status["failed"], 1);
    assert_eq!(status["best_reward"], 15.0);
    let best: serde_json::Value =
        serde_json::from_str(&ok(&dir, &["study", "best", "car"])).unwrap();
    assert_eq!(best["trial"], 1);
    let hist = ok(&dir, &["study", "history", "car"]);
    assert_eq!(hist.lines().count(), 3);
    assert!(hist.contains("2,0,15,,stalled,0.25"), "{hist}");
    ok(&dir, &["study", "export", "car", "--out", "exp"]);
    for f in [
        "history.csv",
        "history.json",
        "best_policy.json",
        "best_policy.csv",
        "learning_curve.png",
    ] {
        assert!(dir.join("exp").join(f).is_file(), "{f}");
    }
    fails(&dir, &["study", "ask", "nobody"], "no such study");
    std::fs::write(dir.join("junk.db"), "not a database at all").unwrap();
    fails(
        &dir,
        &["study", "status", "x", "--db", "junk.db"],
        "not an SQLite database",
    );
    fails(
        &dir,
        &[
            "study",
            "create",
            "w",
            "--kernels",
            "5",
            "--demo",
            "demo.csv",
            "--method",
            "simplex",
        ],
        "invalid value 'simplex'",
    );
    assert!(
        !dir.join("w.cdbo.db").exists(),
        "a failed create left a file"
    );
    let with_length = |metres: &'static str| {
        [
            "study",
            "create",
            "fast",
            "--kernels",
            "5",
            "--demo",
            "demo.csv",
            "--method",
            "pattern-search",
            "--track-length",
            metres,
        ]
    };
    fails(&dir, &with_length("0"), "--track-length");
    fails(&dir, &with_length("NaN"), "--track-length");
    ok(&dir, &with_length("3596"));
    let stored: serde_json::Value =
        serde_json::from_str(&ok(&dir, &["study", "status", "fast", "--json"])).unwrap();
    assert_eq!(stored["track_length_m"], 3596.0);
    assert_eq!(status["track_length_m"], serde_json::Value::Null);
    // The method's knob: checked once at creation (nothing written when refused), stored,
    // shown, and a resume with another refused naming the stored one.
    let tuned = |knob: &'static str| {
        [
            "study",
            "create",
            "tuned",
            "--kernels",
            "5",
            "--demo",
            "demo.csv",
            "--method",
            "turbo",
            "--knob",
            knob,
        ]
    };
    fails(&dir, &tuned("2"), "turbo's knob length");
    assert!(
        !dir.join("tuned.cdbo.db").exists(),
        "a refused knob left a file"
    );
    ok(&dir, &tuned("0.1"));
    let stored: serde_json::Value =
        serde_json::from_str(&ok(&dir, &["study", "status", "tuned", "--json"])).unwrap();
    assert_eq!(stored["knob"], 0.1);
    assert_eq!(status["knob"], serde_json::Value::Null);
    let resumed = [
        "optimize",
        "--evaluator",
        "echo 1",
        "--kernels",
        "5",
        "--laps",
        "1",
        "--storage",
        "tuned.cdbo.db",
        "--demo",
        "demo.csv",
        "--knob",
        "0.3",
    ];
    fails(&dir, &resumed, "created with --knob 0.1");
    // A budget of failed laps: stored at creation, a resume with another refused.
    ok(
        &dir,
        &[
            "study",
            "create",
            "safe",
            "--kernels",
            "5",
            "--demo",
            "demo.csv",
            "--method",
            "safe-pattern-search",
            "--max-failed-laps",
            "3",
        ],
    );
    let budgeted = |n: &'static str| {
        [
            "optimize",
            "--evaluator",
            "echo 1",
            "--kernels",
            "5",
            "--laps",
            "2",
            "--storage",
            "safe.cdbo.db",
            "--demo",
            "demo.csv",
            "--max-failed-laps",
            n,
        ]
    };
    fails(&dir, &budgeted("4"), "created with --max-failed-laps 3");
    ok(&dir, &budgeted("3"));
    // The search box: stored at creation, every trial within it, a resume with another refused.
    let boxed = [
        "study",
        "create",
        "boxed",
        "--kernels",
        "5",
        "--demo",
        "demo.csv",
        "--method",
        "random",
        "--knob",
        "1",
        "--box-radius",
        "0.05",
    ];
    ok(&dir, &boxed);
    let weights = |trial: usize| -> Vec<f64> {
        let ask: serde_json::Value =
            serde_json::from_str(&ok(&dir, &["study", "ask", "boxed"])).unwrap();
        assert_eq!(ask["trial"], trial);
        let t = trial.to_string();
        ok(
            &dir,
            &["study", "tell", "boxed", "--trial", &t, "--reward", &t],
        );
        serde_json::from_value(ask["weights"].clone()).unwrap()
    };
    let w0 = weights(1);
    let farthest = (2..6)
        .flat_map(|t| {
            weights(t)
                .into_iter()
                .zip(w0.clone())
                .map(|(w, s)| (w - s).abs())
        })
        .fold(0.0, f64::max);
    // Random search's σ of 1 sends most weights past the box: they sit on it.
    assert!((farthest - 0.05).abs() < 1e-12, "{farthest}");
    let mut resumed = boxed.to_vec();
    resumed[1..3].copy_from_slice(&["create", "boxed-again"]);
    resumed[12] = "0";
    fails(&dir, &resumed, "--box-radius");
    let mut other = budgeted("3").to_vec();
    other[8] = "boxed.cdbo.db";
    other[11..13].copy_from_slice(&["--box-radius", "0.1"]);
    fails(&dir, &other, "created with --box-radius 0.05");
}

#[test]
fn optimize_records_failed_commands_with_their_reason() {
    let dir = fresh_dir_with_demo("failing");
    let out = ok(
        &dir,
        &optimize_args(
            "f.db",
            3,
            "case $(wc -c < {policy}) in *) echo crashed >&2; exit 4;; esac",
        ),
    );
    assert_eq!(
        out.matches("saved (failed: the command exited").count(),
        3,
        "{out}"
    );
    let out = ok(&dir, &optimize_args("g.db", 2, "echo fast"));
    assert_eq!(out.matches("unparsable output").count(), 2, "{out}");
    let out = ok(
        &dir,
        &[
            optimize_args("h.db", 1, "sleep 3"),
            vec!["--timeout".into(), "0.2".into()],
        ]
        .concat(),
    );
    assert!(out.contains("timeout"), "{out}");
}

/// `cdbo optimize` killed with SIGKILL at 50 random moments loses nothing it reported as
/// saved, and continues exactly as an uninterrupted run.
#[test]
fn sigkill_at_random_moments_loses_nothing() {
    let dir = fresh_dir_with_demo("sigkill");
    let evaluator = common::OVAL_LAP.replace("{cdbo}", CDBO);
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut random_ms = |max: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % max
    };
    let mut saved: Vec<(u64, f64)> = Vec::new();
    // A target that is never reached: every session ends by SIGKILL.
    for _ in 0..50 {
        let mut child = Command::new(CDBO)
            .args(optimize_args("killed.db", 100000, &evaluator))
            .current_dir(&dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let reader = std::thread::spawn(move || {
            BufReader::new(stdout)
                .lines()
                .map_while(Result::ok)
                .filter_map(|l| {
                    let rest = l.strip_prefix("trial ")?;
                    let (id, rest) = rest.split_once(": reward ")?;
                    let reward = rest.split_whitespace().next()?;
                    Some((id.parse().ok()?, reward.parse().ok()?))
                })
                .collect::<Vec<(u64, f64)>>()
        });
        std::thread::sleep(Duration::from_millis(random_ms(80)));
        child.kill().unwrap(); // SIGKILL
        assert!(!child.wait().unwrap().success());
        saved.extend(reader.join().unwrap());
        // Everything reported as saved is in the study, with the reported reward.
        if dir.join("killed.db").exists() {
            let h = history(&dir, "s", "killed.db");
            for (id, reward) in &saved {
                let t = h
                    .iter()
                    .find(|t| t["id"].as_u64() == Some(*id))
                    .unwrap_or_else(|| panic!("trial {id} reported saved but lost"));
                assert_eq!(t["reward"].as_f64(), Some(*reward), "trial {id}");
            }
        }
    }
    // On a loaded machine every kill may come before the study is made: make it now.
    if !dir.join("killed.db").exists() {
        ok(&dir, &optimize_args("killed.db", 0, &evaluator));
    }
    // Finish a few more laps undisturbed, then compare with a run never interrupted.
    let told = history(&dir, "s", "killed.db")
        .iter()
        .filter(|t| t["reward"].is_number())
        .count();
    let laps = told + 3;
    ok(&dir, &optimize_args("killed.db", laps, &evaluator));
    ok(&dir, &optimize_args("reference.db", laps, &evaluator));
    let (killed, reference) = (
        history(&dir, "s", "killed.db"),
        history(&dir, "s", "reference.db"),
    );
    assert_eq!(killed.len(), told + 3);
    assert_eq!(killed.len(), reference.len());
    for (a, b) in killed.iter().zip(&reference) {
        assert_eq!(
            a["weights"], b["weights"],
            "trial {} differs after resuming",
            a["id"]
        );
        assert_eq!(a["reward"], b["reward"]);
    }
}

#[test]
fn serve_sim_answers_json_lines() {
    let mut command = Command::new(CDBO);
    command
        // Since the gearbox shifts at the current throttle, the 8-kernel fits of the 13-18 m/s
        // demonstrations stall on Ridgeway's climb near x = 0.45 (their smoothed pedal holds a
        // high gear there); that of a 20 m/s one completes.
        .args(["serve-sim", "--kernels", "8", "--demo-speed", "20"]);
    let mut service = Service::start(command);
    let mut ask = |line: &str| service.ask(line);
    let info = ask(r#"{"info": true}"#);
    assert_eq!(info["dim"], 8);
    let w0 = info["w0"].clone();
    let lap = ask(&format!(r#"{{"weights": {w0}}}"#));
    assert!(lap["reward_mps"].as_f64().unwrap() > 10.0, "{lap}");
    assert!(lap["failure"].is_null());
    let brake = ask(r#"{"weights": [-1, -1, -1, -1, -1, -1, -1, -1]}"#);
    assert_eq!(brake["reward_mps"], 0.0);
    assert_eq!(brake["failure"]["reason"], "stalled");
    for bad in [
        "{",
        r#"{"weights": [1, 2]}"#,
        r#"{"weights": [1, "a", 1, 1, 1, 1, 1, 1]}"#,
        "[]",
    ] {
        let e = ask(bad);
        assert!(e["error"].is_string(), "{bad}: {e}");
    }
    // Still serving after the errors.
    assert_eq!(ask(&format!(r#"{{"weights": {w0}}}"#)), lap);
    assert!(service.finish().success());
}

/// A study started from a policy raced with the path tracker steers with it: it takes the
/// steering from w₀'s file, writes it into each lap's policy file, and `cdbo lap --policy
/// {policy}` drives its first trial, w₀, to the race's best lap bit for bit (with the PI the
/// same weights spin). Another steering is refused when the study is created or resumed.
#[test]
fn a_study_steers_as_its_initial_policy_was_raced() {
    let dir = common::fresh_dir("study-steering");
    let race = [
        "race",
        "--json",
        "--out",
        "r",
        "--kernels",
        "20",
        "--laps",
        "20",
        "--steering",
        "tracker",
        "--method",
        "pattern-search",
    ];
    let summary: serde_json::Value = serde_json::from_str(&ok(&dir, &race)).unwrap();
    let best = summary["best_reward_mps"].as_f64().unwrap();
    assert!(best > 30.0, "{best}");
    let pi = ok(
        &dir,
        &["lap", "--policy", "r", "--steering", "pi", "--json"],
    );
    let pi: serde_json::Value = serde_json::from_str(&pi).unwrap();
    assert_eq!(pi["completed"], false);
    let study = [
        "--storage",
        "s.db",
        "--kernels",
        "20",
        "--method",
        "pattern-search",
    ];
    let mut create = vec!["study", "create", "s", "--weights", "r/best_policy.json"];
    create.extend(study);
    common::refused(
        &dir,
        &[&create[..], &["--steering", "pi"]].concat(),
        &["best_policy.json", "--steering tracker"],
    );
    ok(&dir, &create);
    let evaluator = EVALUATOR.replace("{cdbo}", CDBO);
    let mut optimize = vec!["optimize", "--evaluator", &evaluator, "--laps", "1"];
    optimize.extend(study);
    ok(&dir, &optimize);
    let first = &history(&dir, "s", "s.db")[0];
    assert_eq!(
        first["reward"].as_f64().map(f64::to_bits),
        Some(best.to_bits())
    );
    let status = ok(
        &dir,
        &["study", "status", "s", "--storage", "s.db", "--json"],
    );
    let status: serde_json::Value = serde_json::from_str(&status).unwrap();
    assert_eq!(status["steering"], "tracker");
    optimize.extend(["--steering", "pi"]);
    common::refused(&dir, &optimize, &["s.db", "--steering tracker", "not pi"]);
}

/// `--preset fast-safe` on `optimize` and `study create` stores the stack it names, the safe
/// pattern search on the path tracker and the minimum-curvature line, and drives the laps its
/// long form drives, reward for reward; a study of another stack resumed with it is refused
/// naming the stored flags, and beside a flag it sets it is refused naming both.
#[test]
fn a_study_of_the_preset_is_its_long_form() {
    let dir = fresh_dir_with_demo("study-preset");
    let evaluator = common::OVAL_LAP.replace("{cdbo}", CDBO);
    let long_form = common::FAST_SAFE_FLAGS;
    let drive = |db: &str, stack: &[&str]| -> Vec<Option<u64>> {
        let mut args = common::optimize_args(&evaluator, db, 4);
        args.extend(stack.iter().map(|s| s.to_string()));
        ok(&dir, &args);
        history(&dir, "s", db)
            .iter()
            .map(|t| t["reward"].as_f64().map(f64::to_bits))
            .collect()
    };
    let preset = drive("preset.db", &["--preset", "fast-safe"]);
    assert_eq!(preset.len(), 4);
    assert_eq!(preset, drive("long.db", &long_form));
    let status = ok(
        &dir,
        &["study", "status", "s", "--storage", "preset.db", "--json"],
    );
    let status: serde_json::Value = serde_json::from_str(&status).unwrap();
    assert_eq!(status["method"], "safe-pattern-search");
    assert_eq!(status["steering"], "tracker");
    assert_eq!(status["line"], "min-curvature");
    let created = common::create_study("c", &["--storage", "c.db", "--preset", "fast-safe"]);
    ok(&dir, &created);
    let status = ok(
        &dir,
        &["study", "status", "c", "--storage", "c.db", "--json"],
    );
    let status: serde_json::Value = serde_json::from_str(&status).unwrap();
    assert_eq!(status["method"], "safe-pattern-search");
    drive("paper.db", &[]);
    let mut resumed = common::optimize_args(&evaluator, "paper.db", 4);
    resumed.extend(["--preset".into(), "fast-safe".into()]);
    common::refused(
        &dir,
        &resumed,
        &[
            "paper.db",
            "--method cdbo --steering pi --line centre",
            "--preset fast-safe",
        ],
    );
    common::refused(
        &dir,
        &common::create_study("d", &["--preset", "fast-safe", "--steering", "pi"]),
        &["--preset", "--steering"],
    );
}
