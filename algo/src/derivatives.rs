//! The derivatives of inverse and forward dynamics (Pinocchio's
//! `computeRNEADerivatives` and `computeABADerivatives`), by running [`crate::rnea`]
//! and [`crate::aba`] themselves on [`Dual`] numbers, `N` directions per pass.
//!
//! Derivatives with respect to `q` are taken in the tangent space, as Pinocchio's:
//! column `d` of `∂τ/∂q` is `d/dε τ(q ⊕ ε e_d)` at `ε = 0`, so that a free flyer's or a
//! ball joint's columns are the derivatives along its angular velocity in its own
//! frame.

use crate::dual::{Dual, DualWorkspace};
use crate::kinematics::check_len;
use crate::multibody::{Multibody, Workspace, PARAMS_PER_BODY};
use crate::Real;

/// Which input a direction of [`sweep`] moves, and along which coordinate.
#[derive(Clone, Copy)]
enum Direction {
    /// Velocity coordinate `d` of the configuration (the tangent space).
    Q(usize),
    /// Entry `d` of the second input (`v`).
    V(usize),
    /// Entry `d` of the third input (`a` or `τ`).
    A(usize),
}

/// Runs `pass` over every direction of `directions` (`N` per pass) with `q`, `v`, `a`
/// seeded accordingly in `dual`, then hands each direction's derivatives of the
/// pass's output (`dual.out[..len]`) to `store`.
#[allow(clippy::too_many_arguments)]
fn sweep<S: Real, const N: usize>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, N>,
    q: &[S],
    v: &[S],
    a: &[S],
    directions: impl Fn(usize) -> Direction,
    count: usize,
    len: usize,
    pass: impl Fn(&mut DualWorkspace<S, N>),
    mut store: impl FnMut(Direction, &[Dual<S, N>], usize),
) {
    let z = dual.zero();
    let one = S::constant(dual.workspace.context, 1.0);
    let mut start = 0;
    while start < count {
        let width = N.min(count - start);
        let dir = |k: usize| (k < width).then(|| directions(start + k));
        dual.seed_configuration(
            multibody,
            q,
            |k, d| match dir(k) {
                Some(Direction::Q(e)) if e == d => one,
                _ => z,
            },
            |k| matches!(dir(k), Some(Direction::Q(_))),
        );
        for (i, (dv, da)) in dual.v.iter_mut().zip(dual.a.iter_mut()).enumerate() {
            *dv = Dual::constant_of(v[i], z);
            *da = Dual::constant_of(a[i], z);
            for k in 0..width {
                match dir(k) {
                    Some(Direction::V(d)) if d == i => dv.tangent[k] = one,
                    Some(Direction::A(d)) if d == i => da.tangent[k] = one,
                    _ => {}
                }
            }
        }
        pass(dual);
        for k in 0..width {
            store(directions(start + k), &dual.out[..len], k);
        }
        start += width;
    }
}

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
    sweep(
        multibody,
        dual,
        q,
        v,
        a,
        |k| if k < nv { Direction::Q(k) } else { Direction::V(k - nv) },
        2 * nv,
        nv,
        |d| {
            let DualWorkspace {
                workspace,
                q,
                v,
                a,
                params,
                out,
            } = d;
            crate::rnea(multibody, workspace, q, v, a, params, &mut out[..nv]);
        },
        |direction, tau, k| {
            let (m, d) = match direction {
                Direction::Q(d) => (&mut *dtau_dq, d),
                Direction::V(d) | Direction::A(d) => (&mut *dtau_dv, d),
            };
            for (i, t) in tau.iter().enumerate() {
                m[i * nv + d] = t.tangent[k];
            }
        },
    );
    crate::crba(multibody, workspace, q, params, dtau_da);
}

/// `q̈ = aba(q, v, τ)` and its derivatives `∂q̈/∂q`, `∂q̈/∂v` (in the tangent space)
/// and `∂q̈/∂τ = M(q)⁻¹`, each `nv × nv` row-major: Pinocchio's
/// `computeABADerivatives`, with the rotor inertias `armature` (one per velocity
/// coordinate, or empty) as [`crate::aba`]. Runs aba on [`Dual`] numbers
/// `⌈3 nv / N⌉` times. Where `M(q)` is singular the results are not finite.
///
/// # Panics
/// If a slice's length does not match the multibody.
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives<S: Real, const N: usize>(
    multibody: &Multibody,
    dual: &mut DualWorkspace<S, N>,
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
    check_len("q", q, multibody.nq());
    check_len("v", v, nv);
    check_len("tau", tau, nv);
    check_len("ddq", ddq, nv);
    check_len("params", params, PARAMS_PER_BODY * multibody.bodies());
    for (name, m) in [("ddq_dq", &*ddq_dq), ("ddq_dv", &*ddq_dv), ("minv", &*minv)] {
        check_len(name, m, nv * nv);
    }
    if !armature.is_empty() {
        check_len("armature", armature, nv);
    }
    dual.set_params(params);
    let z = dual.zero();
    // The armature as constants, in the output's room (6 nv) after the accelerations.
    let with_armature = !armature.is_empty();
    sweep(
        multibody,
        dual,
        q,
        v,
        tau,
        |k| match k / nv {
            0 => Direction::Q(k),
            1 => Direction::V(k - nv),
            _ => Direction::A(k - 2 * nv),
        },
        3 * nv,
        nv,
        |d| {
            let DualWorkspace {
                workspace,
                q,
                v,
                a,
                params,
                out,
            } = d;
            let (acc, rest) = out.split_at_mut(nv);
            let arm = if with_armature {
                for (r, &x) in rest[..nv].iter_mut().zip(armature) {
                    *r = Dual::constant_of(x, z);
                }
                &rest[..nv]
            } else {
                &rest[..0]
            };
            crate::aba(multibody, workspace, q, v, a, params, arm, acc);
        },
        |direction, acc, k| {
            let (m, d) = match direction {
                Direction::Q(d) => (&mut *ddq_dq, d),
                Direction::V(d) => (&mut *ddq_dv, d),
                Direction::A(d) => (&mut *minv, d),
            };
            for (i, x) in acc.iter().enumerate() {
                m[i * nv + d] = x.tangent[k];
            }
        },
    );
    for (x, d) in ddq.iter_mut().zip(&dual.out[..nv]) {
        *x = d.value;
    }
}
