//! Forward kinematics: every body's placement, in its parent and in the base frame.

use crate::mimic::{on_tree, Reduce};
use crate::multibody::{Multibody, Workspace};
use crate::spatial::{add, cross, Motion};
use crate::Real;

/// Panics with a message naming `what` when `x` does not have `expected` entries.
#[track_caller]
pub(crate) fn check_len<S>(what: &str, x: &[S], expected: usize) {
    assert!(
        x.len() == expected,
        "`{what}` has {} entries; the model needs {expected}",
        x.len()
    );
}

/// `λ(i)M_i(q)` of every body into `workspace.placement`.
pub(crate) fn placements<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S]) {
    check_len("q", q, multibody.tree_nq());
    let c = workspace.context;
    for (i, j) in multibody.joints.iter().enumerate() {
        workspace.placement[i + 1] = j.placement(c, &q[j.q_offset..j.q_offset + j.nq()]);
    }
}

/// Every body's placement in its parent (`workspace.placement`) and in the base
/// frame (`workspace.world`, `⁰M_i = ⁰M_λ(i) · λ(i)M_i(q)`): Pinocchio's
/// `forwardKinematics(model, data, q)` (`data.liMi`, `data.oMi`).
pub fn forward_kinematics<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S]) {
    if multibody.reduction.is_some() {
        let tree = |w: &mut Workspace<S>, [q, _, _]: [&[S]; 3], _: &mut [S]| forward_kinematics_tree(multibody, w, q);
        return on_tree(multibody, workspace, [Some(q), None, None], Reduce::None, tree);
    }
    forward_kinematics_tree(multibody, workspace, q);
}

fn forward_kinematics_tree<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S]) {
    placements(multibody, workspace, q);
    let (z, o) = (workspace.zero(), S::constant(workspace.context, 1.0));
    for (i, j) in multibody.joints.iter().enumerate() {
        let local = workspace.placement[i + 1].se3(z, o);
        workspace.world[i + 1] = if j.parent == 0 {
            local
        } else {
            workspace.world[j.parent].compose(&local)
        };
    }
}

/// Every body's placement ([`forward_kinematics`]), spatial velocity
/// (`workspace.velocity`) and gravity-free spatial acceleration
/// (`workspace.acceleration`) in its own frame: Pinocchio's
/// `forwardKinematics(model, data, q, v, a)` (`data.v`, `data.a`),
///
/// ```text
/// v_i = ⁱX_λ(i) v_λ(i) + S_i q̇_i,   a_i = ⁱX_λ(i) a_λ(i) + S_i q̈_i + v_i × S_i q̇_i
/// ```
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn body_motions<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S], v: &[S], a: &[S]) {
    if multibody.reduction.is_some() {
        let tree = |w: &mut Workspace<S>, [q, v, a]: [&[S]; 3], _: &mut [S]| body_motions_tree(multibody, w, q, v, a);
        return on_tree(multibody, workspace, [Some(q), Some(v), Some(a)], Reduce::None, tree);
    }
    body_motions_tree(multibody, workspace, q, v, a);
}

fn body_motions_tree<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S], v: &[S], a: &[S]) {
    check_len("v", v, multibody.tree_nv());
    check_len("a", a, multibody.tree_nv());
    forward_kinematics_tree(multibody, workspace, q);
    let c = workspace.context;
    let z = workspace.zero();
    workspace.velocity[0] = Motion::zero(z);
    workspace.acceleration[0] = Motion::zero(z);
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let range = j.v_offset..j.v_offset + j.nv();
        let x = workspace.placement[i];
        let vj = j.motion(c, &v[range.clone()]);
        let vel = x.motion_to_child(workspace.velocity[j.parent]) + vj;
        workspace.acceleration[i] =
            x.motion_to_child(workspace.acceleration[j.parent]) + j.motion(c, &a[range]) + vel.cross_motion(vj);
        workspace.velocity[i] = vel;
    }
}

/// The Newton–Euler forward pass (Luh, Walker and Paul) at the velocities `v` and
/// accelerations `a`, after [`placements`]: in body `i`'s axes its angular velocity
/// `ω_i`, angular acceleration `ω̇_i` and the linear acceleration `a_i` of its origin,
/// gravity entering as `a_0 = −g`. With the joint's own motion `(ω_q, v_q) = S q̇` and
/// `(ω̇_q, a_q) = S q̈`, and `x_in` the parent's quantities in body `i`'s axes:
///
/// ```text
/// ω_i = ω_in + ω_q,   ω̇_i = ω̇_in + ω̇_q + ω_in × ω_q
/// a_i = Rᵀ (a_λ + ω̇_λ × p + ω_λ × (ω_λ × p)) + a_q + (2 ω_in + ω_q) × v_q
/// ```
pub(crate) fn newton_euler_pass<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, v: &[S], a: &[S]) {
    let c = workspace.context;
    let z = workspace.zero();
    workspace.angular_velocity[0] = [z; 3];
    workspace.angular_acceleration[0] = [z; 3];
    workspace.linear_acceleration[0] =
        crate::joint::constant_vec(c, [-multibody.gravity[0], -multibody.gravity[1], -multibody.gravity[2]]);
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let range = j.v_offset..j.v_offset + j.nv();
        let x = workspace.placement[i];
        let vq = j.motion(c, &v[range.clone()]);
        let aq = j.motion(c, &a[range]);
        let acc = workspace.linear_acceleration[j.parent];
        let (w, wd, acc) = if j.parent == 0 {
            // The base does not move: only gravity comes in.
            (vq.angular, aq.angular, add(x.to_child(acc), aq.linear))
        } else {
            let (w, wd) = (
                workspace.angular_velocity[j.parent],
                workspace.angular_acceleration[j.parent],
            );
            let t = x.translation;
            let origin = add(acc, add(cross(wd, t), cross(w, cross(w, t))));
            let (w_in, wd_in) = (x.to_child(w), x.to_child(wd));
            let wd = add(add(wd_in, aq.angular), cross(w_in, vq.angular));
            let acc = add(x.to_child(origin), aq.linear);
            let acc = if j.moves_linearly() {
                add(acc, cross(add(add(w_in, w_in), vq.angular), vq.linear))
            } else {
                acc
            };
            (add(w_in, vq.angular), wd, acc)
        };
        let acc = if j.parent == 0 && j.moves_linearly() {
            add(acc, cross(vq.angular, vq.linear))
        } else {
            acc
        };
        workspace.angular_velocity[i] = w;
        workspace.angular_acceleration[i] = wd;
        workspace.linear_acceleration[i] = acc;
    }
}
