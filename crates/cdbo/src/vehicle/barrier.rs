//! The body against the barriers: where a lap ends in the wall.
//!
//! simuv2 (`collide.cpp`, `SimCarCollideXYScene`) takes the body as four corners at
//! (±ℓ/2, ±w/2) from the centre of gravity, ℓ the body's length and w its overall width, and
//! collides a corner with the barrier once it is past the track's full width: the road, the
//! border and the side ([`crate::track::Frame::barriers`]). In the car's heading ψ relative to
//! the road's θ, a corner (x, y) of the body stands at
//!
//!   a = s_a + x·cos(ψ − θ) − y·sin(ψ − θ) along the road,
//!   l = l_c + x·sin(ψ − θ) + y·cos(ψ − θ) − κ·a²/2 across it,
//!
//! from the station nearest the car, (s_a, l_c) the car's own place and κ the road's
//! curvature (the centre line bends by κ·a²/2 over a). The corner touches the left barrier at
//! l > b_left and the right one at −l > b_right.

use super::State;
use crate::car::Car;
use crate::track::Frame;

/// The body's corners, as simuv2 collides them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Half the body's length ℓ/2 (m).
    half_length: f64,
    /// Half its overall width w/2 (m).
    half_width: f64,
    /// How far a corner is from the centre of gravity, √((ℓ/2)² + (w/2)²) (m).
    reach: f64,
}

impl Body {
    /// The body of `car` ([`Car::length`], [`Car::width`]).
    pub fn of(car: &Car) -> Body {
        let (half_length, half_width) = (0.5 * car.length, 0.5 * car.width);
        Body {
            half_length,
            half_width,
            reach: half_length.hypot(half_width),
        }
    }

    /// Whether a corner of the body is past a barrier, the car in state `s` near the station
    /// `f`. Free where the track has no barrier (infinite distance) or the car is farther
    /// than its reach inside both.
    #[inline]
    pub fn touches_barrier(&self, s: &State, f: &Frame) -> bool {
        self.near_barrier(s, f, 0.0)
    }

    /// Whether a corner of the body is within `reserve` metres of a barrier (0: touching it,
    /// [`Body::touches_barrier`]): l + r > b_left or −l + r > b_right.
    #[inline]
    pub fn near_barrier(&self, s: &State, f: &Frame, reserve: f64) -> bool {
        let nearest = f.barriers[0].min(f.barriers[1]) - reserve;
        if !nearest.is_finite() {
            return false;
        }
        let (along, lateral) = f.local(s.x, s.y);
        let far = along.abs() + self.reach;
        if lateral.abs() + self.reach + 0.5 * f.curvature.abs() * far * far < nearest {
            return false;
        }
        let (se, ce) = f.relative_heading(s.yaw_sin_cos);
        let (x, y) = (self.half_length, self.half_width);
        [(x, y), (x, -y), (-x, y), (-x, -y)]
            .into_iter()
            .any(|(x, y)| {
                let a = along + x * ce - y * se;
                let l = lateral + x * se + y * ce - 0.5 * f.curvature * a * a;
                l + reserve > f.barriers[0] || -l + reserve > f.barriers[1]
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::{Piece, Track, Verge};

    /// A straight road 10 m wide, with `verge` past both edges.
    fn straight(verge: Verge) -> Track {
        let piece = Piece {
            width: 10.0,
            verges: [verge; 2],
            ..Piece::flat(500.0, 0.0)
        };
        Track::from_pieces("straight", "test", &[piece], vec![])
    }

    /// A 1 m border and a 2 m side on each edge: barriers 8 m from the centre line.
    fn walled_straight() -> Track {
        straight(Verge {
            border_width: 1.0,
            side_width: 2.0,
            barrier: true,
            ..Verge::NONE
        })
    }

    fn car_at(lateral: f64, yaw: f64) -> State {
        let car = Car::spirit_300();
        let mut s = crate::vehicle::Vehicle::new(&car).at_rest(100.0, lateral, 0.0);
        s.yaw = yaw;
        s.yaw_sin_cos = yaw.sin_cos();
        s
    }

    #[test]
    fn a_corner_touches_the_barrier_where_the_closed_form_puts_it() {
        let track = walled_straight();
        let f = track.frame(track.project(100.0, 0.0, 0).index);
        assert_eq!(f.barriers, [8.0, 8.0]);
        let body = Body::of(&Car::spirit_300());
        // Square to the road: the side of the body, w/2 = 0.95 m, meets the wall at 8 m.
        assert!(!body.touches_barrier(&car_at(7.04, 0.0), f));
        assert!(body.touches_barrier(&car_at(7.06, 0.0), f));
        assert!(!body.touches_barrier(&car_at(-7.04, 0.0), f));
        assert!(body.touches_barrier(&car_at(-7.06, 0.0), f));
        // Turned by 0.2 rad towards the left wall: the front corner leads, at
        // l = ℓ/2·sin 0.2 + w/2·cos 0.2.
        let reach = 2.1 * 0.2f64.sin() + 0.95 * 0.2f64.cos();
        assert!(!body.touches_barrier(&car_at(8.0 - reach - 0.01, 0.2), f));
        assert!(body.touches_barrier(&car_at(8.0 - reach + 0.01, 0.2), f));
        // Within a reserve r of the wall: the same places, r nearer the centre line.
        for r in [0.5, 1.0] {
            assert!(!body.near_barrier(&car_at(7.04 - r, 0.0), f, r));
            assert!(body.near_barrier(&car_at(7.06 - r, 0.0), f, r));
            assert!(!body.near_barrier(&car_at(8.0 - reach - r - 0.01, 0.2), f, r));
            assert!(body.near_barrier(&car_at(8.0 - reach - r + 0.01, 0.2), f, r));
        }
    }

    #[test]
    fn a_track_without_barriers_has_none_to_touch() {
        let track = straight(Verge::NONE);
        let f = track.frame(track.project(100.0, 0.0, 0).index);
        assert_eq!(f.barriers, [f64::INFINITY; 2]);
        assert!(!Body::of(&Car::spirit_300()).touches_barrier(&car_at(40.0, 1.0), f));
    }
}
