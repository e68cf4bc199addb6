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
//! - [`policy`]: policies π(x), the paper's RKHS policy and (x, a) tables.
//! - [`gp`], [`acquisition`], [`optimizers`]: the Gaussian process, UCB / EI and the ask/tell
//!   optimisers, CDBO first.
//! - [`experiment`]: learning to race a track end to end, and the paper's experiment grid.
//! - [`study`]: persistent ask/tell studies for a real car; [`evaluator`]: sources of laps;
//!   [`serve`]: laps as a JSON-lines service.
//! - [`torcs`]: the racing game TORCS as a source of laps (its robot, setup and lap runner).
//! - [`benchmarks`]: standard test functions.
//! - [`sizes`]: the bounds on every size a user gives, and the slow-size estimate;
//!   [`bounded`]: the bound on every input read, and its one reader.

pub mod acquisition;
pub mod benchmarks;
pub mod bounded;
pub mod car;
pub mod ceiling;
pub mod data_path;
pub mod drive;
pub mod error;
pub mod evaluator;
pub mod experiment;
pub mod gp;
pub mod interp;
pub mod limit;
pub mod optimizers;
pub mod params;
pub mod policy;
#[cfg(test)]
mod scratch;
pub mod serve;
pub mod sim;
mod simd;
pub mod sizes;
pub mod study;
pub mod torcs;
pub mod track;

pub use error::{Error, Result};
