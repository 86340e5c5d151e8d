//! The derivatives of the dynamics, as the generated `rnea_derivatives` and
//! `aba_derivatives` write them (Pinocchio's `computeRNEADerivatives` and
//! `computeABADerivatives`), and the linearisation of one semi-implicit Euler step
//! built from them, for model-predictive control and trajectory optimisation.

use crate::Scalar;

/// `∂τ/∂q`, `∂τ/∂v` and `∂τ/∂a = M(q)` of inverse dynamics `τ = rnea(q, v, a)`,
/// N × N each, row `i` the derivatives of `τ_i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RneaDerivatives<S: Scalar, const N: usize> {
    pub dtau_dq: [[S; N]; N],
    pub dtau_dv: [[S; N]; N],
    /// The joint-space inertia matrix.
    pub dtau_da: [[S; N]; N],
}

impl<S: Scalar, const N: usize> Default for RneaDerivatives<S, N> {
    fn default() -> Self {
        RneaDerivatives {
            dtau_dq: [[S::ZERO; N]; N],
            dtau_dv: [[S::ZERO; N]; N],
            dtau_da: [[S::ZERO; N]; N],
        }
    }
}

/// Forward dynamics `q̈ = aba(q, v, τ)` and its derivatives: `∂q̈/∂q = −M⁻¹ ∂τ/∂q`,
/// `∂q̈/∂v = −M⁻¹ ∂τ/∂v` (at `a = q̈`) and `∂q̈/∂τ = M⁻¹`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AbaDerivatives<S: Scalar, const N: usize> {
    /// The joint accelerations `aba(q, v, τ)`.
    pub ddq: [S; N],
    pub ddq_dq: [[S; N]; N],
    pub ddq_dv: [[S; N]; N],
    /// `M(q)⁻¹ = ∂q̈/∂τ`, symmetric.
    pub minv: [[S; N]; N],
}

impl<S: Scalar, const N: usize> Default for AbaDerivatives<S, N> {
    fn default() -> Self {
        AbaDerivatives {
            ddq: [S::ZERO; N],
            ddq_dq: [[S::ZERO; N]; N],
            ddq_dv: [[S::ZERO; N]; N],
            minv: [[S::ZERO; N]; N],
        }
    }
}

/// One step of the discrete dynamics `x⁺ = f(x, u)` with state `x = (q, v)` and input
/// `u = τ`, linearised: `δx⁺ = A δx + B δu`. `A` (2N × 2N) and `B` (2N × N) are held as
/// N × N blocks, rows of `q⁺` first: `A = [[a_qq, a_qv], [a_vq, a_vv]]`,
/// `B = [[b_q], [b_v]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearization<S: Scalar, const N: usize> {
    /// The state after the step.
    pub q_next: [S; N],
    pub v_next: [S; N],
    pub a_qq: [[S; N]; N],
    pub a_qv: [[S; N]; N],
    pub a_vq: [[S; N]; N],
    pub a_vv: [[S; N]; N],
    pub b_q: [[S; N]; N],
    pub b_v: [[S; N]; N],
}

impl<S: Scalar, const N: usize> Default for Linearization<S, N> {
    fn default() -> Self {
        let zero = [[S::ZERO; N]; N];
        Linearization {
            q_next: [S::ZERO; N],
            v_next: [S::ZERO; N],
            a_qq: zero,
            a_qv: zero,
            a_vq: zero,
            a_vv: zero,
            b_q: zero,
            b_v: zero,
        }
    }
}

impl<S: Scalar, const N: usize> Linearization<S, N> {
    /// Entry `(r, c)` of `A` (2N × 2N); `None` outside it.
    pub fn a(&self, r: usize, c: usize) -> Option<S> {
        let block = match (r < N, c < N) {
            _ if r >= 2 * N || c >= 2 * N => return None,
            (true, true) => &self.a_qq,
            (true, false) => &self.a_qv,
            (false, true) => &self.a_vq,
            (false, false) => &self.a_vv,
        };
        Some(block[r % N][c % N])
    }

    /// Entry `(r, c)` of `B` (2N × N); `None` outside it.
    pub fn b(&self, r: usize, c: usize) -> Option<S> {
        if r >= 2 * N || c >= N {
            return None;
        }
        Some(if r < N { self.b_q[r][c] } else { self.b_v[r - N][c] })
    }
}

/// Support for generated code: `ddq ← M⁻¹ (tau − h)` with the `M⁻¹` already in
/// `d.minv` (`h` the nonlinear effects; `tau` the joint torques, friction taken off).
#[doc(hidden)]
#[inline]
pub fn __accelerations<S: Scalar, const N: usize>(d: &mut AbaDerivatives<S, N>, tau: &[S; N], h: &[S; N]) {
    let mut b = [S::ZERO; N];
    for j in 0..N {
        b[j] = tau[j] - h[j];
    }
    for i in 0..N {
        let mut s = S::ZERO;
        for j in 0..N {
            s += d.minv[i][j] * b[j];
        }
        d.ddq[i] = s;
    }
}

/// Support for generated code: `ddq_dq ← −M⁻¹ dq`, `ddq_dv ← −M⁻¹ dv`, `dq` and `dv`
/// the inverse-dynamics derivatives `∂τ/∂q`, `∂τ/∂v` taken at `a = ddq` (loops: small
/// code, vectorised).
#[doc(hidden)]
#[inline]
pub fn __times_minus_minv<S: Scalar, const N: usize>(d: &mut AbaDerivatives<S, N>, dq: &[[S; N]; N], dv: &[[S; N]; N]) {
    for i in 0..N {
        let row = &d.minv[i];
        let (mut sq, mut sv) = ([S::ZERO; N], [S::ZERO; N]);
        for k in 0..N {
            let m = row[k];
            for c in 0..N {
                sq[c] += m * dq[k][c];
                sv[c] += m * dv[k][c];
            }
        }
        for c in 0..N {
            d.ddq_dq[i][c] = -sq[c];
            d.ddq_dv[i][c] = -sv[c];
        }
    }
}

/// Support for generated code: [`__times_minus_minv`] when column `c` of `∂τ/∂q` and
/// `∂τ/∂v` can be nonzero only in the rows `support[c]` (the coordinates of joints on
/// one path with `c`'s; the others are structural zeros of the tree): `Σ_c |support[c]|
/// · N` multiply-adds per matrix instead of `N³`. `M⁻¹` is symmetric, so its row `k`
/// serves as its column.
#[doc(hidden)]
#[inline]
pub fn __times_minus_minv_sparse<S: Scalar, const N: usize>(
    d: &mut AbaDerivatives<S, N>,
    dq: &[[S; N]; N],
    dv: &[[S; N]; N],
    support: &[&[usize]; N],
) {
    for c in 0..N {
        let (mut sq, mut sv) = ([S::ZERO; N], [S::ZERO; N]);
        for &k in support[c] {
            let (x, y) = (dq[k][c], dv[k][c]);
            let row = &d.minv[k];
            for i in 0..N {
                sq[i] += row[i] * x;
                sv[i] += row[i] * y;
            }
        }
        for i in 0..N {
            d.ddq_dq[i][c] = -sq[i];
            d.ddq_dv[i][c] = -sv[i];
        }
    }
}

impl<S: Scalar, const N: usize> AbaDerivatives<S, N> {
    /// The semi-implicit (symplectic) Euler step `v⁺ = v + dt·q̈(q, v, τ)`,
    /// `q⁺ = q + dt·v⁺` from the state `(q, v)` these derivatives were taken at,
    /// linearised:
    ///
    /// ```text
    /// A = [[E + dt²·∂q̈/∂q, dt·(E + dt·∂q̈/∂v)],     B = [[dt²·M⁻¹],
    ///      [dt·∂q̈/∂q,      E + dt·∂q̈/∂v     ]],         [dt·M⁻¹ ]]
    /// ```
    ///
    /// (`q ⊕ dt·v` is `q + dt·v` here, which holds when every joint coordinate is an
    /// angle or a displacement. With a free flyer or a ball joint `q` has more
    /// coordinates than `v` and does not fit `[S; N]`. A planar joint's `[x, y, θ]`
    /// fits but is not stepped by `q + dt·v` (its velocity is in the child frame), so
    /// `q_next` is wrong for it. For all three, step the configuration with
    /// [`crate::configuration::integrate`]; the derivatives are then with respect to
    /// the tangent of the configuration, as Pinocchio's.)
    pub fn semi_implicit_euler(&self, q: &[S; N], v: &[S; N], dt: S) -> Linearization<S, N> {
        let mut l = Linearization::default();
        for i in 0..N {
            l.v_next[i] = v[i] + dt * self.ddq[i];
            l.q_next[i] = q[i] + dt * l.v_next[i];
            for j in 0..N {
                let e = if i == j { S::ONE } else { S::ZERO };
                l.a_vq[i][j] = dt * self.ddq_dq[i][j];
                l.a_vv[i][j] = e + dt * self.ddq_dv[i][j];
                l.a_qq[i][j] = e + dt * l.a_vq[i][j];
                l.a_qv[i][j] = dt * l.a_vv[i][j];
                l.b_v[i][j] = dt * self.minv[i][j];
                l.b_q[i][j] = dt * l.b_v[i][j];
            }
        }
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit mass on a spring and damper, `q̈ = τ − k q − c v`: the step's Jacobians
    /// against the closed form.
    #[test]
    fn euler_step_of_a_damped_spring() {
        let (k, c, dt) = (4.0, 0.5, 0.01);
        let (q, v, tau) = ([0.3], [-0.2], [1.5]);
        let d = AbaDerivatives::<f64, 1> {
            ddq: [tau[0] - k * q[0] - c * v[0]],
            ddq_dq: [[-k]],
            ddq_dv: [[-c]],
            minv: [[1.0]],
        };
        let l = d.semi_implicit_euler(&q, &v, dt);
        let v1 = v[0] + dt * d.ddq[0];
        assert_eq!(l.v_next, [v1]);
        assert_eq!(l.q_next, [q[0] + dt * v1]);
        // x⁺ is affine here, so the Jacobians are exact: check them by differences.
        let step = |q: f64, v: f64, tau: f64| {
            let v1 = v + dt * (tau - k * q - c * v);
            [q + dt * v1, v1]
        };
        let base = step(q[0], v[0], tau[0]);
        let h = 1e-3;
        for (col, x) in [step(q[0] + h, v[0], tau[0]), step(q[0], v[0] + h, tau[0])]
            .iter()
            .enumerate()
        {
            for row in 0..2 {
                let fd = (x[row] - base[row]) / h;
                assert!((fd - l.a(row, col).unwrap()).abs() < 1e-9, "A[{row}][{col}]");
            }
        }
        let x = step(q[0], v[0], tau[0] + h);
        for row in 0..2 {
            assert!(
                ((x[row] - base[row]) / h - l.b(row, 0).unwrap()).abs() < 1e-9,
                "B[{row}]"
            );
        }
        assert_eq!(l.a(2, 0), None);
        assert_eq!(l.b(0, 1), None);
    }
}
