//! Velocities and accelerations from measured positions: a zero-phase low-pass filter
//! (forward–backward 2nd-order Butterworth) followed by central differences.

use super::error::{DataError, Location};
use super::trajectory::{column, set_column, Trajectory};
use nalgebra::{Matrix4, Vector4};

/// Largest allowed deviation of one time step from the mean step, relative.
pub const SAMPLING_TOLERANCE: f64 = 0.01;

/// A 2nd-order Butterworth low-pass filter, `H(z) = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²)`,
/// from the analog prototype `1 / (s² + √2 s + 1)` by the bilinear transform with
/// the cutoff prewarped: `K = tan(π f_c Δt)`, `b0 = K² / (1 + √2 K + K²)`,
/// `b1 = 2 b0`, `b2 = b0`, `a1 = 2 (K² − 1) / (…)`, `a2 = (1 − √2 K + K²) / (…)`.
/// Unit gain at DC, −3 dB at exactly `f_c`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Butterworth2 {
    b: [f64; 3],
    a: [f64; 2],
}

impl Butterworth2 {
    fn low_pass(dt: f64, cutoff_hz: f64) -> Self {
        let k = (std::f64::consts::PI * cutoff_hz * dt).tan();
        let sqrt2 = std::f64::consts::SQRT_2;
        let norm = 1.0 / (1.0 + sqrt2 * k + k * k);
        let b0 = k * k * norm;
        Butterworth2 {
            b: [b0, 2.0 * b0, b0],
            a: [2.0 * (k * k - 1.0) * norm, (1.0 - sqrt2 * k + k * k) * norm],
        }
    }

    /// Direct form II transposed, state `z` in place.
    fn run(&self, x: &[f64], mut z: [f64; 2]) -> Vec<f64> {
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        x.iter()
            .map(|&x| {
                let y = b0 * x + z[0];
                z[0] = b1 * x - a1 * y + z[1];
                z[1] = b2 * x - a2 * y;
                y
            })
            .collect()
    }

    /// The state in which a constant input of 1 gives a constant output of 1 (unit
    /// DC gain): starting there, a filter fed a signal starting at `x0` starts
    /// without a step transient (scipy's `lfilter_zi`).
    fn steady_state(&self) -> [f64; 2] {
        let z1 = self.b[2] - self.a[1];
        [1.0 - self.b[0], z1]
    }
}

fn check_dt(dt: f64) -> Result<(), DataError> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(DataError::InvalidArgument {
            name: "dt",
            value: dt,
            expected: "a finite time step > 0 s".into(),
        })
    }
}

fn check_cutoff(dt: f64, cutoff_hz: f64) -> Result<(), DataError> {
    let nyquist = 0.5 / dt;
    if cutoff_hz.is_finite() && cutoff_hz > 0.0 && cutoff_hz < nyquist {
        Ok(())
    } else {
        Err(DataError::InvalidArgument {
            name: "cutoff_hz",
            value: cutoff_hz,
            expected: format!("0 < cutoff_hz < {nyquist} Hz (the Nyquist frequency of Δt = {dt} s)"),
        })
    }
}

fn check_finite(x: &[f64]) -> Result<(), DataError> {
    match x.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(DataError::NonFinite {
            at: Location::Sample(k),
            column: "x".into(),
            value: x[k],
        }),
    }
}

/// The `pad` samples before `x[0]`, oldest first: odd reflection about `x[0]`
/// corrected for curvature, `x[−k] = 2 x[0] − x[k] + c k²`.
///
/// Plain odd reflection (`c = 0`) continues value and slope (and every odd power
/// of a polynomial around `x[0]`) but flips the curvature; the filter then smears
/// that kink, which biases the filtered slope at the end by about curvature ×
/// filter width and the curvature itself by 100 %. `c = 2 c₂` restores the
/// quadratic term, with `c₂` from a least-squares cubic fit to the first `fit`
/// samples (a cubic, so that a cubic trend does not bias `c₂`; its odd terms are
/// already continued exactly by the reflection).
fn extension(x: &[f64], pad: usize, fit: usize) -> Vec<f64> {
    let c = if fit >= 4 && x.len() >= fit {
        quadratic_coefficient(&x[..fit])
    } else {
        0.0
    };
    (1..=pad)
        .rev()
        .map(|k| {
            let k2 = (k * k) as f64;
            2.0 * x[0] - x[k] + 2.0 * c * k2
        })
        .collect()
}

/// `c₂` of the least-squares cubic `c₀ + c₁ k + c₂ k² + c₃ k³` through `(k, x[k])`;
/// 0 if the fit fails (it cannot for 4 or more samples).
fn quadratic_coefficient(x: &[f64]) -> f64 {
    // In the scaled abscissa s = k / len, for a well-conditioned normal matrix.
    let scale = x.len() as f64;
    let mut ata = Matrix4::zeros();
    let mut atb = Vector4::zeros();
    for (k, &xk) in x.iter().enumerate() {
        let s = k as f64 / scale;
        let p = Vector4::new(1.0, s, s * s, s * s * s);
        ata += p * p.transpose();
        atb += p * xk;
    }
    match ata.cholesky() {
        Some(llt) => llt.solve(&atb)[2] / (scale * scale),
        None => 0.0,
    }
}

/// Zero-phase low-pass filtering of `x` (uniformly sampled every `dt` seconds):
/// a 2nd-order Butterworth filter with cutoff `cutoff_hz`, run forward then
/// backward (`filtfilt`), so the result has no lag and the magnitude response
/// `1 / (1 + (f/f_c)⁴)` (prewarped: exact at `f_c`, where it is −6 dB).
///
/// Edges: the signal is extended at both ends over
/// `min(len − 1, max(9, ⌈3 / (f_c Δt)⌉))` samples (three cutoff periods, about 13
/// time constants of the filter) by odd reflection about the end value corrected
/// for curvature: `x[−k] = 2 x[0] − x[k] + x″ (kΔt)²`, with `x″` from a
/// least-squares cubic over the last `max(4, ⌈1 / (f_c Δt)⌉)` samples (one cutoff
/// period: longer fits average noise better but miss faster curvature changes). The
/// extension continues value, slope and curvature (plain odd reflection flips the
/// curvature, which spoils derivatives at the ends). Each pass starts in the steady
/// state of its first value; the padding is removed afterwards.
///
/// Errors: `dt` not positive and finite, `cutoff_hz` not in `(0, 1 / (2 dt))`, a
/// non-finite value in `x`. Signals of 0 or 1 samples are returned unchanged.
pub fn butterworth_filtfilt(x: &[f64], dt: f64, cutoff_hz: f64) -> Result<Vec<f64>, DataError> {
    check_dt(dt)?;
    check_cutoff(dt, cutoff_hz)?;
    check_finite(x)?;
    let n = x.len();
    if n < 2 {
        return Ok(x.to_vec());
    }
    let filter = Butterworth2::low_pass(dt, cutoff_hz);
    // Samples per cutoff period, finite and positive here (casts saturate).
    let period = 1.0 / (cutoff_hz * dt);
    let pad = ((3.0 * period).ceil() as usize).max(9).min(n - 1);
    let fit = (period.ceil() as usize).max(4).min(n);

    let reversed: Vec<f64> = x.iter().rev().copied().collect();
    let mut ext = Vec::with_capacity(n + 2 * pad);
    ext.extend(extension(x, pad, fit));
    ext.extend_from_slice(x);
    ext.extend(extension(&reversed, pad, fit).into_iter().rev());

    let zi = filter.steady_state();
    let forward = filter.run(&ext, zi.map(|z| z * ext[0]));
    let mut reversed: Vec<f64> = forward.into_iter().rev().collect();
    let start = reversed[0];
    reversed = filter.run(&reversed, zi.map(|z| z * start));
    reversed.reverse();
    reversed.truncate(pad + n);
    reversed.drain(..pad);
    Ok(reversed)
}

/// The derivative of `x` (uniformly sampled every `dt` seconds) by finite
/// differences, second-order accurate everywhere: central `(x[k+1] − x[k−1]) / 2Δt`
/// inside, one-sided `(−3 x[0] + 4 x[1] − x[2]) / 2Δt` and
/// `(3 x[n−1] − 4 x[n−2] + x[n−3]) / 2Δt` at the ends. With exactly 2 samples both
/// values are the forward difference.
///
/// Errors: `dt` not positive and finite, fewer than 2 samples, a non-finite value.
pub fn central_difference(x: &[f64], dt: f64) -> Result<Vec<f64>, DataError> {
    check_dt(dt)?;
    check_finite(x)?;
    let n = x.len();
    if n < 2 {
        return Err(DataError::TooFewSamples { found: n, needed: 2 });
    }
    if n == 2 {
        let d = (x[1] - x[0]) / dt;
        return Ok(vec![d, d]);
    }
    let h2 = 2.0 * dt;
    let mut d = Vec::with_capacity(n);
    d.push((-3.0 * x[0] + 4.0 * x[1] - x[2]) / h2);
    d.extend(x.windows(3).map(|w| (w[2] - w[0]) / h2));
    d.push((3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / h2);
    Ok(d)
}

/// The second derivative of `x` (uniformly sampled every `dt` seconds) by finite
/// differences, second-order accurate everywhere: central
/// `(x[k+1] − 2 x[k] + x[k−1]) / Δt²` inside, one-sided
/// `(2 x[0] − 5 x[1] + 4 x[2] − x[3]) / Δt²` (and its mirror) at the ends. With
/// exactly 3 samples all values are the central one.
///
/// Errors: `dt` not positive and finite, fewer than 3 samples, a non-finite value.
pub fn second_difference(x: &[f64], dt: f64) -> Result<Vec<f64>, DataError> {
    check_dt(dt)?;
    check_finite(x)?;
    let n = x.len();
    if n < 3 {
        return Err(DataError::TooFewSamples { found: n, needed: 3 });
    }
    let h2 = dt * dt;
    let inner = x.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]) / h2);
    if n == 3 {
        let d = (x[2] - 2.0 * x[1] + x[0]) / h2;
        return Ok(vec![d; 3]);
    }
    let mut d = Vec::with_capacity(n);
    d.push((2.0 * x[0] - 5.0 * x[1] + 4.0 * x[2] - x[3]) / h2);
    d.extend(inner);
    d.push((2.0 * x[n - 1] - 5.0 * x[n - 2] + 4.0 * x[n - 3] - x[n - 4]) / h2);
    Ok(d)
}

/// Finite-difference weights at `z` for the nodes `x` (at most 4), derivatives 0..=2:
/// `w[k][j]` multiplies the value at `x[j]` in the `k`-th derivative (Fornberg's
/// recursion, exact for polynomials of degree < `x.len()`). On a uniform grid it
/// gives the classical stencils of [`central_difference`] and [`second_difference`].
fn stencil(z: f64, x: &[f64]) -> [[f64; 4]; 3] {
    let mut c = [[0.0; 4]; 3];
    c[0][0] = 1.0;
    let mut c1 = 1.0;
    let mut c4 = x[0] - z;
    for i in 1..x.len() {
        let mn = i.min(2);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = x[i] - z;
        for j in 0..i {
            let c3 = x[i] - x[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[k][i] = c1 * (k as f64 * c[k - 1][i - 1] - c5 * c[k][i - 1]) / c2;
                }
                c[0][i] = -c1 * c5 * c[0][i - 1] / c2;
            }
            for k in (1..=mn).rev() {
                c[k][j] = (c4 * c[k][j] - k as f64 * c[k - 1][j]) / c3;
            }
            c[0][j] = c4 * c[0][j] / c3;
        }
        c1 = c2;
    }
    c
}

fn check_grid(t: &[f64], x: &[f64], needed: usize) -> Result<(), DataError> {
    if t.len() != x.len() {
        return Err(DataError::LengthMismatch {
            what: "x",
            expected: t.len(),
            found: x.len(),
        });
    }
    check_finite(t)?;
    check_finite(x)?;
    if x.len() < needed {
        return Err(DataError::TooFewSamples { found: x.len(), needed });
    }
    match t.windows(2).position(|w| w[1] <= w[0]) {
        None => Ok(()),
        Some(k) => Err(DataError::NonMonotonicTime {
            at: Location::Sample(k + 1),
            t: t[k + 1],
            previous: t[k],
        }),
    }
}

/// The derivative of `x` sampled at strictly increasing times `t` (any spacing), by
/// three-point finite differences: at `t[k]` from `t[k−1], t[k], t[k+1]` inside,
/// from the first or last three samples at the ends. Second-order accurate (exact on
/// quadratics); on a uniform grid the same stencils as [`central_difference`]. With
/// exactly 2 samples both values are the forward difference.
///
/// Errors: lengths differ, fewer than 2 samples, `t` not strictly increasing, a
/// non-finite value.
pub fn nonuniform_difference(t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
    check_grid(t, x, 2)?;
    let n = x.len();
    if n == 2 {
        let d = (x[1] - x[0]) / (t[1] - t[0]);
        return Ok(vec![d, d]);
    }
    Ok((0..n)
        .map(|k| {
            let s = k.clamp(1, n - 2) - 1;
            let w = stencil(t[k], &t[s..s + 3]);
            (0..3).map(|j| w[1][j] * x[s + j]).sum()
        })
        .collect())
}

/// The second derivative of `x` sampled at strictly increasing times `t` (any
/// spacing): three points `t[k−1], t[k], t[k+1]` inside, the first or last four at
/// the ends (so that the ends are as accurate as the inside on a uniform grid, where
/// these are the stencils of [`second_difference`]). With exactly 3 samples all
/// values are the three-point one at the middle sample.
///
/// Errors: lengths differ, fewer than 3 samples, `t` not strictly increasing, a
/// non-finite value.
pub fn nonuniform_second_difference(t: &[f64], x: &[f64]) -> Result<Vec<f64>, DataError> {
    check_grid(t, x, 3)?;
    let n = x.len();
    let apply = |k: usize, s: usize, len: usize| -> f64 {
        let w = stencil(t[k], &t[s..s + len]);
        (0..len).map(|j| w[2][j] * x[s + j]).sum()
    };
    if n == 3 {
        return Ok(vec![apply(1, 0, 3); 3]);
    }
    Ok((0..n)
        .map(|k| match k {
            0 => apply(0, 0, 4),
            k if k == n - 1 => apply(k, n - 4, 4),
            k => apply(k, k - 1, 3),
        })
        .collect())
}

/// For each time of `grid` (increasing), the interval `[t[k], t[k+1]]` of `t` holding
/// it and the position in it, `0..=1` (clamped outside `t`).
pub(super) fn intervals(t: &[f64], grid: &[f64]) -> Vec<(usize, f64)> {
    let mut k = 0;
    grid.iter()
        .map(|&g| {
            while k + 2 < t.len() && t[k + 1] <= g {
                k += 1;
            }
            let s = ((g - t[k]) / (t[k + 1] - t[k])).clamp(0.0, 1.0);
            (k, s)
        })
        .collect()
}

/// Cubic Hermite interpolation of `y` (sampled at `t`) at the points `at`
/// ([`intervals`]), slopes from [`nonuniform_difference`]: exact on quadratics and
/// continuous in value and slope, so that derivatives taken afterwards do not see
/// the kinks linear interpolation would put at every sample.
pub(super) fn hermite(t: &[f64], y: &[f64], at: &[(usize, f64)]) -> Result<Vec<f64>, DataError> {
    let m = nonuniform_difference(t, y)?;
    Ok(at
        .iter()
        .map(|&(k, s)| {
            let h = t[k + 1] - t[k];
            let (s2, s3) = (s * s, s * s * s);
            (2.0 * s3 - 3.0 * s2 + 1.0) * y[k]
                + (s3 - 2.0 * s2 + s) * h * m[k]
                + (-2.0 * s3 + 3.0 * s2) * y[k + 1]
                + (s3 - s2) * h * m[k + 1]
        })
        .collect())
}

/// `f(j)` for every joint column `j`, spread over the machine's cores (the columns
/// are independent), written into a row-major `len × dof` array. The first error in
/// column order is returned, whichever thread met it.
fn per_column(
    len: usize,
    dof: usize,
    f: impl Fn(usize) -> Result<Vec<f64>, DataError> + Sync,
) -> Result<Vec<f64>, DataError> {
    let columns = crate::accumulate::in_parallel(dof, f);
    let mut out = vec![0.0; len * dof];
    for (j, c) in columns.into_iter().enumerate() {
        set_column(&mut out, dof, j, &c?);
    }
    Ok(out)
}

/// Per joint column of a row-major `len × dof` array: `f(F(column))`, `F` the filter.
fn filtered(
    values: &[f64],
    dof: usize,
    dt: f64,
    cutoff_hz: f64,
    f: impl Fn(&[f64], f64) -> Result<Vec<f64>, DataError> + Sync,
) -> Result<Vec<f64>, DataError> {
    per_column(values.len() / dof.max(1), dof, |j| {
        f(&butterworth_filtfilt(&column(values, dof, j), dt, cutoff_hz)?, dt)
    })
}

/// Per joint column of a row-major `len × dof` array sampled at `t`, low-passed at
/// `cutoff_hz` with zero phase ([`butterworth_filtfilt`]): directly when `t` is
/// uniform within [`SAMPLING_TOLERANCE`], otherwise through a uniform grid of as many
/// samples (cubic Hermite there and back, as [`Trajectory::with_derivatives_nonuniform`]
/// does), so that jitter is not read as motion.
fn low_pass_columns(t: &[f64], values: &[f64], dof: usize, cutoff_hz: f64) -> Result<Vec<f64>, DataError> {
    let n = t.len();
    if n < 2 {
        return Ok(values.to_vec());
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    check_cutoff(dt, cutoff_hz)?;
    let uniform = t
        .windows(2)
        .all(|w| (w[1] - w[0] - dt).abs() <= SAMPLING_TOLERANCE * dt);
    if uniform {
        return filtered(values, dof, dt, cutoff_hz, |x, _| Ok(x.to_vec()));
    }
    let grid: Vec<f64> = (0..n)
        .map(|k| if k + 1 == n { t[n - 1] } else { t[0] + k as f64 * dt })
        .collect();
    let (to_grid, back) = (intervals(t, &grid), intervals(&grid, t));
    per_column(n, dof, |j| {
        let uniform = hermite(t, &column(values, dof, j), &to_grid)?;
        let smooth = butterworth_filtfilt(&uniform, dt, cutoff_hz)?;
        hermite(&grid, &smooth, &back)
    })
}

impl Trajectory {
    /// The same trajectory with the positions and, if `velocities`, the velocities
    /// low-passed at `cutoff_hz` with zero phase (per joint, [`butterworth_filtfilt`];
    /// through a uniform grid when the time stamps are irregular). Accelerations and
    /// torques are kept.
    ///
    /// For identification on real logs: the regressor is evaluated at the measured
    /// state, and noise there (a velocity the drive differentiates from its encoder,
    /// quantised positions) enters every column, biasing least squares; filtering the
    /// state as the accelerations are filtered removes that noise above the cutoff
    /// and keeps `q`, `q̇`, `q̈` consistent. Call it after
    /// [`Trajectory::with_derivatives`], which differentiates the unfiltered data
    /// (so nothing is filtered twice).
    ///
    /// Errors: `cutoff_hz` not in `(0, 1 / (2 Δt̄))`, a non-finite value.
    pub fn with_states_low_passed(&self, cutoff_hz: f64, velocities: bool) -> Result<Trajectory, DataError> {
        let dof = self.dof();
        let q = low_pass_columns(self.t(), self.positions(), dof, cutoff_hz)?;
        let v = match self.velocities() {
            Some(v) if velocities => Some(low_pass_columns(self.t(), v, dof, cutoff_hz)?),
            other => other.map(<[f64]>::to_vec),
        };
        let mut out = self.clone();
        out.set_states(q, v)?;
        Ok(out)
    }

    /// The mean time step `(t[n−1] − t[0]) / (n − 1)`, after checking that every
    /// step is within 1 % of it ([`SAMPLING_TOLERANCE`]); the error names the line
    /// (or sample) that ends the first step out of tolerance.
    pub fn uniform_time_step(&self) -> Result<f64, DataError> {
        let t = self.t();
        let n = t.len();
        let nominal = (t[n - 1] - t[0]) / (n - 1) as f64;
        for k in 1..n {
            let step = t[k] - t[k - 1];
            if (step - nominal).abs() > SAMPLING_TOLERANCE * nominal {
                return Err(DataError::NonUniformSampling {
                    at: self.location(k),
                    step,
                    nominal,
                });
            }
        }
        Ok(nominal)
    }

    /// [`Trajectory::with_derivatives`] for time stamps that are not uniform (a
    /// jittered logger): the signal to differentiate is interpolated (cubic Hermite)
    /// onto a uniform grid of as many samples from `t[0]` to `t[n−1]`, filtered and
    /// differentiated there exactly as by [`Trajectory::with_derivatives`], and the
    /// derivatives are interpolated back to the log's own time stamps. (Filtering
    /// the samples as if they were uniform would instead read the jitter as motion.)
    /// `q` and `tau` are kept as they are.
    ///
    /// Errors: `cutoff_hz` not in `(0, 1 / (2 Δt̄))` for the mean step `Δt̄`, fewer
    /// than 3 samples when `a` is computed from `q`.
    pub fn with_derivatives_nonuniform(&self, cutoff_hz: f64) -> Result<Trajectory, DataError> {
        let t = self.t();
        let n = t.len();
        let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
        check_cutoff(dt, cutoff_hz)?;
        let dof = self.dof();
        let grid: Vec<f64> = (0..n)
            .map(|k| if k + 1 == n { t[n - 1] } else { t[0] + k as f64 * dt })
            .collect();
        let to_grid = intervals(t, &grid);
        let back = intervals(&grid, t);
        // Column `j` of `values`, on the grid, filtered; then `d` of it, back on `t`.
        let derive = |values: &[f64], j: usize, d: fn(&[f64], f64) -> Result<Vec<f64>, DataError>| {
            let uniform = hermite(t, &column(values, dof, j), &to_grid)?;
            let smooth = butterworth_filtfilt(&uniform, dt, cutoff_hz)?;
            hermite(&grid, &d(&smooth, dt)?, &back)
        };
        let mut v = self.velocities().map(<[f64]>::to_vec);
        let mut a = self.accelerations().map(<[f64]>::to_vec);
        let (source, first, second) = match (&v, &a) {
            (Some(_), Some(_)) => return Ok(self.clone()),
            (Some(v), None) => (v.clone(), None, Some(central_difference as fn(&[f64], f64) -> _)),
            (None, Some(_)) => (
                self.positions().to_vec(),
                Some(central_difference as fn(&[f64], f64) -> _),
                None,
            ),
            (None, None) => (
                self.positions().to_vec(),
                Some(central_difference as fn(&[f64], f64) -> _),
                Some(second_difference as fn(&[f64], f64) -> _),
            ),
        };
        if let Some(d) = first {
            v = Some(per_column(n, dof, |j| derive(&source, j, d))?);
        }
        if let Some(d) = second {
            a = Some(per_column(n, dof, |j| derive(&source, j, d))?);
        }
        let mut out = self.clone();
        out.set_derivatives(v, a)?;
        Ok(out)
    }

    /// The same trajectory with the missing velocities and accelerations computed
    /// from the positions; values already present are kept, and so are `q` and
    /// `tau` (they are not filtered).
    ///
    /// Per joint, with `F` = [`butterworth_filtfilt`] at `cutoff_hz`, `D` =
    /// [`central_difference`] and `D²` = [`second_difference`] at the mean time step:
    ///
    /// - neither given: `v = D(F(q))`, `a = D²(F(q))` (one filter pass, both
    ///   derivatives of the same smooth signal);
    /// - only `v` given (measured): `a = D(F(v))`;
    /// - only `a` given: `v = D(F(q))`.
    ///
    /// `D²` rather than `D(D(·))`: its stencil is half as wide, its truncation error
    /// a quarter, and at the ends it avoids differentiating the one-sided
    /// differences of `D` a second time.
    ///
    /// Errors: sampling not uniform within 1 % ([`Trajectory::uniform_time_step`]),
    /// `cutoff_hz` not in `(0, f_s / 2)`, fewer than 3 samples when `a` is computed
    /// from `q`.
    pub fn with_derivatives(&self, cutoff_hz: f64) -> Result<Trajectory, DataError> {
        let dt = self.uniform_time_step()?;
        check_cutoff(dt, cutoff_hz)?;
        let dof = self.dof();
        let q = self.positions();
        let (v, a) = match (self.velocities(), self.accelerations()) {
            (Some(v), Some(a)) => (v.to_vec(), a.to_vec()),
            (Some(v), None) => (v.to_vec(), filtered(v, dof, dt, cutoff_hz, central_difference)?),
            (None, Some(a)) => (filtered(q, dof, dt, cutoff_hz, central_difference)?, a.to_vec()),
            (None, None) => {
                // One filter pass per joint for both derivatives: [v; a] per column.
                let both = per_column(2 * q.len() / dof.max(1), dof, |j| {
                    let smooth = butterworth_filtfilt(&column(q, dof, j), dt, cutoff_hz)?;
                    let mut both = central_difference(&smooth, dt)?;
                    both.extend(second_difference(&smooth, dt)?);
                    Ok(both)
                })?;
                let (v, a) = both.split_at(q.len());
                (v.to_vec(), a.to_vec())
            }
        };
        let mut out = self.clone();
        out.set_derivatives(Some(v), Some(a))?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn jittered_grid(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut t = vec![0.3];
        for _ in 1..n {
            let last = t[t.len() - 1];
            t.push(last + rng.gen_range(0.008..0.013));
        }
        t
    }

    #[test]
    fn nonuniform_differences_are_exact_on_quadratics() {
        let t = jittered_grid(1, 30);
        let x: Vec<f64> = t.iter().map(|t| 2.0 - 3.0 * t + 1.5 * t * t).collect();
        let d = nonuniform_difference(&t, &x).unwrap();
        let d2 = nonuniform_second_difference(&t, &x).unwrap();
        for k in 0..t.len() {
            assert!((d[k] - (-3.0 + 3.0 * t[k])).abs() < 1e-9, "{k}: {}", d[k]);
            assert!((d2[k] - 3.0).abs() < 1e-6, "{k}: {}", d2[k]);
        }
    }

    #[test]
    fn nonuniform_differences_on_a_uniform_grid_are_the_classical_ones() {
        let t: Vec<f64> = (0..20).map(|k| k as f64 * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|t| (3.0 * t).sin() + t * t * t).collect();
        let a = nonuniform_difference(&t, &x).unwrap();
        let b = central_difference(&x, 0.01).unwrap();
        let a2 = nonuniform_second_difference(&t, &x).unwrap();
        let b2 = second_difference(&x, 0.01).unwrap();
        for k in 0..t.len() {
            assert!((a[k] - b[k]).abs() < 1e-9 && (a2[k] - b2[k]).abs() < 1e-6, "{k}");
        }
    }

    #[test]
    fn nonuniform_differences_errors() {
        let e = nonuniform_difference(&[0.0], &[1.0]).unwrap_err();
        assert_eq!(e.to_string(), "1 sample(s); at least 2 are needed");
        let e = nonuniform_second_difference(&[0.0, 1.0], &[1.0, 2.0]).unwrap_err();
        assert_eq!(e.to_string(), "2 sample(s); at least 3 are needed");
        let e = nonuniform_difference(&[0.0, 1.0, 1.0], &[1.0, 2.0, 3.0]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("sample 2 (0-based): time t = 1 s does not increase"),
            "{e}"
        );
        let e = nonuniform_difference(&[0.0, 1.0], &[1.0]).unwrap_err();
        assert_eq!(e.to_string(), "`x` has 1 values, expected 2");
    }

    #[test]
    fn hermite_reproduces_quadratics_between_samples() {
        let t = jittered_grid(2, 12);
        let y: Vec<f64> = t.iter().map(|t| 1.0 + t - 4.0 * t * t).collect();
        let grid: Vec<f64> = (0..40).map(|k| t[0] + k as f64 * 0.0025).collect();
        let out = hermite(&t, &y, &intervals(&t, &grid)).unwrap();
        for (g, o) in grid.iter().zip(&out) {
            assert!((o - (1.0 + g - 4.0 * g * g)).abs() < 1e-12, "{g}");
        }
    }
}
