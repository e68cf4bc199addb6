//! A racing line as a [`Track`], for the quasi-steady-state limit on its own curvature and
//! arc length.
//!
//! Periodic cubic splines x(u), y(u) run through the line's points pⱼ, u the chord length
//! from p₀ (within 2 parts in 10⁴ of the arc length at 3 m spacing and 50 m radius); the track
//! samples them every ≈ [`TARGET_DS`] m of u, with heading atan2(y′, x′) and curvature
//! κ = (x′y″ − y′x″)/(x′² + y′²)^{3/2}. Each sample takes the road of the centre-line station
//! it lies across (linear in u between stations): its banking β, width, friction and rolling
//! resistance, and its elevation raised by d·sin β for the offset d (the banked road is higher
//! on its left when β > 0); the grade is the line's own, the central difference of those
//! elevations.

use super::RacingLine;
use crate::track::spline::PeriodicSpline;
use crate::track::{Closure, Sample, TARGET_DS, Track};

impl RacingLine {
    /// The line as a closed track over `track`'s road (the track the line was computed on),
    /// named "NAME racing line".
    pub fn path(&self, track: &Track) -> Track {
        let n = self.points.len();
        let mut u = Vec::with_capacity(n);
        let mut period = 0.0;
        for j in 0..n {
            u.push(period);
            let (p, q) = (self.points[j], self.points[(j + 1) % n]);
            period += (q[0] - p[0]).hypot(q[1] - p[1]);
        }
        let xs: Vec<f64> = self.points.iter().map(|p| p[0]).collect();
        let ys: Vec<f64> = self.points.iter().map(|p| p[1]).collect();
        let (sx, sy) = (
            PeriodicSpline::new(&u, &xs, period),
            PeriodicSpline::new(&u, &ys, period),
        );
        let m = ((period / TARGET_DS).round() as usize).max(8);
        let ds = period / m as f64;
        let h = self.centre_length_m / n as f64;
        let mut samples: Vec<Sample> = Vec::with_capacity(m);
        let mut j = 0;
        let mut heading = 0.0;
        for k in 0..m {
            let uk = k as f64 * ds;
            while j + 1 < n && u[j + 1] <= uk {
                j += 1;
            }
            let u_next = if j + 1 < n { u[j + 1] } else { period };
            let t = (uk - u[j]) / (u_next - u[j]);
            let s = (j as f64 + t) * h;
            let d = self.offsets[j] * (1.0 - t) + self.offsets[(j + 1) % n] * t;
            let c = track.sample(track.index_at(s));
            let (x, dx, ddx) = sx.eval(uk);
            let (y, dy, ddy) = sy.eval(uk);
            let raw = dy.atan2(dx);
            // Continuous heading, as the centre line's.
            heading = if k == 0 {
                raw
            } else {
                heading + crate::geometry::wrap_angle(raw - heading)
            };
            samples.push(Sample {
                s: uk,
                x,
                y,
                z: c.z + c.grade * (s - c.s) + d * c.banking.sin(),
                heading,
                curvature: (dx * ddy - dy * ddx) / (dx * dx + dy * dy).powf(1.5),
                grade: 0.0,
                banking: c.banking,
                width: c.width,
                friction: c.friction,
                rolling_resistance: c.rolling_resistance,
                roughness: c.roughness,
                verges: c.verges,
            });
        }
        let z: Vec<f64> = samples.iter().map(|c| c.z).collect();
        for (k, c) in samples.iter_mut().enumerate() {
            c.grade = (z[(k + 1) % m] - z[(k + m - 1) % m]) / (2.0 * ds);
        }
        let closure = Closure {
            gap_m: 0.0,
            heading_deg: 0.0,
        };
        Track::new(
            &format!("{} racing line", track.name),
            &track.source,
            period,
            closure,
            samples,
            vec![],
        )
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    use crate::line::{LineOptions, RacingLine, SPACING};
    use crate::track::{Piece, Track};

    const OPTIONS: LineOptions = LineOptions {
        margin_m: 1.45,
        spacing_m: SPACING,
    };

    /// A stadium (two 150 m straights each side of two 100 m semicircles) with a chicane in
    /// each long side: left 30°, right 60°, left 30°, each of radius 50 m, 12 m wide. The
    /// chicanes shift the road sideways and back, so the circuit closes.
    fn chicane_stadium() -> (Track, [f64; 2]) {
        let r = 50.0;
        let arc = |deg: f64, sign: f64| Piece::flat(r * deg.to_radians(), sign / r);
        let side = [
            Piece::flat(150.0, 0.0),
            arc(30.0, 1.0),
            arc(60.0, -1.0),
            arc(30.0, 1.0),
            Piece::flat(150.0, 0.0),
            Piece::flat(PI * 100.0, 0.01),
        ];
        let pieces: Vec<Piece> = side.iter().chain(&side).copied().collect();
        let t = Track::from_pieces("chicane", "test", &pieces, vec![]);
        // Stations of the first chicane's right bend's middle and of its first left bend's.
        let first_left = 150.0 + 0.5 * side[1].length;
        let right = 150.0 + side[1].length + 0.5 * side[2].length;
        (t, [first_left, right])
    }

    #[test]
    fn the_chicane_stadium_closes() {
        let (t, _) = chicane_stadium();
        assert!(
            t.closure.is_closed() && t.closure.gap_m < 1e-6,
            "{:?}",
            t.closure
        );
    }

    #[test]
    fn a_chicanes_line_cuts_its_apexes_within_the_road() {
        let (t, [first_left, right]) = chicane_stadium();
        let line = RacingLine::minimum_curvature(&t, &OPTIONS).unwrap();
        let room = 6.0 - OPTIONS.margin_m;
        // At the apex of the left bend the line is on the left, of the right bend on the right.
        assert!(
            line.offset_at(first_left) > 0.5 * room,
            "{}",
            line.offset_at(first_left)
        );
        assert!(
            line.offset_at(right) < -0.5 * room,
            "{}",
            line.offset_at(right)
        );
        // Its curvature through the chicane is well below the centre line's 1/50 m.
        let path = line.path(&t);
        let chicane = |s: f64| (140.0..150.0 + 2.0 * PI * 50.0 / 3.0 + 10.0).contains(&s);
        let worst = path
            .samples
            .iter()
            .filter(|c| chicane(t.project_global(c.x, c.y).s))
            .map(|c| c.curvature.abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.6 / 50.0, "radius {} m", 1.0 / worst);
    }

    #[test]
    fn the_line_never_leaves_the_road_less_its_margin() {
        let (t, _) = chicane_stadium();
        let ridgeway = Track::builtin("ridgeway").unwrap();
        for t in [t, ridgeway] {
            let line = RacingLine::minimum_curvature(&t, &OPTIONS).unwrap();
            for (s, d) in line.stations.iter().zip(&line.offsets) {
                let room = 0.5 * t.sample(t.index_at(*s)).width - OPTIONS.margin_m;
                assert!(d.abs() <= room + 1e-9, "{}: {d} at {s}", t.name);
            }
            // Between its points, too, where the spline bulges by a centimetre or two at most.
            let path = line.path(&t);
            let mut hint = 0;
            for c in &path.samples {
                let p = t.project(c.x, c.y, hint);
                hint = p.index;
                let room = t.frame(p.index).half_width - OPTIONS.margin_m;
                assert!(
                    p.lateral.abs() <= room + 0.02,
                    "{}: {} at {}",
                    t.name,
                    p.lateral,
                    p.s
                );
            }
        }
    }

    #[test]
    fn a_circles_path_has_the_radius_of_its_outer_edge() {
        let r = 100.0;
        let t = Track::from_pieces("circle", "test", &[Piece::flat(TAU * r, 1.0 / r)], vec![]);
        let line = RacingLine::minimum_curvature(&t, &OPTIONS).unwrap();
        let path = line.path(&t);
        let outer = r + 6.0 - OPTIONS.margin_m;
        assert!(
            (path.length / (TAU * outer) - 1.0).abs() < 1e-4,
            "{}",
            path.length
        );
        for c in &path.samples {
            assert!((c.curvature * outer - 1.0).abs() < 1e-3, "{}", c.curvature);
        }
    }
}
