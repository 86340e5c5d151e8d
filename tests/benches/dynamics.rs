//! Generated against reference dynamics, per robot. Each call takes the next of 1,000
//! random states (as Pinocchio's own benchmark does), so nothing is constant-folded.
//! Ratios against Pinocchio are measured in the same sitting; see docs/benchmarks.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use dyngen::{Pose, Robot, Wrench};
use dyngen_reference::Reference;
use dyngen_reference::{sample_states, State};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;

fn states<R: Robot>() -> Vec<State> {
    sample_states(Reference::of::<R>().model(), 1000, 7)
}

fn bench_robot<R: Robot>(c: &mut Criterion, name: &str) {
    let states = states::<R>();
    let params = R::nominal_params().to_vec();
    let reference = Reference::of::<R>();
    let mut group = c.benchmark_group(name);
    let mut k = 0;
    let mut tau = vec![0.0; R::NV];
    group.bench_function("rnea/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::rnea(
                black_box(&s.q),
                black_box(&s.v),
                black_box(&s.a),
                black_box(&params),
                &mut tau,
            );
            black_box(&tau);
        })
    });
    group.bench_function("rnea/reference", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            black_box(reference.rnea(black_box(&s.q), black_box(&s.v), black_box(&s.a), black_box(&params)))
        })
    });
    let mut poses = vec![Pose::default(); R::NBODIES];
    group.bench_function("forward_kinematics/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::forward_kinematics(black_box(&s.q), &mut poses);
            black_box(&poses);
        })
    });
    let mut wrenches = vec![Wrench::default(); R::NBODIES];
    group.bench_function("joint_wrenches/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::joint_wrenches(
                black_box(&s.q),
                black_box(&s.v),
                black_box(&s.a),
                black_box(&params),
                &mut wrenches,
            );
            black_box(&wrenches);
        })
    });
    let mut y = vec![0.0; R::NV * R::NPARAMS];
    group.bench_function("joint_torque_regressor/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::joint_torque_regressor(black_box(&s.q), black_box(&s.v), black_box(&s.a), &mut y);
            black_box(&y);
        })
    });
    let mut yb = vec![0.0; R::NV * R::NBASE];
    group.bench_function("base_regressor/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::base_regressor(black_box(&s.q), black_box(&s.v), black_box(&s.a), &mut yb);
            black_box(&yb);
        })
    });
    let mut m = vec![0.0; R::NV * R::NV];
    group.bench_function("crba/generated", |b| {
        b.iter(|| {
            let s = &states[k % states.len()];
            k += 1;
            R::crba(black_box(&s.q), black_box(&params), &mut m);
            black_box(&m);
        })
    });
    let taus: Vec<Vec<f64>> = states
        .iter()
        .map(|s| reference.rnea(&s.q, &s.v, &s.a, &params))
        .collect();
    let mut acc = vec![0.0; R::NV];
    group.bench_function("aba/generated", |b| {
        b.iter(|| {
            let i = k % states.len();
            k += 1;
            let s = &states[i];
            R::aba(
                black_box(&s.q),
                black_box(&s.v),
                black_box(&taus[i]),
                black_box(&params),
                &mut acc,
            );
            black_box(&acc);
        })
    });
    group.finish();
}

fn dynamics(c: &mut Criterion) {
    bench_robot::<Ur5>(c, "ur5");
    bench_robot::<Panda>(c, "panda");
    bench_robot::<Puma560>(c, "puma560");
    bench_robot::<GripperArm>(c, "gripper_arm");
    bench_robot::<Paper6>(c, "paper6");
    bench_robot::<Planar2>(c, "planar2");
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
