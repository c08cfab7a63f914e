//! sc-plot: force histories (CSV written by sc-solve) → a PNG line plot.
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;
use splinecontact::stages::exit_code;
use splinecontact::stages::plot::{self, args::parse_series, PanelSpec, PlotSpec, SeriesSpec};

/// Plot columns of the CSV files sc-solve writes (<name>.forces.csv,
/// <name>.convergence.csv) against a shared x column, into a PNG.
///
/// Each --series is FILE:COLUMN[:SCALE]: the file is everything up to the first
/// ".csv:", the column the rest (names hold colons: reaction:indenter_top:y), and a
/// last field that reads as a number multiplies the values. With --divide-by every
/// series is divided by that column of its own file (rows where it is 0 are left
/// out). Rows with an empty or NaN cell are left out too. The first of two
/// columns with the same name is used. Labels default to "<file stem>: <column>";
/// --label gives them in the order of the --series. A series with up to 60 points
/// also gets a dot per point.
///
/// This draws one panel; stacked panels (e.g. V and H/V over one x axis) are the
/// `plot` stage of sc-pipeline (docs/pipelines.md), with the same keys per series.
///
/// Exit codes: 0 written, 1 a file could not be read or written, 2 bad input (a
/// missing column, a number that does not parse, an empty CSV); nothing is written
/// on failure.
///
/// Examples:
///   sc-plot forces.png --series out/a.forces.csv:reaction:indenter_top:y:-1
///   sc-plot v.png --title "Shallow ironing" --y-label "V [N/mm]" \
///       --series out/si-facet.forces.csv:reaction:indenter_top:y:-1 --label facet \
///       --series out/si-b3.forces.csv:reaction:indenter_top:y:-1 --label "B-spline 3"
///   sc-plot hv.png --divide-by reaction:indenter_top:y --x-range 1 2 --y-label H/V \
///       --series out/si-b3.forces.csv:reaction:indenter_top:x:-1
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// The PNG to write, or - for standard output.
    output: PathBuf,
    /// A line to draw (repeatable): FILE:COLUMN[:SCALE].
    #[arg(short, long = "series", value_name = "FILE:COLUMN[:SCALE]", required = true, value_parser = parse_series)]
    series: Vec<SeriesSpec>,
    /// Legend entry of the series in the same position (repeatable).
    #[arg(short, long = "label", value_name = "LABEL")]
    labels: Vec<String>,
    /// Divide every series by this column of its file.
    #[arg(long, value_name = "COLUMN")]
    divide_by: Option<String>,
    /// The x column.
    #[arg(short, long, default_value = "load_factor", value_name = "COLUMN")]
    x: String,
    /// Title above the plot.
    #[arg(short, long)]
    title: Option<String>,
    /// x axis label (default: the x column's name).
    #[arg(long)]
    x_label: Option<String>,
    /// y axis label.
    #[arg(long)]
    y_label: Option<String>,
    /// Draw only LO ≤ x ≤ HI.
    #[arg(long, num_args = 2, value_names = ["LO", "HI"], allow_negative_numbers = true)]
    x_range: Option<Vec<f64>>,
    /// Fix the y axis to LO..HI (default: fit the data).
    #[arg(long, num_args = 2, value_names = ["LO", "HI"], allow_negative_numbers = true)]
    y_range: Option<Vec<f64>>,
    /// Image size in pixels.
    #[arg(long, num_args = 2, value_names = ["WIDTH", "HEIGHT"], default_values_t = [1000, 700])]
    size: Vec<u32>,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

fn pair<T: Copy>(v: &Option<Vec<T>>) -> Option<[T; 2]> {
    v.as_ref().map(|v| [v[0], v[1]])
}

fn main() -> ExitCode {
    let args = Args::parse();
    if args.labels.len() > args.series.len() {
        eprintln!("sc-plot: error: {} --label for {} --series (give at most one label per series, in order)", args.labels.len(), args.series.len());
        return ExitCode::from(exit_code::BAD_INPUT);
    }
    let mut series = args.series;
    for (s, l) in series.iter_mut().zip(args.labels) {
        s.label = Some(l);
    }
    for s in &mut series {
        s.divide_by.clone_from(&args.divide_by);
    }
    let spec = PlotSpec {
        output: args.output.clone(),
        title: args.title,
        x: args.x,
        x_label: args.x_label,
        size: Some([args.size[0], args.size[1]]),
        x_range: pair(&args.x_range),
        panels: vec![PanelSpec { y_label: args.y_label, y_range: pair(&args.y_range), series }],
    };
    match plot::plot(&spec, Path::new("")) {
        Ok(msg) => {
            if !args.quiet && args.output.as_os_str() != "-" {
                eprintln!("{msg}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sc-plot: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
