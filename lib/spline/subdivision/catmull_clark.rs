//! Catmull–Clark subdivision (Catmull & Clark 1978) of a local mesh, the subdivision
//! matrix of the `2N+8` stencil around one extraordinary vertex, and the exact
//! evaluation of the limit surface near it by repeated subdivision.
//!
//! **Rules.** One step maps a quad mesh to a finer one with
//! ```text
//! face point    f′ = (v_0 + v_1 + v_2 + v_3)/4                                  (S1)
//! edge point    e′ = (v + w + f′_1 + f′_2)/4        (edge v–w, faces 1 and 2)    (S2)
//! vertex point  v′ = (N−2)/N · v + 1/N² Σ_i e_i + 1/N² Σ_i f′_i   (valence N)    (S3)
//! ```
//! and every face `(v_0 … v_3)` splits into the four faces `(v′_c, e′_{c,c+1}, f′, e′_{c−1,c})`.
//!
//! **Subdivision matrix.** For a face whose corner 0 has valence N and whose other
//! corners are regular, the `2N+8` stencil `P⁰` (order in [`super::stencil`]) maps to the
//! stencil of the child face at that corner by the square matrix `A` (`P¹ = A P⁰`), and
//! to the 16 grid points of the three other children `c = 1, 2, 3` by `R_c` (16 × (2N+8)).
//! Both are read off one application of (S1–S3) to the canonical stencil mesh.
//!
//! **Exact evaluation.** In the stencil's parameters `(s, t) ∈ [0,1]²` (the vertex at
//! the origin), the point with `m = max(s, t) ∈ (2^{−(k+1)}, 2^{−k}]` lies in child
//! `c ≠ 0` of the level-k face, a regular bicubic patch (see [`super::bicubic`]) in
//! the local coordinates `(σ, τ) = 2^{k+1}(s, t) − (c ∈ {1,2}, c ∈ {2,3})`:
//! ```text
//! x(s, t) = b(σ, τ) · R_c · A^k · P⁰,     ∂^{i+j}x/∂s^i∂t^j = 2^{(k+1)(i+j)} ∂^{i+j}b/∂σ^i∂τ^j · R_c A^k P⁰   (E1)
//! ```
//! The row vector `b R_c A^k` is the basis: weights of the original stencil points.
//! Derivative rows sum to zero; `A` has the dominant eigenvalue 1 with right
//! eigenvector `1` and left eigenvector `w_0` (the limit mask, eq. L below), so their
//! exact products never gain a `w_0` component. Rounding would add one of size ε that
//! `A^k` keeps while the true row decays like `λ^k`; each step therefore removes it,
//! `r ← r − (Σ r) w_0`, which keeps the derivatives accurate to round-off relative to
//! their own size at any depth.
//!
//! **Limit mask** of a vertex of valence N with edge neighbours `e_i`, diagonals `f_i`:
//! ```text
//! x(0, 0) = (N² v + 4 Σ e_i + Σ f_i) / (N (N + 5))                                  (L)
//! ```
//! **Subdominant eigenvalue** (Stam 1998):
//! `λ(N) = [5 + cos(2π/N) + cos(π/N)·√(2(9 + cos(2π/N)))]/16`; near the vertex the
//! level-k patch has size `~λ^k` in space and `2^{−k}` in parameter.

use std::collections::HashMap;

use super::bicubic::{self, Rows, ORDERS};
use super::stencil::{grid_index, Boundary, LocalMesh, OpenRing};

/// One Catmull–Clark step of a local mesh (S1–S3). New points whose rule needs a face
/// outside the local mesh are not created, nor are children that would use them.
/// Returns the finer mesh and, per parent face and corner, its child face.
pub(super) fn subdivide(mesh: &LocalMesh) -> (LocalMesh, Vec<[Option<usize>; 4]>) {
    let (fine, children, _) = subdivide_with(mesh, None);
    (fine, children)
}

/// [`subdivide`] with the open boundary's rules where `boundary` marks it
/// ([`super::boundary_vertex`]):
/// ```text
/// boundary edge point     e′ = (v + w)/2                                          (B1)
/// boundary vertex point   v′ = (l + 6v + r)/8,  or v′ = v at a corner              (B2)
/// ```
/// (l, r: v's neighbours along the boundary). A boundary point gets (B2) only when its
/// fan of faces in the local mesh runs from boundary edge to boundary edge. Returns
/// the boundary of the finer mesh too: the children of boundary edges, with the edge
/// points as non-corner boundary points and the vertex points keeping their rule.
pub(super) fn subdivide_with(
    mesh: &LocalMesh,
    boundary: Option<&Boundary>,
) -> (LocalMesh, Vec<[Option<usize>; 4]>, Boundary) {
    let n_base = mesh.n_base;
    let mut fine_boundary = Boundary::default();
    let mut points: Vec<Vec<f64>> = Vec::new();
    let combo = |terms: &[(usize, f64)], pts: &[Vec<f64>]| -> Vec<f64> {
        let mut p = vec![0.0; n_base];
        for &(q, w) in terms {
            for (x, y) in p.iter_mut().zip(&pts[q]) {
                *x += w * y;
            }
        }
        p
    };
    // (S1), kept both as combinations over the base and as indices of the new mesh
    let face_combo: Vec<Vec<f64>> = mesh.faces.iter().map(|f| combo(&f.map(|v| (v, 0.25)), &mesh.points)).collect();
    let mut face_point = Vec::with_capacity(mesh.faces.len());
    for fc in &face_combo {
        face_point.push(points.len());
        points.push(fc.clone());
    }
    // (S2)
    let mut edge_point: HashMap<(usize, usize), usize> = HashMap::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        for c in 0..4 {
            let (a, b) = (face[c], face[(c + 1) % 4]);
            let key = (a.min(b), a.max(b));
            if edge_point.contains_key(&key) {
                continue;
            }
            if let Some((g, _)) = mesh.half_edge(b, a) {
                let mut p = combo(&[(a, 0.25), (b, 0.25)], &mesh.points);
                for (x, (y, z)) in p.iter_mut().zip(face_combo[f].iter().zip(&face_combo[g])) {
                    *x += 0.25 * (y + z);
                }
                edge_point.insert(key, points.len());
                points.push(p);
            } else if boundary.is_some_and(|bd| bd.is_edge(a, b)) {
                // (B1)
                fine_boundary.points.insert(points.len(), false);
                edge_point.insert(key, points.len());
                points.push(combo(&[(a, 0.5), (b, 0.5)], &mesh.points));
            }
        }
    }
    // (S3), for every point whose ring closes
    let mut first_corner: HashMap<usize, (usize, usize)> = HashMap::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        for (c, &v) in face.iter().enumerate() {
            first_corner.entry(v).or_insert((f, c));
        }
    }
    let mut vertex_point: HashMap<usize, usize> = HashMap::new();
    let mut corners: Vec<_> = first_corner.into_iter().collect();
    corners.sort_unstable();
    for (v, (f, c)) in corners {
        let Ok(ring) = mesh.ring(f, c) else {
            // (B2) on a boundary point whose fan runs from boundary edge to boundary edge
            let Some((bd, &corner)) = boundary.and_then(|bd| bd.points.get(&v).map(|c| (bd, c))) else { continue };
            let (l, r) = mesh.fan_ends(f, c);
            if !bd.is_edge(v, l) || !bd.is_edge(v, r) {
                continue;
            }
            let p = if corner { mesh.points[v].clone() } else { combo(&[(l, 0.125), (v, 0.75), (r, 0.125)], &mesh.points) };
            fine_boundary.points.insert(points.len(), corner);
            vertex_point.insert(v, points.len());
            points.push(p);
            continue;
        };
        let n = ring.len() as f64;
        let mut p: Vec<f64> = mesh.points[v].iter().map(|x| x * (n - 2.0) / n).collect();
        for &(g, cg) in &ring {
            let e = mesh.faces[g][(cg + 1) % 4];
            for (x, (y, z)) in p.iter_mut().zip(mesh.points[e].iter().zip(&face_combo[g])) {
                *x += (y + z) / (n * n);
            }
        }
        vertex_point.insert(v, points.len());
        points.push(p);
    }
    // children (v′_c, e′_{c,c+1}, f′, e′_{c−1,c})
    let ep = |a: usize, b: usize| edge_point.get(&(a.min(b), a.max(b))).copied();
    let mut faces = Vec::new();
    let mut children = Vec::with_capacity(mesh.faces.len());
    for (f, face) in mesh.faces.iter().enumerate() {
        let mut ch = [None; 4];
        for (c, slot) in ch.iter_mut().enumerate() {
            let v = vertex_point.get(&face[c]).copied();
            let e1 = ep(face[c], face[(c + 1) % 4]);
            let e2 = ep(face[(c + 3) % 4], face[c]);
            if let (Some(v), Some(e1), Some(e2)) = (v, e1, e2) {
                *slot = Some(faces.len());
                faces.push([v, e1, face_point[f], e2]);
            }
        }
        children.push(ch);
    }
    // the halves of each boundary edge
    if let Some(bd) = boundary {
        for &(a, b) in &bd.edges {
            if let Some(&e) = edge_point.get(&(a, b)) {
                for v in [a, b] {
                    if let Some(&vp) = vertex_point.get(&v) {
                        fine_boundary.edges.insert((vp.min(e), vp.max(e)));
                    }
                }
            }
        }
    }
    (LocalMesh::new(n_base, points, faces), children, fine_boundary)
}

/// Stam's subdominant eigenvalue λ(N) of Catmull–Clark at a vertex of valence N.
pub fn subdominant_eigenvalue(n: usize) -> f64 {
    let c1 = (2.0 * std::f64::consts::PI / n as f64).cos();
    let c2 = (std::f64::consts::PI / n as f64).cos();
    (5.0 + c1 + c2 * (2.0 * (9.0 + c1)).sqrt()) / 16.0
}

/// The canonical stencil mesh of valence N: points 0…2N+7 in stencil order, the N
/// faces around point 0 and the five outer faces of the three regular corners.
pub(super) fn canonical_stencil_mesh(n: usize) -> LocalMesh {
    let m = 2 * n + 8;
    let e = |i: usize| 1 + 2 * (i % n);
    let f = |i: usize| 2 + 2 * (i % n);
    let o = |j: usize| 2 * n + 1 + j;
    let mut faces: Vec<[usize; 4]> = (0..n).map(|i| [0, e(i), f(i), e(i + 1)]).collect();
    faces.extend([
        [f(n - 1), o(0), o(1), e(0)],
        [e(0), o(1), o(2), f(0)],
        [f(0), o(2), o(3), o(4)],
        [e(1), f(0), o(4), o(5)],
        [f(1), e(1), o(5), o(6)],
    ]);
    let points = (0..m)
        .map(|k| {
            let mut p = vec![0.0; m];
            p[k] = 1.0;
            p
        })
        .collect();
    LocalMesh::new(m, points, faces)
}

/// Everything the evaluation needs for one valence N ≠ 4.
#[derive(Debug, Clone)]
pub(super) struct ValenceTables {
    /// Stencil size `2N+8`.
    pub m: usize,
    /// `A`, row-major `m × m`: `P¹_i = Σ_j A[i m + j] P⁰_j` (the evaluation uses its
    /// powers below; the tests read A itself).
    #[cfg_attr(not(test), allow(dead_code))]
    a: Vec<f64>,
    /// `R_c B^k` for k = 0..=levels (k = 0: `R_c` itself) and c = 1, 2, 3, each
    /// row-major `16 × m`, rows in grid order `(i+1) + 4(j+1)`, at
    /// `table[((k·3 + c − 1)·16 + g)·m ..]`. With `A^k = B^k + 1 w_0ᵀ` (k ≥ 1) and
    /// `R_c 1 = 1`, a point's weights at level k are `b·(R_c B^k) + (b·1) w_0ᵀ`, whose
    /// second term vanishes for the derivative rows (`b·1 = 0`): one 16 × m product
    /// per evaluation. B's powers decay like λ^k, so the table keeps the subdominant
    /// part (the derivatives) to relative precision, which `R_c A^k` would bury
    /// under the `1 w_0ᵀ` of order 1.
    table: Vec<f64>,
    /// Limit mask `w_0` (eq. L) over the stencil.
    pub w0: Vec<f64>,
    /// Deepest level: `λ^levels ≤ 1e-16`; closer to the vertex the point moves out
    /// to `max(s, t) = 2^{−levels}`.
    pub levels: u32,
}

impl ValenceTables {
    pub fn new(n: usize) -> Result<Self, OpenRing> {
        let m = 2 * n + 8;
        let canon = canonical_stencil_mesh(n);
        let (fine, children) = subdivide(&canon);
        let child = |c: usize| children[0][c].ok_or(OpenRing);
        let st = fine.stencil(child(0)?, 0)?;
        debug_assert_eq!(st.len(), m);
        let mut a = vec![0.0; m * m];
        for (i, &p) in st.iter().enumerate() {
            a[i * m..(i + 1) * m].copy_from_slice(&fine.points[p]);
        }
        let mut r: [Vec<f64>; 3] = Default::default();
        for c in 1..4 {
            // origin at the child's corner nearest the parent's corner 0, axes as the parent's
            let st = fine.stencil(child(c)?, (4 - c) % 4)?;
            if st.len() != 16 {
                return Err(OpenRing);
            }
            let mut rc = vec![0.0; 16 * m];
            for (k, &p) in st.iter().enumerate() {
                let g = grid_index(k);
                rc[g * m..(g + 1) * m].copy_from_slice(&fine.points[p]);
            }
            r[c - 1] = rc;
        }
        let nf = n as f64;
        let mut w0 = vec![0.0; m];
        w0[0] = nf * nf / (nf * (nf + 5.0));
        for i in 0..n {
            w0[1 + 2 * i] = 4.0 / (nf * (nf + 5.0));
            w0[2 + 2 * i] = 1.0 / (nf * (nf + 5.0));
        }
        let levels = (1e-16f64.ln() / subdominant_eigenvalue(n).ln()).ceil() as u32;
        let mut b = a.clone();
        for i in 0..m {
            for j in 0..m {
                b[i * m + j] -= w0[j];
            }
        }
        // R_c B^k, k = 0..=levels, by repeated products with B (which decay)
        let mut table = vec![0.0; (levels as usize + 1) * 3 * 16 * m];
        for (c, rc) in r.iter().enumerate() {
            table[c * 16 * m..(c + 1) * 16 * m].copy_from_slice(rc);
        }
        for k in 1..=levels as usize {
            let (done, rest) = table.split_at_mut(k * 3 * 16 * m);
            let prev = &done[(k - 1) * 3 * 16 * m..];
            for row in 0..3 * 16 {
                let (src, dst) = (&prev[row * m..(row + 1) * m], &mut rest[row * m..(row + 1) * m]);
                for (l, &x) in src.iter().enumerate() {
                    if x != 0.0 {
                        for (o, &bl) in dst.iter_mut().zip(&b[l * m..(l + 1) * m]) {
                            *o += x * bl;
                        }
                    }
                }
            }
        }
        Ok(Self { m, a, w0, levels, table })
    }

    /// Tables read off a chain of subdivisions rather than a canonical stencil
    /// ([`super::boundary_vertex`]): `table` in the layout above over `m` base points,
    /// `w0` the limit mask of the corner at the origin.
    pub fn from_chain(m: usize, table: Vec<f64>, w0: Vec<f64>, levels: u32) -> Self {
        Self { m, a: Vec::new(), table, w0, levels }
    }

    /// `A[i][j]`.
    #[cfg(test)]
    pub fn a(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.m + j]
    }

    /// Basis weights over the `2N+8` stencil at `(s, t)` for rows `0..n_rows`
    /// (eq. E1), derivatives with respect to `(s, t)`, into `out[r][0..m]`.
    pub fn weights_into(&self, st: [f64; 2], n_rows: usize, out: &mut Rows) {
        let m = self.m;
        let [mut s, mut t] = st.map(|x| x.clamp(0.0, 1.0));
        // at the vertex: move out along the diagonal to the deepest level
        let floor = 0.5f64.powi(self.levels as i32);
        let mx = s.max(t);
        if mx < floor {
            s += floor - mx;
            t += floor - mx;
        }
        let mx = s.max(t);
        // level k: mx ∈ (2^{−(k+1)}, 2^{−k}]
        let mut k = 0u32;
        let mut scale = 2.0; // 2^{k+1}
        while scale * mx <= 1.0 {
            k += 1;
            scale *= 2.0;
        }
        let (sig, tau) = (scale * s, scale * t);
        let c = match (sig > 1.0, tau > 1.0) {
            (true, false) => 1,
            (true, true) => 2,
            _ => 3,
        };
        let local = [
            if c == 3 { sig } else { sig - 1.0 }.clamp(0.0, 1.0),
            if c == 1 { tau } else { tau - 1.0 }.clamp(0.0, 1.0),
        ];
        let mut b: Rows = [[0.0; super::super::MAX_NODES]; bicubic::N_ROWS];
        bicubic::weights_into(local, n_rows, &mut b);
        // b · R_c A^k = b · (R_c B^k) + (b · 1) w_0ᵀ (k ≥ 1; see `table`)
        let at = (k as usize * 3 + c - 1) * 16 * m;
        let pk = &self.table[at..at + 16 * m];
        for (r, (row_out, row_b)) in out.iter_mut().zip(&b).take(n_rows).enumerate() {
            row_out[..m].fill(0.0);
            for (g, &bg) in row_b[..16].iter().enumerate() {
                if bg != 0.0 {
                    for (o, &x) in row_out[..m].iter_mut().zip(&pk[g * m..(g + 1) * m]) {
                        *o += bg * x;
                    }
                }
            }
            if r == 0 && k > 0 {
                let sum: f64 = row_b[..16].iter().sum();
                for (o, &w) in row_out[..m].iter_mut().zip(&self.w0) {
                    *o += sum * w;
                }
            }
        }
        self.deflate(n_rows, out);
        // chain rule of the level-(k+1) scaling: 2^{(k+1)(i+j)}
        for (r, &(i, j)) in ORDERS.iter().enumerate().take(n_rows).skip(1) {
            let f = scale.powi((i + j) as i32);
            for x in out[r][..m].iter_mut() {
                *x *= f;
            }
        }
    }

    /// Removes the round-off `w_0` component from the derivative rows (their exact sum is 0).
    fn deflate(&self, n_rows: usize, out: &mut Rows) {
        let m = self.m;
        for row in out.iter_mut().take(n_rows).skip(1) {
            let sum: f64 = row[..m].iter().sum();
            for (x, w) in row[..m].iter_mut().zip(&self.w0) {
                *x -= sum * w;
            }
        }
    }
}
