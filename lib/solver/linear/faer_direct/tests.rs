//! The faer direct backend against dense references, its fallbacks and its
//! singularity checks.

#![allow(clippy::needless_range_loop)]

use super::*;
use crate::solver::bench::{elastic_cube_system, relative_residual};

use crate::fem::fd::Lcg;

/// CSC (entries where `keep(i, j)`, rows sorted) of a dense matrix.
fn dense_to_csc(a: &[Vec<f64>], keep: impl Fn(usize, usize) -> bool) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
    let n = a.len();
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], vec![], vec![]);
    for j in 0..n {
        for (i, row) in a.iter().enumerate() {
            if keep(i, j) {
                row_idx.push(i);
                values.push(row[j]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    (SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), values)
}

fn residual_of(p: &SymbolicSparseColMat<usize>, v: &[f64], x: &[f64], b: &[f64]) -> f64 {
    relative_residual(p.col_ptr(), p.row_idx(), v, x, b)
}

fn solve(solver: &mut FaerDirect, p: &SymbolicSparseColMat<usize>, v: &[f64], b: &[f64], sym: Symmetry) -> (Vec<f64>, Factorization) {
    solver.analyse(p.as_ref(), sym).unwrap();
    let info = solver.factor(v).unwrap();
    let mut x = b.to_vec();
    solver.solve_in_place(&v, &mut x).unwrap();
    (x, info.method)
}

fn with(symmetric: SymmetricStrategy) -> FaerDirect {
    FaerDirect::new(FaerDirectOptions { symmetric, ..Default::default() })
}

#[test]
fn llt_ldlt_lu_agree_on_elastic_cube() {
    let cube = elastic_cube_system(4).unwrap();
    let p = cube.pattern.symbolic_owned();
    let v = cube.assembly.values();
    let b = &cube.rhs;
    let (x_llt, m1) = solve(&mut with(SymmetricStrategy::LltThenLdlt), p, v, b, Symmetry::Symmetric);
    let (x_ldlt, m2) = solve(&mut with(SymmetricStrategy::Ldlt), p, v, b, Symmetry::Symmetric);
    let (x_lu, m3) = solve(&mut FaerDirect::default(), p, v, b, Symmetry::General);
    assert_eq!((m1, m2, m3), (Factorization::Llt, Factorization::Ldlt, Factorization::Lu));
    for x in [&x_llt, &x_ldlt, &x_lu] {
        let r = residual_of(p, v, x, b);
        assert!(r < 1e-12, "residual {r:e}");
    }
    let norm = x_llt.iter().map(|v| v * v).sum::<f64>().sqrt();
    for x in [&x_ldlt, &x_lu] {
        let d = x.iter().zip(&x_llt).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        assert!(d / norm < 1e-10, "solutions differ by {:e}", d / norm);
    }
    // The load pushes the top face down.
    assert!(x_llt.iter().cloned().fold(0.0, f64::min) < -1.0);
}

/// Quasi-definite `[[K, Bᵀ], [B, −C]]`: symmetric indefinite.
fn saddle_point(nk: usize, nb: usize) -> Vec<Vec<f64>> {
    let n = nk + nb;
    let mut rng = Lcg(3);
    let mut a = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..i {
            let coupled = j < nk && ((i < nk && (i - j) <= 3) || (i >= nk && (i * 7 + j) % 5 == 0));
            if coupled {
                let v = rng.uniform();
                a[i][j] = v;
                a[j][i] = v;
            }
        }
    }
    for i in 0..nk {
        a[i][i] = 8.0 + rng.uniform();
    }
    for i in nk..n {
        a[i][i] = -1e-3 * (1.5 + rng.uniform());
    }
    a
}

#[test]
fn symmetric_indefinite_goes_to_ldlt() {
    let a = saddle_point(24, 8);
    let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
    let b: Vec<f64> = (0..a.len()).map(|i| 1.0 + i as f64 * 0.1).collect();
    let mut s = FaerDirect::default();
    let (x, m) = solve(&mut s, &p, &v, &b, Symmetry::Symmetric);
    assert_eq!(m, Factorization::Ldlt);
    let r = residual_of(&p, &v, &x, &b);
    assert!(r < 1e-12, "residual {r:e}");
    // LLT alone refuses it, with the typed error.
    let mut llt = with(SymmetricStrategy::Llt);
    llt.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
    assert!(matches!(llt.factor(&v), Err(LinearSolverError::NotPositiveDefinite { .. })));
    // LU agrees.
    let (x_lu, _) = solve(&mut FaerDirect::default(), &p, &v, &b, Symmetry::General);
    let d = x.iter().zip(&x_lu).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d < 1e-10 * x.iter().map(|v| v.abs()).fold(0.0, f64::max));
}

#[test]
fn nonsymmetric_with_lu() {
    let n = 40;
    let mut rng = Lcg(11);
    let mut a = vec![vec![0.0; n]; n];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            if i == j {
                *v = 0.5 * rng.uniform(); // not diagonally dominant: pivoting needed
            } else if (i + 2 * j) % 7 == 0 || i.abs_diff(j) == 1 {
                *v = rng.uniform();
            }
        }
    }
    let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
    let b: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 2.0).collect();
    let mut s = FaerDirect::default();
    let (x, m) = solve(&mut s, &p, &v, &b, Symmetry::General);
    assert_eq!(m, Factorization::Lu);
    let r = residual_of(&p, &v, &x, &b);
    assert!(r < 1e-12, "residual {r:e}");
}

#[test]
fn symbolic_factorization_is_reused() {
    let cube = elastic_cube_system(3).unwrap();
    let p = cube.pattern.symbolic_owned();
    let v1 = cube.assembly.values().to_vec();
    // Same pattern, other values: 2 K + 0.5 I-like diagonal shift.
    let mut v2: Vec<f64> = v1.iter().map(|v| 2.0 * v).collect();
    for j in 0..p.nrows() {
        let s = p.col_ptr()[j] + p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]].binary_search(&j).unwrap();
        v2[s] += 0.5;
    }
    for sym in [Symmetry::Symmetric, Symmetry::General] {
        let mut s = FaerDirect::default();
        s.analyse(p.as_ref(), sym).unwrap();
        let mut xs = vec![];
        for v in [&v1, &v2] {
            s.factor(v).unwrap();
            let mut x = cube.rhs.clone();
            s.solve_in_place(&v, &mut x).unwrap();
            let r = residual_of(p, v, &x, &cube.rhs);
            assert!(r < 1e-12, "{sym:?}: residual {r:e}");
            xs.push(x);
        }
        let t = s.timings();
        assert_eq!((t.n_symbolic, t.n_numeric, t.n_solve), (1, 2, 2));
        assert!(t.symbolic > Duration::ZERO && t.numeric > Duration::ZERO && t.solve > Duration::ZERO);
        // The second system is stiffer: smaller displacements.
        let max = |x: &Vec<f64>| x.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(max(&xs[1]) < 0.51 * max(&xs[0]));
    }
}

#[test]
fn singular_matrices_give_typed_errors() {
    // A decoupled dof with a zero diagonal: an exact zero pivot.
    let n = 12;
    let mut a = vec![vec![0.0; n]; n];
    for i in 0..n {
        a[i][i] = 4.0;
        if i + 1 < n {
            a[i][i + 1] = -1.0;
            a[i + 1][i] = -1.0;
        }
    }
    let dead = 7;
    for i in 0..n {
        a[dead][i] = 0.0;
        a[i][dead] = 0.0;
    }
    let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
    for strategy in [SymmetricStrategy::LltThenLdlt, SymmetricStrategy::Ldlt] {
        let mut s = with(strategy);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        let err = s.factor(&v).unwrap_err();
        assert_eq!(err, LinearSolverError::Singular { dof: Some(dead) }, "{strategy:?}");
        assert!(err.to_string().contains("is a body unconstrained?"));
        let mut x = vec![1.0; n];
        assert_eq!(s.solve_in_place(&v, &mut x), Err(LinearSolverError::Order("solve_in_place", "a successful factor")));
    }
    // The same on an elastic cube large enough for the supernodal path.
    let cube = elastic_cube_system(6).unwrap();
    let p6 = cube.pattern.symbolic_owned();
    let mut v6 = cube.assembly.values().to_vec();
    let dead = 100;
    for j in 0..p6.nrows() {
        for s in p6.col_ptr()[j]..p6.col_ptr()[j + 1] {
            if j == dead || p6.row_idx()[s] == dead {
                v6[s] = 0.0;
            }
        }
    }
    for strategy in [SymmetricStrategy::LltThenLdlt, SymmetricStrategy::Ldlt] {
        let mut s = with(strategy);
        s.analyse(p6.as_ref(), Symmetry::Symmetric).unwrap();
        assert!(matches!(s.symbolic, Some(Symbolic::Cholesky(ref c)) if c.structure.is_some()));
        assert_eq!(s.factor(&v6), Err(LinearSolverError::Singular { dof: Some(dead) }), "{strategy:?}");
    }

    // LU: a structurally empty column.
    let (p, v) = dense_to_csc(&a, |i, j| a[i][j] != 0.0);
    let mut s = FaerDirect::default();
    s.analyse(p.as_ref(), Symmetry::General).unwrap();
    match s.factor(&v) {
        Err(LinearSolverError::Singular { .. }) => {}
        other => panic!("expected Singular, got {other:?}"),
    }

    // An unconstrained elastic cube: six rigid modes, round-off pivots.
    let (nodes, hexes) = crate::assembly::pattern::structured_hex_grid(2, 2, 2);
    let pat = crate::assembly::Pattern::build(
        crate::assembly::DofMap::all_free(nodes.len()).unwrap(),
        &hexes,
        crate::assembly::NodeGroups::new(),
    )
    .unwrap();
    let mut asm = crate::assembly::Assembly::new(&pat).unwrap();
    let (values, _) = asm
        .assemble(&pat, |e, _r, k| {
            let x = std::array::from_fn(|a| nodes[hexes[e][a] as usize]);
            *k = crate::solver::bench::hex8_elastic_stiffness(&x, 1.0, 0.3).ok_or(())?;
            Ok::<(), ()>(())
        })
        .unwrap();
    let mut s = FaerDirect::default();
    s.analyse(pat.symbolic(), Symmetry::Symmetric).unwrap();
    match s.factor(values) {
        Err(LinearSolverError::Singular { dof: Some(_) }) => {}
        other => panic!("expected Singular with a dof, got {other:?}"),
    }
}

#[test]
fn misuse_gives_errors_not_panics() {
    let mut s = FaerDirect::default();
    assert!(matches!(s.factor(&[1.0]), Err(LinearSolverError::Order(..))));
    let a = vec![vec![2.0, 0.0], vec![0.0, 3.0]];
    let (p, v) = dense_to_csc(&a, |i, j| i == j);
    s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
    assert!(matches!(s.factor(&[1.0]), Err(LinearSolverError::Dimension { .. })));
    assert_eq!(s.factor(&[1.0, f64::NAN]), Err(LinearSolverError::NonFinite { index: 1 }));
    s.factor(&v).unwrap();
    assert!(matches!(s.solve_in_place(&v, &mut [1.0]), Err(LinearSolverError::Dimension { .. })));
    let mut x = [2.0, 3.0];
    s.solve_in_place(&v, &mut x).unwrap();
    assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15, "{x:?}");
}

#[test]
fn fixed_parallelism_is_reproducible() {
    let cube = elastic_cube_system(6).unwrap();
    let p = cube.pattern.symbolic_owned();
    let run = |par: Par| {
        let mut s = FaerDirect::new(FaerDirectOptions { par: Some(par), ..Default::default() });
        solve(&mut s, p, cube.assembly.values(), &cube.rhs, Symmetry::Symmetric).0
    };
    let bits = |x: Vec<f64>| x.into_iter().map(f64::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(run(Par::Seq)), bits(run(Par::Seq)));
    assert_eq!(bits(run(Par::rayon(2))), bits(run(Par::rayon(2))));
}

/// `FaerDirect`'s `LLᵀ` is the elimination-tree factorization by default, and
/// faer's own with `elimination_tree: false`. With sequential dense kernels the
/// two compute every entry by the same operations in the same order: the same
/// factor, bit for bit (`docs/theory/solver.md`).
#[test]
fn the_elimination_tree_factor_is_faers_own_bit_for_bit_with_sequential_kernels() {
    let cube = elastic_cube_system(10).unwrap();
    let p = cube.pattern.symbolic_owned();
    let factor = |elimination_tree: bool| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let mut s = FaerDirect::new(FaerDirectOptions { par: Some(Par::Seq), elimination_tree, ..Default::default() });
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        assert_eq!(pool.install(|| s.factor(cube.assembly.values())).unwrap().method, Factorization::Llt);
        assert_eq!(s.tree.is_some(), elimination_tree);
        if let Some(tree) = &s.tree {
            // the top supernodes' updates go by column chunks (tree_cholesky::CHUNK_FLOPS)
            assert!(tree.chunks.iter().any(|c| c.len() > 2), "no supernode's updates are chunked");
        }
        s.l_values
    };
    let bits = |l: Vec<f64>| l.into_iter().map(f64::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(factor(true)), bits(factor(false)));
}

/// `analyse_in_background` leaves what `analyse` leaves: on 2 rayon threads the
/// analysis is a task of the pool (pending until `factor` waits for it), from inside
/// the pool or outside it, on one in place, and the factor is the same, bit for bit,
/// with the analysis counted once. A pattern analysed anew while the background analysis still runs waits for
/// it and drops it. (Its failure, a factor too large for the memory, reaches the
/// user as the setup error it was before: `cli::solve`,
/// `a_model_too_large_for_memory_fails_before_factorization_with_an_estimate`.)
#[test]
fn the_background_analysis_is_the_analysis() {
    let cube = elastic_cube_system(8).unwrap();
    let p = cube.pattern.symbolic_owned();
    // `threads`: inside a pool of that many; 0: from outside any pool (the analysis
    // a task of the global pool)
    let factor = |background: bool, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build().unwrap();
        let run = || {
            let mut s = FaerDirect::new(FaerDirectOptions { par: Some(Par::Seq), ..Default::default() });
            if background {
                s.analyse_in_background(cube.pattern.shared(), Symmetry::Symmetric).unwrap();
                assert_eq!(s.pending.is_some(), rayon::current_num_threads() > 1, "{threads} threads");
                assert!(std::sync::Arc::ptr_eq(s.pattern.as_ref().unwrap(), cube.pattern.shared()), "shared, not copied");
            } else {
                s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
            }
            assert_eq!(s.factor(cube.assembly.values()).unwrap().method, Factorization::Llt);
            assert!(s.pending.is_none() && s.timings().n_symbolic == 1);
            let mut x = cube.rhs.clone();
            s.solve_in_place(cube.assembly.values(), &mut x).unwrap();
            assert!(residual_of(p, cube.assembly.values(), &x, &cube.rhs) < 1e-12);
            s.l_values.into_iter().map(f64::to_bits).collect::<Vec<_>>()
        };
        if threads == 0 {
            run()
        } else {
            pool.install(run)
        }
    };
    let direct = factor(false, 2);
    assert_eq!(factor(true, 2), direct);
    assert_eq!(factor(true, 1), direct);
    assert_eq!(factor(true, 0), direct);

    // replaced while running: the new pattern's analysis is the one kept
    let small = elastic_cube_system(3).unwrap();
    let q = small.pattern.symbolic_owned();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| {
        let mut s = FaerDirect::default();
        s.analyse_in_background(cube.pattern.shared(), Symmetry::Symmetric).unwrap();
        s.analyse(q.as_ref(), Symmetry::Symmetric).unwrap();
        assert!(s.pending.is_none());
        assert_eq!(s.pattern().unwrap().nrows(), q.nrows());
        s.factor(small.assembly.values()).unwrap();
        assert_eq!(s.timings().n_symbolic, 2, "both analyses ran, and both are counted");
        let mut x = small.rhs.clone();
        s.solve_in_place(small.assembly.values(), &mut x).unwrap();
        assert!(residual_of(q, small.assembly.values(), &x, &small.rhs) < 1e-12);
    });
}

/// A caller that is worker 0 of its pool (the binaries' main thread:
/// `os::worker_pool`) gets its background analysis even when the pool's only other
/// worker is busy with something that ends only after the analysis is used: the
/// task then waits in the caller's own queue, and `factor` runs it while waiting
/// instead of blocking on a result nobody computes (without the yield in
/// `PendingAnalysis::wait` this test hangs, and fails at its timeout).
#[test]
fn a_worker_waiting_for_its_background_analysis_runs_it_when_no_other_worker_is_free() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let (done_tx, done_rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let cube = elastic_cube_system(4).unwrap();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).use_current_thread().build().unwrap();
        assert_eq!(rayon::current_thread_index(), Some(0), "this thread is worker 0");
        // the other worker, held until the factor exists
        let (held, release) = (Arc::new(AtomicBool::new(false)), Arc::new(AtomicBool::new(false)));
        let (h, r) = (Arc::clone(&held), Arc::clone(&release));
        pool.spawn(move || {
            h.store(true, Ordering::SeqCst);
            while !r.load(Ordering::SeqCst) {
                std::thread::yield_now();
            }
        });
        while !held.load(Ordering::SeqCst) {
            std::thread::yield_now();
        }
        let mut s = FaerDirect::new(FaerDirectOptions { par: Some(Par::Seq), ..Default::default() });
        s.analyse_in_background(cube.pattern.shared(), Symmetry::Symmetric).unwrap();
        assert!(s.pending.is_some(), "the analysis is a task of the pool");
        let method = s.factor(cube.assembly.values()).map(|info| info.method);
        release.store(true, Ordering::SeqCst);
        let _ = done_tx.send(method.map_err(|e| e.to_string()));
        drop(pool);
    });
    let method = done_rx.recv_timeout(std::time::Duration::from_secs(60)).expect("the analysis was never run: the waiting worker blocked");
    assert_eq!(method, Ok(Factorization::Llt));
}

fn single() -> FaerDirect {
    FaerDirect::new(FaerDirectOptions { precision: FactorPrecision::Single, ..Default::default() })
}

#[test]
fn a_single_precision_factor_is_a_preconditioner_in_any_unit_system() {
    let cube = elastic_cube_system(6).unwrap();
    let p = cube.pattern.symbolic_owned();
    let v = cube.assembly.values();
    let b = &cube.rhs;
    let (x64, _) = solve(&mut FaerDirect::default(), p, v, b, Symmetry::Symmetric);
    let norm = x64.iter().map(|x| x * x).sum::<f64>().sqrt();
    // the stiffness in any units: 1e±40 lies outside f32's range (1.2e-38 to
    // 3.4e38), so only the factorization's scale keeps these factors finite
    for units in [1.0, 1e40, 1e-40] {
        let v: Vec<f64> = v.iter().map(|a| a * units).collect();
        let mut s = single();
        let (x, method) = solve(&mut s, p, &v, b, Symmetry::Symmetric);
        assert_eq!(method, Factorization::Llt);
        assert!(!s.solves_exactly(), "a single-precision factor at units {units:e}");
        // f32's round-off 6e-8 times the cube's condition number (~1e3): not the
        // double factor's 1e-15, and good enough to precondition (GMRES gains about
        // three digits per iteration with it)
        let r = residual_of(p, &v, &x, b);
        assert!((1e-10..1e-3).contains(&r), "units {units:e}: residual {r:e}");
        let d = x.iter().zip(&x64).map(|(a, b)| (a * units - b).powi(2)).sum::<f64>().sqrt();
        assert!(d / norm < 1e-3, "units {units:e}: solution off by {:e}", d / norm);
        // half the factor's bytes
        assert!(s.l_values.is_empty() && s.l_values32.len() == s.factor_len());
        // the same matrix in double precision when asked: exact
        s.factor_in_double(&v).unwrap();
        assert!(s.solves_exactly() && s.l_values32.is_empty());
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        assert!(residual_of(p, &v, &x, b) < 1e-12);
    }
}

#[test]
fn a_factor_that_single_precision_cannot_hold_is_made_in_double() {
    // Pairs of dofs joined by a spring that nearly cancels their own,
    // [[1, 1 − δ], [1 − δ, 1]] with δ = 1e-6 (representable in f32: 17 ulps of 1):
    // symmetric positive definite, and the second pivot of each pair is
    // 1 − (1 − δ)² ≈ 2δ = 2e-6 of its diagonal entry, below SINGLE_PIVOT_FLOOR
    let n: usize = 3000;
    let delta = 1e-6;
    let (mut col_ptr, mut row_idx, mut v) = (vec![0], vec![], vec![]);
    for j in 0..n {
        let pair = j - j % 2;
        for i in pair..pair + 2 {
            row_idx.push(i);
            v.push(if i == j { 1.0 } else { 1.0 - delta });
        }
        col_ptr.push(row_idx.len());
    }
    let p = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    let b: Vec<f64> = (0..n).map(|i| ((i % 11) as f64 - 5.0) / 5.0).collect();
    let mut s = single();
    let (x, method) = solve(&mut s, &p, &v, &b, Symmetry::Symmetric);
    assert_eq!(method, Factorization::Llt);
    assert!(s.solves_exactly(), "a double-precision factor");
    // the double factor's operations, bit for bit
    let (x64, _) = solve(&mut FaerDirect::default(), &p, &v, &b, Symmetry::Symmetric);
    assert_eq!(x, x64);
    // and an indefinite matrix goes to LDLᵀ, in double, as without the option
    let (p, v) = {
        let d = saddle_point(40, 12);
        dense_to_csc(&d, |i, j| d[i][j] != 0.0)
    };
    let b: Vec<f64> = (0..p.nrows()).map(|i| (i % 5) as f64 - 2.0).collect();
    let mut s = single();
    let (x, method) = solve(&mut s, &p, &v, &b, Symmetry::Symmetric);
    assert_eq!(method, Factorization::Ldlt);
    assert!(s.solves_exactly());
    assert!(residual_of(&p, &v, &x, &b) < 1e-10);
}

/// `ordering: geometric` is the factorization's ordering when the unknowns'
/// positions are given: the same solution as METIS's to round-off, another factor
/// (its size is the geometric ordering's); without positions it is METIS's.
#[test]
fn the_geometric_ordering_orders_the_factorization_when_given_positions() {
    let n = 6;
    let cube = elastic_cube_system(n).unwrap();
    let (nodes, _) = crate::assembly::pattern::structured_hex_grid(n, n, n);
    let positions: Arc<[[f64; 3]]> = cube.pattern.dofs().global_of_free().iter().map(|&g| nodes[g as usize / 3]).collect();
    let p = cube.pattern.symbolic_owned();
    let v = cube.assembly.values();
    let b = &cube.rhs;
    let geometric = FaerDirectOptions { ordering: FillOrdering::Geometric, ..Default::default() };
    let mut metis = FaerDirect::default();
    let (x_metis, _) = solve(&mut metis, p, v, b, Symmetry::Symmetric);
    let mut with_positions = FaerDirect::new(geometric);
    with_positions.set_unknown_coordinates(positions.clone());
    let (x_geo, _) = solve(&mut with_positions, p, v, b, Symmetry::Symmetric);
    let norm = x_metis.iter().map(|v| v * v).sum::<f64>().sqrt();
    let d = x_geo.iter().zip(&x_metis).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
    assert!(d / norm < 1e-12, "solutions differ by {:e}", d / norm);
    let geometric_len = {
        let perm = crate::solver::ordering::geometric_dissection(p.as_ref(), &positions).unwrap();
        let o = faer::sparse::linalg::cholesky::SymmetricOrdering::Custom(PermRef::new_checked(&perm.forward, &perm.inverse, p.ncols()));
        factorize_symbolic_cholesky(p.as_ref(), Side::Lower, o, CholeskySymbolicParams::default()).unwrap().len_val()
    };
    assert_eq!(with_positions.factor_len(), geometric_len);
    assert_ne!(with_positions.factor_len(), metis.factor_len(), "the cube's two orderings fill differently (measured)");
    let mut without = FaerDirect::new(geometric);
    solve(&mut without, p, v, b, Symmetry::Symmetric);
    assert_eq!(without.factor_len(), metis.factor_len());
}
