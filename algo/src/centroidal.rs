//! The centre of mass, its Jacobian and the centroidal momentum matrix (Orin, Goswami
//! and Lee, "Centroidal dynamics of a humanoid robot", 2013; Pinocchio's
//! `centerOfMass`, `jacobianCenterOfMass` and `ccrba`), from the bodies'
//! inertias in the base frame summed over subtrees.

use crate::dual::DualWorkspace;
use crate::kinematics::check_len;
use crate::mimic::{on_tree, Reduce};
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::spatial::{cross, scale, sub, Force, Inertia, Vec3};
use crate::Real;

/// After [`crate::forward_kinematics`]: every body's inertia in the base frame, summed
/// over its subtree, into `workspace.inertia` (body 0: the whole robot).
fn subtree_inertias<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, params: &[S]) {
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    let z = workspace.zero();
    workspace.inertia[0] = Inertia::zero(z);
    for i in 1..=multibody.bodies() {
        let p = &params[PARAMS_PER_BODY * (i - 1)..PARAMS_PER_BODY * i];
        workspace.inertia[i] = Inertia::from_params(p).act(&workspace.world[i]);
    }
    for (k, j) in multibody.joints.iter().enumerate().rev() {
        let i = k + 1;
        workspace.inertia[j.parent] = workspace.inertia[j.parent].add(&workspace.inertia[i]);
    }
}

/// The centre of mass of the moving bodies in the base frame, for the standard
/// parameters `params`. Leaves `workspace.world` valid. Not finite when the robot
/// has no mass.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn center_of_mass<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S], params: &[S]) -> Vec3<S> {
    crate::forward_kinematics(multibody, workspace, q);
    total_com(multibody, workspace, params)
}

/// After [`crate::forward_kinematics`]: the centre of mass ([`subtree_inertias`] on the way).
fn total_com<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, params: &[S]) -> Vec3<S> {
    subtree_inertias(multibody, workspace, params);
    let total = workspace.inertia[0];
    scale(S::constant(workspace.context, 1.0) / total.mass, total.first_moment)
}

/// Calls `column(d, momentum)` for every velocity coordinate `d`: the spatial
/// momentum (base frame, about its origin) of the subtree its joint moves, moving with
/// the joint's column `S_d` (the momentum per unit `v_d`). Needs [`subtree_inertias`].
fn for_each_column<S: Real>(multibody: &Multibody, workspace: &Workspace<S>, mut column: impl FnMut(usize, Force<S>)) {
    let c = workspace.context;
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        for e in 0..j.nv() {
            let motion = workspace.world[i].act_motion(j.column(c, e));
            column(j.v_offset + e, workspace.inertia[i].apply(motion));
        }
    }
}

/// The Jacobian of the centre of mass (3 × nv row-major, base axes), so that its
/// velocity is `J_com v`; returns the centre of mass. Pinocchio's
/// `jacobianCenterOfMass`.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn com_jacobian<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    params: &[S],
    jacobian: &mut [S],
) -> Vec3<S> {
    check_len("jacobian", jacobian, 3 * multibody.nv());
    crate::forward_kinematics(multibody, workspace, q);
    let com = total_com(multibody, workspace, params);
    match multibody.reduction {
        Some(_) => {
            let tree = |w: &mut Workspace<S>, _: [&[S]; 3], out: &mut [S]| com_jacobian_tree(multibody, w, out);
            on_tree(multibody, workspace, [None; 3], Reduce::Cols(3, jacobian), tree)
        }
        None => com_jacobian_tree(multibody, workspace, jacobian),
    }
    com
}

/// After [`total_com`]: [`com_jacobian`] along the tree's coordinates.
fn com_jacobian_tree<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, jacobian: &mut [S]) {
    let nv = multibody.tree_nv();
    let inverse_mass = S::constant(workspace.context, 1.0) / workspace.inertia[0].mass;
    for_each_column(multibody, workspace, |d, momentum| {
        for r in 0..3 {
            jacobian[r * nv + d] = momentum.linear[r] * inverse_mass;
        }
    });
}

/// The centroidal momentum matrix `A_g` (6 × nv row-major, rows `[linear; angular]`,
/// the angular momentum about the centre of mass, base axes), so that the
/// centroidal momentum is `h_g = A_g v`; returns the centre of mass. Pinocchio's
/// `ccrba` (`data.Ag`).
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn centroidal_map<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    params: &[S],
    a_g: &mut [S],
) -> Vec3<S> {
    check_len("a_g", a_g, 6 * multibody.nv());
    crate::forward_kinematics(multibody, workspace, q);
    let com = total_com(multibody, workspace, params);
    match multibody.reduction {
        Some(_) => {
            let tree = |w: &mut Workspace<S>, _: [&[S]; 3], out: &mut [S]| centroidal_map_tree(multibody, w, com, out);
            on_tree(multibody, workspace, [None; 3], Reduce::Cols(6, a_g), tree)
        }
        None => centroidal_map_tree(multibody, workspace, com, a_g),
    }
    com
}

/// After [`total_com`]: [`centroidal_map`] along the tree's coordinates.
fn centroidal_map_tree<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, com: Vec3<S>, a_g: &mut [S]) {
    let nv = multibody.tree_nv();
    for_each_column(multibody, workspace, |d, f| {
        // The moment about the centre of mass: n − c × f.
        let n = sub(f.angular, cross(com, f.linear));
        for r in 0..3 {
            a_g[r * nv + d] = f.linear[r];
            a_g[(r + 3) * nv + d] = n[r];
        }
    });
}

/// `A_g(q)` and its time variation `Ȧ_g(q, v) = d/dt A_g(q(t))` along `q̇ = v` (each
/// 6 × nv row-major), so that `ḣ_g = A_g a + Ȧ_g v`. Pinocchio's `dccrba` gives
/// another matrix with the same product with `v` (its angular rows leave out
/// `ċ × A_lin`, whose product with `v` is `ċ × m ċ = 0`).
/// [`centroidal_map`] run on [`crate::Dual`] numbers, one direction.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn centroidal_map_time_variation<S: Real>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, 1>,
    q: &[S],
    v: &[S],
    params: &[S],
    a_g: &mut [S],
    a_g_dot: &mut [S],
) {
    let nv = multibody.nv();
    check_len("q", q, multibody.nq());
    check_len("v", v, nv);
    check_len("a_g", a_g, 6 * nv);
    check_len("a_g_dot", a_g_dot, 6 * nv);
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    dual.set_params(params);
    dual.seed_configuration(multibody, q, |_, d| v[d], |_| true);
    let DualWorkspace {
        workspace,
        q,
        params,
        out,
        ..
    } = dual;
    centroidal_map(multibody, workspace, q, params, out);
    for ((x, xd), d) in a_g.iter_mut().zip(a_g_dot.iter_mut()).zip(out.iter()) {
        *x = d.value;
        *xd = d.tangent[0];
    }
}
