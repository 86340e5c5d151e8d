//! The regressors and the dynamics of a loaded [`Model`] as plain `f64` rows:
//! `τ = Y(q, v, a) π`, the principal-parameter regressor `Y · blkdiag(P_i)`, and the
//! model's own inverse dynamics and mass matrix. The algorithms are `dyngen_algo`'s
//! (rnea, crba and the joint torque regressor, written once for every joint type);
//! this module checks the state's lengths and shapes the results for the
//! base-parameter analysis ([`crate::base`]) and the loader's checks.

use crate::math::Mat3;
use crate::principal::PrincipalFrame;
use crate::Model;
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

/// The rotation of a quaternion stored as Pinocchio stores it, `[x, y, z, w]`
/// (not normalised: a configuration is expected to hold a unit quaternion).
pub fn quaternion_xyzw(q: &[f64]) -> Mat3 {
    dyngen_algo::quaternion_rotation((), [q[0], q[1], q[2], q[3]])
}

/// The joint torque regressor as rows (`dyngen_algo::joint_torque_regressor`);
/// lengths are the caller's to check.
///
/// # Panics
/// If the model is not a tree in regular labelling, which only a model whose fields
/// were edited by hand can be.
pub(crate) fn torque_regressor(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<Vec<f64>> {
    let body = model
        .multibody()
        .unwrap_or_else(|e| panic!("model `{}` is not a checked tree: {e}", model.name));
    let cols = STANDARD_PER_BODY * body.bodies();
    let mut y = vec![0.0; body.nv() * cols];
    dyngen_algo::joint_torque_regressor(&body, &mut dyngen_algo::Workspace::new(&body, ()), q, v, a, &mut y);
    y.chunks(cols).map(<[f64]>::to_vec).collect()
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
    /// mass from its mass properties and its spatial motion (`dyngen_algo::body_motions`,
    /// gravity added as an acceleration of every body), shifted to the origin, and
    /// the children's wrenches summed into the parent leaf first.
    fn rnea(model: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
        use crate::math::{add, dot, mat_vec, scale};
        let cross = |a: &[f64; 3], b: &[f64; 3]| dyngen_algo::spatial::cross(*a, *b);
        let n = model.dof();
        let body = model.multibody().unwrap();
        let mut ws = dyngen_algo::Workspace::new(&body, ());
        dyngen_algo::body_motions(&body, &mut ws, q, v, a);
        let mut f = vec![[0.0; 3]; n];
        let mut m = vec![[0.0; 3]; n];
        for (i, b) in model.bodies.iter().enumerate() {
            let Inertial { mass, com: c, inertia } = b.inertial;
            let (vel, acc, world) = (ws.velocity[i + 1], ws.acceleration[i + 1], ws.world[i + 1]);
            let (w, wd) = (&vel.angular, &acc.angular);
            // The classical acceleration of the centre of mass, gravity included.
            let g = dyngen_algo::spatial::mat_tr_vec(&world.rotation, model.gravity);
            let a_o = add(&acc.linear, &cross(w, &vel.linear));
            let a_c = add(&add(&a_o, &cross(wd, &c)), &cross(w, &cross(w, &c)));
            f[i] = scale(mass, &add(&a_c, &scale(-1.0, &g)));
            let about_c = add(&mat_vec(&inertia, wd), &cross(w, &mat_vec(&inertia, w)));
            m[i] = add(&about_c, &cross(&c, &f[i]));
        }
        let mut tau = vec![0.0; n];
        for j in (1..=n).rev() {
            let joint = &model.joints[j - 1];
            tau[j - 1] = dot(
                &joint.axis,
                if joint.kind.is_revolute() { &m[j - 1] } else { &f[j - 1] },
            );
            if joint.parent != 0 {
                let x = ws.placement[j].se3(0.0, 1.0);
                let fp = mat_vec(&x.rotation, &f[j - 1]);
                let mp = add(&mat_vec(&x.rotation, &m[j - 1]), &cross(&x.translation, &fp));
                let k = joint.parent - 1;
                f[k] = add(&f[k], &fp);
                m[k] = add(&m[k], &mp);
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
