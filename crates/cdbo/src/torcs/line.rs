//! The line the game's robot holds: the lap's whole offset d(s) from the centre line — the
//! base line plus the policy's line, clamped to the road exactly as the simulator clamps it
//! ([`held_offset`]) — sampled on a uniform station grid and handed over in the robot's
//! settings (`line L D1 ... DN`), which the robot interpolates linearly around the lap
//! ([`LineTable::offset_at`], `drive::periodic_linear` in `torcs-robot/drive.hpp`).
//!
//! The grid's spacing is at most [`SPACING`]: the linear interpolation's error is h²·|d''|/8,
//! under a millimetre on a line whose offset turns by a metre over 20 m (|d''| ≈ 0.01 /m), and
//! the table stays small (a 6 km track: 6,000 numbers, about 130 KB of settings).

use crate::drive::Pedal;
use crate::interp::periodic_linear;
use crate::line::RacingLine;
use crate::sim::lap::held_offset;
use crate::track::Track;

/// The largest spacing (m) of the stations the line is sampled at.
pub const SPACING: f64 = 1.0;

/// A line as offsets dⱼ (m, positive left) at the N stations sⱼ = j·L/N of a lap of length L,
/// linear in between and around the lap's end.
#[derive(Debug, Clone, PartialEq)]
pub struct LineTable {
    /// The lap's length L (m), cdbo's reading of the track.
    pub length: f64,
    /// The offsets dⱼ, N ≥ 2.
    pub offsets: Vec<f64>,
}

impl LineTable {
    /// The offset the simulator's car holds on `track` for the driver `pedal` from the base
    /// line `base` ([`held_offset`], half the car's width `half_car`), at N stations: the
    /// fewest at most [`SPACING`] apart, and with a base line of N₀ stations the fewest
    /// multiple k·N₀ of its own (so that the table's stations include the base line's and its
    /// linear interpolation is the base line's own between them).
    pub fn held(
        track: &Track,
        half_car: f64,
        base: Option<&RacingLine>,
        pedal: &dyn Pedal,
    ) -> LineTable {
        let fewest = |spacing: f64| (spacing / SPACING).ceil().max(1.0) as usize;
        let n = match base {
            Some(b) => b.offsets.len() * fewest(b.centre_length_m / b.offsets.len() as f64),
            None => fewest(track.length),
        }
        .max(2);
        let offsets = (0..n)
            .map(|j| {
                let s = j as f64 * track.length / n as f64;
                held_offset(track, half_car, base, pedal.line(s / track.length), s)
            })
            .collect();
        LineTable {
            length: track.length,
            offsets,
        }
    }

    /// The offset (m) at station `s` (wrapped into the lap), linear between stations
    /// ([`periodic_linear`]).
    pub fn offset_at(&self, s: f64) -> f64 {
        periodic_linear(&self.offsets, self.length, s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::Car;
    use crate::drive::ConstantPedal;
    use crate::policy::{Policy, RkhsPolicy};
    use crate::track::builtin;

    /// At its own stations the table is the simulator's offset, bit for bit; in between it
    /// stays within a millimetre of it on 99 % of a line that swings across the road (it ramps
    /// over a station where the road's width steps), and never leaves the road less half the
    /// car of its neighbouring stations.
    #[test]
    fn the_table_is_the_simulators_line_at_its_stations_and_close_between() {
        let track = builtin::load(builtin::DEFAULT).unwrap().unwrap();
        let car = Car::spirit_300();
        let half_car = 0.5 * car.width;
        let line = RkhsPolicy::new(vec![3.0, -6.0, 9.0, -4.0, 0.0, 5.0], 0.2).unwrap();
        let policy = Policy {
            pedal: RkhsPolicy::new(vec![0.5; 6], 0.2).unwrap(),
            line: Some(line),
            target: None,
        };
        let driver = policy.driver();
        let table = LineTable::held(&track, half_car, None, &driver);
        let n = table.offsets.len();
        assert_eq!(n, (track.length / SPACING).ceil() as usize);
        let exact = |s: f64| held_offset(&track, half_car, None, driver.line(s / track.length), s);
        for (j, &d) in table.offsets.iter().enumerate() {
            let s = j as f64 * track.length / n as f64;
            assert_eq!(d.to_bits(), exact(s).to_bits(), "s = {s}");
            assert!((table.offset_at(s) - d).abs() < 1e-12, "s = {s}");
        }
        let mut errors = Vec::new();
        for i in 0..10 * n {
            let s = (i as f64 + 0.5) * track.length / (10 * n) as f64;
            let bound = track.frame(track.index_at(s)).half_width - half_car;
            let d = table.offset_at(s);
            // Between two stations within the road the table is within the road.
            let room = [s - SPACING, s + SPACING]
                .map(|s| track.frame(track.index_at(s)).half_width - half_car);
            assert!(
                d.abs() <= bound.max(room[0]).max(room[1]) + 1e-9,
                "s = {s}: {d}"
            );
            errors.push((d - exact(s)).abs());
        }
        // Off the steps of the road's width (where the clamped line jumps and the table ramps
        // over a station) the table is the line within a millimetre.
        errors.sort_by(f64::total_cmp);
        let p99 = errors[errors.len() * 99 / 100];
        assert!(
            p99 < 1e-3,
            "{p99} m off the simulator's line on 1 % of the lap"
        );
        assert!(table.offsets.iter().any(|d| d.abs() > 2.0));
        // A driver without a line on no base line: the centre line.
        let centre = LineTable::held(&track, half_car, None, &ConstantPedal(1.0));
        assert!(centre.offsets.iter().all(|&d| d == 0.0));
    }
}
