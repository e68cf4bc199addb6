//! The minimum-curvature line (Heilmeier et al. 2020, after TUMFTM's `opt_min_curv`): the
//! offsets dⱼ ∈ [−(wⱼ/2 − margin), wⱼ/2 − margin] that minimise Σⱼ κⱼ², κⱼ the curvature of
//! the path pⱼ = cⱼ + dⱼ·nⱼ at its j-th point.
//!
//! **Curvature.** With aⱼ = (pⱼ₊₁ − pⱼ₋₁)/2 and bⱼ = pⱼ₊₁ − 2pⱼ + pⱼ₋₁ (indices mod N), the
//! first and second derivatives of the path by its index, κⱼ = (aⱼ × bⱼ)/|aⱼ|³, where
//! a × b = aₓb_y − a_ybₓ (second-order accurate in the spacing: a circle of radius R sampled
//! every h metres gives 1/R·(1 + h²/4R²)).
//!
//! **Linearisation.** Each pⱼ moves along its normal, ∂pⱼ/∂dⱼ = nⱼ, so around offsets dᵏ
//! κ(d) ≈ κ(dᵏ) + J·(d − dᵏ), with J banded (row j has columns j − 1, j, j + 1):
//! ∂κⱼ/∂a = (b_y, −bₓ)/|a|³ − 3(a × b)·a/|a|⁵, ∂κⱼ/∂b = (−a_y, aₓ)/|a|³, and
//! ∂κⱼ/∂dⱼ₋₁ = (−½∂κⱼ/∂a + ∂κⱼ/∂b)·nⱼ₋₁, ∂κⱼ/∂dⱼ = −2∂κⱼ/∂b·nⱼ,
//! ∂κⱼ/∂dⱼ₊₁ = (½∂κⱼ/∂a + ∂κⱼ/∂b)·nⱼ₊₁.
//! Heilmeier et al. hold the first derivative at the reference line's and let only the
//! second move (their spline's b and c coefficients); that linearisation sees a point moved
//! to the inside of a circle as *less* curved (its second derivative shrinks, its first is
//! held), so here the first derivative moves too (Gauss–Newton on Σκ²): the iteration's
//! fixed point is then a true minimum of Σκⱼ², and a circle's line is its outer edge.
//!
//! **Quadratic programme.** Each step minimises ‖S·(J·d + κ(dᵏ) − J·dᵏ)‖², i.e.
//! ½dᵀPd + qᵀd with P = 2S²JᵀJ (five non-zeros a row) and q = 2S²Jᵀ(κ(dᵏ) − J·dᵏ), over the
//! box of the road (and of a trust radius, none at first, half the rejected step's largest
//! move whenever a step raised Σκ² instead of lowering it), S = [`SCALE`]. Clarabel, a sparse interior-point solver, solves it; the
//! iteration re-linearises at the new offsets until they move by less than [`TOLERANCE`]
//! (as TUMFTM's iterative variant re-linearises around each solution). The centre line is
//! resampled every ≈ [`super::SPACING`] m, so Forza's 5.8 km make about 1,900 unknowns.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus};

use super::{LineOptions, RacingLine};
use crate::error::{Error, Result};
use crate::track::Track;

/// Length (m) the curvatures are multiplied by in the objective, so that its residuals S·κ
/// are of order one for corners of 100 m radius (the minimiser is the same).
pub const SCALE: f64 = 100.0;

/// The iteration stops once no offset moved by more than this (m).
pub const TOLERANCE: f64 = 0.01;

/// Most quadratic programmes solved.
pub const MAX_PROGRAMMES: usize = 15;

impl RacingLine {
    /// The minimum-curvature line of `track` (see the [module](self) documentation), or an
    /// error naming the station where the road is narrower than twice `options.margin_m`, or
    /// the solver's status if it stopped without a solution.
    pub fn minimum_curvature(track: &Track, options: &LineOptions) -> Result<RacingLine> {
        let n = ((track.length / options.spacing_m).round() as usize).max(8);
        let h = track.length / n as f64;
        let stations: Vec<f64> = (0..n).map(|j| j as f64 * h).collect();
        let mut centre = Vec::with_capacity(n);
        let mut normals = Vec::with_capacity(n);
        let (mut lo, mut hi) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for &s in &stations {
            let (x, y) = track.point_at(s);
            let c = track.sample(track.index_at(s));
            let heading = c.heading + c.curvature * (s - c.s);
            centre.push([x, y]);
            normals.push([-heading.sin(), heading.cos()]);
            let room = 0.5 * c.width - options.margin_m;
            if room < 0.0 {
                return Err(Error::InvalidValue {
                    what: format!("the road of {} at {s:.0} m", track.name),
                    value: format!("{:.2} m wide", c.width),
                    expected: format!(
                        "at least {:.2} m wide for a racing line (the car's width and its safety margins)",
                        2.0 * options.margin_m
                    ),
                });
            }
            lo.push(-room);
            hi.push(room);
        }
        let path = |d: &[f64]| -> Vec<[f64; 2]> {
            (0..n)
                .map(|j| {
                    [
                        centre[j][0] + d[j] * normals[j][0],
                        centre[j][1] + d[j] * normals[j][1],
                    ]
                })
                .collect()
        };
        let cost = |d: &[f64]| {
            curvature(&path(d), &normals)
                .0
                .iter()
                .map(|k| k * k)
                .sum::<f64>()
        };

        let mut d = vec![0.0; n];
        let mut best = cost(&d);
        let mut radius = f64::INFINITY;
        let mut iterations = 0;
        while iterations < MAX_PROGRAMMES {
            let (kappa, jac) = curvature(&path(&d), &normals);
            let lo_k: Vec<f64> = (0..n).map(|j| lo[j].max(d[j] - radius)).collect();
            let hi_k: Vec<f64> = (0..n).map(|j| hi[j].min(d[j] + radius)).collect();
            let next = solve(&kappa, &jac, &d, &lo_k, &hi_k).map_err(|status| {
                Error::Numerical(format!(
                    "the minimum-curvature line of {}: quadratic programme {} stopped: {status:?}",
                    track.name,
                    iterations + 1
                ))
            })?;
            iterations += 1;
            let step = next
                .iter()
                .zip(&d)
                .fold(0.0, |m, (a, b)| f64::max(m, (a - b).abs()));
            let next_cost = cost(&next);
            if next_cost <= best {
                d = next;
                best = next_cost;
                if step < TOLERANCE {
                    break;
                }
            } else {
                radius = 0.5 * step;
                if radius < TOLERANCE {
                    break;
                }
            }
        }
        Ok(RacingLine {
            stations,
            points: path(&d),
            offsets: d,
            margin_m: options.margin_m,
            centre_length_m: track.length,
            iterations,
            curvature_cost: best,
        })
    }
}

/// The discrete curvature κⱼ of the closed path `p` and, for each j, ∂κⱼ/∂dᵢ for
/// i = j − 1, j, j + 1 when pᵢ moves along `normals[i]`.
fn curvature(p: &[[f64; 2]], normals: &[[f64; 2]]) -> (Vec<f64>, Vec<[f64; 3]>) {
    let n = p.len();
    let dot = |u: [f64; 2], v: [f64; 2]| u[0] * v[0] + u[1] * v[1];
    let mut kappa = Vec::with_capacity(n);
    let mut jac = Vec::with_capacity(n);
    for j in 0..n {
        let (prev, next) = ((j + n - 1) % n, (j + 1) % n);
        let a = [
            0.5 * (p[next][0] - p[prev][0]),
            0.5 * (p[next][1] - p[prev][1]),
        ];
        let b = [
            p[next][0] - 2.0 * p[j][0] + p[prev][0],
            p[next][1] - 2.0 * p[j][1] + p[prev][1],
        ];
        let cross = a[0] * b[1] - a[1] * b[0];
        let a2 = dot(a, a);
        let a3 = a2 * a2.sqrt();
        let k = cross / a3;
        let ga = [
            b[1] / a3 - 3.0 * k * a[0] / a2,
            -b[0] / a3 - 3.0 * k * a[1] / a2,
        ];
        let gb = [-a[1] / a3, a[0] / a3];
        let side = |sign: f64, nrm: [f64; 2]| {
            dot(
                [0.5 * sign * ga[0] + gb[0], 0.5 * sign * ga[1] + gb[1]],
                nrm,
            )
        };
        kappa.push(k);
        jac.push([
            side(-1.0, normals[prev]),
            -2.0 * dot(gb, normals[j]),
            side(1.0, normals[next]),
        ]);
    }
    (kappa, jac)
}

/// One Gauss–Newton step as a quadratic programme: the d in [lo, hi] minimising
/// ‖S·(J·d + κ − J·d₀)‖², or the solver's status if it found none.
fn solve(
    kappa: &[f64],
    jac: &[[f64; 3]],
    d0: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> std::result::Result<Vec<f64>, SolverStatus> {
    let n = kappa.len();
    let s2 = 2.0 * SCALE * SCALE;
    // Triplets of the upper triangle of P = 2S²JᵀJ; q = 2S²Jᵀc with c = κ − J·d₀.
    let (mut rows, mut cols, mut vals) = (vec![], vec![], vec![]);
    let mut q = vec![0.0; n];
    for j in 0..n {
        let idx = [(j + n - 1) % n, j, (j + 1) % n];
        let c = kappa[j] - (0..3).map(|k| jac[j][k] * d0[idx[k]]).sum::<f64>();
        for a in 0..3 {
            q[idx[a]] += s2 * jac[j][a] * c;
            for b in 0..3 {
                if idx[a] <= idx[b] {
                    rows.push(idx[a]);
                    cols.push(idx[b]);
                    vals.push(s2 * jac[j][a] * jac[j][b]);
                }
            }
        }
    }
    let p = CscMatrix::new_from_triplets(n, n, rows, cols, vals);
    // d ≤ hi and −d ≤ −lo: A = [I; −I], b = [hi; −lo], A·d + s = b, s ≥ 0.
    let a = CscMatrix::new(
        2 * n,
        n,
        (0..=n).map(|k| 2 * k).collect(),
        (0..n).flat_map(|k| [k, n + k]).collect(),
        (0..n).flat_map(|_| [1.0, -1.0]).collect(),
    );
    let b: Vec<f64> = hi.iter().copied().chain(lo.iter().map(|l| -l)).collect();
    let settings = DefaultSettings {
        verbose: false,
        ..DefaultSettings::default()
    };
    let cones = [NonnegativeConeT(2 * n)];
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|_| SolverStatus::NumericalError)?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(solver
            .solution
            .x
            .iter()
            .zip(lo.iter().zip(hi))
            .map(|(x, (l, h))| x.clamp(*l, *h))
            .collect()),
        status => Err(status),
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use super::*;
    use crate::track::Piece;

    /// A level circle of radius `r`, `width` metres wide.
    fn circle(r: f64, width: f64) -> Track {
        let p = Piece {
            width,
            ..Piece::flat(TAU * r, 1.0 / r)
        };
        Track::from_pieces("circle", "test", &[p], vec![])
    }

    #[test]
    fn the_discrete_curvature_of_a_sampled_circle_is_one_over_its_radius() {
        let (r, n) = (50.0, 100);
        let p: Vec<[f64; 2]> = (0..n)
            .map(|j| {
                let t = TAU * j as f64 / n as f64;
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let normals: Vec<[f64; 2]> = p.iter().map(|q| [-q[0] / r, -q[1] / r]).collect();
        let (kappa, jac) = curvature(&p, &normals);
        let h = TAU * r / n as f64;
        for k in &kappa {
            assert!((k * r - 1.0).abs() < 0.3 * h * h / (r * r), "{k}");
        }
        // The Jacobian against central differences of the curvature.
        let eps = 1e-6;
        for j in [0, 37] {
            for (col, i) in [(j + n - 1) % n, j, (j + 1) % n].into_iter().enumerate() {
                let moved = |e: f64| {
                    let mut q = p.clone();
                    q[i] = [q[i][0] + e * normals[i][0], q[i][1] + e * normals[i][1]];
                    curvature(&q, &normals).0[j]
                };
                let fd = (moved(eps) - moved(-eps)) / (2.0 * eps);
                assert!(
                    (fd - jac[j][col]).abs() < 1e-6,
                    "{j} {i}: {fd} vs {}",
                    jac[j][col]
                );
            }
        }
    }

    #[test]
    fn a_road_narrower_than_the_car_and_its_margins_is_refused_naming_where() {
        let options = LineOptions {
            margin_m: 1.45,
            spacing_m: crate::line::SPACING,
        };
        let e = RacingLine::minimum_curvature(&circle(100.0, 2.5), &options)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("the road of circle at 0 m") && e.contains("2.50 m wide"),
            "{e}"
        );
    }

    #[test]
    fn a_circles_line_is_the_circle_along_its_outer_edge() {
        let (r, width) = (100.0, 12.0);
        let options = LineOptions {
            margin_m: 1.45,
            spacing_m: crate::line::SPACING,
        };
        let line = RacingLine::minimum_curvature(&circle(r, width), &options).unwrap();
        let room = 0.5 * width - options.margin_m;
        for d in &line.offsets {
            // A left turn: its outside is to the right, d = −room.
            assert!((d + room).abs() < 1e-3, "{d}");
        }
        let (kappa, _) = curvature(&line.points, &vec![[0.0; 2]; line.points.len()]);
        for k in kappa {
            assert!((k * (r + room) - 1.0).abs() < 1e-3, "{}", 1.0 / k);
        }
    }
}
