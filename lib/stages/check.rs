//! `sc-check`: a model (`.sccontact` or `.scmesh`) and the solve setup `sc-solve`
//! would read → the pre-solve check (`crate::check`): a summary, a CSV per slave
//! node and a `.vtu` of the slave nodes. Changes nothing.

use std::path::Path;

use super::solve::read_model;
use super::StageRunError;
use crate::check::{self, report, CheckReport};
use crate::format::setup::SolveSetup;
use crate::solver::problem::Problem;

/// Where the check writes (each optional; the summary is also returned).
#[derive(Debug, Clone, Copy, Default)]
pub struct CheckOutputs<'a> {
    pub csv: Option<&'a Path>,
    pub vtu: Option<&'a Path>,
    pub summary: Option<&'a Path>,
}

/// Check the model in `input` with `setup` (named `setup_name` in messages) and
/// write the outputs asked for. A model the setup does not fit (an unknown set, a
/// missing material, …) fails as `sc-solve` would; a flipped master does not (it is
/// in the report: [`CheckReport::errors`]).
pub fn check(input: &Path, setup: &SolveSetup, setup_name: &str, outputs: CheckOutputs) -> Result<CheckReport, StageRunError> {
    let (mesh, pairs) = read_model(input)?;
    let problem = Problem::with_contact(&mesh, &pairs, setup, setup_name)?;
    let r = check::run(&mesh, &problem, &input.display().to_string(), setup_name)?;
    if let Some(p) = outputs.csv {
        report::write_csv(&r, p)?;
    }
    if let Some(p) = outputs.vtu {
        report::write_vtu(&r, p)?;
    }
    if let Some(p) = outputs.summary {
        report::write_summary(&r, p)?;
    }
    Ok(r)
}
