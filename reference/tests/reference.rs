//! The reference implementation against closed forms and identities: a pendulum, a
//! planar arm and a lift solved by hand; on random branched trees, wrench
//! projections, per-body Newton–Euler, kinematics by finite differences, linearity
//! in the parameters, the mass matrix two ways, and the power balance.

mod common;

use common::{advance, assert_close, assert_vec3_close, mat3, vec3};
use dyngen::Pose;
use dyngen_model::{
    desc::check_inertial, DeclaredJointType, Description, Inertial, JointDesc, JointKind, Limits, LinkDesc, Model,
    Placement, DEFAULT_GRAVITY,
};
use dyngen_reference::Reference;
use dyngen_reference::{perturbed_params, sample_states, BodyMotion, State};
use nalgebra::{DMatrix, IsometryMatrix3, Matrix3, Rotation3, Translation3, Unit, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const G: f64 = 9.81;

// ---------------------------------------------------------------- model building

fn link(name: &str, inertial: Option<Inertial>) -> LinkDesc {
    LinkDesc {
        name: name.into(),
        inertial,
        line: None,
    }
}

fn joint(name: &str, kind: JointKind, parent: &str, child: &str, origin: Placement, axis: [f64; 3]) -> JointDesc {
    let limits = match kind {
        JointKind::Revolute => Some(Limits {
            lower: -2.5,
            upper: 2.5,
            velocity: 3.0,
            effort: 100.0,
        }),
        JointKind::Prismatic => Some(Limits {
            lower: -0.4,
            upper: 0.4,
            velocity: 1.0,
            effort: 100.0,
        }),
        JointKind::Continuous | JointKind::Spherical | JointKind::FreeFlyer | JointKind::Planar => None,
    };
    JointDesc {
        name: name.into(),
        kind: DeclaredJointType::Moving(kind),
        parent: parent.into(),
        child: child.into(),
        origin,
        axis,
        limits,
        dynamics: Default::default(),
        line: None,
    }
}

fn build(name: &str, gravity: [f64; 3], links: Vec<LinkDesc>, joints: Vec<JointDesc>) -> Model {
    Description {
        name: name.into(),
        gravity,
        links,
        joints,
        mimics: Vec::new(),
    }
    .build()
    .expect("test model is valid")
}

fn inertial(mass: f64, com: [f64; 3], diagonal: [f64; 3]) -> Inertial {
    let d = diagonal;
    Inertial {
        mass,
        com,
        inertia: [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
    }
}

fn random_vector(rng: &mut ChaCha8Rng, half_width: f64) -> Vector3<f64> {
    Vector3::from_fn(|_, _| rng.gen_range(-half_width..half_width))
}

fn random_inertial(rng: &mut ChaCha8Rng) -> Inertial {
    // Principal moments from non-negative second moments: the triangle inequality holds.
    let l: [f64; 3] = std::array::from_fn(|_| rng.gen_range(0.002..0.05));
    let moments = Matrix3::from_diagonal(&Vector3::new(l[1] + l[2], l[0] + l[2], l[0] + l[1]));
    let axes = Rotation3::from_scaled_axis(random_vector(rng, 3.0));
    let inertia = axes.matrix() * moments * axes.matrix().transpose();
    Inertial {
        mass: rng.gen_range(0.5..3.0),
        com: random_vector(rng, 0.3).into(),
        inertia: std::array::from_fn(|r| std::array::from_fn(|c| inertia[(r, c)])),
    }
}

/// A random tree: body `k + 1` hangs from body `parents[k]` (0 = base), with random
/// joint kinds, placements, axes and inertials, under default gravity.
fn random_tree(seed: u64, parents: &[usize]) -> Model {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let name = |i: usize| if i == 0 { "base".to_string() } else { format!("body{i}") };
    let mut links = vec![link("base", None)];
    let mut joints = Vec::new();
    for (k, &parent) in parents.iter().enumerate() {
        links.push(link(&name(k + 1), Some(random_inertial(&mut rng))));
        let kind = [JointKind::Revolute, JointKind::Continuous, JointKind::Prismatic][rng.gen_range(0..3)];
        let origin = Placement::from_xyz_rpy(random_vector(&mut rng, 0.5).into(), random_vector(&mut rng, 3.1).into());
        let axis = random_vector(&mut rng, 1.0).normalize();
        joints.push(joint(
            &format!("joint{}", k + 1),
            kind,
            &name(parent),
            &name(k + 1),
            origin,
            axis.into(),
        ));
    }
    build("random_tree", DEFAULT_GRAVITY, links, joints)
}

/// Branched 4-body trees (and one chain), each from its own seed.
fn random_trees() -> Vec<Model> {
    let shapes: [&[usize]; 5] = [
        &[0, 1, 1, 3],
        &[0, 0, 1, 2],
        &[0, 1, 2, 2],
        &[0, 1, 1, 1],
        &[0, 1, 2, 3],
    ];
    shapes
        .iter()
        .enumerate()
        .map(|(k, parents)| random_tree(100 + k as u64, parents))
        .collect()
}

// ---------------------------------------------------------------- comparisons

// ---------------------------------------------------------------- closed forms

/// A pendulum swinging about y, centre of mass `l` below the axis at `q = 0`:
/// `z_c = −l cos q`, so `V = −m g l cos q`, `T = ½ (I_yy + m l²) q̇²` and
/// `τ = (I_yy + m l²) q̈ + m g l sin q`.
#[test]
fn pendulum_matches_closed_form() {
    let (m, l, iyy) = (1.7, 0.45, 0.03);
    for kind in [JointKind::Revolute, JointKind::Continuous] {
        let model = build(
            "pendulum",
            DEFAULT_GRAVITY,
            vec![
                link("base", None),
                link("arm", Some(inertial(m, [0.0, 0.0, -l], [0.02, iyy, 0.015]))),
            ],
            vec![joint(
                "hinge",
                kind,
                "base",
                "arm",
                Placement::IDENTITY,
                [0.0, 1.0, 0.0],
            )],
        );
        let reference = Reference::new(&model);
        let params = model.standard_params();
        for s in sample_states(&model, 20, 1) {
            let expected = (iyy + m * l * l) * s.a[0] + m * G * l * s.q[0].sin();
            assert_close(
                &reference.rnea(&s.q, &s.v, &s.a, &params),
                &[expected],
                1e-12,
                "pendulum tau",
            );
        }
    }
}

/// The textbook two-link planar arm (Spong, Hutchinson, Vidyasagar, §7.4), rotating
/// about z with gravity along −y: links along x, joint 2 at `l1` on link 1, centres of
/// mass at `lc1`, `lc2`, centroidal moments `I1`, `I2` about z.
#[test]
fn two_link_planar_arm_matches_textbook() {
    let (m1, m2, l1, lc1, lc2, i1, i2) = (2.0, 1.3, 0.6, 0.25, 0.3, 0.05, 0.03);
    let model = build(
        "planar_arm",
        [0.0, -G, 0.0],
        vec![
            link("base", None),
            link("upper", Some(inertial(m1, [lc1, 0.0, 0.0], [0.01, 0.045, i1]))),
            link("fore", Some(inertial(m2, [lc2, 0.0, 0.0], [0.005, 0.026, i2]))),
        ],
        vec![
            joint(
                "shoulder",
                JointKind::Revolute,
                "base",
                "upper",
                Placement::IDENTITY,
                [0.0, 0.0, 1.0],
            ),
            joint(
                "elbow",
                JointKind::Revolute,
                "upper",
                "fore",
                Placement::from_xyz_rpy([l1, 0.0, 0.0], [0.0; 3]),
                [0.0, 0.0, 1.0],
            ),
        ],
    );
    let reference = Reference::new(&model);
    let params = model.standard_params();
    for s in sample_states(&model, 20, 2) {
        let (q, v, a) = (&s.q, &s.v, &s.a);
        let (c2, s2) = (q[1].cos(), q[1].sin());
        let m11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2) + i1 + i2;
        let m12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
        let m22 = m2 * lc2 * lc2 + i2;
        let h = -m2 * l1 * lc2 * s2;
        let g1 = (m1 * lc1 + m2 * l1) * G * q[0].cos() + m2 * lc2 * G * (q[0] + q[1]).cos();
        let g2 = m2 * lc2 * G * (q[0] + q[1]).cos();
        let tau = [
            m11 * a[0] + m12 * a[1] + h * v[1] * v[1] + 2.0 * h * v[0] * v[1] + g1,
            m12 * a[0] + m22 * a[1] - h * v[0] * v[0] + g2,
        ];
        assert_close(&reference.rnea(q, v, a, &params), &tau, 1e-12, "planar arm tau");
        let mass = reference.mass_matrix(q, &params);
        assert_close(mass.as_slice(), &[m11, m12, m12, m22], 1e-12, "planar arm M");
    }
    // Shoulder up, elbow folded back: the forearm frame sits at (0, l1, 0), unrotated.
    let poses = reference.forward_kinematics(&[std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2]);
    assert_vec3_close(
        &poses[1].translation,
        &Vector3::new(0.0, l1, 0.0),
        1e-15,
        "forearm position",
    );
    assert_close(
        poses[1].rotation.as_slice(),
        Matrix3::identity().as_slice(),
        1e-15,
        "forearm rotation",
    );
}

/// A lift: a prismatic joint along +z against gravity −z, `τ = m (q̈ + g)`; with a
/// body spinning about the same vertical axis on top, the lift carries both masses
/// and the spinner needs `(I_zz + m |c_xy|²) q̈₂`.
#[test]
fn prismatic_lift_carries_weight() {
    let (m1, m2, izz, c) = (3.0, 1.2, 0.04, [0.2, -0.1, 0.05]);
    let carriage = || link("carriage", Some(inertial(m1, [0.1, 0.2, 0.0], [0.05, 0.05, 0.05])));
    let lift = || {
        joint(
            "lift",
            JointKind::Prismatic,
            "base",
            "carriage",
            Placement::IDENTITY,
            [0.0, 0.0, 1.0],
        )
    };

    let single = build(
        "lift_only",
        DEFAULT_GRAVITY,
        vec![link("base", None), carriage()],
        vec![lift()],
    );
    let reference = Reference::new(&single);
    for s in sample_states(&single, 10, 4) {
        let tau = reference.rnea(&s.q, &s.v, &s.a, &single.standard_params());
        assert_close(&tau, &[m1 * (s.a[0] + G)], 1e-12, "single lift tau");
    }

    let model = build(
        "lift",
        DEFAULT_GRAVITY,
        vec![
            link("base", None),
            carriage(),
            link("turntable", Some(inertial(m2, c, [0.03, 0.03, izz]))),
        ],
        vec![
            lift(),
            joint(
                "turn",
                JointKind::Continuous,
                "carriage",
                "turntable",
                Placement::from_xyz_rpy([0.3, 0.0, 0.2], [0.0; 3]),
                [0.0, 0.0, 1.0],
            ),
        ],
    );
    let reference = Reference::new(&model);
    let params = model.standard_params();
    for s in sample_states(&model, 20, 3) {
        let expected = [
            (m1 + m2) * (s.a[0] + G),
            (izz + m2 * (c[0] * c[0] + c[1] * c[1])) * s.a[1],
        ];
        assert_close(&reference.rnea(&s.q, &s.v, &s.a, &params), &expected, 1e-12, "lift tau");
    }
}

// ---------------------------------------------------------------- joint wrenches

/// `τ_j = S_jᵀ f_j`: the axis component of the torque (revolute) or force (prismatic).
#[test]
fn joint_torque_is_the_wrench_projected_on_the_axis() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        let params = perturbed_params(&model, 5, 0.3);
        for s in sample_states(&model, 10, 5) {
            let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
            let wrenches = reference.joint_wrenches(&s.q, &s.v, &s.a, &params);
            let projected: Vec<f64> = model
                .joints
                .iter()
                .zip(&wrenches)
                .map(|(j, w)| match j.kind {
                    JointKind::Prismatic => vec3(&j.axis).dot(&w.force),
                    _ => vec3(&j.axis).dot(&w.torque),
                })
                .collect();
            assert_close(&projected, &tau, 1e-12, "S^T f");
        }
    }
}

/// One body on one joint: the joint wrench is the body's Newton–Euler in 3D,
/// `F = m (a_c − g)`, `N_o = I_c ω̇ + ω × I_c ω + c × F`, worked out by hand from
/// the joint motion (the joint origin is fixed in space).
#[test]
fn single_body_wrench_is_its_own_newton_euler() {
    for seed in 0..12u64 {
        let model = random_tree(200 + seed, &[0]);
        let reference = Reference::new(&model);
        let (j, body) = (&model.joints[0], &model.bodies[0].inertial);
        let (k, m, c, ic) = (vec3(&j.axis), body.mass, vec3(&body.com), mat3(&body.inertia));
        for s in sample_states(&model, 5, seed) {
            let (q, qd, qdd) = (s.q[0], s.v[0], s.a[0]);
            let (rotation, w, dw, a_c) = match j.kind {
                JointKind::Prismatic => (mat3(&j.origin.rotation), Vector3::zeros(), Vector3::zeros(), k * qdd),
                _ => {
                    let (w, dw) = (k * qd, k * qdd);
                    let joint_rotation = Rotation3::from_axis_angle(&Unit::new_normalize(k), q);
                    (
                        mat3(&j.origin.rotation) * joint_rotation.matrix(),
                        w,
                        dw,
                        dw.cross(&c) + w.cross(&w.cross(&c)),
                    )
                }
            };
            let g = rotation.transpose() * vec3(&model.gravity);
            let force = m * (a_c - g);
            let torque = ic * dw + w.cross(&(ic * w)) + c.cross(&force);
            let wrench = reference.joint_wrenches(&s.q, &s.v, &s.a, &model.standard_params())[0];
            assert_vec3_close(&wrench.force, &force, 1e-12, "single body force");
            assert_vec3_close(&wrench.torque, &torque, 1e-12, "single body torque");
        }
    }
}

/// The paper's decoupling (docs/design.md, "The paper's graph theory"): the joint wrench on body `i` minus what it
/// passes on to its children is body `i`'s own Newton–Euler, about its frame origin.
#[test]
fn every_body_obeys_its_own_newton_euler() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        let params = model.standard_params();
        for s in sample_states(&model, 5, 6) {
            let poses = reference.forward_kinematics(&s.q);
            let motions = reference.body_motions(&s.q, &s.v, &s.a);
            let wrenches = reference.joint_wrenches(&s.q, &s.v, &s.a, &params);
            for i in 1..=model.dof() {
                let (mut force, mut torque) = (wrenches[i - 1].force, wrenches[i - 1].torque);
                let to_body = poses[i - 1].rotation.transpose();
                for child in model.children(i) {
                    // The child's frame in body i: axes `e`, origin `r`.
                    let e = to_body * poses[child - 1].rotation;
                    let r = to_body * (poses[child - 1].translation - poses[i - 1].translation);
                    let f = e * wrenches[child - 1].force;
                    force -= f;
                    torque -= e * wrenches[child - 1].torque + r.cross(&f);
                }
                let body = &model.bodies[i - 1].inertial;
                let (c, ic) = (vec3(&body.com), mat3(&body.inertia));
                let BodyMotion { velocity, acceleration } = motions[i - 1];
                let g = to_body * vec3(&model.gravity);
                let newton = body.mass * (motions[i - 1].point_acceleration(&c) - g);
                let (w, dw) = (velocity.angular, acceleration.angular);
                let euler = ic * dw + w.cross(&(ic * w)) + c.cross(&newton);
                assert_vec3_close(&force, &newton, 1e-11, "net force");
                assert_vec3_close(&torque, &euler, 1e-11, "net moment about the origin");
            }
        }
    }
}

// ---------------------------------------------------------------- kinematics

/// Poses against nalgebra's own isometries, composed body by body:
/// `⁰M_i = ⁰M_λ(i) · origin_i · joint_i(q_i)`.
#[test]
fn forward_kinematics_composes_placements() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        for s in sample_states(&model, 5, 7) {
            let poses = reference.forward_kinematics(&s.q);
            let mut world = vec![IsometryMatrix3::identity(); model.dof() + 1];
            for (k, j) in model.joints.iter().enumerate() {
                let origin = IsometryMatrix3::from_parts(
                    Translation3::from(vec3(&j.origin.translation)),
                    Rotation3::from_matrix_unchecked(mat3(&j.origin.rotation)),
                );
                let motion = match j.kind {
                    JointKind::Prismatic => {
                        IsometryMatrix3::from_parts(Translation3::from(vec3(&j.axis) * s.q[k]), Rotation3::identity())
                    }
                    _ => IsometryMatrix3::rotation(vec3(&j.axis) * s.q[k]),
                };
                world[k + 1] = world[j.parent] * origin * motion;
            }
            for (i, pose) in poses.iter().enumerate() {
                let expected = &world[i + 1];
                assert_close(
                    pose.rotation.as_slice(),
                    expected.rotation.matrix().as_slice(),
                    1e-14,
                    "rotation",
                );
                assert_vec3_close(&pose.translation, &expected.translation.vector, 1e-14, "translation");
            }
        }
    }
}

/// Body velocities are the time derivatives of the poses (`[ω]× = Rᵀ Ṙ`,
/// `v = Rᵀ ṫ`), body accelerations those of the body-frame velocities, and
/// `point_acceleration` the second derivative of a body point's position; all by
/// central differences along a trajectory.
#[test]
fn body_motions_are_derivatives_of_poses() {
    let h = 1e-4;
    for model in random_trees() {
        let reference = Reference::new(&model);
        for s in sample_states(&model, 5, 8) {
            let (before, after) = (advance(&s, -h), advance(&s, h));
            let poses = |x: &State| reference.forward_kinematics(&x.q);
            let motions = |x: &State| reference.body_motions(&x.q, &x.v, &x.a);
            let (p0, pm, pp) = (poses(&s), poses(&before), poses(&after));
            let (m0, mm, mp) = (motions(&s), motions(&before), motions(&after));
            let point = Vector3::new(0.3, -0.2, 0.1);
            for i in 0..model.dof() {
                let r = p0[i].rotation;
                let w_hat = r.transpose() * (pp[i].rotation - pm[i].rotation) / (2.0 * h);
                let w = Vector3::new(w_hat[(2, 1)], w_hat[(0, 2)], w_hat[(1, 0)]);
                let v = r.transpose() * (pp[i].translation - pm[i].translation) / (2.0 * h);
                assert_vec3_close(&m0[i].velocity.angular, &w, 1e-7, "angular velocity");
                assert_vec3_close(&m0[i].velocity.linear, &v, 1e-7, "linear velocity");

                let a = (mp[i].velocity.to_vector() - mm[i].velocity.to_vector()) / (2.0 * h);
                assert_close(
                    m0[i].acceleration.to_vector().as_slice(),
                    a.as_slice(),
                    1e-7,
                    "spatial acceleration",
                );

                let world = |p: &Pose<f64>| p.rotation * point + p.translation;
                let second = (world(&pp[i]) - 2.0 * world(&p0[i]) + world(&pm[i])) / (h * h);
                let expected = r.transpose() * second;
                assert_vec3_close(&m0[i].point_acceleration(&point), &expected, 1e-5, "point acceleration");
            }
        }
    }
}

// ---------------------------------------------------------------- dynamics identities

/// `τ = Y(q, v, a) π`: scaling and adding parameter vectors scales and adds torques.
#[test]
fn rnea_is_linear_in_the_parameters() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        let (p1, p2) = (perturbed_params(&model, 1, 0.5), perturbed_params(&model, 2, 0.5));
        let sum: Vec<f64> = p1.iter().zip(&p2).map(|(a, b)| a + b).collect();
        let scaled: Vec<f64> = p1.iter().map(|x| -2.5 * x).collect();
        for s in sample_states(&model, 5, 9) {
            let rnea = |p: &[f64]| reference.rnea(&s.q, &s.v, &s.a, p);
            let (t1, t2) = (rnea(&p1), rnea(&p2));
            let added: Vec<f64> = t1.iter().zip(&t2).map(|(a, b)| a + b).collect();
            assert_close(&rnea(&sum), &added, 1e-12, "additivity");
            let expected: Vec<f64> = t1.iter().map(|x| -2.5 * x).collect();
            assert_close(&rnea(&scaled), &expected, 1e-12, "homogeneity");
        }
    }
}

/// `M e_j = rnea(q, 0, e_j) − rnea(q, 0, 0)` is symmetric positive definite and equals
/// the composite-rigid-body `mass_matrix`.
#[test]
fn mass_matrix_from_rnea_is_symmetric_positive_definite_and_matches_crba() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        let params = perturbed_params(&model, 3, 0.3);
        let n = model.dof();
        for s in sample_states(&model, 5, 10) {
            let zero = vec![0.0; n];
            let gravity = reference.rnea(&s.q, &zero, &zero, &params);
            assert_close(
                &reference.generalized_gravity(&s.q, &params),
                &gravity,
                0.0,
                "generalized_gravity",
            );
            let m = DMatrix::from_fn(n, n, |r, c| {
                let mut e = zero.clone();
                e[c] = 1.0;
                reference.rnea(&s.q, &zero, &e, &params)[r] - gravity[r]
            });
            assert!((&m - m.transpose()).amax() < 1e-12, "M not symmetric:\n{m}");
            assert!(m.clone().cholesky().is_some(), "M not positive definite:\n{m}");
            let crba = reference.mass_matrix(&s.q, &params);
            assert_close(crba.as_slice(), m.as_slice(), 1e-12, "crba vs rnea columns");
        }
    }
}

/// `forward_dynamics(q, v, rnea(q, v, a)) = a`, and `nonlinear_effects = rnea(q, v, 0)`.
#[test]
fn forward_dynamics_inverts_rnea() {
    for model in random_trees() {
        let reference = Reference::new(&model);
        let params = perturbed_params(&model, 4, 0.3);
        for s in sample_states(&model, 5, 11) {
            let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
            let a = reference
                .forward_dynamics(&s.q, &s.v, &tau, &params)
                .expect("M is positive definite");
            assert_close(&a, &s.a, 1e-10, "forward dynamics");
            let zero = vec![0.0; model.dof()];
            let expected = reference.rnea(&s.q, &s.v, &zero, &params);
            assert_close(
                &reference.nonlinear_effects(&s.q, &s.v, &params),
                &expected,
                0.0,
                "nonlinear effects",
            );
        }
    }
}

/// Kinetic energy from body motions in 3D, `T = Σ ½ m |v + ω × c|² + ½ ωᵀ I_c ω`.
fn kinetic_energy(model: &Model, motions: &[BodyMotion]) -> f64 {
    model
        .bodies
        .iter()
        .zip(motions)
        .map(|(b, m)| {
            let (w, c, ic) = (m.velocity.angular, vec3(&b.inertial.com), mat3(&b.inertial.inertia));
            let vc = m.velocity.linear + w.cross(&c);
            0.5 * b.inertial.mass * vc.norm_squared() + 0.5 * w.dot(&(ic * w))
        })
        .sum()
}

/// The power balance `dT/dt = q̇ᵀ (τ − g(q))`: the Coriolis and centrifugal terms do
/// no work. `dT/dt` by central differences along a trajectory.
#[test]
fn kinetic_energy_changes_by_the_power_of_non_gravity_torques() {
    let h = 1e-5;
    for model in random_trees() {
        let reference = Reference::new(&model);
        let params = model.standard_params();
        for s in sample_states(&model, 5, 12) {
            let energy = |x: &State| kinetic_energy(&model, &reference.body_motions(&x.q, &x.v, &x.a));
            let rate = (energy(&advance(&s, h)) - energy(&advance(&s, -h))) / (2.0 * h);
            let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
            let gravity = reference.generalized_gravity(&s.q, &params);
            let power: f64 = (0..model.dof()).map(|k| s.v[k] * (tau[k] - gravity[k])).sum();
            assert_close(&[rate], &[power], 1e-7, "power balance");
        }
    }
}

// ---------------------------------------------------------------- sampling

#[test]
fn sampled_states_are_reproducible_and_within_limits() {
    for model in random_trees() {
        let states = sample_states(&model, 50, 42);
        assert_eq!(states, sample_states(&model, 50, 42));
        assert_ne!(states, sample_states(&model, 50, 43));
        for s in &states {
            for (k, j) in model.joints.iter().enumerate() {
                let (lo, hi) = match (j.limits, j.kind) {
                    (Some(l), _) => (l.lower, l.upper),
                    (None, JointKind::Prismatic) => (-0.5, 0.5),
                    (None, _) => (-std::f64::consts::PI, std::f64::consts::PI),
                };
                assert!((lo..=hi).contains(&s.q[k]), "q[{k}] = {} outside [{lo}, {hi}]", s.q[k]);
                assert!((-2.0..=2.0).contains(&s.v[k]) && (-2.0..=2.0).contains(&s.a[k]));
            }
        }
    }
}

#[test]
fn perturbed_params_are_physically_consistent_and_centred_on_nominal() {
    for model in random_trees() {
        let nominal = model.standard_params();
        assert_close(&perturbed_params(&model, 9, 0.0), &nominal, 1e-12, "rel = 0");
        for seed in 0..20 {
            let params = perturbed_params(&model, seed, 0.5);
            assert_eq!(params, perturbed_params(&model, seed, 0.5), "reproducible");
            assert_ne!(params, perturbed_params(&model, seed + 100, 0.5), "seed matters");
            for (i, body) in params.chunks(10).enumerate() {
                let mass = model.bodies[i].inertial.mass;
                assert!(
                    body[0] >= 0.5 * mass && body[0] <= 1.5 * mass,
                    "mass {} vs nominal {mass}",
                    body[0]
                );
                let inertial = Inertial::from_standard_params(body.try_into().unwrap()).expect("positive mass");
                check_inertial(&inertial).unwrap_or_else(|e| panic!("body {}: {e:?}", i + 1));
            }
        }
    }
}

// ---------------------------------------------------------------- misuse

#[test]
#[should_panic(expected = "`v` has 1 entries; the model needs 2")]
fn wrong_length_panics_with_the_argument_name() {
    let model = random_tree(1, &[0, 1]);
    let reference = Reference::new(&model);
    reference.rnea(&[0.0, 0.0], &[0.0], &[0.0, 0.0], &model.standard_params());
}

#[test]
#[should_panic(expected = "`params` has 10 entries; the model needs 20")]
fn wrong_parameter_count_panics() {
    let model = random_tree(1, &[0, 1]);
    let zero = [0.0, 0.0];
    Reference::new(&model).rnea(&zero, &zero, &zero, &[1.0; 10]);
}
