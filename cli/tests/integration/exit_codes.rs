//! Each kind of failure has its own exit code (documented in `dyngen --help`).

use crate::common::{assert_exit, run, simulate_ur5, stdout, temp_dir, ur5};

#[test]
fn exit_codes_say_what_kind_of_failure_it_was() {
    let dir = temp_dir("dyngen-cli", "exit-codes");
    // 2: usage, from clap and from option values.
    assert_exit(&run!("identify"), 2, "");
    assert_exit(&run!("info", ur5(), "--no-such-flag"), 2, "--no-such-flag");
    assert_exit(
        &run!("generate", ur5(), "--name", "not a type"),
        2,
        "not a valid Rust type name",
    );
    let csv = simulate_ur5(&dir, 20, &[]);
    assert_exit(
        &run!("identify", ur5(), csv, "--cutoff", "-1"),
        2,
        "--cutoff -1: out of range; expected a number with 0 < x ≤ 1000000 (Hz)",
    );
    assert_exit(
        &run!("demo", "--draws", "0"),
        2,
        "--draws 0: out of range; expected a whole number from 1 to 10000000",
    );

    // 3: an input file that is missing or invalid.
    assert_exit(&run!("info", dir.join("missing.urdf")), 3, "missing.urdf");
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "t,q1,tau1\n0,0,0\n0.1,oops,0\n0.2,0,0\n").unwrap();
    let pendulum = dir.join("pendulum.urdf");
    std::fs::write(
        &pendulum,
        r#"<robot name="p"><link name="b"/><link name="l"><inertial><mass value="1"/>
        <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="j" type="continuous"><parent link="b"/><child link="l"/><axis xyz="0 0 1"/></joint></robot>"#,
    )
    .unwrap();
    assert_exit(&run!("identify", pendulum, bad), 3, "line 3");

    // 4: an output that exists without --force.
    let o = run!("simulate", ur5(), "-o", csv);
    assert_exit(&o, 4, "--force");

    // 0 for help, with the codes listed.
    let help = run!("--help");
    assert_eq!(help.status.code(), Some(0));
    assert!(stdout(&help).contains("Exit codes:") && stdout(&help).contains("4  an output file exists"));
}
