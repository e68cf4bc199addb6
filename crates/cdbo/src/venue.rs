//! Where laps are driven — a venue: cdbo's simulator, or the game TORCS driven by cdbo's robot
//! (a real car's laps reach a study through an external command,
//! [`crate::evaluator::command`]). A venue drives the demonstration and any policy, and is the
//! evaluator of a race's laps, so that no caller branches on which venue it is.

use std::sync::Arc;

use crate::car::Car;
use crate::drive::steering::Steering;
use crate::error::{Error, Result};
use crate::evaluator::Evaluator;
use crate::evaluator::simulator::SimEvaluator;
use crate::line::RacingLine;
use crate::policy::{Policy, PolicyShape};
use crate::sim::{LapResult, Simulator};
use crate::torcs::evaluator::{TorcsEvaluator, drive};
use crate::torcs::{Game, GamePedal, LapRequest};
use crate::track::Track;

/// Where a race's laps are driven.
#[derive(Debug, Clone)]
pub enum Venue {
    /// cdbo's simulator, on its track with its car.
    Simulator(Box<Simulator>),
    /// The game TORCS: every lap a fresh game process driven by cdbo's robot, on the track and
    /// with the car of `request`.
    Game {
        /// The set-up game.
        game: Game,
        /// The track and car every lap is driven with (its pedal is each lap's).
        request: Box<LapRequest>,
    },
}

impl Venue {
    /// cdbo's simulator on `track` with `car`.
    pub fn simulator(track: Track, car: &Car) -> Venue {
        Venue::Simulator(Box::new(Simulator::new(track, car)))
    }

    /// The game on its track `track` with its car `car` (TORCS names).
    pub fn game(game: &Game, track: &str, car: &str) -> Result<Venue> {
        let request = game.request(track, car, GamePedal::Demo(0.0))?;
        Ok(Venue::Game {
            game: game.clone(),
            request: Box::new(request),
        })
    }

    /// This venue with the car steered by `steering` (the game's robot steers the centre line
    /// with either law).
    pub fn steered(self, steering: Steering) -> Venue {
        match self {
            Venue::Simulator(mut sim) => {
                sim.config.steering = steering;
                Venue::Simulator(sim)
            }
            Venue::Game { game, mut request } => {
                request.config.steering = steering;
                Venue::Game { game, request }
            }
        }
    }

    /// This venue with the car holding `line` where a policy has none (a policy's line is
    /// then an offset from it, [`crate::sim::LapConfig::line`]); the game's robot steers the
    /// centre line only, so a line is refused there.
    pub fn on_line(self, line: Arc<RacingLine>) -> Result<Venue> {
        match self {
            Venue::Simulator(mut sim) => {
                sim.config.line = Some(line);
                Ok(Venue::Simulator(sim))
            }
            Venue::Game { .. } => Err(line_in_game()),
        }
    }

    /// The car as cdbo reads it (for the limit and the plots).
    pub fn car(&self) -> Option<&Car> {
        match self {
            Venue::Simulator(_) => None,
            Venue::Game { request, .. } => Some(&request.car),
        }
    }

    /// The demonstration: the lap of a speed hold at `speed` (m/s), with the (x, a) pairs of
    /// every driver step.
    pub fn demonstrate(&self, speed: f64) -> Result<(LapResult, Vec<(f64, f64)>)> {
        match self {
            Venue::Simulator(sim) => Ok(sim.demonstrate(speed)),
            Venue::Game { game, request } => {
                let lap = drive(game, &recorded(request), GamePedal::Demo(speed))?;
                let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
                Ok((lap, pairs))
            }
        }
    }

    /// One lap of `policy`, traced.
    pub fn drive(&self, policy: &Policy) -> Result<LapResult> {
        match self {
            Venue::Simulator(sim) => Ok(traced(sim).lap(&mut policy.driver())),
            Venue::Game { game, request } => drive(
                game,
                &recorded(request),
                GamePedal::Rkhs(policy.pedal_only().ok_or_else(line_in_game)?.clone()),
            ),
        }
    }

    /// The evaluator of policy weights of shape `shape` here; the game's robot drives the
    /// pedal only, on its centre line, so a shape with a line is refused there.
    pub fn evaluator(&self, shape: PolicyShape) -> Result<Box<dyn Evaluator + Send>> {
        Ok(match self {
            Venue::Simulator(sim) => Box::new(SimEvaluator {
                sim: sim.as_ref().clone(),
                shape,
            }),
            Venue::Game { game, request } => {
                if shape.line.is_some() {
                    return Err(line_in_game());
                }
                Box::new(TorcsEvaluator {
                    game: game.clone(),
                    request: request.as_ref().clone(),
                    lengthscale: shape.pedal.lengthscale,
                })
            }
        })
    }
}

/// The game's robot drives the pedal only, on the centre line.
fn line_in_game() -> Error {
    Error::invalid_value(
        "a policy's line in the game TORCS",
        "a line d(x)",
        "none: cdbo's robot steers the centre line (drive the line in cdbo's simulator)",
    )
}

/// The simulator, recording a trace of its laps.
fn traced(sim: &Simulator) -> Simulator {
    let mut sim = sim.clone();
    sim.config.trace = true;
    sim
}

/// The request, recording the robot's trace of its laps.
fn recorded(request: &LapRequest) -> LapRequest {
    LapRequest {
        record: true,
        ..request.clone()
    }
}
