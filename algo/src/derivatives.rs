//! The derivatives of inverse and forward dynamics (Pinocchio's
//! `computeRNEADerivatives` and `computeABADerivatives`): [`crate::rnea`] itself run
//! on [`Dual`] numbers, `N` directions per pass, and forward dynamics' through `M⁻¹`.
//!
//! Derivatives with respect to `q` are taken in the tangent space, as Pinocchio's:
//! column `d` of `∂τ/∂q` is `d/dε τ(q ⊕ ε e_d)` at `ε = 0`, so that a free flyer's or a
//! ball joint's columns are the derivatives along its angular velocity in its own
//! frame.

use crate::dual::{Dual, DualWorkspace};
use crate::kinematics::check_len;
use crate::multibody::{Multibody, Workspace, NO_PARENT, PARAMS_PER_BODY};
use crate::Real;

/// `∂τ/∂q`, `∂τ/∂v` (in the tangent space) and `∂τ/∂a = M(q)` of [`crate::rnea`] at
/// `(q, v, a)`, each `nv × nv` row-major (row `i` the derivatives of `τ_i`):
/// Pinocchio's `computeRNEADerivatives`. Runs rnea on [`Dual`] numbers `⌈2 nv / N⌉`
/// times, then [`crate::crba`] on `S` in `workspace`.
///
/// # Panics
/// If a slice's length does not match the multibody.
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives<S: Real, const N: usize>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, N>,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    params: &[S],
    dtau_dq: &mut [S],
    dtau_dv: &mut [S],
    dtau_da: &mut [S],
) {
    let nv = multibody.nv();
    check_len("q", q, multibody.nq());
    check_len("v", v, nv);
    check_len("a", a, nv);
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    for (name, m) in [("dtau_dq", &*dtau_dq), ("dtau_dv", &*dtau_dv), ("dtau_da", &*dtau_da)] {
        check_len(name, m, nv * nv);
    }
    dual.set_params(params);
    let (z, one) = (dual.zero(), S::constant(dual.workspace.context, 1.0));
    // Direction d of the 2 nv: q's tangent e_d for d < nv, then v's e_(d − nv).
    let mut start = 0;
    while start < 2 * nv {
        let width = N.min(2 * nv - start);
        dual.seed_configuration(
            multibody,
            q,
            |k, d| if start + k == d { one } else { z },
            |k| k < width && start + k < nv,
        );
        for i in 0..nv {
            dual.v[i] = Dual::constant_of(v[i], z);
            dual.a[i] = Dual::constant_of(a[i], z);
        }
        for k in (0..width).filter(|k| start + k >= nv) {
            dual.v[start + k - nv].tangent[k] = one;
        }
        let DualWorkspace {
            workspace,
            q: dq,
            v: dv,
            a: da,
            params: dp,
            out,
            ..
        } = dual;
        let tau = &mut out[..nv];
        crate::rnea(multibody, workspace, dq, dv, da, dp, tau);
        for k in 0..width {
            let d = start + k;
            let (m, column) = if d < nv {
                (&mut *dtau_dq, d)
            } else {
                (&mut *dtau_dv, d - nv)
            };
            for (i, t) in tau.iter().enumerate() {
                m[i * nv + column] = t.tangent[k];
            }
        }
        start += width;
    }
    crate::crba(multibody, workspace, q, params, dtau_da);
}

/// `q̈ = aba(q, v, τ)` and its derivatives `∂q̈/∂q`, `∂q̈/∂v` (in the tangent space)
/// and `∂q̈/∂τ = M(q)⁻¹`, each `nv × nv` row-major: Pinocchio's
/// `computeABADerivatives`, with the rotor inertias `armature` (one per velocity
/// coordinate, or empty) as [`crate::aba`]. As Pinocchio: `q̈` by [`crate::aba`],
/// then `∂q̈/∂x = −M⁻¹ ∂τ/∂x` at `a = q̈` ([`rnea_derivatives`]; the rotor inertia's
/// `Ia q̈` depends on neither `q` nor `v`), with `M + diag(Ia)` factored as `Lᵀ D L`
/// along the tree (Featherstone, *Rigid Body Dynamics Algorithms*, §6.3: no fill-in
/// outside each coordinate's path to the base). Where `M` is singular the results are
/// not finite.
///
/// # Panics
/// If a slice's length does not match the multibody.
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives<S: Real, const N: usize>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, N>,
    workspace: &mut Workspace<S>,
    q: &[S],
    v: &[S],
    tau: &[S],
    params: &[S],
    armature: &[S],
    ddq: &mut [S],
    ddq_dq: &mut [S],
    ddq_dv: &mut [S],
    minv: &mut [S],
) {
    let nv = multibody.nv();
    check_len("ddq", ddq, nv);
    check_len("minv", minv, nv * nv);
    crate::aba(multibody, workspace, q, v, tau, params, armature, ddq);
    rnea_derivatives(multibody, dual, workspace, q, v, ddq, params, ddq_dq, ddq_dv, minv);
    let factor = &mut dual.matrix;
    factor.copy_from_slice(minv);
    for (d, &ia) in armature.iter().enumerate() {
        factor[d * nv + d] = factor[d * nv + d] + ia;
    }
    ltdl(multibody, factor);
    let (z, one) = (S::constant(workspace.context, 0.0), S::constant(workspace.context, 1.0));
    for c in 0..nv {
        for r in 0..nv {
            minv[r * nv + c] = if r == c { one } else { z };
        }
        ltdl_solve(multibody, factor, minv, nv, c);
        ltdl_solve(multibody, factor, ddq_dq, nv, c);
        ltdl_solve(multibody, factor, ddq_dv, nv, c);
    }
    for x in ddq_dq.iter_mut().chain(ddq_dv.iter_mut()) {
        *x = -*x;
    }
}

/// `M` (nv × nv row-major, symmetric) factored in place as `M = Lᵀ D L`, `L` unit lower
/// triangular with the sparsity of the tree: afterwards the diagonal holds `D` and
/// entry `(k, i)`, `i` on `k`'s path to the base, holds `L_ki` (the rest is left as
/// it was). Featherstone's LTDL (RBDA Table 6.3).
pub(crate) fn ltdl<S: Real>(multibody: &Multibody, m: &mut [S]) {
    let (nv, parent) = (multibody.nv(), &multibody.dof_parent);
    for k in (0..nv).rev() {
        let mut i = parent[k];
        while i != NO_PARENT {
            let a = m[k * nv + i] / m[k * nv + k];
            let mut j = i;
            while j != NO_PARENT {
                m[i * nv + j] = m[i * nv + j] - a * m[k * nv + j];
                j = parent[j];
            }
            m[k * nv + i] = a;
            i = parent[i];
        }
    }
}

/// Column `c` of the row-major matrix `x` (`nv` rows of `width`) replaced by `M⁻¹`
/// times it, `M` factored by [`ltdl`]: `Lᵀ y = x`, `D z = y`, `L w = z` along the
/// tree (RBDA Table 6.5).
pub(crate) fn ltdl_solve<S: Real>(multibody: &Multibody, factor: &[S], x: &mut [S], width: usize, c: usize) {
    let (nv, parent) = (multibody.nv(), &multibody.dof_parent);
    for i in (0..nv).rev() {
        let mut j = parent[i];
        while j != NO_PARENT {
            x[j * width + c] = x[j * width + c] - factor[i * nv + j] * x[i * width + c];
            j = parent[j];
        }
    }
    for i in 0..nv {
        x[i * width + c] = x[i * width + c] / factor[i * nv + i];
    }
    for i in 0..nv {
        let mut j = parent[i];
        while j != NO_PARENT {
            x[i * width + c] = x[i * width + c] - factor[i * nv + j] * x[j * width + c];
            j = parent[j];
        }
    }
}
