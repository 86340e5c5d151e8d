//! The learned residual (`identify --residual`, `validate --residual`) on the
//! MuJoCo fixtures: where MuJoCo applies joint effects the physical model has no
//! term for (direction-dependent viscous friction and ripple), the per-joint
//! networks are kept and predict the other recording better than the physical
//! model alone; where it applies none (the friction `auto` models), they are not
//! kept and no file is written.

use crate::common::{assert_exit, assert_ok, overall, run, stdout, temp_dir, ur5};
use std::path::PathBuf;

fn fixture(set: &str, name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures")
        .join(set)
        .join(name)
}

/// The overall error of the prediction printed after `label`.
fn overall_after(out: &str, label: &str) -> f64 {
    let at = out.find(label).unwrap_or_else(|| panic!("no `{label}` in:\n{out}"));
    overall(&out[at..])
}

#[test]
fn the_residual_is_kept_where_the_model_misses_effects_and_predicts_better() {
    let dir = temp_dir("dyngen-residual", "extras");
    let (params, net) = (dir.join("ur5.json"), dir.join("residual.json"));
    let validation = fixture("mujoco_extras", "ur5_validate.csv");
    let o = run!(
        "identify",
        ur5(),
        fixture("mujoco_extras", "ur5_identify.csv"),
        "--friction",
        "auto",
        "--cutoff",
        "5",
        "--params-json",
        &params,
        "--residual",
        &net,
        "--validate",
        &validation
    );
    assert_ok(&o);
    let out = stdout(&o);
    let line = out
        .lines()
        .find(|l| l.starts_with("learned residual"))
        .expect("a residual line");
    assert!(line.ends_with(": kept"), "{out}");
    assert!(
        out.contains(&format!("wrote the residual network to {}", net.display())),
        "{out}"
    );
    let physical = overall(&out);
    let with = overall_after(&out, "with the learned residual");
    println!("physical model {physical}, with the residual {with}");
    assert!(with < 0.98 * physical, "{out}");
    // `validate` adds the same networks to the same prediction.
    let o = run!("validate", ur5(), &params, &validation, "--residual", &net);
    assert_ok(&o);
    assert!(stdout(&o).contains("with the learned residual of"), "{}", stdout(&o));
    assert!((overall(&stdout(&o)) - with).abs() < 1e-4, "{}", stdout(&o));
    // An existing file is not replaced without --force.
    let o = run!(
        "identify",
        ur5(),
        fixture("mujoco_extras", "ur5_identify.csv"),
        "--friction",
        "auto",
        "--residual",
        &net
    );
    assert_exit(&o, 4, &net.display().to_string());
}

#[test]
fn the_residual_is_not_kept_where_the_model_explains_the_torques() {
    let dir = temp_dir("dyngen-residual", "plain");
    let net = dir.join("residual.json");
    let o = run!(
        "identify",
        ur5(),
        fixture("mujoco", "ur5_identify.csv"),
        "--friction",
        "auto",
        "--cutoff",
        "5",
        "--residual",
        &net
    );
    assert_ok(&o);
    let out = stdout(&o);
    assert!(out.contains("not kept (it must lower the error by 1 %)"), "{out}");
    assert!(out.contains("not written"), "{out}");
    assert!(!net.exists());
}

#[test]
fn bad_residual_uses_are_refused() {
    let dir = temp_dir("dyngen-residual", "errors");
    let data = fixture("mujoco", "ur5_identify.csv");
    assert_exit(
        &run!(
            "identify",
            ur5(),
            &data,
            "--friction",
            "sign",
            "--partial",
            dir.join("a.part"),
            "--residual",
            dir.join("r.json")
        ),
        2,
        "--residual trains on the recording's samples, which partial factors do not keep",
    );
    // A parameters file is no residual, and a residual of another robot does not fit.
    let params = dir.join("ur5.json");
    assert_ok(&run!(
        "identify",
        ur5(),
        &data,
        "--friction",
        "sign",
        "--params-json",
        &params
    ));
    assert_exit(
        &run!("validate", ur5(), &params, &data, "--residual", &params),
        3,
        &params.display().to_string(),
    );
    let net = dir.join("two.json");
    let two = dyngen_nim::residual::ResidualNet::new(
        (0..2)
            .map(|j| dyngen_nim::Mlp::new(&[dyngen_nim::residual::FEATURES, 4, 1], j).unwrap())
            .collect(),
    )
    .unwrap();
    two.save(&net, false).unwrap();
    assert_exit(
        &run!("validate", ur5(), &params, &data, "--residual", &net),
        3,
        "residual networks (one per joint): expected 6, found 2",
    );
}
