//! Generated code against Pinocchio 4.1 values committed as JSON fixtures (made by
//! `scripts/make_fixtures.py`), so these tests need no Python.

use dyngen::{Pose, Robot, Wrench};
use dyngen_tests::{load_fixture, pose_vec, rel_err, wrench_vec};
use robot_gripper_arm::GripperArm;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_ur5::Ur5;

const TOL: f64 = 1e-10;

fn check<R: Robot>(fixture: &str) -> [f64; 4] {
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
    let mut worst = [e_params, 0.0, 0.0, 0.0];
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
    }
    eprintln!(
        "{} vs Pinocchio {}: {} samples; max relative error params {:.2e}, rnea {:.2e}, kinematics {:.2e}, wrenches {:.2e}",
        fx.name,
        fx.pinocchio_version,
        fx.samples.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
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

/// The DSL robots' fixtures were made from the URDF dyngen writes for them; if the
/// description changes, the committed URDF (and the fixture) must be regenerated.
#[test]
fn dsl_robot_urdfs_are_current() {
    for (name, urdf) in [("planar2", Planar2::URDF), ("paper6", Paper6::URDF)] {
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
