//! The reference regressors, mass matrix, articulated body algorithm and the paper's
//! decoupled body model, on small URDF robots: a branched tree (two roots, a
//! prismatic and a continuous joint, rotated origins, non-diagonal inertias, a fixed
//! tool merged into its link), a serial chain and single hanging bodies.

mod common;

use common::{advance, assert_close, assert_vec3_close, mat3, vec3};
use dyngen_model::{graph, parse_urdf, principal_params, JointKind, Model, PrincipalFrame};
use dyngen_reference::Reference;
use dyngen_reference::{
    perturbed_params, principal_matrix, principal_params_to_standard, sample_states, SplitMix64, State,
};
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Unit, Vector3};

// ---------------------------------------------------------------- models

const BRANCHED: &str = r#"<robot name="branched">
  <link name="base"/>
  <link name="torso">
    <inertial><origin xyz="0.05 -0.02 0.2" rpy="0.3 -0.2 0.5"/><mass value="4.0"/>
      <inertia ixx="0.12" ixy="0.01" ixz="-0.008" iyy="0.10" iyz="0.005" izz="0.08"/></inertial>
  </link>
  <link name="wheel">
    <inertial><origin xyz="0.01 0.0 -0.02"/><mass value="0.8"/>
      <inertia ixx="0.006" ixy="0.0004" ixz="0.0" iyy="0.004" iyz="-0.0002" izz="0.0045"/></inertial>
  </link>
  <link name="slider">
    <inertial><origin xyz="0.1 0.03 -0.04"/><mass value="1.5"/>
      <inertia ixx="0.02" ixy="-0.003" ixz="0.002" iyy="0.025" iyz="0.001" izz="0.018"/></inertial>
  </link>
  <link name="upper_arm">
    <inertial><origin xyz="0 0.15 0.02" rpy="0.1 0.2 0.3"/><mass value="2.0"/>
      <inertia ixx="0.03" ixy="0.002" ixz="0.001" iyy="0.01" iyz="-0.002" izz="0.028"/></inertial>
  </link>
  <link name="forearm">
    <inertial><origin xyz="0.12 0 0.01"/><mass value="1.1"/>
      <inertia ixx="0.004" ixy="0.0005" ixz="0" iyy="0.012" iyz="0.0003" izz="0.011"/></inertial>
  </link>
  <link name="tool">
    <inertial><origin xyz="0.02 0.01 0"/><mass value="0.3"/>
      <inertia ixx="0.0004" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.0006"/></inertial>
  </link>
  <joint name="a_waist" type="revolute">
    <parent link="base"/><child link="torso"/>
    <origin xyz="0 0 0.3" rpy="0 0 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-2.5" upper="2.5" effort="100" velocity="3"/>
  </joint>
  <joint name="b_wheel" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <origin xyz="0.5 -0.2 0.1" rpy="0.2 0.1 -0.6"/><axis xyz="1 0 0"/>
  </joint>
  <joint name="c_slide" type="prismatic">
    <parent link="torso"/><child link="slider"/>
    <origin xyz="0.2 0 0.4" rpy="0.5 0 -0.3"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-0.3" upper="0.3" effort="100" velocity="1"/>
  </joint>
  <joint name="d_shoulder" type="continuous">
    <parent link="torso"/><child link="upper_arm"/>
    <origin xyz="-0.1 0.2 0.5" rpy="1.2 -0.4 0.7"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="e_elbow" type="revolute">
    <parent link="upper_arm"/><child link="forearm"/>
    <origin xyz="0 0.3 0" rpy="0 0.3 0"/><axis xyz="0.48 0.6 0.64"/>
    <limit lower="-2.0" upper="2.0" effort="50" velocity="3"/>
  </joint>
  <joint name="f_tool" type="fixed">
    <parent link="forearm"/><child link="tool"/>
    <origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/>
  </joint>
</robot>"#;

const CHAIN: &str = r#"<robot name="chain">
  <link name="base"/>
  <link name="l1">
    <inertial><origin xyz="0 0.02 0.1" rpy="0.2 0 0"/><mass value="3.0"/>
      <inertia ixx="0.05" ixy="0.002" ixz="0" iyy="0.05" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="l2">
    <inertial><origin xyz="0.15 0 0.01" rpy="0 0.3 0.1"/><mass value="2.0"/>
      <inertia ixx="0.004" ixy="0" ixz="0.001" iyy="0.03" iyz="0" izz="0.03"/></inertial>
  </link>
  <link name="l3">
    <inertial><origin xyz="0.05 -0.01 0"/><mass value="1.2"/>
      <inertia ixx="0.003" ixy="0.0004" ixz="-0.0002" iyy="0.008" iyz="0.0001" izz="0.007"/></inertial>
  </link>
  <link name="l4">
    <inertial><origin xyz="0.03 0.02 -0.01" rpy="-0.4 0.2 0.9"/><mass value="0.6"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.0012" iyz="0" izz="0.0015"/></inertial>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="3"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3" rpy="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="3"/>
  </joint>
  <joint name="j3" type="prismatic">
    <parent link="l2"/><child link="l3"/><origin xyz="0.25 0 0" rpy="0 0 0.5"/><axis xyz="1 0 0"/>
    <limit lower="-0.2" upper="0.2" effort="100" velocity="1"/>
  </joint>
  <joint name="j4" type="continuous">
    <parent link="l3"/><child link="l4"/><origin xyz="0.1 0.05 0" rpy="0.3 0.4 0.1"/><axis xyz="0.8 0 0.6"/>
  </joint>
</robot>"#;

fn models() -> Vec<Model> {
    [BRANCHED, CHAIN]
        .iter()
        .map(|text| parse_urdf(text).expect("test URDF is valid"))
        .collect()
}

/// One body on one joint of the given URDF type (tilted axis, rotated origin,
/// centre of mass off the axis, non-diagonal inertia).
fn single_body(kind: &str) -> Model {
    let limit = match kind {
        "continuous" => "",
        _ => r#"<limit lower="-1" upper="1" effort="10" velocity="2"/>"#,
    };
    let text = format!(
        r#"<robot name="hanging">
  <link name="base"/>
  <link name="bob">
    <inertial><origin xyz="0.1 -0.05 -0.4" rpy="0.3 0.5 -0.2"/><mass value="1.7"/>
      <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial>
  </link>
  <joint name="hinge" type="{kind}">
    <parent link="base"/><child link="bob"/>
    <origin xyz="0.1 0.2 1.0" rpy="0.4 -0.3 0.2"/><axis xyz="0 0.6 0.8"/>{limit}
  </joint>
</robot>"#
    );
    parse_urdf(&text).expect("test URDF is valid")
}

/// The models exercise what a serious library must handle: a branched tree with two roots, all
/// three joint kinds, a merged fixed link, and every body's principal axes turned
/// away from its frame's axes; a chain with no branches.
#[test]
fn test_models_have_the_intended_features() {
    let branched = parse_urdf(BRANCHED).unwrap();
    assert_eq!(branched.dof(), 5);
    assert_eq!(branched.children(0).len(), 2);
    for kind in [JointKind::Revolute, JointKind::Continuous, JointKind::Prismatic] {
        assert!(branched.joints.iter().any(|j| j.kind == kind), "{kind:?}");
    }
    assert!(branched.bodies.iter().any(|b| !b.merged.is_empty()));
    let chain = parse_urdf(CHAIN).unwrap();
    assert!((0..=chain.dof()).all(|i| chain.children(i).len() <= 1));
    for model in [branched, chain] {
        for body in &model.bodies {
            let axes = mat3(&PrincipalFrame::of(&body.inertial).rotation);
            assert!(
                (axes - Matrix3::identity()).amax() > 1e-3,
                "{}: principal axes",
                body.name
            );
        }
    }
}

// ---------------------------------------------------------------- helpers

fn times(m: &DMatrix<f64>, x: &[f64]) -> Vec<f64> {
    (m * DVector::from_column_slice(x)).iter().copied().collect()
}

/// Random principal parameters, 4 per body: masses in `[0.5, 3]`, moments in
/// `[0.01, 0.1]` (linear identities need no physical consistency).
fn random_theta(model: &Model, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..model.dof())
        .flat_map(|_| {
            let m = rng.uniform(0.5, 3.0);
            let j: [f64; 3] = std::array::from_fn(|_| rng.uniform(0.01, 0.1));
            [m, j[0], j[1], j[2]]
        })
        .collect()
}

// ---------------------------------------------------------------- regressors

/// `τ = Y(q, v, a) π` for nominal and perturbed parameters.
#[test]
fn torque_regressor_times_params_is_rnea() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        for s in sample_states(&model, 10, 21) {
            let y = reference.joint_torque_regressor(&s.q, &s.v, &s.a);
            assert_eq!(y.shape(), (n, 10 * n));
            for params in [model.standard_params(), perturbed_params(&model, 22, 0.4)] {
                let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
                assert_close(&times(&y, &params), &tau, 1e-12, "Y π");
            }
        }
    }
}

/// `W(q, v, a) π` stacks the joint wrenches `[force; torque]`, joint 1 first.
#[test]
fn wrench_regressor_times_params_is_joint_wrenches() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        let params = perturbed_params(&model, 23, 0.4);
        for s in sample_states(&model, 10, 24) {
            let w = reference.joint_wrench_regressor(&s.q, &s.v, &s.a);
            assert_eq!(w.shape(), (6 * n, 10 * n));
            let expected: Vec<f64> = reference
                .joint_wrenches(&s.q, &s.v, &s.a, &params)
                .iter()
                .flat_map(|f| f.force.iter().chain(f.torque.iter()).copied().collect::<Vec<_>>())
                .collect();
            assert_close(&times(&w, &params), &expected, 1e-12, "W π");
        }
    }
}

/// Block `(j, i)` of `Y` and `W` is exactly zero when joint `j` does not support
/// body `i` (`T_ji = 0`), and not zero when it does (generic states).
#[test]
fn regressor_blocks_follow_the_path_matrix() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        let t = graph::path_matrix(&model);
        let mut zeros = 0;
        for s in sample_states(&model, 5, 25) {
            let y = reference.joint_torque_regressor(&s.q, &s.v, &s.a);
            let w = reference.joint_wrench_regressor(&s.q, &s.v, &s.a);
            for j in 1..=n {
                for i in 1..=n {
                    let y_block = y.view((j - 1, 10 * (i - 1)), (1, 10)).amax();
                    let w_block = w.view((6 * (j - 1), 10 * (i - 1)), (6, 10)).amax();
                    assert_eq!(t[j - 1][i - 1] != 0, model.supports(j, i));
                    if model.supports(j, i) {
                        assert!(y_block > 0.0 && w_block > 0.0, "block ({j}, {i}) vanished");
                    } else {
                        assert_eq!(y_block, 0.0, "Y block ({j}, {i})");
                        assert_eq!(w_block, 0.0, "W block ({j}, {i})");
                        zeros += 1;
                    }
                }
            }
        }
        assert!(zeros > 0, "{}: the test should see some structural zeros", model.name);
    }
}

/// `Y_θ θ = rnea(π)` with `π = blkdiag(P_i) θ`, for the nominal `θ` (which gives
/// back the nominal `π`) and random ones.
#[test]
fn principal_regressor_times_theta_is_rnea() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        let nominal = principal_params(&model);
        assert_close(
            &principal_params_to_standard(&model, &nominal),
            &model.standard_params(),
            1e-12,
            "P θ nominal",
        );
        let p = principal_matrix(&model);
        assert_eq!(p.shape(), (10 * n, 4 * n));
        for s in sample_states(&model, 10, 26) {
            let y_theta = reference.principal_regressor(&s.q, &s.v, &s.a);
            assert_eq!(y_theta.shape(), (n, 4 * n));
            for theta in [nominal.clone(), random_theta(&model, 27)] {
                let params = principal_params_to_standard(&model, &theta);
                assert_close(&params, &times(&p, &theta), 1e-15, "P θ two ways");
                let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
                assert_close(&times(&y_theta, &theta), &tau, 1e-12, "Y P θ");
            }
        }
    }
}

// ---------------------------------------------------------------- mass matrix and forward dynamics

/// `crba` is symmetric positive definite, equals `rnea(q, 0, e_j) − g(q)` column by
/// column, and `mass_matrix` is the same thing.
#[test]
fn crba_is_symmetric_positive_definite_and_matches_rnea_columns() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        for params in [model.standard_params(), perturbed_params(&model, 28, 0.3)] {
            for s in sample_states(&model, 5, 29) {
                let zero = vec![0.0; n];
                let gravity = reference.rnea(&s.q, &zero, &zero, &params);
                let columns = DMatrix::from_fn(n, n, |r, c| {
                    let mut e = zero.clone();
                    e[c] = 1.0;
                    reference.rnea(&s.q, &zero, &e, &params)[r] - gravity[r]
                });
                let m = reference.crba(&s.q, &params);
                assert!((&m - m.transpose()).amax() == 0.0, "crba not symmetric:\n{m}");
                assert!(m.clone().cholesky().is_some(), "crba not positive definite:\n{m}");
                assert_close(m.as_slice(), columns.as_slice(), 1e-12, "crba vs rnea columns");
                assert_eq!(reference.mass_matrix(&s.q, &params), m);
            }
        }
    }
}

/// `aba(q, v, rnea(q, v, a)) = a`, and `aba(q, v, τ) = M⁻¹ (τ − nle)` for random `τ`,
/// which is also what `forward_dynamics` returns.
#[test]
fn aba_inverts_rnea_and_matches_the_mass_matrix() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        let mut rng = SplitMix64::new(30);
        for params in [model.standard_params(), perturbed_params(&model, 31, 0.3)] {
            for s in sample_states(&model, 10, 32) {
                let tau = reference.rnea(&s.q, &s.v, &s.a, &params);
                assert_close(&reference.aba(&s.q, &s.v, &tau, &params), &s.a, 1e-10, "aba ∘ rnea");

                let tau: Vec<f64> = (0..n).map(|_| rng.uniform(-10.0, 10.0)).collect();
                let nle = DVector::from_vec(reference.nonlinear_effects(&s.q, &s.v, &params));
                let m = reference.crba(&s.q, &params);
                let expected = m
                    .lu()
                    .solve(&(DVector::from_column_slice(&tau) - nle))
                    .expect("M regular");
                let aba = reference.aba(&s.q, &s.v, &tau, &params);
                assert_close(&aba, expected.as_slice(), 1e-10, "aba vs M⁻¹ (τ − nle)");
                let cholesky = reference.forward_dynamics(&s.q, &s.v, &tau, &params).unwrap();
                assert_close(&aba, &cholesky, 1e-10, "aba vs forward_dynamics");
            }
        }
    }
}

/// `nle = rnea(q, v, 0)` and `g = rnea(q, 0, 0)`.
#[test]
fn nonlinear_effects_and_gravity_are_rnea_special_cases() {
    for model in models() {
        let reference = Reference::new(&model);
        let zero = vec![0.0; model.dof()];
        let params = perturbed_params(&model, 33, 0.3);
        for s in sample_states(&model, 5, 34) {
            assert_eq!(
                reference.nonlinear_effects(&s.q, &s.v, &params),
                reference.rnea(&s.q, &s.v, &zero, &params)
            );
            assert_eq!(
                reference.generalized_gravity(&s.q, &params),
                reference.rnea(&s.q, &zero, &zero, &params)
            );
        }
    }
}

// ---------------------------------------------------------------- the decoupled body model

fn body_wrench_vector(w: &dyngen::Wrench<f64>) -> Vec<f64> {
    w.force.iter().chain(w.torque.iter()).copied().collect()
}

/// The paper's decoupling: `A_i θ_i` equals the resultant of the joint reactions on
/// body `i`, through `S` and `c_ia`, for every body, with the nominal parameters and
/// with any `π = P θ'`.
#[test]
fn body_regressor_times_theta_is_the_body_resultant() {
    for model in models() {
        let reference = Reference::new(&model);
        let n = model.dof();
        for theta in [principal_params(&model), random_theta(&model, 35)] {
            let params = principal_params_to_standard(&model, &theta);
            for s in sample_states(&model, 10, 36) {
                let a = reference.body_regressor(&s.q, &s.v, &s.a);
                let resultants = reference.body_resultants(&s.q, &s.v, &s.a, &params);
                assert_eq!((a.len(), resultants.len()), (n, n));
                for i in 0..n {
                    let theta_i = nalgebra::Vector4::from_column_slice(&theta[4 * i..4 * i + 4]);
                    let predicted = a[i] * theta_i;
                    assert_close(
                        predicted.as_slice(),
                        &body_wrench_vector(&resultants[i]),
                        1e-11,
                        &format!("{}: A θ = resultant, body {}", model.name, i + 1),
                    );
                }
            }
        }
    }
}

/// Parameters that move the centres of mass leave the frame of `A_i` behind: the
/// resultants change, and `A_i θ_i` (with those parameters' masses and the
/// nominal moments) no longer matches them.
#[test]
fn body_model_needs_the_description_centres_of_mass() {
    for model in models() {
        let reference = Reference::new(&model);
        let nominal = principal_params(&model);
        let moved = perturbed_params(&model, 37, 0.3);
        let s = &sample_states(&model, 1, 38)[0];
        let a = reference.body_regressor(&s.q, &s.v, &s.a);
        let resultants = reference.body_resultants(&s.q, &s.v, &s.a, &moved);
        let worst = (0..model.dof())
            .map(|i| {
                let mut theta_i = nalgebra::Vector4::from_column_slice(&nominal[4 * i..4 * i + 4]);
                theta_i[0] = moved[10 * i];
                let predicted = a[i] * theta_i;
                let actual = DVector::from_vec(body_wrench_vector(&resultants[i]));
                (DVector::from_column_slice(predicted.as_slice()) - actual).amax()
            })
            .fold(0.0, f64::max);
        assert!(
            worst > 1e-3,
            "{}: moved centres of mass went unnoticed ({worst})",
            model.name
        );
    }
}

/// One body on one joint: the resultant is the joint's reaction moved to the centre
/// of mass, and equals Newton–Euler about the centre of mass worked out by hand from
/// the joint motion, in the principal frame. At rest it just carries the weight.
#[test]
fn single_body_resultant_is_its_newton_euler() {
    for kind in ["revolute", "continuous", "prismatic"] {
        let model = single_body(kind);
        let reference = Reference::new(&model);
        let (joint, body) = (&model.joints[0], &model.bodies[0].inertial);
        let frame = PrincipalFrame::of(body);
        let to_principal = mat3(&frame.rotation).transpose();
        assert!(
            (mat3(&frame.rotation) - Matrix3::identity()).amax() > 0.1,
            "principal axes are turned"
        );
        let (k, m, c, ic) = (vec3(&joint.axis), body.mass, vec3(&body.com), mat3(&body.inertia));
        let gravity = vec3(&model.gravity);
        let params = model.standard_params();
        let mut states = sample_states(&model, 10, 39);
        states.push(State {
            q: vec![0.3],
            v: vec![0.0],
            a: vec![0.0],
        });
        for s in states {
            let (q, qd, qdd) = (s.q[0], s.v[0], s.a[0]);
            let (rotation, w, dw, a_c) = match joint.kind {
                JointKind::Prismatic => (
                    mat3(&joint.origin.rotation),
                    Vector3::zeros(),
                    Vector3::zeros(),
                    k * qdd,
                ),
                _ => {
                    let (w, dw) = (k * qd, k * qdd);
                    let turn = Rotation3::from_axis_angle(&Unit::new_normalize(k), q);
                    let a_c = dw.cross(&c) + w.cross(&w.cross(&c));
                    (mat3(&joint.origin.rotation) * turn.matrix(), w, dw, a_c)
                }
            };
            let g = rotation.transpose() * gravity;
            let force = to_principal * (m * (a_c - g));
            let moment = to_principal * (ic * dw + w.cross(&(ic * w)));
            let resultant = reference.body_resultants(&s.q, &s.v, &s.a, &params)[0];
            assert_vec3_close(&resultant.force, &force, 1e-12, "force");
            assert_vec3_close(&resultant.torque, &moment, 1e-12, "moment about the centre of mass");
            if s.v[0] == 0.0 && s.a[0] == 0.0 {
                assert_vec3_close(&resultant.force, &(-m * to_principal * g), 1e-12, "weight");
                assert_vec3_close(&resultant.torque, &Vector3::zeros(), 1e-12, "no moment at rest");
            }
        }
    }
}

/// Momentum balance of the whole tree: the body resultants' forces, summed in the
/// base frame, are what the base's joints pass in (the joint forces cancel in
/// pairs, `Σ_i S_ia = 0`), and equal the rate of total momentum minus the weight,
/// `dP/dt − M g`, with `dP/dt` by central differences.
#[test]
fn resultant_forces_add_up_to_the_momentum_rate() {
    let h = 1e-5;
    for model in models() {
        let reference = Reference::new(&model);
        let params = model.standard_params();
        let frames: Vec<PrincipalFrame> = model.bodies.iter().map(|b| PrincipalFrame::of(&b.inertial)).collect();
        let total_mass: f64 = model.bodies.iter().map(|b| b.inertial.mass).sum();
        let momentum = |x: &State| -> Vector3<f64> {
            let poses = reference.forward_kinematics(&x.q);
            let motions = reference.body_motions(&x.q, &x.v, &x.a);
            model
                .bodies
                .iter()
                .enumerate()
                .map(|(i, b)| {
                    let (v, w) = (motions[i].velocity.linear, motions[i].velocity.angular);
                    poses[i].rotation * (b.inertial.mass * (v + w.cross(&vec3(&b.inertial.com))))
                })
                .sum()
        };
        for s in sample_states(&model, 5, 40) {
            let poses = reference.forward_kinematics(&s.q);
            let resultants = reference.body_resultants(&s.q, &s.v, &s.a, &params);
            let total: Vector3<f64> = (0..model.dof())
                .map(|i| poses[i].rotation * mat3(&frames[i].rotation) * resultants[i].force)
                .sum();
            let wrenches = reference.joint_wrenches(&s.q, &s.v, &s.a, &params);
            let from_base: Vector3<f64> = (1..=model.dof())
                .filter(|&j| model.parent(j) == 0)
                .map(|j| poses[j - 1].rotation * wrenches[j - 1].force)
                .sum();
            let base_reaction = -from_base;
            assert_vec3_close(&(total + base_reaction), &Vector3::zeros(), 1e-11, "forces cancel");
            let rate = (momentum(&advance(&s, h)) - momentum(&advance(&s, -h))) / (2.0 * h);
            let expected = rate - total_mass * vec3(&model.gravity);
            assert_vec3_close(&total, &expected, 1e-7, "momentum rate");
        }
    }
}
