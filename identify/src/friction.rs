//! The Coulomb term's smoothing, identified: `Fc·tanh(q̇/ε)` is linear in `Fc` but
//! not in `ε`, so `ε` is found by a one-dimensional search on the least-squares
//! residual (variable projection: every trial `ε` is a complete linear fit). Real
//! joints stick and creep around velocity reversals, where `sign(q̇)` jumps and the
//! measured torque does not; the smoothing that fits the data best is the one the
//! data support.

/// The search range of `ε` (rad/s or m/s): below it `tanh` is a sign at any logged
/// velocity resolution; above it the term is a second viscous friction.
pub const EPSILON_RANGE: (f64, f64) = (1e-3, 0.3);

/// The `ε` in [`EPSILON_RANGE`] minimising `residual(ε)` (the RMS residual of a
/// linear fit with `Coulomb::Smooth { epsilon: ε }`): a grid of 13 points evenly
/// spaced in `log ε`, then golden-section refinement around the best point (to 1 %
/// in `ε`). Returns the `ε` and its residual; `residual` must be finite.
pub fn best_epsilon(mut residual: impl FnMut(f64) -> f64) -> (f64, f64) {
    let (lo, hi) = (EPSILON_RANGE.0.ln(), EPSILON_RANGE.1.ln());
    let steps = 12;
    let grid: Vec<f64> = (0..=steps).map(|k| lo + (hi - lo) * k as f64 / steps as f64).collect();
    let values: Vec<f64> = grid.iter().map(|&x| residual(x.exp())).collect();
    let best = (0..=steps)
        .min_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(steps)]);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (residual(c.exp()), residual(d.exp()));
    while b - a > 0.01 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = residual(c.exp());
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = residual(d.exp());
        }
    }
    let (x, f) = if fc < fd { (c, fc) } else { (d, fd) };
    if values[best] < f {
        (grid[best].exp(), values[best])
    } else {
        (x.exp(), f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_smooth_residual() {
        let (eps, r) = best_epsilon(|e: f64| 1.0 + (e.ln() - 0.02f64.ln()).powi(2));
        assert!((eps / 0.02 - 1.0).abs() < 0.01, "{eps}");
        assert!((r - 1.0).abs() < 1e-3);
        // At the edge of the range.
        let (eps, _) = best_epsilon(|e: f64| e);
        assert!((eps / EPSILON_RANGE.0 - 1.0).abs() < 0.01, "{eps}");
    }
}
