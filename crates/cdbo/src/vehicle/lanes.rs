//! Arithmetic written once for one wheel (`f64`) and for the four side by side ([`F64x4`]).
//!
//! [`Lane`] is what the tyre's formulas need of a number: the four operations, √, |·|, max,
//! comparisons and a choice between two values. On [`F64x4`] each is the `f64` operation lane by
//! lane, so that a formula written over [`Lane`] gives each wheel's bits exactly as its `f64`
//! evaluation does: on x86-64 two SSE2 registers of two lanes each (every x86-64 processor has
//! SSE2; the four operations and √ are IEEE's correctly rounded ones, a choice is a bitwise
//! blend, a comparison's outcome stays in the registers), elsewhere loops over the lanes.

use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

/// Whether a comparison held in any lane.
pub(crate) trait AnyLane {
    /// Whether any lane holds.
    fn any(self) -> bool;
}

impl AnyLane for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

/// A number the tyre's formulas are written over: `f64`, or four of them ([`F64x4`]).
pub(crate) trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The outcome of a comparison: `bool`, or one per lane.
    type Mask: Copy + BitAnd<Output = Self::Mask> + AnyLane;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
    /// [`f64::sqrt`].
    fn sqrt(self) -> Self;
    /// [`f64::abs`].
    fn abs(self) -> Self;
    /// [`f64::max`]`(self, floor)` for a `floor` that is neither NaN nor a zero: `floor` where
    /// `self` is below it or NaN.
    fn at_least(self, floor: f64) -> Self;
    /// self < other.
    fn lt(self, other: Self) -> Self::Mask;
    /// self ≤ other.
    fn le(self, other: Self) -> Self::Mask;
    /// self > other.
    fn gt(self, other: Self) -> Self::Mask;
    /// self ≥ other.
    fn ge(self, other: Self) -> Self::Mask;
    /// `yes` where `mask` holds, else `no`.
    fn select(mask: Self::Mask, yes: Self, no: Self) -> Self;
}

impl Lane for f64 {
    type Mask = bool;

    #[inline(always)]
    fn splat(x: f64) -> f64 {
        x
    }

    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }

    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }

    #[inline(always)]
    fn at_least(self, floor: f64) -> f64 {
        f64::max(self, floor)
    }

    #[inline(always)]
    fn lt(self, other: f64) -> bool {
        self < other
    }

    #[inline(always)]
    fn le(self, other: f64) -> bool {
        self <= other
    }

    #[inline(always)]
    fn gt(self, other: f64) -> bool {
        self > other
    }

    #[inline(always)]
    fn ge(self, other: f64) -> bool {
        self >= other
    }

    #[inline(always)]
    fn select(mask: bool, yes: f64, no: f64) -> f64 {
        if mask { yes } else { no }
    }
}

/// Four doubles, one per wheel (front left, front right, rear left, rear right), each
/// operation taken lane by lane: lanes 0 and 1 in one [`Pair`], lanes 2 and 3 in the other.
#[derive(Clone, Copy)]
pub(crate) struct F64x4([Pair; 2]);

/// One comparison's outcome per lane of [`F64x4`]: all bits set where it holds, none where not.
#[derive(Clone, Copy)]
pub(crate) struct Mask4([Pair; 2]);

impl F64x4 {
    /// The lanes `x`.
    #[inline(always)]
    pub(crate) fn new(x: [f64; 4]) -> F64x4 {
        F64x4([Pair::new(x[0], x[1]), Pair::new(x[2], x[3])])
    }

    /// The lanes.
    #[inline(always)]
    pub(crate) fn to_array(self) -> [f64; 4] {
        let ([a, b], [c, d]) = (self.0[0].to_array(), self.0[1].to_array());
        [a, b, c, d]
    }

    #[inline(always)]
    fn zip(self, other: F64x4, f: impl Fn(Pair, Pair) -> Pair) -> F64x4 {
        F64x4([f(self.0[0], other.0[0]), f(self.0[1], other.0[1])])
    }

    #[inline(always)]
    fn compare(self, other: F64x4, f: impl Fn(Pair, Pair) -> Pair) -> Mask4 {
        Mask4([f(self.0[0], other.0[0]), f(self.0[1], other.0[1])])
    }
}

impl std::fmt::Debug for F64x4 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("F64x4").field(&self.to_array()).finish()
    }
}

impl Mask4 {
    /// Whether every lane holds.
    #[inline(always)]
    pub(crate) fn all(self) -> bool {
        self.0[0].movemask() & self.0[1].movemask() == 0b11
    }
}

impl AnyLane for Mask4 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0[0].movemask() | self.0[1].movemask() != 0
    }
}

impl BitAnd for Mask4 {
    type Output = Mask4;

    #[inline(always)]
    fn bitand(self, other: Mask4) -> Mask4 {
        Mask4([self.0[0].and(other.0[0]), self.0[1].and(other.0[1])])
    }
}

impl Add for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn add(self, other: F64x4) -> F64x4 {
        self.zip(other, Pair::add)
    }
}

impl Sub for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn sub(self, other: F64x4) -> F64x4 {
        self.zip(other, Pair::sub)
    }
}

impl Mul for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn mul(self, other: F64x4) -> F64x4 {
        self.zip(other, Pair::mul)
    }
}

impl Div for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn div(self, other: F64x4) -> F64x4 {
        self.zip(other, Pair::div)
    }
}

impl Neg for F64x4 {
    type Output = F64x4;

    /// The sign bit flipped, as `-x` does.
    #[inline(always)]
    fn neg(self) -> F64x4 {
        let sign = Pair::splat(-0.0);
        F64x4([self.0[0].xor(sign), self.0[1].xor(sign)])
    }
}

impl Lane for F64x4 {
    type Mask = Mask4;

    #[inline(always)]
    fn splat(x: f64) -> F64x4 {
        F64x4([Pair::splat(x); 2])
    }

    #[inline(always)]
    fn sqrt(self) -> F64x4 {
        F64x4([self.0[0].sqrt(), self.0[1].sqrt()])
    }

    /// The sign bit cleared, as [`f64::abs`] does.
    #[inline(always)]
    fn abs(self) -> F64x4 {
        let sign = Pair::splat(-0.0);
        F64x4([sign.and_not(self.0[0]), sign.and_not(self.0[1])])
    }

    #[inline(always)]
    fn at_least(self, floor: f64) -> F64x4 {
        let floor = Pair::splat(floor);
        F64x4([self.0[0].at_least(floor), self.0[1].at_least(floor)])
    }

    #[inline(always)]
    fn lt(self, other: F64x4) -> Mask4 {
        self.compare(other, Pair::lt)
    }

    #[inline(always)]
    fn le(self, other: F64x4) -> Mask4 {
        self.compare(other, Pair::le)
    }

    #[inline(always)]
    fn gt(self, other: F64x4) -> Mask4 {
        other.compare(self, Pair::lt)
    }

    #[inline(always)]
    fn ge(self, other: F64x4) -> Mask4 {
        other.compare(self, Pair::le)
    }

    /// `yes` where `mask` holds, else `no`: (mask ∧ yes) ∨ (¬mask ∧ no), bit by bit.
    #[inline(always)]
    fn select(mask: Mask4, yes: F64x4, no: F64x4) -> F64x4 {
        let blend = |i: usize| mask.0[i].and(yes.0[i]).or(mask.0[i].and_not(no.0[i]));
        F64x4([blend(0), blend(1)])
    }
}

/// An SSE2 intrinsic of `std::arch::x86_64`, called where every x86-64 processor has it.
#[cfg(target_arch = "x86_64")]
macro_rules! sse2 {
    ($e:expr) => {{
        #[allow(unused_imports)]
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of the x86-64 baseline, so every processor this code runs on
        // has it; the intrinsics used read and write registers only.
        unsafe { $e }
    }};
}

/// Two lanes of [`F64x4`] in one SSE2 register.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
struct Pair(std::arch::x86_64::__m128d);

#[cfg(target_arch = "x86_64")]
impl Pair {
    #[inline(always)]
    fn new(a: f64, b: f64) -> Pair {
        Pair(sse2!(_mm_set_pd(b, a)))
    }

    #[inline(always)]
    fn splat(x: f64) -> Pair {
        Pair(sse2!(_mm_set1_pd(x)))
    }

    #[inline(always)]
    fn to_array(self) -> [f64; 2] {
        [
            sse2!(_mm_cvtsd_f64(self.0)),
            sse2!(_mm_cvtsd_f64(_mm_unpackhi_pd(self.0, self.0))),
        ]
    }

    #[inline(always)]
    fn add(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_add_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn sub(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_sub_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn mul(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_mul_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn div(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_div_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn sqrt(self) -> Pair {
        Pair(sse2!(_mm_sqrt_pd(self.0)))
    }

    #[inline(always)]
    fn and(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_and_pd(self.0, o.0)))
    }

    /// ¬self ∧ o.
    #[inline(always)]
    fn and_not(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_andnot_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn or(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_or_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn xor(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_xor_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn lt(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_cmplt_pd(self.0, o.0)))
    }

    #[inline(always)]
    fn le(self, o: Pair) -> Pair {
        Pair(sse2!(_mm_cmple_pd(self.0, o.0)))
    }

    /// `self` where it is greater than `floor`, else `floor` (SSE2's maximum): [`f64::max`]'s
    /// bits for a `floor` that is neither NaN nor a zero.
    #[inline(always)]
    fn at_least(self, floor: Pair) -> Pair {
        Pair(sse2!(_mm_max_pd(self.0, floor.0)))
    }

    /// The lanes' sign bits, lane 0 in bit 0.
    #[inline(always)]
    fn movemask(self) -> i32 {
        sse2!(_mm_movemask_pd(self.0))
    }
}

/// Two lanes of [`F64x4`], each operation taken lane by lane.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy)]
struct Pair([f64; 2]);

#[cfg(not(target_arch = "x86_64"))]
impl Pair {
    #[inline(always)]
    fn new(a: f64, b: f64) -> Pair {
        Pair([a, b])
    }

    #[inline(always)]
    fn splat(x: f64) -> Pair {
        Pair([x; 2])
    }

    #[inline(always)]
    fn to_array(self) -> [f64; 2] {
        self.0
    }

    #[inline(always)]
    fn map2(self, o: Pair, f: impl Fn(f64, f64) -> f64) -> Pair {
        Pair([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
    }

    #[inline(always)]
    fn bits(self, o: Pair, f: impl Fn(u64, u64) -> u64) -> Pair {
        self.map2(o, |a, b| f64::from_bits(f(a.to_bits(), b.to_bits())))
    }

    #[inline(always)]
    fn mask(self, o: Pair, f: impl Fn(f64, f64) -> bool) -> Pair {
        self.map2(o, |a, b| f64::from_bits(if f(a, b) { u64::MAX } else { 0 }))
    }

    #[inline(always)]
    fn add(self, o: Pair) -> Pair {
        self.map2(o, |a, b| a + b)
    }

    #[inline(always)]
    fn sub(self, o: Pair) -> Pair {
        self.map2(o, |a, b| a - b)
    }

    #[inline(always)]
    fn mul(self, o: Pair) -> Pair {
        self.map2(o, |a, b| a * b)
    }

    #[inline(always)]
    fn div(self, o: Pair) -> Pair {
        self.map2(o, |a, b| a / b)
    }

    #[inline(always)]
    fn sqrt(self) -> Pair {
        Pair(self.0.map(f64::sqrt))
    }

    #[inline(always)]
    fn and(self, o: Pair) -> Pair {
        self.bits(o, |a, b| a & b)
    }

    /// ¬self ∧ o.
    #[inline(always)]
    fn and_not(self, o: Pair) -> Pair {
        self.bits(o, |a, b| !a & b)
    }

    #[inline(always)]
    fn or(self, o: Pair) -> Pair {
        self.bits(o, |a, b| a | b)
    }

    #[inline(always)]
    fn xor(self, o: Pair) -> Pair {
        self.bits(o, |a, b| a ^ b)
    }

    #[inline(always)]
    fn lt(self, o: Pair) -> Pair {
        self.mask(o, |a, b| a < b)
    }

    #[inline(always)]
    fn le(self, o: Pair) -> Pair {
        self.mask(o, |a, b| a <= b)
    }

    /// [`f64::max`] lane by lane.
    #[inline(always)]
    fn at_least(self, floor: Pair) -> Pair {
        self.map2(floor, f64::max)
    }

    /// The lanes' sign bits, lane 0 in bit 0.
    #[inline(always)]
    fn movemask(self) -> i32 {
        let [a, b] = self.0.map(|x| (x.to_bits() >> 63) as i32);
        a | b << 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation on [`F64x4`] gives each lane the bits of the `f64` operation, on
    /// ordinary numbers and on signed zeros, infinities, NaN and subnormals alike.
    #[test]
    fn each_lane_is_the_f64_operation() {
        use rand::Rng;
        let special = [
            0.0,
            -0.0,
            2.0,
            -2.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE / 3.0,
            1e300,
        ];
        let mut rng = crate::rng::rng_for(11, 0);
        let mut pick = || -> f64 {
            if rng.random_bool(0.3) {
                special[rng.random_range(0..special.len())]
            } else {
                rng.random_range(-1e3..1e3)
            }
        };
        let bits = |x: [f64; 4]| x.map(f64::to_bits);
        for _ in 0..20_000 {
            let a: [f64; 4] = std::array::from_fn(|_| pick());
            let b: [f64; 4] = std::array::from_fn(|_| pick());
            let (x, y) = (F64x4::new(a), F64x4::new(b));
            let lanes = |f: &dyn Fn(f64, f64) -> f64| -> [f64; 4] {
                std::array::from_fn(|i| f(a[i], b[i]))
            };
            assert_eq!(bits((x + y).to_array()), bits(lanes(&|p, q| p + q)));
            assert_eq!(bits((x - y).to_array()), bits(lanes(&|p, q| p - q)));
            assert_eq!(bits((x * y).to_array()), bits(lanes(&|p, q| p * q)));
            assert_eq!(bits((x / y).to_array()), bits(lanes(&|p, q| p / q)));
            assert_eq!(bits((-x).to_array()), bits(lanes(&|p, _| -p)));
            assert_eq!(bits(x.sqrt().to_array()), bits(lanes(&|p, _| p.sqrt())));
            assert_eq!(bits(x.abs().to_array()), bits(lanes(&|p, _| p.abs())));
            for floor in [2.0, -2.0, 1e-300, f64::INFINITY] {
                assert_eq!(
                    bits(x.at_least(floor).to_array()),
                    bits(lanes(&|p, _| p.max(floor)))
                );
            }
            type Compare = (fn(F64x4, F64x4) -> Mask4, fn(&f64, &f64) -> bool);
            let compares: [Compare; 4] = [
                (<F64x4 as Lane>::lt, PartialOrd::lt),
                (<F64x4 as Lane>::le, PartialOrd::le),
                (<F64x4 as Lane>::gt, PartialOrd::gt),
                (<F64x4 as Lane>::ge, PartialOrd::ge),
            ];
            for (lane, one) in compares {
                let mask = lane(x, y);
                let want: [bool; 4] = std::array::from_fn(|i| one(&a[i], &b[i]));
                let chosen = F64x4::select(mask, x, y).to_array();
                let chosen_one: [f64; 4] =
                    std::array::from_fn(|i| if want[i] { a[i] } else { b[i] });
                assert_eq!(bits(chosen), bits(chosen_one));
                assert_eq!(mask.all(), want.iter().all(|&w| w));
                assert_eq!(mask.any(), want.iter().any(|&w| w));
                let both = mask & Lane::lt(x, F64x4::splat(0.0));
                assert_eq!(both.all(), (0..4).all(|i| want[i] && a[i] < 0.0));
            }
        }
    }
}
