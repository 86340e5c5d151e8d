//! The generated joint models (rotor inertia and friction, `*_joints`) against the
//! reference implementation with the identification crate's joint regressor, the
//! simulator's joint torques, and Pinocchio with `armature`
//! (`tests/fixtures/armature.json`, made by `scripts/make_armature_fixture.py`); and
//! the identities between them (`[Y | Y_j] · [π; φ] = rnea_joints`,
//! `Y_bj · β_j = rnea_joints`, `aba_joints(rnea_joints(a)) = a`).

use dyngen::{Coulomb, JointDynamics, Robot};
use dyngen_identify::mim::TorqueRegressor;
use dyngen_model::joint_params::Coulomb as ModelCoulomb;
use dyngen_model::sample::SplitMix64;
use dyngen_reference::{perturbed_params, sample_states, Reference};
use dyngen_tests::rel_err;
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

const STATES: usize = 200;
const TOL: f64 = 1e-12;

/// Random joint parameters of plausible drives: `Ia` 0.01–0.5, `Fv` 0–3, `Fc` 0–5,
/// `F0` ±1.
fn joint_params(n: usize, rng: &mut SplitMix64) -> Vec<f64> {
    (0..n)
        .flat_map(|_| [(0.01, 0.5), (0.0, 3.0), (0.0, 5.0), (-1.0, 1.0)])
        .map(|(lo, hi)| rng.uniform(lo, hi))
        .collect()
}

/// The same Coulomb model in the generated code's and the model layer's types.
fn coulombs(k: usize) -> (Coulomb<f64>, ModelCoulomb) {
    if k.is_multiple_of(2) {
        (Coulomb::Sign, ModelCoulomb::Sign)
    } else {
        (Coulomb::smooth(0.05).unwrap(), ModelCoulomb::Smooth { epsilon: 0.05 })
    }
}

/// Worst relative errors of rnea_joints, the widened regressor, crba_joints,
/// aba_joints (against the reference) and of the identities (regressor, base
/// regressor, aba ∘ rnea).
fn check<R: Robot>(seed: u64) -> [f64; 7] {
    let reference = Reference::of::<R>();
    let model = reference.model().clone();
    let n = R::NV;
    let w = R::NPARAMS + R::NJOINT_PARAMS;
    assert_eq!(R::NJOINT_PARAMS, 4 * n);
    let mut rng = SplitMix64::new(seed);
    let mut worst = [0.0f64; 7];
    for (k, s) in sample_states(&model, STATES, seed).iter().enumerate() {
        let (q, v, a) = (&s.q, &s.v, &s.a);
        let params = perturbed_params(&model, seed + k as u64, 0.3);
        let jp = joint_params(n, &mut rng);
        let (coulomb, model_coulomb) = coulombs(k);
        let x: Vec<f64> = params.iter().chain(&jp).copied().collect();

        let mut tau = vec![0.0; n];
        R::rnea_joints(q, v, a, &params, &jp, coulomb, &mut tau);
        let widened = TorqueRegressor::StandardAndJoints(model_coulomb.into());
        let mut y_ref = vec![0.0; n * w];
        let want = widened.predict(&reference, q, v, a, &x, &mut y_ref);
        let e = rel_err(&tau, &want, 1e-9);
        assert!(e < TOL, "{}: rnea_joints state {k}: relative error {e:e}", R::NAME);
        worst[0] = worst[0].max(e);

        let mut y = vec![0.0; n * w];
        R::torque_regressor_joints(q, v, a, coulomb, &mut y);
        let e = rel_err(&y, &y_ref, 1e-9);
        assert!(e < TOL, "{}: torque_regressor_joints state {k}: {e:e}", R::NAME);
        worst[1] = worst[1].max(e);

        let mut m = vec![0.0; n * n];
        R::crba_joints(q, &params, &jp, &mut m);
        let mut m_ref = reference.crba(q, &params);
        for j in 0..n {
            m_ref[(j, j)] += jp[4 * j];
        }
        let e = rel_err(&m, m_ref.transpose().as_slice(), 1e-9);
        assert!(e < TOL, "{}: crba_joints state {k}: {e:e}", R::NAME);
        worst[2] = worst[2].max(e);

        // Forward dynamics: (M + diag Ia) a = tau − h − friction, solved densely.
        let tau_fd: Vec<f64> = (0..n).map(|_| rng.uniform(-10.0, 10.0)).collect();
        let mut acc = vec![0.0; n];
        R::aba_joints(q, v, &tau_fd, &params, &jp, coulomb, &mut acc);
        let h = reference.nonlinear_effects(q, v, &params);
        let rhs = nalgebra::DVector::from_iterator(
            n,
            (0..n).map(|j| {
                let p = dyngen::JointParams::of(&jp, j).unwrap();
                tau_fd[j] - h[j] - p.friction(v[j], coulomb)
            }),
        );
        let want = m_ref
            .clone()
            .cholesky()
            .expect("M + diag(Ia) is positive definite")
            .solve(&rhs);
        let e = rel_err(&acc, want.as_slice(), 1.0);
        assert!(e < TOL, "{}: aba_joints state {k}: {e:e}", R::NAME);
        worst[3] = worst[3].max(e);

        // Identities on the generated code alone.
        let ytau: Vec<f64> = y
            .chunks(w)
            .map(|row| row.iter().zip(&x).map(|(a, b)| a * b).sum())
            .collect();
        worst[4] = worst[4].max(rel_err(&ytau, &tau, 1e-9));
        let mut yb = vec![0.0; n * R::NBASE_JOINTS];
        R::base_regressor_joints(q, v, a, coulomb, &mut yb);
        let mut beta = vec![0.0; R::NBASE_JOINTS];
        R::base_params_joints(&params, &jp, &mut beta);
        let btau: Vec<f64> = yb
            .chunks(R::NBASE_JOINTS)
            .map(|row| row.iter().zip(&beta).map(|(a, b)| a * b).sum())
            .collect();
        worst[5] = worst[5].max(rel_err(&btau, &tau, 1e-9));
        let mut back = vec![0.0; n];
        R::aba_joints(q, v, &tau, &params, &jp, coulomb, &mut back);
        worst[6] = worst[6].max(rel_err(&back, a, 1.0));
        for (name, e) in ["regressor identity", "base identity", "aba(rnea)"]
            .iter()
            .zip(&worst[4..])
        {
            assert!(*e < 1e-10, "{}: {name} at state {k}: {e:e}", R::NAME);
        }
    }
    eprintln!(
        "{}: {STATES} states, max relative error rnea_joints {:.1e}, torque_regressor_joints {:.1e}, \
         crba_joints {:.1e}, aba_joints {:.1e}; identities Y·x {:.1e}, Y_b·β {:.1e}, aba∘rnea {:.1e}; \
         {} base parameters with the joints ({} without)",
        R::NAME,
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4],
        worst[5],
        worst[6],
        R::NBASE_JOINTS,
        R::NBASE
    );
    worst
}

#[test]
fn ur5_joints_match_the_reference() {
    check::<Ur5>(1);
}

#[test]
fn panda_joints_match_the_reference() {
    check::<Panda>(2);
}

#[test]
fn gripper_arm_joints_match_the_reference() {
    check::<GripperArm>(3);
}

#[test]
fn puma560_joints_match_the_reference() {
    check::<Puma560>(4);
}

#[test]
fn dsl_robots_joints_match_the_reference() {
    check::<Planar2>(5);
    check::<Paper6>(6);
}

/// The simulator's drive model (`add_joint_terms` on a recorded experiment) is the
/// generated `rnea_joints`.
#[test]
fn rnea_joints_is_the_simulators_drive_model() {
    use dyngen_identify::simulate::{add_joint_terms, record, Experiment};
    let reference = Reference::of::<Ur5>();
    let model = reference.model().clone();
    let mut rng = SplitMix64::new(9);
    let jp = joint_params(6, &mut rng);
    let mut recording = record(&reference, &model.standard_params(), &Experiment::paper(&model));
    add_joint_terms(&mut recording, &jp, ModelCoulomb::Sign);
    let jp: [f64; 24] = jp.try_into().unwrap();
    let mut worst = 0.0f64;
    for s in &recording.samples {
        let (q, v, a) = (to6(&s.q), to6(&s.v), to6(&s.a));
        let tau = Ur5::rnea_joints(&q, &v, &a, &Ur5::NOMINAL_PARAMS, &jp, Coulomb::Sign);
        worst = worst.max(rel_err(&tau, &s.tau, 1e-9));
    }
    assert!(worst < TOL, "simulator vs rnea_joints: {worst:e}");
}

fn to6(x: &[f64]) -> [f64; 6] {
    x.try_into().unwrap()
}

/// The first joint's rotor turns about the same fixed axis as body 1, so its `Ia1`
/// merges with that body's `Izz1`; the count of base parameters says so.
#[test]
fn rotor_inertia_of_the_first_joint_merges_with_its_link() {
    assert_eq!(Ur5::NBASE_JOINTS, Ur5::NBASE + 24 - 2);
    assert!(!Ur5::BASE_JOINTS_INDEX.contains(&60), "{:?}", Ur5::BASE_JOINTS_INDEX);
    assert!(
        Ur5::BASE_JOINTS_GROUPINGS
            .iter()
            .any(|g| g.starts_with("Izz1") && g.contains("Ia1")),
        "{:?}",
        Ur5::BASE_JOINTS_GROUPINGS
    );
    // URDF <dynamics damping friction> are the nominal Fv, Fc.
    for (j, joint) in Ur5::MODEL.joints.iter().enumerate() {
        assert_eq!(
            Ur5::NOMINAL_JOINT_PARAMS[4 * j..4 * j + 4],
            [0.0, joint.damping, joint.friction, 0.0]
        );
    }
}

#[derive(serde::Deserialize)]
struct ArmatureFixture {
    pinocchio_version: String,
    robots: Vec<ArmatureRobot>,
}

#[derive(serde::Deserialize)]
struct ArmatureRobot {
    name: String,
    joint_names: Vec<String>,
    armature: Vec<f64>,
    samples: Vec<ArmatureSample>,
}

#[derive(serde::Deserialize)]
#[allow(non_snake_case)]
struct ArmatureSample {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    M: Vec<Vec<f64>>,
    tau_fd: Vec<f64>,
    ddq: Vec<f64>,
}

/// `rnea_joints`, `crba_joints` and `aba_joints` with rotor inertias and no
/// friction against Pinocchio with `model.armature`. Returns the worst relative
/// errors (rnea, crba, aba).
fn check_armature<R: Robot>(fx: &ArmatureRobot, version: &str) -> [f64; 3] {
    let names: Vec<&str> = fx.joint_names.iter().map(String::as_str).collect();
    assert_eq!(names, R::joint_names(), "{}: joint order", fx.name);
    let n = R::NV;
    let jp: Vec<f64> = fx.armature.iter().flat_map(|&ia| [ia, 0.0, 0.0, 0.0]).collect();
    let params = R::nominal_params();
    let mut worst = [0.0f64; 3];
    for (k, s) in fx.samples.iter().enumerate() {
        let mut tau = vec![0.0; n];
        R::rnea_joints(&s.q, &s.v, &s.a, params, &jp, Coulomb::Sign, &mut tau);
        worst[0] = worst[0].max(rel_err(&tau, &s.tau, 1e-9));
        let mut m = vec![0.0; n * n];
        R::crba_joints(&s.q, params, &jp, &mut m);
        let want: Vec<f64> = s.M.iter().flatten().copied().collect();
        worst[1] = worst[1].max(rel_err(&m, &want, 1e-9));
        let mut ddq = vec![0.0; n];
        R::aba_joints(&s.q, &s.v, &s.tau_fd, params, &jp, Coulomb::Sign, &mut ddq);
        worst[2] = worst[2].max(rel_err(&ddq, &s.ddq, 1e-9));
        for (name, e) in ["rnea_joints", "crba_joints", "aba_joints"].iter().zip(&worst) {
            assert!(*e < 1e-12, "{}: {name} vs Pinocchio at sample {k}: {e:e}", fx.name);
        }
    }
    eprintln!(
        "{} with armature vs Pinocchio {version}: {} samples; max relative error rnea_joints {:.1e}, \
         crba_joints {:.1e}, aba_joints {:.1e}",
        fx.name,
        fx.samples.len(),
        worst[0],
        worst[1],
        worst[2]
    );
    worst
}

#[test]
fn armature_matches_pinocchio() {
    let path = dyngen_tests::workspace_root().join("tests/fixtures/armature.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let fx: ArmatureFixture = serde_json::from_str(&text).unwrap();
    let names: Vec<&str> = fx.robots.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["ur5", "panda"]);
    check_armature::<Ur5>(&fx.robots[0], &fx.pinocchio_version);
    check_armature::<Panda>(&fx.robots[1], &fx.pinocchio_version);
}

/// The slice methods name the argument whose length is wrong.
#[test]
#[should_panic(expected = "`joint_params` has length 23, expected 24")]
fn a_short_joint_parameter_vector_is_named() {
    let mut tau = [0.0; 6];
    <Ur5 as JointDynamics>::rnea_joints(
        &[0.0; 6],
        &[0.0; 6],
        &[0.0; 6],
        &Ur5::NOMINAL_PARAMS,
        &[0.0; 23],
        Coulomb::Sign,
        &mut tau,
    );
}
