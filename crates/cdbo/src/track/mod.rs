//! Race tracks: a closed centre line sampled at uniform arc length, with elevation, banking,
//! width and road friction at every sample.
//!
//! Tracks come from TORCS / Speed Dreams XML files ([`torcs`]), TUMFTM racetrack-database
//! centre lines ([`csv`]) or the built-in circuits ([`builtin`]); [`catalog`] resolves a name.

pub mod builtin;
pub mod catalog;
pub mod csv;
pub mod spline;
pub mod torcs;

use serde::Serialize;

/// The track's state at one arc-length station of the centre line.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Arc length from the start line (m).
    pub s: f64,
    /// Position (m), x east, y north.
    pub x: f64,
    /// Position (m).
    pub y: f64,
    /// Elevation of the centre line (m).
    pub z: f64,
    /// Heading of the centre line (rad, counter-clockwise from +x).
    pub heading: f64,
    /// Signed curvature κ = dθ/ds (1/m), positive for a left turn.
    pub curvature: f64,
    /// Grade dz/ds (fraction, positive uphill).
    pub grade: f64,
    /// Banking angle (rad), positive when the left edge is higher (helps left turns).
    pub banking: f64,
    /// Full width of the road (m).
    pub width: f64,
    /// Friction coefficient of the road surface (TORCS `friction`), scales the tyre grip.
    pub friction: f64,
    /// Rolling resistance coefficient of the road surface (TORCS `rolling resistance`:
    /// simuv2 takes it from the road, F = c_rr·F_z), when the track names one; else the
    /// car's tyres give it.
    pub rolling_resistance: Option<f64>,
    /// The road surface's roughness ([`Roughness`]; TORCS `roughness`).
    #[serde(skip)]
    pub roughness: Roughness,
    /// What lies past the road's left and right edges ([`Verge`]), `[left, right]`.
    #[serde(skip)]
    pub verges: [Verge; 2],
}

/// A surface a wheel can stand on: its TORCS `friction`, `rolling resistance` (`None`: the
/// car's tyres give the rolling resistance) and roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Friction coefficient, scales the tyre's grip.
    pub friction: f64,
    /// Rolling resistance coefficient, F = c_rr·F_z, if the track gives one.
    pub rolling_resistance: Option<f64>,
    /// Its roughness.
    pub roughness: Roughness,
}

impl Surface {
    /// Friction 1, the tyres' rolling resistance, smooth.
    pub const PLAIN: Surface = Surface {
        friction: 1.0,
        rolling_resistance: None,
        roughness: Roughness::NONE,
    };
}

/// A surface's roughness as TORCS's simuv2 lays it under the wheels (`RtTrackHeightL`): the
/// ground under a wheel at distance l along its segment and t across it (from the segment's
/// right edge) stands h = A·sin(k·t)·sin(k·l) above the smooth surface, A = R/2 and k = 2π/λ
/// of the file's `roughness` R and `roughness wavelength` λ (`track4.cpp`: `kRoughness`,
/// `kRoughWaveLen`). Most roads are smooth; Aalborg's is R = 0.7 to 1.5 cm at λ = 0.7 to
/// 0.9 m in places, G-Track 1's 1 cm at 1 m; grass is 5 cm at 0.5 m. The wheels' bounce over
/// a rough road ([`crate::sim::bounce`]) costs grip.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Roughness {
    /// Amplitude A (m).
    pub amplitude: f64,
    /// Wavenumber k (rad/m).
    pub wavenumber: f64,
}

impl Roughness {
    /// A smooth surface.
    pub const NONE: Roughness = Roughness {
        amplitude: 0.0,
        wavenumber: 0.0,
    };

    /// From a file's `roughness` R and `roughness wavelength` λ > 0 (m): A = R/2, k = 2π/λ.
    pub fn from_file(roughness: f64, wavelength: f64) -> Roughness {
        Roughness {
            amplitude: 0.5 * roughness,
            wavenumber: std::f64::consts::TAU / wavelength,
        }
    }

    /// Whether it is rough enough to feel: an amplitude of [`FELT_ROUGHNESS_M`] or more.
    #[inline]
    pub fn is_rough(&self) -> bool {
        self.amplitude >= FELT_ROUGHNESS_M
    }

    /// The bumps a wheel meets along its path on this surface, t metres across it from its
    /// right edge (a plain surface: A·sin(k·t) is the amplitude along), l metres along.
    #[inline]
    pub fn plain(&self, along: f64, across: f64) -> Bumps {
        Bumps {
            amplitude: self.amplitude * (self.wavenumber * across).sin(),
            wavenumber: self.wavenumber,
            along,
            kink: 0.0,
            kink_slope: 0.0,
        }
    }
}

/// The smallest amplitude A of a surface's roughness cdbo's car feels (m): half a millimetre.
/// Below it the wheels' bounce takes less than 0.2 % of their grip up to 80 m/s (E-Track 2's
/// and E-Track 3's roads, A = 0.25 mm at λ = 2 m) and would triple the cost of the physics
/// step on those tracks; at A = 0.5 mm it takes 0.7 % at 80 m/s (car1-trb1 at λ of 1 to 2 m),
/// at Aalborg's 7.5 mm (λ = 0.7 m) 6 % at 20 m/s and 12 % at 60 to 80 m/s.
pub const FELT_ROUGHNESS_M: f64 = 0.0005;

/// The ground's height along a wheel's path above the road's smoothed profile, h(δ) =
/// a·sin(k·(l + δ)) + k₀ + k′·δ at δ metres past where the wheel stands (l along the surface):
/// a rough surface's bumps ([`Roughness::plain`] at the wheel's place) and the road's kink
/// there ([`Frame::kink_at`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bumps {
    /// The amplitude a (m) across the wheel's path.
    pub amplitude: f64,
    /// The wavenumber k (rad/m).
    pub wavenumber: f64,
    /// Where the wheel stands along the surface, l (m).
    pub along: f64,
    /// The road's kink under the wheel, k (m, [`Frame::kink_at`]).
    pub kink: f64,
    /// Its slope along the wheel's path, k′ (m/m).
    pub kink_slope: f64,
}

impl Bumps {
    /// None: a smooth surface.
    pub const NONE: Bumps = Bumps {
        amplitude: 0.0,
        wavenumber: 0.0,
        along: 0.0,
        kink: 0.0,
        kink_slope: 0.0,
    };

    /// Whether there is anything under the wheel.
    #[inline]
    pub fn any(&self) -> bool {
        self.amplitude != 0.0 || self.kink != 0.0 || self.kink_slope != 0.0
    }

    /// h(δ) (m).
    #[inline]
    pub fn height(&self, ahead: f64) -> f64 {
        let kink = self.kink + self.kink_slope * ahead;
        if self.amplitude == 0.0 {
            return kink;
        }
        kink + self.amplitude * (self.wavenumber * (self.along + ahead)).sin()
    }
}

/// What lies past one edge of the road, as TORCS's `track4.cpp` builds it (`AddSides`): next
/// to the road a border (`Left Border` / `Right Border`: `width`, `surface`; a kerb, a strip of
/// grass), then a side (`Left Side` / `Right Side`: `start width` … `end width`, `surface`;
/// grass, gravel, a run-off), then the barrier. simuv2 finds each wheel's segment (road, border
/// or side) under the wheel's centre (`wheel.cpp`: `RtTrackGlobal2Local` of the wheel's
/// position) and takes that segment's surface's `kFriction` and `kRollRes` for the wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verge {
    /// Width of the border (m); 0 without one.
    pub border_width: f64,
    /// The border's surface.
    pub border: Surface,
    /// How high a kerb the border is (m; its `height` where its `style` is `curb`, else 0):
    /// TORCS raises the kerb's outer edge by it, a ramp cdbo's wheels do not climb.
    pub kerb_height: f64,
    /// Width of the side past the border (m); 0 without one.
    pub side_width: f64,
    /// The side's surface.
    pub side: Surface,
    /// Whether a barrier stands past the side (TORCS version-4 files: `track4.cpp` closes
    /// every side with one), at half the road's width plus the border's and the side's from
    /// the centre line; simuv2 collides the body's corners with it (`collide.cpp`).
    pub barrier: bool,
}

impl Verge {
    /// No border and no side: the road's surface is taken on past its edge (the built-in and
    /// CSV tracks, TORCS version-3 files).
    pub const NONE: Verge = Verge {
        border_width: 0.0,
        border: Surface::PLAIN,
        kerb_height: 0.0,
        side_width: 0.0,
        side: Surface::PLAIN,
        barrier: false,
    };

    /// The surface `excess` metres past the road's edge (excess > 0): the border's within its
    /// width, then the side's; past the side (at the barrier) the side's, or the border's when
    /// there is no side; `None` (the road's) when there is neither.
    #[inline]
    pub fn surface_at(&self, excess: f64) -> Option<&Surface> {
        if self.border_width > 0.0 && (excess <= self.border_width || self.side_width <= 0.0) {
            Some(&self.border)
        } else if self.side_width > 0.0 {
            Some(&self.side)
        } else {
            None
        }
    }
}

/// How far the centre line's end is from its start: a closed track has both near zero.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Closure {
    /// Distance between end and start points (m).
    pub gap_m: f64,
    /// Difference between end and start headings, wrapped to [-180°, 180°] (deg).
    pub heading_deg: f64,
}

/// A closed race track.
#[derive(Debug, Clone)]
pub struct Track {
    /// Display name.
    pub name: String,
    /// Where it was loaded from (file path or `builtin:NAME`).
    pub source: String,
    /// Length of the centre line (m).
    pub length: f64,
    /// Closure error of the raw geometry before sampling.
    pub closure: Closure,
    /// Arc-length spacing of `samples` (m); `samples.len() as f64 * ds == length`.
    pub ds: f64,
    /// Samples at s = i·ds, i = 0..n; the track is periodic (sample n would be sample 0).
    pub samples: Vec<Sample>,
    /// Warnings met while loading (missing entity files, unknown surfaces, ...).
    pub warnings: Vec<String>,
    /// Trigonometry of each sample, pre-computed for the physics step.
    frames: Vec<Frame>,
}

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
/// the window, as a kink under each wheel ([`Frame::kinks`], [`crate::sim::bounce`]).
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

    fn of(c: &Sample) -> Frame {
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

/// Where a point lies relative to the centre line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Index of the sample whose station is nearest.
    pub index: usize,
    /// Arc length of the foot point (m), in [0, length).
    pub s: f64,
    /// Signed lateral offset (m), positive to the left of the centre line.
    pub lateral: f64,
}

impl Track {
    /// A track from samples at s = i·ds, ds = length / samples.len().
    pub fn new(
        name: &str,
        source: &str,
        length: f64,
        closure: Closure,
        samples: Vec<Sample>,
        warnings: Vec<String>,
    ) -> Track {
        let ds = length / samples.len() as f64;
        let mut frames: Vec<Frame> = samples.iter().map(Frame::of).collect();
        // κ_v(sᵢ) = (φ(sᵢ + h) − φ(sᵢ − h)) / 2h around the lap, 2h ≈ VERTICAL_WINDOW_M.
        let n = samples.len();
        let h = ((0.5 * VERTICAL_WINDOW_M / ds).round() as usize).clamp(1, (n / 2).max(1));
        for (i, f) in frames.iter_mut().enumerate() {
            let pitch = |j: usize| samples[j % n].grade.atan();
            f.vertical_curvature = (pitch(i + h) - pitch(i + n - h)) / (2 * h) as f64 / ds;
        }
        // The kinks: z less its mean over the window around each station (the heights
        // taken relative to the station's own, since z need not return to its start).
        let z = |j: usize| samples[j % n].z;
        let kink: Vec<f64> = (0..n)
            .map(|i| {
                let mean = (0..=2 * h).map(|k| z(i + n + k - h) - z(i)).sum::<f64>();
                -mean / (2 * h + 1) as f64
            })
            .collect();
        for (i, f) in frames.iter_mut().enumerate() {
            for (k, v) in f.kinks.iter_mut().enumerate() {
                *v = kink[(i + n + k - KINK_REACH) % n];
            }
            f.ds = ds;
            f.kinked = f.kinks.iter().any(|k| k.abs() >= FELT_KINK_M);
        }
        Track {
            name: name.to_owned(),
            source: source.to_owned(),
            length,
            closure,
            ds,
            samples,
            warnings,
            frames,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: a track has at least a few samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The sample at index `i`, wrapping around the lap.
    #[inline]
    pub fn sample(&self, i: usize) -> &Sample {
        let n = self.samples.len();
        &self.samples[if i < n { i } else { i % n }]
    }

    /// Whether the track gives what lies past its road's edges anywhere ([`Frame::has_verges`]):
    /// TORCS version-4 files do; the built-in and CSV tracks, where a learning lap's reserve
    /// of road is the car's centre [`LapConfig::off_track_margin`](crate::sim::LapConfig::off_track_margin)
    /// from the edge, do not.
    pub fn has_verges(&self) -> bool {
        self.frames.iter().any(|f| f.has_verges)
    }

    /// The pre-computed trigonometry of sample `i` (wrapping around the lap).
    #[inline]
    pub fn frame(&self, i: usize) -> &Frame {
        let n = self.frames.len();
        &self.frames[if i < n { i } else { i % n }]
    }

    /// An arc length wrapped into [0, length): a subtraction for the common near-lap values.
    #[inline]
    pub fn wrap(&self, s: f64) -> f64 {
        if s < 0.0 {
            if s >= -self.length {
                s + self.length
            } else {
                s.rem_euclid(self.length)
            }
        } else if s >= self.length {
            if s < 2.0 * self.length {
                s - self.length
            } else {
                s.rem_euclid(self.length)
            }
        } else {
            s
        }
    }

    /// The index of the sample at or before arc length `s` (wrapped into the lap).
    #[inline]
    pub fn index_at(&self, s: f64) -> usize {
        let s = self.wrap(s);
        ((s / self.ds) as usize).min(self.samples.len() - 1)
    }

    /// The centre-line point at station `s` (wrapping around the lap): the arc of curvature
    /// κ from the sample before it, reached along its chord, of length a·sin(κa/2)/(κa/2)
    /// at the angle κa/2 from the sample's heading (a the distance from the sample).
    #[inline]
    pub fn point_at(&self, s: f64) -> (f64, f64) {
        let s = self.wrap(s);
        let f = &self.frames[self.index_at(s)];
        let a = s - f.s;
        let half_turn = 0.5 * f.curvature * a;
        let (sin, cos) = half_turn.sin_cos();
        let chord = if half_turn == 0.0 {
            a
        } else {
            a * sin / half_turn
        };
        (
            f.x + chord * (f.cos_heading * cos - f.sin_heading * sin),
            f.y + chord * (f.sin_heading * cos + f.cos_heading * sin),
        )
    }

    /// The point `d` metres left of the centre line (right if negative) at station `s`:
    /// c(s) + d·n(s), n = (−sin θ, cos θ) the left normal at the heading θ = θᵢ + κᵢ·(s − sᵢ)
    /// along the arc from the sample before it; the centre-line point itself when d = 0.
    #[inline]
    pub fn point_off(&self, s: f64, d: f64) -> (f64, f64) {
        let (x, y) = self.point_at(s);
        if d == 0.0 {
            return (x, y);
        }
        offset_left((x, y), self.heading_sin_cos(s), d)
    }

    /// (sin θ, cos θ) of the centre line's heading θ = θᵢ + κᵢ·(s − sᵢ) at station `s`
    /// (wrapping around the lap), along the arc from the sample before it.
    #[inline]
    pub fn heading_sin_cos(&self, s: f64) -> (f64, f64) {
        let s = self.wrap(s);
        let f = &self.frames[self.index_at(s)];
        let (sin, cos) = (f.curvature * (s - f.s)).sin_cos();
        (
            f.sin_heading * cos + f.cos_heading * sin,
            f.cos_heading * cos - f.sin_heading * sin,
        )
    }

    /// Projects (x, y) on the centre line, searching from `hint` (the last known index).
    ///
    /// Walks sample to sample while the point's tangential offset d = (p − cᵢ)·tᵢ lies outside
    /// [−ds/2, ds/2]; O(1) when called every physics step with the previous index.
    #[inline]
    pub fn project(&self, x: f64, y: f64, hint: usize) -> Projection {
        let n = self.samples.len();
        let mut i = if hint < n { hint } else { hint % n };
        let half = 0.5 * self.ds;
        for _ in 0..n {
            let c = &self.frames[i];
            let (sin, cos) = (c.sin_heading, c.cos_heading);
            let (dx, dy) = (x - c.x, y - c.y);
            let along = dx * cos + dy * sin;
            if along > half {
                i = if i + 1 == n { 0 } else { i + 1 };
            } else if along < -half {
                i = if i == 0 { n - 1 } else { i - 1 };
            } else {
                // Second-order correction for the arc between stations (κ·along ≪ 1):
                // lateral = l − κa²/2, station offset = a(1 + κl).
                let l = -dx * sin + dy * cos;
                let lateral = l - 0.5 * c.curvature * along * along;
                let s = self.wrap(c.s + along * (1.0 + c.curvature * l));
                return Projection {
                    index: i,
                    s,
                    lateral,
                };
            }
        }
        self.project_global(x, y)
    }

    /// Projects (x, y) by scanning every sample (used when no hint is known).
    pub fn project_global(&self, x: f64, y: f64) -> Projection {
        let nearest = self
            .samples
            .iter()
            .enumerate()
            .map(|(i, c)| (i, (c.x - x).powi(2) + (c.y - y).powi(2)))
            .fold(
                (0, f64::INFINITY),
                |best, cur| if cur.1 < best.1 { cur } else { best },
            )
            .0;
        let c = &self.samples[nearest];
        let (sin, cos) = c.heading.sin_cos();
        let (dx, dy) = (x - c.x, y - c.y);
        Projection {
            index: nearest,
            s: (c.s + dx * cos + dy * sin).rem_euclid(self.length),
            lateral: -dx * sin + dy * cos,
        }
    }

    /// Smallest radius of curvature along the lap (m).
    pub fn min_radius(&self) -> f64 {
        let k = self
            .samples
            .iter()
            .map(|c| c.curvature.abs())
            .fold(0.0, f64::max);
        if k > 0.0 { 1.0 / k } else { f64::INFINITY }
    }

    /// Smallest road width along the lap (m).
    pub fn min_width(&self) -> f64 {
        self.samples
            .iter()
            .map(|c| c.width)
            .fold(f64::INFINITY, f64::min)
    }

    /// Lowest and highest elevation of the centre line (m).
    pub fn z_range(&self) -> (f64, f64) {
        self.samples
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c.z), hi.max(c.z))
            })
    }

    /// Builds a track by sampling a chain of constant-curvature pieces at uniform arc length.
    pub fn from_pieces(name: &str, source: &str, pieces: &[Piece], warnings: Vec<String>) -> Track {
        let length: f64 = pieces.iter().map(|p| p.length).sum();
        let n = (length / TARGET_DS).round().max(8.0) as usize;
        let ds = length / n as f64;
        let mut samples = Vec::with_capacity(n);
        let (mut x, mut y, mut heading, mut start) = (0.0, 0.0, 0.0, 0.0);
        let mut pieces_iter = pieces.iter().filter(|p| p.length > 0.0).peekable();
        let mut i = 0;
        while let Some(p) = pieces_iter.next() {
            let end = start + p.length;
            let last = pieces_iter.peek().is_none();
            while i < n && (i as f64 * ds < end || last) {
                let s = i as f64 * ds;
                let d = s - start;
                let (px, py, ph) = advance(x, y, heading, p.curvature, d);
                let t = d / p.length;
                samples.push(Sample {
                    s,
                    x: px,
                    y: py,
                    z: p.z0 + (p.z1 - p.z0) * t,
                    heading: ph,
                    curvature: p.curvature,
                    grade: (p.z1 - p.z0) / p.length,
                    banking: p.banking0 + (p.banking1 - p.banking0) * t,
                    width: p.width,
                    friction: p.friction,
                    rolling_resistance: p.rolling_resistance,
                    roughness: p.roughness,
                    verges: p.verges,
                });
                i += 1;
            }
            (x, y, heading) = advance(x, y, heading, p.curvature, p.length);
            start = end;
        }
        let heading_err = (heading + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        let closure = Closure {
            gap_m: x.hypot(y),
            heading_deg: heading_err.to_degrees(),
        };
        debug_assert!((ds - length / samples.len() as f64).abs() < 1e-9);
        Track::new(name, source, length, closure, samples, warnings)
    }
}

/// Largest gap between a circuit's end and its start (m) accepted as closed. The 38 tracks of
/// TORCS 1.3.7 and Speed Dreams' Allondaz miss by at most 0.27 m (wheel-2), from the game's
/// own rounding of segment lengths; a gap of metres is a mistake in the file.
pub const CLOSURE_GAP_M: f64 = 1.0;

/// Largest difference between a circuit's end and start headings accepted as closed (deg);
/// real tracks are within 0.02°.
pub const CLOSURE_HEADING_DEG: f64 = 2.0;

/// What a loader does with a track whose end misses its start by more than
/// [`CLOSURE_GAP_M`] or [`CLOSURE_HEADING_DEG`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ends {
    /// Refuse it, naming the gap: a lap must end where it starts (the default).
    #[default]
    MustMeet,
    /// Load it with a warning naming the gap (the user asked for an open track).
    MayMiss,
}

impl Closure {
    /// Whether the ends meet within [`CLOSURE_GAP_M`] and [`CLOSURE_HEADING_DEG`].
    pub fn is_closed(&self) -> bool {
        self.gap_m <= CLOSURE_GAP_M && self.heading_deg.abs() <= CLOSURE_HEADING_DEG
    }

    /// "its end misses its start by G m and H°".
    pub fn describe(&self) -> String {
        format!(
            "its end misses its start by {:.2} m and {:.2}° (a circuit closes within {CLOSURE_GAP_M} m and {CLOSURE_HEADING_DEG}°)",
            self.gap_m, self.heading_deg
        )
    }
}

/// Longest track accepted (m): longer files are refused rather than sampled.
pub const MAX_LENGTH_M: f64 = 100_000.0;

/// Target spacing of the samples (m).
pub const TARGET_DS: f64 = 1.0;

/// A piece of centre line of constant curvature, the unit TORCS sub-divides segments into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Arc length (m).
    pub length: f64,
    /// Signed curvature (1/m), positive left.
    pub curvature: f64,
    /// Elevation at the start and end (m), linear in between.
    pub z0: f64,
    /// Elevation at the end (m).
    pub z1: f64,
    /// Banking at the start (rad).
    pub banking0: f64,
    /// Banking at the end (rad).
    pub banking1: f64,
    /// Road width (m).
    pub width: f64,
    /// Surface friction.
    pub friction: f64,
    /// Surface rolling resistance, if the track gives one.
    pub rolling_resistance: Option<f64>,
    /// The surface's roughness.
    pub roughness: Roughness,
    /// What lies past the left and right edges, `[left, right]`.
    pub verges: [Verge; 2],
}

impl Piece {
    /// A level, unbanked piece 12 m wide on a friction-1 surface, the tyres' rolling
    /// resistance.
    pub fn flat(length: f64, curvature: f64) -> Piece {
        Piece {
            length,
            curvature,
            z0: 0.0,
            z1: 0.0,
            banking0: 0.0,
            banking1: 0.0,
            width: 12.0,
            friction: 1.0,
            rolling_resistance: None,
            roughness: Roughness::NONE,
            verges: [Verge::NONE; 2],
        }
    }
}

/// Moves a pose along a circular arc of curvature `k` by arc length `d`:
/// θ' = θ + k·d, x' = x + (sin θ' − sin θ)/k, y' = y − (cos θ' − cos θ)/k (a line when k = 0).
#[inline]
pub fn advance(x: f64, y: f64, heading: f64, k: f64, d: f64) -> (f64, f64, f64) {
    let h1 = heading + k * d;
    if (k * d).abs() < 1e-9 {
        (x + d * heading.cos(), y + d * heading.sin(), h1)
    } else {
        (
            x + (h1.sin() - heading.sin()) / k,
            y - (h1.cos() - heading.cos()) / k,
            h1,
        )
    }
}

/// The point `d` metres left of `(x, y)` (right if negative) on a line heading θ, given as
/// `heading_sin_cos` = (sin θ, cos θ): (x − d·sin θ, y + d·cos θ). The TORCS robot's
/// `drive::offset_left` is the same arithmetic (`tests/robot_drive.rs`).
#[inline]
pub fn offset_left((x, y): (f64, f64), heading_sin_cos: (f64, f64), d: f64) -> (f64, f64) {
    let (sin_heading, cos_heading) = heading_sin_cos;
    (x - d * sin_heading, y + d * cos_heading)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(radius: f64) -> Track {
        let p = Piece {
            width: 10.0,
            ..Piece::flat(std::f64::consts::TAU * radius, 1.0 / radius)
        };
        Track::from_pieces("circle", "test", &[p], vec![])
    }

    /// A circle whose height is z(s) = A·cos(2πs/L), built of 10 cm pieces each linear in z: the
    /// frames' vertical curvature is dφ/ds = z''/(1 + z'²), φ = atan z', within 2 % of its
    /// largest value, negative over the crest (s = 0) and positive in the dip (s = L/2).
    #[test]
    fn the_vertical_curvature_is_the_pitchs_rate_of_change() {
        let (radius, amplitude) = (100.0, 5.0);
        let length = std::f64::consts::TAU * radius;
        let n = (10.0 * length).round() as usize;
        let ds = length / n as f64;
        let z = |s: f64| amplitude * (std::f64::consts::TAU * s / length).cos();
        let pieces: Vec<Piece> = (0..n)
            .map(|i| Piece {
                z0: z(i as f64 * ds),
                z1: z((i + 1) as f64 * ds),
                width: 10.0,
                ..Piece::flat(ds, 1.0 / radius)
            })
            .collect();
        let t = Track::from_pieces("hills", "test", &pieces, vec![]);
        let w = std::f64::consts::TAU / length;
        let largest = amplitude * w * w;
        for i in 0..t.len() {
            let s = t.sample(i).s;
            let (dz, ddz) = (-amplitude * w * (w * s).sin(), -largest * (w * s).cos());
            let expected = ddz / (1.0 + dz * dz);
            let got = t.frame(i).vertical_curvature;
            assert!(
                (got - expected).abs() < 0.02 * largest,
                "s = {s}: {got} vs {expected}"
            );
        }
        assert!(t.frame(0).vertical_curvature < -0.98 * largest);
        assert!(t.frame(t.len() / 2).vertical_curvature > 0.98 * largest);
    }

    /// A hill of straight grades (up at 4 % from 100 m, down from 200 m, level from 300 m): a
    /// frame's kinks are the heights less their mean over the window around each station,
    /// as brute force has them: zero on a straight grade and on the level, largest at the
    /// crest (the road above its smoothing by g·ds·h(h+1)/(2h + 1), h stations either side),
    /// below it in the dips; `kink_at` interpolates them and their slope between stations.
    #[test]
    fn the_kinks_are_the_profile_less_its_smoothing() {
        let g = 0.04;
        let z = |s: f64| g * (s.clamp(100.0, 200.0) - 100.0) - g * (s.clamp(200.0, 300.0) - 200.0);
        let pieces: Vec<Piece> = (0..600)
            .map(|i| Piece {
                z0: z(i as f64),
                z1: z((i + 1) as f64),
                width: 10.0,
                ..Piece::flat(1.0, 0.01)
            })
            .collect();
        let t = Track::from_pieces("hill", "test", &pieces, vec![]);
        let n = t.len();
        let h = ((0.5 * VERTICAL_WINDOW_M / t.ds).round()) as usize;
        let at = |s: f64| (s / t.ds).round() as usize;
        for i in 0..n {
            let mean = (0..=2 * h)
                .map(|k| t.sample(i + n + k - h).z - t.sample(i).z)
                .sum::<f64>()
                / (2 * h + 1) as f64;
            let f = t.frame(i);
            assert!((f.kinks[KINK_REACH] + mean).abs() < 1e-12, "{i}");
            for k in 0..KINK_SAMPLES {
                assert_eq!(
                    f.kinks[k],
                    t.frame(i + n + k - KINK_REACH).kinks[KINK_REACH]
                );
            }
        }
        for s in [50.0, 150.0, 250.0, 450.0] {
            let f = t.frame(at(s));
            assert!(
                f.kinks.iter().all(|k| k.abs() < 1e-12),
                "{s}: {:?}",
                f.kinks
            );
            assert!(!f.kinked);
        }
        let crest = t.frame(at(200.0));
        let top = g * t.ds * (h * (h + 1)) as f64 / (2 * h + 1) as f64;
        assert!(
            (crest.kinks[KINK_REACH] - top).abs() < 1e-9,
            "{:?}",
            crest.kinks
        );
        assert!(crest.kinked && t.frame(at(100.0)).kinks[KINK_REACH] < -0.4 * top);
        let (k, slope) = crest.kink_at(0.25 * t.ds);
        let (a, b) = (crest.kinks[KINK_REACH], crest.kinks[KINK_REACH + 1]);
        assert!((k - (a + 0.25 * (b - a))).abs() < 1e-12 && (slope - (b - a) / t.ds).abs() < 1e-12);
    }

    #[test]
    fn a_full_circle_closes_and_has_its_radius() {
        let t = circle(100.0);
        assert!(
            t.closure.gap_m < 1e-9 && t.closure.heading_deg.abs() < 1e-9,
            "{:?}",
            t.closure
        );
        assert!((t.length - 200.0 * std::f64::consts::PI).abs() < 1e-9);
        for c in &t.samples {
            assert!((c.x.hypot(c.y - 100.0) - 100.0).abs() < 1e-9);
        }
        assert!((t.min_radius() - 100.0).abs() < 1e-9);
    }

    /// On a circle of radius R from (0, 0) heading +x, the station s lies at angle s/R:
    /// (R·sin(s/R), R − R·cos(s/R)), between samples and across the start line.
    #[test]
    fn points_between_samples_lie_on_the_arc() {
        let t = circle(100.0);
        for s in [0.0, 0.37, 123.456, t.length - 0.01, t.length + 5.0, -2.5] {
            let (x, y) = t.point_at(s);
            let a = s / 100.0;
            let (ex, ey) = (100.0 * a.sin(), 100.0 - 100.0 * a.cos());
            assert!(
                (x - ex).abs() < 1e-9 && (y - ey).abs() < 1e-9,
                "s {s}: ({x}, {y})"
            );
        }
        let straight = Track::from_pieces("line", "test", &[Piece::flat(50.0, 0.0)], vec![]);
        assert_eq!(straight.point_at(12.25), (12.25, 0.0));
    }

    #[test]
    fn projection_recovers_station_and_offset() {
        let t = circle(100.0);
        // A point 3 m outside the circle (to the right of a left turn) at angle 1 rad.
        let (ang, r) = (1.0_f64, 103.0);
        let (x, y) = (r * ang.sin(), 100.0 - r * ang.cos());
        for hint in [0, 50, 300, t.len() - 1] {
            let p = t.project(x, y, hint);
            assert!((p.s - 100.0 * ang).abs() < 1e-4, "s {}", p.s);
            assert!((p.lateral + 3.0).abs() < 1e-4, "lateral {}", p.lateral);
        }
        let g = t.project_global(x, y);
        assert!((g.s - 100.0).abs() < 0.01 && (g.lateral + 3.0).abs() < 0.01);
    }
}
