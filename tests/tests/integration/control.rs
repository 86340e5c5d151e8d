//! The control kernels of every shipped robot against Pinocchio 4.1 (fixtures in
//! `tests/fixtures/control/`, made by `scripts/make_control_fixtures.py`): frame
//! placements, Jacobians, velocities and classical accelerations in the three
//! reference frames, the `J̇v` drift, the centre of mass and its Jacobian, the
//! derivatives of inverse and forward dynamics and `M⁻¹`. Then the same functions
//! against central finite differences of the generated code itself.

use dyngen::{Pose, ReferenceFrame, Robot};
use dyngen_tests::tree12::Tree12;
use dyngen_tests::{json_numbers as nums, load_json, pose_vec, rel_err, Worst};
use robot_gripper_arm::GripperArm;
use robot_panda::Panda;
use robot_paper6::Paper6;
use robot_planar2::Planar2;
use robot_puma560::Puma560;
use robot_ur5::Ur5;
use serde_json::Value;

const TOL: f64 = 1e-10;
const REFS: [(ReferenceFrame, &str); 3] = [
    (ReferenceFrame::World, "world"),
    (ReferenceFrame::Local, "local"),
    (ReferenceFrame::LocalWorldAligned, "lwa"),
];

fn load(name: &str) -> Value {
    load_json(&format!("control/{name}.json"))
}

fn check<R: Robot>(fixture: &str) -> Worst {
    let fx = load(fixture);
    let who = R::NAME;
    let n = R::NV;
    let names: Vec<String> = fx["joint_names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, R::joint_names(), "{who}: joint order");
    // The same frames as Pinocchio's link frames, each on the same body.
    let frames = fx["frames"].as_array().unwrap();
    assert_eq!(frames.len(), R::MODEL.frames.len(), "{who}: frame count");
    let index: Vec<usize> = frames
        .iter()
        .map(|f| {
            let name = f["name"].as_str().unwrap();
            let k = R::MODEL
                .frame_index(name)
                .unwrap_or_else(|| panic!("{who}: no frame {name}"));
            assert_eq!(
                R::MODEL.frames[k].body as u64,
                f["parent_joint"].as_u64().unwrap(),
                "{who}: {name}'s body"
            );
            k
        })
        .collect();

    let params = R::nominal_params();
    let mut worst = Worst::new(|_| TOL);
    for (s, sample) in fx["samples"].as_array().unwrap().iter().enumerate() {
        let (q, v, a, tau) = (
            nums(&sample["q"]),
            nums(&sample["v"]),
            nums(&sample["a"]),
            nums(&sample["tau"]),
        );
        let zero = vec![0.0; n];
        for (f, want) in index.iter().zip(sample["frames"].as_array().unwrap()) {
            let placement = R::frame_placement(&q, *f).unwrap();
            worst.add("placement", who, s, &pose_vec(&placement), &nums(&want["oMf"]), 1.0);
            for (reference, key) in REFS {
                let mut jac = vec![0.0; 6 * n];
                let p = R::frame_jacobian(&q, *f, reference, &mut jac).unwrap();
                assert_eq!(
                    pose_vec(&p),
                    pose_vec(&placement),
                    "{who}: placement beside the Jacobian"
                );
                worst.add("jacobian", who, s, &jac, &nums(&want[format!("J_{key}").as_str()]), 1.0);
                let m = R::frame_motion(&q, &v, &a, *f).unwrap();
                worst.add(
                    "velocity",
                    who,
                    s,
                    &m.velocity_in(reference).to_array(),
                    &nums(&want[format!("v_{key}").as_str()]),
                    1.0,
                );
                let acc = m.classical_acceleration_in(reference).to_array();
                worst.add(
                    "classical acceleration",
                    who,
                    s,
                    &acc,
                    &nums(&want[format!("acc_{key}").as_str()]),
                    1.0,
                );
                let (mut j2, mut jdot) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
                R::frame_jacobian_time_variation(&q, &v, *f, reference, &mut j2, &mut jdot).unwrap();
                worst.add("jacobian beside J̇", who, s, &j2, &jac, 1e-300);
                worst.add("J̇", who, s, &jdot, &nums(&want[format!("dJ_{key}").as_str()]), 1.0);
                let drift = R::frame_motion(&q, &v, &zero, *f)
                    .unwrap()
                    .classical_acceleration_in(reference)
                    .to_array();
                worst.add(
                    "drift J̇v",
                    who,
                    s,
                    &drift,
                    &nums(&want[format!("drift_{key}").as_str()]),
                    1.0,
                );
            }
        }
        worst.add(
            "centre of mass",
            who,
            s,
            &R::center_of_mass(&q, params),
            &nums(&sample["com"]),
            1.0,
        );
        let mut jc = vec![0.0; 3 * n];
        R::com_jacobian(&q, params, &mut jc);
        worst.add("centre of mass Jacobian", who, s, &jc, &nums(&sample["Jcom"]), 1.0);
        let mut ag = vec![0.0; 6 * n];
        R::centroidal_map(&q, params, &mut ag);
        worst.add("centroidal map A_g", who, s, &ag, &nums(&sample["Ag"]), 1.0);
        // Ȧ_g v (Pinocchio's dAg is another matrix with the same product with v).
        let (mut a_g, mut a_dot) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
        R::centroidal_map_time_variation(&q, &v, params, &mut a_g, &mut a_dot);
        assert_eq!(a_g, ag, "{who}: A_g beside its time variation");
        let dagv: Vec<f64> = (0..6).map(|r| (0..n).map(|c| a_dot[r * n + c] * v[c]).sum()).collect();
        worst.add("Ȧ_g v", who, s, &dagv, &nums(&sample["dAg_v"]), 1.0);

        let (mut dq, mut dv, mut m) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        R::rnea_derivatives(&q, &v, &a, params, &mut dq, &mut dv, &mut m);
        worst.add("dtau/dq", who, s, &dq, &nums(&sample["dtau_dq"]), 1.0);
        worst.add("dtau/dv", who, s, &dv, &nums(&sample["dtau_dv"]), 1.0);
        worst.add("dtau/da = M", who, s, &m, &nums(&sample["M"]), 1.0);

        let (mut ddq, mut minv) = (vec![0.0; n], vec![0.0; n * n]);
        R::aba_derivatives(&q, &v, &tau, params, &mut ddq, &mut dq, &mut dv, &mut minv);
        worst.add("aba", who, s, &ddq, &nums(&sample["ddq"]), 1.0);
        worst.add("ddq/dq", who, s, &dq, &nums(&sample["ddq_dq"]), 1.0);
        worst.add("ddq/dv", who, s, &dv, &nums(&sample["ddq_dv"]), 1.0);
        worst.add("Minv", who, s, &minv, &nums(&sample["Minv"]), 1.0);
        let mut alone = vec![0.0; n * n];
        R::inverse_inertia(&q, params, &mut alone);
        worst.add("inverse_inertia", who, s, &alone, &nums(&sample["Minv"]), 1.0);
    }
    // A frame index beyond the frames is refused, not a panic.
    let nf = R::MODEL.frames.len();
    assert!(R::frame_placement(&vec![0.0; n], nf).is_none());
    assert!(R::frame_jacobian(&vec![0.0; n], nf, ReferenceFrame::Local, &mut vec![0.0; 6 * n]).is_none());
    worst
}

#[test]
fn control_kernels_match_pinocchio() {
    let all = [
        ("ur5", check::<Ur5>("ur5")),
        ("gripper_arm", check::<GripperArm>("gripper_arm")),
        ("planar2", check::<Planar2>("planar2")),
        ("paper6", check::<Paper6>("paper6")),
        ("puma560", check::<Puma560>("puma560")),
        ("panda", check::<Panda>("panda")),
        ("tree12", check::<Tree12>("tree12")),
    ];
    for (name, w) in &all {
        let line: Vec<String> = w.items.iter().map(|(k, e)| format!("{k} {e:.1e}")).collect();
        println!("{name}: {}", line.join(", "));
    }
}

/// Central differences of a function of `x` (each coordinate in turn), column by
/// column: `out[r][c] = ∂f_r/∂x_c`.
fn central<F: Fn(&[f64]) -> Vec<f64>>(x: &[f64], h: f64, f: F) -> Vec<Vec<f64>> {
    let rows = f(x).len();
    let mut d = vec![vec![0.0; x.len()]; rows];
    for c in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[c] += h;
        xm[c] -= h;
        let (fp, fm) = (f(&xp), f(&xm));
        for r in 0..rows {
            d[r][c] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    d
}

fn fd_err(got: &[f64], fd: &[Vec<f64>]) -> f64 {
    let want: Vec<f64> = fd.iter().flatten().copied().collect();
    rel_err(got, &want, 1.0)
}

/// The generated Jacobians, drift and derivatives against central differences of the
/// generated placements, velocities, rnea and aba, at random states (fixed seed).
fn finite_differences<R: Robot>() -> [f64; 6] {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
    let n = R::NV;
    let params = R::nominal_params();
    let mut worst = [0.0f64; 6];
    for _ in 0..5 {
        let q: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.5..1.5)).collect();
        let v: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let a: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let tau: Vec<f64> = (0..n).map(|_| rng.gen_range(-5.0..5.0)).collect();
        let h = 1e-6;
        for f in 0..R::MODEL.frames.len() {
            // Translation part of the Jacobian: d(position)/dq.
            let mut jac = vec![0.0; 6 * n];
            R::frame_jacobian(&q, f, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
            let fd = central(&q, h, |x| {
                let p: Pose<f64> = R::frame_placement(x, f).unwrap();
                p.translation.iter().copied().collect()
            });
            worst[0] = worst[0].max(fd_err(&jac[..3 * n], &fd));
            // The classical acceleration is d/dt of the velocity J(q) v along
            // q(t) = q + t v + t² a / 2.
            let vel_at = |t: f64| {
                let qt: Vec<f64> = (0..n).map(|i| q[i] + t * v[i] + 0.5 * t * t * a[i]).collect();
                let vt: Vec<f64> = (0..n).map(|i| v[i] + t * a[i]).collect();
                R::frame_motion(&qt, &vt, &a, f).unwrap().velocity.to_array()
            };
            let fd: Vec<f64> = (0..6).map(|r| (vel_at(h)[r] - vel_at(-h)[r]) / (2.0 * h)).collect();
            let acc = R::frame_motion(&q, &v, &a, f).unwrap().acceleration.to_array();
            worst[1] = worst[1].max(rel_err(&acc, &fd, 1.0));
        }
        let mut jc = vec![0.0; 3 * n];
        R::com_jacobian(&q, params, &mut jc);
        worst[2] = worst[2].max(fd_err(&jc, &central(&q, h, |x| R::center_of_mass(x, params).to_vec())));

        let (mut dq, mut dv, mut m) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        R::rnea_derivatives(&q, &v, &a, params, &mut dq, &mut dv, &mut m);
        let rnea = |q: &[f64], v: &[f64]| {
            let mut t = vec![0.0; n];
            R::rnea(q, v, &a, params, &mut t);
            t
        };
        worst[3] = worst[3].max(fd_err(&dq, &central(&q, h, |x| rnea(x, &v))));
        worst[3] = worst[3].max(fd_err(&dv, &central(&v, h, |x| rnea(&q, x))));

        let (mut ddq, mut minv) = (vec![0.0; n], vec![0.0; n * n]);
        R::aba_derivatives(&q, &v, &tau, params, &mut ddq, &mut dq, &mut dv, &mut minv);
        let aba = |q: &[f64], v: &[f64], tau: &[f64]| {
            let mut t = vec![0.0; n];
            R::aba(q, v, tau, params, &mut t);
            t
        };
        // Relative to the size of q̈, which reaches 1e4 on light wrists.
        let scale = ddq.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let fq = central(&q, h, |x| aba(x, &v, &tau));
        let fv = central(&v, h, |x| aba(&q, x, &tau));
        let ft = central(&tau, h, |x| aba(&q, &v, x));
        for (got, fd) in [(&dq, &fq), (&dv, &fv), (&minv, &ft)] {
            let want: Vec<f64> = fd.iter().flatten().copied().collect();
            let e = got.iter().zip(&want).map(|(g, w)| (g - w).abs()).fold(0.0, f64::max);
            worst[4] = worst[4].max(e / scale.max(want.iter().fold(1.0f64, |m, x| m.max(x.abs()))));
        }
        worst[5] = worst[5].max(rel_err(&ddq, &aba(&q, &v, &tau), 1.0));
    }
    worst
}

#[test]
fn control_kernels_match_finite_differences() {
    let all = [
        ("ur5", finite_differences::<Ur5>()),
        ("gripper_arm", finite_differences::<GripperArm>()),
        ("planar2", finite_differences::<Planar2>()),
        ("paper6", finite_differences::<Paper6>()),
        ("puma560", finite_differences::<Puma560>()),
        ("panda", finite_differences::<Panda>()),
        ("tree12", finite_differences::<Tree12>()),
    ];
    for (name, w) in &all {
        println!(
            "{name}: jacobian {:.1e}, classical acceleration {:.1e}, com jacobian {:.1e}, rnea derivatives {:.1e}, aba derivatives {:.1e}, ddq vs aba {:.1e}",
            w[0], w[1], w[2], w[3], w[4], w[5]
        );
        assert!(w[0] < 1e-7 && w[1] < 1e-6 && w[2] < 1e-7, "{name}: {w:?}");
        assert!(w[3] < 1e-6 && w[4] < 1e-6, "{name}: {w:?}");
        assert!(w[5] < 1e-12, "{name}: {w:?}");
    }
}

/// The planar arm of the paper with frames declared in the description: a tool at
/// the tip of body 2, a camera on body 1 turned a quarter turn about z, a mark on
/// the base.
mod with_frames {
    dyngen::robot! {
        name: Planar2Tool,
        gravity: [0.0, -9.81, 0.0],
        incidence: [[-1, 0], [1, -1], [0, 1]],
        joints: [revolute(z), revolute(z)],
        body_joint_vectors: {
            (0, 1): [0.0, 0.0, 0.0],
            (1, 1): [-0.25, 0.0, 0.0],
            (1, 2): [0.25, 0.0, 0.0],
            (2, 2): [-0.2, 0.0, 0.0],
        },
        bodies: {
            1: cylinder(mass: 5.0, radius: 0.04, length: 0.5, axis: x),
            2: cylinder(mass: 3.0, radius: 0.03, length: 0.4, axis: x),
        },
        frames: {
            tool: (2, [0.2, 0.0, 0.0]),
            camera: (1, [0.0, 0.05, 0.0], rest: [0.0, 0.0, 1.5707963267948966]),
            base_mark: (0, [0.1, 0.0, 0.0]),
        },
    }
}

#[test]
fn frames_declared_in_the_description() {
    use with_frames::{Planar2Tool, Planar2ToolFrame};
    assert_eq!(Planar2ToolFrame::from_name("tool"), Some(Planar2ToolFrame::Tool));
    assert_eq!(Planar2ToolFrame::Tool.body(), 2);
    assert_eq!(Planar2ToolFrame::Camera.body(), 1);
    assert_eq!(Planar2ToolFrame::BaseMark.body(), 0);
    assert_eq!(Planar2ToolFrame::from_name("gripper"), None);
    let (q1, q2) = (0.4f64, -1.1f64);
    let q = [q1, q2];
    // The tip of a 0.5 m and a 0.4 m link in the x–y plane.
    let tip = Planar2Tool::frame_placement(&q, Planar2ToolFrame::Tool).translation;
    let want = [
        0.5 * q1.cos() + 0.4 * (q1 + q2).cos(),
        0.5 * q1.sin() + 0.4 * (q1 + q2).sin(),
        0.0,
    ];
    for d in 0..3 {
        assert!((tip[d] - want[d]).abs() < 1e-15, "tool {tip:?} vs {want:?}");
    }
    // Its Jacobian in world-aligned axes: the planar 2-link Jacobian.
    let mut j = dyngen::FrameJacobian::<f64, 2>::default();
    Planar2Tool::frame_jacobian(&q, Planar2ToolFrame::Tool, ReferenceFrame::LocalWorldAligned, &mut j);
    let jx = [-want[1], -0.4 * (q1 + q2).sin()];
    let jy = [want[0], 0.4 * (q1 + q2).cos()];
    for c in 0..2 {
        assert!((j.jacobian[0][c] - jx[c]).abs() < 1e-15 && (j.jacobian[1][c] - jy[c]).abs() < 1e-15);
        assert_eq!(j.jacobian[5][c], 1.0);
    }
    // The camera: body 1's centre (0.25 m out) plus 0.05 m across, turned by q1 + π/2.
    let cam = Planar2Tool::frame_placement(&q, Planar2ToolFrame::Camera);
    let (s, c) = q1.sin_cos();
    let at = [0.25 * c - 0.05 * s, 0.25 * s + 0.05 * c];
    assert!((cam.translation[0] - at[0]).abs() < 1e-15 && (cam.translation[1] - at[1]).abs() < 1e-15);
    let (s90, c90) = (q1 + std::f64::consts::FRAC_PI_2).sin_cos();
    assert!((cam.rotation[(0, 0)] - c90).abs() < 1e-15 && (cam.rotation[(1, 0)] - s90).abs() < 1e-15);
    // The base mark does not move; all its Jacobian columns are zero.
    let mark = Planar2Tool::frame_placement(&q, Planar2ToolFrame::BaseMark);
    assert_eq!(mark.translation, dyngen::nalgebra::Vector3::new(0.1, 0.0, 0.0));
    Planar2Tool::frame_jacobian(&q, Planar2ToolFrame::BaseMark, ReferenceFrame::World, &mut j);
    assert!(j.jacobian.iter().flatten().all(|&x| x == 0.0));
    // Frames add no mass: the dynamics equal the plain arm's.
    let p = Planar2Tool::NOMINAL_PARAMS;
    assert_eq!(p, Planar2::NOMINAL_PARAMS);
    assert_eq!(
        Planar2Tool::rnea(&q, &[0.3, -0.2], &[1.0, 2.0], &p),
        Planar2::rnea(&q, &[0.3, -0.2], &[1.0, 2.0], &p)
    );
}

/// `aba_joints_derivatives` (rotor inertias, viscous and smooth Coulomb friction, an
/// offset) against central differences of the generated `aba_joints`.
macro_rules! joints_derivatives_fd {
    ($robot:ty) => {{
        const N: usize = <$robot>::NV;
        let params = <$robot>::NOMINAL_PARAMS;
        let mut jp = [0.0; 4 * N];
        for j in 0..N {
            jp[4 * j..4 * j + 4].copy_from_slice(&[0.05 + 0.01 * j as f64, 0.8, 1.5 - 0.1 * j as f64, 0.2]);
        }
        let coulomb = dyngen::Coulomb::smooth(0.05).unwrap();
        let q: [f64; N] = std::array::from_fn(|i| 0.3 * i as f64 - 0.7);
        let v: [f64; N] = std::array::from_fn(|i| 0.04 * i as f64 - 0.1);
        let tau: [f64; N] = std::array::from_fn(|i| 2.0 - 0.5 * i as f64);
        let mut d = dyngen::AbaDerivatives::<f64, N>::default();
        <$robot>::aba_joints_derivatives(&q, &v, &tau, &params, &jp, coulomb, &mut d);
        let aba = |q: &[f64; N], v: &[f64; N], tau: &[f64; N]| <$robot>::aba_joints(q, v, tau, &params, &jp, coulomb);
        let ddq = aba(&q, &v, &tau);
        let mut worst = rel_err(&d.ddq, &ddq, 1.0);
        let h = 1e-6;
        let scale = ddq.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for c in 0..N {
            let step = |x: &[f64; N], s: f64| {
                let mut y = *x;
                y[c] += s;
                y
            };
            let dq: Vec<f64> = aba(&step(&q, h), &v, &tau)
                .iter()
                .zip(aba(&step(&q, -h), &v, &tau))
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect();
            let dv: Vec<f64> = aba(&q, &step(&v, h), &tau)
                .iter()
                .zip(aba(&q, &step(&v, -h), &tau))
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect();
            let dt: Vec<f64> = aba(&q, &v, &step(&tau, h))
                .iter()
                .zip(aba(&q, &v, &step(&tau, -h)))
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect();
            for r in 0..N {
                for (got, want) in [(d.ddq_dq[r][c], dq[r]), (d.ddq_dv[r][c], dv[r]), (d.minv[r][c], dt[r])] {
                    worst = worst.max((got - want).abs() / scale);
                }
            }
        }
        worst
    }};
}

#[test]
fn aba_joints_derivatives_match_finite_differences() {
    for (name, e) in [
        ("ur5", joints_derivatives_fd!(Ur5)),
        ("panda", joints_derivatives_fd!(Panda)),
    ] {
        println!("{name}: aba_joints derivatives against differences {e:.1e}");
        assert!(e < 1e-6, "{name}: {e:e}");
    }
}
