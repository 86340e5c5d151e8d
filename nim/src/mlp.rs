//! The network itself: [`Mlp`] (weights, biases, standardisers), allocation-free
//! inference through a [`Workspace`], batch inference and evaluation over faer, and
//! the JSON file format.

use super::data::{Dataset, Standardizer};
use super::error::NimError;
use dyngen_identify::faer::linalg::matmul::matmul;
use dyngen_identify::faer::{Accum, Mat, MatMut, MatRef, Par};
use dyngen_identify::simulate::Gaussian;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The `schema` string of the JSON format [`Mlp::to_json`] writes and
/// [`Mlp::from_json`] reads.
pub const SCHEMA: &str = "dyngen-mlp/1";

/// A multilayer perceptron `n_in → h1 → … → hk → n_out`: ReLU on every hidden layer,
/// a linear output layer, and a [`Standardizer`] on each side, so that callers see
/// inputs and outputs in their original units.
///
/// With `x` the input, `z0 = S_in(x)` standardised, `z_{l+1} = W_l z_l + b_l` followed
/// by `max(0, ·)` for every layer but the last, and the output is `S_out⁻¹(z_L)`.
/// `W_l` is `sizes[l + 1] × sizes[l]` (rows are the layer's outputs).
///
/// ```
/// use dyngen_nim::Mlp;
/// let net = Mlp::new(&[3, 8, 2], 7).unwrap();
/// let mut ws = net.workspace();
/// let mut y = [0.0; 2];
/// net.predict(&[0.1, -0.2, 0.3], &mut ws, &mut y); // no allocation
/// let again = Mlp::from_json(&net.to_json()).unwrap();
/// let mut y2 = [0.0; 2];
/// again.predict(&[0.1, -0.2, 0.3], &mut ws, &mut y2);
/// assert_eq!(y.map(f64::to_bits), y2.map(f64::to_bits));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Mlp {
    sizes: Vec<usize>,
    /// Layer `l`: `sizes[l + 1] × sizes[l]`, column-major.
    weights: Vec<Vec<f64>>,
    biases: Vec<Vec<f64>>,
    input: Standardizer,
    output: Standardizer,
    /// The widest layer: the length of each [`Workspace`] buffer.
    width: usize,
}

/// Mean squared error over every sample and output of a dataset, in two units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mse {
    /// In standardised output units (each target divided by the training standard
    /// deviation of its output): comparable across outputs of different scale. The
    /// training loss and the stopping threshold are this.
    pub standardised: f64,
    /// In the targets' original units: `mean((ŷ − y)²)` over samples and outputs.
    pub original: f64,
}

/// Buffers for [`Mlp::predict`]: two vectors as long as the widest layer, filled
/// alternately layer by layer. Make one per thread with [`Mlp::workspace`] and reuse
/// it; it fits any net whose widest layer is not wider.
#[derive(Clone, Debug)]
pub struct Workspace {
    a: Vec<f64>,
    b: Vec<f64>,
}

#[inline(always)]
pub(crate) fn relu(z: f64) -> f64 {
    if z > 0.0 {
        z
    } else {
        0.0
    }
}

pub(crate) fn check_sizes(sizes: &[usize]) -> Result<(), NimError> {
    if sizes.len() < 2 {
        return Err(NimError::InvalidSizes {
            sizes: sizes.to_vec(),
            reason: format!("{} sizes given, at least 2 are needed", sizes.len()),
        });
    }
    if let Some(l) = sizes.iter().position(|&n| n == 0) {
        return Err(NimError::InvalidSizes {
            sizes: sizes.to_vec(),
            reason: format!("size {l} is zero"),
        });
    }
    Ok(())
}

impl Workspace {
    /// Room for nets whose widest layer is at most `width` wide.
    pub(crate) fn with_width(width: usize) -> Workspace {
        Workspace {
            a: vec![0.0; width],
            b: vec![0.0; width],
        }
    }
}

impl Mlp {
    /// A freshly initialised net with layer sizes `[n_in, h1, …, hk, n_out]`: He
    /// initialisation (every weight of layer `l` drawn from `N(0, 2 / sizes[l])`,
    /// layer by layer, row by row, from [`Gaussian::new(seed)`](Gaussian)), zero
    /// biases and identity standardisers (training sets them from the data).
    ///
    /// Errors when fewer than two sizes are given or a size is zero.
    pub fn new(sizes: &[usize], seed: u64) -> Result<Mlp, NimError> {
        check_sizes(sizes)?;
        let mut rng = Gaussian::new(seed);
        let mut weights = Vec::with_capacity(sizes.len() - 1);
        for l in 0..sizes.len() - 1 {
            let (n_in, n_out) = (sizes[l], sizes[l + 1]);
            let sigma = (2.0 / n_in as f64).sqrt();
            let mut w = vec![0.0; n_out * n_in];
            for i in 0..n_out {
                for j in 0..n_in {
                    w[j * n_out + i] = rng.normal(sigma);
                }
            }
            weights.push(w);
        }
        Ok(Mlp {
            sizes: sizes.to_vec(),
            weights,
            biases: sizes[1..].iter().map(|&n| vec![0.0; n]).collect(),
            input: Standardizer::identity(sizes[0]),
            output: Standardizer::identity(sizes[sizes.len() - 1]),
            width: *sizes.iter().max().unwrap(),
        })
    }

    /// `[n_in, h1, …, hk, n_out]`.
    pub fn sizes(&self) -> &[usize] {
        &self.sizes
    }

    pub fn n_inputs(&self) -> usize {
        self.sizes[0]
    }

    pub fn n_outputs(&self) -> usize {
        self.sizes[self.sizes.len() - 1]
    }

    /// Number of weight layers (`sizes().len() − 1`).
    pub fn n_layers(&self) -> usize {
        self.weights.len()
    }

    /// Number of trainable parameters (weights and biases).
    pub fn parameter_count(&self) -> usize {
        self.sizes.windows(2).map(|w| (w[0] + 1) * w[1]).sum()
    }

    /// `W_l`, `sizes[l + 1] × sizes[l]`. Panics when `l ≥ n_layers()`.
    pub fn weights(&self, l: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.weights[l], self.sizes[l + 1], self.sizes[l])
    }

    /// `b_l`, length `sizes[l + 1]`. Panics when `l ≥ n_layers()`.
    pub fn bias(&self, l: usize) -> &[f64] {
        &self.biases[l]
    }

    pub fn input_standardizer(&self) -> &Standardizer {
        &self.input
    }

    pub fn output_standardizer(&self) -> &Standardizer {
        &self.output
    }

    /// Replaces both standardisers (lengths must be `n_inputs()` and `n_outputs()`).
    pub fn set_standardizers(&mut self, input: Standardizer, output: Standardizer) -> Result<(), NimError> {
        for (s, n, what) in [
            (&input, self.n_inputs(), "input"),
            (&output, self.n_outputs(), "output"),
        ] {
            if s.len() != n {
                return Err(NimError::DimensionMismatch {
                    what: if what == "input" {
                        "input standardiser length (n_inputs)"
                    } else {
                        "output standardiser length (n_outputs)"
                    },
                    expected: n,
                    found: s.len(),
                });
            }
        }
        self.input = input;
        self.output = output;
        Ok(())
    }

    /// Every layer's weights (column-major), then every layer's biases, for the
    /// optimisers; the order of the gradient buffers.
    pub(crate) fn parameters_mut(&mut self) -> impl Iterator<Item = &mut [f64]> {
        self.weights.iter_mut().chain(&mut self.biases).map(Vec::as_mut_slice)
    }

    /// The lengths of the buffers of [`Mlp::parameters_mut`].
    pub(crate) fn parameter_lengths(&self) -> impl Iterator<Item = usize> + '_ {
        self.weights.iter().chain(&self.biases).map(Vec::len)
    }

    /// Buffers for [`Mlp::predict`].
    pub fn workspace(&self) -> Workspace {
        Workspace::with_width(self.width)
    }

    /// One sample through the net, in original units, without allocating: `input`
    /// has `n_inputs()` values, `out` receives `n_outputs()`.
    ///
    /// # Panics
    ///
    /// When `input` or `out` has the wrong length, or `workspace` is narrower than
    /// this net's widest layer (made by a smaller net): a programming error on the
    /// hot path, so a panic with a message rather than a `Result`.
    pub fn predict(&self, input: &[f64], workspace: &mut Workspace, out: &mut [f64]) {
        assert!(
            input.len() == self.n_inputs(),
            "Mlp::predict: input has length {}, the net takes {}",
            input.len(),
            self.n_inputs()
        );
        assert!(
            out.len() == self.n_outputs(),
            "Mlp::predict: out has length {}, the net gives {}",
            out.len(),
            self.n_outputs()
        );
        assert!(
            workspace.a.len() >= self.width && workspace.b.len() >= self.width,
            "Mlp::predict: the workspace holds {} values per buffer, this net needs {}; make it with Mlp::workspace",
            workspace.a.len().min(workspace.b.len()),
            self.width
        );
        let (mut x, mut y) = (&mut workspace.a[..], &mut workspace.b[..]);
        for (j, (z, &v)) in x.iter_mut().zip(input).enumerate() {
            *z = self.input.apply(j, v);
        }
        let last = self.n_layers() - 1;
        for l in 0..=last {
            let n_out = self.sizes[l + 1];
            let xs = &x[..self.sizes[l]];
            let ys = &mut y[..n_out];
            ys.fill(0.0);
            // y = Σ_j W[:, j] x_j, one contiguous column at a time.
            for (col, &xj) in self.weights[l].chunks_exact(n_out).zip(xs) {
                for (yi, &w) in ys.iter_mut().zip(col) {
                    *yi += w * xj;
                }
            }
            for (yi, &b) in ys.iter_mut().zip(&self.biases[l]) {
                let v = *yi + b;
                *yi = if l < last { relu(v) } else { v };
            }
            std::mem::swap(&mut x, &mut y);
        }
        for (i, (o, &z)) in out.iter_mut().zip(x.iter()).enumerate() {
            *o = self.output.invert(i, z);
        }
    }

    /// Many samples at once (one per row of `inputs`; the result likewise), in
    /// original units, through faer's matrix product. Agrees with [`Mlp::predict`]
    /// up to rounding (the summation order differs).
    ///
    /// # Panics
    ///
    /// When `inputs` does not have `n_inputs()` columns, like [`Mlp::predict`].
    pub fn predict_batch(&self, inputs: MatRef<'_, f64>) -> Mat<f64> {
        assert!(
            inputs.ncols() == self.n_inputs(),
            "Mlp::predict_batch: inputs have {} columns, the net takes {}",
            inputs.ncols(),
            self.n_inputs()
        );
        let count = inputs.nrows();
        let mut acts = self.batch_buffers(count);
        self.standardise_inputs(inputs, &mut acts[0]);
        self.forward(&mut acts, count);
        let out = &acts[self.n_layers()];
        let n_out = self.n_outputs();
        Mat::from_fn(count, n_out, |k, i| self.output.invert(i, out[k * n_out + i]))
    }

    /// The MSE of the net's predictions on `data`, in standardised and original
    /// output units. Errors when the dataset's widths do not match the net.
    pub fn evaluate(&self, data: &Dataset) -> Result<Mse, NimError> {
        self.check_dataset(data, ["dataset inputs per sample", "dataset targets per sample"])?;
        let count = data.len();
        let mut acts = self.batch_buffers(count);
        self.standardise_inputs(data.inputs(), &mut acts[0]);
        self.forward(&mut acts, count);
        let targets = self.standardise_targets(data.targets());
        Ok(self.mse(&acts[self.n_layers()], &targets))
    }

    /// Errors unless `data` has this net's input and output widths; `what` names
    /// the two widths in the message.
    pub(crate) fn check_dataset(&self, data: &Dataset, what: [&'static str; 2]) -> Result<(), NimError> {
        for (expected, found, what) in [
            (self.n_inputs(), data.n_inputs(), what[0]),
            (self.n_outputs(), data.n_outputs(), what[1]),
        ] {
            if found != expected {
                return Err(NimError::DimensionMismatch { what, expected, found });
            }
        }
        Ok(())
    }

    /// One zeroed column-major buffer per layer for `count` samples as columns:
    /// `acts[l]` is `sizes[l] × count`.
    pub(crate) fn batch_buffers(&self, count: usize) -> Vec<Vec<f64>> {
        self.sizes.iter().map(|&n| vec![0.0; n * count]).collect()
    }

    /// `inputs` (one sample per row) standardised into `dst`, samples as columns.
    pub(crate) fn standardise_inputs(&self, inputs: MatRef<'_, f64>, dst: &mut [f64]) {
        let n = self.n_inputs();
        for k in 0..inputs.nrows() {
            for j in 0..n {
                dst[k * n + j] = self.input.apply(j, inputs[(k, j)]);
            }
        }
    }

    /// `targets` (one sample per row) standardised, samples as columns.
    pub(crate) fn standardise_targets(&self, targets: MatRef<'_, f64>) -> Vec<f64> {
        let n = self.n_outputs();
        let mut out = vec![0.0; n * targets.nrows()];
        for k in 0..targets.nrows() {
            for i in 0..n {
                out[k * n + i] = self.output.apply(i, targets[(k, i)]);
            }
        }
        out
    }

    /// The forward pass over the first `count` columns of the layer buffers:
    /// `acts[0]` holds the standardised inputs (samples as columns); every later
    /// `acts[l + 1] = act(W_l acts[l] + b_l)` through faer's matmul, `act` the ReLU
    /// for hidden layers and the identity for the output.
    pub(crate) fn forward(&self, acts: &mut [Vec<f64>], count: usize) {
        let last = self.n_layers() - 1;
        for l in 0..=last {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let (lo, hi) = acts.split_at_mut(l + 1);
            let a = MatRef::from_column_major_slice(&lo[l][..n_in * count], n_in, count);
            let z = &mut hi[0][..n_out * count];
            matmul(
                MatMut::from_column_major_slice_mut(z, n_out, count),
                Accum::Replace,
                self.weights(l),
                a,
                1.0,
                Par::Seq,
            );
            for col in z.chunks_exact_mut(n_out) {
                for (zi, &b) in col.iter_mut().zip(&self.biases[l]) {
                    let v = *zi + b;
                    *zi = if l < last { relu(v) } else { v };
                }
            }
        }
    }

    /// MSE of standardised predictions against standardised targets (same layout,
    /// samples as columns), in both units.
    pub(crate) fn mse(&self, predictions: &[f64], targets: &[f64]) -> Mse {
        let n = self.n_outputs();
        let count = targets.len() / n;
        let (mut standardised, mut original) = (0.0, 0.0);
        for (p, t) in predictions[..targets.len()]
            .chunks_exact(n)
            .zip(targets.chunks_exact(n))
        {
            for i in 0..n {
                let r = p[i] - t[i];
                standardised += r * r;
                original += (r * self.output.std()[i]).powi(2);
            }
        }
        let denom = (count * n) as f64;
        Mse {
            standardised: standardised / denom,
            original: original / denom,
        }
    }

    /// The net as JSON (schema [`SCHEMA`]): layer sizes, per layer the weights as
    /// rows (`weights[i][j]` = `W[i, j]`, output `i`, input `j`) and the bias, and both
    /// standardisers. Numbers are written so that [`Mlp::from_json`] reads back
    /// exactly the same bits.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.to_file()).expect("an Mlp serialises to JSON")
    }

    pub(crate) fn to_file(&self) -> MlpFile {
        MlpFile {
            schema: SCHEMA.to_string(),
            sizes: self.sizes.clone(),
            layers: (0..self.n_layers())
                .map(|l| {
                    let w = self.weights(l);
                    LayerFile {
                        weights: (0..w.nrows())
                            .map(|i| (0..w.ncols()).map(|j| w[(i, j)]).collect())
                            .collect(),
                        bias: self.biases[l].clone(),
                    }
                })
                .collect(),
            input: StandardizerFile::from(&self.input),
            output: StandardizerFile::from(&self.output),
        }
    }

    /// Reads [`Mlp::to_json`]'s format. Errors name what is wrong: another or a
    /// missing `schema`, an unknown or missing field (serde's message with line and
    /// column), a layer whose weights or bias do not have the shape the sizes imply,
    /// a non-finite number, a non-positive standard deviation.
    pub fn from_json(text: &str) -> Result<Mlp, NimError> {
        #[derive(Deserialize)]
        struct Probe {
            schema: Option<String>,
        }
        let json = |e: serde_json::Error| NimError::Json { message: e.to_string() };
        let probe: Probe = serde_json::from_str(text).map_err(json)?;
        if probe.schema.as_deref() != Some(SCHEMA) {
            return Err(NimError::Schema {
                found: probe.schema,
                expected: SCHEMA,
            });
        }
        Mlp::from_file(serde_json::from_str(text).map_err(json)?)
    }

    /// The checks of [`Mlp::from_json`] on a parsed file.
    pub(crate) fn from_file(file: MlpFile) -> Result<Mlp, NimError> {
        if file.schema != SCHEMA {
            return Err(NimError::Schema {
                found: Some(file.schema),
                expected: SCHEMA,
            });
        }
        let sizes = file.sizes;
        check_sizes(&sizes)?;
        if file.layers.len() != sizes.len() - 1 {
            return Err(NimError::Shape {
                layer: None,
                field: "layers".into(),
                expected: format!(
                    "{} layers (one per consecutive pair of sizes {sizes:?})",
                    sizes.len() - 1
                ),
                found: format!("{} layers", file.layers.len()),
            });
        }
        let mut weights = Vec::with_capacity(file.layers.len());
        let mut biases = Vec::with_capacity(file.layers.len());
        for (l, layer) in file.layers.into_iter().enumerate() {
            let (n_in, n_out) = (sizes[l], sizes[l + 1]);
            let expected = format!("{n_out} × {n_in} ({n_out} rows of {n_in}: outputs × inputs)");
            let shape_error = |found: String| NimError::Shape {
                layer: Some(l),
                field: "weights".into(),
                expected: expected.clone(),
                found,
            };
            if layer.weights.len() != n_out {
                return Err(shape_error(format!("{} rows", layer.weights.len())));
            }
            // Every row checked against the sizes before the matrix is allocated: the
            // allocation is then no larger than the values the file holds, whatever
            // sizes it claims (a size of 1e12 is refused here, not by the allocator).
            if let Some((i, row)) = layer.weights.iter().enumerate().find(|(_, row)| row.len() != n_in) {
                return Err(shape_error(format!("row {i} of length {}", row.len())));
            }
            let mut w = vec![0.0; n_out * n_in];
            for (i, row) in layer.weights.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(NimError::InvalidValue {
                            field: format!("layers[{l}].weights[{i}][{j}]"),
                            reason: format!("{v} is not finite"),
                        });
                    }
                    w[j * n_out + i] = v;
                }
            }
            if layer.bias.len() != n_out {
                return Err(NimError::Shape {
                    layer: Some(l),
                    field: "bias".into(),
                    expected: format!("{n_out} values"),
                    found: format!("{} values", layer.bias.len()),
                });
            }
            if let Some(i) = layer.bias.iter().position(|v| !v.is_finite()) {
                return Err(NimError::InvalidValue {
                    field: format!("layers[{l}].bias[{i}]"),
                    reason: format!("{} is not finite", layer.bias[i]),
                });
            }
            weights.push(w);
            biases.push(layer.bias);
        }
        let standardizer = |s: StandardizerFile, n: usize, what: &str| -> Result<Standardizer, NimError> {
            if s.mean.len() != n {
                return Err(NimError::Shape {
                    layer: None,
                    field: format!("{what}.mean"),
                    expected: format!("{n} values (one per {what} of sizes {sizes:?})"),
                    found: format!("{} values", s.mean.len()),
                });
            }
            Standardizer::new(s.mean, s.std, what)
        };
        let input = standardizer(file.input, sizes[0], "input")?;
        let output = standardizer(file.output, sizes[sizes.len() - 1], "output")?;
        Ok(Mlp {
            width: *sizes.iter().max().unwrap(),
            sizes,
            weights,
            biases,
            input,
            output,
        })
    }

    /// Writes [`Mlp::to_json`] to `path`. An existing file is replaced only when
    /// `overwrite` is true; otherwise the call fails with
    /// [`NimError::AlreadyExists`] and leaves the file alone (the check and the
    /// creation are one atomic step).
    pub fn save(&self, path: impl AsRef<Path>, overwrite: bool) -> Result<(), NimError> {
        write_json(path.as_ref(), &self.to_json(), overwrite)
    }

    /// Reads a file written by [`Mlp::save`].
    pub fn load(path: impl AsRef<Path>) -> Result<Mlp, NimError> {
        Mlp::from_json(&read_json(path.as_ref())?)
    }
}

/// Largest weights file read, in bytes: far above any identifier dyngen trains (a
/// few MB), and a bound on what a wrong path (`/dev/zero`) can take.
pub(crate) const MAX_JSON_BYTES: u64 = 1 << 30;

/// The text of a JSON file (its I/O errors name the path); at most
/// [`MAX_JSON_BYTES`].
pub(crate) fn read_json(path: &Path) -> Result<String, NimError> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_JSON_BYTES + 1).read_to_string(&mut text))
        .map_err(|e| NimError::io(path, e))?;
    if text.len() as u64 > MAX_JSON_BYTES {
        return Err(NimError::Io {
            path: path.to_path_buf(),
            message: format!("larger than {MAX_JSON_BYTES} bytes (1 GiB); not a weights file dyngen wrote"),
        });
    }
    Ok(text)
}

/// Writes `json` and a newline to `path`; an existing file only with `overwrite`
/// (refused atomically otherwise, [`NimError::AlreadyExists`]).
pub(crate) fn write_json(path: &Path, json: &str, overwrite: bool) -> Result<(), NimError> {
    dyngen_identify::report::write_new(path, &format!("{json}\n"), overwrite).map_err(|e| match e {
        dyngen_identify::report::ReportError::Exists { .. } => NimError::AlreadyExists {
            path: path.to_path_buf(),
        },
        dyngen_identify::report::ReportError::Io { message, .. } => NimError::Io {
            path: path.to_path_buf(),
            message,
        },
        e => NimError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        },
    })
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MlpFile {
    schema: String,
    sizes: Vec<usize>,
    layers: Vec<LayerFile>,
    input: StandardizerFile,
    output: StandardizerFile,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerFile {
    weights: Vec<Vec<f64>>,
    bias: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StandardizerFile {
    mean: Vec<f64>,
    std: Vec<f64>,
}

impl From<&Standardizer> for StandardizerFile {
    fn from(s: &Standardizer) -> StandardizerFile {
        StandardizerFile {
            mean: s.mean().to_vec(),
            std: s.std().to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn net() -> Mlp {
        let mut net = Mlp::new(&[3, 7, 5, 2], 11).unwrap();
        net.set_standardizers(
            Standardizer::new(vec![0.5, -1.0, 2.0], vec![2.0, 0.5, 1.5], "input").unwrap(),
            Standardizer::new(vec![10.0, -3.0], vec![4.0, 0.25], "output").unwrap(),
        )
        .unwrap();
        net
    }

    #[test]
    fn one_sample_and_batch_inference_agree() {
        let net = net();
        let inputs = Mat::from_fn(13, 3, |i, j| ((i * 3 + j) as f64 * 0.37).sin() * 3.0);
        let batch = net.predict_batch(inputs.as_ref());
        let mut ws = net.workspace();
        let mut out = [0.0; 2];
        for i in 0..13 {
            let x: Vec<f64> = (0..3).map(|j| inputs[(i, j)]).collect();
            net.predict(&x, &mut ws, &mut out);
            for k in 0..2 {
                assert!((out[k] - batch[(i, k)]).abs() <= 1e-12 * (1.0 + out[k].abs()));
            }
        }
        // A wider workspace fits too.
        let mut wide = Mlp::new(&[3, 40, 2], 1).unwrap().workspace();
        net.predict(&[0.1, 0.2, 0.3], &mut wide, &mut out);
    }

    #[test]
    #[should_panic(expected = "the workspace holds 3 values per buffer, this net needs 7")]
    fn a_workspace_of_a_smaller_net_is_refused() {
        let net = net();
        let mut small = Mlp::new(&[2, 3, 1], 1).unwrap().workspace();
        net.predict(&[0.0; 3], &mut small, &mut [0.0; 2]);
    }

    #[test]
    fn json_round_trips_exactly_and_names_what_is_wrong() {
        let net = net();
        let json = net.to_json();
        assert_eq!(Mlp::from_json(&json).unwrap(), net);

        let error = |text: String| Mlp::from_json(&text).unwrap_err().to_string();
        assert_eq!(
            error(json.replace(SCHEMA, "dyngen-mlp/9")),
            "unsupported schema \"dyngen-mlp/9\": this version reads \"dyngen-mlp/1\""
        );
        assert_eq!(
            error(json.replacen(&format!("\"schema\": \"{SCHEMA}\","), "", 1)),
            "missing `schema` field: expected \"schema\": \"dyngen-mlp/1\""
        );
        let mut file = net.to_file();
        file.layers[1].weights[2].pop();
        assert_eq!(
            Mlp::from_file(file).unwrap_err().to_string(),
            "layer 1: `weights` has shape row 2 of length 6, expected 5 × 7 (5 rows of 7: outputs × inputs)"
        );
        let mut file = net.to_file();
        file.output.std[1] = 0.0;
        assert_eq!(
            Mlp::from_file(file).unwrap_err().to_string(),
            "invalid value in `output.std[1]`: 0; a standard deviation must be finite and > 0"
        );
        let mut file = net.to_file();
        file.layers[2].bias.push(1.0);
        assert!(Mlp::from_file(file)
            .unwrap_err()
            .to_string()
            .contains("layer 2: `bias` has shape 3 values"));
        assert!(
            error("{\"schema\": \"dyngen-mlp/1\", \"sizes\": [2, 1], \"extra\": 1}".into())
                .starts_with("invalid network JSON")
        );
        assert!(Mlp::new(&[3], 1)
            .unwrap_err()
            .to_string()
            .contains("at least 2 are needed"));
        assert!(Mlp::new(&[3, 0, 1], 1)
            .unwrap_err()
            .to_string()
            .contains("size 1 is zero"));
    }

    #[test]
    fn a_huge_layer_size_is_refused_before_allocating() {
        // Sizes claiming 1e12 inputs with one row of 7 values: checked against the
        // values the file holds, not allocated (8 TB would abort the process).
        let mut file = net().to_file();
        file.sizes[0] = 1_000_000_000_000;
        assert_eq!(
            Mlp::from_file(file).unwrap_err().to_string(),
            "layer 0: `weights` has shape row 0 of length 3, expected 7 × 1000000000000 (7 rows of 1000000000000: \
             outputs × inputs)"
        );
    }

    #[test]
    fn save_keeps_an_existing_file_unless_told() {
        let dir = std::env::temp_dir().join(format!("dyngen-mlp-save-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("net.json");
        let net = net();
        std::fs::write(&path, "keep me").unwrap();
        let err = net.save(&path, false).unwrap_err();
        assert!(matches!(err, NimError::AlreadyExists { .. }), "{err}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me");
        net.save(&path, true).unwrap();
        assert_eq!(Mlp::load(&path).unwrap(), net);
        let err = Mlp::load(dir.join("missing.json")).unwrap_err();
        assert!(err.to_string().contains("missing.json"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn evaluate_reports_both_units() {
        let net = net();
        let x: Vec<[f64; 3]> = (0..20).map(|k| [k as f64, 1.0, -(k as f64)]).collect();
        let y: Vec<[f64; 2]> = (0..20).map(|k| [k as f64, 0.0]).collect();
        let data = Dataset::from_rows(&x, &y).unwrap();
        let mse = net.evaluate(&data).unwrap();
        let p = net.predict_batch(data.inputs());
        let original: f64 = (0..20)
            .flat_map(|i| (0..2).map(move |k| (i, k)))
            .map(|(i, k)| (p[(i, k)] - y[i][k]).powi(2))
            .sum::<f64>()
            / 40.0;
        assert!((mse.original - original).abs() < 1e-9 * original);
        let standardised: f64 = (0..20)
            .flat_map(|i| (0..2).map(move |k| (i, k)))
            .map(|(i, k)| ((p[(i, k)] - y[i][k]) / [4.0, 0.25][k]).powi(2))
            .sum::<f64>()
            / 40.0;
        assert!((mse.standardised - standardised).abs() < 1e-9 * standardised);
    }
}
