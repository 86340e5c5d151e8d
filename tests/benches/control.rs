//! The control kernels of the UR5 and the Panda, called through their inherent
//! (fixed-size) functions as a controller would: the tool frame's Jacobian, its `J̇v`
//! drift, the centre of mass's Jacobian, the derivatives of inverse and forward
//! dynamics. Each call takes the next of 1,000 random states, as Pinocchio's own
//! benchmark does; ratios against Pinocchio measured in the same sitting are in
//! docs/benchmarks.md.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use dyngen::{AbaDerivatives, FrameJacobian, ReferenceFrame, RneaDerivatives};
use dyngen_reference::{sample_states, Reference};
use robot_panda::{Panda, PandaFrame};
use robot_ur5::{Ur5, Ur5Frame};

/// Times the kernels of one robot type; `$tool` is the frame Pinocchio's benchmark
/// takes (the URDF's last frame).
macro_rules! bench_control {
    ($c:expr, $robot:ty, $name:expr, $tool:expr) => {{
        const N: usize = <$robot>::NV;
        let model = Reference::of::<$robot>();
        let states: Vec<([f64; N], [f64; N], [f64; N])> = sample_states(model.model(), 1000, 7)
            .iter()
            .map(|s| {
                let arr = |x: &[f64]| -> [f64; N] { x.try_into().expect("NV values") };
                (arr(&s.q), arr(&s.v), arr(&s.a))
            })
            .collect();
        let params = <$robot>::NOMINAL_PARAMS;
        let zero = [0.0; N];
        let mut group = $c.benchmark_group($name);
        let mut k = 0;
        let mut next = || {
            k += 1;
            &states[k % states.len()]
        };
        let mut jac = FrameJacobian::<f64, N>::default();
        group.bench_function("frame_jacobian/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::frame_jacobian(black_box(q), $tool, ReferenceFrame::LocalWorldAligned, &mut jac);
                black_box(&jac);
            })
        });
        group.bench_function("frame_classical_acceleration/generated", |b| {
            b.iter(|| {
                let (q, v, _) = next();
                black_box(<$robot>::frame_classical_acceleration(
                    black_box(q),
                    black_box(v),
                    &zero,
                    $tool,
                    ReferenceFrame::LocalWorldAligned,
                ))
            })
        });
        let mut jc = [[0.0; N]; 3];
        group.bench_function("com_jacobian/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::com_jacobian(black_box(q), &params, &mut jc);
                black_box(&jc);
            })
        });
        let mut ag = [[0.0; N]; 6];
        group.bench_function("centroidal_map/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::centroidal_map(black_box(q), &params, &mut ag);
                black_box(&ag);
            })
        });
        let mut rd = RneaDerivatives::<f64, N>::default();
        group.bench_function("rnea_derivatives/generated", |b| {
            b.iter(|| {
                let (q, v, a) = next();
                <$robot>::rnea_derivatives(black_box(q), black_box(v), black_box(a), &params, &mut rd);
                black_box(&rd);
            })
        });
        let mut ad = AbaDerivatives::<f64, N>::default();
        group.bench_function("aba_derivatives/generated", |b| {
            b.iter(|| {
                // As Pinocchio's benchmark: the sampled accelerations serve as torques.
                let (q, v, a) = next();
                <$robot>::aba_derivatives(black_box(q), black_box(v), black_box(a), &params, &mut ad);
                black_box(&ad);
            })
        });
        let zero_joints = [0.0; 4 * N];
        group.bench_function("aba_joints_derivatives/generated", |b| {
            b.iter(|| {
                let (q, v, a) = next();
                <$robot>::aba_joints_derivatives(
                    black_box(q),
                    black_box(v),
                    black_box(a),
                    &params,
                    &zero_joints,
                    dyngen::Coulomb::Sign,
                    &mut ad,
                );
                black_box(&ad);
            })
        });
        let mut minv = [[0.0; N]; N];
        group.bench_function("inverse_inertia/generated", |b| {
            b.iter(|| {
                let (q, _, _) = next();
                <$robot>::inverse_inertia(black_box(q), &params, &mut minv);
                black_box(&minv);
            })
        });
        group.bench_function("rnea/generated", |b| {
            b.iter(|| {
                let (q, v, a) = next();
                black_box(<$robot>::rnea(black_box(q), black_box(v), black_box(a), &params))
            })
        });
        group.finish();
    }};
}

fn control(c: &mut Criterion) {
    bench_control!(c, Ur5, "ur5", Ur5Frame::EeLink);
    bench_control!(c, Panda, "panda", PandaFrame::PandaLink8);
}

criterion_group!(benches, control);
criterion_main!(benches);
