//! The fuzz targets: one per reader, each with the seeds it starts from and what it
//! runs on an input — the whole read path a program takes, so that what a reader
//! accepts is also exercised by what follows it (the mesh built from an MSH file,
//! the pairs checked against the mesh, a restart checked against its results).

use std::path::{Path, PathBuf};

use splinecontact::format::csv::Table;
use splinecontact::format::msh::parse_msh;
use splinecontact::format::pipeline::Pipeline;
use splinecontact::format::sccontact::ContactModel;
use splinecontact::format::scmesh;
use splinecontact::format::scres::Results;
use splinecontact::format::setup::SolveSetup;
use splinecontact::format::stage::StageFile;
use splinecontact::solver::restart::RestartPoint;
use splinecontact::stages::plot::render::render_png;
use splinecontact::stages::plot::{fit_range, series_points, Figure, Panel, Series, SeriesSpec};

use crate::common::repo;

/// How the engine mutates a target's inputs.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Bytes, lines and tokens (MSH, YAML, CSV).
    Text,
    /// As text, and half the time structurally (stage files, resealed).
    Stage,
}

pub struct Target {
    pub name: &'static str,
    pub kind: Kind,
    pub seeds: fn() -> Vec<(String, Vec<u8>)>,
    /// Read the input; `Err` is a refusal (fine), a panic is a crash.
    pub run: fn(&[u8]) -> Result<(), String>,
}

pub const TARGETS: &[Target] = &[
    Target { name: "msh22_ascii", kind: Kind::Text, seeds: || msh_seeds("2.2", false), run: msh },
    Target { name: "msh22_binary", kind: Kind::Text, seeds: || msh_seeds("2.2", true), run: msh },
    Target { name: "msh41_ascii", kind: Kind::Text, seeds: || msh_seeds("4.1", false), run: msh },
    Target { name: "msh41_binary", kind: Kind::Text, seeds: || msh_seeds("4.1", true), run: msh },
    Target { name: "scmesh", kind: Kind::Stage, seeds: scmesh_seeds, run: scmesh_read },
    Target { name: "sccontact", kind: Kind::Stage, seeds: || files_ending(&[".sccontact"]), run: sccontact_read },
    Target { name: "scres", kind: Kind::Stage, seeds: || files_ending(&[".scres"]), run: scres_read },
    Target { name: "setup", kind: Kind::Text, seeds: setup_seeds, run: setup_read },
    Target { name: "pipeline", kind: Kind::Text, seeds: pipeline_seeds, run: pipeline_read },
    Target { name: "plot_csv", kind: Kind::Text, seeds: || files_ending(&[".csv"]), run: csv_read },
];

/// Every `.msh` the repository ships (meshes/, tests/data/msh/) and the committed
/// fuzz seeds.
fn all_msh() -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for dir in ["meshes", "tests/data/msh", "tests/data/fuzz/seeds"] {
        out.extend(read_dir_ending(&repo().join(dir), &[".msh"]));
    }
    out
}

/// The `.msh` seeds of one version and encoding (told by the `$MeshFormat` line).
fn msh_seeds(version: &str, binary: bool) -> Vec<(String, Vec<u8>)> {
    all_msh()
        .into_iter()
        .filter(|(_, b)| {
            let head = String::from_utf8_lossy(&b[..b.len().min(64)]).into_owned();
            let mut words = head.split_whitespace().skip_while(|w| *w != "$MeshFormat").skip(1);
            let (v, ft) = (words.next(), words.next());
            v.is_some_and(|v| v.starts_with(version)) && ft == Some(if binary { "1" } else { "0" })
        })
        .collect()
}

fn read_dir_ending(dir: &Path, ends: &[&str]) -> Vec<(String, Vec<u8>)> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| ends.iter().any(|e| p.to_string_lossy().ends_with(e))).collect())
        .unwrap_or_default();
    paths.sort();
    paths.into_iter().map(|p| (p.strip_prefix(repo()).unwrap_or(&p).display().to_string(), std::fs::read(&p).unwrap())).collect()
}

/// Committed seeds (`tests/data/fuzz/seeds/`, written by a shipped pipeline: see
/// docs/reliability.md) ending in one of `ends`.
fn files_ending(ends: &[&str]) -> Vec<(String, Vec<u8>)> {
    read_dir_ending(&repo().join("tests/data/fuzz/seeds"), ends)
}

/// `.scmesh` seeds: every shipped `.msh` imported now, and the committed ones.
fn scmesh_seeds() -> Vec<(String, Vec<u8>)> {
    let mut out = files_ending(&[".scmesh"]);
    for (name, b) in all_msh() {
        if let Ok((mesh, _)) = parse_msh(&name, &b) {
            out.push((format!("{name} (imported)"), scmesh::encode(&mesh, &name)));
        }
    }
    out
}

/// Every solve setup in the shipped pipelines (the `setup:` mappings, as YAML) and
/// the committed setup files.
fn setup_seeds() -> Vec<(String, Vec<u8>)> {
    let mut out = files_ending(&[".setup.yaml"]);
    for (name, b) in read_dir_ending(&repo().join("pipelines"), &[".yaml"]) {
        let Ok(v) = serde_yaml::from_slice::<serde_yaml::Value>(&b) else { continue };
        let stages = v.get("stages").and_then(|s| s.as_sequence()).cloned().unwrap_or_default();
        for (i, stage) in stages.iter().enumerate() {
            for kind in ["solve", "check"] {
                if let Some(setup) = stage.get(kind).and_then(|s| s.get("setup")) {
                    if let Ok(text) = serde_yaml::to_string(setup) {
                        out.push((format!("{name} stage {i}"), text.into_bytes()));
                    }
                }
            }
        }
    }
    out
}

fn pipeline_seeds() -> Vec<(String, Vec<u8>)> {
    read_dir_ending(&repo().join("pipelines"), &[".yaml"])
}

fn text(b: &[u8]) -> Result<&str, String> {
    std::str::from_utf8(b).map_err(|e| e.to_string())
}

fn msh(b: &[u8]) -> Result<(), String> {
    parse_msh("fuzz.msh", b).map(|_| ()).map_err(|e| e.to_string())
}

fn stage(b: &[u8], format: &str, major: u32) -> Result<StageFile, String> {
    let f = StageFile::parse("fuzz", b, Some((format, major))).map_err(|e| e.to_string())?;
    // sc-export --format yaml prints any stage file it can parse
    f.dump_yaml(&mut std::io::sink()).map_err(|e| e.to_string())?;
    Ok(f)
}

fn scmesh_read(b: &[u8]) -> Result<(), String> {
    scmesh::from_stage(&stage(b, "scmesh", 1)?).map(|_| ()).map_err(|e| e.to_string())
}

fn sccontact_read(b: &[u8]) -> Result<(), String> {
    ContactModel::from_stage(&stage(b, "sccontact", 1)?).map(|_| ()).map_err(|e| e.to_string())
}

/// A results file, then a restart from it against its own model: from its last
/// increment, and from each earlier one (what `sc-solve --restart` reads).
fn scres_read(b: &[u8]) -> Result<(), String> {
    let r = Results::from_stage(&stage(b, "scres", 2)?).map_err(|e| e.to_string())?;
    let file = Path::new("fuzz.scres");
    let _ = RestartPoint::from_results(file, r.clone(), None, &r.mesh, &r.pairs);
    for k in [0, 1, r.increments.len(), r.increments.len() + 1] {
        let _ = RestartPoint::from_results(file, r.clone(), Some(k), &r.mesh, &r.pairs);
    }
    Ok(())
}

/// A solve setup as `sc-solve --setup` reads it, and its load path.
fn setup_read(b: &[u8]) -> Result<(), String> {
    let s = SolveSetup::parse("fuzz.yaml", text(b)?).map_err(|e| e.to_string())?;
    s.load_factors("fuzz.yaml").map(|_| ()).map_err(|e| e.to_string())
}

/// A pipeline as `sc-pipeline` reads it before running its stages.
fn pipeline_read(b: &[u8]) -> Result<(), String> {
    Pipeline::parse("fuzz.yaml", text(b)?).map(|_| ()).map_err(|e| e.to_string())
}

/// A force or convergence table as `sc-plot` reads it: every column against the
/// first (each third one divided by the next), the axes fitted, the figure drawn.
fn csv_read(b: &[u8]) -> Result<(), String> {
    let t = Table::parse("fuzz.csv", text(b)?).map_err(|e| e.to_string())?;
    let x = t.columns[0].clone();
    let mut series = Vec::new();
    for (c, column) in t.columns.iter().enumerate().take(8) {
        let divide_by = (c % 3 == 2).then(|| t.columns[(c + 1) % t.columns.len()].clone());
        let spec = SeriesSpec { input: "fuzz.csv".into(), column: column.clone(), scale: 1.0, divide_by, label: None };
        let points = series_points(&t, &x, &spec, None).map_err(|e| e.to_string())?;
        series.push(Series { label: column.clone(), points });
    }
    let (Some(x_range), Some(y_range)) = (
        fit_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), 0.0),
        fit_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), 0.05),
    ) else {
        return Err("nothing to plot".into());
    };
    let fig = Figure { title: Some(x.clone()), x_label: x, size: (320, 240), x_range, panels: vec![Panel { y_label: None, y_range, series }] };
    render_png(&fig).map(|_| ())
}
