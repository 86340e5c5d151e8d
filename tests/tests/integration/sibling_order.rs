//! One numbering everywhere: a tree whose sibling joints are named out of order
//! (`joint2` and `joint10` both leave body 1; by name `joint10` sorts first). A URDF
//! reader numbers siblings by name, the DSL by declaration; the generated robot
//! carries its own model (`R::MODEL`), so the reference, MIM and NIM see the
//! generator's numbering and attribute every measurement to the right body.

use dyngen::prelude::*;
use dyngen_identify::mim::{self, MimOptions};
use dyngen_identify::simulate::{record, Experiment};
use dyngen_model::principal_params;
use dyngen_nim::{Nim, NimConfig, TrainOptions};
use dyngen_reference::{Dynamics, Generated};

dyngen::robot! {
    name: Tree10,
    incidence: [
        [-1,  0,  0,  0,  0,  0,  0,  0,  0,  0],   // body 0
        [ 1, -1,  0,  0,  0,  0,  0,  0,  0, -1],   // body 1
        [ 0,  1, -1,  0,  0,  0,  0,  0,  0,  0],   // body 2
        [ 0,  0,  1, -1,  0,  0,  0,  0,  0,  0],   // body 3
        [ 0,  0,  0,  1, -1,  0,  0,  0,  0,  0],   // body 4
        [ 0,  0,  0,  0,  1, -1,  0,  0,  0,  0],   // body 5
        [ 0,  0,  0,  0,  0,  1, -1,  0,  0,  0],   // body 6
        [ 0,  0,  0,  0,  0,  0,  1, -1,  0,  0],   // body 7
        [ 0,  0,  0,  0,  0,  0,  0,  1, -1,  0],   // body 8
        [ 0,  0,  0,  0,  0,  0,  0,  0,  1,  0],   // body 9
        [ 0,  0,  0,  0,  0,  0,  0,  0,  0,  1],   // body 10
    ],
    joints: [revolute(z), revolute(y), revolute(y), revolute(x), revolute(z), revolute(y), revolute(x), revolute(z), revolute(y), revolute(y)],
    body_joint_vectors: {
        (0, 1): [0.0, 0.0, 0.0],
        (1, 1): [-0.15, 0.0, 0.0],
        (1, 2): [0.15, 0.0, 0.0],
        (1, 10): [0.0, 0.1, 0.0],
        (2, 2): [-0.15, 0.0, 0.0],
        (2, 3): [0.15, 0.0, 0.0],
        (3, 3): [-0.15, 0.0, 0.0],
        (3, 4): [0.15, 0.0, 0.0],
        (4, 4): [-0.15, 0.0, 0.0],
        (4, 5): [0.15, 0.0, 0.0],
        (5, 5): [-0.15, 0.0, 0.0],
        (5, 6): [0.15, 0.0, 0.0],
        (6, 6): [-0.15, 0.0, 0.0],
        (6, 7): [0.15, 0.0, 0.0],
        (7, 7): [-0.15, 0.0, 0.0],
        (7, 8): [0.15, 0.0, 0.0],
        (8, 8): [-0.15, 0.0, 0.0],
        (8, 9): [0.15, 0.0, 0.0],
        (9, 9): [-0.15, 0.0, 0.0],
        (10, 10): [-0.15, 0.0, 0.0],
    },
    bodies: {
        1: cylinder(mass: 1.0, radius: 0.03, length: 0.3, axis: x),
        2: cylinder(mass: 2.0, radius: 0.03, length: 0.3, axis: x),
        3: cylinder(mass: 3.0, radius: 0.03, length: 0.3, axis: x),
        4: cylinder(mass: 4.0, radius: 0.03, length: 0.3, axis: x),
        5: cylinder(mass: 5.0, radius: 0.03, length: 0.3, axis: x),
        6: cylinder(mass: 6.0, radius: 0.03, length: 0.3, axis: x),
        7: cylinder(mass: 7.0, radius: 0.03, length: 0.3, axis: x),
        8: cylinder(mass: 8.0, radius: 0.03, length: 0.3, axis: x),
        9: cylinder(mass: 9.0, radius: 0.03, length: 0.3, axis: x),
        10: cylinder(mass: 10.0, radius: 0.03, length: 0.3, axis: x),
    },
}

/// Body `i` weighs `i` kg, so a body mistaken for another shows at once.
fn mass(theta: &[f64], body: usize) -> f64 {
    theta[4 * body]
}

#[test]
fn the_runtime_model_keeps_the_generated_numbering() {
    let robot = Generated::<Tree10>::new();
    let names: Vec<&str> = robot.model().joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, Tree10::joint_names());
    assert_eq!(names[1], "joint2");
    assert_eq!(names[9], "joint10");
    for (j, joint) in robot.model().joints.iter().enumerate() {
        assert_eq!(joint.parent, Tree10::parents()[j], "joint {}", j + 1);
    }
    // The hazard this guards against: the same robot written to URDF and read back
    // is numbered by joint name, `joint10` before `joint2`.
    let reread = dyngen_model::parse_urdf(&dyngen_reference::urdf_of::<Tree10>()).unwrap();
    let renamed: Vec<&str> = reread.joints.iter().map(|j| j.name.as_str()).collect();
    assert_ne!(
        renamed, names,
        "a name-ordered reader agrees by chance; the test proves nothing"
    );
}

#[test]
fn mim_attributes_each_body_its_own_parameters() {
    let robot = Generated::<Tree10>::new();
    let truth = principal_params(robot.model());
    for (i, m) in (1..=10).map(|i| (i - 1, i as f64)) {
        assert!((mass(&truth, i) - m).abs() < 1e-12);
        assert!((mass(Tree10::nominal_theta(), i) - m).abs() < 1e-12);
    }
    let experiment = Experiment::paper(robot.model());
    let recording = record(&robot, Tree10::nominal_params(), &experiment);
    let est = mim::samples(&recording, 0..recording.len(), Some(&truth), &MimOptions::default()).unwrap();
    for e in est.errors().unwrap() {
        if e.index == 0 {
            let rel = e
                .relative
                .unwrap_or_else(|| panic!("mass of body {} not identified", e.body + 1));
            assert!(
                rel < 1e-9,
                "mass of body {}: {:?} against {}",
                e.body + 1,
                e.estimate,
                e.truth
            );
        }
    }
}

#[test]
fn nim_attributes_each_body_its_own_parameters() {
    let robot = Generated::<Tree10>::new();
    let nominal = principal_params(robot.model());
    let experiment = Experiment::paper(robot.model());
    let recording = record(&robot, Tree10::nominal_params(), &experiment);
    // A small network: enough to tell a 3 kg body from a 10 kg one.
    let defaults = NimConfig::default();
    let config = NimConfig {
        draws: 200,
        validation_draws: 20,
        train: TrainOptions {
            max_steps: 800,
            ..defaults.train.clone()
        },
        ..defaults
    };
    let (nim, _) = Nim::train("tree10", &recording, &nominal, &config, &|_| {}).unwrap();
    let estimate = nim.identify(&recording, nim.window / 2).unwrap();
    for i in 0..10 {
        let m = estimate.theta[4 * i].unwrap_or_else(|| panic!("no mass for body {}", i + 1));
        let want = (i + 1) as f64;
        assert!(
            (m - want).abs() < 0.3 * want,
            "body {}: NIM mass {m} kg, truth {want} kg",
            i + 1
        );
    }
}
