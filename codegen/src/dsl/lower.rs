//! The checked syntax tree to a [`Description`]: the paper's body-centred quantities
//! (`c_ia` from each body's centre of mass, principal moments) become the joint
//! placements and inertials of a URDF-like description, which the model then checks
//! and renumbers like any other front end's.

use super::ast::Robot;
use dyngen_model::graph::IncidenceTree;
use dyngen_model::math::{self, Vec3};
use dyngen_model::{DeclaredJointType, Description, Inertial, JointDesc, Limits, LinkDesc, Placement, DEFAULT_GRAVITY};
use std::collections::HashMap;

/// Builds the description. `None` only if a part the checks require is absent,
/// which the caller reports as an internal error (the checks make it unreachable).
pub fn lower(robot: &Robot, tree: &IncidenceTree) -> Option<Description> {
    let name = robot.name.value.as_ref()?.to_string();
    let gravity = robot.gravity.value.as_ref().map_or(DEFAULT_GRAVITY, |g| g.value());
    let joints = &robot.joints.value.as_ref()?.joints;
    let n = joints.len();

    // c_ia by (body, joint), both as the user numbers them (joints from 1).
    let mut c: HashMap<(usize, usize), Vec3> = HashMap::new();
    for e in &robot.body_joint_vectors.value.as_ref()?.entries {
        let key = (
            usize::try_from(e.body.value).ok()?,
            usize::try_from(e.joint.value).ok()?,
        );
        c.insert(key, e.vector.as_ref()?.value());
    }
    let vector = |i: usize, a: usize| c.get(&(i, a + 1)).copied();

    // The joint (0-based column) whose outboard body is each body; none for the base.
    let mut inner_joint = vec![None; n + 1];
    for (a, &child) in tree.outboard.iter().enumerate() {
        *inner_joint.get_mut(child)? = Some(a);
    }

    let mut descs = Vec::with_capacity(n);
    for (a, joint) in joints.iter().enumerate() {
        let joint = joint.as_ref()?;
        let (p, child) = (*tree.inboard.get(a)?, *tree.outboard.get(a)?);
        // Body p's frame sits at its own inner joint point (the base's at its origin),
        // so joint a lies at c_pa - c_pb in it, b being p's inner joint.
        let translation = match *inner_joint.get(p)? {
            None => vector(p, a)?,
            Some(b) => math::sub(&vector(p, a)?, &vector(p, b)?),
        };
        let rest = joint.rest.as_ref().map_or([0.0; 3], |r| r.value());
        descs.push(JointDesc {
            name: format!("joint{}", a + 1),
            kind: DeclaredJointType::Moving(joint.kind),
            parent: format!("body{p}"),
            child: format!("body{child}"),
            origin: Placement::from_xyz_rpy(translation, rest),
            axis: if joint.kind.has_axis() {
                joint.axis.as_ref()?.value
            } else {
                [0.0; 3]
            },
            limits: joint.limits.as_ref().map(|l| Limits {
                lower: l.lower.value,
                upper: l.upper.value,
                // Not specified in the DSL.
                velocity: 0.0,
                effort: 0.0,
            }),
            dynamics: Default::default(),
            line: None,
        });
    }

    let mut links = vec![LinkDesc {
        name: "body0".to_string(),
        inertial: None,
        line: None,
    }];
    let bodies = &robot.bodies.value.as_ref()?.entries;
    for (i, joint) in inner_joint.iter().enumerate().skip(1) {
        let a = (*joint)?;
        let body = bodies.iter().find(|e| e.index.value == i as i64)?.body.as_ref()?;
        let j = body.shape.moments();
        links.push(LinkDesc {
            name: format!("body{i}"),
            inertial: Some(Inertial {
                mass: body.shape.mass().value,
                // The body frame is at joint a's point: the centre of mass is at -c_ia.
                com: math::scale(-1.0, &vector(i, a)?),
                inertia: [[j[0], 0.0, 0.0], [0.0, j[1], 0.0], [0.0, 0.0, j[2]]],
            }),
            line: None,
        });
    }

    // Each frame is a massless link on a fixed joint, as a URDF gives a tool point.
    // Body i's link frame is at its inner joint's point, where the centre of mass is
    // at -c_ia, so a frame at p from the centre of mass is at p - c_ia; the base's
    // link frame is the base frame, so there p itself.
    for entry in robot.frames.value.iter().flat_map(|t| &t.entries) {
        let frame = entry.frame.as_ref()?;
        let i = usize::try_from(frame.body.value).ok()?;
        let p = frame.position.value();
        let translation = match *inner_joint.get(i)? {
            None => p,
            Some(a) => math::sub(&p, &vector(i, a)?),
        };
        let rest = frame.rest.as_ref().map_or([0.0; 3], |r| r.value());
        let name = entry.name.to_string();
        descs.push(JointDesc {
            name: format!("{name}_fixed"),
            kind: DeclaredJointType::Fixed,
            parent: format!("body{i}"),
            child: name.clone(),
            origin: Placement::from_xyz_rpy(translation, rest),
            // Unused on a fixed joint; URDF's default, as the URDF front end reads it.
            axis: [1.0, 0.0, 0.0],
            limits: None,
            dynamics: Default::default(),
            line: None,
        });
        links.push(LinkDesc {
            name,
            inertial: None,
            line: None,
        });
    }

    Some(Description {
        name,
        gravity,
        links,
        joints: descs,
        mimics: Vec::new(),
    })
}
