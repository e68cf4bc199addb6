//! Piecewise-linear interpolation through points with increasing x, and through values evenly
//! spaced around a period.

/// y(x) linear between the points (xᵢ, yᵢ), xᵢ increasing, held constant beyond the ends;
/// `i` is the number of points with xᵢ ≤ x (from a search the caller may have cached).
#[inline]
pub fn linear_at(points: &[(f64, f64)], i: usize, x: f64) -> f64 {
    match i {
        0 => points[0].1,
        i if i >= points.len() => points[points.len() - 1].1,
        i => {
            let ((x0, y0), (x1, y1)) = (points[i - 1], points[i]);
            y0 + (y1 - y0) * (x - x0) / (x1 - x0)
        }
    }
}

/// y(x) linear between the points, held constant beyond the ends (binary search).
#[inline]
pub fn linear(points: &[(f64, f64)], x: f64) -> f64 {
    linear_at(points, points.partition_point(|&(xi, _)| xi <= x), x)
}

/// The periodic function through the values yⱼ at xⱼ = j·P/n (j = 0..n, n ≥ 1, y₀ again at P)
/// at x wrapped into [0, P): with u = (x mod P)/(P/n), j = min(⌊u⌋, n − 1) and t = u − j,
/// y = yⱼ·(1 − t) + y₍ⱼ₊₁₎ mod n·t. The TORCS robot's `drive::periodic_linear`
/// (`torcs-robot/drive.hpp`) is the same arithmetic, checked by `tests/robot_drive.rs`.
#[inline]
pub fn periodic_linear(values: &[f64], period: f64, x: f64) -> f64 {
    let n = values.len();
    let h = period / n as f64;
    let u = x.rem_euclid(period) / h;
    let j = (u.floor() as usize).min(n - 1);
    let t = u - j as f64;
    values[j] * (1.0 - t) + values[(j + 1) % n] * t
}

#[cfg(test)]
mod tests {
    #[test]
    fn interpolates_between_and_holds_beyond() {
        let p = [(0.0, 1.0), (2.0, 3.0), (3.0, 0.0)];
        assert_eq!(super::linear(&p, -1.0), 1.0);
        assert_eq!(super::linear(&p, 1.0), 2.0);
        assert_eq!(super::linear(&p, 2.5), 1.5);
        assert_eq!(super::linear(&p, 9.0), 0.0);
    }

    #[test]
    fn periodic_values_wrap_around_the_period() {
        let y = [1.0, 3.0, 0.0, 2.0];
        let at = |x| super::periodic_linear(&y, 8.0, x);
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(1.0), 2.0);
        assert_eq!(at(4.0), 0.0);
        // Between the last value and the first, and a period away either side.
        assert_eq!(at(7.0), 1.5);
        assert_eq!(at(-1.0), 1.5);
        assert_eq!(at(17.0), 2.0);
    }
}
