//! `dyngen identify --partial` and `--merge`: partial factors of pieces of a
//! recording merged give the one-file identification; every refusal names the
//! option or the files.

use crate::common;
use crate::common::{assert_error, assert_ok, pendulum, run, simulate_ur5, stdout, temp_dir, ur5};
use dyngen_identify::report::ParameterReport;
use std::path::{Path, PathBuf};

/// `csv` cut into pieces at the given sample indices (each with the header), as
/// `dir/piece<i>.csv`.
fn split(csv: &Path, dir: &Path, cuts: &[usize]) -> Vec<PathBuf> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let mut bounds = vec![0];
    bounds.extend_from_slice(cuts);
    bounds.push(rows.len());
    bounds
        .windows(2)
        .enumerate()
        .map(|(i, b)| {
            let path = dir.join(format!("piece{i}.csv"));
            let body: String = rows[b[0]..b[1]].iter().map(|r| format!("{r}\n")).collect();
            std::fs::write(&path, format!("{header}\n{body}")).unwrap();
            path
        })
        .collect()
}

/// The largest difference between two parameters files' estimates (the solution,
/// every parameter value and identifiable combination), relative to the largest
/// entry of `b`'s solution; the same parameters must have values.
fn max_difference(a: &Path, b: &Path) -> f64 {
    let (a, b) = (ParameterReport::read(a).unwrap(), ParameterReport::read(b).unwrap());
    let solution = |r: &ParameterReport| r.prediction.as_ref().unwrap().solution.clone();
    let values = |r: &ParameterReport| r.parameters.iter().map(|p| p.value).collect::<Vec<_>>();
    let combinations = |r: &ParameterReport| r.combinations.iter().map(|c| c.value).collect::<Vec<_>>();
    let (va, vb) = (values(&a), values(&b));
    assert_eq!(
        va.iter().map(Option::is_some).collect::<Vec<_>>(),
        vb.iter().map(Option::is_some).collect::<Vec<_>>()
    );
    let (ca, cb) = (combinations(&a), combinations(&b));
    assert_eq!(ca.len(), cb.len());
    let (sa, sb) = (solution(&a), solution(&b));
    let scale = sb.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let known = va.iter().zip(&vb).filter_map(|(x, y)| Some((x.as_ref()?, y.as_ref()?)));
    sa.iter()
        .zip(&sb)
        .chain(ca.iter().zip(&cb))
        .chain(known)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn merged_partials_of_pieces_identify_as_the_whole_file() {
    let dir = temp_dir("dyngen-cli", "partial-merge");
    let csv = simulate_ur5(&dir, 400, &["--noise", "0.01", "--seed", "7"]);
    let pieces = split(&csv, &dir, &[90, 250]);
    // Measured v and a, used as read: each piece's rows are the whole file's.
    for method in ["ols", "wls"] {
        let one = dir.join(format!("one-{method}.json"));
        assert_ok(&run!(
            "identify",
            ur5(),
            &csv,
            "--raw-states",
            "--method",
            method,
            "--params-json",
            &one
        ));
        let parts: Vec<PathBuf> = pieces
            .iter()
            .enumerate()
            .map(|(i, piece)| {
                let part = dir.join(format!("{method}-{i}.part"));
                let o = run!("identify", ur5(), piece, "--raw-states", "--partial", &part);
                assert_ok(&o);
                assert!(stdout(&o).contains("wrote the partial factor to"), "{}", stdout(&o));
                part
            })
            .collect();
        let merged = dir.join(format!("merged-{method}.json"));
        let o = run!(
            "identify",
            ur5(),
            "--merge",
            &parts[0],
            &parts[1],
            &parts[2],
            "--method",
            method,
            "--params-json",
            &merged
        );
        assert_ok(&o);
        assert!(
            stdout(&o).contains("3 recordings (401 samples, 2406 torque rows)"),
            "{}",
            stdout(&o)
        );
        let diff = max_difference(&merged, &one);
        println!("{method}: merged against one file, largest relative difference {diff:e}");
        assert!(diff <= 1e-12, "{method}: {diff:e}");
        let pre = ParameterReport::read(&merged)
            .unwrap()
            .prediction
            .unwrap()
            .preprocessing
            .unwrap();
        assert_eq!(pre.recordings.len(), 3);
        assert_eq!(pre.low_pass_states, Some(false));

        // A reduce tree: the first two merged into a partial, then the third.
        let first_two = dir.join(format!("{method}-01.part"));
        assert_ok(&run!(
            "identify",
            ur5(),
            "--merge",
            &parts[0],
            &parts[1],
            "--partial",
            &first_two
        ));
        let tree = dir.join(format!("tree-{method}.json"));
        assert_ok(&run!(
            "identify",
            ur5(),
            "--merge",
            &first_two,
            &parts[2],
            "--method",
            method,
            "--params-json",
            &tree
        ));
        let diff = max_difference(&tree, &one);
        assert!(diff <= 1e-12, "{method} tree: {diff:e}");
    }
}

/// The extra joint terms (but the load term, which needs a fit of the rows) go
/// through partial factors: the merge equals the one-file identification, and the
/// merged parameters predict with the terms.
#[test]
fn partials_carry_the_extra_joint_terms() {
    let dir = temp_dir("dyngen-cli", "partial-extras");
    let flags = [
        "--coulomb",
        "2",
        "--damping",
        "1",
        "--extra-terms",
        "asymmetric",
        "--extra-params",
        "0.5",
    ];
    let csv = simulate_ur5(&dir, 400, &[&flags[..], &["--noise", "0.01"]].concat());
    let pieces = split(&csv, &dir, &[150]);
    let model = [
        "--raw-states",
        "--friction",
        "sign",
        "--extra-terms",
        "asymmetric,ripple=1",
    ];
    let ur5_path = ur5();
    // `identify DATA <model> FLAG OUT`.
    let identify = |data: &Path, flag: &str, out: &Path| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["identify".as_ref(), ur5_path.as_os_str(), data.as_os_str()];
        args.extend(model.iter().map(std::ffi::OsStr::new));
        args.extend([std::ffi::OsStr::new(flag), out.as_os_str()]);
        assert_ok(&common::dyngen(&args));
    };
    let one = dir.join("one.json");
    identify(&csv, "--params-json", &one);
    let parts: Vec<PathBuf> = pieces
        .iter()
        .enumerate()
        .map(|(i, piece)| {
            let part = dir.join(format!("{i}.part"));
            identify(piece, "--partial", &part);
            part
        })
        .collect();
    let merged = dir.join("merged.json");
    assert_ok(&run!(
        "identify",
        ur5(),
        "--merge",
        &parts[0],
        &parts[1],
        "--params-json",
        &merged
    ));
    let diff = max_difference(&merged, &one);
    assert!(diff <= 1e-12, "{diff:e}");
    let extras = ParameterReport::read(&merged).unwrap().prediction.unwrap().extras;
    assert_eq!(extras.to_string(), "asymmetric,ripple=1");
    // Another list on the command line than the partials'.
    assert_error(
        &run!(
            "identify",
            ur5(),
            "--merge",
            &parts[0],
            &parts[1],
            "--extra-terms",
            "asymmetric"
        ),
        "--extra-terms: the partials were made with asymmetric,ripple=1, the command line gives asymmetric",
    );
}

#[test]
fn partials_that_do_not_merge_are_refused_naming_both_files() {
    let dir = temp_dir("dyngen-cli", "partial-mismatch");
    let csv = simulate_ur5(&dir, 60, &[]);
    let a = dir.join("a.part");
    assert_ok(&run!("identify", ur5(), &csv, "--partial", &a));
    // Other row options.
    let b = dir.join("b.part");
    assert_ok(&run!("identify", ur5(), &csv, "--partial", &b, "--cutoff", "5"));
    assert_error(
        &run!("identify", ur5(), "--merge", &a, &b),
        &format!(
            "{} and {} were made for different cutoff: 10 Hz against 5 Hz",
            a.display(),
            b.display()
        ),
    );
    // Another robot.
    let pend = pendulum(&dir, "pend.urdf", "1");
    let pend_csv = dir.join("pend.csv");
    assert_ok(&run!("simulate", &pend, "-o", &pend_csv, "--steps", "50"));
    let c = dir.join("c.part");
    assert_ok(&run!("identify", &pend, &pend_csv, "--partial", &c));
    assert_error(
        &run!("identify", ur5(), "--merge", &a, &c),
        &format!(
            "{} and {} were made for different robots: robot `ur5`",
            a.display(),
            c.display()
        ),
    );
    // Solved with another robot than the partials'.
    assert_error(
        &run!("identify", &pend, "--merge", &a),
        "pend.urdf: not the robot the partials were made for: different robots: the partials' robot `ur5`",
    );
    // A row option on the command line that is not the partials'.
    assert_error(
        &run!("identify", ur5(), "--merge", &a, "--friction", "sign"),
        "--friction: the partials were made with none, the command line gives sign",
    );
}

#[test]
fn options_partials_cannot_carry_are_refused() {
    let dir = temp_dir("dyngen-cli", "partial-refused");
    let csv = simulate_ur5(&dir, 40, &[]);
    let part = dir.join("x.part");
    for (extra, needle) in [
        (
            vec!["--friction", "auto"],
            "--friction auto cannot be written as a partial factor",
        ),
        (
            vec!["--friction", "stribeck"],
            "--friction stribeck and stribeck-smooth cannot be written",
        ),
        (
            vec!["--mode", "mim"],
            "--mode mim cannot be written as a partial factor",
        ),
        (
            vec!["--method", "wls"],
            "--method does not apply with --partial: it chooses the estimator",
        ),
        (
            vec!["--params-json", "p.json"],
            "--params-json does not apply with --partial",
        ),
        (
            vec!["--validate", "other.csv"],
            "--validate does not apply with --partial",
        ),
    ] {
        let mut args: Vec<std::ffi::OsString> = vec![
            "identify".into(),
            ur5().into(),
            csv.clone().into(),
            "--partial".into(),
            part.clone().into(),
        ];
        args.extend(extra.iter().map(Into::into));
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        assert_error(&common::dyngen(&args), needle);
        assert!(!part.exists());
    }
    assert_ok(&run!("identify", ur5(), &csv, "--partial", &part));
    assert_error(
        &run!("identify", ur5(), "--merge", &part, "--svg", dir.join("x.svg")),
        "--svg does not apply with --merge: it plots the recording's torques",
    );
    assert_error(
        &run!("identify", ur5(), "--merge", &part, "--degrees"),
        "--degrees does not apply with --merge",
    );
    // Not replaced without --force.
    assert_error(&run!("identify", ur5(), &csv, "--partial", &part), "--force");
}

#[test]
fn corrupt_and_other_version_partials_are_refused() {
    let dir = temp_dir("dyngen-cli", "partial-corrupt");
    let csv = simulate_ur5(&dir, 40, &[]);
    let part = dir.join("x.part");
    assert_ok(&run!("identify", ur5(), &csv, "--partial", &part));
    let text = std::fs::read_to_string(&part).unwrap();
    let cut = dir.join("cut.part");
    std::fs::write(&cut, &text[..text.len() / 3]).unwrap();
    assert_error(
        &run!("identify", ur5(), "--merge", &cut),
        &format!("{}: not a partial factor file (", cut.display()),
    );
    let newer = dir.join("newer.part");
    std::fs::write(&newer, text.replace("dyngen-partial/1", "dyngen-partial/2")).unwrap();
    assert_error(
        &run!("identify", ur5(), "--merge", &newer),
        "a `dyngen-partial/2` file; this dyngen reads partial factors of schema `dyngen-partial/1`",
    );
    assert_error(
        &run!("identify", ur5(), "--merge", &csv),
        &format!("{}: not a partial factor file", csv.display()),
    );
}
