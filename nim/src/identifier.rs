//! The generalising NIM ([`Nim`]): window networks trained on parameter draws along
//! one joint motion.

use super::error::NimError;
use super::train::{Decay, Optimizer, TrainHistory, TrainOptions};
use super::window::{train_windows, WindowFile, WindowNet, WindowShape, WindowSource, WindowWorkspace};
use dyngen_identify::mim::{self, MimOptions, ThetaTable, Verdict};
use dyngen_identify::simulate::{Gaussian, Recording};
use dyngen_reference::SplitMix64;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// Features per sample (see [`Nim`]).
pub const FEATURES: usize = 18;

/// The `schema` of [`Nim::to_json`].
pub const NIM_SCHEMA: &str = "dyngen-nim/1";

/// One body's measurements at one instant, in its centroidal principal frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodySample {
    /// Resultant of the joint reactions, N.
    pub force: Vector3<f64>,
    /// `a_c − g`, m/s²: what an accelerometer at the centre of mass reads.
    pub specific_force: Vector3<f64>,
    /// Resultant moment about the centre of mass, N·m.
    pub moment: Vector3<f64>,
    /// `ω`, rad/s.
    pub angular_velocity: Vector3<f64>,
    /// `ω̇`, rad/s².
    pub angular_acceleration: Vector3<f64>,
}

impl BodySample {
    /// Body `body` (0-based) at sample `k` of a recording, noisy or not.
    pub fn from_recording(recording: &Recording, k: usize, body: usize) -> BodySample {
        let m = &recording.samples[k].bodies[body];
        BodySample {
            force: m.resultant.force,
            specific_force: recording.body_regressor(k, body).force.column(0).into_owned(),
            moment: m.resultant.torque,
            angular_velocity: m.angular_velocity,
            angular_acceleration: m.angular_acceleration,
        }
    }

    /// The same kinematics with the wrench of parameters `theta = (m, J1, J2, J3)`:
    /// `F = m s`, `M = diag(J) ω̇ + ω × diag(J) ω`.
    pub fn with_theta(&self, theta: &[f64; 4]) -> BodySample {
        let j = Vector3::new(theta[1], theta[2], theta[3]);
        let (w, wd) = (self.angular_velocity, self.angular_acceleration);
        BodySample {
            force: self.specific_force * theta[0],
            moment: j.component_mul(&wd) + w.cross(&j.component_mul(&w)),
            ..*self
        }
    }
}

/// The features of a window into `out` (`samples.len() × FEATURES`, row-major) and
/// the scales `(ρ_F, ρ_M)`: the RMS of `|F|` and of `|M|` over the window. A scale
/// that is 0 leaves the wrench features at 0.
pub fn window_features(samples: &[BodySample], out: &mut [f64]) -> (f64, f64) {
    assert_eq!(
        out.len(),
        samples.len() * FEATURES,
        "`out` holds {FEATURES} features per sample"
    );
    let count = samples.len().max(1) as f64;
    let rms =
        |f: fn(&BodySample) -> Vector3<f64>| (samples.iter().map(|s| f(s).norm_squared()).sum::<f64>() / count).sqrt();
    let rho_f = rms(|s| s.force);
    let rho_m = rms(|s| s.moment);
    let inv = |r: f64| if r > 0.0 { 1.0 / r } else { 0.0 };
    let (inv_f, inv_m) = (inv(rho_f), inv(rho_m));
    for (s, row) in samples.iter().zip(out.chunks_exact_mut(FEATURES)) {
        let w = s.angular_velocity;
        let parts = [
            s.force * inv_f,
            s.specific_force,
            s.moment * inv_m,
            w,
            s.angular_acceleration,
            Vector3::new(w.y * w.z, w.z * w.x, w.x * w.y),
        ];
        for (chunk, v) in row.chunks_exact_mut(3).zip(parts) {
            chunk.copy_from_slice(v.as_slice());
        }
    }
    (rho_f, rho_m)
}

/// A physically consistent draw of every body's `θ_i = (m, J1, J2, J3)` around
/// `nominal` (`4n`): the mass and each principal second moment of mass
/// `s_k = (J_{k+1} + J_{k+2} − J_k) / 2` are multiplied by independent factors
/// uniform in `[1 − spread, 1 + spread]` (`0 ≤ spread < 1`); `J1 = s2 + s3`, `J2 =
/// s1 + s3`, `J3 = s1 + s2`.
pub fn draw_theta(nominal: &[f64], spread: f64, rng: &mut SplitMix64) -> Vec<f64> {
    let mut theta = nominal.to_vec();
    for body in theta.chunks_exact_mut(4) {
        let [m, j1, j2, j3] = [body[0], body[1], body[2], body[3]];
        let s = [(j2 + j3 - j1) / 2.0, (j1 + j3 - j2) / 2.0, (j1 + j2 - j3) / 2.0];
        body[0] = m * (1.0 + rng.uniform(-spread, spread));
        let s = s.map(|x| x * (1.0 + rng.uniform(-spread, spread)));
        body[1] = s[1] + s[2];
        body[2] = s[0] + s[2];
        body[3] = s[0] + s[1];
    }
    theta
}

/// Settings of [`Nim::train`].
#[derive(Clone, Debug, PartialEq)]
pub struct NimConfig {
    /// Samples per window.
    pub window: usize,
    /// Parameter draws to train on.
    pub draws: usize,
    /// Further draws, never trained on, for the validation curve.
    pub validation_draws: usize,
    /// Relative half-width of the draws ([`draw_theta`]).
    pub spread: f64,
    /// Sensor noise added to the training windows: on each of `F`, `s`, `M`, `ω` and
    /// `ω̇`, Gaussian on every axis with σ this fraction of the 3-vector's RMS along
    /// the motion (nominal θ), pooled over its axes as one 3-axis sensor would be (the
    /// reading of [`NoiseModel::relative`](dyngen_identify::simulate::NoiseModel::relative)),
    /// so an axis that never moves still sees noise. 0 trains on exact data; a net
    /// for noisy measurements should see noise in training.
    pub noise: f64,
    pub shape: WindowShape,
    /// Adam on mini-batches of windows ([`train_windows`]).
    pub train: TrainOptions,
    /// Seeds the draws (training and validation streams) and the nets.
    pub seed: u64,
    /// Bodies trained at once (each on its own thread); 0 = as many as the machine
    /// has cores.
    pub threads: usize,
}

impl Default for NimConfig {
    /// Windows of 20 samples; 1,500 draws (+ 200 for validation) within ±30 %, 1 %
    /// training noise;
    /// encoder 18 → 32 → 32 → 32, decoder 32 → 32 → 32 → outputs; 6,000 Adam steps
    /// of 64 windows, learning rate 5·10⁻³ annealed to 5 %; seed 1.
    fn default() -> NimConfig {
        NimConfig {
            window: 20,
            draws: 1500,
            validation_draws: 200,
            spread: 0.3,
            noise: 0.01,
            shape: WindowShape {
                encoder: vec![32, 32, 32],
                decoder: vec![32, 32],
            },
            train: TrainOptions {
                optimizer: Optimizer::Adam {
                    learning_rate: 5e-3,
                    beta1: 0.9,
                    beta2: 0.999,
                    epsilon: 1e-8,
                    batch_size: 64,
                },
                max_steps: 6000,
                mse_threshold: None,
                seed: 1,
                record_every: 250,
                decay: Decay::Cosine { final_fraction: 0.05 },
            },
            seed: 1,
            threads: 0,
        }
    }
}

impl NimConfig {
    fn check(&self, samples: usize) -> Result<(), NimError> {
        let invalid = |field, reason: String| Err(NimError::InvalidOption { field, reason });
        if self.window == 0 || self.window > samples {
            return invalid(
                "window",
                format!(
                    "{} samples per window along a motion of {samples} samples; expected 1 ≤ window ≤ {samples}",
                    self.window
                ),
            );
        }
        if self.draws == 0 {
            return invalid("draws", "0; expected at least 1".into());
        }
        if !(0.0..1.0).contains(&self.spread) {
            return invalid("spread", format!("{}; expected 0 ≤ spread < 1", self.spread));
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return invalid("noise", format!("{}; expected a fraction ≥ 0 (0.01 = 1 %)", self.noise));
        }
        Ok(())
    }
}

/// One body's identifier: which of `(m, J1, J2, J3)` it predicts, and the net
/// (`None` when the body's equations carry none of them).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyNim {
    /// Indices into `(m, J1, J2, J3)`, ascending.
    pub outputs: Vec<usize>,
    pub net: Option<WindowNet>,
}

/// The generalising NIM: per body, a [`WindowNet`] that reads a short window of the
/// body's own measurements and returns its principal parameters `θ_i = (m, J1, J2,
/// J3)`, trained on many simulated parameter draws along one joint motion and
/// judged on draws it has never seen.
///
/// **Inputs.** Per sample, in the body's centroidal principal frame (what a
/// wrench sensor and an IMU on the body give, [`BodySample`]): the resultant force
/// `F` and moment `M`, the specific force `s = a_c − g` (an accelerometer at the
/// centre of mass), the angular velocity `ω` and acceleration `ω̇`, and the
/// gyroscopic products `ω2ω3, ω3ω1, ω1ω2`: 18 features. `F` and `M` are divided by
/// their RMS over the window (`ρ_F`, `ρ_M`), and the net predicts `ln(m/ρ_F)` and
/// `ln(J_k/ρ_M)`: since `F = m s` and `M = B(ω, ω̇) J`, a body twice as heavy gives
/// the same inputs and twice the output, so the net only has to learn how the motion
/// shapes the wrench, not the scale of the parameters; in logarithms an error is a
/// relative error, and a window that barely moves (small `ρ`, large ratio) does not
/// dominate the loss.
///
/// **Training data.** The joint motion is fixed (a prescribed experiment, or the
/// joint samples of a measurement); the kinematics of every body along it are
/// recorded once. A draw ([`draw_theta`]) changes every body's mass by a factor in
/// `[1 − spread, 1 + spread]` and each of its three principal second moments of mass
/// `s_k = ∫ x_k² dm` likewise, so every draw is physically consistent (`J1 = s2 +
/// s3`, … satisfy the triangle inequalities by construction). Each body's resultant
/// under a draw is `[F; M] = A_i θ_i` (docs/design.md, "The paper's decoupled body model"), exact along a prescribed motion;
/// windows of `window` consecutive samples start anywhere along the motion.
///
/// **Identifiability.** A parameter that does not enter its body's equations along
/// the motion (a turret's `J1`, `J2`) is not an output: it is reported `n/i`, never
/// guessed.
///
#[derive(Clone, Debug, PartialEq)]
pub struct Nim {
    pub robot: String,
    pub body_names: Vec<String>,
    pub window: usize,
    pub spread: f64,
    /// The θ the draws were centred on (`4n`).
    pub nominal: Vec<f64>,
    pub bodies: Vec<BodyNim>,
}

/// What [`Nim::train`] measured besides the nets: the loss curves per body (`None`
/// for a body without outputs).
#[derive(Clone, Debug, PartialEq)]
pub struct NimTraining {
    pub histories: Vec<Option<TrainHistory>>,
    /// Windows available per body and draw (starts along the motion).
    pub windows_per_draw: Vec<usize>,
}

impl Nim {
    /// Trains one window net per body on `config.draws` parameter draws around
    /// `nominal` (`4n`) along the motion of `recording`, which must be noise-free:
    /// only its kinematics are used (each draw's wrenches follow from them and θ).
    /// `robot` names the robot in the saved file. Bodies train in parallel
    /// ([`NimConfig::threads`]); `done(body)` is called as each finishes.
    ///
    /// Errors: an invalid configuration, a `nominal` of the wrong length, a body
    /// that does not move enough for any window to carry its wrench, a diverging
    /// training.
    pub fn train(
        robot: &str,
        recording: &Recording,
        nominal: &[f64],
        config: &NimConfig,
        done: &(dyn Fn(usize) + Sync),
    ) -> Result<(Nim, NimTraining), NimError> {
        let n = recording.nv();
        if nominal.len() != 4 * n {
            return Err(NimError::DimensionMismatch {
                what: "nominal θ (4 per body)",
                expected: 4 * n,
                found: nominal.len(),
            });
        }
        config.check(recording.len())?;
        // What enters each body's equations along this motion.
        let reference =
            mim::samples(recording, 0..recording.len(), Some(nominal), &MimOptions::default()).map_err(|e| {
                NimError::InvalidOption {
                    field: "recording",
                    reason: format!("the motion does not determine the body equations: {e}"),
                }
            })?;
        let outputs: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                (0..4)
                    .filter(|&k| reference.verdict(i, k) == Verdict::Identified)
                    .collect()
            })
            .collect();
        let draws = |count: usize, salt: u64| {
            let mut rng = SplitMix64::new(config.seed ^ salt);
            (0..count)
                .map(|_| draw_theta(nominal, config.spread, &mut rng))
                .collect::<Vec<_>>()
        };
        let train_draws = draws(config.draws, 0x7472_6169_6E00);
        let validation_draws = draws(config.validation_draws, 0x7661_6C69_6400);
        let kinematics: Vec<Vec<BodySample>> = (0..n)
            .map(|i| {
                (0..recording.len())
                    .map(|k| BodySample::from_recording(recording, k, i))
                    .collect()
            })
            .collect();

        let threads = match config.threads {
            0 => std::thread::available_parallelism().map_or(1, |t| t.get()),
            t => t,
        }
        .min(n)
        .max(1);
        let next = std::sync::atomic::AtomicUsize::new(0);
        type Trained = (
            usize,
            Result<(Option<WindowNet>, Option<TrainHistory>, usize), NimError>,
        );
        let results: Vec<Trained> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..threads)
                .map(|_| {
                    scope.spawn(|| {
                        let mut out = Vec::new();
                        loop {
                            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            if i >= n {
                                return out;
                            }
                            let body = BodyTraining {
                                body: i,
                                kinematics: &kinematics[i],
                                outputs: &outputs[i],
                                window: config.window,
                                nominal: &nominal[4 * i..4 * i + 4],
                            };
                            let result = body.train(&train_draws, &validation_draws, config);
                            done(i);
                            out.push((i, result));
                        }
                    })
                })
                .collect();
            workers
                .into_iter()
                .flat_map(|w| w.join().expect("a training thread does not panic"))
                .collect()
        });
        let mut slots: Vec<Option<BodyResult>> = vec![None; n];
        for (i, result) in results {
            slots[i] = Some(result.map_err(|e| e.within(format!("body {} ({})", i + 1, recording.body_names[i])))?);
        }
        let mut bodies = Vec::with_capacity(n);
        let mut training = NimTraining {
            histories: Vec::with_capacity(n),
            windows_per_draw: Vec::with_capacity(n),
        };
        for (i, slot) in slots.into_iter().enumerate() {
            let (net, history, windows) = slot.expect("every body trained");
            bodies.push(BodyNim {
                outputs: outputs[i].clone(),
                net,
            });
            training.histories.push(history);
            training.windows_per_draw.push(windows);
        }
        Ok((
            Nim {
                robot: robot.to_string(),
                body_names: recording.body_names.clone(),
                window: config.window,
                spread: config.spread,
                nominal: nominal.to_vec(),
                bodies,
            },
            training,
        ))
    }

    pub fn n_bodies(&self) -> usize {
        self.bodies.len()
    }

    /// Buffers for [`Nim::predict`].
    pub fn predictor(&self) -> NimPredictor {
        NimPredictor {
            workspaces: self
                .bodies
                .iter()
                .map(|b| b.net.as_ref().map(WindowNet::workspace))
                .collect(),
            features: vec![0.0; self.window * FEATURES],
            out: vec![0.0; 4],
        }
    }

    /// Body `body`'s θ from one window of its samples (any length ≥ 1; the nets
    /// were trained on [`Nim::window`]), without allocating: `out[k]` is `None` for
    /// a parameter the body's equations do not carry, and for every parameter when
    /// the window's force or moment is zero (nothing to scale by).
    ///
    /// # Panics
    ///
    /// When `body` is out of range, `samples` is empty or longer than the
    /// predictor's buffers (made for [`Nim::window`] samples).
    pub fn predict(
        &self,
        body: usize,
        samples: &[BodySample],
        predictor: &mut NimPredictor,
        out: &mut [Option<f64>; 4],
    ) {
        *out = [None; 4];
        let nim = &self.bodies[body];
        let (Some(net), Some(workspace)) = (&nim.net, &mut predictor.workspaces[body]) else {
            return;
        };
        let features = &mut predictor.features[..samples.len() * FEATURES];
        let (rho_f, rho_m) = window_features(samples, features);
        if !(rho_f > 0.0 && rho_m > 0.0 && rho_f.is_finite() && rho_m.is_finite()) {
            return;
        }
        let y = &mut predictor.out[..nim.outputs.len()];
        net.predict(features, workspace, y);
        for (&k, &v) in nim.outputs.iter().zip(y.iter()) {
            out[k] = Some(v.exp() * if k == 0 { rho_f } else { rho_m });
        }
    }

    /// Every body's θ from a recording (noisy or not): the mean of the predictions of
    /// the windows starting at `0, stride, 2·stride, …` (every window that fits),
    /// with the spread of those predictions. A mean smaller than three standard
    /// errors (the spread over the square root of the number of windows that share
    /// no sample) is not significant and has no value, as in MIM. Errors when the
    /// recording has another number of bodies or fewer samples than a window, or
    /// `stride` is 0.
    pub fn identify(&self, recording: &Recording, stride: usize) -> Result<NimEstimate, NimError> {
        let n = self.n_bodies();
        if recording.nv() != n {
            return Err(NimError::DimensionMismatch {
                what: "bodies of the recording",
                expected: n,
                found: recording.nv(),
            });
        }
        if recording.len() < self.window || stride == 0 {
            return Err(NimError::InvalidOption {
                field: if stride == 0 { "stride" } else { "recording" },
                reason: if stride == 0 {
                    "0; expected at least 1".into()
                } else {
                    format!("{} samples, fewer than one window of {}", recording.len(), self.window)
                },
            });
        }
        let mut predictor = self.predictor();
        let starts: Vec<usize> = (0..=recording.len() - self.window).step_by(stride).collect();
        let mut theta = vec![None; 4 * n];
        let mut spread = vec![None; 4 * n];
        let mut verdicts = vec![Verdict::NoEffect; 4 * n];
        // Windows that share no sample: the count behind the standard error.
        let disjoint = (recording.len() / self.window).max(1);
        let independent = disjoint as f64;
        let mut samples = vec![BodySample::default(); self.window];
        let mut out = [None; 4];
        for i in 0..n {
            let mut sums = [(0.0, 0.0, 0usize); 4];
            for &start in &starts {
                for (s, k) in samples.iter_mut().zip(start..) {
                    *s = BodySample::from_recording(recording, k, i);
                }
                self.predict(i, &samples, &mut predictor, &mut out);
                for (sum, v) in sums.iter_mut().zip(out) {
                    if let Some(v) = v {
                        *sum = (sum.0 + v, sum.1 + v * v, sum.2 + 1);
                    }
                }
            }
            for (k, (s, s2, c)) in sums.into_iter().enumerate() {
                let j = 4 * i + k;
                if !self.bodies[i].outputs.contains(&k) {
                    continue;
                }
                verdicts[j] = Verdict::NotSignificant;
                if c == 0 {
                    continue;
                }
                let mean = s / c as f64;
                let deviation = (s2 / c as f64 - mean * mean).max(0.0).sqrt();
                spread[j] = Some(deviation);
                if mean.is_finite() && mean.abs() >= SIGNIFICANCE * deviation / independent.sqrt() {
                    theta[j] = Some(mean);
                    verdicts[j] = Verdict::Identified;
                }
            }
        }
        Ok(NimEstimate {
            body_names: self.body_names.clone(),
            theta,
            spread,
            verdicts,
            disjoint_windows: disjoint,
            windows: starts.len(),
            window: self.window,
            truth: None,
        })
    }

    /// The fraction of body-samples of `recording` unlike anything the nets were
    /// trained on: some feature of the sample (in consecutive windows of
    /// [`Nim::window`] samples) more than 6 training standard deviations from its
    /// training mean. A net is only validated on data like its training data (the
    /// motion, the noise); a large fraction means its answer here is an
    /// extrapolation.
    pub fn unfamiliar_fraction(&self, recording: &Recording) -> f64 {
        let w = self.window.min(recording.len()).max(1);
        let mut features = vec![0.0; w * FEATURES];
        let mut samples = vec![BodySample::default(); w];
        let (mut outside, mut total) = (0usize, 0usize);
        for (i, body) in self.bodies.iter().enumerate().take(recording.nv()) {
            let Some(net) = &body.net else { continue };
            let standardizer = net.encoder().input_standardizer();
            for start in (0..=recording.len() - w).step_by(w) {
                for (s, k) in samples.iter_mut().zip(start..) {
                    *s = BodySample::from_recording(recording, k, i);
                }
                window_features(&samples, &mut features);
                for row in features.chunks_exact(FEATURES) {
                    let far = row.iter().enumerate().any(|(j, &x)| {
                        let z = standardizer.apply(j, x);
                        z.is_nan() || z.abs() > 6.0
                    });
                    outside += usize::from(far);
                    total += 1;
                }
            }
        }
        if total == 0 {
            0.0
        } else {
            outside as f64 / total as f64
        }
    }

    /// The identifier as JSON (schema [`NIM_SCHEMA`]): robot and body names, the
    /// window, the draws' spread and centre, and per body its outputs and net.
    pub fn to_json(&self) -> String {
        let file = NimFile {
            schema: NIM_SCHEMA.into(),
            robot: self.robot.clone(),
            body_names: self.body_names.clone(),
            window: self.window,
            spread: self.spread,
            nominal: self.nominal.clone(),
            bodies: self
                .bodies
                .iter()
                .map(|b| BodyFile {
                    outputs: b.outputs.clone(),
                    net: b.net.as_ref().map(WindowNet::to_file),
                })
                .collect(),
        };
        serde_json::to_string_pretty(&file).expect("a Nim serialises to JSON")
    }

    /// Reads [`Nim::to_json`]'s format, checking that the parts agree with each other.
    pub fn from_json(text: &str) -> Result<Nim, NimError> {
        let file: NimFile = serde_json::from_str(text).map_err(|e| NimError::Json { message: e.to_string() })?;
        if file.schema != NIM_SCHEMA {
            return Err(NimError::Schema {
                found: Some(file.schema),
                expected: NIM_SCHEMA,
            });
        }
        let n = file.body_names.len();
        let shape = |field: &str, expected: String, found: String| NimError::Shape {
            layer: None,
            field: field.into(),
            expected,
            found,
        };
        if file.bodies.len() != n || file.nominal.len() != 4 * n {
            return Err(shape(
                "bodies, nominal",
                format!("{n} bodies and 4 × {n} nominal values (one body per name)"),
                format!("{} bodies and {} values", file.bodies.len(), file.nominal.len()),
            ));
        }
        if file.window == 0 {
            return Err(shape("window", "at least 1".into(), "0".into()));
        }
        let mut bodies = Vec::with_capacity(n);
        for (i, b) in file.bodies.into_iter().enumerate() {
            let context = format!("bodies[{i}]");
            if b.outputs.windows(2).any(|w| w[0] >= w[1]) || b.outputs.iter().any(|&k| k > 3) {
                return Err(shape(
                    &format!("{context}.outputs"),
                    "ascending indices into (m, J1, J2, J3), each 0..=3".into(),
                    format!("{:?}", b.outputs),
                ));
            }
            let net = match b.net {
                Some(f) => {
                    let net = WindowNet::from_file(f).map_err(|e| e.within(format!("{context}.net")))?;
                    if net.n_features() != FEATURES || net.n_outputs() != b.outputs.len() {
                        return Err(shape(
                            &format!("{context}.net"),
                            format!("{FEATURES} features and {} outputs", b.outputs.len()),
                            format!("{} features and {} outputs", net.n_features(), net.n_outputs()),
                        ));
                    }
                    Some(net)
                }
                None if b.outputs.is_empty() => None,
                None => {
                    return Err(shape(
                        &format!("{context}.net"),
                        "a net for the listed outputs".into(),
                        "null".into(),
                    ))
                }
            };
            bodies.push(BodyNim {
                outputs: b.outputs,
                net,
            });
        }
        Ok(Nim {
            robot: file.robot,
            body_names: file.body_names,
            window: file.window,
            spread: file.spread,
            nominal: file.nominal,
            bodies,
        })
    }

    /// Writes [`Nim::to_json`]; an existing file only with `overwrite`.
    pub fn save(&self, path: impl AsRef<Path>, overwrite: bool) -> Result<(), NimError> {
        super::mlp::write_json(path.as_ref(), &self.to_json(), overwrite)
    }

    pub fn load(path: impl AsRef<Path>) -> Result<Nim, NimError> {
        Nim::from_json(&super::mlp::read_json(path.as_ref())?)
    }
}

/// Buffers of [`Nim::predict`], one set per body.
#[derive(Clone, Debug)]
pub struct NimPredictor {
    workspaces: Vec<Option<WindowWorkspace>>,
    features: Vec<f64>,
    out: Vec<f64>,
}

/// A NIM value is significant when its magnitude is at least this many standard
/// errors (MIM's default too).
const SIGNIFICANCE: f64 = 3.0;

/// θ of every body from [`Nim::identify`].
#[derive(Clone, Debug, PartialEq)]
pub struct NimEstimate {
    pub body_names: Vec<String>,
    /// `4n`, body 1 first; `None` when the verdict is not
    /// [`Verdict::Identified`].
    pub theta: Vec<Option<f64>>,
    /// Standard deviation of the window predictions around the mean.
    pub spread: Vec<Option<f64>>,
    /// [`Verdict::NoEffect`]: not an output (does not enter the body's equations
    /// along the trained motion); [`Verdict::NotSignificant`]: the windows disagree
    /// too much (or none carried a wrench).
    pub verdicts: Vec<Verdict>,
    /// Windows averaged, and samples per window.
    pub windows: usize,
    pub window: usize,
    /// How many of the windows could share no sample (the recording's length over
    /// the window's).
    pub disjoint_windows: usize,
    /// The true θ, when known, for the error table.
    pub truth: Option<Vec<f64>>,
}

impl NimEstimate {
    /// The report of a NIM estimate ([`crate::Nim::identify`]): `θ` named
    /// `m1, J1_1, …`; a parameter the body's equations do not carry is
    /// `no_effect`, one whose window predictions disagree `not_significant`, both
    /// without value. `sigma` is the standard error of the mean of the window
    /// predictions (their spread over the square root of the number of windows
    /// that share no sample); `rank` counts the parameters with a value.
    pub fn report(&self, robot: &str) -> dyngen_identify::report::ParameterReport {
        let estimate = self;
        let names = dyngen_model::names::principal_param_names(estimate.body_names.len());
        let parameters: Vec<dyngen_identify::report::ParamReport> = names
            .into_iter()
            .enumerate()
            .map(|(j, name)| {
                let value = estimate.theta[j].filter(|v| v.is_finite());
                let sigma = value.and(estimate.standard_error(j));
                dyngen_identify::report::ParamReport {
                    name,
                    value,
                    sigma,
                    sigma_percent: value.zip(sigma).map(|(v, s)| 100.0 * s / v.abs()),
                    status: match estimate.verdicts[j] {
                        dyngen_identify::mim::Verdict::Identified => dyngen_identify::report::ParamStatus::Identified,
                        dyngen_identify::mim::Verdict::NotSignificant => {
                            dyngen_identify::report::ParamStatus::NotSignificant
                        }
                        dyngen_identify::mim::Verdict::InCombination => {
                            dyngen_identify::report::ParamStatus::InCombination
                        }
                        dyngen_identify::mim::Verdict::NoEffect => dyngen_identify::report::ParamStatus::NoEffect,
                    },
                }
            })
            .collect();
        dyngen_identify::report::ParameterReport {
            schema: dyngen_identify::report::SCHEMA.to_string(),
            robot: robot.to_string(),
            parameterisation: dyngen_identify::report::Parameterisation::Principal,
            method: format!(
                "NIM: window network, mean over {} windows of {} samples",
                estimate.windows, estimate.window
            ),
            rank: parameters.iter().filter(|p| p.value.is_some()).count(),
            condition_number: None,
            residual_rms: Vec::new(),
            channels: Vec::new(),
            parameters,
            combinations: Vec::new(),
            prediction: None,
        }
    }

    /// The estimate with the true θ attached (for [`NimEstimate::max_relative_errors`]
    /// and the error table).
    pub fn with_truth(mut self, truth: &[f64]) -> NimEstimate {
        self.truth = Some(truth.to_vec());
        self
    }

    /// The standard error of parameter `j`'s value: the spread of the window
    /// predictions over `√disjoint_windows` (`None` without a value).
    pub fn standard_error(&self, j: usize) -> Option<f64> {
        self.theta[j]?;
        Some(self.spread[j]? / (self.disjoint_windows as f64).sqrt())
    }

    /// The largest relative error over the parameters with a value, split into
    /// `(masses, principal moments)`; `None` without truth.
    pub fn max_relative_errors(&self) -> Option<(f64, f64)> {
        let truth = self.truth.as_ref()?;
        let mut worst = (0.0f64, 0.0f64);
        for (j, (v, t)) in self.theta.iter().zip(truth).enumerate() {
            if let Some(v) = v {
                let rel = dyngen_identify::relative_error(*v, *t);
                if j % 4 == 0 {
                    worst.0 = worst.0.max(rel);
                } else {
                    worst.1 = worst.1.max(rel);
                }
            }
        }
        Some(worst)
    }
}

impl fmt::Display for NimEstimate {
    /// In the layout of the paper's Tables 4–5.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "NIM, mean of {} windows of {} samples", self.windows, self.window)?;
        let cells: Vec<Result<f64, &str>> = self
            .theta
            .iter()
            .zip(&self.verdicts)
            .map(|(v, verdict)| v.ok_or(verdict.short()))
            .collect();
        let table = ThetaTable {
            body_names: &self.body_names,
            cells: &cells,
            truth: self.truth.as_deref(),
            tables: [4, 5],
        };
        write!(f, "{table}")?;
        if cells.iter().any(Result::is_err) {
            writeln!(
                f,
                "n/i: not identifiable (does not enter the body's equations along the motion); n/s: not significant \
                 (the windows' predictions spread over more than a third of their mean's size times √windows)"
            )?;
        }
        Ok(())
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct NimFile {
    schema: String,
    robot: String,
    body_names: Vec<String>,
    window: usize,
    spread: f64,
    nominal: Vec<f64>,
    bodies: Vec<BodyFile>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    outputs: Vec<usize>,
    net: Option<WindowFile>,
}

/// What training one body gives: its net and loss curves (none without outputs)
/// and the number of window starts along the motion.
type BodyResult = (Option<WindowNet>, Option<TrainHistory>, usize);

/// One body's training data: its kinematics along the motion, and windows of them
/// under each draw.
struct BodyTraining<'a> {
    body: usize,
    kinematics: &'a [BodySample],
    outputs: &'a [usize],
    window: usize,
    nominal: &'a [f64],
}

/// σ of the training noise on each of the five measured 3-vectors of a
/// [`BodySample`] (`F, s, M, ω, ω̇`), and the seed of its draws.
#[derive(Clone, Copy)]
struct TrainingNoise {
    sigma: [f64; 5],
    seed: u64,
}

fn components(s: &BodySample) -> [Vector3<f64>; 5] {
    [
        s.force,
        s.specific_force,
        s.moment,
        s.angular_velocity,
        s.angular_acceleration,
    ]
}

fn components_mut(s: &mut BodySample) -> [&mut Vector3<f64>; 5] {
    [
        &mut s.force,
        &mut s.specific_force,
        &mut s.moment,
        &mut s.angular_velocity,
        &mut s.angular_acceleration,
    ]
}

impl BodyTraining<'_> {
    /// The window starts that carry a wrench: with the nominal θ, `ρ_F` and (when a
    /// moment is an output) `ρ_M` above 10⁻⁶ of their median over all starts.
    fn starts(&self) -> Vec<usize> {
        let theta: [f64; 4] = self.nominal.try_into().expect("4 values");
        let all: Vec<usize> = (0..=self.kinematics.len() - self.window).collect();
        let mut features = vec![0.0; self.window * FEATURES];
        let scales: Vec<(f64, f64)> = all
            .iter()
            .map(|&s| {
                let samples: Vec<BodySample> = self.kinematics[s..s + self.window]
                    .iter()
                    .map(|b| b.with_theta(&theta))
                    .collect();
                window_features(&samples, &mut features)
            })
            .collect();
        let median = |f: fn(&(f64, f64)) -> f64| {
            let mut v: Vec<f64> = scales.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (mf, mm) = (median(|s| s.0), median(|s| s.1));
        let needs_moment = self.outputs.iter().any(|&k| k > 0);
        all.into_iter()
            .zip(&scales)
            .filter(|(_, &(f, m))| f > 1e-6 * mf && f > 0.0 && (!needs_moment || (m > 1e-6 * mm && m > 0.0)))
            .map(|(s, _)| s)
            .collect()
    }

    /// [`NimConfig::noise`] as σ per 3-vector: `level` times its RMS per axis along
    /// the motion at the nominal θ.
    fn noise(&self, level: f64, seed: u64) -> Option<TrainingNoise> {
        if level == 0.0 {
            return None;
        }
        let theta: [f64; 4] = self.nominal.try_into().expect("4 values");
        let mut sums = [0.0; 5];
        for b in self.kinematics {
            for (sum, v) in sums.iter_mut().zip(components(&b.with_theta(&theta))) {
                *sum += v.norm_squared();
            }
        }
        let count = 3.0 * self.kinematics.len() as f64;
        Some(TrainingNoise {
            sigma: sums.map(|s| level * (s / count).sqrt()),
            seed,
        })
    }

    fn train(
        &self,
        train_draws: &[Vec<f64>],
        validation_draws: &[Vec<f64>],
        config: &NimConfig,
    ) -> Result<BodyResult, NimError> {
        if self.outputs.is_empty() {
            return Ok((None, None, 0));
        }
        let starts = self.starts();
        if starts.is_empty() {
            return Err(NimError::InvalidOption {
                field: "recording",
                reason: "no window along the motion carries a force and moment on this body".into(),
            });
        }
        let source = |draws: &[Vec<f64>], salt: u64| Windows {
            training: self,
            starts: starts.clone(),
            thetas: draws
                .iter()
                .map(|d| d[4 * self.body..4 * self.body + 4].try_into().expect("4 values"))
                .collect(),
            noise: self.noise(config.noise, config.seed ^ salt ^ self.body as u64),
        };
        let train = source(train_draws, 0x6E6F_6973_6500);
        let validation = source(validation_draws, 0x6E6F_6973_6501);
        let options = TrainOptions {
            seed: config.train.seed ^ (self.body as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
            ..config.train.clone()
        };
        let (net, history) = train_windows(
            FEATURES,
            &config.shape,
            &train,
            (!validation.thetas.is_empty()).then_some(&validation as &dyn WindowSource),
            &options,
        )?;
        Ok((Some(net), Some(history), starts.len()))
    }
}

/// The windows of one body: every start under every draw (with the same noise
/// every time a window is filled: its draws are seeded by the window's index).
struct Windows<'a> {
    training: &'a BodyTraining<'a>,
    starts: Vec<usize>,
    thetas: Vec<[f64; 4]>,
    noise: Option<TrainingNoise>,
}

impl WindowSource for Windows<'_> {
    fn n_features(&self) -> usize {
        FEATURES
    }

    fn n_outputs(&self) -> usize {
        self.training.outputs.len()
    }

    fn window(&self) -> usize {
        self.training.window
    }

    fn len(&self) -> usize {
        self.starts.len() * self.thetas.len()
    }

    fn fill(&self, index: usize, features: &mut [f64], target: &mut [f64]) {
        let theta = &self.thetas[index / self.starts.len()];
        let start = self.starts[index % self.starts.len()];
        let w = self.training.window;
        let mut samples: Vec<BodySample> = self.training.kinematics[start..start + w]
            .iter()
            .map(|b| b.with_theta(theta))
            .collect();
        if let Some(noise) = &self.noise {
            let mut rng = Gaussian::new(noise.seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            for s in &mut samples {
                for (v, &sigma) in components_mut(s).into_iter().zip(&noise.sigma) {
                    for a in 0..3 {
                        v[a] += rng.normal(sigma);
                    }
                }
            }
        }
        let (rho_f, rho_m) = window_features(&samples, features);
        for (t, &k) in target.iter_mut().zip(self.training.outputs) {
            *t = (theta[k] / if k == 0 { rho_f } else { rho_m }).ln();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_identify::simulate::{record, Experiment, NoiseModel};
    use dyngen_reference::Reference;

    fn paper6() -> (dyngen_model::Model, Reference) {
        let model = dyngen_model::parse_urdf(include_str!("../../tests/fixtures/paper6.urdf")).unwrap();
        let robot = Reference::new(&model);
        (model, robot)
    }

    fn small_config() -> NimConfig {
        let mut config = NimConfig {
            draws: 60,
            validation_draws: 10,
            window: 10,
            ..NimConfig::default()
        };
        config.train.max_steps = 150;
        config.train.record_every = 50;
        config
    }

    #[test]
    fn draws_are_physically_consistent_and_within_the_spread() {
        let (model, _) = paper6();
        let nominal = dyngen_model::principal_params(&model);
        let mut rng = SplitMix64::new(4);
        for _ in 0..200 {
            let theta = draw_theta(&nominal, 0.3, &mut rng);
            for (body, nom) in theta.chunks_exact(4).zip(nominal.chunks_exact(4)) {
                assert!(body[0] > 0.0 && (body[0] / nom[0] - 1.0).abs() <= 0.3);
                let j = [body[1], body[2], body[3]];
                for k in 0..3 {
                    assert!(j[k] > 0.0);
                    // Triangle inequalities, by construction.
                    assert!(j[(k + 1) % 3] + j[(k + 2) % 3] >= j[k] * (1.0 - 1e-12));
                }
            }
        }
        let a = draw_theta(&nominal, 0.3, &mut SplitMix64::new(9));
        assert_eq!(a, draw_theta(&nominal, 0.3, &mut SplitMix64::new(9)));
        // No spread: the nominal θ, up to the rounding of J → s → J.
        for (d, n) in draw_theta(&nominal, 0.0, &mut SplitMix64::new(9)).iter().zip(&nominal) {
            assert!((d - n).abs() <= 1e-14 * n);
        }
    }

    #[test]
    fn features_do_not_change_when_the_wrench_scales() {
        let (model, robot) = paper6();
        let recording = record(&robot, &model.standard_params(), &Experiment::paper(&model));
        let samples: Vec<BodySample> = (30..50).map(|k| BodySample::from_recording(&recording, k, 2)).collect();
        let scaled: Vec<BodySample> = samples
            .iter()
            .map(|s| BodySample {
                force: 3.0 * s.force,
                moment: 3.0 * s.moment,
                ..*s
            })
            .collect();
        let (mut a, mut b) = (vec![0.0; 20 * FEATURES], vec![0.0; 20 * FEATURES]);
        let (rf, rm) = window_features(&samples, &mut a);
        let (sf, sm) = window_features(&scaled, &mut b);
        assert!((sf / rf - 3.0).abs() < 1e-12 && (sm / rm - 3.0).abs() < 1e-12);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()));
        }
    }

    /// The training data's shortcut, `[F; M] = A_i θ_i`, is the simulated
    /// resultant: the wrench a body measures along a prescribed motion.
    #[test]
    fn the_wrench_of_a_draw_is_the_simulated_one() {
        let (model, robot) = paper6();
        let nominal = dyngen_model::principal_params(&model);
        let theta = draw_theta(&nominal, 0.3, &mut SplitMix64::new(2));
        let params = dyngen_reference::principal_params_to_standard(&model, &theta);
        let drawn = record(&robot, &params, &Experiment::paper(&model));
        let base = record(&robot, &model.standard_params(), &Experiment::paper(&model));
        for k in (1..drawn.len()).step_by(7) {
            for i in 0..6 {
                let t: [f64; 4] = theta[4 * i..4 * i + 4].try_into().unwrap();
                let made = BodySample::from_recording(&base, k, i).with_theta(&t);
                let measured = BodySample::from_recording(&drawn, k, i);
                let scale = 1.0 + measured.force.norm() + measured.moment.norm();
                assert!(
                    (made.force - measured.force).norm() < 1e-10 * scale,
                    "body {i} sample {k}"
                );
                assert!(
                    (made.moment - measured.moment).norm() < 1e-10 * scale,
                    "body {i} sample {k}"
                );
            }
        }
    }

    #[test]
    fn a_small_nim_trains_saves_and_identifies() {
        let (model, robot) = paper6();
        let nominal = dyngen_model::principal_params(&model);
        let recording = record(&robot, &model.standard_params(), &Experiment::paper(&model));
        let done = std::sync::atomic::AtomicUsize::new(0);
        let (nim, training) = Nim::train("paper6", &recording, &nominal, &small_config(), &|_| {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        assert_eq!(done.into_inner(), 6);
        // The turret turns about its own axis only: J1, J2 are not outputs.
        assert_eq!(nim.bodies[0].outputs, [0, 3]);
        assert!(nim.bodies[1..].iter().all(|b| b.outputs == [0, 1, 2, 3]));
        assert_eq!(training.windows_per_draw, [92; 6]);
        assert!(training
            .histories
            .iter()
            .all(|h| h.as_ref().unwrap().steps_taken == 150));

        let estimate = nim.identify(&recording, 5).unwrap().with_truth(&nominal);
        assert_eq!(estimate.windows, 19);
        assert_eq!((estimate.theta[1], estimate.verdicts[1]), (None, Verdict::NoEffect));
        let (mass, _) = estimate.max_relative_errors().unwrap();
        assert!(mass < 0.3, "{estimate}");
        let text = estimate.to_string();
        assert!(
            text.contains("(cf. the paper's Table 4)") && text.contains("n/i"),
            "{text}"
        );

        // JSON round trip, bit for bit.
        let again = Nim::from_json(&nim.to_json()).unwrap();
        assert_eq!(again, nim);
        assert_eq!(
            again.identify(&recording, 5).unwrap().theta,
            nim.identify(&recording, 5).unwrap().theta
        );

        // Data like the training data are familiar; far noisier data are not.
        assert!(nim.unfamiliar_fraction(&recording) < 0.01);
        let noisy = NoiseModel::relative(0.5).apply(&recording, 1);
        assert!(nim.unfamiliar_fraction(&noisy) > 0.1);

        // Misuse is an error, not a panic.
        let short = Recording {
            samples: recording.samples[..5].to_vec(),
            ..recording.clone()
        };
        let err = nim.identify(&short, 1).unwrap_err().to_string();
        assert_eq!(err, "invalid recording: 5 samples, fewer than one window of 10");
        assert!(nim
            .identify(&recording, 0)
            .unwrap_err()
            .to_string()
            .contains("invalid stride"));
    }

    #[test]
    fn damaged_identifier_files_are_refused() {
        let (model, robot) = paper6();
        let nominal = dyngen_model::principal_params(&model);
        let recording = record(&robot, &model.standard_params(), &Experiment::paper(&model));
        let mut config = small_config();
        config.train.max_steps = 1;
        let (nim, _) = Nim::train("paper6", &recording, &nominal, &config, &|_| {}).unwrap();
        let json = nim.to_json();
        let err = |text: String| Nim::from_json(&text).unwrap_err().to_string();
        assert!(err(json.replace(NIM_SCHEMA, "dyngen-nim/0")).contains("this version reads \"dyngen-nim/1\""));
        assert_eq!(
            err(json.replacen(
                "\"outputs\": [\n        0,\n        3\n      ]",
                "\"outputs\": [3, 0]",
                1
            )),
            "`bodies[0].outputs` has shape [3, 0], expected ascending indices into (m, J1, J2, J3), each 0..=3"
        );
        let mut file: serde_json::Value = serde_json::from_str(&json).unwrap();
        file["bodies"][2]["net"] = serde_json::Value::Null;
        assert_eq!(
            err(file.to_string()),
            "`bodies[2].net` has shape null, expected a net for the listed outputs"
        );
        let mut file: serde_json::Value = serde_json::from_str(&json).unwrap();
        file["bodies"][1]["net"]["decoder"]["output"]["std"][0] = serde_json::json!(-1.0);
        assert_eq!(
            err(file.to_string()),
            "bodies[1].net: decoder: invalid value in `output.std[0]`: -1; a standard deviation must be finite and > 0"
        );
        let mut file: serde_json::Value = serde_json::from_str(&json).unwrap();
        file["nominal"].as_array_mut().unwrap().pop();
        assert!(err(file.to_string()).contains("6 bodies and 4 × 6 nominal values"));
    }

    #[test]
    fn bad_training_settings_are_errors() {
        let (model, robot) = paper6();
        let nominal = dyngen_model::principal_params(&model);
        let recording = record(&robot, &model.standard_params(), &Experiment::paper(&model));
        let train = |config: NimConfig, nominal: &[f64]| {
            Nim::train("paper6", &recording, nominal, &config, &|_| {})
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            train(small_config(), &nominal[..20]),
            "dimension mismatch in nominal θ (4 per body): expected 24, found 20"
        );
        let window = NimConfig {
            window: 500,
            ..small_config()
        };
        assert!(train(window, &nominal).contains("expected 1 ≤ window ≤ 101"));
        let spread = NimConfig {
            spread: 1.0,
            ..small_config()
        };
        assert!(train(spread, &nominal).contains("invalid spread: 1; expected 0 ≤ spread < 1"));
        let noise = NimConfig {
            noise: -0.1,
            ..small_config()
        };
        assert!(train(noise, &nominal).contains("invalid noise"));
        let draws = NimConfig {
            draws: 0,
            ..small_config()
        };
        assert!(train(draws, &nominal).contains("invalid draws"));
    }
}
