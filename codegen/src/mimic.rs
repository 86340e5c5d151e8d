//! Generated code for a model whose joints follow others (URDF `<mimic>`, MJCF
//! `<equality><joint>`): as the run-time algorithms do it (`dyngen_algo`'s
//! `Multibody::with_mimics`), each function's graph is built on the tree, every joint
//! its own coordinate, at `q_tree = E q + b`, `v_tree = E v`, `a_tree = E a`, and what
//! it returns is reduced with `E`: `τ = Eᵀ τ_tree`, `M = Eᵀ M_tree E`, `J = J_tree E`,
//! `Y = Eᵀ Y_tree`. The substitution is symbolic, so a follower's multiplier and
//! offset fold into the expressions and nothing of the tree's extra coordinates is
//! left in the emitted code. Forward dynamics and `M⁻¹` are not tree recursions then:
//! they factor the reduced `M` densely (`Model::coordinate_parents` is a chain).

use crate::algo::{ARG_A, ARG_Q, ARG_V};
use crate::sym::{Expr, Graph, NodeId};
use dyngen_model::Model;

/// How a block of a function's outputs (row-major) is reduced.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Block {
    /// `len` outputs that index no coordinate (placements, wrenches, parameters).
    Plain(usize),
    /// A matrix with a row per velocity coordinate (torques, regressors): `Eᵀ X`.
    Rows { cols: usize },
    /// A matrix with a column per velocity coordinate (Jacobians): `X E`.
    Cols { rows: usize },
    /// A square matrix over the velocity coordinates (`M`, derivatives): `Eᵀ X E`.
    Both,
}

/// The tree of a model with followers and how its coordinates follow the model's.
struct Followers {
    tree: Model,
    /// Per tree position coordinate: the model's coordinate, the multiplier, the offset.
    q: Vec<(u32, f64, f64)>,
    /// Per tree velocity coordinate: the model's coordinate and the multiplier.
    v: Vec<(u32, f64)>,
    nv: usize,
}

impl Followers {
    fn of(model: &Model) -> Option<Followers> {
        model.mimic_joint()?;
        let mut tree = model.clone();
        tree.joints.iter_mut().for_each(|j| j.mimic = None);
        let (mut q, mut v) = (Vec::new(), Vec::new());
        for (k, joint) in model.joints.iter().enumerate() {
            // A follower and its leader have one coordinate each (checked on load).
            let (leader, multiplier, offset) = joint
                .mimic
                .map_or((k + 1, 1.0, 0.0), |m| (m.leader, m.multiplier, m.offset));
            let (qo, vo) = (model.q_offset(leader), model.v_offset(leader));
            q.extend((0..joint.kind.nq()).map(|c| ((qo + c) as u32, multiplier, offset)));
            v.extend((0..joint.kind.nv()).map(|c| ((vo + c) as u32, multiplier)));
        }
        Some(Followers {
            tree,
            q,
            v,
            nv: model.nv(),
        })
    }

    /// The tree's coordinates as expressions of the model's.
    fn substitute(&self, g: &Graph, outputs: &[NodeId]) -> Vec<NodeId> {
        g.substitute(outputs, |arg, index| {
            let i = index as usize;
            match arg {
                ARG_Q => {
                    let (c, k, b) = self.q[i];
                    Some(g.constant(k) * g.input(ARG_Q, c) + g.constant(b))
                }
                ARG_V | ARG_A => {
                    let (c, k) = self.v[i];
                    Some(g.constant(k) * g.input(arg, c))
                }
                _ => None,
            }
        })
    }

    /// `Eᵀ x` over the tree's velocity coordinates `x` (one expression each; the
    /// multipliers ±1 of most linkages fold to no product).
    fn reduce<'g>(&self, g: &'g Graph, x: &[Expr<'g>]) -> Vec<Expr<'g>> {
        let mut out = vec![g.zero(); self.nv];
        for (&(c, k), &e) in self.v.iter().zip(x) {
            out[c as usize] = out[c as usize] + g.constant(k) * e;
        }
        out
    }

    fn reduce_blocks(&self, g: &Graph, outputs: &[NodeId], layout: &[Block]) -> Vec<NodeId> {
        let nt = self.v.len();
        let mut out = Vec::new();
        let mut rest = outputs;
        for &block in layout {
            let (rows, cols) = match block {
                Block::Plain(len) => (1, len),
                Block::Rows { cols } => (nt, cols),
                Block::Cols { rows } => (rows, nt),
                Block::Both => (nt, nt),
            };
            let (this, next) = rest.split_at(rows * cols);
            rest = next;
            let mut m: Vec<Vec<Expr<'_>>> = this
                .chunks(cols.max(1))
                .map(|r| r.iter().map(|&id| g.expr(id)).collect())
                .collect();
            if matches!(block, Block::Cols { .. } | Block::Both) {
                m = m.iter().map(|row| self.reduce(g, row)).collect();
            }
            if matches!(block, Block::Rows { .. } | Block::Both) {
                let width = m.first().map_or(0, Vec::len);
                let columns: Vec<Vec<Expr<'_>>> = (0..width)
                    .map(|c| self.reduce(g, &m.iter().map(|row| row[c]).collect::<Vec<_>>()))
                    .collect();
                m = (0..self.nv)
                    .map(|r| columns.iter().map(|col| col[r]).collect())
                    .collect();
            }
            out.extend(m.iter().flatten().map(|e| e.id()));
        }
        assert!(
            rest.is_empty(),
            "the layout covers {} outputs fewer than built",
            rest.len()
        );
        out
    }
}

/// The outputs of `build` for `model`, laid out as `layout` says: built on the model
/// itself, or, when joints follow others, on its tree and reduced (see the module).
pub(crate) fn build(
    g: &Graph,
    model: &Model,
    layout: &[Block],
    build: impl FnOnce(&Graph, &Model) -> Vec<NodeId>,
) -> Vec<NodeId> {
    match Followers::of(model) {
        None => build(g, model),
        Some(f) => {
            let outputs = build(g, &f.tree);
            let outputs = f.substitute(g, &outputs);
            f.reduce_blocks(g, &outputs, layout)
        }
    }
}

/// Whether generated functions that follow the tree's structure (the articulated-body
/// recursion, frame Jacobians composed of per-coordinate axes) must be replaced by
/// their dense forms.
pub(crate) fn has_followers(model: &Model) -> bool {
    model.mimic_joint().is_some()
}
