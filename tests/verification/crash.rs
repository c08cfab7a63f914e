//! Crash consistency: a killed run loses at most the increment that was running.
//!
//! The model is the shipped frictional crossed beams (`pipelines/crossed_beams.yaml`:
//! augmented Lagrangian, Coulomb friction, GMRES), its load path cut into 30
//! increments so that a run takes about a second. `sc-solve` runs it once to the
//! end, then again and again, each time killed with SIGKILL at another moment
//! spread over the run (before the first increment, inside increments, inside the
//! appends of the results file). After each kill:
//! - the `.scres` either does not exist (killed before the first increment
//!   converged) or is read, and its increments are the uninterrupted run's first
//!   ones, bit for bit, at least as many as the run had reported converged on its
//!   standard error (it reports an increment after its segment is synced);
//! - a restart from it into the same file completes, and every increment of the
//!   completed file is the uninterrupted run's bit for bit (GMRES included: each
//!   increment factors its preconditioner afresh, as a restart does).
//!
//! A timed kill lands inside an append only by chance, so the middle of a write is
//! also covered exactly: the solver's fault injection (`SC_FAULT_KILL_IN_APPEND`)
//! SIGKILLs it inside chosen appends, and the uninterrupted file cut at bytes
//! inside every increment's segment (what a kill in `write` leaves) reads as the
//! increments before the cut; restarts complete from them.
//!
//! `sc-import`, `sc-tag` and `sc-export` write through a temporary file renamed
//! onto the target: killed at any moment, their output is absent or complete. A
//! kill between writing and renaming leaves the hidden temporary
//! (`.<name>.<pid>.tmp`, which no stage reads); the next write of that output
//! removes it.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use splinecontact::format::scres::Results;

use crate::common::*;

const INCREMENTS: usize = 30;

/// Stage the crossed beams model (import and tag by the shipped pipeline) and a
/// solve setup with a load path of [`INCREMENTS`] steps; returns (dir, model, setup).
fn model() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = staged_pipeline("crossed_beams", &["crossed_beams.msh"]);
    let o = Command::new(env!("CARGO_BIN_EXE_sc-pipeline")).args(["pipelines/crossed_beams.yaml", "-q"]).current_dir(dir.path()).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let yaml = std::fs::read_to_string(dir.path().join("pipelines/crossed_beams.yaml")).unwrap();
    let setup: String = yaml
        .lines()
        .skip_while(|l| l.trim() != "setup:")
        .skip(1)
        .take_while(|l| l.starts_with("        "))
        .map(|l| format!("{}\n", &l[8..]))
        .collect();
    assert!(setup.contains("increments: {count: 3"), "setup not found in the pipeline:\n{setup}");
    let setup = setup.replace("increments: {count: 3,", &format!("increments: {{count: {INCREMENTS},"));
    let setup_path = dir.path().join("long.yaml");
    std::fs::write(&setup_path, setup).unwrap();
    let model = dir.path().join("pipelines/out/crossed_beams.sccontact");
    (dir, model, setup_path)
}

fn solve(dir: &Path, model: &Path, setup: &Path, out: &str, restart: bool) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sc-solve"));
    c.arg(model).arg("--setup").arg(setup).args(["-o", out]).current_dir(dir).env("SC_REPRODUCIBLE", "1");
    if restart {
        c.args(["--restart", out]);
    }
    c
}

/// Largest |u_a − u_b| over the last increments, relative to max |u_b|.
fn final_difference(a: &Results, b: &Results) -> f64 {
    let (ua, ub) = (&a.increments.last().unwrap().u, &b.increments.last().unwrap().u);
    assert_eq!(ua.len(), ub.len());
    let scale = ub.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    ua.iter().flatten().zip(ub.iter().flatten()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// The bits of every number of an increment's state (NaN marks unused slots of
/// the contact state, so `==` on f64 would not do).
fn state_bits(i: &splinecontact::format::scres::Increment) -> Vec<u64> {
    let mut v = vec![i.info.load_factor.to_bits()];
    v.extend(i.u.iter().flatten().map(|x| x.to_bits()));
    v.extend(i.stress.iter().flatten().flatten().map(|x| x.to_bits()));
    v.extend(i.contact.iter().flatten().flatten().map(|x| x.to_bits()));
    v.extend(i.friction.iter().flatten().flatten().map(|x| x.to_bits()));
    v
}

/// The increments of `r` are the first ones of `full`, bit for bit.
fn assert_prefix(r: &Results, full: &Results, what: &str) {
    assert!(r.increments.len() <= full.increments.len(), "{what}: more increments than the full run");
    for (k, (a, b)) in r.increments.iter().zip(&full.increments).enumerate() {
        assert!(state_bits(a) == state_bits(b), "{what}: increment {k} differs from the uninterrupted run's");
    }
}

/// Restart `out` (in `dir`) into itself; the completed run is the uninterrupted
/// one bit for bit, every increment (each increment starts without a kept
/// preconditioner, as a restart does: `LinearSolver::begin_increment`). Returns the
/// final difference in max |u| (0).
fn restart_completes(dir: &Path, model: &Path, setup: &Path, out: &str, full: &Results) -> f64 {
    let o = solve(dir, model, setup, out, true).arg("-q").output().unwrap();
    assert!(o.status.success(), "restart from {out} failed: {}", stderr(&o));
    let r = Results::read(&dir.join(out)).unwrap();
    assert_eq!(r.status, splinecontact::format::scres::RunStatus::Completed);
    assert_eq!(r.increments.len(), full.increments.len(), "{out}");
    let d = final_difference(&r, full);
    assert_prefix(&r, full, &format!("{out} restarted (final difference {d:e} of max |u|)"));
    d
}

#[test]
fn a_killed_solve_keeps_its_increments_and_restarts_to_the_same_end() {
    let (dir, model, setup) = model();
    let d = dir.path();
    let start = Instant::now();
    let o = solve(d, &model, &setup, "full.scres", false).arg("-q").output().unwrap();
    let t_full = start.elapsed();
    assert!(o.status.success(), "{}", stderr(&o));
    let full = Results::read(&d.join("full.scres")).unwrap();
    assert!(full.increments.len() >= INCREMENTS, "{} increments", full.increments.len());

    const KILLS: usize = 24;
    let (mut absent, mut with_tail, mut worst) = (0, 0, 0.0f64);
    let mut kept = Vec::new();
    for i in 0..KILLS {
        let out = format!("killed{i}.scres");
        // spread over the run, from before the start to its end, plus a little jitter
        let at = t_full.mul_f64((i as f64 + 0.37 * ((i * 7 % 5) as f64 / 5.0)) / KILLS as f64 * 1.1);
        let mut child = solve(d, &model, &setup, &out, false).stderr(Stdio::piped()).spawn().unwrap();
        let mut err = child.stderr.take().unwrap();
        let reader = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            s
        });
        std::thread::sleep(at);
        let _ = child.kill(); // SIGKILL
        let status = child.wait().unwrap();
        let log = reader.join().unwrap();
        let reported = log.lines().filter(|l| l.contains("converged at load factor")).count();
        let path = d.join(&out);
        if !path.exists() {
            assert_eq!(reported, 0, "kill {i}: no results file, but {reported} increments were reported");
            absent += 1;
            continue;
        }
        let r = Results::read(&path).unwrap_or_else(|e| panic!("kill {i} ({at:?}, {status}): unreadable: {e}"));
        assert!(r.increments.len() >= reported, "kill {i}: {} increments on disk, {reported} reported", r.increments.len());
        assert_prefix(&r, &full, &format!("kill {i}"));
        with_tail += r.tail.is_some() as usize;
        kept.push(r.increments.len());
        if r.status == splinecontact::format::scres::RunStatus::Completed {
            continue;
        }
        worst = worst.max(restart_completes(d, &model, &setup, &out, &full));
    }
    eprintln!(
        "{KILLS} kills over {t_full:?}: {absent} before the first increment, increments kept {kept:?}, {with_tail} with a partial last segment; restarts end within {worst:.2e} of max |u|"
    );
    assert!(kept.iter().any(|&k| k > 0 && k < full.increments.len()), "no kill landed inside the run: {kept:?}");
}

/// What a kill inside `write` leaves: the file cut inside an increment's segment.
/// Every cut reads as the increments before it; restarts complete from some.
#[test]
fn a_results_file_cut_inside_any_increment_reads_and_restarts() {
    let (dir, model, setup) = model();
    let d = dir.path();
    let o = solve(d, &model, &setup, "full.scres", false).arg("-q").output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(d.join("full.scres")).unwrap();
    let full = Results::read(&d.join("full.scres")).unwrap();
    // where each increment's segment starts: the file is rewritten from the
    // increments' encodings, so cut at fractions of each segment instead
    let ends: Vec<usize> = {
        let mut v = Vec::new();
        let mut i = 0;
        while let Some(k) = bytes[i..].windows(4).position(|w| w == b"END!") {
            v.push(i + k + 20);
            i += k + 20;
        }
        v
    };
    assert!(ends.len() >= INCREMENTS + 2, "{} segments", ends.len());
    let mut cuts = 0;
    let mut worst = 0.0f64;
    for (s, w) in ends.windows(2).enumerate() {
        for frac in [0.0, 0.01, 0.5, 0.99] {
            let cut = w[0] + 1 + ((w[1] - w[0] - 2) as f64 * frac) as usize;
            let name = format!("cut{s}_{}.scres", (frac * 100.0) as u32);
            std::fs::write(d.join(&name), &bytes[..cut]).unwrap();
            let r = Results::read(&d.join(&name)).unwrap_or_else(|e| panic!("cut at {cut}: {e}"));
            assert!(r.tail.is_some(), "cut at {cut}: the partial segment is not reported");
            // segment 0 is the run; segment s + 1 holds increment s (or the status)
            assert_eq!(r.increments.len(), s.min(full.increments.len()), "cut at {cut}");
            assert_prefix(&r, &full, &format!("cut at {cut}"));
            cuts += 1;
            if frac == 0.5 && s % 10 == 3 {
                worst = worst.max(restart_completes(d, &model, &setup, &name, &full));
            }
        }
    }
    eprintln!("{cuts} cuts inside {} segments read back; restarts from 3 of them end within {worst:.2e} of max |u|", ends.len() - 1);
}

/// A real SIGKILL inside an append, at its start, middle and end, early and late in
/// the run (`SC_FAULT_KILL_IN_APPEND=K:F`: the K-th append writes the fraction F of
/// its bytes, syncs and kills its process). The file reads as the increments
/// before that append, reports the partial segment, and a restart completes.
#[test]
fn a_kill_inside_an_append_keeps_the_increments_before_it() {
    use std::os::unix::process::ExitStatusExt;
    let (dir, model, setup) = model();
    let d = dir.path();
    let o = solve(d, &model, &setup, "full.scres", false).arg("-q").output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let full = Results::read(&d.join("full.scres")).unwrap();
    let mut worst = 0.0f64;
    for (k, f) in [(1, 0.5), (2, 0.0), (7, 0.99), (15, 0.5), (29, 0.01)] {
        let out = format!("append{k}_{}.scres", (f * 100.0) as u32);
        let o = solve(d, &model, &setup, &out, false).arg("-q").env("SC_FAULT_KILL_IN_APPEND", format!("{k}:{f}")).output().unwrap();
        // SIGKILL, or SIGABRT where no `kill` tool exists: either stops the process dead
        assert!(matches!(o.status.signal(), Some(9) | Some(6)), "append {k}: not killed: {:?} {}", o.status, stderr(&o));
        let r = Results::read(&d.join(&out)).unwrap_or_else(|e| panic!("append {k} at {f}: unreadable: {e}"));
        // the first write holds increment 1; append k adds increment k + 1
        assert_eq!(r.increments.len(), k, "append {k} at {f}");
        // nothing of the segment written (F = 0) leaves a whole file, one increment short
        assert_eq!(r.tail.is_some(), f > 0.0, "append {k} at {f}: partial segment {:?}", r.tail);
        assert_prefix(&r, &full, &format!("append {k} at {f}"));
        worst = worst.max(restart_completes(d, &model, &setup, &out, &full));
    }
    eprintln!("5 kills inside appends; restarts end within {worst:.2e} of max |u|");
}

/// A killed `sc-import`, `sc-tag` or `sc-export` leaves no output, or a complete one.
#[test]
fn killed_stages_leave_no_partial_output() {
    let dir = staged_meshes(&["hertz.msh", "crossed_beams.msh"]);
    let d = dir.path();
    let o = run("sc-import", &["meshes/crossed_beams.msh", "-o", "cb.scmesh", "-q"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    let pair = "contact:upper_bottom:lower_top:bspline:3:3";
    let o = run("sc-tag", &["cb.scmesh", "-o", "cb.sccontact", "--pair", pair, "-q"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    let tag_args = vec!["cb.scmesh", "-o", "t.sccontact", "--pair", pair, "-q"];
    let cases: [(&str, Vec<&str>, &str); 3] = [
        ("sc-import", vec!["meshes/hertz.msh", "-o", "t.scmesh", "-q"], "t.scmesh"),
        ("sc-tag", tag_args, "t.sccontact"),
        ("sc-export", vec!["cb.sccontact", "--format", "yaml", "-o", "t.yaml", "-q"], "t.yaml"),
    ];
    for (bin, args, out) in &cases {
        let exe = match *bin {
            "sc-import" => env!("CARGO_BIN_EXE_sc-import"),
            "sc-tag" => env!("CARGO_BIN_EXE_sc-tag"),
            _ => env!("CARGO_BIN_EXE_sc-export"),
        };
        let start = Instant::now();
        assert!(Command::new(exe).args(args).current_dir(d).status().unwrap().success());
        let t = start.elapsed();
        let complete = std::fs::read(d.join(out)).unwrap();
        let (mut none, mut whole) = (0, 0);
        for i in 0..20 {
            std::fs::remove_file(d.join(out)).ok();
            let mut child = Command::new(exe).args(args).current_dir(d).stderr(Stdio::null()).spawn().unwrap();
            std::thread::sleep(t.mul_f64(i as f64 / 16.0));
            let _ = child.kill();
            let _ = child.wait();
            match std::fs::read(d.join(out)) {
                Err(_) => none += 1,
                Ok(b) => {
                    assert_eq!(b, complete, "{bin} killed after {:?} left a partial {out}", t.mul_f64(i as f64 / 16.0));
                    whole += 1;
                }
            }
        }
        // killed between its write and its rename, a stage leaves its hidden
        // temporary (`.<name>.<pid>.tmp`), which no stage reads
        let temps = std::fs::read_dir(d).unwrap().filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().ends_with(".tmp")).count();
        // the next run removes them (their processes are gone)
        assert!(Command::new(exe).args(args).current_dir(d).status().unwrap().success());
        let left = std::fs::read_dir(d).unwrap().filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().ends_with(".tmp")).count();
        assert_eq!(left, 0, "{bin}: the temporaries of killed runs survived the next run");
        eprintln!("{bin}: 20 kills over {t:?}: {none} left no {out}, {whole} a complete one; {temps} hidden temporaries, removed by the next run");
    }
}
