//! sc-solve and the solve pipeline from the command line: results, .pvd read by
//! meshio, bad setups, and a stopped solve that keeps its converged increments.

use std::path::Path;

use crate::common::*;

fn write_setup(dir: &Path, text: &str) {
    std::fs::write(dir.join("setup.yaml"), text).unwrap();
}

fn imported_cantilever(dir: &Path) {
    let o = run("sc-import", &[repo().join("meshes/cantilever.msh").to_str().unwrap(), "-o", "c.scmesh", "-q"], dir);
    assert!(o.status.success(), "{}", stderr(&o));
}

const GOOD: &str = "materials: [{body: beam, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints: [{set: clamped, fix: [x, y, z]}]\nloads: [{set: tip, force: [0, 0, -1.0]}]\nincrements: {count: 5}\n";

/// The cantilever imported and solved with [`GOOD`] into `r.scres`, in a scratch
/// folder.
fn solved_cantilever() -> tempfile::TempDir {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), GOOD);
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    dir
}

fn solve_fails(setup: &str, needles: &[&str]) {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), setup);
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres"], dir.path());
    assert_fails(&o, 2, needles, &dir.path().join("r.scres"));
}

#[test]
fn unknown_set_is_named_with_the_available_ones() {
    solve_fails(&GOOD.replace("set: tip", "set: tipp"), &["setup.yaml", "node set 'tipp'", "tip", "clamped"]);
}

#[test]
fn missing_material_names_the_body() {
    solve_fails("materials: []\nconstraints: [{set: clamped, fix: [x, y, z]}]\n", &["setup.yaml", "body 'beam' has no material"]);
}

#[test]
fn negative_young_modulus() {
    solve_fails(&GOOD.replace("E: 1000.0", "E: -5.0"), &["setup.yaml", "beam", "-5"]);
}

#[test]
fn poisson_ratio_of_one_half() {
    solve_fails(&GOOD.replace("nu: 0.3", "nu: 0.5"), &["setup.yaml", "beam", "0.5"]);
}

#[test]
fn unknown_setup_key_names_key_and_line() {
    solve_fails(&GOOD.replace("increments: {count: 5}", "increments: {cuont: 5}"), &["setup.yaml", "cuont", "line 4"]);
}

/// A solve that cannot converge stops with exit code 3, says where, and the results
/// file holds every increment converged before.
#[test]
fn stopped_solve_keeps_converged_increments() {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(
        dir.path(),
        &GOOD.replace("increments: {count: 5}", "increments: {factors: [0.01, 1.0], max_cutbacks: 0}\nnewton: {max_iterations: 3}"),
    );
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("worst element: hexahedron") && err.contains("gmsh tag") && err.contains("solve stopped at increment 2") && err.contains("converged increments are in r.scres"), "{err}");
    let o = run("sc-export", &["r.scres", "--format", "yaml", "-o", "-"], dir.path());
    let yaml = String::from_utf8_lossy(&o.stdout);
    assert!(yaml.contains("stopped:") && yaml.contains("reason:"), "{yaml}");
    assert!(dir.path().join("r.convergence.csv").is_file());
}

/// The shipped cantilever pipeline: import, solve, export; meshio reads every step.
#[test]
fn cantilever_pipeline_results_open_in_meshio() {
    let dir = staged_pipeline("cantilever", &["cantilever.msh"]);
    let o = run("sc-pipeline", &["pipelines/cantilever.yaml"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let pvd = dir.path().join("pipelines/out/cantilever.pvd");
    let o = python_script("check_pvd.py", &[&pvd]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("\"steps\": 6"), "{out}");
    // Regression pin of the tip deflection (max |u_z|): 3.2044 for PL²/EI = 1.2 on this
    // 20x2x2 mesh (large deflection and hex8 locking both shorten it from the linear
    // 4.0). Newton converges to 1e-8, so 1e-4 relative catches any change of the solution.
    let uz: f64 = out.split("\"max_abs_u\": [").nth(1).unwrap().split(']').next().unwrap().split(", ").nth(2).unwrap().parse().unwrap();
    assert!((uz - 3.2044).abs() < 3.2044e-4, "tip deflection {uz}");
    let csv = std::fs::read_to_string(dir.path().join("pipelines/out/cantilever.convergence.csv")).unwrap();
    assert!(csv.starts_with("increment,load_factor,attempt,augmentation,iteration,residual,energy,contact_active,seconds_contact,seconds_assembly,seconds_factor,seconds_solve,krylov_iterations\n"));
    assert!(csv.lines().count() > 10);
}

/// `sc-solve --restart`: the stopped run above (increment 2 fails) continued with a
/// gentler load path, into its own results file. The file then holds the first
/// run's increment and the new ones and says where it was restarted from; the
/// convergence CSV starts with the restored iterations. The cantilever is elastic,
/// so the end state does not depend on the path: the tip deflection equals a direct
/// run's to 1e-6 relative (both converge the residual to 1e-8).
#[test]
fn restart_continues_a_stopped_solve_into_its_own_file() {
    use splinecontact::format::scres::{Results, RunStatus};
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), &GOOD.replace("increments: {count: 5}", "increments: {factors: [0.01, 1.0], max_cutbacks: 0}\nnewton: {max_iterations: 3}"));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "-q"], dir.path());
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    write_setup(dir.path(), GOOD);
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "--restart", "r.scres"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("restart from r.scres: 1 converged increments, continuing from load factor 0.010000 (5 of the setup's 5 increments left)"), "{err}");
    let r = Results::read(&dir.path().join("r.scres")).unwrap();
    assert_eq!(r.status, RunStatus::Completed);
    let factors: Vec<f64> = r.increments.iter().map(|i| i.info.load_factor).collect();
    assert_eq!(factors, [0.01, 0.2, 0.4, 0.6, 0.8, 1.0]);
    assert_eq!(r.restart.as_ref().map(|o| (o.file.as_str(), o.increments, o.load_factor)), Some(("r.scres", 1, 0.01)));
    let csv = std::fs::read_to_string(dir.path().join("r.convergence.csv")).unwrap();
    assert!(csv.lines().nth(1).is_some_and(|l| l.starts_with("1,1e-2,0,0,0,")), "the restored iterations open the CSV:\n{csv}");
    // the same setup from scratch
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "direct.scres", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let direct = Results::read(&dir.path().join("direct.scres")).unwrap();
    let tip = |r: &Results| r.increments.last().unwrap().u.iter().map(|u| u[2]).fold(0.0f64, |m, v| m.max(v.abs()));
    let (a, b) = (tip(&r), tip(&direct));
    assert!((a - b).abs() <= 1e-6 * b, "restarted tip deflection {a}, direct {b}");
    // nothing left: the finished run with the same setup
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "again.scres", "--restart", "r.scres"], dir.path());
    assert_fails(&o, 2, &["r.scres", "already reached load factor 1.000000", "nothing left to solve"], &dir.path().join("again.scres"));
    // killed after its last increment, before it marked itself completed: the
    // restart only writes the status, and the increments stay bit for bit
    let mut killed = r.clone();
    killed.status = RunStatus::Running;
    killed.write(&dir.path().join("killed.scres")).unwrap();
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "killed.scres", "--restart", "killed.scres"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("interrupted before it marked itself completed; this run marks it completed"), "{err}");
    let finished = Results::read(&dir.path().join("killed.scres")).unwrap();
    assert_eq!(finished.status, RunStatus::Completed);
    assert_eq!(finished.increments.len(), r.increments.len());
    let bits = |r: &Results| r.increments.iter().flat_map(|i| i.u.iter().flatten().map(|x| x.to_bits())).collect::<Vec<_>>();
    assert!(bits(&finished) == bits(&r), "the increments changed");
}

/// A restart file from another model, or not a results file: exit 2, the file named,
/// nothing written.
#[test]
fn restart_from_another_model_is_refused() {
    let dir = solved_cantilever();
    let o = run("sc-import", &[repo().join("meshes/parisch.msh").to_str().unwrap(), "-o", "p.scmesh", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run("sc-solve", &["p.scmesh", "--setup", "setup.yaml", "-o", "p.scres", "--restart", "r.scres"], dir.path());
    assert_fails(&o, 2, &["r.scres: cannot restart from it: its mesh has", "the model has 50"], &dir.path().join("p.scres"));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "x.scres", "--restart", "c.scmesh"], dir.path());
    assert_fails(&o, 2, &["c.scmesh", "'scmesh' file, but a 'scres' file is expected"], &dir.path().join("x.scres"));
}

/// The pipeline's `restart:` key (resolved beside the pipeline like every path): the
/// cantilever's pipeline continued to twice its load (`end: 2.0`), into a second
/// results file that opens with the first run's five increments.
#[test]
fn pipeline_solve_stage_restarts() {
    use splinecontact::format::scres::Results;
    let dir = staged_pipeline("cantilever", &["cantilever.msh"]);
    let first = std::fs::read_to_string(repo().join("pipelines/cantilever.yaml")).unwrap();
    let o = run("sc-pipeline", &["pipelines/cantilever.yaml", "-q"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let more = first
        .replace("increments: {count: 5, max_cutbacks: 5}", "increments: {count: 10, end: 2.0, max_cutbacks: 5}")
        .replace("output: out/cantilever.scres ", "restart: out/cantilever.scres\n      output: out/longer.scres ")
        .replace("input: out/cantilever.scres", "input: out/longer.scres")
        .replace("output: out/cantilever.pvd", "output: out/longer.pvd");
    assert!(more.contains("restart: out/cantilever.scres"), "{more}");
    std::fs::write(dir.path().join("pipelines/longer.yaml"), &more).unwrap();
    let o = run("sc-pipeline", &["pipelines/longer.yaml"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let r = Results::read(&dir.path().join("pipelines/out/longer.scres")).unwrap();
    let factors: Vec<f64> = r.increments.iter().map(|i| i.info.load_factor).collect();
    assert_eq!(factors.len(), 10, "{factors:?}");
    assert!((factors[4] - 1.0).abs() < 1e-12 && (factors[9] - 2.0).abs() < 1e-12, "{factors:?}");
    assert!(dir.path().join("pipelines/out/longer.pvd").is_file());
}

/// The results file grows by appending one segment per increment (scres 2.0): the
/// file a solve leaves is byte for byte the file written at once from what it holds.
/// A crash in an append leaves a partial last segment: simulated by cutting the file
/// inside its last increment, the file reads as the increments before (status
/// running), sc-export says what it left out, and a restart continues from there.
#[test]
fn results_file_appends_and_survives_a_cut_append() {
    use splinecontact::format::scres::{Results, RunStatus};
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), GOOD);
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("results: 5 increments,") && err.contains("MB written to r.scres in"), "{err}");
    let bytes = std::fs::read(dir.path().join("r.scres")).unwrap();
    let r = Results::read(&dir.path().join("r.scres")).unwrap();
    assert_eq!((r.increments.len(), &r.status, &r.tail), (5, &RunStatus::Completed, &None));
    assert!(r.encode() == bytes, "the appended file differs from the one written at once");
    // cut 1000 bytes before the end: the status segment (< 200 bytes) and the end
    // of increment 5's stress array
    std::fs::write(dir.path().join("cut.scres"), &bytes[..bytes.len() - 1000]).unwrap();
    let cut = Results::read(&dir.path().join("cut.scres")).unwrap();
    assert_eq!((cut.increments.len(), &cut.status), (4, &RunStatus::Running));
    assert!(cut.tail.as_deref().is_some_and(|t| t.contains("not a complete segment")), "{:?}", cut.tail);
    assert!(cut.increments.iter().zip(&r.increments).all(|(a, b)| a.u == b.u));
    let o = run("sc-export", &["cut.scres", "-o", "cut.pvd", "-q"], dir.path());
    assert!(o.status.success() && stderr(&o).contains("warning: cut.scres: the") && stderr(&o).contains("left out"), "{}", stderr(&o));
    // the library says it as a warning of its own, not inside the line of what it wrote
    use splinecontact::stages::export::export;
    let cut_export = export(&dir.path().join("cut.scres"), &dir.path().join("cut2.pvd"), None).unwrap();
    assert!(cut_export.warnings.len() == 1 && cut_export.warnings[0].contains("cut.scres: the"), "{cut_export:?}");
    assert!(!cut_export.written.contains("warning"), "{cut_export:?}");
    let whole_export = export(&dir.path().join("r.scres"), &dir.path().join("r.pvd"), None).unwrap();
    assert!(whole_export.warnings.is_empty(), "{whole_export:?}");
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "cut.scres", "--restart", "cut.scres", "-q"], dir.path());
    // the restart says what it left out, even when quiet
    assert!(o.status.success() && stderr(&o).starts_with("warning: cut.scres: the") && stderr(&o).contains("left out"), "{}", stderr(&o));
    let healed = Results::read(&dir.path().join("cut.scres")).unwrap();
    assert_eq!((healed.increments.len(), &healed.status, &healed.tail), (5, &RunStatus::Completed, &None));
}

/// `--restart-increment K`: back to an earlier increment of a finished run, redone
/// with finer increments into a new file (the later increments are not carried
/// over); the elastic end state equals the first run's to 1e-6. K outside the file,
/// or without --restart: exit 2, nothing written.
#[test]
fn restart_from_an_earlier_increment() {
    use splinecontact::format::scres::Results;
    let dir = solved_cantilever();
    write_setup(dir.path(), &GOOD.replace("increments: {count: 5}", "increments: {count: 10}"));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "redo.scres", "--restart", "r.scres", "--restart-increment", "2"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("restart from r.scres: 2 converged increments, continuing from load factor 0.400000 (6 of the setup's 10 increments left)"), "{err}");
    let (first, redo) = (Results::read(&dir.path().join("r.scres")).unwrap(), Results::read(&dir.path().join("redo.scres")).unwrap());
    let factors: Vec<f64> = redo.increments.iter().map(|i| i.info.load_factor).collect();
    assert_eq!(factors.len(), 8, "{factors:?}");
    assert!(factors.iter().zip([0.2, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]).all(|(a, b)| (a - b).abs() < 1e-12), "{factors:?}");
    assert_eq!(redo.restart.as_ref().map(|o| (o.increments, o.load_factor)), Some((2, 0.4)));
    let tip = |r: &Results| r.increments.last().unwrap().u.iter().map(|u| u[2]).fold(0.0f64, |m, v| m.max(v.abs()));
    assert!((tip(&redo) - tip(&first)).abs() <= 1e-6 * tip(&first), "{} vs {}", tip(&redo), tip(&first));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "x.scres", "--restart", "r.scres", "--restart-increment", "6"], dir.path());
    assert_fails(&o, 2, &["r.scres: cannot restart from it: it holds converged increments 1 to 5, not increment 6"], &dir.path().join("x.scres"));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "x.scres", "--restart-increment", "2"], dir.path());
    assert_fails(&o, 2, &["--restart"], &dir.path().join("x.scres"));
}

/// A build without the PETSc backend says how to get it when a setup asks for it,
/// before anything is written.
#[cfg(not(feature = "petsc"))]
#[test]
fn petsc_in_a_build_without_it_says_how_to_build_it() {
    solve_fails(&format!("{GOOD}linear_solver: petsc\n"), &["linear_solver: petsc", "--features petsc"]);
}

/// Started by mpirun with two ranks (the launcher's environment, as Open MPI sets
/// it), a build without PETSc says on rank 0 that it runs serially and solves there;
/// rank 1 stops at once and writes nothing.
#[cfg(not(feature = "petsc"))]
#[test]
fn under_mpirun_a_build_without_petsc_runs_serially_on_rank_0() {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), GOOD);
    let exe = env!("CARGO_BIN_EXE_sc-solve");
    let launch = |rank: &str, out: &str| {
        std::process::Command::new(exe)
            .args(["c.scmesh", "--setup", "setup.yaml", "-o", out, "-q"])
            .current_dir(dir.path())
            .env("OMPI_COMM_WORLD_RANK", rank)
            .env("OMPI_COMM_WORLD_SIZE", "2")
            .output()
            .unwrap()
    };
    let o = launch("0", "r0.scres");
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("2 ranks") && err.contains("runs serially on rank 0") && err.contains("--features petsc"), "{err}");
    assert!(dir.path().join("r0.scres").exists());
    let o = launch("1", "r1.scres");
    assert!(o.status.success() && stderr(&o).is_empty(), "{}", stderr(&o));
    assert!(!dir.path().join("r1.scres").exists());
}

/// PETSc options given to a solve that does not use PETSc are not silently dropped:
/// the run says they are ignored (a warning, also under -q) and solves.
#[test]
fn petsc_options_without_the_petsc_solver_are_reported_as_ignored() {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), &format!("{GOOD}linear_solver: direct\n"));
    let o = run("sc-solve", &["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "-q", "--petsc-options", "-ksp_monitor"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("warning: PETSc options are given") && err.contains("they are ignored"), "{err}");
}

/// A model whose factorization does not fit in the memory there is stops before
/// the factorization, with an estimate, writing nothing (the memory is `SC_MEMORY_LIMIT`
/// here: a real machine too small for the test's model would need gigabytes).
#[test]
fn a_model_too_large_for_memory_fails_before_factorization_with_an_estimate() {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), GOOD);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sc-solve"))
        .args(["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres"])
        .current_dir(dir.path())
        .env("SC_MEMORY_LIMIT", "64K")
        .output()
        .unwrap();
    assert_fails(&o, 2, &["too large for this machine's memory", "unknowns holds", "needs about", "64 KiB are available (SC_MEMORY_LIMIT)"], &dir.path().join("r.scres"));
    let err = stderr(&o);
    assert!(!err.contains("increment 1/"), "the solve started increments: {err}");
    // with the memory there is, the same solve runs
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sc-solve"))
        .args(["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "-q"])
        .current_dir(dir.path())
        .env("SC_MEMORY_LIMIT", "1G")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `SC_TIMELINE=1` prints every phase of the run once it ends, each with a start
/// no later than its end, in the order the phases started; without it nothing of
/// the kind is printed.
#[test]
fn the_timeline_lists_the_phases_of_a_run_in_order() {
    let dir = tempdir();
    imported_cantilever(dir.path());
    write_setup(dir.path(), GOOD);
    let solve = |timeline: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_sc-solve"))
            .args(["c.scmesh", "--setup", "setup.yaml", "-o", "r.scres", "-q"])
            .current_dir(dir.path())
            .env("SC_TIMELINE", timeline)
            .output()
            .unwrap()
    };
    let t = std::time::Instant::now();
    let o = solve("1");
    let wall_ms = 1e3 * t.elapsed().as_secs_f64();
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().skip_while(|l| !l.starts_with("timeline (ms since main started)")).skip(1).collect();
    for phase in ["read the setup", "read the model", "set-up: sparsity pattern", "analysis: fill-reducing ordering", "assembly: residual and tangent", "linear solver: factor", "linear solver: solve", "write results and histories"] {
        assert!(lines.iter().any(|l| l.ends_with(phase)), "no '{phase}' in the timeline:\n{err}");
    }
    let mut last_start = 0.0;
    for l in &lines {
        let f: Vec<f64> = l.split_whitespace().take(3).map(|v| v.parse().unwrap_or_else(|_| panic!("not a number in '{l}'"))).collect();
        let (start, end, length) = (f[0], f[1], f[2]);
        assert!(start >= last_start && end >= start, "out of order: '{l}'");
        // the printed length is end − start, each rounded to 0.01 ms
        assert!((end - start - length).abs() <= 0.011, "'{l}'");
        last_start = start;
    }
    // 5 increments of a cantilever: a factorization in each
    assert!(lines.iter().filter(|l| l.ends_with("linear solver: factor")).count() >= 5, "{err}");
    // the clock is one for every thread: the first factorization starts after the
    // first tangent it factors is assembled, and nothing ends after the process did
    let span = |phase: &str| -> (f64, f64) {
        let l = lines.iter().find(|l| l.ends_with(phase)).unwrap();
        let f: Vec<f64> = l.split_whitespace().take(2).map(|v| v.parse().unwrap()).collect();
        (f[0], f[1])
    };
    assert!(span("linear solver: factor").0 >= span("assembly: residual and tangent").1, "{err}");
    let last_end = lines.iter().map(|l| l.split_whitespace().nth(1).unwrap().parse::<f64>().unwrap()).fold(0.0, f64::max);
    assert!(last_end > 0.0 && last_end <= wall_ms, "the timeline ends at {last_end} ms, the process took {wall_ms} ms");
    let o = solve("0");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("timeline"), "{}", stderr(&o));
}
