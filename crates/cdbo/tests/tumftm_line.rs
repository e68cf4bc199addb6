//! Our minimum-curvature line on Monza against TUMFTM's published one
//! (`../shared/tracks/racelines/Monza.csv`: their minimum-curvature line for the same centre
//! line and widths, LGPL-3.0, read and never copied).

mod common;

use cdbo::line::{LineOptions, RacingLine, SPACING};
use cdbo::track::Track;
use common::shared;

/// The numbers of a CSV file's data rows (comments skipped).
fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .collect()
}

/// ∫κ² ds of a closed polyline, κ the curvature of the circle through each point and its
/// neighbours (the planner's discrete curvature), ds the mean of its two chords.
fn curvature_integral(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|j| {
            let (a, b, c) = (p[(j + n - 1) % n], p[j], p[(j + 1) % n]);
            let u = [0.5 * (c[0] - a[0]), 0.5 * (c[1] - a[1])];
            let v = [c[0] - 2.0 * b[0] + a[0], c[1] - 2.0 * b[1] + a[1]];
            let speed = u[0].hypot(u[1]);
            let k = (u[0] * v[1] - u[1] * v[0]) / speed.powi(3);
            k * k * speed
        })
        .sum()
}

/// TUMFTM's line moved into the track's frame: the track's first point is its centre line's
/// first point, the reference line's first row moved half the width difference to the left.
fn published_line(track_file: &str, line_file: &str) -> Vec<[f64; 2]> {
    let centre = rows(&std::fs::read_to_string(shared(track_file)).unwrap());
    let n = centre.len();
    let (p, q) = (&centre[n - 1], &centre[1]);
    let (tx, ty) = (q[0] - p[0], q[1] - p[1]);
    let norm = tx.hypot(ty);
    let shift = 0.5 * (centre[0][3] - centre[0][2]);
    let origin = [
        centre[0][0] - ty / norm * shift,
        centre[0][1] + tx / norm * shift,
    ];
    rows(&std::fs::read_to_string(shared(line_file)).unwrap())
        .iter()
        .map(|r| [r[0] - origin[0], r[1] - origin[1]])
        .collect()
}

/// On Monza, planned with the car's centre 1 m from the edges (a 2 m wide car, as near as the
/// published line keeps to them), our line lies within 0.75 m of TUMFTM's on average and
/// within 1.5 m at 90 % of their points, and its ∫κ² ds is within 10 % of theirs. The two part
/// most (5.8 m, one on either side of the road) on the straight after the Parabolica, where
/// the side a line takes hardly changes Σκ².
#[test]
fn our_minimum_curvature_line_on_monza_agrees_with_tumftms() {
    let track: Track = cdbo::track::csv::read(&shared("tracks/csv/Monza.csv")).unwrap();
    let published = published_line("tracks/csv/Monza.csv", "tracks/racelines/Monza.csv");
    let options = LineOptions {
        margin_m: 1.0,
        spacing_m: SPACING,
    };
    let ours = RacingLine::minimum_curvature(&track, &options).unwrap();
    let (mut sum, mut worst, mut close) = (0.0, 0.0_f64, 0);
    let mut hint = 0;
    for p in &published {
        let at = track.project(p[0], p[1], hint);
        hint = at.index;
        let gap = (at.lateral - ours.offset_at(at.s)).abs();
        sum += gap;
        close += usize::from(gap <= 1.5);
        worst = worst.max(gap);
    }
    let mean = sum / published.len() as f64;
    let within = close as f64 / published.len() as f64;
    let (theirs, mine) = (
        curvature_integral(&published),
        curvature_integral(&ours.points),
    );
    println!(
        "mean {mean:.3} m, worst {worst:.3} m, {:.1} % within 1.5 m, ∫κ²ds ours {mine:.5} theirs {theirs:.5} ({:+.1} %)",
        100.0 * within,
        100.0 * (mine / theirs - 1.0)
    );
    assert!(mean < 0.75, "mean lateral distance {mean:.2} m");
    assert!(within >= 0.9, "{:.1} % within 1.5 m", 100.0 * within);
    assert!(
        (mine / theirs - 1.0).abs() < 0.1,
        "∫κ² ds {mine} against {theirs}"
    );
}
