//! One contact law, two widths: the arithmetic the law needs, for one pair (`f64`) and for four
//! pairs at once ([`F4`]).
//!
//! [`F4`] applies the same `f64` operation to each of its four lanes, so a pair computed in a
//! lane gets exactly the bits the scalar law gives it: every operation the law uses (`+`,
//! `-`, `*`, `/`, `sqrt`, `mul_add`, `max`, `min`, `abs`, comparisons) is correctly rounded or
//! exact in IEEE 754, lane by lane. The lanes are plain arrays written so that LLVM's
//! superword-level vectorizer turns each operation into one AVX2 instruction on the x86-64-v3
//! baseline (`vaddpd`, `vsqrtpd`, `vfmadd...pd`, ...), and a build for another architecture
//! gets correct scalar code. The kernel's contact mask is the exception, written with vector
//! instructions in [`super::simd`].

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The arithmetic of the contact law (see the module documentation).
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A lane mask: one flag per lane.
    type Mask: Copy;
    /// `v` in every lane.
    fn splat(v: f64) -> Self;
    /// `self * a + b` with one rounding.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// `f64::max` lane by lane (a NaN lane takes the other operand).
    fn max(self, o: Self) -> Self;
    /// `f64::min` lane by lane.
    fn min(self, o: Self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `self > o` lane by lane.
    fn gt(self, o: Self) -> Self::Mask;
    /// `if m { a } else { b }` lane by lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f64::max(self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        f64::min(self, o)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m { a } else { b }
    }
}

/// Four `f64` lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F4(pub [f64; 4]);

impl F4 {
    /// Applies `f` to each lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let a = self.0;
        F4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }

    /// Applies `f` to each pair of lanes.
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let (a, b) = (self.0, o.0);
        F4([f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])])
    }
}

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        self.map(|a| -a)
    }
}

/// All bits set in a lane where a mask is true, none where false: a selection is then two bit
/// operations, which the compiler keeps in vector registers (a `[bool; 4]` mask made it branch
/// lane by lane).
#[inline(always)]
fn lane_mask(b: bool) -> u64 {
    (b as u64).wrapping_neg()
}

impl Real for F4 {
    type Mask = [u64; 4];
    #[inline(always)]
    fn splat(v: f64) -> Self {
        F4([v; 4])
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let (s, a, b) = (self.0, a.0, b.0);
        F4([
            s[0].mul_add(a[0], b[0]),
            s[1].mul_add(a[1], b[1]),
            s[2].mul_add(a[2], b[2]),
            s[3].mul_add(a[3], b[3]),
        ])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, f64::max)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.zip(o, f64::min)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f64::abs)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> [u64; 4] {
        let (a, b) = (self.0, o.0);
        [
            lane_mask(a[0] > b[0]),
            lane_mask(a[1] > b[1]),
            lane_mask(a[2] > b[2]),
            lane_mask(a[3] > b[3]),
        ]
    }
    #[inline(always)]
    fn select(m: [u64; 4], a: Self, b: Self) -> Self {
        let pick =
            |l: usize| f64::from_bits((a.0[l].to_bits() & m[l]) | (b.0[l].to_bits() & !m[l]));
        F4([pick(0), pick(1), pick(2), pick(3)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane of an `F4` operation is the `f64` operation on that lane, bit for bit
    /// (including a NaN lane for `max`, which takes the other operand as `f64::max` does).
    #[test]
    fn lanes_are_the_scalar_operations() {
        let a = F4([1.5, -2.25e-7, 3.0e9, f64::NAN]);
        let b = F4([0.1, 7.0, -1.0 / 3.0, 2.0]);
        let c = F4([-0.3, 1e-20, 5.5, 1.0]);
        let bits = |x: F4| x.0.map(f64::to_bits);
        for l in 0..4 {
            let (x, y, z) = (a.0[l], b.0[l], c.0[l]);
            assert_eq!(bits(a + b)[l], (x + y).to_bits());
            assert_eq!(bits(a - b)[l], (x - y).to_bits());
            assert_eq!(bits(a * b)[l], (x * y).to_bits());
            assert_eq!(bits(a / b)[l], (x / y).to_bits());
            assert_eq!(bits(a.mul_add(b, c))[l], x.mul_add(y, z).to_bits());
            assert_eq!(bits(b.abs().sqrt())[l], y.abs().sqrt().to_bits());
            assert_eq!(bits(a.max(b))[l], x.max(y).to_bits());
            assert_eq!(bits(a.min(b))[l], x.min(y).to_bits());
            assert_eq!(bits(-a)[l], (-x).to_bits());
            assert_eq!(a.gt(b)[l] != 0, x > y);
            assert_eq!(bits(F4::select(a.gt(b), a, c))[l], if x > y { x } else { z }.to_bits());
        }
    }
}
