//! A network over a window of samples: every sample goes through one encoder
//! [`Mlp`], the encodings are averaged, and a decoder [`Mlp`] maps the average to the
//! outputs (a "deep set", Zaheer et al. 2017). The average makes the prediction
//! independent of the order of the samples and lets the encoder learn per-sample
//! statistics whose mean carries the answer, as the normal equations of least
//! squares are means of per-sample products.

use super::data::{shuffle, Standardizer};
use super::error::NimError;
use super::mlp::{check_sizes, Mlp, MlpFile, Workspace};
use super::train::{validate, AdamState, Backprop, Optimizer, StopReason, TrainHistory, TrainOptions};
use dyngen_reference::SplitMix64;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The `schema` string of [`WindowNet::to_json`].
pub const WINDOW_SCHEMA: &str = "dyngen-window-net/1";

/// Windows of training data, made on demand: window `index` of
/// [`WindowSource::len`] has [`WindowSource::window`] samples of
/// [`WindowSource::n_features`] features and one target of
/// [`WindowSource::n_outputs`] values, all in original units.
pub trait WindowSource {
    fn n_features(&self) -> usize;
    fn n_outputs(&self) -> usize;
    /// Samples per window.
    fn window(&self) -> usize;
    /// Number of windows (at least 1).
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Window `index`: `features` (`window() × n_features()`, row-major: sample by
    /// sample) and `target` (`n_outputs()`).
    fn fill(&self, index: usize, features: &mut [f64], target: &mut [f64]);
}

/// Layer sizes of a [`WindowNet`]: the encoder is
/// `n_features → encoder[0] → … → encoder[last]` (the last size is the encoding,
/// linear), the decoder `encoding → decoder… → n_outputs` (ReLU hidden layers,
/// linear output).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WindowShape {
    pub encoder: Vec<usize>,
    pub decoder: Vec<usize>,
}

/// A deep set over a window of samples: encoder, mean over the window, decoder
/// (trained by [`train_windows`]). The encoder's input standardiser holds the
/// feature statistics, the decoder's output standardiser the target statistics; the
/// two in between are the identity.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowNet {
    encoder: Mlp,
    decoder: Mlp,
}

/// Buffers of [`WindowNet::predict`].
#[derive(Clone, Debug)]
pub struct WindowWorkspace {
    encoder: Workspace,
    decoder: Workspace,
    encoded: Vec<f64>,
    pooled: Vec<f64>,
}

impl WindowNet {
    /// A freshly initialised net (He initialisation from `seed`, identity
    /// standardisers). Errors on an empty encoder or a zero size.
    pub fn new(n_features: usize, shape: &WindowShape, n_outputs: usize, seed: u64) -> Result<WindowNet, NimError> {
        let encoding = *shape.encoder.last().ok_or_else(|| NimError::InvalidSizes {
            sizes: shape.encoder.clone(),
            reason: "the encoder needs at least one layer (its last size is the encoding)".into(),
        })?;
        let mut enc = vec![n_features];
        enc.extend(&shape.encoder);
        let mut dec = vec![encoding];
        dec.extend(&shape.decoder);
        dec.push(n_outputs);
        check_sizes(&enc)?;
        check_sizes(&dec)?;
        let mut seeds = SplitMix64::new(seed);
        Ok(WindowNet {
            encoder: Mlp::new(&enc, seeds.next_u64())?,
            decoder: Mlp::new(&dec, seeds.next_u64())?,
        })
    }

    pub fn encoder(&self) -> &Mlp {
        &self.encoder
    }

    pub fn decoder(&self) -> &Mlp {
        &self.decoder
    }

    pub fn n_features(&self) -> usize {
        self.encoder.n_inputs()
    }

    pub fn n_outputs(&self) -> usize {
        self.decoder.n_outputs()
    }

    /// Trainable parameters of both nets.
    pub fn parameter_count(&self) -> usize {
        self.encoder.parameter_count() + self.decoder.parameter_count()
    }

    pub fn workspace(&self) -> WindowWorkspace {
        let encoding = self.decoder.n_inputs();
        WindowWorkspace {
            encoder: self.encoder.workspace(),
            decoder: self.decoder.workspace(),
            encoded: vec![0.0; encoding],
            pooled: vec![0.0; encoding],
        }
    }

    /// One window (`samples × n_features()` row-major, original units; any number
    /// of samples ≥ 1) through the net, without allocating; `out` receives
    /// `n_outputs()` values in original units.
    ///
    /// # Panics
    ///
    /// When `window` is empty or not a whole number of samples, `out` has the wrong
    /// length, or the workspace was made for a smaller net.
    pub fn predict(&self, window: &[f64], workspace: &mut WindowWorkspace, out: &mut [f64]) {
        let f = self.n_features();
        assert!(
            !window.is_empty() && window.len().is_multiple_of(f),
            "WindowNet::predict: the window has {} values, not a positive multiple of {f} features",
            window.len()
        );
        let samples = window.len() / f;
        workspace.pooled.fill(0.0);
        for sample in window.chunks_exact(f) {
            self.encoder
                .predict(sample, &mut workspace.encoder, &mut workspace.encoded);
            for (p, &e) in workspace.pooled.iter_mut().zip(&workspace.encoded) {
                *p += e;
            }
        }
        let scale = 1.0 / samples as f64;
        for p in &mut workspace.pooled {
            *p *= scale;
        }
        self.decoder.predict(&workspace.pooled, &mut workspace.decoder, out);
    }

    /// The net as JSON (schema [`WINDOW_SCHEMA`]): both nets in [`Mlp::to_json`]'s
    /// format. Numbers round-trip exactly.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.to_file()).expect("a WindowNet serialises to JSON")
    }

    pub(crate) fn to_file(&self) -> WindowFile {
        WindowFile {
            schema: WINDOW_SCHEMA.into(),
            encoder: self.encoder.to_file(),
            decoder: self.decoder.to_file(),
        }
    }

    /// Reads [`WindowNet::to_json`]'s format; errors name what is wrong, as
    /// [`Mlp::from_json`]'s do, prefixed with the net (`encoder` or `decoder`).
    pub fn from_json(text: &str) -> Result<WindowNet, NimError> {
        let file: WindowFile = serde_json::from_str(text).map_err(|e| NimError::Json { message: e.to_string() })?;
        WindowNet::from_file(file)
    }

    pub(crate) fn from_file(file: WindowFile) -> Result<WindowNet, NimError> {
        if file.schema != WINDOW_SCHEMA {
            return Err(NimError::Schema {
                found: Some(file.schema),
                expected: WINDOW_SCHEMA,
            });
        }
        let encoder = Mlp::from_file(file.encoder).map_err(|e| e.within("encoder"))?;
        let decoder = Mlp::from_file(file.decoder).map_err(|e| e.within("decoder"))?;
        if decoder.n_inputs() != encoder.n_outputs() {
            return Err(NimError::Shape {
                layer: None,
                field: "decoder.sizes[0]".into(),
                expected: format!("{} (the encoder's last size)", encoder.n_outputs()),
                found: decoder.n_inputs().to_string(),
            });
        }
        Ok(WindowNet { encoder, decoder })
    }

    /// Writes [`WindowNet::to_json`]; an existing file only with `overwrite`.
    pub fn save(&self, path: impl AsRef<Path>, overwrite: bool) -> Result<(), NimError> {
        super::mlp::write_json(path.as_ref(), &self.to_json(), overwrite)
    }

    pub fn load(path: impl AsRef<Path>) -> Result<WindowNet, NimError> {
        WindowNet::from_json(&super::mlp::read_json(path.as_ref())?)
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WindowFile {
    schema: String,
    encoder: MlpFile,
    decoder: MlpFile,
}

/// At most this many windows fit the feature standardiser and make the
/// validation set (a seeded selection when there are more).
const MAX_FIT_WINDOWS: usize = 4096;

/// Trains a fresh [`WindowNet`] of `shape` on windows of `train`: feature and
/// target standardisers fitted on (up to 4096 of) its windows, He initialisation
/// from `options.seed`, then mini-batch Adam (the batch is a number of windows) on
/// the MSE in standardised target units, windows drawn in a seeded shuffled order,
/// until the threshold or the step budget. `validation` (up to 4096 of its windows)
/// is only evaluated at record points.
///
/// Errors: [`Optimizer::GradientDescent`] (a window net trains on mini-batches),
/// invalid sizes or options, sources whose widths disagree, an empty source, a
/// diverging loss.
pub fn train_windows(
    n_features: usize,
    shape: &WindowShape,
    train: &dyn WindowSource,
    validation: Option<&dyn WindowSource>,
    options: &TrainOptions,
) -> Result<(WindowNet, TrainHistory), NimError> {
    validate(options)?;
    let Optimizer::Adam {
        learning_rate,
        beta1,
        beta2,
        epsilon,
        batch_size,
    } = options.optimizer
    else {
        return Err(NimError::InvalidOption {
            field: "optimizer",
            reason: "a window net trains with Optimizer::Adam on mini-batches of windows".into(),
        });
    };
    for (source, what) in std::iter::once((train, "training")).chain(validation.map(|v| (v, "validation"))) {
        if source.is_empty() {
            return Err(NimError::Empty {
                what: if what == "training" {
                    "the training set of windows"
                } else {
                    "the validation set of windows"
                },
            });
        }
        for (expected, found, field) in [
            (n_features, source.n_features(), "features per sample of the windows"),
            (train.n_outputs(), source.n_outputs(), "targets per window"),
            (train.window(), source.window(), "samples per window"),
        ] {
            if expected != found {
                return Err(NimError::DimensionMismatch {
                    what: field,
                    expected,
                    found,
                });
            }
        }
    }
    let (w, f, n_out) = (train.window(), n_features, train.n_outputs());
    if w == 0 {
        return Err(NimError::InvalidOption {
            field: "window",
            reason: "0 samples per window; expected at least 1".into(),
        });
    }
    let mut net = WindowNet::new(f, shape, n_out, options.seed)?;

    // Standardisers from a seeded selection of training windows.
    let mut rng = SplitMix64::new(options.seed ^ 0x6E69_6D2D_7769_6E64);
    let fit = Windows::read(train, MAX_FIT_WINDOWS, &mut rng)?;
    let identity = |n| Standardizer::identity(n);
    let encoding = net.decoder.n_inputs();
    net.encoder
        .set_standardizers(Standardizer::fit(fit.sample_matrix()), identity(encoding))?;
    net.decoder
        .set_standardizers(identity(encoding), Standardizer::fit(fit.target_matrix()))?;
    let validation = match validation {
        Some(v) => Some(Windows::read(v, MAX_FIT_WINDOWS, &mut rng)?),
        None => None,
    };

    let batch = batch_size.min(train.len());
    let mut trainer = Pass::new(&net, batch, w);
    let mut adam = AdamState::new(net.encoder.parameter_lengths().chain(net.decoder.parameter_lengths()));
    let mut order: Vec<usize> = (0..train.len()).collect();
    let mut cursor = order.len();
    let (mut features, mut target) = (vec![0.0; w * f], vec![0.0; n_out]);
    let mut history = TrainHistory::default();
    let mut step = 0;
    loop {
        let record = step % options.record_every == 0 || step == options.max_steps;
        if record {
            let train_mse = trainer.evaluate(&net, &fit);
            if !train_mse.0.is_finite() {
                return Err(NimError::Diverged { step, mse: train_mse.0 });
            }
            history.steps.push(step);
            history.train_mse.push(train_mse.0);
            history.train_mse_original.push(train_mse.1);
            if let Some(v) = &validation {
                let (s, o) = trainer.evaluate(&net, v);
                history.validation_mse.push(s);
                history.validation_mse_original.push(o);
            }
            let reached = options.mse_threshold.is_some_and(|t| train_mse.0 <= t);
            if reached || step == options.max_steps {
                history.stopped = if reached {
                    StopReason::Threshold
                } else {
                    StopReason::Budget
                };
                history.steps_taken = step;
                return Ok((net, history));
            }
        }
        // The next mini-batch of windows.
        let mut count = 0;
        while count < batch {
            if cursor >= order.len() {
                shuffle(&mut order, &mut rng);
                cursor = 0;
            }
            train.fill(order[cursor], &mut features, &mut target);
            trainer.load(&net, count, &features, &target);
            cursor += 1;
            count += 1;
        }
        let loss = trainer.step(&net, count);
        if !loss.is_finite() {
            return Err(NimError::Diverged { step, mse: loss });
        }
        let rate = options.decay.factor(step, options.max_steps) * learning_rate;
        let grads = trainer.encoder.grads.buffers().chain(trainer.decoder.grads.buffers());
        let params = net.encoder.parameters_mut().chain(net.decoder.parameters_mut());
        adam.step(params, grads, rate, beta1, beta2, epsilon);
        step += 1;
    }
}

/// Windows read into memory (features row-major sample by sample, targets row by
/// row), all of a source or a seeded selection of `max` of them.
struct Windows {
    n_features: usize,
    n_outputs: usize,
    window: usize,
    features: Vec<f64>,
    targets: Vec<f64>,
}

impl Windows {
    fn read(source: &dyn WindowSource, max: usize, rng: &mut SplitMix64) -> Result<Windows, NimError> {
        let mut indices: Vec<usize> = (0..source.len()).collect();
        if indices.len() > max {
            shuffle(&mut indices, rng);
            indices.truncate(max);
        }
        let (w, f, o) = (source.window(), source.n_features(), source.n_outputs());
        let mut out = Windows {
            n_features: f,
            n_outputs: o,
            window: w,
            features: vec![0.0; indices.len() * w * f],
            targets: vec![0.0; indices.len() * o],
        };
        for (r, &i) in indices.iter().enumerate() {
            source.fill(
                i,
                &mut out.features[r * w * f..(r + 1) * w * f],
                &mut out.targets[r * o..(r + 1) * o],
            );
        }
        if let Some(k) = out.features.iter().position(|x| !x.is_finite()) {
            let per = w * f;
            return Err(NimError::NonFinite {
                part: super::Part::Inputs,
                row: indices[k / per],
                column: k % f,
                value: out.features[k],
            });
        }
        if let Some(k) = out.targets.iter().position(|x| !x.is_finite()) {
            return Err(NimError::NonFinite {
                part: super::Part::Targets,
                row: indices[k / o],
                column: k % o,
                value: out.targets[k],
            });
        }
        Ok(out)
    }

    fn len(&self) -> usize {
        self.targets.len() / self.n_outputs
    }

    /// Every sample of every window, one per row.
    fn sample_matrix(&self) -> faer::MatRef<'_, f64> {
        faer::MatRef::from_row_major_slice(&self.features, self.features.len() / self.n_features, self.n_features)
    }

    fn target_matrix(&self) -> faer::MatRef<'_, f64> {
        faer::MatRef::from_row_major_slice(&self.targets, self.len(), self.n_outputs)
    }
}

/// Buffers of one forward and backward pass over up to `capacity` windows.
struct Pass {
    window: usize,
    encoder: Backprop,
    decoder: Backprop,
    /// Standardised targets, windows as columns.
    targets: Vec<f64>,
}

impl Pass {
    fn new(net: &WindowNet, capacity: usize, window: usize) -> Pass {
        Pass {
            window,
            encoder: Backprop::new(&net.encoder, capacity * window, false),
            decoder: Backprop::new(&net.decoder, capacity, true),
            targets: vec![0.0; capacity * net.n_outputs()],
        }
    }

    /// Window `slot` of the batch from original-unit `features` and `target`.
    fn load(&mut self, net: &WindowNet, slot: usize, features: &[f64], target: &[f64]) {
        let f = net.n_features();
        let column = slot * self.window;
        let input = net.encoder.input_standardizer();
        for (s, sample) in features.chunks_exact(f).enumerate() {
            let dst = &mut self.encoder.acts[0][(column + s) * f..(column + s + 1) * f];
            for (j, (d, &x)) in dst.iter_mut().zip(sample).enumerate() {
                *d = input.apply(j, x);
            }
        }
        let o = net.n_outputs();
        let output = net.decoder.output_standardizer();
        for (i, (d, &y)) in self.targets[slot * o..(slot + 1) * o]
            .iter_mut()
            .zip(target)
            .enumerate()
        {
            *d = output.apply(i, y);
        }
    }

    /// Encoder over every sample, mean per window, decoder; the first `count`
    /// windows.
    fn forward(&mut self, net: &WindowNet, count: usize) {
        let w = self.window;
        net.encoder.forward(&mut self.encoder.acts, count * w);
        let e = net.decoder.n_inputs();
        let encoded = &self.encoder.acts[net.encoder.n_layers()];
        let pooled = &mut self.decoder.acts[0];
        let scale = 1.0 / w as f64;
        for b in 0..count {
            let dst = &mut pooled[b * e..(b + 1) * e];
            dst.fill(0.0);
            for s in 0..w {
                for (d, &x) in dst.iter_mut().zip(&encoded[(b * w + s) * e..(b * w + s + 1) * e]) {
                    *d += x;
                }
            }
            for d in dst.iter_mut() {
                *d *= scale;
            }
        }
        net.decoder.forward(&mut self.decoder.acts, count);
    }

    /// Forward, loss and gradients of both nets for the first `count` windows;
    /// returns the loss.
    fn step(&mut self, net: &WindowNet, count: usize) -> f64 {
        self.forward(net, count);
        let loss = self.decoder.mse_delta(&net.decoder, &self.targets, count);
        self.decoder.backward(&net.decoder, count);
        // The mean spreads ∂L/∂(pooled) evenly over the window's encodings.
        let (w, e) = (self.window, net.decoder.n_inputs());
        let scale = 1.0 / w as f64;
        let upstream = &self.decoder.deltas[0];
        let last = net.encoder.n_layers();
        let delta = &mut self.encoder.deltas[last];
        for b in 0..count {
            for s in 0..w {
                for (d, &u) in delta[(b * w + s) * e..(b * w + s + 1) * e]
                    .iter_mut()
                    .zip(&upstream[b * e..(b + 1) * e])
                {
                    *d = u * scale;
                }
            }
        }
        self.encoder.backward(&net.encoder, count * w);
        loss
    }

    /// MSE over `windows`, standardised and in original target units, in batches.
    fn evaluate(&mut self, net: &WindowNet, windows: &Windows) -> (f64, f64) {
        let capacity = self.targets.len() / net.n_outputs();
        let (w, f, o) = (windows.window, windows.n_features, windows.n_outputs);
        let std = net.decoder.output_standardizer().std();
        let (mut standardised, mut original) = (0.0, 0.0);
        let mut start = 0;
        while start < windows.len() {
            let count = capacity.min(windows.len() - start);
            for slot in 0..count {
                let r = start + slot;
                self.load(
                    net,
                    slot,
                    &windows.features[r * w * f..(r + 1) * w * f],
                    &windows.targets[r * o..(r + 1) * o],
                );
            }
            self.forward(net, count);
            let out = &self.decoder.acts[net.decoder.n_layers()];
            for (k, (p, t)) in out[..count * o].iter().zip(&self.targets[..count * o]).enumerate() {
                let r = p - t;
                standardised += r * r;
                original += (r * std[k % o]).powi(2);
            }
            start += count;
        }
        let denom = (windows.len() * o) as f64;
        (standardised / denom, original / denom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_identify::simulate::Gaussian;

    /// Windows of `(a, b)` pairs with `b = slope · a + noise`, target the least
    /// squares slope `Σab / Σa²`: a ratio of window means, what a deep set is for.
    struct Slopes {
        windows: Vec<(Vec<f64>, f64)>,
        window: usize,
    }

    impl Slopes {
        fn new(count: usize, window: usize, seed: u64) -> Slopes {
            let mut g = Gaussian::new(seed);
            let windows = (0..count)
                .map(|_| {
                    let slope = 1.0 + 0.5 * g.standard();
                    let mut features = Vec::with_capacity(2 * window);
                    let (mut ab, mut aa) = (0.0, 0.0);
                    for _ in 0..window {
                        let a = 1.0 + g.standard();
                        let b = slope * a + 0.1 * g.standard();
                        features.extend([a, b]);
                        ab += a * b;
                        aa += a * a;
                    }
                    (features, ab / aa)
                })
                .collect();
            Slopes { windows, window }
        }
    }

    impl WindowSource for Slopes {
        fn n_features(&self) -> usize {
            2
        }
        fn n_outputs(&self) -> usize {
            1
        }
        fn window(&self) -> usize {
            self.window
        }
        fn len(&self) -> usize {
            self.windows.len()
        }
        fn fill(&self, index: usize, features: &mut [f64], target: &mut [f64]) {
            features.copy_from_slice(&self.windows[index].0);
            target[0] = self.windows[index].1;
        }
    }

    fn shape() -> WindowShape {
        WindowShape {
            encoder: vec![16, 16, 8],
            decoder: vec![16],
        }
    }

    /// The loss of one batch through [`Pass::step`] against central differences on
    /// every parameter of both nets.
    #[test]
    fn window_gradients_match_finite_differences() {
        let source = Slopes::new(5, 4, 3);
        let mut net = WindowNet::new(2, &shape(), 1, 5).unwrap();
        for b in net.encoder.parameters_mut().chain(net.decoder.parameters_mut()) {
            for (k, v) in b.iter_mut().enumerate() {
                *v += 0.01 * (k % 5) as f64 + 0.003;
            }
        }
        let mut pass = Pass::new(&net, 5, 4);
        let (mut f, mut t) = (vec![0.0; 8], [0.0]);
        let load = |pass: &mut Pass, net: &WindowNet| {
            let (mut f, mut t) = (vec![0.0; 8], [0.0]);
            for slot in 0..5 {
                source.fill(slot, &mut f, &mut t);
                pass.load(net, slot, &f, &t);
            }
        };
        source.fill(0, &mut f, &mut t);
        load(&mut pass, &net);
        pass.step(&net, 5);
        let analytic: Vec<Vec<f64>> = pass
            .encoder
            .grads
            .buffers()
            .chain(pass.decoder.grads.buffers())
            .map(<[f64]>::to_vec)
            .collect();
        let loss = |net: &WindowNet| {
            let mut p = Pass::new(net, 5, 4);
            load(&mut p, net);
            p.forward(net, 5);
            p.decoder.mse_delta(&net.decoder, &p.targets, 5)
        };
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for (b, grad) in analytic.iter().enumerate() {
            for k in 0..grad.len() {
                let bump = |net: &mut WindowNet, d: f64| {
                    net.encoder
                        .parameters_mut()
                        .chain(net.decoder.parameters_mut())
                        .nth(b)
                        .unwrap()[k] += d;
                };
                bump(&mut net, h);
                let up = loss(&net);
                bump(&mut net, -2.0 * h);
                let down = loss(&net);
                bump(&mut net, h);
                worst = worst.max(((up - down) / (2.0 * h) - grad[k]).abs() / (1e-3 + grad[k].abs()));
            }
        }
        assert!(worst < 1e-5, "worst relative gradient error {worst:e}");
    }

    #[test]
    fn a_window_net_learns_a_least_squares_slope() {
        let train = Slopes::new(3000, 12, 1);
        let check = Slopes::new(300, 12, 2);
        let options = TrainOptions {
            optimizer: Optimizer::adam(3e-3),
            max_steps: 2500,
            record_every: 500,
            seed: 3,
            ..TrainOptions::default()
        };
        let (net, history) = train_windows(2, &shape(), &train, Some(&check), &options).unwrap();
        let rms = history.validation_mse_original.last().unwrap().sqrt();
        // The slopes spread with σ = 0.5; the net gets them within a few percent.
        assert!(rms < 0.05, "validation RMS {rms}, history {history:?}");
        // One window through `predict` agrees with the batch path, and survives JSON.
        let mut ws = net.workspace();
        let (mut f, mut t, mut out) = (vec![0.0; 24], [0.0], [0.0]);
        check.fill(7, &mut f, &mut t);
        net.predict(&f, &mut ws, &mut out);
        assert!((out[0] - t[0]).abs() < 0.2, "{} vs {}", out[0], t[0]);
        let again = WindowNet::from_json(&net.to_json()).unwrap();
        let mut out2 = [0.0];
        again.predict(&f, &mut again.workspace(), &mut out2);
        assert_eq!(out[0].to_bits(), out2[0].to_bits());
        // The mean makes the order of the samples irrelevant.
        let mut reversed: Vec<f64> = f.chunks_exact(2).rev().flatten().copied().collect();
        net.predict(&reversed, &mut ws, &mut out2);
        assert!((out[0] - out2[0]).abs() < 1e-12);
        reversed.truncate(4);
        net.predict(&reversed, &mut ws, &mut out2); // any window length
    }

    #[test]
    fn window_training_refuses_what_it_cannot_do() {
        let data = Slopes::new(10, 4, 1);
        let gd = TrainOptions {
            optimizer: Optimizer::GradientDescent { learning_rate: 0.1 },
            ..TrainOptions::default()
        };
        let err = train_windows(2, &shape(), &data, None, &gd).unwrap_err();
        assert!(err.to_string().contains("trains with Optimizer::Adam"), "{err}");
        let err = train_windows(3, &shape(), &data, None, &TrainOptions::default()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "dimension mismatch in features per sample of the windows: expected 3, found 2"
        );
        let other = Slopes::new(10, 5, 1);
        let err = train_windows(2, &shape(), &data, Some(&other), &TrainOptions::default()).unwrap_err();
        assert!(
            err.to_string().contains("samples per window: expected 4, found 5"),
            "{err}"
        );
        let empty = Slopes::new(0, 4, 1);
        let err = train_windows(2, &shape(), &empty, None, &TrainOptions::default()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the training set of windows has no samples; at least one is needed"
        );
        let err = WindowNet::new(
            2,
            &WindowShape {
                encoder: vec![],
                decoder: vec![4],
            },
            1,
            1,
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("the encoder needs at least one layer"),
            "{err}"
        );
        let json = WindowNet::new(2, &shape(), 1, 1).unwrap().to_json();
        let err = WindowNet::from_json(&json.replace(WINDOW_SCHEMA, "x")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "unsupported schema \"x\": this version reads \"dyngen-window-net/1\""
        );
    }
}
