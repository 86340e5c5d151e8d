//! Accuracy targets of MIM: the paper's experiment on paper6,
//! noise-free and with 1 % noise, and joint-torque identification on ur5 and the
//! 7-DOF panda validated on a separate trajectory.

use dyngen::prelude::*;
use dyngen_identify::mim::{self, MimEstimate, MimOptions, Verdict, Weighting};
use dyngen_identify::simulate::{
    moment_sigma, record, record_trajectory, Criterion, ExcitationDesign, Experiment, Motion, NoiseModel, Recording,
    Sigma,
};
use dyngen_identify::Options;
use dyngen_reference::{Dynamics, Generated};
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_ur5::Ur5;

/// The turret (body 1) turns about its z axis only: its J1, J2 never enter `B`.
fn is_turret_transverse(body: usize, k: usize) -> bool {
    body == 0 && (k == 1 || k == 2)
}

fn paper6_recording() -> (Generated<Paper6>, Recording) {
    let robot = Generated::<Paper6>::new();
    let experiment = Experiment::paper(robot.model());
    let recording = record(&robot, Paper6::nominal_params(), &experiment);
    (robot, recording)
}

/// Every parameter but the turret's J1, J2 identified within `tolerance` relative;
/// those two reported without a number.
fn check(est: &MimEstimate, tolerance: f64, transverse: &[Verdict]) -> f64 {
    println!("{est}");
    let errors = est.errors().expect("truth given");
    let mut worst: f64 = 0.0;
    for e in &errors {
        if is_turret_transverse(e.body, e.index) {
            assert!(
                transverse.contains(&e.verdict) && e.estimate.is_none(),
                "turret {} must be reported unidentifiable, got {:?} {:?}",
                mim::THETA_NAMES[e.index],
                e.verdict,
                e.estimate
            );
            continue;
        }
        let rel = e.relative.unwrap_or_else(|| {
            panic!(
                "{} of body {} not identified: {:?}",
                mim::THETA_NAMES[e.index],
                e.body + 1,
                e.verdict
            )
        });
        assert!(
            rel <= tolerance,
            "{} of body {}: estimate {:?}, truth {}, relative error {rel:.3e} > {tolerance:e}",
            mim::THETA_NAMES[e.index],
            e.body + 1,
            e.estimate,
            e.truth
        );
        worst = worst.max(rel);
    }
    worst
}

#[test]
fn paper6_noise_free_mim_is_exact() {
    let (robot, recording) = paper6_recording();
    let truth = Paper6::nominal_theta();
    // The truth from the model's principal frames is the generator's.
    let from_model = dyngen_model::principal_params(robot.model());
    for (a, b) in from_model.iter().zip(truth) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0));
    }
    let opts = MimOptions::default();
    let all = 0..recording.len();

    let single = mim::instant(&recording, 1.5, Some(truth), &opts).unwrap();
    assert!((recording.samples[75].t - 1.5).abs() < 1e-12);
    let w1 = check(&single, 1e-9, &[Verdict::NoEffect]);
    let many = mim::samples(&recording, all.clone(), Some(truth), &opts).unwrap();
    let w2 = check(&many, 1e-9, &[Verdict::NoEffect]);
    let whole = mim::whole_robot(&recording, all, Some(truth), &opts).unwrap();
    let w3 = check(&whole, 1e-9, &[Verdict::NoEffect]);
    // One block-diagonal problem: rank 4n − 2 (the turret's J1, J2).
    assert_eq!(whole.estimates[0].rank, 4 * 6 - 2);
    let text = single.to_string();
    assert!(text.contains("n/i") && !text.contains("NaN"));
    println!("worst relative error: instant {w1:.2e}, samples {w2:.2e}, whole robot {w3:.2e}");
}

const UNIDENTIFIABLE: [Verdict; 2] = [Verdict::NotSignificant, Verdict::NoEffect];

#[test]
fn paper6_mim_with_one_percent_noise_per_component() {
    let (_, clean) = paper6_recording();
    let truth = Paper6::nominal_theta();
    let opts = MimOptions::default();
    let mut worst: f64 = 0.0;
    // Several fixed seeds, so the target is not met by one lucky draw.
    for seed in [1, 2, 3] {
        // σ = 1 % of each recorded curve's own RMS (every axis of every body
        // measurement: the reading of "1 % noise on each measured curve").
        let noisy = NoiseModel::mim(0.01).per_axis().apply(&clean, seed);
        // 100 samples: t = 0.02 … 2 s (t = 0 is the state at rest).
        let est = mim::samples(&noisy, 1..noisy.len(), Some(truth), &opts).unwrap();
        worst = worst.max(check(&est, 0.01, &UNIDENTIFIABLE));
        let whole = mim::whole_robot(&noisy, 1..noisy.len(), Some(truth), &opts).unwrap();
        worst = worst.max(check(&whole, 0.01, &UNIDENTIFIABLE));
    }
    println!("1 % noise per component, 100 samples, 3 seeds: worst relative error {worst:.3e}");
}

/// `NoiseModel::mim(0.01)`: σ = 1 % of each 3-axis sensor's pooled RMS. The axial
/// moments J1 of the upper arm and the forearm (bodies 2, 3) are then beyond a 1 %
/// target: their moment axis carries ~3 % (upper arm) and ~1 % (forearm) of the
/// pooled moment RMS, and the paper's motion turns them little about that axis, so
/// their σ̂ is ~2.2 % and ~6 % at 100 samples (per-axis Gautier weighting). They
/// are held to their own σ̂ instead (|error| ≤ 3σ̂) and printed; every other
/// parameter to 1 %. With 1 % of each axis's own RMS instead, all meet 1 %
/// (`paper6_mim_with_one_percent_noise_per_component`).
#[test]
fn paper6_mim_with_one_percent_noise_per_sensor() {
    let (_, clean) = paper6_recording();
    let truth = Paper6::nominal_theta();
    let opts = MimOptions::default();
    let weak = |body: usize, k: usize| (body == 1 || body == 2) && k == 1;
    let mut worst: f64 = 0.0;
    for seed in [1, 2, 3] {
        let noisy = NoiseModel::mim(0.01).apply(&clean, seed);
        let est = mim::samples(&noisy, 1..noisy.len(), Some(truth), &opts).unwrap();
        println!("{est}");
        for e in est.errors().unwrap() {
            if is_turret_transverse(e.body, e.index) {
                assert!(UNIDENTIFIABLE.contains(&e.verdict) && e.estimate.is_none());
                continue;
            }
            let rel = e.relative.expect("identified");
            if weak(e.body, e.index) {
                let sigma = est.sigma(e.body, e.index).unwrap();
                println!(
                    "seed {seed}: J1 of body {}: relative error {:.2} %, σ̂ {:.2} %",
                    e.body + 1,
                    100.0 * rel,
                    100.0 * sigma / e.truth
                );
                assert!(e.absolute.unwrap() <= 3.0 * sigma);
            } else {
                assert!(rel <= 0.01, "{e:?}");
                worst = worst.max(rel);
            }
        }
    }
    println!("1 % noise per sensor, 100 samples, 3 seeds: worst relative error (all but the two axial J1) {worst:.3e}");
    // The single instant with noise: reported, not held to a target (6 equations
    // for 4 unknowns at 1 % noise).
    let noisy = NoiseModel::mim(0.01).apply(&clean, 1);
    let single = mim::instant(&noisy, 1.5, Some(truth), &opts).unwrap();
    println!("{single}");
}

/// The pooled reading of 1 % noise (one σ per 3-axis sensor) meets the 1 % target on
/// an excitation designed for MIM: a Fourier motion over the paper's 2 s and 100
/// samples, optimised for the worst relative σ of a principal moment
/// ([`Criterion::BodyModel`]). The paper's motion turns the upper arm and forearm
/// little about their own axes (`paper6_mim_with_one_percent_noise_per_sensor`).
#[test]
fn paper6_mim_with_pooled_noise_on_an_excitation_designed_for_mim() {
    let robot = Generated::<Paper6>::new();
    let paper = Experiment::paper(robot.model());
    let design = ExcitationDesign {
        criterion: Criterion::BodyModel,
        base_frequency: 0.5,
        duration: 2.0,
        samples: 100,
        max_evaluations: 1500,
        ..ExcitationDesign::new(robot.model())
    };
    let found = design.optimise(&robot);
    let experiment = Experiment {
        motion: Motion::Fourier(found.excitation.clone()),
        ..paper.clone()
    };
    let samples = 1..101;
    let before = moment_sigma(&robot, &paper.motion, &paper.times()[samples.clone()]);
    let after = moment_sigma(&robot, &experiment.motion, &experiment.times()[samples.clone()]);
    println!("worst relative σ per unit noise: paper's motion {before:.3}, designed {after:.3} (start {:.3}, {} evaluations)", found.initial_value, found.evaluations);
    assert!(after < 0.5 && before > 5.0 * after, "{before} → {after}");
    assert!(
        (after - found.value).abs() < 1e-9 * after,
        "the criterion is what was optimised"
    );

    let clean = record(&robot, Paper6::nominal_params(), &experiment);
    let truth = Paper6::nominal_theta();
    let mut worst: f64 = 0.0;
    for seed in [1, 2, 3] {
        let noisy = NoiseModel::mim(0.01).apply(&clean, seed);
        let est = mim::samples(&noisy, samples.clone(), Some(truth), &MimOptions::default()).unwrap();
        worst = worst.max(check(&est, 0.01, &UNIDENTIFIABLE));
    }
    println!("1 % noise pooled per sensor, designed excitation, 3 seeds: worst relative error {worst:.3e}");
}

#[test]
fn paper6_from_joint_torques_says_what_is_identifiable() {
    let (robot, recording) = paper6_recording();
    let truth = Paper6::nominal_theta();
    let all = 0..recording.len();
    let est = mim::torque(
        &robot,
        &recording,
        all.clone(),
        mim::TorqueRegressor::Principal,
        Some(truth),
        Weighting::Ols,
        &Options::default(),
    )
    .unwrap();
    println!("{est}");
    assert_eq!(est.estimate.rank, Paper6::NBASE_PRINCIPAL);
    // Never a number for a parameter that is not identifiable alone.
    for p in &est.estimate.params {
        assert_eq!(p.value.is_some(), p.status == dyngen_identify::Status::Identified);
    }
    // The turret's transverse moments have no effect on the joint torques.
    assert_eq!(est.estimate.params[1].status, dyngen_identify::Status::NoEffect);
    assert_eq!(est.estimate.params[2].status, dyngen_identify::Status::NoEffect);
    for c in est.combination_errors().unwrap() {
        // Relative to the terms' size: J2 − J3 of a cylinder is 0.
        let scale = c.terms.iter().map(|&(j, k)| (k * truth[j]).abs()).fold(0.0, f64::max);
        assert!(c.absolute <= 1e-9 * scale, "{c:?}");
    }
    // Through the generated principal base regressor: every base parameter.
    let base =
        mim::torque_principal_base::<Paper6>(&robot, &recording, all, Weighting::Ols, &Options::default()).unwrap();
    println!("{base}");
    assert_eq!(base.estimate.rank, Paper6::NBASE_PRINCIPAL);
    for (j, value, t) in base.identified() {
        let t = t.unwrap();
        assert!(
            (value - t).abs() <= 1e-8 * t.abs().max(1e-3),
            "{}: {value} vs {t}",
            base.names[j]
        );
    }
}

/// Joint-torque identification with an optimised Fourier excitation and 1 % torque
/// noise (plus encoder noise), validated on a separate trajectory.
fn torque_identification<R: Robot>(evaluations: usize) {
    let robot = Generated::<R>::new();
    let model = robot.model().clone();
    let params = R::nominal_params();
    let n = R::NV;

    let design = |seed: u64, evaluations: usize| ExcitationDesign {
        samples: 60,
        max_evaluations: evaluations,
        restarts: 1,
        seed,
        ..ExcitationDesign::new(&model)
    };
    let identification = design(1, evaluations).optimise(&robot);
    let validation = design(2, 0).optimise(&robot);
    println!(
        "{}: excitation cond {:.1} (start {:.1}, {} evaluations); validation cond {:.1}",
        R::NAME,
        identification.value,
        identification.initial_value,
        identification.evaluations,
        validation.value
    );
    let period = identification.excitation.period();
    let times = |count: usize| (0..count).map(|k| k as f64 * period / count as f64).collect::<Vec<_>>();
    let noise = NoiseModel {
        tau: Sigma::Relative(0.01),
        q: Sigma::Absolute(1e-5),
        ..NoiseModel::none()
    };
    let clean_id = record_trajectory(&robot, params, &identification.excitation, &times(400));
    let measured = noise.apply(&clean_id, 11);
    let clean_val = record_trajectory(&robot, params, &validation.excitation, &times(200));
    let validation_measured = noise.apply(&clean_val, 12);

    let est = mim::torque(
        &robot,
        &measured,
        0..measured.len(),
        mim::TorqueRegressor::Standard,
        Some(params),
        Weighting::WlsIterated(20),
        &Options::default(),
    )
    .unwrap();
    assert_eq!(est.estimate.rank, R::NBASE, "{}: rank", R::NAME);
    for p in &est.estimate.params {
        assert!(p.value.is_none() || p.status == dyngen_identify::Status::Identified);
    }

    let floor: Vec<f64> = (0..n)
        .map(|j| {
            let ms: f64 = clean_val.samples.iter().map(|s| s.tau[j] * s.tau[j]).sum::<f64>() / clean_val.len() as f64;
            0.01 * ms.sqrt()
        })
        .collect();
    let rms = est.validation_rms(&robot, &validation_measured);
    let model_error = est.validation_rms(&robot, &clean_val);
    for j in 0..n {
        println!(
            "{} joint {}: validation RMS {:.4e}, noise floor σ {:.4e}, ratio {:.3}; against clean torques {:.3e} ({:.3}σ)",
            R::NAME,
            j + 1,
            rms[j],
            floor[j],
            rms[j] / floor[j],
            model_error[j],
            model_error[j] / floor[j]
        );
        assert!(
            rms[j] <= 1.5 * floor[j],
            "{} joint {}: validation torque RMS {:.3e} > 1.5 × noise floor {:.3e}",
            R::NAME,
            j + 1,
            rms[j],
            floor[j]
        );
    }
}

#[test]
fn ur5_joint_torque_identification_validates_at_the_noise_floor() {
    torque_identification::<Ur5>(120);
}

#[test]
fn panda_joint_torque_identification_validates_at_the_noise_floor() {
    torque_identification::<Panda>(120);
}
