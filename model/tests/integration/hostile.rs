//! Hostile input to the URDF and MJCF front ends: each answers with an error naming
//! the element and line and saying what would be valid, never a panic, a stack
//! overflow, a quadratic parse or a silently wrong model.
//!
//! The large inputs here finish in well under a second when the scan is linear; a
//! quadratic scan would take minutes on them, and so time the test run out.

use dyngen_model::{parse_mjcf, parse_urdf, Element, ErrorKind, ModelError, ModelErrors};

/// A valid one-joint URDF body (inside `<robot>`): links `a` and `b`, joint `j`.
const URDF_BODY: &str = r#"
  <link name="a"/>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
"#;

/// A valid one-joint MJCF worldbody content.
const MJCF_BODY: &str = r#"
    <body name="b"><joint name="j" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/></body>
"#;

fn urdf(inner: &str) -> String {
    format!("<robot name=\"r\">{URDF_BODY}{inner}</robot>\n")
}

fn mjcf(inner: &str) -> String {
    format!("<mujoco model=\"m\">\n  <worldbody>{MJCF_BODY}{inner}</worldbody>\n</mujoco>\n")
}

/// The single error of `result`, which must be an error.
fn only_error<T: std::fmt::Debug>(result: Result<T, ModelErrors>) -> ModelError {
    let errors = result.expect_err("should be refused").errors;
    assert_eq!(errors.len(), 1, "{errors:?}");
    errors.into_iter().next().unwrap()
}

/// The error's text, which must contain every needle.
fn says(e: &ModelError, needles: &[&str]) -> String {
    let text = e.to_string();
    for n in needles {
        assert!(text.contains(n), "`{n}` not in: {text}");
    }
    assert!(text.len() < 1_000, "a message of {} bytes", text.len());
    text
}

// ---------------------------------------------------------------------------------
// 1. A DOCTYPE cannot lift the nesting limit.

#[test]
fn doctype_cannot_lift_the_nesting_limit() {
    const LEVELS: usize = 14_000;
    let deep = format!("{}{}", "<a>".repeat(LEVELS), "</a>".repeat(LEVELS));
    // Closed DOCTYPEs are skipped whole, and the nesting after them counted.
    for doctype in [
        "<!DOCTYPE r [ ] >",
        "<!DOCTYPE robot>",
        "<!DOCTYPE r SYSTEM \"r.dtd\" [\n  %p;\n]>",
    ] {
        let lines = doctype.lines().count();
        let text = format!("{doctype}\n<robot name=\"r\">\n{deep}</robot>");
        let e = only_error(parse_urdf(&text));
        assert!(
            matches!(&e.kind, ErrorKind::TooDeep { tag } if tag == "a"),
            "{doctype}: {e}"
        );
        assert_eq!(e.line, Some(lines + 2), "{doctype}");
        let text = format!("{doctype}\n<mujoco>\n<worldbody>{deep}</worldbody></mujoco>");
        let e = only_error(parse_mjcf(&text));
        assert!(
            matches!(&e.kind, ErrorKind::TooDeep { tag } if tag == "a"),
            "{doctype}: {e}"
        );
    }
    // DOCTYPEs the scan cannot close are refused at their line, and no other
    // parser sees the text; so are those whose subset holds a `>`, where urdf-rs's
    // reader would end the DOCTYPE and read the deep elements hidden in it.
    let hidden = format!("<!DOCTYPE r [ <!-- {deep} --> ]>");
    let in_literal = format!("<!DOCTYPE r [ <!ENTITY e \"{deep}\"> ]>");
    for (doctype, line, needle) in [
        (
            "<!DOCTYPE r [ <!ENTITY e 'x'> ",
            3,
            "unexpected `<` in the <!DOCTYPE>'s internal subset",
        ),
        ("<!DOCTYPE r [ <!-- ", 2, "never closed"),
        ("<!DOCTYPE r '", 2, "never closed"),
        ("<!DOCTYPE r [ ] ] >", 2, "unexpected"),
        ("<!DOCTYPE r [ ] [ ] >", 2, "unexpected `[` after the internal subset"),
        ("<!DOCTYPE r [ <!ENTITY e 'x'> ]>", 2, "a `>` inside the <!DOCTYPE>"),
        (hidden.as_str(), 2, "a `>` inside the <!DOCTYPE>"),
        (in_literal.as_str(), 2, "a `>` inside the <!DOCTYPE>"),
    ] {
        let shown = &doctype[..doctype.len().min(30)];
        let text = format!("\n{doctype}\n<robot name=\"r\">\n{deep}</robot>");
        let e = only_error(parse_urdf(&text));
        assert_eq!((&e.element, e.line), (&Element::Robot, Some(line)), "{shown}: {e}");
        says(&e, &[needle]);
        let text = format!("\n{doctype}\n<mujoco><worldbody>{deep}</worldbody></mujoco>");
        let e = only_error(parse_mjcf(&text));
        assert_eq!(e.line, Some(line), "{shown}: {e}");
        says(&e, &[needle]);
    }
}

/// urdf-rs's XML reader ends a processing instruction at the first `>` after a `?`,
/// and would read the elements after it that the scan took for the instruction's
/// text. Such markup is refused, whatever it hides; a `<!-->` opens a comment for
/// both, and what it hides is not read.
#[test]
fn markup_read_differently_cannot_hide_deep_elements() {
    let deep = format!("{}{}", "<a>".repeat(14_000), "</a>".repeat(14_000));
    for (text, line, needle) in [
        (
            format!("<?pi ?x>\n{deep} ?>\n<robot name=\"r\"/>"),
            1,
            "a `>` inside a processing instruction",
        ),
        (
            format!("<robot name=\"r\">\n<?pi ?x> {deep} ?></robot>"),
            2,
            "a `>` inside a processing instruction",
        ),
        (
            format!("<robot name=\"r\">\n<!--> {deep} --></robot>"),
            1,
            "nothing moves",
        ),
        (
            format!("<robot name=\"r\">\n<!-- -- {deep} --></robot>"),
            2,
            "`--` inside a comment",
        ),
    ] {
        let e = only_error(parse_urdf(&text));
        assert_eq!(e.line, Some(line), "{e}");
        says(&e, &[needle]);
    }
}

// ---------------------------------------------------------------------------------
// 2. Large hostile inputs are read in linear time.

#[test]
fn a_run_of_ampersands_is_refused_at_its_line() {
    let amps = "&".repeat(2_000_000);
    let text = urdf(&format!("\n<link name=\"c\" note=\"{amps}\"/>"));
    let e = only_error(parse_urdf(&text));
    assert_eq!(e.line, Some(7));
    says(
        &e,
        &[
            "line 7",
            "attribute `note` of <link>",
            "write `&amp;` for a literal `&`",
        ],
    );
    let text = mjcf(&format!("\n<body name=\"c\" user=\"{amps}\"/>"));
    let e = only_error(parse_mjcf(&text));
    assert_eq!(e.line, Some(6));
    says(&e, &["attribute `user` of <body>", "`&amp;`"]);
    // In text too, and a run of unterminated references (`&a&a&a…`).
    let text = urdf(&format!("\n{}", "&lt".repeat(700_000)));
    says(&only_error(parse_urdf(&text)), &["line 7", "in text"]);
}

#[test]
fn many_references_and_comments_are_read_in_linear_time() {
    // Valid, large: 2,000,000 references in an attribute, 200,000 comments.
    // (urdf-rs's second XML reader takes no attribute value this long, so MJCF.)
    let refs = "&amp;&#38;&lt;&#x3C;".repeat(500_000);
    let comments = "<!-- c -->\n".repeat(200_000);
    let text = format!("<mujoco note=\"{refs}\">{comments}<worldbody>{MJCF_BODY}</worldbody></mujoco>");
    assert_eq!(parse_mjcf(&text).expect("valid").dof(), 1);
    let text = format!(
        "<robot name=\"r\" note=\"{}\">{comments}{URDF_BODY}</robot>",
        &refs[..20_000]
    );
    assert_eq!(parse_urdf(&text).expect("valid").dof(), 1);
    // 200,000 attributes on one element, one of them twice.
    let attrs: String = (0..200_000).map(|k| format!(" a{k}=\"{k}\"")).collect();
    let text = format!("<mujoco{attrs}><worldbody>{MJCF_BODY}</worldbody></mujoco>");
    assert_eq!(parse_mjcf(&text).expect("valid").dof(), 1);
    let twice = format!("<robot name=\"r\"{attrs} a199999=\"x\">{URDF_BODY}</robot>");
    says(
        &only_error(parse_urdf(&twice)),
        &["attribute `a199999` of <robot> is given twice"],
    );
}

#[test]
fn stray_declarations_are_refused_at_their_line() {
    let decls = "<!x>".repeat(800_000);
    for text in [format!("\n\n{decls}{}", urdf("")), urdf(&format!("\n\n{decls}"))] {
        let e = only_error(parse_urdf(&text));
        says(&e, &["`<!x` is not XML markup", "`<!--` starts a comment"]);
    }
    let e = only_error(parse_urdf(&format!("\n\n{decls}{}", urdf(""))));
    assert_eq!(e.line, Some(3));
    let e = only_error(parse_mjcf(&mjcf(&format!("\n{decls}"))));
    assert_eq!(e.line, Some(6));
    says(&e, &["`<!x` is not XML markup"]);
    // A DOCTYPE whose subset holds many parameter-entity references is read.
    let refs = "%p;\n".repeat(400_000);
    let text = format!("<!DOCTYPE robot [\n{refs}]>\n{}", urdf(""));
    assert_eq!(parse_urdf(&text).expect("valid").dof(), 1);
    let text = format!("<!DOCTYPE robot [\n{refs}<!x>]>\n{}", urdf(""));
    says(
        &only_error(parse_urdf(&text)),
        &["line 400002", "a `>` inside the <!DOCTYPE>"],
    );
}

// ---------------------------------------------------------------------------------
// 3. Line numbers: `\r\n`, `\r` and `\n` each end a line; NUL is refused.

#[test]
fn every_kind_of_line_end_counts_once() {
    for end in ["\n", "\r\n", "\r"] {
        let text = [
            "<robot name=\"r\">",
            "<link name=\"a\"/>",
            "<link name=\"b\"/>",
            "<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/>",
            "<axis xyz=\"0 0 1\"/>",
            "<origin xyz=\"0 0 oops\"/></joint>",
            "</robot>",
        ]
        .join(end);
        let e = only_error(parse_urdf(&text));
        assert_eq!(e.line, Some(6), "{end:?}: {e}");
        assert_eq!(e.element, Element::Joint("j".into()));
        let text = [
            "<mujoco>",
            "<worldbody>",
            "<body name=\"b\">",
            "<joint name=\"j\" type=\"hinge\" axis=\"0 0 oops\"/>",
            "</body></worldbody></mujoco>",
        ]
        .join(end);
        let e = parse_mjcf(&text).expect_err("a bad axis").errors.remove(0);
        assert_eq!(e.line, Some(4), "{end:?}: {e}");
    }
}

#[test]
fn nul_and_other_forbidden_characters_are_refused_at_their_line() {
    for (bad, what) in [("\0", "U+0000 (NUL)"), ("\u{1b}", "U+001B"), ("\u{ffff}", "U+FFFF")] {
        let text = urdf(&format!("\r\n<!-- {bad} -->"));
        let e = only_error(parse_urdf(&text));
        assert_eq!(e.line, Some(7), "{what}");
        says(&e, &[what, "not allowed in XML"]);
        let text = mjcf(&format!("\r<body name=\"c{bad}\"/>"));
        let e = only_error(parse_mjcf(&text));
        assert_eq!(e.line, Some(6), "{what}");
        says(&e, &[what]);
    }
    // As a character reference too.
    let text = urdf("\n<link name=\"c&#0;\"/>");
    assert_eq!(only_error(parse_urdf(&text)).line, Some(7));
}

// ---------------------------------------------------------------------------------
// 4. URDF 1.1 `quat_xyzw`.

fn quat_urdf(version: &str, origin: &str) -> String {
    format!(
        r#"<robot name="r" version="{version}">
  <link name="a"/>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    {origin}</joint>
</robot>"#
    )
}

#[test]
fn a_quaternion_that_is_no_rotation_is_refused() {
    for (quat, needle) in [
        ("nan 0 0 1", "not a finite number"),
        ("inf 0 0 1", "not a finite number"),
        ("1e-200 0 0 0", "norm 1e-200"),
        ("1e300 1e300 0 0", "norm 1.4142135623730952e300"),
        ("0 0 0 0", "norm 0e0"),
        ("0 0 1", "not four numbers"),
        ("0 0 0 1 0", "not four numbers"),
        ("a b c d", "not four numbers"),
    ] {
        let text = quat_urdf("1.1", &format!("<origin quat_xyzw=\"{quat}\"/>"));
        let e = only_error(parse_urdf(&text));
        assert_eq!((&e.element, e.line), (&Element::Joint("j".into()), Some(6)), "{quat}");
        says(&e, &[needle, "unit quaternion x y z w"]);
    }
    // In an inertial origin, it names the link.
    let text = r#"<robot name="r" version="1.1"><link name="a"/>
  <link name="b"><inertial><origin quat_xyzw="nan 0 0 1"/><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>"#;
    let e = only_error(parse_urdf(text));
    assert_eq!((&e.element, e.line), (&Element::Link("b".into()), Some(2)));
    // With rpy too, or in a URDF 1.0 file that would ignore it.
    let both = quat_urdf("1.1", "<origin rpy=\"0 0 0\" quat_xyzw=\"0 0 0 1\"/>");
    says(&only_error(parse_urdf(&both)), &["line 6", "also gives rpy"]);
    for version in ["1.0", "", "x"] {
        let old = quat_urdf(version, "<origin quat_xyzw=\"0 0 0.7071068 0.7071068\"/>");
        says(
            &only_error(parse_urdf(&old)),
            &["line 6", "URDF 1.0", "version=\"1.1\""],
        );
    }
}

#[test]
fn a_valid_quaternion_is_applied() {
    // 90° about z, not normalised: normalised, as urdfdom does.
    let text = quat_urdf("1.1", "<origin xyz=\"1 2 3\" quat_xyzw=\"0 0 2 2\"/>");
    let model = parse_urdf(&text).expect("valid");
    let origin = &model.joints[0].origin;
    let rz = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    for r in 0..3 {
        for c in 0..3 {
            assert!(
                (origin.rotation[r][c] - rz[r][c]).abs() < 1e-12,
                "{:?}",
                origin.rotation
            );
        }
    }
    assert_eq!(origin.translation, [1.0, 2.0, 3.0]);
}

// ---------------------------------------------------------------------------------
// 5. Document structure.

#[test]
fn the_document_element_must_be_the_format_s() {
    let text = format!("<?xml version=\"1.0\"?>\n<model name=\"r\">{URDF_BODY}</model>");
    let e = only_error(parse_urdf(&text));
    assert_eq!((&e.element, e.line), (&Element::Robot, Some(2)));
    says(&e, &["document element is <model>, not <robot>"]);
    let text = format!("\n<robot name=\"r\">{URDF_BODY}</robot>");
    let e = only_error(parse_mjcf(&text));
    assert_eq!(e.line, Some(2));
    says(&e, &["<robot>, not <mujoco>"]);
}

#[test]
fn a_second_document_element_is_refused() {
    let text = format!("{}\n<robot name=\"s\"/>", urdf(""));
    let e = only_error(parse_urdf(&text));
    assert_eq!(e.line, Some(8));
    says(&e, &["second document element <robot> after <robot> (line 1)"]);
    let text = format!("{}<link name=\"x\"/>", urdf(""));
    says(
        &only_error(parse_urdf(&text)),
        &["line 7", "second document element <link>"],
    );
    let text = format!("{}\n\n<mujoco/>", mjcf(""));
    let e = only_error(parse_mjcf(&text));
    assert_eq!(e.line, Some(9));
    says(&e, &["second document element <mujoco>"]);
    // Nor text after it.
    let text = format!("{}junk", urdf(""));
    says(
        &only_error(parse_urdf(&text)),
        &["line 7", "text after the document element <robot>"],
    );
}

#[test]
fn links_and_joints_need_a_name() {
    let text = urdf("\n  <link name=\"\"/>");
    let e = only_error(parse_urdf(&text));
    assert_eq!((&e.element, e.line), (&Element::Link(String::new()), Some(7)));
    says(&e, &["has an empty name", "name=\"link_1\""]);
    let text = urdf("\n  <joint type=\"fixed\"><parent link=\"a\"/><child link=\"x\"/></joint>");
    let e = parse_urdf(&text).expect_err("no name").errors.remove(0);
    assert_eq!(e.line, Some(7));
    says(&e, &["has no name"]);
    let text = urdf("\n  <joint name=\" \" type=\"fixed\"><parent link=\"a\"/><child link=\"x\"/></joint>");
    assert_eq!(parse_urdf(&text).expect_err("blank name").errors[0].line, Some(7));
}

// ---------------------------------------------------------------------------------
// 6, 7. Names: printable, one line, at most 1,024 characters.

#[test]
fn names_with_control_or_direction_characters_are_refused() {
    for bad in ["a&#13;b", "a&#10;b", "a\u{202e}b", "a\u{2067}b", "a\u{200f}", "a&#x85;"] {
        let text = urdf(&format!("\n  <link name=\"{bad}\"/>"));
        let e = only_error(parse_urdf(&text));
        assert_eq!(e.line, Some(7), "{bad}");
        says(&e, &["the name of <link", "a name must be printable text on one line"]);
        let text = mjcf(&format!("\n<body name=\"{bad}\"/>"));
        let e = only_error(parse_mjcf(&text));
        assert_eq!(e.line, Some(6), "{bad}");
    }
    let text = urdf("").replace("<robot name=\"r\">", "<robot name=\"r\u{202e}\">");
    says(&only_error(parse_urdf(&text)), &["line 1", "text-direction control"]);
}

#[test]
fn very_long_names_are_refused_with_a_short_message() {
    let long = "n".repeat(65_536);
    let text = urdf(&format!("\n  <link name=\"{long}\"/>"));
    let e = only_error(parse_urdf(&text));
    assert_eq!(e.line, Some(7));
    says(&e, &["has 65536 characters, more than the 1024 a name may have"]);
    let text = mjcf(&format!("\n<body name=\"{long}\"/>"));
    says(&only_error(parse_mjcf(&text)), &["line 6", "65536 characters"]);
    // 1,024 is fine.
    let ok = "é".repeat(1024);
    let text = urdf(&format!(
        "\n  <link name=\"{ok}\"/><joint name=\"k\" type=\"fixed\"><parent link=\"b\"/><child link=\"{ok}\"/></joint>"
    ));
    parse_urdf(&text).expect("a name of 1,024 characters");
}

// ---------------------------------------------------------------------------------
// 8. A byte order mark.

#[test]
fn a_byte_order_mark_is_skipped() {
    let text = format!("\u{feff}<?xml version=\"1.0\"?>\n{}", urdf(""));
    assert_eq!(parse_urdf(&text).expect("URDF with a BOM").dof(), 1);
    let text = format!("\u{feff}{}", mjcf(""));
    assert_eq!(parse_mjcf(&text).expect("MJCF with a BOM").dof(), 1);
    // Lines still count from the first.
    let text = format!("\u{feff}\n{}", urdf("\n<link name=\"\"/>"));
    assert_eq!(only_error(parse_urdf(&text)).line, Some(8));
}

// ---------------------------------------------------------------------------------
// The stricter scan still reads every description in the repository.

#[test]
fn every_shipped_description_still_scans() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut dirs = vec![
        root.join("robots"),
        root.join("tests/fixtures"),
        root.join("identify/tests"),
    ];
    let mut scanned = 0;
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "urdf" || e == "xml") {
                let text = std::fs::read_to_string(&path).unwrap();
                if let Err(e) = dyngen_model::xml::scan(&text) {
                    panic!("{}:{}: {}", path.display(), e.line, e.message);
                }
                scanned += 1;
            }
        }
    }
    assert!(scanned >= 20, "only {scanned} descriptions found");
}
