//! Damaged and unusual inputs through the command line: each is refused with a
//! message naming the culprit, never a crash or a silent wrong result.

mod common;

use common::{assert_exit, pendulum, run, temp_dir};

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
