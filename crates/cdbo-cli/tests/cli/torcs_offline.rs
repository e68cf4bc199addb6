//! The game's commands that need no game: a panel of the game's laps scores the simulator,
//! `torcs transfer` refuses a bad reference or a preset beside its flags, `--simulator torcs`
//! is refused where it is not supported, and `torcs calibrate --log` fits a car to a log.

use std::path::Path;

use crate::common::{fails_with, fitted_to_the_demonstration, json, run, scratch, succeed};

/// A panel of laps (here written by hand, as `torcs compare` writes the game's) scores cdbo's
/// simulator policy by policy, without the game.
#[test]
fn a_panel_of_the_games_laps_scores_the_simulator_without_the_game() {
    let (_, w0) = fitted_to_the_demonstration("panel");
    let ours = json(&["lap", "--policy", w0.to_str().unwrap(), "--json"]);
    let t0 = ours["lap_time_s"].as_f64().expect("w0 completes Ridgeway");
    let policy: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&w0).unwrap()).unwrap();
    let mut flat_out = policy.clone();
    for w in flat_out["weights"].as_array_mut().unwrap() {
        *w = serde_json::json!(5.0);
    }
    // The game completed both: in 1 % more time than cdbo's w0, and full throttle too.
    let line = |what: &str, p: &serde_json::Value, t: f64| {
        serde_json::json!({"track": "ridgeway", "what": what, "policy": p,
            "torcs": {"lap_time_s": t, "failure": null, "distance_fail_m": null}})
        .to_string()
    };
    let panel = scratch(
        "panel_ridgeway.jsonl",
        &format!(
            "{}\n{}\n",
            line("policy 0", &policy, 1.01 * t0),
            line("policy 1", &flat_out, 60.0)
        ),
    );
    let v = json(&[
        "torcs",
        "panel",
        panel.to_str().unwrap(),
        "--car",
        "spirit-300",
        "--json",
    ]);
    let s = &v[0];
    assert_eq!(s["track"], "ridgeway");
    assert_eq!(
        (s["laps"].as_u64(), s["agree"].as_u64()),
        (Some(2), Some(1)),
        "{v}"
    );
    assert_eq!(
        (s["cdbo_fails"].as_u64(), s["torcs_fails"].as_u64()),
        (Some(1), Some(0))
    );
    assert!(
        (s["lap_time_bias"].as_f64().unwrap() - 0.01).abs() < 1e-9,
        "{v}"
    );
    // A broken line is named with its file and line, and nothing is scored.
    let broken = scratch(
        "panel_broken.jsonl",
        &format!(
            "{}\n{{\"track\": \"ridgeway\"}}\n",
            line("policy 0", &policy, t0)
        ),
    );
    fails_with(
        &[
            "torcs",
            "panel",
            broken.to_str().unwrap(),
            "--car",
            "spirit-300",
        ],
        &["panel_broken.jsonl:2", "panel lap"],
    );
}

/// `torcs transfer --against` refuses a bad reference before it looks for the game or drives a
/// lap: one line naming the file, the row and the value, and no output folder.
#[test]
fn transfer_refuses_a_bad_reference_before_any_lap() {
    let out = scratch("transfer-out", "");
    std::fs::remove_file(&out).unwrap();
    let bad = scratch(
        "reference.json",
        r#"{"transfers": [{"track": "forza", "best_reward_mps": 52.0},
                          {"track": "aalborg", "best_reward_mps": -3.5}]}"#,
    );
    let args = |file: &Path| {
        [
            "torcs",
            "transfer",
            "--against",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]
        .map(str::to_owned)
    };
    let a = args(&bad);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    fails_with(
        &a,
        &["reference.json", "transfers[1].best_reward_mps", "-3.5"],
    );
    let torn = scratch("torn.json", r#"{"transfers": [{"track": "forza""#);
    let a = args(&torn);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    fails_with(&a, &["torn.json", "EOF"]);
    assert!(!out.exists());
}

/// `torcs transfer --preset fast-safe` learns with the stack it names (up to the reference,
/// read before the game is asked for) and refuses a flag of that stack beside it, in one line
/// naming both.
#[test]
fn transfer_takes_the_preset_but_not_beside_its_flags() {
    let torn = scratch("torn-preset.json", r#"{"transfers": ["#);
    let transfer = ["torcs", "transfer", "--preset", "fast-safe", "--against"];
    fails_with(
        &[&transfer[..], &[torn.to_str().unwrap()]].concat(),
        &["torn-preset.json"],
    );
    for given in [
        ["--method", "pattern-search"],
        ["--steering", "pi"],
        ["--line", "learn"],
    ] {
        fails_with(&[&transfer[..4], &given].concat(), &["--preset", given[0]]);
    }
}

/// The game's laps kept beside the fidelity report (docs/results/torcs/panel_TRACK.jsonl, 300
/// policies a track drawn around three learned ones, driven in TORCS 1.3.7): cdbo's simulator
/// keeps agreeing with them. A change to the model that loses fidelity fails here, without the
/// game: on Forza, E-Track 2 and Aalborg it completed where the game did on 286, 287 and 294
/// of 300 when they were kept, and its laps were 0.2–0.5 % faster; the model before it (its tyres slipping sideways by tan α, not sin α) agrees on 282, 292 and 294 of them,
/// and the one before that (no rolling resistance against the yaw, no pitch from the wings' drag,
/// the launch clutch blended at cdbo's own step) on 287, 279 and 290.
#[test]
#[ignore = "slow: 900 simulator laps, the game's kept panels on three tracks"]
fn the_simulator_still_agrees_with_the_games_kept_laps() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/results/torcs");
    let panels: Vec<String> = ["forza", "e-track-2", "aalborg"]
        .iter()
        .map(|t| docs.join(format!("panel_{t}.jsonl")).display().to_string())
        .collect();
    let mut args = vec!["torcs", "panel", "--json"];
    args.extend(panels.iter().map(String::as_str));
    let v = json(&args);
    for s in v.as_array().unwrap() {
        let (agree, laps) = (s["agree"].as_u64().unwrap(), s["laps"].as_u64().unwrap());
        assert_eq!(laps, 300, "{s}");
        assert!(agree >= 285, "{}: {agree} of {laps}", s["track"]);
        let bias = s["lap_time_bias"].as_f64().unwrap();
        assert!(
            (-0.005..0.015).contains(&bias),
            "{}: bias {bias}",
            s["track"]
        );
    }
}

/// A command that cannot drive the game says so instead of quietly driving cdbo's simulator.
#[test]
fn simulator_torcs_is_refused_where_it_is_not_supported() {
    let works = "--simulator torcs works with `lap`, `race`, `experiment`, `serve-sim` and `optimize --track T`";
    fails_with(&["--simulator", "torcs", "limit"], &[works]);
    fails_with(&["--simulator", "torcs", "ceiling"], &[works]);
    // A grid in the game runs in a folder; workers over storage drive cdbo's simulator only.
    let grid_db = scratch("torcs-grid.db", "");
    std::fs::remove_file(&grid_db).unwrap();
    fails_with(
        &[
            "--simulator",
            "torcs",
            "experiment",
            "quick",
            "--storage",
            grid_db.to_str().unwrap(),
        ],
        &["--simulator torcs runs a grid in a folder", "--storage"],
    );
    assert!(!grid_db.exists());
    // optimize drives the game itself with --track, and refuses the mix-ups before any study
    // file is made.
    let db = scratch("torcs-opt.db", "");
    std::fs::remove_file(&db).unwrap();
    let db = db.to_str().unwrap();
    let common = ["--laps", "3", "--db", db, "--kernels", "5"];
    let mut game_no_track = vec!["--simulator", "torcs", "optimize", "--evaluator", "echo 1"];
    game_no_track.extend(common);
    fails_with(&game_no_track, &["name its --track"]);
    let mut track_no_game = vec!["optimize", "--track", "forza"];
    track_no_game.extend(common);
    fails_with(&track_no_game, &["add --simulator torcs"]);
    assert!(!std::path::Path::new(db).exists());
}

/// `torcs calibrate --log`: a `cdbo lap --trace` file is a one-lap log; the fit writes a car
/// file `--car` takes. A bad log (a missing column, NaN, a station off the track) is one line
/// naming the file, line and column, and nothing is written.
#[test]
fn calibrate_from_a_log_writes_a_car_and_refuses_bad_logs() {
    let dir = scratch("calibrate-placeholder", "")
        .parent()
        .unwrap()
        .to_path_buf();
    let trace = dir.join("calibrate-trace.csv");
    let out = dir.join("calibrate-out");
    let _ = std::fs::remove_dir_all(&out);
    let (trace_s, out_s) = (trace.to_str().unwrap(), out.to_str().unwrap());
    succeed(&["lap", "--demo", "20", "--trace", trace_s]);
    let run = |log: &str| {
        run(&[
            "torcs",
            "calibrate",
            "--track",
            "ridgeway",
            "--car",
            "spirit-300",
            "--log",
            log,
            "--fit",
            "rolling",
            "--evaluations",
            "12",
            "--out",
            out_s,
        ])
    };
    let text = std::fs::read_to_string(&trace).unwrap();
    // The trace with cell `col` of every row from line `from` on (1-based) set to `v`.
    let set = |from: usize, col: usize, v: &str| {
        let lines: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i + 1 < from {
                    return l.to_owned();
                }
                let mut cells: Vec<&str> = l.split(',').collect();
                cells[col] = v;
                cells.join(",")
            })
            .collect();
        lines.join("\n")
    };
    let bad = [
        (
            "no-yaw.csv",
            text.replace(",yaw_rate_rad_s", ",yaw"),
            ":1: column yaw_rate_rad_s: missing",
        ),
        (
            "nan.csv",
            set(6, 3, "NaN"),
            ":6: column speed_mps: \"NaN\" is not a finite number",
        ),
        (
            "far.csv",
            set(2, 1, "99999"),
            ":2: column distance_m: 99999 lies outside the track",
        ),
    ];
    for (name, content, needle) in bad {
        let log = scratch(name, &content);
        let o = run(log.to_str().unwrap());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains(log.to_str().unwrap()) && err.contains(needle),
            "{name}: {err}"
        );
        assert!(!out.exists(), "{name}: wrote {}", out.display());
    }
    let o = run(trace_s);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let car = out.join("car.toml");
    let lap = json(&[
        "lap",
        "--car",
        car.to_str().unwrap(),
        "--demo",
        "20",
        "--json",
    ]);
    assert_eq!(lap["completed"], true, "{lap}");
}
