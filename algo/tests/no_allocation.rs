//! The algorithms allocate nothing per call: every buffer lives in the workspace,
//! made once. Counted by a global allocator on a free-flyer humanoid (31 joints
//! under a free flyer: ball-free, but 6-coordinate root), the planar mobile arm and a
//! gripper with mimic joints.

use dyngen_algo::{
    aba, aba_derivatives, body_motions, centroidal_map, centroidal_map_time_variation, com_jacobian,
    compute_frame_jacobian, crba, forward_kinematics, frame_classical_acceleration, frame_jacobian,
    frame_jacobian_time_variation, frame_velocity, joint_torque_regressor, rnea, rnea_derivatives, DualWorkspace,
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
        // Mimic joints: the tree's coordinates and results live in the workspace too.
        ("tests/fixtures/mimic/arm_linkage_gripper.urdf", false),
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
        let (mut dual8, mut dual1) = (
            DualWorkspace::<f64, 8>::new(&body, ()),
            DualWorkspace::<f64, 1>::new(&body, ()),
        );
        let [mut d1, mut d2, mut d3] = [(); 3].map(|_| vec![0.0; nv * nv]);
        let (mut jac_dot, mut jcom, mut ag, mut ag_dot) = (
            vec![0.0; 6 * nv],
            vec![0.0; 3 * nv],
            vec![0.0; 6 * nv],
            vec![0.0; 6 * nv],
        );
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
            rnea_derivatives(
                &body, &mut dual8, &mut ws, &q, &v, &a, &params, &mut d1, &mut d2, &mut d3,
            );
            aba_derivatives(
                &body, &mut dual8, &mut ws, &q, &v, &tau, &params, &armature, &mut qdd, &mut d1, &mut d2, &mut d3,
            );
            body_motions(&body, &mut ws, &q, &v, &a);
            frame_velocity(&body, &ws, body.bodies(), &frame, ReferenceFrame::Local);
            frame_classical_acceleration(&body, &mut dual1, &q, &v, &a, 1, &frame, ReferenceFrame::World);
            let last = body.bodies();
            frame_jacobian_time_variation(
                &body,
                &mut dual1,
                &q,
                &v,
                last,
                &frame,
                ReferenceFrame::LocalWorldAligned,
                &mut jac,
                &mut jac_dot,
            );
            com_jacobian(&body, &mut ws, &q, &params, &mut jcom);
            centroidal_map(&body, &mut ws, &q, &params, &mut ag);
            centroidal_map_time_variation(&body, &mut dual1, &q, &v, &params, &mut ag, &mut ag_dot);
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
