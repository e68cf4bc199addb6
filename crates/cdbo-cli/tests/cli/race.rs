//! `cdbo race`: its knobs, budgets, lines, steering, presets and warm starts, what it writes,
//! and one clear error line for what it cannot take.

use std::path::{Path, PathBuf};

use crate::common::{fails_with, json, oval_file, run, scratch, shared, succeed};

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
/// by default, with a best lap faster than the demonstration (its profile start's hold,
/// 25.61 m/s: 32.91 m/s after 27 failed laps), and at most 10 with `--max-failed-laps 10`,
/// with a best lap faster than its first (27.72 m/s: 28.23 m/s).
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
            "--track",
            oval_file(),
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
        let out = run(&["race", "--laps", "2", "--box-radius", bad]);
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
        "--track",
        oval_file(),
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
    let policy = policy.to_str().unwrap();
    let lap = json(&["lap", "--track", oval_file(), "--policy", policy, "--json"]);
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
        "--track",
        oval_file(),
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
        let args = ["race", "--track", oval_file(), "--laps", "3"];
        let args = [&args[..], &["--method", method, "--out", dir]].concat();
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
        let mut args = vec!["race", "--track", oval_file(), "--laps", "30"];
        args.extend(["--out", out.to_str().unwrap()]);
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
    let long_form = crate::common::FAST_SAFE_FLAGS;
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

/// `race --warm-start` starts from the file's policy: its first lap is the lap that policy
/// drove as the earlier race's best, bit for bit, the kernels come from the file, and the
/// summary says where it started; a file of other kernels than `--kernels` is refused in one
/// line naming the file and both sizes, as is a study's.
#[test]
fn a_race_warm_starts_from_a_policy_file() {
    let (out, learn, warm) = learn_then_warm("warm");
    let common = [
        "race",
        "--track",
        oval_file(),
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
    study_refuses_warm_start(&out, policy, &[policy, "12 kernels", "--kernels is 20"]);
    let _ = std::fs::remove_dir_all(&out);
}

/// The recommended stack's policy asks for a speed: its file carries the target, a lap of it
/// replays the best lap, a race warm-started from it goes on asking for that speed (its first
/// lap the best again), and a study, whose pedal is open loop, refuses it.
#[test]
fn the_recommended_stacks_policy_carries_its_target_speed() {
    let (out, learn, warm) = learn_then_warm("target");
    let common = ["race", "--preset", "fast-safe", "--kernels", "20", "--json"];
    let run = |more: &[&str]| json(&[&common[..], more].concat());
    let learned = run(&["--laps", "20", "--out", learn.to_str().unwrap()]);
    let best = learned["best_reward_mps"].as_f64().unwrap();
    let policy = learn.join("best_policy.json");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&policy).unwrap()).unwrap();
    assert_eq!(file["target"]["span"].as_f64(), Some(0.25), "{file}");
    assert!(file["target"]["profile"].as_array().unwrap().len() > 100);
    let policy = policy.to_str().unwrap();
    let again = json(&["lap", "--policy", policy, "--json"]);
    assert_eq!(again["reward_mps"].as_f64(), Some(best));
    let warm = warm.to_str().unwrap();
    let v = run(&["--laps", "3", "--warm-start", policy, "--out", warm]);
    assert_eq!(v["first_lap_reward_mps"].as_f64(), Some(best));
    study_refuses_warm_start(&out, policy, &[policy, "target speed", "open-loop pedal"]);
    let _ = std::fs::remove_dir_all(&out);
}

/// A test's folder `cdbo-cli-NAME-PID` and in it the runs `learn` and `warm`.
fn learn_then_warm(name: &str) -> (PathBuf, PathBuf, PathBuf) {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-{name}-{}", std::process::id()));
    let (learn, warm) = (out.join("learn"), out.join("warm"));
    (out, learn, warm)
}

/// `study create` with 20 kernels in `out`, warm-started from `policy`, fails naming `what`.
fn study_refuses_warm_start(out: &Path, policy: &str, what: &[&str]) {
    let storage = out.join("warm.cdbo.db");
    let storage = storage.to_str().unwrap();
    fails_with(
        &[
            "study",
            "create",
            "warm",
            "--storage",
            storage,
            "--kernels",
            "20",
            "--warm-start",
            policy,
        ],
        what,
    );
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
