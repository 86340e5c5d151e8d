//! Regressors: the dynamics as linear functions of the inertial parameters.
//!
//! Each body's net spatial force is `f_i = A_i(v_i, a_i) π_i`
//! ([`force_regressor`]); joint `j` carries the forces of every body it supports,
//! `f_j = Σ_{i ⪰ j} ʲX*_i f_i`, so the regressors are the body regressors carried
//! towards the base, one block per (joint, body) pair with `T_ji ≠ 0`.

use super::spatial::{force_regressor, ForceRegressor, SpatialVector};
use super::Reference;
use dyngen_model::{Model, PrincipalFrame};
use nalgebra::{DMatrix, DVector};

impl Reference {
    /// The joint wrench regressor `W(q, v, a)` (`6n × 10n`): rows `6(j−1)..6j`
    /// give the wrench `[force; torque]` joint `j` applies to body `j` (moment about
    /// joint `j`'s origin, in frame `j`, exactly [`Reference::joint_wrenches`]) as a
    /// linear function of `params`, columns `10(i−1)..10i` body `i`'s parameters.
    ///
    /// ```text
    /// W_ji = ʲX*_i A_i(v_i, a_i)   if joint j supports body i (T_ji = 1), else 0
    /// ```
    ///
    /// with `A_i` the [`force_regressor`] of body `i`'s velocity and acceleration
    /// (gravity included as the base acceleration `−a_g`), and `ʲX*_i` the force
    /// transform from body `i` to frame `j`, built one joint at a time:
    /// `ᵏX*_i = X_jᵀ ʲX*_i` for `k = λ(j)`. Panics if a length differs.
    pub fn joint_wrench_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> DMatrix<f64> {
        let n = self.nq();
        let k = self.forward_pass(q, v, a, -self.gravity);
        let mut w = DMatrix::zeros(6 * n, 10 * n);
        for i in 1..=n {
            // Body i's own net force, then carried through joint i and every joint
            // on the path to the base.
            let mut block: ForceRegressor = force_regressor(&k.v[i], &k.a[i]);
            let mut j = i;
            loop {
                w.fixed_view_mut::<6, 10>(6 * (j - 1), 10 * (i - 1)).copy_from(&block);
                let parent = self.joints[j - 1].parent;
                if parent == 0 {
                    break;
                }
                block = k.x[j].transpose() * block;
                j = parent;
            }
        }
        w
    }

    /// The joint torque regressor `Y(q, v, a)` (`n × 10n`) with
    /// `rnea(q, v, a, π) = Y π`, in Pinocchio's parameter order (docs/design.md, "Conventions"):
    /// row `j` is the projection `S_jᵀ` of joint `j`'s rows of
    /// [`Reference::joint_wrench_regressor`]. Block `(j, i)` (row `j`, columns
    /// `10(i−1)..10i`) is zero unless joint `j` supports body `i`. Panics if a
    /// length differs.
    pub fn joint_torque_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> DMatrix<f64> {
        let n = self.nq();
        let mut y = vec![0.0; 10 * n * n];
        self.joint_torque_regressor_into(q, v, a, &mut y);
        DMatrix::from_row_slice(n, 10 * n, &y)
    }

    /// [`Reference::joint_torque_regressor`] written row-major into `y` (`n × 10n`),
    /// without the wrench regressor in between: with `ⁱX_j S_j` the axis of joint
    /// `j` seen from body `i` (column `j` of body `i`'s Jacobian in its own frame,
    /// carried outwards one joint at a time, `ⁱX_j S_j = X_i · ᵖX_j S_j` for
    /// `p = λ(i)`), `Y_ji = S_jᵀ ʲX*_i A_i = (ⁱX_j S_j)ᵀ A_i`: one 6-vector transform
    /// and ten 6-term dot products per (joint, body) pair instead of a 6 × 10 block
    /// product. The loop identification runs per sample. Panics if a length differs.
    pub fn joint_torque_regressor_into(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        let n = self.nq();
        self.check_len("y", y, 10 * n * n);
        let k = self.forward_pass(q, v, a, -self.gravity);
        y.fill(0.0);
        // axes[n·i + j − 1]: ⁱX_j S_j for joints j on body i's path (zero elsewhere).
        let mut axes = vec![SpatialVector::zeros(); n * (n + 1)];
        for i in 1..=n {
            let parent = self.joints[i - 1].parent;
            let mut j = parent;
            while j != 0 {
                axes[n * i + j - 1] = k.x[i] * axes[n * parent + j - 1];
                j = self.joints[j - 1].parent;
            }
            axes[n * i + i - 1] = self.joints[i - 1].subspace;
            let body: ForceRegressor = force_regressor(&k.v[i], &k.a[i]);
            let mut j = i;
            while j != 0 {
                let axis = &axes[n * i + j - 1];
                let row = &mut y[(j - 1) * 10 * n + 10 * (i - 1)..][..10];
                for (c, x) in row.iter_mut().enumerate() {
                    *x = axis.dot(&body.column(c));
                }
                j = self.joints[j - 1].parent;
            }
        }
    }

    /// The regressor in the principal parameters `θ_i = (m, J1, J2, J3)` (`n × 4n`):
    /// `Y(q, v, a) · blkdiag(P_i)`, so `rnea(q, v, a, blkdiag(P_i) θ) = Y_θ θ`, with
    /// `P_i` from the description's centre of mass and principal axes (see
    /// [`principal_matrix`]). Panics if a length differs.
    pub fn principal_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> DMatrix<f64> {
        self.joint_torque_regressor(q, v, a) * principal_matrix(&self.model)
    }
}

/// `blkdiag(P_1, …, P_n)` (`10n × 4n`), with `P_i` the constant 10 × 4 matrix of body
/// `i`'s [`PrincipalFrame`] (nominal centre of mass and principal axes): the
/// standard parameters of bodies with principal parameters `θ` are `π = blkdiag(P_i) θ`.
pub fn principal_matrix(model: &Model) -> DMatrix<f64> {
    let n = model.dof();
    let mut p = DMatrix::zeros(10 * n, 4 * n);
    for (i, body) in model.bodies.iter().enumerate() {
        let block = PrincipalFrame::of(&body.inertial).p_matrix();
        for r in 0..10 {
            for c in 0..4 {
                p[(10 * i + r, 4 * i + c)] = block[r][c];
            }
        }
    }
    p
}

/// The standard parameters (`10n`) of bodies with the description's centres of mass
/// and principal axes and principal parameters `theta = [m, J1, J2, J3]` per body
/// (`4n`): `π = blkdiag(P_i) θ`. Panics if `theta.len() != 4n`.
pub fn principal_params_to_standard(model: &Model, theta: &[f64]) -> Vec<f64> {
    let n = model.dof();
    assert_eq!(
        theta.len(),
        4 * n,
        "`theta` has length {}, the model needs {}",
        theta.len(),
        4 * n
    );
    (principal_matrix(model) * DVector::from_column_slice(theta))
        .iter()
        .copied()
        .collect()
}
