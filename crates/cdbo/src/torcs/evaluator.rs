//! The game TORCS as an evaluator: one lap of the policy with the given weights (its pedal and,
//! if it has one, its line), driven by cdbo's robot in a fresh game process.

use std::sync::Arc;

use super::line::LineTable;
use super::{Game, GamePedal, LapRequest};
use crate::drive::Pedal;
use crate::error::Result;
use crate::evaluator::{Evaluator, Outcome};
use crate::policy::{Policy, PolicyShape, SpeedTarget};
use crate::sim::lap::{Failure, FailureReason, LapResult};
use crate::track::Track;

/// Laps in TORCS with policies of a fixed shape: the pedal and, if the shape has one, the
/// line, held from the request's base line `config.line` as the simulator holds it
/// ([`with_policy`]).
#[derive(Debug, Clone)]
pub struct TorcsEvaluator {
    /// The set-up game.
    pub game: Game,
    /// The lap to drive (its base line in `config.line`); its pedal and line are each
    /// policy's.
    pub request: LapRequest,
    /// cdbo's reading of the game's track, which the line is bounded and sampled on.
    pub track: Arc<Track>,
    /// The policies' shape.
    pub shape: PolicyShape,
    /// The speed their pedal's action asks for ([`crate::policy::target`]); none: the pedal.
    pub target: Option<SpeedTarget>,
}

impl Evaluator for TorcsEvaluator {
    fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> Result<Outcome> {
        let policy = self.shape.policy(weights)?.targeting(self.target.clone());
        lap_outcome(
            &self.game,
            &with_policy(&self.request, &self.track, &policy),
        )
    }
}

/// The outcome of one lap of `request` in the game; a lap it did not drive fails (the reason
/// on standard error).
fn lap_outcome(game: &Game, request: &LapRequest) -> Result<Outcome> {
    Ok(match game.lap(request)? {
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
        standing_lap_s: None,
        trace: Vec::new(),
    }
}

/// Drives `req`: the game's lap, or a failed lap if it drove none.
pub fn drive(game: &Game, req: &LapRequest) -> Result<LapResult> {
    Ok(game.lap(req)?.unwrap_or_else(|reason| failed_lap(&reason)))
}

/// `req` with the pedal `pedal` and the line the simulator's car holds on `track` for the
/// driver `driver` ([`LineTable::held`]: `req`'s base line `config.line` plus the driver's
/// line); the centre line, no table, where there is neither (`own_line` false and no base
/// line), so that a centre-line lap is the robot's as it always was.
pub fn with_pedal(
    req: &LapRequest,
    track: &Track,
    pedal: GamePedal,
    driver: &dyn Pedal,
    own_line: bool,
) -> LapRequest {
    let base = req.config.line.as_deref();
    let line = (own_line || base.is_some())
        .then(|| LineTable::held(track, 0.5 * req.car.width, base, driver));
    LapRequest {
        pedal,
        line,
        ..req.clone()
    }
}

/// `req` driving `policy`: its pedal, and its line on the base line ([`with_pedal`]).
pub fn with_policy(req: &LapRequest, track: &Track, policy: &Policy) -> LapRequest {
    with_pedal(
        req,
        track,
        game_pedal(policy),
        &policy.driver(),
        policy.line.is_some(),
    )
}

/// The robot's pedal for `policy`: its RKHS pedal, or with a target the profile hold of the
/// speeds it asks for ([`crate::policy::target`]), the same arithmetic as cdbo's.
pub fn game_pedal(policy: &Policy) -> GamePedal {
    match policy.target_hold() {
        Some(hold) => GamePedal::Profile {
            k: 1.0,
            length: hold.length,
            speed: hold.speeds,
        },
        None => GamePedal::Rkhs(policy.pedal.clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::RkhsPolicy;
    use crate::policy::target::SpeedTarget;

    /// The robot is handed a policy's RKHS pedal, or with a target the profile hold (scale 1)
    /// of the speeds the target asks for: the hold cdbo's driver runs.
    #[test]
    fn the_robots_pedal_is_the_policys_or_its_targets_hold() {
        let pedal = RkhsPolicy::new(vec![0.4, -0.2, 0.9], 0.5).unwrap();
        let open = Policy::from(pedal.clone());
        assert!(matches!(game_pedal(&open), GamePedal::Rkhs(p) if p == pedal));
        let target = SpeedTarget::new(vec![0.0, 30.0, 20.0, 40.0], 300.0, 0.7, 0.25).unwrap();
        let held = open.targeting(Some(target.clone()));
        let GamePedal::Profile { k, length, speed } = game_pedal(&held) else {
            panic!("a target's policy handed as an RKHS pedal");
        };
        assert_eq!((k, length), (1.0, 300.0));
        assert_eq!(speed, target.speeds(&pedal));
        assert_eq!(held.target_hold().unwrap().speeds, speed);
    }
}
