//! The race simulator: the vehicle model ([`crate::vehicle`]) driven round a track for one
//! lap ([`lap`]), at a fixed 250 Hz physics step (TORCS: 500 Hz; see [`LapConfig::dt`]) with
//! the driver at 50 Hz; a logged lap ([`log`]) replayed through the same model ([`replay`]); a lap's
//! trace ([`trace`]).

pub mod lap;
pub mod log;
pub mod replay;
pub mod trace;

pub use lap::{Failure, FailureReason, HeldPoint, LapConfig, LapResult, Simulator, held_offset};
pub use trace::TracePoint;
