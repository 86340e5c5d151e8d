//! Inverse dynamics by the recursive Newton–Euler algorithm (Luh, Walker and Paul;
//! Featherstone, *Rigid Body Dynamics Algorithms*, Table 5.1), in body frames.

use crate::kinematics::{check_len, newton_euler_pass, placements};
use crate::mimic::{on_tree, Reduce};
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::spatial::Inertia;
use crate::Real;
use core::ops::Add;

/// `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)` into `tau`, for the standard parameters `params`
/// ([`PARAMS_PER_BODY`] per body):
///
/// ```text
/// base to tip:  ω_i, ω̇_i, a_i of the Newton–Euler pass     (a_0 = −g)
///               f_i = m_i a_i + ω̇_i × h_i + ω_i × (ω_i × h_i)
///               n_i = I_i ω̇_i + ω_i × (I_i ω_i) + h_i × a_i
/// tip to base:  τ_i = S_iᵀ [f_i; n_i],   [f; n]_λ(i) += λ(i)X_i* [f_i; n_i]
/// ```
///
/// Leaves `workspace.force`: the wrench each joint transmits to its body, in the
/// body's frame (Pinocchio's `data.f`).
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn rnea<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    params: &[S],
    tau: &mut [S],
) {
    if multibody.reduction.is_some() {
        let tree =
            |w: &mut Workspace<S>, [q, v, a]: [&[S]; 3], out: &mut [S]| rnea_tree(multibody, w, q, v, a, params, out);
        return on_tree(
            multibody,
            workspace,
            [Some(q), Some(v), Some(a)],
            Reduce::Rows(1, tau),
            tree,
        );
    }
    rnea_tree(multibody, workspace, q, v, a, params, tau);
}

fn rnea_tree<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    params: &[S],
    tau: &mut [S],
) {
    let nv = multibody.tree_nv();
    check_len("v", v, nv);
    check_len("a", a, nv);
    check_len("tau", tau, nv);
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    placements(multibody, workspace, q);
    newton_euler_pass(multibody, workspace, v, a);
    let c = workspace.context;
    for k in 0..multibody.bodies() {
        let i = k + 1;
        let inertia = Inertia::from_params(&params[PARAMS_PER_BODY * k..PARAMS_PER_BODY * i]);
        workspace.force[i] = inertia.newton_euler(
            workspace.angular_velocity[i],
            workspace.angular_acceleration[i],
            workspace.linear_acceleration[i],
        );
    }
    for (k, j) in multibody.joints.iter().enumerate().rev() {
        let i = k + 1;
        let f = workspace.force[i];
        j.project(c, &f, &mut tau[j.v_offset..j.v_offset + j.nv()]);
        if j.parent != 0 {
            workspace.force[j.parent] = workspace.force[j.parent].add(workspace.placement[i].force_to_parent(f));
        }
    }
}
