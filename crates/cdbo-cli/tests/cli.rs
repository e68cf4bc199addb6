//! The command line as a user meets it: outputs, JSON keys, and one clear error line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn cdbo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cdbo"))
        .args(args)
        .env("CDBO_DATA_PATH", shared())
        .output()
        .expect("runs")
}

/// The test data beside the repository, through the one helper of the library's tests.
#[path = "../../cdbo/tests/common/shared.rs"]
#[allow(dead_code)]
mod shared_data;

fn shared() -> PathBuf {
    shared_data::shared("")
}

/// Runs and expects success.
fn succeed(args: &[&str]) -> Output {
    let out = cdbo(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&succeed(args).stdout).expect("JSON")
}

/// A scratch file with `content`, unique to this test.
fn scratch(name: &str, content: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

/// Runs, expects failure with exactly one `error:` line containing every `needle`.
fn fails_with(args: &[&str], needles: &[&str]) {
    let out = cdbo(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    for n in needles {
        assert!(errors[0].contains(n), "{:?} lacks {n:?}", errors[0]);
    }
    assert!(!err.contains("panicked"), "{err}");
}

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

/// Ridgeway's 15 m/s demonstration traced (`cdbo lap --trace`, `TAG-demo.csv`) and w0 of 20
/// kernels fitted to it (`cdbo policy fit`, `TAG-w0.json`).
fn fitted_to_the_demonstration(tag: &str) -> (PathBuf, PathBuf) {
    let trace = scratch(&format!("{tag}-demo.csv"), "");
    succeed(&["lap", "--trace", trace.to_str().unwrap()]);
    let w0 = scratch(&format!("{tag}-w0.json"), "");
    let (demo, out) = (trace.to_str().unwrap(), w0.to_str().unwrap());
    succeed(&[
        "policy",
        "fit",
        "--demo",
        demo,
        "--kernels",
        "20",
        "-o",
        out,
    ]);
    (trace, w0)
}

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

#[test]
fn traces_and_plots_are_written() {
    let trace = scratch("lap.csv", "");
    let png = scratch("lap.png", "");
    let svg = scratch("map.svg", "");
    succeed(&[
        "lap",
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&trace).unwrap();
    assert!(text.starts_with("t_s,distance_m,x,speed_mps") && text.lines().count() > 1000);
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    succeed(&[
        "plot",
        "track",
        "ridgeway",
        "-o",
        svg.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let lined = scratch("line.svg", "");
    succeed(&[
        "plot",
        "track",
        "ridgeway",
        "-o",
        lined.to_str().unwrap(),
        "--line",
        "min-curvature",
    ]);
    let text = std::fs::read_to_string(&lined).unwrap();
    assert!(
        text.contains("magenta: the minimum-curvature line"),
        "{text}"
    );
}

const TRACK: &str = r#"<?xml version="1.0"?>
<params name="t">
  <section name="Main Track">
    <attnum name="width" unit="m" val="10"/>
    <section name="Track Segments">
      <section name="s1"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/></section>
      <section name="c1"><attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/></section>
      <section name="s2"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/></section>
      <section name="c2"><attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/></section>
    </section>
  </section>
</params>
"#;

/// A plot into a folder that does not exist names the file and the folder, in one line.
#[test]
fn a_plot_into_a_missing_folder_names_the_path() {
    fails_with(
        &["plot", "track", "ridgeway", "-o", "/missing/dir/x.svg"],
        &["/missing/dir/x.svg", "/missing/dir does not exist"],
    );
    fails_with(
        &["plot", "track", "ridgeway", "-o", "/missing/dir/x.png"],
        &["/missing/dir/x.png", "does not exist"],
    );
}

#[test]
fn a_hand_written_track_file_loads() {
    let p = scratch("oval.xml", TRACK);
    let v = json(&["track", "info", p.to_str().unwrap(), "--json"]);
    assert!(
        (v["length_m"].as_f64().unwrap() - (200.0 + 100.0 * std::f64::consts::PI)).abs() < 1e-6
    );
}

#[test]
fn bad_track_files_give_one_clear_error() {
    let truncated = scratch("truncated.xml", &TRACK[..TRACK.len() / 2]);
    fails_with(
        &["track", "info", truncated.to_str().unwrap()],
        &["truncated.xml"],
    );
    let no_radius = scratch(
        "noradius.xml",
        &TRACK.replacen(r#"<attnum name="radius" unit="m" val="50"/>"#, "", 1),
    );
    fails_with(
        &["track", "info", no_radius.to_str().unwrap()],
        &[
            "noradius.xml",
            "Main Track/Track Segments/c1/radius",
            "missing",
        ],
    );
    let bad_unit = scratch(
        "badunit.xml",
        &TRACK.replacen(r#"unit="deg""#, r#"unit="gradians""#, 1),
    );
    fails_with(
        &["track", "info", bad_unit.to_str().unwrap()],
        &["badunit.xml", "c1/arc", "gradians"],
    );
    let nan = scratch(
        "nan.csv",
        "# x_m,y_m,w_tr_right_m,w_tr_left_m\n0,0,5,5\n1,NaN,5,5\n",
    );
    fails_with(
        &["track", "info", nan.to_str().unwrap()],
        &["nan.csv:3", "NaN"],
    );
    let few = scratch("few.csv", "0,0,5,5\n10,0,5,5\n10,10,5,5\n");
    fails_with(
        &["track", "info", few.to_str().unwrap()],
        &["few.csv", "at least 10 points"],
    );
    fails_with(
        &["track", "info", "atlantis"],
        &["unknown track", "atlantis", "ridgeway"],
    );
    fails_with(
        &["lap", "--car", "no-such-car"],
        &["unknown car", "no-such-car"],
    );
    fails_with(&["lap", "--throttle", "3"], &["--throttle"]);
    fails_with(&["lap", "--demo", "-5"], &["--demo"]);
}

/// A knob a method cannot take is refused before any lap, naming the method and its knob; the
/// older `--sigma0` is refused where the method's knob is not σ₀.
#[test]
fn bad_race_knobs_are_refused_in_one_line() {
    fails_with(
        &["race", "--method", "turbo", "--knob", "3"],
        &["turbo", "length", "(0, 1.6]"],
    );
    fails_with(
        &["race", "--method", "random", "--knob", "-1"],
        &["random", "sigma0"],
    );
    fails_with(
        &["race", "--method", "rembo-5d", "--sigma0", "0.1"],
        &["--sigma0", "rembo-5d", "box", "--knob"],
    );
}

/// The safe pattern search keeps to its own budget: at most 30 failed laps in a 300-lap race
/// by default, with a best lap faster than the demonstration (27.82 m/s), and at most 10 with
/// `--max-failed-laps 10`, with a best lap faster than its first. (Since the built-in car has
/// two rear wheels, sc-spirit-300.xml's roll centres and springs make it oversteer at less
/// throttle, and with 10 failed laps the search stops at 14.86 m/s, just short of the
/// demonstration's 14.96; it reached 26.87 on the single-track car.)
#[test]
#[ignore = "slow: two 300-lap races of the safe pattern search"]
fn the_safe_search_keeps_its_budget_in_a_race() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-safe-{}", std::process::id()));
    for (budget, most, floor) in [
        (None, 30, "demo_reward_mps"),
        (Some("10"), 10, "first_lap_reward_mps"),
    ] {
        let mut args = vec!["race", "--method", "safe-pattern-search", "--json", "--out"];
        args.push(dir.to_str().unwrap());
        if let Some(n) = budget {
            args.extend(["--max-failed-laps", n]);
        }
        let raced = json(&args);
        assert!(raced["failed_laps"].as_u64().unwrap() <= most, "{raced}");
        assert!(
            raced["best_reward_mps"].as_f64().unwrap() > raced[floor].as_f64().unwrap(),
            "{raced}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--box-radius R` is the box every method searches: a pattern search in a box of 0.1 keeps
/// each best weight within 0.1 of w₀, where the default box (1.5, written in the summary)
/// lets the same race move some weight further; a box that is not a positive number is refused.
#[test]
fn the_box_radius_bounds_the_search() {
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cdbo-cli-box-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let farthest = |box_radius: Option<&str>| {
        let mut args = vec![
            "race",
            "--method",
            "pattern-search",
            "--laps",
            "40",
            "--json",
        ];
        args.extend(["--out", out]);
        if let Some(r) = box_radius {
            args.extend(["--box-radius", r]);
        }
        let raced = json(&args);
        let weights = |file: &str| -> Vec<f64> {
            let text = std::fs::read_to_string(dir.join(file)).unwrap();
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            serde_json::from_value(v["weights"].clone()).unwrap()
        };
        let (best, start) = (weights("best_policy.json"), weights("initial_policy.json"));
        let moved = best.iter().zip(&start).map(|(b, s)| (b - s).abs());
        (
            raced["box_radius"].as_f64().unwrap(),
            moved.fold(0.0, f64::max),
        )
    };
    let (radius, moved) = farthest(Some("0.1"));
    assert!(
        radius == 0.1 && (moved - 0.1).abs() < 1e-12,
        "{radius} {moved}: on the box"
    );
    let (radius, moved) = farthest(None);
    assert!(radius == 1.5 && moved > 0.1, "{radius} {moved}");
    for bad in ["0", "-1", "nan", "inf", "1e308", "1000.5"] {
        let out = cdbo(&["race", "--laps", "2", "--box-radius", bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains("--box-radius"),
            "{err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--max-failed-laps 10` caps a race's failed laps at 10 for every kind of method (a
/// learner, the paper's GP method, a random search), where without it the same races fail
/// more; the best lap is still a completed one.
#[test]
#[ignore = "slow: six 60-lap races, each method with and without the cap"]
fn a_failed_lap_budget_caps_the_failed_laps() {
    for method in ["pattern-search", "cdbo", "random"] {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("cdbo-cli-budget-{method}-{}", std::process::id()));
        let race = |budget: Option<&str>| {
            let mut args = vec![
                "race", "--method", method, "--laps", "60", "--json", "--out",
            ];
            args.push(dir.to_str().unwrap());
            if let Some(n) = budget {
                args.extend(["--max-failed-laps", n]);
            }
            json(&args)
        };
        let free = race(None);
        let capped = race(Some("10"));
        assert!(
            free["failed_laps"].as_u64().unwrap() > 10,
            "{method}: {free}"
        );
        assert!(
            capped["failed_laps"].as_u64().unwrap() <= 10,
            "{method}: {capped}"
        );
        assert!(
            capped["best_reward_mps"].as_f64().unwrap() > 0.0,
            "{method}: {capped}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_race_with_a_learned_line_writes_and_drives_it() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-line-{}", std::process::id()));
    let v = json(&[
        "race",
        "--laps",
        "10",
        "--kernels",
        "20",
        "--line",
        "learn",
        "--line-kernels",
        "6",
        "--method",
        "pattern-search",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(v["line_kernels"].as_u64(), Some(6));
    let csv = std::fs::read_to_string(out.join("best_policy.csv")).unwrap();
    assert!(csv.starts_with("x,a,d\n"), "{}", &csv[..20]);
    let policy = out.join("best_policy.json");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&policy).unwrap()).unwrap();
    assert_eq!(file["line"]["weights"].as_array().map(Vec::len), Some(6));
    let lap = json(&["lap", "--policy", policy.to_str().unwrap(), "--json"]);
    assert_eq!(
        lap["reward_mps"].as_f64(),
        v["best_reward_mps"].as_f64(),
        "the best policy drives its lap again"
    );
    fails_with(&["race", "--line-kernels", "6", "--laps", "2"], &["--line"]);
    let _ = std::fs::remove_dir_all(&out);
}

/// A race's summary says how it drove (simulator, steering, off-track margin), and its best
/// policy's file drives its lap again with the steering it was raced with, where the PI
/// drives another lap.
#[test]
fn a_race_records_how_it_drove_and_its_policy_replays_so() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-steered-{}", std::process::id()));
    let v = json(&[
        "race",
        "--laps",
        "20",
        "--kernels",
        "20",
        "--steering",
        "tracker",
        "--off-track-margin",
        "0.5",
        "--method",
        "pattern-search",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(v["steering"].as_str(), Some("tracker"));
    assert_eq!(v["off_track_margin_m"].as_f64(), Some(0.5));
    // A margin given is the whole rule: nothing else kept in reserve.
    assert!(v["reserve"].is_null(), "{v}");
    assert_eq!(v["simulator"].as_str(), Some("cdbo"));
    let best = v["best_reward_mps"].as_f64().unwrap();
    assert!(best > 30.0, "{best}");
    let policy = out.join("best_policy.json");
    let text = std::fs::read_to_string(&policy).unwrap();
    assert!(text.contains("\"steering\": \"tracker\""), "{text}");
    let policy = policy.to_str().unwrap();
    let again = json(&[
        "lap",
        "--policy",
        policy,
        "--off-track-margin",
        "0.5",
        "--json",
    ]);
    assert_eq!(again["reward_mps"].as_f64(), Some(best));
    let pi = json(&["lap", "--policy", policy, "--steering", "pi", "--json"]);
    assert_ne!(pi["reward_mps"].as_f64(), Some(best));
    let _ = std::fs::remove_dir_all(&out);
}

/// `--line min-curvature` races on the racing line and says so; `--line-start` is refused
/// without `--line learn`.
#[test]
fn a_race_on_the_min_curvature_line_names_it() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-mincurv-{}", std::process::id()));
    let v = json(&[
        "race",
        "--laps",
        "5",
        "--kernels",
        "20",
        "--line",
        "min-curvature",
        "--steering",
        "tracker",
        "--method",
        "pattern-search",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(v["base_line"].as_str(), Some("min-curvature"));
    assert!(v["best_reward_mps"].as_f64().unwrap() > 0.0);
    fails_with(
        &["race", "--line", "centre", "--line-start", "min-curvature"],
        &["--line-start", "--line learn"],
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_short_race_writes_its_results() {
    // 20 kernels: since the gearbox shifts at the current throttle, the 10-kernel fit of the
    // demonstration laps Ridgeway at 8.8 m/s (its smoothed pedal climbs the gears), 20 at 15.4.
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-{}", std::process::id()));
    let args = &[
        "race",
        "--laps",
        "15",
        "--kernels",
        "20",
        "--seed",
        "3",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    let v = json(args);
    // Learning in cdbo's simulator keeps a reserve unless told otherwise, the robust learner
    // a transfer to the game asks for: the wheels 0.25 m off slippery ground, the body 1 m off the
    // walls, and on a road whose verges are not known (this one) the car's centre 1 m inside
    // its edge.
    assert_eq!(v["off_track_margin_m"].as_f64(), Some(-1.0));
    assert_eq!(v["reserve"]["wheels_m"].as_f64(), Some(0.25));
    assert_eq!(v["reserve"]["body_m"].as_f64(), Some(1.0));
    for key in [
        "method",
        "track",
        "kernels",
        "laps",
        "seed",
        "demo_reward_mps",
        "best_reward_mps",
        "best_lap_time_s",
        "limit_reward_mps",
        "wall_s",
        "optimizer_s",
        "simulator_s",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    let (best, demo, limit) = (
        v["best_reward_mps"].as_f64().unwrap(),
        v["demo_reward_mps"].as_f64().unwrap(),
        v["limit_reward_mps"].as_f64().unwrap(),
    );
    // At least the start's lap, the demonstration's 20-kernel fit: within 2 % of it (1.4 %
    // slower on this seed).
    assert!(
        best >= demo * 0.98 && best < limit,
        "best {best}, demo {demo}, limit {limit}"
    );
    let laps = std::fs::read_to_string(out.join("laps.csv")).unwrap();
    assert_eq!(laps.lines().count(), 16);
    assert!(
        laps.starts_with(
            "lap,reward_mps,best_mps,lap_time_s,failure,x_fail,optimizer_s,simulator_s"
        )
    );
    let policy: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("best_policy.json")).unwrap())
            .unwrap();
    assert_eq!(policy["weights"].as_array().unwrap().len(), 20);
    assert!(
        std::fs::read_to_string(out.join("best_policy.csv"))
            .unwrap()
            .lines()
            .count()
            > 100
    );
    // Same seed, same race.
    let again = json(args);
    assert_eq!(again["best_reward_mps"], v["best_reward_mps"]);
    let _ = std::fs::remove_dir_all(&out);
}

/// A race's line says by which rule its laps failed, as it applies on the track: the reserve
/// where the track gives its road's verges (Forza), the car's centre a metre inside the edge
/// where it does not (the built-in Ridgeway: no grass or walls to keep off), the game's rule
/// when told.
#[test]
fn a_race_says_by_which_rule_its_laps_failed() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-rule-{}", std::process::id()));
    let dir = out.to_str().unwrap();
    let race = |extra: &[&str]| {
        let mut args = vec!["race", "--laps", "2", "--kernels", "10", "--out", dir];
        args.extend_from_slice(extra);
        String::from_utf8(succeed(&args).stdout).unwrap()
    };
    let reserve =
        "laps failed keeping the wheels 0.25 m off slippery ground and the body 1 m off the walls";
    let forza = race(&["--data-dir", shared().to_str().unwrap(), "--track", "forza"]);
    assert!(forza.contains(reserve), "{forza}");
    let ridgeway = race(&[]);
    assert!(
        ridgeway.contains("laps failed at 1 m inside the road's edge"),
        "{ridgeway}"
    );
    let game = race(&["--off-track-margin", "1"]);
    assert!(
        game.contains("laps failed at 1 m past the road's edge, the game's rule"),
        "{game}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_cdbo_race_points_to_the_recommended_stack() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-hint-{}", std::process::id()));
    let dir = out.to_str().unwrap();
    let race = |method: &str| {
        let args = ["race", "--laps", "3", "--method", method, "--out", dir];
        String::from_utf8(succeed(&args).stdout).unwrap()
    };
    let hint = "`cdbo race --preset fast-safe`";
    assert!(race("cdbo").contains(hint));
    assert!(!race("pattern-search").contains(hint));
    let _ = std::fs::remove_dir_all(&out);
}

/// `--preset fast-safe` races as its long form, `--method safe-pattern-search --steering
/// tracker --line min-curvature`, bit for bit: the same best reward and the same laps, and the
/// summary names the stack; the preset keeps `--max-failed-laps`; beside a flag it sets, it is
/// refused in one line naming both.
#[test]
fn the_fast_safe_preset_races_as_its_long_form() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-preset-{}", std::process::id()));
    let race = |name: &str, stack: &[&str]| -> (serde_json::Value, String) {
        let out = dir.join(name);
        let mut args = vec!["race", "--laps", "30", "--out", out.to_str().unwrap()];
        args.extend(stack);
        succeed(&args);
        let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
        let laps = std::fs::read_to_string(out.join("laps.csv")).unwrap();
        // Every column but the two timings.
        let laps = laps
            .lines()
            .map(|l| l.rsplitn(3, ',').nth(2).unwrap().to_owned() + "\n")
            .collect();
        (serde_json::from_str(&summary).unwrap(), laps)
    };
    let (preset, preset_laps) = race("preset", &["--preset", "fast-safe"]);
    let long_form = [
        "--method",
        "safe-pattern-search",
        "--steering",
        "tracker",
        "--line",
        "min-curvature",
    ];
    let (long, long_laps) = race("long", &long_form);
    let bits = |v: &serde_json::Value| v["best_reward_mps"].as_f64().unwrap().to_bits();
    assert_eq!(bits(&preset), bits(&long));
    assert_eq!(preset_laps, long_laps);
    assert_eq!(preset_laps.lines().count(), 31, "{preset_laps}");
    for (key, value) in [
        ("method", "safe-pattern-search"),
        ("steering", "tracker"),
        ("base_line", "min-curvature"),
    ] {
        assert_eq!(preset[key], value, "{preset}");
    }
    let (paper, paper_laps) = race("paper", &[]);
    assert_ne!(bits(&paper), bits(&preset));
    assert_ne!(paper_laps, preset_laps);
    let (budget, _) = race(
        "budget",
        &["--preset", "fast-safe", "--max-failed-laps", "2"],
    );
    assert_eq!(budget["max_failed_laps"], 2);
    assert!(budget["failed_laps"].as_u64().unwrap() <= 2, "{budget}");
    for given in [
        ["--method", "cdbo"],
        ["--steering", "pi"],
        ["--line", "centre"],
        ["--line-start", "centre"],
        ["--line-kernels", "4"],
    ] {
        let args = [
            &["race", "--laps", "3", "--preset", "fast-safe"][..],
            &given,
        ]
        .concat();
        fails_with(&args, &["--preset", given[0]]);
    }
    fails_with(&["race", "--preset", "fastest"], &["fastest", "fast-safe"]);
    let _ = std::fs::remove_dir_all(&dir);
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
fn a_race_draws_its_figures() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-plots-{}", std::process::id()));
    succeed(&[
        "race",
        "--laps",
        "12",
        "--kernels",
        "8",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    for name in ["learning_curve", "policy", "speed", "map"] {
        assert_eq!(
            &std::fs::read(out.join(format!("{name}.png"))).unwrap()[1..4],
            b"PNG",
            "{name}"
        );
        assert!(
            std::fs::read_to_string(out.join(format!("{name}.svg")))
                .unwrap()
                .contains("<svg"),
            "{name}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
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

#[test]
fn dashboard_refuses_bad_sources_and_a_port_in_use_in_one_line() {
    let missing = scratch("dash-gone", "");
    std::fs::remove_file(&missing).unwrap();
    let missing = missing.to_str().unwrap();
    fails_with(&["dashboard", "--db", missing], &[missing, "no such study"]);
    let words = scratch("dash-notes.txt", "not a study, only words\n");
    let words = words.to_str().unwrap();
    fails_with(&["dashboard", "--db", words], &[words, "not a cdbo study"]);
    fails_with(
        &["dashboard", "--experiment", missing],
        &[missing, "no such folder"],
    );
    fails_with(&["dashboard"], &["nothing to show"]);
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let dir = env!("CARGO_TARGET_TMPDIR").to_owned();
    fails_with(
        &["dashboard", "--experiment", &dir, "--bind", &addr],
        &[&addr, "in use"],
    );
    fails_with(
        &["dashboard", "--experiment", &dir, "--bind", "localhost"],
        &["--bind", "localhost", "an address and port"],
    );
}

/// Runs, expects failure with stderr exactly one `error:` line refusing `input` as larger than
/// `bound` (e.g. `16 MiB`).
fn refused_as_too_large(args: &[&str], input: &str, bound: &str) {
    let out = cdbo(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{args:?}: not one line: {err}");
    assert!(lines[0].starts_with("error: "), "{args:?}: {err}");
    assert!(
        lines[0].contains(input)
            && lines[0].ends_with(&format!("is larger than its bound of {bound}")),
        "{args:?}: {:?} does not refuse {input} past {bound}",
        lines[0]
    );
}

/// Every file a command reads is read through its bound: an endless one (`/dev/zero`,
/// `/dev/urandom`, or a link to them named as the flag expects) and one past its bound
/// (a sparse file, as a car's category or a track's included entity) are refused in one line
/// naming the file and the bound, instead of being read forever.
#[test]
fn endless_input_files_are_refused_at_their_bound() {
    let dir = scratch("endless", "")
        .parent()
        .unwrap()
        .join("endless-files");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let zero = |name: &str| {
        let p = dir.join(name);
        std::os::unix::fs::symlink("/dev/zero", &p).unwrap();
        p.to_str().unwrap().to_owned()
    };
    let (json, xml, csv) = (zero("zero.json"), zero("zero.xml"), zero("zero.csv"));
    let out = dir.join("out.json");
    let out = out.to_str().unwrap();

    refused_as_too_large(
        &["lap", "--policy", "/dev/urandom"],
        "/dev/urandom: the policy table",
        "64 MiB",
    );
    refused_as_too_large(
        &["lap", "--policy", &json],
        "zero.json: the policy file",
        "1 MiB",
    );
    refused_as_too_large(
        &["lap", "--track", &xml],
        "zero.xml: the track file",
        "16 MiB",
    );
    refused_as_too_large(
        &["lap", "--track", &csv],
        "zero.csv: the track centre-line file",
        "64 MiB",
    );
    refused_as_too_large(&["lap", "--car", &xml], "zero.xml: the car file", "16 MiB");
    refused_as_too_large(
        &["experiment", "/dev/zero"],
        "/dev/zero: the experiment grid file",
        "1 MiB",
    );
    refused_as_too_large(
        &[
            "policy",
            "fit",
            "--demo",
            "/dev/zero",
            "--kernels",
            "10",
            "-o",
            out,
        ],
        "/dev/zero: the demonstration file",
        "256 MiB",
    );
    refused_as_too_large(
        &["policy", "table", "/dev/zero"],
        "/dev/zero: the policy file",
        "1 MiB",
    );
    refused_as_too_large(
        &[
            "study",
            "create",
            "s",
            "--kernels",
            "6",
            "--demo",
            "/dev/zero",
        ],
        "/dev/zero: the demonstration file",
        "256 MiB",
    );
    refused_as_too_large(
        &[
            "plot",
            "track",
            "ridgeway",
            "-o",
            out,
            "--trace",
            "/dev/zero",
        ],
        "/dev/zero: the trace file",
        "256 MiB",
    );
    std::fs::create_dir_all(dir.join("grid/runs")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.join("grid/runs/run.json")).unwrap();
    refused_as_too_large(
        &["report", dir.join("grid").to_str().unwrap()],
        "run.json: the run record",
        "64 MiB",
    );

    // Files past their bound where only a regular file is read: a car's category file and a
    // track's included entity, each a sparse file of 16 MiB and one byte.
    let sparse = |path: &Path| {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::File::create(path)
            .and_then(|f| f.set_len((16 << 20) + 1))
            .unwrap();
    };
    sparse(&dir.join("categories/big.xml"));
    let car = dir.join("cars/c/c.xml");
    std::fs::create_dir_all(car.parent().unwrap()).unwrap();
    std::fs::write(
        &car,
        r#"<params name="c"><section name="Car"><attstr name="category" val="big"/></section></params>"#,
    )
    .unwrap();
    refused_as_too_large(
        &["lap", "--car", car.to_str().unwrap()],
        "big.xml: the car category file",
        "16 MiB",
    );
    sparse(&dir.join("tracks/surfaces.xml"));
    let track = dir.join("tracks/t.xml");
    std::fs::write(
        &track,
        TRACK.replacen(
            "<params name=\"t\">",
            "<!DOCTYPE params SYSTEM \"params.dtd\" [\n<!ENTITY surfaces SYSTEM \"surfaces.xml\">\n]>\n<params name=\"t\">&surfaces;",
            1,
        ),
    )
    .unwrap();
    refused_as_too_large(
        &["track", "info", track.to_str().unwrap()],
        "surfaces.xml: the included entity file",
        "16 MiB",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `race --warm-start` starts from the file's policy: its first lap is the lap that policy
/// drove as the earlier race's best, bit for bit, the kernels come from the file, and the
/// summary says where it started; a file of other kernels than `--kernels` is refused in one
/// line naming the file and both sizes, as is a study's.
#[test]
fn a_race_warm_starts_from_a_policy_file() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-warm-{}", std::process::id()));
    let (learn, warm) = (out.join("learn"), out.join("warm"));
    let common = [
        "race",
        "--method",
        "pattern-search",
        "--seed",
        "2",
        "--json",
    ];
    let learned = json(
        &[
            &common[..],
            &[
                "--kernels",
                "12",
                "--laps",
                "20",
                "--out",
                learn.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    let policy = learn.join("best_policy.json");
    let policy = policy.to_str().unwrap();
    let v = json(
        &[
            &common[..],
            &[
                "--laps",
                "3",
                "--warm-start",
                policy,
                "--out",
                warm.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert_eq!(v["kernels"], 12);
    assert_eq!(v["warm_start"], policy);
    assert_eq!(v["first_lap_reward_mps"], learned["best_reward_mps"]);
    assert!(learned.get("warm_start").is_none());
    fails_with(
        &["race", "--kernels", "20", "--warm-start", policy],
        &[policy, "12 kernels", "20 kernels"],
    );
    fails_with(
        &[
            "study",
            "create",
            "warm",
            "--storage",
            out.join("warm.cdbo.db").to_str().unwrap(),
            "--kernels",
            "20",
            "--warm-start",
            policy,
        ],
        &[policy, "12 kernels", "--kernels is 20"],
    );
    let _ = std::fs::remove_dir_all(&out);
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
        cdbo(&[
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

/// A `.csv` circuit with a road of width 0, a centre line that crosses itself, or fewer than
/// 10 points is refused by `race` in one line naming the file, and no run folder is made.
#[test]
fn a_bad_csv_circuit_gets_one_line_and_no_run_folder() {
    let point = |i: usize, n: usize, widths: &str, eight: bool| {
        let a = i as f64 / n as f64 * std::f64::consts::TAU;
        let (x, y) = if eight {
            (300.0 * a.sin(), 150.0 * (2.0 * a).sin())
        } else {
            (200.0 * a.cos(), 200.0 * a.sin())
        };
        format!("{x},{y},{widths}\n")
    };
    let circuit = |n: usize, widths: &str, eight: bool| {
        (0..n).fold(
            String::from("# x_m,y_m,w_tr_right_m,w_tr_left_m\n"),
            |s, i| s + &point(i, n, widths, eight),
        )
    };
    let bad = [
        (
            "width0.csv",
            circuit(60, "0,0", false),
            "track widths must be positive",
        ),
        (
            "crossing.csv",
            circuit(60, "5,5", true),
            "the centre line crosses itself",
        ),
        (
            "few.csv",
            circuit(8, "5,5", false),
            "at least 10 points, found 8",
        ),
    ];
    for (name, content, needle) in bad {
        let file = scratch(name, &content);
        let out = file.with_extension("run");
        let args = [
            "race",
            "--track",
            file.to_str().unwrap(),
            "--laps",
            "2",
            "--out",
            out.to_str().unwrap(),
        ];
        fails_with(&args, &[file.to_str().unwrap(), needle]);
        assert!(!out.exists(), "{name}: made {}", out.display());
    }
}
