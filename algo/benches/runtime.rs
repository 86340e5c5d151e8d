//! The algorithms on `f64` for robots loaded at run time (URDF → `Multibody`), per
//! call, each call on the next of 1,000 random states (as Pinocchio's benchmark
//! does). Ratios against Pinocchio are measured in the same sitting; see
//! docs/benchmarks.md.
//!
//! `cargo bench -p dyngen-algo --bench runtime`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use dyngen_algo::{
    aba, compute_frame_jacobian, crba, forward_kinematics, joint_torque_regressor, rnea, Multibody, ReferenceFrame,
    Se3, Workspace,
};
use dyngen_model::{load_urdf_options, LoadOptions};
use rand::{Rng, SeedableRng};
use std::path::Path;

struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

fn states(body: &Multibody) -> Vec<State> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    (0..1000)
        .map(|_| {
            let mut q: Vec<f64> = body.neutral().iter().map(|x| x + rng.gen_range(-1.0..1.0)).collect();
            body.normalize(&mut q);
            let mut r = || (0..body.nv()).map(|_| rng.gen_range(-1.0..1.0)).collect();
            State { q, v: r(), a: r() }
        })
        .collect()
}

fn bench_robot(c: &mut Criterion, name: &str, urdf: &str, free_flyer: bool) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let options = LoadOptions {
        free_flyer,
        ..LoadOptions::default()
    };
    let body = load_urdf_options(&root.join(urdf), options)
        .unwrap()
        .multibody()
        .unwrap();
    let (nv, nb) = (body.nv(), body.bodies());
    let states = states(&body);
    let params = body.params.clone();
    let mut ws = Workspace::new(&body, ());
    let mut group = c.benchmark_group(name);
    let mut k = 0;
    let mut next = || {
        k += 1;
        &states[k % states.len()]
    };
    let mut out = vec![0.0; nv];
    group.bench_function("rnea", |b| {
        b.iter(|| {
            let s = next();
            rnea(
                &body,
                &mut ws,
                black_box(&s.q),
                black_box(&s.v),
                black_box(&s.a),
                &params,
                &mut out,
            );
            black_box(&out);
        })
    });
    let mut m = vec![0.0; nv * nv];
    group.bench_function("crba", |b| {
        b.iter(|| {
            let s = next();
            crba(&body, &mut ws, black_box(&s.q), &params, &mut m);
            black_box(&m);
        })
    });
    group.bench_function("aba", |b| {
        b.iter(|| {
            let s = next();
            aba(
                &body,
                &mut ws,
                black_box(&s.q),
                black_box(&s.v),
                black_box(&s.a),
                &params,
                &[],
                &mut out,
            );
            black_box(&out);
        })
    });
    let mut y = vec![0.0; nv * 10 * nb];
    group.bench_function("regressor", |b| {
        b.iter(|| {
            let s = next();
            joint_torque_regressor(
                &body,
                &mut ws,
                black_box(&s.q),
                black_box(&s.v),
                black_box(&s.a),
                &mut y,
            );
            black_box(&y);
        })
    });
    group.bench_function("fk_q", |b| {
        b.iter(|| {
            let s = next();
            forward_kinematics(&body, &mut ws, black_box(&s.q));
            black_box(&ws.world);
        })
    });
    // Pinocchio's `frame_jacobian` times computeFrameJacobian: the kinematics of the
    // frame's path, then the last frame's Jacobian (here the last body's frame).
    let mut jac = vec![0.0; 6 * nv];
    let frame = Se3::identity(0.0, 1.0);
    group.bench_function("frame_jacobian", |b| {
        b.iter(|| {
            let s = next();
            compute_frame_jacobian(
                &body,
                &mut ws,
                black_box(&s.q),
                nb,
                &frame,
                ReferenceFrame::LocalWorldAligned,
                &mut jac,
            );
            black_box(&jac);
        })
    });
    group.finish();
}

fn robots(c: &mut Criterion) {
    bench_robot(c, "runtime/ur5", "robots/ur5/ur5.urdf", false);
    bench_robot(c, "runtime/panda", "robots/panda/panda.urdf", false);
    bench_robot(
        c,
        "runtime/humanoid31_free_flyer",
        "robots/humanoid31/humanoid31.urdf",
        true,
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = robots
}
criterion_main!(benches);
