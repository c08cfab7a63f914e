//! sc-solve: finite-strain static solve of a hex8 mesh, with frictional contact.
// large blocks on huge pages (lib/os/large_pages.rs; SC_HUGE_PAGES=0 turns it off)
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: splinecontact::os::large_pages::LargePages = splinecontact::os::large_pages::LargePages;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::format::setup::SolveSetup;
use splinecontact::solver::log::Verbosity;
use splinecontact::solver::ranks::{self, Participation};
use splinecontact::os::timeline;
use splinecontact::stages::solve;

/// Solve a finite-strain static problem on a .scmesh, or a contact problem on the
/// .sccontact written by sc-tag: neo-Hookean (Ciarlet–Simo or deviatoric/volumetric)
/// or linear elastic bodies of 8-node hexahedra, node-to-surface contact, with
/// Coulomb friction or without, against a B-spline or facet master (penalty or
/// augmented Lagrangian), load
/// increments with Newton–Raphson, cut back when an increment fails.
///
/// The setup YAML gives a material per body, constraints and loads on the mesh's
/// named sets, the contact settings per pair, the increments and the Newton
/// tolerances (every key: docs/pipelines.md):
///
///   materials:   [{body: block, model: neo_hookean, E: 1.0e4, nu: 0.3}]
///   constraints: [{set: base, fix: [x, y, z]}, {set: top, displacement: {z: -1.0}}]
///   loads:       [{set: tip, force: [0, 0, -10]}, {face_set: top, pressure: 2.0}]
///   contact:     [{pair: contact, eps_n: 1.0e5, enforcement: augmented_lagrangian,
///                  penetration_tolerance: 1.0e-4, max_augmentations: 20}]
///   increments:  {count: 10, max_cutbacks: 5}
///   newton:      {max_iterations: 25, residual_tolerance: 1.0e-8, energy_tolerance: 1.0e-12}
///   linear_solver: auto   # Cholesky (nested dissection), kept while GMRES
///                         # solves the next tangents with it; with friction GMRES
///                         # preconditioned by the symmetric part (LU fallback);
///                         # in a --features petsc build, from 300k dofs or
///                         # under mpirun: PETSc CG/GMRES + algebraic multigrid
///
/// Under mpirun (a build with --features petsc) the ranks share the linear solve:
///   mpirun -np 2 sc-solve beams.sccontact --setup solve.yaml -o beams.scres
/// Rank 0 writes the results and the log; a build without PETSc says that it runs
/// serially, on rank 0.
///
/// eps_n is a pressure per unit penetration (times each slave node's tributary area).
/// A body held only by contact must start touching its master or be supported, and
/// its rigid in-plane modes need supports (frictionless contact carries no shear).
///
/// Before the first increment sc-solve checks the model as sc-check does: a master
/// whose normal points away from its slave body is refused (exit code 2; the
/// message says how to fix it, `allow_flipped_master: true` in the pair's contact
/// entry overrides), every body's rigid-body modes that no constraint holds are a
/// warning line ("body 'upper': no constraint holds translation x, …"), and
/// `adjust: <distance>` in a contact entry moves slave nodes within that distance of
/// the master onto it, stress-free (the log lists them). Run sc-check first for the
/// whole picture (gaps and penetrations node by node, a .vtu for ParaView).
///
/// Every converged increment is appended to the results file (.scres) at once, so a run
/// that stops keeps everything it converged, with the contact state (gap, pressure,
/// multiplier, active flag per slave node; force and augmentations per pair). The
/// convergence history goes to a CSV (default: beside the results,
/// <name>.convergence.csv): residual, energy, active contact nodes and the time of
/// contact search, assembly, factorization and solve per Newton iteration. Exit codes: 0 done, 2 bad
/// input, 3 stopped without convergence (converged increments kept), 1 I/O.
///
/// Environment: SC_TIMELINE=1 prints the run's phases at the end (start, end and
/// length in ms, the thread), to see where a run's time goes; SC_REPRODUCIBLE=1
/// records the times as 0 (byte-identical results); SC_HUGE_PAGES=0 keeps large
/// blocks off huge pages; SC_MEMORY_LIMIT=8G sets the memory a factor may take.
///
/// Example:
///   sc-solve block.scmesh --setup solve.yaml -o block.scres
///   sc-export block.scres -o block.pvd          # then: paraview block.pvd
///   sc-tag two.scmesh --pair contact:top_slave:bottom_master:bspline:3:3 -o two.sccontact
///   sc-solve two.sccontact --setup contact.yaml -o two.scres
///   sc-solve two.sccontact --setup longer.yaml -o two.scres --restart two.scres
///                                              # continue a stopped or finished run
///   sc-solve two.sccontact --setup finer.yaml -o redo.scres --restart two.scres --restart-increment 12
///                                              # redo the path from increment 12
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// Input mesh (.scmesh) or contact model (.sccontact), or - for standard input.
    input: PathBuf,
    /// Solve setup (YAML).
    #[arg(short, long)]
    setup: PathBuf,
    /// Output results file (.scres).
    #[arg(short, long)]
    output: PathBuf,
    /// Convergence history CSV (default: <output>.convergence.csv).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Continue the run in this results file (.scres, of the same model) from its
    /// last converged increment: displacements, contact multipliers and friction
    /// history are taken from it, the increments it reached are skipped, and the
    /// output starts with its increments. It may be the output file itself.
    #[arg(long, value_name = "SCRES")]
    restart: Option<PathBuf>,
    /// With --restart: continue from this converged increment of the file instead
    /// of its last (1-based, as the `increment` column of its forces CSV); the
    /// increments after it are not carried over.
    #[arg(long, value_name = "K", requires = "restart")]
    restart_increment: Option<usize>,
    /// PETSc options for `linear_solver: petsc`, after the setup's `petsc.options`
    /// (so they win), e.g. "-ksp_monitor -pc_gamg_threshold 0.02". Needs a build with
    /// the PETSc backend (--features petsc).
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    petsc_options: Option<String>,
    /// Print nothing but warnings and errors.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    // the origin of SC_TIMELINE=1's timeline (lib/os/timeline.rs)
    timeline::epoch();
    let args = Args::parse();
    let rank = match ranks::participate("sc-solve", true) {
        Ok(Participation::Idle) => return ExitCode::SUCCESS,
        Ok(Participation::Serial(why)) => {
            eprintln!("sc-solve: warning: {why}");
            0
        }
        Ok(Participation::Rank { rank, .. }) => rank,
        Ok(Participation::Alone) => 0,
        Err(e) => {
            eprintln!("sc-solve: error: {e}");
            return ExitCode::from(1);
        }
    };
    // this thread works in rayon's parallel phases itself (lib/os/worker_pool.rs)
    splinecontact::os::worker_pool::join_as_worker();
    let code = run(args, rank);
    ranks::finish();
    if rank == 0 {
        timeline::report();
    }
    code
}

fn run(args: Args, rank: usize) -> ExitCode {
    let setup_span = timeline::span("read the setup");
    let mut setup = match SolveSetup::read(&args.setup) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("sc-solve: error: {e}");
            return ExitCode::from(splinecontact::stages::exit_code::BAD_INPUT);
        }
    };
    if let Some(extra) = &args.petsc_options {
        let p = &mut setup.linear_solver.petsc.options;
        *p = format!("{p} {extra}").trim().to_owned();
    }
    drop(setup_span);
    let csv = args.csv.clone().or_else(|| solve::default_csv_path(&args.output));
    let verbosity = if args.quiet { Verbosity::Quiet } else { Verbosity::Normal };
    match solve::solve(&args.input, &setup, &args.setup.display().to_string(), &args.output, csv.as_deref(), args.restart.as_deref().map(|file| solve::Restart { file, increment: args.restart_increment }), verbosity) {
        Ok(r) => {
            if !args.quiet && rank == 0 {
                eprintln!(
                    "solved: {} increments, {} Newton iterations, {} cutbacks, {:.2} s ({:.2} s writing results); wrote {}",
                    r.increments,
                    r.iterations,
                    r.cutbacks,
                    r.seconds,
                    r.write_seconds,
                    args.output.display()
                );
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            if rank == 0 {
                eprintln!("sc-solve: error: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}
