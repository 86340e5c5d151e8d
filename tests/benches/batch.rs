//! Throughput of the generated functions, states per second on one core and on all:
//! one call per state, a batch on 4 and 8 `f64` lanes (rows and columns), and a batch
//! of 8 lanes split across threads. Before the timings it prints each function's
//! operation count and the physical limit of one core, `peak flops per cycle × clock ÷
//! flops per state`, from `BATCH_PEAK_FLOPS_PER_CYCLE` (default 32: two 8-lane FMA
//! units, AVX-512) and `BATCH_CLOCK_GHZ` (default: the processor's from
//! `/proc/cpuinfo`). See docs/benchmarks.md.
//!
//!     RUSTFLAGS="-C target-cpu=native" cargo bench -p dyngen-tests --bench batch

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use dyngen::batch::{Batch, Layout, Threads};
use dyngen::lanes::{F64x4, F64x8, Lanes};
use dyngen::Robot;
use dyngen_reference::{sample_states, Reference};
use robot_panda::Panda;
use robot_ur5::Ur5;
use std::time::Duration;

const STATES: usize = 1024;
const THREADED_STATES: usize = 16 * 1024;

/// Rows of `n` states: q, v, a, and the torques rnea gives (for aba).
struct Data {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
}

fn data<R: Robot>(n: usize) -> Data {
    let s = sample_states(Reference::of::<R>().model(), n, 11);
    let q: Vec<f64> = s.iter().flat_map(|s| s.q.clone()).collect();
    let v: Vec<f64> = s.iter().flat_map(|s| s.v.clone()).collect();
    let a: Vec<f64> = s.iter().flat_map(|s| s.a.clone()).collect();
    let mut tau = vec![0.0; n * R::NV];
    for k in 0..n {
        R::rnea(
            &q[k * R::NQ..][..R::NQ],
            &v[k * R::NV..][..R::NV],
            &a[k * R::NV..][..R::NV],
            R::nominal_params(),
            &mut tau[k * R::NV..][..R::NV],
        );
    }
    Data { q, v, a, tau }
}

fn columns(x: &[f64], n: usize, w: usize) -> Vec<f64> {
    (0..w).flat_map(|i| (0..n).map(move |k| x[k * w + i])).collect()
}

/// The functions timed, by name: output width per state, a per-state call, a batch call.
#[derive(Clone, Copy)]
enum Function {
    Rnea,
    Regressor,
    Crba,
    Aba,
}

impl Function {
    fn name(self) -> &'static str {
        match self {
            Function::Rnea => "rnea",
            Function::Regressor => "joint_torque_regressor",
            Function::Crba => "crba",
            Function::Aba => "aba",
        }
    }

    fn width<R: Robot>(self) -> usize {
        match self {
            Function::Rnea | Function::Aba => R::NV,
            Function::Regressor => R::NV * R::NPARAMS,
            Function::Crba => R::NV * R::NV,
        }
    }

    fn one<R: Robot>(self, d: &Data, k: usize, out: &mut [f64]) {
        let (q, v, a, t) = (
            &d.q[k * R::NQ..][..R::NQ],
            &d.v[k * R::NV..][..R::NV],
            &d.a[k * R::NV..][..R::NV],
            &d.tau[k * R::NV..][..R::NV],
        );
        let p = R::nominal_params();
        match self {
            Function::Rnea => R::rnea(q, v, a, p, out),
            Function::Regressor => R::joint_torque_regressor(q, v, a, out),
            Function::Crba => R::crba(q, p, out),
            Function::Aba => R::aba(q, v, t, p, out),
        }
    }

    fn batch<R: Robot, L: Lanes<Elem = f64>>(self, b: &Batch<L>, d: &Data, out: &mut [f64]) {
        let p = R::nominal_params();
        match self {
            Function::Rnea => b.rnea::<R>(&d.q, &d.v, &d.a, p, out),
            Function::Regressor => b.joint_torque_regressor::<R>(&d.q, &d.v, &d.a, out),
            Function::Crba => b.crba::<R>(&d.q, p, out),
            Function::Aba => b.aba::<R>(&d.q, &d.v, &d.tau, p, out),
        }
        .unwrap()
    }

    fn flops<R: Robot>(self) -> usize {
        let (_, c) = R::op_counts().iter().find(|(n, _)| *n == self.name()).unwrap();
        c.muls + c.divs + c.adds + c.negs
    }
}

fn clock_ghz() -> f64 {
    if let Some(ghz) = std::env::var("BATCH_CLOCK_GHZ").ok().and_then(|s| s.parse().ok()) {
        return ghz;
    }
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("cpu MHz"))
                .and_then(|l| l.split(':').nth(1))
                .and_then(|x| x.trim().parse::<f64>().ok())
        })
        .map_or(1.0, |mhz| mhz / 1000.0)
}

fn bench_robot<R: Robot>(c: &mut Criterion) {
    let d = data::<R>(STATES);
    let cols = Data {
        q: columns(&d.q, STATES, R::NQ),
        v: columns(&d.v, STATES, R::NV),
        a: columns(&d.a, STATES, R::NV),
        tau: columns(&d.tau, STATES, R::NV),
    };
    let big = data::<R>(THREADED_STATES);
    let peak: f64 = std::env::var("BATCH_PEAK_FLOPS_PER_CYCLE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(32.0);
    let ghz = clock_ghz();
    for f in [Function::Rnea, Function::Regressor, Function::Crba, Function::Aba] {
        let flops = f.flops::<R>();
        println!(
            "{} {}: {flops} flops per state; physical limit of one core {:.1} M states/s ({peak} flops/cycle at {ghz:.2} GHz)",
            R::NAME,
            f.name(),
            peak * ghz * 1e3 / flops as f64,
        );
        let w = f.width::<R>();
        let mut out = vec![0.0; THREADED_STATES * w];
        let mut group = c.benchmark_group(format!("batch/{}/{}", R::NAME, f.name()));
        group.throughput(Throughput::Elements(STATES as u64));
        group.bench_function("per_state", |b| {
            b.iter(|| {
                for k in 0..STATES {
                    f.one::<R>(black_box(&d), k, &mut out[k * w..][..w]);
                }
                black_box(&out);
            })
        });
        let one = Threads::Count(1);
        let x4 = Batch::<F64x4>::new(STATES, Layout::Rows).threads(one);
        group.bench_function("f64x4_rows", |b| {
            b.iter(|| f.batch::<R, F64x4>(&x4, black_box(&d), &mut out[..STATES * w]))
        });
        let x8 = Batch::<F64x8>::new(STATES, Layout::Rows).threads(one);
        group.bench_function("f64x8_rows", |b| {
            b.iter(|| f.batch::<R, F64x8>(&x8, black_box(&d), &mut out[..STATES * w]))
        });
        let x8c = Batch::<F64x8>::new(STATES, Layout::Columns).threads(one);
        group.bench_function("f64x8_columns", |b| {
            b.iter(|| f.batch::<R, F64x8>(&x8c, black_box(&cols), &mut out[..STATES * w]))
        });
        group.throughput(Throughput::Elements(THREADED_STATES as u64));
        let threads = Batch::<F64x8>::new(THREADED_STATES, Layout::Rows).threads(Threads::Auto);
        group.bench_function(BenchmarkId::new("f64x8_rows_threads", THREADED_STATES), |b| {
            b.iter(|| f.batch::<R, F64x8>(&threads, black_box(&big), &mut out))
        });
        group.finish();
    }
}

fn benches(c: &mut Criterion) {
    bench_robot::<Ur5>(c);
    bench_robot::<Panda>(c);
}

criterion_group! {
    name = batch;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    targets = benches
}
criterion_main!(batch);
