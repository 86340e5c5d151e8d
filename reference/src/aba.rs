//! Forward dynamics by the articulated body algorithm (Featherstone, *Rigid Body
//! Dynamics Algorithms*, §7.3 and Table 7.1), for joints of one degree of freedom
//! with a constant motion subspace (revolute, continuous, prismatic), so that the
//! joint's own bias acceleration `c_J` is zero.

use super::spatial::{cross_force, cross_motion, spatial_inertia, SpatialMatrix, SpatialVector};
use super::Reference;

impl Reference {
    /// Forward dynamics `q̈ = FD(q, q̇, τ)` by the articulated body algorithm, in
    /// three passes and `O(n)`, without forming the mass matrix:
    ///
    /// ```text
    /// base to tip:  X_i = ⁱX_λ(i)(q_i)
    ///               v_i = X_i v_λ(i) + S_i q̇_i              (v_0 = 0)
    ///               c_i = v_i × S_i q̇_i
    ///               I^A_i = I_i,   p^A_i = v_i ×* I_i v_i
    /// tip to base:  U_i = I^A_i S_i,   D_i = S_iᵀ U_i,   u_i = τ_i − S_iᵀ p^A_i
    ///               I^a = I^A_i − U_i U_iᵀ / D_i
    ///               p^a = p^A_i + I^a c_i + U_i u_i / D_i
    ///               I^A_λ(i) += X_iᵀ I^a X_i,   p^A_λ(i) += X_iᵀ p^a
    /// base to tip:  a'_i = X_i a_λ(i) + c_i                  (a_0 = −a_g)
    ///               q̈_i = (u_i − U_iᵀ a'_i) / D_i
    ///               a_i = a'_i + S_i q̈_i
    /// ```
    ///
    /// Gravity enters as the base acceleration `−a_g`, as in [`Reference::rnea`],
    /// which this inverts: `aba(q, v, rnea(q, v, a)) = a`. `q, v, tau`: `n`;
    /// `params`: `10 n`; returns `n` accelerations. The articulated inertias
    /// `D_i` are positive for physically consistent parameters; otherwise the
    /// result may be infinite or NaN. Panics if a length differs.
    pub fn aba(&self, q: &[f64], v: &[f64], tau: &[f64], params: &[f64]) -> Vec<f64> {
        let n = self.nq();
        self.check_len("q", q, n);
        self.check_len("v", v, n);
        self.check_len("tau", tau, n);
        self.check_len("params", params, 10 * n);

        // Pass 1: velocities, velocity-product accelerations, rigid-body inertias.
        let mut x = vec![SpatialMatrix::identity(); n + 1];
        let mut vel = vec![SpatialVector::zeros(); n + 1];
        let mut c = vec![SpatialVector::zeros(); n + 1];
        let mut articulated = vec![SpatialMatrix::zeros(); n + 1];
        let mut bias = vec![SpatialVector::zeros(); n + 1];
        for i in 1..=n {
            let (parent, s) = (self.joints[i - 1].parent, self.joints[i - 1].subspace);
            x[i] = self.joint_placement(i, q[i - 1]).motion_matrix();
            let joint_velocity = s * v[i - 1];
            vel[i] = x[i] * vel[parent] + joint_velocity;
            c[i] = cross_motion(&vel[i]) * joint_velocity;
            let inertia = spatial_inertia(&params[10 * (i - 1)..10 * i]);
            articulated[i] = inertia;
            bias[i] = cross_force(&vel[i]) * (inertia * vel[i]);
        }

        // Pass 2: articulated-body inertias and bias forces, tip to base.
        let mut u_vec = vec![SpatialVector::zeros(); n + 1];
        let mut d = vec![0.0; n + 1];
        let mut u = vec![0.0; n + 1];
        for i in (1..=n).rev() {
            let (parent, s) = (self.joints[i - 1].parent, self.joints[i - 1].subspace);
            u_vec[i] = articulated[i] * s;
            d[i] = s.dot(&u_vec[i]);
            u[i] = tau[i - 1] - s.dot(&bias[i]);
            if parent != 0 {
                let ia = articulated[i] - u_vec[i] * u_vec[i].transpose() / d[i];
                let pa = bias[i] + ia * c[i] + u_vec[i] * (u[i] / d[i]);
                articulated[parent] += x[i].transpose() * ia * x[i];
                bias[parent] += x[i].transpose() * pa;
            }
        }

        // Pass 3: accelerations, base to tip.
        let mut acc = vec![SpatialVector::zeros(); n + 1];
        acc[0] = -self.gravity;
        let mut qdd = vec![0.0; n];
        for i in 1..=n {
            let (parent, s) = (self.joints[i - 1].parent, self.joints[i - 1].subspace);
            let a_prime = x[i] * acc[parent] + c[i];
            qdd[i - 1] = (u[i] - u_vec[i].dot(&a_prime)) / d[i];
            acc[i] = a_prime + s * qdd[i - 1];
        }
        qdd
    }
}
