//! sc-check: the pre-solve check of a contact model and its solve setup.
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::check::report;
use splinecontact::format::setup::SolveSetup;
use splinecontact::stages::check::{self, CheckOutputs};
use splinecontact::stages::exit_code;

/// Check a model before solving it: read the .sccontact (or .scmesh) and the setup
/// exactly as sc-solve would, and say what the solve will meet at its start.
/// Changes nothing; seconds on a million-dof model.
///
/// Per contact pair:
///   - the slave nodes, and how many project onto the master (inside), beyond its
///     edges (outside), or fail to project (and why);
///   - the initial gap range g_N, the penetration range −g_N and the nodes that
///     penetrate beyond the pair's tolerance (gmsh node tags);
///   - whether the master normal n̄ faces the slave body. A FLIPPED master (the
///     slave body lies behind it) makes sc-solve refuse the model: check which
///     face set is the master, or set `allow_flipped_master: true`;
///   - the capture radius (0.5 h) and the penalty ε_N the solve will use (the
///     setup's, or the default 25 G/h);
///   - how contact is imposed: node-to-surface, or mortar with its multipliers
///     and transfer (`balanced`: on how many master nodes the basis is
///     recombined) and quadrature (`knot_spans`: segments cut by the knot
///     spans), and the friction law;
///   - what `adjust: <distance>` in the pair's contact entry would move: slave
///     nodes with |g_N| ≤ distance put onto the master, stress-free, before the
///     first increment (Abaqus ADJUST, ANSYS ICONT).
///
/// Per body (connected part of the mesh): the rigid-body modes no constraint holds
/// ("translation x", "rotation about z", ...). A body held only by contact is
/// legitimate, but needs contact at the start (zero gap) and, frictionless, supports
/// for its in-plane modes.
///
/// Outputs: the summary on standard output (and --summary FILE); --csv FILE, one row
/// per pair and slave node (node tag, position, projection, g_N, ξ̄, n̄, flags);
/// --vtu FILE, the slave nodes with the same fields for ParaView (colour by `flag`:
/// 0 ok, 1 outside, 2 adjusted, 3 penetrating, 4 failed, 5 behind a flipped master).
/// -o STEM writes all three: STEM.csv, STEM.vtu, STEM.txt. Columns and fields:
/// docs/formats.md, "Pre-solve check"; what to do about each finding:
/// docs/diagnosing.md.
///
/// Exit codes: 0 checked (findings or not), 2 bad input (unreadable model or setup,
/// a setup that does not fit the model) or, with --strict, a finding the solve
/// refuses (a flipped master), 1 I/O.
///
/// Example:
///   sc-check two.sccontact --setup contact.yaml
///   sc-check two.sccontact --setup contact.yaml -o out/two-check --strict
///   paraview out/two-check.vtu
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// The contact model (.sccontact) or mesh (.scmesh), or - for standard input.
    input: PathBuf,
    /// The solve setup (YAML), as given to sc-solve.
    #[arg(short, long)]
    setup: PathBuf,
    /// Write STEM.csv, STEM.vtu and STEM.txt (the summary).
    #[arg(short, long, value_name = "STEM")]
    output: Option<PathBuf>,
    /// The per-node CSV.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// The slave nodes as a .vtu point cloud.
    #[arg(long, value_name = "FILE")]
    vtu: Option<PathBuf>,
    /// The summary, also to this file.
    #[arg(long, value_name = "FILE")]
    summary: Option<PathBuf>,
    /// Exit with code 2 when the check finds what sc-solve refuses (a flipped master).
    #[arg(long)]
    strict: bool,
    /// Do not print the summary (errors still go to standard error).
    #[arg(short, long)]
    quiet: bool,
}

fn with_ext(stem: &std::path::Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

fn main() -> ExitCode {
    let args = Args::parse();
    let setup = match SolveSetup::read(&args.setup) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("sc-check: error: {e}");
            return ExitCode::from(exit_code::BAD_INPUT);
        }
    };
    let pick = |explicit: &Option<PathBuf>, ext: &str| explicit.clone().or_else(|| args.output.as_deref().map(|s| with_ext(s, ext)));
    let (csv, vtu, summary) = (pick(&args.csv, "csv"), pick(&args.vtu, "vtu"), pick(&args.summary, "txt"));
    let outputs = CheckOutputs { csv: csv.as_deref(), vtu: vtu.as_deref(), summary: summary.as_deref() };
    let r = match check::check(&args.input, &setup, &args.setup.display().to_string(), outputs) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("sc-check: error: {e}");
            return ExitCode::from(e.exit_code());
        }
    };
    if !args.quiet {
        for line in report::summary(&r) {
            println!("{line}");
        }
        for p in [&csv, &vtu, &summary].into_iter().flatten() {
            eprintln!("wrote {}", p.display());
        }
    }
    let errors = r.errors();
    if args.strict && !errors.is_empty() {
        for e in &errors {
            eprintln!("sc-check: error: {e}");
        }
        return ExitCode::from(exit_code::BAD_INPUT);
    }
    ExitCode::SUCCESS
}
