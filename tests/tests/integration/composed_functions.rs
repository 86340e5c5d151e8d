//! The functions a large tree composes of other generated functions (`aba_joints`,
//! `nonlinear_effects`, the principal and base regressors, `frame_placement`,
//! `frame_jacobian_time_variation`, `frame_motion`, `aba_derivatives`,
//! `aba_joints_derivatives`) compute what their own graphs do: a
//! UR5 generated with `compose_above(0)` against `robot_ur5::Ur5`. The UR5 is a
//! chain, so the products by `−M⁻¹` take the dense path here; the humanoid's
//! (`tests/floating.rs`) take the sparse one.

use dyngen::{AbaDerivatives, Coulomb, FrameJacobianTimeVariation, ReferenceFrame};
use dyngen_reference::{sample_states, Reference};
use dyngen_tests::composed::{Ur5Composed, Ur5ComposedFrame};
use dyngen_tests::rel_err;
use robot_ur5::{Ur5, Ur5Frame};

fn flat<const R: usize, const C: usize>(m: &[[f64; C]; R]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

fn derivatives(d: &AbaDerivatives<f64, 6>) -> Vec<f64> {
    let mut x = d.ddq.to_vec();
    for m in [&d.ddq_dq, &d.ddq_dv, &d.minv] {
        x.extend(flat(m));
    }
    x
}

#[test]
fn composed_functions_are_composed() {
    let names: Vec<&str> = Ur5Composed::OP_COUNTS.iter().map(|(n, _)| *n).collect();
    for composed in [
        "aba_joints",
        "nonlinear_effects",
        "base_regressor",
        "principal_regressor",
        "principal_base_regressor",
    ] {
        assert!(!names.contains(&composed), "{composed} has a graph of its own");
        assert!(Ur5::OP_COUNTS.iter().any(|(n, _)| *n == composed), "{composed}");
    }
    // `aba` keeps its own graph on every tree (zero rows along the joint axes).
    assert!(names.contains(&"aba"));
    // A Jacobian per frame; one function for the time variations of all of them.
    assert!(!names.iter().any(|n| n.starts_with("frame_placement[")
        || n.starts_with("frame_motion[")
        || n.starts_with("frame_jacobian_time_variation[")));
    assert!(names.iter().any(|n| n.starts_with("frame_jacobian[")));
    assert!(names.contains(&"frame_jacobian_time_variation"));
    assert!(!names.contains(&"aba_derivatives"));
}

#[test]
fn composed_functions_agree_with_their_own_graphs() {
    let model = Reference::of::<Ur5>().model().clone();
    let params = Ur5::NOMINAL_PARAMS;
    let mut jp = [0.0; 24];
    for j in 0..6 {
        jp[4 * j..4 * j + 4].copy_from_slice(&[0.05 + 0.01 * j as f64, 0.8, 1.5 - 0.1 * j as f64, 0.2]);
    }
    let coulomb = Coulomb::smooth(0.05).unwrap();
    let mut worst: f64 = 0.0;
    let mut check = |got: &[f64], want: &[f64]| worst = worst.max(rel_err(got, want, 1.0));
    for s in sample_states(&model, 20, 3) {
        let (q, v, a): ([f64; 6], [f64; 6], [f64; 6]) = (
            s.q.try_into().unwrap(),
            s.v.try_into().unwrap(),
            s.a.try_into().unwrap(),
        );
        let tau = Ur5::rnea(&q, &v, &a, &params);
        check(
            &Ur5Composed::aba(&q, &v, &tau, &params),
            &Ur5::aba(&q, &v, &tau, &params),
        );
        check(
            &Ur5Composed::aba_joints(&q, &v, &tau, &params, &jp, coulomb),
            &Ur5::aba_joints(&q, &v, &tau, &params, &jp, coulomb),
        );
        check(
            &Ur5Composed::nonlinear_effects(&q, &v, &params),
            &Ur5::nonlinear_effects(&q, &v, &params),
        );
        let (mut y, mut want) = ([[0.0; Ur5::NBASE]; 6], [[0.0; Ur5::NBASE]; 6]);
        Ur5Composed::base_regressor(&q, &v, &a, &mut y);
        Ur5::base_regressor(&q, &v, &a, &mut want);
        check(&flat(&y), &flat(&want));
        let (mut y, mut want) = ([[0.0; Ur5::NTHETA]; 6], [[0.0; Ur5::NTHETA]; 6]);
        Ur5Composed::principal_regressor(&q, &v, &a, &mut y);
        Ur5::principal_regressor(&q, &v, &a, &mut want);
        check(&flat(&y), &flat(&want));
        let (mut y, mut want) = ([[0.0; Ur5::NBASE_PRINCIPAL]; 6], [[0.0; Ur5::NBASE_PRINCIPAL]; 6]);
        Ur5Composed::principal_base_regressor(&q, &v, &a, &mut y);
        Ur5::principal_base_regressor(&q, &v, &a, &mut want);
        check(&flat(&y), &flat(&want));
        for (f, g) in Ur5ComposedFrame::ALL.into_iter().zip(Ur5Frame::ALL) {
            let (p, pw) = (Ur5Composed::frame_placement(&q, f), Ur5::frame_placement(&q, g));
            check(&dyngen_tests::pose_vec(&p), &dyngen_tests::pose_vec(&pw));
            let (m, mw) = (
                Ur5Composed::frame_motion(&q, &v, &a, f),
                Ur5::frame_motion(&q, &v, &a, g),
            );
            for (x, y) in [(m.velocity, mw.velocity), (m.acceleration, mw.acceleration)] {
                check(&x.to_array(), &y.to_array());
            }
            for reference in [
                ReferenceFrame::Local,
                ReferenceFrame::World,
                ReferenceFrame::LocalWorldAligned,
            ] {
                let (mut j, mut jw) = (
                    FrameJacobianTimeVariation::default(),
                    FrameJacobianTimeVariation::default(),
                );
                Ur5Composed::frame_jacobian_time_variation(&q, &v, f, reference, &mut j);
                Ur5::frame_jacobian_time_variation(&q, &v, g, reference, &mut jw);
                check(
                    &dyngen_tests::pose_vec(&j.placement),
                    &dyngen_tests::pose_vec(&jw.placement),
                );
                check(&flat(&j.jacobian), &flat(&jw.jacobian));
                check(&flat(&j.jacobian_dot), &flat(&jw.jacobian_dot));
                let (mut j, mut jw) = (Default::default(), Default::default());
                Ur5Composed::frame_jacobian(&q, f, reference, &mut j);
                Ur5::frame_jacobian(&q, g, reference, &mut jw);
                check(
                    &dyngen_tests::pose_vec(&j.placement),
                    &dyngen_tests::pose_vec(&jw.placement),
                );
                check(&flat(&j.jacobian), &flat(&jw.jacobian));
            }
        }
        let (mut d, mut dw) = (AbaDerivatives::default(), AbaDerivatives::default());
        Ur5Composed::aba_derivatives(&q, &v, &tau, &params, &mut d);
        Ur5::aba_derivatives(&q, &v, &tau, &params, &mut dw);
        check(&derivatives(&d), &derivatives(&dw));
        Ur5Composed::aba_joints_derivatives(&q, &v, &tau, &params, &jp, coulomb, &mut d);
        Ur5::aba_joints_derivatives(&q, &v, &tau, &params, &jp, coulomb, &mut dw);
        check(&derivatives(&d), &derivatives(&dw));
    }
    println!("composed UR5 against its own graphs: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}
