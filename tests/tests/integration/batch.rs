//! Batches on lanes and threads against one call per state: bit for bit, for every
//! batched function, both layouts, 1 and 3 threads, 4 and 8 `f64` lanes and 8 and 16
//! `f32` lanes, on a fixed-base arm and a humanoid on a free flyer; and the errors.

use dyngen::batch::{Batch, BatchError, Input, Layout, Output, Threads};
use dyngen::lanes::{F32x16, F32x8, F64x4, F64x8, Lanes};
use dyngen::{Frames, InverseDynamics, OrderedScalar, ReferenceFrame, Robot, Scalar};
use dyngen_reference::{sample_states, Reference};
use robot_humanoid31::Humanoid31;
use robot_panda::Panda;
use robot_ur5::Ur5;

/// 37 states (not a multiple of any lane count), as rows and as columns.
struct States<E> {
    n: usize,
    q: Vec<E>,
    v: Vec<E>,
    a: Vec<E>,
    params: Vec<E>,
}

fn states<R: Robot, E: OrderedScalar>(n: usize, seed: u64) -> States<E> {
    let s = sample_states(Reference::of::<R>().model(), n, seed);
    let e = |x: &f64| E::from_f64(*x);
    States {
        n,
        q: s.iter().flat_map(|s| s.q.iter().map(e)).collect(),
        v: s.iter().flat_map(|s| s.v.iter().map(e)).collect(),
        a: s.iter().flat_map(|s| s.a.iter().map(e)).collect(),
        params: R::nominal_params().iter().map(e).collect(),
    }
}

/// Rows `(n, w)` to columns `(w, n)` and back.
fn transpose<E: Copy>(x: &[E], n: usize, w: usize) -> Vec<E> {
    (0..w).flat_map(|i| (0..n).map(move |k| x[k * w + i])).collect()
}
fn untranspose<E: Copy>(x: &[E], n: usize, w: usize) -> Vec<E> {
    (0..n).flat_map(|k| (0..w).map(move |i| x[i * n + k])).collect()
}

fn assert_bits<E: OrderedScalar>(got: &[E], want: &[E], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            g.to_f64().to_bits() == w.to_f64().to_bits(),
            "{what}[{i}]: {g:?} vs {w:?}"
        );
    }
}

/// Every batched function of `R` on lanes `L`, in both layouts and on 1 and 3
/// threads, against the per-state calls on `L::Elem`.
fn check<R: Robot, L: Lanes>(seed: u64) {
    let s = states::<R, L::Elem>(37, seed);
    let (n, nq, nv, np) = (s.n, R::NQ, R::NV, R::NPARAMS);
    let z = <L::Elem as Scalar>::ZERO;
    // One call per state.
    let (mut rnea, mut nle, mut grav, mut crba, mut aba, mut reg) = (
        vec![z; n * nv],
        vec![z; n * nv],
        vec![z; n * nv],
        vec![z; n * nv * nv],
        vec![z; n * nv],
        vec![z; n * nv * np],
    );
    for k in 0..n {
        let (q, v, a) = (&s.q[k * nq..][..nq], &s.v[k * nv..][..nv], &s.a[k * nv..][..nv]);
        R::rnea(q, v, a, &s.params, &mut rnea[k * nv..][..nv]);
        R::nonlinear_effects(q, v, &s.params, &mut nle[k * nv..][..nv]);
        R::generalized_gravity(q, &s.params, &mut grav[k * nv..][..nv]);
        R::crba(q, &s.params, &mut crba[k * nv * nv..][..nv * nv]);
        // Forward dynamics of the torques rnea gave.
        R::aba(q, v, &rnea[k * nv..][..nv], &s.params, &mut aba[k * nv..][..nv]);
        R::joint_torque_regressor(q, v, a, &mut reg[k * nv * np..][..nv * np]);
    }
    for layout in [Layout::Rows, Layout::Columns] {
        let to = |x: &[L::Elem], w: usize| match layout {
            Layout::Rows => x.to_vec(),
            Layout::Columns => transpose(x, n, w),
        };
        let from = |x: &[L::Elem], w: usize| match layout {
            Layout::Rows => x.to_vec(),
            Layout::Columns => untranspose(x, n, w),
        };
        let (q, v, a, tau) = (to(&s.q, nq), to(&s.v, nv), to(&s.a, nv), to(&rnea, nv));
        for threads in [1, 3] {
            let what = |f: &str| format!("{} {f}, {} lanes, {layout:?}, {threads} threads", R::NAME, L::LANES);
            let batch = Batch::<L>::new(n, layout).threads(Threads::Count(threads));
            let mut out = vec![z; n * nv];
            batch.rnea::<R>(&q, &v, &a, &s.params, &mut out).unwrap();
            assert_bits(&from(&out, nv), &rnea, &what("rnea"));
            batch.nonlinear_effects::<R>(&q, &v, &s.params, &mut out).unwrap();
            assert_bits(&from(&out, nv), &nle, &what("nonlinear_effects"));
            batch.generalized_gravity::<R>(&q, &s.params, &mut out).unwrap();
            assert_bits(&from(&out, nv), &grav, &what("generalized_gravity"));
            batch.aba::<R>(&q, &v, &tau, &s.params, &mut out).unwrap();
            assert_bits(&from(&out, nv), &aba, &what("aba"));
            let mut m = vec![z; n * nv * nv];
            batch.crba::<R>(&q, &s.params, &mut m).unwrap();
            assert_bits(&from(&m, nv * nv), &crba, &what("crba"));
            let mut y = vec![z; n * nv * np];
            batch.joint_torque_regressor::<R>(&q, &v, &a, &mut y).unwrap();
            assert_bits(&from(&y, nv * np), &reg, &what("joint_torque_regressor"));
        }
    }
}

/// An unoptimised build keeps every intermediate of a generated function on the stack,
/// `LANES` times over on lanes: the calling thread of a batch needs a larger stack
/// than a test thread's 2 MB (the threads a batch starts have one).
fn on_a_large_stack(f: impl FnOnce() + Send) {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, f)
            .unwrap()
            .join()
            .unwrap()
    })
}

#[test]
fn f64_lanes_equal_one_call_per_state() {
    on_a_large_stack(|| {
        check::<Ur5, F64x4>(1);
        check::<Ur5, F64x8>(2);
        check::<Panda, F64x8>(3);
        check::<Humanoid31, F64x4>(4);
    });
}

#[test]
fn f32_lanes_equal_one_call_per_state() {
    on_a_large_stack(|| {
        check::<Panda, F32x8>(5);
        check::<Ur5, F32x16>(6);
    });
}

/// Any generated function through `apply`: a frame Jacobian in the world-aligned
/// frame, 12 states of 4 lanes, equal to the per-state call.
#[test]
fn apply_batches_any_generated_function() {
    let s = states::<Ur5, f64>(12, 7);
    let frame = robot_ur5::Ur5Frame::Tool0.index();
    let width = 6 * Ur5::NV;
    let mut j = vec![0.0; 12 * width];
    Batch::<F64x4>::new(12, Layout::Rows)
        .apply(
            &[Input {
                name: "q",
                data: &s.q,
                width: Ur5::NQ,
            }],
            &mut [Output {
                name: "jacobian",
                data: &mut j,
                width,
            }],
            |x, y| {
                <Ur5 as Frames>::frame_jacobian(&x[0], frame, ReferenceFrame::LocalWorldAligned, &mut y[0]).unwrap();
            },
        )
        .unwrap();
    for k in 0..12 {
        let mut want = vec![0.0; width];
        <Ur5 as Frames>::frame_jacobian(&s.q[k * 6..][..6], frame, ReferenceFrame::LocalWorldAligned, &mut want)
            .unwrap();
        assert_bits(&j[k * width..][..width], &want, &format!("jacobian of state {k}"));
    }
}

#[test]
fn a_slice_of_the_wrong_length_is_named() {
    let s = states::<Ur5, f64>(10, 8);
    let mut tau = vec![0.0; 60];
    let batch = Batch::<F64x4>::new(10, Layout::Rows);
    let err = batch
        .rnea::<Ur5>(&s.q, &s.v[..59], &s.a, &s.params, &mut tau)
        .unwrap_err();
    assert_eq!(
        err,
        BatchError::Length {
            argument: "v",
            expected: 60,
            found: 59
        }
    );
    assert_eq!(err.to_string(), "`v` has 59 values where the batch needs 60");
    let err = batch
        .rnea::<Ur5>(&s.q, &s.v, &s.a, &s.params[..10], &mut tau)
        .unwrap_err();
    assert!(matches!(
        err,
        BatchError::Length {
            argument: "params",
            expected: 60,
            found: 10
        }
    ));
    let err = batch
        .rnea::<Ur5>(&s.q, &s.v, &s.a, &s.params, &mut tau[..6])
        .unwrap_err();
    assert!(matches!(err, BatchError::Length { argument: "tau", .. }));
}

/// A non-finite input gives a non-finite result: the error names the first such
/// state, on any thread, and the states before it are computed.
#[test]
fn a_non_finite_result_names_the_state() {
    let mut s = states::<Ur5, f64>(40, 9);
    s.v[6 * 23 + 2] = f64::NAN;
    s.v[6 * 31] = f64::INFINITY;
    for threads in [1, 2, 4] {
        let mut tau = vec![0.0; 240];
        let err = Batch::<F64x8>::new(40, Layout::Rows)
            .threads(Threads::Count(threads))
            .rnea::<Ur5>(&s.q, &s.v, &s.a, &s.params, &mut tau)
            .unwrap_err();
        assert_eq!(
            err,
            BatchError::NonFinite {
                output: "tau",
                state: 23
            },
            "{threads} threads"
        );
        assert!(tau[..6 * 16].iter().all(|x| x.is_finite() && *x != 0.0));
    }
    let err = Batch::<F64x4>::new(1, Layout::Rows)
        .threads(Threads::Count(0))
        .generalized_gravity::<Ur5>(&s.q[..6], &s.params, &mut [0.0; 6])
        .unwrap_err();
    assert_eq!(err, BatchError::NoThreads);
    assert!(err.to_string().contains("Threads::Count(0)"));
}

/// An empty batch does nothing, and threads beyond the groups of lanes are not used.
#[test]
fn empty_and_tiny_batches() {
    let s = states::<Ur5, f64>(3, 10);
    Batch::<F64x4>::new(0, Layout::Columns)
        .rnea::<Ur5>(&[], &[], &[], &s.params, &mut [])
        .unwrap();
    let mut tau = vec![0.0; 18];
    Batch::<F64x8>::new(3, Layout::Columns)
        .threads(Threads::Count(16))
        .generalized_gravity::<Ur5>(&transpose(&s.q, 3, 6), &s.params, &mut tau)
        .unwrap();
    let mut want = [0.0; 6];
    <Ur5 as InverseDynamics>::generalized_gravity(&s.q[12..18], &s.params, &mut want);
    assert_bits(&untranspose(&tau, 3, 6)[12..], &want, "state 2");
}

/// The run-time algorithms (dyngen-algo on a loaded model) on lanes, through
/// `apply_with` and a workspace per thread, equal one f64 call per state.
#[test]
fn runtime_algorithms_on_lanes_equal_one_call_per_state() {
    fn check_model<R: Robot>(seed: u64) {
        let model = Reference::of::<R>().model().clone();
        let body = model.multibody().unwrap();
        let (nq, nv, n) = (body.nq(), body.nv(), 21);
        let s = states::<R, f64>(n, seed);
        let params: Vec<F64x4> = body.params.iter().map(|&p| F64x4::from_f64(p)).collect();
        let armature = vec![F64x4::from_f64(0.1); nv];
        let (mut tau, mut m, mut qdd) = (vec![0.0; n * nv], vec![0.0; n * nv * nv], vec![0.0; n * nv]);
        Batch::<F64x4>::new(n, Layout::Rows)
            .threads(Threads::Count(2))
            .apply_with(
                &[
                    Input {
                        name: "q",
                        data: &s.q,
                        width: nq,
                    },
                    Input {
                        name: "v",
                        data: &s.v,
                        width: nv,
                    },
                    Input {
                        name: "a",
                        data: &s.a,
                        width: nv,
                    },
                ],
                &mut [
                    Output {
                        name: "tau",
                        data: &mut tau,
                        width: nv,
                    },
                    Output {
                        name: "m",
                        data: &mut m,
                        width: nv * nv,
                    },
                    Output {
                        name: "qdd",
                        data: &mut qdd,
                        width: nv,
                    },
                ],
                || dyngen_algo::Workspace::<F64x4>::new(&body, ()),
                |ws, x, y| {
                    let [tau, m, qdd] = y else { unreachable!() };
                    dyngen_algo::rnea(&body, ws, &x[0], &x[1], &x[2], &params, tau);
                    dyngen_algo::crba(&body, ws, &x[0], &params, m);
                    dyngen_algo::aba(&body, ws, &x[0], &x[1], tau, &params, &armature, qdd);
                },
            )
            .unwrap();
        let mut ws = dyngen_algo::Workspace::<f64>::new(&body, ());
        for k in 0..n {
            let (q, v, a) = (&s.q[k * nq..][..nq], &s.v[k * nv..][..nv], &s.a[k * nv..][..nv]);
            let (mut t, mut mm, mut dd) = (vec![0.0; nv], vec![0.0; nv * nv], vec![0.0; nv]);
            dyngen_algo::rnea(&body, &mut ws, q, v, a, &body.params, &mut t);
            dyngen_algo::crba(&body, &mut ws, q, &body.params, &mut mm);
            dyngen_algo::aba(&body, &mut ws, q, v, &t, &body.params, &vec![0.1; nv], &mut dd);
            assert_bits(&tau[k * nv..][..nv], &t, &format!("{} rnea {k}", R::NAME));
            assert_bits(&m[k * nv * nv..][..nv * nv], &mm, &format!("{} crba {k}", R::NAME));
            assert_bits(&qdd[k * nv..][..nv], &dd, &format!("{} aba {k}", R::NAME));
        }
    }
    check_model::<Panda>(12);
    check_model::<Humanoid31>(13);
}
