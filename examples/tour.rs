//! A tour of generated robots at work: each shipped robot's generated dynamics
//! against the reference implementation on random states (accuracy and speed), the
//! paper's graph-theoretic matrices of the 6-DOF manipulator, and the operation
//! counts of the generated code.
//!
//!     cargo run --release -p dyngen-examples --example tour

use dyngen::model::graph;
use dyngen::reference::{sample_states, Reference};
use dyngen::Robot;
use robot_gripper_arm::GripperArm;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_ur5::Ur5;
use std::hint::black_box;
use std::time::Instant;

const STATES: usize = 2000;

fn reference_of<R: Robot>() -> Reference {
    let mut model = dyngen::model::parse_urdf(R::urdf()).expect("generated URDF parses");
    model.gravity = R::gravity();
    Reference::new(&model)
}

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
    let reference = reference_of::<R>();
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

    let model = reference_of::<Paper6>().model().clone();
    println!("\nThe paper's 6-DOF manipulator as a graph (DESIGN §4):");
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

    println!("\nOperation counts of the generated code:");
    for (name, counts) in Ur5::OP_COUNTS {
        println!("  ur5 {name:<20} {counts}");
    }
}
