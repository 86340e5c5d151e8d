//! What a real robot and its logger do to a recording, so that simulated data look
//! like the files identification meets: drives beyond rigid bodies (rotor inertia
//! and friction, [`add_joint_terms`]), a logger whose steps jitter around its period
//! ([`Logger::times`]), rows written twice with one stamp or repeated stale under a
//! new one, and motor currents `i = τ / k` quantised to the drive's resolution
//! ([`Logger::write`]). Everything is seeded.

use super::experiment::Recording;
use crate::extras::ExtraTerms;
use crate::stribeck::{Stribeck, StribeckError};
use dyngen_model::joint_params::{joint_torque, Coulomb, PER_JOINT};
use dyngen_model::sample::SplitMix64;

/// Adds `Ia·q̈ + Fv·q̇ + Fc·s(q̇) + F0` of every joint (`joint_params`: `4n`, joint
/// order, [`dyngen_model::joint_params`]) to the recorded joint torques: what the
/// motors must deliver beyond the rigid bodies. The joint reaction wrenches and body
/// measurements are left as they are: friction and rotor inertia act between the
/// motor and the joint, not on the links.
pub fn add_joint_terms(recording: &mut Recording, joint_params: &[f64], coulomb: Coulomb) {
    let n = recording.joint_names.len();
    assert_eq!(
        joint_params.len(),
        PER_JOINT * n,
        "`joint_params` has length {}, {n} joints need {}",
        joint_params.len(),
        PER_JOINT * n
    );
    for s in &mut recording.samples {
        for j in 0..n {
            let p: &[f64; PER_JOINT] = joint_params[PER_JOINT * j..PER_JOINT * (j + 1)].try_into().unwrap();
            s.tau[j] += joint_torque(p, s.v[j], s.a[j], coulomb);
        }
    }
}

/// Adds the extra joint terms `extras` with parameters `params` (`per_joint()` per
/// joint, [`crate::extras`]) to the recorded joint torques. The load-dependent
/// friction's load is the rigid-body torque, which the recording holds as
/// [`record_trajectory`](super::record_trajectory) made it: call this before
/// [`add_joint_terms`] and any other torque. The motor ripple needs each joint's
/// gear ratio (`gear_ratios`). Refuses a length other than one set per joint, and
/// motor ripple without one gear ratio per joint.
pub fn add_extra_terms(
    recording: &mut Recording,
    extras: ExtraTerms,
    params: &[f64],
    coulomb: Coulomb,
    gear_ratios: Option<&[f64]>,
) -> Result<(), String> {
    let (n, e) = (recording.joint_names.len(), extras.per_joint());
    if params.len() != e * n {
        return Err(format!(
            "`params` has length {}; {n} joints with `{extras}` need {}",
            params.len(),
            e * n
        ));
    }
    let ratios = match gear_ratios {
        Some(r) if r.len() == n => r,
        Some(r) => return Err(format!("{} gear ratios for {n} joints", r.len())),
        None if extras.motor_harmonics > 0 => return Err("motor ripple needs the joints' gear ratios".into()),
        None => &[][..],
    };
    let mut row = vec![0.0; e];
    for s in &mut recording.samples {
        for j in 0..n {
            let load = ExtraTerms::load_entry(s.tau[j], s.v[j], coulomb);
            let motor = ratios.get(j).map_or(0.0, |n| n * s.q[j]);
            extras.row(s.q[j], s.v[j], motor, load, coulomb, &mut row);
            s.tau[j] += row
                .iter()
                .zip(&params[e * j..e * (j + 1)])
                .map(|(y, p)| y * p)
                .sum::<f64>();
        }
    }
    Ok(())
}

/// Adds every joint's Stribeck term `(Fs − Fc)·exp(−(q̇/vs)²)·s(q̇)`
/// ([`crate::stribeck`]) to the recorded joint torques, on top of
/// [`add_joint_terms`] with the same `joint_params` (`4n`, giving `Fc`) and
/// `coulomb`: the friction at rest is then `Fs`. Refuses (naming the joint) a
/// Stribeck velocity that is not positive, and a length other than one set per joint.
pub fn add_stribeck_terms(
    recording: &mut Recording,
    joint_params: &[f64],
    stribeck: &[Stribeck],
    coulomb: Coulomb,
) -> Result<(), StribeckError> {
    let n = recording.joint_names.len();
    crate::stribeck::check(stribeck, n)?;
    if joint_params.len() != PER_JOINT * n {
        return Err(StribeckError::Joints {
            expected: n,
            found: joint_params.len() / PER_JOINT,
        });
    }
    for s in &mut recording.samples {
        crate::stribeck::add_excess(&mut s.tau, &s.v, joint_params, stribeck, coulomb);
    }
    Ok(())
}

/// A logger as real robots have them.
#[derive(Clone, Debug, PartialEq)]
pub struct Logger {
    /// Nominal period, s.
    pub period: f64,
    /// Each step is `period · (1 + u)`, `u` uniform in `±jitter` (0.25: a 10 ms logger
    /// stepping 7.5–12.5 ms).
    pub jitter: f64,
    /// Fraction of rows written twice with the same stamp.
    pub duplicates: f64,
    /// Fraction of rows that repeat the previous row's values under a new stamp (a
    /// logger that polled before the controller published).
    pub stale: f64,
    /// Motor gains `k` (N·m/A per joint): when given, the torque columns are written
    /// as currents `i = τ / k`, named `i1..in`.
    pub gains: Option<Vec<f64>>,
    /// Current resolution (A): currents are rounded to multiples of it; 0 keeps them.
    pub current_quantum: f64,
    pub seed: u64,
}

impl Logger {
    /// A 10 ms logger stepping 8–13 ms (±25 % jitter), 0.5 % duplicated and 0.5 %
    /// stale rows, torques as they are.
    pub fn typical(seed: u64) -> Logger {
        Logger {
            period: 0.01,
            jitter: 0.25,
            duplicates: 0.005,
            stale: 0.005,
            gains: None,
            current_quantum: 0.0,
            seed,
        }
    }

    /// Jittered sample times from 0 up to `duration` (ascending, strictly).
    pub fn times(&self, duration: f64) -> Vec<f64> {
        assert!(
            self.period > 0.0 && (0.0..1.0).contains(&self.jitter),
            "bad logger period or jitter"
        );
        let mut rng = SplitMix64::new(self.seed);
        let mut t = 0.0;
        let mut times = Vec::new();
        while t <= duration {
            times.push(t);
            t += self.period * (1.0 + rng.uniform(-self.jitter, self.jitter));
        }
        times
    }

    /// The recording as a logger writes it: CSV with a header `t, q1.., v1.., tau1..`
    /// (or `i1..` with gains), rows duplicated or stale as configured. The rows'
    /// values are written with full precision (shortest round trip).
    pub fn write(&self, recording: &Recording) -> String {
        let n = recording.joint_names.len();
        if let Some(k) = &self.gains {
            assert_eq!(k.len(), n, "{} gains for {n} joints", k.len());
            assert!(
                k.iter().all(|k| k.is_finite() && *k != 0.0),
                "gains must be finite and non-zero"
            );
        }
        let mut rng = SplitMix64::new(self.seed ^ 0x6c6f_6767_6572);
        let mut out = String::new();
        let effort = if self.gains.is_some() { "i" } else { "tau" };
        let mut header = vec!["t".to_string()];
        for prefix in ["q", "v", effort] {
            header.extend((1..=n).map(|j| format!("{prefix}{j}")));
        }
        out.push_str(&header.join(","));
        out.push('\n');
        let mut previous: Option<Vec<f64>> = None;
        for s in &recording.samples {
            let mut values: Vec<f64> = s.q.iter().chain(&s.v).copied().collect();
            for j in 0..n {
                let mut x = s.tau[j];
                if let Some(k) = &self.gains {
                    x /= k[j];
                    if self.current_quantum > 0.0 {
                        x = (x / self.current_quantum).round() * self.current_quantum;
                    }
                }
                values.push(x);
            }
            if rng.next_f64() < self.stale {
                if let Some(p) = &previous {
                    values = p.clone();
                }
            }
            let line = std::iter::once(s.t)
                .chain(values.iter().copied())
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(",");
            out.push_str(&line);
            out.push('\n');
            if rng.next_f64() < self.duplicates {
                out.push_str(&line);
                out.push('\n');
            }
            previous = Some(values);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Recipe;
    use crate::simulate::{record_trajectory, FourierExcitation};
    use dyngen_reference::Reference;

    fn arm() -> Reference {
        let model = dyngen_model::parse_urdf(include_str!("../../../robots/ur5/ur5.urdf")).unwrap();
        Reference::new(&model)
    }

    #[test]
    fn joint_terms_add_to_the_torques_only() {
        let robot = arm();
        let model = robot.model().clone();
        let motion = FourierExcitation::new(0.5, vec![0.0; 6], &vec![vec![0.3]; 6], &vec![vec![0.1]; 6]);
        let times = [0.1, 0.2, 0.3];
        let clean = record_trajectory(&robot, &model.standard_params(), &motion, &times);
        let mut with = clean.clone();
        let p: Vec<f64> = (0..6).flat_map(|j| [0.1 * j as f64, 2.0, 3.0, -0.5]).collect();
        add_joint_terms(&mut with, &p, Coulomb::Sign);
        for (a, b) in clean.samples.iter().zip(&with.samples) {
            assert_eq!(a.joint_wrenches, b.joint_wrenches);
            for j in 0..6 {
                let want = 0.1 * j as f64 * a.a[j] + 2.0 * a.v[j] + 3.0 * a.v[j].signum() - 0.5;
                assert!((b.tau[j] - a.tau[j] - want).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn logged_file_reads_back_through_a_recipe() {
        let robot = arm();
        let model = robot.model().clone();
        let logger = Logger {
            gains: Some(vec![14.0, 13.0, 12.0, 9.0, 8.5, 8.0]),
            current_quantum: 1e-3,
            duplicates: 0.05,
            stale: 0.02,
            ..Logger::typical(3)
        };
        let times = logger.times(2.0);
        let steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(steps.iter().all(|&d| (0.0075..=0.0125).contains(&d)), "{steps:?}");
        let motion = FourierExcitation::new(0.5, vec![0.0; 6], &vec![vec![0.3]; 6], &vec![vec![0.1]; 6]);
        let rec = record_trajectory(&robot, &model.standard_params(), &motion, &times);
        let text = logger.write(&rec);
        let lines = text.lines().count() - 1;
        assert!(lines > times.len(), "some rows are written twice");
        let mut recipe = Recipe::default();
        for (key, value) in [
            ("q", "2-7"),
            ("v", "8-13"),
            ("tau", "14-19"),
            ("gains", "14,13,12,9,8.5,8"),
        ] {
            recipe.set(key, value).unwrap();
        }
        let loaded = recipe.read_from(text.as_bytes(), Some(6)).unwrap();
        // Rows written twice are dropped and counted; stale rows are kept (a robot at
        // rest repeats its values too).
        assert_eq!(loaded.trajectory.len(), times.len(), "{}", loaded.report);
        for k in 1..times.len() {
            let got = loaded.trajectory.tau(k);
            let fresh = &rec.samples[k].tau;
            let stale = &rec.samples[k - 1].tau;
            let close = |want: &[f64]| (0..6).all(|j| (got[j] - want[j]).abs() <= 0.5e-3 * 14.0 + 1e-9);
            // A stale row repeats the previous row as written, which may itself be stale.
            assert!(
                close(fresh) || close(stale) || loaded.trajectory.tau(k) == loaded.trajectory.tau(k - 1),
                "row {k}"
            );
        }
    }
}
