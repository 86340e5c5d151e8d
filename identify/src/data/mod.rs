//! Measured joint-space data: a CSV schema with a checking reader and an exact
//! writer, the in-memory [`Trajectory`], and velocities and accelerations from
//! positions (zero-phase low-pass filter, then central differences).
//!
//! # CSV schema
//!
//! The first line is a header of column names; each following line is one sample.
//! For a robot with `n` joints (numbered `1..=n` in regular labelling, DESIGN §3):
//!
//! | columns | meaning | unit | |
//! |---|---|---|---|
//! | `t` | time | s | required |
//! | `q1` … `qn` | joint positions | rad (revolute), m (prismatic) | required |
//! | `v1` … `vn` | joint velocities | rad/s, m/s | optional, all `n` or none |
//! | `a1` … `an` | joint accelerations | rad/s², m/s² | optional, all `n` or none |
//! | `tau1` … `taun` | joint torques (forces for prismatic joints) | N·m, N | required |
//! | `fx1, fy1, fz1` … `fzn` | force joint `j` applies to its outboard body `j` | N | optional, all `6n` or none |
//! | `mx1, my1, mz1` … `mzn` | moment of that wrench about the origin of joint `j` | N·m | (same group) |
//!
//! Joint wrenches follow Pinocchio's `data.f` convention: what the parent applies to
//! body `j` through joint `j`, expressed in body `j`'s frame (the joint frame), the
//! moment taken about the joint origin. In memory they are [`Wrench`](dyngen::Wrench)
//! values (`force`, `torque`).
//!
//! Rules the reader enforces (each violation is a [`DataError`] naming the line and
//! column, and saying what would be valid):
//!
//! - columns may come in any order; names are case-sensitive, without leading zeros
//!   (`q1`, not `Q1` or `q01`); spaces around names and numbers are ignored;
//! - every name once; no other columns (nothing is silently ignored);
//! - `n` is the highest `q` index, or the `dof` the caller passes (then it must match);
//! - every row has exactly one field per header column;
//! - fields are numbers as Rust's `f64` parser reads them (`-1.5`, `2e-3`); NaN and
//!   infinities are rejected;
//! - `t` strictly increases; at least 2 samples.
//!
//! Empty lines hold no data and are skipped (before the header, so are lines of
//! spaces); line numbers in errors count them. The reader goes through the whole file
//! and collects up to [`MAX_ERRORS`] errors (a single error is returned as itself,
//! several as [`DataError::Multiple`]); header errors stop it before the rows.
//!
//! The writer puts the columns in the order of the table (wrenches joint by joint:
//! `fx1, fy1, fz1, mx1, my1, mz1, fx2, …`) and every number in the shortest form that
//! reads back to the same bits, so `read_csv(write_csv(x)) == x` exactly. It never
//! replaces an existing file unless asked to ([`overwrite_csv`]).
//!
//! # Velocities and accelerations
//!
//! A file without `v` or `a` gets them from [`Trajectory::with_derivatives`]:
//! zero-phase low-pass filtering ([`butterworth_filtfilt`], forward–backward
//! 2nd-order Butterworth) and finite differences ([`central_difference`],
//! [`second_difference`]), second-order accurate up to the ends. It needs uniform
//! sampling (every step within 1 % of the mean, else an error naming the line). Pick
//! the cutoff above the motion's bandwidth and below the noise: for a trajectory of a
//! few Hz sampled at 100 Hz–1 kHz, 10–20 Hz is typical.
//!
//! # Example
//!
//! ```
//! use dyngen_identify::data::{from_reader, to_writer};
//!
//! let csv = "t, q1, q2, tau1, tau2
//! 0.00, 0.0, 0.1, 1.5, -0.2
//! 0.01, 0.001, 0.1, 1.5, -0.2
//! 0.02, 0.004, 0.1, 1.6, -0.3
//! 0.03, 0.009, 0.1, 1.6, -0.3
//! ";
//! let traj = from_reader(csv.as_bytes(), Some(2))?;
//! assert_eq!((traj.dof(), traj.len()), (2, 4));
//! assert_eq!(traj.q(2), &[0.004, 0.1]);
//! assert!(traj.velocities().is_none());
//!
//! // No velocities or accelerations in the file: estimate them (filter at 20 Hz).
//! let full = traj.with_derivatives(20.0)?;
//! assert_eq!(full.v(0).unwrap().len(), 2);
//!
//! // Bad data names its line.
//! let err = from_reader("t,q1,tau1\n0,0,0\n0.01,oops,0\n".as_bytes(), None).unwrap_err();
//! assert_eq!(err.to_string(), "line 3, column `q1`: `oops` is not a number");
//!
//! let mut out = Vec::new();
//! to_writer(&mut out, &traj)?;
//! assert!(out.starts_with(b"t,q1,q2,tau1,tau2\n0,0,0.1,1.5,-0.2\n"));
//! # Ok::<(), dyngen_identify::data::DataError>(())
//! ```

mod derivatives;
mod error;
mod io;
mod lines;
mod trajectory;

pub use derivatives::{butterworth_filtfilt, central_difference, second_difference, SAMPLING_TOLERANCE};
pub use error::{DataError, Location};
pub use io::{csv_header, from_reader, overwrite_csv, read_csv, to_writer, write_csv, MAX_ERRORS};
pub use trajectory::{Sample, Trajectory};
