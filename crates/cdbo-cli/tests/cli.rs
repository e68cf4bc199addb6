//! The command line as a user meets it: outputs, JSON keys, and one clear error line. One
//! test binary, a file a topic: laps, races, flying laps, plots, benches of circuits, the files
//! a user hands it, and the game's commands that need no game (the game's own in
//! tests/torcs.rs).

mod common;

#[path = "cli/bench.rs"]
mod bench;
#[path = "cli/flying.rs"]
mod flying;
#[path = "cli/input_files.rs"]
mod input_files;
#[path = "cli/lap.rs"]
mod lap;
#[path = "cli/plot.rs"]
mod plot;
#[path = "cli/race.rs"]
mod race;
#[path = "cli/torcs_offline.rs"]
mod torcs_offline;
