//! The pipeline runner: the stages of a YAML pipeline, in order, through the real
//! files between them; it stops at the first failing stage with that stage's error.

use std::path::{Path, PathBuf};

use crate::folder_lock::FolderLock;
use crate::format::pipeline::{Pipeline, PipelineError, Stage};
use crate::format::stage::files::resolve;
use crate::format::setup::SolveSetup;
use crate::solver::log::Verbosity;
use crate::stages::{self, StageRunError};

/// A failed pipeline: which stage, and why.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    #[error("stage {index} ({name}) failed: {source}")]
    Stage { index: usize, name: &'static str, source: StageRunError },
}

impl RunError {
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Pipeline(PipelineError::Io { .. }) => stages::exit_code::IO,
            Self::Pipeline(_) => stages::exit_code::BAD_INPUT,
            Self::Stage { source, .. } => source.exit_code(),
        }
    }
}

/// The setup of a solve or check stage: inline (`setup:`) or from `setup_file:`,
/// with the name it goes by in messages.
fn stage_setup(path: &Path, base: &Path, kind: &str, index: usize, inline: &Option<SolveSetup>, file: &Option<PathBuf>) -> Result<(SolveSetup, String), StageRunError> {
    match (inline, file) {
        (Some(setup), None) => Ok((setup.clone(), format!("{} ({kind} stage {index})", path.display()))),
        (None, Some(f)) => {
            let f = resolve(base, f);
            Ok((SolveSetup::read(&f)?, f.display().to_string()))
        }
        _ => Err(StageRunError::Usage(format!("{}: {kind} stage {index}: give exactly one of `setup` (inline) or `setup_file`", path.display()))),
    }
}

/// The output folders a run holds ([`FolderLock`]), taken at the first write into each.
struct Outputs {
    pipeline: String,
    held: Vec<FolderLock>,
}

impl Outputs {
    /// Create `p`'s folder if needed and take it for this pipeline.
    fn ensure_parent(&mut self, p: &Path) -> Result<(), StageRunError> {
        let d = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !d.exists() {
            std::fs::create_dir_all(d).map_err(|e| StageRunError::Tool(format!("{}: cannot create folder: {e}", d.display())))?;
        }
        let canonical = std::fs::canonicalize(d).map_err(|e| StageRunError::Tool(format!("{}: {e}", d.display())))?;
        if !self.held.iter().any(|l| l.folder == canonical) {
            self.held.push(FolderLock::acquire(d, &self.pipeline).map_err(|e| StageRunError::Tool(e.to_string()))?);
        }
        Ok(())
    }
}

/// Run every stage of the pipeline at `path`; `log` receives one line per event, and
/// `warn` each warning of the import and export stages (a warning names its file; the
/// solve stage prints its own through its log at `verbosity`).
pub fn run(path: &Path, verbosity: Verbosity, log: &mut dyn FnMut(&str), warn: &mut dyn FnMut(&str)) -> Result<(), RunError> {
    let pipeline = Pipeline::read(path)?;
    let base: PathBuf = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut outputs = Outputs { pipeline: path.display().to_string(), held: Vec::new() };
    let n = pipeline.stages.len();
    if let Some(name) = &pipeline.name {
        log(&format!("pipeline {name}: {n} stages"));
    }
    for (i, stage) in pipeline.stages.iter().enumerate() {
        let index = i + 1;
        let fail = |source| RunError::Stage { index, name: stage.name(), source };
        match stage {
            Stage::Gmsh(s) => {
                let (geo, out) = (resolve(&base, &s.geo), resolve(&base, &s.output));
                log(&format!("[{index}/{n}] gmsh {} -> {}", geo.display(), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                stages::gmsh::run_gmsh(&geo, &out, s.format, s.binary).map_err(fail)?;
            }
            Stage::Import(s) => {
                let (input, out) = (resolve(&base, &s.input), resolve(&base, &s.output));
                log(&format!("[{index}/{n}] import {} -> {}", input.display(), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                let (mesh, report) = stages::import::import(&input, &out).map_err(fail)?;
                for line in stages::import::summary(&input, &mesh, &report) {
                    log(&format!("      {line}"));
                }
                for w in &report.warnings {
                    warn(w);
                }
            }
            Stage::Tag(s) => {
                let (input, out) = (resolve(&base, &s.input), resolve(&base, &s.output));
                log(&format!("[{index}/{n}] tag {} -> {}", input.display(), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                for line in stages::tag::tag(&input, &out, &s.pairs).map_err(fail)? {
                    log(&format!("      {line}"));
                }
            }
            Stage::Check(s) => {
                let input = resolve(&base, &s.input);
                let (setup, setup_name) = stage_setup(path, &base, "check", index, &s.setup, &s.setup_file).map_err(fail)?;
                let with_ext = |ext: &str| s.output.as_ref().map(|o| {
                    let mut p = resolve(&base, o).into_os_string();
                    p.push(".");
                    p.push(ext);
                    PathBuf::from(p)
                });
                let pick = |explicit: &Option<PathBuf>, ext: &str| explicit.as_ref().map(|p| resolve(&base, p)).or_else(|| with_ext(ext));
                let (csv, vtu, summary) = (pick(&s.csv, "csv"), pick(&s.vtu, "vtu"), pick(&s.summary, "txt"));
                let written: Vec<String> = [&csv, &vtu, &summary].into_iter().flatten().map(|p| p.display().to_string()).collect();
                log(&format!("[{index}/{n}] check {}{}", input.display(), if written.is_empty() { String::new() } else { format!(" -> {}", written.join(", ")) }));
                for p in [&csv, &vtu, &summary].into_iter().flatten() {
                    outputs.ensure_parent(p).map_err(fail)?;
                }
                let outputs = stages::check::CheckOutputs { csv: csv.as_deref(), vtu: vtu.as_deref(), summary: summary.as_deref() };
                let r = stages::check::check(&input, &setup, &setup_name, outputs).map_err(fail)?;
                let lines = crate::check::report::summary(&r);
                for line in lines.iter().filter(|l| !l.starts_with("warning: ") && !l.starts_with("error: ")) {
                    log(&format!("      {line}"));
                }
                for w in r.warnings() {
                    warn(&w);
                }
                let errors = r.errors();
                if let Some(e) = errors.into_iter().next() {
                    if s.strict {
                        return Err(fail(e.into()));
                    }
                    warn(&format!("{e} (the solve will refuse it)"));
                }
            }
            Stage::Solve(s) => {
                let (input, out) = (resolve(&base, &s.input), resolve(&base, &s.output));
                log(&format!("[{index}/{n}] solve {} -> {}", input.display(), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                let restart_file = s.restart.as_ref().map(|r| resolve(&base, r));
                if s.restart_increment.is_some() && restart_file.is_none() {
                    return Err(fail(StageRunError::Usage(format!("{}: solve stage {index}: `restart_increment` needs `restart` (the results file to continue)", path.display()))));
                }
                let (setup, setup_name) = stage_setup(path, &base, "solve", index, &s.setup, &s.setup_file).map_err(fail)?;
                let csv = s.csv.as_ref().map(|c| resolve(&base, c)).or_else(|| stages::solve::default_csv_path(&out));
                let restart = restart_file.as_deref().map(|file| stages::solve::Restart { file, increment: s.restart_increment });
                let r = stages::solve::solve(&input, &setup, &setup_name, &out, csv.as_deref(), restart, verbosity).map_err(fail)?;
                log(&format!("      {} increments, {} Newton iterations, {} cutbacks, {:.2} s ({:.2} s writing results)", r.increments, r.iterations, r.cutbacks, r.seconds, r.write_seconds));
            }
            Stage::Export(s) => {
                let (input, out) = (resolve(&base, &s.input), resolve(&base, &s.output));
                log(&format!("[{index}/{n}] export {} -> {}", input.display(), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                let exported = stages::export::export(&input, &out, s.format).map_err(fail)?;
                log(&format!("      {}", exported.written));
                for w in &exported.warnings {
                    warn(w);
                }
            }
            Stage::Plot(s) => {
                let out = resolve(&base, &s.output);
                let inputs: std::collections::BTreeSet<String> =
                    s.panels.iter().flat_map(|p| p.series.iter().map(|q| resolve(&base, &q.input).display().to_string())).collect();
                let inputs: Vec<String> = inputs.into_iter().collect();
                log(&format!("[{index}/{n}] plot {} -> {}", inputs.join(", "), out.display()));
                outputs.ensure_parent(&out).map_err(fail)?;
                let msg = stages::plot::plot(s, &base).map_err(|e| fail(e.into()))?;
                log(&format!("      {msg}"));
            }
        }
    }
    log("pipeline finished");
    Ok(())
}
