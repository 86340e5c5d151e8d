//! Identities between the generated algorithms, on every shipped robot, 200 random
//! states each (fixed seeds), with nominal and perturbed parameters:
//! `Y π = rnea`, `Y_b β = rnea`, `Y_θ θ = rnea`, joint wrench regressor · π = joint
//! wrenches, `M` symmetric positive definite with `M a + h = rnea`,
//! `aba(q, v, rnea(q, v, a)) = a`, `nle = rnea(q, v, 0)`, `g = rnea(q, 0, 0)`, and the
//! paper's decoupling `A_i θ_i` = body resultants.

use dyngen::{BodyRegressor, Robot, Wrench};
use dyngen_reference::Reference;
use dyngen_reference::{perturbed_params, sample_states};
use dyngen_tests::tree12::Tree12;
use dyngen_tests::{rel_err, wrench_vec};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

const STATES: usize = 200;
const TOL: f64 = 1e-9;

fn mat_vec(m: &[f64], cols: usize, x: &[f64]) -> Vec<f64> {
    m.chunks(cols)
        .map(|row| row.iter().zip(x).map(|(a, b)| a * b).sum())
        .collect()
}

/// Cholesky without pivoting: `None` unless symmetric positive definite.
fn is_spd(m: &[f64], n: usize) -> bool {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            if (m[i * n + j] - m[j * n + i]).abs() > 1e-12 * (1.0 + m[i * n + j].abs()) {
                return false;
            }
            let s: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            if i == j {
                let d = m[i * n + i] - s;
                if d <= 0.0 {
                    return false;
                }
                l[i * n + i] = d.sqrt();
            } else {
                l[i * n + j] = (m[i * n + j] - s) / l[j * n + j];
            }
        }
    }
    true
}

fn check<R: Robot>(seed: u64) {
    let reference = Reference::of::<R>();
    let model = reference.model().clone();
    let (n, np, nt) = (R::NV, R::NPARAMS, R::NTHETA);
    let zeros = vec![0.0; n];
    for (k, s) in sample_states(&model, STATES, seed).iter().enumerate() {
        let params = if k % 2 == 0 {
            R::nominal_params().to_vec()
        } else {
            perturbed_params(&model, seed + k as u64, 0.3)
        };
        let mut tau = vec![0.0; n];
        R::rnea(&s.q, &s.v, &s.a, &params, &mut tau);

        let mut y = vec![0.0; n * np];
        R::joint_torque_regressor(&s.q, &s.v, &s.a, &mut y);
        let e = rel_err(&mat_vec(&y, np, &params), &tau, 1e-9);
        assert!(e < TOL, "{}: Y π ≠ rnea at state {k}: {e:e}", R::NAME);

        let mut beta = vec![0.0; R::NBASE];
        R::base_params(&params, &mut beta);
        let mut yb = vec![0.0; n * R::NBASE];
        R::base_regressor(&s.q, &s.v, &s.a, &mut yb);
        let e = rel_err(&mat_vec(&yb, R::NBASE, &beta), &tau, 1e-9);
        assert!(e < TOL, "{}: Y_b β ≠ rnea at state {k}: {e:e}", R::NAME);

        let mut yw = vec![0.0; 6 * n * np];
        R::joint_wrench_regressor(&s.q, &s.v, &s.a, &mut yw);
        let mut w = vec![Wrench::default(); n];
        R::joint_wrenches(&s.q, &s.v, &s.a, &params, &mut w);
        let want: Vec<f64> = w.iter().flat_map(wrench_vec).collect();
        let e = rel_err(&mat_vec(&yw, np, &params), &want, 1e-9);
        assert!(
            e < TOL,
            "{}: wrench regressor · π ≠ joint wrenches at state {k}: {e:e}",
            R::NAME
        );

        let mut m = vec![0.0; n * n];
        R::crba(&s.q, &params, &mut m);
        assert!(
            is_spd(&m, n),
            "{}: M not symmetric positive definite at state {k}",
            R::NAME
        );
        let mut h = vec![0.0; n];
        R::nonlinear_effects(&s.q, &s.v, &params, &mut h);
        let mut h_ref = vec![0.0; n];
        R::rnea(&s.q, &s.v, &zeros, &params, &mut h_ref);
        assert!(rel_err(&h, &h_ref, 1e-9) < TOL, "{}: nle ≠ rnea(q, v, 0)", R::NAME);
        let mut gq = vec![0.0; n];
        R::generalized_gravity(&s.q, &params, &mut gq);
        R::rnea(&s.q, &zeros, &zeros, &params, &mut h_ref);
        assert!(rel_err(&gq, &h_ref, 1e-9) < TOL, "{}: g ≠ rnea(q, 0, 0)", R::NAME);
        let ma_h: Vec<f64> = mat_vec(&m, n, &s.a).iter().zip(&h).map(|(x, y)| x + y).collect();
        let e = rel_err(&ma_h, &tau, 1e-9);
        assert!(e < TOL, "{}: M a + h ≠ rnea at state {k}: {e:e}", R::NAME);

        let mut acc = vec![0.0; n];
        R::aba(&s.q, &s.v, &tau, &params, &mut acc);
        let e = rel_err(&acc, &s.a, 1.0);
        assert!(e < 1e-8, "{}: aba(rnea(a)) ≠ a at state {k}: {e:e}", R::NAME);
    }
    // Principal parameters: θ with the description's centres of mass and axes.
    for (k, s) in sample_states(&model, STATES / 4, seed + 1000).iter().enumerate() {
        let theta = R::nominal_theta();
        let mut tau = vec![0.0; n];
        R::rnea(&s.q, &s.v, &s.a, R::nominal_params(), &mut tau);
        let mut yt = vec![0.0; n * nt];
        R::principal_regressor(&s.q, &s.v, &s.a, &mut yt);
        let e = rel_err(&mat_vec(&yt, nt, theta), &tau, 1e-9);
        assert!(e < TOL, "{}: Y_θ θ ≠ rnea at state {k}: {e:e}", R::NAME);
        let mut bt = vec![0.0; R::NBASE_PRINCIPAL];
        R::principal_base_params(theta, &mut bt);
        let mut ybt = vec![0.0; n * R::NBASE_PRINCIPAL];
        R::principal_base_regressor(&s.q, &s.v, &s.a, &mut ybt);
        let e = rel_err(&mat_vec(&ybt, R::NBASE_PRINCIPAL, &bt), &tau, 1e-9);
        assert!(e < TOL, "{}: principal Y_b β ≠ rnea at state {k}: {e:e}", R::NAME);

        // The paper's decoupling: each body's Newton–Euler holds alone.
        let mut a_i = vec![BodyRegressor::default(); n];
        R::body_regressors(&s.q, &s.v, &s.a, &mut a_i);
        let mut res = vec![Wrench::default(); n];
        R::body_resultants(&s.q, &s.v, &s.a, R::nominal_params(), &mut res);
        for b in 0..n {
            let th = nalgebra::Vector4::from_column_slice(&theta[4 * b..4 * b + 4]);
            let got: Vec<f64> = (a_i[b].force * th)
                .iter()
                .chain((a_i[b].moment * th).iter())
                .copied()
                .collect();
            let e = rel_err(&got, &wrench_vec(&res[b]), 1e-9);
            assert!(
                e < TOL,
                "{}: A_{} θ ≠ body resultant at state {k}: {e:e}",
                R::NAME,
                b + 1
            );
        }
    }
    eprintln!(
        "{}: {} base parameters (standard), {} (principal)",
        R::NAME,
        R::NBASE,
        R::NBASE_PRINCIPAL
    );
}

#[test]
fn planar2_identities() {
    check::<Planar2>(21);
}

#[test]
fn paper6_identities() {
    check::<Paper6>(22);
}

#[test]
fn ur5_identities() {
    check::<Ur5>(23);
}

#[test]
fn gripper_arm_identities() {
    check::<GripperArm>(24);
}

#[test]
fn puma560_identities() {
    check::<Puma560>(25);
}

#[test]
fn panda_identities() {
    check::<Panda>(26);
}

#[test]
fn tree12_identities() {
    check::<Tree12>(27);
}

/// The base-parameter analysis picks the same columns with a second seed, and the
/// generated constants are what the generator reports.
#[test]
fn base_parameters_are_confirmed_by_a_second_seed() {
    fn confirm<R: Robot>() {
        let model = dyngen_reference::model_from_static(&R::MODEL);
        let g = dyngen_codegen::analyse_model(&model);
        assert!(
            g.standard.confirmed && g.principal.confirmed,
            "{}: the second seed disagrees",
            R::NAME
        );
        assert_eq!(g.standard.independent, R::base_index(), "{}", R::NAME);
        assert_eq!(g.principal.independent, R::principal_base_index(), "{}", R::NAME);
        assert_eq!(g.standard.groupings, R::base_groupings(), "{}", R::NAME);
    }
    confirm::<Planar2>();
    confirm::<Paper6>();
    confirm::<Ur5>();
    confirm::<GripperArm>();
    confirm::<Puma560>();
    confirm::<Panda>();
    confirm::<Tree12>();
}
