//! Stribeck friction identified by nonlinear least squares from the linear fit
//! (`JointTerms::Stribeck`): on a simulated UR5 whose joints have a static friction
//! above their Coulomb friction (1 % torque noise, fixed seeds), `Fs` and `vs` come
//! back and the model predicts a second recording better than sign friction; on
//! joints without a Stribeck effect every joint falls back to sign friction (the
//! term does not predict held-out time blocks), so it is no worse; its JSON
//! predicts the same.

use crate::common::{add_torque_noise, joint_truth, motion, overall_error, ur5, FC};
use dyngen_identify::data::Trajectory;
use dyngen_identify::pipeline::{self, Identification, IdentifyOptions, JointTerms, PipelineError};
use dyngen_identify::report::{ParamStatus, ParameterReport};
use dyngen_identify::simulate::{add_joint_terms, add_stribeck_terms, record_trajectory, Gaussian};
use dyngen_identify::stribeck::{Stribeck, StribeckError};
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Reference;

const FS: [f64; 6] = [9.0, 9.0, 6.0, 2.2, 2.2, 2.2];
const VS: [f64; 6] = [0.05, 0.05, 0.08, 0.04, 0.04, 0.04];

/// 60 s at 100 Hz of the motion of `seed`, with rotor inertia and linear friction,
/// Stribeck terms when `stribeck`, and 1 % of each joint's RMS torque as noise.
fn recording(robot: &Reference, seed: u64, stribeck: bool) -> Trajectory {
    let times: Vec<f64> = (0..6000).map(|k| 0.01 * k as f64).collect();
    let mut rec = record_trajectory(robot, &robot.model().standard_params(), &motion(seed), &times);
    let joints = joint_truth();
    add_joint_terms(&mut rec, &joints, Coulomb::Sign);
    if stribeck {
        let s: Vec<Stribeck> = (0..6).map(|j| Stribeck { fs: FS[j], vs: VS[j] }).collect();
        add_stribeck_terms(&mut rec, &joints, &s, Coulomb::Sign).unwrap();
    }
    add_torque_noise(&mut rec, &mut Gaussian::new(seed + 100));
    rec.to_trajectory().unwrap()
}

fn identify(robot: &Reference, traj: &Trajectory, joints: JointTerms) -> Identification {
    let options = IdentifyOptions {
        joints,
        ..IdentifyOptions::default()
    };
    pipeline::identify(robot, traj, &options).unwrap()
}

#[test]
fn stribeck_friction_is_recovered_and_predicts_better_than_sign() {
    let robot = ur5();
    let (train, test) = (recording(&robot, 1, true), recording(&robot, 2, true));
    let sign = identify(&robot, &train, JointTerms::Friction(Coulomb::Sign));
    let stribeck = identify(&robot, &train, JointTerms::Stribeck(Coulomb::Sign));
    let fit = stribeck.stribeck.as_ref().expect("a Stribeck fit");
    println!("{fit}");
    assert!(fit.cost < 0.5 * fit.initial_cost, "{fit}");
    // Every joint keeps its term: it predicts held-out time blocks better.
    for (j, c) in fit.choices.iter().enumerate() {
        let [sign, with] = c.held_out.expect("held-out errors");
        assert!(c.kept && with < 0.8 * sign, "joint {}: {c}", j + 1);
        let (lo, hi) = c.range.unwrap();
        assert!(lo < VS[j] && VS[j] < hi, "joint {}: {c}", j + 1);
    }
    assert!(fit.to_string().contains("joint 6: Stribeck kept: "), "{fit}");
    for j in 0..6 {
        let s = fit.joints[j];
        assert!(
            (s.fs / FS[j] - 1.0).abs() < 0.03,
            "joint {}: Fs {} vs {}",
            j + 1,
            s.fs,
            FS[j]
        );
        assert!(
            (s.vs / VS[j] - 1.0).abs() < 0.05,
            "joint {}: vs {} vs {}",
            j + 1,
            s.vs,
            VS[j]
        );
        assert!(
            (fit.fc[j] / FC[j] - 1.0).abs() < 0.02,
            "joint {}: Fc {} vs {}",
            j + 1,
            fit.fc[j],
            FC[j]
        );
        let [sf, sv] = fit.sigma[j];
        assert!(
            sf.is_some_and(|x| x > 0.0) && sv.is_some_and(|x| x > 0.0),
            "joint {}",
            j + 1
        );
    }
    let (e_sign, e_stribeck) = (
        overall_error(&robot, &sign, &test),
        overall_error(&robot, &stribeck, &test),
    );
    println!(
        "validation: sign {:.3} %, stribeck {:.3} %",
        100.0 * e_sign,
        100.0 * e_stribeck
    );
    assert!(e_stribeck < 0.7 * e_sign, "sign {e_sign}, stribeck {e_stribeck}");

    // The report holds Fs and vs (value and σ), and its JSON predicts exactly what
    // the identification does.
    let names: Vec<&str> = stribeck.report.parameters.iter().map(|p| p.name.as_str()).collect();
    assert!(names.ends_with(&["Fs6", "vs6"]), "{names:?}");
    let json = ParameterReport::from_json(&stribeck.report.to_json().unwrap()).unwrap();
    let prediction = json.prediction.as_ref().unwrap();
    assert_eq!(prediction.stribeck.as_deref(), Some(&fit.joints[..]));
    let from_json = pipeline::predict_with(prediction, &robot, &test).unwrap();
    let direct = stribeck.predict(&robot, &test).unwrap();
    for (a, b) in from_json.iter().flatten().zip(direct.iter().flatten()) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

#[test]
fn without_a_stribeck_effect_it_is_no_worse_than_sign() {
    let robot = ur5();
    let (train, test) = (recording(&robot, 3, false), recording(&robot, 4, false));
    let sign = identify(&robot, &train, JointTerms::Friction(Coulomb::Sign));
    let stribeck = identify(&robot, &train, JointTerms::Stribeck(Coulomb::Sign));
    let fit = stribeck.stribeck.as_ref().unwrap();
    println!("{fit}");
    assert!(fit.cost <= fit.initial_cost);
    // No joint's term lowers its held-out error: every joint falls back to the
    // linear model, whose Fs and vs are reported `excluded`, without a value.
    for (j, c) in fit.choices.iter().enumerate() {
        assert!(
            !c.kept && c.reason.contains("does not lower the held-out error"),
            "joint {}: {c}",
            j + 1
        );
    }
    assert!(fit.to_string().contains("joint 1: sign kept: "), "{fit}");
    for p in stribeck.report.parameters.iter().skip(6 * 14) {
        assert!(p.value.is_none() && p.status == ParamStatus::Excluded, "{p:?}");
    }
    let residual = |id: &Identification| -> f64 {
        let predicted = id.predict(&robot, &train).unwrap();
        (0..train.len())
            .flat_map(|k| train.tau(k).iter().zip(&predicted[k]).map(|(m, p)| (m - p).powi(2)))
            .sum()
    };
    assert!(residual(&stribeck) <= residual(&sign) * (1.0 + 1e-12));
    let (e_sign, e_stribeck) = (
        overall_error(&robot, &sign, &test),
        overall_error(&robot, &stribeck, &test),
    );
    println!(
        "validation: sign {:.4} %, stribeck {:.4} %",
        100.0 * e_sign,
        100.0 * e_stribeck
    );
    // Held-out recording: not worse than sign (the same model).
    assert!(
        e_stribeck <= e_sign * (1.0 + 1e-12),
        "sign {e_sign}, stribeck {e_stribeck}"
    );
}

#[test]
fn bad_stribeck_parameters_are_refused_with_the_joint_named() {
    let robot = ur5();
    let traj = recording(&robot, 5, true);
    // The simulator refuses a Stribeck velocity that is not positive.
    let times: Vec<f64> = (0..10).map(|k| 0.01 * k as f64).collect();
    let mut rec = record_trajectory(&robot, &robot.model().standard_params(), &motion(5), &times);
    let mut s = vec![Stribeck { fs: 2.0, vs: 0.05 }; 6];
    s[3].vs = -0.1;
    let err = add_stribeck_terms(&mut rec, &[0.0; 24], &s, Coulomb::Sign).unwrap_err();
    assert_eq!(err, StribeckError::Velocity { joint: 4, vs: -0.1 });
    assert!(
        err.to_string()
            .starts_with("joint 4: the Stribeck velocity must be positive"),
        "{err}"
    );
    let err = add_stribeck_terms(&mut rec, &[0.0; 24], &s[..5], Coulomb::Sign).unwrap_err();
    assert_eq!(err, StribeckError::Joints { expected: 6, found: 5 });

    // A parameter JSON with a broken Stribeck entry, or on a model without the
    // joint terms, predicts nothing.
    let id = identify(&robot, &traj, JointTerms::Stribeck(Coulomb::Sign));
    let mut prediction = id.report.prediction.clone().unwrap();
    prediction.stribeck.as_mut().unwrap()[1].vs = 0.0;
    let err = pipeline::predict_with(&prediction, &robot, &traj).unwrap_err();
    assert!(matches!(err, PipelineError::InvalidOption { .. }), "{err:?}");
    assert!(err.to_string().contains("joint 2: the Stribeck velocity"), "{err}");
    prediction.stribeck.as_mut().unwrap().pop();
    let err = pipeline::predict_with(&prediction, &robot, &traj).unwrap_err();
    assert!(
        err.to_string().contains("5 Stribeck parameter sets for 6 joints"),
        "{err}"
    );

    // Smoothing that is not positive, and Stribeck friction outside the standard mode.
    for options in [
        IdentifyOptions {
            joints: JointTerms::Stribeck(Coulomb::Smooth { epsilon: 0.0 }),
            ..IdentifyOptions::default()
        },
        IdentifyOptions {
            joints: JointTerms::Stribeck(Coulomb::Sign),
            mode: pipeline::Mode::Principal,
            ..IdentifyOptions::default()
        },
    ] {
        let err = options.check().unwrap_err();
        assert!(err.to_string().starts_with("friction "), "{err}");
    }
}

/// A recording longer than `ROUND_SAMPLES`: the rounds run on a part of it, the
/// result is carried to every sample, and the parameters still come back.
#[test]
fn a_long_recording_is_fitted_on_a_part_then_on_every_sample() {
    let robot = ur5();
    let len = dyngen_identify::stribeck::ROUND_SAMPLES + 6_000;
    let times: Vec<f64> = (0..len).map(|k| 0.005 * k as f64).collect();
    let mut rec = record_trajectory(&robot, &robot.model().standard_params(), &motion(7), &times);
    let joints = joint_truth();
    let truth: Vec<Stribeck> = (0..6).map(|j| Stribeck { fs: FS[j], vs: VS[j] }).collect();
    add_joint_terms(&mut rec, &joints, Coulomb::Sign);
    add_stribeck_terms(&mut rec, &joints, &truth, Coulomb::Sign).unwrap();
    add_torque_noise(&mut rec, &mut Gaussian::new(8));
    let traj = rec.to_trajectory().unwrap();
    let id = identify(&robot, &traj, JointTerms::Stribeck(Coulomb::Sign));
    let fit = id.stribeck.as_ref().unwrap();
    println!("{fit}");
    assert_eq!(fit.rows, 6 * len);
    assert!(fit.rounds >= 2 && fit.cost < 0.5 * fit.initial_cost, "{fit}");
    for (j, (s, t)) in fit.joints.iter().zip(&truth).enumerate() {
        assert!((s.fs / t.fs - 1.0).abs() < 0.03, "joint {}: {s:?} vs {t:?}", j + 1);
        assert!((s.vs / t.vs - 1.0).abs() < 0.05, "joint {}: {s:?} vs {t:?}", j + 1);
    }
}
