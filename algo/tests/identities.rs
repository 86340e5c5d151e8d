//! Identities between the algorithms on random states of models with every joint
//! type (ball and free joints from MJCF, planar and prismatic joints from URDF):
//! aba inverts rnea (with and without rotor inertia), crba's columns are rnea's
//! differences, the regressor times the parameters is rnea, and the Jacobian maps
//! velocities to the frame velocity rnea's forward pass would give (checked by a
//! finite difference of the placement).

use dyngen_algo::{
    aba, body_motions, compute_frame_jacobian, crba, forward_kinematics, frame_jacobian, joint_torque_regressor,
    joint_wrench_regressor, rnea, JointType, Multibody, ReferenceFrame, Se3, Workspace,
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
/// `q̇` from each joint's rule (quaternions `½ q ⊗ (ω, 0)`, a free flyer's position
/// `R v`, a planar joint's position `R(θ) [vx, vy]`).
fn integrate(body: &Multibody, q: &[f64], v: &[f64], t: f64) -> Vec<f64> {
    let mut out = q.to_vec();
    for j in &body.joints {
        let (qo, vo) = (j.q_offset, j.v_offset);
        let quaternion = |out: &mut Vec<f64>, at: usize, w: &[f64]| {
            let (x, y, z, s) = (q[at], q[at + 1], q[at + 2], q[at + 3]);
            let d = [
                0.5 * (s * w[0] + y * w[2] - z * w[1]),
                0.5 * (s * w[1] + z * w[0] - x * w[2]),
                0.5 * (s * w[2] + x * w[1] - y * w[0]),
                -0.5 * (x * w[0] + y * w[1] + z * w[2]),
            ];
            for k in 0..4 {
                out[at + k] += d[k] * t;
            }
        };
        match j.kind {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => out[qo] += v[vo] * t,
            JointType::Spherical => quaternion(&mut out, qo, &v[vo..vo + 3]),
            JointType::FreeFlyer => {
                let r = dyngen_algo::quaternion_rotation((), [q[qo + 3], q[qo + 4], q[qo + 5], q[qo + 6]]);
                for k in 0..3 {
                    out[qo + k] += (0..3).map(|c| r[k][c] * v[vo + c]).sum::<f64>() * t;
                }
                quaternion(&mut out, qo + 3, &v[vo + 3..vo + 6]);
            }
            JointType::Planar => {
                let (s, c) = q[qo + 2].sin_cos();
                out[qo] += (c * v[vo] - s * v[vo + 1]) * t;
                out[qo + 1] += (s * v[vo] + c * v[vo + 1]) * t;
                out[qo + 2] += v[vo + 2] * t;
            }
        }
    }
    out
}
