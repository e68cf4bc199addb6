//! The line (`--line`, `--line-kernels`, `--line-start`) beyond `cdbo race`: a study learning a
//! line drives the race's laps and resumes only with its own line; serve-sim drives the lap
//! `cdbo lap` drives; a policy file replays on the line it was raced on.

use std::path::Path;
use std::process::Command;

mod common;

use common::{CDBO, Service, fresh_dir, ok, refused};

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap()
}

/// `cdbo race --json ARGS --out OUT` in `dir`: its summary.
fn race(dir: &Path, out: &str, args: &[&str]) -> serde_json::Value {
    let mut all = vec!["race", "--json", "--out", out, "--kernels", "10"];
    all.extend(args);
    json(&ok(dir, &all))
}

/// A study created with `--line learn` (w₀ the race's initial policy, the lap's length told as
/// the race tells it), driven by `cdbo lap` in two runs, tells the laps `cdbo race` drove with
/// the same flags: every reward (as laps.csv writes them) and the best bit for bit. Resumed
/// with another line it is refused, naming the flags it was created with.
#[test]
fn a_study_learning_a_line_resumes_with_the_races_laps() {
    let dir = fresh_dir("study-line");
    let line = ["--line", "learn", "--line-kernels", "6"];
    let method = ["--method", "pattern-search", "--seed", "2"];
    let laps = 10;
    let summary = race(
        &dir,
        "r",
        &[&method[..], &line[..], &["--laps", "10"]].concat(),
    );
    let length = json(&ok(&dir, &["track", "info", "ridgeway", "--json"]))["length_m"].to_string();
    let study = ["--storage", "s.db", "--kernels", "10"];
    let mut create = vec!["study", "create", "s", "--weights", "r/initial_policy.json"];
    create.extend(
        [
            &study[..],
            &method[..],
            &line[..],
            &["--track-length", &length],
        ]
        .concat(),
    );
    ok(&dir, &create);
    let evaluator = format!("{CDBO} lap --policy {{policy}} --json");
    for (total, flags) in [(4, &line[..]), (laps, &[][..])] {
        let total = total.to_string();
        let mut optimize = vec!["optimize", "--evaluator", &evaluator, "--laps", &total];
        optimize.extend([&study[..], flags].concat());
        ok(&dir, &optimize);
    }
    let history = common::history(&dir, "s", "s.db");
    let told: Vec<f64> = history
        .iter()
        .map(|t| t["reward"].as_f64().unwrap())
        .collect();
    let csv = std::fs::read_to_string(dir.join("r/laps.csv")).unwrap();
    let raced: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(told.len(), laps);
    for (k, (t, r)) in told.iter().zip(&raced).enumerate() {
        assert!((t - r).abs() < 1e-6, "lap {}: study {t}, race {r}", k + 1);
    }
    assert!(told[1..].contains(&0.0), "no lap failed: {told:?}");
    let best = told.iter().copied().fold(0.0, f64::max);
    assert_eq!(
        best.to_bits(),
        summary["best_reward_mps"].as_f64().unwrap().to_bits()
    );
    let status = json(&ok(
        &dir,
        &["study", "status", "s", "--storage", "s.db", "--json"],
    ));
    assert_eq!(status["line"], "learn-m6");
    let more = [&study[..], &["--line", "centre"]].concat();
    let mut resume = vec!["optimize", "--evaluator", "true", "--laps", "20"];
    resume.extend(more);
    refused(
        &dir,
        &resume,
        &["s.db", "--line learn --line-kernels 6", "--line centre"],
    );
}

/// serve-sim with a line learned from the minimum-curvature line: its w₀ is the race's initial
/// policy (the line's weights 0), and the race's best weights drive the race's best lap, the
/// lap `cdbo lap` drives from the best policy's file (which names its base line), bit for bit.
/// A file without the base line (written before it was stored) takes the summary's beside it.
#[test]
fn serve_sim_and_lap_drive_a_policy_on_its_line() {
    let dir = fresh_dir("serve-line");
    // At the game's rule, where `cdbo lap` judges: the PI on this line keeps no lap 1 m
    // inside the road's edge in 12 laps.
    let line = [
        "--line",
        "learn",
        "--line-kernels",
        "5",
        "--line-start",
        "min-curvature",
        "--off-track-margin",
        "1",
    ];
    let summary = race(
        &dir,
        "r",
        &[&line[..], &["--laps", "12", "--method", "pattern-search"]].concat(),
    );
    let best: serde_json::Value =
        json(&std::fs::read_to_string(dir.join("r/best_policy.json")).unwrap());
    assert_eq!(best["base_line"], "min-curvature");
    let initial: serde_json::Value =
        json(&std::fs::read_to_string(dir.join("r/initial_policy.json")).unwrap());
    let joint = |p: &serde_json::Value| -> Vec<f64> {
        let w = |v: &serde_json::Value| -> Vec<f64> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        [w(&p["weights"]), w(&p["line"]["weights"])].concat()
    };
    let mut command = Command::new(CDBO);
    command.args([&["serve-sim", "--kernels", "10"][..], &line[..]].concat());
    let mut service = Service::start(command);
    let info = service.ask(r#"{"info": true}"#);
    assert_eq!(info["dim"], 15);
    assert_eq!(info["line"]["kernels"], 5);
    assert_eq!(info["base_line"], "min-curvature");
    let w0: Vec<f64> = serde_json::from_value(info["w0"].clone()).unwrap();
    assert_eq!(w0, joint(&initial));
    let served = service.ask(&serde_json::json!({ "weights": joint(&best) }).to_string());
    assert!(service.finish().success());
    let lapped = json(&ok(
        &dir,
        &["lap", "--policy", "r/best_policy.json", "--json"],
    ));
    let best_mps = summary["best_reward_mps"].as_f64().unwrap().to_bits();
    assert!(f64::from_bits(best_mps) > 0.0);
    assert_eq!(served["reward_mps"].as_f64().unwrap().to_bits(), best_mps);
    assert_eq!(lapped["reward_mps"].as_f64().unwrap().to_bits(), best_mps);
    // An older file, without its base line: the race's summary beside it names it.
    let mut old = best.clone();
    old.as_object_mut().unwrap().remove("base_line");
    std::fs::write(dir.join("r/old.json"), old.to_string()).unwrap();
    let again = json(&ok(&dir, &["lap", "--policy", "r/old.json", "--json"]));
    assert_eq!(again["reward_mps"], lapped["reward_mps"]);
}

/// `cdbo ceiling --line min-curvature --json` tracks the line's limit and names the centre
/// line's beside it, the limits `cdbo limit --json` prints for both; on the centre line no
/// second limit is written (on the oval, [`common::OVAL`]).
#[test]
fn the_ceiling_on_the_line_names_both_limits() {
    let dir = fresh_dir("ceiling-line");
    std::fs::write(dir.join("oval.xml"), common::OVAL).unwrap();
    let limit = json(&ok(&dir, &["limit", "--track", "oval.xml", "--json"]));
    let on_line = json(&ok(
        &dir,
        &[
            "ceiling",
            "--track",
            "oval.xml",
            "--kernels",
            "6",
            "--steering",
            "tracker",
            "--line",
            "min-curvature",
            "--json",
        ],
    ));
    assert_eq!(on_line["centre_line_limit_mps"], limit["reward_mps"]);
    assert_eq!(
        on_line["limit_mps"],
        limit["min_curvature_line"]["reward_mps"]
    );
    let tracked = on_line["tracked_mps"].as_f64().unwrap();
    assert!(tracked > 0.0 && tracked < on_line["limit_mps"].as_f64().unwrap());
    let centre = json(&ok(
        &dir,
        &["ceiling", "--track", "oval.xml", "--kernels", "6", "--json"],
    ));
    assert_eq!(centre["limit_mps"], limit["reward_mps"]);
    assert!(centre.get("centre_line_limit_mps").is_none(), "{centre}");
}

/// `cdbo ceiling --out FILE` writes the fitted policy with its line and steering, and `cdbo lap
/// --policy FILE` drives the ceiling's lap again to the last bit; where no fitted policy
/// completes (2 kernels) the command fails naming the file and writes nothing.
#[test]
fn the_ceilings_policy_is_written_and_drives_its_lap() {
    let dir = fresh_dir("ceiling-out");
    let ceiling = json(&ok(
        &dir,
        &[
            "ceiling",
            "--kernels",
            "30",
            "--steering",
            "tracker",
            "--line",
            "min-curvature",
            "--out",
            "c.json",
            "--json",
        ],
    ));
    let file = json(&std::fs::read_to_string(dir.join("c.json")).unwrap());
    assert_eq!(file["base_line"], "min-curvature");
    assert_eq!(file["steering"], "tracker");
    assert_eq!(file["weights"].as_array().unwrap().len(), 30);
    let lap = json(&ok(&dir, &["lap", "--policy", "c.json", "--json"]));
    assert_eq!(lap["reward_mps"], ceiling["policy_mps"]);
    // A fit that completes no lap: refused in one line naming the file, nothing written, and
    // the ceiling's figures still printed.
    let args = ["ceiling", "--kernels", "2", "--out", "none.json"];
    refused(&dir, &args, &["none.json", "no fitted policy"]);
    assert!(!dir.join("none.json").exists());
    let printed = String::from_utf8_lossy(&common::cdbo(&dir, &args).stdout).into_owned();
    assert!(
        printed.contains("limit") && printed.contains("none completes within"),
        "{printed}"
    );
}
