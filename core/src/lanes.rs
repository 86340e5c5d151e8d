//! Lane types: several `f64` or `f32` numbers computed as one [`Scalar`], so that a
//! generated function called on them evaluates as many states at once, on the SIMD
//! registers of the target (through the `wide` crate: SSE2 everywhere on x86-64, AVX
//! and AVX-512 with `-C target-cpu=native` where the processor has them, NEON on
//! aarch64).
//!
//! Every lane computes exactly what the scalar type computes for its state: `+ − × ÷`
//! and `√` are correctly rounded in both, `mul_add` is fused in both or in neither (as
//! [`Scalar::mul_add`] says), `sin` and `cos` are [`dyngen_algo::polynomial_sin_cos`]
//! in both (additions and multiplications only, so on the registers too), and `tanh`
//! and `atan2` are the standard library's, lane by lane. So a batch gives bit for bit
//! the results of one call per state.
//!
//! ```
//! use dyngen::lanes::F64x4;
//! use dyngen::Scalar;
//! let x = F64x4::new([1.0, -2.0, 0.0, 4.0]);
//! assert_eq!((x * x + F64x4::ONE).to_array(), [2.0, 5.0, 1.0, 17.0]);
//! assert_eq!(x.sign().to_array(), [1.0, -1.0, 0.0, 1.0]);
//! ```

use crate::{OrderedScalar, Scalar};
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A [`Scalar`] of several lanes, each one state's number, and how to load and store
/// them: what [`crate::batch::Batch`] runs the generated functions on.
pub trait Lanes: Scalar {
    /// The number type of one lane: `f64` or `f32`.
    type Elem: OrderedScalar;
    /// How many lanes.
    const LANES: usize;
    /// The lanes from `LANES` numbers.
    fn from_lanes(x: &[Self::Elem]) -> Self;
    /// Lane `i`.
    fn lane(self, i: usize) -> Self::Elem;
    /// Every lane into `out` (`LANES` long).
    fn write_lanes(self, out: &mut [Self::Elem]);
}

macro_rules! lanes {
    ($(#[$doc:meta])* $name:ident, $wide:ident, $elem:ident, $n:literal, $precision:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        #[repr(transparent)]
        pub struct $name(pub wide::$wide);

        impl $name {
            /// The lanes `x`, state 0 first.
            #[inline(always)]
            pub fn new(x: [$elem; $n]) -> Self {
                $name(wide::$wide::from(x))
            }
            /// Every lane `x`.
            #[inline(always)]
            pub const fn splat(x: $elem) -> Self {
                $name(wide::$wide::splat(x))
            }
            /// The lanes, state 0 first.
            #[inline(always)]
            pub fn to_array(self) -> [$elem; $n] {
                self.0.to_array()
            }
            #[inline(always)]
            fn map(self, f: impl Fn($elem) -> $elem) -> Self {
                Self::new(self.to_array().map(f))
            }
            #[inline(always)]
            fn zip(self, other: Self, f: impl Fn($elem, $elem) -> $elem) -> Self {
                let (a, b) = (self.to_array(), other.to_array());
                Self::new(core::array::from_fn(|i| f(a[i], b[i])))
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, rhs: Self) -> Self {
                $name(self.0 + rhs.0)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, rhs: Self) -> Self {
                $name(self.0 - rhs.0)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, rhs: Self) -> Self {
                $name(self.0 * rhs.0)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, rhs: Self) -> Self {
                $name(self.0 / rhs.0)
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                $name(-self.0)
            }
        }
        impl AddAssign for $name {
            #[inline(always)]
            fn add_assign(&mut self, rhs: Self) {
                *self = *self + rhs;
            }
        }
        impl SubAssign for $name {
            #[inline(always)]
            fn sub_assign(&mut self, rhs: Self) {
                *self = *self - rhs;
            }
        }
        impl MulAssign for $name {
            #[inline(always)]
            fn mul_assign(&mut self, rhs: Self) {
                *self = *self * rhs;
            }
        }

        impl Scalar for $name {
            const ZERO: Self = Self::splat(0.0);
            const ONE: Self = Self::splat(1.0);
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                Self::splat(x as $elem)
            }
            /// [`dyngen_algo::polynomial_sin_cos`] on the registers, as the number
            /// type computes it; a lane beyond its limit (or not finite) takes the
            /// number type's own.
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                let (sin, cos) = dyngen_algo::polynomial_sin_cos((), self, $precision);
                let limit = wide::$wide::splat($precision.limit() as $elem);
                if self.0.abs().simd_le(limit).all() {
                    return (sin, cos);
                }
                // The number type takes the polynomial where it applies, its own
                // beyond: lane by lane, what one call per state gives.
                let x = self.to_array();
                let (mut s, mut c) = ([0.0; $n], [0.0; $n]);
                for i in 0..$n {
                    (s[i], c[i]) = Scalar::sin_cos(x[i]);
                }
                (Self::new(s), Self::new(c))
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                // Correctly rounded, as the scalar square root.
                $name(self.0.sqrt())
            }
            #[inline(always)]
            fn tanh(self) -> Self {
                self.map(|x| Scalar::tanh(x))
            }
            #[inline(always)]
            fn atan2(self, other: Self) -> Self {
                self.zip(other, |y, x| Scalar::atan2(y, x))
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                // Fused exactly where the scalar type fuses.
                #[cfg(any(target_feature = "fma", target_arch = "aarch64"))]
                {
                    $name(self.0.mul_add(a.0, b.0))
                }
                #[cfg(not(any(target_feature = "fma", target_arch = "aarch64")))]
                {
                    self * a + b
                }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $name(self.0.abs())
            }
            #[inline(always)]
            fn sign(self) -> Self {
                self.map(Scalar::sign)
            }
            #[inline(always)]
            fn select_positive(self, a: Self, b: Self) -> Self {
                // NaN > 0 is false in every lane, as in the scalar.
                $name(self.0.simd_gt(wide::$wide::ZERO).select(a.0, b.0))
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                self.0.is_finite().all()
            }
        }

        /// The run-time algorithms of `dyngen-algo` on lanes, as on the number type.
        impl dyngen_algo::Real for $name {
            type Context = ();
            #[inline(always)]
            fn constant(_: (), x: f64) -> Self {
                Self::splat(x as $elem)
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                Scalar::sin_cos(self)
            }
        }

        impl Lanes for $name {
            type Elem = $elem;
            const LANES: usize = $n;
            #[inline(always)]
            fn from_lanes(x: &[$elem]) -> Self {
                let mut a = [0.0; $n];
                a.copy_from_slice(x);
                Self::new(a)
            }
            #[inline(always)]
            fn lane(self, i: usize) -> $elem {
                self.to_array()[i]
            }
            #[inline(always)]
            fn write_lanes(self, out: &mut [$elem]) {
                out.copy_from_slice(&self.to_array());
            }
        }
    };
}

lanes!(
    /// Four `f64` lanes: one AVX register, two SSE2 registers.
    F64x4, f64x4, f64, 4, dyngen_algo::Precision::Double
);
lanes!(
    /// Eight `f64` lanes: one AVX-512 register, two AVX or four SSE2 registers.
    F64x8, f64x8, f64, 8, dyngen_algo::Precision::Double
);
lanes!(
    /// Eight `f32` lanes: one AVX register, two SSE2 registers.
    F32x8, f32x8, f32, 8, dyngen_algo::Precision::Single
);
lanes!(
    /// Sixteen `f32` lanes: one AVX-512 register, two AVX or four SSE2 registers.
    F32x16, f32x16, f32, 16, dyngen_algo::Precision::Single
);

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane operations against the scalar ones, on values that round differently
    /// (so a fused or a reordered operation would show).
    #[test]
    fn every_lane_computes_what_the_scalar_computes() {
        let xs = [0.1, -1.7, 3.0e-8, 2.5, -0.0, 1.0e300, 7.25, -3.3];
        let ys = [0.3, 2.9, -4.0, 1.0e-300, 6.5, -0.2, 1.1, 0.0];
        let (x, y) = (F64x8::new(xs), F64x8::new(ys));
        let check = |got: F64x8, want: &dyn Fn(f64, f64) -> f64| {
            for (i, g) in got.to_array().into_iter().enumerate() {
                let w = want(xs[i], ys[i]);
                assert!(
                    g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                    "lane {i}: {g} vs {w}"
                );
            }
        };
        check(x + y, &|a, b| a + b);
        check(x - y, &|a, b| a - b);
        check(x * y, &|a, b| a * b);
        check(x / y, &|a, b| a / b);
        check(-x, &|a, _| -a);
        check(x.mul_add(y, x), &|a, b| Scalar::mul_add(a, b, a));
        check(x.abs().sqrt(), &|a, _| a.abs().sqrt());
        check(x.sin(), &|a, _| Scalar::sin(a));
        check(x.sin_cos().1, &|a, _| Scalar::cos(a));
        // Beyond the polynomial's limit, and not finite: the number type's own.
        let big = F64x4::new([1.0e6, -3.0, f64::INFINITY, f64::NAN]);
        for (i, (s, c)) in big.sin().to_array().into_iter().zip(big.cos().to_array()).enumerate() {
            let x = big.to_array()[i];
            let (ws, wc) = Scalar::sin_cos(x);
            assert!(
                s.to_bits() == ws.to_bits() || (s.is_nan() && ws.is_nan()),
                "sin lane {i}"
            );
            assert!(
                c.to_bits() == wc.to_bits() || (c.is_nan() && wc.is_nan()),
                "cos lane {i}"
            );
        }
        assert_eq!(Scalar::sin(1.0e6), 1.0e6f64.sin());
        check(x.tanh(), &|a, _| a.tanh());
        check(x.atan2(y), &|a, b| a.atan2(b));
        check(x.sign(), &|a, _| a.sign());
        check(y.select_positive(x, -x), &|a, b| if b > 0.0 { a } else { -a });
        assert!(x.is_finite());
        assert!(!(x / F64x8::ZERO).is_finite());
        let f = F32x16::from_f64(0.1);
        assert_eq!(f.lane(15), 0.1f32);
        assert_eq!(F32x8::from_lanes(&[1.5; 8]).to_array(), [1.5f32; 8]);
        assert_eq!(F64x4::ONE.to_array(), [1.0; 4]);
    }
}
