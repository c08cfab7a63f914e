//! `sc-solve`: a mesh (`.scmesh`) and a solve setup → results (`.scres`) and a
//! convergence-history CSV.

use crate::os::timeline;
use std::path::Path;
use std::time::Instant;

use super::StageRunError;
use crate::format::sccontact::{self, ContactModel};
use crate::format::scmesh;
use crate::format::stage::StageFile;
use crate::format::scres::{RestartOrigin, Results, RunStatus};
use crate::format::setup::SolveSetup;
use crate::solver::free_bodies::FreeBody;
use crate::solver::increments::{self, Outputs};
use crate::solver::log::{SolveLog, Verbosity};
use crate::solver::newton::Newton;
use crate::solver::problem::Problem;
use crate::solver::restart::{increment_number, RestartPoint};

/// Where a solve restarts: a results file and, optionally, which of its converged
/// increments (1-based; default its last).
#[derive(Debug, Clone, Copy)]
pub struct Restart<'a> {
    pub file: &'a Path,
    pub increment: Option<usize>,
}

/// What a finished solve reports.
pub struct SolveReport {
    pub increments: usize,
    pub iterations: usize,
    pub cutbacks: u32,
    pub seconds: f64,
    /// Of which writing the results file (encode, write, sync).
    pub write_seconds: f64,
}

/// The CSV beside a results file: `results.scres` → `results.convergence.csv`. (The
/// force history goes to `results.forces.csv`, always beside the results.)
pub fn default_csv_path(output: &Path) -> Option<std::path::PathBuf> {
    (output.as_os_str() != "-").then(|| output.with_extension("convergence.csv"))
}

/// The mesh and contact pairs of a `.scmesh` (no pairs) or `.sccontact` file, as
/// `sc-solve` and `sc-check` read them.
pub fn read_model(input: &Path) -> Result<(crate::mesh::Mesh, Vec<crate::format::sccontact::ContactPair>), StageRunError> {
    let file = StageFile::read_known(input, &[(scmesh::FORMAT, scmesh::MAJOR), (sccontact::FORMAT, sccontact::MAJOR)])?;
    match file.format.as_str() {
        scmesh::FORMAT => Ok((scmesh::from_stage(&file)?, Vec::new())),
        sccontact::FORMAT => {
            let model = ContactModel::from_stage(&file)?;
            Ok((model.mesh, model.pairs))
        }
        other => Err(StageRunError::Usage(format!("{}: a {other} file; a mesh (.scmesh) or a contact model (.sccontact) is read", input.display()))),
    }
}

/// Solve `setup` on the mesh in `input`, writing `output` after every converged
/// increment and the convergence history to `csv`; with `restart`, continue from an
/// increment of that results file (of the same model; by default its last), whose
/// increments up to it then open `output` (which may be the same file: it is read
/// before anything is written).
pub fn solve(input: &Path, setup: &SolveSetup, setup_name: &str, output: &Path, csv: Option<&Path>, restart: Option<Restart>, verbosity: Verbosity) -> Result<SolveReport, StageRunError> {
    if output.as_os_str() == "-" {
        return Err(StageRunError::Usage("sc-solve writes its results after every increment: give a file with -o, not -".into()));
    }
    let start = Instant::now();
    crate::solver::linear::dense_kernels::warm_in_background();
    let read_span = timeline::span("read the model");
    let (mut mesh, pairs) = read_model(input)?;
    drop(read_span);
    // A restart file of another model is named before the setup is checked against
    // this one; with `adjust` the file holds the adjusted coordinates, so it is
    // compared with them, once the problem has moved the nodes.
    let adjusts = setup.contact.iter().any(|c| c.adjust.is_some_and(|d| d != 0.0));
    let mut point = if adjusts { None } else { restart.map(|r| RestartPoint::read(r.file, r.increment, &mesh, &pairs)).transpose()? };
    let problem_span = timeline::span("problem: materials, constraints, contact pairs");
    let problem = Problem::with_contact(&mesh, &pairs, setup, setup_name)?;
    drop(problem_span);
    // the pre-solve check: a flipped master stops here; free rigid modes are warned about
    // the check and the solver's set-up (the sparsity pattern, the analysis started)
    // side by side: they read the same problem and neither needs the other; a
    // refused model drops the set-up unused. The check runs on a thread of its own
    // and the set-up on this one (under rayon::join, the worker waiting for the
    // other half stole the background analysis' tasks and returned 1-4 ms late)
    let (check, newton) = std::thread::scope(|scope| {
        let check = scope.spawn(|| {
            let _span = timeline::span("pre-solve check");
            crate::check::run(&mesh, &problem, &input.display().to_string(), setup_name)
        });
        let newton = {
            let _span = timeline::span("solver set-up");
            Newton::new(&problem, setup.newton.clone(), setup.linear_solver.clone())
        };
        (check.join(), newton)
    });
    // a panic of the check is the process's, as it would be on this thread
    let check = check.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    let check = check?;
    if let Some(e) = check.errors().into_iter().next() {
        return Err(e.into());
    }
    if !problem.adjustments.is_empty() {
        // the adjusted reference coordinates are the model's from here on (results, restart)
        mesh.nodes = problem.X.iter().map(|x| [x[0], x[1], x[2]]).collect();
    }
    if adjusts {
        point = restart.map(|r| RestartPoint::read(r.file, r.increment, &mesh, &pairs)).transpose()?;
    }
    let factors = setup.load_factors(setup_name)?;
    if let Some(point) = &point {
        // a run killed after its last increment converged but before it marked
        // itself completed is finished here (nothing to solve, the status to write);
        // a completed one asks for a longer load path
        if point.remaining(&factors) == 0 && !point.interrupted {
            return Err(StageRunError::Usage(format!(
                "{}: the run already reached load factor {:.6}, and the setup {setup_name} ends at {:.6}: nothing left to solve (extend the load path to continue)",
                point.file.display(),
                point.load_factor(),
                factors.last().copied().unwrap_or(0.0)
            )));
        }
    }
    let mut newton = newton?;
    let (rank, ranks) = crate::solver::ranks::rank_and_size();
    let mut log = SolveLog::new(if rank > 0 { Verbosity::Silent } else { verbosity }, factors.len());
    if ranks > 1 {
        log.line(&format!("MPI: {ranks} ranks; each owns a contiguous range of nodes, projects the slave nodes among them onto the master (the results are exchanged), assembles the elements and contact elements that touch them and inserts their rows; rank 0 writes the results and this log"));
    }
    for (c, def) in newton.contact.iter().zip(&problem.contact) {
        let s = &c.settings;
        log.line(&format!(
            "contact pair '{}': {} slave nodes, {} master, ε_N = {:e}{}, {}{}{}{}",
            c.name,
            c.slaves.len(),
            c.master_kind.name(),
            s.eps_n,
            if def.eps_n_default { format!(" (default 25 G/h, h = {:.4e})", def.h_master) } else { String::new() },
            match s.enforcement {
                crate::contact::settings::Enforcement::Penalty => "penalty",
                crate::contact::settings::Enforcement::AugmentedLagrangian => "augmented Lagrangian",
            },
            match s.enforcement {
                crate::contact::settings::Enforcement::Penalty => String::new(),
                _ => format!(" (penetration tolerance {:e}, at most {} augmentations)", s.penetration_tolerance, s.max_augmentations),
            },
            if s.frictional() { format!(", Coulomb friction μ = {}, ε_T = {:e}", s.mu, s.eps_t) } else { ", frictionless".into() },
            if s.stabilization > 0.0 {
                format!(", master-surface stabilisation η = {} (c = η ε_N Ā_s = {:.4e} on {} master nodes)", s.stabilization, c.stabilization_stiffness(), c.net_nodes().len())
            } else {
                String::new()
            }
        ));
    }
    for line in crate::check::report::solve_start_lines(&check) {
        log.line(&line);
    }
    for w in crate::check::report::solve_start_warnings(&check) {
        log.warning(&w);
    }
    let free: Vec<_> = check.bodies.iter().filter(|b| !b.free.is_empty()).collect();
    if !free.is_empty() {
        let beta = setup.newton.free_body_damping;
        if beta > 0.0 {
            let bodies = free
                .iter()
                .map(|b| FreeBody { name: b.name.clone(), nodes: b.nodes.clone(), free: b.free.iter().map(|m| m.0).collect(), centroid: b.centroid.into(), length: b.length })
                .collect();
            newton.damp_free_bodies(bodies, beta);
            if let Some(f) = &newton.free_bodies {
                for (body, c, _) in f.bodies() {
                    log.line(&format!("free-body damping of body '{}': c = β G h̄ = {c:.4e} on its {} nodes, until contact holds it (newton.free_body_damping β = {beta})", body.name, body.nodes.len()));
                }
            }
        } else {
            log.line("newton.free_body_damping (e.g. 1.0e-3) damps such a body until contact holds it, if the solve does not start (docs/diagnosing.md)");
        }
    }
    if !setup.linear_solver.petsc.options.trim().is_empty() && !newton.linear_solver_name().starts_with("petsc") {
        log.warning(&format!(
            "PETSc options are given (petsc.options or --petsc-options) but the linear solver is {}: they are ignored{}",
            newton.linear_solver_name(),
            if cfg!(feature = "petsc") { " (linear_solver: petsc uses them)" } else { " (this build has no PETSc backend: --features petsc)" }
        ));
    }
    log.line(&format!(
        "{}: {} nodes, {} hexahedra, {} free dofs, {} nonzeros{}, {} increments, linear solver {}",
        input.display(),
        mesh.nodes.len(),
        mesh.hexes.len(),
        newton.n_free(),
        newton.nnz(),
        if ranks > 1 { " on rank 0 (its share of the assembly)" } else { "" },
        factors.len(),
        newton.linear_solver_name()
    ));
    let mut results = Results {
        source: input.display().to_string(),
        setup: serde_yaml::to_string(setup).unwrap_or_default(),
        status: RunStatus::Running,
        increments: Vec::new(),
        mesh,
        pairs,
        restart: None,
        tail: None,
    };
    if let Some(point) = point {
        // the restart file's increments open the history, and its iterations the CSV
        for inc in &point.increments {
            log.restored(increment_number(&factors, inc.info.load_factor), factors.len(), &inc.info);
        }
        results.restart = Some(RestartOrigin { file: point.file.display().to_string(), increments: point.increments.len() as u32, load_factor: point.load_factor() });
        log.line(&format!(
            "restart from {}: {} converged increments, continuing from load factor {:.6} ({} of the setup's {} increments left)",
            point.file.display(),
            point.increments.len(),
            point.load_factor(),
            point.remaining(&factors),
            factors.len(),
        ));
        if let Some(t) = &point.tail {
            log.warning(&format!("{}: {t}", point.file.display()));
        }
        if point.remaining(&factors) == 0 {
            log.line(&format!("{}: its run reached the end of the load path but was interrupted before it marked itself completed; this run marks it completed", point.file.display()));
        }
        results.increments = point.increments;
    }
    let forces = output.with_extension("forces.csv");
    // under mpirun every rank computes the same increments; the first writes them
    let writer = rank == 0;
    let outputs = Outputs { results: output, csv, forces_csv: Some(&forces), writer };
    let summary = increments::solve(&mut newton, &factors, setup.increments.max_cutbacks, &mut results, &outputs, &mut log);
    if !newton.contact.is_empty() {
        log.line(&format!("contact: the sparsity pattern was rebuilt {} times as contact elements changed", newton.pattern_rebuilds));
    }
    let (checks, misses) = newton.residual_first;
    if checks > 0 {
        log.line(&format!(
            "assembly: {checks} iterates assembled residual first, where Newton's rate predicted convergence; {misses} of them took the tangent after (newton.residual_first)"
        ));
    }
    let t = newton.linear_timings();
    log.line(&format!(
        "linear solver {}: {} analyses {:.2} s, {} factorizations {:.2} s{}, {} solves {:.2} s{}",
        newton.linear_solver_name(),
        t.n_symbolic,
        t.symbolic.as_secs_f64(),
        t.n_numeric,
        t.numeric.as_secs_f64(),
        if t.largest_factor > 0 { format!(" (the largest factor {:.3} M entries)", t.largest_factor as f64 / 1e6) } else { String::new() },
        t.n_solve,
        t.solve.as_secs_f64(),
        if t.n_krylov > 0 || t.n_fallback > 0 {
            format!(
                ", {} Krylov iterations ({:.1} per solve), {} factorizations kept from the iteration before{}",
                t.n_krylov,
                t.n_krylov as f64 / t.n_solve.max(1) as f64,
                t.n_reused,
                if t.n_fallback > 0 { format!(", {} solved by the direct fallback", t.n_fallback) } else { String::new() }
            )
        } else {
            String::new()
        }
    ));
    log.finish();
    let summary = summary?;
    Ok(SolveReport { increments: summary.increments, iterations: summary.iterations, cutbacks: summary.cutbacks, seconds: start.elapsed().as_secs_f64(), write_seconds: summary.write_seconds })
}
