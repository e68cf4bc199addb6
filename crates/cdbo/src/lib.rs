#![warn(missing_docs)]
//! # cdbo — Coordinate Descent Bayesian Optimisation for learning to race
//!
//! A toolkit that teaches a car (or any robot) a fast control policy in few trials, after
//! Oliveira et al., "Learning to Race through Coordinate Descent Bayesian Optimisation".
//!
//! - [`track`]: race tracks from TORCS / Speed Dreams files, TUMFTM centre lines, built-ins.
//! - [`car`]: vehicle parameters from TORCS car files.
//! - [`sim`]: the vehicle model and the lap evaluator.
//! - [`drive`]: the environment's controllers (steering, demonstrator).
//! - [`limit`]: the quasi-steady-state minimum lap time.
//! - [`policy`]: policies π(x), the paper's RKHS policy, policies with a line, (x, a) tables.
//! - [`gp`], [`acquisition`], [`optimizers`]: the Gaussian process, UCB / EI and the generic
//!   ask/tell optimisers of weights in Rᵈ, CDBO first.
//! - [`learner`]: learners that know they learn laps (the pattern search and its repairs).
//! - [`method`]: the one registry of methods, their knobs and settings, and what they cost.
//! - [`experiment`]: learning to race a track end to end, and the paper's experiment grid.
//! - [`study`]: persistent ask/tell studies for a real car; [`evaluator`]: sources of laps;
//!   [`serve`]: laps as a JSON-lines service; [`store`]: the claimed-row store (SQLite or
//!   PostgreSQL) behind studies and shared grids.
//! - [`torcs`]: the racing game TORCS as a source of laps (its robot, setup and lap runner);
//!   [`venue`]: where a race's laps are driven, the simulator or the game.
//! - [`benchmarks`]: standard test functions.
//! - [`sizes`]: the bounds on every size a user gives; [`bounded`]: the bound on every input
//!   read, and its one reader.
//! - [`prelude`]: the names most programs need, in one import.
//!
//! # Learning a lap in twenty lines
//!
//! Load a track, fit the paper's w₀ to a 15 m/s demonstration, then let a method ask for a
//! policy and tell it each lap's reward and, for a failed lap, where and why it failed:
//!
//! ```
//! use cdbo::prelude::*;
//!
//! # fn main() -> cdbo::Result<()> {
//! let track = Track::builtin("ridgeway")?;
//! let sim = Simulator::new(track, &Car::spirit_300());
//! let (demo, pairs) = sim.demonstrate(15.0);
//! let kernels = 30;
//! let w0 = RkhsPolicy::fit(&pairs, kernels, default_lengthscale(kernels), DEFAULT_RIDGE)?;
//! let mut optimizer = Spec::race(Method::PatternSearch)
//!     .seed(7)
//!     .policy(w0.lengthscale)?
//!     .track_length(sim.track.length)?
//!     .optimizer(w0.weights.clone())?;
//! let shape = PolicyShape::pedal(Block::new(kernels, w0.lengthscale)?);
//! let mut laps = SimEvaluator { sim, shape, target: None };
//! for trial in 1..=20 {
//!     let weights = optimizer.ask()?;
//!     let outcome = laps.evaluate(trial, &weights)?;
//!     optimizer.tell_lap(&weights, outcome.reward()?, outcome.failed_lap())?;
//! }
//! let (_, best) = optimizer.best().expect("twenty laps were told");
//! assert!(best > demo.reward_mps, "{best} m/s against the demonstration's {}", demo.reward_mps);
//! # Ok(())
//! # }
//! ```

// The layers, bottom to top: a module uses only modules of its own layer or below, and no two
// modules use each other (docs/design.md; checked by `tests/layers.rs`).

// Foundation: errors, bounds on input, numerics shared by everything above.
pub mod bounded;
pub mod data_path;
pub mod error;
pub mod geometry;
pub mod interp;
pub mod params;
pub mod rng;
#[cfg(test)]
mod scratch;
mod simd;
pub mod sizes;

// Generic optimisation of weights in Rᵈ: Gaussian processes, acquisitions, optimisers.
pub mod acquisition;
pub mod benchmarks;
pub mod gp;
pub mod optimizers;

// The model: track, car, and the vehicle's physics.
pub mod car;
pub mod track;
pub mod vehicle;

// Lines, then the drive (controllers) that follows them, then policies.
pub mod drive;
pub mod line;
pub mod policy;

// The lap simulator and its replay; the physical limit and the drive stack's ceiling.
pub mod ceiling;
pub mod limit;
pub mod sim;

// Learners that know they learn laps, and the registry of methods.
pub mod learner;
pub mod method;

// Where laps come from and where results are kept.
pub mod evaluator;
pub mod store;
pub mod torcs;
pub mod venue;

// Applications: calibration, studies, experiments, the lap service.
pub mod calibrate;
pub mod experiment;
pub mod serve;
pub mod study;

pub mod prelude;

pub use error::{Error, Result};
