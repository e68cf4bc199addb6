//! Experiments that join the simulator, the policy and the optimisers: [`race`] learns to race
//! one track with one method, on the [`line`](crate::line::LineSetting) asked for; [`grid`] lists the runs of the paper's experiment, [`record`]
//! runs and saves one, [`folder`] keeps a grid's folder (its grid and sessions), [`shared`]
//! spreads a grid over workers through a database, and [`summary`] aggregates the runs into
//! the paper's figures and claims.

pub mod folder;
pub mod grid;
pub mod profile_start;
pub mod race;
pub mod record;
pub mod shared;
pub mod start;
pub mod summary;
