//! The algorithms allocate nothing per call: every buffer lives in the workspace,
//! made once. Counted by a global allocator on a free-flyer humanoid (31 joints
//! under a free flyer: ball-free, but 6-coordinate root) and the planar mobile arm.

use dyngen_algo::{
    aba, compute_frame_jacobian, crba, forward_kinematics, frame_jacobian, joint_torque_regressor, rnea,
    ReferenceFrame, Se3, Workspace,
};
use dyngen_model::{load_urdf_options, LoadOptions};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn no_algorithm_allocates_per_call() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for (urdf, free_flyer) in [
        ("robots/humanoid31/humanoid31.urdf", true),
        ("tests/fixtures/mobile_arm.urdf", false),
    ] {
        let options = LoadOptions {
            free_flyer,
            ..LoadOptions::default()
        };
        let model = load_urdf_options(&root.join(urdf), options).unwrap();
        let body = model.multibody().unwrap();
        let (nq, nv) = (body.nq(), body.nv());
        let mut ws = Workspace::new(&body, ());
        let q = body.neutral();
        let (v, a) = (vec![0.3; nv], vec![-0.2; nv]);
        let (mut tau, mut qdd, mut m, mut jac) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv * nv], vec![0.0; 6 * nv]);
        let mut y = vec![0.0; nv * 10 * body.bodies()];
        let params = body.params.clone();
        let armature = vec![0.01; nv];
        let frame = Se3::identity(0.0, 1.0);
        assert_eq!(q.len(), nq);
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..3 {
            rnea(&body, &mut ws, &q, &v, &a, &params, &mut tau);
            crba(&body, &mut ws, &q, &params, &mut m);
            aba(&body, &mut ws, &q, &v, &tau, &params, &armature, &mut qdd);
            forward_kinematics(&body, &mut ws, &q);
            frame_jacobian(&body, &ws, body.bodies(), &frame, ReferenceFrame::Local, &mut jac);
            compute_frame_jacobian(
                &body,
                &mut ws,
                &q,
                body.bodies(),
                &frame,
                ReferenceFrame::World,
                &mut jac,
            );
            joint_torque_regressor(&body, &mut ws, &q, &v, &a, &mut y);
        }
        let after = ALLOCATIONS.load(Ordering::SeqCst);
        assert_eq!(
            after - before,
            0,
            "{urdf}: {} allocations in the algorithms",
            after - before
        );
        assert!(qdd.iter().all(|x| x.is_finite()), "{urdf}");
    }
}
