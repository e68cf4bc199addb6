//! Race tracks: a closed centre line sampled at uniform arc length, with elevation, banking,
//! width and road friction at every sample.
//!
//! Tracks come from TORCS / Speed Dreams XML files ([`torcs`]), TUMFTM racetrack-database
//! centre lines ([`csv`]) or the built-in circuits ([`builtin`]); [`catalog`] resolves a name.

pub mod builtin;
pub mod catalog;
pub mod csv;
mod frame;
pub mod spline;
mod surface;
pub mod torcs;

use serde::Serialize;

pub use frame::{FELT_KINK_M, Frame, KINK_REACH, KINK_SAMPLES, VERTICAL_WINDOW_M};
pub use surface::{Bumps, FELT_ROUGHNESS_M, Roughness, Surface, Verge};

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
    #[inline(always)]
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
