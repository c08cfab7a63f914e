//! Load stepping: the load factors of the setup, one Newton solve each; a failed
//! increment (no convergence, divergence, an inverted element) is cut back — the step
//! halved — up to `max_cutbacks` times in a row, then the solve stops. Every
//! converged increment is written to the results file as soon as it converges, so a
//! stopped run keeps all of them on disk.

#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use crate::os::timeline;
use std::path::Path;
use std::time::Instant;

use super::log::{IterationEvent, SolveLog};
use super::newton::{gauss_stresses, IncrementFailure, Newton, SetupFailure};
use super::uzawa::solve_augmented;
use crate::contact::pair::SlaveStatus;
use crate::format::sccontact::MasterKind;
use crate::format::scres::{FrictionSummary, PairSummary};
use crate::contact::settings::Enforcement;
use super::problem::Problem;
use super::restart::factors_done;
use crate::assembly::DOFS_PER_NODE;
use crate::fem::element::hex8_min_jacobian;
use crate::format::scres::{Increment, IncrementInfo, Reaction, Results, ResultsFile, RunStatus};
use crate::format::stage::{prepare_unsynced, write_atomic_unsynced, Prepared, StageError};

/// The solve stopped.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error("solve stopped at increment {increment} (load factor {load_factor:.6}, last converged {last_converged:.6}) after {cutbacks} cutbacks: {failure}{worst}; the {kept} converged increments are in {results}{hint}")]
    Diverged {
        increment: usize,
        load_factor: f64,
        last_converged: f64,
        cutbacks: u32,
        failure: IncrementFailure,
        worst: String,
        kept: usize,
        results: String,
        /// What to try, when there is something specific (a facet master without
        /// the stabilisation).
        hint: String,
    },
    #[error(transparent)]
    Write(#[from] StageError),
    /// The solver's setup failed when it was completed (the first analysis).
    #[error(transparent)]
    Setup(#[from] SetupFailure),
    #[error("{file}: resuming from its increment at load factor {load_factor:.6}: {failure}")]
    Resume { file: String, load_factor: f64, failure: IncrementFailure },
}

/// What a finished solve reports.
pub struct SolveSummary {
    pub increments: usize,
    pub iterations: usize,
    pub cutbacks: u32,
    /// Writing the results file: seconds (encode, write, sync).
    pub write_seconds: f64,
}

/// Where the results go.
pub struct Outputs<'a> {
    pub results: &'a Path,
    /// Convergence history (one row per Newton iteration).
    pub csv: Option<&'a Path>,
    /// Force history (one row per converged increment): reactions and contact forces.
    pub forces_csv: Option<&'a Path>,
    /// Whether this process writes them: false on every MPI rank but the first.
    pub writer: bool,
}

/// The force history of the converged increments as CSV: load factor, the reaction
/// of every constrained set (x, y, z), and per contact pair the force the master
/// exerts on the slave body, its tangential part, the active / sticking / sliding
/// nodes and the Uzawa updates — the curves a user plots (e.g. an indenter's
/// vertical and horizontal force against its travel).
pub fn forces_csv(results: &Results) -> String {
    let mut out = String::from("increment,load_factor");
    let first = results.increments.first();
    // one column triple per set (a set constrained by two entries, e.g. a press and a
    // slide, is listed once)
    let mut sets: Vec<String> = Vec::new();
    for r in first.map(|i| &i.info.reactions[..]).unwrap_or_default() {
        if !sets.contains(&r.set) {
            sets.push(r.set.clone());
        }
    }
    for s in &sets {
        out.push_str(&format!(",reaction:{s}:x,reaction:{s}:y,reaction:{s}:z"));
    }
    // a pair with a master-surface stabilisation also gets its force ‖f‖
    let stabilized: Vec<bool> = (0..results.pairs.len()).map(|i| results.increments.iter().any(|inc| inc.info.contact.get(i).is_some_and(|c| c.stabilization_force > 0.0))).collect();
    for (p, &st) in results.pairs.iter().zip(&stabilized) {
        let n = &p.name;
        out.push_str(&format!(",contact:{n}:x,contact:{n}:y,contact:{n}:z,tangential:{n}:x,tangential:{n}:y,tangential:{n}:z,active:{n},stick:{n},slip:{n},augmentations:{n}"));
        if st {
            out.push_str(&format!(",stabilization:{n}"));
        }
    }
    out.push('\n');
    for (k, inc) in results.increments.iter().enumerate() {
        out.push_str(&format!("{},{:e}", k + 1, inc.info.load_factor));
        for s in &sets {
            let f = inc.info.reactions.iter().find(|r| &r.set == s).map_or([f64::NAN; 3], |r| r.force);
            out.push_str(&format!(",{:e},{:e},{:e}", f[0], f[1], f[2]));
        }
        for (i, _) in results.pairs.iter().enumerate() {
            match inc.info.contact.get(i) {
                Some(c) => {
                    let (t, st, sl) = c.friction.as_ref().map_or(([0.0; 3], 0, 0), |f| (f.tangential_force, f.stick, f.slip));
                    out.push_str(&format!(
                        ",{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{}",
                        c.force[0], c.force[1], c.force[2], t[0], t[1], t[2], c.active, st, sl, c.augmentations
                    ));
                    if stabilized[i] {
                        out.push_str(&format!(",{:e}", c.stabilization_force));
                    }
                }
                None => out.push_str(if stabilized[i] { ",,,,,,,,,,," } else { ",,,,,,,,,," }),
            }
        }
        out.push('\n');
    }
    out
}

/// The element to look at: the failing one, or else the one with the smallest
/// volume ratio J at the last (failed) iterate.
fn worst_element(p: &Problem, results: &Results, failure: &IncrementFailure, trial: &[f64]) -> String {
    let tag = |e: usize| results.mesh.element_tags.get(e).copied().unwrap_or_default();
    match failure {
        IncrementFailure::Element { element, .. } => format!(" (worst element: hexahedron {element}, gmsh tag {})", tag(*element)),
        _ => {
            let worst = (0..p.hexes.len())
                .filter_map(|e| {
                    let (X, ue) = p.gather(e, trial);
                    hex8_min_jacobian(&X, &ue).ok().map(|j| (e, j))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((e, j)) => format!(" (worst element: hexahedron {e}, gmsh tag {}, smallest J = {j:.4} at the last iterate)", tag(e)),
                None => String::new(),
            }
        }
    }
}

/// Each pair's summary and per-slave state at the converged increment (states
/// updated by the Uzawa loop).
/// Per pair: the summary, the state rows, the friction rows and (atlas masters) the
/// chart of each foot point.
type ContactResults = (Vec<PairSummary>, Vec<Vec<[f64; 6]>>, Vec<Vec<[f64; 9]>>, Vec<Vec<u32>>);

fn contact_results(newton: &Newton, u: &[f64]) -> ContactResults {
    let stabilization = newton.stabilization_forces(u);
    let mut summaries = Vec::with_capacity(newton.contact.len());
    let mut states = Vec::with_capacity(newton.contact.len());
    let mut friction = Vec::with_capacity(newton.contact.len());
    let mut charts = Vec::with_capacity(newton.contact.len());
    for (k, c) in newton.contact.iter().enumerate() {
        charts.push(c.charts().unwrap_or_default());
        let f = c.total_force();
        let max_penetration = c.max_penetration();
        let elastic_slip = c.max_elastic_slip();
        summaries.push(PairSummary {
            pair: c.name.clone(),
            force: [f[0], f[1], f[2]],
            active: c.n_active() as u32,
            max_penetration,
            augmentations: c.augmentations,
            penetration_converged: c.settings.enforcement == Enforcement::Penalty
                || (max_penetration <= c.settings.penetration_tolerance && elastic_slip <= c.settings.penetration_tolerance),
            unprojected: c.failed_projections().0 as u32,
            friction: c.settings.frictional().then(|| {
                let t = c.tangential_force();
                let (stick, slip) = c.n_stick_slip();
                FrictionSummary { tangential_force: [t[0], t[1], t[2]], stick: stick as u32, slip: slip as u32, elastic_slip }
            }),
            stabilization_force: stabilization[k],
        });
        friction.push(if c.settings.frictional() {
            (0..c.slaves.len())
                .map(|s| {
                    let (t, d) = (c.t_t_vector[s], c.slip_increment(s));
                    let code = match (c.status[s], c.slipping[s]) {
                        (SlaveStatus::Active, false) => 1.0,
                        (SlaveStatus::Active, true) => 2.0,
                        _ => 0.0,
                    };
                    [t[0], t[1], t[2], d[0], d[1], d[2], c.t_t[s][0], c.t_t[s][1], code]
                })
                .collect()
        } else {
            Vec::new()
        });
        states.push(
            (0..c.slaves.len())
                .map(|s| {
                    let pr = &c.projections[s];
                    let outside = c.status[s] == SlaveStatus::Outside;
                    [if pr.g.is_finite() { pr.g } else { f64::NAN }, c.t_n[s], c.lambda_n[s], c.status[s].code(), if outside { f64::NAN } else { pr.xi[0] }, if outside { f64::NAN } else { pr.xi[1] }]
                })
                .collect(),
        );
    }
    (summaries, states, friction, charts)
}

/// Run all increments; `results` holds the mesh and setup and receives the increments.
/// When it already holds some (a restart, `results.restart` says from where) the
/// solve continues from the last of them, with the load factors above it.
pub fn solve(newton: &mut Newton, factors: &[f64], max_cutbacks: u32, results: &mut Results, out: &Outputs, log: &mut SolveLog) -> Result<SolveSummary, SolveError> {
    let p: &Problem = newton.problem;
    let (mut u, mut lambda_prev) = match results.increments.last() {
        Some(last) => {
            let lambda = last.info.load_factor;
            newton.resume(&results.increments).map_err(|failure| SolveError::Resume {
                file: results.restart.as_ref().map_or_else(|| results.source.clone(), |o| o.file.clone()),
                load_factor: lambda,
                failure,
            })?;
            (last.displacements(), lambda)
        }
        None => (vec![0.0; DOFS_PER_NODE * p.n_nodes()], 0.0),
    };
    let first = factors_done(factors, lambda_prev);
    let mut trial = u.clone();
    let mut summary = SolveSummary { increments: 0, iterations: 0, cutbacks: 0, write_seconds: 0.0 };
    let mut file = if out.writer { ResultsFile::new(out.results) } else { ResultsFile::not_written(out.results) };
    let mut csvs = WrittenCsvs::default();
    let n_inc = factors.len();
    for (k, &target) in factors.iter().enumerate().skip(first) {
        let mut lambda = target;
        newton.planned_step = Some(target - if k == 0 { 0.0 } else { factors[k - 1] });
        let mut failures = 0u32;
        let mut cutbacks_this = 0u32;
        loop {
            trial.copy_from_slice(&u);
            let attempt = cutbacks_this;
            let outcome = {
                let mut on_it = |row: &crate::format::scres::IterationLog| {
                    log.iteration(&IterationEvent::from_row(k + 1, n_inc, lambda, attempt, row))
                };
                let mut notes = Vec::new();
                let r = solve_augmented(newton, lambda, &mut trial, &mut on_it, &mut |s: &str| notes.push(s.to_string()));
                for n in notes {
                    log.line(&format!("increment {}/{n_inc}: {n}", k + 1));
                }
                r
            };
            match outcome {
                Ok(conv) => {
                    let t = Instant::now();
                    let output_span = timeline::span("increment output: stresses, reactions, contact state");
                    u.copy_from_slice(&trial);
                    // stresses are output only: an MPI rank that does not write skips them
                    let stress = if !out.writer {
                        Vec::new()
                    } else {
                        match gauss_stresses(p, &u) {
                            Ok(s) => s,
                            Err((element, error)) => {
                                let failure = IncrementFailure::Element { iteration: 0, element, error };
                                return Err(stop(p, &trial, results, &mut file, out, log, k + 1, lambda, lambda_prev, cutbacks_this, failure));
                            }
                        }
                    };
                    summary.iterations += conv.iterations.len().saturating_sub(1);
                    let reactions = newton.reactions().into_iter().map(|(set, force)| Reaction { set, force }).collect();
                    let (summaries, states, friction, charts) = contact_results(newton, &u);
                    for c in &newton.contact {
                        if let (n, Some(node)) = c.failed_projections() {
                            log.warning(&format!(
                                "increment {}/{n_inc}: pair '{}': the closest-point projection failed for {n} slave nodes (first: node {}); they are treated as out of contact",
                                k + 1,
                                c.name,
                                p.node_tags.get(node as usize).copied().unwrap_or(node as u64)
                            ));
                        }
                        for lost in c.seam_losses() {
                            let tag = p.node_tags.get(lost.node as usize).copied().unwrap_or(lost.node as u64);
                            log.warning(&format!("increment {}/{n_inc}: pair '{}': {}", k + 1, c.name, lost.describe(tag)));
                        }
                    }
                    for s in &summaries {
                        if s.stabilization_force > 0.0 {
                            let f = (s.force[0].powi(2) + s.force[1].powi(2) + s.force[2].powi(2)).sqrt();
                            log.line(&format!("increment {}/{n_inc}: pair '{}': stabilisation force {:.3e} on the master surface (contact force {:.3e})", k + 1, s.pair, s.stabilization_force, f));
                        }
                        if !s.penetration_converged {
                            log.warning(&format!(
                                "increment {}/{n_inc}: pair '{}' still penetrates {:.3e} after {} augmentations (raise max_augmentations or eps_n)",
                                k + 1,
                                s.pair,
                                s.max_penetration,
                                s.augmentations
                            ));
                        }
                    }
                    for pair in &mut newton.contact {
                        pair.commit();
                    }
                    if let Some(d) = newton.commit_increment(&u, lambda) {
                        // ALLSD / ALLSE of Abaqus: the damping's work against the strain energy
                        let ratio = if d.strain_energy > 0.0 { d.dissipated_total / d.strain_energy } else { f64::INFINITY };
                        log.line(&format!(
                            "increment {}/{n_inc}: free-body damping dissipated {:.3e} in this increment, {:.3e} in all: {:.2e} of the strain energy {:.3e}",
                            k + 1,
                            d.dissipated,
                            d.dissipated_total,
                            ratio,
                            d.strain_energy
                        ));
                        if ratio > crate::solver::free_bodies::ENERGY_WARNING && d.dissipated_total > 0.0 {
                            log.line(&format!(
                                "warning: increment {}/{n_inc}: the free-body damping has dissipated {:.1} % of the strain energy (more than {} %): it carries load the model should carry; lower newton.free_body_damping or hold the body",
                                k + 1,
                                100.0 * ratio,
                                100.0 * crate::solver::free_bodies::ENERGY_WARNING
                            ));
                        }
                        for name in d.released {
                            log.line(&format!("increment {}/{n_inc}: contact holds body '{name}': its damping is off from the next increment", k + 1));
                        }
                    }
                    let face_pressure = face_pressures(results, &states);
                    drop(output_span);
                    results.increments.push(Increment {
                        info: IncrementInfo { load_factor: lambda, cutbacks: cutbacks_this, iterations: conv.iterations, reactions, seconds_output: super::clock::seconds_since(t), contact: summaries },
                        u: u.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                        stress,
                        contact: states,
                        friction,
                        face_pressure,
                        charts,
                    });
                    if k + 1 == n_inc && lambda >= target {
                        // the last increment and the run's status in one append (one fdatasync)
                        results.status = RunStatus::Completed;
                    }
                    write(&mut file, &mut csvs, results, out, log)?;
                    if !out.writer {
                        // nor does it keep the history's arrays (0.2 GB an increment at
                        // 1M dofs); the count and the summaries stay
                        if let Some(old) = results.increments.len().checked_sub(2).and_then(|i| results.increments.get_mut(i)) {
                            (old.u, old.contact, old.friction, old.face_pressure, old.charts) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
                        }
                    }
                    summary.increments += 1;
                    log.line(&format!(
                        "increment {}/{n_inc} converged at load factor {lambda:.6} in {} iterations{}",
                        k + 1,
                        results.increments.last().map(|i| i.info.iterations.len().saturating_sub(1)).unwrap_or(0),
                        if cutbacks_this > 0 { format!(" ({cutbacks_this} cutbacks)") } else { String::new() }
                    ));
                    lambda_prev = lambda;
                    failures = 0;
                    newton.early_segmentation_hold = false;
                    if lambda >= target {
                        break;
                    }
                    lambda = target;
                }
                Err(IncrementFailure::Setup { error }) => return Err(SolveError::Setup(SetupFailure::Linear(error))),
                Err(failure) => {
                    for pair in &mut newton.contact {
                        pair.restore();
                    }
                    // mortar: first the same step again, the segmentation held early
                    // (`Newton::early_segmentation_hold`); then the cutbacks, still so
                    if !newton.early_segmentation_hold && newton.contact.iter().any(|c| c.is_mortar()) {
                        newton.early_segmentation_hold = true;
                        log.line(&format!("increment {}/{n_inc} at load factor {lambda:.6}: {failure}; solving it again with the mortar segmentation held from a relative residual of 1e-1", k + 1));
                        continue;
                    }
                    failures += 1;
                    if failures > max_cutbacks {
                        return Err(stop(p, &trial, results, &mut file, out, log, k + 1, lambda, lambda_prev, cutbacks_this, failure));
                    }
                    cutbacks_this += 1;
                    summary.cutbacks += 1;
                    let next = lambda_prev + 0.5 * (lambda - lambda_prev);
                    log.line(&format!("increment {}/{n_inc} at load factor {lambda:.6}: {failure}; cutting back to {next:.6}", k + 1));
                    lambda = next;
                }
            }
        }
        log.increment_done();
    }
    results.status = RunStatus::Completed;
    write(&mut file, &mut csvs, results, out, log)?;
    log.line(&format!("results: {} increments, {:.1} MB written to {} in {:.2} s", results.increments.len(), file.bytes as f64 / 1e6, out.results.display(), file.seconds));
    summary.write_seconds = file.seconds;
    Ok(summary)
}

/// The two CSV histories as last written (each rewrite is a temporary file, an
/// fdatasync and a rename: one whose text has not changed is skipped).
#[derive(Default)]
struct WrittenCsvs {
    convergence: Option<String>,
    forces: Option<String>,
}

/// Bring the results file up to date (append what converged since) and rewrite the
/// two CSV histories where they changed. The histories, derived from the results
/// file, are renamed into place unsynced and never before it is synced: they are
/// prepared (written to their temporaries) on a thread of their own while the
/// results file is written and synced, and committed after (the Parisch r = 4: the
/// fdatasync 2–3 ms, the two histories' temporaries about 0.5 ms beside it).
fn write(file: &mut ResultsFile, written: &mut WrittenCsvs, results: &Results, out: &Outputs, log: &SolveLog) -> Result<(), StageError> {
    let _span = timeline::span("write results and histories");
    if !out.writer {
        return file.sync(results);
    }
    let convergence_text = log.csv();
    let forces_text = out.forces_csv.map(|_| forces_csv(results));
    let convergence = out.csv.filter(|_| written.convergence.as_deref() != Some(convergence_text));
    let forces = out.forces_csv.filter(|_| written.forces != forces_text);
    if convergence.is_none() && forces.is_none() {
        return file.sync(results);
    }
    let prepare = || -> Result<(Option<Prepared>, Option<Prepared>), StageError> {
        let _span = timeline::span("write: the histories' temporaries");
        let c = convergence.map(|path| prepare_unsynced(path, convergence_text.as_bytes())).transpose()?;
        let f = forces.map(|path| prepare_unsynced(path, forces_text.as_deref().unwrap_or_default().as_bytes())).transpose()?;
        Ok((c, f))
    };
    let (synced, prepared) = std::thread::scope(|scope| {
        // no thread to be had: the histories after the results, on this one
        let side = std::thread::Builder::new().name("sc-histories".into()).spawn_scoped(scope, prepare).ok();
        let synced = file.sync(results);
        let prepared = match side {
            Some(side) => side.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            None => prepare(),
        };
        (synced, prepared)
    });
    // a failed results write drops the prepared histories (their temporaries removed)
    synced?;
    let (c, f) = prepared?;
    if let Some(c) = c {
        c.commit()?;
        written.convergence = Some(convergence_text.to_owned());
    }
    if let Some(f) = f {
        f.commit()?;
        written.forces = forces_text;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn stop(p: &Problem, trial: &[f64], results: &mut Results, file: &mut ResultsFile, out: &Outputs, log: &SolveLog, increment: usize, load_factor: f64, last_converged: f64, cutbacks: u32, failure: IncrementFailure) -> SolveError {
    let worst = worst_element(p, results, &failure, trial);
    let reason = format!("increment {increment} at load factor {load_factor:.6}: {failure}{worst}");
    results.status = RunStatus::Stopped { reason };
    if let Err(e) = file.sync(results) {
        return SolveError::Write(e);
    }
    if let Some(csv) = out.csv.filter(|_| out.writer) {
        if let Err(e) = write_atomic_unsynced(csv, log.csv().as_bytes()) {
            return SolveError::Write(e);
        }
    }
    SolveError::Diverged {
        increment,
        load_factor,
        last_converged,
        cutbacks,
        failure,
        worst,
        kept: results.increments.len(),
        results: out.results.display().to_string(),
        hint: facet_hint(p),
    }
}

/// A stopped solve with a facet master that has no stabilisation: say it exists.
fn facet_hint(p: &Problem) -> String {
    let facets: Vec<&str> = p.contact.iter().filter(|c| c.pair.master_kind == MasterKind::Facet && c.settings.stabilization == 0.0).map(|c| c.pair.name.as_str()).collect();
    if facets.is_empty() {
        return String::new();
    }
    format!(
        " (pair '{}' has a facet master: if it is the softer body under a sliding slave, its quasi-static path can need a snap that Newton cannot follow; `stabilization: 0.15` in its contact entry or a B-spline master can help: docs/pipelines.md)",
        facets.join("', '")
    )
}

/// The mean contact pressure over every slave face of every pair whose slave is a
/// face set (`post::contact_pressure`), from the slave nodes' −t_N of `states`.
fn face_pressures(results: &Results, states: &[Vec<[f64; 6]>]) -> Vec<Vec<f64>> {
    let mesh = &results.mesh;
    results
        .pairs
        .iter()
        .zip(states)
        .map(|(pair, st)| {
            let Some(faces) = pair.slave_faces(mesh) else {
                return Vec::new();
            };
            crate::post::contact_pressure::face_pressures(mesh, &faces, |n| pair.slave_nodes.binary_search(&n).ok().and_then(|s| st.get(s)).map_or(0.0, |row| -row[1]))
        })
        .collect()
}
