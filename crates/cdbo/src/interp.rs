//! Piecewise-linear interpolation through points with increasing x.

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
}
