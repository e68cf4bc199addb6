//! The simulator as an evaluator: one lap of the policy with the given weights.

use super::{Evaluator, Outcome};
use crate::error::Result;
use crate::policy::{PolicyShape, SpeedTarget};
use crate::sim::Simulator;

/// Laps of the simulator with policies of one shape (each action's kernels and length-scale).
#[derive(Debug, Clone)]
pub struct SimEvaluator {
    /// The simulator.
    pub sim: Simulator,
    /// The shape of the policies' weights.
    pub shape: PolicyShape,
    /// The speed their pedal's action asks for ([`crate::policy::target`]); none: the pedal.
    pub target: Option<SpeedTarget>,
}

impl Evaluator for SimEvaluator {
    fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> Result<Outcome> {
        let policy = self.shape.policy(weights)?.targeting(self.target.clone());
        let lap = self.sim.lap(&mut policy.driver());
        Ok(Outcome::of_lap(&lap, self.sim.track.length))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::Car;
    use crate::policy::{Block, RkhsPolicy};

    /// The evaluator reports the simulator's own lap: the time of a completed lap over the
    /// track's length, and where and why a failed lap failed.
    #[test]
    fn outcomes_are_the_simulators_laps() {
        let track = crate::track::builtin::load("ridgeway").unwrap().unwrap();
        let sim = Simulator::new(track, &Car::spirit_300());
        // A steady 7 % throttle completes the lap (the engine brake holds the car slow; from
        // 8 % the gearbox climbs and the car, its rear wheels driven through the differential,
        // spins off past halfway).
        let steady: Vec<(f64, f64)> = (0..=200).map(|i| (i as f64 / 200.0, 0.07)).collect();
        let policy = RkhsPolicy::fit(&steady, 8, 1.0 / 7.0, 1e-3).unwrap();
        let mut e = SimEvaluator {
            sim: sim.clone(),
            shape: PolicyShape::pedal(Block::new(8, policy.lengthscale).unwrap()),
            target: None,
        };
        let lap = sim.lap(&mut policy.pedal());
        let outcome = e.evaluate(1, &policy.weights).unwrap();
        assert_eq!(outcome.reward().unwrap(), lap.reward_mps);
        assert!(lap.reward_mps > 10.0);
        let Outcome::Failed { at, reason } = e.evaluate(1, &[-1.0; 8]).unwrap() else {
            panic!("full braking completed a lap")
        };
        assert_eq!(reason.as_deref(), Some("stalled"));
        assert!(at.is_some_and(|x| x < 0.05), "{at:?}");
    }
}
