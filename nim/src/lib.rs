//! NIM, the numerical (neural-network) identification method of the source paper
//! (Advances in Mechanical Engineering, 2025, doi:10.1177/16878132251321050):
//! networks that read a body's measured motion and wrench and return its principal
//! inertial parameters
//! `θ = (m, J1, J2, J3)`. No machine-learning framework: the networks are written
//! over faer.
//!
//! Two identifiers:
//!
//! * [`paper_nim`]: the paper's NIM as described (per body six inputs, five ReLU
//!   layers, gradient descent to an MSE threshold on the first 80 of 100 samples,
//!   the 20 validation predictions averaged; Tables 4–5 and Fig. 5). Its targets
//!   are the true parameters of the one simulated robot, so it returns its labels:
//!   [`PaperNim`] says so, and the demo shows it by training on wrong labels.
//! * [`Nim`]: the generalising NIM. Per body a window network ([`WindowNet`]: an
//!   encoder per sample, a mean over the window, a decoder) on physically meaningful
//!   features in body axes, trained on many physically consistent parameter draws
//!   ([`draw_theta`]) along one joint motion, judged on draws it has never seen;
//!   parameters that do not enter a body's equations are reported, not guessed.
//!   [`online::track`] follows a body whose θ changes, against recursive least
//!   squares.
//!
//! The machinery under both:
//!
//! * [`Mlp`]: layer sizes `[n_in, h1, …, hk, n_out]`, ReLU hidden layers, a linear
//!   output layer, He initialisation ([`Mlp::new`]), and a [`Standardizer`] on the
//!   inputs and on the outputs, so callers work in original units throughout;
//! * [`Dataset`]: checked (input, target) samples, one per row, with the paper's
//!   ordered split ([`Dataset::split`]: the first 80 of 100 samples train, the last
//!   20 validate) and a seeded shuffled one;
//! * [`train`] and [`train_windows`]: the MSE loss with hand-written
//!   backpropagation over faer matrix products (samples as columns), full-batch
//!   gradient descent (the paper) or mini-batch Adam ([`Optimizer`]) with an
//!   optional cosine schedule ([`Decay`]), stopping at an MSE threshold or a step
//!   budget ([`TrainOptions`]), returning the loss curves ([`TrainHistory`]);
//! * inference: [`Mlp::predict`], [`WindowNet::predict`] and [`Nim::predict`] for
//!   one sample or window without allocation (through reusable workspaces),
//!   [`Mlp::predict_batch`] for many, [`Mlp::evaluate`] for the MSE on a dataset;
//! * JSON files: [`Mlp::to_json`], [`WindowNet::to_json`], [`Nim::to_json`] and their
//!   `from_json`, `save`, `load`; numbers round-trip exactly, so a loaded net
//!   predicts bit-identically.
//!
//! Everything is deterministic: initialisation, draws and shuffling come from
//! [`SplitMix64`](dyngen_reference::SplitMix64) streams seeded by the options, and
//! faer runs sequentially, so the same call gives the same bits on the same build
//! and machine (bodies train on parallel threads, each from its own seed).
//! Failures are [`NimError`]s naming the offending row, column, layer or field.
//!
//! ```
//! use dyngen_nim::{train, Dataset, Optimizer, TrainOptions};
//! // y = (x0 x1, x0 − x1) on a grid.
//! let x: Vec<[f64; 2]> = (0..100).map(|k| [(k % 10) as f64 / 9.0, (k / 10) as f64 / 9.0]).collect();
//! let y: Vec<[f64; 2]> = x.iter().map(|x| [x[0] * x[1], x[0] - x[1]]).collect();
//! let data = Dataset::from_rows(&x, &y).unwrap();
//! let (fit, check) = data.shuffled_split(0.8, 1).unwrap();
//! let options = TrainOptions { optimizer: Optimizer::adam(1e-2), max_steps: 1500, ..TrainOptions::default() };
//! let (net, history) = train(&[2, 16, 16, 2], &fit, Some(&check), &options).unwrap();
//! assert!(history.validation_mse_original.last().unwrap() < &1e-3);
//! let mut ws = net.workspace();
//! let mut out = [0.0; 2];
//! net.predict(&[0.5, 0.5], &mut ws, &mut out);
//! assert!((out[0] - 0.25).abs() < 0.05 && out[1].abs() < 0.05);
//! ```

mod data;
mod error;
mod identifier;
mod mlp;
pub mod online;
mod paper;
pub mod residual;
mod train;
mod window;

pub use data::{Dataset, Standardizer};
pub use error::{NimError, Part};
pub use identifier::{
    draw_theta, window_features, BodyNim, BodySample, Nim, NimConfig, NimEstimate, NimPredictor, NimTraining, FEATURES,
    NIM_SCHEMA,
};
pub use mlp::{Mlp, Mse, Workspace, SCHEMA};
pub use paper::{paper_inputs, paper_nim, PaperNim, PaperNimConfig, PAPER_INPUTS};
pub use train::{train, Decay, Optimizer, StopReason, TrainHistory, TrainOptions};
pub use window::{train_windows, WindowNet, WindowShape, WindowSource, WindowWorkspace, WINDOW_SCHEMA};
