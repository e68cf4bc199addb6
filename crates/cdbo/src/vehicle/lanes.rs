//! Arithmetic written once for one wheel (`f64`) and for the four side by side ([`F64x4`]).
//!
//! [`Lane`] is what the tyre's formulas need of a number: the four operations, √, |·|, max,
//! comparisons and a choice between two values. On [`F64x4`] each is the `f64` operation lane by
//! lane, in loops the compiler turns into vector instructions, so that a formula written over
//! [`Lane`] gives each wheel's bits exactly as its `f64` evaluation does.

use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

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
    type Mask: Copy + BitAnd<Output = Self::Mask>;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
    /// [`f64::sqrt`].
    fn sqrt(self) -> Self;
    /// [`f64::abs`].
    fn abs(self) -> Self;
    /// [`f64::max`].
    fn max(self, other: Self) -> Self;
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
    fn max(self, other: f64) -> f64 {
        f64::max(self, other)
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
/// operation taken lane by lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct F64x4(pub(crate) [f64; 4]);

/// One comparison's outcome per lane of [`F64x4`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Mask4(pub(crate) [bool; 4]);

impl Mask4 {
    /// Whether every lane holds.
    #[inline(always)]
    pub(crate) fn all(self) -> bool {
        self.0[0] & self.0[1] & self.0[2] & self.0[3]
    }
}

impl BitAnd for Mask4 {
    type Output = Mask4;

    #[inline(always)]
    fn bitand(self, other: Mask4) -> Mask4 {
        let mut out = [false; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.0[i] & other.0[i];
        }
        Mask4(out)
    }
}

impl F64x4 {
    /// `f` of each lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F64x4 {
        let mut out = [0.0; 4];
        for (o, x) in out.iter_mut().zip(self.0) {
            *o = f(x);
        }
        F64x4(out)
    }

    /// `f` of each lane of `self` and `other`.
    #[inline(always)]
    fn zip(self, other: F64x4, f: impl Fn(f64, f64) -> f64) -> F64x4 {
        let mut out = [0.0; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = f(self.0[i], other.0[i]);
        }
        F64x4(out)
    }

    /// `f` of each lane of `self` and `other`, a comparison.
    #[inline(always)]
    fn compare(self, other: F64x4, f: impl Fn(f64, f64) -> bool) -> Mask4 {
        let mut out = [false; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = f(self.0[i], other.0[i]);
        }
        Mask4(out)
    }
}

impl Add for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn add(self, other: F64x4) -> F64x4 {
        self.zip(other, |a, b| a + b)
    }
}

impl Sub for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn sub(self, other: F64x4) -> F64x4 {
        self.zip(other, |a, b| a - b)
    }
}

impl Mul for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn mul(self, other: F64x4) -> F64x4 {
        self.zip(other, |a, b| a * b)
    }
}

impl Div for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn div(self, other: F64x4) -> F64x4 {
        self.zip(other, |a, b| a / b)
    }
}

impl Neg for F64x4 {
    type Output = F64x4;

    #[inline(always)]
    fn neg(self) -> F64x4 {
        self.map(|a| -a)
    }
}

impl Lane for F64x4 {
    type Mask = Mask4;

    #[inline(always)]
    fn splat(x: f64) -> F64x4 {
        F64x4([x; 4])
    }

    #[inline(always)]
    fn sqrt(self) -> F64x4 {
        self.map(f64::sqrt)
    }

    #[inline(always)]
    fn abs(self) -> F64x4 {
        self.map(f64::abs)
    }

    #[inline(always)]
    fn max(self, other: F64x4) -> F64x4 {
        self.zip(other, f64::max)
    }

    #[inline(always)]
    fn lt(self, other: F64x4) -> Mask4 {
        self.compare(other, |a, b| a < b)
    }

    #[inline(always)]
    fn le(self, other: F64x4) -> Mask4 {
        self.compare(other, |a, b| a <= b)
    }

    #[inline(always)]
    fn gt(self, other: F64x4) -> Mask4 {
        self.compare(other, |a, b| a > b)
    }

    #[inline(always)]
    fn ge(self, other: F64x4) -> Mask4 {
        self.compare(other, |a, b| a >= b)
    }

    #[inline(always)]
    fn select(mask: Mask4, yes: F64x4, no: F64x4) -> F64x4 {
        let mut out = [0.0; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = if mask.0[i] { yes.0[i] } else { no.0[i] };
        }
        F64x4(out)
    }
}
