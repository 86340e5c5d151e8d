//! Forward simulation from joint torques: the classical fourth-order Runge–Kutta
//! method on `ẋ = (v, aba(q, v, τ(t, q, v)))`.

use dyngen_reference::Dynamics;

/// A simulated run: `steps + 1` states at `t_k = k · dt`, the initial one first.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    pub t: Vec<f64>,
    pub q: Vec<Vec<f64>>,
    pub v: Vec<Vec<f64>>,
    /// `aba(q_k, v_k, tau_k)`: the acceleration at each recorded state.
    pub a: Vec<Vec<f64>>,
    /// The torque the controller applied at each recorded state, `τ(t_k, q_k, v_k)`.
    pub tau: Vec<Vec<f64>>,
}

/// Integrates the robot's motion under `torque(t, q, v, tau)` (which writes the `n`
/// joint torques into `tau`) from `q0`, `v0`, with `steps` classical RK4 steps of
/// `dt`:
///
/// ```text
/// k1 = f(t, x),  k2 = f(t + dt/2, x + dt/2 k1),  k3 = f(t + dt/2, x + dt/2 k2),
/// k4 = f(t + dt, x + dt k3),  x ← x + dt/6 (k1 + 2k2 + 2k3 + k4)
/// ```
///
/// with `x = (q, v)` and `f(t, x) = (v, aba(q, v, τ(t, q, v)))`; the torque is
/// called at every stage (4 calls per step, plus one for the last state). Global
/// error `O(dt⁴)`. Joint positions are integrated as plain coordinates (no
/// wrapping). Panics if `params` (`10 n`), `q0` or `v0` (`n`) have the wrong
/// length.
pub fn simulate_rk4(
    dynamics: &dyn Dynamics,
    params: &[f64],
    q0: &[f64],
    v0: &[f64],
    mut torque: impl FnMut(f64, &[f64], &[f64], &mut [f64]),
    dt: f64,
    steps: usize,
) -> Simulation {
    let (n, np) = (dynamics.nv(), dynamics.nparams());
    assert!(
        q0.len() == n && v0.len() == n && params.len() == np,
        "`q0`, `v0`, `params` have lengths {}, {}, {}; the model needs {n}, {n}, {np}",
        q0.len(),
        v0.len(),
        params.len(),
    );
    let mut tau = vec![0.0; n];
    // f(t, q, v) → acceleration, also returning the torque used.
    let mut accel = |t: f64, q: &[f64], v: &[f64], a: &mut [f64], tau: &mut [f64]| {
        torque(t, q, v, tau);
        dynamics.aba(q, v, tau, params, a);
    };

    let mut out = Simulation {
        t: Vec::with_capacity(steps + 1),
        q: Vec::with_capacity(steps + 1),
        v: Vec::with_capacity(steps + 1),
        a: Vec::with_capacity(steps + 1),
        tau: Vec::with_capacity(steps + 1),
    };
    let (mut q, mut v) = (q0.to_vec(), v0.to_vec());
    let (mut a1, mut a2, mut a3, mut a4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut qs, mut vs) = (vec![0.0; n], vec![0.0; n]);
    let (mut v2, mut v3) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..=steps {
        let t = k as f64 * dt;
        accel(t, &q, &v, &mut a1, &mut tau);
        out.t.push(t);
        out.q.push(q.clone());
        out.v.push(v.clone());
        out.a.push(a1.clone());
        out.tau.push(tau.clone());
        if k == steps {
            break;
        }
        // k1 = (v, a1)
        for i in 0..n {
            qs[i] = q[i] + 0.5 * dt * v[i];
            vs[i] = v[i] + 0.5 * dt * a1[i];
        }
        v2.copy_from_slice(&vs);
        accel(t + 0.5 * dt, &qs, &vs, &mut a2, &mut tau);
        // k2 = (v2, a2)
        for i in 0..n {
            qs[i] = q[i] + 0.5 * dt * v2[i];
            vs[i] = v[i] + 0.5 * dt * a2[i];
        }
        v3.copy_from_slice(&vs);
        accel(t + 0.5 * dt, &qs, &vs, &mut a3, &mut tau);
        // k3 = (v3, a3)
        for i in 0..n {
            qs[i] = q[i] + dt * v3[i];
            vs[i] = v[i] + dt * a3[i];
        }
        accel(t + dt, &qs, &vs, &mut a4, &mut tau);
        // k4 = (vs, a4)
        for i in 0..n {
            q[i] += dt / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + vs[i]);
            v[i] += dt / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
        }
    }
    out
}
