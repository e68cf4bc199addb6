//! Driving policies: the pedal command as a function of the lap fraction x ∈ [0, 1] and,
//! optionally, the line to hold ([`actions`]: one RKHS block per action); the pedal either
//! open loop, as in the paper, or as a target speed ([`target`]).

pub mod actions;
pub mod demo;
pub mod raced;
pub mod repair;
pub mod rkhs;
pub mod table;
pub mod target;

pub use actions::{Block, Policy, PolicyShape};
pub use raced::RacedPolicy;
pub use rkhs::RkhsPolicy;
pub use table::PolicyTable;
pub use target::SpeedTarget;
