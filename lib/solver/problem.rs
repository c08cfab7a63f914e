//! The static boundary-value problem as the solver sees it, built from a mesh and a
#![allow(non_snake_case)] // paper notation: X (reference coordinates)
//! solve setup: a material per hexahedron, the Dirichlet dofs with their prescribed
//! values, the reference external forces and the follower-pressure faces. Every
//! reference to the mesh is checked here, so a bad setup fails before any solve with
//! a message naming the set, body or value at fault.

use nalgebra::Vector3;

use super::amplitude::Amplitude;
use crate::assembly::{DofMap, DOFS_PER_NODE};
use crate::contact::adjust::{adjust_pair, AdjustError, PairAdjustment};
// re-exported: the problem holds its contact pairs as `ContactDefinition`s
pub use crate::contact::definition::ContactDefinition;
use crate::contact::settings::{Integration, PairSettings};
use crate::contact::tributary::tributary_areas;
use crate::format::sccontact::{ContactPair, SlaveKind};
use crate::fem::element::Formulation;
use crate::format::setup::{self, ModelName, SolveSetup};
use crate::material::linear::LinearElastic;
use crate::material::neo_hookean::{CiarletSimo, DevVolNeoHookean};
use crate::material::{MaterialError, MaterialModel};
use crate::mesh::Mesh;

/// A setup that does not fit the mesh (or is invalid in itself).
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    #[error("{file}: {what} '{name}' does not exist in the mesh (it has: {available})")]
    UnknownName { file: String, what: &'static str, name: String, available: String },
    #[error("{file}: body '{body}' has no material (every body needs one entry under `materials`)")]
    MissingMaterial { file: String, body: String },
    #[error("{file}: body '{body}' has two materials")]
    DuplicateMaterial { file: String, body: String },
    #[error("{file}: material of body '{body}': {message}")]
    MaterialParameters { file: String, body: String, message: String },
    #[error("{file}: material of body '{body}': {source}")]
    Material { file: String, body: String, source: MaterialError },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("{file}: {source}")]
    Adjust { file: String, source: AdjustError },
}

/// A follower pressure on one hexahedron face (nodes outward-oriented).
#[derive(Debug, Clone, Copy)]
pub struct PressureFace {
    pub nodes: [u32; 4],
    /// Pressure at amplitude 1.
    pub p: f64,
    /// Index into `Problem::amplitudes`.
    pub amplitude: u32,
}

/// A prescribed displacement component: u[dof] = value · a(t).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prescribed {
    pub dof: usize,
    pub value: f64,
    /// Index into `Problem::amplitudes`.
    pub amplitude: u32,
}

/// A node set moved rigidly (eq.: x = c + R(θ a_θ(t)) (X + d a_d(t) − c)): every
/// component of its nodes is prescribed. R is Rodrigues' rotation about the unit
/// `axis`.
#[derive(Debug, Clone, PartialEq)]
pub struct PrescribedRotation {
    pub nodes: Vec<u32>,
    pub axis: Vector3<f64>,
    pub center: Vector3<f64>,
    pub angle: f64,
    /// Index into `Problem::amplitudes`, of the angle.
    pub amplitude: u32,
    /// The translation applied before the rotation, and its amplitude.
    pub translation: Vector3<f64>,
    pub translation_amplitude: u32,
}

impl PrescribedRotation {
    /// u of reference point `x` at angle amplitude `a` and translation amplitude `b`.
    pub fn displacement(&self, x: &Vector3<f64>, a: f64, b: f64) -> Vector3<f64> {
        let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(self.axis), self.angle * a);
        self.center + r * (x + self.translation * b - self.center) - x
    }
}

/// The problem.
pub struct Problem {
    /// Reference coordinates.
    pub X: Vec<Vector3<f64>>,
    pub hexes: Vec<[u32; 8]>,
    /// Material of each hexahedron (index into `materials`).
    pub hex_material: Vec<u32>,
    pub materials: Vec<MaterialModel>,
    pub formulation: Formulation,
    pub dofs: DofMap,
    /// Nonzero prescribed displacement components.
    pub prescribed: Vec<Prescribed>,
    /// Node sets moved rigidly ([`Self::apply_prescribed`] sets their dofs).
    pub rotations: Vec<PrescribedRotation>,
    /// Amplitudes: 0 is the ramp a(t) = t, then the setup's curves in order.
    pub amplitudes: Vec<Amplitude>,
    /// External nodal forces at amplitude 1, per amplitude (empty when none uses it),
    /// each of length 3·nodes: f_ext(t) = Σ_a a(t) f_ext[a].
    pub f_ext: Vec<Vec<f64>>,
    pub pressure_faces: Vec<PressureFace>,
    /// Constrained node sets, for reaction output: (name, nodes).
    pub reaction_sets: Vec<(String, Vec<u32>)>,
    /// Contact pairs (empty without a contact model).
    pub contact: Vec<ContactDefinition>,
    /// gmsh tag of every node, for messages.
    pub node_tags: Vec<u64>,
    /// The pairs' `adjust` before the first increment, in pair order (pairs with
    /// `adjust` only): which slave nodes moved onto the master and how far. `X` holds
    /// the moved coordinates.
    pub adjustments: Vec<PairAdjustment>,
}

fn names(v: Vec<&str>) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

fn material(file: &str, m: &setup::MaterialSetup) -> Result<MaterialModel, ProblemError> {
    let bad = |message: String| ProblemError::MaterialParameters { file: file.into(), body: m.body.clone(), message };
    let mat_err = |source| ProblemError::Material { file: file.into(), body: m.body.clone(), source };
    let by_lame = match (m.e, m.nu, m.lambda, m.mu) {
        (Some(_), Some(_), None, None) => false,
        (None, None, Some(_), Some(_)) => true,
        _ => return Err(bad("give either `E` and `nu`, or `lambda` and `mu`".into())),
    };
    for (name, v) in [("E", m.e), ("nu", m.nu), ("lambda", m.lambda), ("mu", m.mu)] {
        if let Some(v) = v {
            if !v.is_finite() {
                return Err(bad(format!("`{name}` = {v} is not a finite number")));
            }
        }
    }
    let model: MaterialModel = match (m.model, by_lame) {
        (ModelName::NeoHookean, false) => CiarletSimo::from_young_poisson(m.e.unwrap_or_default(), m.nu.unwrap_or_default()).map_err(mat_err)?.into(),
        (ModelName::NeoHookean, true) => CiarletSimo::from_lame(m.lambda.unwrap_or_default(), m.mu.unwrap_or_default()).map_err(mat_err)?.into(),
        (ModelName::NeoHookeanDevVol, false) => DevVolNeoHookean::from_young_poisson(m.e.unwrap_or_default(), m.nu.unwrap_or_default()).map_err(mat_err)?.into(),
        (ModelName::NeoHookeanDevVol, true) => DevVolNeoHookean::from_lame(m.lambda.unwrap_or_default(), m.mu.unwrap_or_default()).map_err(mat_err)?.into(),
        (ModelName::LinearElastic, false) => LinearElastic::from_young_poisson(m.e.unwrap_or_default(), m.nu.unwrap_or_default()).map_err(mat_err)?.into(),
        (ModelName::LinearElastic, true) => LinearElastic::from_lame(m.lambda.unwrap_or_default(), m.mu.unwrap_or_default()).map_err(mat_err)?.into(),
    };
    Ok(model)
}

/// Match the setup's `contact` entries with the model's pairs and resolve them.
fn contact_definitions(mesh: &Mesh, pairs: &[ContactPair], setup: &SolveSetup, file: &str, materials: &[MaterialModel], hex_material: &[u32]) -> Result<Vec<ContactDefinition>, ProblemError> {
    let invalid = |message: String| ProblemError::Invalid { file: file.into(), message };
    let pair_names = || names(pairs.iter().map(|p| p.name.as_str()).collect());
    for (i, c) in setup.contact.iter().enumerate() {
        if !pairs.iter().any(|p| p.name == c.pair) {
            return Err(if pairs.is_empty() {
                invalid(format!("contact entry {} names pair '{}', but the input has no contact pairs (give the .sccontact written by sc-tag as input)", i + 1, c.pair))
            } else {
                ProblemError::UnknownName { file: file.into(), what: "contact pair", name: c.pair.clone(), available: pair_names() }
            });
        }
        if setup.contact[..i].iter().any(|o| o.pair == c.pair) {
            return Err(invalid(format!("contact pair '{}' has two entries under `contact`", c.pair)));
        }
    }
    let mut out = Vec::with_capacity(pairs.len());
    for pair in pairs {
        let Some(c) = setup.contact.iter().find(|c| c.pair == pair.name) else {
            return Err(invalid(format!("contact pair '{}' has no entry under `contact` (give at least `- {{pair: {}}}`)", pair.name, pair.name)));
        };
        let bad = |m: String| invalid(format!("contact pair '{}': {m}", pair.name));
        let h = mean_net_edge(mesh, pair);
        let (eps_n, eps_n_default) = match c.eps_n {
            Some(e) if !(e.is_finite() && e > 0.0) => return Err(bad(format!("eps_n must be a positive number, found {e}"))),
            Some(e) => (e, false),
            None => (default_penalty(mesh, pair, materials, hex_material, h), true),
        };
        for (key, v) in [("penetration_tolerance", c.penetration_tolerance), ("penetration_tolerance_relative", c.penetration_tolerance_relative)] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(format!("{key} must be a positive number, found {v}")));
                }
            }
        }
        let eps_t = match (c.mu, c.eps_t) {
            (mu, _) if !(mu.is_finite() && mu >= 0.0) => return Err(bad(format!("mu must be zero or positive, found {mu}"))),
            (_, Some(e)) if !(e.is_finite() && e > 0.0) => return Err(bad(format!("eps_t must be a positive number, found {e}"))),
            (mu, None) if mu > 0.0 => eps_n, // default: the normal penalty
            (_, e) => e.unwrap_or(0.0),
        };
        if !(c.uzawa_relaxation >= 1.0 && c.uzawa_relaxation < 2.0) {
            return Err(bad(format!("uzawa_relaxation must lie in [1, 2) (1: the plain Uzawa update), found {}", c.uzawa_relaxation)));
        }
        if !(c.stabilization.is_finite() && c.stabilization >= 0.0) {
            return Err(bad(format!("stabilization must be zero or positive, found {}", c.stabilization)));
        }
        if let Some(d) = c.adjust {
            if !(d.is_finite() && d >= 0.0) {
                return Err(bad(format!("adjust must be a length ≥ 0 (0: off), found {d}")));
            }
        }
        let slave_faces = pair.slave_faces(mesh).unwrap_or_default();
        if c.integration == Integration::Mortar {
            if slave_faces.is_empty() {
                return Err(bad(format!("integration: mortar integrates over the slave faces, but slave '{}' is a node set; give the slave as a face set (sc-tag) or use integration: node", pair.slave)));
            }
        }
        let areas = tributary_areas(mesh, &pair.slave_nodes, (pair.slave_kind == SlaveKind::FaceSet).then_some(pair.slave.as_str()));
        let penetration_tolerance = match (c.penetration_tolerance, c.penetration_tolerance_relative) {
            (Some(_), Some(_)) => return Err(bad("give `penetration_tolerance` or `penetration_tolerance_relative`, not both".into())),
            (Some(t), None) => t,
            (None, Some(r)) => r * h,
            (None, None) => 1e-3 * h,
        };
        out.push(ContactDefinition {
            pair: pair.clone(),
            settings: PairSettings { eps_n, enforcement: c.enforcement, penetration_tolerance, max_augmentations: c.max_augmentations, update_halvings: c.update_halvings, uzawa_relaxation: c.uzawa_relaxation, mu: c.mu, eps_t, stabilization: c.stabilization, integration: c.integration, multipliers: c.multipliers, transfer: c.transfer, quadrature: c.quadrature },
            eps_n_default,
            areas,
            slave_faces,
            h_master: h,
            adjust: c.adjust.filter(|&d| d != 0.0),
            allow_flipped_master: c.allow_flipped_master,
        });
    }
    Ok(out)
}

/// The default normal penalty when a pair gives no `eps_n`:
/// ```text
/// ε_N = 25 G / h
/// ```
/// G the smaller shear modulus of the bodies on either side (the hexahedra of the
/// master face set and those holding slave nodes), h the master net's mean edge
/// length. 25 G/h ≈ 10 E/h at ν = 0.3: the contact spring of a node, ε_N A_s ≈ 10 E h,
/// is ten times the stiffness of an element of the softer body, so the penalty
/// penetration is ~10 % of that element's elastic deformation, and each Uzawa update
/// of the augmented Lagrangian shrinks it about tenfold (contraction
/// k_body / (k_body + ε_N A_s) ≈ 1/11) — stiff enough to be accurate after a few
/// updates, soft enough not to spoil the conditioning.
pub fn default_penalty(mesh: &Mesh, pair: &ContactPair, materials: &[MaterialModel], hex_material: &[u32], h: f64) -> f64 {
    use crate::material::Material;
    let mut g = f64::INFINITY;
    if let Some(fs) = mesh.face_set(&pair.master) {
        for f in &fs.faces {
            g = g.min(materials[hex_material[f.element as usize] as usize].shear_modulus());
        }
    }
    let slave: std::collections::HashSet<u32> = pair.slave_nodes.iter().copied().collect();
    for (e, hex) in mesh.hexes.iter().enumerate() {
        if hex.iter().any(|n| slave.contains(n)) {
            g = g.min(materials[hex_material[e] as usize].shear_modulus());
        }
    }
    25.0 * g / h
}

/// Mean edge length of a pair's master net (reference configuration).
fn mean_net_edge(mesh: &Mesh, pair: &ContactPair) -> f64 {
    let Some(grid) = pair.net.grid() else {
        // any other net: the mean over its distinct cell edges
        let edges = pair.net.edges();
        let x = |k: u32| Vector3::from(mesh.nodes[pair.net.nodes[k as usize] as usize]);
        let sum: f64 = edges.iter().map(|&(u, v)| (x(u) - x(v)).norm()).sum();
        return if edges.is_empty() { 1.0 } else { sum / edges.len() as f64 };
    };
    let (a, b) = (grid.a, grid.b);
    let x = |i: usize, j: usize| Vector3::from(mesh.nodes[grid.at(i, j) as usize]);
    let (mut sum, mut n) = (0.0, 0usize);
    for j in 0..b {
        for i in 0..a {
            if i + 1 < a {
                sum += (x(i + 1, j) - x(i, j)).norm();
                n += 1;
            }
            if j + 1 < b {
                sum += (x(i, j + 1) - x(i, j)).norm();
                n += 1;
            }
        }
    }
    if n > 0 {
        sum / n as f64
    } else {
        1.0
    }
}

impl Problem {
    /// Build and check the problem without contact; `file` names the setup in messages.
    pub fn new(mesh: &Mesh, setup: &SolveSetup, file: &str) -> Result<Self, ProblemError> {
        Self::with_contact(mesh, &[], setup, file)
    }

    /// Build and check the problem with the contact `pairs` of a `.sccontact` model:
    /// every pair needs exactly one `contact` entry in the setup and vice versa.
    pub fn with_contact(mesh: &Mesh, pairs: &[ContactPair], setup: &SolveSetup, file: &str) -> Result<Self, ProblemError> {
        let unknown = |what: &'static str, name: &str, available: Vec<&str>| ProblemError::UnknownName {
            file: file.into(),
            what,
            name: name.into(),
            available: names(available),
        };
        let invalid = |message: String| ProblemError::Invalid { file: file.into(), message };
        // Materials: exactly one per body.
        let mut body_material: Vec<Option<u32>> = vec![None; mesh.bodies.len()];
        let mut materials = Vec::new();
        for m in &setup.materials {
            let b = mesh.body(&m.body).ok_or_else(|| unknown("body", &m.body, mesh.body_names()))?;
            if body_material[b].is_some() {
                return Err(ProblemError::DuplicateMaterial { file: file.into(), body: m.body.clone() });
            }
            body_material[b] = Some(materials.len() as u32);
            materials.push(material(file, m)?);
        }
        let mut hex_material = Vec::with_capacity(mesh.hexes.len());
        for &b in &mesh.hex_body {
            match body_material[b as usize] {
                Some(m) => hex_material.push(m),
                None => return Err(ProblemError::MissingMaterial { file: file.into(), body: mesh.bodies[b as usize].name.clone() }),
            }
        }
        // Amplitudes.
        let mut amplitudes = vec![Amplitude::Ramp];
        for (i, c) in setup.curves.iter().enumerate() {
            if setup.curves[..i].iter().any(|o| o.name == c.name) {
                return Err(invalid(format!("curve '{}' is defined twice", c.name)));
            }
            amplitudes.push(Amplitude::table(&c.points).map_err(|m| invalid(format!("curve '{}' {m}", c.name)))?);
        }
        let amplitude_of = |name: &Option<String>, user: &str| -> Result<u32, ProblemError> {
            match name {
                None => Ok(0),
                Some(n) => setup.curves.iter().position(|c| &c.name == n).map(|i| i as u32 + 1).ok_or_else(|| {
                    invalid(format!("{user} uses curve '{n}', which `curves` does not define (it has: {})", names(setup.curves.iter().map(|c| c.name.as_str()).collect())))
                }),
            }
        };
        // Dirichlet conditions.
        let n = mesh.nodes.len();
        let mut amplitude = vec![0u32; DOFS_PER_NODE * n];
        let mut constrained = vec![false; DOFS_PER_NODE * n];
        let mut value = vec![0.0; DOFS_PER_NODE * n];
        let mut reaction_sets = Vec::new();
        let mut rotations = Vec::new();
        for c in &setup.constraints {
            let set = mesh.node_set(&c.set).ok_or_else(|| unknown("node set", &c.set, mesh.node_set_names()))?;
            let prescribed = c.displacement.as_ref().map(|d| d.as_array()).unwrap_or_default();
            let amp = amplitude_of(&c.curve, &format!("the constraint on '{}'", c.set))?;
            if let Some(r) = &c.rotation {
                if !c.fix.is_empty() {
                    return Err(invalid(format!("constraint on '{}': `rotation` prescribes every component, so `fix` cannot be given with it", c.set)));
                }
                let axis = Vector3::from(r.axis);
                let finite = r.axis.iter().chain(&r.center).all(|v| v.is_finite()) && r.angle.is_finite() && prescribed.iter().flatten().all(|v| v.is_finite());
                if !finite {
                    return Err(invalid(format!("constraint on '{}': the rotation's axis, center, angle and the displacement must be finite", c.set)));
                }
                if axis.norm() == 0.0 {
                    return Err(invalid(format!("constraint on '{}': the rotation axis [0, 0, 0] has no direction", c.set)));
                }
                let rotation_amplitude = amplitude_of(&r.curve, &format!("the rotation of '{}'", c.set))?;
                for &node in &set.nodes {
                    for i in 0..DOFS_PER_NODE {
                        constrained[DOFS_PER_NODE * node as usize + i] = true;
                    }
                }
                rotations.push(PrescribedRotation {
                    nodes: set.nodes.clone(),
                    axis: axis / axis.norm(),
                    center: Vector3::from(r.center),
                    angle: r.angle,
                    amplitude: rotation_amplitude,
                    translation: Vector3::from(prescribed.map(|v| v.unwrap_or(0.0))),
                    translation_amplitude: amp,
                });
                reaction_sets.push((c.set.clone(), set.nodes.clone()));
                continue;
            }
            if c.fix.is_empty() && prescribed.iter().all(Option::is_none) {
                return Err(invalid(format!("constraint on '{}' fixes nothing: give `fix` and/or `displacement`", c.set)));
            }
            for comp in &c.fix {
                if prescribed[comp.index()].is_some() {
                    return Err(invalid(format!("constraint on '{}': component {:?} is both fixed and prescribed", c.set, comp)));
                }
            }
            for &node in &set.nodes {
                for comp in &c.fix {
                    let d = DOFS_PER_NODE * node as usize + comp.index();
                    constrained[d] = true;
                    value[d] = 0.0;
                }
                for (i, v) in prescribed.iter().enumerate() {
                    if let Some(v) = v {
                        if !v.is_finite() {
                            return Err(invalid(format!("constraint on '{}': displacement is not finite", c.set)));
                        }
                        let d = DOFS_PER_NODE * node as usize + i;
                        constrained[d] = true;
                        value[d] = *v;
                        amplitude[d] = amp;
                    }
                }
            }
            reaction_sets.push((c.set.clone(), set.nodes.clone()));
        }
        let dofs = DofMap::from_constrained_mask(&constrained).map_err(|e| invalid(e.to_string()))?;
        let prescribed = (0..constrained.len()).filter(|&d| constrained[d] && value[d] != 0.0).map(|d| Prescribed { dof: d, value: value[d], amplitude: amplitude[d] }).collect();
        // Loads.
        let mut f_ext: Vec<Vec<f64>> = vec![Vec::new(); amplitudes.len()];
        let mut pressure_faces = Vec::new();
        for (i, l) in setup.loads.iter().enumerate() {
            let amp = amplitude_of(&l.curve, &format!("load {}", i + 1))?;
            match (&l.set, l.force, &l.face_set, l.pressure) {
                (Some(s), Some(f), None, None) => {
                    let set = mesh.node_set(s).ok_or_else(|| unknown("node set", s, mesh.node_set_names()))?;
                    if f.iter().any(|v| !v.is_finite()) {
                        return Err(invalid(format!("load {} on '{s}': force is not finite", i + 1)));
                    }
                    let share = if l.per_node { 1.0 } else { 1.0 / set.nodes.len() as f64 };
                    let f_a = &mut f_ext[amp as usize];
                    if f_a.is_empty() {
                        f_a.resize(DOFS_PER_NODE * n, 0.0);
                    }
                    for &node in &set.nodes {
                        for c in 0..3 {
                            f_a[DOFS_PER_NODE * node as usize + c] += f[c] * share;
                        }
                    }
                }
                (None, None, Some(fs), Some(p)) => {
                    let set = mesh.face_set(fs).ok_or_else(|| unknown("face set", fs, mesh.face_set_names()))?;
                    if !p.is_finite() {
                        return Err(invalid(format!("load {} on '{fs}': pressure is not finite", i + 1)));
                    }
                    pressure_faces.extend(set.faces.iter().map(|&f| PressureFace { nodes: mesh.face_nodes(f), p, amplitude: amp }));
                }
                _ => {
                    return Err(invalid(format!(
                        "load {}: give either `set` with `force` (and optionally `per_node`), or `face_set` with `pressure`",
                        i + 1
                    )))
                }
            }
        }
        let contact = contact_definitions(mesh, pairs, setup, file, &materials, &hex_material)?;
        let mut X: Vec<Vector3<f64>> = mesh.nodes.iter().map(|p| Vector3::new(p[0], p[1], p[2])).collect();
        // Adjust (Abaqus ADJUST, ANSYS ICONT): slave nodes onto the master, stress-free.
        let mut adjustments = Vec::new();
        for def in &contact {
            if let Some(d) = def.adjust {
                adjustments.push(adjust_pair(def, d, &mut X, &mesh.hexes, &mesh.node_tags, &mesh.element_tags).map_err(|source| ProblemError::Adjust { file: file.into(), source })?);
            }
        }
        Ok(Self {
            X,
            hexes: mesh.hexes.clone(),
            hex_material,
            materials,
            formulation: match setup.formulation {
                setup::Formulation::TotalLagrangian => Formulation::TotalLagrangian,
                setup::Formulation::UpdatedLagrangian => Formulation::UpdatedLagrangian,
            },
            dofs,
            prescribed,
            rotations,
            amplitudes,
            f_ext,
            pressure_faces,
            reaction_sets,
            contact,
            node_tags: mesh.node_tags.clone(),
            adjustments,
        })
    }

    /// The prescribed displacements at load factor `lambda` into `u`: each
    /// component u[dof] = value · a(t), then the rigidly moved sets (a node in a
    /// moved set takes the set's motion, whatever else names it).
    pub fn apply_prescribed(&self, lambda: f64, u: &mut [f64]) {
        for pr in &self.prescribed {
            u[pr.dof] = self.amplitudes[pr.amplitude as usize].at(lambda) * pr.value;
        }
        for r in &self.rotations {
            let (a, b) = (self.amplitudes[r.amplitude as usize].at(lambda), self.amplitudes[r.translation_amplitude as usize].at(lambda));
            for &n in &r.nodes {
                let d = r.displacement(&self.X[n as usize], a, b);
                u[DOFS_PER_NODE * n as usize..DOFS_PER_NODE * n as usize + 3].copy_from_slice(d.as_slice());
            }
        }
    }

    /// f_ext(t) = Σ_a a(t) f_ext[a] into `out` (length 3·nodes).
    pub fn external_force(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (a, f) in self.amplitudes.iter().zip(&self.f_ext).filter(|(_, f)| !f.is_empty()) {
            let s = a.at(t);
            for (o, v) in out.iter_mut().zip(f) {
                *o += s * v;
            }
        }
    }

    pub fn n_nodes(&self) -> usize {
        self.X.len()
    }

    /// The element's reference coordinates and displacements gathered from `u`.
    #[inline]
    pub fn gather(&self, e: usize, u: &[f64]) -> ([Vector3<f64>; 8], [Vector3<f64>; 8]) {
        let h = &self.hexes[e];
        let X = std::array::from_fn(|a| self.X[h[a] as usize]);
        let ue = std::array::from_fn(|a| {
            let d = DOFS_PER_NODE * h[a] as usize;
            Vector3::new(u[d], u[d + 1], u[d + 2])
        });
        (X, ue)
    }

    /// True if the tangent is symmetric: no follower pressure and every contact
    /// pair's tangent symmetric ([`ContactDefinition::symmetric_tangent`]).
    pub fn symmetric(&self) -> bool {
        self.pressure_faces.is_empty() && self.contact.iter().all(ContactDefinition::symmetric_tangent)
    }
}
