//! Forward-mode automatic differentiation: a number carrying `N` directional
//! derivatives, so that every algorithm of this crate, run on it, gives its
//! derivatives exactly (to rounding) along `N` directions per call.
//!
//! The derivatives of the dynamics ([`crate::rnea_derivatives`],
//! [`crate::aba_derivatives`]) and the time variations of Jacobians and of the
//! centroidal map are the algorithms themselves run on [`Dual`]: one implementation
//! of each algorithm, whatever is asked of it.

use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::Real;
use alloc::vec::Vec;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// `value + Σ_k tangent[k] ε_k` with `ε_j ε_k = 0`: a value and its derivatives
/// along `N` directions.
///
/// ```
/// use dyngen_algo::{Dual, Real};
/// // d/dx (x sin x) at x = 2: sin 2 + 2 cos 2.
/// let x = Dual::<f64, 1>::variable(2.0, [1.0]);
/// let y = x * x.sin_cos().0;
/// assert!((y.tangent[0] - (2f64.sin() + 2.0 * 2f64.cos())).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<S, const N: usize> {
    pub value: S,
    pub tangent: [S; N],
}

impl<S: Real, const N: usize> Dual<S, N> {
    /// A number with the derivatives `tangent`.
    pub fn variable(value: S, tangent: [S; N]) -> Self {
        Dual { value, tangent }
    }

    /// A number that does not vary (`zero` is the scalar's 0).
    pub fn constant_of(value: S, zero: S) -> Self {
        Dual {
            value,
            tangent: [zero; N],
        }
    }

    #[inline(always)]
    fn map2(self, o: Self, f: impl Fn(S, S) -> S) -> [S; N] {
        core::array::from_fn(|k| f(self.tangent[k], o.tangent[k]))
    }
}

impl<S: Real, const N: usize> Add for Dual<S, N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Dual {
            value: self.value + o.value,
            tangent: self.map2(o, |a, b| a + b),
        }
    }
}

impl<S: Real, const N: usize> Sub for Dual<S, N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Dual {
            value: self.value - o.value,
            tangent: self.map2(o, |a, b| a - b),
        }
    }
}

impl<S: Real, const N: usize> Mul for Dual<S, N> {
    type Output = Self;
    /// `(x y)' = x' y + x y'`.
    #[allow(clippy::suspicious_arithmetic_impl)]
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let (x, y) = (self.value, o.value);
        Dual {
            value: x * y,
            tangent: self.map2(o, |a, b| a * y + x * b),
        }
    }
}

impl<S: Real, const N: usize> Div for Dual<S, N> {
    type Output = Self;
    /// `(x/y)' = (x' − (x/y) y') / y`.
    #[allow(clippy::suspicious_arithmetic_impl)]
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let (y, q) = (o.value, self.value / o.value);
        Dual {
            value: q,
            tangent: self.map2(o, |a, b| (a - q * b) / y),
        }
    }
}

impl<S: Real, const N: usize> Neg for Dual<S, N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Dual {
            value: -self.value,
            tangent: self.tangent.map(|a| -a),
        }
    }
}

impl<S: Real, const N: usize> Real for Dual<S, N> {
    type Context = S::Context;

    #[inline(always)]
    fn constant(context: S::Context, x: f64) -> Self {
        Dual::constant_of(S::constant(context, x), S::constant(context, 0.0))
    }

    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.value.sin_cos();
        (
            Dual {
                value: s,
                tangent: self.tangent.map(|a| c * a),
            },
            Dual {
                value: c,
                tangent: self.tangent.map(|a| -(s * a)),
            },
        )
    }
}

/// What an algorithm run on [`Dual`] needs besides its [`Workspace`]: the inputs
/// seeded with their directions and the outputs, made once for a [`Multibody`] so
/// that no derivative allocates.
#[derive(Clone)]
pub struct DualWorkspace<S: Real, const N: usize> {
    pub workspace: Workspace<Dual<S, N>>,
    pub(crate) q: Vec<Dual<S, N>>,
    pub(crate) v: Vec<Dual<S, N>>,
    pub(crate) a: Vec<Dual<S, N>>,
    pub(crate) params: Vec<Dual<S, N>>,
    /// Room for a 6 × nv result.
    pub(crate) out: Vec<Dual<S, N>>,
    /// Room for an nv × nv matrix of `S` (the factor of `M` in the derivatives of aba).
    pub(crate) matrix: Vec<S>,
}

impl<S: Real, const N: usize> DualWorkspace<S, N> {
    pub fn new(multibody: &Multibody, context: S::Context) -> Self {
        let zero = Dual::constant(context, 0.0);
        let (nq, nv) = (multibody.nq(), multibody.nv());
        DualWorkspace {
            workspace: Workspace::new(multibody, context),
            q: alloc::vec![zero; nq],
            v: alloc::vec![zero; nv],
            a: alloc::vec![zero; nv],
            params: alloc::vec![zero; PARAMS_PER_BODY * multibody.bodies()],
            out: alloc::vec![zero; 6 * nv],
            matrix: alloc::vec![S::constant(context, 0.0); nv * nv],
        }
    }

    /// The scalar's zero.
    pub(crate) fn zero(&self) -> S {
        S::constant(self.workspace.context, 0.0)
    }

    /// `params` as constants.
    pub(crate) fn set_params(&mut self, params: &[S]) {
        let z = self.zero();
        for (d, &p) in self.params.iter_mut().zip(params) {
            *d = Dual::constant_of(p, z);
        }
    }

    /// `q` seeded so that its derivative along direction `k` is the motion `dv_k` in
    /// the tangent space: `d/dε (q ⊕ ε dv_k)` at `ε = 0`, `⊕` being Pinocchio's
    /// `integrate`. `direction(k)` gives `dv_k` one velocity coordinate at a time
    /// (`direction(k, d)`), `None` for a direction that does not move `q`.
    pub(crate) fn seed_configuration(
        &mut self,
        multibody: &Multibody,
        q: &[S],
        direction: impl Fn(usize, usize) -> S,
        moves: impl Fn(usize) -> bool,
    ) {
        let c = self.workspace.context;
        let z = self.zero();
        for (d, &x) in self.q.iter_mut().zip(q) {
            *d = Dual::constant_of(x, z);
        }
        let mut dv = [z; 6];
        let mut dq = [z; 7];
        for k in (0..N).filter(|&k| moves(k)) {
            for (n, j) in multibody.joints.iter().enumerate() {
                // A joint following another moves with its leader's coordinate.
                let Some((qo, vo)) = multibody.coordinates_of(n) else {
                    continue;
                };
                let (qs, vs) = (qo..qo + j.nq(), vo..vo + j.nv());
                for (e, d) in vs.clone().enumerate() {
                    dv[e] = direction(k, d);
                }
                j.integrate_tangent(c, &q[qs.clone()], &dv[..j.nv()], &mut dq[..j.nq()]);
                for (e, i) in qs.enumerate() {
                    self.q[i].tangent[k] = dq[e];
                }
            }
        }
    }
}
