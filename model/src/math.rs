//! Small fixed-size math on plain arrays: enough for placements, inertias and the
//! graph-theoretic matrices. Dense matrices of any size (the stacked regressors of the
//! base-parameter analysis) go to faer.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A 3×3 matrix, row-major: `m[row][col]`.
pub type Mat3 = [[f64; 3]; 3];

pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `sin` and `cos` of an angle, exact (0, ±1) when the angle is the `f64` nearest
/// to a quarter turn `kπ/2` (|k| ≤ 4: `FRAC_PI_2`, `PI`, …), so that axis-aligned
/// placements fold to exact constants. Any other value is taken as written: a
/// URDF's `3.14159265359` is not π, and snapping it would move the robot by 2e-13
/// rad away from what every other tool computes.
pub fn sin_cos_exact(angle: f64) -> (f64, f64) {
    let k = (angle / std::f64::consts::FRAC_PI_2).round();
    // `k · FRAC_PI_2` is the f64 nearest to kπ/2 for |k| ≤ 4 (checked in the tests).
    if k.abs() <= 4.0 && angle == k * std::f64::consts::FRAC_PI_2 {
        match (k as i64).rem_euclid(4) {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        angle.sin_cos()
    }
}

/// URDF convention: `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
pub fn rpy_to_matrix(rpy: Vec3) -> Mat3 {
    let (sr, cr) = sin_cos_exact(rpy[0]);
    let (sp, cp) = sin_cos_exact(rpy[1]);
    let (sy, cy) = sin_cos_exact(rpy[2]);
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Inverse of [`rpy_to_matrix`] (URDF roll-pitch-yaw), with exact multiples of π/2
/// preserved where the matrix entries are exact.
pub fn matrix_to_rpy(r: &Mat3) -> Vec3 {
    let sp = (-r[2][0]).clamp(-1.0, 1.0);
    if sp.abs() >= 1.0 - 1e-15 {
        // Gimbal lock: put everything in yaw.
        let pitch = sp.signum() * std::f64::consts::FRAC_PI_2;
        let yaw = (-r[0][1]).atan2(r[1][1]);
        [0.0, pitch, yaw]
    } else {
        let roll = r[2][1].atan2(r[2][2]);
        let pitch = sp.asin();
        let yaw = r[1][0].atan2(r[0][0]);
        [roll, pitch, yaw]
    }
}

/// The rotation of a unit quaternion `[w, x, y, z]`.
pub fn quaternion_to_matrix([w, x, y, z]: [f64; 4]) -> Mat3 {
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The axes `(e₁, e₂)` of the plane normal to the unit vector `n`, with
/// `e₁ × e₂ = n`: the images of `x` and `y` under the shortest rotation that takes `z`
/// to `n` (exactly `x`, `y` for `n = z`). For `n_z < −½` that rotation is found for
/// `−n` and the two axes are swapped, which keeps the division well away from zero
/// (so `n = −z` gives `(y, x)`). A planar joint's coordinates are along these axes.
pub fn plane_basis(n: &Vec3) -> (Vec3, Vec3) {
    let flip = n[2] < -0.5;
    let m = if flip { scale(-1.0, n) } else { *n };
    let k = 1.0 / (1.0 + m[2]);
    let e1 = [1.0 - m[0] * m[0] * k, -m[0] * m[1] * k, -m[0]];
    let e2 = [-m[0] * m[1] * k, 1.0 - m[1] * m[1] * k, -m[1]];
    if flip {
        (e2, e1)
    } else {
        (e1, e2)
    }
}

pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    m
}

pub fn mat_vec(a: &Mat3, v: &Vec3) -> Vec3 {
    [
        a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
        a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
        a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2],
    ]
}

pub fn transpose(a: &Mat3) -> Mat3 {
    [
        [a[0][0], a[1][0], a[2][0]],
        [a[0][1], a[1][1], a[2][1]],
        [a[0][2], a[1][2], a[2][2]],
    ]
}

pub fn add(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(s: f64, a: &Vec3) -> Vec3 {
    [s * a[0], s * a[1], s * a[2]]
}

pub fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn norm(a: &Vec3) -> f64 {
    dot(a, a).sqrt()
}

pub fn mat_add(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = *a;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] += b[i][j];
        }
    }
    m
}

/// `R · I · Rᵀ`: an inertia tensor re-expressed in the axes `R` maps into.
pub fn rotate_inertia(r: &Mat3, inertia: &Mat3) -> Mat3 {
    mat_mul(&mat_mul(r, inertia), &transpose(r))
}

/// Parallel-axis term `m (|c|² E − c cᵀ)`.
pub fn parallel_axis(mass: f64, c: &Vec3) -> Mat3 {
    let c2 = dot(c, c);
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let e = if i == j { c2 } else { 0.0 };
            m[i][j] = mass * (e - c[i] * c[j]);
        }
    }
    m
}

/// Eigenvalues and eigenvectors of a symmetric 3×3 matrix by cyclic Jacobi rotations.
/// Returns `(values, vectors)` with `vectors` holding the eigenvectors as columns,
/// values ascending, and `det(vectors) = +1`.
pub fn symmetric_eigen(a: &Mat3) -> (Vec3, Mat3) {
    let mut m = *a;
    let mut v = IDENTITY;
    for _sweep in 0..64 {
        let off = m[0][1].abs() + m[0][2].abs() + m[1][2].abs();
        let scale_ = m[0][0].abs() + m[1][1].abs() + m[2][2].abs();
        if off <= 1e-300 || off <= f64::EPSILON * 1e-3 * scale_ {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if m[p][q] == 0.0 {
                continue;
            }
            let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // m ← Jᵀ m J with J the Givens rotation in plane (p, q).
            for k in 0..3 {
                let mkp = m[k][p];
                let mkq = m[k][q];
                m[k][p] = c * mkp - s * mkq;
                m[k][q] = s * mkp + c * mkq;
            }
            for k in 0..3 {
                let mpk = m[p][k];
                let mqk = m[q][k];
                m[p][k] = c * mpk - s * mqk;
                m[q][k] = s * mpk + c * mqk;
            }
            for row in v.iter_mut() {
                let vp = row[p];
                let vq = row[q];
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| m[i][i].total_cmp(&m[j][j]));
    let values = [m[idx[0]][idx[0]], m[idx[1]][idx[1]], m[idx[2]][idx[2]]];
    let mut vectors = [[0.0; 3]; 3];
    for (col, &k) in idx.iter().enumerate() {
        for row in 0..3 {
            vectors[row][col] = v[row][k];
        }
    }
    if det(&vectors) < 0.0 {
        for row in vectors.iter_mut() {
            row[2] = -row[2];
        }
    }
    (values, vectors)
}

pub fn det(a: &Mat3) -> f64 {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// Singular values of a dense matrix given as rows (`m × p`, any shape), descending,
/// `min(m, p)` of them (faer's SVD, singular values only). Rows of unequal length
/// are read as zero-padded to the longest. Each value is accurate to a small multiple
/// of `ε σ₁`, which a rank test at `10⁻⁸ σ₁` needs and no more.
pub fn singular_values(rows: &[Vec<f64>]) -> Vec<f64> {
    let p = rows.iter().map(Vec::len).max().unwrap_or(0);
    let a = faer::Mat::<f64>::from_fn(rows.len(), p, |i, j| rows[i].get(j).copied().unwrap_or(0.0));
    singular_values_of(a.as_ref())
}

/// [`singular_values`] of a faer matrix. faer reduces a tall matrix to the triangle
/// of its QR first and bidiagonalises that; the decomposition does not converge only
/// for non-finite input, which gives no singular values (NaN) here.
pub fn singular_values_of(a: faer::MatRef<'_, f64>) -> Vec<f64> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Vec::new();
    }
    a.singular_values()
        .unwrap_or_else(|_| vec![f64::NAN; a.nrows().min(a.ncols())])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_round_trip_and_exact_quarter_turns() {
        let r = rpy_to_matrix([std::f64::consts::FRAC_PI_2, 0.0, -std::f64::consts::PI]);
        for row in &r {
            for &x in row {
                assert!(x == 0.0 || x == 1.0 || x == -1.0, "{r:?}");
            }
        }
        for rpy in [[0.3, -0.2, 1.1], [-2.0, 1.2, 0.4], [0.0, 0.0, 0.0]] {
            let back = matrix_to_rpy(&rpy_to_matrix(rpy));
            let (a, b) = (rpy_to_matrix(rpy), rpy_to_matrix(back));
            for i in 0..3 {
                for j in 0..3 {
                    assert!((a[i][j] - b[i][j]).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn plane_basis_is_orthonormal_and_right_handed() {
        assert_eq!(plane_basis(&[0.0, 0.0, 1.0]), ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
        assert_eq!(plane_basis(&[0.0, 0.0, -1.0]), ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0]));
        assert_eq!(plane_basis(&[1.0, 0.0, 0.0]), ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0]));
        let c = |a: &Vec3, b: &Vec3| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        for n in [
            [0.3, -0.4, 0.5],
            [0.1, 0.2, -0.6],
            [-1.0, 0.0, -1.0],
            [0.0, 1.0, -0.5001],
            [0.0, 1.0, -0.4999],
        ] {
            let n = scale(1.0 / norm(&n), &n);
            let (e1, e2) = plane_basis(&n);
            assert!(
                (norm(&e1) - 1.0).abs() < 1e-15 && (norm(&e2) - 1.0).abs() < 1e-15,
                "{n:?}"
            );
            assert!(dot(&e1, &e2).abs() < 1e-15 && dot(&e1, &n).abs() < 1e-15 && dot(&e2, &n).abs() < 1e-15);
            let m = c(&e1, &e2);
            assert!((0..3).all(|i| (m[i] - n[i]).abs() < 1e-15), "{n:?}: e1 × e2 = {m:?}");
        }
    }

    #[test]
    // Values near π and π/2 that are not the constants are the point.
    #[allow(clippy::approx_constant)]
    fn only_exact_quarter_turns_are_snapped() {
        use std::f64::consts::{FRAC_PI_2, PI, TAU};
        // The f64 nearest to 3π/2 (from 50 digits of π): what `3.0 * FRAC_PI_2` gives.
        assert_eq!(3.0 * FRAC_PI_2, 4.71238898038469);
        assert_eq!(4.0 * FRAC_PI_2, TAU);
        for (angle, exact) in [
            (FRAC_PI_2, (1.0, 0.0)),
            (PI, (0.0, -1.0)),
            (-PI, (0.0, -1.0)),
            (-FRAC_PI_2, (-1.0, 0.0)),
            (4.71238898038469, (-1.0, 0.0)),
            (TAU, (0.0, 1.0)),
        ] {
            assert_eq!(sin_cos_exact(angle), exact, "{angle}");
        }
        // Written with 12 decimals: 2.07e-13 rad from π, kept as written.
        let (s, c) = sin_cos_exact(3.14159265359);
        assert_eq!((s, c), 3.14159265359f64.sin_cos());
        assert!(s < -2.0e-13 && s > -2.1e-13, "{s}");
        // One ulp away from FRAC_PI_2 is not a quarter turn either.
        let next = f64::from_bits(FRAC_PI_2.to_bits() + 1);
        assert_eq!(sin_cos_exact(next), next.sin_cos());
        assert_eq!(sin_cos_exact(1.5707963267949), 1.5707963267949f64.sin_cos());
    }

    #[test]
    fn eigen_reconstructs() {
        let a = [[2.0, 0.3, -0.1], [0.3, 1.5, 0.2], [-0.1, 0.2, 1.0]];
        let (vals, vecs) = symmetric_eigen(&a);
        let d = [[vals[0], 0.0, 0.0], [0.0, vals[1], 0.0], [0.0, 0.0, vals[2]]];
        let back = rotate_inertia(&vecs, &d);
        for i in 0..3 {
            for j in 0..3 {
                assert!((back[i][j] - a[i][j]).abs() < 1e-13, "{back:?}");
            }
        }
        assert!(vals[0] <= vals[1] && vals[1] <= vals[2]);
        assert!((det(&vecs) - 1.0).abs() < 1e-12);
    }
    #[test]
    fn singular_values_of_a_known_matrix() {
        // A = U diag(3, 2, 0) Vᵀ built from two orthonormal columns: rank 2.
        let u = [[0.6, 0.0], [0.8, 0.0], [0.0, 1.0], [0.0, 0.0]];
        let v = [[1.0 / 2f64.sqrt(), 0.0], [1.0 / 2f64.sqrt(), 0.0], [0.0, 1.0]];
        let s = [3.0, 2.0];
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|r| (0..3).map(|c| (0..2).map(|k| u[r][k] * s[k] * v[c][k]).sum()).collect())
            .collect();
        let sv = singular_values(&rows);
        assert_eq!(sv.len(), 3);
        assert!((sv[0] - 3.0).abs() < 1e-14 && (sv[1] - 2.0).abs() < 1e-14, "{sv:?}");
        assert!(sv[2] < 1e-14, "{sv:?}");
    }

    #[test]
    fn singular_values_resolve_small_values() {
        // diag(1, 1e-10) rotated: the small value survives with relative accuracy.
        let (c, s) = (0.8, 0.6);
        let rows = vec![vec![c, -s * 1e-10], vec![s, c * 1e-10]];
        let sv = singular_values(&rows);
        assert!((sv[0] - 1.0).abs() < 1e-15);
        assert!((sv[1] / 1e-10 - 1.0).abs() < 1e-12, "{sv:?}");
    }
}
