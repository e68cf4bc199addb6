//! A panel of the game's laps: the policies `cdbo torcs compare` drew, each with how the game
//! drove it, kept (`panel_TRACK.jsonl`) so that cdbo's simulator can be scored against the
//! same laps again without the game: a change to the model, or a calibrated car, checked in
//! seconds, paired, policy by policy.
//!
//! One JSON object a line: `{"track": T, "what": W, "policy": P, "torcs": {"lap_time_s": t,
//! "failure": f, "x_fail": x, "distance_fail_m": d}}`, P a policy file's object ([`Policy`]),
//! t the lap time of a completed lap (else null), f the failure's name, x (a fraction of the
//! lap) and d where it happened (else null; x may be left out, as panels written before it
//! were). Blank lines are skipped; anything else is refused with its file and line.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::policy::Policy;
use crate::sim::{FailureReason, LapResult};

/// How a simulator drove one lap, in brief: what `cdbo torcs compare`, `panel` and
/// `transfer` keep of each lap, and print as a table's cell ("112.34 s", "off_track at 2602 m
/// (x = 0.423)").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The lap time of a completed lap (s).
    pub lap_time_s: Option<f64>,
    /// Why a failed lap failed ([`FailureReason::name`]).
    pub failure: Option<String>,
    /// Where it failed, as a fraction of the lap.
    #[serde(default)]
    pub x_fail: Option<f64>,
    /// Where it failed (m from the start line).
    pub distance_fail_m: Option<f64>,
}

impl Outcome {
    /// A lap's outcome.
    pub fn of(lap: &LapResult) -> Outcome {
        Outcome {
            lap_time_s: lap.lap_time_s,
            failure: lap.failure.map(|f| f.reason.name().to_owned()),
            x_fail: lap.failure.map(|f| f.x),
            distance_fail_m: lap.failure.map(|f| f.distance_m),
        }
    }

    /// Whether the lap was completed.
    pub fn completed(&self) -> bool {
        self.lap_time_s.is_some()
    }
}

impl fmt::Display for Outcome {
    /// The lap time, where the lap failed, or "–" where neither is known.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.lap_time_s, &self.failure) {
            (Some(t), _) => write!(f, "{t:.2} s"),
            (None, Some(reason)) => {
                write!(
                    f,
                    "{reason} at {:.0} m",
                    self.distance_fail_m.unwrap_or(0.0)
                )?;
                match self.x_fail {
                    Some(x) => write!(f, " (x = {x:.3})"),
                    None => Ok(()),
                }
            }
            (None, None) => f.write_str("–"),
        }
    }
}

/// One policy and how the game drove it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PanelLap {
    /// The track's name, as the game knows it.
    pub track: String,
    /// Which drawn policy ("policy 3", "seed 1 policy 3").
    pub what: String,
    /// The policy.
    pub policy: Policy,
    /// The game's lap.
    pub torcs: Outcome,
}

/// Reads a panel; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Vec<PanelLap>> {
    let mut laps = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let at = |message: String| Error::Parse {
            file: file.to_owned(),
            line: Some((i + 1) as u32),
            element: "panel lap".into(),
            message,
        };
        let lap: PanelLap = serde_json::from_str(line).map_err(|e| at(e.to_string()))?;
        // Every block checked as a policy file's, and a lap either completed or failed.
        let policy = lap
            .policy
            .clone()
            .checked(file)
            .map_err(|e| at(e.to_string()))?;
        let t = &lap.torcs;
        let sound = match (t.lap_time_s, &t.failure) {
            (Some(s), None) => s.is_finite() && s > 0.0 && t.x_fail.is_none(),
            (None, Some(f)) => {
                FailureReason::from_name(f).is_some()
                    && t.distance_fail_m.is_some_and(f64::is_finite)
                    && t.x_fail.is_none_or(|x| (0.0..=1.0).contains(&x))
            }
            _ => false,
        };
        if !sound {
            return Err(at(
                "the game's lap needs either a positive lap_time_s, or a known failure, a finite distance_fail_m and x_fail, if given, within [0, 1]"
                    .into(),
            ));
        }
        laps.push(PanelLap { policy, ..lap });
    }
    Ok(laps)
}

/// One line of a panel.
pub fn line(lap: &PanelLap) -> Result<String> {
    serde_json::to_string(lap).map_err(|e| Error::parse("panel", "lap", e.to_string()))
}

/// cdbo's laps of a track's panel against the game's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Score {
    /// The track.
    pub track: String,
    /// Policies scored.
    pub laps: usize,
    /// Both complete or both fail.
    pub agree: usize,
    /// cdbo's car fails where the game's completes.
    pub cdbo_fails: usize,
    /// The game's car fails where cdbo's completes.
    pub torcs_fails: usize,
    /// Mean |t_game − t_cdbo| / t_cdbo over the laps both complete.
    pub lap_time_error_mean: Option<f64>,
    /// Mean (t_game − t_cdbo) / t_cdbo: positive where cdbo's car is the faster.
    pub lap_time_bias: Option<f64>,
}

/// Scores cdbo's `ours[i]`, its lap of `panel[i]`'s policy, against the game's, for `track`.
pub fn score(track: &str, panel: &[&PanelLap], ours: &[Outcome]) -> Score {
    let pairs = || panel.iter().zip(ours).map(|(p, o)| (&p.torcs, o));
    let errors: Vec<f64> = pairs()
        .filter_map(|(t, o)| Some((t.lap_time_s? - o.lap_time_s?) / o.lap_time_s?))
        .collect();
    let n = errors.len() as f64;
    Score {
        track: track.to_owned(),
        laps: ours.len(),
        agree: pairs()
            .filter(|(t, o)| t.completed() == o.completed())
            .count(),
        cdbo_fails: pairs()
            .filter(|(t, o)| t.completed() && !o.completed())
            .count(),
        torcs_fails: pairs()
            .filter(|(t, o)| !t.completed() && o.completed())
            .count(),
        lap_time_error_mean: (n > 0.0).then(|| errors.iter().map(|e| e.abs()).sum::<f64>() / n),
        lap_time_bias: (n > 0.0).then(|| errors.iter().sum::<f64>() / n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::RkhsPolicy;

    fn lap(torcs: Outcome) -> PanelLap {
        PanelLap {
            track: "forza".into(),
            what: "policy 0".into(),
            policy: Policy::from(RkhsPolicy::new(vec![0.2, 0.3, 0.1], 0.3).unwrap()),
            torcs,
        }
    }

    fn completed(t: f64) -> Outcome {
        Outcome {
            lap_time_s: Some(t),
            failure: None,
            x_fail: None,
            distance_fail_m: None,
        }
    }

    fn failed(at: f64) -> Outcome {
        Outcome {
            lap_time_s: None,
            failure: Some("off_track".into()),
            x_fail: Some(at / 5000.0),
            distance_fail_m: Some(at),
        }
    }

    /// A table's cell: the lap time, or the failure with its place (x where it is known, as
    /// it is not in panels written before it was kept), or a dash.
    #[test]
    fn an_outcome_reads_as_a_cell() {
        assert_eq!(completed(112.346).to_string(), "112.35 s");
        assert_eq!(
            failed(2602.0).to_string(),
            "off_track at 2602 m (x = 0.520)"
        );
        let older = r#"{"lap_time_s": null, "failure": "hit_wall", "distance_fail_m": 12.4}"#;
        let older: Outcome = serde_json::from_str(older).unwrap();
        assert_eq!(older.to_string(), "hit_wall at 12 m");
        let unknown = Outcome {
            failure: None,
            ..older
        };
        assert_eq!(unknown.to_string(), "–");
    }

    #[test]
    fn a_panel_round_trips_and_scores_by_hand() {
        let laps = [
            lap(completed(100.0)),
            lap(failed(420.0)),
            lap(completed(110.0)),
        ];
        let text = laps
            .iter()
            .map(|l| line(l).unwrap() + "\n")
            .collect::<String>();
        let back = parse(&format!("\n{text}\n"), "p.jsonl").unwrap();
        assert_eq!(back, laps);
        // cdbo completes the first two in 99 and 90 s and fails the third.
        let ours = [completed(99.0), completed(90.0), failed(300.0)];
        let s = score("forza", &back.iter().collect::<Vec<_>>(), &ours);
        assert_eq!((s.laps, s.agree, s.cdbo_fails, s.torcs_fails), (3, 1, 1, 1));
        assert_eq!(s.lap_time_bias, Some(1.0 / 99.0));
        assert_eq!(s.lap_time_error_mean, Some(1.0 / 99.0));
    }

    #[test]
    fn a_bad_panel_line_names_its_file_and_line() {
        let good = line(&lap(completed(100.0))).unwrap();
        let bad = |text: &str| parse(text, "p.jsonl").unwrap_err().to_string();
        assert!(bad(&format!("{good}\n{{\"track\": 1}}\n")).starts_with("p.jsonl:2: panel lap:"));
        let neither = good.replace("100.0", "null");
        assert!(
            bad(&neither).contains("either a positive lap_time_s"),
            "{}",
            bad(&neither)
        );
        let nan_weight = good.replace("0.2", "1e999");
        assert!(bad(&nan_weight).starts_with("p.jsonl:1: panel lap:"));
        let unknown = line(&lap(Outcome {
            failure: Some("exploded".into()),
            ..failed(1.0)
        }))
        .unwrap();
        assert!(bad(&unknown).contains("known failure"));
        let past_the_lap = line(&lap(Outcome {
            x_fail: Some(1.5),
            ..failed(1.0)
        }))
        .unwrap();
        assert!(bad(&past_the_lap).contains("x_fail, if given, within [0, 1]"));
    }
}
