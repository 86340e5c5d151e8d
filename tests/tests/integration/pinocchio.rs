//! Generated code against Pinocchio 4.1 values committed as JSON fixtures (made by
//! `scripts/make_fixtures.py`), so these tests need no Python.

use dyngen::{Pose, Robot, Wrench};
use dyngen_tests::tree12::Tree12;
use dyngen_tests::{load_fixture, pose_vec, rel_err, wrench_vec};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

const TOL: f64 = 1e-10;

/// Worst relative errors: params, rnea, kinematics, wrenches, crba, nle, gravity,
/// regressor, aba.
fn check<R: Robot>(fixture: &str) -> [f64; 9] {
    let fx = load_fixture(fixture);
    let names: Vec<&str> = fx.model.joint_names.iter().map(String::as_str).collect();
    assert_eq!(
        names,
        R::joint_names(),
        "{}: joint order differs from Pinocchio's",
        fx.name
    );
    let parents: Vec<usize> = fx.model.parents.clone();
    assert_eq!(parents, R::parents(), "{}: parents differ from Pinocchio's", fx.name);
    assert_eq!(fx.gravity, R::gravity());
    let ours: Vec<f64> = R::nominal_params().to_vec();
    let theirs: Vec<f64> = fx.model.dyn_params.iter().flatten().copied().collect();
    let e_params = rel_err(&ours, &theirs, 1e-9);
    assert!(
        e_params < TOL,
        "{}: parameters differ from Pinocchio's: {e_params:e}",
        fx.name
    );

    let n = R::NV;
    let mut worst = [e_params, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let params = R::nominal_params();
    for (k, s) in fx.samples.iter().enumerate() {
        let mut tau = vec![0.0; n];
        R::rnea(&s.q, &s.v, &s.a, R::nominal_params(), &mut tau);
        let e = rel_err(&tau, &s.tau, 1e-9);
        assert!(
            e < TOL,
            "{}: rnea sample {k}: {tau:?} vs Pinocchio {:?} (rel {e:e})",
            fx.name,
            s.tau
        );
        worst[1] = worst[1].max(e);

        let mut poses = vec![Pose::default(); n];
        R::forward_kinematics(&s.q, &mut poses);
        for (b, p) in poses.iter().enumerate() {
            let e = rel_err(&pose_vec(p), &s.o_m_i[b].to_vec(), 1.0);
            assert!(e < TOL, "{}: pose of body {} sample {k}: error {e:e}", fx.name, b + 1);
            worst[2] = worst[2].max(e);
        }

        let mut wrenches = vec![Wrench::default(); n];
        R::joint_wrenches(&s.q, &s.v, &s.a, R::nominal_params(), &mut wrenches);
        let got: Vec<f64> = wrenches.iter().flat_map(wrench_vec).collect();
        let want: Vec<f64> = s.f.iter().flatten().copied().collect();
        let e = rel_err(&got, &want, 1e-9);
        assert!(e < TOL, "{}: joint wrenches sample {k}: rel {e:e}", fx.name);
        worst[3] = worst[3].max(e);

        let mut m = vec![0.0; n * n];
        R::crba(&s.q, params, &mut m);
        let want: Vec<f64> = s.m.iter().flatten().copied().collect();
        worst[4] = worst[4].max(rel_err(&m, &want, 1e-9));
        let mut h = vec![0.0; n];
        R::nonlinear_effects(&s.q, &s.v, params, &mut h);
        worst[5] = worst[5].max(rel_err(&h, &s.nle, 1e-9));
        R::generalized_gravity(&s.q, params, &mut h);
        worst[6] = worst[6].max(rel_err(&h, &s.g, 1e-9));
        let mut y = vec![0.0; n * R::NPARAMS];
        R::joint_torque_regressor(&s.q, &s.v, &s.a, &mut y);
        let want: Vec<f64> = s.y.iter().flatten().copied().collect();
        worst[7] = worst[7].max(rel_err(&y, &want, 1e-9));
        let mut ddq = vec![0.0; n];
        R::aba(&s.q, &s.v, &s.tau_fd, params, &mut ddq);
        worst[8] = worst[8].max(rel_err(&ddq, &s.ddq, 1e-9));
        for (name, e) in ["crba", "nle", "gravity", "regressor", "aba"].iter().zip(&worst[4..]) {
            assert!(
                *e < TOL,
                "{}: {name} differs from Pinocchio at sample {k}: {e:e}",
                fx.name
            );
        }
    }
    // The number of base parameters is the rank of Pinocchio's stacked regressor.
    let rows: Vec<f64> = fx.samples.iter().flat_map(|s| s.y.iter().flatten().copied()).collect();
    let stacked = nalgebra::DMatrix::from_row_slice(n * fx.samples.len(), R::NPARAMS, &rows);
    let sv = stacked.singular_values();
    let rank = sv.iter().filter(|&&x| x > 1e-8 * sv.max()).count();
    assert_eq!(rank, R::NBASE, "{}: rank of Pinocchio's stacked regressor", fx.name);
    eprintln!(
        "{} vs Pinocchio {}: {} samples; max relative error params {:.1e}, rnea {:.1e}, kinematics {:.1e}, \
         wrenches {:.1e}, crba {:.1e}, nle {:.1e}, gravity {:.1e}, regressor {:.1e}, aba {:.1e}; {} base parameters",
        fx.name,
        fx.pinocchio_version,
        fx.samples.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4],
        worst[5],
        worst[6],
        worst[7],
        worst[8],
        R::NBASE
    );
    worst
}

#[test]
fn ur5_matches_pinocchio() {
    check::<Ur5>("ur5");
}

#[test]
fn gripper_arm_matches_pinocchio() {
    check::<GripperArm>("gripper_arm");
}

#[test]
fn planar2_matches_pinocchio() {
    check::<Planar2>("planar2");
}

#[test]
fn paper6_matches_pinocchio() {
    check::<Paper6>("paper6");
}

#[test]
fn puma560_matches_pinocchio() {
    check::<Puma560>("puma560");
}

#[test]
fn panda_matches_pinocchio() {
    check::<Panda>("panda");
}

#[test]
fn tree12_matches_pinocchio() {
    check::<Tree12>("tree12");
}

/// The DSL robots' fixtures were made from the URDF dyngen writes for them; if the
/// description changes, the committed URDF (and the fixture) must be regenerated.
#[test]
fn dsl_robot_urdfs_are_current() {
    for (name, urdf) in [
        ("planar2", dyngen_reference::urdf_of::<Planar2>()),
        ("paper6", dyngen_reference::urdf_of::<Paper6>()),
    ] {
        let path = dyngen_tests::workspace_root()
            .join("tests/fixtures")
            .join(format!("{name}.urdf"));
        let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            committed,
            urdf,
            "{} is stale: run `cargo run -p dyngen-tests --example export_urdfs` and regenerate the fixtures",
            path.display()
        );
    }
}
