//! Trajectory optimisation on the generated derivatives: iLQR swings the Panda from its
//! ready pose to a goal configuration, at rest, in 100 steps of 10 ms.
//!
//! The discrete dynamics are one semi-implicit Euler step of the generated `aba`
//! (`v⁺ = v + dt·q̈`, `q⁺ = q + dt·v⁺`, torque held); their Jacobians `A = ∂x⁺/∂x`,
//! `B = ∂x⁺/∂τ` come from the generated `aba_derivatives` and
//! `AbaDerivatives::semi_implicit_euler`, and are checked once against central
//! differences of the step. Costs are quadratic: distance to the goal and velocity along
//! the way, torque away from the goal's gravity torque, and a heavy terminal cost on the
//! goal at rest. Each iteration runs the Riccati backward pass (Gauss–Newton,
//! Levenberg–Marquardt regularisation of `Q_uu`) and a forward pass with a backtracking
//! line search on the true dynamics. The trajectories and gains are allocated once, up
//! front; the iterations do not allocate.
//!
//!     cargo run --release -p dyngen-examples --example ilqr

use dyngen::nalgebra::{SMatrix, SVector};
use dyngen::AbaDerivatives;
use robot_panda::Panda;

/// 7 joint positions, velocities or torques.
pub type Joints = [f64; 7];
type Vec7 = SVector<f64, 7>;
type Vec14 = SVector<f64, 14>;
type Mat7 = SMatrix<f64, 7, 7>;
type Mat14 = SMatrix<f64, 14, 14>;
type Mat14x7 = SMatrix<f64, 14, 7>;
type Mat7x14 = SMatrix<f64, 7, 14>;

/// The Panda's ready pose.
pub const Q_READY: Joints = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// The optimal-control problem: horizon, start (at rest), goal (at rest) and cost
/// weights. Running cost `dt·½(w_q |q − q*|² + w_v |v|² + w_u |τ − g(q*)|²)`, terminal
/// cost `½(w_q_final |q − q*|² + w_v_final |v|²)`.
#[derive(Clone, Copy, Debug)]
pub struct Problem {
    pub steps: usize,
    pub dt: f64,
    pub q_start: Joints,
    pub q_goal: Joints,
    pub w_q: f64,
    pub w_v: f64,
    pub w_u: f64,
    pub w_q_final: f64,
    pub w_v_final: f64,
}

impl Default for Problem {
    fn default() -> Self {
        Problem {
            steps: 100,
            dt: 0.01,
            q_start: Q_READY,
            // The ready pose plus (0.8, 0.5, −0.6, 0.7, −0.8, −0.5, 1.0) rad.
            q_goal: [0.8, -0.285, -0.6, -1.656, -0.8, 1.071, 1.785],
            w_q: 1.0,
            w_v: 0.1,
            w_u: 1e-3,
            w_q_final: 1e3,
            w_v_final: 1e2,
        }
    }
}

/// The discrete dynamics: one semi-implicit Euler step of `q̈ = aba(q, v, τ)`.
pub fn step(q: &Joints, v: &Joints, tau: &Joints, dt: f64) -> (Joints, Joints) {
    let a = Panda::aba(q, v, tau, &Panda::NOMINAL_PARAMS);
    let v1: Joints = core::array::from_fn(|j| v[j] + dt * a[j]);
    let q1: Joints = core::array::from_fn(|j| q[j] + dt * v1[j]);
    (q1, v1)
}

/// `A` (14 × 14) and `B` (14 × 7) of [`step`] at `(q, v, τ)`, state `x = (q, v)`.
pub fn linearize(q: &Joints, v: &Joints, tau: &Joints, dt: f64) -> (Mat14, Mat14x7) {
    let mut d = AbaDerivatives::<f64, 7>::default();
    Panda::aba_derivatives(q, v, tau, &Panda::NOMINAL_PARAMS, &mut d);
    let l = d.semi_implicit_euler(q, v, dt);
    let a = Mat14::from_fn(|r, c| l.a(r, c).expect("inside A"));
    let b = Mat14x7::from_fn(|r, c| l.b(r, c).expect("inside B"));
    (a, b)
}

/// Largest difference between [`linearize`]'s `A`, `B` and central differences of
/// [`step`] (steps 1e-6 in `q` and `v`, 1e-5 N·m in `τ`): `(max |ΔA|, max |ΔB|)`.
pub fn linearization_error(q: &Joints, v: &Joints, tau: &Joints, dt: f64) -> (f64, f64) {
    let (a, b) = linearize(q, v, tau, dt);
    let state = |(q, v): (Joints, Joints)| Vec14::from_fn(|i, _| if i < 7 { q[i] } else { v[i - 7] });
    let nudged = |x: &Joints, i: usize, h: f64| -> Joints {
        let mut y = *x;
        y[i] += h;
        y
    };
    let (mut err_a, mut err_b) = (0.0f64, 0.0f64);
    for c in 0..14 {
        let h = 1e-6;
        let (plus, minus) = if c < 7 {
            (step(&nudged(q, c, h), v, tau, dt), step(&nudged(q, c, -h), v, tau, dt))
        } else {
            (
                step(q, &nudged(v, c - 7, h), tau, dt),
                step(q, &nudged(v, c - 7, -h), tau, dt),
            )
        };
        let column = (state(plus) - state(minus)) / (2.0 * h);
        err_a = err_a.max((column - a.column(c)).amax());
    }
    for c in 0..7 {
        let h = 1e-5;
        let plus = step(q, v, &nudged(tau, c, h), dt);
        let minus = step(q, v, &nudged(tau, c, -h), dt);
        let column = (state(plus) - state(minus)) / (2.0 * h);
        err_b = err_b.max((column - b.column(c)).amax());
    }
    (err_a, err_b)
}

/// One iteration, as [`Ilqr::iterate`] reports it.
#[derive(Clone, Copy, Debug)]
pub struct Iteration {
    pub cost: f64,
    /// The step length the line search accepted; `None` when it found no decrease (the
    /// regularisation is raised and the trajectory kept).
    pub alpha: Option<f64>,
    /// The regularisation `μ` of `Q_uu` the backward pass used.
    pub mu: f64,
}

/// The iLQR solver: the current trajectory, a candidate for the line search, and the
/// linearisations and gains of the backward pass, all allocated in [`Ilqr::new`].
pub struct Ilqr {
    pub problem: Problem,
    /// Gravity torque at the goal, the torque the running cost is centred on.
    u_goal: Joints,
    q: Vec<Joints>,
    v: Vec<Joints>,
    u: Vec<Joints>,
    q_new: Vec<Joints>,
    v_new: Vec<Joints>,
    u_new: Vec<Joints>,
    a: Vec<Mat14>,
    b: Vec<Mat14x7>,
    k_ff: Vec<Vec7>,
    k_fb: Vec<Mat7x14>,
    cost: f64,
    mu: f64,
}

impl Ilqr {
    /// The solver, its initial guess the start's gravity torque held throughout (the
    /// robot stays at the start).
    pub fn new(problem: Problem) -> Self {
        let n = problem.steps;
        let hold = Panda::generalized_gravity(&problem.q_start, &Panda::NOMINAL_PARAMS);
        let mut solver = Ilqr {
            problem,
            u_goal: Panda::generalized_gravity(&problem.q_goal, &Panda::NOMINAL_PARAMS),
            q: vec![problem.q_start; n + 1],
            v: vec![[0.0; 7]; n + 1],
            u: vec![hold; n],
            q_new: vec![[0.0; 7]; n + 1],
            v_new: vec![[0.0; 7]; n + 1],
            u_new: vec![[0.0; 7]; n],
            a: vec![Mat14::zeros(); n],
            b: vec![Mat14x7::zeros(); n],
            k_ff: vec![Vec7::zeros(); n],
            k_fb: vec![Mat7x14::zeros(); n],
            cost: 0.0,
            mu: 1e-6,
        };
        // A rollout with no feedback and no change: the initial trajectory and cost.
        solver.cost = solver.rollout(0.0);
        std::mem::swap(&mut solver.q, &mut solver.q_new);
        std::mem::swap(&mut solver.v, &mut solver.v_new);
        std::mem::swap(&mut solver.u, &mut solver.u_new);
        solver
    }

    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// The state at the end of the horizon.
    pub fn final_state(&self) -> (Joints, Joints) {
        (self.q[self.problem.steps], self.v[self.problem.steps])
    }

    /// The state and torque at step `k` of the current trajectory.
    pub fn at(&self, k: usize) -> (Joints, Joints, Joints) {
        (self.q[k], self.v[k], self.u[k])
    }

    fn running_cost(&self, q: &Joints, v: &Joints, u: &Joints) -> f64 {
        let p = &self.problem;
        let mut c = 0.0;
        for j in 0..7 {
            let (dq, du) = (q[j] - p.q_goal[j], u[j] - self.u_goal[j]);
            c += p.w_q * dq * dq + p.w_v * v[j] * v[j] + p.w_u * du * du;
        }
        0.5 * p.dt * c
    }

    fn terminal_cost(&self, q: &Joints, v: &Joints) -> f64 {
        let p = &self.problem;
        let mut c = 0.0;
        for j in 0..7 {
            let dq = q[j] - p.q_goal[j];
            c += p.w_q_final * dq * dq + p.w_v_final * v[j] * v[j];
        }
        0.5 * c
    }

    /// The closed-loop rollout `τ = τ̄ + α k + K (x − x̄)` on the true dynamics into the
    /// candidate trajectory; returns its cost.
    fn rollout(&mut self, alpha: f64) -> f64 {
        let (n, dt) = (self.problem.steps, self.problem.dt);
        self.q_new[0] = self.problem.q_start;
        self.v_new[0] = [0.0; 7];
        let mut cost = 0.0;
        for k in 0..n {
            let dx = Vec14::from_fn(|i, _| {
                if i < 7 {
                    self.q_new[k][i] - self.q[k][i]
                } else {
                    self.v_new[k][i - 7] - self.v[k][i - 7]
                }
            });
            let du = alpha * self.k_ff[k] + self.k_fb[k] * dx;
            self.u_new[k] = core::array::from_fn(|j| self.u[k][j] + du[j]);
            cost += self.running_cost(&self.q_new[k], &self.v_new[k], &self.u_new[k]);
            (self.q_new[k + 1], self.v_new[k + 1]) = step(&self.q_new[k], &self.v_new[k], &self.u_new[k], dt);
        }
        cost + self.terminal_cost(&self.q_new[n], &self.v_new[n])
    }

    /// The Riccati recursion along the current trajectory: fills the gains and returns
    /// the expected decrease's linear and quadratic coefficients in `α`, or `None` when
    /// `Q_uu + μ I` is not positive definite somewhere.
    fn backward_pass(&mut self) -> Option<(f64, f64)> {
        let p = self.problem;
        let n = p.steps;
        let grad_q = |q: &Joints, w: f64| Vec7::from_fn(|j, _| w * (q[j] - p.q_goal[j]));
        let stack = |top: Vec7, bottom: Vec7| Vec14::from_fn(|i, _| if i < 7 { top[i] } else { bottom[i - 7] });
        let weights = |wq: f64, wv: f64| Mat14::from_diagonal(&Vec14::from_fn(|i, _| if i < 7 { wq } else { wv }));

        let (qn, vn) = (&self.q[n], &self.v[n]);
        let mut vx = stack(grad_q(qn, p.w_q_final), Vec7::from(*vn) * p.w_v_final);
        let mut vxx = weights(p.w_q_final, p.w_v_final);
        let lxx = weights(p.dt * p.w_q, p.dt * p.w_v);
        let luu = Mat7::identity() * (p.dt * p.w_u);
        let (mut linear, mut quadratic) = (0.0, 0.0);
        for k in (0..n).rev() {
            let (a, b) = (&self.a[k], &self.b[k]);
            let lx = stack(grad_q(&self.q[k], p.dt * p.w_q), Vec7::from(self.v[k]) * (p.dt * p.w_v));
            let lu = Vec7::from_fn(|j, _| p.dt * p.w_u * (self.u[k][j] - self.u_goal[j]));

            let qx = lx + a.transpose() * vx;
            let qu = lu + b.transpose() * vx;
            let (vxx_a, vxx_b) = (vxx * a, vxx * b);
            let qxx = lxx + a.transpose() * vxx_a;
            let quu = luu + b.transpose() * vxx_b;
            let qux = b.transpose() * vxx_a;

            let chol = (quu + Mat7::identity() * self.mu).cholesky()?;
            let k_ff = -chol.solve(&qu);
            let k_fb = -chol.solve(&qux);

            vx = qx + k_fb.transpose() * (quu * k_ff) + k_fb.transpose() * qu + qux.transpose() * k_ff;
            vxx = qxx + k_fb.transpose() * quu * k_fb + k_fb.transpose() * qux + qux.transpose() * k_fb;
            vxx = 0.5 * (vxx + vxx.transpose());
            linear += k_ff.dot(&qu);
            quadratic += 0.5 * k_ff.dot(&(quu * k_ff));
            self.k_ff[k] = k_ff;
            self.k_fb[k] = k_fb;
        }
        Some((linear, quadratic))
    }

    /// One iteration: linearise along the trajectory, backward pass, line search over
    /// `α = 1, ½, ¼, …` accepting the first step that achieves a tenth of the decrease the
    /// quadratic model predicts.
    pub fn iterate(&mut self) -> Iteration {
        let dt = self.problem.dt;
        for k in 0..self.problem.steps {
            (self.a[k], self.b[k]) = linearize(&self.q[k], &self.v[k], &self.u[k], dt);
        }
        let mu = self.mu;
        let Some((linear, quadratic)) = self.backward_pass() else {
            self.mu *= 10.0;
            return Iteration {
                cost: self.cost,
                alpha: None,
                mu,
            };
        };
        let mut alpha = 1.0;
        for _ in 0..12 {
            let cost = self.rollout(alpha);
            let predicted = -(alpha * linear + alpha * alpha * quadratic);
            if cost < self.cost && self.cost - cost >= 0.1 * predicted {
                std::mem::swap(&mut self.q, &mut self.q_new);
                std::mem::swap(&mut self.v, &mut self.v_new);
                std::mem::swap(&mut self.u, &mut self.u_new);
                self.cost = cost;
                self.mu = (self.mu * 0.3).max(1e-9);
                return Iteration {
                    cost,
                    alpha: Some(alpha),
                    mu,
                };
            }
            alpha *= 0.5;
        }
        self.mu *= 10.0;
        Iteration {
            cost: self.cost,
            alpha: None,
            mu,
        }
    }
}

/// What [`optimize`] reached.
#[derive(Clone, Copy, Debug)]
pub struct IlqrResult {
    pub initial_cost: f64,
    pub final_cost: f64,
    /// `max_j |q_N − q*|`, rad, and `max_j |v_N|`, rad/s.
    pub final_position_error: f64,
    pub final_velocity: f64,
    /// Iterations run: `iterations`, or fewer when the cost stopped decreasing (relative
    /// decrease below 1e-9).
    pub iterations: usize,
    /// Largest `|τ_j|` of the optimised trajectory as a fraction of joint `j`'s effort
    /// limit.
    pub effort: f64,
    /// [`linearization_error`] `(A, B)` halfway along the optimised trajectory.
    pub linearization_error: (f64, f64),
}

/// `iterations` iLQR iterations on `problem`, `log` called with the initial guess
/// (iteration 0) and after each.
pub fn optimize(problem: Problem, iterations: usize, mut log: impl FnMut(usize, &Iteration)) -> IlqrResult {
    let mut solver = Ilqr::new(problem);
    let initial_cost = solver.cost();
    log(
        0,
        &Iteration {
            cost: initial_cost,
            alpha: None,
            mu: solver.mu,
        },
    );
    let mut iterations_run = 0;
    for i in 1..=iterations {
        let previous = solver.cost();
        let it = solver.iterate();
        log(i, &it);
        iterations_run = i;
        if it.alpha.is_some() && previous - it.cost <= 1e-9 * it.cost {
            break;
        }
    }
    let (q, v) = solver.final_state();
    let mut effort = 0.0f64;
    for k in 0..problem.steps {
        let tau = solver.at(k).2;
        for j in 0..7 {
            let limit = Panda::MODEL.joints[j].limits.map_or(f64::INFINITY, |l| l.effort);
            effort = effort.max(tau[j].abs() / limit);
        }
    }
    let (qm, vm, um) = solver.at(problem.steps / 2);
    IlqrResult {
        initial_cost,
        final_cost: solver.cost(),
        final_position_error: (0..7).fold(0.0f64, |m, j| m.max((q[j] - problem.q_goal[j]).abs())),
        final_velocity: v.iter().fold(0.0f64, |m, x| m.max(x.abs())),
        iterations: iterations_run,
        effort,
        linearization_error: linearization_error(&qm, &vm, &um, problem.dt),
    }
}

#[allow(dead_code)]
fn main() {
    let problem = Problem::default();
    println!(
        "iLQR on the Panda: ready pose to goal, at rest, in {} steps of {} ms",
        problem.steps,
        problem.dt * 1e3
    );
    println!("  q* = {:?}\n", problem.q_goal);
    println!("  iter        cost   step α       μ");
    let start = std::time::Instant::now();
    let result = optimize(problem, 20, |i, it| match it.alpha {
        _ if i == 0 => println!("  {i:>4}  {:>12.6e}", it.cost),
        Some(alpha) => println!("  {i:>4}  {:>12.6e}   {alpha:>6}   {:.0e}", it.cost, it.mu),
        None => println!("  {i:>4}  {:>12.6e}  no step   {:.0e}", it.cost, it.mu),
    });
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "\nconverged in {} iterations ({:.2} ms each, linearisation, backward pass and line search): cost {:.4e} → {:.4e}",
        result.iterations,
        1e3 * elapsed / result.iterations as f64,
        result.initial_cost,
        result.final_cost,
    );
    println!(
        "at the end max |q − q*| = {:.1e} rad, max |v| = {:.1e} rad/s; largest torque {:.0} % of its joint's effort limit",
        result.final_position_error,
        result.final_velocity,
        100.0 * result.effort
    );
    let (ea, eb) = result.linearization_error;
    println!(
        "linearisation (aba_derivatives + semi_implicit_euler) against central differences of the step,\n\
         halfway along the optimised trajectory: max |A − A_fd| = {ea:.1e}, max |B − B_fd| = {eb:.1e}"
    );
}
