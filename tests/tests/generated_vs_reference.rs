//! Generated code against the reference implementation on 1,000 random states per
//! robot (fixed seeds), with nominal and with perturbed parameters.

use dyngen::reference::{perturbed_params, sample_states};
use dyngen::{Pose, Robot, Wrench};
use dyngen_tests::{pose_vec, reference_of, rel_err, wrench_vec};
use robot_gripper_arm::GripperArm;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_ur5::Ur5;

const STATES: usize = 1000;
const TOL: f64 = 1e-10;

/// Returns the worst relative errors (rnea, forward kinematics, joint wrenches).
fn check<R: Robot>(seed: u64) -> [f64; 3] {
    let reference = reference_of::<R>();
    let model = reference.model().clone();
    let n = R::NV;
    let mut worst = [0.0f64; 3];
    for (k, s) in sample_states(&model, STATES, seed).iter().enumerate() {
        // Every other state uses parameters that are not the nominal ones, so that
        // the parameters really are a runtime input.
        let params = if k % 2 == 0 {
            R::nominal_params().to_vec()
        } else {
            perturbed_params(&model, seed + k as u64, 0.3)
        };
        let mut tau = vec![0.0; n];
        R::rnea(&s.q, &s.v, &s.a, &params, &mut tau);
        let e = rel_err(&tau, &reference.rnea(&s.q, &s.v, &s.a, &params), 1e-9);
        assert!(e < TOL, "{}: rnea state {k}: relative error {e:e}", R::NAME);
        worst[0] = worst[0].max(e);

        let mut poses = vec![Pose::default(); n];
        R::forward_kinematics(&s.q, &mut poses);
        for (b, (p, r)) in poses.iter().zip(reference.forward_kinematics(&s.q)).enumerate() {
            let e = rel_err(&pose_vec(p), &pose_vec(&r), 1.0);
            assert!(e < TOL, "{}: pose of body {} state {k}: error {e:e}", R::NAME, b + 1);
            worst[1] = worst[1].max(e);
        }

        let mut wrenches = vec![Wrench::default(); n];
        R::joint_wrenches(&s.q, &s.v, &s.a, &params, &mut wrenches);
        let got: Vec<f64> = wrenches.iter().flat_map(wrench_vec).collect();
        let want: Vec<f64> = reference
            .joint_wrenches(&s.q, &s.v, &s.a, &params)
            .iter()
            .flat_map(wrench_vec)
            .collect();
        let e = rel_err(&got, &want, 1e-9);
        assert!(e < TOL, "{}: joint wrenches state {k}: relative error {e:e}", R::NAME);
        worst[2] = worst[2].max(e);
    }
    eprintln!(
        "{}: max relative error rnea {:.2e}, kinematics {:.2e}, wrenches {:.2e}",
        R::NAME,
        worst[0],
        worst[1],
        worst[2]
    );
    worst
}

#[test]
fn planar2_matches_reference() {
    check::<Planar2>(1);
}

#[test]
fn paper6_matches_reference() {
    check::<Paper6>(2);
}

#[test]
fn ur5_matches_reference() {
    check::<Ur5>(3);
}

#[test]
fn gripper_arm_matches_reference() {
    check::<GripperArm>(4);
}

/// The generic `f32` instantiation computes the same thing, to `f32` accuracy.
#[test]
fn f32_instantiation_agrees() {
    let q = [0.3f64, -0.7, 1.1, 0.2, -0.4, 0.9];
    let v = [0.5, -0.2, 0.1, 0.9, -1.0, 0.3];
    let a = [-0.3, 0.8, 0.2, -0.5, 0.6, -0.1];
    let tau64 = Ur5::rnea(&q, &v, &a, &Ur5::NOMINAL_PARAMS);
    let p32 = Ur5::NOMINAL_PARAMS.map(|x| x as f32);
    let tau32 = Ur5::rnea(&q.map(|x| x as f32), &v.map(|x| x as f32), &a.map(|x| x as f32), &p32);
    let tau32: Vec<f64> = tau32.iter().map(|&x| f64::from(x)).collect();
    assert!(rel_err(&tau32, &tau64, 1e-6) < 1e-5);
}

/// The trait's slice API rejects a wrong length with a message naming the argument.
#[test]
#[should_panic(expected = "`q` has length 5, expected 6")]
fn slice_api_names_wrong_length() {
    let mut tau = [0.0; 6];
    <Ur5 as Robot>::rnea(&[0.0; 5], &[0.0; 6], &[0.0; 6], &Ur5::NOMINAL_PARAMS, &mut tau);
}
