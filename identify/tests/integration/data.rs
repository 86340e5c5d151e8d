//! The data module: exact CSV round trips, every reader error with its line and
//! message, the writer's refusal to overwrite, and derivatives of known signals
//! through the zero-phase filter and central differences.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use dyngen::Wrench;
use dyngen_identify::data::{
    butterworth_filtfilt, central_difference, csv_header, from_reader, overwrite_csv, read_csv, second_difference,
    to_writer, write_csv, DataError, Location, Trajectory, MAX_ERRORS,
};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// ---------------------------------------------------------------- helpers

/// A unique path under the temp dir, removed on drop.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str) -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let k = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("dyngen-data-{}-{k}-{name}.csv", std::process::id()));
        let _ = std::fs::remove_file(&path);
        TempFile(path)
    }

    fn with_contents(name: &str, contents: &[u8]) -> Self {
        let f = TempFile::new(name);
        std::fs::write(&f.0, contents).unwrap();
        f
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn read_str(s: &str, dof: Option<usize>) -> Result<Trajectory, DataError> {
    from_reader(s.as_bytes(), dof)
}

fn read_err(s: &str, dof: Option<usize>) -> DataError {
    match read_str(s, dof) {
        Ok(t) => panic!("expected an error, read {} samples", t.len()),
        Err(e) => e,
    }
}

/// Values that stress a number format: tiny, huge, subnormal, negative zero, and
/// decimals with no exact binary form.
fn awkward(rng: &mut ChaCha8Rng) -> f64 {
    match rng.gen_range(0..10) {
        0 => -0.0,
        1 => 5e-324,
        2 => rng.gen_range(-1.0..1.0) * 1e-300,
        3 => rng.gen_range(-1.0..1.0) * 1e300,
        4 => 0.1 + 0.2,
        5 => PI * rng.gen_range(-1.0..1.0),
        6 => rng.gen_range(-1e-5..1e-5),
        7 => rng.gen_range(-1e17..1e17),
        _ => rng.gen_range(-10.0..10.0),
    }
}

/// A random trajectory with the chosen optional groups.
fn random_trajectory(seed: u64, dof: usize, len: usize, v: bool, a: bool, wrenches: bool) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t = Vec::with_capacity(len);
    let mut time: f64 = rng.gen_range(-1.0..1.0);
    for _ in 0..len {
        t.push(time);
        time += rng.gen_range(1e-9..0.1);
    }
    let mut values = |count: usize| -> Vec<f64> { (0..count).map(|_| awkward(&mut rng)).collect() };
    let q = values(len * dof);
    let tau = values(len * dof);
    let vv = values(len * dof);
    let aa = values(len * dof);
    let ww = values(len * dof * 6);
    let mut traj = Trajectory::new(dof, t, q, tau).unwrap();
    if v {
        traj = traj.with_velocities(vv).unwrap();
    }
    if a {
        traj = traj.with_accelerations(aa).unwrap();
    }
    if wrenches {
        let w = ww
            .chunks(6)
            .map(|c| Wrench {
                force: Vector3::new(c[0], c[1], c[2]),
                torque: Vector3::new(c[3], c[4], c[5]),
            })
            .collect();
        traj = traj.with_wrenches(w).unwrap();
    }
    traj
}

/// Every number of a trajectory, as bits, in a fixed order.
fn bits(traj: &Trajectory) -> Vec<u64> {
    let mut all: Vec<f64> = traj.t().to_vec();
    all.extend(traj.positions());
    all.extend(traj.velocities().unwrap_or(&[]));
    all.extend(traj.accelerations().unwrap_or(&[]));
    all.extend(traj.torques());
    for w in traj.joint_wrenches().unwrap_or(&[]) {
        all.extend(w.force.iter().chain(w.torque.iter()));
    }
    all.into_iter().map(f64::to_bits).collect()
}

fn assert_bit_identical(a: &Trajectory, b: &Trajectory) {
    assert_eq!(a.dof(), b.dof());
    assert_eq!(a.len(), b.len());
    assert_eq!(a.velocities().is_some(), b.velocities().is_some());
    assert_eq!(a.accelerations().is_some(), b.accelerations().is_some());
    assert_eq!(a.joint_wrenches().is_some(), b.joint_wrenches().is_some());
    assert_eq!(bits(a), bits(b));
    assert_eq!(a, b);
}

/// The message must contain every fragment.
fn assert_message(e: &DataError, fragments: &[&str]) {
    let msg = e.to_string();
    for f in fragments {
        assert!(msg.contains(f), "message {msg:?} lacks {f:?}");
    }
}

const GOOD: &str = "t,q1,q2,tau1,tau2\n0,0,0,0,0\n0.01,0.1,0.2,1,2\n0.02,0.2,0.4,1,2\n";

// ---------------------------------------------------------------- round trips

#[test]
fn round_trip_is_bit_identical_with_every_group() {
    for (seed, dof) in [(1, 1), (2, 3), (3, 7)] {
        let traj = random_trajectory(seed, dof, 50, true, true, true);
        let file = TempFile::new("roundtrip");
        write_csv(file.path(), &traj).unwrap();
        let back = read_csv(file.path(), Some(dof)).unwrap();
        assert_bit_identical(&traj, &back);
        // dof inferred from the q columns.
        assert_bit_identical(&traj, &read_csv(file.path(), None).unwrap());
        // The read trajectory knows its lines: header on 1, sample k on k + 2.
        assert_eq!(back.location(0), Location::Line(2));
        assert_eq!(back.location(49), Location::Line(51));
    }
}

#[test]
fn round_trip_with_optional_groups_absent_or_partial() {
    for (seed, v, a, w) in [
        (10, false, false, false),
        (11, true, false, false),
        (12, false, true, true),
    ] {
        let traj = random_trajectory(seed, 2, 20, v, a, w);
        let mut out = Vec::new();
        to_writer(&mut out, &traj).unwrap();
        let back = from_reader(out.as_slice(), None).unwrap();
        assert_bit_identical(&traj, &back);
    }
}

#[test]
fn writer_header_follows_the_schema_order() {
    let traj = random_trajectory(20, 2, 3, true, true, true);
    let expected = "t,q1,q2,v1,v2,a1,a2,tau1,tau2,fx1,fy1,fz1,mx1,my1,mz1,fx2,fy2,fz2,mx2,my2,mz2";
    assert_eq!(csv_header(&traj).join(","), expected);
    let mut out = Vec::new();
    to_writer(&mut out, &traj).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert_eq!(text.lines().next().unwrap(), expected);
    assert_eq!(text.lines().count(), 4);
}

#[test]
fn writer_uses_short_exact_numbers() {
    let traj = Trajectory::new(
        1,
        vec![0.0, 1e-7, 0.1],
        vec![0.30000000000000004, -0.0, 1e300],
        vec![2.5, 1e20, 5e-324],
    )
    .unwrap();
    let mut out = Vec::new();
    to_writer(&mut out, &traj).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "t,q1,tau1\n0,0.30000000000000004,2.5\n1e-7,-0,1e20\n0.1,1e300,5e-324\n"
    );
}

#[test]
fn columns_in_any_order_with_spaces_and_wrenches() {
    let ordered = "t,q1,v1,tau1,fx1,fy1,fz1,mx1,my1,mz1\n0,1,2,3,4,5,6,7,8,9\n1,11,12,13,14,15,16,17,18,19\n";
    let shuffled = " mz1 , fx1,tau1, q1 ,my1,t,fy1,v1,mx1,fz1\n9,4,3,1,8,0,5,2,7,6\n19, 14 ,13,11,18,1,15,12,17,16\n";
    let a = read_str(ordered, None).unwrap();
    let b = read_str(shuffled, Some(1)).unwrap();
    assert_bit_identical(&a, &b);
    assert_eq!(a.q(1), &[11.0]);
    assert_eq!(a.v(0), Some(&[2.0][..]));
    assert_eq!(a.a(0), None);
    assert_eq!(a.tau(1), &[13.0]);
    let w = a.wrenches(1).unwrap()[0];
    assert_eq!(w.force, Vector3::new(14.0, 15.0, 16.0));
    assert_eq!(w.torque, Vector3::new(17.0, 18.0, 19.0));
    let s = a.sample(1).unwrap();
    assert_eq!((s.t, s.q, s.tau), (1.0, &[11.0][..], &[13.0][..]));
    assert!(a.sample(2).is_none());
    assert_eq!(a.samples().len(), 2);
}

#[test]
fn empty_lines_are_skipped_and_lines_are_counted() {
    let traj = read_str("\n\nt,q1,tau1\n0,0,0\n\n1,1,1\n", None).unwrap();
    assert_eq!(traj.len(), 2);
    assert_eq!(traj.location(0), Location::Line(4));
    assert_eq!(traj.location(1), Location::Line(6));
}

// ---------------------------------------------------------------- writer safety

#[test]
fn writer_refuses_to_overwrite_unless_asked() {
    let first = random_trajectory(30, 2, 5, false, false, false);
    let second = random_trajectory(31, 2, 8, true, true, false);
    let file = TempFile::new("overwrite");
    write_csv(file.path(), &first).unwrap();
    let before = std::fs::read(file.path()).unwrap();

    let e = write_csv(file.path(), &second).unwrap_err();
    assert!(
        matches!(&e, DataError::FileExists { path } if path == file.path()),
        "{e:?}"
    );
    assert_message(&e, &["already exists", "refusing to overwrite", "overwrite_csv"]);
    assert_eq!(
        std::fs::read(file.path()).unwrap(),
        before,
        "the existing file was touched"
    );

    overwrite_csv(file.path(), &second).unwrap();
    assert_bit_identical(&second, &read_csv(file.path(), None).unwrap());
}

#[test]
fn writer_reports_an_unwritable_path() {
    let dir = std::env::temp_dir().join(format!("dyngen-data-{}-no-such-dir", std::process::id()));
    let path = dir.join("x.csv");
    let e = write_csv(&path, &random_trajectory(32, 1, 2, false, false, false)).unwrap_err();
    assert!(matches!(&e, DataError::Io { path: Some(p), .. } if *p == path), "{e:?}");
    assert_message(&e, &["cannot access", "x.csv"]);
}

// ---------------------------------------------------------------- reader errors: files

#[test]
fn error_missing_file() {
    let path = std::env::temp_dir().join(format!("dyngen-data-{}-missing.csv", std::process::id()));
    let e = read_csv(&path, None).unwrap_err();
    assert!(
        matches!(&e, DataError::Io { path: Some(p), source } if *p == path && source.kind() == std::io::ErrorKind::NotFound)
    );
    assert_message(&e, &["cannot access", "missing.csv"]);
    assert!(std::error::Error::source(&e).is_some());
}

#[test]
fn error_unreadable_file() {
    // A directory opens but cannot be read as a file.
    let e = read_csv(std::env::temp_dir(), None).unwrap_err();
    assert!(matches!(&e, DataError::Io { path: Some(_), .. }), "{e:?}");
    assert_message(&e, &["cannot access"]);
}

#[test]
fn error_empty_file() {
    let file = TempFile::with_contents("empty", b"");
    let e = read_csv(file.path(), None).unwrap_err();
    assert!(matches!(e, DataError::Empty), "{e:?}");
    assert_message(&e, &["empty", "header"]);
    for blank in ["\n", "\n\n\r\n", "   \n  \n"] {
        assert!(matches!(read_err(blank, None), DataError::Empty), "{blank:?}");
    }
}

#[test]
fn error_missing_header() {
    let e = read_err("0,0.1,1.5\n0.01,0.2,1.6\n", None);
    assert!(
        matches!(&e, DataError::MissingHeader { line: 1, found } if found == "0,0.1,1.5"),
        "{e:?}"
    );
    assert_eq!(e.line(), Some(1));
    assert_message(&e, &["line 1", "expected a header", "`0,0.1,1.5`"]);
}

#[test]
fn error_semicolon_or_tab_separated_header() {
    for (sep, name) in [(";", "`;`"), ("\t", "tab")] {
        let text = "t,q1,tau1\n0,0,0\n0.01,0,0\n".replace(',', sep);
        let e = read_err(&text, None);
        assert!(matches!(e, DataError::Separator { line: 1, fields: 3, .. }), "{e:?}");
        assert_eq!(e.line(), Some(1));
        assert_message(
            &e,
            &[&format!(
                "line 1: no `,` separates the fields, but a {name} splits the line into 3"
            )],
        );
    }
}

#[test]
fn error_malformed_utf8() {
    let e = from_reader(&b"t,q1,tau1\n0,0,0\n1,\xff,1\n"[..], None).unwrap_err();
    assert!(matches!(e, DataError::Malformed { line: Some(3), .. }), "{e:?}");
    assert_message(&e, &["line 3", "UTF-8"]);
}

// ---------------------------------------------------------------- reader errors: header

#[test]
fn error_unknown_column() {
    let e = read_err("t,q1,tau1,temperature\n0,0,0,20\n1,1,1,21\n", None);
    assert!(
        matches!(&e, DataError::UnknownColumn { line: 1, column, position: 4, .. } if column == "temperature"),
        "{e:?}"
    );
    assert_message(
        &e,
        &[
            "line 1, column 4",
            "unknown column `temperature`",
            "valid columns",
            "`q1`",
            "`tau1`",
            "`v1`",
            "mz1",
        ],
    );

    // A joint beyond the robot's: tau3 on a 2-joint file.
    let e = read_err("t,q1,q2,tau1,tau2,tau3\n0,0,0,0,0,0\n1,1,1,1,1,1\n", None);
    assert!(
        matches!(&e, DataError::UnknownColumn { column, position: 6, .. } if column == "tau3"),
        "{e:?}"
    );
    assert_message(&e, &["`tau1`..`tau2`", "for 2 joints"]);

    // Case, leading zeros and joint 0 are not the schema's names.
    for bad in ["Q1", "q01", "q0", "T"] {
        let e = read_err(&format!("t,q1,tau1,{bad}\n0,0,0,0\n1,1,1,1\n"), None);
        assert!(
            matches!(&e, DataError::UnknownColumn { column, .. } if column == bad),
            "{bad}: {e:?}"
        );
    }
}

#[test]
fn error_duplicate_column() {
    let e = read_err("t,q1,tau1,q1\n0,0,0,0\n1,1,1,1\n", None);
    assert!(
        matches!(&e, DataError::DuplicateColumn { line: 1, column, first: 2, second: 4 } if column == "q1"),
        "{e:?}"
    );
    assert_message(&e, &["line 1", "`q1` appears twice", "columns 2 and 4"]);
}

#[test]
fn error_missing_required_column() {
    // q3 when dof is 3.
    let e = read_err("t,q1,q2,tau1,tau2,tau3\n0,0,0,0,0,0\n1,1,1,1,1,1\n", Some(3));
    assert!(
        matches!(&e, DataError::MissingColumn { line: 1, column, .. } if column == "q3"),
        "{e:?}"
    );
    assert_message(
        &e,
        &["line 1", "missing required column `q3`", "`q1`..`q3`", "`tau1`..`tau3`"],
    );

    let e = read_err("t,q1,q2,tau1\n0,0,0,0\n1,1,1,1\n", None);
    assert!(
        matches!(&e, DataError::MissingColumn { column, .. } if column == "tau2"),
        "{e:?}"
    );
    assert_message(&e, &["`tau2`"]);

    let e = read_err("time,q1,tau1\n0,0,0\n1,1,1\n", None);
    let errors = e.errors();
    assert_eq!(errors.len(), 2, "{e}");
    assert!(matches!(&errors[0], DataError::UnknownColumn { column, .. } if column == "time"));
    assert!(matches!(&errors[1], DataError::MissingColumn { column, .. } if column == "t"));

    // No q column at all: only q1 is reported, not every joint column.
    let e = read_err("t,tau1\n0,0\n1,1\n", None);
    assert!(
        matches!(&e, DataError::MissingColumn { column, .. } if column == "q1"),
        "{e:?}"
    );
    assert_message(&e, &["`q1`", "n ≥ 1"]);
}

#[test]
fn error_dof_mismatch() {
    let e = read_err(
        "t,q1,q2,q3,q4,tau1,tau2,tau3\n0,0,0,0,0,0,0,0\n1,1,1,1,1,1,1,1\n",
        Some(3),
    );
    assert!(
        matches!(
            e,
            DataError::DofMismatch {
                line: 1,
                expected: 3,
                found: 4
            }
        ),
        "{e:?}"
    );
    assert_message(&e, &["line 1", "`q1`..`q4` (4 joints)", "3 joints were expected"]);

    let e = read_err(GOOD, Some(0));
    assert!(matches!(e, DataError::InvalidArgument { name: "dof", .. }), "{e:?}");
}

#[test]
fn error_incomplete_optional_groups() {
    let e = read_err("t,q1,q2,v1,tau1,tau2\n0,0,0,0,0,0\n1,1,1,1,1,1\n", None);
    assert!(
        matches!(&e, DataError::IncompleteGroup { line: 1, present: 1, missing, .. } if missing == &["v2"]),
        "{e:?}"
    );
    assert_message(
        &e,
        &[
            "line 1",
            "incomplete velocity",
            "1 present",
            "`v2`",
            "all of them or none",
        ],
    );

    // Joint wrench columns for joint 1 only, and mz2 missing.
    let w1 = "fx1,fy1,fz1,mx1,my1,mz1";
    let e = read_err(
        &format!("t,q1,q2,tau1,tau2,{w1}\n0,0,0,0,0,0,0,0,0,0,0\n1,1,1,1,1,1,1,1,1,1,1\n"),
        None,
    );
    match &e {
        DataError::IncompleteGroup {
            group,
            present: 6,
            missing,
            ..
        } => {
            assert!(group.contains("wrench"));
            assert_eq!(missing, &["fx2", "fy2", "fz2", "mx2", "my2", "mz2"]);
        }
        other => panic!("{other:?}"),
    }
    assert_message(&e, &["incomplete joint wrench", "6 missing", "`fx2`", "`mz2`"]);

    let e = read_err(
        &format!(
            "t,q1,q2,tau1,tau2,{w1},fx2,fy2,fz2,mx2,my2\n{}\n{}\n",
            ["0"; 16].join(","),
            ["1"; 16].join(",")
        ),
        None,
    );
    assert!(
        matches!(&e, DataError::IncompleteGroup { present: 11, missing, .. } if missing == &["mz2"]),
        "{e:?}"
    );

    // Velocities without accelerations are fine.
    assert!(read_str("t,q1,v1,tau1\n0,0,0,0\n1,1,1,1\n", None)
        .unwrap()
        .accelerations()
        .is_none());
}

// ---------------------------------------------------------------- reader errors: rows

#[test]
fn error_row_with_too_few_or_too_many_fields() {
    let e = read_err("t,q1,tau1\n0,0,0\n1,1\n2,2,2\n", None);
    assert!(
        matches!(
            e,
            DataError::FieldCount {
                line: 3,
                expected: 3,
                found: 2
            }
        ),
        "{e:?}"
    );
    assert_message(&e, &["line 3", "too few fields: 2, expected 3"]);

    // Blank lines count in the line numbers.
    let e = read_err("t,q1,tau1\n0,0,0\n\n1,1,1\n2,2,2,2\n", None);
    assert!(
        matches!(
            e,
            DataError::FieldCount {
                line: 5,
                expected: 3,
                found: 4
            }
        ),
        "{e:?}"
    );
    assert_message(&e, &["line 5", "too many fields: 4, expected 3"]);

    // A line of spaces is a row with one empty field, not a blank line.
    let e = read_err("t,q1,tau1\n0,0,0\n   \n1,1,1\n", None);
    assert!(matches!(e, DataError::FieldCount { line: 3, found: 1, .. }), "{e:?}");
}

#[test]
fn error_non_numeric_field() {
    let e = read_err("t,q1,tau1\n0,0,0\n0.01,1.2.3,0\n0.02,0,0\n", None);
    assert!(
        matches!(&e, DataError::NotANumber { line: 3, column, text } if column == "q1" && text == "1.2.3"),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "line 3, column `q1`: `1.2.3` is not a number");

    let e = read_err("t,q1,tau1\n0,0,0\n0.01,0,\n0.02,0,0\n", None);
    assert!(matches!(&e, DataError::NotANumber { line: 3, column, text } if column == "tau1" && text.is_empty()));
    assert_eq!(e.to_string(), "line 3, column `tau1`: empty field; expected a number");
}

#[test]
fn error_nan_or_infinite_value() {
    for (text, is_nan) in [("NaN", true), ("nan", true), ("inf", false), ("-infinity", false)] {
        let e = read_err(
            &format!("t,q1,q2,tau1,tau2\n0,0,0,0,0\n0.01,0,0,0,0\n0.02,0,{text},0,0\n"),
            None,
        );
        match &e {
            DataError::NonFinite {
                at: Location::Line(4),
                column,
                value,
            } => {
                assert_eq!(column, "q2");
                assert_eq!(value.is_nan(), is_nan);
            }
            other => panic!("{text}: {other:?}"),
        }
        assert_eq!(e.line(), Some(4));
        assert_message(&e, &["line 4, column `q2`", "is not a finite number"]);
    }
}

#[test]
fn error_non_monotonic_time() {
    let e = read_err("t,q1,tau1\n0,0,0\n0.01,0,0\n0.01,0,0\n", None);
    assert!(
        matches!(e, DataError::NonMonotonicTime { at: Location::Line(4), t, previous } if t == 0.01 && previous == 0.01)
    );
    assert_message(
        &e,
        &[
            "line 4",
            "t = 0.01 s does not increase",
            "previous t = 0.01 s",
            "strictly increasing",
        ],
    );

    let e = read_err("t,q1,tau1\n0.5,0,0\n0.25,0,0\n1,0,0\n", None);
    assert!(
        matches!(
            e,
            DataError::NonMonotonicTime {
                at: Location::Line(3),
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn error_fewer_than_two_samples() {
    let e = read_err("t,q1,tau1\n", None);
    assert!(matches!(e, DataError::TooFewSamples { found: 0, needed: 2 }), "{e:?}");
    let e = read_err("t,q1,tau1\n0,1,2\n", None);
    assert!(matches!(e, DataError::TooFewSamples { found: 1, needed: 2 }), "{e:?}");
    assert_message(&e, &["1 sample(s)", "at least 2"]);
}

#[test]
fn errors_are_collected_across_rows_in_line_order() {
    let text = "t,q1,tau1\n0,0,0\n0.01,x,0\n0.02,0\n0.03,0,inf\n0.03,0,0\n0.04,0,0\n";
    let e = read_err(text, None);
    let DataError::Multiple { errors, truncated } = &e else {
        panic!("{e:?}")
    };
    assert!(!truncated);
    let lines: Vec<_> = errors.iter().map(DataError::line).collect();
    assert_eq!(lines, [Some(3), Some(4), Some(5), Some(6)]);
    assert!(matches!(errors[0], DataError::NotANumber { .. }));
    assert!(matches!(errors[1], DataError::FieldCount { .. }));
    assert!(matches!(errors[2], DataError::NonFinite { .. }));
    assert!(matches!(errors[3], DataError::NonMonotonicTime { .. }));
    assert_eq!(e.line(), Some(3));
    let msg = e.to_string();
    assert!(msg.starts_with("4 errors:\n  line 3, column `q1`"), "{msg}");
    assert_eq!(msg.lines().count(), 5);

    // Past MAX_ERRORS the reader stops and says so.
    let mut text = String::from("t,q1,tau1\n");
    for k in 0..2 * MAX_ERRORS {
        text.push_str(&format!("{k},bad,0\n"));
    }
    let e = read_err(&text, None);
    let DataError::Multiple { errors, truncated } = &e else {
        panic!("{e:?}")
    };
    assert!(truncated);
    assert_eq!(errors.len(), MAX_ERRORS);
    assert_eq!(errors.last().unwrap().line(), Some(MAX_ERRORS as u64 + 1));
    assert_message(&e, &["stopped reading there"]);

    // Exactly MAX_ERRORS, nothing after: complete, not truncated.
    let mut text = String::from("t,q1,tau1\n");
    for k in 0..MAX_ERRORS {
        text.push_str(&format!("{k},bad,0\n"));
    }
    let DataError::Multiple { errors, truncated } = read_err(&text, None) else {
        panic!()
    };
    assert_eq!((errors.len(), truncated), (MAX_ERRORS, false));
}

#[test]
fn header_errors_are_collected_together() {
    let e = read_err("t,q1,q2,q2,tau1,foo\n0,0,0,0,0,0\n1,1,1,1,1,1\n", None);
    let kinds: Vec<_> = e
        .errors()
        .iter()
        .map(|e| match e {
            DataError::DuplicateColumn { .. } => "duplicate",
            DataError::UnknownColumn { .. } => "unknown",
            DataError::MissingColumn { .. } => "missing",
            _ => "other",
        })
        .collect();
    assert_eq!(kinds, ["duplicate", "unknown", "missing"], "{e}");
}

#[test]
fn header_line_number_after_blank_lines() {
    let e = read_err("\n\nt,q1,tau1,x\n0,0,0,0\n1,1,1,1\n", None);
    assert!(matches!(e, DataError::UnknownColumn { line: 3, .. }), "{e:?}");
    let e = read_err("\n1,2,3\n", None);
    assert!(matches!(e, DataError::MissingHeader { line: 2, .. }), "{e:?}");
}

#[test]
fn line_numbers_count_every_line_ending() {
    // `\r\n` endings and a blank line.
    let e = read_err("t,q1,tau1\r\n0,0,0\r\n\r\n1,x,1\r\n", None);
    assert!(matches!(e, DataError::NotANumber { line: 4, .. }), "{e:?}");
    // Old Mac `\r` endings.
    let e = read_err("t,q1,tau1\r0,0,0\r\r1,x,1\r", None);
    assert!(matches!(e, DataError::NotANumber { line: 4, .. }), "{e:?}");
    // A quoted field spanning two lines: the next record starts on line 4.
    let e = read_err("t,q1,tau1\n\"0\n\",0,0\n1,x,1\n", None);
    assert!(matches!(e, DataError::NotANumber { line: 4, .. }), "{e:?}");
    // Many blank lines, long input: line numbers stay exact.
    let mut text = String::from("t,q1,tau1\n");
    for k in 0..5000 {
        text.push_str(&format!("{k},0,0\n\n"));
    }
    text.push_str("5000,0,nan\n");
    let e = read_err(&text, None);
    assert!(
        matches!(
            e,
            DataError::NonFinite {
                at: Location::Line(10002),
                ..
            }
        ),
        "{e:?}"
    );
}

// ---------------------------------------------------------------- in-memory construction

#[test]
fn in_memory_construction_is_checked() {
    let e = Trajectory::new(2, vec![0.0, 1.0], vec![0.0; 3], vec![0.0; 4]).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::LengthMismatch {
                what: "q",
                expected: 4,
                found: 3
            }
        ),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "`q` has 3 values, expected 4");

    let e = Trajectory::new(1, vec![0.0, 1.0, 2.0], vec![0.0, f64::NAN, 0.0], vec![0.0; 3]).unwrap_err();
    assert!(matches!(&e, DataError::NonFinite { at: Location::Sample(1), column, .. } if column == "q1"));
    assert_message(&e, &["sample 1 (0-based), column `q1`", "NaN is not a finite number"]);
    assert_eq!(e.line(), None);

    let e = Trajectory::new(1, vec![0.0, 1.0, 1.0], vec![0.0; 3], vec![0.0; 3]).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::NonMonotonicTime {
                at: Location::Sample(2),
                ..
            }
        ),
        "{e:?}"
    );

    let e = Trajectory::new(1, vec![0.0], vec![0.0], vec![0.0]).unwrap_err();
    assert!(matches!(e, DataError::TooFewSamples { found: 1, needed: 2 }), "{e:?}");

    let e = Trajectory::new(0, vec![0.0, 1.0], vec![], vec![]).unwrap_err();
    assert!(matches!(e, DataError::InvalidArgument { name: "dof", .. }), "{e:?}");

    let traj = Trajectory::new(1, vec![0.0, 1.0], vec![0.0; 2], vec![0.0; 2]).unwrap();
    let e = traj.clone().with_velocities(vec![0.0]).unwrap_err();
    assert!(matches!(e, DataError::LengthMismatch { what: "v", .. }), "{e:?}");
    let mut w = vec![Wrench::<f64>::default(); 2];
    w[1].torque.z = f64::INFINITY;
    let e = traj.with_wrenches(w).unwrap_err();
    assert!(matches!(&e, DataError::NonFinite { at: Location::Sample(1), column, .. } if column == "mz1"));
}

// ---------------------------------------------------------------- derivatives

const FS: f64 = 100.0;
const DT: f64 = 1.0 / FS;

fn sampled(len: usize, f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..len).map(|k| k as f64 * DT).collect();
    let x = t.iter().map(|&t| f(t)).collect();
    (t, x)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
}

/// q = sin(2π·0.5 t), 100 Hz, 1,000 samples, filtered at 10 Hz: v and a against
/// the analytic derivatives.
#[test]
fn derivatives_of_a_sine() {
    let w = 2.0 * PI * 0.5;
    let (t, q) = sampled(1000, |t| (w * t).sin());
    let traj = Trajectory::new(1, t.clone(), q, vec![0.0; 1000]).unwrap();
    let full = traj.with_derivatives(10.0).unwrap();
    let v = full.velocities().unwrap();
    let a = full.accelerations().unwrap();
    let v_true: Vec<f64> = t.iter().map(|&t| w * (w * t).cos()).collect();
    let a_true: Vec<f64> = t.iter().map(|&t| -w * w * (w * t).sin()).collect();
    // Relative to the amplitudes w and w².
    let inner = 10..990;
    let ev = max_abs_diff(&v[inner.clone()], &v_true[inner.clone()]) / w;
    let ea = max_abs_diff(&a[inner.clone()], &a_true[inner]) / (w * w);
    let ev_all = max_abs_diff(v, &v_true) / w;
    let ea_all = max_abs_diff(a, &a_true) / (w * w);
    println!("sine: v {ev:.2e} (ends {ev_all:.2e}), a {ea:.2e} (ends {ea_all:.2e})");
    // Central differences alone err by (wΔt)²/6 ≈ 1.6e-4 on v, twice that on a.
    assert!(ev < 5e-4, "v interior relative error {ev:e}");
    assert!(ea < 1e-3, "a interior relative error {ea:e}");
    assert!(ev_all < 1e-3, "v relative error with ends {ev_all:e}");
    assert!(ea_all < 5e-3, "a relative error with ends {ea_all:e}");
    // q and tau are untouched.
    assert_eq!(full.positions(), traj.positions());
    assert_eq!(full.torques(), traj.torques());
}

/// A signal whose ends are not zero crossings (where odd reflection is not exact),
/// on two joints with different content.
#[test]
fn derivatives_at_the_ends_of_a_general_signal() {
    let w1 = 2.0 * PI * 0.3;
    let w2 = 2.0 * PI * 1.1;
    let len = 500;
    let f = |t: f64| [0.4 + 0.7 * (w1 * t + 0.9).cos(), -1.0 + 0.2 * t + 0.3 * (w2 * t).sin()];
    let df = |t: f64| [-0.7 * w1 * (w1 * t + 0.9).sin(), 0.2 + 0.3 * w2 * (w2 * t).cos()];
    let ddf = |t: f64| [-0.7 * w1 * w1 * (w1 * t + 0.9).cos(), -0.3 * w2 * w2 * (w2 * t).sin()];
    let t: Vec<f64> = (0..len).map(|k| 2.0 + k as f64 * DT).collect();
    let q: Vec<f64> = t.iter().flat_map(|&t| f(t)).collect();
    let traj = Trajectory::new(2, t.clone(), q, vec![0.0; 2 * len]).unwrap();
    let full = traj.with_derivatives(8.0).unwrap();
    let v_true: Vec<f64> = t.iter().flat_map(|&t| df(t)).collect();
    let a_true: Vec<f64> = t.iter().flat_map(|&t| ddf(t)).collect();
    let (v, a) = (full.velocities().unwrap(), full.accelerations().unwrap());
    for j in 0..2 {
        let col = |x: &[f64]| -> Vec<f64> { x.iter().skip(j).step_by(2).copied().collect() };
        let (v, a, v_true, a_true) = (col(v), col(a), col(&v_true), col(&a_true));
        // Relative to the largest true derivative of each kind on this joint.
        let scale_v = v_true.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let scale_a = a_true.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let inner = 20..len - 20;
        let ev = max_abs_diff(&v[inner.clone()], &v_true[inner.clone()]) / scale_v;
        let ea = max_abs_diff(&a[inner.clone()], &a_true[inner]) / scale_a;
        let ev_all = max_abs_diff(&v, &v_true) / scale_v;
        let ea_all = max_abs_diff(&a, &a_true) / scale_a;
        println!(
            "general, joint {}: v {ev:.2e} (ends {ev_all:.2e}), a {ea:.2e} (ends {ea_all:.2e})",
            j + 1
        );
        // Joint 2's 1.1 Hz is attenuated by (1.1/8)⁴ ≈ 4e-4 by the filter.
        assert!(ev < 2e-3, "joint {j}: v interior {ev:e}");
        assert!(ea < 5e-3, "joint {j}: a interior {ea:e}");
        assert!(ev_all < 1e-2, "joint {j}: v with ends {ev_all:e}");
        assert!(ea_all < 0.1, "joint {j}: a with ends {ea_all:e}");
    }
}

/// Noise of 1e-4 rad on q: filtering keeps the velocity error far below what raw
/// central differences give.
#[test]
fn derivatives_of_a_noisy_sine() {
    let w = 2.0 * PI * 0.5;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (t, clean) = sampled(1000, |t| (w * t).sin());
    let q: Vec<f64> = clean.iter().map(|x| x + 1e-4 * rng.gen_range(-1.0..1.0)).collect();
    let v_true: Vec<f64> = t.iter().map(|&t| w * (w * t).cos()).collect();
    let a_true: Vec<f64> = t.iter().map(|&t| -w * w * (w * t).sin()).collect();
    let raw_v = central_difference(&q, DT).unwrap();
    let raw_a = second_difference(&q, DT).unwrap();
    let traj = Trajectory::new(1, t, q, vec![0.0; 1000]).unwrap();
    let full = traj.with_derivatives(5.0).unwrap();
    let (v, a) = (full.velocities().unwrap(), full.accelerations().unwrap());
    let inner = 20..980;
    let ev_raw = max_abs_diff(&raw_v[inner.clone()], &v_true[inner.clone()]) / w;
    let ev = max_abs_diff(&v[inner.clone()], &v_true[inner.clone()]) / w;
    let ea_raw = max_abs_diff(&raw_a[inner.clone()], &a_true[inner.clone()]) / (w * w);
    let ea = max_abs_diff(&a[inner.clone()], &a_true[inner]) / (w * w);
    let ev_all = max_abs_diff(v, &v_true) / w;
    let ea_all = max_abs_diff(a, &a_true) / (w * w);
    println!("noisy: v raw {ev_raw:.2e} filtered {ev:.2e} (ends {ev_all:.2e}); a raw {ea_raw:.2e} filtered {ea:.2e} (ends {ea_all:.2e})");
    assert!(ev < ev_raw / 3.0, "v filtered {ev:e} vs raw {ev_raw:e}");
    assert!(ea < ea_raw / 30.0, "a filtered {ea:e} vs raw {ea_raw:e}");
    assert!(ev < 1e-3, "{ev:e}");
    assert!(ea < 2e-2, "{ea:e}");
    assert!(ev_all < 5e-3, "{ev_all:e}");
    assert!(ea_all < 0.1, "{ea_all:e}");
}

#[test]
fn derivatives_keep_given_values() {
    let (t, q) = sampled(200, |t| t * t);
    let given_v: Vec<f64> = t.iter().map(|&t| 2.0 * t + 1e-3).collect();
    let traj = Trajectory::new(1, t, q, vec![0.0; 200])
        .unwrap()
        .with_velocities(given_v.clone())
        .unwrap();
    let full = traj.with_derivatives(10.0).unwrap();
    assert_eq!(full.velocities().unwrap(), &given_v[..]);
    // a from the given v: d(2t)/dt = 2 (linear v passes the filter unchanged).
    let a = full.accelerations().unwrap();
    assert!(a.iter().all(|a| (a - 2.0).abs() < 1e-5), "{:?}", &a[..3]);
    // Both present: nothing to compute.
    assert_eq!(full.with_derivatives(10.0).unwrap(), full);
}

#[test]
fn error_non_uniform_sampling_names_the_line() {
    let mut text = String::from("t,q1,tau1\n");
    for k in 0..50 {
        // Sample 30 (line 32) comes 2 % of a step late.
        let t = if k == 30 { 0.3002 } else { k as f64 * 0.01 };
        text.push_str(&format!("{t},0,0\n"));
    }
    let traj = read_str(&text, None).unwrap();
    let e = traj.with_derivatives(10.0).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::NonUniformSampling {
                at: Location::Line(32),
                ..
            }
        ),
        "{e:?}"
    );
    assert_message(
        &e,
        &[
            "line 32",
            "time step 0.0102",
            "mean step 0.01",
            "uniform sampling (within 1 %)",
        ],
    );

    // Within 1 %: accepted.
    let text = text.replace("0.3002", "0.30005");
    assert!(read_str(&text, None).unwrap().with_derivatives(10.0).is_ok());
}

#[test]
fn error_invalid_cutoff() {
    let traj = read_str(GOOD, None).unwrap();
    for cutoff in [0.0, -1.0, 50.0, 80.0, f64::NAN] {
        let e = traj.with_derivatives(cutoff).unwrap_err();
        assert!(
            matches!(e, DataError::InvalidArgument { name: "cutoff_hz", .. }),
            "{cutoff}: {e:?}"
        );
        assert_message(&e, &["invalid `cutoff_hz`", "< 50 Hz"]);
    }
    let e = butterworth_filtfilt(&[0.0; 10], 0.01, 60.0).unwrap_err();
    assert!(
        matches!(e, DataError::InvalidArgument { name: "cutoff_hz", .. }),
        "{e:?}"
    );
    let e = butterworth_filtfilt(&[0.0; 10], 0.0, 1.0).unwrap_err();
    assert!(matches!(e, DataError::InvalidArgument { name: "dt", .. }), "{e:?}");
}

// ---------------------------------------------------------------- filter and differences

/// A sine well below the cutoff passes with < 1e-3 relative amplitude error and no
/// lag, at every sample including the ends.
#[test]
fn filtfilt_has_zero_phase() {
    for (f, cutoff) in [(0.5, 10.0), (1.0, 10.0), (2.0, 25.0)] {
        let w = 2.0 * PI * f;
        let (t, x) = sampled(1000, |t| (w * t + 0.3).sin());
        let y = butterworth_filtfilt(&x, DT, cutoff).unwrap();
        assert_eq!(y.len(), x.len());
        let err = max_abs_diff(&x, &y);
        assert!(err < 1e-3, "{f} Hz: max error {err:e}");
        // No lag: in y ≈ A sin(wt + 0.3) + B cos(wt + 0.3), B ≈ 0.
        let (a, b) = quadrature(&t, &y, w, 0.3);
        assert!((a - 1.0).abs() < 1e-3, "{f} Hz: gain {a}");
        assert!(b.abs() < 1e-4, "{f} Hz: quadrature {b:e} (phase {:e} rad)", b.atan2(a));
    }
}

/// `(A, B)` of `y ≈ A sin(wt + φ) + B cos(wt + φ)` by correlation over whole periods.
fn quadrature(t: &[f64], y: &[f64], w: f64, phase: f64) -> (f64, f64) {
    let samples_per_period = 2.0 * PI / w / DT;
    let periods = (t.len() as f64 / samples_per_period).floor();
    let count = (periods * samples_per_period).round() as usize;
    let (mut a, mut b) = (0.0, 0.0);
    for k in 0..count {
        let p = w * t[k] + phase;
        a += y[k] * p.sin();
        b += y[k] * p.cos();
    }
    (2.0 * a / count as f64, 2.0 * b / count as f64)
}

/// Magnitude response of the forward–backward filter: |H|² = 1 / (1 + (f/fc)⁴)
/// for the prewarped design, i.e. exactly 1/2 at the cutoff.
#[test]
fn filtfilt_magnitude_response() {
    let cutoff = 10.0;
    let expected = |f: f64| {
        // Digital response from the prewarped prototype: frequencies map through tan.
        let r = (PI * f * DT).tan() / (PI * cutoff * DT).tan();
        1.0 / (1.0 + r.powi(4))
    };
    for f in [5.0, 10.0, 20.0, 40.0] {
        let w = 2.0 * PI * f;
        let (t, x) = sampled(2000, |t| (w * t).sin());
        let y = butterworth_filtfilt(&x, DT, cutoff).unwrap();
        // Away from the ends, where the response is the steady state.
        let (gain, quad) = quadrature(&t[500..1500], &y[500..1500], w, 0.0);
        let g = expected(f);
        assert!((gain - g).abs() < 1e-3 * g + 1e-4, "{f} Hz: {gain} vs {g}");
        assert!(quad.abs() < 1e-3, "{f} Hz: quadrature {quad:e}");
    }
    assert!((expected(10.0) - 0.5).abs() < 1e-12);
}

#[test]
fn filtfilt_preserves_constants_and_ramps() {
    let x = vec![3.25; 300];
    let y = butterworth_filtfilt(&x, DT, 5.0).unwrap();
    assert!(max_abs_diff(&x, &y) < 1e-12);
    let (_, ramp) = sampled(300, |t| 1.0 - 2.0 * t);
    let y = butterworth_filtfilt(&ramp, DT, 5.0).unwrap();
    // The start-up transient of a ramp decays over the padding to well below 1e-6.
    assert!(max_abs_diff(&ramp, &y) < 1e-6, "{:e}", max_abs_diff(&ramp, &y));
    // Short signals: padding shrinks to fit, 0 or 1 samples come back as they are.
    assert_eq!(butterworth_filtfilt(&[], DT, 5.0).unwrap(), Vec::<f64>::new());
    assert_eq!(butterworth_filtfilt(&[2.0], DT, 5.0).unwrap(), vec![2.0]);
    // 3 samples: too short for the filter to settle, but finite and of the right length.
    let y = butterworth_filtfilt(&[1.0, 2.0, 3.0], DT, 5.0).unwrap();
    assert!(y.len() == 3 && y.iter().all(|y| y.is_finite()), "{y:?}");
    let e = butterworth_filtfilt(&[0.0, f64::NAN], DT, 5.0).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::NonFinite {
                at: Location::Sample(1),
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn central_difference_is_exact_on_quadratics() {
    let (t, x) = sampled(50, |t| 2.0 - 3.0 * t + 4.0 * t * t);
    let d = central_difference(&x, DT).unwrap();
    let exact: Vec<f64> = t.iter().map(|&t| -3.0 + 8.0 * t).collect();
    assert!(max_abs_diff(&d, &exact) < 1e-10, "{:e}", max_abs_diff(&d, &exact));
    assert_eq!(central_difference(&[1.0, 3.0], 0.5).unwrap(), vec![4.0, 4.0]);
    let e = central_difference(&[1.0], 0.5).unwrap_err();
    assert!(matches!(e, DataError::TooFewSamples { found: 1, needed: 2 }), "{e:?}");
    let e = central_difference(&[1.0, 2.0], f64::INFINITY).unwrap_err();
    assert!(matches!(e, DataError::InvalidArgument { name: "dt", .. }), "{e:?}");
}

#[test]
fn second_difference_is_exact_on_cubics() {
    let (t, x) = sampled(50, |t| 2.0 - 3.0 * t + 4.0 * t * t - 5.0 * t * t * t);
    let d = second_difference(&x, DT).unwrap();
    let exact: Vec<f64> = t.iter().map(|&t| 8.0 - 30.0 * t).collect();
    assert!(max_abs_diff(&d, &exact) < 1e-7, "{:e}", max_abs_diff(&d, &exact));
    assert_eq!(second_difference(&[1.0, 2.0, 5.0], 1.0).unwrap(), vec![2.0; 3]);
    let e = second_difference(&[1.0, 2.0], 1.0).unwrap_err();
    assert!(matches!(e, DataError::TooFewSamples { found: 2, needed: 3 }), "{e:?}");
    assert_message(&e, &["2 sample(s); at least 3 are needed"]);
}

/// Low-passing the measured state removes noise above the cutoff from positions and
/// measured velocities, on uniform and on jittered time stamps, and leaves the
/// signal, the accelerations and the torques as they were.
#[test]
fn measured_states_low_passed_lose_their_noise_not_their_signal() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for jitter in [false, true] {
        let mut t = vec![0.0];
        for _ in 1..2000 {
            let step = if jitter { rng.gen_range(0.008..0.013) } else { 0.01 };
            t.push(t[t.len() - 1] + step);
        }
        let (w, n) = (2.0 * PI * 0.4, t.len());
        let q_true: Vec<f64> = t.iter().map(|t| (w * t).sin()).collect();
        let v_true: Vec<f64> = t.iter().map(|t| w * (w * t).cos()).collect();
        let q: Vec<f64> = q_true.iter().map(|q| q + 2e-3 * rng.gen_range(-1.0..1.0)).collect();
        let v: Vec<f64> = v_true.iter().map(|v| v + 2e-2 * rng.gen_range(-1.0..1.0)).collect();
        let tau: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let raw = Trajectory::new(1, t.clone(), q, tau.clone())
            .unwrap()
            .with_velocities(v)
            .unwrap()
            .with_accelerations(vec![0.5; n])
            .unwrap();
        let smooth = raw.with_states_low_passed(5.0, true).unwrap();
        // Away from the ends, where the filter's padding is a guess.
        let rms = |x: &[f64], truth: &[f64]| {
            let inner = 50..n - 50;
            (inner.clone().map(|k| (x[k] - truth[k]).powi(2)).sum::<f64>() / inner.len() as f64).sqrt()
        };
        let (q_raw, q_smooth) = (rms(raw.positions(), &q_true), rms(smooth.positions(), &q_true));
        let (v_raw, v_smooth) = (
            rms(raw.velocities().unwrap(), &v_true),
            rms(smooth.velocities().unwrap(), &v_true),
        );
        assert!(
            q_smooth < 0.4 * q_raw,
            "jitter {jitter}: q RMS {q_raw:.2e} → {q_smooth:.2e}"
        );
        assert!(
            v_smooth < 0.4 * v_raw,
            "jitter {jitter}: v RMS {v_raw:.2e} → {v_smooth:.2e}"
        );
        assert_eq!(smooth.accelerations(), raw.accelerations());
        assert_eq!(smooth.torques(), raw.torques());
        assert_eq!(smooth.t(), raw.t());
        // Velocities not asked for are kept.
        let only_q = raw.with_states_low_passed(5.0, false).unwrap();
        assert_eq!(only_q.velocities(), raw.velocities());
        // A cutoff at or above Nyquist is refused.
        let e = raw.with_states_low_passed(60.0, true).unwrap_err();
        assert!(e.to_string().contains("cutoff_hz"), "{e}");
    }
}
