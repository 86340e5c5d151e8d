//! Damaged and unusual inputs through the command line: each is refused with a
//! message naming the culprit, never a crash or a silent wrong result.

use crate::common;
use crate::common::{assert_exit, assert_ok, pendulum, run, stderr, temp_dir};

#[test]
fn deeply_nested_xml_is_refused_not_a_stack_overflow() {
    let dir = temp_dir("dyngen-cli", "deep-xml");
    let path = dir.join("deep.urdf");
    let depth = 20_000;
    let text = format!(
        "<robot name=\"r\">\n<link name=\"base\">{}{}</link>\n</robot>\n",
        "<a>".repeat(depth),
        "</a>".repeat(depth)
    );
    std::fs::write(&path, text).unwrap();
    assert_exit(
        &run!("info", path),
        3,
        "deep.urdf:2: robot: <a> is nested more than 256 elements deep",
    );
}

#[test]
fn huge_and_misseparated_csv_values_are_named() {
    let dir = temp_dir("dyngen-cli", "csv-values");
    let urdf = pendulum(&dir, "pendulum.urdf", "1");
    let rows: String = (0..40)
        .map(|k| {
            let t = 0.01 * k as f64;
            let q = if k == 17 {
                "1e308".to_string()
            } else {
                (0.3 * t).sin().to_string()
            };
            format!("{t},{q},0.1\n")
        })
        .collect();
    let csv = dir.join("huge.csv");
    std::fs::write(&csv, format!("t,q1,tau1\n{rows}")).unwrap();
    assert_exit(&run!("identify", urdf, csv), 3, "line 19, column `q1`: 1e308");

    let csv = dir.join("semicolons.csv");
    std::fs::write(
        &csv,
        format!("t;q1;tau1\n{}", rows.replace("1e308", "0").replace(',', ";")),
    )
    .unwrap();
    assert_exit(
        &run!("identify", urdf, csv),
        3,
        "line 1: no `,` separates the fields, but a `;` splits the line into 3: the file looks semicolon-separated",
    );
}

#[test]
fn cad_rounded_inertia_is_a_warning_and_strict_refuses_it() {
    let dir = temp_dir("dyngen-cli", "cad-rounding");
    let path = dir.join("plate.urdf");
    // A flat plate (J3 = J1 + J2) whose moments were rounded to four digits:
    // 3e-10 over the sum, 1.3e-4 of the largest moment.
    std::fs::write(
        &path,
        r#"<robot name="plate">
  <link name="base"/>
  <link name="plate"><inertial><mass value="0.01"/>
    <inertia ixx="9.137e-7" iyy="1.386e-6" izz="2.300e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="plate"/><axis xyz="1 0 0"/></joint>
</robot>
"#,
    )
    .unwrap();
    let o = run!("info", path);
    assert_ok(&o);
    let err = stderr(&o);
    assert!(
        err.contains("warning: ")
            && err.contains("plate.urdf:3: link `plate`: principal moments")
            && err.contains("accepted as written: within the relative tolerance of 1e-3 for CAD rounding"),
        "{err}"
    );
    assert_exit(
        &run!("info", path, "--strict"),
        3,
        "plate.urdf:3: link `plate`: principal moments",
    );
}

#[test]
fn a_non_physical_inertia_loads_as_written_balanced_or_refused() {
    let dir = temp_dir("dyngen-cli", "non-physical");
    let path = dir.join("rod.urdf");
    // J3 = 3 > J1 + J2 = 2: a third of the largest moment beyond physical.
    std::fs::write(
        &path,
        r#"<robot name="rod">
  <link name="base"/>
  <link name="rod"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/><axis xyz="1 0 0"/></joint>
</robot>
"#,
    )
    .unwrap();
    let o = run!("info", path);
    assert_ok(&o);
    let err = stderr(&o);
    assert!(
        err.contains("rod.urdf:3: link `rod`: principal moments")
            && err.contains("33.333 % of its largest moment away from physical")
            && err.contains("--balance-inertia"),
        "{err}"
    );
    let o = run!("info", path, "--balance-inertia");
    assert_ok(&o);
    let err = stderr(&o);
    assert!(
        err.contains("replaced by the nearest physical inertia (principal moments 1.333333e0, 1.333333e0, 2.666667e0"),
        "{err}"
    );
    assert_exit(
        &run!("info", path, "--strict"),
        3,
        "rod.urdf:3: link `rod`: principal moments",
    );
}

#[test]
fn too_few_samples_to_estimate_the_noise_are_refused() {
    let dir = temp_dir("dyngen-cli", "few-samples");
    // Three samples of six joints: 18 rows for 60 parameters.
    let csv = common::simulate_ur5(&dir, 2, &[]);
    assert_exit(
        &run!("identify", common::ur5(), &csv),
        3,
        "3 samples give 18 torque rows for 60 parameters: no more equations than unknowns, so the fit matches any \
         data and its σ means nothing; record more than 10 samples",
    );
}
