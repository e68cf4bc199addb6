//! Where laps are driven — a venue: cdbo's simulator, or the game TORCS driven by cdbo's robot
//! (a real car's laps reach a study through an external command,
//! [`crate::evaluator::command`]). A venue drives the demonstration and any policy, and is the
//! evaluator of a race's laps, so that no caller branches on which venue it is.

use std::sync::Arc;

use crate::car::Car;
use crate::drive::demo::SpeedHold;
use crate::drive::profile::ProfileHold;
use crate::drive::steering::Steering;
use crate::error::Result;
use crate::evaluator::Evaluator;
use crate::evaluator::simulator::SimEvaluator;
use crate::line::RacingLine;
use crate::policy::{Policy, PolicyShape, SpeedTarget};
use crate::sim::lap::{GAME_OFF_TRACK_MARGIN, Reserve};
use crate::sim::{LapConfig, LapResult, Simulator};
use crate::torcs::evaluator::{TorcsEvaluator, drive, with_pedal, with_policy};
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
        /// The track, car, steering and base line every lap is driven with (its pedal and
        /// line are each lap's).
        request: Box<LapRequest>,
        /// cdbo's reading of the game's track: the line the robot holds is bounded to its road
        /// and sampled on it as the simulator's car would hold it ([`crate::torcs::line`]).
        track: Arc<Track>,
    },
}

impl Venue {
    /// cdbo's simulator on `track` with `car`.
    pub fn simulator(track: Track, car: &Car) -> Venue {
        Venue::Simulator(Box::new(Simulator::new(track, car)))
    }

    /// The game on its track `name` with its car `car` (TORCS names); `track` is cdbo's reading
    /// of that track.
    pub fn game(game: &Game, name: &str, car: &str, track: Track) -> Result<Venue> {
        let request = game.request(name, car, GamePedal::Demo(0.0))?;
        Ok(Venue::Game {
            game: game.clone(),
            request: Box::new(request),
            track: Arc::new(track),
        })
    }

    /// This venue with the car steered by `steering` (in the game too, on any line).
    pub fn steered(self, steering: Steering) -> Venue {
        self.configured(|config| config.steering = steering)
    }

    /// This venue with the car holding `line` where a policy has none (a policy's line is
    /// then an offset from it, [`crate::sim::LapConfig::line`]), in the simulator and in the
    /// game alike (there the robot is handed the line, [`crate::torcs::line`]).
    pub fn on_line(self, line: Arc<RacingLine>) -> Venue {
        self.configured(|config| config.line = Some(line))
    }

    /// This venue with a lap failing once the car's centre is `margin` metres past the road's
    /// edge ([`LapConfig::off_track_margin`]; negative: inside the road), and at the barriers,
    /// nothing kept in reserve, in the simulator and the game alike.
    pub fn off_track_at(self, margin: f64) -> Venue {
        self.configured(|config| config.fail_at(margin))
    }

    /// This venue as a policy learns in it: in cdbo's simulator, its laps failing `margin`
    /// metres past the road's edge if given, else keeping a reserve of the road
    /// ([`LapConfig::learn_with`]); in the game, failing at `margin` if given, else at the
    /// game's own rule, [`GAME_OFF_TRACK_MARGIN`].
    pub fn for_learning(self, margin: Option<f64>) -> Venue {
        match &self {
            Venue::Simulator(_) => self.configured(|config| config.learn_with(margin)),
            Venue::Game { .. } => self.off_track_at(margin.unwrap_or(GAME_OFF_TRACK_MARGIN)),
        }
    }

    /// This venue timing flying laps ([`LapConfig::flying`]): the second of two laps from the
    /// standing start, in the simulator and in the game alike (there cdbo's robot times it).
    pub fn flying(self) -> Venue {
        self.configured(|config| config.flying = true)
    }

    /// The settings every lap here is driven with (its steering, line and failure rules).
    pub fn config(&self) -> &LapConfig {
        match self {
            Venue::Simulator(sim) => &sim.config,
            Venue::Game { request, .. } => &request.config,
        }
    }

    /// What this venue's laps keep in reserve of the road ([`LapConfig::reserve`]).
    pub fn reserve(&self) -> Option<Reserve> {
        self.config().reserve
    }

    /// Where this venue's laps fail: the car's centre this far past the road's edge (m).
    pub fn off_track_margin(&self) -> f64 {
        self.config().off_track_margin
    }

    /// This venue with its laps' settings changed by `change`.
    fn configured(self, change: impl FnOnce(&mut LapConfig)) -> Venue {
        match self {
            Venue::Simulator(mut sim) => {
                change(&mut sim.config);
                Venue::Simulator(sim)
            }
            Venue::Game {
                game,
                mut request,
                track,
            } => {
                change(&mut request.config);
                Venue::Game {
                    game,
                    request,
                    track,
                }
            }
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
            Venue::Game {
                game,
                request,
                track,
            } => {
                let pedal = GamePedal::Demo(speed);
                let hold = SpeedHold::new(speed);
                let req = with_pedal(&recorded(request), track, pedal, &hold, false);
                let lap = drive(game, &req)?;
                let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
                Ok((lap, pairs))
            }
        }
    }

    /// The profile demonstration: the lap of a profile hold ([`ProfileHold`]) at k times
    /// `profile`'s speeds (m/s, at stations spaced evenly over the lap), with the (x, a)
    /// pairs of every driver step.
    pub fn demonstrate_profile(
        &self,
        profile: &[f64],
        k: f64,
    ) -> Result<(LapResult, Vec<(f64, f64)>)> {
        match self {
            Venue::Simulator(sim) => {
                let length = sim.track.length;
                let lap = traced(sim).lap(&mut ProfileHold { profile, length, k });
                let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
                Ok((lap, pairs))
            }
            Venue::Game {
                game,
                request,
                track,
            } => {
                let length = track.length;
                let pedal = GamePedal::Profile {
                    k,
                    length,
                    speed: profile.to_vec(),
                };
                let hold = ProfileHold { profile, length, k };
                let req = with_pedal(&recorded(request), track, pedal, &hold, false);
                let lap = drive(game, &req)?;
                let pairs = lap.trace.iter().map(|p| (p.x, p.pedal)).collect();
                Ok((lap, pairs))
            }
        }
    }

    /// One lap of `policy`, traced.
    pub fn drive(&self, policy: &Policy) -> Result<LapResult> {
        match self {
            Venue::Simulator(sim) => Ok(traced(sim).lap(&mut policy.driver())),
            Venue::Game {
                game,
                request,
                track,
            } => drive(game, &with_policy(&recorded(request), track, policy)),
        }
    }

    /// The evaluator of policy weights of shape `shape` here (a pedal and, if the shape has
    /// one, a line), the pedal's action asking for `target`'s speeds if given
    /// ([`crate::policy::target`]).
    pub fn evaluator(
        &self,
        shape: PolicyShape,
        target: Option<SpeedTarget>,
    ) -> Result<Box<dyn Evaluator + Send>> {
        Ok(match self {
            Venue::Simulator(sim) => Box::new(SimEvaluator {
                sim: sim.as_ref().clone(),
                shape,
                target,
            }),
            Venue::Game {
                game,
                request,
                track,
            } => Box::new(TorcsEvaluator {
                game: game.clone(),
                request: request.as_ref().clone(),
                track: track.clone(),
                shape,
                target,
            }),
        })
    }
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
