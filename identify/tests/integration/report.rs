//! Report outputs: the parameter JSON round-trips exactly and never overwrites
//! silently; the rewritten URDF parses back to the identified inertials with every
//! other byte kept; the SVG report has one pair of curves per joint and its labels.

use std::path::PathBuf;

use dyngen_identify::report::{
    rewrite_urdf_inertials, rewrite_urdf_inertials_with, MergedLinks, ParamStatus, ParameterReport, Parameterisation,
    ReportError,
};
use dyngen_identify::{self as identify, faer::Mat, Status};
use dyngen_model::{parse_urdf, Inertial};

const UR5: &str = include_str!("../../../robots/ur5/ur5.urdf");
const GRIPPER_ARM: &str = include_str!("../../../robots/gripper_arm/gripper_arm.urdf");

/// A fresh path in cargo's per-test scratch directory (removed first if present).
fn scratch(name: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_file(&path);
    path
}

/// Columns 1 and 2 equal: `x1 + x2` identifiable, `x1`, `x2` alone not; column 3 zero.
fn rank_deficient_estimate() -> identify::Estimate {
    let a = Mat::from_fn(12, 4, |i, j| match j {
        0 => 1.0,
        3 => 0.0,
        _ => (i as f64).sin(),
    });
    let y: Vec<f64> = (0..12)
        .map(|i| 1.0 + 3.0 * (i as f64).sin() + 1e-3 * (7.0 * i as f64).cos())
        .collect();
    identify::ols(a.as_ref(), &y).unwrap()
}

#[test]
fn json_round_trips_and_marks_unidentifiable_parameters() {
    let est = rank_deficient_estimate();
    assert_eq!(est.params[1].status, Status::InCombination);
    let report = ParameterReport::from_estimate("toy", Parameterisation::Standard, &est, &["m", "a", "b", "c"], &[]);
    assert_eq!(report.parameters[0].status, ParamStatus::Identified);
    assert!(report.parameters[0].sigma.is_some() && report.parameters[0].sigma_percent.is_some());
    assert_eq!(report.parameters[1].status, ParamStatus::InCombination);
    assert_eq!(report.parameters[1].value, None);
    assert_eq!(report.parameters[3].status, ParamStatus::NoEffect);
    assert_eq!(report.combinations.len(), 1);
    assert_eq!(report.combinations[0].expression, "a + b");
    assert!((report.combinations[0].value - 3.0).abs() < 1e-2);

    let text = report.to_json().unwrap();
    assert!(text.contains("\"status\": \"in_combination\""), "{text}");
    assert!(text.contains("\"value\": null"), "{text}");
    assert!(text.contains("\"parameterisation\": \"standard\""), "{text}");
    assert_eq!(ParameterReport::from_json(&text).unwrap(), report);

    let path = scratch("report_params.json");
    report.write(&path, false).unwrap();
    assert_eq!(ParameterReport::read(&path).unwrap(), report);
    // Never silently overwritten; with the flag it is.
    let err = report.write(&path, false).unwrap_err();
    assert!(matches!(err, ReportError::Exists { .. }), "{err}");
    report.write(&path, true).unwrap();

    // Wrong schema and unknown fields are errors with a position.
    let bad = text.replace("dyngen-parameters/1", "other/2");
    assert!(matches!(
        ParameterReport::from_json(&bad),
        Err(ReportError::Json { .. })
    ));
    let bad = text.replacen("\"rank\"", "\"rnak\"", 1);
    match ParameterReport::from_json(&bad) {
        Err(ReportError::Json { line, .. }) => assert!(line > 1),
        other => panic!("{other:?}"),
    }
}

/// `inertial` changed in every number, with a full inertia tensor.
fn perturbed(i: &Inertial, k: usize) -> Inertial {
    let f = 1.0 + 0.1 * (k as f64 + 1.0);
    let mut inertia = i.inertia;
    for r in 0..3 {
        inertia[r][r] = inertia[r][r] * f + 1e-3;
    }
    for (r, c) in [(0, 1), (0, 2), (1, 2)] {
        let off = 1e-5 * (k + r + c) as f64 - 2e-5;
        inertia[r][c] = off;
        inertia[c][r] = off;
    }
    Inertial {
        mass: i.mass * f,
        com: [i.com[0] + 0.01, i.com[1] - 0.02 * f, i.com[2] + 1.0 / 3.0],
        inertia,
    }
}

fn assert_inertial_eq(got: &Inertial, want: &Inertial, link: &str) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    let ok = close(got.mass, want.mass)
        && (0..3).all(|r| close(got.com[r], want.com[r]))
        && (0..3).all(|r| (0..3).all(|c| close(got.inertia[r][c], want.inertia[r][c])));
    assert!(ok, "{link}: got {got:?}, want {want:?}");
}

/// The text with every `<inertial>` element removed together with its line.
fn without_inertials(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find("<inertial>") {
        let line_start = rest[..start].rfind('\n').map_or(0, |k| k + 1);
        let end = rest[start..].find("</inertial>").unwrap() + start + "</inertial>".len();
        let end = if rest[end..].starts_with('\n') { end + 1 } else { end };
        let cut = if rest[line_start..start].trim().is_empty() {
            line_start
        } else {
            start
        };
        out.push_str(&rest[..cut]);
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// Rewrites every moving body of `text` with a perturbed inertial (lumping merged
/// links) and checks the result.
fn check_round_trip(text: &str, lumped: &str, merged: &[&str]) {
    let model = parse_urdf(text).unwrap();
    let updates: Vec<(String, Inertial)> = model
        .bodies
        .iter()
        .enumerate()
        .map(|(k, b)| (b.name.clone(), perturbed(&b.inertial, k)))
        .collect();

    // A body that lumped fixed-joint links is refused by default, naming them.
    match rewrite_urdf_inertials(text, &updates) {
        Err(ReportError::MergedLinks { link, line, merged: m }) => {
            assert_eq!(link, lumped);
            assert_eq!(m, merged);
            let expected = 1 + text
                .lines()
                .position(|l| l.contains(&format!("name=\"{lumped}\"")))
                .unwrap();
            assert_eq!(line, expected);
        }
        other => panic!("{other:?}"),
    }

    let out = rewrite_urdf_inertials_with(text, &updates, MergedLinks::Lump).unwrap();
    let back = parse_urdf(&out).unwrap();
    assert_eq!(back.dof(), model.dof());
    for (name, want) in &updates {
        let body = back.bodies.iter().find(|b| &b.name == name).unwrap();
        assert_inertial_eq(&body.inertial, want, name);
    }
    // Kinematics and everything else are untouched.
    assert_eq!(back.joints, model.joints);
    assert_eq!(without_inertials(&out), without_inertials(text));
    // Merged links no longer carry mass: their <inertial> elements are gone.
    let link_text = |doc: &str, name: &str| -> Option<String> {
        let k = doc.find(&format!("<link name=\"{name}\">"))?;
        Some(doc[k..].split("</link>").next().unwrap().to_string())
    };
    for m in merged {
        if let Some(l) = link_text(&out, m) {
            assert!(!l.contains("<inertial>"), "{m} keeps its inertial");
        }
    }
    let body = back.bodies.iter().find(|b| b.name == lumped).unwrap();
    assert_eq!(body.merged, merged);
    // The fixed base was not updated: its element is byte-identical.
    assert_eq!(link_text(&out, "base_link"), link_text(text, "base_link"));
    assert!(link_text(text, "base_link").unwrap().contains("<inertial>"));
}

#[test]
fn ur5_rewrite_keeps_every_other_byte() {
    check_round_trip(UR5, "wrist_3_link", &["tool0", "ee_link"]);
}

#[test]
fn gripper_arm_rewrite_keeps_every_other_byte() {
    check_round_trip(GRIPPER_ARM, "wrist_link", &["palm_link"]);
}

#[test]
fn urdf_rewrite_errors_name_the_link() {
    let i = Inertial::principal(1.0, [0.1, 0.2, 0.25]);
    let err = |name: &str| rewrite_urdf_inertials(UR5, &[(name, i)]).unwrap_err();
    assert_eq!(err("nope"), ReportError::LinkNotFound { link: "nope".into() });
    match err("tool0") {
        ReportError::NotABody { link, body, line } => {
            assert_eq!((link.as_str(), body.as_deref()), ("tool0", Some("wrist_3_link")));
            assert!(UR5.lines().nth(line - 1).unwrap().contains("name=\"tool0\""));
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(err("base_link"), ReportError::NotABody { body: None, .. }));
    let twice = rewrite_urdf_inertials(UR5, &[("shoulder_link", i), ("shoulder_link", i)]).unwrap_err();
    assert!(matches!(twice, ReportError::DuplicateUpdate { .. }));
    let bad = Inertial { mass: f64::NAN, ..i };
    assert!(matches!(
        rewrite_urdf_inertials(UR5, &[("shoulder_link", bad)]),
        Err(ReportError::InvalidInertial { .. })
    ));
    // The message says what to do.
    let msg = rewrite_urdf_inertials(UR5, &[("wrist_3_link", i)])
        .unwrap_err()
        .to_string();
    assert!(msg.contains("tool0") && msg.contains("MergedLinks::Lump"), "{msg}");
}

#[test]
fn missing_and_self_closing_links_get_an_inertial() {
    let text = "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n\t<link name=\"base\"/>\n\t<!-- keep -->\n\t<link name=\"a\">\n\t\t<visual><geometry><box size=\"1 1 1\"/></geometry></visual>\n\t</link>\n\t<joint name=\"j1\" type=\"continuous\">\n\t\t<parent link=\"base\"/>\n\t\t<child link=\"a\"/>\n\t\t<axis xyz=\"0 0 1\"/>\n\t</joint>\n\t<link  name=\"b\"  />\n\t<joint name=\"j2\" type=\"continuous\">\n\t\t<parent link=\"a\"/>\n\t\t<child link=\"b\"/>\n\t\t<axis xyz=\"1 0 0\"/>\n\t</joint>\n</robot>\n";
    let ia = Inertial {
        mass: 2.5,
        com: [0.1, -0.2, 1e-7],
        inertia: [[0.3, 0.01, -0.02], [0.01, 0.4, 0.03], [-0.02, 0.03, 0.5]],
    };
    let ib = Inertial::principal(0.5, [0.01, 0.02, 0.025]);
    let out = rewrite_urdf_inertials(text, &[("a", ia), ("b", ib)]).unwrap();
    let expected = text
        .replace(
            "<link name=\"a\">\n",
            "<link name=\"a\">\n\t\t<inertial>\n\t\t\t<origin xyz=\"0.1 -0.2 1e-7\" rpy=\"0 0 0\"/>\n\t\t\t<mass value=\"2.5\"/>\n\t\t\t<inertia ixx=\"0.3\" ixy=\"0.01\" ixz=\"-0.02\" iyy=\"0.4\" iyz=\"0.03\" izz=\"0.5\"/>\n\t\t</inertial>\n",
        )
        .replace(
            "<link  name=\"b\"  />",
            "<link  name=\"b\">\n\t\t<inertial>\n\t\t\t<origin xyz=\"0.0 0.0 0.0\" rpy=\"0 0 0\"/>\n\t\t\t<mass value=\"0.5\"/>\n\t\t\t<inertia ixx=\"0.01\" ixy=\"0.0\" ixz=\"0.0\" iyy=\"0.02\" iyz=\"0.0\" izz=\"0.025\"/>\n\t\t</inertial>\n\t</link>",
        );
    assert_eq!(out, expected);
    let back = parse_urdf(&out).unwrap();
    assert_inertial_eq(&back.bodies[0].inertial, &ia, "a");
    assert_inertial_eq(&back.bodies[1].inertial, &ib, "b");
}
