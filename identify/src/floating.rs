//! Identification of a floating-base robot from the rows of its dynamics that a
//! recording measures.
//!
//! For a robot whose joint 1 is a free flyer (a generated type with
//! `R::MODEL.joints[0].kind == JointType::FreeFlyer`), the dynamics read
//! `Y(q, v, a) π = Sᵀ τ + Σ_c J_c(q)ᵀ F_c`: the first six rows say what the contacts
//! (or a force-torque sensor holding the base) exert on the base, the others what the
//! joint motors and the contacts exert on the joints. Nothing actuates the base, so
//! its six rows need no motor model at all: with the contact wrenches measured (force
//! plates, foot sensors), they determine every base parameter of the robot, the
//! joint torques add data but no new parameter ([`dyngen_model::base::analyse_rows`]
//! counts both). [`FloatingBase`] stacks the rows chosen by [`FloatingRows`], one
//! channel per row of the dynamics, into an [`Accumulator`]; every estimator of the
//! crate runs on it, and the rank and the identifiable combinations come with the
//! estimate.
//!
//! ```
//! use dyngen_identify::floating::{FloatingBase, FloatingRows};
//! # fn check<R: dyngen::Robot>(q: &[f64], v: &[f64], a: &[f64]) {
//! // The generalized forces: the base wrench from the contacts, then the joint torques.
//! let mut tau = vec![0.0; R::NV];
//! R::rnea(q, v, a, R::nominal_params(), &mut tau);
//! let mut id = FloatingBase::<R>::new(FloatingRows::Base).unwrap();
//! id.push(q, v, a, &tau).unwrap();
//! # }
//! ```

use crate::error::check_len;
use crate::{Accumulator, Channels, Estimate, IdentifyError, Options};
use dyngen::{JointType, ReferenceFrame, Robot};
use faer::Mat;
use std::marker::PhantomData;

/// Which rows of the dynamics a recording measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FloatingRows {
    /// The six base rows: the wrench on the base (from measured contact wrenches).
    Base,
    /// The joint rows: joint torques (with the contacts' share, when known).
    Joints,
    /// Both.
    All,
}

impl FloatingRows {
    /// Whether row `d` of the dynamics is used.
    pub fn keeps(self, d: usize) -> bool {
        match self {
            FloatingRows::Base => d < 6,
            FloatingRows::Joints => d >= 6,
            FloatingRows::All => true,
        }
    }
}

/// A contact wrench on the robot at a frame: `force` (N) and `moment` (N·m) about the
/// frame's origin, in world axes (Pinocchio's `LOCAL_WORLD_ALIGNED`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Index into `R::MODEL.frames` (the generated frame enum's `index()`).
    pub frame: usize,
    pub force: [f64; 3],
    pub moment: [f64; 3],
}

/// The identification data of a floating-base robot `R`: the standard-parameter
/// regressor rows chosen by [`FloatingRows`], one channel per row of the dynamics
/// (row `d` of every sample in channel `d`).
pub struct FloatingBase<R: Robot> {
    rows: FloatingRows,
    acc: Accumulator,
    y: Vec<f64>,
    jacobian: Vec<f64>,
    robot: PhantomData<R>,
}

impl<R: Robot> FloatingBase<R> {
    /// An empty data set. Errors if `R`'s joint 1 is not a free flyer.
    pub fn new(rows: FloatingRows) -> Result<Self, IdentifyError> {
        if R::MODEL.joints.first().map(|j| j.kind) != Some(JointType::FreeFlyer) {
            return Err(IdentifyError::InvalidArgument {
                what: "robot",
                reason: format!("`{}` has a fixed base: its joint 1 is not a free flyer", R::NAME),
            });
        }
        Ok(FloatingBase {
            rows,
            acc: Accumulator::with_channels(R::NPARAMS, Channels::Interleaved(R::NV))?,
            y: vec![0.0; R::NV * R::NPARAMS],
            jacobian: vec![0.0; 6 * R::NV],
            robot: PhantomData,
        })
    }

    /// Adds one sample: the state `(q, v, a)` (`NQ`, `NV`, `NV`) and the generalized
    /// forces `tau` (`NV`): the wrench on the base in the base frame (force, then
    /// moment: what the first six rows of `rnea` give), then the joint torques. Only
    /// the rows [`FloatingRows`] keeps are read; the others may hold anything finite
    /// or not.
    pub fn push(&mut self, q: &[f64], v: &[f64], a: &[f64], tau: &[f64]) -> Result<(), IdentifyError> {
        check_len(q, R::NQ, "q")?;
        check_len(v, R::NV, "v")?;
        check_len(a, R::NV, "a")?;
        check_len(tau, R::NV, "tau")?;
        R::joint_torque_regressor(q, v, a, &mut self.y);
        let keep: Vec<bool> = (0..R::NV).map(|d| self.rows.keeps(d)).collect();
        let y = Mat::from_fn(R::NV, R::NPARAMS, |r, c| self.y[r * R::NPARAMS + c]);
        let rhs: Vec<f64> = tau.iter().zip(&keep).map(|(&t, &k)| if k { t } else { 0.0 }).collect();
        self.acc.push_rows_masked(y.as_ref(), &rhs, &keep)
    }

    /// Adds one sample from what the robot measures: joint torques (`NV − 6`) and
    /// the contact wrenches, which enter the dynamics as `Σ_c J_c(q)ᵀ F_c` (the base
    /// rows from the contacts alone). Errors name a frame that does not exist.
    pub fn push_contacts(
        &mut self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        joint_torques: &[f64],
        contacts: &[Contact],
    ) -> Result<(), IdentifyError> {
        // `q` before the Jacobians read it; `v` and `a` in `push`.
        check_len(joint_torques, R::NV - 6, "joint torques")?;
        check_len(q, R::NQ, "q")?;
        let mut tau = vec![0.0; R::NV];
        tau[6..].copy_from_slice(joint_torques);
        for c in contacts {
            if R::frame_jacobian(q, c.frame, ReferenceFrame::LocalWorldAligned, &mut self.jacobian).is_none() {
                return Err(IdentifyError::InvalidArgument {
                    what: "contact frame",
                    reason: format!(
                        "{} is not a frame index of `{}` ({} frames)",
                        c.frame,
                        R::NAME,
                        R::MODEL.frames.len()
                    ),
                });
            }
            let w = [
                c.force[0],
                c.force[1],
                c.force[2],
                c.moment[0],
                c.moment[1],
                c.moment[2],
            ];
            for (d, t) in tau.iter_mut().enumerate() {
                *t += (0..6).map(|r| self.jacobian[r * R::NV + d] * w[r]).sum::<f64>();
            }
        }
        self.push(q, v, a, &tau)
    }

    /// The stacked data, for any estimator of the crate.
    pub fn accumulator(&self) -> &Accumulator {
        &self.acc
    }

    /// Ordinary least squares on the stacked rows: the identifiable combinations of
    /// the standard parameters, with the rank found from the data.
    pub fn ols(&self, opts: &Options) -> Result<Estimate, IdentifyError> {
        self.acc.ols(opts)
    }
}
