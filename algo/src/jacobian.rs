//! Frames: their Jacobians (Pinocchio's `getFrameJacobian`), velocities, classical
//! accelerations and the Jacobians' time variation.

use crate::dual::{Dual, DualWorkspace};
use crate::kinematics::check_len;
use crate::mimic::{on_tree, times, Reduce};
use crate::multibody::{Multibody, Workspace};
use crate::spatial::{add, cross, mat_tr_vec, mat_vec, neg, Motion, Se3, Vec3};
use crate::Real;

/// In which frame a velocity or a Jacobian is expressed (Pinocchio's
/// `ReferenceFrame`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReferenceFrame {
    /// The base frame, about its origin.
    World,
    /// The frame itself.
    Local,
    /// The frame's origin, with the base frame's axes.
    LocalWorldAligned,
}

/// The Jacobian of the frame `frame` rigidly attached to body `body` (its placement
/// in the body) into `jacobian`, 6 × nv row-major (`jacobian[r · nv + d]`, rows
/// `[linear; angular]`), so that the frame's spatial velocity is `J q̇` in
/// `reference`. Reads `workspace.world`: call [`crate::forward_kinematics`] first.
///
/// # Panics
/// If `body` is not a body of the multibody (0 is the base, whose Jacobian is
/// zero) or `jacobian` is not `6 nv` long.
pub fn frame_jacobian<S: Real>(
    multibody: &Multibody,
    workspace: &Workspace<S>,
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
    jacobian: &mut [S],
) {
    let nv = multibody.nv();
    check_len("jacobian", jacobian, 6 * nv);
    assert!(body <= multibody.bodies(), "body {body} is not a body of the multibody");
    let c = workspace.context;
    jacobian.fill(workspace.zero());
    let offset: Se3<S> = crate::joint::constant_se3(c, frame);
    let placement = workspace.world[body].compose(&offset);
    let reduction = multibody.reduction.as_deref();
    let mut i = body;
    while i != 0 {
        let j = &multibody.joints[i - 1];
        for e in 0..j.nv() {
            let world = workspace.world[i].act_motion(j.column(c, e));
            let column: Motion<S> = match reference {
                ReferenceFrame::World => world,
                ReferenceFrame::LocalWorldAligned => Motion {
                    linear: add(world.linear, cross(world.angular, placement.translation)),
                    angular: world.angular,
                },
                ReferenceFrame::Local => placement.inv_act_motion(world),
            };
            let d = j.v_offset + e;
            match reduction {
                None => {
                    for (r, x) in column.to_array().into_iter().enumerate() {
                        jacobian[r * nv + d] = x;
                    }
                }
                // A follower's column adds to its leader's, scaled (`J_tree E`).
                Some(reduction) => {
                    let (k, a) = reduction.v[d];
                    for (r, x) in column.to_array().into_iter().enumerate() {
                        jacobian[r * nv + k] = jacobian[r * nv + k] + times(c, x, a);
                    }
                }
            }
        }
        i = j.parent;
    }
}

/// [`frame_jacobian`] from `q` alone: the placements of the bodies on the path from
/// `body` to the base only (Pinocchio's `computeFrameJacobian`), then the Jacobian.
/// Leaves `workspace.world` valid on that path.
///
/// # Panics
/// As [`frame_jacobian`], or if `q` is not `nq` long.
pub fn compute_frame_jacobian<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
    jacobian: &mut [S],
) {
    if multibody.reduction.is_some() {
        let tree = |w: &mut Workspace<S>, [q, _, _]: [&[S]; 3], _: &mut [S]| {
            compute_frame_jacobian_tree(multibody, w, q, body, frame, reference, jacobian)
        };
        return on_tree(multibody, workspace, [Some(q), None, None], Reduce::None, tree);
    }
    compute_frame_jacobian_tree(multibody, workspace, q, body, frame, reference, jacobian);
}

fn compute_frame_jacobian_tree<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
    jacobian: &mut [S],
) {
    check_len("q", q, multibody.tree_nq());
    assert!(body <= multibody.bodies(), "body {body} is not a body of the multibody");
    let c = workspace.context;
    let (z, o) = (workspace.zero(), S::constant(c, 1.0));
    // The path, tip first, then placed from the base out.
    let mut len = 0;
    let mut i = body;
    while i != 0 {
        workspace.path[len] = i;
        len += 1;
        i = multibody.joints[i - 1].parent;
    }
    for k in (0..len).rev() {
        let i = workspace.path[k];
        let j = &multibody.joints[i - 1];
        let local = j.placement(c, &q[j.q_offset..j.q_offset + j.nq()]);
        workspace.placement[i] = local;
        workspace.world[i] = if j.parent == 0 {
            local.se3(z, o)
        } else {
            workspace.world[j.parent].compose(&local.se3(z, o))
        };
    }
    frame_jacobian(multibody, workspace, body, frame, reference, jacobian);
}

/// The spatial velocity of the frame `frame` rigidly attached to body `body` (its
/// placement in the body) in `reference`: Pinocchio's `getFrameVelocity`. Reads
/// `workspace.world` and `workspace.velocity`: call [`crate::body_motions`] first.
///
/// # Panics
/// If `body` is not a body of the multibody.
pub fn frame_velocity<S: Real>(
    multibody: &Multibody,
    workspace: &Workspace<S>,
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
) -> Motion<S> {
    assert!(body <= multibody.bodies(), "body {body} is not a body of the multibody");
    let offset: Se3<S> = crate::joint::constant_se3(workspace.context, frame);
    let local = offset.inv_act_motion(workspace.velocity[body]);
    let placement = workspace.world[body].compose(&offset);
    match reference {
        ReferenceFrame::Local => local,
        ReferenceFrame::World => placement.act_motion(local),
        ReferenceFrame::LocalWorldAligned => Motion {
            linear: mat_vec(&placement.rotation, local.linear),
            angular: mat_vec(&placement.rotation, local.angular),
        },
    }
}

/// The frame's Jacobian `J(q)` and its time variation `J̇(q, v) = d/dt J(q(t))` along
/// `q̇ = v` (each 6 × nv row-major) in `reference`: Pinocchio's
/// `getFrameJacobianTimeVariation`. [`frame_jacobian`] run on [`Dual`] numbers, one
/// direction.
///
/// # Panics
/// As [`compute_frame_jacobian`], or if a slice's length does not match the
/// multibody.
#[allow(clippy::too_many_arguments)]
pub fn frame_jacobian_time_variation<S: Real>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, 1>,
    q: &[S],
    v: &[S],
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
    jacobian: &mut [S],
    jacobian_dot: &mut [S],
) {
    let nv = multibody.nv();
    check_len("q", q, multibody.nq());
    check_len("v", v, nv);
    check_len("jacobian", jacobian, 6 * nv);
    check_len("jacobian_dot", jacobian_dot, 6 * nv);
    dual.seed_configuration(multibody, q, |_, d| v[d], |_| true);
    let DualWorkspace { workspace, q, out, .. } = dual;
    compute_frame_jacobian(multibody, workspace, q, body, frame, reference, out);
    for ((j, jd), x) in jacobian.iter_mut().zip(jacobian_dot.iter_mut()).zip(out.iter()) {
        *j = x.value;
        *jd = x.tangent[0];
    }
}

/// The frame's classical acceleration at `(q, v, a)` in `reference` (Pinocchio's
/// `getFrameClassicalAcceleration`, its spatial acceleration plus `[ω × v; 0]`):
/// in `LocalWorldAligned` the second derivative of the frame's origin and the
/// derivative of its angular velocity, in world axes; in `Local` the same in the
/// frame's axes; in `World` those of the body-fixed point at the world origin. With
/// `a = 0` it is the drift `J̇ v` of `LocalWorldAligned`. The frame's velocity in
/// `LocalWorldAligned` differentiated along the motion on [`Dual`] numbers.
///
/// # Panics
/// If `body` is not a body of the multibody or a slice's length does not match it.
#[allow(clippy::too_many_arguments)]
pub fn frame_classical_acceleration<S: Real>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, 1>,
    q: &[S],
    v: &[S],
    a: &[S],
    body: usize,
    frame: &Se3<f64>,
    reference: ReferenceFrame,
) -> Motion<S> {
    let nv = multibody.nv();
    check_len("q", q, multibody.nq());
    check_len("v", v, nv);
    check_len("a", a, nv);
    assert!(body <= multibody.bodies(), "body {body} is not a body of the multibody");
    dual.seed_configuration(multibody, q, |_, d| v[d], |_| true);
    let z = dual.zero();
    for i in 0..nv {
        dual.v[i] = Dual::variable(v[i], [a[i]]);
        dual.a[i] = Dual::constant_of(z, z);
    }
    let DualWorkspace { workspace, q, v, a, .. } = dual;
    crate::body_motions(multibody, workspace, q, v, a);
    let velocity = frame_velocity(multibody, workspace, body, frame, ReferenceFrame::LocalWorldAligned);
    let placement = workspace.world[body].compose(&crate::joint::constant_se3(workspace.context, frame));
    let (value, tangent) = (
        |x: Vec3<Dual<S, 1>>| x.map(|x| x.value),
        |x: Vec3<Dual<S, 1>>| x.map(|x| x.tangent[0]),
    );
    let (acc, alpha, w) = (
        tangent(velocity.linear),
        tangent(velocity.angular),
        value(velocity.angular),
    );
    let rotation = placement.rotation.map(value);
    match reference {
        ReferenceFrame::LocalWorldAligned => Motion {
            linear: acc,
            angular: alpha,
        },
        ReferenceFrame::Local => Motion {
            linear: mat_tr_vec(&rotation, acc),
            angular: mat_tr_vec(&rotation, alpha),
        },
        ReferenceFrame::World => {
            // The body-fixed point at the origin, at r = −p from the frame's origin:
            // a + α × r + ω × (ω × r).
            let r = neg(value(placement.translation));
            Motion {
                linear: add(add(acc, cross(alpha, r)), cross(w, cross(w, r))),
                angular: alpha,
            }
        }
    }
}
