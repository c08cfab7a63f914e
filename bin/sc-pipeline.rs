//! sc-pipeline: run the stages of a YAML pipeline in order.
// large blocks on huge pages (lib/os/large_pages.rs; SC_HUGE_PAGES=0 turns it off)
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: splinecontact::os::large_pages::LargePages = splinecontact::os::large_pages::LargePages;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

/// Run a splinecontact pipeline: the stages listed in a YAML file (gmsh, import,
/// export, …), in order, through the real files between them.
///
/// Relative paths in the YAML are resolved against the YAML's own folder, so a
/// pipeline runs the same from any working directory. Each stage is printed as it
/// starts; the first failing stage stops the run with its error (exit code 2 for
/// bad input, 1 for I/O, 3 for a solve that did not converge). The schema is in
/// docs/pipelines.md.
///
/// Example:
///   sc-pipeline pipelines/parisch.yaml
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// The pipeline YAML file.
    pipeline: PathBuf,
    /// Print nothing but warnings and errors.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    // the origin of SC_TIMELINE=1's timeline (lib/os/timeline.rs)
    splinecontact::os::timeline::epoch();
    let args = Args::parse();
    match splinecontact::solver::ranks::participate("sc-pipeline", false) {
        Ok(splinecontact::solver::ranks::Participation::Idle) => return ExitCode::SUCCESS,
        Ok(splinecontact::solver::ranks::Participation::Serial(why)) => eprintln!("sc-pipeline: warning: {why}"),
        Ok(_) => {}
        Err(e) => {
            eprintln!("sc-pipeline: error: {e}");
            return ExitCode::from(splinecontact::stages::exit_code::BAD_INPUT);
        }
    }
    // this thread works in rayon's parallel phases itself (lib/os/worker_pool.rs)
    splinecontact::os::worker_pool::join_as_worker();
    let quiet = args.quiet;
    let mut log = |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    let verbosity = if quiet { splinecontact::solver::log::Verbosity::Quiet } else { splinecontact::solver::log::Verbosity::Normal };
    // warnings are said even when quiet
    let mut warn = |line: &str| eprintln!("warning: {line}");
    let outcome = splinecontact::pipeline::run(&args.pipeline, verbosity, &mut log, &mut warn);
    splinecontact::os::timeline::report();
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sc-pipeline: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
