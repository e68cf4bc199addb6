//! `cdbo bench circuits`: a folder of circuits raced with each stack, one row each, the same
//! races `cdbo race` runs.

use crate::common::{fresh_dir, json, run};

/// An ellipse of half-axes `a` and `b` metres, 12 m wide, as a TUMFTM `.csv` centre line.
fn ellipse(a: f64, b: f64) -> String {
    (0..120).fold(
        String::from("# x_m,y_m,w_tr_right_m,w_tr_left_m\n"),
        |s, i| {
            let t = i as f64 / 120.0 * std::f64::consts::TAU;
            s + &format!("{},{},6,6\n", a * t.cos(), b * t.sin())
        },
    )
}

#[test]
fn every_circuit_of_a_folder_is_raced_with_each_stack_as_race_races_it() {
    let dir = fresh_dir("two");
    std::fs::write(dir.join("Round.csv"), ellipse(150.0, 150.0)).unwrap();
    std::fs::write(dir.join("Long.csv"), ellipse(300.0, 120.0)).unwrap();
    std::fs::write(dir.join("notes.txt"), "not a track").unwrap();
    let report = json(&[
        "bench",
        "circuits",
        dir.to_str().unwrap(),
        "--stacks",
        "fast-safe,pattern-search",
        "--laps",
        "12",
        "--seed",
        "3",
        "--jobs",
        "2",
        "--json",
    ]);
    let rows = report["rows"].as_array().unwrap();
    let names: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r["circuit"].as_str().unwrap(), r["stack"].as_str().unwrap()))
        .collect();
    assert_eq!(
        names,
        [
            ("Long", "fast-safe"),
            ("Long", "pattern-search"),
            ("Round", "fast-safe"),
            ("Round", "pattern-search"),
        ]
    );
    for row in rows {
        assert_eq!(row["started"], 1, "{row}");
        assert!(row["first_completed_lap"].as_u64().is_some(), "{row}");
        let share = row["best_of_limit"].as_f64().unwrap();
        assert!(share > 0.2 && share < 1.5, "{row}");
    }
    // Each run is the race `cdbo race` runs with the same stack, bit for bit.
    for run in report["runs"].as_array().unwrap() {
        let file = dir.join(format!("{}.csv", run["circuit"].as_str().unwrap()));
        let stack = run["stack"].as_str().unwrap();
        let flag = if stack == "fast-safe" {
            "--preset"
        } else {
            "--method"
        };
        let out = fresh_dir(&format!(
            "race-{}-{stack}",
            run["circuit"].as_str().unwrap()
        ));
        let summary = json(&[
            "race",
            "--track",
            file.to_str().unwrap(),
            flag,
            stack,
            "--laps",
            "12",
            "--seed",
            "3",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(run["seed"], 3, "{run}");
        assert_eq!(run["best_mps"], summary["best_reward_mps"], "{run}");
        assert_eq!(run["failed_laps"], summary["failed_laps"], "{run}");
    }
}

#[test]
fn a_folder_without_circuits_and_an_unknown_stack_get_one_clear_line() {
    let dir = fresh_dir("empty");
    let out = run(&["bench", "circuits", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("no track in this folder"), "{err}");
    let out = run(&["bench", "circuits", "ridgeway", "--stacks", "fastest"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("\"fastest\" is neither a preset (fast-safe, fast) nor a method"),
        "{err}"
    );
}
