//! The race simulator: the vehicle model ([`vehicle`]) driven round a track for one lap
//! ([`lap`]), at TORCS's fixed 500 Hz physics step with the driver at 50 Hz.

pub mod lap;
pub mod powertrain;
pub mod table;
pub mod tyre;
pub mod vehicle;

pub use lap::{Failure, FailureReason, LapConfig, LapResult, Simulator, TracePoint};
