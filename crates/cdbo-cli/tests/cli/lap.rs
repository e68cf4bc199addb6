//! A lap, a track's figures, the limit, a replay and a policy's table as the user meets them:
//! outputs, JSON keys, and one clear error line.

use crate::common::{fails_with, fitted_to_the_demonstration, json, scratch, succeed};

#[test]
fn track_info_reports_the_papers_lengths() {
    let v = json(&["track", "info", "forza", "--json"]);
    assert!((v["length_m"].as_f64().unwrap() - 5784.1).abs() < 0.5);
    assert_eq!(v["width_m"].as_f64(), Some(11.0));
    for key in ["name", "min_radius_m", "z_min_m", "z_max_m"] {
        assert!(v.get(key).is_some(), "{key}");
    }
}

#[test]
fn a_demo_lap_reports_reward_and_limit() {
    let v = json(&["lap", "--demo", "15", "--json"]);
    assert_eq!(v["completed"], true);
    assert!(v["failure"].is_null());
    let (reward, limit) = (
        v["reward_mps"].as_f64().unwrap(),
        v["limit_reward_mps"].as_f64().unwrap(),
    );
    assert!((14.0..15.5).contains(&reward) && limit > reward);
    let t = v["lap_time_s"].as_f64().unwrap();
    assert!((t * reward - 3595.9).abs() < 1.0, "L = R·T");
    assert!(v["limit_lap_time_s"].as_f64().unwrap() < t);
}

#[test]
fn the_path_tracker_drives_a_lap_and_lifts_the_ceiling() {
    let pi = json(&["lap", "--json"]);
    let tracker = json(&["lap", "--steering", "tracker", "--json"]);
    assert_eq!(tracker["completed"], true);
    let ceiling = |v: &serde_json::Value| v["ceiling_reward_mps"].as_f64().unwrap();
    assert!(
        ceiling(&tracker) > ceiling(&pi) + 5.0,
        "{} against {}",
        ceiling(&tracker),
        ceiling(&pi)
    );
}

#[test]
fn full_throttle_on_forza_names_where_it_failed() {
    let v = json(&["lap", "--track", "forza", "--throttle", "1", "--json"]);
    assert_eq!(v["completed"], false);
    assert_eq!(v["reward_mps"].as_f64(), Some(0.0));
    let x = v["failure"]["x"].as_f64().unwrap();
    assert!(x > 0.0 && x < 1.0);
    assert!(v["failure"]["reason"].is_string() && v["failure"]["distance_m"].is_number());
}

/// `--off-track-margin`: full throttle round Ridgeway leaves the road where the car's centre
/// passes the margin beyond the edge, so a stricter margin fails the lap sooner, by about the
/// margin's difference over the car's drift (metres, not the lap); the demonstration, which
/// holds the centre, completes with the car kept 3 m inside the edges; without the flag a lap
/// is judged by the game's rule, 1 m; a margin past the bound is refused naming the flag.
#[test]
fn the_off_track_margin_moves_where_a_lap_leaves_the_road() {
    let at = |margin: &str| {
        let v = json(&[
            "lap",
            "--throttle",
            "1",
            "--off-track-margin",
            margin,
            "--json",
        ]);
        assert_eq!(v["failure"]["reason"], "off_track", "{v}");
        v["failure"]["distance_m"].as_f64().unwrap()
    };
    let (inside, rule, outside) = (at("-1"), at("1"), at("3"));
    assert!(inside < rule && rule < outside, "{inside} {rule} {outside}");
    // A lap is judged by the game's rule unless told otherwise (a race learns inside it).
    let judged = json(&["lap", "--throttle", "1", "--json"]);
    assert_eq!(judged["failure"]["distance_m"].as_f64(), Some(rule));
    assert!(outside - inside < 50.0, "{inside} {outside}");
    let demo = json(&["lap", "--demo", "15", "--off-track-margin", "-3", "--json"]);
    assert_eq!(demo["completed"], true);
    fails_with(
        &["lap", "--off-track-margin", "-4"],
        &["--off-track-margin", "[-3, 5]"],
    );
}

#[test]
fn limit_and_bench_print_their_keys() {
    let v = json(&["limit", "--json"]);
    assert!(v["lap_time_s"].as_f64().unwrap() > 0.0 && v["reward_mps"].as_f64().unwrap() > 0.0);
    // The minimum-curvature line's limit beside it, its speed the centre line's length over
    // its lap time.
    let line = &v["min_curvature_line"];
    let (t, r) = (
        line["lap_time_s"].as_f64().unwrap(),
        line["reward_mps"].as_f64().unwrap(),
    );
    assert!(t < v["lap_time_s"].as_f64().unwrap(), "{line}");
    assert!(
        (r * t - v["track_length_m"].as_f64().unwrap()).abs() < 1e-6,
        "{line}"
    );
    for key in ["line_length_m", "max_offset_m", "margin_m", "iterations"] {
        assert!(line[key].as_f64().unwrap() > 0.0, "{key}");
    }
    let v = json(&["bench", "sim", "--laps", "1", "--json"]);
    for key in ["laps", "simulated_s", "wall_s", "realtime_factor"] {
        assert!(v[key].as_f64().unwrap() > 0.0, "{key}");
    }
}

#[test]
fn a_traced_lap_replays_through_the_model_window_by_window() {
    let trace = scratch("replayed.csv", "");
    succeed(&["lap", "--trace", trace.to_str().unwrap()]);
    let v = json(&["replay", "--log", trace.to_str().unwrap(), "--json"]);
    let lap = &v[0];
    // Ridgeway's 15 m/s lap, a window every 0.5 s: its own commands give it back.
    let windows = lap["windows"].as_array().unwrap();
    assert!(windows.len() > 300, "{}", windows.len());
    assert!(lap["yaw_rate_rms"].as_f64().unwrap() < 0.003, "{lap}");
    assert!(lap["mean_abs_lateral_m"].as_f64().unwrap() < 0.01, "{lap}");
    let text = String::from_utf8(
        succeed(&["replay", "--log", trace.to_str().unwrap(), "--worst", "3"]).stdout,
    )
    .unwrap();
    assert!(
        text.contains("where they part most")
            && text.contains("| driving |")
            && text.lines().count() == 13,
        "{text}"
    );
    // A log without the steering it applied cannot be replayed: one line says so.
    let pedal_only = scratch(
        "pedal-only.csv",
        "t_s,distance_m,speed_mps,lateral_m,yaw_rate_rms,pedal\n0,0,0,0,0,1\n",
    );
    fails_with(
        &["replay", "--log", pedal_only.to_str().unwrap()],
        &["pedal-only.csv", "yaw_rate_rad_s", "missing"],
    );
    let text = std::fs::read_to_string(&trace).unwrap();
    let no_steer: String = text
        .lines()
        .map(|l| l.replace("steer_rad", "wheel_rad"))
        .collect::<Vec<_>>()
        .join("\n");
    let no_steer_file = scratch("no-steer.csv", &no_steer);
    fails_with(
        &["replay", "--log", no_steer_file.to_str().unwrap()],
        &["no-steer.csv", "lap 0", "t_s and steer_rad"],
    );
    fails_with(
        &["replay", "--log", trace.to_str().unwrap(), "--window", "0"],
        &["--window"],
    );
}

#[test]
fn policies_fit_to_a_trace_and_print_tables() {
    let (trace, weights) = fitted_to_the_demonstration("table");
    let out = succeed(&[
        "policy",
        "table",
        weights.to_str().unwrap(),
        "--points",
        "11",
    ]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert_eq!(table.lines().count(), 12);
    // The fitted table drives the car round like the demonstration did.
    let csv = scratch("table.csv", &table);
    let v = json(&["lap", "--policy", csv.to_str().unwrap(), "--json"]);
    assert!(v["completed"].as_bool().unwrap() || v["failure"]["x"].as_f64().unwrap() > 0.0);
    fails_with(
        &[
            "policy",
            "fit",
            "--demo",
            trace.to_str().unwrap(),
            "--kernels",
            "1",
            "-o",
            weights.to_str().unwrap(),
        ],
        &["--kernels", "at least 2"],
    );
    let empty = scratch("empty.csv", "x,a\n");
    fails_with(
        &[
            "policy",
            "fit",
            "--demo",
            empty.to_str().unwrap(),
            "--kernels",
            "5",
            "-o",
            weights.to_str().unwrap(),
        ],
        &["empty"],
    );
}

#[test]
fn bench_suggest_reports_its_keys() {
    let v = json(&[
        "bench",
        "suggest",
        "--observations",
        "30",
        "--dims",
        "8",
        "--repeats",
        "3",
        "--json",
    ]);
    for key in [
        "median_ms",
        "p90_ms",
        "observations",
        "dims",
        "af_evals_per_suggest",
        "refit_ms",
    ] {
        assert!(v[key].as_f64().is_some(), "{key}");
    }
}

#[test]
fn bench_optimizers_compares_every_method() {
    let v = json(&[
        "bench",
        "optimizers",
        "--problem",
        "ackley",
        "--dims",
        "5",
        "--evals",
        "15",
        "--seeds",
        "2",
        "--json",
    ]);
    let results = v["results"].as_array().unwrap();
    let methods: Vec<&str> = results
        .iter()
        .map(|r| r["method"].as_str().unwrap())
        .collect();
    assert_eq!(methods, cdbo::method::Method::ALL.map(|m| m.name()));
    for r in results {
        assert!(
            r["mean_best"].as_f64().unwrap() <= 0.0 && r["stderr_best"].as_f64().unwrap() >= 0.0
        );
    }
    fails_with(
        &["bench", "optimizers", "--problem", "nope"],
        &["unknown problem", "hartmann6"],
    );
    fails_with(
        &["bench", "optimizers", "--methods", "simplex"],
        &["invalid value 'simplex'", "cdbo", "pattern-search"],
    );
}
