//! sc-export: any splinecontact stage file → VTK for ParaView, or readable YAML.
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::stages::export::{self, ExportFormat};

/// Export a splinecontact stage file for ParaView, or dump it as YAML.
///
/// A mesh (.scmesh) becomes one .vtu (cell data: body, gmsh_element_tag; point
/// data: gmsh_node_tag and one 0/1 array "set:<name>" per node set). A contact
/// model (.sccontact) becomes that mesh .vtu plus, per pair, <stem>_<pair>_surface.vtu
/// (the master surface, 8×8 quads per knot span, point data normal = n̄ and xi) and
/// <stem>_<pair>_net.vtu (the control net as lines). Results (.scres) become a .pvd
/// series. Any stage file can be dumped, every record, with --format yaml.
///
/// The format follows the output's extension (.vtu, .pvd, .yaml) unless --format
/// is given; it must be given when the output is standard output (-).
///
/// Examples:
///   sc-export parisch.scmesh -o parisch.vtu        # then: paraview parisch.vtu
///   sc-export parisch.scmesh --format yaml -o -    # inspect a stage file
///   sc-export parisch.sccontact -o contact.vtu     # + contact_<pair>_surface.vtu, _net.vtu
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// Input stage file (.scmesh, .sccontact, .scres), or - for standard input.
    input: PathBuf,
    /// Output file, or - for standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// Output format (default: from the output's extension).
    #[arg(short, long, value_enum)]
    format: Option<ExportFormat>,
    /// Print nothing but warnings and errors.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match export::export(&args.input, &args.output, args.format) {
        Ok(exported) => {
            if !args.quiet && args.output.as_os_str() != "-" {
                eprintln!("{}", exported.written);
            }
            // an incomplete results file is said even when quiet
            for warning in &exported.warnings {
                eprintln!("sc-export: warning: {warning}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sc-export: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
