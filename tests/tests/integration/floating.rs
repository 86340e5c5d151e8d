//! The floating-base robots (`robot-quadruped12`, `robot-humanoid31`: the root link on
//! a free flyer) against Pinocchio 4.1 with `JointModelFreeFlyer`, and the mobile arm on
//! two planar joints against its `JointModelPlanar` (fixtures in
//! `tests/fixtures/floating/`, made by `scripts/make_floating_fixtures.py`): every
//! generated algorithm, the base rows included, frames and Jacobians, the centre of
//! mass and the centroidal map. Then identities of the generated code itself.

use dyngen::{Frames, InverseDynamics, JointDynamics, MassMatrix, ReferenceFrame, Robot, RobotDescription};
use dyngen_tests::mobile_arm::MobileArm;
use dyngen_tests::{json_numbers as nums, load_json, pose_vec, rel_err, Worst};
use robot_humanoid31::Humanoid31;
use robot_quadruped12::Quadruped12;
use serde_json::Value;

const TOL: f64 = 1e-12;
/// Against Pinocchio, the forward-dynamics derivatives and `M⁻¹` of the humanoid
/// (`M`'s condition number up to 2.5e5, entries of 1e3) differ by up to 1.3e-12: that
/// is Pinocchio's own error, which `forward_derivatives_against_extended_precision`
/// measures (Pinocchio 8.0e-13 and 1.3e-12 from the `long double` values, dyngen 2.3e-15
/// and 3.2e-14, held to 1e-12 there).
const TOL_FORWARD_DERIVATIVES: f64 = 5e-12;

fn load(name: &str) -> Value {
    load_json(&format!("floating/{name}.json"))
}

/// The forward-dynamics derivatives and `M⁻¹` get [`TOL_FORWARD_DERIVATIVES`].
fn tolerance(what: &str) -> f64 {
    if what.starts_with("aba_derivatives") || what == "inverse_inertia" {
        TOL_FORWARD_DERIVATIVES
    } else {
        TOL
    }
}

fn check<R: Robot>(fixture: &str) -> Worst {
    let fx = load(fixture);
    let who = R::NAME;
    let (nq, nv, nb) = (R::NQ, R::NV, R::NBODIES);
    let model = &fx["model"];
    assert_eq!(nv, model["nv"].as_u64().unwrap() as usize, "{who}: nv");
    let samples = fx["samples"].as_array().unwrap();
    assert_eq!(nq, samples[0]["q"].as_array().unwrap().len(), "{who}: nq");
    let names: Vec<&str> = model["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(names, R::joint_names(), "{who}: joint order");
    let parents: Vec<usize> = nums(&model["parents"]).iter().map(|&p| p as usize).collect();
    assert_eq!(parents, R::parents(), "{who}: parents");
    let mut worst = Worst::new(tolerance);
    worst.add("params", who, 0, R::nominal_params(), &nums(&model["params"]), 1.0);

    let params = R::nominal_params();
    for (s, x) in samples.iter().enumerate() {
        let (q, v, a) = (nums(&x["q"]), nums(&x["v"]), nums(&x["a"]));
        let mut out = vec![0.0; nv];
        R::rnea(&q, &v, &a, params, &mut out);
        worst.add("rnea", who, s, &out, &nums(&x["tau"]), 1.0);
        R::nonlinear_effects(&q, &v, params, &mut out);
        worst.add("nonlinear_effects", who, s, &out, &nums(&x["nle"]), 1.0);
        R::generalized_gravity(&q, params, &mut out);
        worst.add("generalized_gravity", who, s, &out, &nums(&x["gravity"]), 1.0);
        let mut m = vec![0.0; nv * nv];
        R::crba(&q, params, &mut m);
        worst.add("crba", who, s, &m, &nums(&x["M"]), 1.0);
        R::aba(&q, &v, &nums(&x["tau_rand"]), params, &mut out);
        worst.add("aba", who, s, &out, &nums(&x["ddq"]), 1.0);
        let mut y = vec![0.0; nv * 10 * nb];
        R::joint_torque_regressor(&q, &v, &a, &mut y);
        worst.add("joint_torque_regressor", who, s, &y, &nums(&x["Y"]), 1.0);
        let mut poses = vec![dyngen::Pose::default(); nb];
        R::forward_kinematics(&q, &mut poses);
        let got: Vec<f64> = poses.iter().flat_map(pose_vec).collect();
        worst.add("forward_kinematics", who, s, &got, &nums(&x["oMi"]), 1.0);
        for f in x["frames"].as_array().unwrap() {
            let name = f["name"].as_str().unwrap();
            let k = R::MODEL
                .frame_index(name)
                .unwrap_or_else(|| panic!("{who}: no frame {name}"));
            let mut jac = vec![0.0; 6 * nv];
            let pose = R::frame_jacobian(&q, k, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
            worst.add("frame_placement", who, s, &pose_vec(&pose), &nums(&f["placement"]), 1.0);
            worst.add("frame_jacobian", who, s, &jac, &nums(&f["jacobian"]), 1.0);
        }
        worst.add(
            "center_of_mass",
            who,
            s,
            &R::center_of_mass(&q, params),
            &nums(&x["com"]),
            1.0,
        );
        let mut jc = vec![0.0; 3 * nv];
        R::com_jacobian(&q, params, &mut jc);
        worst.add("com_jacobian", who, s, &jc, &nums(&x["Jcom"]), 1.0);
        let (mut ag, mut ag_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
        R::centroidal_map(&q, params, &mut ag);
        worst.add("centroidal_map", who, s, &ag, &nums(&x["Ag"]), 1.0);
        R::centroidal_map_time_variation(&q, &v, params, &mut ag, &mut ag_dot);
        let hg: Vec<f64> = (0..6).map(|r| (0..nv).map(|c| ag[r * nv + c] * v[c]).sum()).collect();
        worst.add("centroidal momentum A_g v", who, s, &hg, &nums(&x["hg"]), 1.0);
        let dag_v: Vec<f64> = (0..6)
            .map(|r| (0..nv).map(|c| ag_dot[r * nv + c] * v[c]).sum())
            .collect();
        worst.add(
            "centroidal_map_time_variation (Ȧ_g v)",
            who,
            s,
            &dag_v,
            &nums(&x["dAg_v"]),
            1.0,
        );
        // The base rows of rnea are the wrench on the base, joint_wrenches' first: all
        // of it for a free flyer; for a planar joint (normal z) the forces along x and
        // y and the torque about z.
        let mut w = vec![dyngen::Wrench::default(); nb];
        R::joint_wrenches(&q, &v, &a, params, &mut w);
        R::rnea(&q, &v, &a, params, &mut out);
        let base = dyngen_tests::wrench_vec(&w[0]);
        let (rows, base) = match R::MODEL.joints[0].kind {
            dyngen::JointType::FreeFlyer => (6, base.to_vec()),
            dyngen::JointType::Planar => (3, vec![base[0], base[1], base[5]]),
            k => panic!("{who}: joint 1 is {k:?}"),
        };
        worst.add("base rows of rnea = joint 1's wrench", who, s, &out[..rows], &base, 1.0);
        let (mut dq, mut dv, mut mm) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
        R::rnea_derivatives(&q, &v, &a, params, &mut dq, &mut dv, &mut mm);
        worst.add("rnea_derivatives ∂τ/∂q", who, s, &dq, &nums(&x["dtau_dq"]), 1.0);
        worst.add("rnea_derivatives ∂τ/∂v", who, s, &dv, &nums(&x["dtau_dv"]), 1.0);
        worst.add("rnea_derivatives ∂τ/∂a", who, s, &mm, &nums(&x["M"]), 1.0);
        let mut minv = vec![0.0; nv * nv];
        R::aba_derivatives(
            &q,
            &v,
            &nums(&x["tau_rand"]),
            params,
            &mut out,
            &mut dq,
            &mut dv,
            &mut minv,
        );
        worst.add("aba_derivatives q̈", who, s, &out, &nums(&x["ddq"]), 1.0);
        worst.add("aba_derivatives ∂q̈/∂q", who, s, &dq, &nums(&x["ddq_dq"]), 1.0);
        worst.add("aba_derivatives ∂q̈/∂v", who, s, &dv, &nums(&x["ddq_dv"]), 1.0);
        worst.add("aba_derivatives M⁻¹", who, s, &minv, &nums(&x["Minv"]), 1.0);
        let mut alone = vec![0.0; nv * nv];
        R::inverse_inertia(&q, params, &mut alone);
        worst.add("inverse_inertia", who, s, &alone, &nums(&x["Minv"]), 1.0);
    }
    worst
}

#[test]
fn quadruped12_matches_pinocchio_free_flyer() {
    let w = check::<Quadruped12>("quadruped12");
    eprintln!("quadruped12: {:?}", w.items);
}

/// Two planar joints (the base on the ground, a tilted stage at the wrist) against
/// Pinocchio's `JointModelPlanar`, converted from its `(x, y, cos θ, sin θ)`.
#[test]
fn mobile_arm_matches_pinocchio_planar() {
    let w = check::<MobileArm>("mobile_arm");
    eprintln!("mobile_arm: {:?}", w.items);
}

#[test]
fn humanoid31_matches_pinocchio_free_flyer() {
    let w = check::<Humanoid31>("humanoid31");
    eprintln!("humanoid31: {:?}", w.items);
}

/// Floating-base identification from the base rows (contact wrenches), the joint
/// rows (joint torques) and both, on simulated samples of the quadruped with noise:
/// which base parameters each gives, and that the estimate recovers them.
#[test]
fn quadruped12_identification_from_base_and_joint_rows() {
    use dyngen_identify::floating::{Contact, FloatingBase, FloatingRows};
    use dyngen_model::base::analyse_rows;
    use dyngen_model::Parameterisation;
    use rand::{Rng, SeedableRng};

    type R = Quadruped12;
    let nv = <R as RobotDescription>::NV;
    let model = dyngen_reference::model_from_static(&<R as RobotDescription>::MODEL);
    let base_rows: Vec<usize> = (0..6).collect();
    let joint_rows: Vec<usize> = (6..nv).collect();
    let all_rows: Vec<usize> = (0..nv).collect();
    let from_base = analyse_rows(&model, Parameterisation::Standard, &base_rows);
    let from_joints = analyse_rows(&model, Parameterisation::Standard, &joint_rows);
    let from_all = analyse_rows(&model, Parameterisation::Standard, &all_rows);
    eprintln!(
        "quadruped12 base parameters: base rows {}, joint rows {}, all rows {} (of {})",
        from_base.count(),
        from_joints.count(),
        from_all.count(),
        <R as RobotDescription>::NPARAMS
    );
    // The base rows alone determine every base parameter; the joint torques alone do
    // not see the trunk (body 1) at all.
    assert_eq!(from_base.count(), from_all.count());
    assert!(from_joints.count() < from_all.count());
    assert!(
        from_joints.independent.iter().all(|&c| c >= 10),
        "joint rows see no trunk parameter"
    );
    assert!(from_all.is_consistent() && from_base.is_consistent());

    // Simulated recording: random states, generalized forces from rnea plus noise.
    let truth = <R as RobotDescription>::nominal_params();
    let states = dyngen_model::sample::sample_states(&model, 400, 11);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let noise = 0.05;
    let mut sets = Vec::new();
    for rows in [FloatingRows::Base, FloatingRows::Joints, FloatingRows::All] {
        let mut id = FloatingBase::<R>::new(rows).unwrap();
        for s in &states {
            let mut tau = vec![0.0; nv];
            <R as InverseDynamics>::rnea(&s.q, &s.v, &s.a, truth, &mut tau);
            for t in &mut tau {
                *t += rng.gen_range(-noise..noise);
            }
            id.push(&s.q, &s.v, &s.a, &tau).unwrap();
        }
        sets.push((rows, id));
    }
    let opts = dyngen_identify::Options::default();
    for ((rows, id), base) in sets.iter().zip([&from_base, &from_joints, &from_all]) {
        let est = id.ols(&opts).unwrap();
        assert_eq!(est.rank, base.count(), "{rows:?}: rank");
        // Every base parameter of the analysis is recovered: β = K π.
        for (k, row) in base.k.iter().enumerate() {
            let value = est.value_of(row).expect("identifiable");
            let want: f64 = row.iter().zip(truth).map(|(a, b)| a * b).sum();
            let scale = row.iter().map(|x| x.abs()).sum::<f64>().max(1.0);
            assert!(
                (value - want).abs() < 0.02 * scale,
                "{rows:?}: {}: {value} vs {want}",
                base.groupings[k]
            );
        }
        eprintln!(
            "{rows:?}: rank {}, condition number {:.1e}, residual rms {:.3} (noise rms {:.3})",
            est.rank,
            est.condition_number,
            est.residuals.rms,
            noise / 3f64.sqrt()
        );
    }

    // Contact wrenches instead of the base rows: a foot force on each foot frame,
    // mapped through the frames' Jacobians, gives the same data.
    let feet: Vec<usize> = (0..<R as RobotDescription>::MODEL.frames.len())
        .filter(|&f| <R as RobotDescription>::MODEL.frames[f].name.ends_with("foot"))
        .collect();
    assert_eq!(feet.len(), 4, "four feet");
    let s = &states[0];
    let mut tau = vec![0.0; nv];
    <R as InverseDynamics>::rnea(&s.q, &s.v, &s.a, truth, &mut tau);
    // One contact at a foot: the base rows of Jᵀ F carry the whole generalized force
    // on the base; choose F so that the dynamics hold, from the base rows.
    let mut jac = vec![0.0; 6 * nv];
    <R as Frames>::frame_jacobian(&s.q, feet[0], ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
    // J[:, 0..6] is invertible (a rigid transform of the base twist): solve Jbᵀ w = τ_base.
    let jb = nalgebra::Matrix6::from_fn(|r, c| jac[r * nv + c]);
    let w = jb
        .transpose()
        .lu()
        .solve(&nalgebra::Vector6::from_column_slice(&tau[..6]))
        .unwrap();
    let joint_torques: Vec<f64> = (6..nv)
        .map(|d| tau[d] - (0..6).map(|r| jac[r * nv + d] * w[r]).sum::<f64>())
        .collect();
    let mut by_contact = FloatingBase::<R>::new(FloatingRows::All).unwrap();
    let contact = Contact {
        frame: feet[0],
        force: [w[0], w[1], w[2]],
        moment: [w[3], w[4], w[5]],
    };
    by_contact
        .push_contacts(&s.q, &s.v, &s.a, &joint_torques, &[contact])
        .unwrap();
    let mut direct = FloatingBase::<R>::new(FloatingRows::All).unwrap();
    direct.push(&s.q, &s.v, &s.a, &tau).unwrap();
    let (a, b) = (by_contact.accumulator(), direct.accumulator());
    assert_eq!(a.rows(), b.rows());
    // The same equations: the nominal parameters fit both exactly.
    let fit = |acc: &dyngen_identify::Accumulator| acc.ols(&opts).unwrap().residuals.rms;
    assert!(fit(a) < 1e-9 && fit(b) < 1e-9);

    // Errors: a fixed-base robot, a frame that does not exist, wrong lengths.
    assert!(FloatingBase::<robot_panda::Panda>::new(FloatingRows::All).is_err());
    let bad = Contact { frame: 999, ..contact };
    let e = by_contact
        .push_contacts(&s.q, &s.v, &s.a, &joint_torques, &[bad])
        .unwrap_err();
    assert!(e.to_string().contains("999"), "{e}");
    assert!(direct.push(&s.q[..5], &s.v, &s.a, &tau).is_err());
}

dyngen::robot! {
    name: Floater,
    incidence: [
        [-1,  0,  0],
        [ 1, -1,  0],
        [ 0,  1, -1],
        [ 0,  0,  1],
    ],
    joints: [free(), spherical(rest: [0.0, 0.0, 0.5]), revolute(y)],
    body_joint_vectors: {
        (0, 1): [0.0, 0.0, 0.0],
        (1, 1): [0.0, 0.0, 0.0], (1, 2): [0.2, 0.0, 0.0],
        (2, 2): [-0.1, 0.0, 0.0], (2, 3): [0.1, 0.0, 0.0],
        (3, 3): [-0.1, 0.0, 0.0],
    },
    bodies: {
        1: principal(mass: 5.0, moments: [0.1, 0.2, 0.25]),
        2: cylinder(mass: 1.0, radius: 0.03, length: 0.2, axis: x),
        3: cylinder(mass: 0.5, radius: 0.02, length: 0.2, axis: x),
    },
}

/// A floating base written in the `robot!` DSL (`free()`, `spherical()`): the base
/// rows of `rnea` at rest carry the weight; `aba` inverts `rnea`; `M` is symmetric
/// positive definite with the total mass in its linear block.
#[test]
fn dsl_floating_base_with_a_ball_joint() {
    assert_eq!((Floater::NQ, Floater::NV), (12, 10));
    let mut q = [0.0; 12];
    q[6] = 1.0;
    q[10] = 1.0;
    let g = Floater::generalized_gravity(&q, &Floater::NOMINAL_PARAMS);
    assert!((g[2] - 6.5 * 9.81).abs() < 1e-12, "{g:?}");
    let mut states = dyngen_model::sample::sample_states(&dyngen_reference::model_from_static(&Floater::MODEL), 5, 3);
    for s in states.drain(..) {
        let q: [f64; 12] = s.q.try_into().unwrap();
        let v: [f64; 10] = s.v.try_into().unwrap();
        let a: [f64; 10] = s.a.try_into().unwrap();
        let tau = Floater::rnea(&q, &v, &a, &Floater::NOMINAL_PARAMS);
        let back = Floater::aba(&q, &v, &tau, &Floater::NOMINAL_PARAMS);
        assert!(rel_err(&back, &a, 1.0) < 1e-12);
        let mut m = [[0.0; 10]; 10];
        Floater::crba(&q, &Floater::NOMINAL_PARAMS, &mut m);
        for r in 0..3 {
            assert!((m[r][r] - 6.5).abs() < 1e-12);
        }
    }
}

/// The joint models on a floating robot (parameters per velocity coordinate, the free
/// flyer's six included): `aba_joints` inverts `rnea_joints` with rotor inertias and
/// friction everywhere, `crba_joints` adds the rotor inertias to `M`'s diagonal, and
/// the widened regressor reproduces `rnea_joints`.
#[test]
fn joint_models_invert_and_match_the_regressor_on_floating_robots() {
    joint_models_invert_and_match_the_regressor::<Quadruped12>();
    // Above `Config::compose_above`'s 24 coordinates, `aba_joints` is composed:
    // `M + diag(Ia)` solved by the tree's `LᵀDL` factorisation.
    joint_models_invert_and_match_the_regressor::<Humanoid31>();
}

fn joint_models_invert_and_match_the_regressor<R: Robot>() {
    let (nv, np) = (<R as RobotDescription>::NV, <R as RobotDescription>::NPARAMS);
    let model = dyngen_reference::model_from_static(&<R as RobotDescription>::MODEL);
    let params = <R as RobotDescription>::nominal_params();
    let joint_params: Vec<f64> = (0..nv)
        .flat_map(|d| [0.01 * (d + 1) as f64, 0.2, 0.3 + 0.01 * d as f64, -0.05])
        .collect();
    assert_eq!(joint_params.len(), <R as RobotDescription>::NJOINT_PARAMS);
    let coulomb = dyngen::Coulomb::smooth(0.05).unwrap();
    for s in dyngen_model::sample::sample_states(&model, 4, 21) {
        let mut tau = vec![0.0; nv];
        <R as JointDynamics>::rnea_joints(&s.q, &s.v, &s.a, params, &joint_params, coulomb, &mut tau);
        let mut back = vec![0.0; nv];
        <R as JointDynamics>::aba_joints(&s.q, &s.v, &tau, params, &joint_params, coulomb, &mut back);
        assert!(rel_err(&back, &s.a, 1.0) < 1e-12, "{back:?} vs {:?}", s.a);
        let (mut m, mut mj) = (vec![0.0; nv * nv], vec![0.0; nv * nv]);
        <R as MassMatrix>::crba(&s.q, params, &mut m);
        <R as JointDynamics>::crba_joints(&s.q, params, &joint_params, &mut mj);
        for d in 0..nv {
            m[d * nv + d] += joint_params[4 * d];
        }
        assert!(rel_err(&mj, &m, 1.0) < 1e-14);
        let mut y = vec![0.0; nv * (np + 4 * nv)];
        <R as JointDynamics>::torque_regressor_joints(&s.q, &s.v, &s.a, coulomb, &mut y);
        let x: Vec<f64> = params.iter().chain(&joint_params).copied().collect();
        let from_y: Vec<f64> = (0..nv)
            .map(|r| (0..x.len()).map(|c| y[r * x.len() + c] * x[c]).sum())
            .collect();
        assert!(rel_err(&from_y, &tau, 1.0) < 1e-12);
    }
}

/// The humanoid's `aba_joints_derivatives` (above `Config::compose_above`'s 24
/// coordinates: composed of `inverse_inertia`, `nonlinear_effects` and
/// `rnea_derivatives`) with rotor inertias, viscous and smooth Coulomb friction and an
/// offset, against central differences of the generated `aba_joints`: every column of
/// `∂q̈/∂v` and `∂q̈/∂τ`, and the columns of `∂q̈/∂q` of the revolute joints (their
/// coordinates are plain angles; the free flyer's tangent columns are checked against
/// Pinocchio in `humanoid31_matches_pinocchio_free_flyer`). With zero joint parameters
/// it is `aba_derivatives`.
#[test]
fn humanoid31_aba_joints_derivatives_match_finite_differences() {
    type H = Humanoid31;
    const NV: usize = H::NV;
    let model = dyngen_reference::model_from_static(&<H as RobotDescription>::MODEL);
    let params = H::NOMINAL_PARAMS;
    let mut jp = [0.0; 4 * NV];
    for j in 0..NV {
        jp[4 * j..4 * j + 4].copy_from_slice(&[0.05 + 0.01 * j as f64, 0.8, 1.5 - 0.03 * j as f64, 0.2]);
    }
    let coulomb = dyngen::Coulomb::smooth(0.05).unwrap();
    let s = &dyngen_model::sample::sample_states(&model, 1, 5)[0];
    let q: [f64; NV + 1] = s.q.clone().try_into().unwrap();
    let v: [f64; NV] = s.v.clone().try_into().unwrap();
    let tau: [f64; NV] = std::array::from_fn(|i| 2.0 - 0.1 * i as f64);
    let mut d = dyngen::AbaDerivatives::<f64, NV>::default();
    H::aba_joints_derivatives(&q, &v, &tau, &params, &jp, coulomb, &mut d);
    let aba = |q: &[f64; NV + 1], v: &[f64; NV], tau: &[f64; NV]| H::aba_joints(q, v, tau, &params, &jp, coulomb);
    let ddq = aba(&q, &v, &tau);
    assert!(rel_err(&d.ddq, &ddq, 1.0) < 1e-12, "{:?} vs {ddq:?}", d.ddq);
    let central = |f: &dyn Fn(f64) -> [f64; NV], h: f64| -> Vec<f64> {
        f(h).iter().zip(f(-h)).map(|(p, m)| (p - m) / (2.0 * h)).collect()
    };
    let h = 1e-6;
    let scale = ddq.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    let mut worst: f64 = 0.0;
    for c in 0..NV {
        let mut columns = vec![
            (
                central(
                    &|e| {
                        let mut w = v;
                        w[c] += e;
                        aba(&q, &w, &tau)
                    },
                    h,
                ),
                d.ddq_dv.map(|row| row[c]),
            ),
            (
                central(
                    &|e| {
                        let mut t = tau;
                        t[c] += e;
                        aba(&q, &v, &t)
                    },
                    h,
                ),
                d.minv.map(|row| row[c]),
            ),
        ];
        if c >= 6 {
            // Velocity coordinate c ≥ 6 is the angle q[c + 1].
            let fd = central(
                &|e| {
                    let mut p = q;
                    p[c + 1] += e;
                    aba(&p, &v, &tau)
                },
                h,
            );
            columns.push((fd, d.ddq_dq.map(|row| row[c])));
        }
        for (fd, got) in columns {
            for r in 0..NV {
                worst = worst.max((got[r] - fd[r]).abs() / scale);
            }
        }
    }
    eprintln!("humanoid31: aba_joints_derivatives against differences {worst:.1e}");
    assert!(worst < 1e-6, "{worst:e}");

    let zeros = [0.0; 4 * NV];
    let mut dj = dyngen::AbaDerivatives::<f64, NV>::default();
    H::aba_joints_derivatives(&q, &v, &tau, &params, &zeros, coulomb, &mut dj);
    let mut da = dyngen::AbaDerivatives::<f64, NV>::default();
    H::aba_derivatives(&q, &v, &tau, &params, &mut da);
    assert_eq!(dj, da);
}

/// `Y_b β = τ`, `Y_pb β_p = τ` and `Y_θ θ = τ` on states the base analysis never saw,
/// worst relative error over the three. The humanoid's base regressors are composed
/// (the independent columns of the full ones), and so is its principal regressor
/// (the standard one times each body's `P_i`); the quadruped's are generated on their
/// own.
fn base_regressors_reproduce_rnea<R: Robot>() -> f64 {
    let model = dyngen_reference::model_from_static(&R::MODEL);
    let nv = R::NV;
    let (p, theta) = (R::nominal_params(), R::nominal_theta());
    let (mut beta, mut beta_p) = (vec![0.0; R::NBASE], vec![0.0; R::NBASE_PRINCIPAL]);
    R::base_params(p, &mut beta);
    R::principal_base_params(theta, &mut beta_p);
    let times = |y: &[f64], x: &[f64]| -> Vec<f64> {
        y.chunks(x.len())
            .map(|row| row.iter().zip(x).map(|(a, b)| a * b).sum())
            .collect()
    };
    let mut worst: f64 = 0.0;
    for s in dyngen_model::sample::sample_states(&model, 3, 9) {
        let mut tau = vec![0.0; nv];
        R::rnea(&s.q, &s.v, &s.a, p, &mut tau);
        let mut y = vec![0.0; nv * R::NBASE];
        R::base_regressor(&s.q, &s.v, &s.a, &mut y);
        worst = worst.max(rel_err(&times(&y, &beta), &tau, 1.0));
        let mut y = vec![0.0; nv * R::NBASE_PRINCIPAL];
        R::principal_base_regressor(&s.q, &s.v, &s.a, &mut y);
        worst = worst.max(rel_err(&times(&y, &beta_p), &tau, 1.0));
        let mut y = vec![0.0; nv * R::NTHETA];
        R::principal_regressor(&s.q, &s.v, &s.a, &mut y);
        worst = worst.max(rel_err(&times(&y, theta), &tau, 1.0));
    }
    worst
}

#[test]
fn base_regressors_reproduce_rnea_on_floating_robots() {
    for (name, e) in [
        ("quadruped12", base_regressors_reproduce_rnea::<Quadruped12>()),
        ("humanoid31", base_regressors_reproduce_rnea::<Humanoid31>()),
    ] {
        eprintln!("{name}: base regressors against rnea {e:.1e}");
        assert!(e < 1e-10, "{name}: {e:e}");
    }
}

/// The humanoid's `frame_motion` (above `Config::compose_above`'s 24 coordinates: `J v` and
/// `J a + J̇ v` from the frame's Jacobian and its time variation) against differences
/// along the path `q(t) = q ⊕ (v t + a t²/2)`, whose velocity is `v` and acceleration
/// `a` at `t = 0`: the frame origin's velocity and classical acceleration, and the
/// angular velocity from `R(h) R(−h)ᵀ = exp(2h [ω]×)`, for every frame.
#[test]
fn humanoid31_frame_motion_matches_differences() {
    type H = Humanoid31;
    const NV: usize = H::NV;
    let model = dyngen_reference::model_from_static(&<H as RobotDescription>::MODEL);
    let s = &dyngen_model::sample::sample_states(&model, 1, 13)[0];
    let q: [f64; NV + 1] = s.q.clone().try_into().unwrap();
    let v: [f64; NV] = s.v.clone().try_into().unwrap();
    let a: [f64; NV] = s.a.clone().try_into().unwrap();
    let at = |t: f64| -> [f64; NV + 1] {
        let step: Vec<f64> = v.iter().zip(&a).map(|(v, a)| v * t + 0.5 * a * t * t).collect();
        let mut out = [0.0; NV + 1];
        dyngen::configuration::integrate(&<H as RobotDescription>::MODEL, &q, &step, &mut out).unwrap();
        out
    };
    let h = 1e-4;
    let (qp, qm) = (at(h), at(-h));
    let mut worst: f64 = 0.0;
    for frame in robot_humanoid31::Humanoid31Frame::ALL {
        let m = H::frame_motion(&q, &v, &a, frame);
        let (p0, pp, pm) = (
            H::frame_placement(&q, frame),
            H::frame_placement(&qp, frame),
            H::frame_placement(&qm, frame),
        );
        let scale = 1.0 + m.velocity.linear.norm() + m.acceleration.linear.norm() + m.velocity.angular.norm();
        for k in 0..3 {
            let vel = (pp.translation[k] - pm.translation[k]) / (2.0 * h);
            let acc = (pp.translation[k] - 2.0 * p0.translation[k] + pm.translation[k]) / (h * h);
            worst = worst.max((vel - m.velocity.linear[k]).abs() / scale);
            worst = worst.max((acc - m.acceleration.linear[k]).abs() / scale);
        }
        let turn = pp.rotation * pm.rotation.transpose();
        let w = [
            turn[(2, 1)] - turn[(1, 2)],
            turn[(0, 2)] - turn[(2, 0)],
            turn[(1, 0)] - turn[(0, 1)],
        ];
        for k in 0..3 {
            worst = worst.max((w[k] / (4.0 * h) - m.velocity.angular[k]).abs() / scale);
        }
    }
    eprintln!("humanoid31: frame_motion against differences {worst:.1e}");
    assert!(worst < 1e-5, "{worst:e}");
}

/// dyngen's `M⁻¹` and `∂q̈/∂q` and Pinocchio's, both against the extended-precision
/// evaluation of the fixture (`*_extended.json`: `M⁻¹` of Pinocchio's `M` and
/// `−M⁻¹ ∂τ/∂q` in `long double`, from `scripts/forward_derivative_conditioning.py
/// --write`). Returns the worst relative errors `[dyngen M⁻¹, dyngen ∂q̈/∂q,
/// Pinocchio M⁻¹, Pinocchio ∂q̈/∂q]`: how far each double-precision result is from the
/// better one, which is what `M`'s conditioning (κ up to 2.5e5 on the humanoid)
/// allows rather than how far two of them are from each other.
fn against_extended<R: Robot>(name: &str) -> [f64; 4] {
    let (fx, ext) = (load(name), load(&format!("{name}_extended")));
    let (nv, params) = (R::NV, R::nominal_params());
    let mut worst = [0.0f64; 4];
    let samples = fx["samples"].as_array().unwrap();
    for (x, e) in samples.iter().zip(ext["samples"].as_array().unwrap()) {
        let (q, v, tau) = (nums(&x["q"]), nums(&x["v"]), nums(&x["tau_rand"]));
        let (mut ddq, mut dq, mut dv, mut minv) = (
            vec![0.0; nv],
            vec![0.0; nv * nv],
            vec![0.0; nv * nv],
            vec![0.0; nv * nv],
        );
        R::aba_derivatives(&q, &v, &tau, params, &mut ddq, &mut dq, &mut dv, &mut minv);
        let (want_minv, want_dq) = (nums(&e["Minv"]), nums(&e["ddq_dq"]));
        for (k, (got, want)) in [
            (&minv, &want_minv),
            (&dq, &want_dq),
            (&nums(&x["Minv"]), &want_minv),
            (&nums(&x["ddq_dq"]), &want_dq),
        ]
        .into_iter()
        .enumerate()
        {
            worst[k] = worst[k].max(rel_err(got, want, 1.0));
        }
    }
    worst
}

#[test]
fn forward_derivatives_against_extended_precision() {
    for (name, w) in [
        ("quadruped12", against_extended::<Quadruped12>("quadruped12")),
        ("humanoid31", against_extended::<Humanoid31>("humanoid31")),
    ] {
        eprintln!(
            "{name} against long double: dyngen M⁻¹ {:.1e}, ∂q̈/∂q {:.1e}; Pinocchio M⁻¹ {:.1e}, ∂q̈/∂q {:.1e}",
            w[0], w[1], w[2], w[3]
        );
        assert!(w[0] <= 1e-12 && w[1] <= 1e-12, "{name}: {w:?}");
    }
}

dyngen::robot! {
    name: Tilted,
    incidence: [
        [-1,  0,  0],
        [ 1, -1,  0],
        [ 0,  1, -1],
        [ 0,  0,  1],
    ],
    joints: [planar([0.6, 0.0, 0.8]), revolute(y), planar(-z, rest: [0.2, -0.4, 0.3])],
    body_joint_vectors: {
        (0, 1): [0.1, 0.0, 0.2],
        (1, 1): [0.0, 0.0, 0.0], (1, 2): [0.2, 0.05, 0.0],
        (2, 2): [-0.1, 0.0, 0.0], (2, 3): [0.15, 0.0, 0.02],
        (3, 3): [-0.05, 0.01, 0.0],
    },
    bodies: {
        1: principal(mass: 5.0, moments: [0.1, 0.2, 0.25]),
        2: cylinder(mass: 1.0, radius: 0.03, length: 0.2, axis: x),
        3: principal(mass: 0.5, moments: [0.01, 0.02, 0.025]),
    },
}

/// The generated code's tangent convention on planar joints, against central
/// differences along `q ⊕ h e_c` (`configuration::integrate`), for every velocity
/// coordinate `c`: each frame's Jacobian (`LOCAL_WORLD_ALIGNED`: the origin's velocity,
/// the angular velocity from `R(h) R(−h)ᵀ`) and `∂τ/∂q`, `∂τ/∂v` of `rnea`. Also
/// `aba` inverts `rnea`. Worst error relative to `1 + |value|`.
fn tangent_checks<R: Robot>(seed: u64) -> f64 {
    let (nq, nv) = (R::NQ, R::NV);
    let model = dyngen_reference::model_from_static(&R::MODEL);
    let params = R::nominal_params();
    let frames = R::MODEL.frames.len();
    assert!(frames > 0, "{}: no frames to check", R::NAME);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for s in dyngen_model::sample::sample_states(&model, 3, seed) {
        let (q, v, a) = (&s.q, &s.v, &s.a);
        let moved = |c: usize, t: f64| {
            let mut step = vec![0.0; nv];
            step[c] = t;
            let mut out = vec![0.0; nq];
            dyngen::configuration::integrate(&R::MODEL, q, &step, &mut out).unwrap();
            out
        };
        let mut tau = vec![0.0; nv];
        R::rnea(q, v, a, params, &mut tau);
        let mut back = vec![0.0; nv];
        R::aba(q, v, &tau, params, &mut back);
        worst = worst.max(rel_err(&back, a, 1.0));
        let (mut dq, mut dv, mut m) = (vec![0.0; nv * nv], vec![0.0; nv * nv], vec![0.0; nv * nv]);
        R::rnea_derivatives(q, v, a, params, &mut dq, &mut dv, &mut m);
        let mut jac = vec![0.0; 6 * nv];
        for c in 0..nv {
            let (qp, qm) = (moved(c, h), moved(c, -h));
            let (mut tp, mut tm) = (vec![0.0; nv], vec![0.0; nv]);
            R::rnea(&qp, v, a, params, &mut tp);
            R::rnea(&qm, v, a, params, &mut tm);
            let (mut vp, mut vm) = (v.clone(), v.clone());
            vp[c] += h;
            vm[c] -= h;
            let (mut up, mut um) = (vec![0.0; nv], vec![0.0; nv]);
            R::rnea(q, &vp, a, params, &mut up);
            R::rnea(q, &vm, a, params, &mut um);
            for r in 0..nv {
                let scale = 1.0 + dq[r * nv + c].abs() + dv[r * nv + c].abs();
                worst = worst.max(((tp[r] - tm[r]) / (2.0 * h) - dq[r * nv + c]).abs() / scale);
                worst = worst.max(((up[r] - um[r]) / (2.0 * h) - dv[r * nv + c]).abs() / scale);
            }
            for f in 0..frames {
                R::frame_jacobian(q, f, ReferenceFrame::LocalWorldAligned, &mut jac).unwrap();
                let (pp, pm) = (R::frame_placement(&qp, f).unwrap(), R::frame_placement(&qm, f).unwrap());
                let turn = pp.rotation * pm.rotation.transpose();
                let w = [
                    turn[(2, 1)] - turn[(1, 2)],
                    turn[(0, 2)] - turn[(2, 0)],
                    turn[(1, 0)] - turn[(0, 1)],
                ];
                for k in 0..3 {
                    let lin = (pp.translation[k] - pm.translation[k]) / (2.0 * h);
                    let (jl, ja) = (jac[k * nv + c], jac[(3 + k) * nv + c]);
                    worst = worst.max((lin - jl).abs() / (1.0 + jl.abs()));
                    worst = worst.max((w[k] / (4.0 * h) - ja).abs() / (1.0 + ja.abs()));
                }
            }
        }
    }
    worst
}

/// Planar joints with tilted normals (`[0.6, 0, 0.8]` on the ground, `−z` under a
/// turned origin): the kinematics and the derivatives follow `q ⊕ v`, and every
/// body of a planar joint moves in its plane: the origin's displacement is normal to
/// the plane's normal and the turn is about it.
#[test]
fn planar_joints_follow_the_configuration_manifold() {
    let (tilted, mobile) = (tangent_checks::<Tilted>(3), tangent_checks::<MobileArm>(4));
    eprintln!("planar joints against differences along q ⊕ h e: tilted {tilted:.1e}, mobile_arm {mobile:.1e}");
    assert!(
        tilted < 1e-7 && mobile < 1e-7,
        "tilted {tilted:e}, mobile_arm {mobile:e}"
    );

    // Joint 1 of `Tilted` moves body 1 in the plane through its origin normal to n.
    let n = [0.6, 0.0, 0.8];
    let (q0, q1) = ([0.0; 7], [0.7, -0.4, 1.1, 0.3, 0.0, 0.0, 0.0]);
    let body1 = Tilted::MODEL.frames.iter().position(|f| f.body == 1).unwrap();
    let placement = |q: &[f64]| <Tilted as Frames>::frame_placement(q, body1).unwrap();
    let (p0, p1) = (placement(&q0), placement(&q1));
    let d = p1.translation - p0.translation;
    assert!((d[0] * n[0] + d[1] * n[1] + d[2] * n[2]).abs() < 1e-15, "{d:?}");
    assert!((d.norm() - (0.7f64.hypot(0.4))).abs() < 1e-15, "{d:?}");
    let turned = p1.rotation * p0.rotation.transpose() * dyngen::nalgebra::Vector3::from(n);
    assert!((0..3).all(|k| (turned[k] - n[k]).abs() < 1e-15), "{turned:?}");
}
