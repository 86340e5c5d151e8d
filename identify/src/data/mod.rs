//! Measured joint-space data: a CSV schema with a checking reader and an exact
//! writer, the in-memory [`Trajectory`], and velocities and accelerations from
//! positions (zero-phase low-pass filter, then central differences).
//!
//! # CSV schema
//!
//! The first line is a header of column names; each following line is one sample.
//! For a robot with `n` joints (numbered `1..=n` in regular labelling, docs/design.md, "Conventions"):
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
//! A UTF-8 byte order mark at the start of the file is skipped; a line longer than
//! [`MAX_LINE_BYTES`] (1 MiB) is an error naming it, raised before the line is read
//! whole. Files are read as a stream, line by line: only the samples are kept.
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
//! On a non-uniform grid (a jittered logger read as it is),
//! [`Trajectory::with_derivatives_nonuniform`] interpolates onto a uniform grid of
//! as many samples (cubic Hermite), filters and differentiates there, and
//! interpolates the derivatives back to the log's time stamps. Finite differences
//! on any grid: [`nonuniform_difference`] and [`nonuniform_second_difference`]
//! (three-point stencils, exact on quadratics).
//!
//! # Recipes
//!
//! Real loggers write files the schema above does not describe: no header, their
//! own column names and order, semicolons or spaces, degrees, motor currents,
//! jittered and repeated time stamps, hours of data. A [`Recipe`] says how to read
//! one logger's files; [`Recipe::read`] reads a log through it into a [`Loaded`]
//! trajectory with a [`LoadReport`] of what was done (rows dropped and why, the
//! time steps, which quantities were measured and which estimated), and
//! [`Loaded::with_derivatives`] estimates what was not measured.
//!
//! A recipe file is plain text, one `key = value` per line; `#` starts a comment
//! (to the end of the line), blank lines are ignored, each key at most once, keys
//! not given keep their defaults. Errors name the recipe line. The same keys can be
//! set one at a time with [`Recipe::set`] (how `dyngen identify`'s flags override a
//! file).
//!
//! | key | values | default |
//! |---|---|---|
//! | `delimiter` | `comma`, `semicolon`, `tab`, `whitespace` (runs of spaces and tabs) | `comma` |
//! | `header` | `true`, `false`: whether the first line (after `skip`) names the columns | `true` |
//! | `skip` | lines to skip before the header or first row (a preamble) | `0` |
//! | `time` | the time column: its number (from 1) or header name | `1` when `q` is given |
//! | `q` | one column per joint: numbers (1 to [`MAX_COLUMNS`]), names, ranges `2-7`, comma-separated | |
//! | `v` | measured velocities, one column per joint (optional) | |
//! | `a` | measured accelerations, one column per joint (optional) | |
//! | `tau` | torques (forces), or motor currents when `gains` is given, one per joint | |
//! | `time_unit` | `s`, `ms`, `us` (`µs`), `ns` | `s` |
//! | `time_origin` | `file` (time stamps as they are) or `first` (the first row read is t = 0) | `file` |
//! | `units` | `rad`, `deg`, `m`, `mm`: once for all joints or once per joint; applies to q, v, a | `rad` |
//! | `gains` | torque constants k (N·m/A): τ = k·i; once for all joints or once per joint | none: `tau` is torque |
//! | `sign` | `1` or `-1`, once for all joints or per joint: multiplies q, v, a and τ | all `1` |
//! | `window` | `t0:t1`, seconds after `time_unit` and `time_origin`, inclusive; either end may be left out | all |
//! | `rows` | `first:last`, data rows counted from 1 (blank lines not counted), inclusive | all |
//! | `decimate` | `N`: keep every N-th sample (no anti-alias filter: for logs sampled far above the motion) | `1` |
//! | `resample` | `DT` in s: interpolate onto a uniform grid; `off`: time stamps as they are | `off` |
//! | `stale` | `keep` or `drop` rows repeating every value of the previous row under a new time stamp | `keep` |
//!
//! Columns: without `q` and `tau`, a file with a header is read by the schema above
//! (names `t`, `q1`, …), and a file without one in the writer's order — `t`, the
//! `q`s, the `v`s (if any), the `a`s (if any), the `tau`s, the 6 wrench components
//! per joint (if any) — recognised by the number of fields. With `q` and `tau`,
//! exactly the named columns are read and every other column is ignored (joint
//! wrenches only come through the schema). Fields may be wrapped in double quotes.
//!
//! Each row is handled in this order: outside `rows` → skipped unread; its time
//! stamp converted (`time_unit`, `time_origin`); outside `window` → skipped, the
//! rest of the row unread (a window can cut away a damaged part); every read field
//! parsed and scaled (`units`, `gains`, `sign`) and checked: not a number, NaN or
//! infinite, or beyond ±[`MAX_ABS_VALUE`] in SI units is an error naming the line and
//! the column. Then against the previous kept row: the same time stamp is a
//! duplicate, dropped and counted (`repeated` when every value is equal too,
//! `same_time` when not: the first row of a time stamp wins); an earlier time stamp
//! is an error ([`DataError::TimeNotIncreasing`]); with `stale = drop` a row with a
//! new time stamp but every value equal is dropped. Then decimation. Errors are
//! collected over the whole file, as for the schema reader.
//!
//! Time stamps that are not uniform are accepted. `resample` off (the default): they
//! are used as they are; [`Loaded::with_derivatives`] then estimates derivatives at
//! those time stamps ([`Trajectory::with_derivatives_nonuniform`]; on a uniform
//! grid, within 1 %, it is exactly [`Trajectory::with_derivatives`]). `resample = DT`: every column is interpolated
//! (cubic Hermite, slopes from three-point differences, so value and slope are
//! continuous) onto `t₀, t₀ + DT, …` up to the last time stamp, and derivatives are
//! then taken on that uniform grid; resampled samples have no file line. The report
//! gives the smallest, median and largest step either way.
//!
//! [`Recipe::default`] reads the schema exactly as [`read_csv`] does; it differs
//! only in dropping duplicate time stamps, which [`read_csv`] rejects.
//!
//! An example recipe for a headerless 10 ms logger of a 6-joint arm writing
//! semicolon-separated degrees and motor currents:
//!
//! ```
//! use dyngen_identify::data::Recipe;
//!
//! let recipe = Recipe::parse("
//! ## robot controller log, 100 Hz
//! delimiter = semicolon
//! header = false
//! time = 1
//! time_unit = ms
//! q = 2-7
//! v = 8-13          ## measured by the drives
//! tau = 14-19       ## motor currents, A
//! units = deg
//! gains = 0.11, 0.11, 0.11, 0.05, 0.05, 0.05
//! sign = 1, -1, 1, 1, 1, 1
//! window = 5:65     ## s, after time_unit
//! ")?;
//! let row = |ms: f64| format!("{ms};90;90;0;0;0;0;0;0;0;0;0;0;2;2;2;2;2;2\n");
//! let log: String = [4990.0, 5000.0, 5011.0, 5011.0, 5019.0].map(row).concat();
//! let loaded = recipe.read_from(log.as_bytes(), Some(6))?;
//! let traj = &loaded.trajectory;
//! assert_eq!(traj.t(), &[5.0, 5.011, 5.019]); // one row before the window, one repeated
//! assert_eq!(traj.q(0)[..2], [std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2]);
//! assert_eq!(traj.tau(0)[..2], [0.22, -0.22]);
//! assert_eq!((loaded.report.outside_window, loaded.report.repeated), (1, 1));
//! // Accelerations from the measured velocities, at the log's own time stamps.
//! let full = loaded.with_derivatives(20.0)?;
//! assert!(full.report.to_string().contains("velocity: measured (columns 8–13); acceleration: estimated"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
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
mod log;
mod recipe;
mod trajectory;

pub use derivatives::{
    butterworth_filtfilt, central_difference, nonuniform_difference, nonuniform_second_difference, second_difference,
    SAMPLING_TOLERANCE,
};
pub use error::{DataError, Field, Location, MAX_ABS_VALUE, MAX_COLUMNS, MAX_LINE_BYTES};
pub use io::{csv_header, from_reader, overwrite_csv, read_csv, to_writer, write_csv, MAX_ERRORS};
pub use log::{LoadReport, Loaded, Provenance, TimeSteps, MAX_RESAMPLE_FACTOR};
pub use recipe::{
    ColumnRef, Columns, Delimiter, JointUnit, Recipe, RecipeError, RowWindow, Sampling, Stale, TimeOrigin, TimeUnit,
    TimeWindow, RECIPE_KEYS,
};
pub use trajectory::{Sample, Trajectory};
