//! Driving policies π(x): the pedal command as a function of the lap fraction x ∈ [0, 1].

pub mod demo;
pub mod rkhs;
pub mod table;

pub use rkhs::RkhsPolicy;
pub use table::PolicyTable;
