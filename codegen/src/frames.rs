//! Frames in generated code: every link of the description (and every frame a `robot!`
//! description declares) is a named frame with a placement, a Jacobian, a velocity
//! and a classical acceleration, and the robot gets its centre of mass, the centre of
//! mass's Jacobian and the centroidal momentum matrix with its time variation. Each frame's functions walk only the bodies between the
//! base and the frame, so only the Jacobian columns of the joints on that path are
//! computed; the others are exact zeros. A large tree (more than
//! [`crate::Options::compose_above_nv`] coordinates) carries one function per frame, the
//! Jacobian: its placements come from [`build_placements`], its Jacobians' time variations from the
//! world axes of all coordinates and their time derivatives
//! ([`build_axes_time_variation`]), each frame's columns put together at run time.
//!
//! Everything is built in world axes at the frame origin (Pinocchio's
//! `LOCAL_WORLD_ALIGNED`): joint `k`'s column is `[z_k × (p − o_k); z_k]` for a
//! revolute joint (`z_k` its axis, `o_k` its origin, `p` the frame origin) and
//! `[z_k; 0]` for a prismatic one. `dyngen::FrameJacobian` and `dyngen::FrameMotion`
//! turn that into `LOCAL` or `WORLD` at run time, a few products per column.

use crate::algo::{BodyParams, JointTransform, ARG_A, ARG_PARAMS, ARG_Q, ARG_V, M3, V3};
use crate::emit::{self, Arg, FnReport, FnSpec, Output};
use crate::generate::{doc_attrs, Record, Sizes};
use crate::mimic::Block;
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::{JointKind, Model};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// A body's placement and motion in world axes: rotation `r`, origin `t`, angular
/// velocity `w`, velocity `v` and classical acceleration `acc` of the origin, angular
/// acceleration `wd`. Gravity plays no part here.
#[derive(Clone, Copy)]
struct WorldBody<'g> {
    r: M3<'g>,
    t: V3<'g>,
    w: V3<'g>,
    v: V3<'g>,
    wd: V3<'g>,
    acc: V3<'g>,
}

/// One degree of freedom of a joint in world axes: a rotation about the axis `z`
/// through the joint's origin, or a translation along `z`.
#[derive(Clone, Copy)]
enum WorldDof<'g> {
    Rotation(V3<'g>),
    Translation(V3<'g>),
}

/// Joint `k`'s degrees of freedom (the first `nv` of `dofs`) and origin `o` in the
/// world (the origin is body `k`'s).
#[derive(Clone, Copy)]
struct WorldJoint<'g> {
    dofs: [WorldDof<'g>; 6],
    nv: usize,
    o: V3<'g>,
}

impl<'g> WorldJoint<'g> {
    fn dofs(&self) -> &[WorldDof<'g>] {
        &self.dofs[..self.nv]
    }
}

/// What a walk from the base computes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Walk {
    /// Placements only.
    Placement,
    /// Placements, velocities and accelerations (reading `v` and `a`).
    Motion,
}

/// What [`walk`] computed for body or joint `i`. Every function walks the bodies it
/// reads (each one's parent first), so this never fails.
fn walked<T: Copy>(computed: &[Option<T>], i: usize) -> T {
    computed[i].expect("a body is walked before it is read") // ok: an invariant of `walk`'s callers
}

/// The bodies from the base to `body`, base side first (body 0 excluded).
fn path(model: &Model, body: usize) -> Vec<usize> {
    let mut p = Vec::new();
    let mut k = body;
    while k != 0 {
        p.push(k);
        k = model.parent(k);
    }
    p.reverse();
    p
}

/// Walks `bodies` (each one's parent walked before it, or the base) and returns, for
/// every body index `0..=n`, its world placement and motion where it was walked, and
/// the joints of the walked bodies.
fn walk<'g>(
    g: &'g Graph,
    model: &Model,
    bodies: &[usize],
    what: Walk,
) -> (Vec<Option<WorldBody<'g>>>, Vec<Option<WorldJoint<'g>>>) {
    let n = model.dof();
    let zero = V3::zero(g);
    let mut world: Vec<Option<WorldBody<'g>>> = vec![None; n + 1];
    world[0] = Some(WorldBody {
        r: M3::constant(g, dyngen_model::math::IDENTITY),
        t: zero,
        w: zero,
        v: zero,
        wd: zero,
        acc: zero,
    });
    let mut joints = vec![None; n + 1];
    for &k in bodies {
        let p = walked(&world, model.parent(k));
        let x = JointTransform::new(g, model, k);
        let joint = &model.joints[k - 1];
        let r0 = p.r.mul(&x.origin);
        let d = p.r.mul_vec(x.translation);
        let t = p.t + d;
        let r = r0.mul(&x.motion);
        let column = |c: usize| V3([r.0[0][c], r.0[1][c], r.0[2][c]]);
        let mut dofs = [WorldDof::Translation(zero); 6];
        match joint.kind {
            JointKind::Revolute | JointKind::Continuous => {
                dofs[0] = WorldDof::Rotation(r0.mul_vec(V3::constant(g, joint.axis)));
            }
            JointKind::Prismatic => dofs[0] = WorldDof::Translation(r0.mul_vec(V3::constant(g, joint.axis))),
            JointKind::Spherical => {
                for c in 0..3 {
                    dofs[c] = WorldDof::Rotation(column(c));
                }
            }
            JointKind::FreeFlyer => {
                for c in 0..3 {
                    dofs[c] = WorldDof::Translation(column(c));
                    dofs[3 + c] = WorldDof::Rotation(column(c));
                }
            }
            JointKind::Planar => {
                // The child frame's plane axes and the normal (which the turn keeps).
                let (e1, e2) = dyngen_model::math::plane_basis(&joint.axis);
                dofs[0] = WorldDof::Translation(r.mul_vec(V3::constant(g, e1)));
                dofs[1] = WorldDof::Translation(r.mul_vec(V3::constant(g, e2)));
                dofs[2] = WorldDof::Rotation(r0.mul_vec(V3::constant(g, joint.axis)));
            }
        }
        let wj = WorldJoint {
            dofs,
            nv: joint.kind.nv(),
            o: t,
        };
        joints[k] = Some(wj);
        let mut b = WorldBody {
            r,
            t,
            w: zero,
            v: zero,
            wd: zero,
            acc: zero,
        };
        if what == Walk::Motion {
            // The parent's velocity and acceleration carried to the joint origin.
            let v = p.v + p.w.cross(d);
            let acc = p.acc + p.wd.cross(d) + p.w.cross(p.w.cross(d));
            // ω = ω_p + ω_q, ω̇ = ω̇_p + ω̇_q + ω_p × ω_q, v = v_p + v_q,
            // a = a_p + a_q + 2 ω_p × v_q + ω_q × v_q (world axes, at the origin; the
            // terms a joint does not have fold away).
            let (mut wq, mut wdq, mut vq, mut aq) = (zero, zero, zero, zero);
            for (dof, i) in wj.dofs().iter().zip(crate::algo::dofs(model, k)) {
                let (qd, qdd) = (g.input(ARG_V, i as u32), g.input(ARG_A, i as u32));
                match dof {
                    WorldDof::Rotation(z) => {
                        wq = wq + z.scale(qd);
                        wdq = wdq + z.scale(qdd);
                    }
                    WorldDof::Translation(z) => {
                        vq = vq + z.scale(qd);
                        aq = aq + z.scale(qdd);
                    }
                }
            }
            b.w = p.w + wq;
            b.wd = p.wd + wdq + p.w.cross(wq);
            b.v = v + vq;
            b.acc = acc + aq + p.w.cross(vq).scale(g.constant(2.0)) + wq.cross(vq);
        }
        world[k] = Some(b);
    }
    (world, joints)
}

/// The frame's world rotation and origin, and its offset `e = R_b p_f` from its
/// body's origin.
fn frame_pose<'g>(g: &'g Graph, model: &Model, f: usize, body: &WorldBody<'g>) -> (M3<'g>, V3<'g>, V3<'g>) {
    let pl = &model.frames[f].placement;
    let e = body.r.mul_vec(V3::constant(g, pl.translation));
    (body.r.mul(&M3::constant(g, pl.rotation)), body.t + e, e)
}

fn pose_ids(r: &M3<'_>, t: &V3<'_>) -> Vec<NodeId> {
    r.0.iter().flatten().chain(t.0.iter()).map(|x| x.id()).collect()
}

fn v3_ids<'a>(v: &'a V3<'_>) -> impl Iterator<Item = NodeId> + 'a {
    v.0.iter().map(|x| x.id())
}

/// Frame `f`'s placement (12 outputs: rotation row-major, translation).
pub fn build_placement(g: &Graph, model: &Model, f: usize) -> Vec<NodeId> {
    let b = model.frames[f].body;
    let (world, _) = walk(g, model, &path(model, b), Walk::Placement);
    let (r, t, _) = frame_pose(g, model, f, &walked(&world, b));
    pose_ids(&r, &t)
}

/// Every frame's placement, one walk over all bodies.
pub fn build_placements(g: &Graph, model: &Model) -> Vec<NodeId> {
    let all: Vec<usize> = (1..=model.dof()).collect();
    let (world, _) = walk(g, model, &all, Walk::Placement);
    (0..model.frames.len())
        .flat_map(|f| {
            let (r, t, _) = frame_pose(g, model, f, &walked(&world, model.frames[f].body));
            pose_ids(&r, &t)
        })
        .collect()
}

/// Frame `f`'s placement (12) and `LOCAL_WORLD_ALIGNED` Jacobian (6 × n, row-major).
pub fn build_jacobian(g: &Graph, model: &Model, f: usize) -> Vec<NodeId> {
    let b = model.frames[f].body;
    let on_path = path(model, b);
    let (world, joints) = walk(g, model, &on_path, Walk::Placement);
    let (r, p, _) = frame_pose(g, model, f, &walked(&world, b));
    let mut jac = vec![vec![g.zero(); model.nv()]; 6];
    for &k in &on_path {
        let j = walked(&joints, k);
        for (dof, c) in j.dofs().iter().zip(crate::algo::dofs(model, k)) {
            let (lin, ang) = match dof {
                WorldDof::Rotation(z) => (z.cross(p - j.o), *z),
                WorldDof::Translation(z) => (*z, V3::zero(g)),
            };
            for (row, e) in lin.0.iter().chain(ang.0.iter()).enumerate() {
                jac[row][c] = *e;
            }
        }
    }
    let mut out = pose_ids(&r, &p);
    out.extend(jac.iter().flatten().map(|x| x.id()));
    out
}

/// The time derivatives of `ids` along `q̇ = v`: one forward-mode tangent
/// ([`Graph::tangents`]), reusing every node of `ids`.
fn time_derivatives<'g>(g: &'g Graph, model: &Model, ids: &[NodeId]) -> Vec<Expr<'g>> {
    g.tangents(ids, |id| match g.node(id) {
        crate::sym::Node::Input { arg, index } if arg == ARG_Q => crate::algo::q_dot(g, model, index as usize),
        _ => None,
    })
}

/// Frame `f`'s placement (12), `LOCAL_WORLD_ALIGNED` Jacobian (6 × n) and its time
/// variation `J̇(q, v)` (6 × n): one forward-mode tangent of the Jacobian along `q̇ = v`.
pub fn build_jacobian_time_variation(g: &Graph, model: &Model, f: usize) -> Vec<NodeId> {
    let mut out = build_jacobian(g, model, f);
    let dot = time_derivatives(g, model, &out[12..]);
    out.extend(dot.iter().map(|x| x.id()));
    out
}

/// What a large tree composes every frame's `J̇` of
/// (`dyngen::__private::frame_jacobian_time_variation_from_axes`), from one walk over
/// all bodies with their velocities: each velocity coordinate's axis `z` and origin
/// `o` in the world (6 per coordinate; the origin of a translation unused), each
/// frame's placement (12 per frame), then the time derivatives along `q̇ = v` of the
/// axes and origins (6 per coordinate) and of the frame origins (3 per frame); and
/// whether each coordinate is a rotation (`true`) or a translation. Every axis is
/// fixed in the body its joint moves (or, for a rotation, unmoved by it), so
/// `ż = ω × z` with that body's angular velocity `ω`; the origin moves with the
/// body's origin, `ȯ = v`; a frame's origin at `e` from its body's, `ṗ = v + ω × e`.
pub fn build_axes_time_variation(g: &Graph, model: &Model) -> (Vec<NodeId>, Vec<bool>) {
    let n = model.dof();
    let all: Vec<usize> = (1..=n).collect();
    let (world, joints) = walk(g, model, &all, Walk::Motion);
    let nv = model.nv();
    let mut axes = vec![V3::zero(g); 2 * nv];
    let mut rates = vec![V3::zero(g); 2 * nv];
    let mut rotation = vec![false; nv];
    for k in 1..=n {
        let (j, b) = (walked(&joints, k), walked(&world, k));
        for (dof, c) in j.dofs().iter().zip(crate::algo::dofs(model, k)) {
            let z = match dof {
                WorldDof::Rotation(z) => {
                    rotation[c] = true;
                    *z
                }
                WorldDof::Translation(z) => *z,
            };
            (axes[2 * c], axes[2 * c + 1]) = (z, j.o);
            (rates[2 * c], rates[2 * c + 1]) = (b.w.cross(z), b.v);
        }
    }
    let mut out: Vec<NodeId> = axes.iter().flat_map(v3_ids).collect();
    let mut frame_rates = Vec::new();
    for f in 0..model.frames.len() {
        let b = walked(&world, model.frames[f].body);
        let (r, t, e) = frame_pose(g, model, f, &b);
        out.extend(pose_ids(&r, &t));
        frame_rates.push(b.v + b.w.cross(e));
    }
    out.extend(rates.iter().chain(&frame_rates).flat_map(v3_ids));
    (out, rotation)
}

/// Frame `f`'s placement (12), velocity (6) and classical acceleration (6) of its
/// origin, `LOCAL_WORLD_ALIGNED`.
pub fn build_motion(g: &Graph, model: &Model, f: usize) -> Vec<NodeId> {
    let bi = model.frames[f].body;
    let (world, _) = walk(g, model, &path(model, bi), Walk::Motion);
    let b = walked(&world, bi);
    let (r, p, e) = frame_pose(g, model, f, &b);
    let v = b.v + b.w.cross(e);
    let acc = b.acc + b.wd.cross(e) + b.w.cross(b.w.cross(e));
    let mut out = pose_ids(&r, &p);
    out.extend(v3_ids(&v).chain(v3_ids(&b.w)).chain(v3_ids(&acc)).chain(v3_ids(&b.wd)));
    out
}

/// Per body `i`: `m_i` and `m_i c_i` (the first moment about the world origin, world
/// axes), from the symbolic parameters.
fn moments<'g>(g: &'g Graph, model: &Model, world: &[Option<WorldBody<'g>>]) -> Vec<(Expr<'g>, V3<'g>)> {
    (1..=model.dof())
        .map(|i| {
            let b = walked(world, i);
            let p = BodyParams::input(g, i);
            (p.m, b.t.scale(p.m) + b.r.mul_vec(p.h))
        })
        .collect()
}

/// The centre of mass (3 outputs).
pub fn build_com(g: &Graph, model: &Model) -> Vec<NodeId> {
    let all: Vec<usize> = (1..=model.dof()).collect();
    let (world, _) = walk(g, model, &all, Walk::Placement);
    let (m, h) = moments(g, model, &world)
        .into_iter()
        .fold((g.zero(), V3::zero(g)), |(m, h), (mi, hi)| (m + mi, h + hi));
    v3_ids(&h.scale(g.one() / m)).collect()
}

/// The centre of mass's Jacobian (3 × n, row-major): column `k` is
/// `z_k × (h_k − m_k o_k) / m` for a revolute joint and `z_k m_k / m` for a prismatic
/// one, `m_k` and `h_k` the mass and first moment of the bodies joint `k` carries.
pub fn build_com_jacobian(g: &Graph, model: &Model) -> Vec<NodeId> {
    let n = model.dof();
    let all: Vec<usize> = (1..=n).collect();
    let (world, joints) = walk(g, model, &all, Walk::Placement);
    let mut sub = moments(g, model, &world);
    for i in (1..=n).rev() {
        let p = model.parent(i);
        if p > 0 {
            let (mi, hi) = sub[i - 1];
            let (mp, hp) = sub[p - 1];
            sub[p - 1] = (mp + mi, hp + hi);
        }
    }
    let total = (1..=n)
        .filter(|&i| model.parent(i) == 0)
        .fold(g.zero(), |m, i| m + sub[i - 1].0);
    let inv = g.one() / total;
    let mut jac = vec![vec![g.zero(); model.nv()]; 3];
    for k in 1..=n {
        let j = walked(&joints, k);
        let (mk, hk) = sub[k - 1];
        for (dof, c) in j.dofs().iter().zip(crate::algo::dofs(model, k)) {
            let col = match dof {
                WorldDof::Rotation(z) => z.cross(hk - j.o.scale(mk)).scale(inv),
                WorldDof::Translation(z) => z.scale(mk * inv),
            };
            for r in 0..3 {
                jac[r][c] = col.0[r];
            }
        }
    }
    jac.iter().flatten().map(|x| x.id()).collect()
}

/// The centroidal momentum matrix `A_g` (6 × n, row-major, rows `[linear; angular]`):
/// `h_g = A_g(q) v` is the momentum of all moving bodies, the angular part about the
/// centre of mass, world axes (Pinocchio's `computeCentroidalMap`). Column `k` is the
/// momentum of the bodies joint `k` carries when it moves at unit speed: their
/// composite inertia (`crba`'s, in body `k`'s frame) times the joint's axis, rotated
/// into world axes and moved to the centre of mass `c`:
/// `[R_k f; R_k n + (o_k − c) × R_k f]`, `(f, n) = I_k S_k` at body `k`'s origin `o_k`.
pub fn build_centroidal_map(g: &Graph, model: &Model) -> Vec<NodeId> {
    let n = model.dof();
    let all: Vec<usize> = (1..=n).collect();
    let (world, _) = walk(g, model, &all, Walk::Placement);
    let x: Vec<JointTransform<'_>> = (1..=n).map(|j| JointTransform::new(g, model, j)).collect();
    let composite = crate::derivatives::composites(model, &x, (1..=n).map(|i| BodyParams::input(g, i)).collect());
    // The centre of mass from the composites of the bodies on the base.
    let (total, first) = (1..=n)
        .filter(|&i| model.parent(i) == 0)
        .fold((g.zero(), V3::zero(g)), |(m, h), i| {
            let (c, b) = (&composite[i - 1], walked(&world, i));
            (m + c.m, h + b.t.scale(c.m) + b.r.mul_vec(c.h))
        });
    let com = first.scale(g.one() / total);
    let mut a = vec![vec![g.zero(); model.nv()]; 6];
    for k in 1..=n {
        let c = &composite[k - 1];
        let b = walked(&world, k);
        for (s, col) in crate::algo::subspace(g, model, k)
            .into_iter()
            .zip(crate::algo::dofs(model, k))
        {
            // (f, n) = I_k S_k, as crba builds it.
            let f = s.v.scale(c.m) + s.w.cross(c.h);
            let m = c.inertia.mul_vec(s.w) + c.h.cross(s.v);
            let (fw, mw) = (b.r.mul_vec(f), b.r.mul_vec(m));
            let l = mw + (b.t - com).cross(fw);
            for r in 0..3 {
                a[r][col] = fw.0[r];
                a[3 + r][col] = l.0[r];
            }
        }
    }
    a.iter().flatten().map(|x| x.id()).collect()
}

/// `A_g` and its time variation `Ȧ_g(q, v)` (6 × n each, row-major, `A_g` first):
/// `ḣ_g = A_g a + Ȧ_g v` (Pinocchio's `computeCentroidalMapTimeVariation`). `Ȧ_g` is one
/// forward-mode tangent of [`build_centroidal_map`] along `q̇ = v`
/// ([`Graph::tangents`]), so it reuses every node of `A_g`.
pub fn build_centroidal_map_time_variation(g: &Graph, model: &Model) -> Vec<NodeId> {
    let a_g = build_centroidal_map(g, model);
    let dot = time_derivatives(g, model, &a_g);
    a_g.into_iter().chain(dot.iter().map(|x| x.id())).collect()
}

/// A Rust identifier for frame names: `wrist_3_link` → `Wrist3Link`, unique among
/// the frames: where two names would meet (`a`, `A`, `a.`), the later frame's index
/// `k` is appended, and should that be taken too (by a frame `a3`), `_1`, `_2`, …
/// after it, so the names depend only on the frames and their order.
fn variant_names(model: &Model) -> Vec<syn::Ident> {
    let mut taken = std::collections::HashSet::new();
    model
        .frames
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let mut s: String = f
                .name
                .split(|c: char| !c.is_ascii_alphanumeric())
                .filter(|w| !w.is_empty())
                .map(|w| {
                    let mut c = w.chars();
                    let first = c.next().map(|x| x.to_ascii_uppercase());
                    first.into_iter().chain(c).collect::<String>()
                })
                .collect();
            if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) || syn::parse_str::<syn::Ident>(&s).is_err()
            {
                s = format!("Frame{s}");
            }
            if !taken.insert(s.clone()) {
                let base = format!("{s}{k}");
                s = base.clone();
                let mut j = 0;
                while !taken.insert(s.clone()) {
                    j += 1;
                    s = format!("{base}_{j}");
                }
            }
            format_ident!("{}", s)
        })
        .collect()
}

/// The frame enum's name for the robot type `ty`.
pub(crate) fn frame_type(ty: &syn::Ident) -> syn::Ident {
    format_ident!("{}Frame", ty)
}

/// What frames add to the generated code.
pub(crate) struct FrameFns {
    /// The frame enum, outside the robot type's `impl`.
    pub enum_item: TokenStream,
    /// Inherent functions and constants of the robot type, by name.
    pub items: Vec<(String, TokenStream)>,
    /// The bodies of the generated functions ([`emit::Emitted`]), by name.
    pub bodies: Vec<(String, TokenStream)>,
    /// The `dyngen::Frames` methods.
    pub methods: TokenStream,
    /// The `dyngen::Centroidal` methods.
    pub centroidal_methods: TokenStream,
    pub reports: Vec<FnReport>,
}

fn arg(id: u8, name: &'static str, len: usize) -> Arg {
    Arg { id, name, len }
}

/// The frame enum and every frame function of the robot type `ty`.
pub(crate) fn generate(model: &Model, ty: &syn::Ident, sizes: &Sizes, options: &crate::Options) -> FrameFns {
    let (max_statements, above) = (options.max_statements, options.compose_above_nv);
    // Columns, velocities and accelerations go by velocity coordinate.
    let n = sizes.nv;
    let nf = model.frames.len();
    let [n_l, nq_l, nf_l] = [n, sizes.nq, nf].map(emit::usize_lit);
    let fty = frame_type(ty);
    let variants = variant_names(model);
    let home = emit::home(ty);
    let mut items = Vec::new();
    let mut reports = Vec::new();
    let mut bodies = Vec::new();
    // Emits `spec`, reporting its operation count under `report_as`.
    let mut emit_one = |spec: FnSpec<'_>, g: &Graph, report_as: String| {
        let (emitted, mut report) = emit::emit_fn(g, &spec, max_statements, &home);
        report.name = report_as;
        reports.push(report);
        bodies.push((spec.name.to_string(), emitted.body));
        emitted.method
    };
    let q = || arg(ARG_Q, "q", sizes.nq);
    let pose_ret = Record::Pose.ty();
    let assemble_pose = |outs: &[TokenStream]| Record::Pose.build(outs);

    // Per frame: placement, Jacobian, motion; private, dispatched by the enum.
    // The composition of a large tree's Jacobians puts each coordinate's axis in its
    // column, which a leader moving bodies off its own path does not have.
    let large = n > above && !crate::mimic::has_followers(model);
    let mut placement_fns = Vec::new();
    let mut jacobian_fns = Vec::new();
    let mut jacobian_dot_fns = Vec::new();
    let mut motion_fns = Vec::new();
    let mut per_frame = Vec::new();
    for (f, frame) in model.frames.iter().enumerate() {
        let label = &frame.name;
        let (pn, jn, dn, mn) = (
            format!("__frame_placement_{f}"),
            format!("__frame_jacobian_{f}"),
            format!("__frame_jacobian_dot_{f}"),
            format!("__frame_motion_{f}"),
        );
        // The enum's dispatch to them (a large tree's functions use only the Jacobian's).
        let variant = &variants[f];
        let [pi, ji, di, mi] = [&pn, &jn, &dn, &mn].map(|name| format_ident!("{}", name));
        placement_fns.push(quote!(#fty::#variant => Self::#pi(q)));
        jacobian_fns.push(quote!(#fty::#variant => Self::#ji(q, out)));
        jacobian_dot_fns.push(quote!(#fty::#variant => Self::#di(q, v, out)));
        motion_fns.push(quote!(#fty::#variant => Self::#mi(q, v, a)));
        // A large tree takes one frame's placement from all of them (`frame_placements`,
        // below) rather than carry a function per frame.
        let mut t = TokenStream::new();
        if !large {
            let g = Graph::new();
            let outputs = crate::mimic::build(&g, model, &[Block::Plain(12)], |g, model| build_placement(g, model, f));
            let spec = FnSpec {
                name: &pn,
                public: false,
                doc: format!("The placement of frame `{label}`."),
                args: vec![q()],
                ret: pose_ret.clone(),
                output: Output::Return(Box::new(assemble_pose)),
                outputs,
            };
            t.extend(emit_one(spec, &g, format!("frame_placement[{label}]")));
        }

        let g = Graph::new();
        let outputs = crate::mimic::build(&g, model, &[Block::Plain(12), Block::Cols { rows: 6 }], |g, model| {
            build_jacobian(g, model, f)
        });
        let place = move |k: usize| {
            if k < 9 {
                let (r, c) = (emit::usize_lit(k / 3), emit::usize_lit(k % 3));
                quote!(out.placement.rotation[(#r, #c)])
            } else if k < 12 {
                let i = emit::usize_lit(k - 9);
                quote!(out.placement.translation[#i])
            } else if k < 12 + 6 * n {
                let k = emit::usize_lit(k - 12);
                quote!(jacobian[#k])
            } else {
                let k = emit::usize_lit(k - 12 - 6 * n);
                quote!(jacobian_dot[#k])
            }
        };
        let jacobian_view = quote!(let jacobian = out.jacobian.as_flattened_mut(););
        let spec = FnSpec {
            name: &jn,
            public: false,
            doc: format!("The placement and `LOCAL_WORLD_ALIGNED` Jacobian of frame `{label}`."),
            args: vec![q()],
            ret: quote!(::dyngen::FrameJacobian<S, #n_l>),
            output: Output::InPlace {
                place: Box::new(place),
                clear: quote!(*out = ::core::default::Default::default();),
                views: jacobian_view.clone(),
            },
            outputs,
        };
        t.extend(emit_one(spec, &g, format!("frame_jacobian[{label}]")));

        // A large tree composes every frame's `J̇` of the axes of all coordinates
        // (`__frame_axes_time_variation`, below) and takes the motion from it, rather
        // than carry two more functions per frame.
        if large {
            per_frame.push(t);
            continue;
        }
        let g = Graph::new();
        let layout = [Block::Plain(12), Block::Cols { rows: 6 }, Block::Cols { rows: 6 }];
        let outputs = crate::mimic::build(&g, model, &layout, |g, model| {
            build_jacobian_time_variation(g, model, f)
        });
        let spec = FnSpec {
            name: &dn,
            public: false,
            doc: format!("The placement, `LOCAL_WORLD_ALIGNED` Jacobian and its time variation of frame `{label}`."),
            args: vec![q(), arg(ARG_V, "v", n)],
            ret: quote!(::dyngen::FrameJacobianTimeVariation<S, #n_l>),
            output: Output::InPlace {
                place: Box::new(place),
                clear: quote!(*out = ::core::default::Default::default();),
                views: quote! {
                    #jacobian_view
                    let jacobian_dot = out.jacobian_dot.as_flattened_mut();
                },
            },
            outputs,
        };
        t.extend(emit_one(spec, &g, format!("frame_jacobian_time_variation[{label}]")));

        let g = Graph::new();
        let outputs = crate::mimic::build(&g, model, &[Block::Plain(24)], |g, model| build_motion(g, model, f));
        let assemble = |o: &[TokenStream]| {
            let pose = Record::Pose.build(&o[..12]);
            let m = |s: &[TokenStream]| {
                let (l, a) = (&s[..3], &s[3..]);
                quote!(::dyngen::Motion {
                    linear: ::dyngen::nalgebra::Vector3::new(#(#l),*),
                    angular: ::dyngen::nalgebra::Vector3::new(#(#a),*),
                })
            };
            let (v, a) = (m(&o[12..18]), m(&o[18..24]));
            quote!(::dyngen::FrameMotion { placement: #pose, velocity: #v, acceleration: #a })
        };
        let spec = FnSpec {
            name: &mn,
            public: false,
            doc: format!(
                "The placement, velocity and classical acceleration of frame `{label}`,\n`LOCAL_WORLD_ALIGNED`."
            ),
            args: vec![q(), arg(ARG_V, "v", n), arg(ARG_A, "a", n)],
            ret: quote!(::dyngen::FrameMotion<S>),
            output: Output::Return(Box::new(assemble)),
            outputs,
        };
        t.extend(emit_one(spec, &g, format!("frame_motion[{label}]")));
        per_frame.push(t);
    }

    // A large tree's Jacobian time variations, composed at run time of the axes of all
    // coordinates, the placements of all frames and their time derivatives.
    let mut composed = None;
    if large {
        let g = Graph::new();
        let (outputs, rotation) = build_axes_time_variation(&g, model);
        let len = emit::usize_lit(outputs.len());
        let spec = FnSpec {
            name: "__frame_axes_time_variation",
            public: false,
            doc: "Every coordinate's axis and origin and every frame's placement in the world, then\nthe time variations of the axes, origins and frame origins.".to_string(),
            args: vec![q(), arg(ARG_V, "v", n)],
            ret: quote!([S; #len]),
            output: Output::InPlace {
                place: Box::new(|k: usize| {
                    let k = emit::usize_lit(k);
                    quote!(out[#k])
                }),
                clear: quote!(*out = [S::ZERO; #len];),
                views: TokenStream::new(),
            },
            outputs,
        };
        let axes = emit_one(spec, &g, "frame_jacobian_time_variation".to_string());
        let columns = model.frames.iter().map(|frame| {
            let c = path(model, frame.body)
                .into_iter()
                .flat_map(|k| crate::algo::dofs(model, k))
                .map(emit::usize_lit);
            quote!(&[#(#c),*])
        });
        composed = Some((
            quote! {
                /// Whether each velocity coordinate is a rotation (or a translation).
                const __COORDINATE_ROTATES: [bool; #n_l] = [#(#rotation),*];
                /// The columns of each frame's Jacobian that are not zero: the coordinates of
                /// the joints between the base and the frame.
                const __FRAME_COLUMNS: [&'static [usize]; #nf_l] = [#(#columns),*];
                #axes
            },
            len,
        ));
    }

    // All placements at once, and the centre of mass.
    let g = Graph::new();
    let outputs = crate::mimic::build(&g, model, &[Block::Plain(12 * nf)], build_placements);
    let spec = FnSpec {
        name: "frame_placements",
        public: true,
        doc: format!(
            "Every frame's placement in the world at `q` ({n} joint positions), in the order of\n`{fty}::ALL` (`Self::MODEL.frames`): `x_world = rotation · x_frame + translation`."
        ),
        args: vec![q()],
        ret: quote!([::dyngen::Pose<S>; #nf_l]),
        output: Output::Return(Box::new(|outs: &[TokenStream]| {
            let items = outs.chunks(12).map(|c| Record::Pose.build(c));
            quote!([#(#items),*])
        })),
        outputs,
    };
    let placements = emit_one(spec, &g, "frame_placements".to_string());

    let params = || arg(ARG_PARAMS, "params", 10 * sizes.n);
    let g = Graph::new();
    let outputs = crate::mimic::build(&g, model, &[Block::Plain(3)], build_com);
    let spec = FnSpec {
        name: "center_of_mass",
        public: true,
        doc: format!(
            "The centre of mass of all moving bodies in the world, m (Pinocchio's `centerOfMass`\nwithout the base). `q`: {n} joint positions; {}.",
            sizes.params()
        ),
        args: vec![q(), params()],
        ret: quote!([S; 3]),
        output: Output::Return(Box::new(|outs: &[TokenStream]| quote!([#(#outs),*]))),
        outputs,
    };
    let com = emit_one(spec, &g, "center_of_mass".to_string());

    let g = Graph::new();
    let outputs = crate::mimic::build(&g, model, &[Block::Cols { rows: 3 }], build_com_jacobian);
    let spec = FnSpec {
        name: "com_jacobian",
        public: true,
        doc: format!(
            "The Jacobian of the centre of mass (3 × {n}): `ċ = J_c(q) v`, world axes (Pinocchio's\n`jacobianCenterOfMass`). {}.",
            sizes.params()
        ),
        args: vec![q(), params()],
        ret: quote!([[S; #n_l]; 3]),
        output: emit::matrix_output(),
        outputs,
    };
    let com_jacobian = emit_one(spec, &g, "com_jacobian".to_string());

    let g = Graph::new();
    let outputs = crate::mimic::build(&g, model, &[Block::Cols { rows: 6 }], build_centroidal_map);
    let spec = FnSpec {
        name: "centroidal_map",
        public: true,
        doc: format!(
            "The centroidal momentum matrix `A_g(q)` (6 × {n}, rows `[linear; angular]`): `A_g v` is\nthe momentum of the moving bodies, the angular part about their centre of mass,\nworld axes (Pinocchio's `computeCentroidalMap`; `ccrba` computes it with `A_g v`).\n{}.",
            sizes.params()
        ),
        args: vec![q(), params()],
        ret: quote!([[S; #n_l]; 6]),
        output: emit::matrix_output(),
        outputs,
    };
    let centroidal = emit_one(spec, &g, "centroidal_map".to_string());

    let g = Graph::new();
    let layout = [Block::Cols { rows: 6 }; 2];
    let outputs = crate::mimic::build(&g, model, &layout, build_centroidal_map_time_variation);
    let spec = FnSpec {
        name: "centroidal_map_time_variation",
        public: true,
        doc: format!(
            "The centroidal momentum matrix and its time variation (Pinocchio's\n`computeCentroidalMapTimeVariation`): writes `(A_g(q), Ȧ_g(q, v))` to `out`\n(6 × {n} each), so that `ḣ_g = A_g a + Ȧ_g v`, the rate of the centroidal\nmomentum that whole-body controllers constrain. `q, v`: {n} positions and\nvelocities; {}.",
            sizes.params()
        ),
        args: vec![q(), arg(ARG_V, "v", n), params()],
        ret: quote!(([[S; #n_l]; 6], [[S; #n_l]; 6])),
        output: Output::InPlace {
            place: Box::new(move |k: usize| {
                let i = emit::usize_lit(k % (6 * n));
                if k < 6 * n {
                    quote!(map[#i])
                } else {
                    quote!(map_dot[#i])
                }
            }),
            clear: quote!(*out = ([[S::ZERO; #n_l]; 6], [[S::ZERO; #n_l]; 6]);),
            views: quote! {
                let map = out.0.as_flattened_mut();
                let map_dot = out.1.as_flattened_mut();
            },
        },
        outputs,
    };
    let centroidal_dot = emit_one(spec, &g, "centroidal_map_time_variation".to_string());

    let zero_a = quote!(&[S::ZERO; #n_l]);
    let (placement_body, walks) = if large {
        (
            quote!(Self::frame_placements(q)[frame.index()]),
            format!("Taken from [`Self::frame_placements`] (a robot of more than\n{above} velocity coordinates carries no function per frame for it)."),
        )
    } else {
        (
            quote!(match frame { #(#placement_fns,)* }),
            "Walks only the bodies between the\nbase and the frame.".to_string(),
        )
    };
    let dispatch_doc = doc_attrs(&format!(
        "Frame `frame`'s placement in the world at `q` ({n} joint positions):\n`x_world = rotation · x_frame + translation`. {walks}"
    ));
    let (jacobian_dot_body, composed_items, composed_how) = match composed {
        Some((items, len)) => (
            quote! {
                let mut axes = [S::ZERO; #len];
                Self::__frame_axes_time_variation(q, v, &mut axes);
                ::dyngen::__private::frame_jacobian_time_variation_from_axes(
                    &axes, #nf_l, &Self::__COORDINATE_ROTATES, Self::__FRAME_COLUMNS[frame.index()], frame.index(), out,
                );
            },
            items,
            format!(
                "\nComposed of the axes of all coordinates, the placements of all frames and their\ntime variations, computed together (a robot of more than {above} velocity coordinates\ncarries no function per frame for it)."
            ),
        ),
        None => (quote!(match frame { #(#jacobian_dot_fns,)* }), TokenStream::new(), String::new()),
    };
    let jacobian_doc = doc_attrs(&format!(
        "Frame `frame`'s placement and Jacobian (6 × {n}, rows `[linear; angular]`) at `q`, in\n`reference` (Pinocchio's `computeFrameJacobian`). Only the columns of the joints\nbetween the base and the frame are computed; the others are zero. Written to `out`."
    ));
    let jacobian_dot_doc = doc_attrs(&format!(
        "Frame `frame`'s placement, Jacobian `J` and its time variation `J̇(q, v)` (6 × {n} each)\nin `reference` (Pinocchio's `getFrameJacobianTimeVariation`), written to `out`:\n`ẍ = J q̈ + J̇ q̇`. `J̇` is the time derivative of `J` along `q̇ = v`.{composed_how}"
    ));
    let (motion_body, motion_how) = if large {
        (
            quote! {
                let mut jacobians = ::dyngen::FrameJacobianTimeVariation::<S, #n_l>::default();
                let reference = ::dyngen::ReferenceFrame::LocalWorldAligned;
                Self::frame_jacobian_time_variation(q, v, frame, reference, &mut jacobians);
                ::dyngen::__private::frame_motion(&jacobians, v, a)
            },
            format!(
                " From the frame's\n`LOCAL_WORLD_ALIGNED` `J` and `J̇`: `J v` and `J a + J̇ v` (a robot of more than {above}\nvelocity coordinates carries no function per frame for it)."
            ),
        )
    } else {
        (quote!(match frame { #(#motion_fns,)* }), String::new())
    };
    let motion_doc = doc_attrs(&format!(
        "Frame `frame`'s placement, velocity and classical acceleration at `(q, v, a)`,\n`LOCAL_WORLD_ALIGNED`; `FrameMotion::velocity_in` and\n`FrameMotion::classical_acceleration_in` express them in another reference frame.{motion_how}",
    ));
    let velocity_doc =
        doc_attrs("Frame `frame`'s velocity at `(q, v)` in `reference` (Pinocchio's `getFrameVelocity`):\n`J(q) v`.");
    let acc_doc = doc_attrs(
        "Frame `frame`'s classical acceleration at `(q, v, a)` in `reference` (Pinocchio's\n`getFrameClassicalAcceleration`). With `a = 0` it is the drift `J̇(q, v)·v` of\n`ẍ = J q̈ + J̇ q̇`, the term operational-space and task-space controllers subtract.",
    );
    let nframes_doc = doc_attrs(&format!(
        "Number of frames: every link of the description and every declared frame (`{fty}`)."
    ));
    items.push((
        "frames".to_string(),
        quote! {
            #nframes_doc
            pub const NFRAMES: usize = #nf_l;
            #dispatch_doc
            #[inline]
            pub fn frame_placement<S: ::dyngen::Scalar>(q: &[S; #nq_l], frame: #fty) -> ::dyngen::Pose<S> {
                #placement_body
            }
            #jacobian_doc
            #[inline]
            pub fn frame_jacobian<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], frame: #fty, reference: ::dyngen::ReferenceFrame, out: &mut ::dyngen::FrameJacobian<S, #n_l>,
            ) {
                match frame { #(#jacobian_fns,)* }
                ::dyngen::__private::express_jacobian(out, reference);
            }
            #jacobian_dot_doc
            #[inline]
            pub fn frame_jacobian_time_variation<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], v: &[S; #n_l], frame: #fty, reference: ::dyngen::ReferenceFrame,
                out: &mut ::dyngen::FrameJacobianTimeVariation<S, #n_l>,
            ) {
                #jacobian_dot_body
                ::dyngen::__private::express_jacobian_time_variation(out, v, reference);
            }
            #motion_doc
            #[inline]
            pub fn frame_motion<S: ::dyngen::Scalar>(q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], frame: #fty) -> ::dyngen::FrameMotion<S> {
                #motion_body
            }
            #velocity_doc
            #[inline]
            pub fn frame_velocity<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], v: &[S; #n_l], frame: #fty, reference: ::dyngen::ReferenceFrame,
            ) -> ::dyngen::Motion<S> {
                Self::frame_motion(q, v, #zero_a, frame).velocity_in(reference)
            }
            #acc_doc
            #[inline]
            pub fn frame_classical_acceleration<S: ::dyngen::Scalar>(
                q: &[S; #nq_l], v: &[S; #n_l], a: &[S; #n_l], frame: #fty, reference: ::dyngen::ReferenceFrame,
            ) -> ::dyngen::Motion<S> {
                Self::frame_motion(q, v, a, frame).classical_acceleration_in(reference)
            }
            #placements
            #com
            #com_jacobian
            #centroidal
            #centroidal_dot
            #composed_items
            #(#per_frame)*
        },
    ));

    let names: Vec<&str> = model.frames.iter().map(|f| f.name.as_str()).collect();
    let frame_bodies = model.frames.iter().map(|f| emit::usize_lit(f.body));
    let indices = (0..nf).map(emit::usize_lit);
    let variant_docs = model.frames.iter().map(|f| {
        let what = match f.body {
            0 => "on the base".to_string(),
            b if model.bodies[b - 1].name == f.name => format!("body {b}'s own frame"),
            b => format!("on body {b} (`{}`)", model.bodies[b - 1].name),
        };
        format!(" Frame `{}`, {what}.", f.name)
    });
    let enum_doc = doc_attrs(&format!(
        "The frames of [`{ty}`]: every link of the description (links on fixed joints\nincluded) and every frame the description declares, in the order of\n`{ty}::MODEL.frames`."
    ));
    let index_arms = variants
        .iter()
        .zip(indices.clone())
        .map(|(v, i)| quote!(#fty::#v => #i));
    let from_index_arms = variants.iter().zip(indices).map(|(v, i)| quote!(#i => Some(#fty::#v)));
    let enum_item = quote! {
        #enum_doc
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[allow(non_camel_case_types)]
        pub enum #fty {
            #(#[doc = #variant_docs] #variants,)*
        }

        #[allow(clippy::all)]
        impl #fty {
            /// Every frame, in index order.
            pub const ALL: [#fty; #nf_l] = [#(#fty::#variants),*];
            /// Frame names (the description's link names), in index order.
            pub const NAMES: [&'static str; #nf_l] = [#(#names),*];
            /// The body each frame is attached to (0 = base), in index order.
            pub const BODIES: [usize; #nf_l] = [#(#frame_bodies),*];

            /// The frame's index in `ALL` and in the robot's `MODEL.frames`.
            pub const fn index(self) -> usize {
                match self { #(#index_arms,)* }
            }

            /// The frame at `index`, if there is one.
            pub const fn from_index(index: usize) -> ::core::option::Option<#fty> {
                match index { #(#from_index_arms,)* _ => None }
            }

            /// The frame named `name` (a link name of the description), if there is one.
            pub fn from_name(name: &str) -> ::core::option::Option<#fty> {
                Self::NAMES.iter().position(|n| *n == name).and_then(Self::from_index)
            }

            /// The frame's name.
            pub const fn name(self) -> &'static str {
                Self::NAMES[self.index()]
            }

            /// The body the frame is attached to (0 = base).
            pub const fn body(self) -> usize {
                Self::BODIES[self.index()]
            }
        }
    };
    let methods = quote! {
        fn frame_placement<S: ::dyngen::Scalar>(q: &[S], frame: usize) -> ::core::option::Option<::dyngen::Pose<S>> {
            use ::dyngen::__private::as_array;
            Some(Self::frame_placement(as_array(q, "q"), #fty::from_index(frame)?))
        }
        fn frame_jacobian<S: ::dyngen::Scalar>(
            q: &[S], frame: usize, reference: ::dyngen::ReferenceFrame, jacobian: &mut [S],
        ) -> ::core::option::Option<::dyngen::Pose<S>> {
            use ::dyngen::__private::{as_array, as_rows_mut};
            let frame = #fty::from_index(frame)?;
            let mut j = ::dyngen::FrameJacobian::<S, #n_l>::default();
            Self::frame_jacobian(as_array(q, "q"), frame, reference, &mut j);
            *as_rows_mut::<S, #n_l, 6>(jacobian, "jacobian") = j.jacobian;
            Some(j.placement)
        }
        fn frame_jacobian_time_variation<S: ::dyngen::Scalar>(
            q: &[S], v: &[S], frame: usize, reference: ::dyngen::ReferenceFrame, jacobian: &mut [S], jacobian_dot: &mut [S],
        ) -> ::core::option::Option<::dyngen::Pose<S>> {
            use ::dyngen::__private::{as_array, as_rows_mut};
            let frame = #fty::from_index(frame)?;
            let mut j = ::dyngen::FrameJacobianTimeVariation::<S, #n_l>::default();
            Self::frame_jacobian_time_variation(as_array(q, "q"), as_array(v, "v"), frame, reference, &mut j);
            *as_rows_mut::<S, #n_l, 6>(jacobian, "jacobian") = j.jacobian;
            *as_rows_mut::<S, #n_l, 6>(jacobian_dot, "jacobian_dot") = j.jacobian_dot;
            Some(j.placement)
        }
        fn frame_motion<S: ::dyngen::Scalar>(q: &[S], v: &[S], a: &[S], frame: usize) -> ::core::option::Option<::dyngen::FrameMotion<S>> {
            use ::dyngen::__private::as_array;
            Some(Self::frame_motion(as_array(q, "q"), as_array(v, "v"), as_array(a, "a"), #fty::from_index(frame)?))
        }
    };
    let centroidal_methods = quote! {
        fn center_of_mass<S: ::dyngen::Scalar>(q: &[S], params: &[S]) -> [S; 3] {
            use ::dyngen::__private::as_array;
            Self::center_of_mass(as_array(q, "q"), as_array(params, "params"))
        }
        fn centroidal_map<S: ::dyngen::Scalar>(q: &[S], params: &[S], a_g: &mut [S]) {
            use ::dyngen::__private::{as_array, as_rows_mut};
            Self::centroidal_map(as_array(q, "q"), as_array(params, "params"), as_rows_mut::<S, #n_l, 6>(a_g, "a_g"));
        }
        fn centroidal_map_time_variation<S: ::dyngen::Scalar>(q: &[S], v: &[S], params: &[S], a_g: &mut [S], a_g_dot: &mut [S]) {
            use ::dyngen::__private::{as_array, as_rows_mut};
            let zero = [S::ZERO; #n_l];
            let mut both = ([zero; 6], [zero; 6]);
            Self::centroidal_map_time_variation(as_array(q, "q"), as_array(v, "v"), as_array(params, "params"), &mut both);
            *as_rows_mut::<S, #n_l, 6>(a_g, "a_g") = both.0;
            *as_rows_mut::<S, #n_l, 6>(a_g_dot, "a_g_dot") = both.1;
        }
        fn com_jacobian<S: ::dyngen::Scalar>(q: &[S], params: &[S], jacobian: &mut [S]) {
            use ::dyngen::__private::{as_array, as_rows_mut};
            Self::com_jacobian(as_array(q, "q"), as_array(params, "params"), as_rows_mut::<S, #n_l, 3>(jacobian, "jacobian"));
        }
    };
    FrameFns {
        enum_item,
        items,
        bodies,
        methods,
        centroidal_methods,
        reports,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_model::{Frame, Placement};

    /// Link names become distinct Rust identifiers, whatever characters they hold.
    #[test]
    fn frame_names_become_distinct_identifiers() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../robots/ur5/ur5.urdf");
        let mut model = dyngen_model::load_urdf(&path).expect("the UR5 loads");
        model.frames.clear();
        for name in [
            "wrist_3_link",
            "3d-camera",
            "self",
            "link_1",
            "link1",
            "Link-1",
            "",
            "ü",
        ] {
            model.frames.push(Frame {
                name: name.to_string(),
                body: 0,
                placement: Placement::IDENTITY,
            });
        }
        let names: Vec<String> = variant_names(&model).iter().map(|i| i.to_string()).collect();
        assert_eq!(
            names,
            [
                "Wrist3Link",
                "Frame3dCamera",
                "FrameSelf",
                "Link1",
                "Link14",
                "Link15",
                "Frame",
                "Frame7"
            ]
        );
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len());
    }

    /// A name with a carriage return or a text-direction control would make the
    /// generated documentation lie or not compile: the front end refuses it, naming
    /// the file and line, and nothing is generated.
    #[test]
    fn control_characters_in_names_stop_generation() {
        let dir = std::env::temp_dir().join(format!("dyngen-frames-names-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (k, bad) in ["a&#13;b", "a\u{202e}b", "a\rb"].iter().enumerate() {
            let urdf = dir.join(format!("bad{k}.urdf"));
            let text = format!(
                "<robot name=\"r\">\n<link name=\"base\"/>\n<link name=\"{bad}\"><inertial><mass value=\"1\"/>\
                 <inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n\
                 <joint name=\"j\" type=\"continuous\"><parent link=\"base\"/><child link=\"{bad}\"/></joint>\n\
                 </robot>"
            );
            std::fs::write(&urdf, text).unwrap();
            let err = crate::Config::new()
                .out_dir(&dir)
                .compile_urdf(&urdf, "Bad")
                .unwrap_err();
            let message = err.to_string();
            assert!(message.starts_with(&format!("{}:3: ", urdf.display())), "{message}");
            assert!(
                message.contains("a name must be printable text on one line"),
                "{message}"
            );
            assert!(!dir.join(format!("bad{k}.rs")).exists());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Names that differ only in case or punctuation, where the numeric suffix of one
    /// would meet another's name (`a3` → `A3`, then `a.` → `A` + 3), still give
    /// distinct identifiers, and the generated code parses.
    #[test]
    fn colliding_frame_names_get_distinct_identifiers() {
        let link = |name: &str| {
            format!(
                "<link name=\"{name}\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" iyy=\"0.1\" izz=\"0.1\" \
                 ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"
            )
        };
        let names = ["a3", "a", "A", "a.", "A3", "a_3", "A3_1"];
        let mut urdf = String::from("<robot name=\"r\"><link name=\"base\"/>");
        let mut parent = "base";
        for (k, name) in names.iter().enumerate() {
            urdf += &link(name);
            // One moving joint, so that generation is quick; fixed links are frames too.
            let kind = if k == 0 { "continuous" } else { "fixed" };
            urdf += &format!(
                "<joint name=\"j{k}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{name}\"/>\
                 <axis xyz=\"0 0 1\"/><origin xyz=\"0 0 0.1\"/></joint>"
            );
            parent = name;
        }
        urdf += "</robot>";
        let model = dyngen_model::parse_urdf(&urdf).expect("valid URDF");
        let variants: Vec<String> = variant_names(&model).iter().map(|i| i.to_string()).collect();
        let mut unique = variants.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), variants.len(), "{variants:?}");
        assert_eq!(&variants[..5], ["Base", "A3", "A", "A3_1", "A4"], "{variants:?}");

        let bases = crate::base::analyse_model(&model);
        let code = crate::generate(&model, "Colliding", &bases, &crate::Options::default()).file("colliding.urdf");
        let file = syn::parse_file(&code).expect("the generated code parses");
        let frame_enum = file
            .items
            .iter()
            .find_map(|item| match item {
                syn::Item::Enum(e) if e.ident == "CollidingFrame" => Some(e),
                _ => None,
            })
            .expect("the frame enum");
        let mut found: Vec<String> = frame_enum.variants.iter().map(|v| v.ident.to_string()).collect();
        assert_eq!(found, variants);
        found.sort();
        found.dedup();
        assert_eq!(found.len(), model.frames.len());
    }
}
