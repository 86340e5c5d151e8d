//! The Coulomb term's smoothing, identified: `Fc·tanh(q̇/ε)` is linear in `Fc` but
//! not in `ε`. Real joints stick and creep around velocity reversals, where
//! `sign(q̇)` jumps and the measured torque does not; the smoothing the data
//! support is the one that predicts held-out parts of the recording best, which
//! [`crate::choice::epsilons`] finds per joint (`--friction auto`).

/// The search range of `ε` (rad/s or m/s): below it `tanh` is a sign at any logged
/// velocity resolution; above it the term is a second viscous friction.
pub const EPSILON_RANGE: (f64, f64) = (1e-3, 0.3);
