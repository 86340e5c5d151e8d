//! Identities between the algorithms on random states of models with every joint
//! type (ball and free joints from MJCF, planar and prismatic joints from URDF):
//! aba inverts rnea (with and without rotor inertia), crba's columns are rnea's
//! differences, the regressor times the parameters is rnea, and the Jacobian maps
//! velocities to the frame velocity rnea's forward pass would give (checked by a
//! finite difference of the placement); the derivatives and time variations against
//! central differences.

use dyngen_algo::{
    aba, aba_derivatives, body_motions, centroidal_map, centroidal_map_time_variation, compute_frame_jacobian, crba,
    forward_kinematics, frame_classical_acceleration, frame_jacobian, frame_jacobian_time_variation, frame_velocity,
    joint_torque_regressor, joint_wrench_regressor, rnea, rnea_derivatives, DualWorkspace, JointType, Multibody,
    ReferenceFrame, Se3, Workspace,
};
use dyngen_model::{load_robot, load_urdf_options, LoadOptions};
use rand::{Rng, SeedableRng};
use std::path::Path;

fn models() -> Vec<(&'static str, Multibody)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = Vec::new();
    for file in [
        "tests/fixtures/mjcf/floating.xml",
        "tests/fixtures/mjcf/armature.xml",
        "tests/fixtures/mobile_arm.urdf",
    ] {
        out.push((file, load_robot(&root.join(file)).unwrap().multibody().unwrap()));
    }
    let options = LoadOptions {
        free_flyer: true,
        ..LoadOptions::default()
    };
    let humanoid = load_urdf_options(&root.join("robots/humanoid31/humanoid31.urdf"), options).unwrap();
    out.push(("humanoid31 on a free flyer", humanoid.multibody().unwrap()));
    out
}

fn random_q(body: &Multibody, rng: &mut impl Rng) -> Vec<f64> {
    let mut q: Vec<f64> = body.neutral().iter().map(|x| x + rng.gen_range(-1.0..1.0)).collect();
    body.normalize(&mut q);
    q
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0f64, |s, x| s.max(x.abs()));
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn the_algorithms_agree_with_each_other() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for (name, body) in models() {
        let (nq, nv, nb) = (body.nq(), body.nv(), body.bodies());
        assert!(body.joints.iter().any(|j| j.kind != JointType::Revolute), "{name}");
        let mut ws = Workspace::new(&body, ());
        let params = body.params.clone();
        for _ in 0..5 {
            let q = random_q(&body, &mut rng);
            assert_eq!(q.len(), nq);
            let v: Vec<f64> = (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let a: Vec<f64> = (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let zero = vec![0.0; nv];
            let mut tau = vec![0.0; nv];
            rnea(&body, &mut ws, &q, &v, &a, &params, &mut tau);

            let mut qdd = vec![0.0; nv];
            aba(&body, &mut ws, &q, &v, &tau, &params, &[], &mut qdd);
            assert!(
                max_diff(&qdd, &a) < 1e-10,
                "{name}: aba(rnea(a)) = a: {:e}",
                max_diff(&qdd, &a)
            );

            // With rotor inertia: τ + Ia a is what makes a.
            let armature: Vec<f64> = (0..nv).map(|_| rng.gen_range(0.0..0.5)).collect();
            let with: Vec<f64> = (0..nv).map(|d| tau[d] + armature[d] * a[d]).collect();
            aba(&body, &mut ws, &q, &v, &with, &params, &armature, &mut qdd);
            assert!(
                max_diff(&qdd, &a) < 1e-10,
                "{name}: aba with armature: {:e}",
                max_diff(&qdd, &a)
            );

            let mut m = vec![0.0; nv * nv];
            crba(&body, &mut ws, &q, &params, &mut m);
            let mut bias = vec![0.0; nv];
            rnea(&body, &mut ws, &q, &v, &zero, &params, &mut bias);
            let ma: Vec<f64> = (0..nv)
                .map(|r| (0..nv).map(|c| m[r * nv + c] * a[c]).sum::<f64>() + bias[r])
                .collect();
            assert!(
                max_diff(&ma, &tau) < 1e-10,
                "{name}: M a + h = rnea: {:e}",
                max_diff(&ma, &tau)
            );

            let mut y = vec![0.0; nv * 10 * nb];
            joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
            let ypi: Vec<f64> = (0..nv)
                .map(|r| (0..10 * nb).map(|c| y[r * 10 * nb + c] * params[c]).sum())
                .collect();
            assert!(
                max_diff(&ypi, &tau) < 1e-10,
                "{name}: Y π = rnea: {:e}",
                max_diff(&ypi, &tau)
            );

            // The wrench regressor times the parameters is every joint's wrench.
            let mut w = vec![0.0; 6 * nb * 10 * nb];
            joint_wrench_regressor(&body, &mut ws, &q, &v, &a, &mut w);
            rnea(&body, &mut ws, &q, &v, &a, &params, &mut tau);
            let wrenches: Vec<f64> = ws.force[1..].iter().flat_map(|f| f.to_array()).collect();
            let wpi: Vec<f64> = (0..6 * nb)
                .map(|r| (0..10 * nb).map(|c| w[r * 10 * nb + c] * params[c]).sum())
                .collect();
            assert!(
                max_diff(&wpi, &wrenches) < 1e-10,
                "{name}: W π = f: {:e}",
                max_diff(&wpi, &wrenches)
            );

            // The LOCAL Jacobian maps q̇ to the body's own spatial velocity.
            let mut jac = vec![0.0; 6 * nv];
            body_motions(&body, &mut ws, &q, &v, &a);
            frame_jacobian(
                &body,
                &ws,
                nb,
                &Se3::identity(0.0, 1.0),
                ReferenceFrame::Local,
                &mut jac,
            );
            let jv: Vec<f64> = (0..6).map(|r| (0..nv).map(|c| jac[r * nv + c] * v[c]).sum()).collect();
            let own = ws.velocity[nb].to_array();
            assert!(
                max_diff(&jv, &own) < 1e-12,
                "{name}: J v = v_body: {:e}",
                max_diff(&jv, &own)
            );
            // The same Jacobian from q alone, the path's kinematics only.
            let mut fresh = Workspace::new(&body, ());
            let mut jac2 = vec![0.0; 6 * nv];
            let origin = Se3::identity(0.0, 1.0);
            compute_frame_jacobian(&body, &mut fresh, &q, nb, &origin, ReferenceFrame::Local, &mut jac2);
            assert_eq!(jac, jac2, "{name}: compute_frame_jacobian");

            // The LOCAL_WORLD_ALIGNED Jacobian's linear rows are the velocity of the
            // last body's origin: a central difference of its position along a step
            // of the configuration (positions moved by the joint's own rules).
            forward_kinematics(&body, &mut ws, &q);
            frame_jacobian(
                &body,
                &ws,
                nb,
                &Se3::identity(0.0, 1.0),
                ReferenceFrame::LocalWorldAligned,
                &mut jac,
            );
            let jv: Vec<f64> = (0..3).map(|r| (0..nv).map(|c| jac[r * nv + c] * v[c]).sum()).collect();
            let h = 1e-6;
            let position = |step: f64, ws: &mut Workspace<f64>| {
                let q1 = integrate(&body, &q, &v, step);
                forward_kinematics(&body, ws, &q1);
                ws.world[nb].translation
            };
            let (p1, p0) = (position(h, &mut ws), position(-h, &mut ws));
            let fd: Vec<f64> = (0..3).map(|k| (p1[k] - p0[k]) / (2.0 * h)).collect();
            assert!(max_diff(&jv, &fd) < 1e-7, "{name}: J v = ṗ: {:e}", max_diff(&jv, &fd));
        }
    }
}

/// `q ⊕ v t` to first order in `t`, enough for a central difference: `q + q̇ t` with
/// `q̇` from each joint's rule ([`dyngen_algo::Joint::integrate_tangent`]).
fn integrate(body: &Multibody, q: &[f64], v: &[f64], t: f64) -> Vec<f64> {
    let mut out = q.to_vec();
    let mut dq = [0.0; 7];
    for j in &body.joints {
        let (qs, vs) = (j.q_offset..j.q_offset + j.nq(), j.v_offset..j.v_offset + j.nv());
        j.integrate_tangent((), &q[qs.clone()], &v[vs], &mut dq[..j.nq()]);
        for (k, i) in qs.enumerate() {
            out[i] += dq[k] * t;
        }
    }
    out
}

/// The central difference `(f(+h) − f(−h)) / 2h` of a vector function.
fn difference(f: &mut dyn FnMut(f64) -> Vec<f64>, h: f64) -> Vec<f64> {
    let (p, m) = (f(h), f(-h));
    p.iter().zip(&m).map(|(a, b)| (a - b) / (2.0 * h)).collect()
}

/// Column `c` of an `rows × cols` row-major matrix.
fn column(m: &[f64], cols: usize, c: usize) -> Vec<f64> {
    m.iter().skip(c).step_by(cols).copied().collect()
}

/// The derivatives, time variations and classical accelerations that run the
/// algorithms on dual numbers, against central differences of the algorithms on
/// `f64` along each joint's own motion (ball joints, free flyers, planar and
/// prismatic joints included), and `M⁻¹ (M + diag Ia) = E` with rotor inertia.
#[test]
fn derivatives_are_the_differences_of_the_algorithms() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    let h = 1e-6;
    for (name, body) in models() {
        let (nv, nb) = (body.nv(), body.bodies());
        let params = body.params.clone();
        let mut ws = Workspace::new(&body, ());
        let mut dual8 = DualWorkspace::<f64, 8>::new(&body, ());
        let mut dual1 = DualWorkspace::<f64, 1>::new(&body, ());
        let q = random_q(&body, &mut rng);
        let v: Vec<f64> = (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let a: Vec<f64> = (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let armature: Vec<f64> = (0..nv).map(|_| rng.gen_range(0.0..0.1)).collect();
        let unit = |d: usize| -> Vec<f64> { (0..nv).map(|k| f64::from(u8::from(k == d))).collect() };
        let shifted = |x: &[f64], d: usize, t: f64| -> Vec<f64> {
            let mut y = x.to_vec();
            y[d] += t;
            y
        };
        let mut worst = 0.0f64;
        let mut check = |what: &str, ours: &[f64], fd: &[f64]| {
            let e = max_diff(ours, fd);
            assert!(e < 1e-6, "{name}: {what}: {e:e}");
            worst = worst.max(e);
        };

        let [mut dq, mut dv, mut m] = [(); 3].map(|_| vec![0.0; nv * nv]);
        rnea_derivatives(
            &body, &mut dual8, &mut ws, &q, &v, &a, &params, &mut dq, &mut dv, &mut m,
        );
        let mut tau = vec![0.0; nv];
        for d in 0..nv {
            let mut along_q = |t: f64| {
                rnea(
                    &body,
                    &mut ws,
                    &integrate(&body, &q, &unit(d), t),
                    &v,
                    &a,
                    &params,
                    &mut tau,
                );
                tau.clone()
            };
            check("∂τ/∂q", &column(&dq, nv, d), &difference(&mut along_q, h));
            let mut along_v = |t: f64| {
                rnea(&body, &mut ws, &q, &shifted(&v, d, t), &a, &params, &mut tau);
                tau.clone()
            };
            check("∂τ/∂v", &column(&dv, nv, d), &difference(&mut along_v, h));
        }
        let mut crba_m = vec![0.0; nv * nv];
        crba(&body, &mut ws, &q, &params, &mut crba_m);
        assert_eq!(m, crba_m, "{name}: ∂τ/∂a is crba's M");

        rnea(&body, &mut ws, &q, &v, &a, &params, &mut tau);
        let (mut ddq, mut minv) = (vec![0.0; nv], vec![0.0; nv * nv]);
        aba_derivatives(
            &body, &mut dual8, &mut ws, &q, &v, &tau, &params, &armature, &mut ddq, &mut dq, &mut dv, &mut minv,
        );
        let mut plain = vec![0.0; nv];
        aba(&body, &mut ws, &q, &v, &tau, &params, &armature, &mut plain);
        assert_eq!(ddq, plain, "{name}: the derivatives' q̈ is aba's");
        for d in 0..nv {
            let mut along_q = |t: f64| {
                aba(
                    &body,
                    &mut ws,
                    &integrate(&body, &q, &unit(d), t),
                    &v,
                    &tau,
                    &params,
                    &armature,
                    &mut plain,
                );
                plain.clone()
            };
            check("∂q̈/∂q", &column(&dq, nv, d), &difference(&mut along_q, h));
            let mut along_v = |t: f64| {
                aba(
                    &body,
                    &mut ws,
                    &q,
                    &shifted(&v, d, t),
                    &tau,
                    &params,
                    &armature,
                    &mut plain,
                );
                plain.clone()
            };
            check("∂q̈/∂v", &column(&dv, nv, d), &difference(&mut along_v, h));
        }
        // M⁻¹ (M + diag Ia) = E.
        let product: Vec<f64> = (0..nv * nv)
            .map(|rc| {
                let (r, c) = (rc / nv, rc % nv);
                (0..nv)
                    .map(|k| minv[r * nv + k] * (crba_m[k * nv + c] + if k == c { armature[c] } else { 0.0 }))
                    .sum()
            })
            .collect();
        let identity: Vec<f64> = (0..nv * nv).map(|rc| f64::from(u8::from(rc / nv == rc % nv))).collect();
        assert!(max_diff(&product, &identity) < 1e-9, "{name}: M⁻¹ (M + Ia)");

        // J̇ and Ȧ_g along q̇ = v; the classical acceleration is d/dt of the frame's
        // LOCAL_WORLD_ALIGNED velocity J(q(t)) (v + t a).
        let frame = Se3 {
            rotation: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            translation: [0.05, -0.02, 0.1],
        };
        for reference in [
            ReferenceFrame::World,
            ReferenceFrame::Local,
            ReferenceFrame::LocalWorldAligned,
        ] {
            let (mut jac, mut jac_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
            frame_jacobian_time_variation(&body, &mut dual1, &q, &v, nb, &frame, reference, &mut jac, &mut jac_dot);
            let mut along = |t: f64| {
                let mut j = vec![0.0; 6 * nv];
                compute_frame_jacobian(
                    &body,
                    &mut ws,
                    &integrate(&body, &q, &v, t),
                    nb,
                    &frame,
                    reference,
                    &mut j,
                );
                j
            };
            check("J̇", &jac_dot, &difference(&mut along, h));
        }
        let mut along = |t: f64| {
            let vt: Vec<f64> = v.iter().zip(&a).map(|(v, a)| v + a * t).collect();
            body_motions(&body, &mut ws, &integrate(&body, &q, &v, t), &vt, &a);
            frame_velocity(&body, &ws, nb, &frame, ReferenceFrame::LocalWorldAligned)
                .to_array()
                .to_vec()
        };
        let fd = difference(&mut along, h);
        let acc = frame_classical_acceleration(
            &body,
            &mut dual1,
            &q,
            &v,
            &a,
            nb,
            &frame,
            ReferenceFrame::LocalWorldAligned,
        );
        check("classical acceleration", &acc.to_array(), &fd);
        let (mut ag, mut ag_dot) = (vec![0.0; 6 * nv], vec![0.0; 6 * nv]);
        centroidal_map_time_variation(&body, &mut dual1, &q, &v, &params, &mut ag, &mut ag_dot);
        let mut along = |t: f64| {
            let mut x = vec![0.0; 6 * nv];
            centroidal_map(&body, &mut ws, &integrate(&body, &q, &v, t), &params, &mut x);
            x
        };
        check("Ȧ_g", &ag_dot, &difference(&mut along, h));
        println!("{name}: worst relative difference {worst:.1e}");
    }
}
