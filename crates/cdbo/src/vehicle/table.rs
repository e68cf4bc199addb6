//! Cubic Hermite tables: a smooth function and its derivative, sampled once and interpolated
//! in the hot loop (the tyre's Magic-Formula shape and load sensitivity).
//!
//! With values fₖ and slopes f′ₖ at xₖ = k·h, on t = (x − xₖ)/h ∈ [0, 1]:
//! f(x) ≈ (2t³ − 3t² + 1)fₖ + (t³ − 2t² + t)h·f′ₖ + (3t² − 2t³)fₖ₊₁ + (t³ − t²)h·f′ₖ₊₁,
//! exact for cubics, with error O(h⁴·f⁗); the derivative of this interpolant is returned too.

/// A function and its derivative tabulated on [0, len·step].
#[derive(Debug, Clone, PartialEq)]
pub struct HermiteTable {
    inv_step: f64,
    /// Number of intervals, as a float for the range check.
    intervals: f64,
    step: f64,
    /// (f, h·f′) at each node.
    nodes: Vec<(f64, f64)>,
}

impl HermiteTable {
    /// Samples `f` (returning value and derivative) at `len + 1` nodes spaced by `step`;
    /// `len` below 2³¹.
    pub fn new(step: f64, len: usize, f: impl Fn(f64) -> (f64, f64)) -> HermiteTable {
        assert!(
            len < 1 << 31,
            "a Hermite table of {len} intervals: at most 2³¹ − 1"
        );
        let nodes = (0..=len)
            .map(|k| {
                let (v, d) = f(k as f64 * step);
                (v, d * step)
            })
            .collect();
        HermiteTable {
            inv_step: 1.0 / step,
            intervals: len as f64,
            step,
            nodes,
        }
    }

    /// (f(x), f′(x)) for x in the table's range, `None` outside it.
    #[inline(always)]
    pub fn eval(&self, x: f64) -> Option<(f64, f64)> {
        let u = x * self.inv_step;
        if !(u >= 0.0 && u < self.intervals) {
            return None;
        }
        // u ∈ [0, len) and len < 2³¹ (`new`): k = ⌊u⌋ as a 32-bit integer, whose conversions
        // from and to a float take a few instructions where a usize's take a dozen.
        let k = u as u32;
        let t = u - f64::from(k);
        let k = k as usize;
        let [(f0, m0), (f1, m1)] = self.nodes[k..k + 2] else {
            return None;
        };
        let (t2, t3) = (t * t, t * t * t);
        let f = (2.0 * t3 - 3.0 * t2 + 1.0) * f0
            + (t3 - 2.0 * t2 + t) * m0
            + (3.0 * t2 - 2.0 * t3) * f1
            + (t3 - t2) * m1;
        let d = (6.0 * (t2 - t) * (f0 - f1)
            + (3.0 * t2 - 4.0 * t + 1.0) * m0
            + (3.0 * t2 - 2.0 * t) * m1)
            * self.inv_step;
        Some((f, d))
    }

    /// The end of the table's range.
    pub fn max_x(&self) -> f64 {
        (self.nodes.len() - 1) as f64 * self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_cubics_and_close_for_smooth_functions() {
        let cubic = HermiteTable::new(0.25, 8, |x| (x * x * x - 2.0 * x, 3.0 * x * x - 2.0));
        for i in 0..200 {
            let x = i as f64 * 0.00999;
            let (f, d) = cubic.eval(x).unwrap();
            assert!(
                (f - (x * x * x - 2.0 * x)).abs() < 1e-12
                    && (d - (3.0 * x * x - 2.0)).abs() < 1e-11
            );
        }
        let exp = HermiteTable::new(1.0 / 64.0, 256, |x| ((-x).exp(), -(-x).exp()));
        for i in 0..4000 {
            let x = i as f64 * 0.000999;
            assert!((exp.eval(x).unwrap().0 - (-x).exp()).abs() < 1e-9);
        }
        assert_eq!(exp.eval(-0.1), None);
        assert_eq!(exp.eval(exp.max_x() + 1e-9), None);
        assert_eq!(exp.eval(f64::NAN), None);
    }
}
