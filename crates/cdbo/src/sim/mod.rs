//! The race simulator: the vehicle model ([`vehicle`]) driven round a track for one lap
//! ([`lap`]), at a fixed 250 Hz physics step (TORCS: 500 Hz; see [`LapConfig::dt`]) with the driver at
//! 50 Hz.

pub mod barrier;
pub mod bounce;
pub mod lap;
pub mod powertrain;
pub mod replay;
pub mod table;
pub mod tyre;
pub mod vehicle;

pub use lap::{
    Failure, FailureReason, HeldPoint, LapConfig, LapResult, Simulator, TracePoint, held_offset,
};
