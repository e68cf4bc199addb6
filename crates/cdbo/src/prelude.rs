//! The names a program that learns laps needs, in one import: `use cdbo::prelude::*;`.

pub use crate::car::Car;
pub use crate::error::{Error, Result};
pub use crate::evaluator::simulator::SimEvaluator;
pub use crate::evaluator::{Evaluator, Outcome};
pub use crate::experiment::race::{RaceConfig, race};
pub use crate::limit::{Limit, limit_lap};
pub use crate::method::{Method, Spec};
pub use crate::optimizers::{FailedLap, Optimizer};
pub use crate::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
pub use crate::policy::{Block, Policy, PolicyShape, RkhsPolicy};
pub use crate::sim::{LapResult, Simulator};
pub use crate::study::{Study, StudyConfig};
pub use crate::track::Track;
pub use crate::venue::Venue;
