//! Learners: methods that know they are learning laps. Where a generic optimiser
//! ([`crate::optimizers`]) sees weights in Rᵈ and a reward, a learner also reads the weights
//! as a policy's pedal over the lap and a failed lap's place and reason ([`FailedLap`]), and
//! repairs the pedal before the place a lap failed. Every learner speaks the same ask/tell
//! [`Optimizer`] face as the generic methods.
//!
//! [`FailedLap`]: crate::optimizers::FailedLap
//! [`Optimizer`]: crate::optimizers::Optimizer

pub mod budget;
pub mod pattern_search;
pub mod safe_search;
