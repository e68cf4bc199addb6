//! Driving policies π(x): the pedal command as a function of the lap fraction x ∈ [0, 1].

pub mod table;

pub use table::PolicyTable;
