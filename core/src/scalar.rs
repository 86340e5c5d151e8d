//! The scalar type generated code computes in. Generated functions are generic over
//! [`Scalar`]; `f64` is the reference, `f32` suits microcontrollers, and a lane type
//! (feature `batch`: [`crate::batch`]) computes several states in one call.
//!
//! [`Scalar`] has no order: a lane type holds several numbers, and code that branched
//! on a value would take one branch for all of them. Generated code never branches on a
//! value; what must (the friction sign, a guard) uses the lane-wise [`Scalar::sign`] and
//! [`Scalar::select_positive`]. Code that needs the order of one number (the maps of
//! [`crate::configuration`], [`crate::log3`], [`crate::Coulomb::smooth`]) asks for
//! [`OrderedScalar`], which `f64` and `f32` are.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real number type: the arithmetic generated code uses, and nothing else.
pub trait Scalar:
    Copy
    + PartialEq
    + Debug
    + Default
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + nalgebra::Scalar
{
    const ZERO: Self;
    const ONE: Self;
    /// Converts a constant of the generated code (rounding for narrower types; the
    /// same in every lane of a lane type).
    fn from_f64(x: f64) -> Self;
    /// `sin_cos(self).0`.
    #[inline(always)]
    fn sin(self) -> Self {
        Scalar::sin_cos(self).0
    }
    /// `sin_cos(self).1`.
    #[inline(always)]
    fn cos(self) -> Self {
        Scalar::sin_cos(self).1
    }
    /// Both at once: one call where the platform computes them together.
    fn sin_cos(self) -> (Self, Self);
    fn sqrt(self) -> Self;
    /// The hyperbolic tangent: the smooth Coulomb friction `tanh(q̇/ε)`
    /// ([`crate::Coulomb::Smooth`]).
    fn tanh(self) -> Self;
    /// The angle of the point `(other, self)`: `atan2(y = self, x = other)`, for the
    /// logarithm of a rotation ([`crate::log3`]).
    fn atan2(self, other: Self) -> Self;
    /// `self · a + b`: what generated code writes for a product that is only summed.
    /// `f64` and `f32` fuse it into one instruction with one rounding where the target
    /// has one and the standard library is linked (x86-64 with `-C target-cpu=native`
    /// on any processor since 2013, or `-C target-feature=+fma`; every aarch64), and
    /// otherwise compute the product and the sum, so that no build calls a software
    /// fused multiply-add. The default is the product and the sum.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    /// `|self|`.
    fn abs(self) -> Self;
    /// `−1`, `0` or `1` by the sign of `self` (`+0` for `±0`, NaN for NaN), lane by lane.
    fn sign(self) -> Self;
    /// `a` where `self > 0` and `b` elsewhere (NaN included), lane by lane. Both
    /// `a` and `b` are computed.
    fn select_positive(self, a: Self, b: Self) -> Self;
    /// Whether the value is finite (every lane of a lane type).
    fn is_finite(self) -> bool;
}

/// A [`Scalar`] holding one number: ordered, and convertible to `f64`. `f64` and
/// `f32` are; lane types are not. What branches on a value asks for it.
pub trait OrderedScalar: Scalar + PartialOrd {
    /// The value as an `f64` (exact for `f32`).
    fn to_f64(self) -> f64;
}

macro_rules! impl_scalar {
    ($t:ty) => {
        impl Scalar for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            /// `dyngen_algo`'s ([`dyngen_algo::polynomial_sin_cos`] where it applies):
            /// the run-time algorithms, generated code and the lane types compute the
            /// same numbers.
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                dyngen_algo::Real::sin_cos(self)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                num_traits::Float::sqrt(self)
            }
            #[inline(always)]
            fn tanh(self) -> Self {
                num_traits::Float::tanh(self)
            }
            #[inline(always)]
            fn atan2(self, other: Self) -> Self {
                num_traits::Float::atan2(self, other)
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                #[cfg(all(feature = "std", any(target_feature = "fma", target_arch = "aarch64")))]
                {
                    num_traits::Float::mul_add(self, a, b)
                }
                #[cfg(not(all(feature = "std", any(target_feature = "fma", target_arch = "aarch64"))))]
                {
                    self * a + b
                }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                num_traits::Float::abs(self)
            }
            #[inline(always)]
            fn sign(self) -> Self {
                if self > 0.0 {
                    1.0
                } else if self < 0.0 {
                    -1.0
                } else if self == 0.0 {
                    0.0
                } else {
                    self
                }
            }
            #[inline(always)]
            fn select_positive(self, a: Self, b: Self) -> Self {
                if self > 0.0 {
                    a
                } else {
                    b
                }
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                num_traits::Float::is_finite(self)
            }
        }

        impl OrderedScalar for $t {
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
        }
    };
}

impl_scalar!(f64);
impl_scalar!(f32);

#[cfg(test)]
mod tests {
    use super::Scalar;

    /// `(1 + 2⁻³⁰)(1 − 2⁻³⁰) − 1 = −2⁻⁶⁰` exactly; the rounded product is 1, so the
    /// product and the sum give 0, the fused operation gives `−2⁻⁶⁰`. Which one a build
    /// computes is fixed by its target.
    #[test]
    fn mul_add_is_fused_exactly_where_the_target_fuses() {
        let e = 2f64.powi(-30);
        let got = Scalar::mul_add(1.0 + e, 1.0 - e, -1.0);
        if cfg!(all(
            feature = "std",
            any(target_feature = "fma", target_arch = "aarch64")
        )) {
            assert_eq!(got, -2f64.powi(-60));
        } else {
            assert_eq!(got, 0.0);
        }
        assert_eq!(Scalar::mul_add(3.0f32, 0.5, 0.25), 1.75);
    }
}
