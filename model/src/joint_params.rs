//! Joint parameters beyond rigid bodies: rotor inertia and friction, 4 per joint in
//! joint order after the `10n` standard parameters, `[Ia, Fv, Fc, F0]`:
//!
//! ```text
//! τ_j += Ia_j·q̈_j + Fv_j·q̇_j + Fc_j·s(q̇_j) + F0_j
//! ```
//!
//! `Ia` is the rotor inertia reflected to the joint (Pinocchio's `armature`), `Fv`
//! viscous and `Fc` Coulomb friction, `F0` an offset (a sensor bias, or the mean of an
//! asymmetric friction). `s` is `sign`, or `tanh(q̇/ε)` where a smooth model is wanted
//! ([`Coulomb`]). Each term acts on its own joint only, so the columns of joint `j`
//! are non-zero in row `j` alone.
//!
//! ```
//! use dyngen_model::joint_params::{joint_regressor_row, joint_torque, Coulomb};
//! let p = [0.2, 1.5, 3.0, -0.1]; // Ia, Fv, Fc, F0
//! let row = joint_regressor_row(0.5, 2.0, Coulomb::Sign);
//! let tau: f64 = row.iter().zip(&p).map(|(y, p)| y * p).sum();
//! assert_eq!(tau, joint_torque(&p, 0.5, 2.0, Coulomb::Sign));
//! assert_eq!(tau, 0.2 * 2.0 + 1.5 * 0.5 + 3.0 - 0.1);
//! ```

use crate::ir::Model;
use crate::names::param_name;

/// Joint parameters per joint.
pub const PER_JOINT: usize = 4;
/// Their names, in order.
pub const NAMES: [&str; PER_JOINT] = ["Ia", "Fv", "Fc", "F0"];

/// How the Coulomb term depends on the joint velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coulomb {
    /// `sign(q̇)` (0 at exactly zero velocity).
    Sign,
    /// `tanh(q̇/ε)`: the same away from rest, continuous through it, for data where
    /// the joint reverses often and slowly.
    Smooth { epsilon: f64 },
}

impl Coulomb {
    /// `s(q̇)`.
    pub fn eval(self, v: f64) -> f64 {
        match self {
            Coulomb::Sign => {
                if v > 0.0 {
                    1.0
                } else if v < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
            Coulomb::Smooth { epsilon } => (v / epsilon).tanh(),
        }
    }
}

/// Names of the joint parameters of an `n`-joint model: `Ia1, Fv1, Fc1, F0_1, Ia2, …`
/// (an underscore before the joint number where the name ends in a digit, as
/// [`crate::names`] writes all parameter names).
pub fn joint_param_names(n: usize) -> Vec<String> {
    (1..=n)
        .flat_map(|j| NAMES.iter().map(move |s| param_name(s, j)))
        .collect()
}

/// The regressor entries of one joint's parameters `[Ia, Fv, Fc, F0]` at joint
/// velocity `v` and acceleration `a`: `[a, v, s(v), 1]`.
pub fn joint_regressor_row(v: f64, a: f64, coulomb: Coulomb) -> [f64; PER_JOINT] {
    [a, v, coulomb.eval(v), 1.0]
}

/// One joint's torque from its parameters `p = [Ia, Fv, Fc, F0]`.
pub fn joint_torque(p: &[f64; PER_JOINT], v: f64, a: f64, coulomb: Coulomb) -> f64 {
    let r = joint_regressor_row(v, a, coulomb);
    r.iter().zip(p).map(|(y, p)| y * p).sum()
}

/// The description's nominal joint parameters, 4 per velocity coordinate (`4 nv`;
/// one coordinate per joint with an axis, 3 per ball joint, 6 per free flyer): rotor
/// inertia from [`JointDynamics::armature`](crate::ir::JointDynamics) (MJCF
/// `armature`; 0 from a URDF), viscous and Coulomb friction from `<dynamics damping
/// friction>` (MJCF `damping frictionloss`), offset 0, the same on each coordinate of
/// a joint. A joint that follows another (`<mimic>`, multiplier `k`) adds its own to
/// its leader's as their virtual work does: `k² Ia`, `k² Fv`, `|k| Fc`.
pub fn nominal_joint_params(model: &Model) -> Vec<f64> {
    let mut p: Vec<f64> = model
        .joints
        .iter()
        .filter(|j| j.mimic.is_none())
        .flat_map(|j| {
            std::iter::repeat_n(
                [j.dynamics.armature, j.dynamics.damping, j.dynamics.friction, 0.0],
                j.kind.nv(),
            )
        })
        .flatten()
        .collect();
    for j in &model.joints {
        if let Some(m) = j.mimic {
            let (d, k) = (model.v_offset(m.leader), m.multiplier);
            let leader = &mut p[PER_JOINT * d..PER_JOINT * (d + 1)];
            leader[0] += k * k * j.dynamics.armature;
            leader[1] += k * k * j.dynamics.damping;
            leader[2] += k.abs() * j.dynamics.friction;
        }
    }
    p
}

/// Appends the joint-parameter columns to a torque regressor given as rows (`n` rows
/// of `p` entries): row `j` gains `4n` entries, non-zero only at `4j..4j + 4`.
pub fn append_joint_columns(rows: &mut [Vec<f64>], v: &[f64], a: &[f64], coulomb: Coulomb) {
    let n = rows.len();
    for (j, row) in rows.iter_mut().enumerate() {
        let start = row.len();
        row.resize(start + PER_JOINT * n, 0.0);
        row[start + PER_JOINT * j..start + PER_JOINT * (j + 1)]
            .copy_from_slice(&joint_regressor_row(v[j], a[j], coulomb));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_one_format() {
        assert_eq!(
            joint_param_names(2),
            ["Ia1", "Fv1", "Fc1", "F0_1", "Ia2", "Fv2", "Fc2", "F0_2"]
        );
    }

    #[test]
    fn smooth_coulomb_tends_to_sign_away_from_rest() {
        let smooth = Coulomb::Smooth { epsilon: 0.01 };
        assert!((smooth.eval(0.2) - 1.0).abs() < 1e-15);
        assert!((smooth.eval(-0.2) + 1.0).abs() < 1e-15);
        assert_eq!(smooth.eval(0.0), 0.0);
        assert!((smooth.eval(0.005) - 0.5f64.tanh()).abs() < 1e-15);
        assert_eq!(Coulomb::Sign.eval(-1e-300), -1.0);
        assert_eq!(Coulomb::Sign.eval(0.0), 0.0);
    }

    #[test]
    fn appended_columns_sit_on_their_own_joint() {
        let mut rows = vec![vec![1.0; 3], vec![2.0; 3]];
        append_joint_columns(&mut rows, &[0.5, -2.0], &[3.0, 4.0], Coulomb::Sign);
        assert_eq!(rows[0], [1.0, 1.0, 1.0, 3.0, 0.5, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(rows[1], [2.0, 2.0, 2.0, 0.0, 0.0, 0.0, 0.0, 4.0, -2.0, -1.0, 1.0]);
    }
}
