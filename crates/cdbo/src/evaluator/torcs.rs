//! The game TORCS as an evaluator: one lap of the RKHS policy with the given weights, driven
//! by cdbo's robot in a fresh game process ([`crate::torcs`]).

use super::{Evaluator, Outcome};
use crate::error::Result;
use crate::policy::RkhsPolicy;
use crate::torcs::{Game, GamePedal, LapRequest};

/// Laps in TORCS with RKHS policies of a fixed length-scale.
#[derive(Debug, Clone)]
pub struct TorcsEvaluator {
    /// The set-up game.
    pub game: Game,
    /// The lap to drive; its pedal is replaced by each policy.
    pub request: LapRequest,
    /// The policy kernels' length-scale.
    pub lengthscale: f64,
}

impl Evaluator for TorcsEvaluator {
    fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> Result<Outcome> {
        let policy = RkhsPolicy::new(weights.to_vec(), self.lengthscale)?;
        self.request.pedal = GamePedal::Rkhs(policy);
        Ok(match self.game.lap(&self.request)? {
            // The robot measures the reward; the lap's length follows from it and the time.
            Ok(lap) => Outcome::of_lap(&lap, lap.reward_mps * lap.lap_time_s.unwrap_or(0.0)),
            Err(reason) => {
                eprintln!("warning: TORCS drove no lap: {reason}");
                Outcome::Failed {
                    at: None,
                    reason: Some(reason),
                }
            }
        })
    }
}
