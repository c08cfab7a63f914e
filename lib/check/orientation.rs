//! Which way the master faces: is n̄ pointing at the slave body (as the contact law
//! needs, eq. 4.3: g_N > 0 open, the pressure pushes the slave along +n̄), or away
//! from it — a flipped master?
//!
//! **Slave-side criterion (decides).** Every slave node s whose projection lies on
//! the master (inside the patch) votes. Its interior point c_s is the mean of the
//! centroids of the hexahedra that hold it: a point of the slave body beside s. With
//! x̄, n̄ the foot point and normal of s,
//! ```text
//! (c_s − x̄)·n̄ > 0   the slave body lies in front of the master (right)
//! (c_s − x̄)·n̄ < 0   the slave body lies behind it: s sees the master from behind
//! ```
//! It is measured from the foot point, not from s, so it holds for a slave node that
//! touches or slightly penetrates the master, and for the nodes of a curved slave
//! whose body is on one side of the master's tangent plane. The pair is **flipped**
//! when more than half of the voters see the master from behind. This catches both
//! ways a master ends up facing away: a face set whose quads are attached to the
//! wrong hexahedra (an interface between two bodies: the quad's node order picks
//! the hexahedron, `docs/formats.md`) or a control net reversed by hand, and the
//! wrong face set chosen as master (the slave body behind the master body: the far
//! side of the master body picked).
//!
//! **Master-side criterion (reported).** Each cell (i, j) of the control net is a
//! master face: its normal (P_{i+1,j+1} − P_{i,j}) × (P_{i,j+1} − P_{i+1,j}) has the
//! sign of ā_1 × ā_2 (the patch normal n̄ of the B-spline and of the facets over that
//! net), compared with the direction from the centroid of the face's hexahedron to
//! the face's centre: n̄ should point out of the master body. `sc-tag` orients every
//! net that way, so a disagreement means a net not written by `sc-tag` or a face set
//! attached to the other body's hexahedra. When no slave node projects onto the
//! master (nothing votes), it decides alone.

#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use std::collections::HashMap;

use nalgebra::Vector3;

use crate::format::sccontact::ContactPair;
use crate::mesh::Mesh;

type V3 = Vector3<f64>;

/// The interior point of each of `nodes`: the mean of the centroids of the hexahedra
/// that hold it (NaN for a node no hexahedron holds).
pub fn interior_points(X: &[V3], hexes: &[[u32; 8]], nodes: &[u32]) -> Vec<V3> {
    let mut index = HashMap::with_capacity(nodes.len());
    for (k, &n) in nodes.iter().enumerate() {
        index.insert(n, k);
    }
    let mut sum = vec![V3::zeros(); nodes.len()];
    let mut count = vec![0u32; nodes.len()];
    for hex in hexes {
        let mut hit = false;
        for n in hex {
            hit |= index.contains_key(n);
        }
        if !hit {
            continue;
        }
        let c = hex.iter().map(|&n| X[n as usize]).sum::<V3>() / 8.0;
        for n in hex {
            if let Some(&k) = index.get(n) {
                sum[k] += c;
                count[k] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / c as f64 } else { V3::from_element(f64::NAN) }).collect()
}

/// Does the slave body beside a node lie behind the master? `c_s` its interior
/// point, `x_bar` and `n_bar` the foot point and normal; `None` when undecided
/// (not finite, or c_s on the tangent plane).
pub fn behind(c_s: &V3, x_bar: &V3, n_bar: &V3) -> Option<bool> {
    let d = (c_s - x_bar).dot(n_bar);
    (d.is_finite() && d != 0.0).then_some(d < 0.0)
}

/// The master-side count: (cells whose normal points into the master body, cells
/// compared). A cell whose four nodes are not one face of the master face set is
/// not compared.
pub fn master_cells_inward(mesh: &Mesh, X: &[V3], pair: &ContactPair) -> (usize, usize) {
    let Some(fs) = mesh.face_set(&pair.master) else { return (0, 0) };
    let mut owner: HashMap<[u32; 4], u32> = HashMap::with_capacity(fs.faces.len());
    for f in &fs.faces {
        let mut key = mesh.face_nodes(*f);
        key.sort_unstable();
        owner.insert(key, f.element);
    }
    let (mut inward, mut compared) = (0, 0);
    for cell in pair.net.cells() {
        {
            let q = cell.map(|k| pair.net.nodes[k as usize]);
            let mut key = q;
            key.sort_unstable();
            let Some(&e) = owner.get(&key) else { continue };
            let p = q.map(|n| X[n as usize]);
            let n_cell = (p[2] - p[0]).cross(&(p[3] - p[1]));
            let centre = (p[0] + p[1] + p[2] + p[3]) / 4.0;
            let hex_centroid = mesh.hexes[e as usize].iter().map(|&n| X[n as usize]).sum::<V3>() / 8.0;
            let d = n_cell.dot(&(centre - hex_centroid));
            if d.is_finite() && d != 0.0 {
                compared += 1;
                if d < 0.0 {
                    inward += 1;
                }
            }
        }
    }
    (inward, compared)
}

/// The orientation verdict of one pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Orientation {
    /// Slave nodes on the master that voted, and those that see it from behind.
    pub voters: usize,
    pub behind: usize,
    /// Master net cells compared with their hexahedron, and those facing inward.
    pub cells: usize,
    pub cells_inward: usize,
}

impl Orientation {
    /// The master faces away from the slave body: most voters see it from behind
    /// or, with no voter, most net cells face into the master body.
    pub fn flipped(&self) -> bool {
        if self.voters > 0 {
            2 * self.behind > self.voters
        } else {
            2 * self.cells_inward > self.cells
        }
    }

    /// The votes disagree among themselves (some nodes in front, some behind), or the
    /// master-side count disagrees with the verdict.
    pub fn mixed(&self) -> bool {
        let votes_mixed = self.behind > 0 && self.behind < self.voters;
        let cells_disagree = if self.flipped() { self.cells_inward < self.cells } else { self.cells_inward > 0 };
        votes_mixed || (self.cells > 0 && cells_disagree)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slave_behind_the_tangent_plane_votes_flipped() {
        let x_bar = V3::new(0.0, 0.0, 1.0);
        let up = V3::new(0.0, 0.0, 1.0);
        assert_eq!(behind(&V3::new(0.3, 0.2, 1.5), &x_bar, &up), Some(false));
        assert_eq!(behind(&V3::new(0.3, 0.2, 1.5), &x_bar, &(-up)), Some(true));
        assert_eq!(behind(&V3::new(0.3, 0.2, 1.0), &x_bar, &up), None);
        let o = Orientation { voters: 9, behind: 9, cells: 9, cells_inward: 0 };
        assert!(o.flipped() && o.mixed());
        let o = Orientation { voters: 0, behind: 0, cells: 4, cells_inward: 3 };
        assert!(o.flipped());
        let o = Orientation { voters: 10, behind: 5, cells: 4, cells_inward: 0 };
        assert!(!o.flipped() && o.mixed(), "a tie is not certainly flipped");
    }
}
