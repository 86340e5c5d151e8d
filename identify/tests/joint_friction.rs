//! Identification of a robot with rotor inertia and friction, as real robots are:
//! the standard parameters and per joint `[Ia, Fv, Fc, F0]` from joint torques, on a
//! simulated UR5 whose recordings pass through a real-looking logger (jittered
//! stamps, duplicate rows, motor currents, 1 % torque noise), validated on a second
//! recording it was not identified on.

use dyngen_identify::data::Recipe;
use dyngen_identify::faer::Mat;
use dyngen_identify::mim::{self, TorqueRegressor, Weighting};
use dyngen_identify::simulate::{add_joint_terms, record_trajectory, FourierExcitation, Gaussian, Logger, Recording};
use dyngen_identify::validate::Validation;
use dyngen_identify::{Accumulator, Channels, Options};
use dyngen_model::joint_params::Coulomb;
use dyngen_model::sample::SplitMix64;
use dyngen_reference::Reference;

const IA: [f64; 6] = [0.40, 0.40, 0.20, 0.08, 0.08, 0.08];
const FV: [f64; 6] = [3.0, 3.0, 2.0, 0.6, 0.6, 0.6];
const FC: [f64; 6] = [6.0, 6.0, 4.0, 1.5, 1.5, 1.5];
const F0: [f64; 6] = [0.2, -0.3, 0.1, 0.05, -0.05, 0.02];
const GAINS: [f64; 6] = [14.0, 13.0, 12.0, 9.0, 8.5, 8.0];

fn robot() -> Reference {
    Reference::new(&dyngen_model::parse_urdf(include_str!("../../robots/ur5/ur5.urdf")).unwrap())
}

fn joint_truth() -> Vec<f64> {
    (0..6).flat_map(|j| [IA[j], FV[j], FC[j], F0[j]]).collect()
}

/// A multi-sine of 5 harmonics of 0.1 Hz per joint, seeded: velocity amplitudes up
/// to 0.3 rad/s per harmonic (so accelerations reach ~1 rad/s², which the rotor
/// inertias need), about a pose where gravity on the shoulder and elbow varies.
fn motion(seed: u64) -> FourierExcitation {
    let mut rng = SplitMix64::new(seed);
    let harmonics = 5;
    let mut coef = || -> Vec<Vec<f64>> {
        (0..6)
            .map(|_| (1..=harmonics).map(|_| rng.uniform(-0.3, 0.3)).collect())
            .collect()
    };
    let (a, b) = (coef(), coef());
    FourierExcitation::new(0.1, vec![0.0, -1.0, 1.0, 0.0, 0.0, 0.0], &a, &b)
}

fn recording(robot: &Reference, seed: u64, times: &[f64]) -> Recording {
    let mut rec = record_trajectory(robot, &robot.model().standard_params(), &motion(seed), times);
    add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
    rec
}

/// 1 % of each joint's RMS torque as Gaussian noise on the torques (or currents).
fn add_torque_noise(rec: &mut Recording, noise: &mut Gaussian) -> Vec<f64> {
    let rms: Vec<f64> = (0..6)
        .map(|j| (rec.samples.iter().map(|s| s.tau[j] * s.tau[j]).sum::<f64>() / rec.len() as f64).sqrt())
        .collect();
    let sigma: Vec<f64> = rms.iter().map(|r| 0.01 * r).collect();
    for s in &mut rec.samples {
        for j in 0..6 {
            s.tau[j] += noise.normal(sigma[j]);
        }
    }
    sigma
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
    let robot = robot();
    let times: Vec<f64> = (0..2000).map(|k| 0.01 * k as f64).collect();
    let rec = recording(&robot, 1, &times);
    let est = mim::torque(
        &robot,
        &rec,
        0..rec.len(),
        TorqueRegressor::StandardAndJoints(Coulomb::Sign),
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
    let robot = robot();
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
    let regressor = TorqueRegressor::StandardAndJoints(Coulomb::Sign);
    let p = regressor.columns(6);
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
    let robot = robot();
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
            "k{} = {:.4} (stacked least squares {:.4}; truth {})",
            j + 1,
            est.gains[j],
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
    }
}
