//! Identification throughput, end to end, for 100,000 samples of the Panda (7 DOF):
//! per sample the regressor is evaluated, rows are pushed into the streaming
//! [`Accumulator`] in blocks of 1,000 samples (7,000 rows, one reused buffer), then
//! `finish()` solves (OLS with rank handling). States and measured torques are
//! prepared outside the timed region.
//!
//! Two regressors:
//! - `full`: the joint torque regressor, 7 × 70; the estimator finds the rank (43)
//!   and the identifiable combinations itself;
//! - `base`: the generated base regressor, 7 × 43, full column rank (the fast path);
//!
//! each accumulated by Householder QR (the default, backward stable) and, as
//! `*_ne`, by the normal equations ([`Accumulation::NormalEquations`]: faster,
//! squares the condition number, which is 15–20 here).
//!
//! `*/regressor_only` and `*/finish_only` split the end-to-end time. The peer is
//! `scripts/bench_identification_pinocchio.py` (Pinocchio's regressor plus numpy
//! least squares), to be run in the same sitting; see docs/benchmarks.md.

use dyngen_reference::Reference;
use std::time::{Duration, Instant};

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use dyngen_identify::faer::MatRef;
use dyngen_identify::simulate::Gaussian;
use dyngen_identify::{Accumulation, Accumulator, Channels, Estimate};
use dyngen_reference::sample_states;
use robot_panda::Panda;

const N: usize = 100_000;
const BLOCK: usize = 1_000;
const NV: usize = Panda::NV;
const NOISE_SIGMA: f64 = 0.01;
const SEED: u64 = 2024;

/// Pre-generated input: states within the joint limits and the torques they need
/// under the nominal parameters, plus seeded Gaussian noise.
struct Data {
    q: Vec<[f64; NV]>,
    v: Vec<[f64; NV]>,
    a: Vec<[f64; NV]>,
    /// Measured torques, sample-major (`7 N` entries).
    tau: Vec<f64>,
    /// The same without noise.
    tau_true: Vec<f64>,
}

fn to_array(x: &[f64]) -> [f64; NV] {
    x.try_into().expect("7 joints")
}

fn data() -> Data {
    let reference = Reference::of::<Panda>();
    let states = sample_states(reference.model(), N, SEED);
    let mut noise = Gaussian::new(SEED + 1);
    let mut d = Data {
        q: Vec::with_capacity(N),
        v: Vec::with_capacity(N),
        a: Vec::with_capacity(N),
        tau: Vec::with_capacity(NV * N),
        tau_true: Vec::with_capacity(NV * N),
    };
    for s in &states {
        let (q, v, a) = (to_array(&s.q), to_array(&s.v), to_array(&s.a));
        let tau = Panda::rnea(&q, &v, &a, &Panda::NOMINAL_PARAMS);
        d.tau_true.extend_from_slice(&tau);
        d.tau.extend(tau.iter().map(|t| t + noise.normal(NOISE_SIGMA)));
        d.q.push(q);
        d.v.push(v);
        d.a.push(a);
    }
    d
}

/// A generated regressor: `(q, v, a, out)`, `out` is `7 × P`.
type Regressor<const P: usize> = fn(&[f64; NV], &[f64; NV], &[f64; NV], &mut [[f64; P]; NV]);

/// Fills `block` (row-major, `7 · BLOCK` rows of `P`) with the regressors of the
/// samples `start..start + BLOCK`.
fn fill_block<const P: usize>(d: &Data, start: usize, block: &mut [[[f64; P]; NV]], regressor: Regressor<P>) {
    for (k, y) in block.iter_mut().enumerate() {
        let i = start + k;
        regressor(&d.q[i], &d.v[i], &d.a[i], y);
    }
}

/// Regressor evaluation and accumulation over all samples; the accumulator is
/// returned unsolved.
fn accumulate<const P: usize>(
    d: &Data,
    block: &mut [[[f64; P]; NV]],
    regressor: Regressor<P>,
    accumulation: Accumulation,
) -> Accumulator {
    let mut acc = Accumulator::with_accumulation(P, Channels::Interleaved(NV), accumulation).expect("7 channels");
    for start in (0..N).step_by(BLOCK) {
        fill_block(d, start, block, regressor);
        let rows = block.as_flattened().as_flattened();
        let a = MatRef::from_row_major_slice(rows, NV * BLOCK, P);
        acc.push_rows(a, &d.tau[NV * start..NV * (start + BLOCK)])
            .expect("finite rows");
    }
    acc
}

fn end_to_end<const P: usize>(
    d: &Data,
    block: &mut [[[f64; P]; NV]],
    regressor: Regressor<P>,
    accumulation: Accumulation,
) -> Estimate {
    accumulate(d, block, regressor, accumulation)
        .finish()
        .expect("solvable")
}

fn full_regressor(q: &[f64; NV], v: &[f64; NV], a: &[f64; NV], y: &mut [[f64; 70]; NV]) {
    Panda::joint_torque_regressor(q, v, a, y);
}

fn base_regressor(q: &[f64; NV], v: &[f64; NV], a: &[f64; NV], y: &mut [[f64; 43]; NV]) {
    Panda::base_regressor(q, v, a, y);
}

/// One-off check that the benchmark measures the right work: the estimate must fit
/// the torques to the noise level and recover the nominal base parameters.
fn verify(d: &Data, name: &str, est: &Estimate, base_of_solution: [f64; 43], seconds: f64) {
    let truth = Panda::base_params(&Panda::NOMINAL_PARAMS);
    let base_err = base_of_solution
        .iter()
        .zip(&truth)
        .map(|(x, t)| (x - t).abs())
        .fold(0.0, f64::max);
    // Prediction of the noise-free torques on the first 1,000 samples.
    let base_params = base_of_solution;
    let mut y = [[0.0; 43]; NV];
    let mut sq = 0.0;
    for i in 0..1000 {
        Panda::base_regressor(&d.q[i], &d.v[i], &d.a[i], &mut y);
        for j in 0..NV {
            let pred: f64 = y[j].iter().zip(&base_params).map(|(r, p)| r * p).sum();
            sq += (pred - d.tau_true[NV * i + j]).powi(2);
        }
    }
    let pred_rms = (sq / (NV * 1000) as f64).sqrt();
    eprintln!(
        "verify {name}: {} rows, rank {} of {}, cond {:.3e}, residual RMS {:.5} N·m (noise σ {NOISE_SIGMA}), \
         per joint [{}], max |base param error| {:.2e}, noise-free torque RMS error {:.2e} N·m, one-off {:.3} s",
        est.residuals.rows,
        est.rank,
        est.n_params(),
        est.condition_number,
        est.residuals.rms,
        est.residuals
            .per_channel_rms
            .iter()
            .map(|r| format!("{r:.5}"))
            .collect::<Vec<_>>()
            .join(", "),
        base_err,
        pred_rms,
        seconds,
    );
    assert!(
        (est.residuals.rms / NOISE_SIGMA - 1.0).abs() < 0.05,
        "{name}: residual RMS {} is not the noise level {NOISE_SIGMA}",
        est.residuals.rms
    );
    assert!(
        pred_rms < 0.1 * NOISE_SIGMA,
        "{name}: torque prediction error {pred_rms}"
    );
}

fn identification(c: &mut Criterion) {
    let d = data();
    let mut full_block = vec![[[0.0; 70]; NV]; BLOCK];
    let mut base_block = vec![[[0.0; 43]; NV]; BLOCK];

    for (suffix, accumulation) in [("", Accumulation::Qr), ("_ne", Accumulation::NormalEquations)] {
        let t = Instant::now();
        let est = end_to_end(&d, &mut full_block, full_regressor, accumulation);
        let s = t.elapsed().as_secs_f64();
        assert_eq!(est.rank, Panda::NBASE, "full regressor: rank");
        let x: [f64; 70] = est.solution.as_slice().try_into().expect("70 parameters");
        verify(&d, &format!("full{suffix} (7x70)"), &est, Panda::base_params(&x), s);

        let t = Instant::now();
        let est = end_to_end(&d, &mut base_block, base_regressor, accumulation);
        let s = t.elapsed().as_secs_f64();
        assert_eq!(est.rank, Panda::NBASE, "base regressor: rank");
        let x: [f64; 43] = est.solution.as_slice().try_into().expect("43 parameters");
        verify(&d, &format!("base{suffix} (7x43)"), &est, x, s);
    }

    let mut group = c.benchmark_group("identification_panda_100k");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(2));
    group.measurement_time(Duration::from_secs(15));

    group.bench_function("full/regressor_only", |b| {
        b.iter(|| {
            for start in (0..N).step_by(BLOCK) {
                fill_block(black_box(&d), start, &mut full_block, full_regressor);
                black_box(&full_block);
            }
        })
    });
    group.bench_function("base/regressor_only", |b| {
        b.iter(|| {
            for start in (0..N).step_by(BLOCK) {
                fill_block(black_box(&d), start, &mut base_block, base_regressor);
                black_box(&base_block);
            }
        })
    });
    for (suffix, accumulation) in [("", Accumulation::Qr), ("_ne", Accumulation::NormalEquations)] {
        group.bench_function(format!("full{suffix}/end_to_end"), |b| {
            b.iter(|| black_box(end_to_end(black_box(&d), &mut full_block, full_regressor, accumulation)))
        });
        let acc = accumulate(&d, &mut full_block, full_regressor, accumulation);
        group.bench_function(format!("full{suffix}/finish_only"), |b| {
            b.iter(|| black_box(acc.finish().expect("solvable")))
        });
        group.bench_function(format!("base{suffix}/end_to_end"), |b| {
            b.iter(|| black_box(end_to_end(black_box(&d), &mut base_block, base_regressor, accumulation)))
        });
        let acc = accumulate(&d, &mut base_block, base_regressor, accumulation);
        group.bench_function(format!("base{suffix}/finish_only"), |b| {
            b.iter(|| black_box(acc.finish().expect("solvable")))
        });
    }
    group.finish();
}

criterion_group!(benches, identification);
criterion_main!(benches);
