//! sc-solve: finite-strain static solve of a hex8 mesh.
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::format::setup::SolveSetup;
use splinecontact::solver::log::Verbosity;
use splinecontact::stages::solve;

/// Solve a finite-strain static problem on a .scmesh: neo-Hookean (Ciarlet–Simo or
/// deviatoric/volumetric) or linear elastic bodies of 8-node hexahedra, load
/// increments with Newton–Raphson, cut back when an increment fails.
///
/// The setup YAML gives a material per body, constraints and loads on the mesh's
/// named sets, the increments and the Newton tolerances (every key: docs/pipelines.md):
///
///   materials:   [{body: block, model: neo_hookean, E: 1.0e4, nu: 0.3}]
///   constraints: [{set: base, fix: [x, y, z]}, {set: top, displacement: {z: -1.0}}]
///   loads:       [{set: tip, force: [0, 0, -10]}, {face_set: top, pressure: 2.0}]
///   increments:  {count: 10, max_cutbacks: 5}
///   newton:      {max_iterations: 25, residual_tolerance: 1.0e-8, energy_tolerance: 1.0e-12}
///
/// The results file (.scres) is rewritten after every converged increment, so a run
/// that stops keeps everything it converged. The convergence history goes to a CSV
/// (default: beside the results, <name>.convergence.csv). Exit codes: 0 done, 2 bad
/// input, 3 stopped without convergence (converged increments kept), 1 I/O.
///
/// Example:
///   sc-solve block.scmesh --setup solve.yaml -o block.scres
///   sc-export block.scres -o block.pvd          # then: paraview block.pvd
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// Input mesh (.scmesh), or - for standard input.
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
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let setup = match SolveSetup::read(&args.setup) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("sc-solve: error: {e}");
            return ExitCode::from(splinecontact::stages::exit_code::BAD_INPUT);
        }
    };
    let csv = args.csv.clone().or_else(|| solve::default_csv_path(&args.output));
    let verbosity = if args.quiet { Verbosity::Quiet } else { Verbosity::Normal };
    match solve::solve(&args.input, &setup, &args.setup.display().to_string(), &args.output, csv.as_deref(), verbosity) {
        Ok(r) => {
            if !args.quiet {
                eprintln!(
                    "solved: {} increments, {} Newton iterations, {} cutbacks, {:.2} s; wrote {}",
                    r.increments,
                    r.iterations,
                    r.cutbacks,
                    r.seconds,
                    args.output.display()
                );
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sc-solve: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
