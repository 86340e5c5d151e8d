//! Frame Jacobians, as Pinocchio's `getFrameJacobian`.

use crate::kinematics::check_len;
use crate::multibody::{Multibody, Workspace};
use crate::spatial::{add, cross, Motion, Se3};
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
            for (r, x) in column.to_array().into_iter().enumerate() {
                jacobian[r * nv + d] = x;
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
    check_len("q", q, multibody.nq());
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
