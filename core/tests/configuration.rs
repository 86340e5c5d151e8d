//! Configuration-space operations (`dyngen::configuration`): round trips on random
//! states, identities, errors, the quaternion ↔ matrix helpers against independent
//! matrix formulas, and Pinocchio 4.1's `integrate` / `difference`
//! (tests/fixtures/configuration/pinocchio.json, written by
//! scripts/make_configuration_fixtures.py).

use dyngen::configuration::{
    difference, integrate, matrix_to_quaternion, neutral, normalize, quaternion_to_matrix, ConfigurationError,
};
use dyngen::nalgebra::{Matrix3, Vector3};
use dyngen::{log3, BodyModel, JointModel, JointType, RobotModel};

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
const BODY: BodyModel = BodyModel {
    name: "body",
    mass: 1.0,
    com: [0.0; 3],
    inertia: IDENTITY,
    merged: &[],
};

const fn joint(name: &'static str, kind: JointType, parent: usize) -> JointModel {
    JointModel {
        name,
        kind,
        parent,
        rotation: IDENTITY,
        translation: [0.0, 0.0, 0.1],
        axis: match kind {
            JointType::Spherical | JointType::FreeFlyer => [0.0; 3],
            _ => [0.0, 0.0, 1.0],
        },
        limits: None,
        armature: 0.0,
        damping: 0.0,
        friction: 0.0,
        mimic: None,
    }
}

/// The fixture's model (free flyer, ball, revolute about z), nq = 12, nv = 10.
const MODEL: RobotModel = RobotModel {
    name: "floating_ball_wrist",
    gravity: [0.0, 0.0, -9.81],
    base: "world",
    joints: &[
        joint("root", JointType::FreeFlyer, 0),
        joint("ball", JointType::Spherical, 1),
        joint("wrist", JointType::Revolute, 2),
    ],
    bodies: &[BODY, BODY, BODY],
    frames: &[],
};

/// Every joint type, two ball joints in a row, the free flyer first.
const MIXED: RobotModel = RobotModel {
    name: "mixed",
    gravity: [0.0, 0.0, -9.81],
    base: "world",
    joints: &[
        joint("root", JointType::FreeFlyer, 0),
        joint("slide", JointType::Prismatic, 1),
        joint("ball1", JointType::Spherical, 2),
        joint("ball2", JointType::Spherical, 3),
        joint("spin", JointType::Continuous, 4),
        joint("elbow", JointType::Revolute, 5),
    ],
    bodies: &[BODY; 6],
    frames: &[],
};
const MIXED_NQ: usize = 7 + 1 + 4 + 4 + 1 + 1;
const MIXED_NV: usize = 6 + 1 + 3 + 3 + 1 + 1;

/// A 64-bit linear congruential generator (Knuth's MMIX constants): uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    /// A direction uniform on the sphere.
    fn direction(&mut self) -> [f64; 3] {
        loop {
            let d = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if n > 0.1 && n <= 1.0 {
                return d.map(|x| x / n);
            }
        }
    }
    /// A unit quaternion, uniform on the rotations.
    fn quaternion(&mut self) -> [f64; 4] {
        loop {
            let q = [0; 4].map(|_| self.range(-1.0, 1.0));
            let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 0.1 && n <= 1.0 {
                return q.map(|x| x / n);
            }
        }
    }
}

/// Rotation-vector magnitudes the round trips visit: zero, tiny, around the Taylor
/// switch at 10⁻², moderate, up to π − 0.1.
const ANGLES: [f64; 14] = [
    0.0,
    1e-300,
    1e-12,
    1e-9,
    1e-6,
    1e-3,
    0.0099999,
    0.0100001,
    0.3,
    1.0,
    2.0,
    2.9,
    std::f64::consts::PI - 0.1,
    std::f64::consts::PI - 1e-3,
];

fn random_q(rng: &mut Lcg, model: &RobotModel) -> Vec<f64> {
    let mut q = Vec::new();
    for j in model.joints {
        match j.kind {
            JointType::FreeFlyer => {
                q.extend([0; 3].map(|_| rng.range(-2.0, 2.0)));
                q.extend(rng.quaternion());
            }
            JointType::Spherical => q.extend(rng.quaternion()),
            _ => q.push(rng.range(-3.0, 3.0)),
        }
    }
    q
}

/// A velocity whose rotation vectors have the magnitude `angle`.
fn random_v(rng: &mut Lcg, model: &RobotModel, angle: f64) -> Vec<f64> {
    let mut v = Vec::new();
    for j in model.joints {
        match j.kind {
            JointType::FreeFlyer => {
                v.extend([0; 3].map(|_| rng.range(-2.0, 2.0)));
                v.extend(rng.direction().map(|x| angle * x));
            }
            JointType::Spherical => v.extend(rng.direction().map(|x| angle * x)),
            _ => v.push(rng.range(-2.0, 2.0)),
        }
    }
    v
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// The largest difference of the quaternions of two configurations up to sign (and
/// of the other coordinates).
fn max_config_diff(model: &RobotModel, a: &[f64], b: &[f64]) -> f64 {
    let (mut i, mut err) = (0, 0.0f64);
    for j in model.joints {
        let k = j.kind.nq();
        if k == 1 {
            err = err.max((a[i] - b[i]).abs());
        } else {
            err = err.max(max_abs_diff(&a[i..i + k - 4], &b[i..i + k - 4]));
            let (qa, qb) = (&a[i + k - 4..i + k], &b[i + k - 4..i + k]);
            let plus = max_abs_diff(qa, qb);
            let minus = qa.iter().zip(qb).map(|(x, y)| (x + y).abs()).fold(0.0, f64::max);
            err = err.max(plus.min(minus));
        }
        i += k;
    }
    err
}

#[test]
fn difference_of_integrate_is_the_velocity() {
    let mut rng = Lcg(1);
    let mut worst = 0.0f64;
    for &angle in &ANGLES {
        for _ in 0..50 {
            let q = random_q(&mut rng, &MIXED);
            let v = random_v(&mut rng, &MIXED, angle);
            let mut q1 = [0.0; MIXED_NQ];
            integrate(&MIXED, &q, &v, &mut q1).unwrap();
            let mut d = [0.0; MIXED_NV];
            difference(&MIXED, &q, &q1, &mut d).unwrap();
            let err = max_abs_diff(&d, &v);
            assert!(
                err <= 1e-12,
                "|ω| = {angle}: difference(q, integrate(q, v)) − v = {err:e}\nv = {v:?}\nd = {d:?}"
            );
            worst = worst.max(err);
        }
    }
    println!("max |difference(q, integrate(q, v)) − v| = {worst:e}");
}

#[test]
fn integrate_of_difference_is_the_target() {
    // Arbitrary pairs: relative rotations of every angle up to π.
    let mut rng = Lcg(2);
    let mut worst = 0.0f64;
    for _ in 0..500 {
        let q0 = random_q(&mut rng, &MIXED);
        let q1 = random_q(&mut rng, &MIXED);
        let mut d = [0.0; MIXED_NV];
        difference(&MIXED, &q0, &q1, &mut d).unwrap();
        let mut q = [0.0; MIXED_NQ];
        integrate(&MIXED, &q0, &d, &mut q).unwrap();
        let err = max_config_diff(&MIXED, &q, &q1);
        assert!(err <= 1e-12, "integrate(q0, difference(q0, q1)) − q1 = {err:e}");
        worst = worst.max(err);
        // |ω| ≤ π: the shortest rotation.
        for w in [&d[3..6], &d[7..10], &d[10..13]] {
            assert!(w.iter().map(|x| x * x).sum::<f64>().sqrt() <= std::f64::consts::PI + 1e-12);
        }
    }
    println!("max |integrate(q0, difference(q0, q1)) − q1| = {worst:e}");
}

#[test]
fn difference_near_pi_is_accurate() {
    // Relative rotations within 1e-9 of a half turn, built exactly as quaternions.
    let mut rng = Lcg(3);
    for &eps in &[0.0, 1e-15, 1e-12, 1e-9, 1e-6] {
        for _ in 0..20 {
            let theta = std::f64::consts::PI - eps;
            let axis = rng.direction();
            let w = axis.map(|x| theta * x);
            let q0 = rng.quaternion();
            // q1 = q0 ⊗ [sin(θ/2) a, cos(θ/2)] for the free flyer and the first ball
            // joint, through integrate with a zero translation.
            let mut v = vec![0.0; MIXED_NV];
            v[3..6].copy_from_slice(&w);
            v[7..10].copy_from_slice(&w);
            let q = {
                let mut q = random_q(&mut rng, &MIXED);
                q[3..7].copy_from_slice(&q0);
                q[8..12].copy_from_slice(&q0);
                q
            };
            let mut q1 = [0.0; MIXED_NQ];
            integrate(&MIXED, &q, &v, &mut q1).unwrap();
            let mut d = [0.0; MIXED_NV];
            difference(&MIXED, &q, &q1, &mut d).unwrap();
            for got in [&d[3..6], &d[7..10]] {
                // At θ = π exactly either sign is right.
                let err = max_abs_diff(got, &w).min(max_abs_diff(got, &w.map(|x| -x)));
                assert!(err <= 1e-12, "θ = π − {eps:e}: log = {got:?}, expected ±{w:?}");
            }
        }
    }
}

#[test]
fn integrate_matches_matrix_exponential() {
    // The free flyer against M₀ exp₆ with Rodrigues' matrices, independently of the
    // quaternion code; the ball against R₀ exp₃(ω).
    let mut rng = Lcg(4);
    for &angle in &ANGLES[..13] {
        for _ in 0..10 {
            let q = random_q(&mut rng, &MODEL);
            let v = random_v(&mut rng, &MODEL, angle);
            let mut q1 = [0.0; 12];
            integrate(&MODEL, &q, &v, &mut q1).unwrap();
            let w = Vector3::new(v[3], v[4], v[5]);
            let lin = Vector3::new(v[0], v[1], v[2]);
            let (exp, vmat) = rodrigues(&w);
            let r0 = quaternion_to_matrix([q[3], q[4], q[5], q[6]]);
            let p1 = Vector3::new(q[0], q[1], q[2]) + r0 * vmat * lin;
            let r1 = r0 * exp;
            assert!((Vector3::new(q1[0], q1[1], q1[2]) - p1).amax() < 1e-12, "{angle}");
            assert!((quaternion_to_matrix([q1[3], q1[4], q1[5], q1[6]]) - r1).amax() < 1e-12);
            let wb = Vector3::new(v[6], v[7], v[8]);
            let rb = quaternion_to_matrix([q[7], q[8], q[9], q[10]]) * rodrigues(&wb).0;
            assert!((quaternion_to_matrix([q1[7], q1[8], q1[9], q1[10]]) - rb).amax() < 1e-12);
            assert_eq!(q1[11], q[11] + v[9]);
            // The brief's definition of the difference: ω = log3(R₀ᵀ R₁).
            let mut d = [0.0; 10];
            difference(&MODEL, &q, &q1, &mut d).unwrap();
            let r1 = quaternion_to_matrix([q1[7], q1[8], q1[9], q1[10]]);
            let w = log3(&(quaternion_to_matrix([q[7], q[8], q[9], q[10]]).transpose() * r1));
            assert!((Vector3::new(d[6], d[7], d[8]) - w).amax() < 1e-12);
        }
    }
}

/// `(exp₃(ω), V(ω))` by the textbook formulas (with Taylor series for tiny angles).
fn rodrigues(w: &Vector3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let t = w.norm();
    let k = w.cross_matrix();
    let (a, b, c) = if t < 1e-4 {
        (1.0 - t * t / 6.0, 0.5 - t * t / 24.0, 1.0 / 6.0 - t * t / 120.0)
    } else {
        (t.sin() / t, (1.0 - t.cos()) / (t * t), (t - t.sin()) / (t * t * t))
    };
    let e = Matrix3::identity();
    (e + k * a + k * k * b, e + k * b + k * k * c)
}

#[test]
fn zero_velocity_is_the_identity() {
    let mut rng = Lcg(5);
    for _ in 0..100 {
        let q = random_q(&mut rng, &MIXED);
        let mut q1 = [0.0; MIXED_NQ];
        integrate(&MIXED, &q, &[0.0; MIXED_NV], &mut q1).unwrap();
        let err = max_abs_diff(&q, &q1);
        assert!(err <= 4.0 * f64::EPSILON, "integrate(q, 0) − q = {err:e}");
        let mut d = [1.0; MIXED_NV];
        difference(&MIXED, &q, &q, &mut d).unwrap();
        assert!(
            d.iter().all(|x| x.abs() <= 4.0 * f64::EPSILON),
            "difference(q, q) = {d:?}"
        );
    }
    // From the neutral configuration, exactly.
    let mut q = [f64::NAN; MIXED_NQ];
    neutral(&MIXED, &mut q).unwrap();
    let mut q1 = [f64::NAN; MIXED_NQ];
    integrate(&MIXED, &q, &[0.0; MIXED_NV], &mut q1).unwrap();
    assert_eq!(q, q1);
}

#[test]
fn neutral_and_normalize() {
    let mut q = [7.0f64; MIXED_NQ];
    neutral(&MIXED, &mut q).unwrap();
    let expected = [0., 0., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0.];
    assert_eq!(q, expected);

    let mut rng = Lcg(6);
    let mut q = random_q(&mut rng, &MIXED);
    let unit = q.clone();
    for (i, s) in [(3, 2.5), (8, 1e-200), (12, 1e200)] {
        for x in &mut q[i..i + 4] {
            *x *= s;
        }
    }
    normalize(&MIXED, &mut q).unwrap();
    assert!(max_abs_diff(&q, &unit) <= 4.0 * f64::EPSILON, "{q:?}\n{unit:?}");

    // A zero quaternion: an error naming the joint; it and the joints after it are left alone.
    let mut bad = unit.clone();
    bad[8..12].fill(0.0);
    bad[12..16].iter_mut().for_each(|x| *x *= 3.0);
    let before = bad.clone();
    assert_eq!(
        normalize(&MIXED, &mut bad),
        Err(ConfigurationError::NonFinite {
            joint: 3,
            name: "ball1"
        })
    );
    assert_eq!(bad[8..], before[8..]);
}

#[test]
fn wrong_lengths_are_errors() {
    let (nq, nv) = (MIXED_NQ, MIXED_NV);
    let (q, v) = (vec![0.0f64; nq], vec![0.0f64; nv]);
    let mut q_out = vec![0.0f64; nq];
    let mut v_out = vec![0.0f64; nv];
    let length = |argument, expected, found| {
        Err(ConfigurationError::Length {
            argument,
            expected,
            found,
        })
    };

    assert_eq!(integrate(&MIXED, &q[1..], &v, &mut q_out), length("q", nq, nq - 1));
    assert_eq!(integrate(&MIXED, &q, &q, &mut q_out), length("v", nv, nq));
    assert_eq!(integrate(&MIXED, &q, &v, &mut v_out), length("out", nq, nv));
    assert_eq!(difference(&MIXED, &v, &q, &mut v_out), length("q0", nq, nv));
    assert_eq!(difference(&MIXED, &q, &[], &mut v_out), length("q1", nq, 0));
    assert_eq!(difference(&MIXED, &q, &q, &mut q_out), length("out", nv, nq));
    assert_eq!(neutral(&MIXED, &mut v_out), length("out", nq, nv));
    assert_eq!(normalize(&MIXED, &mut v_out), length("q", nq, nv));

    let e = integrate(&MIXED, &q, &q, &mut q_out).unwrap_err();
    assert_eq!(e.to_string(), "`v` has 18 entries, expected 15");
    #[cfg(feature = "std")]
    let _: &dyn std::error::Error = &e;
}

#[test]
fn non_finite_results_are_errors() {
    let mut q = vec![0.0f64; MIXED_NQ];
    neutral(&MIXED, &mut q).unwrap();
    let v = vec![0.1f64; MIXED_NV];
    let mut q1 = vec![0.0; MIXED_NQ];
    let mut d = vec![0.0; MIXED_NV];
    let non_finite = |joint, name| Err(ConfigurationError::NonFinite { joint, name });

    // A zero quaternion of a ball joint, in either argument.
    let mut zero = q.clone();
    zero[12..16].fill(0.0);
    assert_eq!(integrate(&MIXED, &zero, &v, &mut q1), non_finite(4, "ball2"));
    assert_eq!(difference(&MIXED, &zero, &q, &mut d), non_finite(4, "ball2"));
    assert_eq!(difference(&MIXED, &q, &zero, &mut d), non_finite(4, "ball2"));
    // ... and of the free flyer.
    let mut zero = q.clone();
    zero[3..7].fill(0.0);
    assert_eq!(integrate(&MIXED, &zero, &v, &mut q1), non_finite(1, "root"));
    assert_eq!(difference(&MIXED, &q, &zero, &mut d), non_finite(1, "root"));
    // NaN and infinite inputs.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for (i, joint, name) in [
            (0, 1, "root"),
            (5, 1, "root"),
            (7, 2, "slide"),
            (9, 3, "ball1"),
            (17, 6, "elbow"),
        ] {
            let mut qb = q.clone();
            qb[i] = bad;
            assert_eq!(
                integrate(&MIXED, &qb, &v, &mut q1),
                non_finite(joint, name),
                "q[{i}] = {bad}"
            );
            assert_eq!(
                difference(&MIXED, &q, &qb, &mut d),
                non_finite(joint, name),
                "q1[{i}] = {bad}"
            );
        }
        for (i, joint, name) in [(1, 1, "root"), (4, 1, "root"), (8, 3, "ball1"), (13, 5, "spin")] {
            let mut vb = v.clone();
            vb[i] = bad;
            assert_eq!(
                integrate(&MIXED, &q, &vb, &mut q1),
                non_finite(joint, name),
                "v[{i}] = {bad}"
            );
        }
    }
    let e = ConfigurationError::NonFinite {
        joint: 4,
        name: "ball2",
    };
    assert!(e.to_string().starts_with("joint 4 (`ball2`): the result is not finite"));
}

#[test]
fn quaternion_matrix_round_trip() {
    let mut rng = Lcg(7);
    let mut quats: Vec<[f64; 4]> = (0..1000).map(|_| rng.quaternion()).collect();
    // Half turns (w = 0) about axes and diagonals, and near them; near the identity.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    quats.extend([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [h, h, 0.0, 0.0],
        [0.0, -h, h, 0.0],
        [0.6, 0.0, -0.8, 0.0],
        [h, 0.0, 0.0, h],
        [0.0, 0.0, -h, h],
    ]);
    for eps in [1e-12f64, 1e-8, 1e-4] {
        let d = rng.direction();
        let (big, small) = (eps.cos(), eps.sin());
        quats.push([big * d[0], big * d[1], big * d[2], small]);
        quats.push([small * d[0], small * d[1], small * d[2], big]);
    }
    let (mut worst_orthogonality, mut worst_round_trip, mut worst_matrix) = (0.0f64, 0.0f64, 0.0f64);
    for q in quats {
        let r = quaternion_to_matrix(q);
        worst_orthogonality = worst_orthogonality.max((r.transpose() * r - Matrix3::identity()).amax());
        assert!((r.determinant() - 1.0).abs() < 4e-15);
        let p = matrix_to_quaternion(&r);
        assert!(p[3] >= 0.0);
        let s = if q[3] < 0.0 { -1.0 } else { 1.0 };
        let err = (0..4).map(|i| (p[i] - s * q[i]).abs()).fold(0.0, f64::max);
        // At w = 0 both signs have w ≥ 0.
        let err = if q[3] == 0.0 {
            err.min((0..4).map(|i| (p[i] + q[i]).abs()).fold(0.0, f64::max))
        } else {
            err
        };
        assert!(err < 1e-15, "{q:?} → {p:?}");
        worst_round_trip = worst_round_trip.max(err);
        worst_matrix = worst_matrix.max((quaternion_to_matrix(p) - r).amax());
    }
    println!(
        "max |RᵀR − E| = {worst_orthogonality:e}, max |q(R(q)) ∓ q| = {worst_round_trip:e}, \
         max |R(q(R)) − R| = {worst_matrix:e}"
    );
    assert!(worst_orthogonality < 4e-15 && worst_matrix < 4e-15);
    // The columns of R(q) are the rotated axes: a quarter turn about z takes x to y.
    let r = quaternion_to_matrix([0.0, 0.0, h, h]);
    assert!((r * Vector3::x() - Vector3::y()).amax() < 1e-15);
}

#[test]
fn generic_over_f32() {
    let mut rng = Lcg(8);
    let q = random_q(&mut rng, &MIXED);
    let v = random_v(&mut rng, &MIXED, 1.3);
    let (qf, vf): (Vec<f32>, Vec<f32>) = (
        q.iter().map(|&x| x as f32).collect(),
        v.iter().map(|&x| x as f32).collect(),
    );
    let mut q1 = [0.0f32; MIXED_NQ];
    integrate(&MIXED, &qf, &vf, &mut q1).unwrap();
    let mut d = [0.0f32; MIXED_NV];
    difference(&MIXED, &qf, &q1, &mut d).unwrap();
    let err = d.iter().zip(&vf).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(err < 1e-5, "{err}");
    // The f64 result, to f32 precision.
    let mut q64 = [0.0; MIXED_NQ];
    integrate(&MIXED, &q, &v, &mut q64).unwrap();
    let q32: Vec<f64> = q1.iter().map(|&x| x as f64).collect();
    assert!(max_abs_diff(&q32, &q64) < 1e-5);
}

// ---------------------------------------------------------------------------------
// Pinocchio 4.1

const FIXTURE: &str = include_str!("../../tests/fixtures/configuration/pinocchio.json");

#[test]
fn matches_pinocchio() {
    let json = Json::parse(FIXTURE);
    assert_eq!(json.get("pinocchio_version").as_str(), "4.1.0");
    assert_eq!(json.get("nq").as_f64(), 12.0);
    assert_eq!(json.get("nv").as_f64(), 10.0);

    let mut q = [0.0; 12];
    neutral(&MODEL, &mut q).unwrap();
    assert_eq!(q.as_slice(), json.get("neutral").as_f64s());

    let samples = json.get("samples").as_array();
    assert_eq!(samples.len(), 5);
    let (mut worst_integrate, mut worst_difference) = (0.0f64, 0.0f64);
    for s in samples {
        let (q, v, q1) = (s.get("q").as_f64s(), s.get("v").as_f64s(), s.get("q1").as_f64s());
        let mut out = [0.0; 12];
        integrate(&MODEL, &q, &v, &mut out).unwrap();
        // Component-wise, quaternion signs included.
        worst_integrate = worst_integrate.max(max_abs_diff(&out, &s.get("integrate").as_f64s()));
        let mut d = [0.0; 10];
        difference(&MODEL, &q, &q1, &mut d).unwrap();
        worst_difference = worst_difference.max(max_abs_diff(&d, &s.get("difference").as_f64s()));
    }
    println!("max |integrate − pin.integrate| = {worst_integrate:e}");
    println!("max |difference − pin.difference| = {worst_difference:e}");
    assert!(worst_integrate <= 1e-12, "integrate: {worst_integrate:e}");
    assert!(worst_difference <= 1e-12, "difference: {worst_difference:e}");
}

/// A planar base on the ground and an arm turning about z: the model of
/// `planar.json`, nq = nv = 4.
const PLANAR: RobotModel = RobotModel {
    name: "planar_base",
    gravity: [0.0, 0.0, -9.81],
    base: "world",
    joints: &[
        joint("base", JointType::Planar, 0),
        joint("arm", JointType::Revolute, 1),
    ],
    bodies: &[BODY, BODY],
    frames: &[],
};

/// Pinocchio's `JointModelPlanar` (`q = [x, y, cos θ, sin θ]`): `integrate` to the exact
/// step (50-digit decimals, in the fixture) and to Pinocchio's position and cos, sin of
/// the angle; `difference` where the angles are less than π apart (Pinocchio wraps the
/// angle, dyngen does not). Turns from 1e-7 to 3 rad cover the Taylor series and the
/// closed forms. Pinocchio's own step is 4.7e-10 off the exact one at a turn of 1e-7
/// rad (its `(1 − cos ω)/ω` cancels), hence the looser bound against it.
#[test]
fn planar_matches_pinocchio() {
    let json = Json::parse(include_str!("../../tests/fixtures/configuration/planar.json"));
    assert_eq!(json.get("pinocchio_version").as_str(), "4.1.0");
    let samples = json.get("samples").as_array();
    assert_eq!(samples.len(), 5);
    let (mut worst_exact, mut worst_pinocchio, mut worst_difference) = (0.0f64, 0.0f64, 0.0f64);
    for s in samples {
        let (q, v, q1) = (s.get("q").as_f64s(), s.get("v").as_f64s(), s.get("q1").as_f64s());
        let mut out = [0.0; 4];
        integrate(&PLANAR, &q, &v, &mut out).unwrap();
        worst_exact = worst_exact.max(max_abs_diff(&out, &s.get("integrate_exact").as_f64s()));
        let (sin, cos) = out[2].sin_cos();
        worst_pinocchio = worst_pinocchio
            .max(max_abs_diff(&out, &s.get("integrate").as_f64s()))
            .max(max_abs_diff(&[cos, sin], &s.get("integrate_cos_sin").as_f64s()));
        let mut d = [0.0; 4];
        difference(&PLANAR, &q, &q1, &mut d).unwrap();
        worst_difference = worst_difference.max(max_abs_diff(&d, &s.get("difference").as_f64s()));
        // And back: q ⊕ (q1 ⊖ q) = q1.
        integrate(&PLANAR, &q, &d, &mut out).unwrap();
        assert!(max_abs_diff(&out, &q1) < 1e-14, "{out:?} against {q1:?}");
    }
    println!(
        "planar: max |integrate − exact| = {worst_exact:e}, |integrate − pin.integrate| = {worst_pinocchio:e}, \
         |difference − pin.difference| = {worst_difference:e}"
    );
    assert!(
        worst_exact <= 1e-15,
        "integrate against the exact step: {worst_exact:e}"
    );
    assert!(
        worst_pinocchio <= 1e-9,
        "integrate against Pinocchio: {worst_pinocchio:e}"
    );
    assert!(worst_difference <= 1e-13, "difference: {worst_difference:e}");
}

/// A planar joint's neutral configuration is zero, `normalize` leaves it alone, and a
/// non-finite coordinate is an error naming the joint.
#[test]
fn planar_neutral_normalize_and_errors() {
    let mut q = [1.0; 4];
    neutral(&PLANAR, &mut q).unwrap();
    assert_eq!(q, [0.0; 4]);
    let mut q = [0.3, -0.2, 5.0, 1.0];
    normalize(&PLANAR, &mut q).unwrap();
    assert_eq!(q, [0.3, -0.2, 5.0, 1.0]);
    let mut out = [0.0; 4];
    assert_eq!(
        integrate(&PLANAR, &[0.0, f64::NAN, 0.0, 0.0], &[0.0; 4], &mut out),
        Err(ConfigurationError::NonFinite { joint: 1, name: "base" })
    );
    let mut d = [0.0; 4];
    assert_eq!(
        difference(&PLANAR, &[0.0; 4], &[0.0, 0.0, f64::INFINITY, 0.0], &mut d),
        Err(ConfigurationError::NonFinite { joint: 1, name: "base" })
    );
}

/// Just enough JSON for the fixture (objects, arrays, numbers, strings without
/// escapes, literals), so that core needs no JSON dependency.
#[derive(Debug)]
enum Json {
    Number(f64),
    Str(String),
    Array(Vec<Json>),
    Object(Vec<(String, Json)>),
    Literal,
}

impl Json {
    fn parse(text: &str) -> Json {
        let mut p = Parser {
            s: text.as_bytes(),
            i: 0,
        };
        let v = p.value();
        p.ws();
        assert_eq!(p.i, p.s.len(), "trailing characters");
        v
    }
    fn get(&self, key: &str) -> &Json {
        match self {
            Json::Object(m) => {
                &m.iter()
                    .find(|(k, _)| k == key)
                    .unwrap_or_else(|| panic!("no key {key}"))
                    .1
            }
            _ => panic!("not an object"),
        }
    }
    fn as_array(&self) -> &[Json] {
        match self {
            Json::Array(a) => a,
            _ => panic!("not an array"),
        }
    }
    fn as_f64(&self) -> f64 {
        match self {
            Json::Number(x) => *x,
            _ => panic!("not a number"),
        }
    }
    fn as_f64s(&self) -> Vec<f64> {
        self.as_array().iter().map(Json::as_f64).collect()
    }
    fn as_str(&self) -> &str {
        match self {
            Json::Str(s) => s,
            _ => panic!("not a string"),
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn eat(&mut self, c: u8) -> bool {
        self.ws();
        let hit = self.s.get(self.i) == Some(&c);
        self.i += hit as usize;
        hit
    }
    fn string(&mut self) -> String {
        assert!(self.eat(b'"'));
        let start = self.i;
        while self.s[self.i] != b'"' {
            assert_ne!(self.s[self.i], b'\\', "escapes are not supported");
            self.i += 1;
        }
        self.i += 1;
        String::from_utf8(self.s[start..self.i - 1].to_vec()).unwrap()
    }
    fn list<T>(&mut self, close: u8, mut item: impl FnMut(&mut Self) -> T) -> Vec<T> {
        let mut out = Vec::new();
        if self.eat(close) {
            return out;
        }
        loop {
            out.push(item(self));
            if self.eat(close) {
                return out;
            }
            assert!(self.eat(b','), "expected , at byte {}", self.i);
        }
    }
    fn value(&mut self) -> Json {
        self.ws();
        match self.s[self.i] {
            b'{' => {
                self.i += 1;
                Json::Object(self.list(b'}', |p| {
                    let k = p.string();
                    assert!(p.eat(b':'));
                    (k, p.value())
                }))
            }
            b'[' => {
                self.i += 1;
                Json::Array(self.list(b']', Parser::value))
            }
            b'"' => Json::Str(self.string()),
            b't' | b'f' | b'n' => {
                while self.i < self.s.len() && self.s[self.i].is_ascii_alphabetic() {
                    self.i += 1;
                }
                Json::Literal
            }
            _ => {
                let start = self.i;
                while self.i < self.s.len() && matches!(self.s[self.i], b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E')
                {
                    self.i += 1;
                }
                Json::Number(std::str::from_utf8(&self.s[start..self.i]).unwrap().parse().unwrap())
            }
        }
    }
}

/// A joint that follows another has no coordinate: the operations skip it, so `q` and
/// `v` hold the leaders' coordinates only (a revolute leader, its follower, a ball).
#[test]
fn followers_have_no_coordinates() {
    const FOLLOWING: RobotModel = RobotModel {
        name: "following",
        gravity: [0.0, 0.0, -9.81],
        base: "world",
        joints: &[
            joint("leader", JointType::Revolute, 0),
            JointModel {
                mimic: Some(dyngen::JointMimic {
                    leader: 1,
                    multiplier: -2.0,
                    offset: 0.5,
                }),
                ..joint("follower", JointType::Revolute, 1)
            },
            joint("ball", JointType::Spherical, 2),
        ],
        bodies: &[BODY; 3],
        frames: &[],
    };
    assert_eq!(FOLLOWING.own_joints().map(|(j, _)| j).collect::<Vec<_>>(), [0, 2]);
    let mut q = [0.0; 5];
    neutral(&FOLLOWING, &mut q).unwrap();
    assert_eq!(q, [0.0, 0.0, 0.0, 0.0, 1.0]);
    let mut out = [0.0; 5];
    integrate(&FOLLOWING, &q, &[0.25, 0.0, 0.0, 0.0], &mut out).unwrap();
    assert_eq!(out, [0.25, 0.0, 0.0, 0.0, 1.0]);
    let mut v = [0.0; 4];
    difference(&FOLLOWING, &q, &out, &mut v).unwrap();
    assert_eq!(v, [0.25, 0.0, 0.0, 0.0]);
    let wrong = integrate(&FOLLOWING, &[0.0; 6], &[0.0; 4], &mut [0.0; 6]);
    assert!(
        matches!(
            wrong,
            Err(ConfigurationError::Length {
                argument: "q",
                expected: 5,
                found: 6
            })
        ),
        "{wrong:?}"
    );
}
