//! The SVG report: measured against predicted torques, one small plot per joint
//! with time on x, and, when the true parameters are known, the relative error of
//! each parameter as a bar chart on a log scale (unidentifiable ones marked).
//!
//! Drawn with plotters' SVG backend and no font feature: text becomes SVG `<text>`
//! elements (`font-family="sans-serif"`) that the viewer renders, so nothing needs
//! font files or system libraries; plotters only estimates text widths for layout.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor;

use super::ReportError;

const MEASURED: RGBColor = RGBColor(31, 119, 180);
const PREDICTED: RGBColor = RGBColor(214, 39, 40);
const UNIDENTIFIABLE: RGBColor = RGBColor(190, 190, 190);

/// Layout of [`svg_report`].
#[derive(Clone, Debug, PartialEq)]
pub struct SvgOptions {
    /// Width of the whole image in pixels.
    pub width: u32,
    /// Joint plots per row.
    pub columns: usize,
    /// Height of one joint plot in pixels.
    pub plot_height: u32,
    /// Height of the parameter-error chart in pixels.
    pub error_height: u32,
    /// Unit of the joint efforts, for the y axis.
    pub effort_unit: String,
}

impl Default for SvgOptions {
    fn default() -> Self {
        Self {
            width: 1000,
            columns: 2,
            plot_height: 220,
            error_height: 360,
            effort_unit: "N·m or N".into(),
        }
    }
}

/// The report as an SVG document, with the default [`SvgOptions`].
///
/// `t` has one time per sample; `measured[k]` and `predicted[k]` hold the `n`
/// joint efforts at sample `k`; `joint_names` has `n` names. `param_errors`, when
/// the truth is known, gives per parameter its name and relative error
/// `(x̂ − x)/x` (`None`: not identifiable, drawn as a grey marker).
pub fn svg_report(
    title: &str,
    t: &[f64],
    measured: &[Vec<f64>],
    predicted: &[Vec<f64>],
    joint_names: &[&str],
    param_errors: Option<&[(String, Option<f64>)]>,
) -> Result<String, ReportError> {
    svg_report_with(
        title,
        t,
        measured,
        predicted,
        joint_names,
        param_errors,
        &SvgOptions::default(),
    )
}

/// The report of an identification by `method` on the recording `data` (loaded as
/// `traj`): its measured joint efforts against `predicted` (one row per sample), with
/// the parameter errors when the truth is known; titled with the robot, the method and
/// the file name, as `dyngen identify --report` and the Python package write it.
pub fn identification_report(
    model: &dyngen_model::Model,
    method: &str,
    data: &std::path::Path,
    traj: &crate::data::Trajectory,
    predicted: &[Vec<f64>],
    param_errors: Option<&[(String, Option<f64>)]>,
) -> Result<String, ReportError> {
    let file = data
        .file_name()
        .map_or_else(|| data.display().to_string(), |f| f.to_string_lossy().into_owned());
    let title = format!("{}: {method} on {file}", model.name);
    trajectory_report(&title, model, traj, predicted, param_errors)
}

/// [`svg_report`] of a recording `traj` of `model`'s joints: its measured efforts
/// against `predicted` (one row per sample).
pub fn trajectory_report(
    title: &str,
    model: &dyngen_model::Model,
    traj: &crate::data::Trajectory,
    predicted: &[Vec<f64>],
    param_errors: Option<&[(String, Option<f64>)]>,
) -> Result<String, ReportError> {
    let measured: Vec<Vec<f64>> = (0..traj.len()).map(|k| traj.tau(k).to_vec()).collect();
    let joint_names: Vec<&str> = model.own_joints().map(|j| j.name.as_str()).collect();
    svg_report(title, traj.t(), &measured, predicted, &joint_names, param_errors)
}

/// [`svg_report`] with explicit layout options.
pub fn svg_report_with(
    title: &str,
    t: &[f64],
    measured: &[Vec<f64>],
    predicted: &[Vec<f64>],
    joint_names: &[&str],
    param_errors: Option<&[(String, Option<f64>)]>,
    options: &SvgOptions,
) -> Result<String, ReportError> {
    let n = joint_names.len();
    check(t, measured, predicted, n, param_errors)?;
    let columns = options.columns.max(1);
    let rows = n.div_ceil(columns).max(1);
    let title_height = 50;
    let plots_height = rows as u32 * options.plot_height;
    let errors_height = if param_errors.is_some() {
        options.error_height
    } else {
        0
    };
    let size = (options.width, title_height + plots_height + errors_height);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(plot_error)?;
        let (plots, errors) = root.split_vertically(plots_height);
        let areas = plots.split_evenly((rows, columns));
        for (j, area) in areas.iter().enumerate().take(n) {
            let m: Vec<(f64, f64)> = t.iter().zip(measured).map(|(&t, y)| (t, y[j])).collect();
            let p: Vec<(f64, f64)> = t.iter().zip(predicted).map(|(&t, y)| (t, y[j])).collect();
            joint_plot(area, joint_names[j], &m, &p, j == 0, &options.effort_unit)?;
        }
        if let Some(e) = param_errors {
            error_chart(&errors, e)?;
        }
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

fn check(
    t: &[f64],
    measured: &[Vec<f64>],
    predicted: &[Vec<f64>],
    n: usize,
    param_errors: Option<&[(String, Option<f64>)]>,
) -> Result<(), ReportError> {
    let mismatch = |what: &str, expected: usize, found: usize| ReportError::DimensionMismatch {
        what: what.into(),
        expected,
        found,
    };
    if t.is_empty() {
        return Err(mismatch("t (samples)", 1, 0));
    }
    for (what, data) in [("measured", measured), ("predicted", predicted)] {
        if data.len() != t.len() {
            return Err(mismatch(what, t.len(), data.len()));
        }
        for (k, row) in data.iter().enumerate() {
            if row.len() != n {
                return Err(mismatch(&format!("{what}[{k}] (one value per joint)"), n, row.len()));
            }
            if let Some(j) = row.iter().position(|x| !x.is_finite()) {
                return Err(ReportError::NonFinite {
                    what: format!("{what}[{k}]"),
                    index: j,
                });
            }
        }
    }
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(ReportError::NonFinite {
            what: "t".into(),
            index: k,
        });
    }
    if let Some(k) = param_errors.and_then(|e| e.iter().position(|(_, v)| v.is_some_and(|v| !v.is_finite()))) {
        return Err(ReportError::NonFinite {
            what: "param_errors".into(),
            index: k,
        });
    }
    Ok(())
}

fn plot_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> ReportError {
    ReportError::Plot { message: e.to_string() }
}

/// `lo..hi` padded by 5%, never empty.
fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1.0) * 0.05
    };
    lo - pad..hi + pad
}

fn joint_plot(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    name: &str,
    measured: &[(f64, f64)],
    predicted: &[(f64, f64)],
    legend: bool,
    unit: &str,
) -> Result<(), ReportError> {
    let x = range(measured.iter().map(|p| p.0));
    let y = range(measured.iter().chain(predicted).map(|p| p.1));
    let mut chart = ChartBuilder::on(area)
        .caption(name, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_labels(6)
        .y_labels(5)
        .x_desc("t (s)")
        .y_desc(unit)
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 11))
        .light_line_style(WHITE)
        .draw()
        .map_err(plot_error)?;
    let m = chart
        .draw_series(LineSeries::new(measured.iter().copied(), MEASURED.stroke_width(2)))
        .map_err(plot_error)?;
    if legend {
        m.label("measured")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], MEASURED.stroke_width(2)));
    }
    let p = chart
        .draw_series(LineSeries::new(predicted.iter().copied(), PREDICTED.stroke_width(1)))
        .map_err(plot_error)?;
    if legend {
        p.label("predicted")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], PREDICTED.stroke_width(1)));
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 11))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK.mix(0.3))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_error)?;
    }
    Ok(())
}

/// Bars of `log10(100·|error|)` (percent on a log axis); an exact zero sits at the floor.
fn error_chart(area: &DrawingArea<SVGBackend<'_>, Shift>, errors: &[(String, Option<f64>)]) -> Result<(), ReportError> {
    const FLOOR: f64 = -14.0;
    let log = |e: f64| (100.0 * e.abs()).log10().max(FLOOR);
    let known: Vec<f64> = errors.iter().filter_map(|(_, e)| e.map(log)).collect();
    let lo = known.iter().copied().fold(f64::INFINITY, f64::min).floor().min(-1.0);
    let hi = known
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil()
        .max(lo + 1.0);
    let (lo, hi) = if known.is_empty() { (-3.0, 2.0) } else { (lo, hi) };
    let count = errors.len().max(1) as f64;
    let mut chart = ChartBuilder::on(area)
        .caption(
            "relative parameter error |x̂ − x| / |x| in % (grey ×: not identifiable, 0: exact)",
            ("sans-serif", 15),
        )
        .margin(8)
        .x_label_area_size(70)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..count, lo..hi)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_labels((hi - lo) as usize + 1)
        .y_label_formatter(&|v| format!("1e{}", v.round()))
        .y_desc("error (%)")
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 11))
        .light_line_style(WHITE)
        .draw()
        .map_err(plot_error)?;
    let bars = errors.iter().enumerate().filter_map(|(k, (_, e))| {
        e.map(|e| Rectangle::new([(k as f64 + 0.15, lo), (k as f64 + 0.85, log(e))], MEASURED.filled()))
    });
    chart.draw_series(bars).map_err(plot_error)?;
    // Grey × for an unidentifiable parameter, "0" for an exact estimate (no bar).
    let marks = errors.iter().enumerate().filter_map(|(k, (_, e))| {
        let (mark, colour) = match e {
            None => ("×", UNIDENTIFIABLE),
            Some(e) if *e == 0.0 => ("0", BLACK),
            Some(_) => return None,
        };
        Some(Text::new(
            mark,
            (k as f64 + 0.5, lo + 0.05 * (hi - lo)),
            ("sans-serif", 14).into_font().color(&colour).pos(text_anchor::Pos::new(
                text_anchor::HPos::Center,
                text_anchor::VPos::Bottom,
            )),
        ))
    });
    chart.draw_series(marks).map_err(plot_error)?;
    // Parameter names, rotated, under each bar.
    let names = errors.iter().enumerate().map(|(k, (name, e))| {
        let colour = if e.is_some() { BLACK } else { UNIDENTIFIABLE };
        let style = ("sans-serif", 10)
            .into_font()
            .transform(FontTransform::Rotate270)
            .color(&colour)
            .pos(text_anchor::Pos::new(
                text_anchor::HPos::Right,
                text_anchor::VPos::Center,
            ));
        (k, name.clone(), style)
    });
    let (x0, y0) = chart.backend_coord(&(0.0, lo));
    let (x1, _) = chart.backend_coord(&(count, lo));
    let step = f64::from(x1 - x0) / count;
    let root = area.strip_coord_spec();
    let offset = area.get_base_pixel();
    for (k, name, style) in names {
        let x = x0 - offset.0 + (step * (k as f64 + 0.5)).round() as i32;
        root.draw(&Text::new(name, (x, y0 - offset.1 + 6), style))
            .map_err(plot_error)?;
    }
    Ok(())
}

use super::{Corner, LineChart};

/// Lines against a common x axis, e.g. the paper's Fig. 5 (MSE against training
/// step, log scale) or estimates against time. Non-finite points, and points with
/// `y ≤ 0` on a log axis, are an error.
pub fn svg_lines(chart: &LineChart<'_>) -> Result<String, ReportError> {
    for (c, (_, points)) in chart.curves.iter().enumerate() {
        if let Some(k) = points
            .iter()
            .position(|&(x, y)| !(x.is_finite() && y.is_finite() && (!chart.log_y || y > 0.0)))
        {
            return Err(ReportError::NonFinite {
                what: format!(
                    "curves[{c}] (x and y finite{})",
                    if chart.log_y { ", y > 0 on a log axis" } else { "" }
                ),
                index: k,
            });
        }
    }
    let points = || chart.curves.iter().flat_map(|(_, p)| p.iter());
    let x = range(points().map(|p| p.0));
    let ys = || points().map(|p| p.1).chain(chart.reference.map(|r| r.1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        if chart.log_y {
            let lo = ys().filter(|y| *y > 0.0).fold(f64::INFINITY, f64::min);
            let hi = ys().fold(f64::NEG_INFINITY, f64::max);
            let (lo, hi) = if lo.is_finite() && hi > lo {
                (lo / 2.0, hi * 2.0)
            } else {
                (1e-6, 1.0)
            };
            draw_lines(&root, chart, x, (lo..hi).log_scale(), &|v| format!("{v:.0e}"))?;
        } else {
            draw_lines(&root, chart, x, range(ys()), &|v| format!("{v:.3}"))?;
        }
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

fn draw_lines<Y>(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    chart: &LineChart<'_>,
    x: std::ops::Range<f64>,
    y: Y,
    y_format: &dyn Fn(&f64) -> String,
) -> Result<(), ReportError>
where
    Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let (x_lo, x_hi) = (x.start, x.end);
    let mut plot = ChartBuilder::on(root)
        .caption(chart.title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(plot_error)?;
    plot.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc(chart.y_label)
        .y_label_formatter(y_format)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 12))
        .light_line_style(WHITE)
        .draw()
        .map_err(plot_error)?;
    for (c, (name, points)) in chart.curves.iter().enumerate() {
        let colour = Palette99::pick(c).to_rgba();
        plot.draw_series(LineSeries::new(points.iter().copied(), colour.stroke_width(2)))
            .map_err(plot_error)?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
    }
    if let Some((name, level)) = chart.reference {
        plot.draw_series(LineSeries::new(
            [(x_lo, level), (x_hi, level)],
            BLACK.mix(0.5).stroke_width(1),
        ))
        .map_err(plot_error)?
        .label(name)
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.mix(0.5).stroke_width(1)));
    }
    plot.configure_series_labels()
        .label_font(("sans-serif", 12))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK.mix(0.3))
        .position(match chart.legend {
            Corner::UpperRight => SeriesLabelPosition::UpperRight,
            Corner::LowerRight => SeriesLabelPosition::LowerRight,
        })
        .draw()
        .map_err(plot_error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::write_report;

    #[test]
    fn svg_report_has_a_plot_per_joint_and_labels() {
        let joints = ["shoulder", "elbow", "wrist"];
        let t: Vec<f64> = (0..100).map(|k| 0.02 * k as f64).collect();
        let measured: Vec<Vec<f64>> = t
            .iter()
            .map(|&t| {
                (0..3)
                    .map(|j| (t * (j + 1) as f64).sin() + 0.02 * (37.0 * t).sin())
                    .collect()
            })
            .collect();
        let predicted: Vec<Vec<f64>> = t
            .iter()
            .map(|&t| (0..3).map(|j| (t * (j + 1) as f64).sin()).collect())
            .collect();
        let errors: Vec<(String, Option<f64>)> = (0..20i32)
            .map(|k| {
                let e = match k % 5 {
                    3 => None,
                    4 => Some(0.0),
                    _ => Some(10f64.powi(-k % 9) * if k % 2 == 0 { 1.0 } else { -1.0 }),
                };
                (format!("p{k}"), e)
            })
            .collect();
        let svg = svg_report("ur5 torque fit", &t, &measured, &predicted, &joints, Some(&errors)).unwrap();
        let dir = std::env::temp_dir().join(format!("dyngen-svg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("report.svg");
        let _ = std::fs::remove_file(&path);
        write_report(&path, &svg, false).unwrap();
        assert!(matches!(
            write_report(&path, &svg, false),
            Err(ReportError::Exists { .. })
        ));
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        assert!(svg.trim_end().ends_with("</svg>"));
        // One measured and one predicted curve per joint, plus one legend swatch each
        // (axes and ticks are black polylines).
        let curves = |colour: &str| {
            svg.matches(&format!("<polyline fill=\"none\" opacity=\"1\" stroke=\"{colour}\""))
                .count()
        };
        assert_eq!(curves("#1F77B4"), joints.len() + 1);
        assert_eq!(curves("#D62728"), joints.len() + 1);
        for label in [
            "ur5 torque fit",
            "shoulder",
            "elbow",
            "wrist",
            "measured",
            "predicted",
            "t (s)",
            "p0",
            "p19",
        ] {
            assert!(svg.contains(&format!(">\n{label}\n</text>")), "missing label {label}");
        }
        // 16 known errors as bars, 4 unidentifiable marked.
        assert_eq!(svg.matches(">\n×\n</text>").count(), 4);
        // No font files, no raster images.
        assert!(!svg.contains("<image") && !svg.contains("@font-face"));

        let short = svg_report("x", &t[..5], &measured, &predicted, &joints, None).unwrap_err();
        assert!(matches!(short, ReportError::DimensionMismatch { .. }), "{short}");
        let mut nan = measured.clone();
        nan[7][1] = f64::NAN;
        let e = svg_report("x", &t, &nan, &predicted, &joints, None).unwrap_err();
        assert_eq!(e.to_string(), "non-finite value in measured[7] at index 1");
    }
}
