//! Derivative-free minimisation by the Nelder–Mead simplex method (Nelder and Mead,
//! *Computer Journal* 7, 1965), with the dimension-dependent coefficients of Gao and
//! Han (*Comput. Optim. Appl.* 51, 2012), which keep it useful beyond ten variables.

/// What one run found.
pub(crate) struct Minimum {
    pub x: Vec<f64>,
    pub f: f64,
}

/// Minimises `f` from `x0`, with an initial simplex `x0 + steps[k] e_k`, spending at
/// most `budget` evaluations (counted into `evaluations`). Stops early when the
/// simplex's values agree to `1e-12` (absolute).
///
/// Coefficients for `d` variables: reflection 1, expansion `1 + 2/d`, contraction
/// `3/4 − 1/(2d)`, shrink `1 − 1/d`.
pub(crate) fn minimise(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    steps: &[f64],
    budget: usize,
    evaluations: &mut usize,
) -> Minimum {
    let d = x0.len();
    let dim = d.max(2) as f64;
    let (expand, contract, shrink) = (1.0 + 2.0 / dim, 0.75 - 0.5 / dim, 1.0 - 1.0 / dim);
    let mut spent = 0usize;
    let mut eval = |x: &[f64], spent: &mut usize| {
        *spent += 1;
        let y = f(x);
        if y.is_nan() {
            f64::INFINITY
        } else {
            y
        }
    };

    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(d + 1);
    let f0 = eval(x0, &mut spent);
    simplex.push((x0.to_vec(), f0));
    for k in 0..d {
        if spent >= budget {
            break;
        }
        let mut x = x0.to_vec();
        x[k] += steps[k];
        let y = eval(&x, &mut spent);
        simplex.push((x, y));
    }

    while spent < budget && simplex.len() == d + 1 {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (simplex[0].1, simplex[d].1);
        if (worst - best).abs() <= 1e-12 {
            break;
        }
        let second_worst = simplex[d - 1].1;
        let mut centroid = vec![0.0; d];
        for (x, _) in &simplex[..d] {
            for k in 0..d {
                centroid[k] += x[k] / d as f64;
            }
        }
        let toward =
            |t: f64, x: &[f64]| -> Vec<f64> { (0..d).map(|k| centroid[k] + t * (x[k] - centroid[k])).collect() };

        let reflected = toward(-1.0, &simplex[d].0);
        let fr = eval(&reflected, &mut spent);
        if fr < best {
            let expanded = toward(-expand, &simplex[d].0);
            let fe = if spent < budget {
                eval(&expanded, &mut spent)
            } else {
                f64::INFINITY
            };
            simplex[d] = if fe < fr { (expanded, fe) } else { (reflected, fr) };
            continue;
        }
        if fr < second_worst {
            simplex[d] = (reflected, fr);
            continue;
        }
        if spent >= budget {
            break;
        }
        // Contract: outside when the reflection improved on the worst, else inside.
        let (contracted, limit) = if fr < worst {
            (toward(-contract, &simplex[d].0), fr)
        } else {
            (toward(contract, &simplex[d].0), worst)
        };
        let fc = eval(&contracted, &mut spent);
        if fc < limit {
            simplex[d] = (contracted, fc);
            continue;
        }
        // Shrink towards the best vertex.
        let best_x = simplex[0].0.clone();
        for vertex in simplex.iter_mut().skip(1) {
            if spent >= budget {
                break;
            }
            let x: Vec<f64> = (0..d).map(|k| best_x[k] + shrink * (vertex.0[k] - best_x[k])).collect();
            let y = eval(&x, &mut spent);
            *vertex = (x, y);
        }
    }

    *evaluations += spent;
    let (x, f) = simplex
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((x0.to_vec(), f0));
    Minimum { x, f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_rosenbrock() {
        let mut f = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let mut evaluations = 0;
        let m = minimise(&mut f, &[-1.2, 1.0], &[0.5, 0.5], 2000, &mut evaluations);
        assert!(evaluations <= 2000);
        assert!((m.x[0] - 1.0).abs() < 1e-4 && (m.x[1] - 1.0).abs() < 1e-4, "{:?}", m.x);
    }

    #[test]
    fn respects_the_budget_in_many_dimensions() {
        let mut f = |x: &[f64]| x.iter().enumerate().map(|(k, v)| (k as f64 + 1.0) * v * v).sum::<f64>();
        let x0 = vec![1.0; 20];
        let mut evaluations = 0;
        let m = minimise(&mut f, &x0, &[0.3; 20], 500, &mut evaluations);
        assert!(evaluations <= 500);
        assert!(m.f < f(&x0) * 0.5);
    }
}
