//! The joint torque regressor in plain `f64`: `τ = Y(q, v, a) π`, by the classical
//! (Luh–Walker–Paul) Newton–Euler recursion on a checked [`Model`].
//!
//! Forward pass, body frames, body 0 the base with `ω₀ = ω̇₀ = 0` and `a₀ = −g` (so
//! gravity comes in as an acceleration of the base). Joint `i` maps body `i`'s frame
//! into its parent's by the rotation `R_i` and the translation `p_i` (its origin, plus
//! `R_i z_i q_i` for a prismatic joint), with `z_i` its unit axis in body `i`'s frame:
//!
//! ```text
//! revolute:  ω_i = R_iᵀ ω_λ + z_i v_i
//!            ω̇_i = R_iᵀ ω̇_λ + (R_iᵀ ω_λ) × z_i v_i + z_i a_i
//!            a_i = R_iᵀ (a_λ + ω̇_λ × p_i + ω_λ × (ω_λ × p_i))
//! prismatic: ω_i = R_iᵀ ω_λ,  ω̇_i = R_iᵀ ω̇_λ
//!            a_i = R_iᵀ (a_λ + ω̇_λ × p_i + ω_λ × (ω_λ × p_i)) + 2 ω_i × z_i v_i + z_i a_i
//! ```
//!
//! With `π_i = [m, h, I]` (`h = m c`, `I` about the body origin), the net wrench on
//! body `i` about its origin is linear in `π_i`:
//!
//! ```text
//! f_i = m a_i + ω̇_i × h + ω_i × (ω_i × h)
//! n_i = I ω̇_i + ω_i × (I ω_i) + h × a_i
//! ```
//!
//! Column `k` of body `i`'s wrench regressor is that wrench with `π_i = e_k`. Joint `j`
//! carries the wrenches of every body it supports, moved towards the base one joint at
//! a time (`f ← R f`, `n ← R n + p × R f`), and `τ_j = z_jᵀ n` (revolute) or `z_jᵀ f`
//! (prismatic).

use crate::math::{self, Mat3, Vec3};
use crate::principal::PrincipalFrame;
use crate::{JointKind, Model};
use std::fmt;

/// Standard parameters per body: `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`.
pub const STANDARD_PER_BODY: usize = 10;
/// Principal parameters per body: `θ = (m, J1, J2, J3)`.
pub const PRINCIPAL_PER_BODY: usize = 4;

/// A state that does not fit the model, or a model that is not a tree.
#[derive(Clone, Debug, PartialEq)]
pub enum RegressorError {
    /// The model's fields were edited into something that is not a tree in regular
    /// labelling (a loaded model always is one).
    Tree(dyngen_algo::TreeError),
    /// `argument` (`"q"`, `"v"` or `"a"`) has `found` entries; the model needs
    /// `expected` (`nq` positions for `q`, `nv` velocities for `v` and `a`).
    Length {
        argument: &'static str,
        expected: usize,
        found: usize,
    },
}

impl fmt::Display for RegressorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RegressorError::Tree(e) => write!(f, "{e}"),
            RegressorError::Length {
                argument,
                expected,
                found,
            } => {
                let what = if *argument == "q" {
                    "position coordinates"
                } else {
                    "velocity coordinates"
                };
                write!(f, "`{argument}` has {found} entries; the model has {expected} {what}")
            }
        }
    }
}

impl std::error::Error for RegressorError {}

/// The joint torque regressor `Y(q, v, a)`: `n` rows of `10 n` numbers with
/// `τ = Y π` for the standard parameters `π` of every body (body 1 first, each in
/// Pinocchio's order `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, inertia
/// about the body-frame origin, as [`Model::standard_params`]), gravity from
/// `model.gravity`. Entry `(j, 10(i−1)+k)` is zero unless joint `j` supports body `i`.
/// The formulas are in the module docs.
pub fn joint_torque_regressor(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Result<Vec<Vec<f64>>, RegressorError> {
    check_state(model, q, v, a)?;
    Ok(torque_regressor(model, q, v, a))
}

/// The principal-parameter regressor `Y_θ(q, v, a) = Y(q, v, a) · blkdiag(P_1, …, P_n)`:
/// `n` rows of `4 n` numbers with `τ = Y_θ θ`, `θ_i = (m, J1, J2, J3)` and `P_i` the
/// constant 10 × 4 matrix of body `i`'s nominal [`PrincipalFrame`] (`π_i = P_i θ_i`).
pub fn principal_regressor(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Result<Vec<Vec<f64>>, RegressorError> {
    check_state(model, q, v, a)?;
    Ok(principal_from_standard(model, &torque_regressor(model, q, v, a)))
}

/// Inverse dynamics with the model's own (nominal) parameters, `τ = M(q) a + h(q, v)`
/// (`dyngen_algo::rnea`).
pub fn inverse_dynamics(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Result<Vec<f64>, RegressorError> {
    check_state(model, q, v, a)?;
    let body = model.multibody().map_err(RegressorError::Tree)?;
    let mut tau = vec![0.0; model.nv()];
    dyngen_algo::rnea(
        &body,
        &mut dyngen_algo::Workspace::new(&body, ()),
        q,
        v,
        a,
        &body.params,
        &mut tau,
    );
    Ok(tau)
}

/// The joint-space mass matrix `M(q)` of the model's own parameters, as rows
/// (`dyngen_algo::crba`).
pub fn mass_matrix(model: &Model, q: &[f64]) -> Result<Vec<Vec<f64>>, RegressorError> {
    let zero = vec![0.0; model.nv()];
    check_state(model, q, &zero, &zero)?;
    let body = model.multibody().map_err(RegressorError::Tree)?;
    let n = model.nv();
    let mut m = vec![0.0; n * n];
    dyngen_algo::crba(
        &body,
        &mut dyngen_algo::Workspace::new(&body, ()),
        q,
        &body.params,
        &mut m,
    );
    Ok(m.chunks(n).map(<[f64]>::to_vec).collect())
}

fn check_state(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Result<(), RegressorError> {
    for (argument, x, expected) in [("q", q, model.nq()), ("v", v, model.nv()), ("a", a, model.nv())] {
        if x.len() != expected {
            return Err(RegressorError::Length {
                argument,
                expected,
                found: x.len(),
            });
        }
    }
    Ok(())
}

/// `Y · blkdiag(P_i)`, skipping the blocks that are structurally zero.
pub(crate) fn principal_from_standard(model: &Model, y: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = model.dof();
    let p: Vec<[[f64; 4]; 10]> = model
        .bodies
        .iter()
        .map(|b| PrincipalFrame::of(&b.inertial).p_matrix())
        .collect();
    y.iter()
        .map(|row| {
            let mut out = vec![0.0; PRINCIPAL_PER_BODY * n];
            for (i, pi) in p.iter().enumerate() {
                for c in 0..PRINCIPAL_PER_BODY {
                    out[PRINCIPAL_PER_BODY * i + c] = (0..STANDARD_PER_BODY)
                        .map(|k| row[STANDARD_PER_BODY * i + k] * pi[k][c])
                        .sum();
                }
            }
            out
        })
        .collect()
}

/// Where a body is and how it moves: its joint's placement at `q` and the body's
/// angular velocity, angular acceleration and origin acceleration (gravity included),
/// in the body's own frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BodyMotion {
    /// Body frame → parent frame.
    pub rotation: Mat3,
    pub translation: Vec3,
    pub omega: Vec3,
    pub omega_dot: Vec3,
    pub accel: Vec3,
}

/// Joint `j`'s placement at `q` (body frame → parent frame) and its relative
/// motion in the body frame: angular and linear velocity, angular and linear
/// acceleration, `(vq_w, vq_v, aq_w, aq_v)`.
pub(crate) fn joint_state(model: &Model, j: usize, q: &[f64], v: &[f64], a: &[f64]) -> (Mat3, Vec3, [Vec3; 4]) {
    let joint = &model.joints[j - 1];
    let (qo, vo) = (model.q_offset(j), model.v_offset(j));
    let origin = &joint.origin;
    let z = joint.axis;
    let v3 = |x: &[f64], o: usize| [x[o], x[o + 1], x[o + 2]];
    let zero = [0.0; 3];
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => (
            math::mat_mul(&origin.rotation, &axis_rotation(&z, q[qo])),
            origin.translation,
            [math::scale(v[vo], &z), zero, math::scale(a[vo], &z), zero],
        ),
        JointKind::Prismatic => {
            let slide = math::mat_vec(&origin.rotation, &math::scale(q[qo], &z));
            (
                origin.rotation,
                math::add(&origin.translation, &slide),
                [zero, math::scale(v[vo], &z), zero, math::scale(a[vo], &z)],
            )
        }
        JointKind::Spherical => (
            math::mat_mul(&origin.rotation, &quaternion_xyzw(&q[qo..qo + 4])),
            origin.translation,
            [v3(v, vo), zero, v3(a, vo), zero],
        ),
        JointKind::FreeFlyer => {
            let slide = math::mat_vec(&origin.rotation, &v3(q, qo));
            (
                math::mat_mul(&origin.rotation, &quaternion_xyzw(&q[qo + 3..qo + 7])),
                math::add(&origin.translation, &slide),
                [v3(v, vo + 3), v3(v, vo), v3(a, vo + 3), v3(a, vo)],
            )
        }
        JointKind::Planar => {
            let (e1, e2) = math::plane_basis(&z);
            let in_plane = |x: &[f64], o: usize| math::add(&math::scale(x[o], &e1), &math::scale(x[o + 1], &e2));
            let slide = math::mat_vec(&origin.rotation, &in_plane(q, qo));
            (
                math::mat_mul(&origin.rotation, &axis_rotation(&z, q[qo + 2])),
                math::add(&origin.translation, &slide),
                [
                    math::scale(v[vo + 2], &z),
                    in_plane(v, vo),
                    math::scale(a[vo + 2], &z),
                    in_plane(a, vo),
                ],
            )
        }
    }
}

/// The rotation of a quaternion stored as Pinocchio stores it, `[x, y, z, w]`
/// (not normalised: a configuration is expected to hold a unit quaternion).
pub fn quaternion_xyzw(q: &[f64]) -> Mat3 {
    math::quaternion_to_matrix([q[3], q[0], q[1], q[2]])
}

/// The forward pass of the module docs, body 1 first, for any joint: with the
/// joint's relative velocity `(ω_q, v_q)` and acceleration `(ω̇_q, a_q)` in body axes,
/// `ω = ω_in + ω_q`, `ω̇ = ω̇_in + ω̇_q + ω_in × ω_q`, and the origin's acceleration
/// `a = a_in + a_q + 2 ω_in × v_q + ω_q × v_q`. Lengths are the caller's to check.
pub(crate) fn forward(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<BodyMotion> {
    let mut out: Vec<BodyMotion> = Vec::with_capacity(model.dof());
    for (k, joint) in model.joints.iter().enumerate() {
        let (w_p, wd_p, a_p) = match joint.parent {
            0 => ([0.0; 3], [0.0; 3], math::scale(-1.0, &model.gravity)),
            p => (out[p - 1].omega, out[p - 1].omega_dot, out[p - 1].accel),
        };
        let (rotation, translation, [vq_w, vq_v, aq_w, aq_v]) = joint_state(model, k + 1, q, v, a);
        let rt = math::transpose(&rotation);
        let p = translation;
        let carried = math::add(&math::add(&a_p, &cross(&wd_p, &p)), &cross(&w_p, &cross(&w_p, &p)));
        let w_in = math::mat_vec(&rt, &w_p);
        let wd_in = math::mat_vec(&rt, &wd_p);
        let accel_in = math::mat_vec(&rt, &carried);
        let coriolis = math::add(&math::scale(2.0, &cross(&w_in, &vq_v)), &cross(&vq_w, &vq_v));
        out.push(BodyMotion {
            rotation,
            translation,
            omega: math::add(&w_in, &vq_w),
            omega_dot: math::add(&math::add(&wd_in, &cross(&w_in, &vq_w)), &aq_w),
            accel: math::add(&math::add(&accel_in, &coriolis), &aq_v),
        });
    }
    out
}

/// Joint `j`'s rows of `τ = Sᵀ [f; n]` for the wrench `(f, n)` in its body frame:
/// one for a joint with an axis, `n` for a ball joint, `[f; n]` for a free flyer, the
/// two in-plane forces and the torque about the normal for a planar joint.
pub(crate) fn joint_rows(model: &Model, j: usize, f: &Vec3, n: &Vec3) -> Vec<f64> {
    let joint = &model.joints[j - 1];
    match joint.kind {
        JointKind::Revolute | JointKind::Continuous => vec![math::dot(&joint.axis, n)],
        JointKind::Prismatic => vec![math::dot(&joint.axis, f)],
        JointKind::Spherical => n.to_vec(),
        JointKind::FreeFlyer => f.iter().chain(n).copied().collect(),
        JointKind::Planar => {
            let (e1, e2) = math::plane_basis(&joint.axis);
            vec![math::dot(&e1, f), math::dot(&e2, f), math::dot(&joint.axis, n)]
        }
    }
}

/// The net wrench `(f, n)` on a body about its origin for standard parameters `pi`
/// (linear in `pi`; see the module docs).
fn body_wrench(m: &BodyMotion, pi: &[f64; 10]) -> (Vec3, Vec3) {
    let mass = pi[0];
    let h = [pi[1], pi[2], pi[3]];
    let inertia = [[pi[4], pi[5], pi[7]], [pi[5], pi[6], pi[8]], [pi[7], pi[8], pi[9]]];
    let (w, wd) = (&m.omega, &m.omega_dot);
    let f = math::add(
        &math::add(&math::scale(mass, &m.accel), &cross(wd, &h)),
        &cross(w, &cross(w, &h)),
    );
    let n = math::add(
        &math::add(&math::mat_vec(&inertia, wd), &cross(w, &math::mat_vec(&inertia, w))),
        &cross(&h, &m.accel),
    );
    (f, n)
}

/// The torque regressor of the module docs; lengths are the caller's to check.
/// `O(n · depth)` wrenches carried; the velocity offsets are taken once.
pub(crate) fn torque_regressor(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<Vec<f64>> {
    let n = model.dof();
    let motion = forward(model, q, v, a);
    let offsets: Vec<usize> = model
        .joints
        .iter()
        .scan(0, |o, j| {
            let here = *o;
            *o += j.kind.nv();
            Some(here)
        })
        .collect();
    let mut y = vec![vec![0.0; STANDARD_PER_BODY * n]; model.nv()];
    for i in 1..=n {
        for k in 0..STANDARD_PER_BODY {
            let mut unit = [0.0; 10];
            unit[k] = 1.0;
            let (mut f, mut m) = body_wrench(&motion[i - 1], &unit);
            let col = STANDARD_PER_BODY * (i - 1) + k;
            let mut j = i;
            while j != 0 {
                let joint = &model.joints[j - 1];
                let row = offsets[j - 1];
                match joint.kind {
                    JointKind::Revolute | JointKind::Continuous => y[row][col] = math::dot(&joint.axis, &m),
                    JointKind::Prismatic => y[row][col] = math::dot(&joint.axis, &f),
                    _ => {
                        for (r, x) in joint_rows(model, j, &f, &m).into_iter().enumerate() {
                            y[row + r][col] = x;
                        }
                    }
                }
                let (r, p) = (&motion[j - 1].rotation, &motion[j - 1].translation);
                f = math::mat_vec(r, &f);
                m = math::add(&math::mat_vec(r, &m), &cross(p, &f));
                j = joint.parent;
            }
        }
    }
    y
}

fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Rotation by `angle` about the unit `axis` (Rodrigues): `E + sin S(u) + (1 − cos) S(u)²`.
fn axis_rotation(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = *axis;
    [
        [c + t * x * x, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, c + t * z * z],
    ]
}

/// The robots with a Pinocchio fixture (`tests/fixtures/<name>.json`) and their
/// URDF, relative to the workspace root.
#[cfg(test)]
pub(crate) const PINOCCHIO_FIXTURES: [(&str, &str); 7] = [
    ("ur5", "robots/ur5/ur5.urdf"),
    ("puma560", "robots/puma560/puma560.urdf"),
    ("panda", "robots/panda/panda.urdf"),
    ("gripper_arm", "robots/gripper_arm/gripper_arm.urdf"),
    ("planar2", "tests/fixtures/planar2.urdf"),
    ("paper6", "tests/fixtures/paper6.urdf"),
    ("tree12", "tests/fixtures/tree12.urdf"),
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::sample_states;
    use crate::Inertial;

    /// Inverse dynamics written another way: each body's wrench about its centre of
    /// mass from its mass properties, shifted to the origin, and the children's
    /// wrenches summed into the parent leaf first.
    fn rnea(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
        let n = model.dof();
        let motion = forward(model, q, v, a);
        let mut f = vec![[0.0; 3]; n];
        let mut m = vec![[0.0; 3]; n];
        for (i, (body, mo)) in model.bodies.iter().zip(&motion).enumerate() {
            let Inertial { mass, com: c, inertia } = body.inertial;
            let (w, wd) = (&mo.omega, &mo.omega_dot);
            let a_c = math::add(&math::add(&mo.accel, &cross(wd, &c)), &cross(w, &cross(w, &c)));
            f[i] = math::scale(mass, &a_c);
            let about_c = math::add(&math::mat_vec(&inertia, wd), &cross(w, &math::mat_vec(&inertia, w)));
            m[i] = math::add(&about_c, &cross(&c, &f[i]));
        }
        let mut tau = vec![0.0; n];
        for j in (1..=n).rev() {
            let joint = &model.joints[j - 1];
            tau[j - 1] = math::dot(
                &joint.axis,
                if joint.kind.is_revolute() { &m[j - 1] } else { &f[j - 1] },
            );
            if joint.parent != 0 {
                let (r, p) = (&motion[j - 1].rotation, &motion[j - 1].translation);
                let fp = math::mat_vec(r, &f[j - 1]);
                let mp = math::add(&math::mat_vec(r, &m[j - 1]), &cross(p, &fp));
                let k = joint.parent - 1;
                f[k] = math::add(&f[k], &fp);
                m[k] = math::add(&m[k], &mp);
            }
        }
        tau
    }

    fn robot(path: &str) -> Model {
        let file = format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file}: {e}"));
        crate::parse_urdf(&text).unwrap_or_else(|e| panic!("{file}: {e}"))
    }

    const URDFS: [&str; 7] = [
        "robots/ur5/ur5.urdf",
        "robots/puma560/puma560.urdf",
        "robots/panda/panda.urdf",
        "robots/gripper_arm/gripper_arm.urdf",
        "tests/fixtures/planar2.urdf",
        "tests/fixtures/paper6.urdf",
        "tests/fixtures/tree12.urdf",
    ];

    fn mat_vec_rows(y: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
        y.iter().map(|r| r.iter().zip(x).map(|(a, b)| a * b).sum()).collect()
    }

    fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        assert_eq!(a.len(), b.len(), "{what}");
        let scale = b.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol * scale, "{what}: {a:?} vs {b:?}");
        }
    }

    #[test]
    fn regressor_times_params_is_inverse_dynamics() {
        for path in URDFS {
            let model = robot(path);
            let pi = model.standard_params();
            for s in sample_states(&model, 25, 11) {
                let y = joint_torque_regressor(&model, &s.q, &s.v, &s.a).unwrap();
                assert_close(&mat_vec_rows(&y, &pi), &rnea(&model, &s.q, &s.v, &s.a), 1e-12, path);
            }
        }
    }

    #[test]
    fn principal_regressor_times_theta_is_inverse_dynamics() {
        for path in URDFS {
            let model = robot(path);
            let theta = crate::principal_params(&model);
            for s in sample_states(&model, 10, 12) {
                let y = principal_regressor(&model, &s.q, &s.v, &s.a).unwrap();
                assert_eq!(y[0].len(), 4 * model.dof());
                assert_close(&mat_vec_rows(&y, &theta), &rnea(&model, &s.q, &s.v, &s.a), 1e-12, path);
            }
        }
    }

    #[test]
    fn wrong_lengths_are_errors() {
        let model = robot("robots/ur5/ur5.urdf");
        let ok = vec![0.0; 6];
        assert_eq!(
            joint_torque_regressor(&model, &ok, &[0.0; 5], &ok),
            Err(RegressorError::Length {
                argument: "v",
                expected: 6,
                found: 5
            })
        );
        let e = principal_regressor(&model, &ok, &ok, &[0.0; 7]).unwrap_err();
        assert_eq!(e.to_string(), "`a` has 7 entries; the model has 6 velocity coordinates");
    }

    /// Pinocchio's `tau` and `Y` for each fixture sample, with the fixture's gravity.
    #[test]
    fn matches_pinocchio_fixtures() {
        for (name, path) in crate::regressor::PINOCCHIO_FIXTURES {
            let mut model = robot(path);
            let file = format!("{}/../tests/fixtures/{name}.json", env!("CARGO_MANIFEST_DIR"));
            let text = std::fs::read_to_string(&file).unwrap();
            let fx: serde_json::Value = serde_json::from_str(&text).unwrap();
            let vec = |v: &serde_json::Value| -> Vec<f64> {
                v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
            };
            let g = vec(&fx["gravity"]);
            model.gravity = [g[0], g[1], g[2]];
            let names: Vec<&str> = fx["model"]["joint_names"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_str().unwrap())
                .collect();
            let ours: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
            assert_eq!(ours, names, "{name}: joint order");
            let samples = fx["samples"].as_array().unwrap();
            assert!(!samples.is_empty());
            for s in samples {
                let (q, v, a) = (vec(&s["q"]), vec(&s["v"]), vec(&s["a"]));
                let y = joint_torque_regressor(&model, &q, &v, &a).unwrap();
                let y_pin: Vec<Vec<f64>> = s["Y"].as_array().unwrap().iter().map(vec).collect();
                for (r, (ours, theirs)) in y.iter().zip(&y_pin).enumerate() {
                    assert_close(ours, theirs, 1e-10, &format!("{name}: Y row {r}"));
                }
                assert_close(
                    &mat_vec_rows(&y, &model.standard_params()),
                    &vec(&s["tau"]),
                    1e-10,
                    name,
                );
            }
        }
    }
}
