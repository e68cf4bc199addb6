//! The track map coloured by speed: a trial's policy re-driven in the simulator, with the line
//! it holds when it learns one or was raced on one.

use cdbo::Result;
use cdbo::car::Car;
use cdbo::experiment::line::RacedPolicy;
use cdbo::sim::Simulator;
use cdbo::track::Track;
use serde::Serialize;

/// At most this many trace points are sent (the 50 Hz trace thinned evenly).
pub const MAP_POINTS: usize = 2000;

/// A re-driven lap on the map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapView {
    /// The track's name.
    pub track: String,
    /// Which policy was driven.
    pub key: String,
    /// Reward of the re-driven lap (m/s), 0 if it failed.
    pub reward: f64,
    /// Lap time (s), if completed.
    pub lap_time_s: Option<f64>,
    /// Why it failed, if it did.
    pub failure: Option<String>,
    /// The centre line, x (m).
    pub centre_x: Vec<f64>,
    /// The centre line, y (m).
    pub centre_y: Vec<f64>,
    /// The car's path, x (m).
    pub x: Vec<f64>,
    /// The car's path, y (m).
    pub y: Vec<f64>,
    /// Its speed there (m/s).
    pub speed: Vec<f64>,
    /// The line the policy holds where it is not the centre line (a learned line, or a race's
    /// base line), x (m); empty on the centre line.
    pub line_x: Vec<f64>,
    /// The line, y (m).
    pub line_y: Vec<f64>,
}

/// Drives `policy` once on `track` with `car`, on the line it was raced on, and returns its
/// path and speed, and the line it holds (as the simulator clamps it,
/// [`Simulator::held_line`]) where that is not the centre line.
pub fn drive(track: Track, car: &Car, key: String, raced: &RacedPolicy) -> Result<MapView> {
    let line = raced.base_line.line(&track, car)?;
    let mut sim = Simulator::new(track, car);
    sim.config.line = line;
    sim.config.trace = true;
    let lap = sim.lap(&mut raced.policy.driver());
    let every = lap.trace.len().div_ceil(MAP_POINTS).max(1);
    let trace: Vec<_> = lap.trace.iter().step_by(every).collect();
    let centre_every = sim.track.samples.len().div_ceil(MAP_POINTS).max(1);
    let centre: Vec<_> = sim.track.samples.iter().step_by(centre_every).collect();
    let held = if raced.policy.line.is_some() || sim.config.line.is_some() {
        sim.held_line(|x| raced.policy.line_offset(x))
    } else {
        Vec::new()
    };
    let held: Vec<_> = held.iter().step_by(centre_every).collect();
    Ok(MapView {
        track: sim.track.name.clone(),
        key,
        reward: lap.reward_mps,
        lap_time_s: lap.lap_time_s,
        failure: lap.failure.map(|f| f.reason.name().to_owned()),
        centre_x: centre.iter().map(|s| s.x).collect(),
        centre_y: centre.iter().map(|s| s.y).collect(),
        x: trace.iter().map(|p| p.pos_x).collect(),
        y: trace.iter().map(|p| p.pos_y).collect(),
        speed: trace.iter().map(|p| p.speed).collect(),
        line_x: held.iter().map(|p| p.x).collect(),
        line_y: held.iter().map(|p| p.y).collect(),
    })
}
