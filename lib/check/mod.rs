//! The pre-solve check (`sc-check`, the pipeline's `check` stage, and the start of
//! every `sc-solve`): a model explained before it is solved.
//!
//! | file | concept |
//! |------|---------|
//! | [`contact_check`] | per pair: every slave node projected as the solve will (eq. 2.2), inside / outside / failed, initial gaps and penetrations (eq. 4.3), the adjust's moves |
//! | [`orientation`] | does the master normal n̄ face the slave body? (the flipped-master criterion) |
//! | [`rigid_modes`] | the bodies and the rigid-body modes their Dirichlet conditions leave free |
//! | [`report`] | the readable summary, the per-node CSV and the `.vtu` |
//!
//! The check changes nothing: it reads the model and the setup, builds the
//! [`Problem`] exactly as `sc-solve` does (so it sees the same penalties, tolerances
//! and adjusted coordinates), and reports. Its cost is one contact search per pair
//! (parallel, near-linear in the slave nodes) and one pass over the hexahedra.

pub mod contact_check;
pub mod orientation;
pub mod report;
pub mod rigid_modes;

use contact_check::{check_pair, PairCheck};
use rigid_modes::{components, free_modes, BodyModes};

use crate::assembly::DOFS_PER_NODE;
use crate::contact::pair::PairError;
use crate::mesh::Mesh;
use crate::solver::problem::Problem;

/// The version of the check's outputs (CSV columns, `.vtu` fields, summary), as
/// documented in `docs/formats.md`.
pub const VERSION: &str = "1.0";

/// A model the solve refuses (`sc-check --strict` too).
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    #[error(
        "{file}: contact pair '{pair}': the master normal points away from the slave body ({behind} of {voters} slave nodes on master '{master}' see it from behind{cells}): a flipped master. \
         Check which surface is the master (the face set of the body the slave presses on, on the side that faces the slave), and that face set's orientation \
         (a face set on an interface between two bodies is attached to the hexahedra its quads' node order points out of: reverse the quads in gmsh, or name the other body's face); \
         to solve it as it is, set `allow_flipped_master: true` in the pair's `contact` entry"
    )]
    FlippedMaster { file: String, pair: String, master: String, behind: usize, voters: usize, cells: String },
    #[error("{file}: {source}")]
    Pair { file: String, source: PairError },
}

/// The whole check.
#[derive(Debug, Clone)]
pub struct CheckReport {
    /// The model file and the setup it was checked with.
    pub source: String,
    pub setup: String,
    pub nodes: usize,
    pub hexes: usize,
    pub dofs: usize,
    pub free_dofs: usize,
    pub pairs: Vec<PairCheck>,
    pub bodies: Vec<BodyModes>,
    pub seconds: f64,
}

/// Check `problem` (built from `mesh` and the setup by [`Problem::with_contact`]).
/// `source` and `setup` name the files in the report and in errors.
pub fn run(mesh: &Mesh, problem: &Problem, model: &str, setup: &str) -> Result<CheckReport, CheckError> {
    let start = std::time::Instant::now();
    let mut pairs = Vec::with_capacity(problem.contact.len());
    for def in &problem.contact {
        let adjustment = problem.adjustments.iter().find(|a| a.pair == def.pair.name);
        pairs.push(check_pair(mesh, def, &problem.X, adjustment).map_err(|source| CheckError::Pair { file: model.into(), source })?);
    }
    // rigid modes of each body, at the coordinates the solve starts from
    let bodies = components(mesh)
        .into_iter()
        .map(|c| {
            let (free, centroid, length, constrained_dofs) = free_modes(&problem.X, &c.nodes, |d| problem.dofs.is_constrained(d));
            let on_body = |n: &u32| c.nodes.binary_search(n).is_ok();
            let contact_pairs = problem
                .contact
                .iter()
                .filter(|d| d.pair.slave_nodes.iter().any(on_body) || d.pair.net.nodes.iter().any(on_body))
                .map(|d| d.pair.name.clone())
                .collect();
            BodyModes { name: c.name, nodes: c.nodes, constrained_dofs, centroid: centroid.into(), length, free, contact_pairs }
        })
        .collect();
    Ok(CheckReport {
        source: model.into(),
        setup: setup.into(),
        nodes: mesh.nodes.len(),
        hexes: mesh.hexes.len(),
        dofs: DOFS_PER_NODE * mesh.nodes.len(),
        free_dofs: problem.dofs.n_free(),
        pairs,
        bodies,
        seconds: start.elapsed().as_secs_f64(),
    })
}

impl CheckReport {
    /// What makes the solve refuse the model: flipped masters the setup does not allow.
    pub fn errors(&self) -> Vec<CheckError> {
        self.pairs
            .iter()
            .filter(|p| p.refused())
            .map(|p| CheckError::FlippedMaster {
                file: self.source.clone(),
                pair: p.name.clone(),
                master: p.master.clone(),
                behind: p.orientation.behind,
                voters: p.orientation.voters,
                cells: if p.orientation.cells_inward > 0 { format!("; {} of {} master faces point into the master body", p.orientation.cells_inward, p.orientation.cells) } else { String::new() },
            })
            .collect()
    }

    /// Findings that do not stop the solve, one line each naming the pair or body.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        for p in &self.pairs {
            let o = &p.orientation;
            if o.flipped() && p.allow_flipped_master {
                w.push(format!("contact pair '{}': the master normal points away from the slave body ({} of {} nodes see it from behind); solved anyway (allow_flipped_master)", p.name, o.behind, o.voters));
            } else if o.mixed() {
                w.push(format!(
                    "contact pair '{}': the master's orientation is not clear-cut: {} of {} slave nodes on the master see it from behind, {} of {} master faces point into the master body",
                    p.name, o.behind, o.voters, o.cells_inward, o.cells
                ));
            }
            if let Some((_, _, defect)) = p.balance.filter(|b| b.2.is_nan() || b.2 > 1e-8) {
                w.push(format!(
                    "contact pair '{}': transfer: balanced could not recombine the master's basis to its faces' forces (M q − f: {defect:.1e} of max f); a uniform pressure will not give the faces' consistent forces",
                    p.name
                ));
            }
            let (inside, _, failed) = p.counts();
            if failed > 0 {
                let why: Vec<String> = p.failures().iter().map(|(r, n)| format!("{n}: {}", r.explain())).collect();
                let first = p.rows.iter().find(|r| matches!(r.projected, contact_check::Projected::Failed(_))).map_or(0, |r| r.tag);
                w.push(format!("contact pair '{}': the projection failed for {failed} slave nodes (first: node {first}; {}); they start out of contact", p.name, why.join("; ")));
            }
            if inside == 0 && !p.rows.is_empty() {
                w.push(format!("contact pair '{}': no slave node projects onto the master (all beyond its edges): the pair cannot be in contact at the start", p.name));
            }
            let pen = p.penetrating_after_adjust();
            if !pen.is_empty() {
                let worst = pen.iter().max_by(|a, b| (-a.g_n).total_cmp(&-b.g_n)).map_or((0, 0.0), |r| (r.tag, -r.g_n));
                w.push(format!(
                    "contact pair '{}': {} slave nodes penetrate the master by more than the tolerance {:.3e} (deepest: node {} by {:.4e}){}",
                    p.name,
                    pen.len(),
                    p.settings.penetration_tolerance,
                    worst.0,
                    worst.1,
                    if p.adjustment.is_some() { "; beyond the adjust distance" } else { "; `adjust` moves such nodes onto the master" }
                ));
            }
        }
        w.extend(self.bodies.iter().filter_map(BodyModes::warning));
        w
    }
}
