//! Experiments that join the simulator, the policy and the optimisers: [`race`] learns to race
//! one track with one method; [`grid`] lists the runs of the paper's experiment, [`record`]
//! runs and saves one, and [`summary`] aggregates them into the paper's figures and claims.

pub mod grid;
pub mod race;
pub mod record;
pub mod summary;
