//! Small dense helpers shared by the estimators (vectors as slices, matrices as
//! faer `Mat`). The heavy lifting (QR, SVD, LU) is faer's.

use faer::{Mat, MatRef};

/// A slice as a one-column matrix.
pub(crate) fn column(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), 1, |i, _| v[i])
}

/// The first column of a matrix as a vector.
pub(crate) fn first_column(m: MatRef<'_, f64>) -> Vec<f64> {
    (0..m.nrows()).map(|i| m[(i, 0)]).collect()
}

/// `A x`.
pub(crate) fn mat_vec(a: MatRef<'_, f64>, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj != 0.0 {
            for i in 0..a.nrows() {
                out[i] += a[(i, j)] * xj;
            }
        }
    }
    out
}

/// `Aᵀ x`.
pub(crate) fn mat_t_vec(a: MatRef<'_, f64>, x: &[f64]) -> Vec<f64> {
    (0..a.ncols())
        .map(|j| (0..a.nrows()).map(|i| a[(i, j)] * x[i]).sum())
        .collect()
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `xᵀ C x` for a square matrix `C`.
/// `‖new − old‖ / ‖new‖` (0 where both are 0).
pub(crate) fn relative_change(new: &[f64], old: &[f64]) -> f64 {
    let (mut change, mut size) = (0.0, 0.0);
    for (a, b) in new.iter().zip(old) {
        change += (a - b) * (a - b);
        size += a * a;
    }
    if size > 0.0 {
        (change / size).sqrt()
    } else {
        change.sqrt()
    }
}

pub(crate) fn quadratic_form(c: MatRef<'_, f64>, x: &[f64]) -> f64 {
    dot(x, &mat_vec(c, x))
}

/// `V diag(w) Vᵀ` over the first `k` columns of `V`.
pub(crate) fn scaled_gram(v: MatRef<'_, f64>, w: &[f64]) -> Mat<f64> {
    let p = v.nrows();
    let mut out = Mat::zeros(p, p);
    for (k, &wk) in w.iter().enumerate() {
        for i in 0..p {
            let vik = v[(i, k)] * wk;
            if vik != 0.0 {
                for j in 0..p {
                    out[(i, j)] += vik * v[(j, k)];
                }
            }
        }
    }
    out
}
