//! A payload identified on a known robot: a simulated UR5 carrying 2.5 kg on its
//! last link, with rotor inertia and friction in its drives and 1 % torque noise; the
//! load's mass, centre of mass and inertia from `τ − τ_known = Y_6 · π_L`.

use crate::common::{joint_truth, motion, ur5};
use dyngen_identify::payload::{self, KnownRobot, Payload};
use dyngen_identify::simulate::{add_joint_terms, record_trajectory, Gaussian};
use dyngen_identify::{IdentifyError, Options};
use dyngen_model::joint_params::Coulomb;
use dyngen_reference::Reference;

/// 2.5 kg, centre of mass 3 cm off the flange axis and 6 cm beyond it, a box
/// 8 × 6 × 10 cm about its centre.
fn load() -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let (m, (a, b, c)) = (2.5, (0.08f64, 0.06f64, 0.10f64));
    let inertia = [
        [m * (b * b + c * c) / 12.0, 0.0, 0.0],
        [0.0, m * (a * a + c * c) / 12.0, 0.0],
        [0.0, 0.0, m * (a * a + b * b) / 12.0],
    ];
    (m, [0.03, -0.01, 0.06], inertia)
}

/// The loaded robot's recording (2 minutes at 100 Hz), with the drives and 1 % of
/// each joint's RMS torque as noise.
fn loaded_recording(robot: &Reference, payload: &Payload) -> dyngen_identify::data::Trajectory {
    let mut params = robot.model().standard_params();
    for k in 0..10 {
        params[10 * (payload.body - 1) + k] += payload.params[k];
    }
    let times: Vec<f64> = (0..12_000).map(|k| k as f64 * 0.01).collect();
    let mut rec = record_trajectory(robot, &params, &motion(4), &times);
    add_joint_terms(&mut rec, &joint_truth(), Coulomb::Sign);
    let mut noise = Gaussian::new(17);
    for j in 0..6 {
        let rms = (rec.samples.iter().map(|s| s.tau[j] * s.tau[j]).sum::<f64>() / rec.len() as f64).sqrt();
        for s in &mut rec.samples {
            s.tau[j] += noise.normal(0.01 * rms);
        }
    }
    rec.to_trajectory().unwrap()
}

#[test]
fn a_payload_on_the_last_link_is_recovered() {
    let robot = ur5();
    let (m, c, inertia) = load();
    let truth = Payload::from_mass_properties(6, m, c, inertia);
    let data = loaded_recording(&robot, &truth);
    let (nominal, jp) = (robot.model().standard_params(), joint_truth());
    let known = KnownRobot {
        dynamics: &robot,
        params: &nominal,
        joints: Some((&jp, Coulomb::Sign)),
    };
    let est = payload::identify(&known, 6, &data, &Options::default()).unwrap();
    println!(
        "mass {:.4} ± {:.4} kg (truth {m}); centre of mass {:?} ± {:?} m (truth {c:?}); \
         inertia about it {:?}; residual RMS {:.3} N·m over {} rows, condition number {:.0}",
        est.mass, est.mass_sigma, est.com, est.com_sigma, est.inertia, est.residual_rms, est.rows, est.condition_number
    );
    assert!((est.mass - m).abs() < 0.005 * m, "mass {} vs {m}", est.mass);
    for i in 0..3 {
        assert!(
            (est.com[i] - c[i]).abs() < 1e-3,
            "centre of mass {:?} vs {c:?}",
            est.com
        );
        // The stated uncertainty covers the error.
        assert!(
            (est.com[i] - c[i]).abs() < 4.0 * est.com_sigma[i] + 1e-12,
            "{:?}",
            est.com_sigma
        );
    }
    assert!((est.mass - m).abs() < 4.0 * est.mass_sigma, "σ {}", est.mass_sigma);
    assert_eq!(est.payload().body, 6);

    // Without the drives in the known model, their torques are blamed on the load.
    let rigid_only = KnownRobot { joints: None, ..known };
    let biased = payload::identify(&rigid_only, 6, &data, &Options::default()).unwrap();
    assert!(
        (biased.mass - m).abs() > (est.mass - m).abs(),
        "{} vs {}",
        biased.mass,
        est.mass
    );
}

#[test]
fn bad_arguments_are_named() {
    let robot = ur5();
    let truth = Payload::from_mass_properties(6, 1.0, [0.0; 3], [[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]]);
    let data = loaded_recording(&robot, &truth);
    let nominal = robot.model().standard_params();
    let known = KnownRobot {
        dynamics: &robot,
        params: &nominal,
        joints: None,
    };
    let err = payload::identify(&known, 7, &data, &Options::default()).unwrap_err();
    assert!(err.to_string().contains("payload body"), "{err}");
    let short = KnownRobot {
        params: &nominal[..50],
        ..known
    };
    let err = payload::identify(&short, 6, &data, &Options::default()).unwrap_err();
    assert!(
        matches!(
            err,
            IdentifyError::DimensionMismatch {
                what: "robot standard parameters",
                ..
            }
        ),
        "{err}"
    );
    let jp = vec![0.0; 23];
    let wrong = KnownRobot {
        joints: Some((&jp, Coulomb::Sign)),
        ..known
    };
    let err = payload::identify(&wrong, 6, &data, &Options::default()).unwrap_err();
    assert!(err.to_string().contains("robot joint parameters"), "{err}");
    // Without velocities and accelerations.
    let bare = dyngen_identify::data::Trajectory::new(
        6,
        data.t().to_vec(),
        data.positions().to_vec(),
        data.torques().to_vec(),
    )
    .unwrap();
    let err = payload::identify(&known, 6, &bare, &Options::default()).unwrap_err();
    assert!(err.to_string().contains("velocities and accelerations"), "{err}");
    // Held still, the robot shows the load's weight but not its inertia.
    let still = bare
        .with_velocities(vec![0.0; data.positions().len()])
        .unwrap()
        .with_accelerations(vec![0.0; data.positions().len()])
        .unwrap();
    let err = payload::identify(&known, 6, &still, &Options::default()).unwrap_err();
    assert!(
        err.to_string().contains("does not determine the payload's Ixx"),
        "{err}"
    );
    // A "load" of negative mass is no load.
    let negative = Payload {
        body: 6,
        params: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    };
    let err = payload::identify(&known, 6, &loaded_recording(&robot, &negative), &Options::default()).unwrap_err();
    assert!(err.to_string().contains("payload mass"), "{err}");
}
