//! Derivative-free minimisation within a budget of objective evaluations: the
//! Nelder–Mead simplex method of the `argmin` crate (Nelder and Mead, *Computer
//! Journal* 7, 1965), for the excitation design and the drive-gain search.

use argmin::core::{
    CostFunction, Error, Executor, IterState, Problem, Solver, State, TerminationReason, TerminationStatus, KV,
};
use argmin::solver::neldermead::NelderMead;
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// What one run found.
pub(crate) struct Minimum {
    pub x: Vec<f64>,
    pub f: f64,
    /// Evaluations of the objective spent.
    pub evaluations: usize,
}

/// The function minimised.
type Function<'f> = &'f mut dyn FnMut(&[f64]) -> f64;

/// The objective, counted: past the budget it returns `+∞` without calling `f`, and a
/// NaN counts as `+∞`.
struct Counted<'f> {
    f: RefCell<Function<'f>>,
    spent: Cell<usize>,
    budget: usize,
}

impl CostFunction for Counted<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        if self.spent.get() >= self.budget {
            return Ok(f64::INFINITY);
        }
        self.spent.set(self.spent.get() + 1);
        let y = (self.f.borrow_mut())(x);
        Ok(if y.is_nan() { f64::INFINITY } else { y })
    }
}

type Simplex = NelderMead<Vec<f64>, f64>;
type Iterate = IterState<Vec<f64>, (), (), (), (), f64>;

/// argmin's Nelder–Mead, stopped once the budget of evaluations is spent or the
/// deadline has passed (argmin itself counts iterations, which cost one to `d + 1`
/// evaluations each).
struct Budgeted {
    simplex: Simplex,
    budget: u64,
    deadline: Option<Instant>,
}

impl<'f> Solver<Counted<'f>, Iterate> for Budgeted {
    const NAME: &'static str = "Nelder-Mead within a budget of evaluations";

    fn init(&mut self, problem: &mut Problem<Counted<'f>>, state: Iterate) -> Result<(Iterate, Option<KV>), Error> {
        self.simplex.init(problem, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<Counted<'f>>,
        state: Iterate,
    ) -> Result<(Iterate, Option<KV>), Error> {
        self.simplex.next_iter(problem, state)
    }

    fn terminate(&mut self, state: &Iterate) -> TerminationStatus {
        let spent = state.get_func_counts().get("cost_count").copied().unwrap_or(0);
        if spent >= self.budget {
            return TerminationStatus::Terminated(TerminationReason::MaxItersReached);
        }
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            return TerminationStatus::Terminated(TerminationReason::Timeout);
        }
        <Simplex as Solver<Counted<'f>, Iterate>>::terminate(&mut self.simplex, state)
    }
}

/// Minimises `f` from `x0`, with the initial simplex `x0 + steps[k] e_k`, spending at
/// most `budget` evaluations (none when `budget ≤ d + 1`, too few for the first
/// simplex: then `x0` comes back unevaluated, `f = +∞`). Stops early when the
/// standard deviation of the simplex's values falls below `1e-12`, or at `deadline`.
///
/// Coefficients for `d` variables: reflection 1, expansion `1 + 2/d`, contraction
/// 1/2, shrink `1 − 1/d` (the expansion and shrink of Gao and Han, *Comput. Optim.
/// Appl.* 51, 2012, which keep the method useful beyond ten variables; argmin caps
/// the contraction at 1/2).
pub(crate) fn minimise(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    steps: &[f64],
    budget: usize,
    deadline: Option<Instant>,
) -> Minimum {
    let d = x0.len();
    let unevaluated = Minimum {
        x: x0.to_vec(),
        f: f64::INFINITY,
        evaluations: 0,
    };
    if d == 0 || budget <= d + 1 {
        return unevaluated;
    }
    let mut vertices = vec![x0.to_vec()];
    for k in 0..d {
        let mut x = x0.to_vec();
        x[k] += steps[k];
        vertices.push(x);
    }
    let dim = d.max(2) as f64;
    let simplex = NelderMead::new(vertices)
        .with_gamma(1.0 + 2.0 / dim)
        .and_then(|s| s.with_sigma(1.0 - 1.0 / dim))
        .and_then(|s| s.with_sd_tolerance(1e-12))
        .expect("the coefficients are within argmin's ranges");
    let problem = Counted {
        f: RefCell::new(f),
        spent: Cell::new(0),
        budget,
    };
    let solver = Budgeted {
        simplex,
        budget: budget as u64,
        deadline,
    };
    // The objective never fails and the coefficients are valid, so neither can the
    // run; should it all the same, the start is kept.
    let Ok(mut result) = Executor::new(problem, solver)
        .configure(|s| s.max_iters(budget as u64))
        .timer(false)
        .run()
    else {
        return unevaluated;
    };
    let evaluations = result.problem.problem.as_ref().map_or(0, |p| p.spent.get());
    let f = result.state.get_best_cost();
    match result.state.take_best_param() {
        Some(x) => Minimum { x, f, evaluations },
        None => Minimum {
            evaluations,
            ..unevaluated
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_rosenbrock() {
        let mut f = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let m = minimise(&mut f, &[-1.2, 1.0], &[0.5, 0.5], 2000, None);
        assert!(m.evaluations <= 2000);
        assert!((m.x[0] - 1.0).abs() < 1e-4 && (m.x[1] - 1.0).abs() < 1e-4, "{:?}", m.x);
    }

    #[test]
    fn respects_the_budget_in_many_dimensions() {
        let mut calls = 0;
        let mut f = |x: &[f64]| {
            calls += 1;
            x.iter().enumerate().map(|(k, v)| (k as f64 + 1.0) * v * v).sum::<f64>()
        };
        let x0 = vec![1.0; 20];
        let m = minimise(&mut f, &x0, &[0.3; 20], 500, None);
        assert_eq!(m.evaluations, 500);
        assert_eq!(calls, 500);
        let y0: f64 = (1..=20).map(|k| k as f64).sum();
        assert!(m.f < 0.5 * y0, "{}", m.f);
    }

    #[test]
    fn too_small_a_budget_keeps_the_start() {
        let mut f = |x: &[f64]| x[0] * x[0];
        let m = minimise(&mut f, &[3.0, 1.0], &[0.1, 0.1], 3, None);
        assert_eq!((m.x, m.evaluations), (vec![3.0, 1.0], 0));
        assert_eq!(m.f, f64::INFINITY);
    }

    #[test]
    fn nan_loses_to_any_number() {
        let mut f = |x: &[f64]| {
            if x[0] > 0.5 {
                f64::NAN
            } else {
                (x[0] - 0.2).powi(2) + x[1] * x[1]
            }
        };
        let m = minimise(&mut f, &[0.0, 0.3], &[0.1, 0.1], 400, None);
        assert!(m.f < 1e-6 && m.f.is_finite(), "{}", m.f);
    }
}
