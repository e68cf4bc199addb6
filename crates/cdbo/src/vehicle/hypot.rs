//! √(x² + y²) without the call into the platform's libm, for the wheels' slip speeds at every
//! physics step.
//!
//! On finite arguments with y_min = min(|x|, |y|) not tiny (≥ 2⁻⁴⁵⁹), x_max = max(|x|, |y|)
//! not huge (≤ 2⁵¹¹) and y_min > 2⁻⁵⁴·x_max, it is h = √(x_max² + y_min²) corrected once for
//! the rounding of the squares (C. F. Borges, "An improved algorithm for hypot(a, b)", 2019):
//!
//! - if h ≤ 2·y_min: δ = h − y_min, t₁ = x_max·(2δ − x_max), t₂ = (δ − 2·(x_max − y_min))·δ;
//! - else: δ = h − x_max, t₁ = 2δ·(x_max − 2·y_min), t₂ = (4δ − y_min)·y_min + δ²;
//!
//! and h ← h − (t₁ + t₂)/(2h), each operation rounded on its own (no fused multiply-add). These
//! are the operations, in order, of glibc's `hypot` (2.35 and later) on x86-64, which the
//! simulator called before; other arguments go to [`f64::hypot`]. Inlined, the step saves the
//! call and the spilling of every live register around it.

use super::lanes::{F64x4, Lane};

/// 2⁵¹¹: above it, squaring could overflow.
const LARGE: f64 = f64::from_bits(0x5fe0_0000_0000_0000);
/// 2⁻⁴⁵⁹: below it, squaring could lose precision.
const TINY: f64 = f64::from_bits(0x2340_0000_0000_0000);
/// 2⁻⁵⁴: below this ratio the smaller argument does not change the rounded result.
const EPS: f64 = f64::from_bits(0x3c90_0000_0000_0000);

/// √(x² + y²), as the module computes it.
#[inline]
pub(crate) fn hypot(x: f64, y: f64) -> f64 {
    let (big, small) = ordered(x, y);
    if !within(big, small) {
        return x.hypot(y);
    }
    corrected(big, small)
}

/// [`hypot`] of four pairs side by side, `hypot(x[i], y[i])` bit for bit, in vector registers
/// ([`F64x4`]); unless every lane is within the algorithm's arguments, each goes to [`hypot`].
#[inline(always)]
pub(crate) fn hypot_lanes(x: F64x4, y: F64x4) -> F64x4 {
    let (big, small) = ordered(x, y);
    if !within(big, small).all() {
        let (x, y) = (x.to_array(), y.to_array());
        return F64x4::new(std::array::from_fn(|i| hypot(x[i], y[i])));
    }
    corrected(big, small)
}

/// (x_max, y_min) = (max(|x|, |y|), min(|x|, |y|)).
#[inline(always)]
fn ordered<T: Lane>(x: T, y: T) -> (T, T) {
    let (x, y) = (x.abs(), y.abs());
    let swap = x.lt(y);
    (T::select(swap, y, x), T::select(swap, x, y))
}

/// Whether the module's algorithm takes (x_max, y_min): false on a NaN or an infinity too.
#[inline(always)]
fn within<T: Lane>(big: T, small: T) -> T::Mask {
    big.le(T::splat(LARGE)) & small.ge(T::splat(TINY)) & small.gt(big * T::splat(EPS))
}

/// h = √(x_max² + y_min²) corrected once for the rounding of the squares (the module's
/// formulas): both cases' terms are computed and the one for h ≤ 2·y_min or not kept.
#[inline(always)]
fn corrected<T: Lane>(big: T, small: T) -> T {
    let (two, four) = (T::splat(2.0), T::splat(4.0));
    let h = (big * big + small * small).sqrt();
    let near = {
        let delta = h - small;
        (
            big * (two * delta - big),
            (delta - two * (big - small)) * delta,
        )
    };
    let far = {
        let delta = h - big;
        (
            two * delta * (big - two * small),
            (four * delta - small) * small + delta * delta,
        )
    };
    let is_near = h.le(two * small);
    let (t1, t2) = (
        T::select(is_near, near.0, far.0),
        T::select(is_near, near.1, far.1),
    );
    h - (t1 + t2) / (two * h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    /// Within the platform's rounding of √(x² + y²): at most one unit in the last place from
    /// the exact value, and on glibc (x86-64) the very bits of its `hypot`.
    #[test]
    fn agrees_with_the_platforms_hypot() {
        let mut rng = crate::rng::rng_for(7, 0);
        let mut cases = vec![
            (3.0, 4.0),
            (0.0, 0.0),
            (-1e-300, 2.0),
            (1e300, 1e300),
            (f64::NAN, 1.0),
        ];
        for _ in 0..200_000 {
            // Wheel speeds: up to 100 m/s along, a few m/s across, and pairs of any scale.
            let scale = 10f64.powf(rng.random_range(-6.0..3.0));
            let across = 10.0 * rng.random_range(-1.0..1.0);
            cases.push((scale * rng.random_range(-1.0..1.0), across));
            cases.push((
                rng.random_range(-100.0..100.0),
                rng.random_range(-100.0..100.0),
            ));
        }
        for (x, y) in cases {
            let (ours, platform) = (hypot(x, y), x.hypot(y));
            if platform.is_nan() {
                assert!(ours.is_nan(), "hypot({x}, {y})");
                continue;
            }
            let ulp = f64::from_bits(platform.to_bits() + 1) - platform;
            assert!(
                (ours - platform).abs() <= ulp,
                "hypot({x}, {y}): {ours} against {platform}"
            );
            if cfg!(all(
                target_arch = "x86_64",
                target_os = "linux",
                target_env = "gnu"
            )) {
                assert_eq!(ours.to_bits(), platform.to_bits(), "hypot({x}, {y})");
            }
        }
    }

    /// Four pairs side by side give each pair's [`hypot`], bit for bit, whether or not every
    /// lane is within the algorithm's arguments.
    #[test]
    fn four_lanes_are_four_hypots() {
        let mut rng = crate::rng::rng_for(8, 0);
        let mut lanes = vec![([0.0, 3.0, 1e-300, 5.0], [0.0, 4.0, 2.0, f64::NAN])];
        for _ in 0..50_000 {
            let mut pair = || {
                let scale = 10f64.powf(rng.random_range(-3.0..2.0));
                (
                    scale * rng.random_range(-1.0..1.0),
                    10.0 * rng.random_range(-1.0..1.0),
                )
            };
            let p = [pair(), pair(), pair(), pair()];
            lanes.push((p.map(|p| p.0), p.map(|p| p.1)));
        }
        for (x, y) in lanes {
            let four = hypot_lanes(F64x4::new(x), F64x4::new(y)).to_array();
            for i in 0..4 {
                let one = hypot(x[i], y[i]);
                assert_eq!(
                    four[i].to_bits(),
                    one.to_bits(),
                    "hypot({}, {})",
                    x[i],
                    y[i]
                );
            }
        }
    }
}
