//! TUMFTM racetrack-database centre lines: `# x_m,y_m,w_tr_right_m,w_tr_left_m`.
//!
//! The file gives a reference line and the distances to the right and left edges. The road's
//! centre is the reference moved by (w_left − w_right)/2 along the left normal, its width
//! w_left + w_right. A periodic cubic spline through the centre points (parameterised by chord
//! length) makes the track closed and smooth; it is then sampled at uniform arc length, with
//! heading atan2(y′, x′) and curvature κ = (x′y″ − y′x″)/(x′² + y′²)^{3/2}. Survey noise in the
//! points makes κ ragged, so κ is averaged over a centred window of [`CURVATURE_WINDOW_M`]
//! (a circle keeps its exact curvature).

use std::path::Path;

use super::spline::PeriodicSpline;
use super::{Closure, MAX_LENGTH_M, Sample, TARGET_DS, Track};
use crate::bounded;
use crate::error::{Error, Result};

/// Width of the moving average applied to the curvature (m).
pub const CURVATURE_WINDOW_M: f64 = 10.0;

/// Reads a TUMFTM centre-line CSV file.
pub fn read(path: &Path) -> Result<Track> {
    let text = bounded::read_text(path, &bounded::TRACK_CSV)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse(&text, &name, &path.display().to_string())
}

/// Parses CSV text; `file` is used in messages and recorded as the source.
pub fn parse(text: &str, name: &str, file: &str) -> Result<Track> {
    let mut rows: Vec<[f64; 4]> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let err = |msg: String| Error::Parse {
            file: file.to_owned(),
            line: Some(i as u32 + 1),
            element: "row".into(),
            message: msg,
        };
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 4 {
            return Err(err(format!(
                "expected 4 columns x_m,y_m,w_tr_right_m,w_tr_left_m, found {}",
                fields.len()
            )));
        }
        let mut row = [0.0; 4];
        for (k, f) in fields.iter().enumerate() {
            let v: f64 = f
                .parse()
                .map_err(|_| err(format!("column {} value {f:?} is not a number", k + 1)))?;
            if !v.is_finite() {
                return Err(err(format!("column {} value {f:?} is not finite", k + 1)));
            }
            row[k] = v;
        }
        if row[2] < 0.0 || row[3] < 0.0 || row[2] + row[3] <= 0.0 {
            return Err(err(format!(
                "track widths must be positive, got right {} m, left {} m",
                row[2], row[3]
            )));
        }
        if let Some(prev) = rows.last()
            && (prev[0] - row[0]).hypot(prev[1] - row[1]) < 1e-6
        {
            continue; // a repeated point carries no geometry
        }
        rows.push(row);
    }
    if let (Some(first), Some(last)) = (rows.first(), rows.last())
        && rows.len() > 1
        && (first[0] - last[0]).hypot(first[1] - last[1]) < 1e-6
    {
        rows.pop(); // the closing point repeats the first
    }
    if rows.len() < 10 {
        return Err(Error::parse(
            file,
            "rows",
            format!(
                "a closed track needs at least 10 points, found {}",
                rows.len()
            ),
        ));
    }
    if let Some(spread) = collinear_spread(&rows) {
        return Err(Error::parse(
            file,
            "rows",
            format!(
                "a degenerate centre line: its {} points lie within {spread:.3} m of one straight line (a circuit needs at least {MIN_SPREAD_M} m across it)",
                rows.len()
            ),
        ));
    }
    let perimeter: f64 = (0..rows.len())
        .map(|i| {
            let (p, q) = (rows[i], rows[(i + 1) % rows.len()]);
            (p[0] - q[0]).hypot(p[1] - q[1])
        })
        .sum();
    if perimeter > MAX_LENGTH_M {
        return Err(Error::parse(
            file,
            "rows",
            format!("the track is {perimeter:.0} m long, more than {MAX_LENGTH_M} m"),
        ));
    }
    build(&rows, name, file)
}

/// Least width across its main axis a centre line must span to be a circuit (m).
pub const MIN_SPREAD_M: f64 = 1.0;

/// `Some(spread)` when the points lie within a band narrower than [`MIN_SPREAD_M`] around
/// their principal axis (the eigenvector of the largest eigenvalue of their covariance);
/// the spread is the band's width, max − min of the offsets across that axis.
fn collinear_spread(rows: &[[f64; 4]]) -> Option<f64> {
    let n = rows.len() as f64;
    let (mx, my) = rows
        .iter()
        .fold((0.0, 0.0), |(x, y), r| (x + r[0] / n, y + r[1] / n));
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for r in rows {
        let (dx, dy) = (r[0] - mx, r[1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // Direction of the principal axis: θ = ½·atan2(2·sxy, sxx − syy).
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let (sin, cos) = theta.sin_cos();
    let (lo, hi) = rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
            let across = -(r[0] - mx) * sin + (r[1] - my) * cos;
            (lo.min(across), hi.max(across))
        });
    let spread = hi - lo;
    (spread < MIN_SPREAD_M).then_some(spread)
}

fn build(rows: &[[f64; 4]], name: &str, file: &str) -> Result<Track> {
    let n = rows.len();
    // Centre points: move the reference line by (w_left − w_right)/2 along its left normal.
    let centre: Vec<(f64, f64, f64)> = (0..n)
        .map(|i| {
            let (p, q) = (rows[(i + n - 1) % n], rows[(i + 1) % n]);
            let (tx, ty) = (q[0] - p[0], q[1] - p[1]);
            let norm = tx.hypot(ty).max(1e-12);
            let shift = 0.5 * (rows[i][3] - rows[i][2]);
            (
                rows[i][0] - ty / norm * shift,
                rows[i][1] + tx / norm * shift,
                rows[i][2] + rows[i][3],
            )
        })
        .collect();
    if let Some((i, j)) = first_crossing(&centre) {
        return Err(Error::parse(
            file,
            "rows",
            format!(
                "the centre line crosses itself: its segment from point {} to {} crosses the one from point {} to {} (near ({:.1}, {:.1}) m); a circuit's centre line must not cross",
                i + 1,
                (i + 1) % n + 1,
                j + 1,
                (j + 1) % n + 1,
                centre[j].0,
                centre[j].1
            ),
        ));
    }
    let mut t = vec![0.0; n];
    for i in 1..n {
        t[i] = t[i - 1] + (centre[i].0 - centre[i - 1].0).hypot(centre[i].1 - centre[i - 1].1);
    }
    let period = t[n - 1] + (centre[0].0 - centre[n - 1].0).hypot(centre[0].1 - centre[n - 1].1);
    let xs: Vec<f64> = centre.iter().map(|c| c.0).collect();
    let ys: Vec<f64> = centre.iter().map(|c| c.1).collect();
    let ws: Vec<f64> = centre.iter().map(|c| c.2).collect();
    let sx = PeriodicSpline::new(&t, &xs, period);
    let sy = PeriodicSpline::new(&t, &ys, period);
    let sw = PeriodicSpline::new(&t, &ws, period);

    // Arc length s(t) on a fine grid (16 chords per knot interval).
    const SUB: usize = 16;
    let m = n * SUB;
    let mut tt = Vec::with_capacity(m + 1);
    let mut ss = Vec::with_capacity(m + 1);
    let (mut s, mut prev) = (0.0, (sx.eval(0.0).0, sy.eval(0.0).0));
    for k in 0..=m {
        let tk = if k == m {
            period
        } else {
            t[k / SUB]
                + (k % SUB) as f64 / SUB as f64
                    * (if k / SUB + 1 < n {
                        t[k / SUB + 1]
                    } else {
                        period
                    } - t[k / SUB])
        };
        let p = (sx.eval(tk).0, sy.eval(tk).0);
        s += (p.0 - prev.0).hypot(p.1 - prev.1);
        prev = p;
        tt.push(tk);
        ss.push(s);
    }
    let length = s;
    // The centre moves off the reference by half the width difference: a road kilometres wide
    // makes a centre line far longer than the points' perimeter.
    if !length.is_finite() || length > MAX_LENGTH_M {
        return Err(Error::parse(
            file,
            "rows",
            format!("the centre line is {length:.0} m long, more than {MAX_LENGTH_M} m"),
        ));
    }
    let count = ((length / TARGET_DS).round() as usize).max(8);
    let ds = length / count as f64;
    let (x0, y0) = (sx.eval(0.0).0, sy.eval(0.0).0);
    let mut samples = Vec::with_capacity(count);
    let mut k = 0;
    for i in 0..count {
        let si = i as f64 * ds;
        while k + 1 < ss.len() - 1 && ss[k + 1] < si {
            k += 1;
        }
        let f = if ss[k + 1] > ss[k] {
            (si - ss[k]) / (ss[k + 1] - ss[k])
        } else {
            0.0
        };
        let ti = tt[k] + f * (tt[k + 1] - tt[k]);
        let (x, dx, ddx) = sx.eval(ti);
        let (y, dy, ddy) = sy.eval(ti);
        let speed2 = dx * dx + dy * dy;
        samples.push(Sample {
            s: si,
            x: x - x0,
            y: y - y0,
            z: 0.0,
            heading: dy.atan2(dx),
            curvature: (dx * ddy - dy * ddx) / (speed2 * speed2.sqrt()),
            grade: 0.0,
            banking: 0.0,
            width: sw.eval(ti).0,
            friction: 1.0,
            rolling_resistance: None,
            roughness: super::Roughness::NONE,
            verges: [super::Verge::NONE; 2],
        });
    }
    smooth_curvature(
        &mut samples,
        (0.5 * CURVATURE_WINDOW_M / ds).round() as usize,
    );
    Ok(Track::new(
        name,
        file,
        length,
        Closure {
            gap_m: 0.0,
            heading_deg: 0.0,
        },
        samples,
        Vec::new(),
    ))
}

/// The first pair (i, j), i < j, of segments pᵢpᵢ₊₁ and pⱼpⱼ₊₁ of the closed polygon `p` that
/// are not neighbours and cross: each segment's ends lie on opposite sides of the other's
/// line (the signs of the cross products differ). Segments are compared only where their
/// bounding boxes overlap, after sorting by their least x.
fn first_crossing(p: &[(f64, f64, f64)]) -> Option<(usize, usize)> {
    let n = p.len();
    let seg = |i: usize| ((p[i].0, p[i].1), (p[(i + 1) % n].0, p[(i + 1) % n].1));
    let side = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| {
        (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
    };
    let mut order: Vec<usize> = (0..n).collect();
    let min_x = |i: usize| seg(i).0.0.min(seg(i).1.0);
    order.sort_by(|&a, &b| min_x(a).total_cmp(&min_x(b)));
    let mut found: Option<(usize, usize)> = None;
    for (k, &i) in order.iter().enumerate() {
        let (a, b) = seg(i);
        let max_x = a.0.max(b.0);
        for &j in &order[k + 1..] {
            if min_x(j) > max_x {
                break;
            }
            if (i + 1) % n == j || (j + 1) % n == i {
                continue;
            }
            let (c, d) = seg(j);
            let crosses =
                side(a, b, c) * side(a, b, d) < 0.0 && side(c, d, a) * side(c, d, b) < 0.0;
            if crosses {
                let pair = (i.min(j), i.max(j));
                found = Some(found.map_or(pair, |f| f.min(pair)));
            }
        }
    }
    found
}

/// Replaces each curvature by its mean over samples i−half..=i+half (periodic).
/// The window is cut to the lap on a lap shorter than it.
fn smooth_curvature(samples: &mut [Sample], half: usize) {
    let n = samples.len();
    let half = half.min(n.saturating_sub(1) / 2);
    let raw: Vec<f64> = samples.iter().map(|c| c.curvature).collect();
    let width = (2 * half + 1) as f64;
    let mut sum: f64 = (0..=2 * half).map(|k| raw[(k + n - half) % n]).sum();
    for i in 0..n {
        samples[i].curvature = sum / width;
        sum += raw[(i + half + 1) % n] - raw[(i + n - half) % n];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle_csv(n: usize, r: f64) -> String {
        let mut s = String::from("# x_m,y_m,w_tr_right_m,w_tr_left_m\n");
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            s += &format!("{},{},4.0,6.0\n", r * a.cos(), r * a.sin());
        }
        s
    }

    #[test]
    fn a_sampled_circle_becomes_a_smooth_closed_circle() {
        let t = parse(&circle_csv(72, 200.0), "c", "c.csv").unwrap();
        // Centre moves 1 m to the left (inside): radius 199 m.
        let expect = std::f64::consts::TAU * 199.0;
        assert!(
            (t.length - expect).abs() < 0.05,
            "length {} vs {expect}",
            t.length
        );
        for c in &t.samples {
            assert!(
                (c.curvature - 1.0 / 199.0).abs() < 1e-5,
                "curvature {}",
                c.curvature
            );
            assert!((c.width - 10.0).abs() < 1e-9);
        }
    }

    #[test]
    fn bad_rows_are_reported_with_their_line() {
        let bad = circle_csv(20, 100.0).replacen("4.0,6.0", "4.0,NaN", 1);
        let e = parse(&bad, "c", "c.csv").unwrap_err().to_string();
        assert!(e.starts_with("c.csv:2") && e.contains("NaN"), "{e}");
        let e = parse("1,2,3,4\n5,6,7,8\n", "c", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least 10 points"), "{e}");
        let e = parse("1,2,3\n", "c", "c.csv").unwrap_err().to_string();
        assert!(e.contains("expected 4 columns"), "{e}");
    }

    /// A figure of eight crosses itself at its waist: refused, naming the two segments.
    #[test]
    fn a_centre_line_that_crosses_itself_is_refused() {
        let n = 60;
        let mut s = String::new();
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            s += &format!("{},{},5,5\n", 300.0 * a.sin(), 150.0 * (2.0 * a).sin());
        }
        let e = parse(&s, "c", "c.csv").unwrap_err().to_string();
        assert!(e.contains("the centre line crosses itself"), "{e}");
        assert!(
            e.contains("segment from point 31 to 32 crosses the one from point 60 to 1"),
            "{e}"
        );
        assert!(parse(&circle_csv(72, 200.0), "c", "c.csv").is_ok());
    }

    #[test]
    fn collinear_centre_lines_are_refused() {
        // Out and back along a tilted line, 0.2 mm of noise across it: no circuit.
        let mut s = String::new();
        for i in 0..40 {
            let t = if i < 20 { i } else { 40 - i } as f64 * 10.0;
            let jitter = if i % 2 == 0 { 1e-4 } else { -1e-4 };
            s += &format!("{},{},4,4\n", 3.0 * t - jitter, 4.0 * t + jitter);
        }
        let e = parse(&s, "c", "c.csv").unwrap_err().to_string();
        assert!(e.contains("degenerate") && e.contains("40 points"), "{e}");
        // A 2 m-wide sliver passes this check; a circle is nowhere near it.
        assert!(
            collinear_spread(&[
                [0.0, 0.0, 1.0, 1.0],
                [10.0, 2.0, 1.0, 1.0],
                [20.0, 0.0, 1.0, 1.0]
            ])
            .is_none()
        );
        assert!(parse(&circle_csv(72, 200.0), "c", "c.csv").is_ok());
    }
}
