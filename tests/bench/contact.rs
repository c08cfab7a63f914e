//! Benchmark: a frictionless contact solve at growing mesh sizes, with the time of
//! each phase per Newton iteration (contact search, assembly, factorization, solve).
//!
//! Two stacked unit-square blocks of height 0.5 (lower n × n × 2 hexahedra, the master
//! top; upper (n+1) × (n+1) × 2, the slave bottom, non-matching), linear elastic
//! E = 1000, ν = 0.3, symmetry supports, the upper top pushed down by 1e-3, B-spline
//! master of orders 3 × 3 (and facets for comparison), augmented Lagrangian. Each
//! case runs through the real stages (`.sccontact` on disk → solve → `.scres`).
//! Search time per slave node should stay flat as the net grows (span tree,
//! near-linear); assembly scales with the elements; the direct factorization
//! superlinearly.
//!
//! cargo bench --bench contact
//! SC_BENCH_CONTACT_SIZES="8,16" cargo bench --bench contact   (quick)

use std::time::Instant;

use splinecontact::format::sccontact::MasterKind;
use splinecontact::format::scres::{Results, RunStatus};
use splinecontact::format::setup::SolveSetup;
use splinecontact::solver::log::Verbosity;
use splinecontact::stages::solve::solve;
use splinecontact::stages::tag::{build_model, PairSpec};

#[path = "../common/grid.rs"]
#[allow(dead_code)]
mod grid;

const DEFAULT_SIZES: &str = "8,16,32,64";

const SETUP: &str = "materials:\n  - {body: lower, model: linear_elastic, E: 1000.0, nu: 0.3}\n  - {body: upper, model: linear_elastic, E: 1000.0, nu: 0.3}\n\
constraints:\n  - {set: lower_x0, fix: [x]}\n  - {set: lower_y0, fix: [y]}\n  - {set: lower_z0, fix: [z]}\n  - {set: upper_x0, fix: [x]}\n  - {set: upper_y0, fix: [y]}\n  - {set: upper_z1, displacement: {z: -1.0e-3}}\n\
contact:\n  - {pair: c, eps_n: 1.0e5, enforcement: augmented_lagrangian, penetration_tolerance_relative: 1.0e-4}\n";

fn main() {
    let sizes = std::env::var("SC_BENCH_CONTACT_SIZES").unwrap_or_else(|_| DEFAULT_SIZES.into());
    println!("| master | n | nodes | slaves | dofs | iterations | augmentations | search/it [ms] | search/slave [µs] | assembly/it [ms] | factor/it [ms] | solve/it [ms] | wall [s] |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for n in sizes.split(',').filter_map(|s| s.trim().parse::<usize>().ok()) {
        for (kind, orders, label) in [(MasterKind::Bspline, Some([3, 3]), "bspline 3×3"), (MasterKind::Facet, None, "facet")] {
            let lower = grid::block([n, n, 2], [1.0, 1.0, 0.5], 0.0);
            let upper = grid::block([n + 1, n + 1, 2], [1.0, 1.0, 0.5], 0.0);
            let mesh = grid::two_bodies("lower", &lower, "upper", &upper, [0.0, 0.0, 0.5]);
            let spec = PairSpec { name: "c".into(), slave: "upper_z0".into(), master: "lower_z1".into(), master_kind: kind, orders };
            let model = build_model(mesh, "bench", &[spec]).expect("tag");
            let dir = tempfile::tempdir().expect("temp dir");
            let input = dir.path().join("m.sccontact");
            model.write(&input).expect("write model");
            let setup = SolveSetup::parse("bench", SETUP).expect("setup");
            let out = dir.path().join("r.scres");
            let t = Instant::now();
            let report = solve(&input, &setup, "bench", &out, None, None, Verbosity::Quiet);
            let wall = t.elapsed().as_secs_f64();
            if let Err(e) = report {
                println!("| {label} | {n} | solve failed: {e} |");
                continue;
            }
            let r = Results::read(&out).expect("results");
            assert_eq!(r.status, RunStatus::Completed);
            let inc = r.increments.last().expect("an increment");
            let its = &inc.info.iterations;
            let k = its.len() as f64;
            let sum = |f: fn(&splinecontact::format::scres::IterationLog) -> f64| its.iter().map(f).sum::<f64>();
            let slaves = r.pairs[0].slave_nodes.len();
            let search = sum(|i| i.seconds_contact) / k;
            println!(
                "| {label} | {n} | {} | {slaves} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {wall:.2} |",
                r.mesh.nodes.len(),
                3 * r.mesh.nodes.len(),
                its.len() - 1,
                inc.info.contact[0].augmentations,
                1e3 * search,
                1e6 * search / slaves as f64,
                1e3 * sum(|i| i.seconds_assembly) / k,
                1e3 * sum(|i| i.seconds_factor) / k,
                1e3 * sum(|i| i.seconds_solve) / k,
            );
        }
    }
}
