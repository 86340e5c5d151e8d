//! Training: hand-written backpropagation over faer matrix products, full-batch
//! gradient descent and mini-batch Adam, stopping at an MSE threshold or a step
//! budget.

use super::data::{shuffle, Dataset, Standardizer};
use super::error::NimError;
use super::mlp::{check_sizes, Mlp, Mse};
use dyngen_identify::faer::linalg::matmul::matmul;
use dyngen_identify::faer::{Accum, MatMut, MatRef, Par};
use dyngen_reference::SplitMix64;

/// How parameters are updated from the gradient of the training loss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Optimizer {
    /// Full-batch gradient descent, `θ ← θ − η ∇L(θ)` with `L` the MSE over the
    /// whole training set (the paper's method). One step = one pass over all
    /// training samples.
    GradientDescent { learning_rate: f64 },
    /// Adam (Kingma and Ba, 2015) with bias correction on mini-batches of
    /// `batch_size` samples. The training samples are reshuffled at the start of every
    /// epoch; the last batch of an epoch takes the remainder and may be smaller. A
    /// `batch_size` of at least the training-set size is full-batch Adam. One step =
    /// one mini-batch.
    Adam {
        learning_rate: f64,
        beta1: f64,
        beta2: f64,
        epsilon: f64,
        batch_size: usize,
    },
}

impl Optimizer {
    /// Adam with the usual `β1 = 0.9`, `β2 = 0.999`, `ε = 10⁻⁸` and batches of 32.
    pub fn adam(learning_rate: f64) -> Optimizer {
        Optimizer::Adam {
            learning_rate,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
            batch_size: 32,
        }
    }
}

impl Default for Optimizer {
    /// [`Optimizer::adam`]`(1e-3)`.
    fn default() -> Optimizer {
        Optimizer::adam(1e-3)
    }
}

/// Settings of [`train`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrainOptions {
    pub optimizer: Optimizer,
    /// The step budget: at most this many parameter updates (see [`Optimizer`] for
    /// what one step is).
    pub max_steps: usize,
    /// Stop as soon as the training MSE, over the whole training set in
    /// standardised output units ([`Mse::standardised`]), is at or below this.
    /// Checked before every step with [`Optimizer::GradientDescent`] (its full-batch
    /// forward pass gives that MSE at no extra cost) and at every record point with
    /// [`Optimizer::Adam`] (see `record_every`). `None`: run the whole budget.
    pub mse_threshold: Option<f64>,
    /// Seeds the He initialisation ([`Mlp::new`]) and, with Adam, the mini-batch
    /// shuffling (an independent [`SplitMix64`] stream derived from it).
    pub seed: u64,
    /// The history records the state after step 0 (the initial net), every
    /// `record_every` steps, and the last step; at least 1.
    pub record_every: usize,
    /// How the learning rate changes over the step budget.
    pub decay: Decay,
}

/// Learning-rate schedule over the step budget `T` ([`TrainOptions::max_steps`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Decay {
    /// The optimizer's learning rate throughout.
    #[default]
    Constant,
    /// Cosine annealing (Loshchilov and Hutter, 2017) from the learning rate `η` at
    /// step 0 to `final_fraction · η` at step `T`:
    /// `η_t = η (f + (1 − f)(1 + cos(π t / T)) / 2)`.
    Cosine { final_fraction: f64 },
}

impl Decay {
    /// The factor on the learning rate at `step` of `budget`.
    pub(crate) fn factor(self, step: usize, budget: usize) -> f64 {
        match self {
            Decay::Constant => 1.0,
            Decay::Cosine { final_fraction: f } => {
                let progress = step as f64 / budget.max(1) as f64;
                f + (1.0 - f) * 0.5 * (1.0 + (std::f64::consts::PI * progress.min(1.0)).cos())
            }
        }
    }
}

impl Default for TrainOptions {
    /// Adam ([`Optimizer::default`]), 10 000 steps, no threshold, seed 0, a record
    /// every 100 steps, a constant learning rate.
    fn default() -> TrainOptions {
        TrainOptions {
            optimizer: Optimizer::default(),
            max_steps: 10_000,
            mse_threshold: None,
            seed: 0,
            record_every: 100,
            decay: Decay::Constant,
        }
    }
}

/// Why training stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The training MSE reached [`TrainOptions::mse_threshold`].
    Threshold,
    /// [`TrainOptions::max_steps`] steps were taken.
    Budget,
}

impl Default for TrainHistory {
    /// No record points yet, [`StopReason::Budget`].
    fn default() -> TrainHistory {
        TrainHistory {
            steps: Vec::new(),
            train_mse: Vec::new(),
            train_mse_original: Vec::new(),
            validation_mse: Vec::new(),
            validation_mse_original: Vec::new(),
            stopped: StopReason::Budget,
            steps_taken: 0,
        }
    }
}

/// The loss curves of one [`train`] call, one entry per record point (see
/// [`TrainOptions::record_every`]). Every MSE is over all samples and outputs of
/// its set, computed with the final standardisers (fitted on the training set).
#[derive(Clone, Debug, PartialEq)]
pub struct TrainHistory {
    /// Steps taken at each record point: `0, r, 2r, …` and the last step.
    pub steps: Vec<usize>,
    /// Training-set MSE in standardised output units (the loss).
    pub train_mse: Vec<f64>,
    /// Training-set MSE in the targets' original units.
    pub train_mse_original: Vec<f64>,
    /// Validation-set MSE in standardised output units; empty without a
    /// validation set.
    pub validation_mse: Vec<f64>,
    /// Validation-set MSE in original units; empty without a validation set.
    pub validation_mse_original: Vec<f64>,
    pub stopped: StopReason,
    /// Parameter updates made (the last entry of `steps`).
    pub steps_taken: usize,
}

/// Trains a fresh net of layer sizes `[n_in, h1, …, hk, n_out]` on `train`:
/// standardisers fitted on the training set ([`Standardizer::fit`]), He
/// initialisation from `options.seed`, then [`TrainOptions::optimizer`] steps on the
/// MSE in standardised units until the threshold or the budget. The optional
/// `validation` set is only evaluated (at record points), never trained on.
///
/// The result depends only on the arguments: the same call gives bit-identical
/// weights on the same build and machine (faer runs sequentially, [`Par::Seq`]).
///
/// Errors on invalid sizes or options, datasets whose widths do not match `sizes`,
/// and a diverging loss ([`NimError::Diverged`]).
///
/// ```
/// use dyngen_nim::{train, Dataset, Optimizer, StopReason, TrainOptions};
/// let x: Vec<[f64; 1]> = (0..40).map(|k| [k as f64 / 40.0]).collect();
/// let y: Vec<[f64; 1]> = x.iter().map(|x| [3.0 * x[0] + 1.0]).collect();
/// let (fit, check) = Dataset::from_rows(&x, &y).unwrap().split(0.8).unwrap();
/// let options = TrainOptions {
///     optimizer: Optimizer::GradientDescent { learning_rate: 0.05 },
///     max_steps: 5_000,
///     mse_threshold: Some(1e-4),
///     ..TrainOptions::default()
/// };
/// let (net, history) = train(&[1, 8, 1], &fit, Some(&check), &options).unwrap();
/// assert_eq!(history.stopped, StopReason::Threshold);
/// let mut y = [0.0];
/// net.predict(&[0.5], &mut net.workspace(), &mut y);
/// assert!((y[0] - 2.5).abs() < 0.05);
/// ```
pub fn train(
    sizes: &[usize],
    train: &Dataset,
    validation: Option<&Dataset>,
    options: &TrainOptions,
) -> Result<(Mlp, TrainHistory), NimError> {
    check_sizes(sizes)?;
    validate(options)?;
    let mut mlp = Mlp::new(sizes, options.seed)?;
    mlp.check_dataset(
        train,
        ["training set inputs per sample", "training set targets per sample"],
    )?;
    if let Some(v) = validation {
        mlp.check_dataset(
            v,
            ["validation set inputs per sample", "validation set targets per sample"],
        )?;
    }
    mlp.set_standardizers(Standardizer::fit(train.inputs()), Standardizer::fit(train.targets()))?;
    let history = Trainer::new(&mlp, train, validation, options).run(&mut mlp)?;
    Ok((mlp, history))
}

pub(crate) fn validate(options: &TrainOptions) -> Result<(), NimError> {
    let invalid = |field, reason: String| Err(NimError::InvalidOption { field, reason });
    let positive = |field, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            invalid(field, format!("{v}; expected a finite number > 0"))
        }
    };
    match options.optimizer {
        Optimizer::GradientDescent { learning_rate } => positive("learning_rate", learning_rate)?,
        Optimizer::Adam {
            learning_rate,
            beta1,
            beta2,
            epsilon,
            batch_size,
        } => {
            positive("learning_rate", learning_rate)?;
            positive("epsilon", epsilon)?;
            for (field, beta) in [("beta1", beta1), ("beta2", beta2)] {
                if !(0.0..1.0).contains(&beta) {
                    return invalid(field, format!("{beta}; expected 0 ≤ β < 1"));
                }
            }
            if batch_size == 0 {
                return invalid("batch_size", "0; expected at least 1".into());
            }
        }
    }
    if let Some(t) = options.mse_threshold {
        if !(t.is_finite() && t >= 0.0) {
            return invalid("mse_threshold", format!("{t}; expected a finite number ≥ 0"));
        }
    }
    if options.record_every == 0 {
        return invalid("record_every", "0; expected at least 1".into());
    }
    if let Decay::Cosine { final_fraction } = options.decay {
        if !(0.0..=1.0).contains(&final_fraction) {
            return invalid("final_fraction", format!("{final_fraction}; expected 0 ≤ f ≤ 1"));
        }
    }
    Ok(())
}

/// Gradients of the loss, shaped like the net's parameters.
#[derive(Clone, Debug)]
pub(crate) struct Gradients {
    /// Layer `l`: `sizes[l + 1] × sizes[l]`, column-major, as the weights.
    pub w: Vec<Vec<f64>>,
    pub b: Vec<Vec<f64>>,
}

impl Gradients {
    fn zeros(mlp: &Mlp) -> Gradients {
        Gradients {
            w: (0..mlp.n_layers())
                .map(|l| vec![0.0; mlp.weights(l).nrows() * mlp.weights(l).ncols()])
                .collect(),
            b: (0..mlp.n_layers()).map(|l| vec![0.0; mlp.bias(l).len()]).collect(),
        }
    }

    /// Weights then biases, in the order of [`Mlp::parameters_mut`].
    pub fn buffers(&self) -> impl Iterator<Item = &[f64]> {
        self.w.iter().chain(&self.b).map(Vec::as_slice)
    }
}

/// Forward and backward buffers for up to `capacity` samples as columns.
pub(crate) struct Backprop {
    /// `acts[0]`: the standardised inputs; `acts[l]`, `l ≥ 1`: layer `l`'s output
    /// (after the ReLU for hidden layers).
    pub acts: Vec<Vec<f64>>,
    /// `deltas[l]`, `l ≥ 1`: `∂L/∂z_l` (before the activation). `deltas[0]`:
    /// `∂L/∂(input)` when the buffers were made with `input_gradient`, else empty.
    pub deltas: Vec<Vec<f64>>,
    pub grads: Gradients,
}

impl Backprop {
    pub fn new(mlp: &Mlp, capacity: usize, input_gradient: bool) -> Backprop {
        let mut deltas = mlp.batch_buffers(capacity);
        if !input_gradient {
            deltas[0] = Vec::new();
        }
        Backprop {
            acts: mlp.batch_buffers(capacity),
            deltas,
            grads: Gradients::zeros(mlp),
        }
    }

    /// After [`Mlp::forward`] on the first `count` columns of `acts`: the output
    /// delta of `L = Σ (ŷ − y)² / (count · n_out)` into `deltas[L]`, `targets`
    /// standardised with samples as columns, `δ_L = 2 (ŷ − y) / (count · n_out)`.
    /// Returns `L`.
    pub fn mse_delta(&mut self, mlp: &Mlp, targets: &[f64], count: usize) -> f64 {
        let layers = mlp.n_layers();
        let total = mlp.n_outputs() * count;
        let scale = 2.0 / total as f64;
        let mut loss = 0.0;
        for ((d, &p), &y) in self.deltas[layers][..total]
            .iter_mut()
            .zip(&self.acts[layers][..total])
            .zip(&targets[..total])
        {
            let r = p - y;
            loss += r * r;
            *d = scale * r;
        }
        loss / total as f64
    }

    /// From the output delta in `deltas[L]` (first `count` columns): the gradient
    /// of the loss with respect to every weight and bias into `grads`, and
    /// `∂L/∂(input)` into `deltas[0]` when it was asked for.
    ///
    /// `∂L/∂W_l = δ_{l+1} a_lᵀ`, `∂L/∂b_l = δ_{l+1} 1`,
    /// `δ_l = (W_lᵀ δ_{l+1}) ⊙ [a_l > 0]` (no ReLU factor for the input).
    pub fn backward(&mut self, mlp: &Mlp, count: usize) {
        let sizes = mlp.sizes();
        let input_gradient = !self.deltas[0].is_empty();
        for l in (0..mlp.n_layers()).rev() {
            let (n_in, n_o) = (sizes[l], sizes[l + 1]);
            let (lo, hi) = self.deltas.split_at_mut(l + 1);
            let delta = &hi[0][..n_o * count];
            let d = MatRef::from_column_major_slice(delta, n_o, count);
            let a = MatRef::from_column_major_slice(&self.acts[l][..n_in * count], n_in, count);
            matmul(
                MatMut::from_column_major_slice_mut(&mut self.grads.w[l], n_o, n_in),
                Accum::Replace,
                d,
                a.transpose(),
                1.0,
                Par::Seq,
            );
            let gb = &mut self.grads.b[l];
            gb.fill(0.0);
            for col in delta.chunks_exact(n_o) {
                for (g, &v) in gb.iter_mut().zip(col) {
                    *g += v;
                }
            }
            if l > 0 || input_gradient {
                let prev = &mut lo[l][..n_in * count];
                matmul(
                    MatMut::from_column_major_slice_mut(prev, n_in, count),
                    Accum::Replace,
                    mlp.weights(l).transpose(),
                    d,
                    1.0,
                    Par::Seq,
                );
                if l > 0 {
                    for (p, &a) in prev.iter_mut().zip(&self.acts[l][..n_in * count]) {
                        if a <= 0.0 {
                            *p = 0.0;
                        }
                    }
                }
            }
        }
    }
}

/// Adam's first and second moment estimates for a list of parameter buffers, and
/// the running `β^t`.
pub(crate) struct AdamState {
    m: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
    beta1_t: f64,
    beta2_t: f64,
}

impl AdamState {
    /// Zero moments for buffers of these lengths.
    pub fn new(lengths: impl Iterator<Item = usize>) -> AdamState {
        let m: Vec<Vec<f64>> = lengths.map(|n| vec![0.0; n]).collect();
        AdamState {
            v: m.clone(),
            m,
            beta1_t: 1.0,
            beta2_t: 1.0,
        }
    }

    /// One bias-corrected Adam update of `params` (buffer by buffer, as at
    /// construction) with the gradients `grads` and learning rate `learning_rate`.
    pub fn step<'p, 'g>(
        &mut self,
        params: impl Iterator<Item = &'p mut [f64]>,
        grads: impl Iterator<Item = &'g [f64]>,
        learning_rate: f64,
        beta1: f64,
        beta2: f64,
        epsilon: f64,
    ) {
        self.beta1_t *= beta1;
        self.beta2_t *= beta2;
        let (c1, c2) = (1.0 - self.beta1_t, 1.0 - self.beta2_t);
        for (((p, g), m), v) in params.zip(grads).zip(&mut self.m).zip(&mut self.v) {
            for (((p, &g), m), v) in p.iter_mut().zip(g).zip(m.iter_mut()).zip(v.iter_mut()) {
                *m = beta1 * *m + (1.0 - beta1) * g;
                *v = beta2 * *v + (1.0 - beta2) * g * g;
                *p -= learning_rate * (*m / c1) / ((*v / c2).sqrt() + epsilon);
            }
        }
    }
}

/// Salt for the mini-batch shuffling stream, so that it is not the He
/// initialisation's stream for the same seed.
const SHUFFLE_SALT: u64 = 0x6E69_6D2D_7368_7566;

struct Trainer<'a> {
    options: &'a TrainOptions,
    /// Training inputs standardised, samples as columns.
    x: Vec<f64>,
    /// Training targets standardised, samples as columns.
    y: Vec<f64>,
    n: usize,
    /// Full-batch buffers (`acts[0] = x`); the working buffers of gradient descent.
    full: Backprop,
    /// Adam's mini-batch buffers and targets.
    batch: Option<(Backprop, Vec<f64>)>,
    adam: Option<AdamState>,
    order: Vec<usize>,
    cursor: usize,
    rng: SplitMix64,
    /// Validation layer buffers (`[0]` = standardised inputs) and standardised
    /// targets.
    validation: Option<(Vec<Vec<f64>>, Vec<f64>, usize)>,
}

impl<'a> Trainer<'a> {
    fn new(mlp: &Mlp, train: &Dataset, validation: Option<&Dataset>, options: &'a TrainOptions) -> Trainer<'a> {
        let n = train.len();
        let mut full = Backprop::new(mlp, n, false);
        mlp.standardise_inputs(train.inputs(), &mut full.acts[0]);
        let (batch, adam) = match options.optimizer {
            Optimizer::GradientDescent { .. } => (None, None),
            Optimizer::Adam { batch_size, .. } => {
                let size = batch_size.min(n);
                (
                    Some((Backprop::new(mlp, size, false), vec![0.0; size * mlp.n_outputs()])),
                    Some(AdamState::new(mlp.parameter_lengths())),
                )
            }
        };
        let validation = validation.map(|v| {
            let mut acts = mlp.batch_buffers(v.len());
            mlp.standardise_inputs(v.inputs(), &mut acts[0]);
            (acts, mlp.standardise_targets(v.targets()), v.len())
        });
        Trainer {
            options,
            x: full.acts[0].clone(),
            y: mlp.standardise_targets(train.targets()),
            n,
            full,
            batch,
            adam,
            order: (0..n).collect(),
            cursor: n,
            rng: SplitMix64::new(options.seed ^ SHUFFLE_SALT),
            validation,
        }
    }

    fn run(mut self, mlp: &mut Mlp) -> Result<TrainHistory, NimError> {
        let o = self.options;
        let gd = matches!(o.optimizer, Optimizer::GradientDescent { .. });
        let mut history = TrainHistory::default();
        let layers = mlp.n_layers();
        let mut step = 0;
        loop {
            let record = step % o.record_every == 0 || step == o.max_steps;
            // The training MSE at the current parameters: every step for gradient
            // descent (whose step needs this forward pass anyway), at record points
            // for Adam.
            let mse = if gd || record {
                mlp.forward(&mut self.full.acts, self.n);
                let mse = mlp.mse(&self.full.acts[layers], &self.y);
                if !mse.standardised.is_finite() {
                    return Err(NimError::Diverged {
                        step,
                        mse: mse.standardised,
                    });
                }
                Some(mse)
            } else {
                None
            };
            let stop = match (o.mse_threshold, mse) {
                (Some(threshold), Some(mse)) if mse.standardised <= threshold => Some(StopReason::Threshold),
                _ if step == o.max_steps => Some(StopReason::Budget),
                _ => None,
            };
            if let (true, Some(mse)) = (record || stop.is_some(), mse) {
                self.record(mlp, &mut history, step, mse);
            }
            if let Some(reason) = stop {
                history.stopped = reason;
                history.steps_taken = step;
                return Ok(history);
            }
            let rate = o.decay.factor(step, o.max_steps);
            let loss = match o.optimizer {
                Optimizer::GradientDescent { learning_rate } => {
                    let loss = self.full.mse_delta(mlp, &self.y, self.n);
                    self.full.backward(mlp, self.n);
                    for (p, g) in mlp.parameters_mut().zip(self.full.grads.buffers()) {
                        for (p, &g) in p.iter_mut().zip(g) {
                            *p -= rate * learning_rate * g;
                        }
                    }
                    loss
                }
                Optimizer::Adam { .. } => self.adam_step(mlp, rate),
            };
            if !loss.is_finite() {
                return Err(NimError::Diverged { step, mse: loss });
            }
            step += 1;
        }
    }

    fn record(&mut self, mlp: &Mlp, history: &mut TrainHistory, step: usize, mse: Mse) {
        history.steps.push(step);
        history.train_mse.push(mse.standardised);
        history.train_mse_original.push(mse.original);
        if let Some((acts, targets, count)) = &mut self.validation {
            mlp.forward(acts, *count);
            let v = mlp.mse(&acts[mlp.n_layers()], targets);
            history.validation_mse.push(v.standardised);
            history.validation_mse_original.push(v.original);
        }
    }

    /// One Adam update on the next mini-batch, the learning rate scaled by `rate`;
    /// returns the mini-batch loss.
    fn adam_step(&mut self, mlp: &mut Mlp, rate: f64) -> f64 {
        let Optimizer::Adam {
            learning_rate,
            beta1,
            beta2,
            epsilon,
            batch_size,
        } = self.options.optimizer
        else {
            unreachable!("adam_step with another optimizer")
        };
        let (bp, targets) = self.batch.as_mut().expect("Adam buffers");
        let state = self.adam.as_mut().expect("Adam state");
        if self.cursor >= self.n {
            shuffle(&mut self.order, &mut self.rng);
            self.cursor = 0;
        }
        let count = batch_size.min(self.n - self.cursor);
        let (n_in, n_out) = (mlp.n_inputs(), mlp.n_outputs());
        for (c, &k) in self.order[self.cursor..self.cursor + count].iter().enumerate() {
            bp.acts[0][c * n_in..(c + 1) * n_in].copy_from_slice(&self.x[k * n_in..(k + 1) * n_in]);
            targets[c * n_out..(c + 1) * n_out].copy_from_slice(&self.y[k * n_out..(k + 1) * n_out]);
        }
        self.cursor += count;
        mlp.forward(&mut bp.acts, count);
        let loss = bp.mse_delta(mlp, targets, count);
        bp.backward(mlp, count);
        state.step(
            mlp.parameters_mut(),
            bp.grads.buffers(),
            rate * learning_rate,
            beta1,
            beta2,
            epsilon,
        );
        loss
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dyngen_identify::simulate::Gaussian;

    /// Random inputs and targets, samples as columns (already "standardised").
    fn batch(n_in: usize, n_out: usize, count: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut g = Gaussian::new(seed);
        let x = (0..n_in * count).map(|_| g.standard()).collect();
        let y = (0..n_out * count).map(|_| g.standard()).collect();
        (x, y)
    }

    fn loss(mlp: &Mlp, x: &[f64], y: &[f64], count: usize) -> f64 {
        let mut bp = Backprop::new(mlp, count, false);
        bp.acts[0][..x.len()].copy_from_slice(x);
        mlp.forward(&mut bp.acts, count);
        bp.mse_delta(mlp, y, count)
    }

    /// Backpropagation against central differences, every weight and bias, and the
    /// input gradient, on nets of several shapes.
    #[test]
    fn gradients_match_finite_differences() {
        for (sizes, count, seed) in [
            (&[3, 5, 2][..], 7, 1),
            (&[4, 6, 5, 3], 5, 2),
            (&[2, 3, 3, 3, 3, 3, 1], 9, 3),
        ] {
            let mut mlp = Mlp::new(sizes, seed).unwrap();
            // Non-zero biases: with a zero bias, a unit whose inputs are all dead sits
            // exactly on the ReLU's kink, where no finite difference is a derivative.
            for b in mlp.parameters_mut().skip(sizes.len() - 1) {
                for (k, v) in b.iter_mut().enumerate() {
                    *v = 0.1 * (k % 3) as f64 - 0.05;
                }
            }
            let (n_in, n_out) = (sizes[0], sizes[sizes.len() - 1]);
            let (x, y) = batch(n_in, n_out, count, seed + 10);
            let mut bp = Backprop::new(&mlp, count, true);
            bp.acts[0].copy_from_slice(&x);
            mlp.forward(&mut bp.acts, count);
            bp.mse_delta(&mlp, &y, count);
            bp.backward(&mlp, count);
            let analytic: Vec<Vec<f64>> = bp.grads.buffers().map(<[f64]>::to_vec).collect();

            let h = 1e-6;
            let mut worst: f64 = 0.0;
            for (b, grad) in analytic.iter().enumerate() {
                for k in 0..grad.len() {
                    let bump = |mlp: &mut Mlp, delta: f64| {
                        mlp.parameters_mut().nth(b).unwrap()[k] += delta;
                    };
                    bump(&mut mlp, h);
                    let up = loss(&mlp, &x, &y, count);
                    bump(&mut mlp, -2.0 * h);
                    let down = loss(&mlp, &x, &y, count);
                    bump(&mut mlp, h);
                    let numeric = (up - down) / (2.0 * h);
                    worst = worst.max((numeric - grad[k]).abs() / (1e-3 + grad[k].abs()));
                }
            }
            assert!(worst < 1e-5, "{sizes:?}: worst relative gradient error {worst:e}");
            // ∂L/∂input.
            for j in 0..n_in * count {
                let mut xp = x.clone();
                xp[j] += h;
                let up = loss(&mlp, &xp, &y, count);
                xp[j] -= 2.0 * h;
                let down = loss(&mlp, &xp, &y, count);
                let numeric = (up - down) / (2.0 * h);
                assert!(
                    (numeric - bp.deltas[0][j]).abs() < 1e-6 * (1.0 + numeric.abs()),
                    "input {j}"
                );
            }
        }
    }

    fn linear_data(count: usize) -> Dataset {
        let x: Vec<[f64; 2]> = (0..count).map(|k| [k as f64 / count as f64, (k % 7) as f64]).collect();
        let y: Vec<[f64; 1]> = x.iter().map(|x| [2.0 * x[0] - 0.5 * x[1] + 1.0]).collect();
        Dataset::from_rows(&x, &y).unwrap()
    }

    #[test]
    fn training_is_deterministic_for_a_seed() {
        let data = linear_data(50);
        let options = TrainOptions {
            max_steps: 300,
            record_every: 50,
            seed: 7,
            ..TrainOptions::default()
        };
        let (a, ha) = train(&[2, 8, 1], &data, None, &options).unwrap();
        let (b, hb) = train(&[2, 8, 1], &data, None, &options).unwrap();
        assert_eq!(a.to_json(), b.to_json());
        assert_eq!(ha, hb);
        let (c, _) = train(&[2, 8, 1], &data, None, &TrainOptions { seed: 8, ..options }).unwrap();
        assert_ne!(a.to_json(), c.to_json());
    }

    #[test]
    fn history_records_every_step_asked_and_the_last() {
        let data = linear_data(40);
        let options = TrainOptions {
            max_steps: 25,
            record_every: 10,
            ..TrainOptions::default()
        };
        let (_, h) = train(&[2, 4, 1], &data, Some(&data), &options).unwrap();
        assert_eq!(h.steps, [0, 10, 20, 25]);
        assert_eq!((h.train_mse.len(), h.validation_mse.len()), (4, 4));
        assert_eq!((h.stopped, h.steps_taken), (StopReason::Budget, 25));
        // Adam lowers the loss on a linear target.
        assert!(h.train_mse[3] < h.train_mse[0]);
    }

    #[test]
    fn cosine_decay_runs_from_the_rate_to_its_fraction() {
        let d = Decay::Cosine { final_fraction: 0.1 };
        assert_eq!(d.factor(0, 100), 1.0);
        assert!((d.factor(50, 100) - 0.55).abs() < 1e-12);
        assert!((d.factor(100, 100) - 0.1).abs() < 1e-12);
        assert_eq!(Decay::Constant.factor(70, 100), 1.0);
    }

    #[test]
    fn bad_options_and_divergence_are_errors() {
        let data = linear_data(20);
        let invalid = |options: TrainOptions, field: &str| {
            let err = train(&[2, 4, 1], &data, None, &options).unwrap_err();
            assert!(
                matches!(&err, NimError::InvalidOption { field: f, .. } if *f == field),
                "{err}"
            );
        };
        invalid(
            TrainOptions {
                optimizer: Optimizer::GradientDescent { learning_rate: -1.0 },
                ..TrainOptions::default()
            },
            "learning_rate",
        );
        invalid(
            TrainOptions {
                record_every: 0,
                ..TrainOptions::default()
            },
            "record_every",
        );
        invalid(
            TrainOptions {
                mse_threshold: Some(f64::NAN),
                ..TrainOptions::default()
            },
            "mse_threshold",
        );
        invalid(
            TrainOptions {
                decay: Decay::Cosine { final_fraction: 2.0 },
                ..TrainOptions::default()
            },
            "final_fraction",
        );
        let wide = Dataset::from_rows(&[[1.0, 2.0, 3.0]], &[[1.0]]).unwrap();
        let err = train(&[2, 4, 1], &wide, None, &TrainOptions::default()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "dimension mismatch in training set inputs per sample: expected 2, found 3"
        );
        let err = train(
            &[2, 4, 1],
            &data,
            None,
            &TrainOptions {
                optimizer: Optimizer::GradientDescent { learning_rate: 1e6 },
                max_steps: 200,
                ..TrainOptions::default()
            },
        )
        .unwrap_err();
        assert!(matches!(err, NimError::Diverged { .. }), "{err}");
        assert!(err.to_string().contains("lower the learning rate"), "{err}");
    }
}
