//! The control examples' core functions with fixed settings, and the outcomes they must
//! reach; and that their loops do not allocate. The examples are included as modules,
//! so example and test run the same code.

#[path = "../computed_torque.rs"]
mod computed_torque;
#[path = "../ilqr.rs"]
mod ilqr;
#[path = "../inverse_kinematics.rs"]
mod inverse_kinematics;

use robot_panda::Panda;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the allocations each thread makes (tests run on
/// several threads at once).
struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// How many allocations `f` makes on this thread.
fn allocations<T>(f: impl FnOnce() -> T) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    std::hint::black_box(f());
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn inverse_kinematics_reaches_the_target_within_limits() {
    let settings = inverse_kinematics::IkSettings::default();
    let panda = inverse_kinematics::panda_flange(&settings);
    assert!(panda.converged, "{panda:?}");
    assert!(
        panda.position_error < 1e-9 && panda.orientation_error < 1e-9,
        "{panda:?}"
    );
    // The start is far enough that early steps hit limits; the answer respects them.
    assert!(panda.clamped_iterations > 0, "{panda:?}");
    let limits = inverse_kinematics::joint_limits::<7>(&Panda::MODEL);
    assert!((0..7).all(|j| (limits[j].0..=limits[j].1).contains(&panda.q[j])));

    let ur5 = inverse_kinematics::ur5_tool0(&settings);
    assert!(ur5.converged, "{ur5:?}");
    assert!(ur5.position_error < 1e-9 && ur5.orientation_error < 1e-9, "{ur5:?}");
    assert!(ur5.iterations < 20, "{ur5:?}");
}

#[test]
fn computed_torque_tracks_despite_model_mismatch() {
    use computed_torque::{computed_torque, perturbed_plant, JointGains, SimSettings};
    let sim = SimSettings::default();
    // Plant = model: only the 1 ms zero-order hold is left.
    let exact = computed_torque(&Panda::NOMINAL_PARAMS, &JointGains::pd(25.0), &sim);
    assert!(exact.max_error < 5e-4, "{exact:?}");
    // 0.5 kg payload and links 3 % heavier: PD leaves a few centiradians at the wrist,
    // PID (same bandwidth) well under one.
    let plant = perturbed_plant();
    let pd = computed_torque(&plant, &JointGains::pd(25.0), &sim);
    assert!(pd.max_error < 0.1, "{pd:?}");
    let pid = computed_torque(&plant, &JointGains::pid(25.0), &sim);
    assert!(pid.max_error < 0.01 && pid.final_error < 5e-3, "{pid:?}");
    assert!(pid.max_torque < 87.0, "{pid:?}");
}

#[test]
fn operational_space_control_reaches_the_goal() {
    use computed_torque::{operational_space, perturbed_plant, OscGains, SimSettings};
    let (sim, gains) = (SimSettings::default(), OscGains::default());
    let exact = operational_space(&Panda::NOMINAL_PARAMS, &gains, &sim);
    assert!(exact.distance > 0.15, "{exact:?}");
    assert!(exact.max_error < 1e-4 && exact.final_error < 1e-6, "{exact:?}");
    // With the payload the task-space PD settles short by weight / stiffness.
    let perturbed = operational_space(&perturbed_plant(), &gains, &sim);
    assert!(
        perturbed.max_error < 5e-3 && perturbed.final_error < 5e-3,
        "{perturbed:?}"
    );
}

#[test]
fn ilqr_decreases_the_cost_and_its_linearization_is_exact() {
    // The example's problem (100 steps of 10 ms), a few iterations.
    let mut costs = Vec::new();
    let result = ilqr::optimize(ilqr::Problem::default(), 4, |_, it| costs.push(it.cost));
    assert!(costs.windows(2).all(|w| w[1] <= w[0]), "{costs:?}");
    assert!(result.final_cost < 0.1 * result.initial_cost, "{result:?}");
    assert!(result.final_position_error < 1e-2, "{result:?}");
    let (ea, eb) = result.linearization_error;
    assert!(ea < 1e-5 && eb < 1e-5, "{result:?}");
}

#[test]
fn control_loops_do_not_allocate() {
    use computed_torque::{computed_torque, operational_space, perturbed_plant, JointGains, OscGains, SimSettings};
    assert_eq!(allocations(|| vec![0.0; 3]), 1, "the counter counts");
    let settings = inverse_kinematics::IkSettings::default();
    assert_eq!(allocations(|| inverse_kinematics::panda_flange(&settings)), 0, "IK");
    let (sim, plant) = (
        SimSettings {
            dt: 1e-3,
            duration: 0.1,
        },
        perturbed_plant(),
    );
    let pid = JointGains::pid(25.0);
    assert_eq!(
        allocations(|| computed_torque(&plant, &pid, &sim)),
        0,
        "computed torque"
    );
    let gains = OscGains::default();
    assert_eq!(
        allocations(|| operational_space(&plant, &gains, &sim)),
        0,
        "operational space"
    );
    // iLQR allocates its trajectories and gains once, up front.
    let mut solver = ilqr::Ilqr::new(ilqr::Problem::default());
    assert_eq!(allocations(|| solver.iterate()), 0, "iLQR iteration");
}
