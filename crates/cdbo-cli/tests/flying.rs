//! `cdbo race --flying`: learning on the flying lap, and both laps of the best policy in
//! every race's summary.

use std::path::Path;
use std::process::Command;

fn race(extra: &[&str], name: &str) -> serde_json::Value {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-flying-test-{}-{name}", std::process::id()));
    let mut args = vec!["race", "--preset", "fast-safe", "--laps", "30", "--json"];
    args.extend(extra);
    args.extend(["--out", out_dir.to_str().unwrap()]);
    let out = Command::new(env!("CARGO_BIN_EXE_cdbo"))
        .args(&args)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

#[test]
fn a_race_learns_on_the_flying_lap_and_reports_both_laps() {
    let standing = race(&[], "standing");
    let flying = race(&["--flying"], "flying");
    // The lap learned on is the one driven again: the standing lap without --flying, the
    // flying lap with it, bit for bit.
    assert_eq!(standing["best_lap_time_s"], standing["best_standing_lap_s"]);
    assert_eq!(flying["best_lap_time_s"], flying["best_flying_lap_s"]);
    assert_eq!(flying["flying"], true);
    assert!(standing.get("flying").is_none(), "{standing}");
    // A flying lap starts at speed: faster than the same policy's standing lap.
    let t = |v: &serde_json::Value, key: &str| v[key].as_f64().unwrap();
    assert!(
        t(&flying, "best_flying_lap_s") < t(&flying, "best_standing_lap_s"),
        "{flying}"
    );
    let length = t(&flying, "best_reward_mps") * t(&flying, "best_lap_time_s");
    let standing_length = t(&standing, "best_reward_mps") * t(&standing, "best_lap_time_s");
    assert!((length - standing_length).abs() < 1e-6 * length);
}
