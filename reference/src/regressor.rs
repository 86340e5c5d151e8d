//! Regressors: the dynamics as linear functions of the inertial parameters.
//!
//! Each body's net spatial force is linear in its parameters
//! (`dyngen_algo::force_regressor`); joint `j` carries the forces of every body it
//! supports, `f_j = Σ_{i ⪰ j} ʲX*_i f_i`, so the regressors are the body regressors
//! carried towards the base, one block per (joint, body) pair with `T_ji ≠ 0`.

use super::Reference;
use dyngen_model::{Model, PrincipalFrame};
use nalgebra::{DMatrix, DVector};

impl Reference {
    /// The joint wrench regressor `W(q, v, a)` (`6n × 10n`): rows `6(j−1)..6j`
    /// give the wrench `[force; torque]` joint `j` applies to body `j` (moment about
    /// joint `j`'s origin, in frame `j`, exactly [`Reference::joint_wrenches`]) as a
    /// linear function of `params`, columns `10(i−1)..10i` body `i`'s parameters;
    /// block `(j, i)` is zero unless joint `j` supports body `i`
    /// (`dyngen_algo::joint_wrench_regressor`).
    pub fn joint_wrench_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> DMatrix<f64> {
        let n = self.bodies();
        let mut w = vec![0.0; 60 * n * n];
        self.with_workspace(|ws| dyngen_algo::joint_wrench_regressor(self.multibody(), ws, q, v, a, &mut w));
        DMatrix::from_row_slice(6 * n, 10 * n, &w)
    }

    /// The joint torque regressor `Y(q, v, a)` (`nv × 10n`) with
    /// `rnea(q, v, a, π) = Y π`, in Pinocchio's parameter order (docs/design.md,
    /// "Conventions"): the projection of [`Reference::joint_wrench_regressor`] on the
    /// motion subspaces. Block `(d, i)` is zero unless coordinate `d` moves body `i`.
    pub fn joint_torque_regressor(&self, q: &[f64], v: &[f64], a: &[f64]) -> DMatrix<f64> {
        let (nv, n) = (self.nv(), self.bodies());
        let mut y = vec![0.0; 10 * n * nv];
        self.joint_torque_regressor_into(q, v, a, &mut y);
        DMatrix::from_row_slice(nv, 10 * n, &y)
    }

    /// [`Reference::joint_torque_regressor`] written row-major into `y` (`nv × 10n`),
    /// by `dyngen_algo::joint_torque_regressor`: the loop identification runs per
    /// sample.
    pub fn joint_torque_regressor_into(&self, q: &[f64], v: &[f64], a: &[f64], y: &mut [f64]) {
        self.with_workspace(|ws| dyngen_algo::joint_torque_regressor(self.multibody(), ws, q, v, a, y));
    }

    /// The regressor in the principal parameters `θ_i = (m, J1, J2, J3)` (`nv × 4n`):
    /// `Y(q, v, a) · blkdiag(P_i)`, so `rnea(q, v, a, blkdiag(P_i) θ) = Y_θ θ`, with
    /// `P_i` from the description's centre of mass and principal axes (see
    /// [`principal_matrix`]).
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
