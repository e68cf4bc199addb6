//! The simulator as an evaluator: one lap of the RKHS policy with the given weights.

use super::{Evaluator, Outcome};
use crate::error::Result;
use crate::policy::RkhsPolicy;
use crate::sim::Simulator;

/// Laps of the simulator with RKHS policies of a fixed length-scale.
#[derive(Debug, Clone)]
pub struct SimEvaluator {
    /// The simulator.
    pub sim: Simulator,
    /// The policy kernels' length-scale.
    pub lengthscale: f64,
}

impl Evaluator for SimEvaluator {
    fn evaluate(&mut self, weights: &[f64]) -> Result<Outcome> {
        let mut policy = RkhsPolicy::new(weights.to_vec(), self.lengthscale)?;
        let lap = self.sim.lap(&mut policy);
        Ok(match (lap.lap_time_s, lap.failure) {
            (Some(t), None) => Outcome::Lap {
                time_s: t,
                length_m: self.sim.track.length,
            },
            (_, failure) => Outcome::Failed {
                at: failure.map(|f| f.x),
                reason: failure.map(|f| f.reason.name().to_owned()),
            },
        })
    }
}
