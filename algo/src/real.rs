//! The arithmetic the algorithms need, and nothing else: `f64` and `f32` for a model
//! loaded at run time, a symbolic expression type to generate code.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real number type the algorithms run on.
///
/// Constants of the model (joint placements, axes) enter through [`Real::constant`],
/// which takes a context: nothing for a number type, the expression graph for a
/// symbolic type. The algorithms never branch on a value, only on the model's
/// structure, so running them on a symbolic type records one straight-line program.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// What a constant is made in: `()` for numbers.
    type Context: Copy;
    /// The constant `x`.
    fn constant(context: Self::Context, x: f64) -> Self;
    /// `(sin x, cos x)`.
    fn sin_cos(self) -> (Self, Self);
    /// `self · a + b`. The default is the product and the sum.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
}

macro_rules! impl_real {
    ($t:ident) => {
        impl Real for $t {
            type Context = ();
            #[inline(always)]
            fn constant(_: (), x: f64) -> $t {
                x as $t
            }
            #[inline(always)]
            fn sin_cos(self) -> ($t, $t) {
                #[cfg(feature = "std")]
                {
                    $t::sin_cos(self)
                }
                #[cfg(all(not(feature = "std"), feature = "libm"))]
                {
                    impl_real!(@libm $t, self)
                }
                #[cfg(all(not(feature = "std"), not(feature = "libm")))]
                {
                    compile_error!("dyngen-algo needs the `std` or the `libm` feature for sin and cos")
                }
            }
        }
    };
    (@libm f64, $x:expr) => {
        (libm::sin($x), libm::cos($x))
    };
    (@libm f32, $x:expr) => {
        (libm::sinf($x), libm::cosf($x))
    };
}

impl_real!(f64);
impl_real!(f32);
