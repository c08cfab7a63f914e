//! The limit surface at a boundary node in three or more faces (a concave corner of
//! the boundary, or a boundary node of valence ≠ 2 on a straight or curved edge):
//! exact evaluation by a chain of subdivisions with the open boundary's rules.
//!
//! **Rules.** Inside, (S1–S3) as everywhere. On the boundary, the boundary curve
//! subdivides on its own as a cubic B-spline curve (eqs. B1–B2 in
//! [`super::catmull_clark::subdivide_with`]); a boundary node in one face (a convex
//! corner) and a boundary node in three or more faces are *corners*, v′ = v: the
//! surface passes through them, and the boundary curves on either side are the
//! end-interpolating cubic B-splines of the boundary nodes. These are the rules of
//! Hoppe et al. (1994) with every irregular boundary node a corner. Where a boundary
//! node lies in two faces, (B1–B2) are the phantom points' rules ([`super::stencil`]),
//! so the surface there is the one the rest of the code evaluates.
//!
//! **Exact evaluation.** As at an interior extraordinary vertex (eq. E1), a point with
//! `max(s, t) ∈ (2^{−(k+1)}, 2^{−k}]` lies in one of the three children of the level-k
//! face that do not touch the corner. Those children have regular corners (valence 4,
//! or boundary nodes in two faces or one), and the rules that shape them after level
//! k + 1 are the regular ones with phantom points, so each is the bicubic B-spline of
//! its 16 grid points, phantoms included. Unlike the interior case, the stencil of a
//! boundary fan has no fixed size and its children's grids are not the same rows at
//! every level, so the chain is subdivided explicitly, level by level, keeping only
//! the faces around the level-k face's corners; the grids of the three children at
//! every level are the table `R_c A^k` that [`ValenceTables`] otherwise builds from
//! powers of A. Every point is carried as its deviation from the corner's limit point
//! (the limit mask `w_0`: the corner itself), which the rules map to deviations
//! because they are affine; so the derivative rows keep their relative precision at
//! every depth, as `R_c B^k` does at an interior vertex. The chain stops when the
//! deviations have decayed to 1e-16 of their first level.

use std::borrow::Cow;
use std::collections::HashMap;

use super::catmull_clark::{subdivide_with, ValenceTables};
use super::control_mesh::QuadControlMesh;
use super::stencil::{grid_index, local_mesh, Boundary, LocalMesh, Net, OpenRing};
use super::topology::{Ring, Topology};

/// Deepest level of a chain (the interior tables reach 83 at valence 14).
const MAX_LEVELS: u32 = 120;

/// Whether global node `v` (a boundary node) is a corner: in one face, or in three or more.
pub(super) fn is_corner(topo: &Topology, v: u32) -> bool {
    let ring = &topo.rings[v as usize];
    ring.boundary && ring.faces.len() != 2
}

/// Whether global node `v` is a boundary node in three or more faces.
pub(super) fn is_irregular_boundary(topo: &Topology, v: u32) -> bool {
    let ring = &topo.rings[v as usize];
    ring.boundary && ring.faces.len() > 2
}

/// A subdivided local mesh read as a [`Net`]: its points are the nodes.
struct SubNet<'a> {
    lm: &'a LocalMesh,
    at: HashMap<usize, (usize, usize)>,
}

impl<'a> SubNet<'a> {
    fn new(lm: &'a LocalMesh) -> Self {
        let mut at = HashMap::new();
        for (f, face) in lm.faces.iter().enumerate() {
            for (c, &p) in face.iter().enumerate() {
                at.entry(p).or_insert((f, c));
            }
        }
        Self { lm, at }
    }
}

impl Net for SubNet<'_> {
    fn quad(&self, g: usize) -> [u32; 4] {
        self.lm.faces[g].map(|p| p as u32)
    }
    fn ring(&self, v: u32) -> Cow<'_, Ring> {
        let (faces, closed) = match self.at.get(&(v as usize)) {
            Some(&(f, c)) => self.lm.fan(f, c),
            None => (Vec::new(), true),
        };
        Cow::Owned(Ring { faces, boundary: !closed })
    }
    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.lm.half_edge(a as usize, b as usize).is_some()
    }
}

/// The local mesh of face `g` of a subdivided local mesh (face 0 of the result): the
/// faces around its corners with phantom points added across the boundary, each point
/// a combination of `lm`'s base.
pub(super) fn stencil_rows(lm: &LocalMesh, g: usize) -> Result<LocalMesh, OpenRing> {
    let (ph, support) = local_mesh(&SubNet::new(lm), g).map_err(|_| OpenRing)?;
    let points = ph
        .points
        .iter()
        .map(|p| {
            let mut row = vec![0.0; lm.n_base];
            for (&w, &s) in p.iter().zip(&support) {
                if w != 0.0 {
                    for (o, &x) in row.iter_mut().zip(&lm.points[s as usize]) {
                        *o += w * x;
                    }
                }
            }
            row
        })
        .collect();
    Ok(LocalMesh::new(lm.n_base, points, ph.faces.clone()))
}

/// The real faces around the four corners of global face `face` (face 0 of the
/// result), its points the identity over the returned support (global nodes), and the
/// open boundary among them.
pub(super) fn real_local_mesh(mesh: &QuadControlMesh, topo: &Topology, face: usize) -> (LocalMesh, Boundary, Vec<u32>) {
    let mut faces: Vec<usize> = vec![face];
    for &v in &mesh.faces[face] {
        for &(g, _) in &topo.rings[v as usize].faces {
            if !faces.contains(&g) {
                faces.push(g);
            }
        }
    }
    let mut support: Vec<u32> = Vec::new();
    let mut col = |n: u32| match support.iter().position(|&s| s == n) {
        Some(i) => i,
        None => {
            support.push(n);
            support.len() - 1
        }
    };
    let local: Vec<[usize; 4]> = faces.iter().map(|&g| mesh.faces[g].map(&mut col)).collect();
    let m = support.len();
    let points = (0..m)
        .map(|k| {
            let mut p = vec![0.0; m];
            p[k] = 1.0;
            p
        })
        .collect();
    let mut boundary = Boundary::default();
    for (k, &n) in support.iter().enumerate() {
        if topo.rings[n as usize].boundary {
            boundary.points.insert(k, is_corner(topo, n));
        }
    }
    for (&g, q) in faces.iter().zip(&local) {
        let nodes = mesh.faces[g];
        for c in 0..4 {
            if topo.half_edge(nodes[(c + 1) % 4], nodes[c]).is_none() {
                let (a, b) = (q[c], q[(c + 1) % 4]);
                boundary.edges.insert((a.min(b), a.max(b)));
            }
        }
    }
    (LocalMesh::new(m, points, local), boundary, support)
}

/// The faces of `lm` around the corners of face `g` (face 0 of the result, same
/// corner order), their points renumbered, and the boundary among them.
fn neighbourhood(lm: &LocalMesh, bd: &Boundary, g: usize) -> Result<(LocalMesh, Boundary), OpenRing> {
    let mut keep: Vec<usize> = vec![g];
    for c in 0..4 {
        let (fan, closed) = lm.fan(g, c);
        let v = lm.faces[g][c];
        if !closed && !bd.points.contains_key(&v) {
            return Err(OpenRing);
        }
        for (f, _) in fan {
            if !keep.contains(&f) {
                keep.push(f);
            }
        }
    }
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut points = Vec::new();
    let faces: Vec<[usize; 4]> = keep
        .iter()
        .map(|&f| {
            lm.faces[f].map(|p| {
                *index.entry(p).or_insert_with(|| {
                    points.push(lm.points[p].clone());
                    points.len() - 1
                })
            })
        })
        .collect();
    let mut nb = Boundary::default();
    for (&p, &corner) in &bd.points {
        if let Some(&q) = index.get(&p) {
            nb.points.insert(q, corner);
        }
    }
    for &(a, b) in &bd.edges {
        if let (Some(&p), Some(&q)) = (index.get(&a), index.get(&b)) {
            nb.edges.insert((p.min(q), p.max(q)));
        }
    }
    Ok((LocalMesh::new(lm.n_base, points, faces), nb))
}

/// The limit mask of boundary point `v` of `lm` (corner `corner` of face `g`): the
/// point itself at a corner, `(l + 4v + r)/6` on a smooth stretch of the boundary.
fn boundary_limit(lm: &LocalMesh, bd: &Boundary, g: usize, corner: usize) -> Result<Vec<f64>, OpenRing> {
    let v = lm.faces[g][corner];
    match bd.points.get(&v) {
        Some(true) => Ok(lm.points[v].clone()),
        Some(false) => {
            let (l, r) = lm.fan_ends(g, corner);
            Ok(lm.points[v].iter().zip(&lm.points[l]).zip(&lm.points[r]).map(|((x, y), z)| (4.0 * x + y + z) / 6.0).collect())
        }
        None => Err(OpenRing),
    }
}

/// The evaluation tables of face `g` of `lm` (a real local mesh or one subdivision
/// of it) near its corner `r`, a boundary node: the grids of the three children that
/// do not touch the corner at every level, in [`ValenceTables`]' layout over `lm`'s base.
pub(super) fn corner_tables(lm: &LocalMesh, bd: &Boundary, g: usize, r: usize) -> Result<ValenceTables, OpenRing> {
    let m = lm.n_base;
    let w0 = boundary_limit(lm, bd, g, r)?;
    // every point as its deviation from the limit point
    let deviations = lm.points.iter().map(|p| p.iter().zip(&w0).map(|(x, w)| x - w).collect()).collect();
    let (mut lm, mut bd) = neighbourhood(&LocalMesh::new(m, deviations, lm.faces.clone()), bd, g)?;
    let (mut g, mut r) = (0, r);
    let mut table: Vec<f64> = Vec::new();
    let mut first = 0.0;
    let mut levels = 0;
    for k in 0..=MAX_LEVELS {
        let (fine, children, fine_bd) = subdivide_with(&lm, Some(&bd));
        let mut size = 0.0f64;
        for c in 1..4 {
            let child = children[g][(r + c) % 4].ok_or(OpenRing)?;
            let st_mesh = stencil_rows(&fine, child)?;
            let st = st_mesh.stencil(0, (4 - c) % 4)?;
            if st.len() != 16 {
                return Err(OpenRing);
            }
            let mut rc = vec![0.0; 16 * m];
            for (i, &p) in st.iter().enumerate() {
                let row = &mut rc[grid_index(i) * m..(grid_index(i) + 1) * m];
                row.copy_from_slice(&st_mesh.points[p]);
                size = size.max(row.iter().fold(0.0f64, |a, x| a.max(x.abs())));
                if k == 0 {
                    for (o, w) in row.iter_mut().zip(&w0) {
                        *o += w;
                    }
                }
            }
            table.extend(rc);
        }
        levels = k;
        if k == 1 {
            first = size;
        } else if k > 1 && size <= 1e-16 * first {
            break;
        }
        let next = children[g][r].ok_or(OpenRing)?;
        (lm, bd) = neighbourhood(&fine, &fine_bd, next)?;
        (g, r) = (0, 0);
    }
    Ok(ValenceTables::from_chain(m, table, w0, levels))
}

/// Whether the faces of global face `face` need this module: a corner is a boundary
/// node in three or more faces.
pub(super) fn touches_irregular_boundary(mesh: &QuadControlMesh, topo: &Topology, face: usize) -> bool {
    mesh.faces[face].iter().any(|&v| is_irregular_boundary(topo, v))
}
