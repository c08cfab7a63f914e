//! Timing benchmark of the linear-solver path on a linear-elastic cube.
//!
//! An `n × n × n` grid of unit hex8 elements (E = 1, ν = 0.3, 2×2×2 Gauss), the
//! face `z = 0` clamped, a unit downward force on every node of the face `z = n`.
//! [`elastic_cube`] builds the pattern, assembles `K_ff` (parallel,
//! deterministic), then analyses, factors and solves with the given backend, and
//! returns the wall time of each phase. The main binary / pipeline calls it; the
//! `#[ignore]`d test below prints a table (`cargo test --release --lib
//! bench_table -- --ignored --nocapture`).

#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use std::time::{Duration, Instant};

use nalgebra::Vector3;

use crate::assembly::{Assembly, AssemblyError, DofMap, HexMatrix, HexVector, NodeGroups, Pattern, PatternError};
use crate::fem::element::{hex8_residual_tangent, Formulation};
use crate::material::linear::LinearElastic;
use crate::material::MaterialModel;
use crate::assembly::pattern::structured_hex_grid;

use super::linear::{Factorization, LinearSolver, LinearSolverError, Symmetry};

/// Errors of the benchmark.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Dofs(#[from] crate::assembly::DofError),
    #[error(transparent)]
    Pattern(#[from] PatternError),
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    #[error("hexahedron {0} has a non-positive Jacobian")]
    InvertedElement(usize),
    #[error(transparent)]
    Solver(#[from] LinearSolverError),
}

/// Wall times and sizes of one benchmark run.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchTimings {
    pub elements_per_edge: usize,
    pub n_free: usize,
    pub nnz: usize,
    /// Pattern and assembly-workspace construction (once per pattern).
    pub pattern: Duration,
    /// One assembly (element tangents in parallel + deterministic sum).
    pub assembly: Duration,
    /// Of which the fixed-order sum phase.
    pub assembly_sum: Duration,
    /// Bytes of the assembly workspace.
    pub assembly_bytes: usize,
    pub symbolic: Duration,
    pub numeric: Duration,
    pub solve: Duration,
    pub method: Factorization,
    /// ‖K u − f‖ / ‖f‖ of the computed solution.
    pub relative_residual: f64,
}

/// Small-strain stiffness of a hex8 (VTK node order, 2×2×2 Gauss): the tangent of
/// the library's element ([`crate::fem::element`]) with a linear-elastic material at
/// u = 0. `None` if the element is degenerate or the parameters are invalid.
pub fn hex8_elastic_stiffness(x: &[[f64; 3]; 8], young: f64, nu: f64) -> Option<HexMatrix> {
    let mat: MaterialModel = LinearElastic::from_young_poisson(young, nu).ok()?.into();
    let X: [Vector3<f64>; 8] = std::array::from_fn(|a| Vector3::new(x[a][0], x[a][1], x[a][2]));
    let u = [Vector3::zeros(); 8];
    let (mut r, mut k) = (HexVector::zeros(), HexMatrix::zeros());
    hex8_residual_tangent(&X, &u, &mat, Formulation::TotalLagrangian, &mut r, &mut k).ok()?;
    Some(k)
}

/// The assembled clamped cube: pattern, workspace (holding `K_ff` values) and the
/// load restricted to the free dofs.
pub struct ElasticCube {
    pub pattern: Pattern,
    pub assembly: Assembly,
    pub rhs: Vec<f64>,
    pub pattern_time: Duration,
    pub assembly_time: Duration,
}

/// Builds and assembles the clamped `n × n × n` cube (see the module doc).
pub fn elastic_cube_system(n: usize) -> Result<ElasticCube, BenchError> {
    let start = Instant::now();
    let (nodes, hexes) = structured_hex_grid(n, n, n);
    let mut mask = vec![false; 3 * nodes.len()];
    let mut force = vec![0.0; 3 * nodes.len()];
    for (a, x) in nodes.iter().enumerate() {
        if x[2] == 0.0 {
            mask[3 * a..3 * a + 3].fill(true);
        }
        if x[2] == n as f64 {
            force[3 * a + 2] = -1.0;
        }
    }
    let dofs = DofMap::from_constrained_mask(&mask)?;
    let pattern = Pattern::build(dofs, &hexes, NodeGroups::new())?;
    let mut assembly = Assembly::new(&pattern)?;
    let pattern_time = start.elapsed();

    let start = Instant::now();
    assembly
        .assemble(&pattern, |e, _r, k| {
            let h = &hexes[e];
            let x = std::array::from_fn(|a| nodes[h[a] as usize]);
            *k = hex8_elastic_stiffness(&x, 1.0, 0.3).ok_or(())?;
            Ok(())
        })
        .map_err(|(e, ())| BenchError::InvertedElement(e))?;
    let assembly_time = start.elapsed();

    let mut rhs = vec![0.0; pattern.n_free()];
    pattern.dofs().gather_free(&force, &mut rhs);
    Ok(ElasticCube { pattern, assembly, rhs, pattern_time, assembly_time })
}

/// `y = A x` for the CSC pattern with both triangles stored.
pub fn csc_matvec(col_ptr: &[usize], row_idx: &[usize], values: &[f64], x: &[f64], y: &mut [f64]) {
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate() {
        for s in col_ptr[j]..col_ptr[j + 1] {
            y[row_idx[s]] += values[s] * xj;
        }
    }
}

/// Relative residual ‖A x − b‖ / ‖b‖.
pub fn relative_residual(col_ptr: &[usize], row_idx: &[usize], values: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let mut ax = vec![0.0; b.len()];
    csc_matvec(col_ptr, row_idx, values, x, &mut ax);
    let num: f64 = ax.iter().zip(b).map(|(a, b)| (a - b) * (a - b)).sum();
    let den: f64 = b.iter().map(|b| b * b).sum();
    (num / den).sqrt()
}

/// Runs the benchmark on the `n × n × n` cube with `solver`.
pub fn elastic_cube(n: usize, solver: &mut dyn LinearSolver, symmetry: Symmetry) -> Result<BenchTimings, BenchError> {
    let cube = elastic_cube_system(n)?;
    let p = &cube.pattern;
    let values = cube.assembly.values();
    let before = solver.timings();
    solver.analyse(p.symbolic(), symmetry)?;
    let info = solver.factor(values)?;
    let mut x = cube.rhs.clone();
    solver.solve_in_place(values, &mut x)?;
    let after = solver.timings();
    Ok(BenchTimings {
        elements_per_edge: n,
        n_free: p.n_free(),
        nnz: p.nnz(),
        pattern: cube.pattern_time,
        assembly: cube.assembly_time,
        assembly_sum: cube.assembly.timings().sum,
        assembly_bytes: cube.assembly.memory_bytes(),
        symbolic: after.symbolic - before.symbolic,
        numeric: after.numeric - before.numeric,
        solve: after.solve - before.solve,
        method: info.method,
        relative_residual: relative_residual(p.col_ptr(), p.row_idx(), values, &x, &cube.rhs),
    })
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::solver::linear::{FaerDirect, FaerDirectOptions};
    use faer::Par;

    #[test]
    fn small_cube_solves() {
        let mut s = FaerDirect::default();
        let t = elastic_cube(3, &mut s, Symmetry::Symmetric).unwrap();
        assert_eq!(t.n_free, 3 * 16 * 3);
        assert_eq!(t.method, Factorization::Llt);
        assert!(t.relative_residual < 1e-12, "{}", t.relative_residual);
    }

    #[test]
    fn element_stiffness_has_six_rigid_modes() {
        let x = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
        let k = hex8_elastic_stiffness(&x, 1.0, 0.3).unwrap();
        assert!((k - k.transpose()).abs().max() < 1e-14);
        let eig = k.symmetric_eigenvalues();
        let zeros = eig.iter().filter(|v| v.abs() < 1e-12).count();
        assert_eq!(zeros, 6);
        assert!(eig.iter().all(|&v| v > -1e-12));
        // Rigid translation gives no force.
        let u = nalgebra::SVector::<f64, 24>::from_fn(|i, _| if i % 3 == 0 { 1.0 } else { 0.0 });
        assert!((k * u).abs().max() < 1e-14);
    }

    /// `cargo test --release --lib bench_table -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn bench_table() {
        let sizes: Vec<usize> = std::env::var("SC_BENCH_SIZES")
            .ok()
            .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
            .unwrap_or_else(|| vec![10, 20, 30]);
        let threads: Vec<usize> = std::env::var("SC_BENCH_THREADS")
            .ok()
            .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
            .unwrap_or_else(|| vec![1, 2]);
        println!("| n³ | threads | unknowns | nnz | pattern s | assembly s (sum) | asm MB | symbolic s | numeric s | solve s | method | ‖Ku−f‖/‖f‖ |");
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
        for &n in &sizes {
            for &t in &threads {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
                let r = pool.install(|| {
                    let par = if t == 1 { Par::Seq } else { Par::rayon(t) };
                    let mut s = FaerDirect::new(FaerDirectOptions { par: Some(par), ..Default::default() });
                    elastic_cube(n, &mut s, Symmetry::Symmetric).unwrap()
                });
                println!(
                    "| {n}³ | {t} | {} | {} | {:.3} | {:.3} ({:.3}) | {} | {:.3} | {:.3} | {:.3} | {:?} | {:.1e} |",
                    r.n_free,
                    r.nnz,
                    r.pattern.as_secs_f64(),
                    r.assembly.as_secs_f64(),
                    r.assembly_sum.as_secs_f64(),
                    r.assembly_bytes / 1_000_000,
                    r.symbolic.as_secs_f64(),
                    r.numeric.as_secs_f64(),
                    r.solve.as_secs_f64(),
                    r.method,
                    r.relative_residual
                );
            }
        }
    }
}
/// Fill and time of the Cholesky factorization of the clamped elastic cube, per
/// ordering and thread count (`docs/performance.md`, "Orderings and threads"):
/// `cargo test --release --lib bench_orderings_and_threads -- --ignored --nocapture`.
#[cfg(test)]
mod orderings {
    use super::*;
    use crate::solver::linear::{FaerDirect, FaerDirectOptions};
    use crate::solver::ordering::FillOrdering;
    use faer::Par;

    #[test]
    #[ignore]
    fn bench_orderings_and_threads() {
        let sizes: Vec<usize> = std::env::var("SC_BENCH_CUBES").ok().map_or(vec![20, 30], |s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect());
        println!("| cube | dofs | ordering | threads | numeric LLᵀ | L entries | widest supernode | factor s | solve s |");
        println!("|---|---|---|---|---|---|---|---|---|");
        for n in sizes {
            for ordering in [FillOrdering::NestedDissection, FillOrdering::Amd] {
                for (threads, par) in [(1, Par::Seq), (2, Par::rayon(2))] {
                    for elimination_tree in [false, true] {
                        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                        let mut s = FaerDirect::new(FaerDirectOptions { par: Some(par), ordering, elimination_tree, ..Default::default() });
                        let t = pool.install(|| elastic_cube(n, &mut s, Symmetry::Symmetric)).unwrap();
                        assert!(t.relative_residual < 1e-10);
                        println!(
                            "| {n}³ | {} | {ordering:?} | {threads} | {} | {} | {} | {:.3} | {:.4} |",
                            t.n_free,
                            if elimination_tree { "tree" } else { "faer" },
                            s.factor_len(),
                            s.largest_supernode(),
                            t.numeric.as_secs_f64(),
                            t.solve.as_secs_f64()
                        );
                    }
                }
            }
        }
    }
}
