//! Joint terms past viscous and Coulomb friction (`dyngen_identify::extras`) on a
//! simulated UR5 whose joints have them: direction-dependent viscous friction, two
//! harmonics of torque ripple and of position-dependent Coulomb friction, and
//! Coulomb friction growing with the transmitted torque, on top of rotor inertia,
//! sign friction and 1 % torque noise. Each term is recovered, predicts another
//! recording at the noise level, and the automatic choice finds exactly them.

use crate::common::{add_torque_noise, joint_truth, motion, overall_error, ur5};
use dyngen_identify::choice::{choose, DEFAULT_EXTRAS};
use dyngen_identify::data::Trajectory;
use dyngen_identify::extras::ExtraTerms;
use dyngen_identify::pipeline::{self, IdentifyOptions, JointTerms, Prediction};
use dyngen_identify::report::ParameterReport;
use dyngen_identify::simulate::{add_extra_terms, add_joint_terms, record_trajectory, Gaussian};
use dyngen_identify::Status;
use dyngen_model::joint_params::{Coulomb, PER_JOINT};
use dyngen_reference::Reference;

const ALL: ExtraTerms = ExtraTerms {
    asymmetric: true,
    harmonics: 2,
    motor_harmonics: 0,
    load: true,
};

/// Per joint `[Fva, Ts1, Tc1, Fcs1, Fcc1, Ts2, Tc2, Fcs2, Fcc2, Fcl]`: a few percent
/// to a tenth of each joint's Coulomb friction, load dependence 3-6 %.
fn extras_truth() -> Vec<f64> {
    let scale = [1.0, 1.0, 0.7, 0.25, 0.25, 0.25];
    let fcl = [0.05, 0.04, 0.06, 0.03, 0.05, 0.04];
    (0..6)
        .flat_map(|j| {
            let s = scale[j];
            [
                0.8 * s,
                0.3 * s,
                -0.2 * s,
                0.5 * s,
                0.25 * s,
                -0.4 * s,
                0.3 * s,
                0.5 * s,
                -0.6 * s,
                fcl[j],
            ]
        })
        .collect()
}

/// 30 s at 100 Hz with every term, 1 % torque noise.
fn recording(robot: &Reference, motion_seed: u64, noise_seed: u64, extras: bool) -> Trajectory {
    let times: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64).collect();
    let mut rec = record_trajectory(robot, &robot.model().standard_params(), &motion(motion_seed), &times);
    if extras {
        add_extra_terms(&mut rec, ALL, &extras_truth(), Coulomb::Sign, None).unwrap();
    }
    add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
    add_torque_noise(&mut rec, &mut Gaussian::new(noise_seed));
    rec.to_trajectory().unwrap()
}

fn options(extras: ExtraTerms) -> IdentifyOptions {
    IdentifyOptions {
        joints: JointTerms::Friction(Coulomb::Sign),
        extras,
        ..IdentifyOptions::default()
    }
}

#[test]
fn extra_terms_are_identified_and_predict_held_out_data() {
    let robot = ur5();
    let (traj, check) = (recording(&robot, 1, 5, true), recording(&robot, 2, 6, true));
    let with = pipeline::identify(&robot, &traj, &options(ALL)).unwrap();
    let without = pipeline::identify(&robot, &traj, &options(ExtraTerms::NONE)).unwrap();
    let Prediction::Regressor(estimate) = &with.prediction else {
        panic!("a regressor estimate")
    };
    let first = 60 + PER_JOINT * 6;
    let names = ALL.names(6);
    let (mut worst, mut identified, mut combined) = (0.0f64, 0, Vec::new());
    for (k, truth) in extras_truth().into_iter().enumerate() {
        assert_eq!(estimate.names[first + k], names[k]);
        let p = &estimate.estimate.params[first + k];
        match p.status {
            Status::Identified => {
                let (value, sigma) = (p.value.unwrap(), p.sigma.unwrap());
                let z = (value - truth) / sigma;
                println!("{:<8} {truth:>8.4} {value:>10.5} ± {sigma:.5} ({z:+.2} σ)", names[k]);
                worst = worst.max(z.abs());
                identified += 1;
                // Direction-dependent viscous friction is determined on every
                // joint, the load-dependent friction on the joints the links load
                // (1-3; the wrists carry little): σ below a third of the value.
                // The ripple harmonics have large σ where a joint sweeps a small
                // part of a turn.
                let (term, joint) = (k % ALL.per_joint(), k / ALL.per_joint());
                if term == 0 || (term == 9 && joint < 3) {
                    assert!(sigma < truth.abs() / 3.0, "{}: {value} ± {sigma}", names[k]);
                }
            }
            status => {
                println!("{:<8} {status:?}", names[k]);
                combined.push(names[k].as_str());
            }
        }
    }
    // The shoulder's first ripple harmonic is the form of its gravity torque
    // (a·cos q2 + b·sin q2 from the links' first moments): only in combination
    // with them. (The elbow's gravity is a function of q2 + q3, not of q3.)
    // Everything else is identified, within 4 σ.
    assert_eq!(combined, ["Ts1_2", "Tc1_2"]);
    assert_eq!(identified, 58);
    assert!(worst < 4.0, "worst {worst:.2} σ");
    let (e_with, e_without) = (
        overall_error(&robot, &with, &check),
        overall_error(&robot, &without, &check),
    );
    println!("held-out error: with the extra terms {e_with:.5}, without {e_without:.5}");
    // 1 % noise: the model with the terms predicts within a tenth of the noise
    // level (the weakly determined harmonics cost the rest on another motion),
    // without them at twice it.
    assert!(e_with < 0.0112, "{e_with}");
    assert!(e_without > 1.9 * e_with, "{e_without} {e_with}");
    // The parameters file's prediction (what `dyngen validate` reads) is the same.
    let json = ParameterReport::from_json(&with.report.to_json().unwrap()).unwrap();
    let prediction = json.prediction.as_ref().unwrap();
    assert_eq!(prediction.extras, ALL);
    let from_json = pipeline::predict_with(prediction, &robot, &check).unwrap();
    let direct = with.predict(&robot, &check).unwrap();
    for (a, b) in from_json.iter().flatten().zip(direct.iter().flatten()) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} {b}");
    }
}

/// The choice adds each term the joints have (without them it adds none: see
/// `joint_friction::the_chosen_joint_model_has_what_the_joints_have`).
#[test]
fn the_choice_adds_the_terms_the_data_have() {
    let robot = ur5();
    let traj = recording(&robot, 1, 5, true).select(|k| k < 2000).unwrap();
    let choice = choose(&robot, &traj, &IdentifyOptions::default(), DEFAULT_EXTRAS).unwrap();
    println!("{choice}");
    // The second harmonic is small against the noise over the joints' angle
    // ranges: whether it is kept depends on the noise; the other terms are.
    let chosen = choice.chosen().extras;
    assert!(chosen.asymmetric && chosen.load && chosen.harmonics >= 1, "{choice}");
    let error = choice.scores[choice.chosen].held_out.as_ref().unwrap().overall;
    assert!(error < 0.8 * choice.error("sign").unwrap(), "{choice}");
    // The options it hands on fit the chosen model.
    assert_eq!(choice.apply(&IdentifyOptions::default()).extras, chosen);
}

#[test]
fn extra_terms_refuse_what_they_cannot_extend() {
    let robot = ur5();
    let traj = recording(&robot, 1, 5, false).select(|k| k < 300).unwrap();
    for (joints, says) in [
        (
            JointTerms::None,
            "extra-terms load extends the friction model: give --friction sign, smooth or auto",
        ),
        (
            JointTerms::Stribeck(Coulomb::Sign),
            "extra-terms do not combine with Stribeck friction",
        ),
    ] {
        let opts = IdentifyOptions {
            joints,
            extras: ExtraTerms {
                load: true,
                ..ExtraTerms::NONE
            },
            ..IdentifyOptions::default()
        };
        let e = pipeline::identify(&robot, &traj, &opts).unwrap_err();
        assert!(e.to_string().starts_with(says), "{e}");
    }
}

/// Ripple of the motor angle (gear ratio 101, two harmonics) on every joint: the
/// joints sweep hundreds of motor periods, so each harmonic is determined, and the
/// parameters file keeps the gear ratios.
#[test]
fn motor_ripple_is_identified_through_the_gear_ratios() {
    let robot = ur5();
    let ratios = vec![101.0; 6];
    let motor: ExtraTerms = "motor-ripple=2".parse().unwrap();
    // Tms1, Tmc1, Tms2, Tmc2 per joint.
    let truth: Vec<f64> = (0..6)
        .flat_map(|j| {
            let s = [1.0, 1.0, 0.7, 0.25, 0.25, 0.25][j];
            [0.4 * s, -0.3 * s, 0.2 * s, 0.15 * s]
        })
        .collect();
    let make = |motion_seed: u64, noise_seed: u64| {
        let times: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64).collect();
        let mut rec = record_trajectory(&robot, &robot.model().standard_params(), &motion(motion_seed), &times);
        add_extra_terms(&mut rec, motor, &truth, Coulomb::Sign, Some(&ratios)).unwrap();
        add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
        add_torque_noise(&mut rec, &mut Gaussian::new(noise_seed));
        rec.to_trajectory().unwrap()
    };
    let (traj, check) = (make(1, 5), make(2, 6));
    let geared = IdentifyOptions {
        gear_ratios: Some(ratios.clone()),
        ..options(motor)
    };
    let with = pipeline::identify(&robot, &traj, &geared).unwrap();
    let Prediction::Regressor(estimate) = &with.prediction else {
        panic!("a regressor estimate")
    };
    let first = 60 + PER_JOINT * 6;
    // To 15 % (OLS pools one noise level over the joints, so the shoulder's σ is
    // too small to judge it by).
    for (k, truth) in truth.iter().enumerate() {
        let value = estimate.estimate.params[first + k].value.unwrap();
        println!("{}: {value:.4} (truth {truth})", estimate.names[first + k]);
        assert!(
            (value - truth).abs() < 0.15 * truth.abs(),
            "{}: {value} against {truth}",
            estimate.names[first + k]
        );
    }
    let plain = pipeline::identify(&robot, &traj, &options(ExtraTerms::NONE)).unwrap();
    let (e_with, e_without) = (
        overall_error(&robot, &with, &check),
        overall_error(&robot, &plain, &check),
    );
    println!("held-out error: with the motor ripple {e_with:.5}, without {e_without:.5}");
    assert!(e_with < 0.0105 && e_without > 1.5 * e_with, "{e_with} {e_without}");
    // The parameters file keeps the gear ratios: it predicts as the identification.
    let json = ParameterReport::from_json(&with.report.to_json().unwrap()).unwrap();
    let prediction = json.prediction.as_ref().unwrap();
    assert_eq!(prediction.gear_ratios.as_deref(), Some(&ratios[..]));
    let from_json = pipeline::predict_with(prediction, &robot, &check).unwrap();
    let direct = with.predict(&robot, &check).unwrap();
    for (a, b) in from_json.iter().flatten().zip(direct.iter().flatten()) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} {b}");
    }
    // Without gear ratios, and with fewer than joints.
    let e = pipeline::identify(&robot, &traj, &options(motor)).unwrap_err();
    assert!(
        e.to_string()
            .contains("motor-ripple needs each joint's gear ratio (--gear-ratios)"),
        "{e}"
    );
    let short = IdentifyOptions {
        gear_ratios: Some(vec![101.0; 5]),
        ..options(motor)
    };
    let e = pipeline::identify(&robot, &traj, &short).unwrap_err();
    assert!(e.to_string().contains("5 values for 6 joints"), "{e}");
}
