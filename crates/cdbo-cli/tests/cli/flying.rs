//! `cdbo race --flying`: learning on the flying lap, and both laps of the best policy in
//! every race's summary.

use crate::common::{fresh_dir, json, oval_file};

/// `cdbo race --preset fast-safe` of 30 laps on the oval ([`oval_file`]) with `extra`: its
/// summary.
fn race(extra: &[&str], name: &str) -> serde_json::Value {
    let out_dir = fresh_dir(&format!("flying-{name}"));
    let mut args = vec!["race", "--track", oval_file(), "--preset", "fast-safe"];
    args.extend(["--laps", "30", "--json"]);
    args.extend(extra);
    args.extend(["--out", out_dir.to_str().unwrap()]);
    json(&args)
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
