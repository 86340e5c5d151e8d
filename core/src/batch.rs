//! Many states per call: the generated functions run on a [`Lanes`] type, several
//! states per evaluation on the SIMD registers, and a batch is split across threads.
//!
//! A [`Batch`] takes the states of `N` evaluations as slices in one of two
//! [`Layout`]s: [`Layout::Rows`], one state after the other (a C-ordered `(N, nq)`
//! array, as numpy and nalgebra's row-major views have it), or [`Layout::Columns`],
//! the structure of arrays (a `(nq, N)` array: each coordinate of every state
//! together), which the lanes load without a gather. Results are written in the same
//! layout. The parameters are shared by the batch.
//!
//! The results are bit for bit those of one call per state ([`crate::lanes`] says why),
//! and a non-finite result is an error naming the state, never a silent value.
//!
//! ```
//! # #[cfg(feature = "macros")] {
//! use dyngen::batch::{Batch, Layout};
//! use dyngen::lanes::F64x4;
//! use dyngen::prelude::*;
//!
//! dyngen::robot! {
//!     name: Pendulum,
//!     incidence: [[-1], [1]],
//!     joints: [revolute(y)],
//!     body_joint_vectors: { (0, 1): [0.0, 0.0, 0.0], (1, 1): [0.0, 0.0, 0.5] },
//!     bodies: { 1: principal(mass: 2.0, moments: [0.01, 0.01, 0.001]) },
//! }
//!
//! // 10 states, one per row: q, v, a each (10, 1).
//! let q: Vec<f64> = (0..10).map(|k| 0.1 * k as f64).collect();
//! let (v, a) = (vec![0.0; 10], vec![0.0; 10]);
//! let mut tau = vec![0.0; 10];
//! Batch::<F64x4>::new(10, Layout::Rows)
//!     .rnea::<Pendulum>(&q, &v, &a, Pendulum::nominal_params(), &mut tau)
//!     .unwrap();
//! for k in 0..10 {
//!     let one: [f64; 1] = Pendulum::rnea(&[q[k]], &[v[k]], &[a[k]], &Pendulum::NOMINAL_PARAMS);
//!     assert_eq!(tau[k].to_bits(), one[0].to_bits());
//! }
//! # }
//! ```

use crate::lanes::Lanes;
use crate::{ForwardDynamics, InverseDynamics, MassMatrix, OrderedScalar, Regressors, Scalar};
use core::fmt;
use core::marker::PhantomData;
use std::string::{String, ToString};
use std::sync::OnceLock;
use std::vec;
use std::vec::Vec;

/// How the states of a batch lie in a slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// One state after the other: value `i` of state `k` at `k·n + i` (a C-ordered
    /// `(N, n)` array).
    Rows,
    /// Structure of arrays: value `i` of state `k` at `i·N + k` (a C-ordered `(n, N)`
    /// array).
    Columns,
}

/// How many threads a batch is split across.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Threads {
    /// One per core (read once per process), but never fewer than
    /// [`Batch::STATES_PER_THREAD`] states per thread: a small batch stays on the
    /// calling thread.
    Auto,
    /// This many, at most one per group of lanes; at least 1.
    Count(usize),
}

/// Why a batch was refused or failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BatchError {
    /// A slice has the wrong length.
    Length {
        /// The argument, as the function names it.
        argument: &'static str,
        /// `N × width`, or the width of a shared argument.
        expected: usize,
        /// Its length.
        found: usize,
    },
    /// A result is not finite (from non-finite input, or a singular mass matrix).
    NonFinite {
        /// The output, as the function names it.
        output: &'static str,
        /// The state, counted from 0.
        state: usize,
    },
    /// `Threads::Count(0)`.
    NoThreads,
    /// The system refused a thread (the message it gave).
    Spawn(String),
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BatchError::Length {
                argument,
                expected,
                found,
            } => write!(f, "`{argument}` has {found} values where the batch needs {expected}"),
            BatchError::NonFinite { output, state } => {
                write!(
                    f,
                    "`{output}` of state {state} is not finite (non-finite input, or a singular mass matrix)"
                )
            }
            BatchError::NoThreads => f.write_str("a batch needs at least one thread; Threads::Count(0) was given"),
            BatchError::Spawn(error) => write!(f, "could not start a batch thread: {error}"),
        }
    }
}

impl std::error::Error for BatchError {}

/// One input of [`Batch::apply`]: `width` values per state.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a, E> {
    /// Named in errors.
    pub name: &'static str,
    /// `N × width` values in the batch's layout.
    pub data: &'a [E],
    /// Values per state.
    pub width: usize,
}

/// One output of [`Batch::apply`]: `width` values per state.
#[derive(Debug)]
pub struct Output<'a, E> {
    /// Named in errors.
    pub name: &'static str,
    /// `N × width` values in the batch's layout.
    pub data: &'a mut [E],
    /// Values per state.
    pub width: usize,
}

/// `N` evaluations of a generated function, `L::LANES` states per call, split across
/// threads. See the [module](self) documentation.
#[derive(Clone, Copy, Debug)]
pub struct Batch<L: Lanes> {
    states: usize,
    layout: Layout,
    threads: Threads,
    lanes: PhantomData<L>,
}

/// The cores, read once: `available_parallelism` reads cgroup files on every call.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

impl<L: Lanes> Batch<L> {
    /// [`Threads::Auto`] gives each thread at least this many states.
    pub const STATES_PER_THREAD: usize = 512;
    /// The stack of the threads a batch starts (address space, committed only as
    /// used): a generated function on lanes keeps `LANES` times the values of one
    /// state, and an unoptimised build keeps every intermediate on the stack. The
    /// calling thread computes its share on its own stack.
    pub const THREAD_STACK: usize = 64 << 20;

    /// A batch of `states` states in `layout`, on [`Threads::Auto`].
    pub fn new(states: usize, layout: Layout) -> Self {
        Batch {
            states,
            layout,
            threads: Threads::Auto,
            lanes: PhantomData,
        }
    }

    /// The same batch on `threads`.
    pub fn threads(self, threads: Threads) -> Self {
        Batch { threads, ..self }
    }

    /// The number of states.
    pub fn states(&self) -> usize {
        self.states
    }

    /// [`InverseDynamics::rnea`] of every state: `q` (`NQ` per state), `v`, `a`, `tau`
    /// (`NV`); `params` (`NPARAMS`) shared.
    pub fn rnea<R: InverseDynamics>(
        &self,
        q: &[L::Elem],
        v: &[L::Elem],
        a: &[L::Elem],
        params: &[L::Elem],
        tau: &mut [L::Elem],
    ) -> Result<(), BatchError> {
        let p = shared::<L>("params", params, R::NPARAMS)?;
        self.apply(
            &[
                Input::of("q", q, R::NQ),
                Input::of("v", v, R::NV),
                Input::of("a", a, R::NV),
            ],
            &mut [Output::of("tau", tau, R::NV)],
            |x, y| R::rnea(&x[0], &x[1], &x[2], &p, &mut y[0]),
        )
    }

    /// [`InverseDynamics::nonlinear_effects`] of every state: `q` (`NQ`), `v`, `tau`
    /// (`NV`); `params` shared.
    pub fn nonlinear_effects<R: InverseDynamics>(
        &self,
        q: &[L::Elem],
        v: &[L::Elem],
        params: &[L::Elem],
        tau: &mut [L::Elem],
    ) -> Result<(), BatchError> {
        let p = shared::<L>("params", params, R::NPARAMS)?;
        self.apply(
            &[Input::of("q", q, R::NQ), Input::of("v", v, R::NV)],
            &mut [Output::of("tau", tau, R::NV)],
            |x, y| R::nonlinear_effects(&x[0], &x[1], &p, &mut y[0]),
        )
    }

    /// [`InverseDynamics::generalized_gravity`] of every state: `q` (`NQ`), `tau`
    /// (`NV`); `params` shared.
    pub fn generalized_gravity<R: InverseDynamics>(
        &self,
        q: &[L::Elem],
        params: &[L::Elem],
        tau: &mut [L::Elem],
    ) -> Result<(), BatchError> {
        let p = shared::<L>("params", params, R::NPARAMS)?;
        self.apply(
            &[Input::of("q", q, R::NQ)],
            &mut [Output::of("tau", tau, R::NV)],
            |x, y| R::generalized_gravity(&x[0], &p, &mut y[0]),
        )
    }

    /// [`MassMatrix::crba`] of every state: `q` (`NQ`), `m` (`NV × NV` row-major per
    /// state); `params` shared.
    pub fn crba<R: MassMatrix>(&self, q: &[L::Elem], params: &[L::Elem], m: &mut [L::Elem]) -> Result<(), BatchError> {
        let p = shared::<L>("params", params, R::NPARAMS)?;
        self.apply(
            &[Input::of("q", q, R::NQ)],
            &mut [Output::of("m", m, R::NV * R::NV)],
            |x, y| R::crba(&x[0], &p, &mut y[0]),
        )
    }

    /// [`ForwardDynamics::aba`] of every state: `q` (`NQ`), `v`, `tau`, `a` (`NV`);
    /// `params` shared. A state whose mass matrix is singular is reported.
    pub fn aba<R: ForwardDynamics>(
        &self,
        q: &[L::Elem],
        v: &[L::Elem],
        tau: &[L::Elem],
        params: &[L::Elem],
        a: &mut [L::Elem],
    ) -> Result<(), BatchError> {
        let p = shared::<L>("params", params, R::NPARAMS)?;
        self.apply(
            &[
                Input::of("q", q, R::NQ),
                Input::of("v", v, R::NV),
                Input::of("tau", tau, R::NV),
            ],
            &mut [Output::of("a", a, R::NV)],
            |x, y| R::aba(&x[0], &x[1], &x[2], &p, &mut y[0]),
        )
    }

    /// [`Regressors::joint_torque_regressor`] of every state: `q` (`NQ`), `v`, `a`
    /// (`NV`), `y` (`NV × NPARAMS` row-major per state).
    pub fn joint_torque_regressor<R: Regressors>(
        &self,
        q: &[L::Elem],
        v: &[L::Elem],
        a: &[L::Elem],
        y: &mut [L::Elem],
    ) -> Result<(), BatchError> {
        self.apply(
            &[
                Input::of("q", q, R::NQ),
                Input::of("v", v, R::NV),
                Input::of("a", a, R::NV),
            ],
            &mut [Output::of("y", y, R::NV * R::NPARAMS)],
            |x, y| R::joint_torque_regressor(&x[0], &x[1], &x[2], &mut y[0]),
        )
    }

    /// Any function of the states: `kernel` gets every input as `width` lanes
    /// (`L::LANES` states; a last, partial group repeats its last state) and writes
    /// every output as `width` lanes. Lengths are checked first; a non-finite output
    /// value stops the batch with the first such state.
    ///
    /// ```
    /// use dyngen::batch::{Batch, Input, Layout, Output};
    /// use dyngen::lanes::F64x4;
    /// use dyngen::Scalar;
    /// // The norm of 6 two-vectors, in columns: x = row 0, y = row 1.
    /// let xy = [3.0, 0.0, 1.0, 5.0, 6.0, 8.0, 4.0, 2.0, 1.0, 12.0, 8.0, 6.0];
    /// let mut norm = [0.0; 6];
    /// Batch::<F64x4>::new(6, Layout::Columns)
    ///     .apply(
    ///         &[Input { name: "xy", data: &xy, width: 2 }],
    ///         &mut [Output { name: "norm", data: &mut norm, width: 1 }],
    ///         |x, y| y[0][0] = (x[0][0] * x[0][0] + x[0][1] * x[0][1]).sqrt(),
    ///     )
    ///     .unwrap();
    /// assert_eq!(norm, [5.0, 2.0, 1.4142135623730951, 13.0, 10.0, 10.0]);
    /// ```
    pub fn apply<F>(
        &self,
        inputs: &[Input<'_, L::Elem>],
        outputs: &mut [Output<'_, L::Elem>],
        kernel: F,
    ) -> Result<(), BatchError>
    where
        F: Fn(&[Vec<L>], &mut [Vec<L>]) + Sync,
    {
        self.apply_with(inputs, outputs, || (), |_, x, y| kernel(x, y))
    }

    /// [`Batch::apply`] with a state per thread, made by `init` on the thread: the
    /// workspace of a run-time algorithm, say. `dyngen-algo`'s algorithms run on the
    /// lane types too:
    ///
    /// ```
    /// use dyngen::batch::{Batch, Input, Layout, Output};
    /// use dyngen::lanes::F64x4;
    /// use dyngen_algo::{rnea, JointSpec, JointType, Multibody, Se3, Workspace};
    /// use dyngen::Scalar;
    /// // A pendulum about y, 2 kg at 0.5 m below the joint (see dyngen_algo).
    /// let (m, l) = (2.0, -0.5);
    /// let joint = JointSpec { kind: JointType::Revolute, parent: 0, origin: Se3::identity(0.0, 1.0),
    ///     axis: [0.0, 1.0, 0.0], plane: [[0.0; 3]; 2],
    ///     params: [m, 0.0, 0.0, m * l, m * l * l, 0.0, m * l * l, 0.0, 0.0, 0.0] };
    /// let body = Multibody::new([0.0, 0.0, -9.81], &[joint]).unwrap();
    /// let params: Vec<F64x4> = body.params.iter().map(|&p| F64x4::from_f64(p)).collect();
    /// let q = [0.0, 0.5, 1.0, 1.5, 2.0];
    /// let mut tau = [0.0; 5];
    /// Batch::<F64x4>::new(5, Layout::Rows)
    ///     .apply_with(
    ///         &[Input { name: "q", data: &q, width: 1 }],
    ///         &mut [Output { name: "tau", data: &mut tau, width: 1 }],
    ///         || Workspace::<F64x4>::new(&body, ()),
    ///         |ws, x, y| rnea(&body, ws, &x[0], &[F64x4::ZERO], &[F64x4::ZERO], &params, &mut y[0]),
    ///     )
    ///     .unwrap();
    /// assert!((tau[1] - m * 9.81 * 0.5 * 0.5f64.sin()).abs() < 1e-12);
    /// ```
    pub fn apply_with<T, I, F>(
        &self,
        inputs: &[Input<'_, L::Elem>],
        outputs: &mut [Output<'_, L::Elem>],
        init: I,
        kernel: F,
    ) -> Result<(), BatchError>
    where
        I: Fn() -> T + Sync,
        F: Fn(&mut T, &[Vec<L>], &mut [Vec<L>]) + Sync,
    {
        let n = self.states;
        for x in inputs {
            check_length(x.name, x.data.len(), n * x.width)?;
        }
        for y in outputs.iter() {
            check_length(y.name, y.data.len(), n * y.width)?;
        }
        let groups = n.div_ceil(L::LANES);
        let threads = match self.threads {
            Threads::Count(0) => return Err(BatchError::NoThreads),
            Threads::Count(t) => t.min(groups).max(1),
            Threads::Auto if n < 2 * Self::STATES_PER_THREAD => 1,
            Threads::Auto => cores().min(n / Self::STATES_PER_THREAD).max(1),
        };
        // Each thread a range of whole groups.
        let per_thread = groups.div_ceil(threads) * L::LANES;
        let ranges: Vec<(usize, usize)> = (0..threads)
            .map(|t| ((t * per_thread).min(n), ((t + 1) * per_thread).min(n)))
            .filter(|(s, e)| s < e)
            .collect();
        let mut ins: Vec<Vec<View<'_, L::Elem>>> = vec![Vec::with_capacity(inputs.len()); ranges.len()];
        for x in inputs {
            for (t, view) in View::split(x.data, x.width, n, self.layout, &ranges)
                .into_iter()
                .enumerate()
            {
                ins[t].push(view);
            }
        }
        let mut outs: Vec<Vec<ViewMut<'_, L::Elem>>> = (0..ranges.len()).map(|_| Vec::new()).collect();
        for y in outputs.iter_mut() {
            let (name, width) = (y.name, y.width);
            for (t, view) in ViewMut::split(&mut *y.data, name, width, n, self.layout, &ranges)
                .into_iter()
                .enumerate()
            {
                outs[t].push(view);
            }
        }
        let (init, kernel) = (&init, &kernel);
        let mut work = ranges.iter().zip(ins).zip(outs);
        let Some(((&first, first_in), first_out)) = work.next() else {
            return Ok(());
        };
        std::thread::scope(|scope| {
            let mut handles = Vec::with_capacity(ranges.len() - 1);
            for ((&range, x), y) in work {
                let thread = std::thread::Builder::new().stack_size(Self::THREAD_STACK);
                match thread.spawn_scoped(scope, move || run(range, &x, y, init, kernel)) {
                    Ok(handle) => handles.push(handle),
                    Err(error) => return Err(BatchError::Spawn(error.to_string())),
                }
            }
            let mut result = run(first, &first_in, first_out, init, kernel);
            for handle in handles {
                let r = handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
                if result.is_ok() {
                    result = r;
                }
            }
            result
        })
    }
}

impl<'a, E> Input<'a, E> {
    fn of(name: &'static str, data: &'a [E], width: usize) -> Self {
        Input { name, data, width }
    }
}

impl<'a, E> Output<'a, E> {
    fn of(name: &'static str, data: &'a mut [E], width: usize) -> Self {
        Output { name, data, width }
    }
}

fn check_length(argument: &'static str, found: usize, expected: usize) -> Result<(), BatchError> {
    if found == expected {
        Ok(())
    } else {
        Err(BatchError::Length {
            argument,
            expected,
            found,
        })
    }
}

/// A shared argument, the same in every lane.
fn shared<L: Lanes>(argument: &'static str, x: &[L::Elem], width: usize) -> Result<Vec<L>, BatchError> {
    check_length(argument, x.len(), width)?;
    Ok(x.iter().map(|&x| L::from_f64(x.to_f64())).collect())
}

/// One thread's part of an input: its states' values.
#[derive(Clone)]
enum View<'a, E> {
    /// The rows of its states, `width` values each.
    Rows(&'a [E], usize),
    /// Per value, its states' part of that value's row.
    Columns(Vec<&'a [E]>),
}

impl<'a, E: Copy> View<'a, E> {
    fn width(&self) -> usize {
        match self {
            View::Rows(_, width) => *width,
            View::Columns(rows) => rows.len(),
        }
    }

    fn split(data: &'a [E], width: usize, n: usize, layout: Layout, ranges: &[(usize, usize)]) -> Vec<Self> {
        match layout {
            Layout::Rows => ranges
                .iter()
                .map(|&(s, e)| View::Rows(&data[s * width..e * width], width))
                .collect(),
            Layout::Columns => ranges
                .iter()
                .map(|&(s, e)| View::Columns((0..width).map(|i| &data[i * n + s..i * n + e]).collect()))
                .collect(),
        }
    }

    /// Value `i` of the states `k..k + count` into `lanes[i]`, the last state
    /// repeated to fill the lanes. `tile`: `width × LANES` values of room.
    fn gather<L: Lanes<Elem = E>>(&self, k: usize, count: usize, tile: &mut [E], lanes: &mut [L]) {
        let n = L::LANES;
        match self {
            View::Columns(rows) if count == n => {
                for (lane, row) in lanes.iter_mut().zip(rows) {
                    *lane = L::from_lanes(&row[k..k + n]);
                }
            }
            View::Columns(rows) => {
                for (lane, row) in lanes.iter_mut().zip(rows) {
                    let tile = &mut tile[..n];
                    for (j, t) in tile.iter_mut().enumerate() {
                        *t = row[k + j.min(count - 1)];
                    }
                    *lane = L::from_lanes(tile);
                }
            }
            View::Rows(data, width) => {
                // The states' rows, read in order, into a tile of one lane group per value.
                for j in 0..n {
                    let state = k + j.min(count - 1);
                    for (i, &x) in data[state * width..(state + 1) * width].iter().enumerate() {
                        tile[i * n + j] = x;
                    }
                }
                for (lane, tile) in lanes.iter_mut().zip(tile.chunks_exact(n)) {
                    *lane = L::from_lanes(tile);
                }
            }
        }
    }
}

/// One thread's part of an output.
enum ViewMut<'a, E> {
    Rows {
        name: &'static str,
        data: &'a mut [E],
        width: usize,
    },
    Columns {
        name: &'static str,
        rows: Vec<&'a mut [E]>,
    },
}

impl<'a, E: OrderedScalar> ViewMut<'a, E> {
    fn width(&self) -> usize {
        match self {
            ViewMut::Rows { width, .. } => *width,
            ViewMut::Columns { rows, .. } => rows.len(),
        }
    }

    fn split(
        data: &'a mut [E],
        name: &'static str,
        width: usize,
        n: usize,
        layout: Layout,
        ranges: &[(usize, usize)],
    ) -> Vec<Self> {
        match layout {
            Layout::Rows => {
                let mut rest = data;
                let mut views = Vec::with_capacity(ranges.len());
                for &(s, e) in ranges {
                    let (mine, tail) = core::mem::take(&mut rest).split_at_mut((e - s) * width);
                    views.push(ViewMut::Rows {
                        name,
                        data: mine,
                        width,
                    });
                    rest = tail;
                }
                views
            }
            Layout::Columns => {
                let mut views: Vec<Vec<&'a mut [E]>> = (0..ranges.len()).map(|_| Vec::with_capacity(width)).collect();
                for row in data.chunks_mut(n.max(1)).take(width) {
                    let mut rest = row;
                    for (t, &(s, e)) in ranges.iter().enumerate() {
                        let (mine, tail) = core::mem::take(&mut rest).split_at_mut(e - s);
                        views[t].push(mine);
                        rest = tail;
                    }
                }
                views.into_iter().map(|rows| ViewMut::Columns { name, rows }).collect()
            }
        }
    }

    /// `lanes` (value `i` in `lanes[i]`) into the states `k..k + count`; the first
    /// state with a non-finite value is an error (`offset`: the thread's first state).
    /// `tile`: `width × LANES` values of room.
    fn scatter<L: Lanes<Elem = E>>(
        &mut self,
        k: usize,
        count: usize,
        offset: usize,
        tile: &mut [E],
        lanes: &[L],
    ) -> Result<(), BatchError> {
        let n = L::LANES;
        match self {
            ViewMut::Columns { rows, .. } if count == n => {
                for (lane, row) in lanes.iter().zip(rows.iter_mut()) {
                    lane.write_lanes(&mut row[k..k + n]);
                }
            }
            ViewMut::Columns { rows, .. } => {
                for (lane, row) in lanes.iter().zip(rows.iter_mut()) {
                    lane.write_lanes(&mut tile[..n]);
                    row[k..k + count].copy_from_slice(&tile[..count]);
                }
            }
            ViewMut::Rows { data, width, .. } => {
                // Each state's row in order, lane j of every value (read in place).
                for j in 0..count {
                    let state = k + j;
                    for (x, lane) in data[state * *width..(state + 1) * *width].iter_mut().zip(lanes) {
                        *x = lane.lane(j);
                    }
                }
            }
        }
        // The padding lanes repeat the last state, so every lane is finite exactly
        // when every state is; only then is each state looked at.
        if lanes.iter().all(|x| x.is_finite()) {
            return Ok(());
        }
        let mut scratch = vec![E::ZERO; n];
        let first = (0..count)
            .find(|&j| {
                lanes.iter().any(|lane| {
                    lane.write_lanes(&mut scratch[..n]);
                    !scratch[j].is_finite()
                })
            })
            .unwrap_or(0);
        let output = match self {
            ViewMut::Rows { name, .. } | ViewMut::Columns { name, .. } => *name,
        };
        Err(BatchError::NonFinite {
            output,
            state: offset + k + first,
        })
    }
}

/// One thread's states `range`, a group of lanes at a time.
fn run<L: Lanes, T, I, F>(
    (start, end): (usize, usize),
    inputs: &[View<'_, L::Elem>],
    mut outputs: Vec<ViewMut<'_, L::Elem>>,
    init: &I,
    kernel: &F,
) -> Result<(), BatchError>
where
    I: Fn() -> T,
    F: Fn(&mut T, &[Vec<L>], &mut [Vec<L>]),
{
    let mut state = init();
    let mut x: Vec<Vec<L>> = inputs.iter().map(|v| vec![L::ZERO; v.width()]).collect();
    let mut y: Vec<Vec<L>> = outputs.iter().map(|v| vec![L::ZERO; v.width()]).collect();
    let widest = inputs
        .iter()
        .map(View::width)
        .chain(outputs.iter().map(ViewMut::width))
        .max();
    let mut tile = vec![L::Elem::ZERO; widest.unwrap_or(0) * L::LANES];
    let n = end - start;
    let mut k = 0;
    while k < n {
        let count = L::LANES.min(n - k);
        for (view, lanes) in inputs.iter().zip(&mut x) {
            view.gather(k, count, &mut tile, lanes);
        }
        kernel(&mut state, &x, &mut y);
        for (view, lanes) in outputs.iter_mut().zip(&y) {
            view.scatter(k, count, start, &mut tile, lanes)?;
        }
        k += count;
    }
    Ok(())
}
