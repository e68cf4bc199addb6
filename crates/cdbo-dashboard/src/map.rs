//! The track map coloured by speed: a trial's policy re-driven in the simulator, with the line
//! it holds when it learns one or was raced on one.

use cdbo::Result;
use cdbo::car::Car;
use cdbo::policy::RacedPolicy;
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

/// Drives `policy` once on `track` with `car`, on the line and with the steering it was raced
/// with, and returns its path and speed, and the line it holds (as the simulator clamps it,
/// [`Simulator::held_line`]) where that is not the centre line.
pub fn drive(track: Track, car: &Car, key: String, raced: &RacedPolicy) -> Result<MapView> {
    let line = raced.base_line.line(&track, car)?;
    let mut sim = Simulator::new(track, car);
    sim.config.line = line;
    sim.config.steering = raced.steering.steering();
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

#[cfg(test)]
mod tests {
    use super::*;
    use cdbo::line::BaseLine;
    use cdbo::policy::{Policy, RkhsPolicy};

    /// A learned line is drawn (within the road less half the car's width, as the lap holds
    /// it) and the lap is driven on it; the paper's pedal-only policy has no line to draw.
    #[test]
    fn the_map_draws_the_line_a_policy_holds() {
        let track = cdbo::track::builtin::load("ridgeway").unwrap().unwrap();
        let car = Car::spirit_300();
        let pedal = RkhsPolicy::new(vec![0.3; 6], 0.2).unwrap();
        let line = RkhsPolicy::new(vec![1.5, -1.5, 0.0, 2.0], 1.0 / 3.0).unwrap();
        let paper = RacedPolicy {
            policy: Policy::from(pedal.clone()),
            base_line: BaseLine::Centre,
            steering: Default::default(),
        };
        let learned = RacedPolicy {
            policy: Policy {
                pedal,
                line: Some(line),
                target: None,
            },
            ..paper.clone()
        };
        let centre = drive(track.clone(), &car, "a".into(), &paper).unwrap();
        assert!(centre.line_x.is_empty() && centre.line_y.is_empty());
        let map = drive(track.clone(), &car, "b".into(), &learned).unwrap();
        assert_eq!(map.line_x.len(), map.centre_x.len());
        let room = |i: usize| 0.5 * track.samples[i].width - 0.5 * car.width;
        let every = track.samples.len().div_ceil(MAP_POINTS).max(1);
        for (k, (x, y)) in map.line_x.iter().zip(&map.line_y).enumerate() {
            let d = (x - map.centre_x[k]).hypot(y - map.centre_y[k]);
            assert!(d <= room(k * every) + 1e-9, "{d} m off the centre line");
        }
        let sim = Simulator::new(track, &car);
        let lap = sim.lap(&mut learned.policy.driver());
        assert_eq!(map.reward, lap.reward_mps);
        assert_eq!(map.x.len(), map.speed.len());
    }
}
