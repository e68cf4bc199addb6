//! Learning to race in the game: the demonstration driven in TORCS, w₀ fitted to it, then
//! every lap of the optimisation a lap in TORCS driven by the [`TorcsEvaluator`]
//! ([`crate::experiment::race::race_with`]).

use super::{Game, GamePedal, LapRequest};
use crate::error::Result;
use crate::evaluator::torcs::TorcsEvaluator;
use crate::experiment::race::{LapRecord, RaceConfig, RaceOutcome, race_with};
use crate::limit::limit_lap;
use crate::policy::rkhs::default_lengthscale;
use crate::sim::lap::{Failure, FailureReason, LapResult};
use crate::track::Track;

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

/// Drives `req` with `pedal`.
pub fn drive(game: &Game, req: &LapRequest, pedal: GamePedal) -> Result<LapResult> {
    let mut req = req.clone();
    req.pedal = pedal;
    Ok(game.lap(&req)?.unwrap_or_else(|reason| failed_lap(&reason)))
}

/// Runs a race in the game on `track` (cdbo's reading of the game's track file, for the
/// limit) with the car of `req`.
pub fn race(
    game: &Game,
    req: &LapRequest,
    track: &Track,
    config: &RaceConfig,
    progress: impl FnMut(&LapRecord),
) -> Result<RaceOutcome> {
    let limit = limit_lap(track, &req.car);
    let mut demo_req = req.clone();
    demo_req.record = true;
    let demo = drive(game, &demo_req, GamePedal::Demo(config.demo_speed))?;
    let pairs = demo.trace.iter().map(|p| (p.x, p.pedal)).collect();
    let mut evaluator = TorcsEvaluator {
        game: game.clone(),
        request: req.clone(),
        lengthscale: default_lengthscale(config.kernels),
    };
    race_with(
        &track.name,
        (demo, pairs),
        limit,
        config,
        &mut evaluator,
        progress,
    )
}
