//! The joint-space mass matrix by the composite rigid body algorithm
//! (Featherstone, *Rigid Body Dynamics Algorithms*, Table 6.2).

use crate::kinematics::{check_len, placements};
use crate::mimic::{on_tree, Reduce};
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::spatial::Inertia;
use crate::Real;

/// `M(q)` into `m` (`nv × nv`, row-major, both triangles): composite inertias
/// `I^c_λ(i) += λ(i)X_i* I^c_i ⁱX_λ(i)` from tip to base, then for each coordinate
/// `d` of joint `i`, `F = I^c_i S_d` carried towards the base, `M_{d'd} = S_d'ᵀ F`
/// for every coordinate `d'` on the way.
///
/// # Panics
/// If a slice's length does not match the multibody.
pub fn crba<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S], params: &[S], m: &mut [S]) {
    if multibody.reduction.is_some() {
        check_len("m", m, multibody.nv() * multibody.nv());
        let tree = |w: &mut Workspace<S>, [q, _, _]: [&[S]; 3], out: &mut [S]| crba_tree(multibody, w, q, params, out);
        return on_tree(multibody, workspace, [Some(q), None, None], Reduce::Both(m), tree);
    }
    crba_tree(multibody, workspace, q, params, m);
}

fn crba_tree<S: Real>(multibody: &Multibody, workspace: &mut Workspace<S>, q: &[S], params: &[S], m: &mut [S]) {
    let nv = multibody.tree_nv();
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    check_len("m", m, nv * nv);
    placements(multibody, workspace, q);
    let c = workspace.context;
    for (k, _) in multibody.joints.iter().enumerate() {
        workspace.inertia[k + 1] = Inertia::from_params(&params[PARAMS_PER_BODY * k..PARAMS_PER_BODY * (k + 1)]);
    }
    for (k, j) in multibody.joints.iter().enumerate().rev() {
        if j.parent != 0 {
            let moved = workspace.placement[k + 1].inertia_to_parent(&workspace.inertia[k + 1]);
            workspace.inertia[j.parent] = workspace.inertia[j.parent].add(&moved);
        }
    }
    m.fill(workspace.zero());
    let mut column = [workspace.zero(); 6];
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        for e in 0..j.nv() {
            let d = j.v_offset + e;
            let mut f = j.inertia_column(c, &workspace.inertia[i], e);
            let (mut body, mut joint) = (i, j);
            loop {
                let rows = joint.nv();
                joint.project(c, &f, &mut column[..rows]);
                for (r, &x) in column[..rows].iter().enumerate() {
                    let dr = joint.v_offset + r;
                    m[dr * nv + d] = x;
                    m[d * nv + dr] = x;
                }
                if joint.parent == 0 {
                    break;
                }
                f = workspace.placement[body].force_to_parent(f);
                body = joint.parent;
                joint = &multibody.joints[body - 1];
            }
        }
    }
}
