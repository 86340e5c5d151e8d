//! The MJCF front end: MuJoCo's own conversions of the UR5 and Panda URDFs give the
//! URDF's model (to MuJoCo's printed rounding), the mass matrix and bias forces of the
//! models read from MJCF equal MuJoCo's (`tests/fixtures/mjcf/*.json`, written by
//! `scripts/make_mjcf_fixtures.py`), the hand-written `small.xml` gives its documented
//! numbers, the hand-written `floating.xml` (a free flyer and a ball joint) gives its
//! documented model and MuJoCo's mass matrix and bias forces in dyngen's coordinates,
//! the hand-written `armature.xml`, `geoms.xml`, `compiler.xml` and `ref.xml` give
//! MuJoCo's `qM` as `M + diag(Ia)`, its site poses, its geom-derived and
//! compiler-adjusted inertias and its dynamics with joint `ref` and several joints in
//! one body (`scripts/make_mjcf_armature_fixtures.py`), `<include>` splices files
//! (each refusal named with the `<include>`'s line, errors in included files with
//! theirs), linear `<equality><joint>` couplings are mimic joints with MuJoCo's offset,
//! each `<equality>` element the model cannot hold is warned about with its reason,
//! and one test per refused construct checks the message names the element and its
//! line.

use dyngen_model::regressor::{inverse_dynamics, mass_matrix};
use dyngen_model::{load_mjcf, load_robot, load_urdf, parse_mjcf, Element, ErrorKind, JointKind, Model, ModelErrors};

use crate::common::{load_error, TempDir};
use serde_json::Value;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn fixture(name: &str) -> PathBuf {
    root().join("tests/fixtures/mjcf").join(name)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn flat3(m: &[[f64; 3]; 3]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// Mass matrix and bias `τ(q, v, 0)` with the model's nominal parameters, for any
/// model (`nq` positions, `nv` velocities).
fn dynamics(model: &Model, q: &[f64], v: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let zero = vec![0.0; model.nv()];
    (
        mass_matrix(model, q).unwrap(),
        inverse_dynamics(model, q, v, &zero).unwrap(),
    )
}

fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(numbers).collect(),
        Value::Number(x) => vec![x.as_f64().unwrap()],
        _ => panic!("not a number: {v}"),
    }
}

/// Largest difference of `M` and of the bias from MuJoCo's, over the fixture's states.
fn against_mujoco(name: &str) -> (f64, f64) {
    let model = load_mjcf(&fixture(&format!("{name}.xml"))).unwrap();
    let text = std::fs::read_to_string(fixture(&format!("{name}.json"))).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let joints: Vec<&str> = reference["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let ours: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(ours, joints, "{name}: joint order");
    assert_eq!(model.gravity.to_vec(), numbers(&reference["gravity"]));
    let (mut dm, mut db) = (0.0f64, 0.0f64);
    for s in reference["samples"].as_array().unwrap() {
        let (q, v) = (numbers(&s["q"]), numbers(&s["v"]));
        let (m, bias) = dynamics(&model, &q, &v);
        let m: Vec<f64> = m.into_iter().flatten().collect();
        dm = dm.max(max_abs_diff(&m, &numbers(&s["M"])));
        db = db.max(max_abs_diff(&bias, &numbers(&s["bias"])));
    }
    eprintln!("{name}: |M - M_mujoco| <= {dm:.2e}, |bias - bias_mujoco| <= {db:.2e}");
    (dm, db)
}

#[test]
fn mass_matrix_and_bias_equal_mujocos() {
    for name in ["ur5", "panda", "small"] {
        let (dm, db) = against_mujoco(name);
        assert!(dm < 1e-12 && db < 1e-11, "{name}: M {dm:e}, bias {db:e}");
    }
}

/// MuJoCo prints 6 significant digits: a rounded quaternion is normalised back to
/// the exact rotation when its entries are equal (`0.707107 0.707107 0 0`), but
/// centres of mass, inertias, limits and general principal axes differ from the
/// URDF's by up to half a unit in the sixth digit.
fn compare_with_urdf(name: &str, urdf: &str) -> [f64; 4] {
    let from_mjcf = load_mjcf(&fixture(&format!("{name}.xml"))).unwrap();
    let from_urdf = load_urdf(&root().join(urdf)).unwrap();
    assert_eq!(from_mjcf.dof(), from_urdf.dof());
    assert_eq!(from_mjcf.base, "world");
    let (mut placement, mut axis, mut inertial, mut limits) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (a, b) in from_mjcf.joints.iter().zip(&from_urdf.joints) {
        assert_eq!((&a.name, a.kind, a.parent), (&b.name, b.kind, b.parent));
        placement = placement.max(max_abs_diff(&flat3(&a.origin.rotation), &flat3(&b.origin.rotation)));
        placement = placement.max(max_abs_diff(&a.origin.translation, &b.origin.translation));
        axis = axis.max(max_abs_diff(&a.axis, &b.axis));
        let (la, lb) = (a.limits.unwrap(), b.limits.unwrap());
        limits = limits.max(max_abs_diff(
            &[la.lower, la.upper, la.effort],
            &[lb.lower, lb.upper, lb.effort],
        ));
    }
    for (a, b) in from_mjcf.bodies.iter().zip(&from_urdf.bodies) {
        assert_eq!((&a.name, &a.merged), (&b.name, &b.merged));
        let (ia, ib) = (a.inertial, b.inertial);
        // Relative to the body's largest moment for the tensor, absolute for the rest.
        let scale = ib.inertia.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        inertial = inertial.max((ia.mass - ib.mass).abs() / ib.mass);
        inertial = inertial.max(max_abs_diff(&ia.com, &ib.com));
        inertial = inertial.max(max_abs_diff(&flat3(&ia.inertia), &flat3(&ib.inertia)) / scale);
    }
    // The URDF's frames are the MJCF's without `world`.
    let frames: Vec<_> = from_mjcf.frames.iter().filter(|f| f.name != "world").collect();
    assert_eq!(frames.len(), from_urdf.frames.len());
    for (a, b) in frames.iter().zip(&from_urdf.frames) {
        assert_eq!((&a.name, a.body), (&b.name, b.body));
        placement = placement.max(max_abs_diff(&a.placement.translation, &b.placement.translation));
        placement = placement.max(max_abs_diff(
            &flat3(&a.placement.rotation),
            &flat3(&b.placement.rotation),
        ));
    }
    eprintln!(
        "{name}: placements {placement:.1e}, axes {axis:.1e}, inertials (relative) {inertial:.1e}, limits {limits:.1e}"
    );
    [placement, axis, inertial, limits]
}

#[test]
fn mujocos_ur5_is_the_urdfs() {
    let [placement, axis, inertial, limits] = compare_with_urdf("ur5", "robots/ur5/ur5.urdf");
    assert!(placement < 1e-12 && axis == 0.0, "{placement:e} {axis:e}");
    assert!(inertial < 5e-6 && limits < 5e-6, "{inertial:e} {limits:e}");
}

#[test]
fn mujocos_panda_is_the_urdfs() {
    let [placement, axis, inertial, limits] = compare_with_urdf("panda", "robots/panda/panda.urdf");
    assert!(placement < 1e-12 && axis == 0.0, "{placement:e} {axis:e}");
    assert!(inertial < 5e-6 && limits < 5e-6, "{inertial:e} {limits:e}");
}

#[test]
fn small_gives_its_documented_numbers() {
    let model = load_robot(&fixture("small.xml")).unwrap();
    assert_eq!(model.name, "small");
    assert_eq!(model.base, "world");
    let close = |a: &[f64], b: &[f64]| max_abs_diff(a, b) < 1e-15;
    let [shoulder, slider] = [&model.joints[0], &model.joints[1]];
    assert_eq!(
        (shoulder.name.as_str(), shoulder.kind, shoulder.parent),
        ("shoulder", JointKind::Revolute, 0)
    );
    assert!(close(
        &flat3(&shoulder.origin.rotation),
        &[0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    ));
    assert!(close(&shoulder.origin.translation, &[0.0, 0.0, 0.35]));
    assert!(close(&shoulder.axis, &[0.0, 1.0, 0.0]));
    let l = shoulder.limits.unwrap();
    assert!(close(
        &[l.lower, l.upper],
        &[-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2]
    ));
    assert_eq!((shoulder.dynamics.damping, shoulder.dynamics.friction), (0.5, 0.1));

    assert_eq!(
        (slider.name.as_str(), slider.kind, slider.parent),
        ("slider", JointKind::Prismatic, 1)
    );
    assert!(close(&slider.origin.translation, &[0.0, 0.0, 0.45]));
    assert!(close(
        &flat3(&slider.origin.rotation),
        &flat3(&dyngen_model::math::IDENTITY)
    ));
    assert!(close(&slider.axis, &[1.0, 0.0, 0.0]));
    let l = slider.limits.unwrap();
    assert_eq!((l.lower, l.upper), (-0.2, 0.3));
    assert_eq!((slider.dynamics.damping, slider.dynamics.friction), (0.5, 0.1));

    let upper = &model.bodies[0].inertial;
    assert_eq!(upper.mass, 2.0);
    assert!(close(&upper.com, &[0.0, 0.0, 0.2]));
    assert!(close(
        &flat3(&upper.inertia),
        &[0.05, 0.0, 0.0, 0.0, 0.04, 0.0, 0.0, 0.0, 0.02]
    ));
    let fore = &model.bodies[1];
    // The site `tool` in `tip` is a frame of `fore`, at tip's place, with no mass.
    assert_eq!(fore.merged, ["tip", "tool"]);
    let tool = model.frames.iter().find(|f| f.name == "tool").unwrap();
    assert_eq!(tool.body, 2);
    assert!(close(&tool.placement.translation, &[0.2, 0.0, 0.0]));
    assert!(close(
        &flat3(&tool.placement.rotation),
        &flat3(&dyngen_model::math::IDENTITY)
    ));
    assert_eq!(fore.inertial.mass, 1.5);
    assert!(close(&fore.inertial.com, &[0.4 / 3.0, 0.0, 0.0]));
    // 0.004 0.002 0.003 about fore's centre, 1e-4 each for the tip, plus the
    // parallel-axis terms of 1 kg at -1/30 and 0.5 kg at +2/30 along x (y and z only).
    let d = 1.0 * (1.0f64 / 30.0).powi(2) + 0.5 * (2.0f64 / 30.0).powi(2);
    let expected = [0.0041, 0.0, 0.0, 0.0, 0.0021 + d, 0.0, 0.0, 0.0, 0.0031 + d];
    assert!(max_abs_diff(&flat3(&fore.inertial.inertia), &expected) < 1e-15);
    let names: Vec<&str> = model.frames.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["world", "base", "upper", "fore", "tip", "tool"]);
}

#[test]
fn load_robot_dispatches_on_the_extension() {
    let urdf = load_robot(&root().join("robots/ur5/ur5.urdf")).unwrap();
    assert_eq!(urdf, load_urdf(&root().join("robots/ur5/ur5.urdf")).unwrap());
    let mjcf = load_robot(&fixture("small.xml")).unwrap();
    assert_eq!(mjcf, load_mjcf(&fixture("small.xml")).unwrap());
    // Anything but `.xml` and `.mjcf` is read as URDF.
    let e = load_robot(&root().join("README.md")).unwrap_err();
    assert!(e.to_string().contains("README.md"), "{e}");
}

// ---------------------------------------------------------------------------------
// Errors: each names its element and line.

/// A document whose worldbody holds `lines`, so that `lines[k]` sits on line `k + 3`.
fn mjcf(lines: &[&str]) -> String {
    let mut text = String::from("<mujoco model=\"t\">\n<worldbody>\n");
    for l in lines {
        text.push_str(l);
        text.push('\n');
    }
    text.push_str("</worldbody>\n</mujoco>\n");
    text
}

const INERTIAL: &str = r#"<inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>"#;

fn errors(text: &str) -> ModelErrors {
    parse_mjcf(text).expect_err("should be refused")
}

/// The only error, checked for its element, line and a part of its message.
fn only_error(text: &str, element: Element, line: usize, says: &str) -> ErrorKind {
    let e = errors(text);
    assert_eq!(e.errors.len(), 1, "{e}");
    let err = &e.errors[0];
    assert_eq!((&err.element, err.line), (&element, Some(line)), "{e}");
    let message = e.to_string();
    assert!(message.starts_with(&format!("line {line}: {element}: ")), "{message}");
    assert!(message.contains(says), "{message}");
    err.kind.clone()
}

/// Two joints in one body: a chain through a massless link named after the body and
/// its first joint, the body's inertial on the last, each joint at its own `pos`.
#[test]
fn two_joints_in_one_body_are_a_chain() {
    let text = mjcf(&[
        "<body name=\"a\" pos=\"0 0 1\">",
        INERTIAL,
        "<joint name=\"j1\" axis=\"1 0 0\" pos=\"0.1 0 0\"/>",
        "<joint name=\"j2\" axis=\"0 1 0\" pos=\"0 0.2 0\"/>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    let names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["a (j1)", "a"]);
    assert_eq!(model.bodies[0].inertial.mass, 0.0);
    assert_eq!(model.joints[0].origin.translation, [0.1, 0.0, 1.0]);
    assert_eq!(model.joints[1].origin.translation, [-0.1, 0.2, 0.0]);
    assert_eq!(model.joints[1].parent, 1);
    assert_eq!(model.joints[1].axis, [0.0, 1.0, 0.0]);
    // The body's inertial in the last joint's frame.
    assert_eq!(model.bodies[1].inertial.com, [0.0, -0.2, 0.0]);
}

/// MuJoCo's `inertiafromgeom="auto"` (its default): a body without <inertial> takes
/// the inertia of its geoms (a sphere of radius 0.1 and density 1000 here).
#[test]
fn a_body_without_inertial_takes_its_geoms() {
    let text = mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"j\"/>",
        "<geom type=\"sphere\" size=\"0.1\" pos=\"0 0 0.5\"/>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    let i = &model.bodies[0].inertial;
    let m = 4.0 / 3.0 * std::f64::consts::PI * 1e-3 * 1000.0;
    assert!((i.mass - m).abs() < 1e-15 * m);
    assert_eq!(i.com, [0.0, 0.0, 0.5]);
    assert!(
        max_abs_diff(
            &flat3(&i.inertia),
            &[
                0.4 * m * 0.01,
                0.0,
                0.0,
                0.0,
                0.4 * m * 0.01,
                0.0,
                0.0,
                0.0,
                0.4 * m * 0.01
            ]
        ) < 1e-16
    );
    // Not with inertiafromgeom="false": then the body has no mass.
    let text = text.replace("<worldbody>", "<compiler inertiafromgeom=\"false\"/>\n<worldbody>");
    let d = dyngen_model::mjcf::mjcf_description(&text).unwrap();
    assert_eq!(d.links.iter().find(|l| l.name == "a").unwrap().inertial, None);
    // A massless marker at the end of a chain is fine.
    let text = mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"j\"/>",
        INERTIAL,
        "<body name=\"marker\" pos=\"0 0 1\"/>",
        "</body>",
    ]);
    assert_eq!(parse_mjcf(&text).unwrap().bodies[0].merged, ["marker"]);
}

#[test]
fn bad_numbers_name_their_line() {
    let text = mjcf(&[
        "<body name=\"a\" pos=\"0 0\">",
        "<joint name=\"j\" range=\"-1 one\"/>",
        INERTIAL,
        "</body>",
    ]);
    let e = errors(&text);
    assert_eq!(e.errors.len(), 2, "{e}");
    assert_eq!(
        (&e.errors[0].element, e.errors[0].line),
        (&Element::Link("a".into()), Some(3))
    );
    assert_eq!(
        (&e.errors[1].element, e.errors[1].line),
        (&Element::Joint("j".into()), Some(4))
    );
    let message = e.to_string();
    assert!(
        message.contains("line 3: link `a`: <body pos=\"0 0\"> is not 3 numbers"),
        "{message}"
    );
    assert!(
        message.contains("line 4: joint `j`: <joint range=\"-1 one\"> is not 2 numbers"),
        "{message}"
    );
}

#[test]
fn include_in_text_is_refused() {
    let text = "<mujoco model=\"t\">\n  <include file=\"arm.xml\"/>\n  <worldbody/>\n</mujoco>\n";
    let e = errors(text);
    assert_eq!(
        (&e.errors[0].element, e.errors[0].line),
        (&Element::Robot, Some(2)),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains("line 2: robot: <include file=\"arm.xml\">: MJCF text read without its file")
            && e.to_string().contains("load_mjcf"),
        "{e}"
    );
}

const BODY_A: &str =
    "<body name=\"a\"><joint name=\"ja\"/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"0.1 0.1 0.1\"/></body>";

#[test]
fn include_is_replaced_by_the_included_files_elements() {
    let dir = TempDir::new("mjcf-include-splice");
    // Paths relative to the top-level file's folder, nested includes too (MuJoCo's
    // rule: `sub/b.xml` includes `c.xml` of the top folder, not `sub/c.xml`).
    let top = dir.write(
        "top.xml",
        "<mujoco model=\"t\">\n<include file=\"sub/b.xml\"/>\n<worldbody>\n<include file=\"./arm.xml\"/>\n\
         <body name=\"z\"><joint name=\"jz\"/><inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 1 1\"/></body>\n\
         </worldbody>\n</mujoco>\n",
    );
    dir.write("sub/b.xml", "<mujoco>\n<include file=\"c.xml\"/>\n</mujoco>\n");
    dir.write("sub/c.xml", "<mujoco><option gravity=\"0 0 -4\"/></mujoco>\n");
    dir.write("c.xml", "<mujoco><option gravity=\"0 0 -3\"/></mujoco>\n");
    dir.write(
        "arm.xml",
        format!("<mujoco>\n{BODY_A}\n<body name=\"b\"><joint name=\"jb\"/>{INERTIAL}</body>\n</mujoco>\n"),
    );
    let model = load_mjcf(&top).unwrap();
    assert_eq!(model.gravity, [0.0, 0.0, -3.0]);
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    // In place of the <include>, in order.
    assert_eq!(names, ["ja", "jb", "jz"]);
}

#[test]
fn errors_in_an_included_file_name_it_and_its_line() {
    let dir = TempDir::new("mjcf-include-inner");
    let top = dir.write(
        "top.xml",
        "<mujoco model=\"t\">\n<worldbody>\n<include file=\"parts/arm.xml\"/>\n</worldbody>\n</mujoco>\n",
    );
    dir.write(
        "parts/arm.xml",
        "<mujoco>\n<body name=\"a\">\n<joint name=\"j\" damping=\"fast\"/>\n</body>\n</mujoco>\n",
    );
    let message = load_error(
        &top,
        3,
        "in `parts/arm.xml` line 3: <joint damping=\"fast\"> is not a number",
    );
    assert!(message.contains("joint `j`"), "{message}");
    // Nested: the chain of includes is named.
    dir.write(
        "parts/arm.xml",
        "<mujoco>\n\n<include file=\"parts/hand.xml\"/>\n</mujoco>\n",
    );
    dir.write(
        "parts/hand.xml",
        "<mujoco>\n<body name=\"h\">\n<frame/>\n</body>\n</mujoco>\n",
    );
    load_error(
        &top,
        3,
        "in `parts/hand.xml` line 3, included from `parts/arm.xml` line 3: <frame>",
    );
    // Not XML.
    dir.write("parts/arm.xml", "<mujoco>\n<body>\n</mujoco>\n");
    load_error(&top, 3, "in `parts/arm.xml` line 3: not valid XML");
    // Warnings too.
    dir.write("parts/arm.xml", format!("<mujoco>\n{BODY_A}\n</mujoco>\n"));
    let top2 = dir.write(
        "top.xml",
        "<mujoco model=\"t\">\n<worldbody>\n<include file=\"parts/arm.xml\"/>\n</worldbody>\n\
         <include file=\"eq.xml\"/>\n</mujoco>\n",
    );
    dir.write(
        "eq.xml",
        "<mujoco>\n<equality>\n<joint joint1=\"ja\"/>\n</equality>\n</mujoco>\n",
    );
    let model = load_mjcf(&top2).unwrap();
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert_eq!(model.warnings[0].line, Some(5));
    assert!(
        model.warnings[0]
            .to_string()
            .contains("in `eq.xml` line 3: <equality> <joint>"),
        "{:?}",
        model.warnings
    );
}

#[test]
fn include_errors_name_the_include_and_what_is_valid() {
    let dir = TempDir::new("mjcf-include-errors");
    let top_with = |include: &str| {
        dir.write(
            "top.xml",
            format!("<mujoco model=\"t\">\n<worldbody>\n{BODY_A}\n</worldbody>\n{include}\n</mujoco>\n"),
        )
    };
    let top = top_with("<include/>");
    load_error(&top, 5, "<include> has no `file`; write <include file=\"NAME.xml\"/>");
    let top = top_with("<include file=\"missing.xml\"/>");
    load_error(&top, 5, "<include file=\"missing.xml\">: cannot read");
    let absolute = dir.write("abs.xml", "<mujoco/>");
    let top = top_with(&format!("<include file=\"{}\"/>", absolute.display()));
    load_error(
        &top,
        5,
        "is an absolute path; name the included file by a path relative",
    );
    let top = top_with("<include file=\"sub/../../x.xml\"/>");
    load_error(
        &top,
        5,
        "<include file=\"sub/../../x.xml\"> leads out of the top-level model file's folder",
    );
    // `..` that stays inside is fine.
    dir.write("inside.xml", "<mujoco><option gravity=\"0 0 -1\"/></mujoco>");
    let top = top_with("<include file=\"sub/../inside.xml\"/>");
    assert_eq!(load_mjcf(&top).unwrap().gravity, [0.0, 0.0, -1.0]);
    // Children in the <include>.
    let top = top_with("<include file=\"inside.xml\"><option/></include>");
    load_error(
        &top,
        5,
        "<include file=\"inside.xml\"> has child elements; an <include> must be empty",
    );
    // Root other than <mujoco>.
    dir.write("robot.xml", "<robot name=\"r\"/>");
    let top = top_with("<include file=\"robot.xml\"/>");
    load_error(
        &top,
        5,
        "in `robot.xml` line 1: the document element of an included file is <robot>, not <mujoco>",
    );
    // The same file twice, as MuJoCo refuses it.
    let top = top_with("<include file=\"inside.xml\"/><include file=\"./inside.xml\"/>");
    load_error(&top, 5, "`inside.xml` is already included (line 5 of `");
    // A cycle.
    dir.write("loop.xml", "<mujoco>\n<include file=\"top.xml\"/>\n</mujoco>");
    let top = top_with("<include file=\"loop.xml\"/>");
    load_error(
        &top,
        5,
        "in `loop.xml` line 2: <include file=\"top.xml\"> includes a file that is including it",
    );
    dir.write("self.xml", "<mujoco>\n<include file=\"self.xml\"/>\n</mujoco>");
    let top = top_with("<include file=\"self.xml\"/>");
    load_error(
        &top,
        5,
        "in `self.xml` line 2: <include file=\"self.xml\"> includes a file that is including it",
    );
    // Too deep: d0 includes d1 ... up to d9.
    for k in 0..10 {
        dir.write(
            &format!("d{k}.xml"),
            format!("<mujoco>\n<include file=\"d{}.xml\"/>\n</mujoco>", k + 1),
        );
    }
    dir.write("d10.xml", "<mujoco/>");
    let top = top_with("<include file=\"d0.xml\"/>");
    load_error(
        &top,
        5,
        "<include file=\"d8.xml\"> is nested 9 includes deep, more than the 8 allowed",
    );
    // Too large.
    let big = format!(
        "<mujoco>{}</mujoco>",
        " ".repeat(dyngen_model::urdf::MAX_FILE_BYTES as usize)
    );
    dir.write("big.xml", &big);
    let top = top_with("<include file=\"big.xml\"/>");
    load_error(&top, 5, "<include file=\"big.xml\">: `big.xml`: ");
}

#[test]
fn empty_names_are_no_names() {
    let text = mjcf(&[
        "<body name=\"\"><joint name=\"\"/>",
        INERTIAL,
        "<body name=\"\"><joint name=\"\"/>",
        INERTIAL,
        "<site name=\"\"/></body></body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["joint_0", "joint_1"]);
    assert!(
        model.frames.iter().all(|f| !f.name.is_empty()),
        "{:?}",
        model.frames.iter().map(|f| &f.name).collect::<Vec<_>>()
    );
}

#[test]
fn unknown_class_is_refused() {
    let text = mjcf(&[
        "<body name=\"a\">",
        INERTIAL,
        "<joint name=\"j\" class=\"nowhere\"/>",
        "</body>",
    ]);
    let kind = only_error(
        &text,
        Element::Joint("j".into()),
        5,
        "default class `nowhere` is not defined",
    );
    assert_eq!(kind, ErrorKind::UnknownClass("nowhere".into()));
    let text = mjcf(&[
        "<body name=\"a\" childclass=\"gone\">",
        INERTIAL,
        "<joint name=\"j\"/>",
        "</body>",
    ]);
    only_error(
        &text,
        Element::Link("a".into()),
        3,
        "default class `gone` is not defined",
    );
}

#[test]
fn errors_are_all_collected_with_the_file_name() {
    let dir = std::env::temp_dir().join(format!("dyngen-mjcf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.xml");
    let text = mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"b\" damping=\"fast\"/>",
        INERTIAL,
        "<body name=\"c\"><joint name=\"d\"/><inertial mass=\"1\" fullinertia=\"1 1 1 0 0 0\" quat=\"1 0 0 0\"/></body>",
        "</body>",
    ]);
    std::fs::write(&path, text).unwrap();
    let e = load_mjcf(&path).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    let message = e.to_string();
    let lines: Vec<&str> = message.lines().collect();
    assert_eq!(lines.len(), 2, "{message}");
    assert!(
        lines[0].ends_with(
            "bad.xml:4: joint `b`: <joint damping=\"fast\"> is not a number; write one number such as `0.5`"
        ),
        "{message}"
    );
    assert!(
        lines[1].ends_with(
            "bad.xml:6: link `c`: <inertial> gives both `fullinertia` and an orientation (`quat`), which MuJoCo \
             refuses: give `fullinertia` in the body frame without an orientation, or `diaginertia` with `quat`"
        ),
        "{message}"
    );
}

/// `armature` is the rotor inertia `Ia` of each of the joint's coordinates (a ball
/// joint has 3); `stiffness` is left out with a warning naming its `springref`.
#[test]
fn armature_is_the_rotor_inertia_and_stiffness_a_warning() {
    let text = mjcf(&[
        "<body name=\"a\">",
        INERTIAL,
        "<joint name=\"j\" armature=\"0.1\" stiffness=\"3\" springref=\"0.2\" damping=\"0.4\"/>",
        "<body name=\"b\">",
        INERTIAL,
        "<joint name=\"k\" type=\"ball\" armature=\"0.25\"/>",
        "</body>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    assert_eq!(model.joints[0].dynamics.armature, 0.1);
    assert_eq!(
        dyngen_model::joint_params::nominal_joint_params(&model),
        [
            [0.1, 0.4, 0.0, 0.0],
            [0.25, 0.0, 0.0, 0.0],
            [0.25, 0.0, 0.0, 0.0],
            [0.25, 0.0, 0.0, 0.0]
        ]
        .concat()
    );
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let w = model.warnings[0].warning_message();
    assert!(
        w.starts_with("line 5: joint `j`: stiffness = 3 (springref 0.2) is left out"),
        "{w}"
    );
    // A negative armature is refused.
    let text = text.replace("armature=\"0.25\"", "armature=\"-0.25\"");
    only_error(
        &text,
        Element::Joint("k".into()),
        8,
        "armature = -0.25 is not a rotor inertia; give a value >= 0",
    );
}

#[test]
fn not_mujoco_and_too_deep_are_refused() {
    let e = errors("<robot name=\"r\"/>\n");
    assert!(
        e.to_string()
            .contains("line 1: robot: the document element is <robot>, not <mujoco>"),
        "{e}"
    );
    let deep = format!("<mujoco>\n{}{}</mujoco>", "<a>".repeat(300), "</a>".repeat(300));
    let e = errors(&deep);
    assert!(matches!(e.errors[0].kind, ErrorKind::TooDeep { .. }), "{e}");
}

/// Orientations against MuJoCo's `xmat` of a body at `q = 0` (MuJoCo 4.0.0, printed
/// with `repr`), for every way of writing one; angles in degrees, the default.
#[test]
fn orientations_are_mujocos() {
    let cases: [(&str, &str, [f64; 9]); 6] = [
        (
            "xyz",
            r#"euler="30 40 50""#,
            [
                0.49240387650610407,
                -0.5868240888334653,
                0.6427876096865394,
                0.8700019037522058,
                0.3104684609733674,
                -0.383022221559489,
                0.025201386257487357,
                0.7478280708194913,
                0.6634139481689385,
            ],
        ),
        (
            "zyX",
            r#"euler="30 40 50""#,
            [
                0.6634139481689386,
                -0.5,
                0.5566703992264195,
                0.7386058147591561,
                0.5566703992264195,
                -0.38023613325019795,
                -0.11976386674980224,
                0.6634139481689385,
                0.7386058147591562,
            ],
        ),
        (
            "XYZ",
            r#"euler="30 40 50""#,
            [
                0.4924038765061042,
                -0.4568259925856712,
                0.7408430568614908,
                0.5868240888334654,
                0.8028723374794715,
                0.10504046113295201,
                -0.6427876096865395,
                0.383022221559489,
                0.6634139481689386,
            ],
        ),
        (
            "xyz",
            r#"axisangle="1 2 3 70""#,
            [
                0.3890187045166923,
                -0.659433128159501,
                0.6432825172674365,
                0.8474273729235955,
                0.5300143880897634,
                0.03084795029895926,
                -0.3612911501212944,
                0.5331347839933247,
                0.7650071940448816,
            ],
        ),
        (
            "xyz",
            r#"xyaxes="1 1 0 -1 2 0.5""#,
            [
                0.7071067811865472,
                -0.6882472016116852,
                0.16222142113076252,
                0.7071067811865475,
                0.6882472016116852,
                -0.1622214211307625,
                0.0,
                0.22941573387056174,
                0.973328526784575,
            ],
        ),
        (
            "xyz",
            r#"zaxis="1 -2 2""#,
            [
                0.9333333333333333,
                0.13333333333333336,
                0.3333333333333333,
                0.13333333333333336,
                0.7333333333333332,
                -0.6666666666666666,
                -0.3333333333333333,
                0.6666666666666666,
                0.6666666666666665,
            ],
        ),
    ];
    for (seq, attr, expected) in cases {
        let text = format!(
            r#"<mujoco><compiler eulerseq="{seq}"/><worldbody><body name="a" {attr}>{INERTIAL}<joint name="j"/></body></worldbody></mujoco>"#
        );
        let model = parse_mjcf(&text).unwrap();
        let d = max_abs_diff(&flat3(&model.joints[0].origin.rotation), &expected);
        assert!(d < 1e-15, "{seq} {attr}: {d:e}");
    }
}

// ---------------------------------------------------------------------------------
// Ball and free joints.

/// The 1-based number of the first line of `text` holding `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).expect(needle) + 1
}

fn rotation_xyz(a: f64, b: f64, c: f64) -> [[f64; 3]; 3] {
    use dyngen_model::math::mat_mul;
    let (sa, ca) = a.sin_cos();
    let (sb, cb) = b.sin_cos();
    let (sc, cc) = c.sin_cos();
    let rx = [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]];
    let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
    let rz = [[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]];
    mat_mul(&mat_mul(&rx, &ry), &rz)
}

#[test]
fn floating_gives_its_documented_model() {
    use dyngen_model::math::{mat_vec, IDENTITY};
    let text = std::fs::read_to_string(fixture("floating.xml")).unwrap();
    let model = load_mjcf(&fixture("floating.xml")).unwrap();
    assert_eq!((model.name.as_str(), model.base.as_str()), ("floating", "world"));
    assert!(model.is_floating());
    let kinds: Vec<(&str, JointKind, usize)> = model
        .joints
        .iter()
        .map(|j| (j.name.as_str(), j.kind, j.parent))
        .collect();
    assert_eq!(
        kinds,
        [
            ("root", JointKind::FreeFlyer, 0),
            ("shoulder", JointKind::Spherical, 1),
            ("elbow", JointKind::Revolute, 2),
            ("wrist", JointKind::Prismatic, 3),
        ]
    );
    assert_eq!((model.nq(), model.nv(), model.dof()), (13, 11, 4));
    let q_offsets: Vec<usize> = (1..=4).map(|j| model.q_offset(j)).collect();
    let v_offsets: Vec<usize> = (1..=4).map(|j| model.v_offset(j)).collect();
    assert_eq!((q_offsets, v_offsets), (vec![0, 7, 11, 12], vec![0, 6, 9, 10]));
    let close = |a: &[f64], b: &[f64]| max_abs_diff(a, b) < 1e-15;

    // The free flyer: from the world's origin whatever the torso's pos and quat.
    let [root, shoulder, elbow, wrist] = [0, 1, 2, 3].map(|k| &model.joints[k]);
    assert_eq!(root.origin, dyngen_model::Placement::IDENTITY);
    assert_eq!((root.axis, root.limits), ([0.0; 3], None));
    // The ball joint: the upper arm's placement moved to the joint pos; no axis, no
    // limits (its range left out with a warning), its damping kept.
    let r = rotation_xyz(0.3, -0.2, 0.1);
    assert!(close(&flat3(&shoulder.origin.rotation), &flat3(&r)));
    let at = mat_vec(&r, &[0.0, 0.03, 0.02]);
    assert!(close(
        &shoulder.origin.translation,
        &[0.05 + at[0], 0.2 + at[1], 0.18 + at[2]]
    ));
    assert_eq!((shoulder.axis, shoulder.limits), ([0.0; 3], None));
    assert_eq!(shoulder.dynamics.damping, 0.2);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let w = &model.warnings[0];
    let shoulder_line = line_of(&text, "name=\"shoulder\"");
    assert_eq!(
        (&w.element, w.line),
        (&Element::Joint("shoulder".into()), Some(shoulder_line))
    );
    assert!(matches!(w.kind, ErrorKind::Ignored(_)));
    assert!(
        w.warning_message().ends_with(
            "the limit of this ball joint (range 0 1.5) is left out: the model has no limits for ball joints"
        ),
        "{}",
        w.warning_message()
    );
    // The elbow: the forearm's placement (below the shoulder's pos) moved to its pos.
    assert!(close(&flat3(&elbow.origin.rotation), &flat3(&IDENTITY)));
    assert!(close(&elbow.origin.translation, &[0.0, -0.02, -0.305]));
    assert_eq!(elbow.axis, [0.0, 1.0, 0.0]);
    let l = elbow.limits.unwrap();
    assert_eq!((l.lower, l.upper), (-2.5, 0.1));
    // The wrist: a slide along (0.2 0 1), normalised, below the elbow's pos.
    assert!(close(&wrist.origin.translation, &[0.0, 0.0, -0.275]));
    let n = 1.04f64.sqrt();
    assert!(close(&wrist.axis, &[0.2 / n, 0.0, 1.0 / n]));
    assert_eq!(wrist.limits.map(|l| (l.lower, l.upper)), Some((-0.05, 0.05)));

    // The fullinertia of the forearm, as written, its centre in the elbow's frame.
    let forearm = &model.bodies[2].inertial;
    assert_eq!(forearm.mass, 0.9);
    assert!(close(&forearm.com, &[0.01, 0.0, -0.135]));
    assert!(close(
        &flat3(&forearm.inertia),
        &[0.009, 0.0002, -0.0004, 0.0002, 0.0095, 0.0001, -0.0004, 0.0001, 0.0012]
    ));
    assert_eq!(model.bodies[0].merged, ["head"]);
    assert!((model.bodies[0].inertial.mass - 7.6).abs() < 1e-15);
    let names: Vec<&str> = model.frames.iter().map(|f| f.name.as_str()).collect();
    // The site `palm` in `hand` is a frame too.
    assert_eq!(
        names,
        ["world", "torso", "head", "upper_arm", "forearm", "hand", "palm"]
    );
}

/// The largest magnitude in `x`.
fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, y| m.max(y.abs()))
}

/// MuJoCo's mass matrix and bias forces of `floating.xml`, converted to dyngen's
/// coordinates by the script (quaternions `x y z w`, the free joint's linear velocity
/// in the body frame, `M = T⁻ᵀ M_mj T⁻¹`, `b = T⁻ᵀ b_mj + M [ω × v; 0]`), equal the
/// regressor's on the model read from the same file.
#[test]
fn floating_mass_matrix_and_bias_equal_mujocos() {
    let model = load_mjcf(&fixture("floating.xml")).unwrap();
    let text = std::fs::read_to_string(fixture("floating.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let joints: Vec<&str> = reference["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let ours: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(ours, joints);
    assert_eq!(
        (model.nq() as u64, model.nv() as u64),
        (reference["nq"].as_u64().unwrap(), reference["nv"].as_u64().unwrap())
    );
    assert_eq!(model.gravity.to_vec(), numbers(&reference["gravity"]));
    let (mut dm, mut db) = (0.0f64, 0.0f64);
    let samples = reference["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 3);
    for s in samples {
        let (q, v) = (numbers(&s["q"]), numbers(&s["v"]));
        // Unit quaternions, stored x y z w.
        for qa in [3, 7] {
            let norm: f64 = q[qa..qa + 4].iter().map(|x| x * x).sum();
            assert!((norm - 1.0).abs() < 1e-15);
        }
        let (m, bias) = dynamics(&model, &q, &v);
        let m: Vec<f64> = m.into_iter().flatten().collect();
        let (m_ref, bias_ref) = (numbers(&s["M"]), numbers(&s["bias"]));
        dm = dm.max(max_abs_diff(&m, &m_ref) / max_abs(&m_ref));
        db = db.max(max_abs_diff(&bias, &bias_ref) / max_abs(&bias_ref));
    }
    eprintln!("floating: |M - M_mujoco| / |M_mujoco| <= {dm:.2e}, |b - b_mujoco| / |b_mujoco| <= {db:.2e}");
    // MuJoCo reads the hand-written numbers exactly: only rounding is left.
    assert!(dm <= 1e-12 && db <= 1e-12, "M {dm:e}, bias {db:e}");
}

/// A torso on the free joint `free` (a `<joint type="free">` or a `<freejoint>`),
/// with `body_attrs`, and an arm on a hinge below it.
fn free_body(free: &str, body_attrs: &str) -> String {
    mjcf(&[
        &format!("<body name=\"torso\" {body_attrs}>"),
        free,
        INERTIAL,
        "<body name=\"arm\" pos=\"0 0 0.5\">",
        "<joint name=\"j\" axis=\"1 0 0\"/>",
        INERTIAL,
        "</body>",
        "</body>",
    ])
}

#[test]
fn a_free_joint_is_a_free_flyer_from_the_world() {
    let short = parse_mjcf(&free_body("<freejoint name=\"f\"/>", "")).unwrap();
    assert_eq!(short.joints[0].kind, JointKind::FreeFlyer);
    assert_eq!((short.nq(), short.nv()), (8, 7));
    assert!(short.is_floating());
    // `<joint type="free">` is the same joint; MuJoCo ignores its pos and axis.
    let long = parse_mjcf(&free_body(
        "<joint name=\"f\" type=\"free\" pos=\"1 2 3\" axis=\"1 0 0\"/>",
        "",
    ))
    .unwrap();
    assert_eq!(long, short);
    // The body's placement is MuJoCo's qpos0 alone: the model does not change.
    let moved = parse_mjcf(&free_body(
        "<freejoint name=\"f\"/>",
        "pos=\"1 2 3\" euler=\"10 20 30\"",
    ))
    .unwrap();
    assert_eq!(moved, short);
    // Damping and friction of a `free` joint are kept; `<freejoint>` has none.
    let damped = parse_mjcf(&free_body(
        "<joint name=\"f\" type=\"free\" damping=\"2\" frictionloss=\"0.5\"/>",
        "",
    ))
    .unwrap();
    assert_eq!(
        (damped.joints[0].dynamics.damping, damped.joints[0].dynamics.friction),
        (2.0, 0.5)
    );
    // A class may make a joint free.
    let text = format!(
        "<mujoco><default><default class=\"float\"><joint type=\"free\"/></default></default><worldbody>\
         <body name=\"torso\"><joint name=\"f\" class=\"float\"/>{INERTIAL}</body></worldbody></mujoco>"
    );
    assert_eq!(parse_mjcf(&text).unwrap().joints[0].kind, JointKind::FreeFlyer);
}

#[test]
fn a_ball_joint_is_spherical_about_its_pos() {
    let ball = |attrs: &str| {
        mjcf(&[
            "<body name=\"a\" pos=\"0 0 1\" euler=\"0 0 90\">",
            &format!("<joint name=\"b\" type=\"ball\" pos=\"0.1 0 0\" {attrs}/>"),
            INERTIAL,
            "</body>",
        ])
    };
    let model = parse_mjcf(&ball("axis=\"1 0 0\" limited=\"false\" range=\"0 60\"")).unwrap();
    let joint = &model.joints[0];
    assert_eq!(
        (joint.kind, joint.axis, joint.limits),
        (JointKind::Spherical, [0.0; 3], None)
    );
    assert_eq!((model.nq(), model.nv()), (4, 3));
    // Rz(90°) takes the pos 0.1 0 0 to 0 0.1 0.
    assert!(max_abs_diff(&joint.origin.translation, &[0.0, 0.1, 1.0]) < 1e-15);
    // The body's inertial sits in the joint frame: its centre moves by -pos.
    assert!(max_abs_diff(&model.bodies[0].inertial.com, &[-0.1, 0.0, 0.0]) < 1e-15);
    assert!(model.warnings.is_empty());
    // A range in effect (autolimits, or limited="true", even without a range as
    // MuJoCo allows for a ball) is left out with a warning; no range, no warning.
    for attrs in ["range=\"0 60\"", "limited=\"true\" range=\"0 60\"", "limited=\"true\""] {
        let model = parse_mjcf(&ball(attrs)).unwrap();
        assert_eq!(model.warnings.len(), 1, "{attrs}");
        let w = model.warnings[0].warning_message();
        assert!(w.starts_with("line 4: joint `b`: the limit of this ball joint"), "{w}");
    }
    assert!(parse_mjcf(&ball("")).unwrap().warnings.is_empty());
}

#[test]
fn a_free_joint_below_the_top_level_is_refused() {
    // Under a moving body (the description's own check would catch this too).
    let text = mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"j\"/>",
        INERTIAL,
        "<body name=\"b\" pos=\"0 0 1\">",
        INERTIAL,
        "<freejoint name=\"f\"/>",
        "</body>",
        "</body>",
    ]);
    let kind = only_error(&text, Element::Joint("f".into()), 8, "must join the root link");
    assert_eq!(kind, ErrorKind::FreeFlyerNotAtRoot);
    // Under a jointless body: MuJoCo refuses it ("free joint can only be used on top
    // level") though the body is fixed to the world.
    let text = mjcf(&[
        "<body name=\"stand\">",
        "<body name=\"b\">",
        "<joint name=\"f\" type=\"free\"/>",
        INERTIAL,
        "</body>",
        "</body>",
    ]);
    only_error(
        &text,
        Element::Joint("f".into()),
        5,
        "(in MJCF: a free joint only in a body directly in <worldbody>)",
    );
    // With the file name and line, as for URDF.
    let dir = std::env::temp_dir().join(format!("dyngen-mjcf-free-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("nested.xml");
    std::fs::write(&path, &text).unwrap();
    let e = load_mjcf(&path).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    let message = e.to_string();
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(
        message.ends_with(
            "nested.xml:5: joint `f`: a floating (free-flyer) joint must join the root link to a body (in MJCF: a \
             free joint only in a body directly in <worldbody>); make it the joint of a child of the root link, or \
             leave the body fixed"
        ),
        "{message}"
    );
}

#[test]
fn a_free_body_after_a_moving_one_loads_as_a_second_free_flyer() {
    // Top level, as MuJoCo allows: a free flyer on the world beside the hinged body.
    let text = mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"j\"/>",
        INERTIAL,
        "</body>",
        "<body name=\"b\">",
        INERTIAL,
        "<freejoint name=\"f\"/>",
        "</body>",
    ]);
    let model = dyngen_model::parse_mjcf(&text).unwrap();
    assert_eq!((model.nq(), model.nv()), (8, 7));
    assert_eq!(
        (model.joints[1].kind, model.joints[1].parent),
        (JointKind::FreeFlyer, 0)
    );
    // Not a floating base (joint 1 is the hinge), and no generated code for it.
    assert!(!model.is_floating());
    let body = model.multibody().unwrap();
    assert_eq!((body.nq(), body.nv()), (8, 7));
    // But not on the free flyer of `LoadOptions::free_flyer`: the body floats already.
    let options = dyngen_model::LoadOptions {
        free_flyer: true,
        ..Default::default()
    };
    let e = dyngen_model::parse_mjcf_options(&free_body("<freejoint name=\"f\"/>", ""), options).unwrap_err();
    assert_eq!(e.errors.len(), 1, "{e}");
    assert_eq!(
        (&e.errors[0].element, e.errors[0].line),
        (&Element::Joint("f".into()), Some(4))
    );
    assert!(
        e.to_string()
            .contains("line 4: joint `f`: body `torso` already floats on this free joint; the free-flyer load option"),
        "{e}"
    );
}

#[test]
fn a_free_body_aligned_with_its_inertia_is_refused() {
    let alone = |compiler: &str, free: &str| {
        format!(
            "<mujoco>\n{compiler}\n<worldbody>\n<body name=\"a\">\n{free}\n{INERTIAL}\n</body>\n</worldbody>\n</mujoco>\n"
        )
    };
    let says = "body `a` would be aligned with its principal axes of inertia";
    only_error(
        &alone("", "<freejoint name=\"f\" align=\"true\"/>"),
        Element::Joint("f".into()),
        5,
        says,
    );
    let aligned = "<compiler alignfree=\"true\"/>";
    only_error(
        &alone(aligned, "<freejoint name=\"f\"/>"),
        Element::Joint("f".into()),
        5,
        says,
    );
    only_error(
        &alone(aligned, "<joint name=\"f\" type=\"free\"/>"),
        Element::Joint("f".into()),
        5,
        says,
    );
    only_error(
        &alone("", "<freejoint name=\"f\" align=\"maybe\"/>"),
        Element::Joint("f".into()),
        5,
        "<freejoint align=\"maybe\"> is not `true`, `false` or `auto`",
    );
    // align="false" keeps the frame; MuJoCo does not align a body with children.
    assert!(parse_mjcf(&alone(aligned, "<freejoint name=\"f\" align=\"false\"/>")).is_ok());
    let with_child = free_body("<freejoint name=\"f\" align=\"true\"/>", "");
    assert!(parse_mjcf(&with_child).unwrap().is_floating());
}

#[test]
fn a_free_joint_with_another_joint_is_refused() {
    let text = mjcf(&[
        "<body name=\"a\">",
        INERTIAL,
        "<freejoint name=\"f\"/>",
        "<joint name=\"j\"/>",
        "</body>",
    ]);
    only_error(
        &text,
        Element::Joint("f".into()),
        5,
        "body `a` has a free joint and other joints; a free joint must be the only joint of its body",
    );
}

/// The same floating robot in both formats: the quadruped's URDF loaded with its root
/// link on a free flyer, and MuJoCo's MJCF export of that URDF with a `floating` root
/// joint (`scripts/make_mjcf_fixtures.py`: a `<joint type="free">`) give the same
/// joints and the same dynamics, as far as MuJoCo's printed digits allow.
#[test]
fn floating_quadruped_reads_the_same_from_urdf_and_mjcf() {
    let options = dyngen_model::LoadOptions {
        free_flyer: true,
        ..Default::default()
    };
    let urdf = dyngen_model::load_urdf_options(&root().join("robots/quadruped12/quadruped12.urdf"), options).unwrap();
    let mjcf = load_mjcf(&fixture("quadruped12.xml")).unwrap();
    let names = |m: &Model| {
        m.joints
            .iter()
            .map(|j| (j.name.clone(), j.kind, j.parent))
            .collect::<Vec<_>>()
    };
    assert_eq!(names(&urdf), names(&mjcf));
    assert_eq!(mjcf.joints[0].kind, JointKind::FreeFlyer);
    assert_eq!((mjcf.nq(), mjcf.nv()), (19, 18));
    let dynamics = |m: &Model, q: &[f64], v: &[f64], a: &[f64]| inverse_dynamics(m, q, v, a).unwrap();
    let mut worst: f64 = 0.0;
    for s in dyngen_model::sample::sample_states(&urdf, 5, 9) {
        let (a, b) = (dynamics(&urdf, &s.q, &s.v, &s.a), dynamics(&mjcf, &s.q, &s.v, &s.a));
        let scale = a.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        worst = worst.max(max_abs_diff(&a, &b) / scale);
    }
    eprintln!("quadruped12, URDF + free flyer against MJCF: relative difference {worst:.1e}");
    // MuJoCo prints 6 significant digits (the inertias' principal axes, the hips'
    // pitch); measured 1.8e-10.
    assert!(worst < 1e-8, "relative difference {worst:e}");
}

// ---------------------------------------------------------------------------------
// Armature, sites, inertia from geoms, compiler mass rules, joint `ref`, several
// joints in one body: against MuJoCo (`scripts/make_mjcf_armature_fixtures.py`).

fn reference_json(name: &str) -> Value {
    let text = std::fs::read_to_string(fixture(&format!("{name}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// MuJoCo's `qpos` as dyngen's `q`: ball-joint quaternions `w x y z` to `x y z w`.
fn dyngen_q(model: &Model, qpos: &[f64]) -> Vec<f64> {
    let mut q = qpos.to_vec();
    for j in 1..=model.dof() {
        if model.joints[j - 1].kind == JointKind::Spherical {
            q[model.q_offset(j)..model.q_offset(j) + 4].rotate_left(1);
        }
    }
    q
}

/// Largest differences from MuJoCo over the fixture's states: of the rigid-body mass
/// matrix (MuJoCo's with `dof_armature` zeroed), of `M + diag(Ia)` (Ia the nominal
/// rotor inertias) from MuJoCo's `qM`, and of the bias forces.
fn armature_against_mujoco(name: &str) -> [f64; 3] {
    let model = load_mjcf(&fixture(&format!("{name}.xml"))).unwrap();
    let reference = reference_json(name);
    let joints: Vec<&str> = reference["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let ours: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(ours, joints, "{name}: joint order");
    let nv = model.nv();
    assert_eq!(nv as u64, reference["nv"].as_u64().unwrap());
    let ia: Vec<f64> = dyngen_model::joint_params::nominal_joint_params(&model)
        .chunks(4)
        .map(|p| p[0])
        .collect();
    assert_eq!(
        ia,
        numbers(&reference["armature"]),
        "{name}: Ia is MuJoCo's dof_armature"
    );
    let (mut dr, mut dm, mut db) = (0.0f64, 0.0f64, 0.0f64);
    for s in reference["samples"].as_array().unwrap() {
        let (q, v) = (numbers(&s["q"]), numbers(&s["v"]));
        assert_eq!(q, dyngen_q(&model, &numbers(&s["mujoco_qpos"])));
        let (m, bias) = dynamics(&model, &q, &v);
        let rigid: Vec<f64> = m.iter().flatten().copied().collect();
        let with_rotors: Vec<f64> = (0..nv * nv)
            .map(|k| rigid[k] + if k / nv == k % nv { ia[k / nv] } else { 0.0 })
            .collect();
        dr = dr.max(max_abs_diff(&rigid, &numbers(&s["M_rigid"])));
        dm = dm.max(max_abs_diff(&with_rotors, &numbers(&s["M"])));
        db = db.max(max_abs_diff(&bias, &numbers(&s["bias"])));
    }
    eprintln!(
        "{name}: |M - M_rigid_mujoco| <= {dr:.2e}, |M + diag(Ia) - qM| <= {dm:.2e}, |bias - qfrc_bias| <= {db:.2e}"
    );
    [dr, dm, db]
}

/// Joint armature is the rotor inertia `Ia`: `M + diag(Ia)` is MuJoCo's `qM` on a
/// hinge, slide and ball chain with armature from classes and joints.
#[test]
fn mass_matrix_with_armature_equals_mujocos_qm() {
    let [dr, dm, db] = armature_against_mujoco("armature");
    assert!(
        dr <= 1e-12 && dm <= 1e-12 && db <= 1e-11,
        "M_rigid {dr:e}, M {dm:e}, bias {db:e}"
    );
    // And the armature is in it: without it the difference is the armature.
    let model = load_mjcf(&fixture("armature.xml")).unwrap();
    let s = &reference_json("armature")["samples"][1];
    let (m, _) = dynamics(&model, &numbers(&s["q"]), &numbers(&s["v"]));
    let qm = numbers(&s["M"]);
    assert!((qm[8] - m[1][1] - 0.35).abs() < 1e-12);
}

/// Joint `ref` (on hinges in degrees and a slide, with joint `pos`) and several joints
/// in one body (a hinge, a slide and a ball; two hinges): dyngen's q is MuJoCo's qpos
/// and the dynamics are MuJoCo's, with armature.
#[test]
fn joint_ref_and_several_joints_in_a_body_are_mujocos() {
    let [dr, dm, db] = armature_against_mujoco("ref");
    assert!(
        dr <= 1e-12 && dm <= 1e-12 && db <= 1e-11,
        "M_rigid {dr:e}, M {dm:e}, bias {db:e}"
    );
    let model = load_mjcf(&fixture("ref.xml")).unwrap();
    let names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(
        names,
        ["a", "b", "c", "multi (m1)", "multi (m2)", "multi", "pair (p1)", "pair"]
    );
}

/// World pose of every body at `q` (index 0 the base), by composing joint origins and
/// joint motions.
fn body_poses(model: &Model, q: &[f64]) -> Vec<dyngen_model::Placement> {
    use dyngen_model::math::{scale, IDENTITY};
    use dyngen_model::Placement;
    let mut poses = vec![Placement::IDENTITY];
    for j in 1..=model.dof() {
        let joint = &model.joints[j - 1];
        let qa = model.q_offset(j);
        let motion = match joint.kind {
            JointKind::Revolute | JointKind::Continuous => {
                let [x, y, z] = joint.axis;
                let (s, c) = q[qa].sin_cos();
                let t = 1.0 - c;
                Placement {
                    rotation: [
                        [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
                        [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
                        [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
                    ],
                    translation: [0.0; 3],
                }
            }
            JointKind::Prismatic => Placement {
                rotation: IDENTITY,
                translation: scale(q[qa], &joint.axis),
            },
            JointKind::Spherical => Placement {
                rotation: dyngen_model::regressor::quaternion_xyzw(&q[qa..qa + 4]),
                translation: [0.0; 3],
            },
            other => panic!("{other:?} not in these fixtures"),
        };
        let pose = poses[joint.parent].compose(&joint.origin).compose(&motion);
        poses.push(pose);
    }
    poses
}

/// Named sites are frames of their body, placed as MuJoCo places them (`site_xpos`,
/// `site_xmat` at `qpos0`), in rotated bodies, bodies moved by their joint `pos` and
/// `ref`, and a body with two joints; an unnamed site is no frame.
#[test]
fn sites_are_frames_where_mujoco_puts_them() {
    let mut worst = 0.0f64;
    for (name, sites) in [("armature", 3), ("ref", 1)] {
        let model = load_mjcf(&fixture(&format!("{name}.xml"))).unwrap();
        let reference = reference_json(name);
        let q = dyngen_q(&model, &numbers(&reference["qpos0"]));
        let poses = body_poses(&model, &q);
        let expected = reference["sites"].as_object().unwrap();
        assert_eq!(expected.len(), sites);
        for (site, want) in expected {
            let frame = model.frames.iter().find(|f| f.name == *site).unwrap();
            let pose = poses[frame.body].compose(&frame.placement);
            worst = worst.max(max_abs_diff(&pose.translation, &numbers(&want["pos"])));
            worst = worst.max(max_abs_diff(&flat3(&pose.rotation), &numbers(&want["rotation"])));
        }
        // Bodies, intermediate links of multi-joint bodies and named sites are the frames.
        assert_eq!(model.frames.len(), 1 + model.dof() + sites, "{name}");
    }
    eprintln!("sites: |pose - MuJoCo's| <= {worst:.2e}");
    assert!(worst <= 1e-14, "{worst:e}");
}

/// Each body's inertial as the MJCF reader gives it (in the link frame, which is the
/// body frame when joints have no `pos`) against MuJoCo's compiled `body_mass`,
/// `body_ipos` and `body_iquat`·diag(`body_inertia`): the largest difference in mass,
/// centre of mass and tensor.
fn bodies_against_mujoco(name: &str) -> [f64; 3] {
    use dyngen_model::math::{mat_mul, quaternion_to_matrix, transpose};
    let text = std::fs::read_to_string(fixture(&format!("{name}.xml"))).unwrap();
    let desc = dyngen_model::mjcf::mjcf_description(&text).unwrap();
    let reference = reference_json(name);
    let (mut dm, mut dc, mut di) = (0.0f64, 0.0f64, 0.0f64);
    for (body, want) in reference["bodies"].as_object().unwrap() {
        let link = desc.links.iter().find(|l| l.name == *body).unwrap();
        let mass = want["mass"].as_f64().unwrap();
        let Some(i) = link.inertial else {
            assert_eq!(mass, 0.0, "{name}: {body}");
            continue;
        };
        let q = numbers(&want["iquat"]);
        let r = quaternion_to_matrix([q[0], q[1], q[2], q[3]]);
        let d = numbers(&want["inertia"]);
        let diag = [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]];
        let tensor = mat_mul(&mat_mul(&r, &diag), &transpose(&r));
        dm = dm.max((i.mass - mass).abs() / mass);
        dc = dc.max(max_abs_diff(&i.com, &numbers(&want["ipos"])));
        di = di.max(max_abs_diff(&flat3(&i.inertia), &flat3(&tensor)) / d[2].max(d[1]).max(d[0]));
    }
    eprintln!("{name} bodies: mass rel {dm:.2e}, com {dc:.2e}, inertia rel {di:.2e}");
    [dm, dc, di]
}

/// Inertia from geoms (every primitive, fromto, pos and orientation, density, mass,
/// classes, inertiagrouprange, balanceinertia on a written inertial) is MuJoCo's, and
/// so are the dynamics of the model built on it.
#[test]
fn inertia_from_geoms_is_mujocos() {
    let [dm, dc, di] = bodies_against_mujoco("geoms");
    assert!(
        dm <= 1e-14 && dc <= 1e-15 && di <= 1e-13,
        "mass {dm:e}, com {dc:e}, inertia {di:e}"
    );
    let [dr, dq, db] = armature_against_mujoco("geoms");
    assert!(
        dr <= 1e-12 && dq <= 1e-12 && db <= 1e-11,
        "M_rigid {dr:e}, M {dq:e}, bias {db:e}"
    );
}

/// `inertiafromgeom="true"` (a written inertial ignored), boundmass, boundinertia,
/// balanceinertia and settotalmass are MuJoCo's.
#[test]
fn compiler_mass_rules_are_mujocos() {
    let [dm, dc, di] = bodies_against_mujoco("compiler");
    assert!(
        dm <= 1e-14 && dc <= 1e-15 && di <= 1e-13,
        "mass {dm:e}, com {dc:e}, inertia {di:e}"
    );
    let [dr, dq, db] = armature_against_mujoco("compiler");
    assert!(
        dr <= 1e-12 && dq <= 1e-12 && db <= 1e-11,
        "M_rigid {dr:e}, M {dq:e}, bias {db:e}"
    );
    let total: f64 = reference_json("compiler")["bodies"]
        .as_object()
        .unwrap()
        .values()
        .map(|b| b["mass"].as_f64().unwrap())
        .sum();
    assert!((total - 7.5).abs() < 1e-12, "{total}");
}

/// Warnings (the model loads): each names its element and line.
fn warnings_of(text: &str) -> Vec<String> {
    parse_mjcf(text)
        .unwrap()
        .warnings
        .iter()
        .map(|w| w.warning_message())
        .collect()
}

/// Four bodies in a chain: hinges `j` (ref 30°) and `k` (ref 10°), a slide `s` (ref
/// 0.2) and a ball joint; `<equality>` holds `elements`, the first on line 18.
fn with_equality(elements: &[&str]) -> String {
    mjcf(&[
        "<body name=\"a\">",
        INERTIAL,
        "<joint name=\"j\" ref=\"30\"/>",
        "<body name=\"b\">",
        INERTIAL,
        "<joint name=\"k\" ref=\"10\" axis=\"0 1 0\"/>",
        "<body name=\"c\">",
        INERTIAL,
        "<joint name=\"s\" type=\"slide\" ref=\"0.2\" axis=\"1 0 0\"/>",
        "<body name=\"d\">",
        INERTIAL,
        "<joint name=\"ball\" type=\"ball\"/>",
        "</body></body></body></body>",
    ])
    .replace(
        "</mujoco>",
        &format!("<equality>\n{}\n</equality>\n</mujoco>", elements.join("\n")),
    )
}

/// A linear `<equality><joint>` makes joint1 follow joint2 as MuJoCo holds it:
/// `q1 - ref1 = c0 + c1 (q2 - ref2)`, `ref` in radians (converted from the file's
/// degrees), `polycoef` as written, its missing numbers MuJoCo's default `0 1 0 0 0`.
#[test]
fn linear_joint_couplings_are_mimic_joints() {
    let model = parse_mjcf(&with_equality(&[
        "<joint name=\"double\" joint1=\"k\" joint2=\"j\" polycoef=\"0.1 2\"/>",
        "<joint joint1=\"s\" joint2=\"j\" polycoef=\"-0.05 0.5 0 0 0\"/>",
    ]))
    .unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.nv(), 4, "j and the ball joint");
    let (j, k) = (30f64.to_radians(), 10f64.to_radians());
    let follower = |name: &str| model.joints.iter().find(|x| x.name == name).unwrap().mimic.unwrap();
    let m = follower("k");
    assert_eq!((m.leader, m.multiplier), (1, 2.0));
    assert!((m.offset - (k + 0.1 - 2.0 * j)).abs() < 1e-15, "{m:?}");
    let m = follower("s");
    assert_eq!((m.leader, m.multiplier), (1, 0.5));
    assert!((m.offset - (0.2 - 0.05 - 0.5 * j)).abs() < 1e-15, "{m:?}");
    // Without polycoef, joint1 moves as joint2 from the references: offset ref1 - ref2.
    let model = parse_mjcf(&with_equality(&["<joint joint1=\"k\" joint2=\"j\" polycoef=\"\"/>"])).unwrap();
    let m = model.joints[1].mimic.unwrap();
    assert_eq!((m.leader, m.multiplier), (1, 1.0));
    assert!((m.offset - (k - j)).abs() < 1e-15, "{m:?}");
}

/// What the model cannot hold is left out with a warning naming the element, its line
/// and why; an inactive constraint (MuJoCo starts with it off) is skipped silently.
#[test]
fn equality_constraints_not_in_the_model_are_warned_with_the_reason() {
    let mut text = with_equality(&[
        "<joint name=\"bend\" joint1=\"k\" joint2=\"j\" polycoef=\"0 1 0 0.3 -1\"/>",
        "<joint name=\"lock\" joint1=\"s\"/>",
        "<joint joint1=\"s\" polycoef=\"0.5\"/>",
        "<joint joint1=\"k\" joint2=\"j\" active=\"false\"/>",
        "<connect body1=\"a\" body2=\"c\" anchor=\"0 0 0\"/>",
        "<weld name=\"w\" body1=\"d\"/>",
        "<tendon tendon1=\"t\"/>",
        "<flex flex=\"f\"/>",
        "<weld body1=\"d\" active=\"false\"/>",
        "<joint joint1=\"k\" joint2=\"j\"/>",
        "<joint joint1=\"k\" joint2=\"s\"/>",
        "<joint joint1=\"j\" joint2=\"k\"/>",
    ]);
    text = text.replace(
        "</mujoco>",
        "<tendon>\n<fixed name=\"t\"><joint joint=\"j\" coef=\"1\"/></fixed>\n</tendon>\n</mujoco>",
    );
    let model = parse_mjcf(&text).unwrap();
    let w: Vec<String> = model.warnings.iter().map(|w| w.warning_message()).collect();
    let expected = [
        (
            18,
            "<equality> <joint name=\"bend\"> is left out: its polycoef has c3 = 0.3, c4 = -1, a nonlinear \
             coupling, and a follower moves linearly with its leader; joint `k` is left independent of `j` (only \
             c0 and c1 may be nonzero for it to follow: q1 = c1 q2 + offset)",
        ),
        (
            19,
            "<equality> <joint name=\"lock\"> is left out: without joint2 it locks joint `s` at q = ref + c0 = 0.2 m, \
             and the model has no locked joints: `s` is left free; to lock it, remove the <joint> from its body, \
             which then stays where the file places it (at q = ref)",
        ),
        (
            20,
            "<equality> <joint> is left out: without joint2 it locks joint `s` at q = ref + c0 = 0.7 m, and the model \
             has no locked joints: `s` is left free; to lock it, remove the <joint> from its body and place the \
             body as it is at q = 0.7 m (the file places it at q = ref = 0.2 m)",
        ),
        (
            22,
            "<equality> <connect> is left out: a connect constraint (a ball joint between two bodies outside the \
             tree: a closed kinematic loop) is not in the model",
        ),
        (
            23,
            "<equality> <weld name=\"w\"> is left out: a weld constraint (two bodies held in a fixed relative pose",
        ),
        (
            24,
            "<equality> <tendon> is left out: a tendon coupling is not in the model, which has no tendons",
        ),
        (
            25,
            "<equality> <flex> is left out: a flex constraint is not in the model, which has rigid bodies only",
        ),
        (
            28,
            "<equality> <joint> is left out: joint `k` already follows `j` (the coupling at line 27), and a joint \
             follows one joint at most; couple `j` and `s` instead if they move together",
        ),
        (
            29,
            "<equality> <joint> is left out: joint `k` already follows `j` through the couplings above, so this \
             one closes a cycle of couplings",
        ),
        (32, "<tendon> <fixed name=\"t\"> is left out: a tendon"),
    ];
    assert_eq!(w.len(), expected.len(), "{w:#?}");
    for (message, (line, says)) in w.iter().zip(expected) {
        assert!(
            message.starts_with(&format!("line {line}: robot: {says}")),
            "{message}\n{w:#?}"
        );
    }
    // The one coupling kept: k follows j, on line 27.
    let followers: Vec<(&str, usize)> = model
        .joints
        .iter()
        .filter_map(|x| x.mimic.map(|m| (x.name.as_str(), m.leader)))
        .collect();
    assert_eq!(followers, [("k", 1)]);
    // A hinge locked: its position in radians, whatever the file's unit.
    let w = warnings_of(&with_equality(&["<joint joint1=\"k\"/>"]));
    let at = format!("locks joint `k` at q = ref + c0 = {} rad,", 10f64.to_radians());
    assert!(w.len() == 1 && w[0].contains(&at), "{w:?}");
}

/// `active` from the element, else its class, else the class's ancestors.
#[test]
fn equality_active_comes_from_the_default_class() {
    let text = with_equality(&[
        "<joint joint1=\"k\" joint2=\"j\"/>",
        "<joint joint1=\"s\" joint2=\"j\" class=\"on\"/>",
        "<weld body1=\"d\"/>",
    ])
    .replace(
        "<worldbody>",
        "<default><equality active=\"false\"/><default class=\"on\"><equality active=\"true\"/></default></default>\n\
         <worldbody>",
    );
    let model = parse_mjcf(&text).unwrap();
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let followers: Vec<&str> = model
        .joints
        .iter()
        .filter(|x| x.mimic.is_some())
        .map(|x| x.name.as_str())
        .collect();
    assert_eq!(followers, ["s"]);
}

/// What MuJoCo refuses in `<equality><joint>` is refused, active or not, naming the
/// element and its line and saying what is valid.
#[test]
fn joint_couplings_mujoco_refuses_are_refused() {
    for (element, says) in [
        (
            "<joint joint1=\"nope\" joint2=\"j\"/>",
            "<equality> <joint>: joint1=\"nope\" names no joint of this model; name a hinge or slide joint (MuJoCo \
             refuses it too)",
        ),
        (
            "<joint name=\"c\" joint1=\"k\" joint2=\"ball\" active=\"false\"/>",
            "<equality> <joint name=\"c\">: joint2=\"ball\" is a ball joint; only hinge and slide joints can be \
             coupled (MuJoCo refuses it too)",
        ),
        (
            "<joint joint1=\"k\" joint2=\"k\"/>",
            "joint1 and joint2 both name `k`; a joint cannot follow itself",
        ),
        (
            "<joint joint2=\"k\"/>",
            "no `joint1`; name the joint that the coupling moves",
        ),
        (
            "<joint joint1=\"k\" joint2=\"j\" polycoef=\"0 1 0 0 0 0\"/>",
            "polycoef=\"0 1 0 0 0 0\" is not up to 5 finite numbers; give `c0 c1 c2 c3 c4` (default `0 1 0 0 0`",
        ),
        (
            "<joint joint1=\"k\" joint2=\"j\" polycoef=\"0 one\"/>",
            "is not up to 5 finite numbers",
        ),
        (
            "<connect body1=\"a\" anchor=\"0 0 0\" active=\"yes\"/>",
            "<equality> <connect>: active=\"yes\" is neither `true` nor `false`",
        ),
    ] {
        only_error(&with_equality(&[element]), Element::Robot, 18, says);
    }
    let kind = only_error(
        &with_equality(&["<joint joint1=\"k\" joint2=\"j\" class=\"nope\"/>"]),
        Element::Robot,
        18,
        "nope",
    );
    assert!(matches!(kind, ErrorKind::UnknownClass(_)), "{kind:?}");
}

#[test]
fn compiler_attributes_not_read_are_warned() {
    let text = mjcf(&["<body name=\"a\">", INERTIAL, "<joint name=\"j\"/>", "</body>"]).replace(
        "<worldbody>",
        "<compiler fusestatic=\"true\" newthing=\"3\"/>\n<worldbody>",
    );
    let w = warnings_of(&text);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("line 2: robot: <compiler newthing=\"3\"> is not read"),
        "{w:?}"
    );
    // Bad values are refused, naming the line.
    let bad = |attrs: &str, says: &str| {
        let text = mjcf(&["<body name=\"a\">", INERTIAL, "<joint name=\"j\"/>", "</body>"])
            .replace("<worldbody>", &format!("<compiler {attrs}/>\n<worldbody>"));
        only_error(&text, Element::Robot, 2, says);
    };
    bad(
        "inertiafromgeom=\"yes\"",
        "<compiler inertiafromgeom=\"yes\"> is not `true`, `false` or `auto`",
    );
    bad(
        "inertiagrouprange=\"0\"",
        "<compiler inertiagrouprange=\"0\"> is not two integers",
    );
    bad(
        "balanceinertia=\"1\"",
        "<compiler balanceinertia=\"1\"> is neither `true` nor `false`",
    );
    bad("boundmass=\"x\"", "<compiler boundmass=\"x\"> is not a number");
    bad(
        "coordinate=\"global\"",
        "<compiler coordinate=\"global\"> is not supported",
    );
}

/// A body whose inertia would come from geoms that cannot give one: named with its
/// line and what to do instead.
#[test]
fn geoms_that_cannot_give_an_inertia_are_refused() {
    let body = |geom: &str| mjcf(&["<body name=\"a\">", "<joint name=\"j\"/>", geom, "</body>"]);
    only_error(
        &body("<geom name=\"field\" type=\"sdf\" mesh=\"m\"/>"),
        Element::Link("a".into()),
        5,
        "geom `field` of type `sdf` would give the body its inertia (<compiler inertiafromgeom>), but the \
         inertia of a signed distance field is not computed here; give the body an <inertial>",
    );
    // A mesh's is (`tests/mjcf_mesh.rs`), from a <mesh> of <asset>.
    only_error(
        &body("<geom name=\"shell\" type=\"mesh\" mesh=\"m\"/>"),
        Element::Link("a".into()),
        5,
        "geom `shell` names mesh `m`, which no <mesh> in <asset> defines",
    );
    only_error(
        &body("<geom type=\"box\" size=\"0.1 0.1 0.1\" shellinertia=\"true\"/>"),
        Element::Link("a".into()),
        5,
        "<geom type=\"box\"> asks for shellinertia=\"true\", which is not supported yet",
    );
    only_error(
        &body("<geom type=\"capsule\" size=\"0.1\"/>"),
        Element::Link("a".into()),
        5,
        "<geom type=\"capsule\"> needs a positive size for its inertia (size=\"0.1 0 0\"); give its `size`",
    );
    only_error(
        &body("<geom type=\"sphere\" size=\"0.1\" fromto=\"0 0 0 0 0 1\"/>"),
        Element::Link("a".into()),
        5,
        "<geom type=\"sphere\"> has a `fromto`, which only a capsule, cylinder, box or ellipsoid may have",
    );
    // Not when the geom gives no mass, or the body has an <inertial>.
    parse_mjcf(&body("<geom type=\"mesh\" mesh=\"m\" mass=\"0\"/>")).unwrap();
    parse_mjcf(&body("<geom type=\"mesh\" mesh=\"m\" group=\"6\"/>")).unwrap();
    parse_mjcf(&mjcf(&[
        "<body name=\"a\">",
        "<joint name=\"j\"/>",
        INERTIAL,
        "<geom type=\"mesh\" mesh=\"m\"/>",
        "</body>",
    ]))
    .unwrap();
}

#[test]
fn fullinertia_with_an_orientation_is_refused() {
    for o in ["quat=\"1 0 0 0\"", "euler=\"0 0 10\""] {
        let text = mjcf(&[
            "<body name=\"a\">",
            "<joint name=\"j\"/>",
            &format!("<inertial mass=\"1\" fullinertia=\"0.1 0.1 0.1 0 0 0\" {o}/>"),
            "</body>",
        ]);
        let key = o.split('=').next().unwrap();
        only_error(
            &text,
            Element::Link("a".into()),
            5,
            &format!("<inertial> gives both `fullinertia` and an orientation (`{key}`), which MuJoCo refuses"),
        );
    }
}

/// MuJoCo's sites and bodies have separate names (the control suite names sites after
/// their bodies); dyngen's frames share the bodies' namespace: the site is left out
/// with a warning.
#[test]
fn a_site_named_as_a_body_is_left_out_with_a_warning() {
    let text = mjcf(&[
        "<body name=\"a\">",
        INERTIAL,
        "<joint name=\"j\"/>",
        "<body name=\"b\" pos=\"0 0 1\"><site name=\"a\"/><site name=\"s\"/></body>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let w = &model.warnings[0];
    assert_eq!((&w.element, w.line), (&Element::Link("a".into()), Some(6)));
    assert!(
        w.to_string().contains(
            "site `a` has the name of a body and is left out: sites become frames of the model, which share one \
             namespace with the bodies (MuJoCo's do not); rename the site to have its frame"
        ),
        "{w}"
    );
    let a = model.frames.iter().find(|f| f.name == "a").unwrap();
    assert_eq!(a.placement.translation, [0.0; 3], "the body's frame, not the site's");
    assert!(model.frames.iter().any(|f| f.name == "s"));
}

/// A site in a body with a joint `pos` and a rotation: its frame is in the link frame
/// (on the joint), so its translation loses the joint's `pos`; a site in
/// `<worldbody>` is a frame of the base.
#[test]
fn a_site_is_placed_in_its_link_frame() {
    let text = mjcf(&[
        "<site name=\"fixed\" pos=\"1 2 3\" zaxis=\"1 0 0\"/>",
        "<body name=\"a\" euler=\"0 0 90\">",
        INERTIAL,
        "<joint name=\"j\" pos=\"0.1 0 0\"/>",
        "<site name=\"s\" pos=\"0.3 0.2 0\" axisangle=\"0 0 1 90\"/>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    let s = model.frames.iter().find(|f| f.name == "s").unwrap();
    assert_eq!(s.body, 1);
    assert!(max_abs_diff(&s.placement.translation, &[0.2, 0.2, 0.0]) < 1e-15);
    assert!(
        max_abs_diff(
            &flat3(&s.placement.rotation),
            &[0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
        ) < 1e-15
    );
    let f = model.frames.iter().find(|f| f.name == "fixed").unwrap();
    assert_eq!((f.body, f.placement.translation), (0, [1.0, 2.0, 3.0]));
    assert!(
        max_abs_diff(
            &flat3(&f.placement.rotation),
            &[0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0]
        ) < 1e-15
    );
}

/// A body welded to the world does not enter the dynamics: its mesh geoms are no
/// error, unless `settotalmass` would count their mass.
#[test]
fn mesh_geoms_of_a_body_welded_to_the_world_are_no_error() {
    let text = mjcf(&[
        "<body name=\"base\">",
        "<geom type=\"mesh\" mesh=\"m\"/>",
        "<body name=\"a\">",
        INERTIAL,
        "<joint name=\"j\"/>",
        "</body>",
        "</body>",
    ]);
    let model = parse_mjcf(&text).unwrap();
    assert_eq!(model.bodies.len(), 1);
    let text = text.replace("<worldbody>", "<compiler settotalmass=\"3\"/>\n<worldbody>");
    only_error(
        &text,
        Element::Link("base".into()),
        4,
        "<compiler settotalmass> counts the mass of body `base`, whose geoms' inertia is not computed here",
    );
}

/// `<option><flag gravity="disable"/></option>` turns gravity off, as in MuJoCo (the
/// control suite's finger and fish).
#[test]
fn a_gravity_flag_disables_gravity() {
    let body = format!("<worldbody><body name=\"a\"><joint name=\"j\"/>{INERTIAL}</body></worldbody>");
    let with = |option: &str| format!("<mujoco model=\"t\">\n{option}\n{body}\n</mujoco>\n");
    let on = parse_mjcf(&with("<option gravity=\"0 0 -5\"><flag gravity=\"enable\"/></option>")).unwrap();
    assert_eq!(on.gravity, [0.0, 0.0, -5.0]);
    let off = parse_mjcf(&with(
        "<option gravity=\"0 0 -5\"><flag contact=\"disable\" gravity=\"disable\"/></option>",
    ))
    .unwrap();
    assert_eq!(off.gravity, [0.0; 3]);
    let e = errors(&with("<option><flag gravity=\"off\"/></option>"));
    assert_eq!(e.errors[0].line, Some(2), "{e}");
    assert!(
        e.to_string()
            .contains("<flag gravity=\"off\"> is neither `enable` nor `disable`"),
        "{e}"
    );
}
