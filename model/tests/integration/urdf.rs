//! The URDF front end and writer: one test per user-facing error (each checks that
//! the message names the element and its line), fixed-joint merging against a hand
//! computation, depth-first numbering, and `to_urdf` → `parse_urdf` round trips.

use dyngen_model::math;
use dyngen_model::urdf::urdf_description;
use dyngen_model::{
    load_urdf, parse_urdf, parse_urdf_with, to_urdf, Element, ErrorKind, JointKind, JointMimic, Model, ModelError,
    ModelErrors,
};
use std::path::PathBuf;

/// A robot whose body is `lines`, so that `lines[k]` sits on line `k + 2`.
fn robot(lines: &[&str]) -> String {
    let mut text = String::from("<robot name=\"t\">\n");
    for l in lines {
        text.push_str(l);
        text.push('\n');
    }
    text.push_str("</robot>\n");
    text
}

/// A link with a valid inertial, on one line.
fn link(name: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>"#
    )
}

/// A link with the given mass and principal moments, on one line.
fn link_with(name: &str, mass: &str, moments: [&str; 3]) -> String {
    let [x, y, z] = moments;
    format!(
        r#"<link name="{name}"><inertial><mass value="{mass}"/><inertia ixx="{x}" iyy="{y}" izz="{z}" ixy="0" ixz="0" iyz="0"/></inertial></link>"#
    )
}

/// A joint with optional extra elements, on one line.
fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{extra}</joint>"#)
}

fn errors(text: &str) -> Vec<ModelError> {
    match parse_urdf(text) {
        Ok(m) => panic!("expected errors, got a model of {} bodies", m.dof()),
        Err(e) => {
            assert_eq!(e.file, None);
            e.errors
        }
    }
}

/// Exactly one error; its message names `element` and `line`.
fn single(text: &str, element: Element, line: usize) -> ModelError {
    let errs = errors(text);
    assert_eq!(errs.len(), 1, "{errs:#?}");
    let e = errs.into_iter().next().unwrap();
    assert_named(&e, &element, line);
    e
}

fn assert_named(e: &ModelError, element: &Element, line: usize) {
    assert_eq!(&e.element, element, "{e}");
    assert_eq!(e.line, Some(line), "{e}");
    let message = e.to_string();
    assert!(message.starts_with(&format!("line {line}: {element}: ")), "{message}");
}

// ---------------------------------------------------------------------------------
// Structure errors

#[test]
fn unknown_parent_link() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "nope", "a", ""),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::UnknownParentLink("nope".into()));
    assert!(e.to_string().contains("parent link `nope` does not exist"), "{e}");
}

#[test]
fn unknown_child_link() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "nope", ""),
    ]);
    // `a` then has no parent joint; the name is the mistake, not a second root.
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::UnknownChildLink("nope".into()));
    assert!(e.to_string().contains("child link `nope` does not exist"), "{e}");
}

#[test]
fn unknown_parent_link_in_a_chain_is_not_a_missing_root() {
    // Every link has a parent joint, one of them from a misspelt link.
    let text = robot(&[
        &link("a"),
        &link("b"),
        &joint("ja", "continuous", "bsae", "a", ""),
        &joint("jb", "continuous", "a", "b", ""),
    ]);
    let e = single(&text, Element::Joint("ja".into()), 4);
    assert_eq!(e.kind, ErrorKind::UnknownParentLink("bsae".into()));
}

#[test]
fn several_roots() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("stray"),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    let e = single(&text, Element::Robot, 1);
    assert_eq!(e.kind, ErrorKind::SeveralRoots(vec!["base".into(), "stray".into()]));
    assert!(e.to_string().contains("several root links (base, stray)"), "{e}");
}

#[test]
fn detached_loop_is_a_cycle() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &link("c"),
        &joint("ja", "continuous", "base", "a", ""),
        &joint("jbc", "continuous", "b", "c", ""),
        &joint("jcb", "continuous", "c", "b", ""),
    ]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 2, "{errs:#?}");
    assert_named(&errs[0], &Element::Joint("jbc".into()), 7);
    assert_named(&errs[1], &Element::Joint("jcb".into()), 8);
    for e in &errs {
        assert_eq!(e.kind, ErrorKind::Cycle);
        assert!(e.to_string().contains("closes a kinematic loop"), "{e}");
    }
}

#[test]
fn joint_into_the_root_is_a_cycle() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("up", "continuous", "base", "a", ""),
        &joint("back", "continuous", "a", "base", ""),
    ]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 2, "{errs:#?}");
    assert_named(&errs[0], &Element::Joint("up".into()), 4);
    assert_named(&errs[1], &Element::Joint("back".into()), 5);
    assert!(errs.iter().all(|e| e.kind == ErrorKind::Cycle));
}

#[test]
fn joint_into_an_ancestor_gives_two_parents() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint("ja", "continuous", "base", "a", ""),
        &joint("jb", "continuous", "a", "b", ""),
        &joint("loop", "continuous", "b", "a", ""),
    ]);
    let e = single(&text, Element::Link("a".into()), 3);
    assert_eq!(e.kind, ErrorKind::SeveralParents(vec!["ja".into(), "loop".into()]));
}

#[test]
fn link_with_two_parent_joints() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint("j1", "continuous", "base", "a", ""),
        &joint("j2", "continuous", "base", "b", ""),
        &joint("j3", "continuous", "a", "b", ""),
    ]);
    let e = single(&text, Element::Link("b".into()), 4);
    assert!(e.to_string().contains("is the child of several joints (j2, j3)"), "{e}");
}

#[test]
fn duplicate_names() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("a"),
        &joint("j", "continuous", "base", "a", ""),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    let errs = errors(&text);
    let find = |kind: ErrorKind| {
        errs.iter()
            .find(|e| e.kind == kind)
            .unwrap_or_else(|| panic!("{errs:#?}"))
    };
    assert_named(find(ErrorKind::DuplicateLink), &Element::Link("a".into()), 4);
    assert_named(find(ErrorKind::DuplicateJoint), &Element::Joint("j".into()), 6);
}

#[test]
fn duplicate_link_is_not_reported_as_a_second_root() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("a"),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    let e = single(&text, Element::Link("a".into()), 4);
    assert_eq!(e.kind, ErrorKind::DuplicateLink);
    assert!(e.to_string().contains("defined more than once"), "{e}");
}

#[test]
fn nothing_moves() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "fixed", "base", "a", ""),
    ]);
    let e = single(&text, Element::Robot, 1);
    assert_eq!(e.kind, ErrorKind::NoMovingJoint);
}

// ---------------------------------------------------------------------------------
// Joint errors

#[test]
fn zero_axis() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", r#"<axis xyz="0 0 0"/>"#),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::ZeroAxis);
    assert!(e.to_string().contains("the axis is zero"), "{e}");
}

#[test]
fn unsupported_joint_types() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "screw", "base", "a", ""),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::UnsupportedJointType("screw".into()));
    assert!(
        e.to_string()
            .contains("joint type `screw` is not supported; use revolute, continuous, prismatic, planar"),
        "{e}"
    );
}

/// A planar joint moves in the plane normal to its axis (normalised, as any axis):
/// three coordinates, no limits (a `<limit>` is for one-coordinate joints).
#[test]
fn planar_joints_have_three_coordinates() {
    let text = robot(&[
        r#"<link name="ground"/>"#,
        &link("base"),
        &link("arm"),
        &joint(
            "drive",
            "planar",
            "ground",
            "base",
            r#"<axis xyz="0 0 2"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        ),
        &joint("shoulder", "continuous", "base", "arm", r#"<axis xyz="0 1 0"/>"#),
    ]);
    let model = parse_urdf(&text).unwrap();
    let kinds: Vec<JointKind> = model.joints.iter().map(|j| j.kind).collect();
    assert_eq!(kinds, [JointKind::Planar, JointKind::Continuous]);
    assert!(!model.is_floating());
    assert_eq!((model.nq(), model.nv(), model.v_offset(2)), (4, 4, 3));
    assert_eq!(model.joints[0].axis, [0.0, 0.0, 1.0]);
    assert_eq!(model.joints[0].limits, None);
    assert_eq!(model.multi_dof_joint().map(|j| j.name.as_str()), Some("drive"));
    assert!(model.warnings.is_empty());
}

/// Without `<axis>` a planar joint follows URDF's default axis x (Pinocchio's reader
/// would take z): accepted with a warning naming the joint and its line, refused by a
/// strict build.
#[test]
fn a_planar_joint_without_an_axis_is_warned_about() {
    let text = robot(&[
        r#"<link name="ground"/>"#,
        &link("base"),
        &joint("drive", "planar", "ground", "base", ""),
    ]);
    let model = parse_urdf(&text).unwrap();
    assert_eq!(model.joints[0].axis, [1.0, 0.0, 0.0]);
    assert_eq!(model.warnings.len(), 1);
    let w = &model.warnings[0];
    assert_eq!((&w.element, w.line), (&Element::Joint("drive".into()), Some(4)));
    assert!(w.warning_message().contains("has no <axis>"), "{}", w.warning_message());
    let e = parse_urdf_with(&text, true).unwrap_err();
    assert_eq!(e.errors.len(), 1);
    assert!(e.to_string().contains("Give <axis xyz=\"0 0 1\"/>"), "{e}");
}

#[test]
fn floating_and_spherical_joints_have_their_coordinates() {
    let text = robot(&[
        r#"<link name="world"/>"#,
        &link("trunk"),
        &link("arm"),
        &link("hand"),
        &joint("free", "floating", "world", "trunk", ""),
        &joint("shoulder", "spherical", "trunk", "arm", r#"<origin xyz="0 0.2 0"/>"#),
        &joint(
            "wrist",
            "revolute",
            "arm",
            "hand",
            r#"<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        ),
    ]);
    let model = parse_urdf(&text).unwrap();
    let kinds: Vec<JointKind> = model.joints.iter().map(|j| j.kind).collect();
    assert_eq!(kinds, [JointKind::FreeFlyer, JointKind::Spherical, JointKind::Revolute]);
    assert!(model.is_floating());
    assert_eq!((model.dof(), model.nq(), model.nv()), (3, 12, 10));
    assert_eq!(
        (
            model.q_offset(2),
            model.v_offset(2),
            model.q_offset(3),
            model.v_offset(3)
        ),
        (7, 6, 11, 9)
    );
    assert_eq!(
        (model.joint_of_v(5), model.joint_of_v(6), model.joint_of_v(9)),
        (1, 2, 3)
    );
    assert_eq!(
        (
            model.joint_of_q(6),
            model.joint_of_q(7),
            model.joint_of_q(11),
            model.joint_of_q(12)
        ),
        (Some(1), Some(2), Some(3), None)
    );
    assert_eq!(model.joints[0].axis, [0.0; 3]);
    assert_eq!(model.multi_dof_joint().map(|j| j.name.as_str()), Some("free"));
}

#[test]
fn a_floating_joint_must_hang_from_the_root() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint(
            "j",
            "revolute",
            "base",
            "a",
            r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        ),
        &joint("free", "floating", "a", "b", ""),
    ]);
    let e = single(&text, Element::Joint("free".into()), 6);
    assert_eq!(e.kind, ErrorKind::FreeFlyerNotAtRoot);
    assert!(e.to_string().contains("must join the root link"), "{e}");
}

#[test]
fn the_free_flyer_option_floats_the_root_link_as_pinocchio_does() {
    let text = robot(&[
        &link("base"),
        &link("a"),
        &joint(
            "j",
            "revolute",
            "base",
            "a",
            r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        ),
    ]);
    let fixed = parse_urdf(&text).unwrap();
    let options = dyngen_model::LoadOptions {
        free_flyer: true,
        ..Default::default()
    };
    let floating = dyngen_model::parse_urdf_options(&text, options).unwrap();
    assert_eq!(fixed.dof(), 1);
    assert_eq!((floating.dof(), floating.nq(), floating.nv()), (2, 8, 7));
    assert_eq!(floating.base, dyngen_model::WORLD_LINK);
    assert_eq!(floating.joints[0].name, dyngen_model::FREE_FLYER_JOINT);
    assert_eq!(floating.joints[0].kind, JointKind::FreeFlyer);
    // The root link's inertial now counts: it is body 1.
    assert_eq!(floating.bodies[0].name, "base");
    assert_eq!(floating.bodies[0].inertial.mass, 1.0);
    assert_eq!(floating.joints[1].parent, 1);
}

#[test]
fn unknown_joint_type_is_named_with_its_line() {
    // urdf-rs rejects this without a position; the scan supplies it.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "screw", "base", "a", ""),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::UnsupportedJointType("screw".into()));
}

#[test]
fn bad_limits() {
    let limit = r#"<limit lower="1" upper="-1" effort="1" velocity="1"/>"#;
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "revolute", "base", "a", limit),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(
        e.kind,
        ErrorKind::BadLimits {
            lower: 1.0,
            upper: -1.0
        }
    );
}

#[test]
fn non_finite_origin() {
    let origin = r#"<origin xyz="nan 0 0"/>"#;
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", origin),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(e.kind, ErrorKind::NonFiniteValue("origin"));
}

// ---------------------------------------------------------------------------------
// Inertial errors

fn one_body(link_line: &str) -> String {
    robot(&[
        r#"<link name="base"/>"#,
        link_line,
        &joint("j", "continuous", "base", "a", ""),
    ])
}

/// The model of `text` with its warnings' elements and lines.
fn load_warned(text: &str) -> (Model, Vec<(Element, Option<usize>)>) {
    let model = parse_urdf(text).unwrap_or_else(|e| panic!("{e}"));
    let warned = model.warnings.iter().map(|w| (w.element.clone(), w.line)).collect();
    (model, warned)
}

fn strict_errors(text: &str) -> Vec<ModelError> {
    parse_urdf_with(text, true).unwrap_err().errors
}

#[test]
fn massless_moving_link_loads_with_a_singular_mass_matrix_warning() {
    // No <inertial>, and an all-zero one: a massless body, as Pinocchio reads it.
    for a in [r#"<link name="a"/>"#.to_string(), link_with("a", "0", ["0", "0", "0"])] {
        let (model, warned) = load_warned(&one_body(&a));
        assert_eq!(model.bodies[0].inertial.mass, 0.0);
        assert_eq!(warned, [(Element::Joint("j".into()), Some(4))]);
        assert_eq!(model.warnings[0].kind, ErrorKind::SingularMassMatrix);
        let message = model.warnings[0].warning_message();
        assert!(
            message.starts_with("line 4: joint `j`: the mass matrix is singular along this joint")
                && message.contains("forward dynamics (aba) has no solution")
                && message.contains("a strict build refuses it"),
            "{message}"
        );
        let errs = strict_errors(&one_body(&a));
        assert_eq!(errs.len(), 1, "{errs:#?}");
        assert_named(&errs[0], &Element::Joint("j".into()), 4);
    }
}

#[test]
fn massless_links_that_carry_mass_load_without_a_word() {
    // A massless link between two joints (a finger's knuckle, a universal joint's
    // cross): the mass matrix stays regular, so nothing to say.
    let text = robot(&[
        r#"<link name="base"/>"#,
        r#"<link name="cross"/>"#,
        &link_with("a", "1", ["0.1", "0.2", "0.25"]),
        &joint("jx", "continuous", "base", "cross", ""),
        &joint("jy", "continuous", "cross", "a", r#"<axis xyz="0 1 0"/>"#),
    ]);
    let (model, warned) = load_warned(&text);
    assert_eq!(model.dof(), 2);
    assert!(warned.is_empty(), "{warned:?}");
    assert!(parse_urdf_with(&text, true).is_ok());
    // Two coaxial joints with only a massless link between them move the same
    // mass: the second adds nothing, and it is named.
    let coaxial = text.replace(r#"<axis xyz="0 1 0"/>"#, "");
    let (_, warned) = load_warned(&coaxial);
    assert_eq!(warned, [(Element::Joint("jy".into()), Some(6))]);
}

#[test]
fn massless_parts_keep_their_rotational_inertia_when_merged() {
    // An inertia-only rotor (mass 0) with an inertia-only cap fixed to it: the body
    // turns with both moments (1e-3 + 2e-3 about z), as Pinocchio adds them.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link_with("rotor", "0", ["1e-3", "1e-3", "1e-3"]),
        &link_with("cap", "0", ["2e-3", "2e-3", "2e-3"]),
        &joint("spin", "continuous", "base", "rotor", r#"<axis xyz="0 0 1"/>"#),
        &joint("fix", "fixed", "rotor", "cap", r#"<origin xyz="0 0 0.1"/>"#),
    ]);
    let (model, warned) = load_warned(&text);
    assert_close(model.bodies[0].inertial.inertia[2][2], 3e-3, 1e-18, "merged moment");
    assert_eq!(model.bodies[0].inertial.mass, 0.0);
    // Not a rigid body (mass 0 with inertia), but the joint moves inertia: M is regular.
    assert_eq!(warned, [(Element::Link("rotor".into()), Some(3))]);
}

#[test]
fn a_strict_load_names_every_bad_body_at_once() {
    // A negative mass (an error in any load) and a broken triangle inequality (an
    // error when strict) in two bodies: both, in file order.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link_with("a", "-1", ["1", "1", "1"]),
        &link_with("b", "1", ["1", "1", "3"]),
        &joint("ja", "continuous", "base", "a", ""),
        &joint("jb", "continuous", "a", "b", ""),
    ]);
    let lines: Vec<Option<usize>> = strict_errors(&text).iter().map(|e| e.line).collect();
    assert_eq!(lines, [Some(3), Some(4)]);
}

#[test]
fn zero_and_negative_mass() {
    // Mass 0 with a rotational inertia is not a rigid body: loaded, with a warning.
    let (model, warned) = load_warned(&one_body(&link_with("a", "0", ["1", "1", "1"])));
    assert_eq!(warned, [(Element::Link("a".into()), Some(3))]);
    assert_eq!(model.warnings[0].kind, ErrorKind::NonPositiveMass(0.0));
    let message = model.warnings[0].warning_message();
    assert!(
        message.contains("mass 0 with a nonzero rotational inertia is not a rigid body"),
        "{message}"
    );
    assert!(
        message.contains("accepted as written, as Pinocchio reads it"),
        "{message}"
    );
    assert_eq!(strict_errors(&one_body(&link_with("a", "0", ["1", "1", "1"]))).len(), 1);
    // A negative mass is a mistake in that link.
    let e = single(
        &one_body(&link_with("a", "-1.5", ["1", "1", "1"])),
        Element::Link("a".into()),
        3,
    );
    assert_eq!(e.kind, ErrorKind::NonPositiveMass(-1.5));
    assert!(e.to_string().contains("mass -1.5 is negative"), "{e}");
}

#[test]
fn non_finite_mass() {
    // urdf-rs reads `NaN` and `inf` as numbers, so the check is ours.
    for mass in ["NaN", "inf", "-inf"] {
        let e = single(
            &one_body(&link_with("a", mass, ["1", "1", "1"])),
            Element::Link("a".into()),
            3,
        );
        assert_eq!(e.kind, ErrorKind::NonFiniteValue("mass"), "{mass}");
        assert!(e.to_string().contains("mass is not a finite number"), "{e}");
    }
}

#[test]
fn unreadable_number_names_the_element_and_line() {
    let e = single(
        &one_body(&link_with("a", "heavy", ["1", "1", "1"])),
        Element::Link("a".into()),
        3,
    );
    assert_eq!(
        e.kind,
        ErrorKind::BadNumber {
            attribute: "mass value".into(),
            value: "heavy".into(),
            expected: 1
        }
    );
    assert_eq!(
        e.to_string(),
        "line 3: link `a`: <mass value=\"heavy\"> is not a number; write one number such as `0.5`"
    );
}

#[test]
fn wrong_count_or_unreadable_vectors_name_the_element_and_line() {
    let cases = [
        (r#"<origin xyz="0 0 1" rpy="0 1.57"/>"#, "origin rpy", "0 1.57", 3),
        (r#"<origin xyz="0 0 1 0"/>"#, "origin xyz", "0 0 1 0", 3),
        (r#"<origin xyz="0, 0, 1"/>"#, "origin xyz", "0, 0, 1", 3),
        (r#"<axis xyz="z"/>"#, "axis xyz", "z", 3),
        (
            r#"<limit lower="-1" upper="one" effort="1" velocity="1"/>"#,
            "limit upper",
            "one",
            1,
        ),
        (r#"<dynamics damping="0.1 0.2"/>"#, "dynamics damping", "0.1 0.2", 1),
    ];
    for (extra, attribute, value, expected) in cases {
        let text = robot(&[
            r#"<link name="base"/>"#,
            &link("a"),
            &joint("j", "revolute", "base", "a", extra),
        ]);
        let e = single(&text, Element::Joint("j".into()), 4);
        assert_eq!(
            e.kind,
            ErrorKind::BadNumber {
                attribute: attribute.into(),
                value: value.into(),
                expected
            },
            "{extra}"
        );
        assert!(e.to_string().contains(&format!("=\"{value}\"> is not")), "{e}");
    }
    // Inertia values and the inertial origin, all reported at once.
    let text = robot(&[
        r#"<link name="base"/>"#,
        r#"<link name="a"><inertial><origin rpy="0 0"/><mass value="1"/>"#,
        r#"<inertia ixx="1e-3" iyy="x" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        &joint("j", "continuous", "base", "a", ""),
    ]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 2, "{errs:#?}");
    assert_named(&errs[0], &Element::Link("a".into()), 3);
    assert_named(&errs[1], &Element::Link("a".into()), 4);
    assert!(
        errs[1].to_string().contains("<inertia iyy=\"x\"> is not a number"),
        "{}",
        errs[1]
    );
    // Geometry is not read, so its numbers are not checked.
    let text = robot(&[
        r#"<link name="base"><visual><origin xyz="bogus"/><geometry><box size="1 1"/></geometry></visual></link>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    assert_eq!(parse_urdf(&text).map(|m| m.dof()), Ok(1));
}

#[test]
fn mimic_joints_follow_their_leader() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &link("c"),
        &link("d"),
        &joint("ja", "revolute", "base", "a", ""),
        &joint(
            "jb",
            "prismatic",
            "a",
            "b",
            r#"<mimic joint="ja" multiplier="-0.5" offset="0.2"/><dynamics damping="0.2" friction="0.3"/>"#,
        ),
        &joint(
            "jc",
            "continuous",
            "b",
            "c",
            r#"<mimic joint="jb" multiplier="3" offset="1"/>"#,
        ),
        &joint("jd", "revolute", "a", "d", r#"<mimic joint="ja"/>"#),
    ]);
    let (model, warned) = load_warned(&text);
    assert!(warned.is_empty(), "{warned:?}");
    assert_eq!((model.dof(), model.nq(), model.nv()), (4, 1, 1));
    let mimic = |name: &str| model.joints.iter().find(|j| j.name == name).unwrap().mimic;
    assert_eq!(mimic("ja"), None);
    assert_eq!(
        mimic("jb"),
        Some(JointMimic {
            leader: 1,
            multiplier: -0.5,
            offset: 0.2
        })
    );
    // A follower of a follower follows the first leader: 3 (−0.5 q + 0.2) + 1.
    let jc = mimic("jc").unwrap();
    assert_eq!((jc.leader, jc.multiplier), (1, -1.5));
    assert!((jc.offset - 1.6).abs() < 1e-15);
    // URDF's defaults: multiplier 1, offset 0.
    assert_eq!(
        mimic("jd"),
        Some(JointMimic {
            leader: 1,
            multiplier: 1.0,
            offset: 0.0
        })
    );
    assert!((1..=4).all(|j| model.v_offset(j) == 0 && model.q_offset(j) == 0));
    assert_eq!(model.mimic_joint().map(|j| j.name.as_str()), Some("jb"));
    let body = model.multibody().unwrap();
    assert_eq!((body.nq(), body.nv(), body.mimics().len()), (1, 1, 3));
    // The follower's friction acts on the leader's coordinate through k = −0.5:
    // k² Fv and |k| Fc.
    assert_eq!(
        dyngen_model::joint_params::nominal_joint_params(&model),
        [0.0, 0.25 * 0.2, 0.5 * 0.3, 0.0]
    );
}

#[test]
fn a_mimic_that_cannot_be_followed_is_named_with_its_line() {
    let cases = [
        (
            r#"<mimic joint="nobody"/>"#,
            "revolute",
            "joint=\"nobody\" names no joint of this robot",
        ),
        (r#"<mimic joint="jf"/>"#, "revolute", "its leader `jf` is a fixed joint"),
        (r#"<mimic joint="jb"/>"#, "revolute", "a joint cannot follow itself"),
        (
            r#"<mimic joint="ja"/>"#,
            "planar",
            "a planar joint follows a revolute joint; only revolute",
        ),
        (r#"<mimic joint="ja" multiplier="nan"/>"#, "revolute", "must be finite"),
    ];
    for (mimic, kind, message) in cases {
        let text = robot(&[
            r#"<link name="base"/>"#,
            &link("a"),
            &link("b"),
            &link("f"),
            &joint("ja", "revolute", "base", "a", ""),
            &joint("jf", "fixed", "base", "f", ""),
            &joint("jb", kind, "a", "b", mimic),
        ]);
        let e = single(&text, Element::Joint("jb".into()), 8);
        assert!(matches!(e.kind, ErrorKind::BadMimic(_)), "{e}");
        assert!(e.to_string().contains(message), "{e}");
    }
    // A cycle of followers: each named.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint("ja", "revolute", "base", "a", r#"<mimic joint="jb"/>"#),
        &joint("jb", "revolute", "a", "b", r#"<mimic joint="ja"/>"#),
    ]);
    let e = single(&text, Element::Joint("ja".into()), 5);
    assert!(e.to_string().contains("run in a cycle"), "{e}");
    // A multiplier that is not a number, at its line.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint("ja", "revolute", "base", "a", ""),
        &joint("jb", "revolute", "a", "b", r#"<mimic joint="ja" multiplier="twice"/>"#),
    ]);
    let e = single(&text, Element::Joint("jb".into()), 6);
    assert!(
        e.to_string().contains("<mimic multiplier=\"twice\"> is not a number"),
        "{e}"
    );
}

#[test]
fn mimic_on_a_fixed_joint_is_ignored() {
    // The joint is locked: its <mimic> has nothing to follow with.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &joint("ja", "continuous", "base", "a", ""),
        &joint("jb", "fixed", "a", "b", r#"<mimic joint="ja" multiplier="-1"/>"#),
    ]);
    let (model, warned) = load_warned(&text);
    assert!(warned.is_empty(), "{warned:?}");
    assert_eq!(model.dof(), 1);
    assert_eq!(model.bodies[0].merged, ["b"]);
    assert!(urdf_description(&text).is_ok());
}

#[test]
fn nesting_beyond_the_limit_is_an_error_not_a_stack_overflow() {
    let depth = 20_000;
    let text = format!(
        "<robot name=\"r\">\n<link name=\"base\">\n{}{}</link>\n</robot>\n",
        "<a>".repeat(depth),
        "</a>".repeat(depth)
    );
    let e = single(&text, Element::Robot, 3);
    assert_eq!(e.kind, ErrorKind::TooDeep { tag: "a".into() });
    assert!(
        e.to_string().contains("<a> is nested more than 256 elements deep"),
        "{e}"
    );
    // Just inside the limit, the file is read (the unknown elements are ignored).
    let depth = dyngen_model::xml::MAX_DEPTH - 3;
    let text = robot(&[
        &format!(
            "<link name=\"base\">{}{}</link>",
            "<a>".repeat(depth),
            "</a>".repeat(depth)
        ),
        &link("a"),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    assert_eq!(parse_urdf(&text).map(|m| m.dof()), Ok(1));
}

#[test]
fn file_beyond_the_size_limit_is_an_error() {
    let limit = dyngen_model::urdf::MAX_FILE_BYTES as usize;
    let mut text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    text.push_str(&" ".repeat(limit + 1 - text.len()));
    let errs = errors(&text);
    assert_eq!(
        errs[0].kind,
        ErrorKind::TooLarge {
            bytes: limit as u64 + 1
        }
    );
    let file = TempFile::new("large.urdf", &text);
    let e = load_urdf(&file.0).unwrap_err();
    assert_eq!(
        e.errors[0].kind,
        ErrorKind::TooLarge {
            bytes: limit as u64 + 1
        }
    );
    assert!(e.to_string().contains("more than the 64 MiB"), "{e}");
}

#[test]
// Values near π and π/2 that are not the constants are the point.
#[allow(clippy::approx_constant)]
fn rpy_near_a_quarter_turn_is_taken_as_written() {
    let urdf = |rpy: &str| {
        robot(&[
            r#"<link name="base"/>"#,
            &link("a"),
            &joint("j", "continuous", "base", "a", &format!(r#"<origin rpy="{rpy}"/>"#)),
        ])
    };
    let rotation = |rpy: &str| parse_urdf(&urdf(rpy)).unwrap().joints[0].origin.rotation;
    // As written: 2.07e-13 rad short of π, as Pinocchio reads it.
    let r = rotation("3.14159265359 0 0");
    let (s, c) = 3.14159265359f64.sin_cos();
    assert_eq!((r[2][1], r[1][1]), (s, c));
    assert!(r[2][1] != 0.0);
    // The f64 nearest π is a half turn, exactly.
    let r = rotation("3.141592653589793 0 0");
    assert_eq!((r[2][1], r[1][1]), (0.0, -1.0));
}

#[test]
fn inertia_not_positive_definite() {
    let text = one_body(&link_with("a", "1", ["1", "1", "-0.01"]));
    let (model, warned) = load_warned(&text);
    assert_eq!(warned, [(Element::Link("a".into()), Some(3))]);
    assert!(matches!(model.warnings[0].kind, ErrorKind::NotPositiveDefinite(_)));
    let message = model.warnings[0].warning_message();
    assert!(message.contains("inertia is not positive definite"), "{message}");
    // 0.01 of the largest moment 1: 1 %, beyond CAD rounding.
    assert!(
        message.contains("although it is 1.000 % of its largest moment away from physical"),
        "{message}"
    );
    let errs = strict_errors(&text);
    assert!(matches!(errs[0].kind, ErrorKind::NotPositiveDefinite(_)), "{errs:?}");
    assert_named(&errs[0], &Element::Link("a".into()), 3);
}

#[test]
fn triangle_inequality_violated() {
    let text = one_body(&link_with("a", "1", ["1", "1", "3"]));
    let (model, warned) = load_warned(&text);
    assert_eq!(warned, [(Element::Link("a".into()), Some(3))]);
    assert!(matches!(model.warnings[0].kind, ErrorKind::TriangleInequality(_)));
    let message = model.warnings[0].warning_message();
    assert!(message.contains("break the triangle inequality"), "{message}");
    assert!(message.contains("33.333 % of its largest moment"), "{message}");
    assert!(message.contains("--balance-inertia"), "{message}");
    // Kept as written, as Pinocchio keeps it.
    assert_eq!(model.bodies[0].inertial.inertia[2][2], 3.0);
    let errs = strict_errors(&text);
    assert!(matches!(errs[0].kind, ErrorKind::TriangleInequality(_)), "{errs:?}");
}

#[test]
fn balance_inertia_replaces_a_non_physical_inertia_by_the_nearest_physical_one() {
    let text = one_body(&link_with("a", "2", ["1", "1", "3"]));
    let options = dyngen_model::LoadOptions {
        balance_inertia: true,
        ..Default::default()
    };
    let model = dyngen_model::parse_urdf_options(&text, options).unwrap();
    // Each moment moved by a third of the excess 1: 4/3, 4/3, 8/3.
    let (ev, _) = model.bodies[0].inertial.principal_axes();
    for (x, expected) in ev.iter().zip([4.0 / 3.0, 4.0 / 3.0, 8.0 / 3.0]) {
        assert_close(*x, expected, 1e-12, "balanced moment");
    }
    assert_eq!(model.bodies[0].inertial.mass, 2.0);
    assert!(dyngen_model::check_inertial(&model.bodies[0].inertial).is_ok());
    assert_eq!(model.warnings.len(), 1);
    let message = model.warnings[0].warning_message();
    assert!(
        message.starts_with("line 3: link `a`: principal moments")
            && message.contains(
                "replaced by the nearest physical inertia (principal moments 1.333333e0, 1.333333e0, 2.666667e0"
            ),
        "{message}"
    );
    // Strict still refuses.
    let strict = dyngen_model::LoadOptions {
        strict: true,
        ..options
    };
    assert!(dyngen_model::parse_urdf_options(&text, strict).is_err());
}

#[test]
fn merged_link_error_is_reported_once() {
    // The bad fixed child spoils its body too; only the link at fault is named.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link_with("tool", "-3", ["1", "1", "1"]),
        &joint("j", "continuous", "base", "a", ""),
        &joint("f", "fixed", "a", "tool", ""),
    ]);
    let e = single(&text, Element::Link("tool".into()), 4);
    assert_eq!(e.kind, ErrorKind::NonPositiveMass(-3.0));
}

#[test]
fn point_masses_and_massless_frames_on_fixed_joints_are_merged() {
    // Each part need only be physical; the merged body must be strictly positive.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link_with("camera", "0.01", ["0", "0", "0"]),
        &link_with("foot", "0", ["1e-6", "1e-6", "1e-6"]),
        &joint("j", "continuous", "base", "a", ""),
        &joint("cam", "fixed", "a", "camera", r#"<origin xyz="0 0 1"/>"#),
        &joint("ankle", "fixed", "a", "foot", ""),
    ]);
    let m = parse_urdf(&text).unwrap();
    // Siblings are walked by joint name (`ankle` before `cam`), as Pinocchio does.
    assert_eq!(m.bodies[0].merged, ["foot", "camera"]);
    assert_close(m.bodies[0].inertial.mass, 1.01, 1e-15, "mass");
}

/// A trunk as public quadruped descriptions have it: a dummy root link whose
/// exported inertia is rounding noise (a moment of −1.2e-22), a fixed joint, and the
/// real 5.6 kg trunk, with a leg.
fn dummy_root_trunk() -> String {
    robot(&[
        r#"<link name="base"><inertial><mass value="0.001"/><inertia ixx="-1.2e-22" iyy="0" izz="3e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        r#"<link name="trunk"><inertial><mass value="5.6"/><inertia ixx="0.018" iyy="0.068" izz="0.077" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        &link("thigh"),
        &joint("floating_base", "fixed", "base", "trunk", ""),
        &joint("hip", "continuous", "trunk", "thigh", r#"<origin xyz="0.2 0.1 0"/>"#),
    ])
}

#[test]
fn inertias_are_checked_on_the_merged_bodies() {
    let text = dummy_root_trunk();
    // The dummy link alone breaks positive definiteness and the triangle inequality
    // (3e-6 > 0 + 0), yet the body it is part of is physical: no word, fixed or floating.
    let (fixed, warned) = load_warned(&text);
    assert!(warned.is_empty(), "{warned:?}");
    assert_eq!(fixed.dof(), 1);
    let options = dyngen_model::LoadOptions {
        free_flyer: true,
        strict: true,
        ..Default::default()
    };
    let floating = dyngen_model::parse_urdf_options(&text, options).unwrap();
    assert!(floating.warnings.is_empty(), "{:?}", floating.warnings);
    assert_eq!(floating.bodies[0].name, "base");
    assert_eq!(floating.bodies[0].merged, ["trunk"]);
    assert_close(floating.bodies[0].inertial.mass, 5.601, 1e-14, "merged mass");
    assert!(dyngen_model::check_inertial(&floating.bodies[0].inertial).is_ok());
    // A link's own values are still its own: a negative mass is named, merged or not.
    let bad = text.replace(r#"<mass value="0.001"/>"#, r#"<mass value="-0.001"/>"#);
    let e = dyngen_model::parse_urdf_options(&bad, options).unwrap_err();
    assert_eq!(e.errors.len(), 1, "{e}");
    assert_named(&e.errors[0], &Element::Link("base".into()), 2);
}

#[test]
fn a_single_body_floats_on_a_free_flyer() {
    // A quadrotor: one link, no joint.
    let text = robot(&[&link_with("quadrotor", "1.5", ["0.03", "0.03", "0.05"])]);
    let options = dyngen_model::LoadOptions {
        free_flyer: true,
        ..Default::default()
    };
    let model = dyngen_model::parse_urdf_options(&text, options).unwrap();
    assert_eq!((model.dof(), model.nq(), model.nv()), (1, 7, 6));
    assert_eq!(model.joints[0].kind, JointKind::FreeFlyer);
    assert_eq!(model.bodies[0].name, "quadrotor");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    // Fixed, nothing moves: said so, at <robot>.
    let e = single(&text, Element::Robot, 1);
    assert_eq!(e.kind, ErrorKind::NoMovingJoint);
}

// ---------------------------------------------------------------------------------
// File-level errors

#[test]
fn raw_xacro_is_rejected() {
    let text = "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <link name=\"base\"/>\n  <xacro:property name=\"l\" value=\"0.5\"/>\n</robot>\n";
    let e = single(text, Element::Robot, 3);
    assert_eq!(e.kind, ErrorKind::Xacro);
    assert!(e.to_string().contains("expand it first"), "{e}");

    let text = one_body(&link("a")).replace(r#"<parent link="base"/>"#, r#"<parent link="${prefix}base"/>"#);
    let e = single(&text, Element::Robot, 4);
    assert_eq!(e.kind, ErrorKind::Xacro);
}

#[test]
fn expanded_urdf_with_xacro_leftovers_is_accepted() {
    // Shipped URDFs keep `xmlns:xacro` and commented-out xacro; neither is a macro.
    let text = one_body(&link("a"))
        .replace(
            "<robot name=\"t\">",
            "<robot name=\"t\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">",
        )
        .replace(
            "</robot>",
            "<!-- <xacro:macro name=\"m\" params=\"${x}\"/> -->\n</robot>",
        );
    assert_eq!(parse_urdf(&text).map(|m| m.dof()), Ok(1));
}

#[test]
fn malformed_xml() {
    let text = "<robot name=\"r\">\n  <link name=\"base\">\n  <link name=\"a\"/>\n</robot>\n";
    let e = single(text, Element::Robot, 4);
    assert!(
        matches!(&e.kind, ErrorKind::Parse(m) if m.contains("</robot> closes <link> opened on line 2")),
        "{e:?}"
    );

    let errs = errors("this is not xml");
    assert_eq!(errs.len(), 1);
    assert!(matches!(errs[0].kind, ErrorKind::Parse(_)), "{errs:?}");
}

#[test]
fn unreadable_file() {
    let path = PathBuf::from("/nonexistent/dyngen/robot.urdf");
    let e = load_urdf(&path).unwrap_err();
    assert_eq!(e.file.as_deref(), Some("/nonexistent/dyngen/robot.urdf"));
    assert!(matches!(e.errors[0].kind, ErrorKind::Io(_)), "{e:?}");
    assert!(
        e.to_string()
            .starts_with("/nonexistent/dyngen/robot.urdf: robot: cannot read the file"),
        "{e}"
    );

    // A directory is not readable as text either.
    let e = load_urdf(&std::env::temp_dir()).unwrap_err();
    assert!(matches!(e.errors[0].kind, ErrorKind::Io(_)), "{e:?}");
}

/// A scratch file that removes itself.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str, text: &str) -> TempFile {
        let path = std::env::temp_dir().join(format!("dyngen-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        TempFile(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn display_prints_file_and_line() {
    let file = TempFile::new("display.urdf", &one_body(&link_with("a", "-1", ["1", "1", "1"])));
    let e: ModelErrors = load_urdf(&file.0).unwrap_err();
    let shown = e.to_string();
    let expected = format!("{}:3: link `a`: mass -1 is negative", file.0.display());
    assert!(shown.starts_with(&expected), "{shown}");
}

#[test]
fn all_errors_of_a_file_are_reported_together() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &link("c"),
        &joint("ja", "continuous", "bsae", "a", ""),
        &joint("jb", "continuous", "base", "b", r#"<axis xyz="0 0 0"/>"#),
        &joint("jc", "planar", "base", "c", r#"<axis xyz="0 0 0"/>"#),
    ]);
    let e = parse_urdf(&text).unwrap_err();
    let kinds: Vec<(&Element, Option<usize>, &ErrorKind)> =
        e.errors.iter().map(|e| (&e.element, e.line, &e.kind)).collect();
    assert_eq!(
        kinds,
        [
            (
                &Element::Joint("ja".into()),
                Some(6),
                &ErrorKind::UnknownParentLink("bsae".into())
            ),
            (&Element::Joint("jb".into()), Some(7), &ErrorKind::ZeroAxis),
            (&Element::Joint("jc".into()), Some(8), &ErrorKind::ZeroAxis),
        ]
    );
    assert_eq!(e.to_string().lines().count(), 3);

    // Value errors are collected across bodies too.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link_with("a", "-1", ["1", "1", "1"]),
        &link_with("b", "1", ["1", "1", "inf"]),
        r#"<link name="c"><inertial><origin xyz="nan 0 0"/><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        &joint("ja", "continuous", "base", "a", ""),
        &joint("jb", "continuous", "a", "b", ""),
        &joint("jc", "continuous", "b", "c", ""),
    ]);
    let lines: Vec<Option<usize>> = errors(&text).iter().map(|e| e.line).collect();
    assert_eq!(lines, [Some(3), Some(4), Some(5)]);
}

// ---------------------------------------------------------------------------------
// Reading

#[test]
fn lines_found_across_quote_and_whitespace_styles() {
    let text = "<?xml version=\"1.0\"?>\n<!-- <link name=\"a\"/> is not here -->\n<robot name='t'>\n  <link name='base'/>\n  <link\n     name = \"a\" ><inertial><mass value='-1'/><inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial>\n  </link>\n  <joint name='j' type=\"continuous\">\n    <parent link=\"base\"/><child link='a'/>\n  </joint>\n</robot>\n";
    let e = single(text, Element::Link("a".into()), 5);
    assert_eq!(e.kind, ErrorKind::NonPositiveMass(-1.0));
}

#[test]
fn transmission_joints_are_not_joints() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        r#"<transmission name="t"><joint name="j"><hardwareInterface>x</hardwareInterface></joint></transmission>"#,
        r#"<link name="a"/>"#,
        &joint("j", "continuous", "base", "a", ""),
    ]);
    // The massless link's joint is named at its own line, not the transmission's.
    assert_eq!(load_warned(&text).1, [(Element::Joint("j".into()), Some(5))]);
}

#[test]
fn geometry_is_ignored_and_lines_still_hold() {
    // urdf-rs would reject the file-less <texture/>; dynamics never reads it.
    let text = robot(&[
        r#"<material name="skin"><texture/></material>"#,
        r#"<link name="base"><visual><geometry><capsule radius="-1"/></geometry>"#,
        r#"  <material name="m"><color rgba="1 0 0 1"/></material></visual>"#,
        r#"  <collision><geometry><mesh/></geometry></collision></link>"#,
        &link_with("a", "-2", ["1", "1", "1"]),
        &joint("j", "continuous", "base", "a", ""),
    ]);
    let e = single(&text, Element::Link("a".into()), 6);
    assert_eq!(e.kind, ErrorKind::NonPositiveMass(-2.0));
}

#[test]
fn limits_only_when_written() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &link("c"),
        &joint(
            "ja",
            "revolute",
            "base",
            "a",
            r#"<limit lower="-1.5" upper="2" effort="30" velocity="4"/>"#,
        ),
        &joint("jb", "revolute", "a", "b", ""),
        &joint("jc", "continuous", "b", "c", r#"<limit effort="1" velocity="2"/>"#),
    ]);
    let m = parse_urdf(&text).unwrap();
    let l = m.joints[0].limits.unwrap();
    assert_eq!((l.lower, l.upper, l.effort, l.velocity), (-1.5, 2.0, 30.0, 4.0));
    assert_eq!(m.joints[1].limits, None);
    assert_eq!(m.joints[2].limits, None);
}

#[test]
fn description_keeps_what_was_written() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        r#"<link name="tip"/>"#,
        &joint("ja", "revolute", "base", "a", r#"<axis xyz="0 0 2"/>"#),
        &joint("tip", "fixed", "a", "tip", ""),
    ]);
    let d = urdf_description(&text).unwrap();
    assert_eq!(d.name, "t");
    assert_eq!(d.gravity, dyngen_model::DEFAULT_GRAVITY);
    assert_eq!(
        d.links.iter().map(|l| l.line).collect::<Vec<_>>(),
        [Some(2), Some(3), Some(4)]
    );
    assert!(d.links[0].inertial.is_none() && d.links[2].inertial.is_none());
    assert_eq!(d.joints[0].axis, [0.0, 0.0, 2.0]);
    assert_eq!(d.joints[0].limits, None);
    assert_eq!(d.joints[1].kind, dyngen_model::DeclaredJointType::Fixed);
}

fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs())),
        "{what}: {a} vs {b}"
    );
}

fn assert_mat_close(a: &math::Mat3, b: &math::Mat3, tol: f64, what: &str) {
    for r in 0..3 {
        for c in 0..3 {
            assert_close(a[r][c], b[r][c], tol, what);
        }
    }
}

#[test]
fn inertial_origin_rotation_is_applied() {
    let inertial = |rpy: &str| {
        format!(
            r#"<link name="a"><inertial><origin xyz="0.1 0.2 0.3" rpy="{rpy}"/><mass value="2"/><inertia ixx="1" iyy="2" izz="2.5" ixy="0.1" ixz="-0.2" iyz="0.05"/></inertial></link>"#
        )
    };
    // A quarter turn about z swaps the x and y axes.
    let m = parse_urdf(&one_body(&inertial("0 0 1.5707963267948966"))).unwrap();
    let i = m.bodies[0].inertial;
    assert_eq!(i.com, [0.1, 0.2, 0.3]);
    assert_eq!(i.inertia, [[2.0, -0.1, -0.05], [-0.1, 1.0, -0.2], [-0.05, -0.2, 2.5]]);

    let rpy = [0.3, -0.4, 1.1];
    let m = parse_urdf(&one_body(&inertial("0.3 -0.4 1.1"))).unwrap();
    let local = [[1.0, 0.1, -0.2], [0.1, 2.0, 0.05], [-0.2, 0.05, 2.5]];
    let expected = math::rotate_inertia(&math::rpy_to_matrix(rpy), &local);
    assert_mat_close(&m.bodies[0].inertial.inertia, &expected, 1e-15, "R I Rᵀ");
    let i = m.bodies[0].inertial.inertia;
    assert_eq!((i[0][1], i[0][2], i[1][2]), (i[1][0], i[2][0], i[2][1]), "symmetric");
}

// ---------------------------------------------------------------------------------
// Fixed joints and numbering

#[test]
fn fixed_joint_merging_matches_hand_computation() {
    let text = robot(&[
        r#"<link name="base"/>"#,
        r#"<link name="arm"><inertial><origin xyz="0 0 0.1"/><mass value="2"/><inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        r#"<link name="tool"><inertial><origin xyz="0.02 0 0"/><mass value="0.5"/><inertia ixx="0.001" iyy="0.002" izz="0.003" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        &link("finger"),
        &joint("shoulder", "continuous", "base", "arm", ""),
        &joint(
            "mount",
            "fixed",
            "arm",
            "tool",
            r#"<origin xyz="0.1 0 0.3" rpy="0 0 1.5707963267948966"/>"#,
        ),
        &joint(
            "grip",
            "prismatic",
            "tool",
            "finger",
            r#"<origin xyz="0 0 0.05"/><axis xyz="1 0 0"/><limit lower="0" upper="0.04" effort="10" velocity="0.1"/>"#,
        ),
    ]);
    let m = parse_urdf(&text).unwrap();
    assert_eq!(m.dof(), 2);
    let arm = &m.bodies[0];
    assert_eq!(arm.merged, ["tool"]);
    // Tool in arm axes: Rz(90°) turns its com (0.02, 0, 0) into (0, 0.02, 0), then
    // the mount offset adds (0.1, 0, 0.3); its moments swap to (0.002, 0.001, 0.003).
    // Mass 2.5; first moment 2·(0, 0, 0.1) + 0.5·(0.1, 0.02, 0.3) = (0.05, 0.01, 0.35).
    // Inertia about the arm origin, part by part (I_c + m(|c|²E − ccᵀ)):
    //   arm  diag(0.01, 0.02, 0.03) + 2·diag(0.01, 0.01, 0)         = diag(0.03, 0.04, 0.03)
    //   tool diag(0.002, 0.001, 0.003) + 0.5·(0.1004 E − c cᵀ):
    //        xx 0.0472, yy 0.051, zz 0.0082, xy −0.001, xz −0.015, yz −0.003
    let expected = [2.5, 0.05, 0.01, 0.35, 0.0772, -0.001, 0.091, -0.015, -0.003, 0.0382];
    let got = arm.inertial.standard_params();
    for (k, (g, e)) in got.iter().zip(expected).enumerate() {
        assert_close(*g, e, 1e-14, &format!("standard parameter {k}"));
    }
    for (g, e) in arm.inertial.com.iter().zip([0.02, 0.004, 0.14]) {
        assert_close(*g, e, 1e-15, "com");
    }
    // The finger hangs off the tool, so off the arm body, through the mount.
    let grip = &m.joints[1];
    assert_eq!((grip.parent, grip.kind), (1, JointKind::Prismatic));
    assert_eq!(
        grip.origin.rotation,
        [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    );
    for (g, e) in grip.origin.translation.iter().zip([0.1, 0.0, 0.35]) {
        assert_close(*g, e, 1e-15, "grip origin");
    }
}

#[test]
fn depth_first_numbering_of_a_branched_tree() {
    // Declaration order interleaves branches; siblings are walked by joint name (as
    // urdfdom and Pinocchio do), and a fixed joint (`ja0`) sorts before its moving
    // sibling `ja1`: the body behind it (`fx`) must be numbered first.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("f"),
        &link("fx"),
        &link("a1"),
        &link("a11"),
        &link("b"),
        &link("b1"),
        &joint("ja", "continuous", "base", "a", ""),
        &joint("ja0", "fixed", "a", "f", ""),
        &joint("ja1", "continuous", "a", "a1", ""),
        &joint("jb", "continuous", "base", "b", ""),
        &joint("jfx", "continuous", "f", "fx", ""),
        &joint("ja11", "continuous", "a1", "a11", ""),
        &joint("jb1", "continuous", "b", "b1", ""),
    ]);
    let m = parse_urdf(&text).unwrap();
    let names: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["a", "fx", "a1", "a11", "b", "b1"]);
    let joints: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(joints, ["ja", "jfx", "ja1", "ja11", "jb", "jb1"]);
    let parents: Vec<usize> = (1..=m.dof()).map(|i| m.parent(i)).collect();
    assert_eq!(parents, [0, 1, 1, 3, 0, 5]);
    assert!((1..=m.dof()).all(|i| m.parent(i) < i));
    assert_eq!(m.bodies[0].merged, ["f"]);
    assert_eq!(m.base, "base");
    assert_eq!(m.name, "t");
}

// ---------------------------------------------------------------------------------
// Writing

/// A branched tree with every moving joint type, rotated joint and inertial
/// origins, off-diagonal inertias and numbers that need all 17 digits.
fn branched_urdf() -> String {
    let body = |name: &str, rpy: &str| {
        format!(
            r#"<link name="{name}"><inertial><origin xyz="0.013 -0.021 0.1" rpy="{rpy}"/><mass value="1.2345678901234567"/><inertia ixx="0.011" iyy="0.012" izz="0.0135" ixy="0.0003" ixz="-0.0002" iyz="0.0001"/></inertial></link>"#
        )
    };
    robot(&[
        r#"<link name="world"/>"#,
        &body("torso", "0.1 0.2 0.3"),
        &body("left", "0 0 0"),
        &body("left_tip", "-1.2 0.4 2.9"),
        &body("right", "0 1.5707963267948966 0"),
        &body("slide", "0.7 -0.1 0"),
        r#"<link name="marker"/>"#,
        &joint(
            "waist",
            "continuous",
            "world",
            "torso",
            r#"<origin xyz="0 0 0.8" rpy="0 0 0.7853981633974483"/><axis xyz="0 0 1"/>"#,
        ),
        &joint(
            "l1",
            "revolute",
            "torso",
            "left",
            r#"<origin xyz="0.1 0.2 -1e-7" rpy="0.3 -0.2 1.1"/><axis xyz="0 0.6 0.8"/><limit lower="-2.5" upper="1.0000000000000002" effort="50" velocity="3.3"/>"#,
        ),
        &joint(
            "l2",
            "prismatic",
            "left",
            "left_tip",
            r#"<origin xyz="0 0 0.35" rpy="-2.0 1.2 0.4"/><axis xyz="1 1 0"/><limit lower="0" upper="0.2" effort="100" velocity="0.5"/>"#,
        ),
        &joint(
            "r1",
            "revolute",
            "torso",
            "right",
            r#"<origin xyz="0.1 -0.2 0" rpy="3.141592653589793 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="5" velocity="6"/>"#,
        ),
        &joint("mark", "fixed", "right", "marker", r#"<origin xyz="0 0 0.1"/>"#),
        &joint(
            "r2",
            "prismatic",
            "torso",
            "slide",
            r#"<origin xyz="-0.3 0 0.25" rpy="0 0.5 0"/><axis xyz="0 0 -1"/><limit lower="-0.1" upper="0.1" effort="20" velocity="1"/>"#,
        ),
    ])
}

/// Models equal up to `tol` relative on every number, and exactly on structure.
/// Merged link names are not compared: URDF output only lists them in a comment.
fn assert_models_close(a: &Model, b: &Model, tol: f64) {
    assert_eq!(
        (&a.name, &a.base, a.gravity, a.dof()),
        (&b.name, &b.base, b.gravity, b.dof())
    );
    for (ja, jb) in a.joints.iter().zip(&b.joints) {
        assert_eq!((&ja.name, ja.kind, ja.parent), (&jb.name, jb.kind, jb.parent));
        assert_mat_close(&ja.origin.rotation, &jb.origin.rotation, tol, &ja.name);
        for k in 0..3 {
            assert_close(ja.origin.translation[k], jb.origin.translation[k], tol, &ja.name);
            assert_close(ja.axis[k], jb.axis[k], tol, &ja.name);
        }
        assert_eq!(ja.limits, jb.limits, "{}", ja.name);
    }
    for (ba, bb) in a.bodies.iter().zip(&b.bodies) {
        assert_eq!(ba.name, bb.name);
        let (ia, ib) = (ba.inertial, bb.inertial);
        assert_close(ia.mass, ib.mass, tol, &ba.name);
        for k in 0..3 {
            assert_close(ia.com[k], ib.com[k], tol, &ba.name);
        }
        assert_mat_close(&ia.inertia, &ib.inertia, tol, &ba.name);
    }
}

#[test]
fn to_urdf_round_trips() {
    let model = parse_urdf(&branched_urdf()).unwrap();
    assert_eq!(model.dof(), 5);
    let kinds: Vec<JointKind> = model.joints.iter().map(|j| j.kind).collect();
    use dyngen_algo::JointType::*;
    assert_eq!(kinds, [Continuous, Revolute, Prismatic, Revolute, Prismatic]);

    let written = to_urdf(&model);
    assert!(
        written.contains("<!-- generated by dyngen from model t -->"),
        "{written}"
    );
    assert!(written.contains("<!-- includes fixed links: marker -->"), "{written}");
    assert!(written.contains(r#"xyz="0.1 0.2 -1e-7""#), "{written}");
    let back = parse_urdf(&written).unwrap_or_else(|e| panic!("{e}\n{written}"));
    assert_models_close(&model, &back, 1e-15);
    assert!(back.bodies.iter().all(|b| b.merged.is_empty()));

    // Numbers that were not rotated come back bit for bit.
    assert_eq!(back.bodies[1].inertial.mass, 1.2345678901234567);
    assert_eq!(back.joints[1].limits, model.joints[1].limits);
    assert_eq!(back.joints[0].origin.translation, [0.0, 0.0, 0.8]);

    // Writing again changes nothing but rounding in re-derived angles.
    let again = parse_urdf(&to_urdf(&back)).unwrap();
    assert_models_close(&back, &again, 1e-15);
}

#[test]
fn to_urdf_gives_unlimited_joints_wide_limits() {
    // urdfdom insists on a <limit> for these types, so "no limits" is written wide.
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &link("b"),
        &link("c"),
        &joint("r", "revolute", "base", "a", ""),
        &joint("p", "prismatic", "a", "b", ""),
        &joint("c", "continuous", "b", "c", ""),
    ]);
    let m = parse_urdf(&text).unwrap();
    assert!(m.joints.iter().all(|j| j.limits.is_none()));
    let written = to_urdf(&m);
    let back = parse_urdf(&written).unwrap();
    let wide = 1e6;
    for j in &back.joints[..2] {
        let l = j.limits.unwrap();
        assert_eq!(
            (l.lower, l.upper, l.effort, l.velocity),
            (-wide, wide, wide, wide),
            "{}",
            j.name
        );
    }
    assert_eq!(back.joints[2].limits, None);
    assert_eq!(
        written.matches("<limit").count(),
        2,
        "continuous joints get none:\n{written}"
    );
}

#[test]
fn to_urdf_escapes_names() {
    let mut m = parse_urdf(&one_body(&link("a"))).unwrap();
    m.name = "r&d <1> \"q\"".into();
    m.bodies[0].name = "a'b".into();
    let back = parse_urdf(&to_urdf(&m)).unwrap();
    assert_eq!(back.name, m.name);
    assert_eq!(back.bodies[0].name, "a'b");
}

#[test]
fn joint_dynamics_are_read_and_written_back() {
    let dynamics = r#"<limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="0.7" friction="1.25"/>"#;
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "revolute", "base", "a", dynamics),
    ]);
    let model = parse_urdf(&text).unwrap();
    assert_eq!(model.joints[0].dynamics.damping, 0.7);
    assert_eq!(model.joints[0].dynamics.friction, 1.25);
    assert_eq!(
        dyngen_model::joint_params::nominal_joint_params(&model),
        [0.0, 0.7, 1.25, 0.0]
    );
    let written = to_urdf(&model);
    assert!(
        written.contains(r#"<dynamics damping="0.7" friction="1.25"/>"#),
        "{written}"
    );
    assert_eq!(
        parse_urdf(&written).unwrap().joints[0].dynamics,
        model.joints[0].dynamics
    );
}

#[test]
fn negative_friction() {
    let dynamics = r#"<dynamics damping="-0.5" friction="1"/>"#;
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", dynamics),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(
        e.kind,
        ErrorKind::NegativeFriction {
            damping: -0.5,
            friction: 1.0
        }
    );
    assert!(e.to_string().contains("give values ≥ 0"), "{e}");
}

// ---------------------------------------------------------------------------------
// CAD rounding of inertias

/// A finger of three flat links (a plate has `J3 = J1 + J2` exactly) whose largest
/// moments are 2.3e-6, 3.5e-6 and 7.3e-6 kg·m², written with four significant digits
/// as CAD exporters do, so that rounding breaks the triangle inequality (the first
/// two) or positive definiteness (the third, a rod whose zero moment came out
/// negative). `third` replaces the third link's moments.
fn cad_finger(third: [&str; 3]) -> String {
    robot(&[
        r#"<link name="palm"/>"#,
        &link_with("f1", "0.01", ["9.137e-7", "1.386e-6", "2.300e-6"]),
        &link_with("f2", "0.01", ["1.234e-6", "2.265e-6", "3.500e-6"]),
        &link_with("f3", "0.01", third),
        &joint("j1", "continuous", "palm", "f1", ""),
        &joint("j2", "continuous", "f1", "f2", ""),
        &joint("j3", "continuous", "f2", "f3", ""),
    ])
}

#[test]
fn cad_rounding_within_the_tolerance_is_accepted_with_warnings() {
    use dyngen_model::{inertia_violation, INERTIA_TOLERANCE};
    let text = cad_finger(["-2.0e-10", "7.300e-6", "7.300e-6"]);
    let model = parse_urdf(&text).unwrap();
    let warned: Vec<(&Element, Option<usize>)> = model.warnings.iter().map(|w| (&w.element, w.line)).collect();
    assert_eq!(
        warned,
        [
            (&Element::Link("f1".into()), Some(3)),
            (&Element::Link("f2".into()), Some(4)),
            (&Element::Link("f3".into()), Some(5)),
            // f3's near-zero moment is about j3's axis (URDF's default x): turning it
            // moves (almost) no inertia.
            (&Element::Joint("j3".into()), Some(8)),
        ]
    );
    let violations: Vec<f64> = model
        .warnings
        .iter()
        .take(3)
        .map(|w| match w.kind {
            ErrorKind::TriangleInequality(ev) | ErrorKind::NotPositiveDefinite(ev) => inertia_violation(ev),
            ref k => panic!("{k:?}"),
        })
        .collect();
    // 3e-10 / 2.3e-6, 1e-9 / 3.5e-6, 2e-10 / 7.3e-6: parts in ten thousand or less.
    for (v, expected) in violations.iter().zip([1.304e-4, 2.857e-4, 2.740e-5]) {
        assert!((v / expected - 1.0).abs() < 1e-3, "{violations:?}");
        assert!(*v < INERTIA_TOLERANCE);
    }
    assert!(matches!(model.warnings[2].kind, ErrorKind::NotPositiveDefinite(_)));
    let message = model.warnings[0].warning_message();
    assert!(
        message.starts_with("line 3: link `f1`: principal moments")
            && message.contains("break the triangle inequality")
            && message.contains("accepted as written: within the relative tolerance of 1e-3 for CAD rounding"),
        "{message}"
    );
    // Kept as written (as Pinocchio reads them); the nearest physical model moves
    // each moment by at most the violation.
    assert_eq!(model.bodies[0].inertial.inertia[0][0], 9.137e-7);
    let physical = model.nearest_physical();
    assert_eq!(physical.warnings, model.warnings[3..]);
    for (body, fixed) in model.bodies.iter().zip(&physical.bodies) {
        let (ev, _) = fixed.inertial.principal_axes();
        assert!(inertia_violation(ev) < 1e-12, "{ev:?}");
        assert!(dyngen_model::check_inertial(&fixed.inertial).is_ok(), "{ev:?}");
        for r in 0..3 {
            for c in 0..3 {
                let d = (fixed.inertial.inertia[r][c] - body.inertial.inertia[r][c]).abs();
                assert!(d <= 1.1e-9, "{} moved by {d:e}", body.name);
            }
        }
        assert_eq!(fixed.inertial.mass, body.inertial.mass);
        assert_eq!(fixed.inertial.com, body.inertial.com);
    }
    // A strict read refuses every one of them, as errors with their lines.
    let e = dyngen_model::parse_urdf_with(&text, true).unwrap_err();
    let lines: Vec<Option<usize>> = e.errors.iter().map(|e| e.line).collect();
    assert_eq!(lines, [Some(3), Some(4), Some(5), Some(8)]);
}

#[test]
fn violations_beyond_the_tolerance_load_with_a_warning_that_says_so() {
    // The same 7.3e-6 link with a moment off by 4 %: a mistake, not rounding.
    let text = cad_finger(["3.000e-6", "4.000e-6", "7.300e-6"]);
    let (model, warned) = load_warned(&text);
    assert_eq!(warned[2], (Element::Link("f3".into()), Some(5)));
    assert!(matches!(model.warnings[2].kind, ErrorKind::TriangleInequality(_)));
    let message = model.warnings[2].warning_message();
    assert!(
        message.contains("4.110 % of its largest moment away from physical"),
        "{message}"
    );
    assert!(
        message.contains("beyond the relative tolerance of 1e-3 for CAD rounding: check the file"),
        "{message}"
    );
    let errs = strict_errors(&text);
    assert_eq!(errs.len(), 3, "{errs:#?}");
    assert_named(&errs[2], &Element::Link("f3".into()), 5);
    // A clearly negative moment too.
    let (model, _) = load_warned(&cad_finger(["-1e-7", "7.300e-6", "7.300e-6"]));
    assert!(matches!(model.warnings[2].kind, ErrorKind::NotPositiveDefinite(_)));
}

#[test]
fn nearest_physical_moments_move_least() {
    use dyngen_model::{inertia_violation, nearest_physical_moments};
    // Triangle: each moment moves by a third of the excess, toward J3 = J1 + J2.
    let j = nearest_physical_moments([1.0, 2.0, 3.3]);
    assert!((j[0] - 1.1).abs() < 1e-15 && (j[1] - 2.1).abs() < 1e-15 && (j[2] - 3.2).abs() < 1e-15);
    assert_eq!(inertia_violation(j), 0.0);
    // A negative moment is raised to a tiny positive one.
    let j = nearest_physical_moments([-1e-9, 1.0, 1.0]);
    assert!(j[0] > 0.0 && j[0] <= 1e-9 && j[1] == 1.0 && j[2] == 1.0, "{j:?}");
    // Physical moments are left alone.
    assert_eq!(nearest_physical_moments([1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
}

#[test]
fn values_beyond_any_machine_are_errors_not_overflows() {
    let e = single(
        &one_body(&link_with("a", "1e308", ["1", "1", "1"])),
        Element::Link("a".into()),
        3,
    );
    assert_eq!(
        e.kind,
        ErrorKind::OutOfRange {
            what: "mass",
            value: 1e308
        }
    );
    assert!(
        e.to_string().contains("mass holds 1e308, beyond ±1e9 in SI units"),
        "{e}"
    );
    let text = robot(&[
        r#"<link name="base"/>"#,
        &link("a"),
        &joint("j", "continuous", "base", "a", r#"<origin xyz="0 0 -2e10"/>"#),
    ]);
    let e = single(&text, Element::Joint("j".into()), 4);
    assert_eq!(
        e.kind,
        ErrorKind::OutOfRange {
            what: "origin",
            value: -2e10
        }
    );
}
