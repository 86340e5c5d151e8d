//! The unchecked description every front end produces, and the one place where it is
//! checked and turned into a [`Model`]: tree structure, joint types, axes, inertials;
//! fixed joints merged; bodies numbered in regular labelling (depth first; siblings in
//! declaration order, or by joint name as Pinocchio and urdfdom number them).

use crate::error::{Element, ErrorKind, ModelError};
use crate::ir::{Body, Frame, Inertial, Joint, JointDynamics, JointKind, JointMimic, Limits, Model, Placement};
use crate::math;
use std::collections::HashMap;

/// A joint type as declared, before checking.
#[derive(Clone, Debug, PartialEq)]
pub enum DeclaredJointType {
    Moving(JointKind),
    Fixed,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LinkDesc {
    pub name: String,
    pub inertial: Option<Inertial>,
    pub line: Option<usize>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct JointDesc {
    pub name: String,
    pub kind: DeclaredJointType,
    pub parent: String,
    pub child: String,
    pub origin: Placement,
    pub axis: [f64; 3],
    pub limits: Option<Limits>,
    /// `<dynamics damping friction>`; zero when not given.
    pub dynamics: JointDynamics,
    pub line: Option<usize>,
}

/// A joint that follows another (URDF `<mimic>`, a linear MJCF `<equality><joint>`):
/// `q = multiplier · q_leader + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct MimicDesc {
    /// The following joint and its leader, by name.
    pub joint: String,
    pub leader: String,
    pub multiplier: f64,
    pub offset: f64,
    pub line: Option<usize>,
}

/// A robot as a front end read it: links and joints by name, in declaration order.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    pub name: String,
    pub gravity: [f64; 3],
    pub links: Vec<LinkDesc>,
    pub joints: Vec<JointDesc>,
    /// The moving joints that follow others.
    pub mimics: Vec<MimicDesc>,
}

/// The order in which the depth-first numbering visits a link's child joints.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SiblingOrder {
    /// As declared (the `robot!` DSL: the user's own order).
    #[default]
    Declaration,
    /// By joint name, as urdfdom stores them and so as Pinocchio numbers URDF trees.
    Name,
}

/// Default gravity, m/s², in the base frame.
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn finite_mat(m: &[[f64; 3]; 3]) -> bool {
    m.iter().all(finite3)
}

/// Relative tolerance for CAD rounding: principal moments `J1 ≤ J2 ≤ J3` (about the
/// centre of mass) that break positive definiteness (`J1 ≤ 0`) or the triangle
/// inequality (`J3 > J1 + J2`) by at most this fraction of the largest moment
/// ([`inertia_violation`]) are accepted with a warning, as written; a strict build
/// refuses them. CAD tools export inertias with a few significant digits, and
/// thin parts sit on the triangle boundary, so their files break it by parts in ten
/// thousand: 1e-3 accepts that rounding (Pinocchio loads such files without a word)
/// while any real mistake (a moment off by a factor, a swapped entry) stays an
/// error. Where consistency is needed, use [`Inertial::nearest_physical`].
pub const INERTIA_TOLERANCE: f64 = 1e-3;

/// How far principal moments `ev` (ascending) are from a physical inertia, as a
/// fraction of the largest magnitude: the larger of `−J1` and `J3 − J1 − J2`, over
/// `max |J|`; 0 when both hold (a zero tensor counts as physical).
pub fn inertia_violation(ev: [f64; 3]) -> f64 {
    let scale = ev.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return if scale == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let worst = (-ev[0]).max(ev[2] - ev[0] - ev[1]);
    if worst > 0.0 {
        worst / scale
    } else {
        0.0
    }
}

/// The physically consistent moments nearest to `ev` (ascending): negative or zero
/// moments raised to `1e-9 · max |J|`, then, if `J3 > J1 + J2`, the moments projected
/// onto `J3 = J1 + J2` (each moved by `(J3 − J1 − J2) / 3`, the least change in the
/// Euclidean norm; order is kept).
pub fn nearest_physical_moments(ev: [f64; 3]) -> [f64; 3] {
    let scale = ev.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let floor = 1e-9 * scale;
    let mut j = ev.map(|x| x.max(floor));
    let excess = j[2] - j[0] - j[1];
    if excess > 0.0 {
        let d = excess / 3.0;
        j = [j[0] + d, j[1] + d, j[2] - d];
    }
    j
}

/// Checks one body's inertial: finite, mass > 0, inertia about the centre of mass
/// positive definite and satisfying the triangle inequalities.
pub fn check_inertial(inertial: &Inertial) -> Result<(), ErrorKind> {
    check_finite(inertial)?;
    if inertial.mass <= 0.0 {
        return Err(ErrorKind::NonPositiveMass(inertial.mass));
    }
    let (ev, _) = inertial.principal_axes();
    if ev.iter().any(|&x| x <= 0.0) {
        return Err(ErrorKind::NotPositiveDefinite(ev));
    }
    check_triangle(ev)
}

/// Checks that an inertial is physical: finite, mass ≥ 0, inertia about the centre
/// of mass positive semi-definite and satisfying the triangle inequalities (point
/// masses and massless frames pass, where [`check_inertial`] wants a strictly
/// positive body). An identified inertial is held to this before it is written.
pub fn check_physical(inertial: &Inertial) -> Result<(), ErrorKind> {
    check_finite(inertial)?;
    if inertial.mass < 0.0 {
        return Err(ErrorKind::NonPositiveMass(inertial.mass));
    }
    let (ev, _) = inertial.principal_axes();
    // Thin and flat parts have a zero moment that rounding can make slightly negative.
    if ev[0] < -1e-9 * (ev[0].abs() + ev[1].abs() + ev[2].abs()) {
        return Err(ErrorKind::NotPositiveDefinite(ev));
    }
    check_triangle(ev)
}

/// Largest magnitude of any number of a description in SI units (a length in m, a
/// mass in kg, an inertia in kg·m², gravity, friction): far beyond any machine, and
/// small enough that the products the dynamics form stay finite. A larger value is
/// a unit mistake or a damaged file.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// Finite and within [`MAX_MAGNITUDE`], or the error naming `what`.
fn check_value(what: &'static str, values: &[f64]) -> Result<(), ErrorKind> {
    match values.iter().find(|x| x.is_nan() || x.abs() > MAX_MAGNITUDE) {
        Some(x) if x.is_finite() => Err(ErrorKind::OutOfRange { what, value: *x }),
        Some(_) => Err(ErrorKind::NonFiniteValue(what)),
        None => Ok(()),
    }
}

fn check_finite(inertial: &Inertial) -> Result<(), ErrorKind> {
    check_value("mass", &[inertial.mass])?;
    check_value("centre of mass", &inertial.com)?;
    check_value("inertia", inertial.inertia.as_flattened())
}

/// Principal moments `ev` (ascending) of a real body: the largest is at most the sum
/// of the other two.
fn check_triangle(ev: [f64; 3]) -> Result<(), ErrorKind> {
    match triangle_violation(ev) {
        Some(_) => Err(ErrorKind::TriangleInequality(ev)),
        None => Ok(()),
    }
}

/// The moment (index into `moments`, in the order given) that exceeds the sum of
/// the other two, if one does: no rigid body has one (`J1 + J2 − J3 = 2∫z² dm ≥ 0`).
/// Thin rods sit exactly on the boundary, so rounding of `1e-9` of the sum is allowed.
/// The one rule, for every front end.
pub fn triangle_violation(moments: [f64; 3]) -> Option<usize> {
    let tol = 1e-9 * (moments[0].abs() + moments[1].abs() + moments[2].abs());
    (0..3).find(|&k| moments[k] > moments[(k + 1) % 3] + moments[(k + 2) % 3] + tol)
}

/// The fixed world link and the free-flyer joint [`Description::with_free_flyer`]
/// adds, named as Pinocchio names them when it puts a `JointModelFreeFlyer` under a
/// URDF's root link.
pub const WORLD_LINK: &str = "universe";
/// See [`WORLD_LINK`].
pub const FREE_FLYER_JOINT: &str = "root_joint";

/// Options every front end's loader takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Refuse what would be accepted with a warning (non-physical inertias, a singular
    /// mass matrix).
    pub strict: bool,
    /// Put the description's root link on a free flyer ([`Description::with_free_flyer`]):
    /// a floating base, as Pinocchio's `buildModel(urdf, JointModelFreeFlyer())`.
    pub free_flyer: bool,
    /// Replace every non-physical body inertia by the nearest physical one
    /// ([`Inertial::nearest_physical`]: the least change of the moments, where
    /// MuJoCo's `balanceinertia` sets them to their mean), each with a warning naming
    /// the link and the moments before and after. Without it the inertia is kept as
    /// written, as Pinocchio reads it, with a warning.
    pub balance_inertia: bool,
}

impl Description {
    /// The same robot with its root link floating: a link [`WORLD_LINK`] (no
    /// inertial) and a [`JointKind::FreeFlyer`] joint [`FREE_FLYER_JOINT`] from it to
    /// the root link, whose inertial then counts. Unchanged when there is no single
    /// root (the build reports that).
    pub fn with_free_flyer(mut self) -> Description {
        let children: std::collections::HashSet<&str> = self.joints.iter().map(|j| j.child.as_str()).collect();
        let roots: Vec<&LinkDesc> = self
            .links
            .iter()
            .filter(|l| !children.contains(l.name.as_str()))
            .collect();
        let [root] = roots.as_slice() else {
            return self;
        };
        let (root, line) = (root.name.clone(), root.line);
        self.links.insert(
            0,
            LinkDesc {
                name: WORLD_LINK.into(),
                inertial: None,
                line: None,
            },
        );
        self.joints.insert(
            0,
            JointDesc {
                name: FREE_FLYER_JOINT.into(),
                kind: DeclaredJointType::Moving(JointKind::FreeFlyer),
                parent: WORLD_LINK.into(),
                child: root,
                origin: Placement::IDENTITY,
                axis: [0.0; 3],
                limits: None,
                dynamics: JointDynamics::default(),
                line,
            },
        );
        self
    }

    /// Checks the description and builds the model, collecting every error.
    pub fn build(&self) -> Result<Model, Vec<ModelError>> {
        self.build_with(SiblingOrder::Declaration)
    }

    /// [`Description::build`] with siblings numbered in the given order.
    pub fn build_with(&self, order: SiblingOrder) -> Result<Model, Vec<ModelError>> {
        self.build_checked(order, LoadOptions::default())
    }

    /// [`Description::build_with`] with the checks `options` asks for (its
    /// `free_flyer` is the front end's to apply, by [`Description::with_free_flyer`]).
    ///
    /// Inertias are checked on the merged bodies (each link with the fixed links
    /// lumped into it), not link by link: a dummy link with a rounding-noise inertia
    /// on a fixed joint is part of a physical body. A link's own values must be finite
    /// and its mass ≥ 0. A merged body that is not physical (mass 0 with a rotational
    /// inertia, a moment ≤ 0, a broken triangle inequality) is kept as written with a
    /// warning in [`Model::warnings`] (within [`INERTIA_TOLERANCE`] it is CAD rounding,
    /// beyond it the warning says so), replaced by the nearest physical one with
    /// `options.balance_inertia`, refused with `options.strict`. A moving body with no
    /// mass at all (no `<inertial>`, or mass 0) loads, as in Pinocchio; where nothing
    /// with mass moves along some coordinate, the mass matrix is singular and a warning
    /// ([`ErrorKind::SingularMassMatrix`]) names the joints (an error when strict).
    pub fn build_checked(&self, order: SiblingOrder, options: LoadOptions) -> Result<Model, Vec<ModelError>> {
        let strict = options.strict;
        let mut errors = Vec::new();
        let err = |element: Element, line: Option<usize>, kind: ErrorKind| ModelError { element, line, kind };

        if let Err(kind) = check_value("gravity", &self.gravity) {
            errors.push(err(Element::Robot, None, kind));
        }

        // Names.
        let mut link_index: HashMap<&str, usize> = HashMap::new();
        for (k, l) in self.links.iter().enumerate() {
            if link_index.insert(l.name.as_str(), k).is_some() {
                errors.push(err(Element::Link(l.name.clone()), l.line, ErrorKind::DuplicateLink));
            }
        }
        let mut joint_names: HashMap<&str, ()> = HashMap::new();
        for j in &self.joints {
            if joint_names.insert(j.name.as_str(), ()).is_some() {
                errors.push(err(Element::Joint(j.name.clone()), j.line, ErrorKind::DuplicateJoint));
            }
        }

        // Joints on their own.
        let mut parent_joint: Vec<Vec<usize>> = vec![Vec::new(); self.links.len()];
        for (k, j) in self.joints.iter().enumerate() {
            let el = || Element::Joint(j.name.clone());
            if !link_index.contains_key(j.parent.as_str()) {
                errors.push(err(el(), j.line, ErrorKind::UnknownParentLink(j.parent.clone())));
            }
            match link_index.get(j.child.as_str()) {
                Some(&c) => parent_joint[c].push(k),
                None => errors.push(err(el(), j.line, ErrorKind::UnknownChildLink(j.child.clone()))),
            }
            if !finite_mat(&j.origin.rotation) {
                errors.push(err(el(), j.line, ErrorKind::NonFiniteValue("origin")));
            } else if let Err(kind) = check_value("origin", &j.origin.translation) {
                errors.push(err(el(), j.line, kind));
            }
            if let DeclaredJointType::Moving(kind) = j.kind {
                if !kind.has_axis() {
                    // A ball joint or a free flyer has no axis: whatever is given is unused.
                } else if let Err(kind) = check_value("axis", &j.axis) {
                    errors.push(err(el(), j.line, kind));
                } else if math::norm(&j.axis) < 1e-12 {
                    errors.push(err(el(), j.line, ErrorKind::ZeroAxis));
                }
            }
            let d = j.dynamics;
            if let Err(kind) = check_value("<dynamics>", &[d.damping, d.friction]) {
                errors.push(err(el(), j.line, kind));
            } else if d.damping < 0.0 || d.friction < 0.0 {
                errors.push(err(
                    el(),
                    j.line,
                    ErrorKind::NegativeFriction {
                        damping: d.damping,
                        friction: d.friction,
                    },
                ));
            }
            if let Some(l) = j.limits {
                if !(l.lower.is_finite() && l.upper.is_finite() && l.velocity.is_finite() && l.effort.is_finite()) {
                    errors.push(err(el(), j.line, ErrorKind::NonFiniteValue("a limit")));
                } else if l.lower > l.upper {
                    errors.push(err(
                        el(),
                        j.line,
                        ErrorKind::BadLimits {
                            lower: l.lower,
                            upper: l.upper,
                        },
                    ));
                }
            }
        }
        for (c, ps) in parent_joint.iter().enumerate() {
            if ps.len() > 1 {
                let l = &self.links[c];
                let names = ps.iter().map(|&k| self.joints[k].name.clone()).collect();
                errors.push(err(
                    Element::Link(l.name.clone()),
                    l.line,
                    ErrorKind::SeveralParents(names),
                ));
            }
        }
        let roots: Vec<usize> = (0..self.links.len()).filter(|&c| parent_joint[c].is_empty()).collect();
        // A joint naming a link that does not exist, or two links of one name, leave
        // links without their parent joint: the roots and loops that follow from that
        // are not the user's mistake, the name is.
        let names_wrong = errors.iter().any(|e| {
            matches!(
                e.kind,
                ErrorKind::UnknownChildLink(_) | ErrorKind::UnknownParentLink(_) | ErrorKind::DuplicateLink
            )
        });
        if names_wrong {
            // Reported above.
        } else if roots.len() > 1 {
            let names = roots.iter().map(|&r| self.links[r].name.clone()).collect();
            errors.push(err(Element::Robot, None, ErrorKind::SeveralRoots(names)));
        } else if roots.is_empty() && !self.links.is_empty() {
            // Point at the joints of the loop (they have lines) when it can be traced.
            match self.trace_loop(&parent_joint, &link_index) {
                Some(joints) => {
                    for k in joints {
                        let j = &self.joints[k];
                        errors.push(err(Element::Joint(j.name.clone()), j.line, ErrorKind::Cycle));
                    }
                }
                None => errors.push(err(Element::Robot, None, ErrorKind::NoRoot)),
            }
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        let root = match roots.first() {
            Some(&r) => r,
            None => return Err(vec![err(Element::Robot, None, ErrorKind::NoMovingJoint)]),
        };

        // Children of each link, in joint declaration order.
        let mut child_joints: Vec<Vec<usize>> = vec![Vec::new(); self.links.len()];
        for (k, j) in self.joints.iter().enumerate() {
            child_joints[link_index[j.parent.as_str()]].push(k);
        }
        if order == SiblingOrder::Name {
            for children in &mut child_joints {
                children.sort_by(|&a, &b| self.joints[a].name.cmp(&self.joints[b].name));
            }
        }

        // Depth-first walk from the root. A moving joint is numbered when the walk
        // reaches it, so bodies come out in preorder (parent before child, siblings in
        // declaration order) even when fixed joints sit between them. Joints never
        // reached close a loop.
        let mut model = Model {
            name: self.name.clone(),
            gravity: self.gravity,
            base: self.links[root].name.clone(),
            joints: Vec::new(),
            bodies: Vec::new(),
            frames: vec![Frame {
                name: self.links[root].name.clone(),
                body: 0,
                placement: Placement::IDENTITY,
            }],
            warnings: Vec::new(),
        };
        let mut warnings = Vec::new();
        let mut body_inertial: Vec<Option<Inertial>> = Vec::new();
        let mut visited = vec![false; self.joints.len()];
        // (joint, body owning its parent link, placement of that link in the body frame)
        let mut stack: Vec<(usize, usize, Placement)> = child_joints[root]
            .iter()
            .rev()
            .map(|&k| (k, 0, Placement::IDENTITY))
            .collect();
        // Each link has at most one parent joint by now, so each joint is pushed once.
        while let Some((k, owner, placement)) = stack.pop() {
            visited[k] = true;
            let j = &self.joints[k];
            let link = link_index[j.child.as_str()];
            let origin = placement.compose(&j.origin);
            let (body, placement) = match &j.kind {
                DeclaredJointType::Moving(kind) => {
                    if *kind == JointKind::FreeFlyer && owner != 0 {
                        errors.push(err(
                            Element::Joint(j.name.clone()),
                            j.line,
                            ErrorKind::FreeFlyerNotAtRoot,
                        ));
                    }
                    let keeps_limits = matches!(kind, JointKind::Revolute | JointKind::Prismatic);
                    model.joints.push(Joint {
                        name: j.name.clone(),
                        kind: *kind,
                        parent: owner,
                        origin,
                        axis: if kind.has_axis() {
                            math::scale(1.0 / math::norm(&j.axis), &j.axis)
                        } else {
                            [0.0; 3]
                        },
                        limits: if keeps_limits { j.limits } else { None },
                        dynamics: j.dynamics,
                        mimic: None,
                    });
                    model.bodies.push(Body {
                        name: self.links[link].name.clone(),
                        inertial: Inertial::principal(0.0, [0.0; 3]),
                        merged: Vec::new(),
                    });
                    body_inertial.push(None);
                    (model.joints.len(), Placement::IDENTITY)
                }
                _ => (owner, origin),
            };
            model.frames.push(Frame {
                name: self.links[link].name.clone(),
                body,
                placement,
            });
            // Lump this link's inertial into its owning body (the base's is ignored).
            // Its values are checked here, its physics on the merged body below.
            if body > 0 {
                if let Some(inertial) = &self.links[link].inertial {
                    match check_link_values(inertial) {
                        Ok(()) => {
                            let moved = inertial.transformed(&placement);
                            let slot = &mut body_inertial[body - 1];
                            *slot = Some(match slot {
                                Some(prev) => prev.combined(&moved),
                                None => moved,
                            });
                        }
                        Err(kind) => {
                            let l = &self.links[link];
                            errors.push(err(Element::Link(l.name.clone()), l.line, kind));
                        }
                    }
                }
                if model.bodies[body - 1].name != self.links[link].name {
                    model.bodies[body - 1].merged.push(self.links[link].name.clone());
                }
            }
            // Pushed in reverse so that the first declared child is walked first.
            stack.extend(child_joints[link].iter().rev().map(|&c| (c, body, placement)));
        }
        for (k, j) in self.joints.iter().enumerate() {
            if !visited[k] {
                errors.push(err(Element::Joint(j.name.clone()), j.line, ErrorKind::Cycle));
            }
        }
        if model.joints.is_empty() && errors.is_empty() {
            errors.push(err(Element::Robot, None, ErrorKind::NoMovingJoint));
        }
        if errors.is_empty() {
            errors.extend(self.followers(&mut model));
        }
        // Only a tree without errors so far has a mass matrix worth factoring below.
        let factor = errors.is_empty();
        for (b, inertial) in body_inertial.into_iter().enumerate() {
            let body = &mut model.bodies[b];
            body.inertial = inertial.unwrap_or(Inertial::principal(0.0, [0.0; 3]));
            if is_massless_marker(&body.inertial) {
                continue;
            }
            if let Err(kind) = check_inertial(&body.inertial) {
                let line = self.links.iter().find(|l| l.name == body.name).and_then(|l| l.line);
                let e = err(Element::Link(body.name.clone()), line, kind);
                if strict {
                    errors.push(e);
                } else if options.balance_inertia
                    && matches!(
                        e.kind,
                        ErrorKind::NotPositiveDefinite(_) | ErrorKind::TriangleInequality(_)
                    )
                {
                    let balanced = body.inertial.nearest_physical();
                    warnings.push(balanced_warning(e, &balanced));
                    body.inertial = balanced;
                } else {
                    warnings.push(e);
                }
            }
        }
        let singular = if factor { singular_joints(&model) } else { Vec::new() };
        for k in singular {
            let name = &model.joints[k].name;
            let line = self.joints.iter().find(|j| j.name == *name).and_then(|j| j.line);
            let e = err(Element::Joint(name.clone()), line, ErrorKind::SingularMassMatrix);
            if strict {
                errors.push(e);
            } else {
                warnings.push(e);
            }
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        model.warnings = warnings;
        Ok(model)
    }

    /// Sets [`Joint::mimic`] of every follower in [`Description::mimics`], resolved to
    /// a leader that follows no other; returns what cannot be followed.
    fn followers(&self, model: &mut Model) -> Vec<ModelError> {
        let mut errors = Vec::new();
        let one = |k: JointKind| k.nq() == 1 && k.nv() == 1;
        for m in &self.mimics {
            let mut bad = |why: String| {
                errors.push(ModelError {
                    element: Element::Joint(m.joint.clone()),
                    line: m.line,
                    kind: ErrorKind::BadMimic(why),
                })
            };
            let Some(f) = model.joints.iter().position(|j| j.name == m.joint) else {
                bad("only a moving joint can follow another".into());
                continue;
            };
            let Some(l) = model.joints.iter().position(|j| j.name == m.leader) else {
                bad(if self.joints.iter().any(|j| j.name == m.leader) {
                    format!(
                        "its leader `{}` is a fixed joint, which has no coordinate to follow; follow a moving joint, \
                         or make this joint fixed too",
                        m.leader
                    )
                } else {
                    format!(
                        "joint=\"{}\" names no joint of this robot; name the revolute, continuous or prismatic joint \
                         this one follows",
                        m.leader
                    )
                });
                continue;
            };
            let (kind, leader_kind) = (model.joints[f].kind, model.joints[l].kind);
            if f == l {
                bad("a joint cannot follow itself; name another joint".into());
            } else if !one(kind) || !one(leader_kind) {
                bad(format!(
                    "a {} joint follows a {} joint; only revolute, continuous and prismatic joints can follow or be \
                     followed",
                    kind.urdf_name(),
                    leader_kind.urdf_name()
                ));
            } else if !(m.multiplier.is_finite() && m.offset.is_finite()) {
                bad(format!(
                    "multiplier {} and offset {} must be finite numbers",
                    m.multiplier, m.offset
                ));
            } else {
                model.joints[f].mimic = Some(JointMimic {
                    leader: l + 1,
                    multiplier: m.multiplier,
                    offset: m.offset,
                });
            }
        }
        // A follower of a follower follows the first leader.
        match dyngen_algo::Mimic::resolve(&model.algo_mimics(), model.joints.len()) {
            Ok(resolved) => {
                for r in resolved {
                    model.joints[r.joint].mimic = Some(JointMimic {
                        leader: r.leader + 1,
                        multiplier: r.multiplier,
                        offset: r.offset,
                    });
                }
            }
            Err(joint) => {
                let name = model.joints[joint].name.clone();
                errors.push(ModelError {
                    line: self.mimics.iter().find(|d| d.joint == name).and_then(|d| d.line),
                    element: Element::Joint(name),
                    kind: ErrorKind::BadMimic(dyngen_algo::MIMIC_CYCLE.into()),
                });
            }
        }
        errors
    }

    /// Follows parent joints up from the first link until a link repeats; returns the
    /// joints of that loop in declaration order, or `None` if an unknown parent link
    /// or a parentless link interrupts the trail.
    fn trace_loop(&self, parent_joint: &[Vec<usize>], link_index: &HashMap<&str, usize>) -> Option<Vec<usize>> {
        let mut trail: Vec<(usize, usize)> = Vec::new();
        let mut link = 0;
        loop {
            if let Some(pos) = trail.iter().position(|&(l, _)| l == link) {
                let mut joints: Vec<usize> = trail[pos..].iter().map(|&(_, k)| k).collect();
                joints.sort_unstable();
                return Some(joints);
            }
            let &k = parent_joint.get(link)?.first()?;
            trail.push((link, k));
            link = *link_index.get(self.joints[k].parent.as_str())?;
        }
    }
}

/// An all-zero inertial (mass 0, no inertia), as URDFs give to tool frames and
/// markers: treated as no inertial at all.
fn is_massless_marker(inertial: &Inertial) -> bool {
    inertial.mass == 0.0 && inertial.inertia.iter().flatten().all(|&x| x == 0.0)
}

/// One link's own inertial values, before it is merged into its body: finite, within
/// [`MAX_MAGNITUDE`], mass ≥ 0.
fn check_link_values(inertial: &Inertial) -> Result<(), ErrorKind> {
    check_finite(inertial)?;
    if inertial.mass < 0.0 {
        return Err(ErrorKind::NonPositiveMass(inertial.mass));
    }
    Ok(())
}

/// The warning for a non-physical body inertia replaced by `balanced`.
fn balanced_warning(e: ModelError, balanced: &Inertial) -> ModelError {
    let (after, _) = balanced.principal_axes();
    ModelError {
        kind: ErrorKind::Ignored(format!(
            "{}; replaced by the nearest physical inertia (principal moments {:.6e}, {:.6e}, {:.6e}; mass and \
             centre of mass kept), as balance_inertia asks",
            e.kind, after[0], after[1], after[2]
        )),
        ..e
    }
}

/// The joints along whose coordinates nothing with mass moves: where the LDLᵀ
/// factorisation of the mass matrix at a generic configuration (a fixed draw) meets
/// a pivot below `1e-12` of the largest diagonal entry. Only a body whose spatial
/// inertia is not positive definite (no mass, or a principal moment ≤ 0) can cause
/// that, so for every other model nothing is computed; otherwise `M` comes from
/// [`crate::regressor::mass_matrix`].
fn singular_joints(model: &Model) -> Vec<usize> {
    let degenerate = model.bodies.iter().any(|b| {
        let (ev, _) = b.inertial.principal_axes();
        b.inertial.mass <= 0.0 || ev[0] <= 0.0
    });
    if !degenerate {
        return Vec::new();
    }
    let n = model.nv();
    let q = crate::sample::structure_states(model, 1, 0x5eed).remove(0).q;
    let Ok(m) = crate::regressor::mass_matrix(model, &q) else {
        return Vec::new();
    };
    let scale = (0..n).fold(0.0f64, |s, k| s.max(m[k][k].abs()));
    // LDLᵀ without pivoting; a collapsed pivot's row and column are left out.
    let mut l = vec![vec![0.0; n]; n];
    let mut d = vec![0.0; n];
    let mut joints = Vec::new();
    for k in 0..n {
        d[k] = m[k][k] - (0..k).map(|j| l[k][j] * l[k][j] * d[j]).sum::<f64>();
        if d[k] <= 1e-12 * scale {
            d[k] = 0.0;
            let joint = model.joint_of_v(k) - 1;
            if joints.last() != Some(&joint) {
                joints.push(joint);
            }
            continue;
        }
        for r in k + 1..n {
            l[r][k] = (m[r][k] - (0..k).map(|j| l[r][j] * l[k][j] * d[j]).sum::<f64>()) / d[k];
        }
    }
    joints
}
