//! A tour of generated robots at work: each shipped robot's generated dynamics
//! against the reference implementation on random states (accuracy and speed), the
//! paper's graph-theoretic matrices of the 6-DOF manipulator and its decoupled
//! per-body model, base parameters, and the operation counts of the generated code.
//!
//!     cargo run --release -p dyngen-examples --example tour

use dyngen::Robot;
use dyngen_model::graph;
use dyngen_reference::{sample_states, Reference};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;
use std::hint::black_box;
use std::time::Instant;

const STATES: usize = 2000;

/// Median over 5 rounds of the mean time per call, in nanoseconds.
fn time_ns(mut f: impl FnMut(usize)) -> f64 {
    let mut rounds: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            for k in 0..STATES * 10 {
                f(k % STATES);
            }
            start.elapsed().as_nanos() as f64 / (STATES * 10) as f64
        })
        .collect();
    rounds.sort_by(f64::total_cmp);
    rounds[2]
}

fn tour<R: Robot>() {
    let reference = Reference::of::<R>();
    let states = sample_states(reference.model(), STATES, 42);
    let params = R::nominal_params();
    let mut worst = 0.0f64;
    let mut tau = vec![0.0; R::NV];
    for s in &states {
        R::rnea(&s.q, &s.v, &s.a, params, &mut tau);
        let want = reference.rnea(&s.q, &s.v, &s.a, params);
        let scale = want.iter().fold(1e-9f64, |m, x| m.max(x.abs()));
        let err = tau.iter().zip(&want).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
        worst = worst.max(err);
    }
    let generated = time_ns(|k| {
        let s = &states[k];
        R::rnea(
            black_box(&s.q),
            black_box(&s.v),
            black_box(&s.a),
            black_box(params),
            &mut tau,
        );
        black_box(&tau);
    });
    let refd = time_ns(|k| {
        let s = &states[k];
        black_box(reference.rnea(black_box(&s.q), black_box(&s.v), black_box(&s.a), black_box(params)));
    });
    let ops = R::op_counts()
        .iter()
        .find(|(n, _)| *n == "rnea")
        .map(|(_, o)| *o)
        .unwrap_or_default();
    println!(
        "{:<12} {:>3} dof  max rel. error {:>8.1e}  rnea {:>7.1} ns generated, {:>8.1} ns reference ({:>5.1}x)  {:>5} flops",
        R::NAME,
        R::NV,
        worst,
        generated,
        refd,
        refd / generated,
        ops.muls + ops.adds
    );
}

fn main() {
    println!("Generated rnea against the reference implementation, {STATES} random states each:\n");
    tour::<Planar2>();
    tour::<Paper6>();
    tour::<Ur5>();
    tour::<GripperArm>();
    tour::<Puma560>();
    tour::<Panda>();

    let model = Reference::of::<Paper6>().model().clone();
    println!("\nThe paper's 6-DOF manipulator as a graph (docs/design.md, \"The paper's graph theory\"):");
    println!("incidence matrix S (rows bodies 0..6, columns joints 1..6):");
    for row in graph::incidence(&model) {
        println!("  {}", row.iter().map(|x| format!("{x:>3}")).collect::<String>());
    }
    println!("path matrix T = S⁻¹ (rows joints, columns bodies):");
    for row in graph::path_matrix(&model) {
        println!("  {}", row.iter().map(|x| format!("{x:>3}")).collect::<String>());
    }
    let q = [0.1, -0.6, 0.9, 0.3, -0.5, 0.2];
    let tau = Paper6::rnea(&q, &[0.0; 6], &[0.0; 6], &Paper6::NOMINAL_PARAMS);
    println!("\nholding torques at q = {q:?}:");
    println!("  {}", tau.iter().map(|t| format!("{t:>9.3}")).collect::<String>());

    // The paper's decoupling: each body's Newton–Euler equation holds alone, with its
    // own four parameters, so one instant identifies θ_i = (m, J1, J2, J3).
    let (v, a) = ([0.4, -0.3, 0.8, 1.1, -0.6, 0.9], [0.5, 1.2, -0.7, 0.3, 0.8, -1.0]);
    let bodies = Paper6::body_regressors(&q, &v, &a);
    let resultants = Paper6::body_resultants(&q, &v, &a, &Paper6::NOMINAL_PARAMS);
    println!("\nthe paper's MIM on paper6 from one instant (noise-free), θ = (m, J1, J2, J3) in kg and kg·m²:");
    for (i, (body, res)) in bodies.iter().zip(&resultants).enumerate() {
        let stacked = dyngen::nalgebra::SMatrix::<f64, 6, 4>::from_rows(&[
            body.force.row(0).into_owned(),
            body.force.row(1).into_owned(),
            body.force.row(2).into_owned(),
            body.moment.row(0).into_owned(),
            body.moment.row(1).into_owned(),
            body.moment.row(2).into_owned(),
        ]);
        let rhs = dyngen::nalgebra::Vector6::new(
            res.force.x,
            res.force.y,
            res.force.z,
            res.torque.x,
            res.torque.y,
            res.torque.z,
        );
        // A parameter is identifiable from this instant only if it has no component
        // in the null space of A_i (the turret, spinning about z alone, cannot
        // reveal J1 and J2): those are reported as such, never as estimates.
        let svd = stacked.svd(true, true);
        let tol = 1e-10 * svd.singular_values.max();
        let theta = svd.solve(&rhs, tol).expect("SVD solve");
        let v_t = svd.v_t.expect("V is computed");
        let unidentifiable = |k: usize| (0..4).any(|r| svd.singular_values[r] <= tol && v_t[(r, k)].abs() > 1e-8);
        let truth = &Paper6::NOMINAL_THETA[4 * i..4 * i + 4];
        let cells: Vec<String> = (0..4)
            .map(|k| {
                if unidentifiable(k) {
                    "unidentifiable".into()
                } else {
                    format!("{:.5}", theta[k])
                }
            })
            .collect();
        let err = (0..4).filter(|&k| !unidentifiable(k)).fold(0.0f64, |m, k| {
            m.max(dyngen_identify::relative_error(theta[k], truth[k]))
        });
        println!(
            "  B{}: m {:>9}  J1 {:>14}  J2 {:>14}  J3 {:>8}  (max rel. error {err:.1e})",
            i + 1,
            cells[0],
            cells[1],
            cells[2],
            cells[3]
        );
    }

    println!(
        "\nbase parameters: ur5 {}, puma560 {}, panda {}; e.g. for the UR5:",
        Ur5::NBASE,
        Puma560::NBASE,
        Panda::NBASE
    );
    for g in &Ur5::BASE_GROUPINGS[..3] {
        println!("  {g}");
    }

    println!("\nOperation counts of the generated code (ur5):");
    for (name, counts) in Ur5::OP_COUNTS {
        println!("  {name:<26} {counts}");
    }
}
