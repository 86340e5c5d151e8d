//! The floating-base robots (`robot-quadruped12`, `robot-humanoid31`: the root link on
//! a free flyer) through their inherent (fixed-size) functions: `rnea`, `crba`, `aba`,
//! `aba_joints`, the centroidal momentum matrix (against Pinocchio's `ccrba`), the frame Jacobian of
//! the URDF's last frame and the dynamics derivatives. Each call takes the next of 1,000
//! random states (unit quaternions), as Pinocchio's benchmark does with
//! `BENCH_FREEFLYER=1`; ratios measured in the same sitting are in docs/benchmarks.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use dyngen::{AbaDerivatives, FrameJacobian, ReferenceFrame, RneaDerivatives};
use dyngen_model::sample::sample_states;
use dyngen_reference::model_from_static;
use robot_humanoid31::{Humanoid31, Humanoid31Frame};
use robot_quadruped12::{Quadruped12, Quadruped12Frame};

macro_rules! bench_floating {
    ($c:expr, $robot:ty, $name:expr, $tool:expr) => {{
        const NQ: usize = <$robot>::NQ;
        const NV: usize = <$robot>::NV;
        let model = model_from_static(&<$robot>::MODEL);
        let states: Vec<([f64; NQ], [f64; NV], [f64; NV])> = sample_states(&model, 1000, 7)
            .iter()
            .map(|s| {
                (
                    s.q.clone().try_into().unwrap(),
                    s.v.clone().try_into().unwrap(),
                    s.a.clone().try_into().unwrap(),
                )
            })
            .collect();
        let params = <$robot>::NOMINAL_PARAMS;
        let mut group = $c.benchmark_group($name);
        let mut k = 0;
        let mut next = || {
            k += 1;
            &states[k % states.len()]
        };
        group.bench_function("rnea/generated", |b| {
            b.iter(|| {
                let (q, v, a) = next();
                black_box(<$robot>::rnea(black_box(q), black_box(v), black_box(a), &params))
            })
        });
        let mut m = [[0.0; NV]; NV];
        group.bench_function("crba/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::crba(black_box(q), &params, &mut m);
                black_box(&m);
            })
        });
        group.bench_function("aba/generated", |b| {
            b.iter(|| {
                let (q, v, tau) = next();
                black_box(<$robot>::aba(black_box(q), black_box(v), black_box(tau), &params))
            })
        });
        // With rotor inertias and friction: the articulated-body recursion on the
        // quadruped, `M + diag(Ia)` solved by the tree's LᵀDL on the humanoid.
        let joint_params = [0.05; 4 * NV];
        group.bench_function("aba_joints/generated", |b| {
            b.iter(|| {
                let (q, v, tau) = next();
                black_box(<$robot>::aba_joints(
                    black_box(q),
                    black_box(v),
                    black_box(tau),
                    &params,
                    &joint_params,
                    dyngen::Coulomb::Sign,
                ))
            })
        });
        let mut ag = [[0.0; NV]; 6];
        group.bench_function("centroidal_map/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::centroidal_map(black_box(q), &params, &mut ag);
                black_box(&ag);
            })
        });
        let mut jac = FrameJacobian::<f64, NV>::default();
        group.bench_function("frame_jacobian/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::frame_jacobian(black_box(q), $tool, ReferenceFrame::LocalWorldAligned, &mut jac);
                black_box(&jac);
            })
        });
        // One frame's placement (on a large tree taken from all of them; Pinocchio's
        // peer is `fk_q`, forward kinematics of every joint).
        group.bench_function("frame_placement/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                black_box(<$robot>::frame_placement(black_box(q), $tool));
            })
        });
        // The drift `J̇ v` of `ẍ = J q̈ + J̇ q̇` (Pinocchio's `frame_classical_acc`: forward
        // kinematics with `a = 0`, then `getFrameClassicalAcceleration`).
        let zero = [0.0; NV];
        group.bench_function("frame_classical_acceleration/generated", |b| {
            b.iter(|| {
                let (q, v, _) = next();
                black_box(<$robot>::frame_classical_acceleration(
                    black_box(q),
                    black_box(v),
                    &zero,
                    $tool,
                    ReferenceFrame::LocalWorldAligned,
                ));
            })
        });
        let mut rd = RneaDerivatives::<f64, NV>::default();
        group.bench_function("rnea_derivatives/generated", |b| {
            b.iter(|| {
                let (q, v, a) = next();
                <$robot>::rnea_derivatives(black_box(q), black_box(v), black_box(a), &params, &mut rd);
                black_box(&rd);
            })
        });
        let mut ad = AbaDerivatives::<f64, NV>::default();
        group.bench_function("aba_derivatives/generated", |b| {
            b.iter(|| {
                let (q, v, tau) = next();
                <$robot>::aba_derivatives(black_box(q), black_box(v), black_box(tau), &params, &mut ad);
                black_box(&ad);
            })
        });
        let zero_joints = [0.0; 4 * NV];
        group.bench_function("aba_joints_derivatives/generated", |b| {
            b.iter(|| {
                let (q, v, tau) = next();
                <$robot>::aba_joints_derivatives(
                    black_box(q),
                    black_box(v),
                    black_box(tau),
                    &params,
                    &zero_joints,
                    dyngen::Coulomb::Sign,
                    &mut ad,
                );
                black_box(&ad);
            })
        });
        group.finish();
    }};
}

fn floating(c: &mut Criterion) {
    bench_floating!(
        c,
        Quadruped12,
        "quadruped12",
        Quadruped12Frame::ALL[Quadruped12Frame::ALL.len() - 1]
    );
    bench_floating!(
        c,
        Humanoid31,
        "humanoid31",
        Humanoid31Frame::ALL[Humanoid31Frame::ALL.len() - 1]
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = floating
}
criterion_main!(benches);
