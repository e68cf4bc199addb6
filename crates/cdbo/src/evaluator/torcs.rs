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
    fn evaluate(&mut self, weights: &[f64]) -> Result<Outcome> {
        let policy = RkhsPolicy::new(weights.to_vec(), self.lengthscale)?;
        self.request.pedal = GamePedal::Rkhs(policy);
        Ok(match self.game.lap(&self.request)? {
            Ok(lap) => match (lap.lap_time_s, lap.failure) {
                (Some(t), None) => Outcome::Lap {
                    time_s: t,
                    length_m: lap.reward_mps * t,
                },
                (_, failure) => Outcome::Failed {
                    at: failure.map(|f| f.x),
                    reason: failure.map(|f| f.reason.name().to_owned()),
                },
            },
            Err(reason) => Outcome::Failed {
                at: None,
                reason: Some(reason),
            },
        })
    }
}
