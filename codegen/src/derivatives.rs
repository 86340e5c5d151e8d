//! Derivatives of the dynamics, built as nodes of the graph so they are emitted as
//! straight-line code like the algorithms of [`crate::algo`].
//!
//! - [`rnea_derivatives`]: `∂τ/∂q`, `∂τ/∂v` and `∂τ/∂a = M(q)` of inverse dynamics.
//! - [`aba_derivatives`]: `q̈ = aba(q, v, τ)`, `∂q̈/∂q = −M⁻¹ ∂τ/∂q`,
//!   `∂q̈/∂v = −M⁻¹ ∂τ/∂v` (both taken at `a = q̈`) and `M⁻¹`.
//!
//! A joint's coordinate is its angle (revolute and continuous) or displacement
//! (prismatic); row `i` is `τ_i` (or `q̈_i`), column `k` is `q_k` (or `v_k`), as
//! Pinocchio's `computeRNEADerivatives` / `computeABADerivatives`.
//!
//! # How `∂τ/∂q` and `∂τ/∂v` are built
//!
//! Not by differentiating the rnea graph (that is [`Graph::tangents`], kept as
//! [`rnea_derivatives_forward`] for reference: it carries a perturbation through every
//! body below each joint, two directions per joint), but in closed form, in the
//! spirit of Carpentier & Mansard (2018) and Singh, Russell & Wensing (2022), written
//! here in body frames so that axis-aligned joints keep their zeros. Spatial vectors
//! in body `k`'s frame: velocity `v_k`, acceleration `a_k` (gravity included as a base
//! acceleration), joint axis `S_k`, composite inertia `Ic_k` (as `crba`), composite
//! momentum `Hc_k = Σ I_i v_i`, composite wrench `F_k` (rnea's), and the composite rate
//! of inertia `Cc_k = Σ (v_i ×* I_i − I_i v_i ×)`, which is symmetric and has the form
//! of a rigid-body inertia (mass rate 0), so it is carried to the parent like `Ic`.
//! Changing `q_k` turns the subtree of `k` about `S_k`; seen from frame `k` only the
//! motion coming in from the parent turns, which perturbs every body of the subtree
//! by the same velocity `β_k = v_k × S_k` and acceleration
//! `α_k = a_k × S_k + v_k × β_k` (plus `β_k × (v_i − v_k)` through the joints below).
//! Summed over a subtree, the wrench responds by `Ic α + Cc β + β ×* Hc`. Changing
//! `v_k` is the same with `(α, β) = (2β_k, S_k)`. Hence, with `ρ_j = Ic_j S_j` and
//! `σ_j = Cc_j S_j − S_j ×* Hc_j` carried from frame `j` up to frame `k`:
//!
//! - `k ⪯ j` (`k` on the path from `j` to the root): `∂τ_j/∂q_k = ρ_j·α_k + σ_j·β_k`,
//!   `∂τ_j/∂v_k = 2 ρ_j·β_k + σ_j·S_k`;
//! - `j ≺ k`: `∂τ_j/∂q_k = S_j·G_k`, `∂τ_j/∂v_k = S_j·G'_k`, with
//!   `G_k = Ic_k α_k + Cc_k β_k + β_k ×* Hc_k + S_k ×* F_k` (the last term: the joint's
//!   own transform turns `F_k`) and `G'_k = 2 Ic_k β_k + Cc_k S_k + S_k ×* Hc_k`
//!   carried from frame `k` up to frame `j`;
//! - joints on different branches: exact zeros, never built.
//!
//! `ρ_j` carried up is exactly what `crba` carries, so those nodes are shared with `M`.
//! Per pair of joints on one path this is three force transforms and a few dot
//! products; the rest is linear in the number of bodies.
//!
//! In [`aba_derivatives`] the same closed form is taken at `a = q̈`, with the spatial
//! accelerations and bias forces built as `aba` builds them (so they are `aba`'s
//! nodes) and `∂q̈/∂(q, v) = −M⁻¹ ∂τ/∂(q, v)`. Generated code emits the parts
//! ([`aba_joints_derivative_parts`]: `q̈ = M⁻¹ (τ − h)` and an rnea at `q̈`, which on
//! the arms ran faster than next to `aba`) once, with the rotor inertias as inputs,
//! for `aba_derivatives` (zeros) and `aba_joints_derivatives`. For large trees it
//! emits no such graph: their `aba_derivatives` calls the generated
//! `inverse_inertia`, `nonlinear_effects` and `rnea_derivatives`, whose code the
//! single graph repeats in full.
//!
//! # `M⁻¹`
//!
//! Featherstone's `LᵀDL` factorisation (RBDA §6.5): with regular labelling a tree's
//! `M` factors without fill-in, `L` has the sparsity of the tree and so has `L⁻¹`;
//! `M⁻¹ = L⁻¹ D⁻¹ L⁻ᵀ`, one division per joint, upper triangle built and mirrored.

use crate::algo::{self, BodyParams, Force, Inputs, JointTransform, Kinematics, Motion, ARG_Q, ARG_TAU, ARG_V, M3, V3};
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::Model;

/// Derivatives of inverse dynamics `τ = rnea(q, v, a)`; `n × n` each, row `i` is `τ_i`,
/// column `k` is `q_k` / `v_k` / `a_k`.
pub struct RneaDerivatives<'g> {
    pub dtau_dq: Vec<Vec<Expr<'g>>>,
    pub dtau_dv: Vec<Vec<Expr<'g>>>,
    /// `∂τ/∂a = M(q)`: the nodes of [`algo::crba`].
    pub m: Vec<Vec<Expr<'g>>>,
}

/// Forward dynamics `q̈ = aba(q, v, τ)` and its derivatives; `n × n` each, row `i` is
/// `q̈_i`, column `k` is `q_k` / `v_k`.
pub struct AbaDerivatives<'g> {
    pub ddq: Vec<Expr<'g>>,
    pub ddq_dq: Vec<Vec<Expr<'g>>>,
    pub ddq_dv: Vec<Vec<Expr<'g>>>,
    /// `M(q)⁻¹ = ∂q̈/∂τ`, symmetric (both halves are the same nodes).
    pub minv: Vec<Vec<Expr<'g>>>,
}

/// How [`aba_derivatives_with`] computes `q̈`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ddq {
    /// The nodes of [`algo::aba`] (without armature): `ddq` is bit for bit `aba`.
    Aba,
    /// `M⁻¹ (τ − h(q, v))` with the `M⁻¹` that the derivatives need anyway and
    /// `h = rnea(q, v, 0)`: the same values up to rounding, fewer operations.
    InverseInertia,
}

/// `∂τ/∂q`, `∂τ/∂v` and `M` of `rnea(q, v, a)`, reading `q`, `v`, `a` and the standard
/// parameters from [`algo::ARG_Q`], [`algo::ARG_V`], [`algo::ARG_A`] and
/// [`algo::ARG_PARAMS`], as [`algo::rnea`] with [`Inputs::Full`].
pub fn rnea_derivatives<'g>(g: &'g Graph, model: &Model) -> RneaDerivatives<'g> {
    let n = model.nv();
    let k = algo::kinematics(g, model, Inputs::Full);
    let r = algo::rnea(g, model, Inputs::Full);
    let qd: Vec<Expr<'g>> = (0..n).map(|i| g.input(ARG_V, i as u32)).collect();
    let m = algo::crba(g, model);
    let (dtau_dq, dtau_dv) = rnea_partials(g, model, &qd, &k, &r.wrenches);
    RneaDerivatives { dtau_dq, dtau_dv, m }
}

/// [`aba_derivatives_with`] taking `q̈` from [`algo::aba`]: inputs `q`, `v`, `τ` (in the
/// slot of `a`, [`ARG_TAU`]) and the standard parameters.
pub fn aba_derivatives<'g>(g: &'g Graph, model: &Model) -> AbaDerivatives<'g> {
    aba_derivatives_with(g, model, Ddq::Aba)
}

/// `q̈`, `∂q̈/∂q = −M⁻¹ ∂τ/∂q (q, v, q̈)`, `∂q̈/∂v = −M⁻¹ ∂τ/∂v (q, v, q̈)` and `M⁻¹`.
/// The inverse-dynamics derivatives are taken at `a = q̈`, given as expressions: what
/// `q̈` itself depends on is not differentiated again.
pub fn aba_derivatives_with<'g>(g: &'g Graph, model: &Model, how: Ddq) -> AbaDerivatives<'g> {
    let n = model.nv();
    let AbaParts {
        ddq,
        dtau_dq: dq,
        dtau_dv: dv,
        minv,
    } = aba_derivative_parts(g, model, how);
    g.mark("derivatives: −M⁻¹ ∂τ/∂q, −M⁻¹ ∂τ/∂v");
    let times_minv = |d: &[Vec<Expr<'g>>]| -> Vec<Vec<Expr<'g>>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|c| {
                        let col: Vec<Expr<'g>> = d.iter().map(|row| row[c]).collect();
                        -dot(&minv[i], &col)
                    })
                    .collect()
            })
            .collect()
    };
    AbaDerivatives {
        ddq_dq: times_minv(&dq),
        ddq_dv: times_minv(&dv),
        ddq,
        minv,
    }
}

/// What [`aba_derivatives_with`] multiplies: `q̈`, `∂τ/∂q` and `∂τ/∂v` at `a = q̈`, and
/// `M⁻¹`. Generated code takes these and does the two `n × n` products in a loop:
/// written out, they would add `2 n²(2n − 1)` straight-line operations to a function
/// that is already larger than the instruction cache.
pub struct AbaParts<'g> {
    pub ddq: Vec<Expr<'g>>,
    pub dtau_dq: Vec<Vec<Expr<'g>>>,
    pub dtau_dv: Vec<Vec<Expr<'g>>>,
    pub minv: Vec<Vec<Expr<'g>>>,
}

/// The parts of [`aba_derivatives_with`], before the products with `−M⁻¹`.
pub fn aba_derivative_parts<'g>(g: &'g Graph, model: &Model, how: Ddq) -> AbaParts<'g> {
    parts(g, model, how, false)
}

/// [`aba_derivative_parts`] with each joint's rotor inertia `Ia` (read from
/// `joint_params[4(j−1)]`, [`algo::ARG_JOINT_PARAMS`]) on the diagonal of `M`:
/// `q̈ = (M + diag(Ia))⁻¹ (τ − h)`, the rigid `∂τ/∂q`, `∂τ/∂v` at `a = q̈` (`Ia·q̈` does
/// not depend on `q` or `v`), and `(M + diag(Ia))⁻¹`. `τ` is the torque left once
/// friction is taken off (friction's `∂/∂v` is added at run time).
pub fn aba_joints_derivative_parts<'g>(g: &'g Graph, model: &Model) -> AbaParts<'g> {
    parts(g, model, Ddq::InverseInertia, true)
}

fn parts<'g>(g: &'g Graph, model: &Model, how: Ddq, armature: bool) -> AbaParts<'g> {
    let n = model.nv();
    let mass_matrix = || {
        let mut m = algo::crba(g, model);
        if armature {
            for (i, row) in m.iter_mut().enumerate() {
                row[i] = row[i] + g.input(algo::ARG_JOINT_PARAMS, (4 * i) as u32);
            }
        }
        m
    };
    let (ddq, minv) = match how {
        Ddq::Aba => {
            let ddq = algo::aba(g, model, algo::Armature::None);
            (ddq, inverse_inertia(g, model, &mass_matrix()))
        }
        Ddq::InverseInertia => {
            let minv = inverse_inertia(g, model, &mass_matrix());
            let h = algo::rnea(g, model, Inputs::NoAcceleration).tau;
            g.mark("joint accelerations M⁻¹ (tau − h)");
            let b: Vec<Expr<'g>> = (0..n).map(|i| g.input(ARG_TAU, i as u32) - h[i]).collect();
            let ddq = (0..n).map(|i| dot(&minv[i], &b)).collect();
            (ddq, minv)
        }
    };
    let qd: Vec<Expr<'g>> = (0..n).map(|i| g.input(ARG_V, i as u32)).collect();
    // Next to `aba`, its accelerations and bias forces give the state (fewer new
    // operations than an rnea at a = q̈); otherwise the classical rnea is cheaper.
    let (dq, dv) = match how {
        Ddq::Aba => spatial_partials(g, model, &qd, &ddq),
        Ddq::InverseInertia => {
            let k = algo::kinematics_with(g, model, |d| qd[d], |d| ddq[d]);
            let r = algo::rnea_with_acceleration(g, model, &ddq);
            rnea_partials(g, model, &qd, &k, &r.wrenches)
        }
    };
    AbaParts {
        ddq,
        dtau_dq: dq,
        dtau_dv: dv,
        minv,
    }
}

fn dot<'g>(a: &[Expr<'g>], b: &[Expr<'g>]) -> Expr<'g> {
    let mut terms = a.iter().zip(b).map(|(&x, &y)| x * y);
    let first = terms.next().expect("non-empty"); // ok: a model has at least one joint
    terms.fold(first, |s, t| s + t)
}

fn force_sub<'g>(a: Force<'g>, b: Force<'g>) -> Force<'g> {
    Force {
        f: a.f - b.f,
        n: a.n - b.n,
    }
}

fn force_scale<'g>(a: Force<'g>, s: Expr<'g>) -> Force<'g> {
    Force {
        f: a.f.scale(s),
        n: a.n.scale(s),
    }
}

/// A spatial inertia given by its 10 parameters times a motion (as `crba` builds
/// `I S`): force `m u + ω × h`, moment `I ω + h × u`.
fn inertia_times<'g>(b: &BodyParams<'g>, m: Motion<'g>) -> Force<'g> {
    Force {
        f: m.v.scale(b.m) + m.w.cross(b.h),
        n: b.inertia.mul_vec(m.w) + b.h.cross(m.v),
    }
}

/// Every body's parameters with its descendants' added, leaves first, as `crba` does
/// (so the composite inertias are `crba`'s nodes).
pub fn composites<'g>(model: &Model, x: &[JointTransform<'g>], mut c: Vec<BodyParams<'g>>) -> Vec<BodyParams<'g>> {
    for i in (1..=model.dof()).rev() {
        let p = model.parent(i);
        if p > 0 {
            let moved = algo::composite_to_parent(&x[i - 1], &c[i - 1]);
            let cp = &mut c[p - 1];
            *cp = BodyParams {
                m: cp.m + moved.m,
                h: cp.h + moved.h,
                inertia: cp.inertia.add(&moved.inertia),
            };
        }
    }
    c
}

/// The rate of change of a body's spatial inertia when it moves at `v = (u, ω)`,
/// `v×* I − I v×`, which is again of the form of a rigid-body inertia: mass rate 0,
/// `ḣ = m u + ω × h`, `İ = S(ω) I − I S(ω) − S(u) S(h) − S(h) S(u)` (symmetric).
/// With `A = S(ω) I`: off the diagonal `İ_ij = A_ij + A_ji − h_i u_j − u_i h_j`, on it
/// `İ_ii = 2 (A_ii + Σ_{k≠i} u_k h_k)`; upper triangle built and mirrored.
fn inertia_rate<'g>(g: &'g Graph, b: &BodyParams<'g>, v: Motion<'g>) -> BodyParams<'g> {
    let (w, u, h) = (v.w, v.v, b.h);
    let a = M3::skew(w).mul(&b.inertia).0;
    let uh = [0, 1, 2].map(|k| u.0[k] * h.0[k]);
    let mut r = [[g.zero(); 3]; 3];
    for i in 0..3 {
        let e = a[i][i] + (uh[(i + 1) % 3] + uh[(i + 2) % 3]);
        r[i][i] = e + e;
        for j in i + 1..3 {
            let e = a[i][j] + a[j][i] - (h.0[i] * u.0[j] + u.0[i] * h.0[j]);
            r[i][j] = e;
            r[j][i] = e;
        }
    }
    BodyParams {
        m: g.zero(),
        h: u.scale(b.m) + w.cross(h),
        inertia: M3(r),
    }
}

/// `(∂τ/∂q, ∂τ/∂v)` of inverse dynamics in closed form (see the module documentation),
/// at the state of `k`: forward kinematics built with joint velocities `qd` (whatever
/// the accelerations: inputs, or expressions such as `aba`'s outputs), and `wrenches`,
/// the joint wrenches of the rnea on that `k` ([`algo::Rnea::wrenches`]). Standard
/// parameters are read from [`algo::ARG_PARAMS`]. Entries for joints on different
/// branches are exact zeros.
pub fn rnea_partials<'g>(
    g: &'g Graph,
    model: &Model,
    qd: &[Expr<'g>],
    k: &Kinematics<'g>,
    wrenches: &[Force<'g>],
) -> (Vec<Vec<Expr<'g>>>, Vec<Vec<Expr<'g>>>) {
    let n = model.dof();
    assert_eq!(qd.len(), model.nv(), "one velocity per velocity coordinate");
    let x = &k.x;
    g.mark("derivatives: spatial velocities and accelerations");
    let v = velocities(g, model, x, qd);
    // The spatial acceleration, gravity included: the classical acceleration of the
    // frame origin minus ω × u (the base at rest, accelerating at −g).
    let mut a = vec![Motion::zero(g); n + 1];
    a[0] = Motion {
        v: k.motion[0].acc,
        w: V3::zero(g),
    };
    for i in 1..=n {
        let m = &k.motion[i];
        a[i] = Motion {
            v: m.acc - m.w.cross(v[i].v),
            w: m.wd,
        };
    }
    partials(g, model, x, &v, &a, wrenches)
}

/// [`rnea_partials`] at joint accelerations given as expressions, with the spatial
/// accelerations and body wrenches built as `aba` builds its accelerations and bias
/// forces, so that next to `aba` in one graph they are `aba`'s nodes.
fn spatial_partials<'g>(
    g: &'g Graph,
    model: &Model,
    qd: &[Expr<'g>],
    qdd: &[Expr<'g>],
) -> (Vec<Vec<Expr<'g>>>, Vec<Vec<Expr<'g>>>) {
    let n = model.dof();
    let x: Vec<JointTransform<'g>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    g.mark("derivatives: spatial velocities, accelerations and wrenches");
    let v = velocities(g, model, &x, qd);
    let mut a = vec![Motion {
        v: V3::constant(g, model.gravity.map(|c| -c)),
        w: V3::zero(g),
    }];
    let mut f: Vec<Force<'g>> = Vec::with_capacity(n);
    for i in 1..=n {
        let dofs = algo::dofs(model, i);
        let (vj, aj) = (
            algo::subspace_times(g, model, i, &qd[dofs.clone()]),
            algo::subspace_times(g, model, i, &qdd[dofs]),
        );
        let bias = v[i].cross_motion(vj);
        let ai = x[i - 1].motion_to_child(a[model.parent(i)]) + bias + aj;
        let body = BodyParams::input(g, i);
        f.push(inertia_times(&body, ai) + v[i].cross_force(inertia_times(&body, v[i])));
        a.push(ai);
    }
    for i in (1..=n).rev() {
        let p = model.parent(i);
        if p > 0 {
            f[p - 1] = f[p - 1] + x[i - 1].force_to_parent(f[i - 1]);
        }
    }
    partials(g, model, &x, &v, &a, &f)
}

/// Spatial velocities (linear part: the velocity of the frame origin) in body axes,
/// index 0 the base, built as `aba` builds them.
fn velocities<'g>(g: &'g Graph, model: &Model, x: &[JointTransform<'g>], qd: &[Expr<'g>]) -> Vec<Motion<'g>> {
    let n = model.dof();
    let mut v = vec![Motion::zero(g); n + 1];
    for i in 1..=n {
        let vj = algo::subspace_times(g, model, i, &qd[algo::dofs(model, i)]);
        v[i] = x[i - 1].motion_to_child(v[model.parent(i)]) + vj;
    }
    v
}

/// The closed form from spatial velocities `v` and accelerations `a` (gravity
/// included; index 0 the base) and the joint wrenches.
fn partials<'g>(
    g: &'g Graph,
    model: &Model,
    x: &[JointTransform<'g>],
    v: &[Motion<'g>],
    a: &[Motion<'g>],
    wrenches: &[Force<'g>],
) -> (Vec<Vec<Expr<'g>>>, Vec<Vec<Expr<'g>>>) {
    let (n, nv) = (model.dof(), model.nv());
    // Per velocity coordinate d: its body, its motion S_d in that body's frame.
    let body: Vec<usize> = (0..nv).map(|d| model.joint_of_v(d)).collect();
    let s: Vec<Motion<'g>> = (1..=n).flat_map(|j| algo::subspace(g, model, j)).collect();
    g.mark("derivatives: composite inertias, inertia rates and momenta");
    let own: Vec<BodyParams<'g>> = (1..=n).map(|j| BodyParams::input(g, j)).collect();
    let ic = composites(model, x, own.clone());
    let cc = composites(model, x, (1..=n).map(|j| inertia_rate(g, &own[j - 1], v[j])).collect());
    let mut hc: Vec<Force<'g>> = (1..=n).map(|j| inertia_times(&own[j - 1], v[j])).collect();
    for i in (1..=n).rev() {
        let p = model.parent(i);
        if p > 0 {
            hc[p - 1] = hc[p - 1] + x[i - 1].force_to_parent(hc[i - 1]);
        }
    }
    let two = g.constant(2.0);
    // Changing a coordinate of joint k turns what comes in from the parent: β and α
    // are taken at the motion coming in to body k. For a joint with one degree of
    // freedom that is the body's own motion (S × S = 0 makes the two equal); a ball
    // joint, a free flyer or a planar joint takes the parent's motion seen in frame k.
    let incoming: Vec<(Motion<'g>, Motion<'g>)> = (1..=n)
        .map(|j| {
            if model.joints[j - 1].kind.nv() == 1 {
                (v[j], a[j])
            } else {
                let p = model.parent(j);
                (x[j - 1].motion_to_child(v[p]), x[j - 1].motion_to_child(a[p]))
            }
        })
        .collect();
    let beta: Vec<Motion<'g>> = (0..nv).map(|d| incoming[body[d] - 1].0.cross_motion(s[d])).collect();
    let alpha: Vec<Motion<'g>> = (0..nv)
        .map(|d| {
            let (vi, ai) = incoming[body[d] - 1];
            ai.cross_motion(s[d]) + vi.cross_motion(beta[d])
        })
        .collect();
    // Changing a velocity moves the subtree by S_e: its own bias acceleration changes by
    // β (the incoming motion's) and the joints below add the turn of S_e at the body's
    // own velocity; for one degree of freedom both are β, hence 2β.
    // (Built for the coordinates of multi-coordinate joints only.)
    let beta_v: Vec<Option<Motion<'g>>> = (0..nv)
        .map(|d| {
            let b = body[d];
            (model.joints[b - 1].kind.nv() > 1).then(|| beta[d] + v[b].cross_motion(s[d]))
        })
        .collect();
    let ccs: Vec<Force<'g>> = (0..nv).map(|d| inertia_times(&cc[body[d] - 1], s[d])).collect();
    let mut dq = vec![vec![g.zero(); nv]; nv];
    let mut dv = vec![vec![g.zero(); nv]; nv];
    // Row d, columns of the joints on the path from d's joint to the root (its own
    // joint included).
    for d in 0..nv {
        let j = body[d];
        g.mark(format!("derivatives: row {}, joints from {j} to the root", d + 1));
        let mut rho = inertia_times(&ic[j - 1], s[d]);
        let mut sigma = force_sub(ccs[d], s[d].cross_force(hc[j - 1]));
        let mut c = j;
        loop {
            for e in algo::dofs(model, c) {
                dq[d][e] = rho.dot(alpha[e]) + sigma.dot(beta[e]);
                dv[d][e] = match beta_v[e] {
                    None => two * rho.dot(beta[e]) + sigma.dot(s[e]),
                    Some(bv) => rho.dot(bv) + sigma.dot(s[e]),
                };
            }
            let p = model.parent(c);
            if p == 0 {
                break;
            }
            rho = x[c - 1].force_to_parent(rho);
            sigma = x[c - 1].force_to_parent(sigma);
            c = p;
        }
    }
    // Column e, rows of the joints strictly above e's joint.
    for e in 0..nv {
        let c = body[e];
        if model.parent(c) == 0 {
            continue;
        }
        g.mark(format!("derivatives: column {}, joints above {c}", e + 1));
        let (h, sc, be) = (hc[c - 1], s[e], beta[e]);
        let mut gq = inertia_times(&ic[c - 1], alpha[e])
            + inertia_times(&cc[c - 1], be)
            + be.cross_force(h)
            + sc.cross_force(wrenches[c - 1]);
        let mut gv = match beta_v[e] {
            None => force_scale(inertia_times(&ic[c - 1], be), two) + ccs[e] + sc.cross_force(h),
            Some(bv) => inertia_times(&ic[c - 1], bv) + ccs[e] + sc.cross_force(h),
        };
        let mut j = c;
        while model.parent(j) != 0 {
            gq = x[j - 1].force_to_parent(gq);
            gv = x[j - 1].force_to_parent(gv);
            j = model.parent(j);
            for (d, sd) in algo::dofs(model, j).zip(algo::subspace(g, model, j)) {
                dq[d][e] = gq.dot(sd);
                dv[d][e] = gv.dot(sd);
            }
        }
    }
    (dq, dv)
}

/// `M⁻¹` from the joint-space inertia matrix `m` (as [`algo::crba`] builds it) by the
/// `LᵀDL` factorisation of a tree (Featherstone, RBDA §6.5): `M = Lᵀ D L` with `L`
/// unit lower triangular and nonzero only where a joint supports another, so no
/// fill-in; `M⁻¹ = L⁻¹ D⁻¹ L⁻ᵀ`, where `L⁻¹` has the same sparsity. One division per
/// velocity coordinate. Symmetric: the upper triangle is built and mirrored.
pub fn inverse_inertia<'g>(g: &'g Graph, model: &Model, m: &[Vec<Expr<'g>>]) -> Vec<Vec<Expr<'g>>> {
    let n = model.nv();
    // The tree of velocity coordinates (`Model::coordinate_parents`), 1-based, 0 the
    // base: `M` factors on it without fill-in.
    let parents: Vec<usize> = model
        .coordinate_parents()
        .into_iter()
        .map(|p| p.map_or(0, |p| p + 1))
        .collect();
    let parent = |i: usize| parents[i - 1];
    g.mark("inverse of M: LᵀDL factorisation");
    // In place: the diagonal becomes D, the entries below it (joint k, ancestor i) L.
    let mut h: Vec<Vec<Expr<'g>>> = m.to_vec();
    let mut dinv = vec![g.zero(); n + 1];
    for k in (1..=n).rev() {
        let inv = g.one() / h[k - 1][k - 1];
        dinv[k] = inv;
        let mut i = parent(k);
        while i != 0 {
            let a = h[k - 1][i - 1] * inv;
            let mut j = i;
            while j != 0 {
                h[i - 1][j - 1] = h[i - 1][j - 1] - a * h[k - 1][j - 1];
                j = parent(j);
            }
            h[k - 1][i - 1] = a;
            i = parent(i);
        }
    }
    g.mark("inverse of M: L⁻¹ D⁻¹ L⁻ᵀ");
    // N = L⁻¹: N_kk = 1, N_ki = −Σ_{i ⪯ l ≺ k} L_kl N_li for i an ancestor of k.
    let mut ninv: Vec<Vec<Option<Expr<'g>>>> = vec![vec![None; n + 1]; n + 1];
    for k in 1..=n {
        ninv[k][k] = Some(g.one());
        let mut i = parent(k);
        while i != 0 {
            let mut sum = g.zero();
            let mut l = parent(k);
            loop {
                sum = sum + h[k - 1][l - 1] * ninv[l][i].expect("ancestors are filled first"); // ok: regular labelling
                if l == i {
                    break;
                }
                l = parent(l);
            }
            ninv[k][i] = Some(-sum);
            i = parent(i);
        }
    }
    // M⁻¹_ij = Σ_k N_ik D⁻¹_k N_jk over the common ancestors k of i and j.
    let mut out = vec![vec![g.zero(); n]; n];
    for i in 1..=n {
        for j in i..=n {
            let mut sum = g.zero();
            for k in 1..=i {
                if let (Some(a), Some(b)) = (ninv[i][k], ninv[j][k]) {
                    sum = sum + a * dinv[k] * b;
                }
            }
            out[i - 1][j - 1] = sum;
            out[j - 1][i - 1] = sum;
        }
    }
    out
}

/// The same matrices as [`rnea_derivatives`] by forward-mode differentiation of the
/// rnea graph ([`Graph::tangents`], one direction per `q_k` and per `v_k`; `M` from
/// `crba`). A cross-check: it builds 1.4 to 2.2 times the operations.
pub fn rnea_derivatives_forward<'g>(g: &'g Graph, model: &Model) -> RneaDerivatives<'g> {
    let n = model.dof();
    let r = algo::rnea(g, model, Inputs::Full);
    let tau: Vec<NodeId> = r.tau.iter().map(|e| e.id()).collect();
    let column = |arg: u8, c: usize| {
        let x = g.input(arg, c as u32).id();
        g.tangents(&tau, |id| (id == x).then(|| g.one()))
    };
    let cq: Vec<Vec<Expr<'g>>> = (0..n).map(|c| column(ARG_Q, c)).collect();
    let cv: Vec<Vec<Expr<'g>>> = (0..n).map(|c| column(ARG_V, c)).collect();
    let rows = |cols: &[Vec<Expr<'g>>]| (0..n).map(|i| (0..n).map(|c| cols[c][i]).collect()).collect();
    RneaDerivatives {
        dtau_dq: rows(&cq),
        dtau_dv: rows(&cv),
        m: algo::crba(g, model),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algo::{ARG_A, ARG_PARAMS};
    use crate::sym::OpCount;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const ROBOTS: [&str; 4] = [
        "robots/ur5/ur5.urdf",
        "robots/panda/panda.urdf",
        "robots/gripper_arm/gripper_arm.urdf",
        "tests/fixtures/tree12.urdf",
    ];

    fn load(rel: &str) -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel);
        dyngen_model::load_urdf(&path).unwrap()
    }

    fn ids(m: &[Vec<Expr>]) -> Vec<NodeId> {
        m.iter().flatten().map(|e| e.id()).collect()
    }

    fn vids(v: &[Expr]) -> Vec<NodeId> {
        v.iter().map(|e| e.id()).collect()
    }

    /// Evaluates `outs` at `q`, `v`, `a` (or `tau`) and the parameters.
    fn eval(g: &Graph, outs: &[NodeId], q: &[f64], v: &[f64], a: &[f64], p: &[f64]) -> Vec<f64> {
        g.eval(outs, |arg, i| {
            let i = i as usize;
            match arg {
                ARG_Q => q[i],
                ARG_V => v[i],
                ARG_A => a[i],
                ARG_PARAMS => p[i],
                _ => panic!("argument {arg}"),
            }
        })
    }

    fn random(rng: &mut ChaCha8Rng, n: usize, r: f64) -> Vec<f64> {
        (0..n).map(|_| rng.gen_range(-r..r)).collect()
    }

    /// Central differences of `outs` (n values) with respect to argument `wrt` (0 = q,
    /// 1 = v): an n × n row-major matrix. The dynamics are quadratic in `v`, so central
    /// differences are exact there up to rounding and take a larger step.
    fn central(g: &Graph, outs: &[NodeId], wrt: usize, x: [&[f64]; 3], p: &[f64]) -> Vec<f64> {
        let n = x[0].len();
        let h = if wrt == 0 { 1e-5 } else { 1e-3 };
        let mut jac = vec![0.0; n * n];
        for c in 0..n {
            let mut plus = [x[0].to_vec(), x[1].to_vec(), x[2].to_vec()];
            let mut minus = plus.clone();
            plus[wrt][c] += h;
            minus[wrt][c] -= h;
            let fp = eval(g, outs, &plus[0], &plus[1], &plus[2], p);
            let fm = eval(g, outs, &minus[0], &minus[1], &minus[2], p);
            for r in 0..n {
                jac[r * n + c] = (fp[r] - fm[r]) / (2.0 * h);
            }
        }
        jac
    }

    /// Normwise relative error `max |got − want| / max |want|`.
    fn rel_error(got: &[f64], want: &[f64]) -> f64 {
        let scale = want.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
        got.iter().zip(want).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale
    }

    #[test]
    fn rnea_derivatives_match_finite_differences() {
        for rel in ROBOTS {
            let model = load(rel);
            let n = model.dof();
            let params = model.standard_params();
            let g = Graph::new();
            let tau = vids(&algo::rnea(&g, &model, Inputs::Full).tau);
            let d = rnea_derivatives(&g, &model);
            assert_eq!(ids(&d.m), ids(&algo::crba(&g, &model)), "{rel}: m is crba");
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let mut worst = [0.0f64; 2];
            for _ in 0..3 {
                let (q, v, a) = (
                    random(&mut rng, n, 3.0),
                    random(&mut rng, n, 2.0),
                    random(&mut rng, n, 2.0),
                );
                for (w, got) in [(0, &d.dtau_dq), (1, &d.dtau_dv)] {
                    let got = eval(&g, &ids(got), &q, &v, &a, &params);
                    let fd = central(&g, &tau, w, [&q, &v, &a], &params);
                    worst[w] = worst[w].max(rel_error(&got, &fd));
                }
            }
            println!("{rel}: dtau_dq {:.1e}, dtau_dv {:.1e}", worst[0], worst[1]);
            assert!(worst[0] <= 1e-6 && worst[1] <= 1e-6, "{rel}: {worst:?}");
        }
    }

    #[test]
    fn aba_derivatives_match_finite_differences() {
        for rel in ROBOTS {
            let model = load(rel);
            let n = model.dof();
            let params = model.standard_params();
            let g = Graph::new();
            let aba = vids(&algo::aba(&g, &model, algo::Armature::None));
            let d = aba_derivatives(&g, &model);
            assert_eq!(vids(&d.ddq), aba, "{rel}: ddq is aba");
            let m = ids(&algo::crba(&g, &model));
            let alt = aba_derivatives_with(&g, &model, Ddq::InverseInertia);
            let mut rng = ChaCha8Rng::seed_from_u64(12);
            let (mut worst, mut inv, mut alt_err) = ([0.0f64; 2], 0.0f64, 0.0f64);
            for _ in 0..3 {
                let (q, v, tau) = (
                    random(&mut rng, n, 3.0),
                    random(&mut rng, n, 2.0),
                    random(&mut rng, n, 20.0),
                );
                for (w, got) in [(0, &d.ddq_dq), (1, &d.ddq_dv)] {
                    let got = eval(&g, &ids(got), &q, &v, &tau, &params);
                    let fd = central(&g, &aba, w, [&q, &v, &tau], &params);
                    worst[w] = worst[w].max(rel_error(&got, &fd));
                }
                // M⁻¹ M = I, and M⁻¹ symmetric.
                let mi = eval(&g, &ids(&d.minv), &q, &v, &tau, &params);
                let mm = eval(&g, &m, &q, &v, &tau, &params);
                for r in 0..n {
                    for c in 0..n {
                        let e: f64 = (0..n).map(|l| mi[r * n + l] * mm[l * n + c]).sum();
                        inv = inv.max((e - if r == c { 1.0 } else { 0.0 }).abs());
                        assert_eq!(d.minv[r][c].id(), d.minv[c][r].id());
                    }
                }
                // q̈ = M⁻¹ (τ − h) gives the same values.
                for (a, b) in [(&d.ddq, &alt.ddq)].into_iter().map(|(a, b)| (vids(a), vids(b))).chain(
                    [(&d.ddq_dq, &alt.ddq_dq), (&d.ddq_dv, &alt.ddq_dv)]
                        .into_iter()
                        .map(|(a, b)| (ids(a), ids(b))),
                ) {
                    let want = eval(&g, &a, &q, &v, &tau, &params);
                    alt_err = alt_err.max(rel_error(&eval(&g, &b, &q, &v, &tau, &params), &want));
                }
            }
            println!(
                "{rel}: ddq_dq {:.1e}, ddq_dv {:.1e}, |M⁻¹M − I| {inv:.1e}, via M⁻¹ {alt_err:.1e}",
                worst[0], worst[1]
            );
            assert!(worst[0] <= 1e-6 && worst[1] <= 1e-6, "{rel}: {worst:?}");
            assert!(inv <= 1e-10, "{rel}: {inv}");
            assert!(alt_err <= 1e-10, "{rel}: {alt_err}");
        }
    }

    /// Forward-mode differentiation of the graph gives the same matrices: of `rnea`
    /// directly, and of `rnea` at `a = aba(q, v, τ)` with the `aba` nodes seeded as
    /// constants, which is what the closed form takes there.
    #[test]
    fn forward_mode_agrees() {
        for rel in ROBOTS {
            let model = load(rel);
            let n = model.dof();
            let params = model.standard_params();
            let g = Graph::new();
            let d = rnea_derivatives(&g, &model);
            let f = rnea_derivatives_forward(&g, &model);
            let ddq = algo::aba(&g, &model, algo::Armature::None);
            let tau = vids(&algo::rnea_with_acceleration(&g, &model, &ddq).tau);
            let held: Vec<NodeId> = vids(&ddq);
            let column = |arg: u8, c: usize| {
                let x = g.input(arg, c as u32).id();
                g.tangents(&tau, |id| {
                    if id == x {
                        Some(g.one())
                    } else {
                        held.contains(&id).then(|| g.zero())
                    }
                })
            };
            let fq: Vec<Vec<Expr>> = (0..n).map(|c| column(ARG_Q, c)).collect();
            let fv: Vec<Vec<Expr>> = (0..n).map(|c| column(ARG_V, c)).collect();
            let qd: Vec<Expr> = (0..n).map(|i| g.input(ARG_V, i as u32)).collect();
            let k = algo::kinematics_with(&g, &model, |d| qd[d], |d| ddq[d]);
            let r = algo::rnea_with_acceleration(&g, &model, &ddq);
            let (aq, av) = rnea_partials(&g, &model, &qd, &k, &r.wrenches);
            let transpose = |m: &[Vec<Expr>]| -> Vec<NodeId> {
                (0..n)
                    .flat_map(|i| (0..n).map(move |c| (i, c)))
                    .map(|(i, c)| m[c][i].id())
                    .collect()
            };
            let mut rng = ChaCha8Rng::seed_from_u64(13);
            for _ in 0..2 {
                let (q, v, a) = (
                    random(&mut rng, n, 3.0),
                    random(&mut rng, n, 2.0),
                    random(&mut rng, n, 2.0),
                );
                let at = |o: &[NodeId]| eval(&g, o, &q, &v, &a, &params);
                for (x, y) in [
                    (ids(&d.dtau_dq), ids(&f.dtau_dq)),
                    (ids(&d.dtau_dv), ids(&f.dtau_dv)),
                    (ids(&aq), transpose(&fq)),
                    (ids(&av), transpose(&fv)),
                ] {
                    let e = rel_error(&at(&y), &at(&x));
                    assert!(e <= 1e-12, "{rel}: {e}");
                }
            }
        }
    }

    /// Joints on different branches do not act on each other: exact zeros, no code.
    #[test]
    fn different_branches_are_exact_zeros() {
        for rel in ["robots/gripper_arm/gripper_arm.urdf", "tests/fixtures/tree12.urdf"] {
            let model = load(rel);
            let n = model.dof();
            let g = Graph::new();
            let d = rnea_derivatives(&g, &model);
            let mut zeros = 0;
            for j in 1..=n {
                for c in 1..=n {
                    if !model.supports(j, c) && !model.supports(c, j) {
                        assert!(d.dtau_dq[j - 1][c - 1].is_zero() && d.dtau_dv[j - 1][c - 1].is_zero());
                        zeros += 1;
                    }
                }
            }
            assert!(zeros > 0, "{rel} has branches");
        }
    }

    /// The operation counts, against `rnea` and against forward mode.
    #[test]
    fn op_counts() {
        for rel in ROBOTS {
            let model = load(rel);
            let count = |build: &dyn Fn(&Graph) -> Vec<NodeId>| {
                let g = Graph::new();
                let outs = build(&g);
                OpCount::of(&g, &outs).flops()
            };
            let rnea = count(&|g| vids(&algo::rnea(g, &model, Inputs::Full).tau));
            let crba = count(&|g| ids(&algo::crba(g, &model)));
            let aba = count(&|g| vids(&algo::aba(g, &model, algo::Armature::None)));
            let rd = |d: RneaDerivatives| [ids(&d.dtau_dq), ids(&d.dtau_dv), ids(&d.m)].concat();
            let ad = |d: AbaDerivatives| [vids(&d.ddq), ids(&d.ddq_dq), ids(&d.ddq_dv), ids(&d.minv)].concat();
            let rnea_d = count(&|g| rd(rnea_derivatives(g, &model)));
            let rnea_f = count(&|g| rd(rnea_derivatives_forward(g, &model)));
            let aba_d = count(&|g| ad(aba_derivatives(g, &model)));
            let aba_m = count(&|g| ad(aba_derivatives_with(g, &model, Ddq::InverseInertia)));
            let minv = count(&|g| ids(&inverse_inertia(g, &model, &algo::crba(g, &model))));
            println!(
                "{rel}: rnea {rnea}, crba {crba}, aba {aba}, minv (with crba) {minv}, rnea_derivatives {rnea_d} \
                 ({:.2}× rnea; forward mode {rnea_f}), aba_derivatives {aba_d} (ddq by M⁻¹: {aba_m})",
                rnea_d as f64 / rnea as f64
            );
            assert!(rnea_d < rnea_f && aba_m < aba_d);
        }
    }
}
