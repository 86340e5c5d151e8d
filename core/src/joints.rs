//! Joint models beyond rigid bodies, as the generated `*_joints` functions take them:
//! rotor inertia and friction, 4 parameters per joint in joint order,
//! `[Ia, Fv, Fc, F0]`, after the `10n` standard parameters:
//!
//! ```text
//! τ_j = rnea_j(q, q̇, q̈) + Ia_j·q̈_j + Fv_j·q̇_j + Fc_j·c(q̇_j) + F0_j
//! ```
//!
//! `Ia` is the rotor inertia reflected to the joint (Pinocchio's `armature`), `Fv`
//! viscous and `Fc` Coulomb friction, `F0` an offset; `c` is `sign` or `tanh(q̇/ε)`
//! ([`Coulomb`]).
//!
//! ```
//! use dyngen::{Coulomb, JointParams};
//! let p = JointParams::<f64>::from_array([0.2, 1.5, 3.0, -0.1]); // Ia, Fv, Fc, F0
//! let tau = p.torque(0.5, 2.0, Coulomb::Sign);
//! assert!((tau - (0.2 * 2.0 + 1.5 * 0.5 + 3.0 - 0.1)).abs() < 1e-12);
//! let row = JointParams::regressor_row(0.5, 2.0, Coulomb::Sign);
//! assert_eq!(row, [2.0, 0.5, 1.0, 1.0]);
//! ```

use crate::{OrderedScalar, Scalar};

/// Joint parameters per joint: `[Ia, Fv, Fc, F0]`.
pub const JOINT_PARAMS_PER_JOINT: usize = 4;

/// How the Coulomb friction depends on the joint velocity `q̇`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Coulomb<S> {
    /// `sign(q̇)`, 0 at exactly zero velocity.
    #[default]
    Sign,
    /// `tanh(q̇/ε)`: the same away from rest, continuous through it. Build it with
    /// [`Coulomb::smooth`], which rejects an `ε` that is not positive and finite; a
    /// `Smooth` whose `ε` is not positive evaluates as its limit `ε → 0⁺`, the sign.
    Smooth { epsilon: S },
}

/// A smoothing `ε` of [`Coulomb::Smooth`] that is not a positive finite number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InvalidEpsilon(pub f64);

impl core::fmt::Display for InvalidEpsilon {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "Coulomb smoothing epsilon {} is not a positive finite velocity",
            self.0
        )
    }
}

impl<S: OrderedScalar> Coulomb<S> {
    /// `Coulomb::Smooth { epsilon }`, or an error naming `epsilon` when it is not
    /// positive and finite.
    pub fn smooth(epsilon: S) -> Result<Coulomb<S>, InvalidEpsilon> {
        if epsilon.is_finite() && epsilon > S::ZERO {
            Ok(Coulomb::Smooth { epsilon })
        } else {
            Err(InvalidEpsilon(epsilon.to_f64()))
        }
    }
}

impl<S: Scalar> Coulomb<S> {
    /// `c'(q̇)`, the slope of the model: 0 for `sign` (away from `q̇ = 0`),
    /// `(1 − tanh²(q̇/ε)) / ε` for the smooth model (0 where `ε` is not positive).
    #[inline]
    pub fn slope(self, v: S) -> S {
        match self {
            Coulomb::Smooth { epsilon } => {
                let t = (v / epsilon).tanh();
                epsilon.select_positive((S::ONE - t * t) / epsilon, S::ZERO)
            }
            Coulomb::Sign => S::ZERO,
        }
    }

    /// `c(q̇)`: `sign(q̇)` (NaN for NaN) or `tanh(q̇/ε)` (`sign` where `ε` is not
    /// positive).
    #[inline]
    pub fn eval(self, v: S) -> S {
        match self {
            Coulomb::Smooth { epsilon } => epsilon.select_positive((v / epsilon).tanh(), v.sign()),
            Coulomb::Sign => v.sign(),
        }
    }
}

/// One joint's parameters beyond the rigid bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointParams<S> {
    /// `Ia`: rotor inertia reflected to the joint, kg·m² (or kg): `τ += Ia·q̈`.
    pub armature: S,
    /// `Fv`: viscous friction, N·m·s/rad (or N·s/m): `τ += Fv·q̇`.
    pub viscous: S,
    /// `Fc`: Coulomb friction, N·m (or N): `τ += Fc·c(q̇)`.
    pub coulomb: S,
    /// `F0`: a constant offset, N·m (or N).
    pub offset: S,
}

impl<S: Scalar> JointParams<S> {
    /// From `[Ia, Fv, Fc, F0]`.
    #[inline]
    pub fn from_array(p: [S; JOINT_PARAMS_PER_JOINT]) -> JointParams<S> {
        let [armature, viscous, coulomb, offset] = p;
        JointParams {
            armature,
            viscous,
            coulomb,
            offset,
        }
    }

    /// `[Ia, Fv, Fc, F0]`.
    #[inline]
    pub fn to_array(self) -> [S; JOINT_PARAMS_PER_JOINT] {
        [self.armature, self.viscous, self.coulomb, self.offset]
    }

    /// Joint `j`'s (0-based) parameters in a vector of `4n`, `None` when it is too short.
    #[inline]
    pub fn of(joint_params: &[S], j: usize) -> Option<JointParams<S>> {
        let p = joint_params.get(JOINT_PARAMS_PER_JOINT * j..JOINT_PARAMS_PER_JOINT * (j + 1))?;
        Some(JointParams::from_array([p[0], p[1], p[2], p[3]]))
    }

    /// The friction torque `Fv·q̇ + Fc·c(q̇) + F0`.
    #[inline]
    pub fn friction(&self, v: S, coulomb: Coulomb<S>) -> S {
        self.viscous * v + self.coulomb * coulomb.eval(v) + self.offset
    }

    /// `∂/∂q̇` of the friction torque: `Fv + Fc·c'(q̇)`.
    #[inline]
    pub fn friction_slope(&self, v: S, coulomb: Coulomb<S>) -> S {
        self.viscous + self.coulomb * coulomb.slope(v)
    }

    /// The whole joint torque `Ia·q̈ + Fv·q̇ + Fc·c(q̇) + F0`.
    #[inline]
    pub fn torque(&self, v: S, a: S, coulomb: Coulomb<S>) -> S {
        self.armature * a + self.friction(v, coulomb)
    }

    /// The regressor entries of `[Ia, Fv, Fc, F0]`: `[q̈, q̇, c(q̇), 1]`, so that
    /// `regressor_row(v, a, c) · p.to_array() == p.torque(v, a, c)`.
    #[inline]
    pub fn regressor_row(v: S, a: S, coulomb: Coulomb<S>) -> [S; JOINT_PARAMS_PER_JOINT] {
        [a, v, coulomb.eval(v), S::ONE]
    }
}

/// Support for generated code: solves `H x = b` in place (`b` becomes `x`) for a
/// joint-space inertia matrix `H` (symmetric positive definite; its lower triangle is
/// read and overwritten) whose entry `(k, i)` can be nonzero only when coordinate `i`
/// supports coordinate `k` in the tree of coordinates: `ancestors[k]` lists `k`'s
/// ancestors, parent first, so that the ancestors of `ancestors[k][m]` are
/// `ancestors[k][m + 1..]`. Featherstone's `LᵀDL` factorisation (RBDA §6.5), which has
/// no fill-in on such a matrix, then the two triangular solves; the lists spare the
/// walk up the tree one dependent load at a time. A zero pivot gives infinities or
/// NaN, as a division by zero does.
#[doc(hidden)]
#[inline]
pub fn __tree_ldl_solve<S: Scalar, const N: usize>(ancestors: &[&[usize]; N], h: &mut [[S; N]; N], b: &mut [S; N]) {
    for k in (0..N).rev() {
        let up = ancestors[k];
        let inv = S::ONE / h[k][k];
        for (m, &i) in up.iter().enumerate() {
            let a = h[k][i] * inv;
            h[i][i] -= a * h[k][i];
            for &j in &up[m + 1..] {
                h[i][j] -= a * h[k][j];
            }
            h[k][i] = a;
        }
    }
    // Lᵀ y = b, leaves first.
    for i in (0..N).rev() {
        let x = b[i];
        for &j in ancestors[i] {
            b[j] -= h[i][j] * x;
        }
    }
    for i in 0..N {
        b[i] = b[i] / h[i][i];
    }
    // L x = D⁻¹ y, root first.
    for i in 0..N {
        let mut x = b[i];
        for &j in ancestors[i] {
            x -= h[i][j] * b[j];
        }
        b[i] = x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coulomb_sign_and_smooth() {
        assert_eq!(Coulomb::Sign.eval(-1e-300), -1.0);
        assert_eq!(Coulomb::Sign.eval(0.0), 0.0);
        assert_eq!(Coulomb::<f64>::Sign.eval(2.0), 1.0);
        let smooth = Coulomb::smooth(0.01).unwrap();
        assert!((smooth.eval(0.005) - 0.5f64.tanh()).abs() < 1e-15);
        assert!((smooth.eval(-0.2) + 1.0).abs() < 1e-15);
        assert_eq!(Coulomb::smooth(0.01f32).unwrap().eval(0.0), 0.0);
    }

    #[test]
    fn a_bad_epsilon_is_an_error_and_never_a_nan() {
        for e in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            let err = Coulomb::smooth(e).unwrap_err();
            let mut s = std::string::String::new();
            core::fmt::write(&mut s, format_args!("{err}")).unwrap();
            assert!(s.contains("epsilon"), "{s}");
        }
        // Built by hand: the ε → 0⁺ limit, not 0/0.
        assert_eq!(Coulomb::Smooth { epsilon: 0.0 }.eval(0.0), 0.0);
        assert_eq!(Coulomb::Smooth { epsilon: 0.0 }.eval(-3.0), -1.0);
    }

    #[test]
    fn torque_is_the_regressor_row_times_the_parameters() {
        let p = JointParams::from_array([0.2, 1.5, 3.0, -0.1]);
        for c in [Coulomb::Sign, Coulomb::Smooth { epsilon: 0.3 }] {
            for (v, a) in [(0.5, 2.0), (-0.1, 0.3), (0.0, -1.0)] {
                let row = JointParams::regressor_row(v, a, c);
                let y: f64 = row.iter().zip(p.to_array()).map(|(r, p)| r * p).sum();
                assert!((y - p.torque(v, a, c)).abs() < 1e-15);
            }
        }
        assert_eq!(
            JointParams::of(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], 1),
            Some(JointParams::from_array([5.0, 6.0, 7.0, 8.0]))
        );
        assert_eq!(JointParams::<f64>::of(&[1.0; 7], 1), None);
    }

    /// A branched tree of five coordinates (0 ← 1 ← 2, 0 ← 3 ← 4): `H` with the
    /// tree's sparsity, built as `Lᵀ D L` from a known factor, and `b = H x`.
    #[test]
    fn tree_ldl_solve_inverts_a_tree_sparse_matrix() {
        let ancestors: [&[usize]; 5] = [&[], &[0], &[1, 0], &[0], &[3, 0]];
        let ancestor = |k: usize, i: usize| ancestors[k].contains(&i);
        let d = [2.0, 1.5, 0.7, 3.0, 0.9];
        let mut l = [[0.0; 5]; 5];
        for k in 0..5 {
            l[k][k] = 1.0;
            for i in 0..k {
                if ancestor(k, i) {
                    l[k][i] = 0.3 * (k as f64) - 0.2 * (i as f64) + 0.1;
                }
            }
        }
        let mut h = [[0.0; 5]; 5];
        for r in 0..5 {
            for c in 0..5 {
                h[r][c] = (0..5).map(|m| l[m][r] * d[m] * l[m][c]).sum();
            }
        }
        // The sparsity: coordinates 2 and 4 are on different branches.
        assert_eq!(h[4][2], 0.0);
        let x = [0.5, -1.0, 2.0, 0.25, -0.75];
        let mut b: [f64; 5] = core::array::from_fn(|r| (0..5).map(|c| h[r][c] * x[c]).sum());
        __tree_ldl_solve(&ancestors, &mut h, &mut b);
        for (got, want) in b.iter().zip(x) {
            assert!((got - want).abs() < 1e-14, "{b:?}");
        }
    }
}
