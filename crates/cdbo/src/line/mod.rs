//! Racing lines: a closed path within the road, given as lateral offsets dⱼ from the centre
//! line at stations sⱼ, and the same path as a [`Track`] whose own curvature and arc length
//! the quasi-steady-state limit ([`crate::limit`]) can drive.
//!
//! [`RacingLine::minimum_curvature`] computes the minimum-curvature line of Heilmeier et al.,
//! *Minimum curvature trajectory planning and control for an autonomous race car*, Vehicle
//! System Dynamics 58(10), 2020 (doi:10.1080/00423114.2019.1631455), as a sequence of
//! quadratic programmes ([`min_curvature`]); [`RacingLine::path`] turns it into a track
//! ([`path`]).

pub mod min_curvature;
pub mod path;
pub mod setting;

pub use setting::{BaseLine, LineKind, LineSetting};

use serde::Serialize;

use crate::car::Car;
use crate::track::Track;

/// Clearance (m) kept between the car's side and the road's edge, beyond half the car's width.
pub const SAFETY_MARGIN: f64 = 0.5;

/// How far inside the road's edge (m) a lap learned in cdbo's simulator fails where the track
/// does not give its verges (the built-in and CSV tracks): the car's centre a metre inside it
/// ([`LEARNING_OFF_TRACK_MARGIN`](crate::sim::lap::LEARNING_OFF_TRACK_MARGIN) is its negative),
/// and the racing line keeps it too ([`LineOptions::for_race`]).
pub const NO_VERGES_RESERVE: f64 = 1.0;

/// Spacing (m) of the stations the offsets are optimised at: the centre line is resampled at
/// the nearest spacing that divides its length.
pub const SPACING: f64 = 3.0;

/// How a racing line is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineOptions {
    /// Distance kept from the centre of the car to the road's edge (m).
    pub margin_m: f64,
    /// Spacing of the stations (m).
    pub spacing_m: f64,
}

impl LineOptions {
    /// For `car`: a margin of half its width plus `safety_margin_m`, stations every
    /// [`SPACING`] m.
    pub fn for_car(car: &Car, safety_margin_m: f64) -> LineOptions {
        LineOptions {
            margin_m: 0.5 * car.width + safety_margin_m,
            spacing_m: SPACING,
        }
    }

    /// For `car` racing on `track` as it learns there: half its width plus [`SAFETY_MARGIN`]
    /// inside the edge its laps are learned by. Where the track gives its verges that edge is
    /// the road's (the learning reserve keeps the wheels off the grass past it, and they are
    /// inside half the car's width); where it does not (the built-in and CSV tracks), a lap
    /// fails once the car's centre is [`LEARNING_OFF_TRACK_MARGIN`] inside the road's edge, and
    /// the line keeps that metre too ([`NO_VERGES_RESERVE`]): |d| ≤ w/2 − 1 m − w_car/2 − 0.5 m.
    /// Planned a metre closer, the tracker's error in a chicane at the demonstration's 15 m/s
    /// was enough to fail the lap on 6 of TUMFTM's 13 circuits.
    ///
    /// [`LEARNING_OFF_TRACK_MARGIN`]: crate::sim::lap::LEARNING_OFF_TRACK_MARGIN
    pub fn for_race(car: &Car, track: &Track) -> LineOptions {
        LineOptions::for_track(car, track, SAFETY_MARGIN)
    }

    /// For `car` on `track`: half its width plus `safety_margin_m` inside the edge laps are
    /// learned by, as [`for_race`](Self::for_race) with another safety margin.
    pub fn for_track(car: &Car, track: &Track, safety_margin_m: f64) -> LineOptions {
        let inside = if track.has_verges() {
            0.0
        } else {
            NO_VERGES_RESERVE
        };
        LineOptions::for_car(car, safety_margin_m + inside)
    }
}

/// A closed racing line: the path pⱼ = cⱼ + dⱼ·nⱼ through the centre-line points cⱼ at
/// stations sⱼ = j·L/N, nⱼ the unit normal pointing to the left of the centre line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RacingLine {
    /// Stations sⱼ on the centre line (m), evenly spaced from 0.
    pub stations: Vec<f64>,
    /// Lateral offsets dⱼ (m), positive to the left of the centre line.
    pub offsets: Vec<f64>,
    /// The points pⱼ (m), [x, y].
    pub points: Vec<[f64; 2]>,
    /// Distance kept from the centre of the car to the road's edge (m): half the car's width
    /// plus the safety margin; |dⱼ| ≤ wⱼ/2 − margin, wⱼ the road's width.
    pub margin_m: f64,
    /// The centre line's length L (m).
    pub centre_length_m: f64,
    /// How many quadratic programmes were solved.
    pub iterations: usize,
    /// Σⱼ κⱼ² of the path's discrete curvature at its points (1/m²), the objective.
    pub curvature_cost: f64,
}

impl RacingLine {
    /// The offset (m) at centre-line station `s` (wrapped into the lap), linear between
    /// stations.
    pub fn offset_at(&self, s: f64) -> f64 {
        crate::interp::periodic_linear(&self.offsets, self.centre_length_m, s)
    }

    /// The largest |dⱼ| (m).
    pub fn max_offset(&self) -> f64 {
        self.offsets.iter().fold(0.0, |m, d| f64::max(m, d.abs()))
    }
}
