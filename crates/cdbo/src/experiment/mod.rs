//! Experiments that join the simulator, the policy and the optimisers: [`race`] learns to race
//! one track with one method.

pub mod race;
