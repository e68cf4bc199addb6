//! `cdbo experiment` and `cdbo report`: results independent of --jobs, shards that partition
//! the grid and merge, resuming by skipping finished runs, and clear errors.

use std::path::{Path, PathBuf};

mod common;

use common::{cdbo, fresh_dir, ok};

const GRID: &str = r#"
laps = 8
repeats = 2
methods = ["cdbo", "random"]

[[tracks]]
track = "oval.xml"
kernels = [6]
"#;

/// A fresh folder with the grid of 4 runs on the oval ([`common::OVAL`]), `grid.toml`.
fn setup(name: &str) -> PathBuf {
    let dir = fresh_dir(name);
    std::fs::write(dir.join("grid.toml"), GRID).unwrap();
    std::fs::write(dir.join("oval.xml"), common::OVAL).unwrap();
    dir
}

/// [`setup`]'s grid of CDBO alone on Ridgeway (2 runs), whose ceiling in a run record is the
/// one `cdbo ceiling` prints.
fn setup_cdbo_on_ridgeway(name: &str) -> PathBuf {
    let dir = fresh_dir(name);
    let grid = GRID
        .replace("track = \"oval.xml\"", "track = \"ridgeway\"")
        .replace("methods = [\"cdbo\", \"random\"]", "methods = [\"cdbo\"]");
    std::fs::write(dir.join("grid.toml"), grid).unwrap();
    dir
}

/// The laps of every run in a folder, without the timings.
fn laps(dir: &Path) -> Vec<(String, Vec<(f64, f64)>)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| {
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
            let laps = v["laps"]
                .as_array()
                .unwrap()
                .iter()
                .map(|l| {
                    (
                        l["reward_mps"].as_f64().unwrap(),
                        l["best_mps"].as_f64().unwrap(),
                    )
                })
                .collect();
            (f.file_name().unwrap().to_string_lossy().into_owned(), laps)
        })
        .collect()
}

/// A grid's runs are the same laps one job at a time or two at once in three shards; one
/// method's cells then the rest give them too; the shards' folders merge into one report.
#[test]
fn results_do_not_depend_on_jobs_and_shards_merge() {
    let dir = setup("jobs");
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "one", "--jobs", "1"],
    );
    let one = laps(&dir.join("one"));
    assert_eq!(one.len(), 4);
    // Three shards, two jobs at once (the first shard holds two runs): together the runs of
    // one job.
    for shard in ["0/3", "1/3", "2/3"] {
        let out = format!("s{}", &shard[..1]);
        let args = ["experiment", "grid.toml", "--out", &out, "--shard", shard];
        ok(&dir, &[&args[..], &["--jobs", "2"]].concat());
    }
    assert_eq!(laps(&dir.join("s0")).len(), 2);
    let mut shards: Vec<_> = ["s0", "s1", "s2"]
        .iter()
        .flat_map(|s| laps(&dir.join(s)))
        .collect();
    shards.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(shards, one);
    // One method's cells, then the rest into the same folder: the same runs.
    let only = |methods| {
        [
            "experiment",
            "grid.toml",
            "--out",
            "m",
            "--methods",
            methods,
        ]
    };
    let out = ok(&dir, &only("random"));
    assert!(out.contains("4 runs in the grid, 2 selected"), "{out}");
    assert!(
        laps(&dir.join("m"))
            .iter()
            .all(|(f, _)| f.contains("-random-"))
    );
    let out = ok(&dir, &["experiment", "grid.toml", "--out", "m"]);
    assert!(out.contains("2 already done, 2 to run"), "{out}");
    assert_eq!(laps(&dir.join("m")), one);
    let out = cdbo(&dir, &only("turbo"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("turbo is not a method of the grid"),
        "{err}"
    );
    let out = ok(&dir, &["report", "s0", "s1", "s2", "--out", "merged"]);
    assert!(out.contains("4 runs from 3 folder(s)"), "{out}");
    let results = std::fs::read_to_string(dir.join("merged/results.md")).unwrap();
    assert!(results.contains("| oval.xml | 6 | cdbo | 2 |"), "{results}");
    for f in [
        "curves_oval.xml.png",
        "curves_oval.xml.svg",
        "table1.md",
        "fig3a_policy_oval.xml.svg",
        "tradeoff_oval.xml_6.png",
        "tradeoff_oval.xml_6.svg",
    ] {
        assert!(dir.join("merged").join(f).is_file(), "{f}");
    }
    // The budget line's best with no cap is the table's fastest method, by brute force over
    // the table's rows: | oval.xml | 6 | METHOD | runs | MEAN ± SE | ….
    let (method, best) = results
        .lines()
        .filter_map(|l| l.strip_prefix("| oval.xml | 6 | "))
        .map(|l| {
            let cols: Vec<&str> = l.split(" | ").collect();
            (cols[0], cols[2].split(" ± ").next().unwrap())
        })
        .max_by(|a, b| a.1.parse::<f64>().unwrap().total_cmp(&b.1.parse().unwrap()))
        .unwrap();
    let line = results
        .lines()
        .find(|l| l.starts_with("- oval.xml 6: at most 10 % ("))
        .expect("the panel's budget line");
    assert!(
        line.contains(&format!("no cap: {method} {best} ± ")),
        "{line}"
    );
    assert!(results.contains("(tradeoff_oval.xml_6.png)"), "{results}");
}

/// Every run records the ceiling (the tracked limit profile's lap, as `cdbo ceiling`
/// prints it) and `report` gives the best as % of it; records written before the ceiling was
/// stored still parse, and their cells show no percentage.
#[test]
fn report_gives_the_percentage_of_the_ceiling_and_reads_old_records() {
    let dir = setup_cdbo_on_ridgeway("ceiling");
    ok(&dir, &["experiment", "grid.toml", "--out", "new"]);
    let ceiling = ok(&dir, &["ceiling", "--track", "ridgeway", "--kernels", "6"]);
    let old = dir.join("old/runs");
    std::fs::create_dir_all(&old).unwrap();
    let mut cdbo_best = Vec::new();
    let mut recorded = Vec::new();
    for entry in std::fs::read_dir(dir.join("new/runs")).unwrap() {
        let path = entry.unwrap().path();
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        recorded.push(v["ceiling_reward_mps"].as_f64().unwrap());
        if v["spec"]["method"] == "cdbo" {
            cdbo_best.push(v["best_reward_mps"].as_f64().unwrap());
        }
        v.as_object_mut().unwrap().remove("ceiling_reward_mps");
        std::fs::write(old.join(path.file_name().unwrap()), v.to_string()).unwrap();
    }
    let c = recorded[0];
    assert!(recorded.iter().all(|&r| r == c), "{recorded:?}");
    assert!(ceiling.contains(&format!("{c:.2}")), "{c} not in {ceiling}");
    ok(&dir, &["report", "new", "--out", "new-report"]);
    let results = std::fs::read_to_string(dir.join("new-report/results.md")).unwrap();
    let mean = cdbo_best.iter().sum::<f64>() / cdbo_best.len() as f64;
    let row = results
        .lines()
        .find(|l| l.starts_with("| ridgeway | 6 | cdbo |"))
        .unwrap();
    assert!(
        row.contains(&format!("| {:.1} |", 100.0 * mean / c)),
        "{row} ({mean} of {c})"
    );
    ok(&dir, &["report", "old", "--out", "old-report"]);
    let results = std::fs::read_to_string(dir.join("old-report/results.md")).unwrap();
    let row = results
        .lines()
        .find(|l| l.starts_with("| ridgeway | 6 | cdbo |"))
        .unwrap();
    assert!(row.contains("| – |"), "{row}");
}

#[test]
fn an_interrupted_grid_resumes_with_the_missing_runs() {
    let dir = setup("resume");
    ok(&dir, &["experiment", "grid.toml", "--out", "g"]);
    let before = laps(&dir.join("g"));
    let victim = dir.join("g/runs").join(&before[1].0);
    std::fs::remove_file(&victim).unwrap();
    // A half-written temporary file of a killed run is ignored and replaced.
    std::fs::write(victim.with_extension("json.tmp"), "{\"trunc").unwrap();
    let out = ok(&dir, &["experiment", "grid.toml", "--out", "g"]);
    assert!(out.contains("3 already done, 1 to run"), "{out}");
    assert_eq!(laps(&dir.join("g")), before);
    // A different grid in the same folder is refused.
    std::fs::write(dir.join("other.toml"), GRID.replace("laps = 8", "laps = 9")).unwrap();
    let out = cdbo(&dir, &["experiment", "other.toml", "--out", "g"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("different grid"));
}

#[test]
fn bad_grids_and_shards_are_clear_errors() {
    let dir = setup("bad");
    for (args, needle) in [
        (vec!["experiment", "nope.toml"], "preset"),
        (vec!["experiment", "grid.toml", "--shard", "3/3"], "--shard"),
        (vec!["report", "missing-dir"], "cdbo experiment"),
    ] {
        let out = cdbo(&dir, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(
            err.contains(needle) && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    std::fs::write(dir.join("typo.toml"), GRID.replace("repeats", "repeat")).unwrap();
    let err =
        String::from_utf8_lossy(&cdbo(&dir, &["experiment", "typo.toml"]).stderr).into_owned();
    assert!(err.contains("typo.toml") && err.contains("repeat"), "{err}");
}

/// The runs of a grid in an SQLite file, filled by two workers at once: the same laps as the
/// grid run into a folder, each cell once; the report from the file equals the folder's
/// where it does not time; a finished grid runs nothing more, and a different grid under the
/// same file, a study file or a missing grid are refused.
#[test]
fn workers_fill_a_grid_in_an_sqlite_file() {
    let dir = setup("workers");
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "one", "--jobs", "1"],
    );
    let stored = ok(&dir, &["experiment", "grid.toml", "--storage", "g.db"]);
    assert!(
        stored.contains("4 runs in the grid at g.db: 0 finished"),
        "{stored}"
    );
    let workers: Vec<_> = (0..2)
        .map(|_| {
            let mut worker = std::process::Command::new(common::CDBO);
            worker.args([
                "experiment",
                "grid.toml",
                "--storage",
                "g.db",
                "--worker",
                "--jobs",
                "1",
            ]);
            common::spawn(worker, &dir)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .map(|w| w.wait_with_output().expect("runs"))
        .collect();
    let mut ran = Vec::new();
    for w in &workers {
        assert!(w.status.success(), "{}", String::from_utf8_lossy(&w.stderr));
        let out = String::from_utf8_lossy(&w.stdout);
        ran.extend(
            out.lines()
                .filter_map(|l| l.strip_prefix("ran ")?.split(':').next().map(String::from)),
        );
    }
    ran.sort();
    assert_eq!(ran.len(), 4, "{ran:?}");
    ran.dedup();
    assert_eq!(ran.len(), 4, "a cell ran twice: {ran:?}");
    let again = ok(
        &dir,
        &["experiment", "grid.toml", "--storage", "g.db", "--worker"],
    );
    assert!(again.contains("0 runs done"), "{again}");
    ok(
        &dir,
        &[
            "report",
            "--storage",
            "g.db",
            "--out",
            "rep",
            "--export",
            "exported",
        ],
    );
    assert_eq!(laps(&dir.join("exported")), laps(&dir.join("one")));
    ok(&dir, &["report", "one", "--out", "rep-one"]);
    assert_eq!(
        common::rewards_table(&dir.join("rep")),
        common::rewards_table(&dir.join("rep-one"))
    );
    // Refusals, each one line, nothing written.
    std::fs::write(dir.join("other.toml"), GRID.replace("laps = 8", "laps = 9")).unwrap();
    common::refused(
        &dir,
        &["experiment", "other.toml", "--storage", "g.db", "--worker"],
        &["g.db", "a different grid"],
    );
    ok(&dir, &["report", "--storage", "g.db", "--out", "rep-after"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("rep-after/results.md")).unwrap(),
        std::fs::read_to_string(dir.join("rep/results.md")).unwrap(),
        "the refused worker changed the grid"
    );
    common::demo(&dir);
    ok(&dir, &common::create_study("s", &[]));
    common::refused(
        &dir,
        &[
            "experiment",
            "grid.toml",
            "--storage",
            "s.cdbo.db",
            "--worker",
        ],
        &["s.cdbo.db", "not a cdbo grid", "without a grid"],
    );
    common::refused(
        &dir,
        &["report", "--storage", "none.db"],
        &["none.db", "no such grid"],
    );
    assert!(!dir.join("none.db").exists());
}

/// A grid's `line` races every run as `cdbo race --line` does (the same best, bit for bit);
/// the run record keeps the line's kernels and the joint weights, and the report names the
/// line; a bad line is refused naming the file.
#[test]
fn a_grid_learning_a_line_races_as_race_does() {
    let dir = fresh_dir("grid-line");
    std::fs::write(dir.join("oval.xml"), common::OVAL).unwrap();
    let grid = "laps = 6\nrepeats = 1\nmethods = [\"random\"]\nline = \"learn\"\nline_kernels = 4\n\n[[tracks]]\ntrack = \"oval.xml\"\nkernels = [6]\n";
    std::fs::write(dir.join("grid.toml"), grid).unwrap();
    ok(&dir, &["experiment", "grid.toml", "--out", "g"]);
    let text = std::fs::read_to_string(dir.join("g/runs/oval_xml-m6-random-r0.json")).unwrap();
    let record: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(record["line_kernels"], 4);
    assert_eq!(record["best_weights"].as_array().unwrap().len(), 10);
    let raced = ok(
        &dir,
        &[
            "race",
            "--track",
            "oval.xml",
            "--json",
            "--method",
            "random",
            "--kernels",
            "6",
            "--laps",
            "6",
            "--knob",
            "0.03",
            "--line",
            "learn",
            "--line-kernels",
            "4",
            "--out",
            "r",
        ],
    );
    let raced: serde_json::Value = serde_json::from_str(&raced).unwrap();
    assert_eq!(record["best_reward_mps"], raced["best_reward_mps"]);
    ok(&dir, &["report", "g", "--out", "rep"]);
    let results = std::fs::read_to_string(dir.join("rep/results.md")).unwrap();
    assert!(results.contains("learn-m4 (1 runs)"), "{results}");
    std::fs::write(
        dir.join("bad.toml"),
        grid.replace("line_kernels = 4", "line_start = \"apex\""),
    )
    .unwrap();
    let err = String::from_utf8_lossy(&cdbo(&dir, &["experiment", "bad.toml"]).stderr).into_owned();
    assert!(err.contains("bad.toml") && err.contains("apex"), "{err}");
}

/// A grid's `steering = "tracker"` drives its runs and their ceiling as `cdbo race --steering
/// tracker` does: the same best, ceiling and failed laps, and not those of the PI steering.
#[test]
fn a_grid_steers_with_the_tracker_as_race_does() {
    let dir = fresh_dir("steering");
    std::fs::write(dir.join("oval.xml"), common::OVAL).unwrap();
    let grid = "laps = 8\nrepeats = 1\nmethods = [\"random\"]\nsteering = \"tracker\"\n\
                [[tracks]]\ntrack = \"oval.xml\"\nkernels = [6]\n";
    std::fs::write(dir.join("grid.toml"), grid).unwrap();
    ok(&dir, &["experiment", "grid.toml", "--out", "g"]);
    let run: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("g/runs/oval_xml-m6-random-r0.json")).unwrap(),
    )
    .unwrap();
    let race = |steering: &str| -> serde_json::Value {
        let args = [
            "race",
            "--track",
            "oval.xml",
            "--kernels",
            "6",
            "--laps",
            "8",
            "--method",
            "random",
            "--knob",
            "0.03",
            "--seed",
            "0",
            "--steering",
            steering,
            "--json",
            "--out",
            steering,
        ];
        serde_json::from_str(&ok(&dir, &args)).unwrap()
    };
    let failed = run["laps"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| !l["failure"].is_null())
        .count();
    let tracker = race("tracker");
    assert_eq!(run["best_reward_mps"], tracker["best_reward_mps"]);
    assert_eq!(run["ceiling_reward_mps"], tracker["ceiling_reward_mps"]);
    assert_eq!(failed as u64, tracker["failed_laps"].as_u64().unwrap());
    assert_ne!(run["ceiling_reward_mps"], race("pi")["ceiling_reward_mps"]);
}

/// A grid's `off_track_margin` fails its laps where `cdbo race --off-track-margin` does: the
/// same places, not the default margin's; without it a grid learns with the reserve `cdbo
/// race` takes by default; a margin out of bounds is refused naming the file.
#[test]
fn a_grid_keeps_its_off_track_margin_as_race_does() {
    let dir = fresh_dir("margin");
    let grid = "laps = 8\nrepeats = 1\nmethods = [\"pattern-search\"]\noff_track_margin = 1.0\n\
                [[tracks]]\ntrack = \"ridgeway\"\nkernels = [10]\n";
    let grid_places = |text: &str, out: &str| -> Vec<String> {
        std::fs::write(dir.join("grid.toml"), text).unwrap();
        ok(&dir, &["experiment", "grid.toml", "--out", out]);
        let run: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(
                dir.join(out)
                    .join("runs/ridgeway-m10-pattern-search-r0.json"),
            )
            .unwrap(),
        )
        .unwrap();
        run["laps"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| {
                l["x_fail"]
                    .as_f64()
                    .map_or(String::new(), |x| format!("{x:.5}"))
            })
            .collect()
    };
    let race_places = |margin: Option<&str>| -> Vec<String> {
        let out = format!("margin{}", margin.unwrap_or("default"));
        let mut args = vec![
            "race",
            "--kernels",
            "10",
            "--laps",
            "8",
            "--method",
            "pattern-search",
            "--json",
            "--out",
            &out,
        ];
        if let Some(margin) = margin {
            args.extend(["--off-track-margin", margin]);
        }
        ok(&dir, &args);
        let csv = std::fs::read_to_string(dir.join(&out).join("laps.csv")).unwrap();
        csv.lines()
            .skip(1)
            .map(|l| l.split(',').nth(5).unwrap().to_owned())
            .collect()
    };
    let at_the_rule = grid_places(grid, "g");
    assert_eq!(at_the_rule, race_places(Some("1")));
    assert_ne!(at_the_rule, race_places(None));
    let by_default = grid_places(&grid.replace("off_track_margin = 1.0\n", ""), "d");
    assert_eq!(by_default, race_places(None));
    assert_eq!(by_default, race_places(Some("-1")));
    std::fs::write(dir.join("bad.toml"), grid.replace("1.0", "9.0")).unwrap();
    let err = String::from_utf8_lossy(&cdbo(&dir, &["experiment", "bad.toml"]).stderr).into_owned();
    assert!(
        err.contains("bad.toml") && err.contains("off-track margin"),
        "{err}"
    );
}

/// A grid's `preset = "fast-safe"` races every run as `cdbo race --preset fast-safe` does at
/// the grid's knob (the same best, bit for bit): its runs are the safe pattern search's, their
/// records name the path tracker and the minimum-curvature line, and the grid kept in the
/// folder names the stack, not the preset.
#[test]
fn a_grid_of_the_preset_races_as_race_does() {
    let dir = fresh_dir("grid-preset");
    std::fs::write(dir.join("oval.xml"), common::OVAL).unwrap();
    let grid = "laps = 8\nrepeats = 1\npreset = \"fast-safe\"\n\
                [[tracks]]\ntrack = \"oval.xml\"\nkernels = [6]\n";
    std::fs::write(dir.join("grid.toml"), grid).unwrap();
    ok(&dir, &["experiment", "grid.toml", "--out", "g"]);
    let run: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("g/runs/oval_xml-m6-safe-pattern-search-r0.json"))
            .unwrap(),
    )
    .unwrap();
    assert_eq!(run["spec"]["method"], "safe-pattern-search");
    assert_eq!(run["steering"], "tracker");
    assert_eq!(run["base_line"], "min-curvature");
    let kept = std::fs::read_to_string(dir.join("g/experiment.toml")).unwrap();
    assert!(
        kept.contains("methods = [\"safe-pattern-search\"]") && !kept.contains("preset"),
        "{kept}"
    );
    let args = [
        "race",
        "--track",
        "oval.xml",
        "--preset",
        "fast-safe",
        "--kernels",
        "6",
        "--laps",
        "8",
        "--knob",
        "0.03",
        "--json",
        "--out",
        "r",
    ];
    let raced: serde_json::Value = serde_json::from_str(&ok(&dir, &args)).unwrap();
    assert_eq!(run["best_reward_mps"], raced["best_reward_mps"]);
}
