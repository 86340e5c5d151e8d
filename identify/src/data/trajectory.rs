//! The in-memory trajectory: joint-space samples in row-major arrays, checked once
//! at construction so that everything downstream may rely on them.

use super::error::{DataError, Location};
use dyngen::Wrench;

/// Joint-space measurements: `len()` samples of a robot with `dof()` joints.
///
/// Arrays are row-major and contiguous: sample `k` of `q` is
/// `positions()[k * dof .. (k + 1) * dof]` (or [`Trajectory::q`]`(k)`). Every
/// trajectory holds at least 2 samples, finite values only, and strictly increasing
/// time; the constructors check this, so users of a `Trajectory` need not.
///
/// Units: `t` in s; `q` in rad (revolute) or m (prismatic); `v` in rad/s or m/s; `a`
/// in rad/s² or m/s²; `tau` in N·m or N; joint wrenches in N and N·m (see the
/// [module docs](super) for their frame and reference point).
///
/// A trajectory read from a file remembers each sample's file line, so that later
/// checks ([`Trajectory::with_derivatives`]) can name the line. Equality (`==`)
/// compares the data only, not where it came from.
#[derive(Clone, Debug)]
pub struct Trajectory {
    dof: usize,
    t: Vec<f64>,
    q: Vec<f64>,
    v: Option<Vec<f64>>,
    a: Option<Vec<f64>>,
    tau: Vec<f64>,
    wrenches: Option<Vec<Wrench<f64>>>,
    /// File line of each sample, when read from a file.
    lines: Option<Vec<u64>>,
}

impl PartialEq for Trajectory {
    fn eq(&self, other: &Self) -> bool {
        self.dof == other.dof
            && self.t == other.t
            && self.q == other.q
            && self.v == other.v
            && self.a == other.a
            && self.tau == other.tau
            && self.wrenches == other.wrenches
    }
}

/// One sample of a [`Trajectory`], borrowed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<'a> {
    pub t: f64,
    /// `dof` joint positions.
    pub q: &'a [f64],
    /// `dof` joint velocities, when the trajectory has them.
    pub v: Option<&'a [f64]>,
    /// `dof` joint accelerations, when the trajectory has them.
    pub a: Option<&'a [f64]>,
    /// `dof` joint torques or forces.
    pub tau: &'a [f64],
    /// `dof` joint reaction wrenches, when the trajectory has them.
    pub wrenches: Option<&'a [Wrench<f64>]>,
}

impl Trajectory {
    /// A trajectory of `t.len()` samples from time stamps `t`, positions `q` and
    /// joint torques `tau` (both row-major, `t.len() × dof`).
    ///
    /// Errors: `dof == 0`, a length that is not `t.len() × dof`, fewer than 2
    /// samples, a NaN or infinite value, `t` not strictly increasing.
    pub fn new(dof: usize, t: Vec<f64>, q: Vec<f64>, tau: Vec<f64>) -> Result<Self, DataError> {
        if dof == 0 {
            return Err(DataError::InvalidArgument {
                name: "dof",
                value: 0.0,
                expected: "at least 1 joint".into(),
            });
        }
        let traj = Trajectory {
            dof,
            t,
            q,
            v: None,
            a: None,
            tau,
            wrenches: None,
            lines: None,
        };
        traj.check()?;
        Ok(traj)
    }

    /// The same trajectory with joint velocities `v` (row-major, `len() × dof`).
    pub fn with_velocities(mut self, v: Vec<f64>) -> Result<Self, DataError> {
        self.v = Some(v);
        self.check()?;
        Ok(self)
    }

    /// The same trajectory with joint accelerations `a` (row-major, `len() × dof`).
    pub fn with_accelerations(mut self, a: Vec<f64>) -> Result<Self, DataError> {
        self.a = Some(a);
        self.check()?;
        Ok(self)
    }

    /// The same trajectory with the joint torques replaced by `tau` (row-major,
    /// `len() × dof`), e.g. torques with a known term taken out.
    pub fn with_torques(mut self, tau: Vec<f64>) -> Result<Self, DataError> {
        self.tau = tau;
        self.check()?;
        Ok(self)
    }

    /// The same trajectory with joint reaction wrenches (row-major, `len() × dof`):
    /// `wrenches[k * dof + j]` is what joint `j + 1` applies to its outboard body at
    /// sample `k`, in that body's frame, moment about the joint origin.
    pub fn with_wrenches(mut self, wrenches: Vec<Wrench<f64>>) -> Result<Self, DataError> {
        self.wrenches = Some(wrenches);
        self.check()?;
        Ok(self)
    }

    /// The samples whose index `keep` accepts, in order, with everything they carry
    /// (velocities, accelerations, wrenches, file lines). Errors as
    /// [`Trajectory::new`]: fewer than 2 samples kept.
    pub fn select(&self, keep: impl Fn(usize) -> bool) -> Result<Trajectory, DataError> {
        let kept: Vec<usize> = (0..self.len()).filter(|&k| keep(k)).collect();
        let rows = |data: &[f64], width: usize| -> Vec<f64> {
            kept.iter()
                .flat_map(|&k| data[k * width..(k + 1) * width].iter().copied())
                .collect()
        };
        let dof = self.dof;
        Trajectory::from_checked_parts(
            dof,
            kept.iter().map(|&k| self.t[k]).collect(),
            rows(&self.q, dof),
            self.v.as_ref().map(|v| rows(v, dof)),
            self.a.as_ref().map(|a| rows(a, dof)),
            rows(&self.tau, dof),
            self.wrenches.as_ref().map(|w| {
                kept.iter()
                    .flat_map(|&k| w[k * dof..(k + 1) * dof].iter().copied())
                    .collect()
            }),
            self.lines.as_ref().map(|l| kept.iter().map(|&k| l[k]).collect()),
        )
    }

    /// Used by the readers, which have already checked every value and know each
    /// sample's line (none for resampled data).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn from_checked_parts(
        dof: usize,
        t: Vec<f64>,
        q: Vec<f64>,
        v: Option<Vec<f64>>,
        a: Option<Vec<f64>>,
        tau: Vec<f64>,
        wrenches: Option<Vec<Wrench<f64>>>,
        lines: Option<Vec<u64>>,
    ) -> Result<Self, DataError> {
        let traj = Trajectory {
            dof,
            t,
            q,
            v,
            a,
            tau,
            wrenches,
            lines,
        };
        traj.check()?;
        Ok(traj)
    }

    /// Lengths, finiteness and time order, the first failure reported.
    fn check(&self) -> Result<(), DataError> {
        let n = self.t.len();
        let dof = self.dof;
        let expect = |what: &'static str, found: usize, expected: usize| {
            if found == expected {
                Ok(())
            } else {
                Err(DataError::LengthMismatch { what, expected, found })
            }
        };
        expect("q", self.q.len(), n * dof)?;
        expect("tau", self.tau.len(), n * dof)?;
        if let Some(v) = &self.v {
            expect("v", v.len(), n * dof)?;
        }
        if let Some(a) = &self.a {
            expect("a", a.len(), n * dof)?;
        }
        if let Some(w) = &self.wrenches {
            expect("wrenches", w.len(), n * dof)?;
        }
        if let Some(lines) = &self.lines {
            expect("lines", lines.len(), n)?;
        }
        if n < 2 {
            return Err(DataError::TooFewSamples { found: n, needed: 2 });
        }
        for k in 0..n {
            // The column's name is only built for the error: checking allocates nothing.
            let finite = |column: &dyn Fn() -> String, value: f64| {
                if value.is_finite() {
                    Ok(())
                } else {
                    Err(DataError::NonFinite {
                        at: self.location(k),
                        column: column(),
                        value,
                    })
                }
            };
            finite(&|| "t".into(), self.t[k])?;
            let groups = [
                ("q", Some(&self.q)),
                ("v", self.v.as_ref()),
                ("a", self.a.as_ref()),
                ("tau", Some(&self.tau)),
            ];
            for (name, values) in groups {
                if let Some(values) = values {
                    for j in 0..dof {
                        finite(&|| format!("{name}{}", j + 1), values[k * dof + j])?;
                    }
                }
            }
            if let Some(w) = &self.wrenches {
                for j in 0..dof {
                    let w = &w[k * dof + j];
                    for (axis, x) in ["x", "y", "z"].iter().zip(w.force.iter()) {
                        finite(&|| format!("f{axis}{}", j + 1), *x)?;
                    }
                    for (axis, x) in ["x", "y", "z"].iter().zip(w.torque.iter()) {
                        finite(&|| format!("m{axis}{}", j + 1), *x)?;
                    }
                }
            }
            if k > 0 && self.t[k] <= self.t[k - 1] {
                return Err(DataError::NonMonotonicTime {
                    at: self.location(k),
                    t: self.t[k],
                    previous: self.t[k - 1],
                });
            }
        }
        Ok(())
    }

    /// Number of joints `n`.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of samples (at least 2).
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Always `false`: a trajectory has at least 2 samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Where sample `k` came from: its file line when read from a file, else its index.
    pub fn location(&self, k: usize) -> Location {
        match self.lines.as_ref().and_then(|lines| lines.get(k)) {
            Some(&line) => Location::Line(line),
            None => Location::Sample(k),
        }
    }

    /// Time stamps (s), strictly increasing.
    pub fn t(&self) -> &[f64] {
        &self.t
    }

    /// All joint positions, row-major `len() × dof`.
    pub fn positions(&self) -> &[f64] {
        &self.q
    }

    /// All joint velocities, row-major `len() × dof`, when present.
    pub fn velocities(&self) -> Option<&[f64]> {
        self.v.as_deref()
    }

    /// All joint accelerations, row-major `len() × dof`, when present.
    pub fn accelerations(&self) -> Option<&[f64]> {
        self.a.as_deref()
    }

    /// All joint torques or forces, row-major `len() × dof`.
    pub fn torques(&self) -> &[f64] {
        &self.tau
    }

    /// All joint reaction wrenches, row-major `len() × dof`, when present.
    pub fn joint_wrenches(&self) -> Option<&[Wrench<f64>]> {
        self.wrenches.as_deref()
    }

    /// Joint positions of sample `k` (`dof` values). Panics if `k >= len()`.
    pub fn q(&self, k: usize) -> &[f64] {
        &self.q[k * self.dof..(k + 1) * self.dof]
    }

    /// Joint velocities of sample `k`, when present. Panics if `k >= len()`.
    pub fn v(&self, k: usize) -> Option<&[f64]> {
        self.v.as_ref().map(|v| &v[k * self.dof..(k + 1) * self.dof])
    }

    /// Joint accelerations of sample `k`, when present. Panics if `k >= len()`.
    pub fn a(&self, k: usize) -> Option<&[f64]> {
        self.a.as_ref().map(|a| &a[k * self.dof..(k + 1) * self.dof])
    }

    /// Joint torques of sample `k` (`dof` values). Panics if `k >= len()`.
    pub fn tau(&self, k: usize) -> &[f64] {
        &self.tau[k * self.dof..(k + 1) * self.dof]
    }

    /// Joint reaction wrenches of sample `k`, when present. Panics if `k >= len()`.
    pub fn wrenches(&self, k: usize) -> Option<&[Wrench<f64>]> {
        self.wrenches.as_ref().map(|w| &w[k * self.dof..(k + 1) * self.dof])
    }

    /// Sample `k`, or `None` past the end.
    pub fn sample(&self, k: usize) -> Option<Sample<'_>> {
        (k < self.len()).then(|| Sample {
            t: self.t[k],
            q: self.q(k),
            v: self.v(k),
            a: self.a(k),
            tau: self.tau(k),
            wrenches: self.wrenches(k),
        })
    }

    /// Every sample in time order.
    pub fn samples(&self) -> impl ExactSizeIterator<Item = Sample<'_>> + '_ {
        (0..self.len()).map(move |k| Sample {
            t: self.t[k],
            q: self.q(k),
            v: self.v(k),
            a: self.a(k),
            tau: self.tau(k),
            wrenches: self.wrenches(k),
        })
    }

    /// Replaces `q` and `v` (filtered ones), checked like the rest.
    pub(super) fn set_states(&mut self, q: Vec<f64>, v: Option<Vec<f64>>) -> Result<(), DataError> {
        self.q = q;
        self.v = v;
        self.check()
    }

    /// Replaces `v` and `a` (computed ones), checked like the rest.
    pub(super) fn set_derivatives(&mut self, v: Option<Vec<f64>>, a: Option<Vec<f64>>) -> Result<(), DataError> {
        self.v = v;
        self.a = a;
        self.check()
    }
}

/// Column `j` of a row-major `len × dof` array.
pub(super) fn column(values: &[f64], dof: usize, j: usize) -> Vec<f64> {
    values.iter().skip(j).step_by(dof).copied().collect()
}

/// Writes `col` into column `j` of a row-major `len × dof` array.
pub(super) fn set_column(values: &mut [f64], dof: usize, j: usize, col: &[f64]) {
    for (x, c) in values.iter_mut().skip(j).step_by(dof).zip(col) {
        *x = *c;
    }
}
