//! Where each wheel stands: the surface and the bumps under it, and whether the wheels keep
//! clear of slippery ground.

use super::{State, Vehicle};
use crate::track::{Bumps, Frame};

/// What a wheel stands on: its surface's friction and rolling resistance coefficient, and the
/// bumps it meets.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ground {
    pub(super) friction: f64,
    pub(super) rolling: f64,
    pub(super) bumps: Bumps,
}

impl Vehicle {
    /// Each wheel's ground, front left, front right, rear left, rear right: its surface's
    /// friction and rolling resistance coefficient (the tyres' where the surface gives none),
    /// and the bumps of a rough road under it ([`crate::track::Roughness::plain`] at
    /// t = l + w/2 from the road's right edge and the station s + a) with the road's kink there
    /// ([`Frame::kink_at`]`(a)`); `None` while all four stand on a smooth, unkinked road, as
    /// they do whenever the road has no verges of its own ([`Frame::has_verges`]) or the car
    /// is more than its reach inside both edges.
    ///
    /// As simuv2's `wheel.cpp` (`SimWheelUpdateRide`: `RtTrackGlobal2Local` of the wheel's
    /// position, then the segment's `surface->kFriction` and `kRollRes`), a wheel takes the
    /// surface under its centre: at body coordinates (x_w, y_w) = (a, ±y_f), (−b, ±y_r), with
    /// e = ψ − θ the car's heading against the road's, d = (X − Xᵢ, Y − Yᵢ) its position from the
    /// frame's station and t, n the road's tangent and left normal there, the wheel lies
    /// a = d·t + x_w·cos e − y_w·sin e along the road and l = d·n + x_w·sin e + y_w·cos e − κa²/2
    /// to the left of the centre line (the projection's second-order arc correction,
    /// [`crate::track::Track::project`]); past an edge by l − w/2 > 0 (or −l − w/2 on the
    /// right) it is on that side's [`crate::track::Verge`], border then side. A verge's own
    /// roughness is left out: smoothing the verges in the game changes none of 42 laps'
    /// outcomes, while adding them to cdbo's changes 10, 6 of them away from the game's
    /// (docs/results/torcs.md, "The road's roughness").
    #[inline]
    pub(super) fn wheel_ground(&self, s: &State, f: &Frame) -> Option<[Ground; 4]> {
        // A rough or kinked road: the wheels on it bounce.
        let rough_road = (f.roughness.is_rough() || f.kinked) && self.corners.is_some();
        if !f.has_verges && !rough_road {
            return None;
        }
        let (along, lateral) = f.local(s.x, s.y);
        if self.inside_edges(f, along, lateral, 0.0) && !rough_road {
            return None;
        }
        let road_rolling = f.rolling_resistance.unwrap_or(self.rolling);
        let mut out = [Ground {
            friction: f.friction,
            rolling: road_rolling,
            bumps: Bumps::NONE,
        }; 4];
        let mut off = false;
        for (i, (a, l)) in self
            .wheel_places(s, f, along, lateral)
            .into_iter()
            .enumerate()
        {
            let excess = l.abs() - f.half_width;
            let verge = &f.verges[if l > 0.0 { 0 } else { 1 }];
            let off_road = if excess > 0.0 {
                verge.surface_at(excess)
            } else {
                None
            };
            match off_road {
                Some(surface) => {
                    out[i] = Ground {
                        friction: surface.friction,
                        rolling: surface.rolling_resistance.unwrap_or(self.rolling),
                        bumps: Bumps::NONE,
                    };
                    off = true;
                }
                None if rough_road => {
                    // simuv2's t: the distance from the road's right edge.
                    let mut bumps = if f.roughness.is_rough() {
                        f.roughness.plain(f.s + a, l + f.half_width)
                    } else {
                        Bumps::NONE
                    };
                    if f.kinked {
                        (bumps.kink, bumps.kink_slope) = f.kink_at(a);
                    }
                    out[i].bumps = bumps;
                }
                None => {}
            }
        }
        (off || rough_road).then_some(out)
    }

    /// Whether a wheel stands on a raised kerb ([`crate::track::Verge::kerb_height`], whose
    /// ramp cdbo's wheels do not climb), or would, moved `reserve` metres further out from the
    /// centre line, stand on slippery ground: a verge's border or side whose friction is below
    /// `fraction`·μ_road (grass, sand, gravel; a flat kerb as grippy as the road is not). Each
    /// wheel stands where the step finds its ground (`wheel_ground`); a road without verges of
    /// its own has none.
    pub fn wheel_near_slippery(&self, s: &State, f: &Frame, reserve: f64, fraction: f64) -> bool {
        if !f.has_verges {
            return false;
        }
        let (along, lateral) = f.local(s.x, s.y);
        if self.inside_edges(f, along, lateral, reserve) {
            return false;
        }
        let places = self.wheel_places(s, f, along, lateral);
        places.into_iter().any(|(_, l)| {
            let past_edge = l.abs() - f.half_width;
            let verge = &f.verges[if l > 0.0 { 0 } else { 1 }];
            let on_kerb =
                verge.kerb_height > 0.0 && past_edge > 0.0 && past_edge <= verge.border_width;
            let excess = past_edge + reserve;
            on_kerb
                || (excess > 0.0
                    && verge
                        .surface_at(excess)
                        .is_some_and(|ground| ground.friction < fraction * f.friction))
        })
    }

    /// Whether every wheel of a car at (`along`, `lateral`) from the frame's station stands
    /// more than `reserve` inside both edges, whatever its heading: its reach, and what the
    /// road's bend adds over it, short of the edge.
    #[inline]
    pub(super) fn inside_edges(&self, f: &Frame, along: f64, lateral: f64, reserve: f64) -> bool {
        let far = along.abs() + self.reach;
        lateral.abs() + self.reach + reserve + 0.5 * f.curvature.abs() * far * far < f.half_width
    }

    /// Where each wheel's centre stands, front left, front right, rear left, rear right, the
    /// car at (`along`, `lateral`) from the frame's station: (a, l) along the road and left of
    /// the centre line, as [`Vehicle::wheel_ground`] places them.
    #[inline]
    pub(super) fn wheel_places(
        &self,
        s: &State,
        f: &Frame,
        along: f64,
        lateral: f64,
    ) -> [(f64, f64); 4] {
        let (se, ce) = f.relative_heading(s.yaw_sin_cos);
        let [yf, yr] = self.car.axles.half_track;
        let place = |xw: f64, yw: f64| {
            let a = along + xw * ce - yw * se;
            (a, lateral + xw * se + yw * ce - 0.5 * f.curvature * a * a)
        };
        [
            place(self.a, yf),
            place(self.a, -yf),
            place(-self.b, yr),
            place(-self.b, -yr),
        ]
    }
}
