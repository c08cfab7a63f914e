//! sc-tag: define the contact pairs of a mesh and order each master surface into
//! the B-spline control net.
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use splinecontact::stages::exit_code;
use splinecontact::stages::tag::{self, PairSpec};

/// Tag the contact surfaces of a .scmesh and write the contact model (.sccontact).
///
/// A contact pair presses SLAVE nodes against a MASTER surface. The master face set
/// is smoothed by ONE B-spline patch whose control points are its nodes (Santos &
/// Bandeira 2018, sec. 5), so it must be a topologically rectangular grid of quads
/// in one body: no holes, no branches, 4 corners, every interior node in 4 faces.
/// sc-tag orders its nodes into an a × b control net with the patch normal pointing
/// out of the master body, and refuses (naming the faces) anything else.
///
/// A pair, on the command line (repeatable):
///   --pair NAME:SLAVE:MASTER                   B-spline master, orders 3 × 3
///   --pair NAME:SLAVE:MASTER:bspline:KA:KB     B-spline master, orders KA × KB
///   --pair NAME:SLAVE:MASTER:facet             bilinear facets (the classic baseline)
/// SLAVE is a node set or a face set (its nodes). Order k = degree + 1: 2 bilinear,
/// 3 quadratic (C¹), 4 cubic (C²); a row of n master nodes carries at most order n.
///
/// Or in a YAML file (--pairs):
///   pairs:
///     - {name: contact, slave: upper_bottom, master: lower_top, master_kind: bspline, orders: [3, 3]}
///
/// Exit codes: 0 written, 2 bad input (nothing is written), 1 I/O.
///
/// Example:
///   sc-tag parisch.scmesh -o parisch.sccontact --pair contact:upper_bottom:lower_top:bspline:3:3
///   sc-export parisch.sccontact -o parisch.vtu   # + parisch_contact_surface.vtu, _net.vtu
#[derive(Parser)]
#[command(version, about, long_about, verbatim_doc_comment)]
struct Args {
    /// Input mesh (.scmesh), or - for standard input.
    input: PathBuf,
    /// Output contact model (.sccontact), or - for standard output.
    #[arg(short, long)]
    output: PathBuf,
    /// A contact pair NAME:SLAVE:MASTER[:bspline:KA:KB|:facet] (repeatable).
    #[arg(long = "pair", value_name = "PAIR")]
    pairs: Vec<String>,
    /// YAML file with the pairs (`pairs: [...]`), in addition to any --pair.
    #[arg(long = "pairs", value_name = "YAML")]
    pairs_file: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[allow(clippy::result_large_err)] // cold path; the error carries its culprit
fn specs(args: &Args) -> Result<Vec<PairSpec>, tag::TagError> {
    let mut out = Vec::new();
    if let Some(f) = &args.pairs_file {
        out.extend(tag::read_pairs_file(f)?);
    }
    for p in &args.pairs {
        out.push(PairSpec::parse(p)?);
    }
    Ok(out)
}

fn main() -> ExitCode {
    let args = Args::parse();
    let specs = match specs(&args) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("sc-tag: error: {e}");
            return ExitCode::from(exit_code::BAD_INPUT);
        }
    };
    match tag::tag(&args.input, &args.output, &specs) {
        Ok(lines) => {
            if !args.quiet {
                for l in lines {
                    eprintln!("{l}");
                }
                if args.output.as_os_str() != "-" {
                    eprintln!("wrote {}", args.output.display());
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sc-tag: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
