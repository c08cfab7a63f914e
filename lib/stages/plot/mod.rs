//! `sc-plot`: force histories (the CSV tables `sc-solve` writes) → a PNG line plot.
//!
//! A plot is one or more stacked panels sharing the x axis; each panel draws one
//! or more series; a series is one column of one CSV file, optionally scaled and
//! divided by another column of the same file:
//!
//! ```text
//! x_i = X[i]            (the `x` column, default load_factor)
//! y_i = s · Y[i] / D[i] (the `column` Y, `scale` s (default 1), `divide_by` D (default 1))
//! ```
//! Rows where D = 0, where x or y is not finite (a missing cell, NaN) or where x is
//! outside `x_range` are left out of the line. The pipeline stage and the binary
//! both call [`plot`] with a [`PlotSpec`] (the stage's YAML block, keys in
//! `docs/pipelines.md`); [`render`] draws it.

pub mod args;
pub mod figure;
pub mod render;
pub mod text;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::format::csv::{CsvError, Table};
use crate::format::stage::files::resolve;
use crate::format::stage::{write_atomic, StageError};

use super::exit_code;
pub use figure::{Figure, Panel, Series};

/// Default image width in pixels.
pub const DEFAULT_WIDTH: u32 = 1000;
/// Default image height: this per panel, plus [`DEFAULT_HEIGHT_EXTRA`] once (at
/// most the largest accepted size).
pub const DEFAULT_PANEL_HEIGHT: u32 = 350;
pub const DEFAULT_HEIGHT_EXTRA: u32 = 350;
/// Accepted image sizes (each side), in pixels.
pub const SIZE_LIMITS: (u32, u32) = (200, 10_000);

/// The `plot` stage (and `sc-plot`'s figure): what to draw and where.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlotSpec {
    /// The PNG to write (atomically; `-` is standard output).
    pub output: PathBuf,
    /// Drawn above the panels.
    #[serde(default)]
    pub title: Option<String>,
    /// The x column, the same name in every file.
    #[serde(default = "default_x")]
    pub x: String,
    /// Under the bottom panel (default: the x column's name).
    #[serde(default)]
    pub x_label: Option<String>,
    /// [width, height] in pixels (default [1000, 350 + 350 × panels]).
    #[serde(default)]
    pub size: Option<[u32; 2]>,
    /// Draw only lo ≤ x ≤ hi (default: every x).
    #[serde(default)]
    pub x_range: Option<[f64; 2]>,
    /// Stacked top to bottom, sharing x.
    pub panels: Vec<PanelSpec>,
}

/// One sub-plot.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelSpec {
    #[serde(default)]
    pub y_label: Option<String>,
    /// Fix the y axis to [lo, hi] (default: fit the data).
    #[serde(default)]
    pub y_range: Option<[f64; 2]>,
    pub series: Vec<SeriesSpec>,
}

/// One line: `scale · column / divide_by` of one CSV file against its x column.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeriesSpec {
    pub input: PathBuf,
    pub column: String,
    #[serde(default = "one")]
    pub scale: f64,
    #[serde(default)]
    pub divide_by: Option<String>,
    /// The legend entry (default: `<file stem>: <column>`). Series with the same
    /// label share a colour in every panel.
    #[serde(default)]
    pub label: Option<String>,
}

fn default_x() -> String {
    "load_factor".into()
}

fn one() -> f64 {
    1.0
}

/// Why a plot could not be made. Every variant names its culprit: the file (and
/// line) for CSV trouble, the file and column for a missing column, the panel and
/// series (1-based) for a bad setting.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error(transparent)]
    Csv(#[from] CsvError),
    #[error("{path}: no {role} '{column}' (the file has: {available})")]
    MissingColumn { path: String, role: &'static str, column: String, available: String },
    #[error("a plot needs at least one panel (`panels:` is empty)")]
    NoPanels,
    #[error("panel {panel} has no series (give at least one under `series:`)")]
    NoSeries { panel: usize },
    #[error("size [{width}, {height}]: each side must be between {} and {} pixels", SIZE_LIMITS.0, SIZE_LIMITS.1)]
    BadSize { width: u32, height: u32 },
    #[error("{what} [{lo}, {hi}]: needs finite lo < hi")]
    BadRange { what: String, lo: f64, hi: f64 },
    #[error(transparent)]
    Undrawable(#[from] figure::Undrawable),
    #[error("panel {panel}, series {series}: scale must be a finite number, found {scale}")]
    BadScale { panel: usize, series: usize, scale: f64 },
    #[error("panel {panel}: nothing to draw: {detail}")]
    NoData { panel: usize, detail: String },
    #[error("{path}: the output must be a .png file (or - for standard output)")]
    NotPng { path: String },
    #[error("{path}: cannot draw the plot: {message}")]
    Render { path: String, message: String },
    #[error(transparent)]
    Write(#[from] StageError),
}

impl PlotError {
    /// 1 when a file could not be read or written, 2 for bad input.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Csv(CsvError::Io { .. }) | Self::Write(_) | Self::Render { .. } => exit_code::IO,
            _ => exit_code::BAD_INPUT,
        }
    }
}

/// The points of one series from its table: (x_i, s · Y_i / D_i) over the rows,
/// leaving out rows with D_i = 0, a non-finite x_i or y_i, or x_i outside `x_range`.
/// A missing column is an error naming the file and listing its columns.
pub fn series_points(table: &Table, x: &str, spec: &SeriesSpec, x_range: Option<[f64; 2]>) -> Result<Vec<(f64, f64)>, PlotError> {
    let find = |role: &'static str, name: &str| {
        table.column(name).ok_or_else(|| PlotError::MissingColumn {
            path: table.path.clone(),
            role,
            column: name.to_string(),
            available: table.distinct_columns().join(", "),
        })
    };
    let cx = find("x column", x)?;
    let cy = find("column", &spec.column)?;
    let cd = spec.divide_by.as_deref().map(|d| find("divide_by column", d)).transpose()?;
    let inside = |v: f64| x_range.is_none_or(|[lo, hi]| lo <= v && v <= hi);
    Ok(table
        .rows
        .iter()
        .filter_map(|row| {
            let d = cd.map_or(1.0, |c| row[c]);
            let (xv, yv) = (row[cx], spec.scale * row[cy] / d);
            (d != 0.0 && xv.is_finite() && yv.is_finite() && inside(xv)).then_some((xv, yv))
        })
        .collect())
}

/// The legend entry of a series without a `label`: `<file stem>: <column>`, with
/// ` / <divide_by>` and ` × <scale>` when given.
pub fn default_label(spec: &SeriesSpec) -> String {
    let stem = spec.input.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let stem = stem.strip_suffix(".csv").unwrap_or(&stem);
    let stem = stem.strip_suffix(".forces").unwrap_or(stem);
    let mut l = format!("{stem}: {}", spec.column);
    if let Some(d) = &spec.divide_by {
        l.push_str(&format!(" / {d}"));
    }
    if spec.scale != 1.0 {
        l.push_str(&format!(" × {}", spec.scale));
    }
    l
}

fn check_range(what: String, r: [f64; 2]) -> Result<(f64, f64), PlotError> {
    let [lo, hi] = r;
    if lo.is_finite() && hi.is_finite() && lo < hi {
        Ok((lo, hi))
    } else {
        Err(PlotError::BadRange { what, lo, hi })
    }
}

/// The smallest and largest of `values`, widened when they (nearly) coincide so an
/// axis never has zero length, and padded by `pad` × the span on each side.
pub fn fit_range(values: impl Iterator<Item = f64>, pad: f64) -> Option<(f64, f64)> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return None;
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(hi.abs()) {
        let w = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return Some((lo - w, hi + w));
    }
    Some((lo - pad * span, hi + pad * span))
}

/// Read the tables (each file once, paths resolved against `base`) and build the
/// figure: check the settings, compute every series, fit the axes.
pub fn figure(spec: &PlotSpec, base: &Path) -> Result<Figure, PlotError> {
    if spec.panels.is_empty() {
        return Err(PlotError::NoPanels);
    }
    let n = spec.panels.len() as u32;
    let default_height = (DEFAULT_HEIGHT_EXTRA + DEFAULT_PANEL_HEIGHT * n).min(SIZE_LIMITS.1);
    let [w, h] = spec.size.unwrap_or([DEFAULT_WIDTH, default_height]);
    let (min, max) = SIZE_LIMITS;
    if !(min..=max).contains(&w) || !(min..=max).contains(&h) {
        return Err(PlotError::BadSize { width: w, height: h });
    }
    let x_range = spec.x_range.map(|r| check_range("x_range".into(), r)).transpose()?;
    let mut tables: BTreeMap<PathBuf, Table> = BTreeMap::new();
    let mut panels = Vec::with_capacity(spec.panels.len());
    for (p, ps) in spec.panels.iter().enumerate() {
        let panel = p + 1;
        if ps.series.is_empty() {
            return Err(PlotError::NoSeries { panel });
        }
        let y_fixed = ps.y_range.map(|r| check_range(format!("panel {panel}: y_range"), r)).transpose()?;
        let mut series = Vec::with_capacity(ps.series.len());
        for (s, ss) in ps.series.iter().enumerate() {
            if !ss.scale.is_finite() {
                return Err(PlotError::BadScale { panel, series: s + 1, scale: ss.scale });
            }
            let path = resolve(base, &ss.input);
            if !tables.contains_key(&path) {
                let t = Table::read(&path)?;
                tables.insert(path.clone(), t);
            }
            let points = series_points(&tables[&path], &spec.x, ss, spec.x_range)?;
            series.push(Series { label: ss.label.clone().unwrap_or_else(|| default_label(ss)), points });
        }
        let Some(fitted) = fit_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), 0.05) else {
            let names = series.iter().map(|s| format!("'{}'", s.label)).collect::<Vec<_>>().join(", ");
            let place = if spec.x_range.is_some() { " inside x_range" } else { "" };
            return Err(PlotError::NoData { panel, detail: format!("no finite point{place} in {names}") });
        };
        let y_range = y_fixed.unwrap_or(fitted);
        panels.push(Panel { y_label: ps.y_label.clone(), y_range, series });
    }
    let all_x = panels.iter().flat_map(|p| p.series.iter().flat_map(|s| s.points.iter().map(|q| q.0)));
    // every panel has a point (checked above), so the fit exists
    let x_range = x_range.or_else(|| fit_range(all_x, 0.0)).unwrap_or((0.0, 1.0));
    let figure = Figure {
        title: spec.title.clone(),
        x_label: spec.x_label.clone().unwrap_or_else(|| spec.x.clone()),
        size: (w, h),
        x_range,
        panels,
    };
    figure.check_drawable()?;
    Ok(figure)
}

/// Make the plot: read, compute, draw and write the PNG atomically (nothing is
/// written on failure). Relative paths in `spec` are resolved against `base` (the
/// pipeline YAML's folder; empty for the working directory). Returns one line
/// describing what was written.
pub fn plot(spec: &PlotSpec, base: &Path) -> Result<String, PlotError> {
    let output = resolve(base, &spec.output);
    let is_png = output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png && output.as_os_str() != "-" {
        return Err(PlotError::NotPng { path: output.display().to_string() });
    }
    let fig = figure(spec, base)?;
    let png = render::render_png(&fig).map_err(|message| PlotError::Render { path: output.display().to_string(), message })?;
    write_atomic(&output, &png)?;
    let series: usize = fig.panels.iter().map(|p| p.series.len()).sum();
    let points: usize = fig.panels.iter().flat_map(|p| p.series.iter().map(|s| s.points.len())).sum();
    let empty: Vec<&str> = fig.panels.iter().flat_map(|p| p.series.iter().filter(|s| s.points.is_empty()).map(|s| s.label.as_str())).collect();
    let warn = if empty.is_empty() { String::new() } else { format!("; no point to draw in: {}", empty.join(", ")) };
    Ok(format!(
        "wrote {} ({} × {} px, {} panel(s), {series} series, {points} points){warn}",
        output.display(),
        fig.size.0,
        fig.size.1,
        fig.panels.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "increment,load_factor,reaction:top:x,reaction:top:y,reaction:top:x,reaction:top:y\n\
                       1,0.5,1e0,-4e0,7,7\n\
                       2,1e0,2e0,0e0,7,7\n\
                       3,1.5e0,3e0,-6e0,7,7\n\
                       4,2e0,,-8e0,7,7\n";

    fn table() -> Table {
        Table::parse("out/a.forces.csv", CSV).unwrap()
    }

    fn series(column: &str) -> SeriesSpec {
        SeriesSpec { input: "out/a.forces.csv".into(), column: column.into(), scale: 1.0, divide_by: None, label: None }
    }

    #[test]
    fn scale_multiplies_and_takes_the_first_of_duplicate_columns() {
        let s = SeriesSpec { scale: -1.0, ..series("reaction:top:y") };
        let p = series_points(&table(), "load_factor", &s, None).unwrap();
        assert_eq!(p, [(0.5, 4.0), (1.0, -0.0), (1.5, 6.0), (2.0, 8.0)]);
    }

    #[test]
    fn divide_by_skips_zero_divisors_and_missing_cells() {
        // H/V = −x/y: row 2 has V = 0 (skipped), row 4 a missing H (skipped)
        let s = SeriesSpec { scale: -1.0, divide_by: Some("reaction:top:y".into()), ..series("reaction:top:x") };
        let p = series_points(&table(), "load_factor", &s, None).unwrap();
        assert_eq!(p, [(0.5, 0.25), (1.5, 0.5)]);
    }

    #[test]
    fn x_range_keeps_the_rows_inside() {
        let p = series_points(&table(), "load_factor", &series("reaction:top:y"), Some([1.0, 1.5])).unwrap();
        assert_eq!(p, [(1.0, 0.0), (1.5, -6.0)]);
        let p = series_points(&table(), "increment", &series("reaction:top:y"), None).unwrap();
        assert_eq!(p.iter().map(|q| q.0).collect::<Vec<_>>(), [1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn missing_column_names_file_and_lists_columns_once() {
        let e = series_points(&table(), "load_factor", &series("reaction:bottom:y"), None).unwrap_err();
        assert_eq!(e.exit_code(), exit_code::BAD_INPUT);
        let m = e.to_string();
        assert_eq!(m, "out/a.forces.csv: no column 'reaction:bottom:y' (the file has: increment, load_factor, reaction:top:x, reaction:top:y)");
        let s = SeriesSpec { divide_by: Some("V".into()), ..series("reaction:top:x") };
        let m = series_points(&table(), "load_factor", &s, None).unwrap_err().to_string();
        assert!(m.contains("no divide_by column 'V'"), "{m}");
        let m = series_points(&table(), "time", &series("reaction:top:x"), None).unwrap_err().to_string();
        assert!(m.contains("no x column 'time'"), "{m}");
    }

    #[test]
    fn default_labels() {
        assert_eq!(default_label(&series("reaction:top:y")), "a: reaction:top:y");
        let s = SeriesSpec { scale: -1.0, divide_by: Some("reaction:top:y".into()), ..series("reaction:top:x") };
        assert_eq!(default_label(&s), "a: reaction:top:x / reaction:top:y × -1");
    }

    #[test]
    fn an_axis_near_the_largest_f64_is_refused() {
        let panel = |y_range| Panel { y_label: None, y_range, series: Vec::new() };
        let fig = Figure { title: None, x_label: "x".into(), size: (320, 240), x_range: (0.0, 1.0), panels: vec![panel((-1e200, 1e200)), panel((0.0, 1e308))] };
        assert_eq!(fig.check_drawable(), Err(figure::Undrawable { what: "panel 2: the y axis".into(), value: 1e308 }));
        let fig = Figure { panels: vec![panel((-1e200, 1e200))], ..fig };
        assert_eq!(fig.check_drawable(), Ok(()));
    }

    #[test]
    fn fit_range_pads_and_never_collapses() {
        assert_eq!(fit_range([0.0, 10.0].into_iter(), 0.05), Some((-0.5, 10.5)));
        assert_eq!(fit_range([0.0, 0.0].into_iter(), 0.05), Some((-1.0, 1.0)));
        assert_eq!(fit_range([5.0].into_iter(), 0.05), Some((4.5, 5.5)));
        assert_eq!(fit_range(std::iter::empty(), 0.05), None);
    }

    fn spec(dir: &Path, panels: Vec<PanelSpec>) -> PlotSpec {
        std::fs::write(dir.join("a.forces.csv"), CSV).unwrap();
        PlotSpec { output: "p.png".into(), title: None, x: default_x(), x_label: None, size: None, x_range: None, panels }
    }

    fn panel(series: Vec<SeriesSpec>) -> PanelSpec {
        PanelSpec { y_label: None, y_range: None, series }
    }

    #[test]
    fn figure_reads_relative_to_base_and_fits_axes() {
        let dir = tempfile::tempdir().unwrap();
        let s = SeriesSpec { input: "a.forces.csv".into(), ..series("reaction:top:y") };
        let f = figure(&spec(dir.path(), vec![panel(vec![s.clone()]), panel(vec![s])]), dir.path()).unwrap();
        assert_eq!(f.size, (1000, 1050));
        assert_eq!(f.x_range, (0.5, 2.0));
        assert_eq!(f.x_label, "load_factor");
        let (lo, hi) = f.panels[0].y_range;
        assert!((lo + 8.4).abs() < 1e-12 && (hi - 0.4).abs() < 1e-12, "{lo} {hi}");
    }

    #[test]
    fn figure_settings_are_checked() {
        let dir = tempfile::tempdir().unwrap();
        let s = SeriesSpec { input: "a.forces.csv".into(), ..series("reaction:top:y") };
        let e = figure(&spec(dir.path(), vec![]), dir.path()).unwrap_err();
        assert!(matches!(e, PlotError::NoPanels));
        let e = figure(&spec(dir.path(), vec![panel(vec![s.clone()]), panel(vec![])]), dir.path()).unwrap_err();
        assert_eq!(e.to_string(), "panel 2 has no series (give at least one under `series:`)");
        let mut sp = spec(dir.path(), vec![panel(vec![s.clone()])]);
        sp.size = Some([10, 700]);
        assert!(matches!(figure(&sp, dir.path()), Err(PlotError::BadSize { .. })));
        sp.size = None;
        sp.x_range = Some([2.0, 1.0]);
        assert!(figure(&sp, dir.path()).unwrap_err().to_string().contains("x_range [2, 1]"));
        sp.x_range = Some([10.0, 11.0]);
        let e = figure(&sp, dir.path()).unwrap_err().to_string();
        assert!(e.contains("panel 1: nothing to draw: no finite point inside x_range in 'a: reaction:top:y'"), "{e}");
        sp.x_range = None;
        sp.panels[0].series[0].scale = f64::NAN;
        assert!(matches!(figure(&sp, dir.path()), Err(PlotError::BadScale { panel: 1, series: 1, .. })));
        let missing = SeriesSpec { input: "b.forces.csv".into(), ..series("reaction:top:y") };
        let e = figure(&spec(dir.path(), vec![panel(vec![missing])]), dir.path()).unwrap_err();
        assert_eq!(e.exit_code(), exit_code::IO);
        assert!(e.to_string().contains("b.forces.csv: cannot read"), "{e}");
    }

    #[test]
    fn output_must_be_png() {
        let dir = tempfile::tempdir().unwrap();
        let s = SeriesSpec { input: "a.forces.csv".into(), ..series("reaction:top:y") };
        let mut sp = spec(dir.path(), vec![panel(vec![s])]);
        sp.output = "p.svg".into();
        assert!(matches!(plot(&sp, dir.path()), Err(PlotError::NotPng { .. })));
        assert!(!dir.path().join("p.svg").exists());
    }
}
