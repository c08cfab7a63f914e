//! The pipeline YAML schema (documented key by key in `docs/pipelines.md`).
//!
//! ```yaml
//! version: 1
//! name: parisch                  # optional, for messages
//! stages:
//!   - import: { input: ../meshes/parisch.msh, output: out/parisch.scmesh }
//!   - tag:
//!       input: out/parisch.scmesh
//!       output: out/parisch.sccontact
//!       pairs: [{name: contact, slave: upper_bottom, master: lower_top, master_kind: bspline, orders: [3, 3]}]
//!   - export: { input: out/parisch.scmesh, output: out/parisch.vtu }
//!   - plot:
//!       output: out/parisch_forces.png
//!       panels: [{series: [{input: out/parisch.forces.csv, column: "contact:contact:z"}]}]
//! ```
//! Every struct denies unknown keys, so a misspelt key is an error that names it
//! and its line (serde_yaml reports `at line L column C`).

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::stages::export::ExportFormat;
use crate::format::setup::SolveSetup;
// the pipeline's paths are resolved against its folder (defined with the other
// file-system helpers)
pub use crate::format::stage::files::resolve;
use crate::stages::gmsh::MshFlavour;
use crate::stages::plot::PlotSpec;
use crate::stages::tag::PairSpec;

/// The pipeline versions this build reads.
pub const VERSION: u32 = 1;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pipeline {
    /// Schema version; must be 1.
    pub version: u32,
    #[serde(default)]
    pub name: Option<String>,
    /// serde_yaml 0.9 reads enums only as `!tag`s; `singleton_map_recursive`
    /// restores the natural one-key-map form `- import: {...}`.
    #[serde(with = "serde_yaml::with::singleton_map_recursive")]
    pub stages: Vec<Stage>,
}

/// One stage: a map with a single key naming the stage.
// A pipeline holds a handful of stages, read once: the inline solve setup's size is no concern.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Stage {
    Gmsh(GmshStage),
    Import(ImportStage),
    Tag(TagStage),
    /// The pre-solve check of a model and its setup (`sc-check`).
    Check(CheckStage),
    Solve(SolveStage),
    Export(ExportStage),
    /// Force-history CSVs → a PNG line plot; the keys are [`PlotSpec`]'s.
    Plot(PlotSpec),
}

impl Stage {
    pub fn name(&self) -> &'static str {
        match self {
            Self::Gmsh(_) => "gmsh",
            Self::Import(_) => "import",
            Self::Tag(_) => "tag",
            Self::Check(_) => "check",
            Self::Solve(_) => "solve",
            Self::Export(_) => "export",
            Self::Plot(_) => "plot",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GmshStage {
    /// The `.geo` to mesh in 3D.
    pub geo: PathBuf,
    /// The `.msh` to write.
    pub output: PathBuf,
    #[serde(default)]
    pub format: MshFlavour,
    #[serde(default)]
    pub binary: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImportStage {
    pub input: PathBuf,
    pub output: PathBuf,
}

/// Tag: contact pairs on a mesh → contact model (`.sccontact`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TagStage {
    pub input: PathBuf,
    pub output: PathBuf,
    /// `[{name, slave, master, master_kind, orders}, …]`.
    pub pairs: Vec<PairSpec>,
}

/// Solve: the setup inline (`setup:`) or in a file (`setup_file:`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolveStage {
    pub input: PathBuf,
    pub output: PathBuf,
    #[serde(default)]
    pub setup: Option<SolveSetup>,
    #[serde(default)]
    pub setup_file: Option<PathBuf>,
    /// Convergence history CSV (default: beside the output).
    #[serde(default)]
    pub csv: Option<PathBuf>,
    /// Continue the run in this results file from its last converged increment
    /// (`sc-solve --restart`).
    #[serde(default)]
    pub restart: Option<PathBuf>,
    /// ... or from this one of its converged increments (1-based;
    /// `sc-solve --restart-increment`).
    #[serde(default)]
    pub restart_increment: Option<usize>,
}

/// Check: a model and a solve setup → the pre-solve check (`sc-check`); the setup
/// inline (`setup:`, e.g. a YAML alias of the solve stage's) or in a file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckStage {
    pub input: PathBuf,
    #[serde(default)]
    pub setup: Option<SolveSetup>,
    #[serde(default)]
    pub setup_file: Option<PathBuf>,
    /// Write `<output>.csv`, `<output>.vtu` and `<output>.txt`.
    #[serde(default)]
    pub output: Option<PathBuf>,
    /// Or each on its own (these win over `output`).
    #[serde(default)]
    pub csv: Option<PathBuf>,
    #[serde(default)]
    pub vtu: Option<PathBuf>,
    #[serde(default)]
    pub summary: Option<PathBuf>,
    /// Fail the stage (and the pipeline) on what the solve refuses (a flipped master).
    #[serde(default)]
    pub strict: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExportStage {
    pub input: PathBuf,
    pub output: PathBuf,
    #[serde(default)]
    pub format: Option<ExportFormat>,
}

/// A pipeline file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: {message}")]
    Yaml { path: String, message: String },
    #[error("{path}: pipeline version {found} is not read by this build (it reads version {VERSION})")]
    Version { path: String, found: u32 },
}

impl Pipeline {
    /// Parse a pipeline from YAML text (`path` is for messages).
    pub fn parse(path: &str, text: &str) -> Result<Self, PipelineError> {
        let p: Pipeline = serde_yaml::from_str(text).map_err(|e| PipelineError::Yaml { path: path.to_string(), message: e.to_string() })?;
        if p.version != VERSION {
            return Err(PipelineError::Version { path: path.to_string(), found: p.version });
        }
        Ok(p)
    }

    pub fn read(path: &Path) -> Result<Self, PipelineError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| PipelineError::Io { path: shown.clone(), source })?;
        Self::parse(&shown, &text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_key_names_key_and_line() {
        let y = "version: 1\nstages:\n  - import:\n      input: a.msh\n      outptu: b.scmesh\n";
        let e = Pipeline::parse("p.yaml", y).unwrap_err().to_string();
        assert!(e.contains("outptu") && e.contains("line 5"), "{e}");
    }

    #[test]
    fn unknown_stage_lists_the_known_ones() {
        let y = "version: 1\nstages:\n  - imprt: {input: a, output: b}\n";
        let e = Pipeline::parse("p.yaml", y).unwrap_err().to_string();
        assert!(e.contains("imprt") && e.contains("import") && e.contains("line 3"), "{e}");
    }

    #[test]
    fn wrong_type_names_line() {
        let y = "version: 1\nstages:\n  - gmsh: {geo: a.geo, output: b.msh, binary: maybe}\n";
        let e = Pipeline::parse("p.yaml", y).unwrap_err().to_string();
        assert!(e.contains("binary") || e.contains("boolean"), "{e}");
        assert!(e.contains("line 3"), "{e}");
    }

    #[test]
    fn tag_stage_parses() {
        let y = "version: 1\nstages:\n  - tag:\n      input: a.scmesh\n      output: a.sccontact\n      pairs:\n        - {name: c, slave: s, master: m, master_kind: facet}\n        - {name: d, slave: s, master: m, orders: [4, 2]}\n";
        let p = Pipeline::parse("p.yaml", y).unwrap();
        let Stage::Tag(t) = &p.stages[0] else { panic!("not a tag stage") };
        assert_eq!(t.pairs.len(), 2);
        assert_eq!(t.pairs[1].orders, Some([4, 2]));
        let bad = y.replace("master_kind: facet", "master_kind: nurbs");
        let e = Pipeline::parse("p.yaml", &bad).unwrap_err().to_string();
        assert!(e.contains("nurbs") && e.contains("line 7"), "{e}");
    }

    #[test]
    fn plot_stage_parses() {
        let y = r#"version: 1
stages:
  - plot:
      output: out/forces.png
      title: "Shallow ironing, mu = 0.3"
      x_label: "pseudo-time t"
      size: [1000, 700]
      x_range: [1.0, 2.0]
      panels:
        - y_label: "V [N/mm]"
          series:
            - {input: out/a.forces.csv, column: "reaction:indenter_top:y", scale: -1.0, label: "facet"}
        - y_label: "H/V"
          series:
            - {input: out/a.forces.csv, column: "reaction:indenter_top:x", divide_by: "reaction:indenter_top:y"}
"#;
        let p = Pipeline::parse("p.yaml", y).unwrap();
        let Stage::Plot(s) = &p.stages[0] else { panic!("not a plot stage") };
        assert_eq!((s.x.as_str(), s.size, s.x_range), ("load_factor", Some([1000, 700]), Some([1.0, 2.0])));
        assert_eq!(s.panels.len(), 2);
        assert_eq!(s.panels[0].series[0].scale, -1.0);
        let h = &s.panels[1].series[0];
        assert_eq!((h.scale, h.divide_by.as_deref(), h.label.as_deref()), (1.0, Some("reaction:indenter_top:y"), None));
        let bad = y.replace("divide_by:", "divde_by:");
        let e = Pipeline::parse("p.yaml", &bad).unwrap_err().to_string();
        assert!(e.contains("divde_by") && e.contains("line 15"), "{e}");
    }

    #[test]
    fn check_stage_shares_the_solve_setup_by_an_alias() {
        let y = "version: 1\nstages:\n  - check:\n      input: m.sccontact\n      output: out/m-check\n      strict: true\n      setup: &s\n        materials: [{body: b, model: linear_elastic, E: 1.0, nu: 0.3}]\n        contact: [{pair: c, adjust: 1.0e-3, allow_flipped_master: true}]\n  - solve: {input: m.sccontact, output: m.scres, setup: *s}\n";
        let p = Pipeline::parse("p.yaml", y).unwrap();
        let (Stage::Check(c), Stage::Solve(s)) = (&p.stages[0], &p.stages[1]) else { panic!("not check, solve") };
        assert!(c.strict && c.output.as_deref() == Some(Path::new("out/m-check")));
        let (a, b) = (c.setup.as_ref().unwrap(), s.setup.as_ref().unwrap());
        assert_eq!((a.contact[0].adjust, a.contact[0].allow_flipped_master), (Some(1e-3), true));
        assert_eq!(serde_yaml::to_string(a).unwrap(), serde_yaml::to_string(b).unwrap());
        let bad = y.replace("strict: true", "stict: true");
        let e = Pipeline::parse("p.yaml", &bad).unwrap_err().to_string();
        assert!(e.contains("stict") && e.contains("line 6"), "{e}");
    }

    #[test]
    fn newer_version_is_refused() {
        let e = Pipeline::parse("p.yaml", "version: 2\nstages: []\n").unwrap_err().to_string();
        assert!(e.contains("version 2"), "{e}");
    }
}
