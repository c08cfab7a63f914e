//! The pipeline stages as library calls. Each binary (`sc-import`, `sc-export`, …)
//! and the pipeline runner call these same functions, so a stage behaves the same
//! from the shell and from a pipeline YAML. Every stage fails with a
//! [`StageRunError`], which names the process's [`exit_code`].

pub mod check;
pub mod exit_code;
pub mod export;
pub mod gmsh;
pub mod import;
pub mod plot;
pub mod solve;
pub mod tag;
pub mod tag_error;

use crate::check::CheckError;
use crate::format::msh::MshError;
use crate::format::setup::SetupError;
use crate::solver::increments::SolveError;
use crate::solver::newton::SetupFailure;
use crate::solver::problem::ProblemError;
use crate::solver::restart::RestartError;
use crate::format::stage::StageError;
use crate::format::vtk::VtkError;
use plot::PlotError;
use tag_error::TagError;


/// Why a stage failed. Every variant carries the file (and line, element or set)
/// at fault in its message.
#[derive(Debug, thiserror::Error)]
pub enum StageRunError {
    #[error(transparent)]
    Msh(#[from] MshError),
    #[error(transparent)]
    Stage(#[from] StageError),
    #[error(transparent)]
    Vtk(#[from] VtkError),
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error(transparent)]
    Problem(#[from] ProblemError),
    #[error(transparent)]
    SolverSetup(#[from] SetupFailure),
    #[error(transparent)]
    Solve(#[from] SolveError),
    #[error(transparent)]
    Restart(#[from] RestartError),
    #[error(transparent)]
    Tag(#[from] TagError),
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error(transparent)]
    Check(#[from] CheckError),
    #[error("{0}")]
    Usage(String),
    #[error("{0}")]
    Tool(String),
}

impl StageRunError {
    /// The process exit code this error maps to.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Stage(StageError::Io { .. })
            | Self::Msh(MshError::Io { .. })
            | Self::Vtk(VtkError::Stage(StageError::Io { .. }))
            | Self::Solve(SolveError::Write(StageError::Io { .. }))
            | Self::Restart(RestartError::Read(StageError::Io { .. }))
            | Self::Tool(_) => exit_code::IO,
            Self::Solve(SolveError::Diverged { .. }) => exit_code::DIVERGED,
            Self::Plot(e) => e.exit_code(),
            _ => exit_code::BAD_INPUT,
        }
    }
}
