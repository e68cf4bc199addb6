//! The game TORCS as an evaluator: one lap of the RKHS policy with the given weights, driven
//! by cdbo's robot in a fresh game process.

use super::{Game, GamePedal, LapRequest};
use crate::error::Result;
use crate::evaluator::{Evaluator, Outcome};
use crate::policy::RkhsPolicy;
use crate::sim::lap::{Failure, FailureReason, LapResult};

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

/// A lap the game did not drive (it hung and was killed, or crashed) counts as a failed lap
/// at the time limit; the reason goes to standard error.
fn failed_lap(reason: &str) -> LapResult {
    eprintln!("warning: TORCS drove no lap: {reason}");
    LapResult {
        completed: false,
        lap_time_s: None,
        reward_mps: 0.0,
        failure: Some(Failure {
            reason: FailureReason::TimeLimit,
            x: 0.0,
            distance_m: 0.0,
            time_s: 0.0,
        }),
        simulated_s: 0.0,
        trace: Vec::new(),
    }
}

/// Drives `req` with `pedal`: the game's lap, or a failed lap if it drove none.
pub fn drive(game: &Game, req: &LapRequest, pedal: GamePedal) -> Result<LapResult> {
    let mut req = req.clone();
    req.pedal = pedal;
    Ok(game.lap(&req)?.unwrap_or_else(|reason| failed_lap(&reason)))
}
