//! NIM inference and training on the paper's 6-DOF arm, with the estimators it is
//! compared with on the same data (MIM over a recording, one RLS update).
//!
//! - `nim/window`: one body's θ from one window of 20 samples (the default net:
//!   encoder 18 → 32 → 32 → 32, decoder 32 → 32 → 32 → 4), allocation-free; per
//!   body-sample it is this time over 20;
//! - `nim/identify_recording`: every body's θ from a 100-sample recording, windows
//!   every 10 samples (as the demo identifies);
//! - `paper_nim/sample`: the paper-faithful net (6 → 5 × 16 → 4) on one sample;
//! - `mim/samples`: MIM least squares per body over the same 100 samples;
//! - `rls/sample`: one RLS update of a body (six rows, four parameters).
//!
//! Inference time does not depend on the weights, so these nets train for a few
//! steps only. After the criterion groups the default training of the generalising
//! NIM (1,500 draws, 6,000 Adam steps per body, every core) is timed once and
//! printed: `cargo bench -p dyngen-tests --bench nim`.

use criterion::{black_box, criterion_group, Criterion};
use dyngen_identify::mim::{self, MimOptions};
use dyngen_identify::simulate::{record, Criterion as Design, ExcitationDesign, Experiment, Motion, Recording};
use dyngen_identify::Rls;
use dyngen_nim::{paper_nim, BodySample, Nim, NimConfig, PaperNimConfig};
use dyngen_reference::{Dynamics, Generated};
use robot_paper6::Paper6;
use std::time::Instant;

struct Setup {
    recording: Recording,
    training: Recording,
    nominal: Vec<f64>,
}

fn setup() -> Setup {
    let robot = Generated::<Paper6>::new();
    let design = ExcitationDesign {
        criterion: Design::BodyModel,
        base_frequency: 0.5,
        duration: 2.0,
        samples: 100,
        ..ExcitationDesign::new(robot.model())
    };
    let experiment = Experiment {
        duration: 2.0,
        steps: 100,
        motion: Motion::Fourier(design.optimise(&robot).excitation),
    };
    let two = Experiment {
        duration: 4.0,
        steps: 200,
        motion: experiment.motion.clone(),
    };
    Setup {
        recording: record(&robot, &Paper6::NOMINAL_PARAMS, &experiment),
        training: record(&robot, &Paper6::NOMINAL_PARAMS, &two),
        nominal: dyngen_model::principal_params(robot.model()),
    }
}

fn inference(c: &mut Criterion) {
    let s = setup();
    let mut quick = NimConfig {
        draws: 50,
        ..NimConfig::default()
    };
    quick.train.max_steps = 20;
    let (nim, _) = Nim::train("paper6", &s.training, &s.nominal, &quick, &|_| {}).unwrap();
    let body = 2;
    let window: Vec<BodySample> = (40..40 + nim.window)
        .map(|k| BodySample::from_recording(&s.recording, k, body))
        .collect();
    let mut predictor = nim.predictor();
    let mut out = [None; 4];
    c.bench_function("nim/window", |b| {
        b.iter(|| {
            nim.predict(body, black_box(&window), &mut predictor, &mut out);
            black_box(out)
        })
    });
    c.bench_function("nim/identify_recording", |b| {
        b.iter(|| black_box(nim.identify(black_box(&s.recording), nim.window / 2).unwrap()))
    });

    let paper = paper_nim(&s.recording, 1..101, &s.nominal, &PaperNimConfig::default()).unwrap();
    let net = &paper.nets[body];
    let inputs = dyngen_nim::paper_inputs(&s.recording, 50, body);
    let mut workspace = net.workspace();
    let mut y = [0.0; 4];
    c.bench_function("paper_nim/sample", |b| {
        b.iter(|| {
            net.predict(black_box(&inputs), &mut workspace, &mut y);
            black_box(y)
        })
    });

    let options = MimOptions::default();
    c.bench_function("mim/samples", |b| {
        b.iter(|| black_box(mim::samples(black_box(&s.recording), 1..101, None, &options).unwrap()))
    });

    let mut rls = Rls::with_initial(&s.nominal[8..12], 0.99, 1e3).unwrap();
    let block = s.recording.body_regressor(50, body);
    let wrench = s.recording.body_wrench(50, body);
    c.bench_function("rls/sample", |b| {
        b.iter(|| {
            for r in 0..6 {
                rls.update(&block.row(r), wrench[r]).unwrap();
            }
            black_box(rls.estimate()[0])
        })
    });
}

criterion_group!(benches, inference);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    // The training is timed once, unless the run lists, tests, or filters it out.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let filters: Vec<&String> = args.iter().filter(|a| !a.starts_with('-')).collect();
    let wanted = filters.is_empty() || filters.iter().any(|f| "nim/train_default".contains(f.as_str()));
    if !wanted || args.iter().any(|a| a == "--test" || a == "--list") {
        return;
    }
    let s = setup();
    let config = NimConfig::default();
    let start = Instant::now();
    let (nim, _) = Nim::train("paper6", &s.training, &s.nominal, &config, &|_| {}).unwrap();
    println!(
        "nim/train_default: {:.1} s for {} bodies ({} draws, {} Adam steps of 64 windows each, {} threads)",
        start.elapsed().as_secs_f64(),
        nim.n_bodies(),
        config.draws,
        config.train.max_steps,
        std::thread::available_parallelism().map_or(1, |t| t.get())
    );
}
