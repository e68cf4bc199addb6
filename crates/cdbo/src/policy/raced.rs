//! A policy file that carries how it was raced ([`RacedPolicy`]): its base line and its
//! steering, so that a lap replays a policy on the line it was raced on.

use serde::{Deserialize, Serialize};

use super::Policy;
use crate::drive::steering::SteeringLaw;
use crate::error::{Error, Result};
use crate::line::BaseLine;

/// A policy as a race writes it (`best_policy.json`): the policy's own file ([`Policy`]) and
/// how the race drove it, so that a lap drives it again the same way: when the race held a
/// line other than the centre line, `"base_line": "min-curvature"`; when it steered with other
/// than the paper's PI, `"steering": "tracker"`. A file without them (every file written
/// before they were stored) is on the centre line with the PI steering.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RacedPolicy {
    /// The policy.
    #[serde(flatten)]
    pub policy: Policy,
    /// The line its offsets are measured from.
    #[serde(default, skip_serializing_if = "BaseLine::is_centre")]
    pub base_line: BaseLine,
    /// The steering it was raced with.
    #[serde(default, skip_serializing_if = "SteeringLaw::is_pi")]
    pub steering: SteeringLaw,
}

impl RacedPolicy {
    /// A policy file's text, every block checked; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<RacedPolicy> {
        #[derive(Deserialize)]
        struct Raced {
            #[serde(default)]
            base_line: BaseLine,
            #[serde(default)]
            steering: SteeringLaw,
        }
        let raced: Raced = serde_json::from_str(text).map_err(|e| {
            Error::parse(
                file,
                "base_line, steering",
                format!("not a base line and steering law: {e}"),
            )
        })?;
        Ok(RacedPolicy {
            policy: Policy::from_json(text, file)?,
            base_line: raced.base_line,
            steering: raced.steering,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::RkhsPolicy;

    /// A policy file keeps its base line and steering; one written before them (or on the
    /// centre line with the PI) reads as the centre line with the PI and writes as the
    /// paper's file.
    #[test]
    fn a_policy_file_carries_its_base_line_and_steering() {
        let pedal = RkhsPolicy::new(vec![0.25, -1.5, 0.75], 0.5).unwrap();
        let raced = RacedPolicy {
            policy: Policy::from(pedal.clone()),
            base_line: BaseLine::MinCurvature,
            steering: SteeringLaw::Tracker,
        };
        let text = serde_json::to_string(&raced).unwrap();
        assert!(text.contains("\"base_line\":\"min-curvature\""), "{text}");
        assert!(text.contains("\"steering\":\"tracker\""), "{text}");
        assert_eq!(RacedPolicy::from_json(&text, "p.json").unwrap(), raced);
        let old = serde_json::to_string(&pedal).unwrap();
        let read = RacedPolicy::from_json(&old, "p.json").unwrap();
        assert_eq!(read.base_line, BaseLine::Centre);
        assert_eq!(read.steering, SteeringLaw::Pi);
        let centre = RacedPolicy {
            base_line: BaseLine::Centre,
            steering: SteeringLaw::Pi,
            ..raced
        };
        assert_eq!(serde_json::to_string(&centre).unwrap(), old);
        let e = RacedPolicy::from_json(
            r#"{"lengthscale": 0.5, "weights": [0, 1], "base_line": "apex"}"#,
            "p.json",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("p.json") && e.contains("apex"), "{e}");
        let e = RacedPolicy::from_json(
            r#"{"lengthscale": 0.5, "weights": [0, 1], "steering": "stanley"}"#,
            "p.json",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("p.json") && e.contains("steering") && e.contains("stanley"),
            "{e}"
        );
    }
}
