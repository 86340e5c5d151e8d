//! Targets of the generalising NIM on the paper's 6-DOF arm, with
//! the generated dynamics: trained with the default settings along the excitation
//! designed for MIM, judged on 100 parameter draws it has never seen, simulated by
//! the full dynamics; then a payload followed online against recursive least
//! squares. Times are measured by the benchmarks and the demo, not here.

use dyngen::prelude::*;
use dyngen_identify::mim::Verdict;
use dyngen_identify::simulate::{record, Criterion, ExcitationDesign, Experiment, Motion, NoiseModel, Recording};
use dyngen_nim::online::{track, Tracking};
use dyngen_nim::{draw_theta, Nim, NimConfig};
use dyngen_reference::{principal_params_to_standard, SplitMix64};
use dyngen_reference::{Dynamics, Generated};
use robot_paper6::Paper6;

/// The demo's experiment: a Fourier excitation over the paper's 2 s and 100 steps,
/// optimised for MIM.
fn designed(robot: &Generated<Paper6>) -> Experiment {
    let design = ExcitationDesign {
        criterion: Criterion::BodyModel,
        base_frequency: 0.5,
        duration: 2.0,
        samples: 100,
        ..ExcitationDesign::new(robot.model())
    };
    Experiment {
        duration: 2.0,
        steps: 100,
        motion: Motion::Fourier(design.optimise(robot).excitation),
    }
}

fn repeat(experiment: &Experiment, periods: usize) -> Experiment {
    Experiment {
        duration: periods as f64 * experiment.duration,
        steps: periods * experiment.steps,
        motion: experiment.motion.clone(),
    }
}

#[test]
fn generalising_nim_meets_its_targets_on_unseen_draws() {
    let robot = Generated::<Paper6>::new();
    let model = robot.model().clone();
    let nominal = dyngen_model::principal_params(&model);
    let experiment = designed(&robot);
    let training = record(&robot, Paper6::nominal_params(), &repeat(&experiment, 2));
    let config = NimConfig::default();
    let (nim, _) = Nim::train("paper6", &training, &nominal, &config, &|_| {}).unwrap();

    let mut rng = SplitMix64::new(2024);
    let (mut clean_worst, mut noisy_worst) = ((0.0f64, 0.0f64), (0.0f64, 0.0f64));
    for d in 0..100 {
        let theta = draw_theta(&nominal, config.spread, &mut rng);
        let clean = record(&robot, &principal_params_to_standard(&model, &theta), &experiment);
        let estimate = nim.identify(&clean, nim.window / 2).unwrap().with_truth(&theta);
        for (j, verdict) in estimate.verdicts.iter().enumerate() {
            // The turret (body 1) turns about its own axis only.
            let expected = if j == 1 || j == 2 {
                Verdict::NoEffect
            } else {
                Verdict::Identified
            };
            assert_eq!(*verdict, expected, "draw {d}, parameter {j}:\n{estimate}");
        }
        let (m, j) = estimate.max_relative_errors().unwrap();
        clean_worst = (clean_worst.0.max(m), clean_worst.1.max(j));
        let noisy = NoiseModel::mim(0.01).per_axis().apply(&clean, d);
        let (m, j) = nim
            .identify(&noisy, nim.window / 2)
            .unwrap()
            .with_truth(&theta)
            .max_relative_errors()
            .unwrap();
        noisy_worst = (noisy_worst.0.max(m), noisy_worst.1.max(j));
    }
    println!(
        "100 unseen draws: noise-free worst {:.3}% (masses), {:.3}% (moments); 1% noise {:.3}%, {:.3}%",
        100.0 * clean_worst.0,
        100.0 * clean_worst.1,
        100.0 * noisy_worst.0,
        100.0 * noisy_worst.1
    );
    // The targets: noise-free, ≤ 2 % on every mass and ≤ 5 % on every principal moment.
    assert!(clean_worst.0 <= 0.02, "mass {:.3}%", 100.0 * clean_worst.0);
    assert!(clean_worst.1 <= 0.05, "moment {:.3}%", 100.0 * clean_worst.1);
    // With 1 % noise per curve: no stated target; a guard against regressions. The
    // excitation designed on a fixed grid by argmin's Nelder–Mead gives 0.37 % and
    // 11.4 % here (the noise-free targets above: 0.054 %, 2.6 %).
    assert!(noisy_worst.0 <= 0.02 && noisy_worst.1 <= 0.12, "{noisy_worst:?}");

    payload_is_followed_within_a_window(&robot, &experiment, &nim, &nominal);
}

/// A 0.3 kg payload on the flange at t = 4 s of four periods: NIM settles within
/// one window (20 samples, 0.4 s); RLS with a memory of as many samples is slower to
/// settle on the mass.
fn payload_is_followed_within_a_window(robot: &Generated<Paper6>, experiment: &Experiment, nim: &Nim, nominal: &[f64]) {
    let model = robot.model();
    let long = repeat(experiment, 4);
    let change = long.steps / 2;
    let mut after = nominal.to_vec();
    let (m, r, l) = (0.3, 0.04, 0.04);
    after[20] += m;
    after[21] += m * r * r / 2.0;
    after[22] += m * (3.0 * r * r + l * l) / 12.0;
    after[23] += m * (3.0 * r * r + l * l) / 12.0;
    let first = record(robot, &principal_params_to_standard(model, nominal), &long);
    let second = record(robot, &principal_params_to_standard(model, &after), &long);
    let mut spliced: Recording = first;
    spliced.samples[change..].clone_from_slice(&second.samples[change..]);
    let tracking = Tracking {
        body: 5,
        change,
        before: nominal[20..24].try_into().unwrap(),
        after: after[20..24].try_into().unwrap(),
        lambda: 1.0 - 1.0 / (6 * nim.window) as f64,
        tolerance: (0.02, 0.05),
    };
    let (_, [by_nim, by_rls]) = track(nim, &spliced, &tracking).unwrap();
    println!("NIM {by_nim:?}\nRLS {by_rls:?}");
    let window = nim.window as f64 * experiment.duration / experiment.steps as f64;
    let nim_delay = by_nim.delay_mass.expect("NIM settles on the mass");
    assert!(
        nim_delay <= window,
        "NIM settles in {nim_delay} s, a window is {window} s"
    );
    assert!(by_nim.delay_moments.is_some_and(|d| d <= window), "{by_nim:?}");
    assert!(
        by_rls.delay_mass.expect("RLS settles on the mass") > nim_delay,
        "{by_rls:?}"
    );
    assert!(by_nim.error_after.0 < 0.01 && by_nim.error_after.1 < 0.03, "{by_nim:?}");
}
