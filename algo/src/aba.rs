//! Forward dynamics by the articulated body algorithm (Featherstone, *Rigid Body
//! Dynamics Algorithms*, Table 7.1), for joints of any number of coordinates.

use crate::kinematics::{check_len, placements};
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::spatial::{Force, Inertia, Motion};
use crate::Real;
use core::ops::Add;

/// `D⁻¹` of a symmetric positive definite `n × n` matrix (row-major in `d`), by
/// Gauss–Jordan elimination without pivoting (the same operations for every value,
/// so a symbolic scalar records one program). A singular `D` gives non-finite
/// entries, as the division by zero it is.
fn invert<S: Real>(d: &[S; 36], n: usize, zero: S, one: S) -> [S; 36] {
    if n == 1 {
        let mut out = [zero; 36];
        out[0] = one / d[0];
        return out;
    }
    let mut a = *d;
    let mut inv = [zero; 36];
    for r in 0..n {
        inv[r * 6 + r] = one;
    }
    for p in 0..n {
        let pivot = one / a[p * 6 + p];
        for c in 0..n {
            a[p * 6 + c] = a[p * 6 + c] * pivot;
            inv[p * 6 + c] = inv[p * 6 + c] * pivot;
        }
        for r in 0..n {
            if r != p {
                let factor = a[r * 6 + p];
                for c in 0..n {
                    a[r * 6 + c] = a[r * 6 + c] - factor * a[p * 6 + c];
                    inv[r * 6 + c] = inv[r * 6 + c] - factor * inv[p * 6 + c];
                }
            }
        }
    }
    // Row-major with stride n, as the caller reads it.
    let mut out = [zero; 36];
    for r in 0..n {
        for c in 0..n {
            out[r * n + c] = inv[r * 6 + c];
        }
    }
    out
}

/// `q̈ = M(q)⁻¹ (τ − C(q, q̇) q̇ − g(q))` into `qdd`, in `O(n)`:
///
/// ```text
/// base to tip:  v_i = ⁱX_λ(i) v_λ(i) + S_i q̇_i,   c_i = v_i × S_i q̇_i
///               I^A_i = I_i,   p^A_i = v_i ×* I_i v_i
/// tip to base:  U_i = I^A_i S_i,   D_i = S_iᵀ U_i,   u_i = τ_i − S_iᵀ p^A_i
///               I^a = I^A_i − U_i D_i⁻¹ U_iᵀ,   p^a = p^A_i + I^a c_i + U_i D_i⁻¹ u_i
///               I^A_λ(i) += λ(i)X_i* I^a ⁱX_λ(i),   p^A_λ(i) += λ(i)X_i* p^a
/// base to tip:  a'_i = ⁱX_λ(i) a_λ(i) + c_i                   (a_0 = −g)
///               q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i),   a_i = a'_i + S_i q̈_i
/// ```
///
/// `armature` (one per velocity coordinate, or empty for none) adds the rotor
/// inertia `Ia` to `D_i`'s diagonal, as Pinocchio's `model.armature` and MuJoCo's
/// joint `armature`. Where `M(q)` is singular (a massless tip) the result is not
/// finite; check it (`f64::is_finite`) before use.
///
/// # Panics
/// If a slice's length does not match the multibody.
#[allow(clippy::too_many_arguments)]
pub fn aba<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    tau: &[S],
    params: &[S],
    armature: &[S],
    qdd: &mut [S],
) {
    if multibody.reduction.is_some() {
        return aba_with_mimics(multibody, workspace, q, v, tau, params, armature, qdd);
    }
    let nv = multibody.nv();
    check_len("v", v, nv);
    check_len("tau", tau, nv);
    check_len("qdd", qdd, nv);
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    if !armature.is_empty() {
        check_len("armature", armature, nv);
    }
    placements(multibody, workspace, q);
    let c = workspace.context;
    let (z, one) = (workspace.zero(), S::constant(c, 1.0));
    workspace.velocity[0] = Motion::zero(z);
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let x = workspace.placement[i];
        let vj = j.motion(c, &v[j.v_offset..j.v_offset + j.nv()]);
        let vel = if j.parent == 0 {
            vj
        } else {
            x.motion_to_child(workspace.velocity[j.parent]).add(vj)
        };
        let inertia = Inertia::from_params(&params[PARAMS_PER_BODY * k..PARAMS_PER_BODY * i]);
        workspace.velocity[i] = vel;
        workspace.bias_acceleration[i] = vel.cross_motion(vj);
        workspace.articulated[i] = inertia.to_matrix(z);
        workspace.bias_force[i] = vel.cross_force(inertia.apply(vel));
    }
    let mut d = [z; 36];
    let mut projected = [z; 6];
    for (k, j) in multibody.joints.iter().enumerate().rev() {
        let i = k + 1;
        let (n, off) = (j.nv(), j.v_offset);
        let ia = workspace.articulated[i];
        for e in 0..n {
            workspace.u[off + e] = j.apply_column(c, &ia, e);
        }
        for e in 0..n {
            j.project(c, &workspace.u[off + e], &mut projected[..n]);
            for r in 0..n {
                d[r * 6 + e] = projected[r];
            }
            if !armature.is_empty() {
                d[e * 6 + e] = d[e * 6 + e] + armature[off + e];
            }
        }
        let d_inv = invert(&d, n, z, one);
        j.project(c, &workspace.bias_force[i], &mut projected[..n]);
        for e in 0..n {
            workspace.u_torque[off + e] = tau[off + e] - projected[e];
        }
        workspace.d_inv[i] = d_inv;
        if j.parent != 0 {
            // W = U D⁻¹ (columns), I^a = I^A − W Uᵀ, p^a = p^A + I^a c + W u.
            let mut reduced = ia;
            let mut pa = workspace.bias_force[i];
            for e in 0..n {
                let mut w = Force::zero(z);
                for l in 0..n {
                    w = w.add(workspace.u[off + l].scale(d_inv[l * n + e]));
                }
                reduced = reduced.sub_outer(w, workspace.u[off + e]);
                pa = pa.add(w.scale(workspace.u_torque[off + e]));
            }
            let reduced = reduced.symmetrised();
            pa = pa.add(reduced.apply(workspace.bias_acceleration[i]));
            let x = workspace.placement[i];
            workspace.articulated[j.parent] = workspace.articulated[j.parent].add(&x.matrix_to_parent(&reduced));
            workspace.bias_force[j.parent] = workspace.bias_force[j.parent].add(x.force_to_parent(pa));
        }
    }
    workspace.acceleration[0] = Motion {
        linear: crate::joint::constant_vec(c, [-multibody.gravity[0], -multibody.gravity[1], -multibody.gravity[2]]),
        angular: [z; 3],
    };
    for (k, j) in multibody.joints.iter().enumerate() {
        let i = k + 1;
        let (n, off) = (j.nv(), j.v_offset);
        let a_prime = workspace.placement[i]
            .motion_to_child(workspace.acceleration[j.parent])
            .add(workspace.bias_acceleration[i]);
        let mut rhs = [z; 6];
        for e in 0..n {
            rhs[e] = workspace.u_torque[off + e] - a_prime.dot(workspace.u[off + e]);
        }
        let d_inv = &workspace.d_inv[i];
        for r in 0..n {
            let mut x = z;
            for e in 0..n {
                x = x + d_inv[r * n + e] * rhs[e];
            }
            qdd[off + r] = x;
        }
        workspace.acceleration[i] = a_prime.add(j.motion(c, &qdd[off..off + n]));
    }
}

/// [`aba`] for a multibody with [`crate::Mimic`] joints, where the articulated-body
/// recursion does not apply: `M + diag(Ia)` by [`crate::crba`] factored densely
/// (`Lᵀ D L`), `τ − h` by [`crate::rnea`] at `q̈ = 0`.
#[allow(clippy::too_many_arguments)]
fn aba_with_mimics<S: Real>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    tau: &[S],
    params: &[S],
    armature: &[S],
    qdd: &mut [S],
) {
    let nv = multibody.nv();
    check_len("tau", tau, nv);
    check_len("qdd", qdd, nv);
    if !armature.is_empty() {
        check_len("armature", armature, nv);
    }
    let mut matrix = core::mem::take(&mut workspace.mimic.matrix);
    let zero = core::mem::take(&mut workspace.mimic.zero);
    crate::crba(multibody, workspace, q, params, &mut matrix);
    for (d, &ia) in armature.iter().enumerate() {
        matrix[d * nv + d] = matrix[d * nv + d] + ia;
    }
    crate::rnea(multibody, workspace, q, v, &zero, params, qdd);
    for (x, &t) in qdd.iter_mut().zip(tau) {
        *x = t - *x;
    }
    crate::derivatives::ltdl(multibody, &mut matrix);
    crate::derivatives::ltdl_solve(multibody, &matrix, qdd, 1, 0);
    workspace.mimic.matrix = matrix;
    workspace.mimic.zero = zero;
}
