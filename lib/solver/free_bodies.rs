//! Viscous stabilisation of bodies that only contact holds (Abaqus' `*STATIC,
//! STABILIZE`, ANSYS' `STABDAMP`): `newton.free_body_damping`.
//!
//! A body whose Dirichlet conditions leave rigid modes free (found before the
//! solve, `docs/theory/check.md`, "Rigid-body modes") has a singular tangent until
//! contact holds it, and Newton wanders or the factorization fails. The damping
//! adds to every free dof a of such a body a viscous force against its motion in
//! the increment:
//! ```text
//! f_a   = c (u_a − u_{n,a}) · Δλ̂/Δλ        u_n: the last converged state
//! K_aa += c · Δλ̂/Δλ                       Δλ̂ the planned step, Δλ the step taken
//! c     = β G h̄                           β = free_body_damping, G the body's
//!                                           smallest shear modulus, h̄ its mean
//!                                           element size (V/n_hex)^{1/3}
//! ```
//! G h̄ is the stiffness of one element at a node, so β is the damping's share of
//! it; a cut-back step (a larger velocity for the same motion) makes it stiffer.
//!
//! **The energy it takes.** Over an increment the force does the work
//! W = Σ_a c (Δλ̂/Δλ) (Δu_a)², which the solve adds up (ALLSD in Abaqus) and compares
//! with the strain energy ∫ W(F) dV of the converged state (ALLSE); the log warns
//! when the ratio passes [`ENERGY_WARNING`]: the damping then carries load the
//! model should carry.
//!
//! **Switched off once contact holds the body.** After every converged increment the
//! active contact nodes on the body (as slave nodes, or as the master points under
//! a slave) give the rows n̄ · [e_k, e_k × (x − c)/L] (their normals against the six
//! rigid modes; with friction also the two tangents of a sticking node); with Q the
//! body's free modes and G_c = Σ rows rowsᵀ, the body is held when the smallest
//! eigenvalue of Qᵀ G_c Q reaches [`HELD`]: every free mode then meets a contact
//! constraint, and the damping is off from the next increment on.

use nalgebra::{DMatrix, Vector3, Vector6};

use super::problem::Problem;
use crate::assembly::{Pattern, DOFS_PER_NODE};
use crate::contact::pair::{PairSolver, SlaveStatus};
use crate::fem::element::hex8_strain_energy;
use crate::fem::hex8::hex8_volume;

/// Ratio of dissipated to strain energy above which the log warns (Abaqus' guideline
/// for its ALLSD/ALLSE).
pub const ENERGY_WARNING: f64 = 0.05;

/// Smallest eigenvalue of the contact rows' Gram matrix over the free modes at which
/// contact holds a body (the rows are unit normals against unit modes: one contact
/// node that meets a mode squarely contributes 1).
pub const HELD: f64 = 1e-2;

/// A body with free rigid modes, as the pre-solve check finds it.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeBody {
    pub name: String,
    /// Its nodes, sorted.
    pub nodes: Vec<u32>,
    /// Its free modes, unit vectors over (translation x, y, z, rotation about x, y,
    /// z), the rotations scaled by `length`.
    pub free: Vec<[f64; 6]>,
    pub centroid: Vector3<f64>,
    /// L, the RMS distance of its nodes from the centroid.
    pub length: f64,
}

struct Damped {
    body: FreeBody,
    /// c of this body.
    c: f64,
    /// Its unconstrained dofs.
    dofs: Vec<u32>,
    /// Still damped (contact does not hold it yet).
    active: bool,
    /// Whether a node belongs to it, by node index.
    member: Vec<bool>,
}

/// What one converged increment did.
#[derive(Debug, Clone, PartialEq)]
pub struct DampingReport {
    /// Work of the damping in this increment and since the start.
    pub dissipated: f64,
    pub dissipated_total: f64,
    /// ∫ W(F) dV at the converged state.
    pub strain_energy: f64,
    /// Bodies contact now holds (damping off from the next increment).
    pub released: Vec<String>,
}

/// The damping of a problem's free bodies.
pub struct FreeBodyDamping {
    bodies: Vec<Damped>,
    /// u_n, the last converged state.
    u_n: Vec<f64>,
    /// Δλ̂ / Δλ of the current solve.
    scale: f64,
    dissipated_total: f64,
}

impl FreeBodyDamping {
    /// Damping `beta` on `bodies` of `problem` (those with free modes).
    pub fn new(problem: &Problem, bodies: Vec<FreeBody>, beta: f64) -> Self {
        let n_nodes = problem.n_nodes();
        let mut damped = Vec::new();
        for body in bodies.into_iter().filter(|b| !b.free.is_empty()) {
            let mut member = vec![false; n_nodes];
            for &a in &body.nodes {
                member[a as usize] = true;
            }
            let (mut g, mut volume, mut n_hex) = (f64::INFINITY, 0.0, 0usize);
            for (e, hex) in problem.hexes.iter().enumerate() {
                if member[hex[0] as usize] {
                    g = g.min(crate::material::Material::shear_modulus(&problem.materials[problem.hex_material[e] as usize]));
                    volume += hex8_volume(&hex.map(|a| problem.X[a as usize]));
                    n_hex += 1;
                }
            }
            let h = if n_hex > 0 { (volume / n_hex as f64).cbrt() } else { 0.0 };
            let dofs = body
                .nodes
                .iter()
                .flat_map(|&a| (0..DOFS_PER_NODE).map(move |k| DOFS_PER_NODE * a as usize + k))
                .filter(|&d| !problem.dofs.is_constrained(d))
                .map(|d| d as u32)
                .collect();
            damped.push(Damped { body, c: beta * g * h, dofs, active: true, member });
        }
        Self { bodies: damped, u_n: vec![0.0; DOFS_PER_NODE * n_nodes], scale: 1.0, dissipated_total: 0.0 }
    }

    /// The damped bodies: (body, c, still damped).
    pub fn bodies(&self) -> impl Iterator<Item = (&FreeBody, f64, bool)> {
        self.bodies.iter().map(|d| (&d.body, d.c, d.active))
    }

    /// The next solve's step is `cutback_ratio` (Δλ̂/Δλ ≥ 1) times shorter than planned.
    pub fn set_cutback_ratio(&mut self, cutback_ratio: f64) {
        self.scale = cutback_ratio;
    }

    /// Start from the converged state `u` (a restart).
    pub fn restart_from(&mut self, u: &[f64]) {
        self.u_n.copy_from_slice(u);
    }

    /// residual += f.
    pub fn add_residual(&self, u: &[f64], residual: &mut [f64]) {
        for b in self.bodies.iter().filter(|b| b.active) {
            let c = self.scale * b.c;
            for &d in &b.dofs {
                let d = d as usize;
                residual[d] += c * (u[d] - self.u_n[d]);
            }
        }
    }

    /// K_ff += c Δλ̂/Δλ on the diagonal of the damped dofs.
    pub fn add_tangent(&self, pattern: &Pattern, values: &mut [f64]) {
        for b in self.bodies.iter().filter(|b| b.active) {
            let c = self.scale * b.c;
            for &d in &b.dofs {
                if let Some(slot) = pattern.dofs().free(d as usize).and_then(|j| pattern.diagonal_slot(j)) {
                    values[slot] += c;
                }
            }
        }
    }

    /// Accept the converged state `u`: the work of this increment, the strain
    /// energy, and which bodies contact holds now.
    pub fn commit(&mut self, problem: &Problem, u: &[f64], contact: &[PairSolver]) -> DampingReport {
        let mut dissipated = 0.0;
        for b in self.bodies.iter().filter(|b| b.active) {
            let c = self.scale * b.c;
            dissipated += b.dofs.iter().map(|&d| c * (u[d as usize] - self.u_n[d as usize]).powi(2)).sum::<f64>();
        }
        self.dissipated_total += dissipated;
        self.u_n.copy_from_slice(u);
        let mut released = Vec::new();
        for b in self.bodies.iter_mut().filter(|b| b.active) {
            if holds(b, problem, u, contact) {
                b.active = false;
                released.push(b.body.name.clone());
            }
        }
        DampingReport { dissipated, dissipated_total: self.dissipated_total, strain_energy: strain_energy(problem, u), released }
    }
}

/// Whether the active contact nodes on `b` hold its free modes (module docs).
fn holds(b: &Damped, problem: &Problem, u: &[f64], contact: &[PairSolver]) -> bool {
    let x = |a: u32| {
        let d = DOFS_PER_NODE * a as usize;
        problem.X[a as usize] + Vector3::new(u[d], u[d + 1], u[d + 2])
    };
    let (c, l) = (b.body.centroid, b.body.length.max(f64::MIN_POSITIVE));
    let mut gram = nalgebra::Matrix6::<f64>::zeros();
    let mut add = |at: Vector3<f64>, dir: Vector3<f64>| {
        let r = (at - c) / l;
        let mut row = Vector6::zeros();
        for k in 0..3 {
            row[k] = dir[k];
        }
        // dir · (e_k × r) = e_k · (r × dir)
        let m = r.cross(&dir);
        for k in 0..3 {
            row[3 + k] = m[k];
        }
        gram += row * row.transpose();
    };
    for pair in contact {
        for (s, &node) in pair.slaves.iter().enumerate() {
            if pair.status[s] != SlaveStatus::Active {
                continue;
            }
            let on_slave = b.member[node as usize];
            let on_master = pair.master_nodes_of(s).any(|a| b.member[a as usize]);
            if !(on_slave || on_master) {
                continue;
            }
            let (n, tangents) = pair.contact_frame(s);
            let at = if on_slave { x(node) } else { pair.projections[s].x_bar };
            add(at, n);
            if pair.settings.frictional() && !pair.slipping[s] {
                for t in tangents {
                    add(at, t);
                }
            }
        }
    }
    let k = b.body.free.len();
    let q = DMatrix::from_fn(6, k, |i, j| b.body.free[j][i]);
    let reduced = q.transpose() * DMatrix::from_fn(6, 6, |i, j| gram[(i, j)]) * &q;
    reduced.symmetric_eigenvalues().iter().copied().fold(f64::INFINITY, f64::min) >= HELD
}

/// ∫ W(F) dV over every hexahedron at `u`, summed in element order (0 where an
/// element's energy cannot be evaluated: the solve has accepted the state).
fn strain_energy(problem: &Problem, u: &[f64]) -> f64 {
    use rayon::prelude::*;
    let per_element: Vec<f64> = (0..problem.hexes.len())
        .into_par_iter()
        .map(|e| {
            let (x_ref, ue) = problem.gather(e, u);
            hex8_strain_energy(&x_ref, &ue, &problem.materials[problem.hex_material[e] as usize]).unwrap_or(0.0)
        })
        .collect();
    per_element.iter().sum()
}

