//! Generated code against the reference implementation on 1,000 random states per
//! robot (fixed seeds), with nominal and with perturbed parameters.

use dyngen::{BodyRegressor, InverseDynamics, Pose, Robot, Wrench};
use dyngen_reference::Reference;
use dyngen_reference::{perturbed_params, sample_states};
use dyngen_tests::tree12::Tree12;
use dyngen_tests::{pose_vec, rel_err, wrench_vec};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

const STATES: usize = 1000;
const TOL: f64 = 1e-10;

fn mat(rows: usize, cols: usize, data: &[f64]) -> nalgebra::DMatrix<f64> {
    nalgebra::DMatrix::from_row_slice(rows, cols, data)
}

/// Returns the worst relative errors (rnea, forward kinematics, joint wrenches,
/// crba, aba, torque regressor, wrench regressor, principal regressor, body
/// regressors, body resultants).
fn check<R: Robot>(seed: u64) -> [f64; 10] {
    let reference = Reference::of::<R>();
    let model = reference.model().clone();
    let n = R::NV;
    let mut worst = [0.0f64; 10];
    let n6 = 6 * n;
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

        if k % 10 != 0 {
            continue;
        }
        let (q, v, a) = (&s.q, &s.v, &s.a);
        let mut m = vec![0.0; n * n];
        R::crba(q, &params, &mut m);
        worst[3] = worst[3].max(rel_err(&m, reference.crba(q, &params).transpose().as_slice(), 1e-9));
        let mut acc = vec![0.0; n];
        R::aba(q, v, &tau, &params, &mut acc);
        worst[4] = worst[4].max(rel_err(&acc, &reference.aba(q, v, &tau, &params), 1.0));
        // Row-major generated matrices against column-major nalgebra ones.
        let mut y = vec![0.0; n * R::NPARAMS];
        R::joint_torque_regressor(q, v, a, &mut y);
        let want = reference.joint_torque_regressor(q, v, a);
        worst[5] = worst[5].max(rel_err(mat(n, R::NPARAMS, &y).as_slice(), want.as_slice(), 1e-9));
        let mut yw = vec![0.0; n6 * R::NPARAMS];
        R::joint_wrench_regressor(q, v, a, &mut yw);
        let want = reference.joint_wrench_regressor(q, v, a);
        worst[6] = worst[6].max(rel_err(mat(n6, R::NPARAMS, &yw).as_slice(), want.as_slice(), 1e-9));
        let mut yt = vec![0.0; n * R::NTHETA];
        R::principal_regressor(q, v, a, &mut yt);
        let want = reference.principal_regressor(q, v, a);
        worst[7] = worst[7].max(rel_err(mat(n, R::NTHETA, &yt).as_slice(), want.as_slice(), 1e-9));
        let mut ai = vec![BodyRegressor::default(); n];
        R::body_regressors(q, v, a, &mut ai);
        for (b, want) in reference.body_regressor(q, v, a).iter().enumerate() {
            let got: Vec<f64> = (0..6)
                .flat_map(|r| (0..4).map(move |c| (r, c)))
                .map(|(r, c)| {
                    if r < 3 {
                        ai[b].force[(r, c)]
                    } else {
                        ai[b].moment[(r - 3, c)]
                    }
                })
                .collect();
            let want: Vec<f64> = (0..6).flat_map(|r| (0..4).map(move |c| want[(r, c)])).collect();
            worst[8] = worst[8].max(rel_err(&got, &want, 1e-9));
        }
        let mut res = vec![Wrench::default(); n];
        R::body_resultants(q, v, a, &params, &mut res);
        let got: Vec<f64> = res.iter().flat_map(wrench_vec).collect();
        let want: Vec<f64> = reference
            .body_resultants(q, v, a, &params)
            .iter()
            .flat_map(wrench_vec)
            .collect();
        worst[9] = worst[9].max(rel_err(&got, &want, 1e-9));
        let names = [
            "crba",
            "aba",
            "torque regressor",
            "wrench regressor",
            "principal regressor",
            "body regressors",
            "body resultants",
        ];
        for (name, e) in names.iter().zip(&worst[3..]) {
            assert!(*e < TOL, "{}: {name} state {k}: relative error {e:e}", R::NAME);
        }
    }
    eprintln!(
        "{}: max relative error rnea {:.1e}, kinematics {:.1e}, wrenches {:.1e}, crba {:.1e}, aba {:.1e}, \
         regressors (torque, wrench, principal) {:.1e} {:.1e} {:.1e}, body regressors {:.1e}, body resultants {:.1e}",
        R::NAME,
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4],
        worst[5],
        worst[6],
        worst[7],
        worst[8],
        worst[9]
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
    <Ur5 as InverseDynamics>::rnea(&[0.0; 5], &[0.0; 6], &[0.0; 6], &Ur5::NOMINAL_PARAMS, &mut tau);
}

#[test]
fn puma560_matches_reference() {
    check::<Puma560>(5);
}

#[test]
fn panda_matches_reference() {
    check::<Panda>(6);
}

#[test]
fn tree12_matches_reference() {
    check::<Tree12>(7);
}
