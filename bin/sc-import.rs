//! sc-import: gmsh MSH (2.2 or 4.1, ASCII or binary) → splinecontact mesh (.scmesh).
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::stages::import;

/// Import a gmsh mesh of 8-node hexahedra into a versioned .scmesh stage file.
///
/// Reads gmsh MSH 2.2 and 4.1, ASCII and binary. Every physical volume becomes a
/// body; every physical group becomes a node set; every physical surface of quads
/// becomes a face set (faces oriented out of their hexahedron). Only hex8 volume
/// elements are supported. Mirrored hexahedra are reordered (and reported), twisted
/// ones refused; nodes no hexahedron uses are dropped (and reported).
///
/// Examples:
///   sc-import meshes/parisch.msh -o parisch.scmesh
///   gmsh part.geo -3 -o - | sc-import - -o - | sc-export - --format yaml -o -
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// Input .msh file, or - for standard input.
    input: PathBuf,
    /// Output .scmesh file, or - for standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// Print nothing but warnings and errors.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match import::import(&args.input, &args.output) {
        Ok((mesh, report)) => {
            if !args.quiet {
                for line in import::summary(&args.input, &mesh, &report) {
                    eprintln!("{line}");
                }
                if args.output.as_os_str() != "-" {
                    eprintln!("wrote {}", args.output.display());
                }
            }
            for warning in &report.warnings {
                eprintln!("sc-import: warning: {warning}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sc-import: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
