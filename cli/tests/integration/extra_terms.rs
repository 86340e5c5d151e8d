//! `--extra-terms`: `dyngen simulate` adds direction-dependent viscous friction,
//! ripple and load-dependent friction to a recording, `dyngen identify` fits them
//! and records them in the parameters file, and `dyngen validate` predicts with
//! them; the automatic choice may leave them out; bad lists are refused.

use crate::common::{assert_error, assert_ok, overall, run, simulate_ur5, stdout, temp_dir, ur5};

const TERMS: &str = "asymmetric,ripple=1,load";
/// Fva, Ts1, Tc1, Fcs1, Fcc1, Fcl for every joint.
const PARAMS: &str = "0.4,0.2,-0.1,0.3,0.15,0.05";

#[test]
fn extra_terms_go_from_simulate_through_identify_to_validate() {
    let dir = temp_dir("dyngen-cli-extra-terms", "round-trip");
    let friction = [
        "--armature",
        "0.1",
        "--damping",
        "1.5",
        "--coulomb",
        "2",
        "--extra-terms",
        TERMS,
        "--extra-params",
        PARAMS,
        "--noise",
        "0.005",
    ];
    let csv = simulate_ur5(&dir, 1500, &friction);
    let params = dir.join("p.json");
    let o = run!(
        "identify",
        ur5(),
        &csv,
        "--friction",
        "sign",
        "--extra-terms",
        TERMS,
        "--params-json",
        &params,
        "--validate",
        &csv
    );
    assert_ok(&o);
    let out = stdout(&o);
    for name in ["Fva1", "Ts1_3", "Fcc1_6", "Fcl2"] {
        assert!(out.contains(name), "{name} in:\n{out}");
    }
    let with = overall(&out);
    // `validate` predicts from the parameters file as identify did.
    let o = run!("validate", ur5(), &params, &csv);
    assert_ok(&o);
    assert_eq!(overall(&stdout(&o)), with);
    let o = run!("identify", ur5(), &csv, "--friction", "sign", "--validate", &csv);
    assert_ok(&o);
    let without = overall(&stdout(&o));
    println!("relative error with the extra terms {with}, without {without}");
    assert!(with < 0.012 && without > 1.8 * with, "{with} {without}");
}

/// Motor ripple through the gear ratios: simulated, identified, recorded with the
/// ratios in the parameters file, and predicted by `validate` as by `identify`.
#[test]
fn motor_ripple_needs_and_keeps_the_gear_ratios() {
    let dir = temp_dir("dyngen-cli-extra-terms", "motor");
    let ripple = ["--extra-terms", "motor-ripple=1", "--gear-ratios", "101"];
    let csv = simulate_ur5(
        &dir,
        800,
        &[&ripple[..], &["--extra-params", "0.3,-0.2", "--coulomb", "1"]].concat(),
    );
    let params = dir.join("p.json");
    let o = run!(
        "identify",
        ur5(),
        &csv,
        "--friction",
        "sign",
        ripple[0],
        ripple[1],
        ripple[2],
        ripple[3],
        "--params-json",
        &params,
        "--validate",
        &csv
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(out.contains("Tms1_1") && out.contains("Tmc1_6"), "{out}");
    let o = run!("validate", ur5(), &params, &csv);
    assert_ok(&o);
    assert_eq!(overall(&stdout(&o)), overall(&out));
    assert_error(
        &run!(
            "identify",
            ur5(),
            &csv,
            "--friction",
            "sign",
            "--extra-terms",
            "motor-ripple=1"
        ),
        "motor-ripple needs each joint's gear ratio (--gear-ratios)",
    );
    assert_error(
        &run!(
            "identify",
            ur5(),
            &csv,
            "--friction",
            "sign",
            ripple[0],
            ripple[1],
            "--gear-ratios",
            "101,0"
        ),
        "--gear-ratios: 2 values for 6 joints",
    );
    assert_error(
        &run!(
            "identify",
            ur5(),
            &csv,
            "--friction",
            "sign",
            ripple[0],
            ripple[1],
            "--gear-ratios",
            "0"
        ),
        "joint 1's gear ratio must be finite and not 0, got 0",
    );
}

#[test]
fn bad_extra_terms_are_refused() {
    let dir = temp_dir("dyngen-cli-extra-terms", "refused");
    let csv = simulate_ur5(&dir, 100, &[]);
    assert_error(
        &run!("identify", ur5(), &csv, "--extra-terms", "asymetric"),
        "term 1 `asymetric` is unknown or repeated; valid: a comma-separated list of asymmetric, ripple=H",
    );
    assert_error(
        &run!("identify", ur5(), &csv, "--extra-terms", "ripple=9"),
        "`ripple=9`: the harmonics must be 1 to 8",
    );
    assert_error(
        &run!("identify", ur5(), &csv, "--friction", "none", "--extra-terms", "load"),
        "--extra-terms load extends the friction model: give --friction sign, smooth or auto as well",
    );
    assert_error(
        &run!(
            "identify",
            ur5(),
            &csv,
            "--friction",
            "stribeck",
            "--extra-terms",
            "load"
        ),
        "--extra-terms do not combine with Stribeck friction",
    );
    assert_error(
        &run!(
            "identify",
            ur5(),
            &csv,
            "--friction",
            "sign",
            "--extra-terms",
            "load",
            "--partial",
            dir.join("x.part")
        ),
        "--extra-terms load cannot be written as a partial factor",
    );
    let out = dir.join("x.csv");
    assert_error(
        &run!(
            "simulate",
            ur5(),
            "-o",
            &out,
            "--extra-terms",
            "asymmetric,load",
            "--extra-params",
            "1,2,3"
        ),
        "--extra-params: 3 values for 6 joints; give 2 for all joints or 12 (2 per joint, joint by joint)",
    );
    assert!(!out.exists());
}
