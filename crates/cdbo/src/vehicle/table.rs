//! Cubic Hermite tables: a smooth function and its derivative, sampled once and interpolated
//! in the hot loop (the tyre's Magic-Formula shape and load sensitivity).
//!
//! With values fₖ and slopes f′ₖ at xₖ = k·h, on t = (x − xₖ)/h ∈ [0, 1]:
//! f(x) ≈ (2t³ − 3t² + 1)fₖ + (t³ − 2t² + t)h·f′ₖ + (3t² − 2t³)fₖ₊₁ + (t³ − t²)h·f′ₖ₊₁,
//! exact for cubics, with error O(h⁴·f⁗); the derivative of this interpolant is returned too.

use super::lanes::{F64x4, Lane};

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
        let (k, t) = node_and_fraction(u);
        let [(f0, m0), (f1, m1)] = self.nodes[k..k + 2] else {
            return None;
        };
        Some(interpolate(t, [f0, m0, f1, m1], self.inv_step))
    }

    /// [`HermiteTable::eval`] of four tables side by side, `tables[i]` at `x[i]`, bit for bit:
    /// the values in one vector and the derivatives in another ([`F64x4`]); `None` unless
    /// every xᵢ is in its table's range.
    #[inline(always)]
    pub(crate) fn eval_lanes(tables: [&HermiteTable; 4], x: F64x4) -> Option<(F64x4, F64x4)> {
        let inv_step = F64x4::new(tables.map(|t| t.inv_step));
        let u = x * inv_step;
        let inside = u.ge(F64x4::splat(0.0)) & u.lt(F64x4::new(tables.map(|t| t.intervals)));
        if !inside.all() {
            return None;
        }
        let u = u.to_array();
        let mut t = [0.0; 4];
        // [fₖ, h·f′ₖ, fₖ₊₁, h·f′ₖ₊₁], each a vector of the four lanes.
        let mut nodes = [[0.0; 4]; 4];
        for i in 0..4 {
            let k;
            (k, t[i]) = node_and_fraction(u[i]);
            let [(f0, m0), (f1, m1)] = tables[i].nodes[k..k + 2] else {
                return None;
            };
            (nodes[0][i], nodes[1][i], nodes[2][i], nodes[3][i]) = (f0, m0, f1, m1);
        }
        Some(interpolate(F64x4::new(t), nodes.map(F64x4::new), inv_step))
    }

    /// The end of the table's range.
    pub fn max_x(&self) -> f64 {
        (self.nodes.len() - 1) as f64 * self.step
    }
}

/// The interpolant and its derivative at the fraction `t` of the interval from node k,
/// [fₖ, h·f′ₖ, fₖ₊₁, h·f′ₖ₊₁] = `[f0, m0, f1, m1]`, with 1/h = `inv_step` (the module's
/// formula).
#[inline(always)]
fn interpolate<T: Lane>(t: T, [f0, m0, f1, m1]: [T; 4], inv_step: T) -> (T, T) {
    let c = T::splat;
    let (t2, t3) = (t * t, t * t * t);
    let f = (c(2.0) * t3 - c(3.0) * t2 + c(1.0)) * f0
        + (t3 - c(2.0) * t2 + t) * m0
        + (c(3.0) * t2 - c(2.0) * t3) * f1
        + (t3 - t2) * m1;
    let d = (c(6.0) * (t2 - t) * (f0 - f1)
        + (c(3.0) * t2 - c(4.0) * t + c(1.0)) * m0
        + (c(3.0) * t2 - c(2.0) * t) * m1)
        * inv_step;
    (f, d)
}

/// The node k = ⌊u⌋ and the fraction t = u − k of u = x/h in [0, len), len < 2³¹
/// ([`HermiteTable::new`]): k as a 32-bit integer, whose conversions from and to a float take a
/// few instructions where a usize's take a dozen.
#[inline(always)]
fn node_and_fraction(u: f64) -> (usize, f64) {
    let k = u as u32;
    (k as usize, u - f64::from(k))
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
