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
track = "ridgeway"
kernels = [6]
"#;

fn setup(name: &str) -> PathBuf {
    let dir = fresh_dir(name);
    std::fs::write(dir.join("grid.toml"), GRID).unwrap();
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

#[test]
fn results_do_not_depend_on_jobs_and_shards_merge() {
    let dir = setup("jobs");
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "one", "--jobs", "1"],
    );
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "two", "--jobs", "2"],
    );
    let one = laps(&dir.join("one"));
    assert_eq!(one.len(), 4);
    assert_eq!(one, laps(&dir.join("two")));
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "s0", "--shard", "0/3"],
    );
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "s1", "--shard", "1/3"],
    );
    ok(
        &dir,
        &["experiment", "grid.toml", "--out", "s2", "--shard", "2/3"],
    );
    let mut shards: Vec<_> = ["s0", "s1", "s2"]
        .iter()
        .flat_map(|s| laps(&dir.join(s)))
        .collect();
    shards.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(shards, one);
    let out = ok(&dir, &["report", "s0", "s1", "s2", "--out", "merged"]);
    assert!(out.contains("4 runs from 3 folder(s)"), "{out}");
    let results = std::fs::read_to_string(dir.join("merged/results.md")).unwrap();
    assert!(results.contains("| ridgeway | 6 | cdbo | 2 |"), "{results}");
    for f in [
        "curves_ridgeway.png",
        "curves_ridgeway.svg",
        "table1.md",
        "fig3a_policy_ridgeway.svg",
    ] {
        assert!(dir.join("merged").join(f).is_file(), "{f}");
    }
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
