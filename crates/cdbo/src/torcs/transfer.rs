//! The reference a transfer is read against (`cdbo torcs transfer --against`): the best reward
//! each track's race reached in an earlier run, so that a new run's rewards read as a share of
//! it, track by track (docs/results/torcs/transfer-bc6f3c4.json, the transfer measured at
//! bc6f3c4, is the reference the pace line is read against).
//!
//! The file is a transfer report (`transfer.json`, as `cdbo torcs transfer` writes it) or any
//! JSON object of that shape: `{"transfers": [{"track": T, "best_reward_mps": r}, …]}`, other
//! fields ignored. A track's reference is the mean of its rows' r (one a seed); every r must be
//! a finite reward above 0 m/s.

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::error::{Error, Result};

#[derive(Deserialize)]
struct Report {
    transfers: Vec<Row>,
}

#[derive(Deserialize)]
struct Row {
    track: String,
    best_reward_mps: f64,
}

/// Each track's reference best reward (m/s), by track name; `file` names the text in errors.
pub fn reference(text: &str, file: &str) -> Result<BTreeMap<String, f64>> {
    let report: Report = serde_json::from_str(text).map_err(|source| Error::Json {
        what: file.to_owned(),
        source,
    })?;
    if report.transfers.is_empty() {
        return Err(invalid(
            file,
            "transfers",
            "no row: nothing to read a reward against",
        ));
    }
    let mut sums: BTreeMap<String, (f64, usize)> = BTreeMap::new();
    for (i, row) in report.transfers.iter().enumerate() {
        let element = format!("transfers[{i}]");
        if row.track.trim().is_empty() {
            return Err(invalid(file, &element, "the track has no name"));
        }
        let r = row.best_reward_mps;
        if !(r.is_finite() && r > 0.0) {
            return Err(invalid(
                file,
                &format!("{element}.best_reward_mps"),
                &format!("{r}: must be a finite reward above 0 m/s"),
            ));
        }
        let sum = sums.entry(row.track.clone()).or_default();
        sum.0 += r;
        sum.1 += 1;
    }
    Ok(sums
        .into_iter()
        .map(|(track, (sum, n))| (track, sum / n as f64))
        .collect())
}

fn invalid(file: &str, element: &str, message: &str) -> Error {
    Error::Parse {
        file: file.to_owned(),
        line: None,
        element: element.to_owned(),
        message: message.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tracks_reference_is_the_mean_of_its_seeds() {
        let text = r#"{"car": "car1-trb1", "transfers": [
            {"track": "forza", "seed": 0, "best_reward_mps": 50.0, "failed_laps": 3},
            {"track": "aalborg", "best_reward_mps": 30.0},
            {"track": "forza", "seed": 1, "best_reward_mps": 53.0}]}"#;
        let r = reference(text, "t.json").unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(r["forza"], 51.5);
        assert_eq!(r["aalborg"], 30.0);
    }

    /// The reference kept in docs/results/torcs: the best laps measured at bc6f3c4 on the 21 road
    /// tracks, as rewards (Forza: its 5,784.11 m in 111.21 s).
    #[test]
    fn the_kept_reference_reads_as_its_laps() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../docs/results/torcs/transfer-bc6f3c4.json"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let r = reference(&text, path).unwrap();
        assert_eq!(r.len(), 21);
        assert!(
            (r["forza"] - 5784.11 / 111.21).abs() < 1e-3,
            "{}",
            r["forza"]
        );
        assert!((r["g-track-1"] - 2057.56 / 46.68).abs() < 1e-3);
    }

    #[test]
    fn a_bad_reference_names_its_file_row_and_value() {
        let err = |text: &str| reference(text, "ref.json").unwrap_err().to_string();
        let zero = err(r#"{"transfers": [{"track": "a", "best_reward_mps": 1},
                                         {"track": "b", "best_reward_mps": 0}]}"#);
        assert!(zero.contains("ref.json") && zero.contains("transfers[1].best_reward_mps"));
        assert!(zero.contains("0: must be"), "{zero}");
        assert!(err(r#"{"transfers": []}"#).contains("no row"));
        assert!(
            err(r#"{"transfers": [{"track": " ", "best_reward_mps": 1}]}"#).contains("no name")
        );
        let missing = err(r#"{"transfers": [{"track": "a"}]}"#);
        assert!(
            missing.contains("ref.json") && missing.contains("best_reward_mps"),
            "{missing}"
        );
        assert!(err("[1, 2").contains("ref.json"));
    }
}
