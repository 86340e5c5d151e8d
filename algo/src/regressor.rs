//! The joint torque regressor, as Pinocchio's `computeJointTorqueRegressor`:
//! `τ = Y(q, q̇, q̈) π`, linear in the standard parameters of every body.

use crate::kinematics::{check_len, newton_euler_pass, placements};
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

/// `Y(q, q̇, q̈)` into `y`, `nv × 10 n` row-major (`y[d · 10n + 10(i − 1) + k]`): each
/// body's [`force_regressor`] carried towards the base, `Y_{d, i} = S_dᵀ ᵈX_i* F_i`
/// for every coordinate `d` on the path from body `i` to the base, zero elsewhere.
/// Gravity enters as the base acceleration `−g`, so `Y π = rnea(q, q̇, q̈, π)`.
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
    let (nv, nb) = (multibody.nv(), multibody.bodies());
    check_len("v", v, nv);
    check_len("a", a, nv);
    check_len("y", y, nv * PARAMS_PER_BODY * nb);
    placements(multibody, workspace, q);
    newton_euler_pass(multibody, workspace, v, a);
    let c = workspace.context;
    let z = workspace.zero();
    y.fill(z);
    let cols = PARAMS_PER_BODY * nb;
    let mut projected = [z; 6];
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let mut forces = force_regressor(
            c,
            workspace.angular_velocity[i],
            workspace.angular_acceleration[i],
            workspace.linear_acceleration[i],
        );
        let (mut body, mut joint) = (i, j);
        loop {
            let n = joint.nv();
            for (p, f) in forces.iter().enumerate() {
                joint.project(c, f, &mut projected[..n]);
                for (r, &x) in projected[..n].iter().enumerate() {
                    y[(joint.v_offset + r) * cols + PARAMS_PER_BODY * k + p] = x;
                }
            }
            if joint.parent == 0 {
                break;
            }
            let x = workspace.placement[body];
            for f in forces.iter_mut() {
                *f = x.force_to_parent(*f);
            }
            body = joint.parent;
            joint = &multibody.joints[body - 1];
        }
    }
}
