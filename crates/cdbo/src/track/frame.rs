//! What the physics step and the projection read of a sample ([`Frame`]).

use super::{Roughness, Sample, Verge};

/// What the physics step and the projection read of a sample, packed in one place and with
/// its sines and cosines pre-computed once per track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Station position (m).
    pub x: f64,
    /// Station position (m).
    pub y: f64,
    /// Arc length (m).
    pub s: f64,
    /// Curvature (1/m).
    pub curvature: f64,
    /// Half the road width (m).
    pub half_width: f64,
    /// Surface friction.
    pub friction: f64,
    /// The surface's rolling resistance coefficient, if the track gives one.
    pub rolling_resistance: Option<f64>,
    /// The road surface's roughness.
    pub roughness: Roughness,
    /// What lies past the road's left and right edges, `[left, right]`.
    pub verges: [Verge; 2],
    /// Whether either verge differs from the road: a border or side of its own.
    pub has_verges: bool,
    /// Distance from the centre line to the left and right barriers (m): half the road's
    /// width plus the verge's border and side, or infinite where the verge has no barrier
    /// ([`Verge::barrier`]).
    pub barriers: [f64; 2],
    /// sin of the heading.
    pub sin_heading: f64,
    /// cos of the heading.
    pub cos_heading: f64,
    /// sin of the road's pitch atan(grade).
    pub sin_pitch: f64,
    /// cos of the pitch.
    pub cos_pitch: f64,
    /// sin of the banking.
    pub sin_banking: f64,
    /// cos of the banking.
    pub cos_banking: f64,
    /// Vertical curvature κ_v = dφ/ds of the pitch φ = atan(grade) (1/m): negative over a
    /// crest, positive in a dip; the pitch's change over [`VERTICAL_WINDOW_M`] of road.
    pub vertical_curvature: f64,
    /// The road's kinks under this station and its neighbours: the height z less its mean
    /// over [`VERTICAL_WINDOW_M`] around each station (m), at the stations
    /// [`KINK_REACH`] samples before it to as many after it ([`Frame::kink_at`]).
    pub kinks: [f64; KINK_SAMPLES],
    /// The stations' spacing (m).
    pub ds: f64,
    /// Whether any of [`Frame::kinks`] reaches [`FELT_KINK_M`].
    pub kinked: bool,
}

/// Stations either side of a frame whose kinks it keeps: a wheel stands within a car's reach
/// of the frame's station (the nearest to the car's centre), less than 3 m on a car of 4.5 m.
pub const KINK_REACH: usize = 3;
/// Kinks a frame keeps.
pub const KINK_SAMPLES: usize = 2 * KINK_REACH + 1;

/// The smallest kink a car's wheels meet (m of height off the road's smoothed profile): 2 mm,
/// a change of grade of about 0.3 % (at 30 m/s a step of 0.1 m/s in the ground's vertical
/// speed). Below it the wheels' bounce costs grip it cannot measure against the game's laps
/// and would run the bounce over most of every lap (measured: Forza's laps of car1-trb1 cost
/// 2 % more simulator time at 2 mm, 66 % more at 0.1 mm, for the same agreement).
pub const FELT_KINK_M: f64 = 0.002;

/// The length of road (m) over which a frame's vertical curvature is measured: a car's
/// wheelbase or two. The heights of TORCS's tracks are linear on sub-segments of a few metres
/// (their `profil steps`), so the pitch is piecewise constant; the car's quasi-static load
/// takes its changes spread over this window (measured: windows of 2 to 30 m place the game's
/// failures alike), and a car on springs meets what is left, the height less its mean over
/// the window, as a kink under each wheel ([`Frame::kinks`], [`crate::vehicle::bounce`]).
pub const VERTICAL_WINDOW_M: f64 = 6.0;

impl Frame {
    /// The road's kink (m, [`Frame::kinks`]) `along` metres from the station, and its slope
    /// along the road: linear between the stations, as TORCS's heights are; held at the
    /// outermost stations' past them.
    #[inline]
    pub fn kink_at(&self, along: f64) -> (f64, f64) {
        let p = (along / self.ds + KINK_REACH as f64).clamp(0.0, (KINK_SAMPLES - 1) as f64);
        let k = (p.floor() as usize).min(KINK_SAMPLES - 2);
        let t = p - k as f64;
        let (a, b) = (self.kinks[k], self.kinks[k + 1]);
        (a + t * (b - a), (b - a) / self.ds)
    }

    /// The point (x, y) in the station's road coordinates: (along, left) of it, the heading's
    /// unit vector and its left normal.
    #[inline]
    pub fn local(&self, x: f64, y: f64) -> (f64, f64) {
        let (dx, dy) = (x - self.x, y - self.y);
        (
            dx * self.cos_heading + dy * self.sin_heading,
            -dx * self.sin_heading + dy * self.cos_heading,
        )
    }

    /// (sin(ψ − θ), cos(ψ − θ)) of a heading ψ given as (sin ψ, cos ψ), against the road's θ.
    #[inline]
    pub fn relative_heading(&self, (sin, cos): (f64, f64)) -> (f64, f64) {
        (
            sin * self.cos_heading - cos * self.sin_heading,
            cos * self.cos_heading + sin * self.sin_heading,
        )
    }

    pub(super) fn of(c: &Sample) -> Frame {
        let (sin_heading, cos_heading) = c.heading.sin_cos();
        let (sin_pitch, cos_pitch) = c.grade.atan().sin_cos();
        let (sin_banking, cos_banking) = c.banking.sin_cos();
        Frame {
            x: c.x,
            y: c.y,
            s: c.s,
            curvature: c.curvature,
            half_width: 0.5 * c.width,
            friction: c.friction,
            rolling_resistance: c.rolling_resistance,
            roughness: c.roughness,
            verges: c.verges,
            has_verges: c
                .verges
                .iter()
                .any(|v| v.border_width > 0.0 || v.side_width > 0.0),
            barriers: c.verges.map(|v| {
                if v.barrier {
                    0.5 * c.width + v.border_width + v.side_width
                } else {
                    f64::INFINITY
                }
            }),
            sin_heading,
            cos_heading,
            sin_pitch,
            cos_pitch,
            sin_banking,
            cos_banking,
            vertical_curvature: 0.0,
            kinks: [0.0; KINK_SAMPLES],
            ds: 1.0,
            kinked: false,
        }
    }
}
