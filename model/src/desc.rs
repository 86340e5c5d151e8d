//! The unchecked description every front end produces, and the one place where it is
//! checked and turned into a [`Model`]: tree structure, joint types, axes, inertials;
//! fixed joints merged; bodies renumbered to regular labelling (depth first, children
//! in the order their joints were declared, as Pinocchio numbers them).

use crate::error::{Element, ErrorKind, ModelError};
use crate::ir::{Body, Inertial, Joint, JointKind, Limits, Model, Placement};
use crate::math;
use std::collections::HashMap;

/// A joint type as declared, before checking.
#[derive(Clone, Debug, PartialEq)]
pub enum DeclaredJointType {
    Moving(JointKind),
    Fixed,
    /// Anything else (floating, planar, spherical, ...), by its declared name.
    Unsupported(String),
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
    pub line: Option<usize>,
}

/// A robot as a front end read it: links and joints by name, in declaration order.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    pub name: String,
    pub gravity: [f64; 3],
    pub links: Vec<LinkDesc>,
    pub joints: Vec<JointDesc>,
}

/// Default gravity, m/s², in the base frame.
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn finite_mat(m: &[[f64; 3]; 3]) -> bool {
    m.iter().all(finite3)
}

/// Checks one inertial: finite, mass > 0, inertia about the centre of mass positive
/// definite and satisfying the triangle inequalities.
pub fn check_inertial(inertial: &Inertial) -> Result<(), ErrorKind> {
    if !inertial.mass.is_finite() {
        return Err(ErrorKind::NonFiniteValue("mass"));
    }
    if !finite3(&inertial.com) {
        return Err(ErrorKind::NonFiniteValue("centre of mass"));
    }
    if !finite_mat(&inertial.inertia) {
        return Err(ErrorKind::NonFiniteValue("inertia"));
    }
    if inertial.mass <= 0.0 {
        return Err(ErrorKind::NonPositiveMass(inertial.mass));
    }
    let (ev, _) = inertial.principal_axes();
    if ev.iter().any(|&x| x <= 0.0) {
        return Err(ErrorKind::NotPositiveDefinite(ev));
    }
    // Thin rods sit exactly on the boundary; allow rounding there.
    let tol = 1e-9 * (ev[0] + ev[1] + ev[2]);
    if ev[2] > ev[0] + ev[1] + tol {
        return Err(ErrorKind::TriangleInequality(ev));
    }
    Ok(())
}

impl Description {
    /// Checks the description and builds the model, collecting every error.
    pub fn build(&self) -> Result<Model, Vec<ModelError>> {
        let mut errors = Vec::new();
        let err = |element: Element, line: Option<usize>, kind: ErrorKind| ModelError { element, line, kind };

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
            if let DeclaredJointType::Unsupported(t) = &j.kind {
                errors.push(err(el(), j.line, ErrorKind::UnsupportedJointType(t.clone())));
            }
            if !finite3(&j.origin.translation) || !finite_mat(&j.origin.rotation) {
                errors.push(err(el(), j.line, ErrorKind::NonFiniteValue("origin")));
            }
            if let DeclaredJointType::Moving(_) = j.kind {
                if !finite3(&j.axis) {
                    errors.push(err(el(), j.line, ErrorKind::NonFiniteValue("axis")));
                } else if math::norm(&j.axis) < 1e-12 {
                    errors.push(err(el(), j.line, ErrorKind::ZeroAxis));
                }
            }
            if let Some(l) = j.limits {
                if !(l.lower.is_finite() && l.upper.is_finite() && l.velocity.is_finite() && l.effort.is_finite()) {
                    errors.push(err(el(), j.line, ErrorKind::NonFiniteValue("a limit")));
                } else if l.lower > l.upper {
                    errors.push(err(el(), j.line, ErrorKind::BadLimits { lower: l.lower, upper: l.upper }));
                }
            }
        }
        for (c, ps) in parent_joint.iter().enumerate() {
            if ps.len() > 1 {
                let l = &self.links[c];
                let names = ps.iter().map(|&k| self.joints[k].name.clone()).collect();
                errors.push(err(Element::Link(l.name.clone()), l.line, ErrorKind::SeveralParents(names)));
            }
        }
        let roots: Vec<usize> = (0..self.links.len()).filter(|&c| parent_joint[c].is_empty()).collect();
        if roots.len() > 1 {
            let names = roots.iter().map(|&r| self.links[r].name.clone()).collect();
            errors.push(err(Element::Robot, None, ErrorKind::SeveralRoots(names)));
        } else if roots.is_empty() && !self.links.is_empty() {
            errors.push(err(Element::Robot, None, ErrorKind::NoRoot));
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

        // Depth-first walk from the root; joints never reached close a loop.
        let mut model = Model {
            name: self.name.clone(),
            gravity: self.gravity,
            base: self.links[root].name.clone(),
            joints: Vec::new(),
            bodies: Vec::new(),
        };
        let mut body_inertial: Vec<Option<Inertial>> = Vec::new();
        let mut visited = vec![false; self.joints.len()];
        // (link, owning body index 0..n, placement of the link in the owning body frame)
        let mut stack = vec![(root, 0usize, Placement::IDENTITY)];
        while let Some((link, body, placement)) = stack.pop() {
            // Lump this link's inertial into its owning body (the base's is ignored).
            if body > 0 {
                if let Some(inertial) = &self.links[link].inertial {
                    let moved = inertial.transformed(&placement);
                    let slot = &mut body_inertial[body - 1];
                    *slot = Some(match slot {
                        Some(prev) => prev.combined(&moved),
                        None => moved,
                    });
                    if !is_massless_marker(inertial) {
                        if let Err(kind) = check_inertial(inertial) {
                            let l = &self.links[link];
                            errors.push(err(Element::Link(l.name.clone()), l.line, kind));
                        }
                    }
                }
                if model.bodies[body - 1].name != self.links[link].name {
                    model.bodies[body - 1].merged.push(self.links[link].name.clone());
                }
            }
            // Number children in declaration order; push them in reverse so the
            // first declared is also walked first.
            let mut pushes = Vec::new();
            for &k in &child_joints[link] {
                if visited[k] {
                    continue;
                }
                visited[k] = true;
                let j = &self.joints[k];
                let child = link_index[j.child.as_str()];
                let origin = placement.compose(&j.origin);
                match &j.kind {
                    DeclaredJointType::Moving(kind) => {
                        // Placeholder order: renumbered below once the walk is done.
                        model.joints.push(Joint {
                            name: j.name.clone(),
                            kind: *kind,
                            parent: body,
                            origin,
                            axis: math::scale(1.0 / math::norm(&j.axis), &j.axis),
                            limits: if *kind == JointKind::Continuous { None } else { j.limits },
                        });
                        model.bodies.push(Body { name: self.links[child].name.clone(), inertial: Inertial::principal(0.0, [0.0; 3]), merged: Vec::new() });
                        body_inertial.push(None);
                        pushes.push((child, model.joints.len(), Placement::IDENTITY));
                    }
                    _ => pushes.push((child, body, origin)),
                }
            }
            stack.extend(pushes.into_iter().rev());
        }
        for (k, j) in self.joints.iter().enumerate() {
            if !visited[k] {
                errors.push(err(Element::Joint(j.name.clone()), j.line, ErrorKind::Cycle));
            }
        }
        if model.joints.is_empty() && errors.is_empty() {
            errors.push(err(Element::Robot, None, ErrorKind::NoMovingJoint));
        }
        for (b, inertial) in body_inertial.iter().enumerate() {
            let body = &mut model.bodies[b];
            let line = self.links.iter().find(|l| l.name == body.name).and_then(|l| l.line);
            match inertial {
                Some(i) if !is_massless_marker(i) => {
                    if let Err(kind) = check_inertial(i) {
                        // Per-link value errors were reported above; report the
                        // combined body only when each part was fine on its own.
                        if !errors.iter().any(|e| matches!(&e.element, Element::Link(n) if *n == body.name)) {
                            errors.push(err(Element::Link(body.name.clone()), line, kind));
                        }
                    }
                    body.inertial = *i;
                }
                _ => errors.push(err(Element::Link(body.name.clone()), line, ErrorKind::MissingInertial)),
            }
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        renumber_depth_first(&mut model);
        Ok(model)
    }
}

/// An all-zero inertial (mass 0, no inertia), as URDFs give to tool frames and
/// markers: treated as no inertial at all.
fn is_massless_marker(inertial: &Inertial) -> bool {
    inertial.mass == 0.0 && inertial.inertia.iter().flatten().all(|&x| x == 0.0)
}

/// The stack walk above numbers bodies in discovery order, which is depth first with
/// children in declaration order already; this re-derives the order explicitly so
/// that `parent < child` holds by construction.
fn renumber_depth_first(model: &mut Model) {
    let n = model.dof();
    let mut order = Vec::with_capacity(n);
    let mut stack = vec![0usize];
    while let Some(b) = stack.pop() {
        if b > 0 {
            order.push(b);
        }
        let children = model.children(b);
        stack.extend(children.into_iter().rev());
    }
    let mut new_index = vec![0usize; n + 1];
    for (k, &old) in order.iter().enumerate() {
        new_index[old] = k + 1;
    }
    let joints: Vec<Joint> = order
        .iter()
        .map(|&old| {
            let mut j = model.joints[old - 1].clone();
            j.parent = new_index[j.parent];
            j
        })
        .collect();
    let bodies: Vec<Body> = order.iter().map(|&old| model.bodies[old - 1].clone()).collect();
    model.joints = joints;
    model.bodies = bodies;
}
