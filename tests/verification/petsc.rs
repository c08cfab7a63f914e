//! The PETSc backend (`--features petsc`; `./test.sh` runs these in a second build
//! when PETSc and Open MPI are installed) against faer's direct solvers on the
//! frictional crossed beams (n = 4: 4 × 4 × 60 hex8 per beam, 8,925 free dofs, the
//! mesh of `docs/scripts/ccx_compare.py`), on one MPI rank and on two.

use std::path::{Path, PathBuf};
use std::process::Command;

use splinecontact::format::scres::{Results, RunStatus};

use crate::common::{python, repo, stderr};

/// The level-4 crossed beams, meshed, tagged and solved by the direct solver through
/// ccx_compare.py (without ccx): its folder, model and setup.
fn crossed_beams_level_4(out: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_sc-solve")).parent().unwrap();
    let o = Command::new(python())
        .arg(repo().join("docs/scripts/ccx_compare.py"))
        .args(["crossed_beams", "--levels", "4", "--no-ccx", "--linear-solver", "direct", "--json", "--out"])
        .arg(out)
        .env("SC_BIN_DIR", bin_dir)
        .output()
        .expect("python runs");
    assert!(o.status.success(), "ccx_compare.py: {}", stderr(&o));
    let dir = out.join("crossed_beams_L4");
    (dir.clone(), dir.join("crossed_beams_L4.sccontact"), dir.join("crossed_beams_L4.setup.yaml"))
}

/// The setup with `linear_solver` replaced.
fn with_linear_solver(setup: &Path, linear_solver: &str, out: &Path) {
    let text = std::fs::read_to_string(setup).unwrap();
    let kept: Vec<&str> = text.lines().take_while(|l| !l.starts_with("linear_solver")).collect();
    std::fs::write(out, format!("{}\nlinear_solver: {linear_solver}\n", kept.join("\n"))).unwrap();
}

fn solve(dir: &Path, mpi_ranks: Option<usize>, setup: &str, out: &str, extra: &[&str]) -> std::process::Output {
    let exe = env!("CARGO_BIN_EXE_sc-solve");
    let mut c = match mpi_ranks {
        None => Command::new(exe),
        Some(np) => {
            // a rank that waits for a collective the other never calls would hang the
            // test: stop it (the whole run takes seconds)
            let mut c = Command::new("timeout");
            c.args(["300", "mpirun", "-np", &np.to_string(), "--oversubscribe", exe]);
            c
        }
    };
    c.args(["crossed_beams_L4.sccontact", "--setup", setup, "-o", out]).args(extra).current_dir(dir);
    // Open MPI refuses root unless told (CI runs as root); one thread per rank
    c.env("OMPI_ALLOW_RUN_AS_ROOT", "1").env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1").env("RAYON_NUM_THREADS", "1");
    c.output().expect("sc-solve runs")
}

/// Largest |Δu| between two runs' last increments, over their largest |u|.
fn difference(a: &Results, b: &Results) -> f64 {
    let (ua, ub) = (&a.increments.last().unwrap().u, &b.increments.last().unwrap().u);
    let norm = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let max_u = ua.iter().map(norm).fold(0.0, f64::max);
    let diff = ua.iter().zip(ub).map(|(x, y)| norm(&[x[0] - y[0], x[1] - y[1], x[2] - y[2]])).fold(0.0, f64::max);
    diff / max_u
}

fn corrections(r: &Results) -> usize {
    r.increments.iter().map(|i| i.info.iterations.len() - 1).sum()
}

/// "N Krylov iterations (x per solve)" of the solver line of the log.
fn krylov_per_solve(log: &str) -> f64 {
    let line = log.lines().find(|l| l.starts_with("linear solver petsc-gamg:")).unwrap_or_else(|| panic!("no solver line:\n{log}"));
    let at = line.find("Krylov iterations (").unwrap() + "Krylov iterations (".len();
    line[at..].split_whitespace().next().unwrap().parse().unwrap()
}

/// GAMG on one rank and on two gives the direct solver's answer: both Newton loops
/// stop at a relative residual of 1e-8 with the same augmented-Lagrangian updates, so
/// the displacements agree to about 1e-8 of max |u| (measured 1e-12 on one rank);
/// 1e-6 leaves the round-off of a different preconditioner room while a wrong dof
/// mapping, a lost constrained row or a rank that inserted the wrong rows is off by
/// O(1).
///
/// Newton corrections: with every Krylov solve converged (`inexact_newton: false`)
/// PETSc's tangent solves are the direct solver's, and Newton takes as many
/// corrections (measured 23 against 24; ±2 allowed: a solve at 1e-10 rather than at
/// round-off can tip one contact state at a switch). With the inexact Newton's
/// forcing terms (docs/theory/solver.md, "Inexact Newton") the first solve of each
/// Newton loop stops at 1e-3, and the contact states can switch an iteration later
/// than after the faer GMRES solves (4 iterations per solve, each one reducing the
/// residual by orders of magnitude, so the same η is overshot): measured 28
/// against 24; at most 1.25× the direct count allowed. Krylov iterations per solve:
/// 33 (1 rank) measured; AMG that lost its near-null space needs 3–5× more, so at
/// most 60 (exact solves: 57 measured, at most 90).
#[test]
fn gamg_gives_the_direct_answer_on_one_rank_and_on_two() {
    let out = tempfile::tempdir().unwrap();
    let (dir, _model, setup) = crossed_beams_level_4(out.path());
    let direct = Results::read(&dir.join("crossed_beams_L4.scres")).unwrap();
    assert_eq!(direct.status, RunStatus::Completed);
    with_linear_solver(&setup, "petsc", &dir.join("petsc.yaml"));

    let o = solve(&dir, None, "petsc.yaml", "one.scres", &[]);
    let log = stderr(&o);
    assert!(o.status.success(), "{log}");
    let one = Results::read(&dir.join("one.scres")).unwrap();
    assert_eq!(one.status, RunStatus::Completed);
    let d1 = difference(&direct, &one);
    assert!(d1 <= 1e-6, "1 rank: max |Δu| / max |u| = {d1:e}");
    assert!(4 * corrections(&one) <= 5 * corrections(&direct), "{} against {}", corrections(&one), corrections(&direct));
    let k1 = krylov_per_solve(&log);
    assert!(k1 > 1.0 && k1 <= 60.0, "{k1} Krylov iterations per solve");
    with_linear_solver(&setup, "{method: petsc, inexact_newton: false}", &dir.join("exact.yaml"));
    let o = solve(&dir, None, "exact.yaml", "exact.scres", &[]);
    let exact_log = stderr(&o);
    assert!(o.status.success(), "{exact_log}");
    let exact = Results::read(&dir.join("exact.scres")).unwrap();
    assert!(difference(&direct, &exact) <= 1e-6);
    assert!(corrections(&exact).abs_diff(corrections(&direct)) <= 2, "exact solves: {} against {}", corrections(&exact), corrections(&direct));
    let k_exact = krylov_per_solve(&exact_log);
    assert!(k_exact > k1 && k_exact <= 90.0, "{k_exact} Krylov iterations per exact solve");
    // the convergence CSV carries each solve's Krylov iterations: they add up to the
    // log's total
    let csv = std::fs::read_to_string(dir.join("one.convergence.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "krylov_iterations").expect("krylov_iterations column");
    let sum: u64 = csv.lines().skip(1).map(|l| l.split(',').nth(col).unwrap().parse::<u64>().unwrap()).sum();
    let line = log.lines().find(|l| l.starts_with("linear solver petsc-gamg:")).unwrap();
    let total: u64 = line.split(" Krylov iterations").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    assert_eq!(sum, total, "{line}");

    let o = solve(&dir, Some(2), "petsc.yaml", "two.scres", &[]);
    let log = stderr(&o);
    assert!(o.status.success(), "{log}");
    // rank 0 speaks for both: one header, one summary; each rank assembled its share
    assert_eq!(log.matches("MPI: 2 ranks").count(), 1, "{log}");
    assert!(log.contains("nonzeros on rank 0"), "{log}");
    assert_eq!(log.matches("solved: 3 increments").count(), 1, "{log}");
    let two = Results::read(&dir.join("two.scres")).unwrap();
    let d2 = difference(&one, &two);
    assert!(d2 <= 1e-6, "2 ranks against 1: max |Δu| / max |u| = {d2:e}");
    assert!(4 * corrections(&two) <= 5 * corrections(&direct), "2 ranks: {} against {}", corrections(&two), corrections(&direct));
    let k2 = krylov_per_solve(&log);
    assert!(k2 > 1.0 && k2 <= 60.0, "{k2} Krylov iterations per solve on 2 ranks");
    // both wrote the same model: the friction history of the last increment agrees
    let (f1, f2) = (&one.increments.last().unwrap().friction, &two.increments.last().unwrap().friction);
    assert_eq!(f1.len(), f2.len());
}

/// PETSc options from the command line reach PETSc (BiCGStab instead of GMRES gives
/// the same answer), and a bad one is an error that names PETSc's function, before
/// anything is written.
#[test]
fn petsc_options_reach_petsc_and_a_bad_one_names_the_function() {
    let out = tempfile::tempdir().unwrap();
    let (dir, _model, setup) = crossed_beams_level_4(out.path());
    with_linear_solver(&setup, "{method: petsc, petsc: {options: -ksp_type bcgs}}", &dir.join("bcgs.yaml"));
    let o = solve(&dir, None, "bcgs.yaml", "bcgs.scres", &["--petsc-options", "-ksp_converged_reason"]);
    let log = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr(&o);
    assert!(o.status.success(), "{log}");
    // -ksp_converged_reason prints PETSc's own line per solve, naming the method
    assert!(log.contains("Linear solve converged due to"), "{log}");
    let direct = Results::read(&dir.join("crossed_beams_L4.scres")).unwrap();
    let bcgs = Results::read(&dir.join("bcgs.scres")).unwrap();
    assert!(difference(&direct, &bcgs) <= 1e-6);

    let o = solve(&dir, None, "bcgs.yaml", "bad.scres", &["--petsc-options", "-pc_type no_such_preconditioner"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("PETSc KSPSetFromOptions failed"), "{err}");
    assert!(!dir.join("bad.scres").exists());
}
