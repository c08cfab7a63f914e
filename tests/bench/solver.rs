//! Benchmark: the finite-strain solver on a cantilever at three mesh sizes.
//!
//! A block 10 × 1 × 1 (x × y × z) of unit-aspect-ratio-ish hex8 elements, the face
//! x = 0 clamped (x, y, z), a total downward force on the face x = 10 spread evenly
//! over its nodes; Ciarlet–Simo neo-Hookean (E = 1000, ν = 0.3), total Lagrangian,
//! 2 load increments, tip deflection about 15 % of the length (visibly nonlinear).
//! Each case runs through the real stage (`.scmesh` on disk → `sc-solve` →
//! `.scres` on disk) and prints one table row from the timings recorded in the
//! results file: per-Newton-iteration assembly / factorization / solve, per-increment
//! output (Gauss stresses + atomic rewrite of the results file), and wall time of the
//! whole solve call. "other" is wall minus the four phases: reading the mesh, the
//! problem setup, the sparsity pattern and the symbolic analysis (AMD ordering).
//!
//! cargo bench --bench solver
//! SC_BENCH_SOLVER_SIZES="40x4x4,100x10x10" cargo bench --bench solver   (quick)

use std::path::Path;
use std::time::Instant;

use splinecontact::format::scmesh;
use splinecontact::format::scres::{Results, RunStatus};
use splinecontact::format::setup::SolveSetup;
use splinecontact::mesh::Mesh;
use splinecontact::solver::log::Verbosity;
use splinecontact::stages::solve::solve;

const LENGTH: f64 = 10.0;
/// Total tip force (downward, −z). Linear beam theory gives δ = PL³/(3EI) = 4P.
const TIP_FORCE: f64 = 0.4;
const DEFAULT_SIZES: &str = "40x4x4,100x10x10,200x22x22";

/// The structured block of the integration tests (`tests/common/grid.rs`): body
/// "block", node sets "x0" (clamped) and "x1" (loaded) among the six faces.
#[path = "../common/grid.rs"]
#[allow(dead_code)]
mod grid;

fn cantilever(nx: usize, ny: usize, nz: usize) -> Mesh {
    grid::block([nx, ny, nz], [LENGTH, 1.0, 1.0], 0.0)
}

fn setup_yaml() -> String {
    format!(
        "formulation: total_lagrangian\n\
         materials: [{{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}}]\n\
         constraints: [{{set: x0, fix: [x, y, z]}}]\n\
         loads: [{{set: x1, force: [0, 0, {}]}}]\n\
         increments: {{count: 2}}\n",
        -TIP_FORCE
    )
}

/// Peak resident set size of this process so far (VmHWM), in GB.
fn peak_rss_gb() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0 / 1e9)
}

fn parse_sizes(s: &str) -> Vec<[usize; 3]> {
    s.split(',')
        .filter(|t| !t.trim().is_empty())
        .map(|t| {
            let v: Vec<usize> = t.trim().split('x').map(|n| n.trim().parse().unwrap_or_else(|_| panic!("bad size '{t}': expected e.g. 40x4x4"))).collect();
            assert!(v.len() == 3 && v.iter().all(|&n| n > 0), "bad size '{t}': expected e.g. 40x4x4");
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn main() {
    let sizes = parse_sizes(&std::env::var("SC_BENCH_SOLVER_SIZES").unwrap_or_else(|_| DEFAULT_SIZES.into()));
    let setup = SolveSetup::parse("bench-setup", &setup_yaml()).expect("bench setup parses");
    let dir = std::env::temp_dir().join(format!("sc-bench-solver-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    println!("cantilever {LENGTH}×1×1, neo_hookean E=1000 ν=0.3, tip force {TIP_FORCE} in 2 increments, {} rayon threads", rayon::current_num_threads());
    println!("| mesh | elements | nodes | free DOFs | increments | Newton its | assembly s | factor s | solve s | output s | other s | wall s | tip δ/L | peak RSS GB |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for [nx, ny, nz] in sizes {
        let mesh = cantilever(nx, ny, nz);
        let mesh_path = dir.join(format!("cantilever-{nx}x{ny}x{nz}.scmesh"));
        let out = dir.join(format!("cantilever-{nx}x{ny}x{nz}.scres"));
        scmesh::write(&mesh_path, &mesh, "bench").unwrap();
        let tip = mesh.node_sets[1].nodes.clone();
        let (elements, nodes, free) = (mesh.hexes.len(), mesh.nodes.len(), 3 * (mesh.nodes.len() - mesh.node_sets[0].nodes.len()));
        drop(mesh);

        let t = Instant::now();
        let report = solve(&mesh_path, &setup, "bench-setup", &out, None, None, Verbosity::Quiet);
        let wall = t.elapsed().as_secs_f64();
        let results = Results::read(Path::new(&out)).expect("results file reads back");
        let report = report.unwrap_or_else(|e| panic!("{nx}x{ny}x{nz}: solve failed: {e}"));
        assert_eq!(results.status, RunStatus::Completed);

        // output: Gauss stresses and contact state, plus writing the results file
        let (mut asm, mut fac, mut sol, mut outp, mut its) = (0.0, 0.0, 0.0, report.write_seconds, 0usize);
        for inc in &results.increments {
            outp += inc.info.seconds_output;
            its += inc.info.iterations.len().saturating_sub(1);
            for row in &inc.info.iterations {
                asm += row.seconds_assembly;
                fac += row.seconds_factor;
                sol += row.seconds_solve;
            }
        }
        let last = results.increments.last().expect("at least one increment");
        let deflection = -tip.iter().map(|&n| last.u[n as usize][2]).sum::<f64>() / tip.len() as f64;
        let rss = peak_rss_gb().map(|g| format!("{g:.2}")).unwrap_or_else(|| "?".into());
        println!(
            "| {nx}×{ny}×{nz} | {elements} | {nodes} | {free} | {} | {its} | {asm:.2} | {fac:.2} | {sol:.2} | {outp:.2} | {:.2} | {wall:.2} | {:.3} | {rss} |",
            results.increments.len(),
            wall - asm - fac - sol - outp,
            deflection / LENGTH
        );
        std::fs::remove_file(&mesh_path).ok();
        std::fs::remove_file(&out).ok();
    }
    std::fs::remove_dir_all(&dir).ok();
}
