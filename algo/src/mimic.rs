//! Joints that follow others ([`Mimic`]): the algorithms run on the tree, every joint
//! with its own coordinate, from `q_tree = E q + b`, `v_tree = E v`, `a_tree = E a`,
//! and what they return along the coordinates is reduced with `E`: `τ = Eᵀ τ_tree`
//! (a follower's effort does its virtual work through its leader), `M = Eᵀ M_tree E`,
//! Jacobians `J_tree E`. This is Pinocchio's mimic joint, whose results it equals.
//!
//! [`Mimic`]: crate::Mimic

use crate::kinematics::check_len;
use crate::multibody::{Multibody, Reduction, Workspace};
use crate::Real;
use alloc::vec::Vec;

/// The tree's coordinates and results, for a [`Workspace`] of a multibody with
/// [`Mimic`] joints (empty otherwise).
#[derive(Clone, Debug)]
pub(crate) struct MimicBuffers<S> {
    pub(crate) q: Vec<S>,
    pub(crate) v: Vec<S>,
    pub(crate) a: Vec<S>,
    /// A result along the tree's coordinates (at most `nv_tree × max(nv_tree, 10 n, 6)`).
    pub(crate) out: Vec<S>,
    /// `Eᵀ` times a matrix (`nv × nv_tree`).
    pub(crate) half: Vec<S>,
    /// Forward dynamics: `M + diag(Ia)` and its factor (`nv × nv`), and `nv` zeros.
    pub(crate) matrix: Vec<S>,
    pub(crate) zero: Vec<S>,
}

impl<S> Default for MimicBuffers<S> {
    fn default() -> Self {
        MimicBuffers {
            q: Vec::new(),
            v: Vec::new(),
            a: Vec::new(),
            out: Vec::new(),
            half: Vec::new(),
            matrix: Vec::new(),
            zero: Vec::new(),
        }
    }
}

impl<S: Real> MimicBuffers<S> {
    pub(crate) fn new(multibody: &Multibody, z: S) -> Self {
        if multibody.reduction.is_none() {
            return MimicBuffers::default();
        }
        let (nv, tq, tv) = (multibody.nv(), multibody.tree_nq(), multibody.tree_nv());
        let widest = tv.max(crate::PARAMS_PER_BODY * multibody.bodies()).max(6);
        MimicBuffers {
            q: alloc::vec![z; tq],
            v: alloc::vec![z; tv],
            a: alloc::vec![z; tv],
            out: alloc::vec![z; tv * widest],
            half: alloc::vec![z; nv * widest],
            matrix: alloc::vec![z; nv * nv],
            zero: alloc::vec![z; nv],
        }
    }
}

/// `x · a` without a multiplication where `a` is 1 (bit for bit the tree's value).
#[inline(always)]
pub(crate) fn times<S: Real>(c: S::Context, x: S, a: f64) -> S {
    if a == 1.0 {
        x
    } else {
        S::constant(c, a) * x
    }
}

impl Reduction {
    /// `q_tree = E q + b`.
    pub(crate) fn expand_q<S: Real>(&self, c: S::Context, q: &[S], out: &mut [S]) {
        for (o, &(k, a, b)) in out.iter_mut().zip(&self.q) {
            *o = if b == 0.0 {
                times(c, q[k], a)
            } else {
                times(c, q[k], a) + S::constant(c, b)
            };
        }
    }

    /// `v_tree = E v` (velocities and accelerations).
    pub(crate) fn expand_v<S: Real>(&self, c: S::Context, v: &[S], out: &mut [S]) {
        for (o, &(k, a)) in out.iter_mut().zip(&self.v) {
            *o = times(c, v[k], a);
        }
    }

    /// `out = Eᵀ full`, `full` being `nv_tree × cols` row-major, `out` `nv × cols`.
    pub(crate) fn reduce_rows<S: Real>(&self, c: S::Context, full: &[S], cols: usize, out: &mut [S]) {
        out.fill(S::constant(c, 0.0));
        for (d, &(k, a)) in self.v.iter().enumerate() {
            for col in 0..cols {
                let o = &mut out[k * cols + col];
                *o = *o + times(c, full[d * cols + col], a);
            }
        }
    }

    /// `out = full E`, `full` being `rows × nv_tree` row-major, `out` `rows × nv`.
    pub(crate) fn reduce_cols<S: Real>(&self, c: S::Context, full: &[S], rows: usize, out: &mut [S]) {
        let (tree, nv) = (self.v.len(), self.nv);
        out.fill(S::constant(c, 0.0));
        for r in 0..rows {
            for (d, &(k, a)) in self.v.iter().enumerate() {
                let o = &mut out[r * nv + k];
                *o = *o + times(c, full[r * tree + d], a);
            }
        }
    }
}

/// How a result along the tree's coordinates becomes the multibody's, written into
/// the slice it holds.
pub(crate) enum Reduce<'a, S> {
    /// Nothing to reduce (the result is not along the coordinates).
    None,
    /// `Eᵀ x`, `x` having this many columns.
    Rows(usize, &'a mut [S]),
    /// `x E`, `x` having this many rows.
    Cols(usize, &'a mut [S]),
    /// `Eᵀ x E`.
    Both(&'a mut [S]),
}

/// Runs `tree` (an algorithm on the tree's coordinates) on `[q, v, a]` expanded
/// (those given: the others hold what they last held, for `tree` to leave unread),
/// with room for its result along the tree's coordinates, which it then reduces as
/// `reduce` says.
pub(crate) fn on_tree<S: Real, R>(
    multibody: &Multibody,
    workspace: &mut Workspace<S>,
    inputs: [Option<&[S]>; 3],
    reduce: Reduce<'_, S>,
    tree: impl FnOnce(&mut Workspace<S>, [&[S]; 3], &mut [S]) -> R,
) -> R {
    let r = multibody.reduction.as_deref().expect("a multibody with mimic joints");
    let c = workspace.context;
    let mut b = core::mem::take(&mut workspace.mimic);
    let [q, v, a] = inputs;
    if let Some(q) = q {
        check_len("q", q, r.nq);
        r.expand_q(c, q, &mut b.q);
    }
    for (name, x, buffer) in [("v", v, &mut b.v), ("a", a, &mut b.a)] {
        if let Some(x) = x {
            check_len(name, x, r.nv);
            r.expand_v(c, x, buffer);
        }
    }
    let (tree_nv, nv) = (r.v.len(), r.nv);
    let out_len = match &reduce {
        Reduce::None => 0,
        Reduce::Rows(k, _) | Reduce::Cols(k, _) => k * tree_nv,
        Reduce::Both(_) => tree_nv * tree_nv,
    };
    let result = tree(workspace, [&b.q, &b.v, &b.a], &mut b.out[..out_len]);
    let full = &b.out[..out_len];
    match reduce {
        Reduce::None => {}
        Reduce::Rows(cols, out) => r.reduce_rows(c, full, cols, out),
        Reduce::Cols(rows, out) => r.reduce_cols(c, full, rows, out),
        Reduce::Both(out) => {
            r.reduce_rows(c, full, tree_nv, &mut b.half[..nv * tree_nv]);
            r.reduce_cols(c, &b.half[..nv * tree_nv], nv, out);
        }
    }
    workspace.mimic = b;
    result
}
