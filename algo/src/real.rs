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

/// The precision of [`polynomial_sin_cos`]: which constants it uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// `f64` lanes: degree-13/14 polynomials, reduction valid for `|x| ≤ 65536`.
    Double,
    /// `f32` lanes: degree-7/8 polynomials, reduction valid for `|x| ≤ 8192`.
    Single,
}

impl Precision {
    /// The largest `|x|` [`polynomial_sin_cos`] reduces exactly; beyond it (and for
    /// infinities and NaN) the standard library's sine and cosine are used.
    pub const fn limit(self) -> f64 {
        match self {
            Precision::Double => 65536.0,
            Precision::Single => 8192.0,
        }
    }
}

/// `(sin x, cos x)` by additions and multiplications only, so that `f64`, `f32` and
/// any SIMD lane type built from them compute bit for bit the same numbers, and a lane
/// type computes them on its registers. For `|x| ≤ precision.limit()`; within about
/// one unit in the last place of the correctly rounded values.
///
/// `x` is reduced by the nearest multiple `j` of `π/2` (Cody and Waite's three-part
/// `π/2`, each product exact for `|j| < 2¹⁶` in `f64`, `2¹³` in `f32`), the remainder
/// `|r| ≤ π/4` goes through Cephes' minimax polynomials (Moshier), and the quadrant
/// `j mod 4` picks and signs them by arithmetic, not by a branch. Rounding to an
/// integer adds and subtracts `1.5·2⁵²` (`1.5·2²³`): exact in round-to-nearest.
///
/// ```
/// use dyngen_algo::{polynomial_sin_cos, Precision};
/// for x in [0.0, 0.3, -1.2, 2.0, 3.1, -4.5, 100.0, 1000.5] {
///     let (s, c) = polynomial_sin_cos((), x, Precision::Double);
///     assert!((s - f64::sin(x)).abs() <= 2.0 * f64::EPSILON && (c - f64::cos(x)).abs() <= 2.0 * f64::EPSILON);
/// }
/// ```
// The constants as published, digits beyond a double's included.
#[allow(clippy::excessive_precision)]
#[inline(always)]
pub fn polynomial_sin_cos<T: Real>(context: T::Context, x: T, precision: Precision) -> (T, T) {
    let k = |v: f64| T::constant(context, v);
    let (magic, p1, p2, p3) = match precision {
        Precision::Double => (
            6755399441055744.0,
            1.570_796_251_296_997_070_31,
            7.549_789_415_861_596_353_35e-8,
            5.390_302_858_158_119_052_90e-15,
        ),
        Precision::Single => (
            12582912.0,
            1.5703125,
            4.837_512_969_970_703_125e-4,
            7.549_789_954_891_882_16e-8,
        ),
    };
    // Nearest integer, for |y| well below 2⁵¹ (2²²).
    let round = |y: T| (y + k(magic)) - k(magic);
    let j = round(x * k(core::f64::consts::FRAC_2_PI));
    let r = ((x - j * k(p1)) - j * k(p2)) - j * k(p3);
    let z = r * r;
    let (sin, cos) = match precision {
        Precision::Double => {
            let ps = ((((k(1.589_623_015_765_465_680_60e-10) * z + k(-2.505_074_776_285_780_728_66e-8)) * z
                + k(2.755_731_362_138_572_452_13e-6))
                * z
                + k(-1.984_126_982_958_953_859_96e-4))
                * z
                + k(8.333_333_333_322_118_588_78e-3))
                * z
                + k(-1.666_666_666_666_663_072_95e-1);
            let pc = ((((k(-1.135_853_652_138_768_173_00e-11) * z + k(2.087_570_084_197_473_167_78e-9)) * z
                + k(-2.755_731_417_929_673_881_12e-7))
                * z
                + k(2.480_158_728_885_170_453_48e-5))
                * z
                + k(-1.388_888_888_887_305_641_16e-3))
                * z
                + k(4.166_666_666_666_659_292_18e-2);
            (r + r * z * ps, (k(1.0) - k(0.5) * z) + z * z * pc)
        }
        Precision::Single => {
            let ps = (k(-1.951_529_589_1e-4) * z + k(8.332_160_873_6e-3)) * z + k(-1.666_665_461_1e-1);
            let pc = (k(2.443_315_711_809_948e-5) * z + k(-1.388_731_625_493_765e-3)) * z + k(4.166_664_568_298_827e-2);
            (r + r * z * ps, (k(1.0) - k(0.5) * z) + z * z * pc)
        }
    };
    // The quadrant q = j mod 4 and its bits, exactly: floor(j/4) is the nearest
    // integer to j/4 − 3/8, floor(q/2) the nearest to q/2 − 1/4.
    let q = j - k(4.0) * round(j * k(0.25) - k(0.375));
    let high = round(q * k(0.5) - k(0.25)); // q ∈ {2, 3}
    let odd = q - k(2.0) * high; // q ∈ {1, 3}
    let h = round((q + k(1.0)) * k(0.5) - k(0.25)); // floor((q + 1)/2)
    let cos_negative = h - k(2.0) * round(h * k(0.5) - k(0.25)); // q ∈ {1, 2}
    let even = k(1.0) - odd;
    (
        (k(1.0) - k(2.0) * high) * (even * sin + odd * cos),
        (k(1.0) - k(2.0) * cos_negative) * (even * cos + odd * sin),
    )
}

macro_rules! impl_real {
    ($t:ident, $precision:expr) => {
        impl Real for $t {
            type Context = ();
            #[inline(always)]
            fn constant(_: (), x: f64) -> $t {
                x as $t
            }
            /// [`polynomial_sin_cos`] within its limit, the standard library's (or
            /// libm's) beyond it.
            #[inline(always)]
            fn sin_cos(self) -> ($t, $t) {
                let precision = $precision;
                if (if self < 0.0 { -self } else { self }) <= precision.limit() as $t {
                    polynomial_sin_cos((), self, precision)
                } else {
                    impl_real!(@exact $t, self)
                }
            }
        }
    };
    (@exact $t:ident, $x:expr) => {{
        #[cfg(feature = "std")]
        {
            $t::sin_cos($x)
        }
        #[cfg(all(not(feature = "std"), feature = "libm"))]
        {
            impl_real!(@libm $t, $x)
        }
        #[cfg(all(not(feature = "std"), not(feature = "libm")))]
        {
            compile_error!("dyngen-algo needs the `std` or the `libm` feature for sin and cos")
        }
    }};
    (@libm f64, $x:expr) => {
        (libm::sin($x), libm::cos($x))
    };
    (@libm f32, $x:expr) => {
        (libm::sinf($x), libm::cosf($x))
    };
}

impl_real!(f64, Precision::Double);
impl_real!(f32, Precision::Single);
