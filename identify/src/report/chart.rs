//! What a line chart shows, as plain data: the libraries describe their figures (the
//! paper's Fig. 5, training curves, payload tracking) and a front end draws them (as
//! SVG through the `svg` feature's `svg_lines`), so no library links a plotting crate
//! unless asked.

/// A corner of a chart, for its legend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Corner {
    #[default]
    UpperRight,
    LowerRight,
}

/// Lines against a common x axis: curves of `(x, y)` points, optionally a
/// horizontal reference line.
#[derive(Clone, Debug, PartialEq)]
pub struct LineChart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    /// A logarithmic y axis (every y must then be > 0).
    pub log_y: bool,
    /// `(name, [(x, y)])` per line.
    pub curves: &'a [(String, Vec<(f64, f64)>)],
    /// A horizontal reference line: `(name, y)`.
    pub reference: Option<(&'a str, f64)>,
    /// Where the legend goes (pick the corner the lines leave free).
    pub legend: Corner,
}
