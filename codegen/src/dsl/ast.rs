//! The syntax tree of one `robot!` invocation, as written: user numbering, every
//! value with the source range it came from, so checks can point at it. A part that
//! failed to parse is `None` (its error is already recorded) and is skipped by the
//! checks, which keeps one mistake from causing a cascade of follow-up errors.

use super::ctxt::Loc;
use super::symbol::Symbol;
use dyngen_model::JointKind;

/// The whole invocation.
pub struct Robot {
    pub name: Attr<syn::Ident>,
    pub urdf: Attr<syn::LitStr>,
    pub gravity: Attr<Vector>,
    pub incidence: Attr<Matrix>,
    pub joints: Attr<JointList>,
    pub body_joint_vectors: Attr<VectorTable>,
    pub bodies: Attr<BodyTable>,
    pub frames: Attr<FrameTable>,
    pub functions: Attr<crate::Selection>,
}

/// One top-level `keyword: value`.
pub struct Attr<T> {
    pub symbol: Symbol,
    /// The keyword as written, when given.
    pub key: Option<syn::Ident>,
    /// The value, when given and well-formed.
    pub value: Option<T>,
}

impl<T> Attr<T> {
    pub fn none(symbol: Symbol) -> Attr<T> {
        Attr {
            symbol,
            key: None,
            value: None,
        }
    }

    pub fn is_given(&self) -> bool {
        self.key.is_some()
    }
}

/// A number literal, with its optional leading minus.
#[derive(Clone, Copy, Debug)]
pub struct Num {
    pub value: f64,
    /// The value when the literal is an integer.
    pub int: Option<i64>,
    pub loc: Loc,
}

/// `[x, y, z]`.
#[derive(Clone, Copy, Debug)]
pub struct Vector {
    pub parts: [Num; 3],
    pub loc: Loc,
}

impl Vector {
    pub fn value(&self) -> [f64; 3] {
        self.parts.map(|p| p.value)
    }
}

/// The incidence matrix, rows bodies `0..=n`, columns joints `1..=n`.
pub struct Matrix {
    /// `None` for a row that is not a list.
    pub rows: Vec<Option<Row>>,
    pub loc: Loc,
}

pub struct Row {
    pub entries: Vec<Entry>,
    pub loc: Loc,
}

pub struct Entry {
    /// `None` when the entry is not an integer literal.
    pub value: Option<i64>,
    pub loc: Loc,
}

/// `joints: [...]`; one slot per element written, `None` where it did not parse.
pub struct JointList {
    pub joints: Vec<Option<Joint>>,
    pub loc: Loc,
}

pub struct Joint {
    pub kind: JointKind,
    pub kind_loc: Loc,
    pub axis: Option<Axis>,
    pub rest: Option<Vector>,
    pub limits: Option<Limits>,
}

/// A joint axis in the joint (= outboard body) frame.
pub struct Axis {
    pub value: [f64; 3],
    pub loc: Loc,
}

/// `limits: [lower, upper]`.
pub struct Limits {
    pub key_loc: Loc,
    pub lower: Num,
    pub upper: Num,
    pub loc: Loc,
}

/// A non-negative or negative integer used as a body or joint number.
#[derive(Clone, Copy, Debug)]
pub struct Index {
    pub value: i64,
    pub loc: Loc,
}

/// `body_joint_vectors: { (i, a): [x, y, z], ... }`.
pub struct VectorTable {
    pub entries: Vec<VectorEntry>,
    pub loc: Loc,
}

pub struct VectorEntry {
    pub body: Index,
    pub joint: Index,
    /// The `(i, a)` key.
    pub key_loc: Loc,
    pub vector: Option<Vector>,
    /// The whole `(i, a): [..]` entry.
    pub loc: Loc,
}

/// `bodies: { i: kind(...), ... }`.
pub struct BodyTable {
    pub entries: Vec<BodyEntry>,
    pub loc: Loc,
}

pub struct BodyEntry {
    pub index: Index,
    pub body: Option<Body>,
}

pub struct Body {
    pub shape: Shape,
    /// The `cylinder`/`principal` word.
    pub kind_loc: Loc,
}

/// A body's mass properties in its centroidal principal frame.
pub enum Shape {
    /// A homogeneous cylinder whose axis is body axis `axis.0` (0, 1, 2 for x, y, z).
    Cylinder {
        mass: Num,
        radius: Num,
        length: Num,
        axis: (usize, Loc),
    },
    /// Mass and principal moments `[J1, J2, J3]` about the centre of mass.
    Principal { mass: Num, moments: Vector },
}

impl Shape {
    pub fn mass(&self) -> Num {
        match self {
            Shape::Cylinder { mass, .. } | Shape::Principal { mass, .. } => *mass,
        }
    }

    /// Principal moments `[J1, J2, J3]` about the centre of mass, in body axes.
    pub fn moments(&self) -> [f64; 3] {
        match self {
            Shape::Cylinder {
                mass,
                radius,
                length,
                axis,
            } => {
                let (m, r, l) = (mass.value, radius.value, length.value);
                let across = m * (3.0 * r * r + l * l) / 12.0;
                let mut j = [across; 3];
                j[axis.0] = m * r * r / 2.0;
                j
            }
            Shape::Principal { moments, .. } => moments.value(),
        }
    }
}

/// `frames: { name: (i, [x, y, z], rest: [r, p, y]), ... }`.
pub struct FrameTable {
    pub entries: Vec<FrameEntry>,
}

/// One named frame fixed to body `i`: its origin at `position` from the body's centre
/// of mass (for the base, from the base origin) in the body's axes, its axes rotated
/// by `rest` (roll-pitch-yaw) from the body's.
pub struct FrameEntry {
    pub name: syn::Ident,
    /// `None` when the value did not parse (its error is recorded); the name is kept
    /// for the duplicate check.
    pub frame: Option<Frame>,
}

pub struct Frame {
    pub body: Index,
    pub position: Vector,
    pub rest: Option<Vector>,
}
