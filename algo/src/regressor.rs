//! The joint torque regressor, as Pinocchio's `computeJointTorqueRegressor`:
//! `τ = Y(q, q̇, q̈) π`, linear in the standard parameters of every body.

use crate::kinematics::{check_len, newton_euler_pass, placements};
use crate::mimic::{on_tree, Reduce};
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::spatial::{add, cross, Force, Vec3};
use crate::Real;

/// The Newton–Euler wrench of a body ([`crate::Inertia::newton_euler`]) as a linear
/// function of its parameters `π = [m, h, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]` (`h = m c`,
/// `I` about the origin), for its angular velocity `w`, angular acceleration `dw` and
/// origin acceleration `ac`: column `k` is the wrench for `π = e_k`,
///
/// ```text
/// m:  [a; 0]      h:  [ω̇ × h + ω × (ω × h); h × a]      I:  [0; I ω̇ + ω × (I ω)]
/// ```
pub fn force_regressor<S: Real>(
    context: S::Context,
    w: Vec3<S>,
    dw: Vec3<S>,
    ac: Vec3<S>,
) -> [Force<S>; PARAMS_PER_BODY] {
    let z = S::constant(context, 0.0);
    let o = S::constant(context, 1.0);
    let mut out = [Force::zero(z); PARAMS_PER_BODY];
    out[0].linear = ac;
    for k in 0..3 {
        let mut h = [z; 3];
        h[k] = o;
        out[1 + k] = Force {
            linear: add(cross(dw, h), cross(w, cross(w, h))),
            angular: cross(h, ac),
        };
    }
    // [xx, xy, yy, xz, yz, zz]: the symmetric unit B = e_r e_cᵀ + e_c e_rᵀ (r ≠ c).
    for (k, (r, c)) in [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)].into_iter().enumerate() {
        let unit = |x: [S; 3]| {
            let mut y = [z; 3];
            y[r] = x[c];
            if r != c {
                y[c] = x[r];
            }
            y
        };
        out[4 + k] = Force {
            linear: [z; 3],
            angular: add(unit(dw), cross(w, unit(w))),
        };
    }
    out
}

/// `Y(q, q̇, q̈)` into `y`, `nv × 10 n` row-major (`y[d · 10n + 10(i − 1) + k]`), zero
/// unless coordinate `d` moves body `i`. With `ⁱX_d S_d` the motion subspace of
/// coordinate `d` seen from body `i` (carried outwards one joint at a time,
/// `ⁱX_d S_d = ⁱX_λ(i) · λ(i)X_d S_d`) and `F_i` body `i`'s [`force_regressor`],
/// `Y_{d, i} = (ⁱX_d S_d)ᵀ F_i`: one motion transform and ten dot products per
/// (coordinate, body) pair. Gravity enters as the base acceleration `−g`, so
/// `Y π = rnea(q, q̇, q̈, π)`.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn joint_torque_regressor<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    y: &mut [S],
) {
    if multibody.reduction.is_some() {
        check_len("y", y, multibody.nv() * PARAMS_PER_BODY * multibody.bodies());
        let tree = |w: &mut Workspace<S>, [q, v, a]: [&[S]; 3], out: &mut [S]| {
            joint_torque_regressor_tree(multibody, w, q, v, a, out)
        };
        let rows = Reduce::Rows(PARAMS_PER_BODY * multibody.bodies(), y);
        return on_tree(multibody, workspace, [Some(q), Some(v), Some(a)], rows, tree);
    }
    joint_torque_regressor_tree(multibody, workspace, q, v, a, y);
}

fn joint_torque_regressor_tree<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    y: &mut [S],
) {
    let (nv, nb) = (multibody.tree_nv(), multibody.bodies());
    check_len("v", v, nv);
    check_len("a", a, nv);
    check_len("y", y, nv * PARAMS_PER_BODY * nb);
    placements(multibody, workspace, q);
    newton_euler_pass(multibody, workspace, v, a);
    let c = workspace.context;
    y.fill(workspace.zero());
    let cols = PARAMS_PER_BODY * nb;
    let offsets = &multibody.support_offsets;
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let x = workspace.placement[i];
        let (from, inherited) = (offsets[i], offsets[j.parent + 1] - offsets[j.parent]);
        for t in 0..inherited {
            workspace.axes[from + t] = x.motion_to_child(workspace.axes[offsets[j.parent] + t]);
        }
        for e in 0..j.nv() {
            workspace.axes[from + inherited + e] = j.column(c, e);
        }
        let forces = force_regressor(
            c,
            workspace.angular_velocity[i],
            workspace.angular_acceleration[i],
            workspace.linear_acceleration[i],
        );
        for t in from..offsets[i + 1] {
            let (d, axis) = (multibody.supports[t], workspace.axes[t]);
            let row = &mut y[d * cols + PARAMS_PER_BODY * k..][..PARAMS_PER_BODY];
            for (x, f) in row.iter_mut().zip(&forces) {
                *x = axis.dot(*f);
            }
        }
    }
}

/// The joint wrench regressor `W(q, q̇, q̈)` into `w`, `6 n × 10 n` row-major
/// (`w[(6(j − 1) + r) · 10n + 10(i − 1) + k]`): block `(j, i)` is `ʲX_i* F_i`, body
/// `i`'s [`force_regressor`] moved into joint `j`'s frame, for every joint `j` that
/// supports body `i`, zero elsewhere. `W π` is every joint's wrench on its body
/// (rnea's `workspace.force`); `Y` is its projection on the motion subspaces.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn joint_wrench_regressor<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    w: &mut [S],
) {
    if multibody.reduction.is_some() {
        let tree = |ws: &mut Workspace<S>, [q, v, a]: [&[S]; 3], _: &mut [S]| {
            joint_wrench_regressor_tree(multibody, ws, q, v, a, w)
        };
        return on_tree(multibody, workspace, [Some(q), Some(v), Some(a)], Reduce::None, tree);
    }
    joint_wrench_regressor_tree(multibody, workspace, q, v, a, w);
}

fn joint_wrench_regressor_tree<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    w: &mut [S],
) {
    let (nv, nb) = (multibody.tree_nv(), multibody.bodies());
    check_len("v", v, nv);
    check_len("a", a, nv);
    check_len("w", w, 6 * nb * PARAMS_PER_BODY * nb);
    placements(multibody, workspace, q);
    newton_euler_pass(multibody, workspace, v, a);
    let c = workspace.context;
    w.fill(workspace.zero());
    let cols = PARAMS_PER_BODY * nb;
    for k in 0..nb {
        let i = k + 1;
        let mut forces = force_regressor(
            c,
            workspace.angular_velocity[i],
            workspace.angular_acceleration[i],
            workspace.linear_acceleration[i],
        );
        let mut body = i;
        loop {
            for (p, f) in forces.iter().enumerate() {
                for (r, x) in f.to_array().into_iter().enumerate() {
                    w[(6 * (body - 1) + r) * cols + PARAMS_PER_BODY * k + p] = x;
                }
            }
            let parent = multibody.joints[body - 1].parent;
            if parent == 0 {
                break;
            }
            let x = workspace.placement[body];
            for f in forces.iter_mut() {
                *f = x.force_to_parent(*f);
            }
            body = parent;
        }
    }
}
