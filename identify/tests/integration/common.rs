//! What the simulated-UR5 tests of joint friction, Stribeck friction and payloads
//! share: the robot, the drive parameters of its joints, the excitation, torque
//! noise and the prediction error of an identification.
#![allow(dead_code)] // each test file uses a part

use dyngen_identify::data::Trajectory;
use dyngen_identify::pipeline::Identification;
use dyngen_identify::simulate::{FourierExcitation, Gaussian, Recording};
use dyngen_identify::validate::Validation;
use dyngen_model::sample::SplitMix64;
use dyngen_reference::Reference;

/// Rotor inertia, viscous and Coulomb friction and offset per joint, of the order
/// of a UR5's drives.
pub const IA: [f64; 6] = [0.40, 0.40, 0.20, 0.08, 0.08, 0.08];
pub const FV: [f64; 6] = [3.0, 3.0, 2.0, 0.6, 0.6, 0.6];
pub const FC: [f64; 6] = [6.0, 6.0, 4.0, 1.5, 1.5, 1.5];
pub const F0: [f64; 6] = [0.2, -0.3, 0.1, 0.05, -0.05, 0.02];

pub fn ur5() -> Reference {
    Reference::new(&dyngen_model::parse_urdf(include_str!("../../../robots/ur5/ur5.urdf")).unwrap())
}

/// `[Ia, Fv, Fc, F0]` per joint.
pub fn joint_truth() -> Vec<f64> {
    (0..6).flat_map(|j| [IA[j], FV[j], FC[j], F0[j]]).collect()
}

/// A multi-sine of 5 harmonics of 0.1 Hz per joint, seeded: velocity amplitudes up
/// to 0.3 rad/s per harmonic (so accelerations reach ~1 rad/s², which the rotor
/// inertias need), about a pose where gravity on the shoulder and elbow varies.
pub fn motion(seed: u64) -> FourierExcitation {
    let mut rng = SplitMix64::new(seed);
    let mut coef = || -> Vec<Vec<f64>> {
        (0..6)
            .map(|_| (1..=5).map(|_| rng.uniform(-0.3, 0.3)).collect())
            .collect()
    };
    let (a, b) = (coef(), coef());
    FourierExcitation::new(0.1, vec![0.0, -1.0, 1.0, 0.0, 0.0, 0.0], &a, &b)
}

/// 1 % of each joint's RMS torque as Gaussian noise on the torques (or currents);
/// the σ per joint.
pub fn add_torque_noise(rec: &mut Recording, noise: &mut Gaussian) -> Vec<f64> {
    let sigma: Vec<f64> = (0..6)
        .map(|j| 0.01 * (rec.samples.iter().map(|s| s.tau[j] * s.tau[j]).sum::<f64>() / rec.len() as f64).sqrt())
        .collect();
    for s in &mut rec.samples {
        for j in 0..6 {
            s.tau[j] += noise.normal(sigma[j]);
        }
    }
    sigma
}

/// The overall relative error of `id`'s prediction of `traj`'s torques.
pub fn overall_error(robot: &Reference, id: &Identification, traj: &Trajectory) -> f64 {
    let predicted = id.predict(robot, traj).unwrap();
    let names: Vec<String> = robot.model().joints.iter().map(|j| j.name.clone()).collect();
    Validation::new(
        &names,
        (0..traj.len()).map(|k| traj.tau(k)),
        predicted.iter().map(|p| &p[..]),
    )
    .unwrap()
    .overall
}
