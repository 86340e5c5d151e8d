//! Identification of a robot with rotor inertia and friction, as real robots are:
//! the standard parameters and per joint `[Ia, Fv, Fc, F0]` from joint torques, on a
//! simulated UR5 whose recordings pass through a real-looking logger (jittered
//! stamps, duplicate rows, motor currents, 1 % torque noise), validated on a second
//! recording it was not identified on.

use crate::common::{add_torque_noise, joint_truth, motion, overall_error, ur5, F0, FC, FV, IA};
use dyngen_identify::data::{Recipe, Trajectory};
use dyngen_identify::extras::ExtraTerms;
use dyngen_identify::faer::Mat;
use dyngen_identify::mim::{self, TorqueRegressor, Weighting};
use dyngen_identify::pipeline::{self, Estimator, IdentifyOptions, JointTerms, PipelineError, Prediction};
use dyngen_identify::report::{MergedLinks, ParamReport, ParamStatus, Parameterisation};
use dyngen_identify::simulate::{add_joint_terms, record_trajectory, Gaussian, Logger, Recording};
use dyngen_identify::validate::Validation;
use dyngen_identify::{Accumulator, Channels, Method, Options, Status};
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Reference;

const GAINS: [f64; 6] = [14.0, 13.0, 12.0, 9.0, 8.5, 8.0];

fn recording(robot: &Reference, seed: u64, times: &[f64]) -> Recording {
    let mut rec = record_trajectory(robot, &robot.model().standard_params(), &motion(seed), times);
    add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
    rec
}

/// A file `Logger::write` wrote, read back with velocities and accelerations;
/// `gains` when the last columns are currents to turn into torques. Stale rows (old
/// values under a new stamp) would put q and τ at the wrong time: they are dropped.
fn read_log(text: &str, gains: Option<&str>) -> dyngen_identify::data::Trajectory {
    let mut recipe = Recipe::default();
    for (key, value) in [("q", "2-7"), ("v", "8-13"), ("tau", "14-19"), ("stale", "drop")] {
        recipe.set(key, value).unwrap();
    }
    if let Some(g) = gains {
        recipe.set("gains", g).unwrap();
    }
    recipe
        .read_from(text.as_bytes(), Some(6))
        .unwrap()
        .with_derivatives(5.0)
        .unwrap()
        .trajectory
}

#[test]
fn noise_free_identification_recovers_friction_and_rotor_inertia() {
    let robot = ur5();
    let times: Vec<f64> = (0..2000).map(|k| 0.01 * k as f64).collect();
    let rec = recording(&robot, 1, &times);
    let est = mim::torque(
        &robot,
        &rec,
        0..rec.len(),
        TorqueRegressor::StandardAndJoints(Coulomb::Sign.into()),
        None,
        Weighting::Ols,
        &Options::default(),
    )
    .unwrap();
    // 36 rigid-body base parameters, 4 per joint but the first two rotors.
    assert_eq!(est.estimate.rank, 36 + 22);
    for j in 0..6 {
        for (k, truth) in [(1, FV[j]), (2, FC[j]), (3, F0[j])] {
            let got = est.estimate.params[60 + 4 * j + k].value.expect("identifiable");
            assert!(
                (got - truth).abs() < 1e-8 * truth.abs().max(1.0),
                "joint {} [{k}]: {got}",
                j + 1
            );
        }
        if j >= 2 {
            let got = est.estimate.params[60 + 4 * j].value.expect("identifiable");
            assert!((got - IA[j]).abs() < 1e-8, "Ia{}: {got}", j + 1);
        } else {
            assert!(
                est.estimate.params[60 + 4 * j].value.is_none(),
                "Ia{} groups with Izz",
                j + 1
            );
        }
    }
    let other = recording(&robot, 2, &times);
    let predicted: Vec<Vec<f64>> = other
        .samples
        .iter()
        .map(|s| est.predict(&robot, &s.q, &s.v, &s.a))
        .collect();
    let v = Validation::new(
        &other.joint_names,
        other.samples.iter().map(|s| &s.tau[..]),
        predicted.iter().map(|p| &p[..]),
    )
    .unwrap();
    assert!(v.overall < 1e-9, "{v}");
}

/// The logger's file, read back through a recipe, with torques estimated from 1 %
/// noisy currents and accelerations from filtered positions.
#[test]
fn identification_through_a_real_looking_log_meets_its_targets() {
    let robot = ur5();
    let logger = Logger {
        gains: Some(GAINS.to_vec()),
        current_quantum: 1e-4,
        ..Logger::typical(11)
    };
    let times = logger.times(300.0);
    let mut rec = recording(&robot, 1, &times);
    // 1 % of each joint's RMS torque, as the noise floor.
    let mut noise = Gaussian::new(5);
    let sigma = add_torque_noise(&mut rec, &mut noise);
    let loaded = read_log(&logger.write(&rec), Some("14,13,12,9,8.5,8"));
    let traj = &loaded;
    let regressor = TorqueRegressor::StandardAndJoints(Coulomb::Sign.into());
    let p = regressor.columns(robot.model());
    let mut acc = Accumulator::with_channels(p, Channels::Interleaved(6)).unwrap();
    let mut y = vec![0.0; 6 * p];
    // Skip the filter's edges.
    let edge = 50;
    for s in traj.samples().skip(edge).take(traj.len() - 2 * edge) {
        regressor.eval(&robot, s.q, s.v.unwrap(), s.a.unwrap(), &mut y);
        acc.push_rows(Mat::from_fn(6, p, |r, c| y[r * p + c]).as_ref(), s.tau)
            .unwrap();
    }
    let est = acc.ols(&Options::default()).unwrap();
    let value = |c: usize| est.params[c].value.expect("identifiable");
    for j in 0..6 {
        println!(
            "joint {}: Ia {:?} Fv {:.4} ± {:.4} Fc {:.4} F0 {:.4}",
            j + 1,
            est.params[60 + 4 * j].value,
            value(60 + 4 * j + 1),
            est.params[60 + 4 * j + 1].sigma.unwrap_or(f64::NAN),
            value(60 + 4 * j + 2),
            value(60 + 4 * j + 3)
        );
    }
    for j in 0..6 {
        let (fv, fc) = (value(60 + 4 * j + 1), value(60 + 4 * j + 2));
        assert!((fv - FV[j]).abs() < 0.02 * FV[j], "Fv{}: {fv} vs {}", j + 1, FV[j]);
        assert!((fc - FC[j]).abs() < 0.02 * FC[j], "Fc{}: {fc} vs {}", j + 1, FC[j]);
        if j >= 2 {
            let ia = value(60 + 4 * j);
            assert!((ia - IA[j]).abs() < 0.05 * IA[j], "Ia{}: {ia} vs {}", j + 1, IA[j]);
        }
    }
    // Validation on another motion, torques with the same noise: the prediction
    // error should be the noise itself.
    let mut other = recording(&robot, 2, &(0..2000).map(|k| 0.01 * k as f64).collect::<Vec<_>>());
    let clean: Vec<Vec<f64>> = other.samples.iter().map(|s| s.tau.clone()).collect();
    for s in &mut other.samples {
        for j in 0..6 {
            s.tau[j] += noise.normal(sigma[j]);
        }
    }
    let predicted: Vec<Vec<f64>> = other
        .samples
        .iter()
        .map(|s| regressor.predict(&robot, &s.q, &s.v, &s.a, &est.solution, &mut y))
        .collect();
    let v = Validation::new(
        &other.joint_names,
        other.samples.iter().map(|s| &s.tau[..]),
        predicted.iter().map(|p| &p[..]),
    )
    .unwrap();
    let floor = Validation::new(
        &other.joint_names,
        other.samples.iter().map(|s| &s.tau[..]),
        clean.iter().map(|p| &p[..]),
    )
    .unwrap();
    println!("{v}\nnoise floor:\n{floor}");
    for j in 0..6 {
        assert!(v.rms[j] <= 1.1 * floor.rms[j], "joint {}: {v}\n{floor}", j + 1);
    }
}

/// Drive gains from a known 5 kg payload (Gautier and Briot): two logs of motor
/// currents, one without and one with the load, 1 % current noise.
#[test]
fn drive_gains_from_a_known_payload() {
    use dyngen_identify::gains::identify_gains;
    use dyngen_identify::payload::Payload;
    let robot = ur5();
    let nominal = robot.model().standard_params();
    // 5 kg, centre of mass 10 cm off the flange's axis and 5 cm beyond it, a
    // cylinder of radius 5 cm and length 10 cm about its centre, moved to the body
    // origin (a gripper holding a part to one side).
    let (m, c) = (5.0, [0.1, 0.0, 0.05]);
    let (ixx, izz) = (
        m * (3.0 * 0.05f64.powi(2) + 0.1f64.powi(2)) / 12.0,
        m * 0.05f64.powi(2) / 2.0,
    );
    let payload = Payload {
        body: 6,
        params: [
            m,
            m * c[0],
            m * c[1],
            m * c[2],
            ixx + m * (c[1] * c[1] + c[2] * c[2]),
            -m * c[0] * c[1],
            ixx + m * (c[0] * c[0] + c[2] * c[2]),
            -m * c[0] * c[2],
            -m * c[1] * c[2],
            izz + m * (c[0] * c[0] + c[1] * c[1]),
        ],
    };
    let mut loaded_params = nominal.clone();
    for k in 0..10 {
        loaded_params[50 + k] += payload.params[k];
    }
    let logger = Logger {
        gains: Some(GAINS.to_vec()),
        ..Logger::typical(21)
    };
    let mut noise = Gaussian::new(8);
    let mut log = |params: &[f64], seed: u64| {
        let times = logger.times(120.0);
        let mut rec = record_trajectory(&robot, params, &motion(seed), &times);
        add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
        add_torque_noise(&mut rec, &mut noise);
        // Currents as they are: the gains are what is sought.
        read_log(&logger.write(&rec), None)
    };
    let unloaded = log(&nominal, 1);
    let loaded = log(&loaded_params, 3);
    let est = identify_gains(&robot, &unloaded, &loaded, &payload, Coulomb::Sign, &Options::default()).unwrap();
    for j in 0..6 {
        println!(
            "k{} = {:.4} ± {:.4} (stacked least squares {:.4}; truth {})",
            j + 1,
            est.gains[j],
            est.gain_sigma[j],
            est.initial.solution[84 + j],
            GAINS[j]
        );
    }
    println!(
        "{} linear solves; the simplex moved the gains by {:.2e}",
        est.iterations, est.last_change
    );
    for j in 0..6 {
        let k = est.gains[j];
        assert!(
            (k - GAINS[j]).abs() < 0.01 * GAINS[j],
            "k{}: {k} vs {}",
            j + 1,
            GAINS[j]
        );
        // The standard deviation accounts for the error, and is not so wide as to
        // say nothing.
        let sigma = est.gain_sigma[j];
        assert!(
            sigma > 0.0 && (k - GAINS[j]).abs() <= 4.0 * sigma && sigma < 0.005 * k,
            "k{}: {k} ± {sigma} vs {}",
            j + 1,
            GAINS[j]
        );
    }
}

/// A simulated recording with joint terms `joints` (`[Ia, Fv, Fc, F0]` per joint)
/// and 1 % torque noise, as a trajectory with exact velocities and accelerations.
fn noisy_trajectory(robot: &Reference, joints: &[f64], motion_seed: u64, noise_seed: u64) -> Trajectory {
    let times: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64).collect();
    let mut rec = record_trajectory(robot, &robot.model().standard_params(), &motion(motion_seed), &times);
    add_joint_terms(&mut rec, joints, Coulomb::Sign);
    add_torque_noise(&mut rec, &mut Gaussian::new(noise_seed));
    rec.to_trajectory().unwrap()
}

fn with_friction(estimator: Estimator) -> IdentifyOptions {
    IdentifyOptions {
        estimator,
        joints: JointTerms::Friction(Coulomb::Sign),
        ..IdentifyOptions::default()
    }
}

/// Joint 4 without viscous friction: with 1 % torque noise OLS makes its Fv
/// negative; the consistent estimator keeps every Ia, Fv, Fc ≥ 0 (Fv4 held at the
/// bound) and predicts another recording as well as OLS.
#[test]
fn consistent_estimation_keeps_friction_and_rotor_inertia_nonnegative() {
    let robot = ur5();
    let mut joints = joint_truth();
    joints[4 * 3 + 1] = 0.0;
    let traj = noisy_trajectory(&robot, &joints, 1, 3);
    let check = noisy_trajectory(&robot, &joints, 2, 4);
    let ols = pipeline::identify(&robot, &traj, &with_friction(Estimator::Ols)).unwrap();
    let consistent = pipeline::identify(&robot, &traj, &with_friction(Estimator::Consistent)).unwrap();
    let fv4 = 60 + 4 * 3 + 1;
    let solution = |id: &pipeline::Identification| match &id.prediction {
        Prediction::Regressor(t) => t.estimate.clone(),
        Prediction::Parameters(_) => panic!("a torque estimate"),
    };
    let (ols_est, est) = (solution(&ols), solution(&consistent));
    println!(
        "Fv4: OLS {:.4}, consistent {:.3e}",
        ols_est.solution[fv4], est.solution[fv4]
    );
    assert!(ols_est.solution[fv4] < 0.0, "OLS Fv4 {}", ols_est.solution[fv4]);
    for j in 0..6 {
        for k in 0..3 {
            let i = 60 + 4 * j + k;
            assert!(est.solution[i] >= 0.0, "joint {} [{k}]: {}", j + 1, est.solution[i]);
        }
    }
    // Truly zero, estimated at it (2.8e-12 here, held by the bound; 7e-4 when the
    // directions the data leave open were pulled toward 0 instead of the URDF).
    assert!(est.solution[fv4] < 0.01, "{}", est.solution[fv4]);
    let Method::StandardConsistent { params_at_bound, .. } = &est.method else {
        panic!("{}", est.method)
    };
    println!("{}; at the bound: {params_at_bound:?}", est.method);
    assert!(!params_at_bound.is_empty());
    for &i in params_at_bound {
        assert!(matches!(
            est.params[i].status,
            Status::Constrained | Status::InCombination
        ));
    }
    let param = &consistent.report.parameters[fv4];
    assert_eq!(param.name, "Fv4");
    assert!(param.value.is_some_and(|v| v >= 0.0), "{param:?}");
    // The fit and the prediction of an unseen recording: within 1 % of OLS's.
    assert!(est.residuals.rms <= 1.01 * ols_est.residuals.rms);
    let (e_ols, e_cons) = (
        overall_error(&robot, &ols, &check),
        overall_error(&robot, &consistent, &check),
    );
    println!("validation: OLS {e_ols:.5}, consistent {e_cons:.5}");
    assert!(e_cons <= 1.01 * e_ols, "consistent {e_cons} vs OLS {e_ols}");
    // Every joint's friction goes to the URDF, those at a bound included.
    let urdf = include_str!("../../../robots/ur5/ur5.urdf");
    let rewrite = consistent.rewrite_urdf(urdf, robot.model(), MergedLinks::Lump).unwrap();
    assert_eq!(rewrite.dynamics.len(), 6, "{:?}", rewrite.dynamics_kept);
    assert!(rewrite.dynamics.iter().all(|(_, fv, fc)| *fv >= 0.0 && *fc >= 0.0));
    // The smoothed Coulomb term is constrained the same way.
    let smooth = IdentifyOptions {
        joints: JointTerms::Friction(Coulomb::Smooth { epsilon: 0.01 }),
        ..with_friction(Estimator::Consistent)
    };
    let id = pipeline::identify(&robot, &traj, &smooth).unwrap();
    let est = solution(&id);
    assert!((0..6).all(|j| (0..3).all(|k| est.solution[60 + 4 * j + k] >= 0.0)));
    // The principal form takes no joint terms: refused, by name.
    let principal = IdentifyOptions {
        mode: pipeline::Mode::Principal,
        ..with_friction(Estimator::Consistent)
    };
    let e = pipeline::identify(&robot, &traj, &principal).unwrap_err();
    assert!(
        e.to_string().starts_with("friction applies to the standard mode"),
        "{e}"
    );
}

/// Rows of a joint slower than the threshold are left out of its equations and
/// counted; the identification still recovers the friction; bad thresholds are
/// refused by name.
#[test]
fn rows_below_a_speed_are_left_out_and_counted() {
    let robot = ur5();
    let traj = noisy_trajectory(&robot, &joint_truth(), 1, 3);
    let speed = 0.05;
    let options = IdentifyOptions {
        exclude_below: Some(speed),
        ..with_friction(Estimator::Ols)
    };
    let id = pipeline::identify(&robot, &traj, &options).unwrap();
    let expected: Vec<usize> = (0..6)
        .map(|j| (0..traj.len()).filter(|&k| traj.v(k).unwrap()[j].abs() < speed).count())
        .collect();
    println!("left out per joint: {expected:?} of {}", traj.len());
    assert_eq!(id.excluded_rows, expected);
    assert!(expected.iter().all(|&c| c > 0 && c < traj.len() / 4), "{expected:?}");
    let Prediction::Regressor(t) = &id.prediction else {
        panic!()
    };
    assert_eq!(
        t.estimate.residuals.rows,
        6 * traj.len() - expected.iter().sum::<usize>()
    );
    for j in 0..6 {
        let (fv, fc) = (t.estimate.solution[60 + 4 * j + 1], t.estimate.solution[60 + 4 * j + 2]);
        assert!((fv - FV[j]).abs() < 0.05 * FV[j], "Fv{}: {fv}", j + 1);
        assert!((fc - FC[j]).abs() < 0.05 * FC[j], "Fc{}: {fc}", j + 1);
    }
    let all = pipeline::identify(&robot, &traj, &with_friction(Estimator::Ols)).unwrap();
    assert_eq!(all.excluded_rows, vec![0; 6]);
    for bad in [-0.1, 0.0, f64::NAN, f64::INFINITY] {
        let o = IdentifyOptions {
            exclude_below: Some(bad),
            ..options.clone()
        };
        let e = pipeline::identify(&robot, &traj, &o).unwrap_err();
        assert!(
            matches!(
                e,
                PipelineError::InvalidOption {
                    option: "exclude-below",
                    ..
                }
            ),
            "{bad}: {e:?}"
        );
        assert!(e.to_string().contains("must be a positive speed"), "{e}");
    }
    let e = pipeline::identify(
        &robot,
        &traj,
        &IdentifyOptions {
            exclude_below: Some(1e6),
            ..options.clone()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("leaves no torque row"), "{e}");
    let mim = IdentifyOptions {
        mode: pipeline::Mode::Mim,
        exclude_below: Some(speed),
        ..IdentifyOptions::default()
    };
    assert!(mim.check().unwrap_err().to_string().contains("MIM uses every sample"));
}

/// The rotor inertia on its own (`IdentifyOptions::rotor_inertia`): friction without
/// it on a robot whose drives have none, rotor inertia without friction on a robot
/// whose joints have no friction; each recovers what is in the data, reports the
/// terms left out as `excluded` (0 in the solution); bad combinations are refused
/// by name.
#[test]
fn rotor_inertia_is_fitted_or_left_out_on_its_own() {
    let robot = ur5();
    let truth = joint_truth();
    let only = |keep: [bool; 4]| -> Vec<f64> {
        truth
            .iter()
            .enumerate()
            .map(|(i, x)| if keep[i % 4] { *x } else { 0.0 })
            .collect()
    };
    let terms = |id: &pipeline::Identification| -> Vec<ParamReport> { id.report.parameters[60..84].to_vec() };
    // Friction without rotor inertia.
    let joints = only([false, true, true, true]);
    let traj = noisy_trajectory(&robot, &joints, 1, 3);
    let options = IdentifyOptions {
        rotor_inertia: Some(false),
        ..with_friction(Estimator::Ols)
    };
    let id = pipeline::identify(&robot, &traj, &options).unwrap();
    let solution = match &id.prediction {
        Prediction::Regressor(t) => t.estimate.solution.clone(),
        Prediction::Parameters(_) => panic!("a torque estimate"),
    };
    for (i, p) in terms(&id).iter().enumerate() {
        if i % 4 == 0 {
            assert_eq!((p.value, p.status), (None, ParamStatus::Excluded), "{p:?}");
            assert_eq!(solution[60 + i], 0.0);
        } else {
            let (v, sigma) = (p.value.unwrap(), p.sigma.unwrap());
            assert!((v - joints[i]).abs() < 4.0 * sigma, "{p:?} vs {}", joints[i]);
        }
    }
    let pre = id.report.prediction.as_ref().unwrap().preprocessing.as_ref().unwrap();
    assert_eq!(pre.rotor_inertia, Some(false));
    // Rotor inertia without friction: Ia of joints 3–6 (1 and 2 group with Izz).
    let joints = only([true, false, false, false]);
    let traj = noisy_trajectory(&robot, &joints, 2, 4);
    let options = IdentifyOptions {
        rotor_inertia: Some(true),
        ..IdentifyOptions::default()
    };
    let id = pipeline::identify(&robot, &traj, &options).unwrap();
    assert_eq!(id.report.parameterisation, Parameterisation::StandardAndJoints);
    for (i, p) in terms(&id).iter().enumerate() {
        match (i % 4, i / 4) {
            (0, j) if j >= 2 => {
                let (v, sigma) = (p.value.unwrap(), p.sigma.unwrap());
                assert!((v - IA[j]).abs() < 4.0 * sigma && sigma < 0.25 * IA[j], "{p:?}");
            }
            (0, _) => assert_eq!(p.status, ParamStatus::InCombination, "{p:?}"),
            _ => assert_eq!((p.value, p.status), (None, ParamStatus::Excluded), "{p:?}"),
        }
    }
    // The friction terms left out of the model are not friction to write.
    let urdf = include_str!("../../../robots/ur5/ur5.urdf");
    let rewrite = id.rewrite_urdf(urdf, robot.model(), MergedLinks::Lump).unwrap();
    assert!(rewrite.dynamics.is_empty());
    assert!(rewrite
        .dynamics_kept
        .iter()
        .all(|(_, why)| why == "friction left out of the model"));
    // Leaving it out without friction terms, or outside the standard mode: refused.
    for bad in [
        IdentifyOptions {
            rotor_inertia: Some(false),
            ..IdentifyOptions::default()
        },
        IdentifyOptions {
            rotor_inertia: Some(true),
            mode: pipeline::Mode::Principal,
            ..IdentifyOptions::default()
        },
    ] {
        let e = pipeline::identify(&robot, &traj, &bad).unwrap_err();
        assert!(
            matches!(
                e,
                PipelineError::InvalidOption {
                    option: "rotor-inertia",
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().starts_with("rotor-inertia "), "{e}");
    }
}

/// The joint model chosen on held-out time blocks of a recording whose joints have
/// rotor inertia and sign friction (1 % torque noise): a model with both, never
/// rigid bodies alone or friction without rotor inertia, no worse held out than
/// sign friction, and no extra term (the joints have none).
#[test]
fn the_chosen_joint_model_has_what_the_joints_have() {
    use dyngen_identify::choice::{choose, BLOCKS, DEFAULT_EXTRAS};
    let robot = ur5();
    // 15 s of the 30 s recording: enough for the choice, half the time.
    let traj = noisy_trajectory(&robot, &joint_truth(), 1, 5)
        .select(|k| k < 1500)
        .unwrap();
    let choice = choose(&robot, &traj, &IdentifyOptions::default(), DEFAULT_EXTRAS).unwrap();
    println!("{choice}");
    let error = |name: &str| {
        let s = choice.scores.iter().find(|s| s.candidate.name == name).unwrap();
        s.held_out.as_ref().unwrap().overall
    };
    let chosen = choice.chosen().name;
    assert!(["sign", "auto", "stribeck"].contains(&chosen), "{choice}");
    assert!(error(chosen) <= error("sign"), "{choice}");
    assert!(error("none") > 5.0 * error("sign"), "{choice}");
    assert!(error("sign-no-rotor-inertia") > error("sign"), "{choice}");
    assert!(choice.chosen().extras.is_empty(), "{choice}");
    assert!(
        choice.scores.len() > dyngen_identify::choice::CANDIDATES.len(),
        "the extra terms were tried: {choice}"
    );
    let applied = choice.apply(&IdentifyOptions::default());
    assert_eq!(applied.joints, choice.chosen().joints);
    // Too short a recording for the blocks, and another mode.
    let short = traj.select(|k| k < 2 * BLOCKS - 1).unwrap();
    let e = choose(&robot, &short, &IdentifyOptions::default(), ExtraTerms::NONE).unwrap_err();
    assert!(
        e.to_string()
            .contains("at least 2 samples in each of its 4 time blocks"),
        "{e}"
    );
    let principal = IdentifyOptions {
        mode: pipeline::Mode::Principal,
        ..IdentifyOptions::default()
    };
    let e = choose(&robot, &traj, &principal, ExtraTerms::NONE).unwrap_err();
    assert!(e.to_string().contains("standard mode"), "{e}");
}
