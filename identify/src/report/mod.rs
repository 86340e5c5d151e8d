//! What identification hands to people and to other tools: the parameters as JSON
//! ([`ParameterReport`]), the URDF rewritten with identified inertials
//! ([`rewrite_urdf_inertials`]), and beside it the joint terms a URDF cannot hold
//! ([`JointParamsFile`]), and with the `svg` feature SVG charts drawn with plotters
//! (`svg_report`: measured against predicted torques, `svg_lines`: any [`LineChart`]).
//!
//! Each output is built as a string with no I/O; [`write_new`] writes it and never
//! replaces an existing file unless asked to.

mod chart;
mod error;
mod joint_params;
mod json;
#[cfg(feature = "svg")]
mod svg;
mod urdf;

pub use chart::{Corner, LineChart};
pub use error::ReportError;
pub use joint_params::{JointParams, JointParamsFile, JOINT_PARAMS_SCHEMA};
pub use json::{
    CombinationReport, CoulombReport, DataSpan, NonPhysical, ParamReport, ParamStatus, ParameterReport,
    Parameterisation, PredictionModel, Preprocessing, Term, SCHEMA,
};
#[cfg(feature = "svg")]
pub use svg::{identification_report, svg_lines, svg_report, svg_report_with, trajectory_report, SvgOptions};
pub use urdf::{rewrite_urdf_dynamics, rewrite_urdf_inertials, rewrite_urdf_inertials_with, MergedLinks};

use std::io::Write;
use std::path::Path;

/// Writes `contents` to `path`. Without `overwrite` an existing file is an error
/// ([`ReportError::Exists`]), checked atomically (`create_new`), so two runs cannot
/// both believe they wrote the file.
pub fn write_new(path: &Path, contents: &str, overwrite: bool) -> Result<(), ReportError> {
    let io = |e: std::io::Error| ReportError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    if overwrite {
        options.create(true).truncate(true);
    } else {
        options.create_new(true);
    }
    let mut file = options.open(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::AlreadyExists {
            ReportError::Exists {
                path: path.display().to_string(),
            }
        } else {
            io(e)
        }
    })?;
    file.write_all(contents.as_bytes()).map_err(io)
}

/// Writes an SVG report (a [`LineChart`] rendered to text) as [`write_new`] writes any file.
pub fn write_report(path: &Path, svg: &str, overwrite: bool) -> Result<(), ReportError> {
    write_new(path, svg, overwrite)
}
