//! Spatial algebra in Pinocchio's conventions, on any [`Real`]: motion vectors
//! `[v; ω]` (the velocity of the point at the frame origin, and the angular
//! velocity), force vectors `[f; n]` (the force, and the moment about the frame
//! origin), placements `x_parent = R x_child + p`.
//!
//! Everything is plain arrays, so that a symbolic scalar records exactly the
//! operations written here and `f64` compiles to straight-line code.

use crate::Real;

/// A 3-vector.
pub type Vec3<S> = [S; 3];
/// A 3 × 3 matrix, row-major.
pub type Mat3<S> = [[S; 3]; 3];

#[inline(always)]
pub fn add<S: Real>(a: Vec3<S>, b: Vec3<S>) -> Vec3<S> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub fn sub<S: Real>(a: Vec3<S>, b: Vec3<S>) -> Vec3<S> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn neg<S: Real>(a: Vec3<S>) -> Vec3<S> {
    [-a[0], -a[1], -a[2]]
}

#[inline(always)]
pub fn scale<S: Real>(s: S, a: Vec3<S>) -> Vec3<S> {
    [s * a[0], s * a[1], s * a[2]]
}

#[inline(always)]
pub fn dot<S: Real>(a: Vec3<S>, b: Vec3<S>) -> S {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}

#[inline(always)]
pub fn cross<S: Real>(a: Vec3<S>, b: Vec3<S>) -> Vec3<S> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `m v`.
#[inline(always)]
pub fn mat_vec<S: Real>(m: &Mat3<S>, v: Vec3<S>) -> Vec3<S> {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `mᵀ v`.
#[inline(always)]
pub fn mat_tr_vec<S: Real>(m: &Mat3<S>, v: Vec3<S>) -> Vec3<S> {
    let c = |k: usize| m[0][k].mul_add(v[0], m[1][k].mul_add(v[1], m[2][k] * v[2]));
    [c(0), c(1), c(2)]
}

/// `a b`.
#[inline(always)]
pub fn mat_mul<S: Real>(a: &Mat3<S>, b: &Mat3<S>) -> Mat3<S> {
    let e = |r: usize, c: usize| a[r][0].mul_add(b[0][c], a[r][1].mul_add(b[1][c], a[r][2] * b[2][c]));
    [
        [e(0, 0), e(0, 1), e(0, 2)],
        [e(1, 0), e(1, 1), e(1, 2)],
        [e(2, 0), e(2, 1), e(2, 2)],
    ]
}

/// `aᵀ`.
#[inline(always)]
pub fn transpose<S: Real>(a: &Mat3<S>) -> Mat3<S> {
    [
        [a[0][0], a[1][0], a[2][0]],
        [a[0][1], a[1][1], a[2][1]],
        [a[0][2], a[1][2], a[2][2]],
    ]
}

#[inline(always)]
fn mat_add<S: Real>(a: &Mat3<S>, b: &Mat3<S>) -> Mat3<S> {
    [add(a[0], b[0]), add(a[1], b[1]), add(a[2], b[2])]
}

#[inline(always)]
fn mat_sub<S: Real>(a: &Mat3<S>, b: &Mat3<S>) -> Mat3<S> {
    [sub(a[0], b[0]), sub(a[1], b[1]), sub(a[2], b[2])]
}

/// The symmetric matrix of `m`'s upper triangle: for a result known to be
/// symmetric, the lower triangle is not computed a second time.
#[inline(always)]
fn mirror_upper<S: Real>(m: Mat3<S>) -> Mat3<S> {
    [
        [m[0][0], m[0][1], m[0][2]],
        [m[0][1], m[1][1], m[1][2]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// `[x]×`, with `[x]× y = x × y`.
#[inline(always)]
fn skew<S: Real>(x: Vec3<S>, zero: S) -> Mat3<S> {
    [[zero, -x[2], x[1]], [x[2], zero, -x[0]], [-x[1], x[0], zero]]
}

/// `[p]× a` without forming `[p]×`: row `r` is `p × (column of a)` taken row-wise.
#[inline(always)]
fn skew_mul<S: Real>(p: Vec3<S>, a: &Mat3<S>) -> Mat3<S> {
    let col = |c: usize| cross(p, [a[0][c], a[1][c], a[2][c]]);
    let (c0, c1, c2) = (col(0), col(1), col(2));
    [[c0[0], c1[0], c2[0]], [c0[1], c1[1], c2[1]], [c0[2], c1[2], c2[2]]]
}

/// `a [p]×`: row `r` is `a_r × p` negated, `(a [p]×)_r = −p × a_r`.
#[inline(always)]
fn mul_skew<S: Real>(a: &Mat3<S>, p: Vec3<S>) -> Mat3<S> {
    [cross(a[0], p), cross(a[1], p), cross(a[2], p)]
}

/// A rotation by its action on vectors, so that a placement kept in factors
/// ([`crate::JointPlacement`]) and a plain matrix rotate inertias alike.
pub trait Rotate<S> {
    /// `R x`.
    fn rotate(&self, x: Vec3<S>) -> Vec3<S>;
}

impl<S: Real> Rotate<S> for Mat3<S> {
    #[inline(always)]
    fn rotate(&self, x: Vec3<S>) -> Vec3<S> {
        mat_vec(self, x)
    }
}

/// `R X Rᵀ`: `R` applied to the columns of `X`, then to the rows of the result.
#[inline(always)]
pub fn rotate_matrix<S: Real, R: Rotate<S>>(x: &Mat3<S>, r: &R) -> Mat3<S> {
    let c0 = r.rotate([x[0][0], x[1][0], x[2][0]]);
    let c1 = r.rotate([x[0][1], x[1][1], x[2][1]]);
    let c2 = r.rotate([x[0][2], x[1][2], x[2][2]]);
    // a = R X has columns c0, c1, c2; row k of (R X) Rᵀ is R (row k of a).
    [
        r.rotate([c0[0], c1[0], c2[0]]),
        r.rotate([c0[1], c1[1], c2[1]]),
        r.rotate([c0[2], c1[2], c2[2]]),
    ]
}

/// [`rotate_matrix`] of a symmetric matrix stored `[xx, xy, yy, xz, yz, zz]`.
#[inline(always)]
pub fn rotate_symmetric<S: Real, R: Rotate<S>>(x: &[S; 6], r: &R) -> [S; 6] {
    let c0 = r.rotate([x[0], x[1], x[3]]);
    let c1 = r.rotate([x[1], x[2], x[4]]);
    let c2 = r.rotate([x[3], x[4], x[5]]);
    let r0 = r.rotate([c0[0], c1[0], c2[0]]);
    let r1 = r.rotate([c0[1], c1[1], c2[1]]);
    let r2 = r.rotate([c0[2], c1[2], c2[2]]);
    // Rows 0, 1, 2 of the result; the lower triangle is the upper one.
    [r0[0], r0[1], r1[1], r0[2], r1[2], r2[2]]
}

/// A spatial motion vector `[v; ω]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion<S> {
    pub linear: Vec3<S>,
    pub angular: Vec3<S>,
}

/// A spatial force vector `[f; n]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force<S> {
    pub linear: Vec3<S>,
    pub angular: Vec3<S>,
}

impl<S: Real> Motion<S> {
    #[inline(always)]
    pub fn zero(zero: S) -> Motion<S> {
        Motion {
            linear: [zero; 3],
            angular: [zero; 3],
        }
    }

    #[inline(always)]
    pub fn scale(self, s: S) -> Motion<S> {
        Motion {
            linear: scale(s, self.linear),
            angular: scale(s, self.angular),
        }
    }

    /// `self × m`: `[ω × v_m + v × ω_m; ω × ω_m]`.
    #[inline(always)]
    pub fn cross_motion(self, m: Motion<S>) -> Motion<S> {
        Motion {
            linear: add(cross(self.angular, m.linear), cross(self.linear, m.angular)),
            angular: cross(self.angular, m.angular),
        }
    }

    /// `self ×* f`: `[ω × f; ω × n + v × f]`.
    #[inline(always)]
    pub fn cross_force(self, f: Force<S>) -> Force<S> {
        Force {
            linear: cross(self.angular, f.linear),
            angular: add(cross(self.angular, f.angular), cross(self.linear, f.linear)),
        }
    }

    /// `fᵀ m`: the power of `f` on `m`.
    #[inline(always)]
    pub fn dot(self, f: Force<S>) -> S {
        dot(self.linear, f.linear) + dot(self.angular, f.angular)
    }

    pub fn to_array(self) -> [S; 6] {
        let ([a, b, c], [d, e, f]) = (self.linear, self.angular);
        [a, b, c, d, e, f]
    }
}

impl<S: Real> Force<S> {
    #[inline(always)]
    pub fn zero(zero: S) -> Force<S> {
        Force {
            linear: [zero; 3],
            angular: [zero; 3],
        }
    }

    #[inline(always)]
    pub fn scale(self, s: S) -> Force<S> {
        Force {
            linear: scale(s, self.linear),
            angular: scale(s, self.angular),
        }
    }

    pub fn to_array(self) -> [S; 6] {
        let ([a, b, c], [d, e, f]) = (self.linear, self.angular);
        [a, b, c, d, e, f]
    }
}

impl<S: Real> core::ops::Add for Motion<S> {
    type Output = Motion<S>;
    #[inline(always)]
    fn add(self, o: Motion<S>) -> Motion<S> {
        Motion {
            linear: add(self.linear, o.linear),
            angular: add(self.angular, o.angular),
        }
    }
}

impl<S: Real> core::ops::Add for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn add(self, o: Force<S>) -> Force<S> {
        Force {
            linear: add(self.linear, o.linear),
            angular: add(self.angular, o.angular),
        }
    }
}

impl<S: Real> core::ops::Sub for Force<S> {
    type Output = Force<S>;
    #[inline(always)]
    fn sub(self, o: Force<S>) -> Force<S> {
        Force {
            linear: sub(self.linear, o.linear),
            angular: sub(self.angular, o.angular),
        }
    }
}

/// A rigid placement: `x_parent = rotation · x_child + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3<S> {
    pub rotation: Mat3<S>,
    pub translation: Vec3<S>,
}

impl<S: Real> Se3<S> {
    pub fn identity(zero: S, one: S) -> Se3<S> {
        Se3 {
            rotation: [[one, zero, zero], [zero, one, zero], [zero, zero, one]],
            translation: [zero; 3],
        }
    }

    /// `self · other`: first `other`, then `self`.
    #[inline(always)]
    pub fn compose(&self, other: &Se3<S>) -> Se3<S> {
        Se3 {
            rotation: mat_mul(&self.rotation, &other.rotation),
            translation: add(mat_vec(&self.rotation, other.translation), self.translation),
        }
    }

    /// A point of the child frame in the parent frame.
    #[inline(always)]
    pub fn transform_point(&self, x: Vec3<S>) -> Vec3<S> {
        add(mat_vec(&self.rotation, x), self.translation)
    }

    /// A child-frame motion in the parent frame: `ω' = R ω`, `v' = R v + p × ω'`.
    #[inline(always)]
    pub fn act_motion(&self, m: Motion<S>) -> Motion<S> {
        let angular = mat_vec(&self.rotation, m.angular);
        Motion {
            linear: add(mat_vec(&self.rotation, m.linear), cross(self.translation, angular)),
            angular,
        }
    }

    /// A parent-frame motion in the child frame: `ω' = Rᵀ ω`, `v' = Rᵀ (v − p × ω)`.
    #[inline(always)]
    pub fn inv_act_motion(&self, m: Motion<S>) -> Motion<S> {
        Motion {
            linear: mat_tr_vec(&self.rotation, sub(m.linear, cross(self.translation, m.angular))),
            angular: mat_tr_vec(&self.rotation, m.angular),
        }
    }

    /// A child-frame force in the parent frame: `f' = R f`, `n' = R n + p × f'`.
    #[inline(always)]
    pub fn act_force(&self, f: Force<S>) -> Force<S> {
        let linear = mat_vec(&self.rotation, f.linear);
        Force {
            linear,
            angular: add(mat_vec(&self.rotation, f.angular), cross(self.translation, linear)),
        }
    }

    /// A parent-frame force in the child frame: `f' = Rᵀ f`, `n' = Rᵀ (n − p × f)`.
    #[inline(always)]
    pub fn inv_act_force(&self, f: Force<S>) -> Force<S> {
        Force {
            linear: mat_tr_vec(&self.rotation, f.linear),
            angular: mat_tr_vec(&self.rotation, sub(f.angular, cross(self.translation, f.linear))),
        }
    }
}

/// A rigid body's spatial inertia about its frame origin, by its 10 standard
/// parameters: mass `m`, first moment `h = m c`, rotational inertia `I` about the
/// origin (symmetric, stored `[xx, xy, yy, xz, yz, zz]`, Pinocchio's order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia<S> {
    pub mass: S,
    pub first_moment: Vec3<S>,
    pub rotational: [S; 6],
}

/// `I v` for `I` stored `[xx, xy, yy, xz, yz, zz]`.
#[inline(always)]
fn sym_vec<S: Real>(i: &[S; 6], v: Vec3<S>) -> Vec3<S> {
    [
        i[0].mul_add(v[0], i[1].mul_add(v[1], i[3] * v[2])),
        i[1].mul_add(v[0], i[2].mul_add(v[1], i[4] * v[2])),
        i[3].mul_add(v[0], i[4].mul_add(v[1], i[5] * v[2])),
    ]
}

#[inline(always)]
fn sym_full<S: Real>(i: &[S; 6]) -> Mat3<S> {
    [[i[0], i[1], i[3]], [i[1], i[2], i[4]], [i[3], i[4], i[5]]]
}

impl<S: Real> Inertia<S> {
    /// From `[m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (inertia about the
    /// frame origin).
    #[inline(always)]
    pub fn from_params(p: &[S]) -> Inertia<S> {
        Inertia {
            mass: p[0],
            first_moment: [p[1], p[2], p[3]],
            rotational: [p[4], p[5], p[6], p[7], p[8], p[9]],
        }
    }

    pub fn zero(zero: S) -> Inertia<S> {
        Inertia {
            mass: zero,
            first_moment: [zero; 3],
            rotational: [zero; 6],
        }
    }

    /// `I m`: `f = m v − h × ω`, `n = I ω + h × v`.
    #[inline(always)]
    pub fn apply(&self, m: Motion<S>) -> Force<S> {
        Force {
            linear: sub(scale(self.mass, m.linear), cross(self.first_moment, m.angular)),
            angular: add(sym_vec(&self.rotational, m.angular), cross(self.first_moment, m.linear)),
        }
    }

    /// The wrench about the origin that moves the body with angular velocity `w`,
    /// angular acceleration `wd` and origin acceleration `a` (Newton–Euler):
    /// `f = m a + ω̇ × h + ω × (ω × h)`, `n = I ω̇ + ω × (I ω) + h × a`.
    #[inline(always)]
    pub fn newton_euler(&self, w: Vec3<S>, wd: Vec3<S>, a: Vec3<S>) -> Force<S> {
        let h = self.first_moment;
        Force {
            linear: add(scale(self.mass, a), add(cross(wd, h), cross(w, cross(w, h)))),
            angular: add(
                add(sym_vec(&self.rotational, wd), cross(w, sym_vec(&self.rotational, w))),
                cross(h, a),
            ),
        }
    }

    #[inline(always)]
    pub fn add(&self, o: &Inertia<S>) -> Inertia<S> {
        let (a, b) = (&self.rotational, &o.rotational);
        Inertia {
            mass: self.mass + o.mass,
            first_moment: add(self.first_moment, o.first_moment),
            rotational: [
                a[0] + b[0],
                a[1] + b[1],
                a[2] + b[2],
                a[3] + b[3],
                a[4] + b[4],
                a[5] + b[5],
            ],
        }
    }

    /// The same body seen from the parent frame of `x` (`x` maps this body's
    /// coordinates to the parent's): `h' = R h + m p`, and about the parent origin
    /// `I' = R I Rᵀ + m(|p|² E − p pᵀ) + 2(p·h_R) E − h_R pᵀ − p h_Rᵀ` with `h_R = R h`.
    #[inline(always)]
    pub fn act(&self, x: &Se3<S>) -> Inertia<S> {
        self.act_with(&x.rotation, x.translation)
    }

    /// [`Inertia::act`] for the placement of rotation `r` and translation `p`.
    #[inline(always)]
    pub fn act_with<R: Rotate<S>>(&self, r: &R, p: Vec3<S>) -> Inertia<S> {
        let h = r.rotate(self.first_moment);
        let rot = rotate_symmetric(&self.rotational, r);
        let e = |a: usize, b: usize| rot[[[0, 1, 3], [1, 2, 4], [3, 4, 5]][a][b]];
        // m(|p|² E − p pᵀ) + 2(p·h) E − h pᵀ − p hᵀ, with mp = m p:
        // diagonal a: m(|p|² − p_a²) + 2 p·h − 2 h_a p_a; off-diagonal: −m p_a p_b − h_a p_b − p_a h_b.
        let mp = scale(self.mass, p);
        let w = add(mp, h); // m p + h
        let pw = dot(p, add(mp, add(h, h))); // m|p|² + 2 p·h
        let shift = |a: usize, b: usize| {
            if a == b {
                pw - p[a] * (w[a] + h[a])
            } else {
                -(p[a] * w[b] + h[a] * p[b])
            }
        };
        Inertia {
            mass: self.mass,
            first_moment: add(h, mp),
            rotational: [
                e(0, 0) + shift(0, 0),
                e(0, 1) + shift(0, 1),
                e(1, 1) + shift(1, 1),
                e(0, 2) + shift(0, 2),
                e(1, 2) + shift(1, 2),
                e(2, 2) + shift(2, 2),
            ],
        }
    }

    /// As a general symmetric 6 × 6 operator (an articulated inertia).
    pub fn to_matrix(&self, zero: S) -> SpatialMatrix<S> {
        let m = self.mass;
        SpatialMatrix {
            a: [[m, zero, zero], [zero, m, zero], [zero, zero, m]],
            b: skew(neg(self.first_moment), zero),
            d: sym_full(&self.rotational),
        }
    }
}

/// A symmetric 6 × 6 operator from motions to forces, `[[a, b], [bᵀ, d]]` (an
/// articulated-body inertia): `f = a v + b ω`, `n = bᵀ v + d ω`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialMatrix<S> {
    pub a: Mat3<S>,
    pub b: Mat3<S>,
    pub d: Mat3<S>,
}

impl<S: Real> SpatialMatrix<S> {
    #[inline(always)]
    pub fn apply(&self, m: Motion<S>) -> Force<S> {
        Force {
            linear: add(mat_vec(&self.a, m.linear), mat_vec(&self.b, m.angular)),
            angular: add(mat_tr_vec(&self.b, m.linear), mat_vec(&self.d, m.angular)),
        }
    }

    #[inline(always)]
    pub fn add(&self, o: &SpatialMatrix<S>) -> SpatialMatrix<S> {
        SpatialMatrix {
            a: mat_add(&self.a, &o.a),
            b: mat_add(&self.b, &o.b),
            d: mat_add(&self.d, &o.d),
        }
    }

    /// `self − u wᵀ` for forces `u`, `w` (stacked `[f; n]`), kept symmetric when the
    /// caller sums symmetric terms.
    #[inline(always)]
    pub fn sub_outer(&self, u: Force<S>, w: Force<S>) -> SpatialMatrix<S> {
        let outer = |x: Vec3<S>, y: Vec3<S>| [scale(x[0], y), scale(x[1], y), scale(x[2], y)];
        SpatialMatrix {
            a: mat_sub(&self.a, &outer(u.linear, w.linear)),
            b: mat_sub(&self.b, &outer(u.linear, w.angular)),
            d: mat_sub(&self.d, &outer(u.angular, w.angular)),
        }
    }

    /// The same operator with `a` and `d` made exactly symmetric from their upper
    /// triangles (after a sum of [`SpatialMatrix::sub_outer`] that is symmetric).
    #[inline(always)]
    pub fn symmetrised(&self) -> SpatialMatrix<S> {
        SpatialMatrix {
            a: mirror_upper(self.a),
            b: self.b,
            d: mirror_upper(self.d),
        }
    }

    /// The operator seen from the parent frame of `x`: `X* A X⁻¹`, by blocks with
    /// `B = diag(R, R) A diag(Rᵀ, Rᵀ)` and `P = [p]×`:
    /// `[[B11, B12 − B11 P], [·, P B12 + B22 − (P B11 + B21) P]]`.
    #[inline(always)]
    pub fn act(&self, x: &Se3<S>) -> SpatialMatrix<S> {
        self.act_with(&x.rotation, x.translation)
    }

    /// [`SpatialMatrix::act`] for the placement of rotation `r` and translation `p`.
    #[inline(always)]
    pub fn act_with<R: Rotate<S>>(&self, r: &R, p: Vec3<S>) -> SpatialMatrix<S> {
        let (b11, b12, b22) = (
            rotate_matrix(&self.a, r),
            rotate_matrix(&self.b, r),
            rotate_matrix(&self.d, r),
        );
        let b21 = transpose(&b12);
        // (P B11 + B21) P, and P B12.
        let left = mat_add(&skew_mul(p, &b11), &b21);
        SpatialMatrix {
            a: mirror_upper(b11),
            b: mat_sub(&b12, &mul_skew(&b11, p)),
            d: mirror_upper(mat_sub(&mat_add(&skew_mul(p, &b12), &b22), &mul_skew(&left, p))),
        }
    }
}
