//! Rigid-body modes that no Dirichlet condition holds: the zero-energy modes of each
//! body under its constraints, found before the first solve.
//!
//! **Bodies.** The connected components of the hexahedral mesh (hexahedra sharing a
//! node belong together, across physical volumes: a glued interface makes one
//! mechanical body), each named by the physical volumes it holds (`lower`,
//! `lower+upper`; a volume split into several components: `lower (part 2 of 3)`).
//!
//! **Modes.** With c the body's centroid and L the RMS distance of its nodes from c,
//! the six rigid modes of a node at X are, per unit parameter,
//! ```text
//! translation e_k:        u = e_k                       (k = x, y, z)
//! rotation about e_k:     u = e_k × (X − c) / L
//! ```
//! (the rotations scaled by L so all six columns have the size of a unit
//! translation). Every constrained dof d (fixed or prescribed) of a body node gives
//! the row r_d = [the d-component of the six modes]: a rigid motion q ∈ ℝ⁶ is held
//! when R q ≠ 0. The free modes are the null space of R (m × 6), from the singular
//! values of the 6 × 6 Gram matrix G = Rᵀ R = V Σ² Vᵀ (nalgebra's SVD; σ² are its
//! singular values): a mode is free when σ ≤ 10⁻⁶ σ_max, or all six when no dof of
//! the body is constrained. The null-space basis is brought to reduced row-echelon
//! form over the six (translations first), so the common cases read as single modes
//! ("translation x", "rotation about z") and a coupled one as a unit vector over the
//! six (e.g. rotation about an axis away from the centroid).
//!
//! A body whose free modes only contact can hold is legitimate (a block pressed onto
//! another): the solve warns, it does not fail. The touching-node rule
//! (`docs/theory/contact.md`, "Touching nodes") gives it normal stiffness at a zero
//! gap; its tangential modes need friction in stick, or supports.
#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use nalgebra::{Matrix6, Vector3, Vector6};

use crate::mesh::Mesh;

type V3 = Vector3<f64>;

/// The six rigid modes, in order.
pub const MODE_NAMES: [&str; 6] = ["translation x", "translation y", "translation z", "rotation about x", "rotation about y", "rotation about z"];

/// Relative tolerance on the singular values of R: σ ≤ RELATIVE_TOLERANCE · σ_max is zero.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;

/// One connected body of the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    pub name: String,
    /// Sorted node indices.
    pub nodes: Vec<u32>,
    /// Physical volumes (indices into `mesh.bodies`) it holds.
    pub bodies: Vec<usize>,
}

/// The connected components of the hexahedra (through shared nodes), in the order of
/// their first hexahedron.
pub fn components(mesh: &Mesh) -> Vec<Component> {
    let n = mesh.nodes.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            let p = parent[parent[a as usize] as usize];
            parent[a as usize] = p;
            a = p;
        }
        a
    }
    for hex in &mesh.hexes {
        let r0 = root(&mut parent, hex[0]);
        for &v in &hex[1..] {
            let r = root(&mut parent, v);
            if r != r0 {
                parent[r as usize] = r0;
            }
        }
    }
    let mut index_of_root: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    let mut comps: Vec<Component> = Vec::new();
    for (e, hex) in mesh.hexes.iter().enumerate() {
        let r = root(&mut parent, hex[0]);
        let k = *index_of_root.entry(r).or_insert_with(|| {
            comps.push(Component { name: String::new(), nodes: Vec::new(), bodies: Vec::new() });
            comps.len() - 1
        });
        let b = mesh.hex_body.get(e).copied().unwrap_or(0) as usize;
        if !comps[k].bodies.contains(&b) {
            comps[k].bodies.push(b);
        }
    }
    let mut seen = vec![false; n];
    for hex in &mesh.hexes {
        for &v in hex {
            if !seen[v as usize] {
                seen[v as usize] = true;
                let r = root(&mut parent, v);
                comps[index_of_root[&r]].nodes.push(v);
            }
        }
    }
    for c in &mut comps {
        c.nodes.sort_unstable();
        c.bodies.sort_unstable();
    }
    // names: the physical volumes it holds; a volume in several components is numbered
    let body_name = |b: usize| mesh.bodies.get(b).map_or_else(|| format!("body {b}"), |x| x.name.clone());
    let names: Vec<String> = comps.iter().map(|c| c.bodies.iter().map(|&b| body_name(b)).collect::<Vec<_>>().join("+")).collect();
    for (k, c) in comps.iter_mut().enumerate() {
        let same: Vec<usize> = (0..names.len()).filter(|&j| names[j] == names[k]).collect();
        c.name = if same.len() > 1 { format!("{} (part {} of {})", names[k], same.iter().position(|&j| j == k).unwrap_or(0) + 1, same.len()) } else { names[k].clone() };
    }
    comps
}

/// A free rigid mode: a unit vector q over [`MODE_NAMES`] (rotations scaled by the
/// body's length L).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeMode(pub [f64; 6]);

impl FreeMode {
    /// In plain words: "translation x", or "0.707 translation x + 0.707 rotation about z".
    pub fn describe(&self) -> String {
        let q = self.0;
        let terms: Vec<usize> = (0..6).filter(|&i| q[i].abs() > 1e-9).collect();
        if terms.len() == 1 {
            return MODE_NAMES[terms[0]].to_string();
        }
        let mut s = String::new();
        for (k, &i) in terms.iter().enumerate() {
            let v = q[i];
            if k == 0 {
                s.push_str(&format!("{:.3} {}", v, MODE_NAMES[i]));
            } else {
                s.push_str(&format!(" {} {:.3} {}", if v < 0.0 { '-' } else { '+' }, v.abs(), MODE_NAMES[i]));
            }
        }
        s
    }

    /// The unit mode, when this is one.
    pub fn single(&self) -> Option<&'static str> {
        let terms: Vec<usize> = (0..6).filter(|&i| self.0[i].abs() > 1e-9).collect();
        (terms.len() == 1).then(|| MODE_NAMES[terms[0]])
    }
}

/// The rigid modes of one body and those no constraint holds.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyModes {
    pub name: String,
    /// Its nodes, sorted.
    pub nodes: Vec<u32>,
    /// Constrained dofs of the body (fixed or prescribed).
    pub constrained_dofs: usize,
    pub centroid: [f64; 3],
    /// L, the RMS distance of the nodes from the centroid (the rotations' scale).
    pub length: f64,
    /// The free modes (empty: the constraints hold all six).
    pub free: Vec<FreeMode>,
    /// Contact pairs with slave or master nodes on this body (what can hold it).
    pub contact_pairs: Vec<String>,
}

impl BodyModes {
    /// "translation x, translation y, rotation about z".
    pub fn free_list(&self) -> String {
        self.free.iter().map(FreeMode::describe).collect::<Vec<_>>().join(", ")
    }

    /// The warning about a body with free modes (`None` when the constraints hold all six).
    pub fn warning(&self) -> Option<String> {
        if self.free.is_empty() {
            return None;
        }
        let held = if self.contact_pairs.is_empty() {
            "and no contact pair touches the body: expect a singular tangent".to_string()
        } else {
            format!("only contact ({}) can", self.contact_pairs.iter().map(|p| format!("pair '{p}'")).collect::<Vec<_>>().join(", "))
        };
        Some(format!("body '{}': no constraint holds {}; {held}", self.name, self.free_list()))
    }
}

/// The free rigid modes of the body made of `nodes` (positions `X`), whose dof d is
/// constrained when `constrained(d)` (d = 3·node + component). Returns (free modes,
/// centroid, L, constrained dofs).
pub fn free_modes(X: &[V3], nodes: &[u32], constrained: impl Fn(usize) -> bool) -> (Vec<FreeMode>, V3, f64, usize) {
    if nodes.is_empty() {
        return (Vec::new(), V3::zeros(), 0.0, 0);
    }
    let c = nodes.iter().map(|&n| X[n as usize]).sum::<V3>() / nodes.len() as f64;
    let l = (nodes.iter().map(|&n| (X[n as usize] - c).norm_squared()).sum::<f64>() / nodes.len() as f64).sqrt();
    let l = if l > 0.0 { l } else { 1.0 };
    // G = Rᵀ R, accumulated row by row (R has one row per constrained dof)
    let mut g = Matrix6::<f64>::zeros();
    let mut m = 0usize;
    for &n in nodes {
        let r = (X[n as usize] - c) / l;
        for k in 0..3 {
            if !constrained(3 * n as usize + k) {
                continue;
            }
            m += 1;
            // component k of the six modes: e_j (translation), (e_j × r)_k (rotation)
            let mut row = Vector6::<f64>::zeros();
            row[k] = 1.0;
            for j in 0..3 {
                let mut e = V3::zeros();
                e[j] = 1.0;
                row[3 + j] = e.cross(&r)[k];
            }
            g += row * row.transpose();
        }
    }
    let free = if m == 0 {
        (0..6).map(|i| {
            let mut q = [0.0; 6];
            q[i] = 1.0;
            FreeMode(q)
        }).collect()
    } else {
        null_space(&g)
    };
    (free, c, l, m)
}

/// The null space of R from G = Rᵀ R: singular vectors of G with σ_G ≤ tol² σ_G,max
/// (σ_G = σ_R²), in reduced row-echelon form over the six modes.
pub fn null_space(g: &Matrix6<f64>) -> Vec<FreeMode> {
    let svd = g.svd(false, true);
    let Some(v_t) = svd.v_t else { return Vec::new() };
    let s_max = svd.singular_values.max();
    let zero = RELATIVE_TOLERANCE * RELATIVE_TOLERANCE * s_max;
    let mut basis: Vec<[f64; 6]> = (0..6).filter(|&i| svd.singular_values[i] <= zero).map(|i| std::array::from_fn(|j| v_t[(i, j)])).collect();
    // reduced row-echelon form: pivot on the modes in order (translations first)
    let mut row = 0;
    for col in 0..6 {
        if row == basis.len() {
            break;
        }
        let Some(p) = (row..basis.len()).max_by(|&a, &b| basis[a][col].abs().total_cmp(&basis[b][col].abs())) else { break };
        if basis[p][col].abs() < 1e-8 {
            continue;
        }
        basis.swap(row, p);
        let pivot = basis[row][col];
        for v in basis[row].iter_mut() {
            *v /= pivot;
        }
        let pivot_row = basis[row];
        for (r, q) in basis.iter_mut().enumerate() {
            let f = q[col];
            if r != row && f != 0.0 {
                for (v, p) in q.iter_mut().zip(&pivot_row) {
                    *v -= f * p;
                }
            }
        }
        row += 1;
    }
    basis
        .into_iter()
        .map(|mut q| {
            for v in q.iter_mut() {
                if v.abs() < 1e-9 {
                    *v = 0.0;
                }
            }
            let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            FreeMode(q.map(|v| v / norm))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 8 corners of the unit cube [0, 1]³.
    fn cube() -> Vec<V3> {
        (0..8).map(|i| V3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64)).collect()
    }

    fn names(free: &[FreeMode]) -> Vec<String> {
        free.iter().map(FreeMode::describe).collect()
    }

    #[test]
    fn unconstrained_body_has_all_six() {
        let x = cube();
        let nodes: Vec<u32> = (0..8).collect();
        let (free, c, _, m) = free_modes(&x, &nodes, |_| false);
        assert_eq!((free.len(), m), (6, 0));
        assert!((c - V3::new(0.5, 0.5, 0.5)).norm() < 1e-15);
        assert_eq!(names(&free), MODE_NAMES.map(String::from).to_vec());
    }

    #[test]
    fn z_held_on_the_bottom_face_leaves_the_in_plane_modes() {
        let x = cube();
        let nodes: Vec<u32> = (0..8).collect();
        // bottom face z = 0: nodes 0..4, their z dof
        let (free, ..) = free_modes(&x, &nodes, |d| d % 3 == 2 && d / 3 < 4);
        assert_eq!(names(&free), ["translation x", "translation y", "rotation about z"]);
    }

    #[test]
    fn clamped_face_holds_everything() {
        let x = cube();
        let nodes: Vec<u32> = (0..8).collect();
        let (free, _, _, m) = free_modes(&x, &nodes, |d| d / 3 < 4);
        assert_eq!(m, 12);
        assert!(free.is_empty(), "{:?}", names(&free));
    }

    #[test]
    fn one_pinned_corner_leaves_rotations_about_it() {
        // node 0 at the origin held in x, y, z: the three rotations about the corner
        // are free; about the centroid (0.5, 0.5, 0.5) each is a rotation plus a
        // translation, so in echelon form each free mode couples a translation
        // with rotations
        let x = cube();
        let nodes: Vec<u32> = (0..8).collect();
        let (free, c, l, _) = free_modes(&x, &nodes, |d| d / 3 == 0);
        assert_eq!(free.len(), 3);
        for q in &free {
            // a rigid motion that keeps node 0 in place: u(0) = t + ω × (X_0 − c) = 0
            let t = V3::new(q.0[0], q.0[1], q.0[2]);
            let w = V3::new(q.0[3], q.0[4], q.0[5]) / l;
            let u0 = t + w.cross(&(x[0] - c));
            assert!(u0.norm() < 1e-12, "{} moves the pinned node by {u0}", q.describe());
            assert!(q.single().is_none(), "{}", q.describe());
        }
    }

    #[test]
    fn a_line_of_pinned_nodes_leaves_the_rotation_about_it() {
        // nodes on the edge x = 0, y = 0 (0 and 4) held in x, y, z: rotation about
        // that edge (parallel to z, off the centroid) is free, and nothing else
        let x = cube();
        let nodes: Vec<u32> = (0..8).collect();
        let (free, ..) = free_modes(&x, &nodes, |d| d / 3 == 0 || d / 3 == 4);
        assert_eq!(free.len(), 1);
        let q = free[0].0;
        // about the z axis through (0, 0): ω e_z × (X − c) + t = 0 at X = (0, 0, ·)
        assert!(q[2].abs() < 1e-12 && q[3].abs() < 1e-12 && q[4].abs() < 1e-12, "{}", free[0].describe());
        assert!(q[5].abs() > 0.1 && q[0].abs() > 0.1 && q[1].abs() > 0.1, "{}", free[0].describe());
    }

    #[test]
    fn the_tolerance_is_relative() {
        // the same constraints on a body a million times larger give the same modes
        let nodes: Vec<u32> = (0..8).collect();
        let big: Vec<V3> = cube().iter().map(|p| p * 1e6 + V3::new(3e7, 0.0, -1e6)).collect();
        let (free, ..) = free_modes(&big, &nodes, |d| d % 3 == 2 && d / 3 < 4);
        assert_eq!(names(&free), ["translation x", "translation y", "rotation about z"]);
    }
}
