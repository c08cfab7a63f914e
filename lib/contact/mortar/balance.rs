//! `transfer: balanced`: the master's own smooth basis, recombined so that a
//! uniform pressure gives the master body the consistent nodal forces of its faces.
//!
//! Through the surface's basis Q_A (eq. 6.2, `transfer: surface`) a uniform pressure
//! p gives master node A the force p ∫ Q_A dA. The master body's hex8 faces take p
//! ∫ N^F_k dA (the trace's bilinear functions), and only those forces leave a
//! uniformly pressed body uniformly strained: near the patch's edges the open knot
//! vector's basis weighs the nodes differently (1D, order 3: ∫ Q h⁻¹ = 0.58, 0.88,
//! … against 0.5, 1, …), and the patch test fails (37 % pointwise). The balanced
//! transfer basis is
//! ```text
//! T_k = Σ_A M_kA Q_A            with   Σ_k M_kA = 1   (Σ_k T_k = 1: forces balance)
//!                                      Σ_A M_kA q_A = f_k   (a uniform p: the faces' forces)
//! q_A = ∫_Γ Q_A dA  (the smooth surface),   f_k = ∫ N^F_k dA  (the facets)
//! ```
//! M fixed in the reference configuration (a constant of the model, so δT_k =
//! Σ_A M_kA δQ_A), as close to the identity as these conditions allow: M_kA ≠ δ_kA
//! only for k, A sharing a trace cell, both in the region where f and q differ (and
//! its first ring), and the least change ‖M − I‖_F there. Its Lagrange conditions
//! give M_kA = δ_kA + α_A + β_k q_A with α_A = −q_A B_A / |P_A|, B_A = Σ_{j∈P_A} β_j,
//! and β the solution of the weighted graph Laplacian
//! ```text
//! S_k β_k − Σ_{A∈P_k} (q_A² / |P_A|) B_A = f_k − q_k,     S_k = Σ_{A∈P_k} q_A²
//! ```
//! (P_A: the nodes k that may take a share of Q_A), solved by conjugate gradients on
//! each connected piece of the region. M moves force only within a piece, so each
//! piece's f is first scaled to its Σ q (on a flat net's edge band they agree; where
//! the master is curved, the facets' area is the smooth surface's to O(h²)). On a flat uniform net the region is the band
//! along the patch's edges, and inside it T_k = Q_k: the surface transfer's
//! smoothness in sliding is kept. On a facet master Q = N^F and M = I.
//!
//! What it does not give: the trace transfer's exactness. The mortar integrals of
//! T_k run over the slave's segments, cut by the trace cells, not by the knot lines
//! where T_k's derivatives jump, and the open patch's parameter is not affine in x
//! near its edges; both are quadrature errors of the uniform pressure's forces.

use super::segment::gauss_legendre;
use super::trace::Trace;
use crate::contact::master::Projector;
use crate::spline::{SurfaceBasis, Vec3};

/// Gauss–Legendre points per direction of the surface and facet integrals (degree 15).
const GAUSS_POINTS: usize = 8;

/// The recombination M of a master net's basis (module docs), stored by columns:
/// the nodes k that receive a share M_kA of Q_A.
#[derive(Debug, Clone)]
pub struct Balance {
    offsets: Vec<u32>,
    entries: Vec<(u32, f64)>,
    /// max_k |Σ_A M_kA q_A − f_k| / max_k f_k after the solve.
    pub defect: f64,
    /// Net nodes where M differs from the identity.
    pub region: usize,
}

/// One transfer function at a point: net node k, T_k and T_{k,α}.
pub type TransferValue = (usize, f64, [f64; 2]);

impl Balance {
    /// The balance of the master `geometry` (reference configuration) over the trace
    /// cells of its net, `x_net` the net's reference positions.
    pub fn new(geometry: &Projector, trace: &Trace, x_net: &[Vec3]) -> Self {
        let n = x_net.len();
        let identity = |defect| Self { offsets: (0..=n as u32).collect(), entries: (0..n as u32).map(|k| (k, 1.0)).collect(), defect, region: 0 };
        if geometry.is_facets() {
            return identity(0.0);
        }
        let q = surface_integrals(geometry, n);
        let mut f = facet_integrals(trace, x_net);
        let f_max = f.iter().copied().fold(0.0, f64::max);
        if f_max.is_nan() || f_max <= 0.0 {
            return identity(f64::INFINITY);
        }
        // the net's adjacency: nodes sharing a trace cell
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
        for c in 0..trace.n_cells() {
            let cs = trace.corners(c);
            for &a in &cs {
                adj[a as usize].extend_from_slice(&cs);
            }
        }
        for a in adj.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        // the region: where f and q differ, and its first ring
        let differs: Vec<bool> = (0..n).map(|k| (f[k] - q[k]).abs() > 1e-13 * f_max).collect();
        let mut in_region = differs.clone();
        for k in 0..n {
            if differs[k] {
                for &j in &adj[k] {
                    in_region[j as usize] = true;
                }
            }
        }
        let region = in_region.iter().filter(|&&r| r).count();
        if region == 0 {
            return identity(0.0);
        }
        // P_A: the region's nodes next to A (A itself included)
        let pat: Vec<Vec<u32>> = (0..n).map(|a| if in_region[a] { adj[a].iter().copied().filter(|&k| in_region[k as usize]).collect() } else { Vec::new() }).collect();
        // M only moves force within a connected piece of the region (Σ_k (M q)_k =
        // Σ_A q_A over it), so each piece's f is scaled to its q: on a flat net's
        // edge band the two sums agree already; where the master is curved the
        // facets' area is the smooth surface's to O(h²)
        let piece = pieces(&pat, &in_region);
        let (sum_q, sum_f) = (per_piece(&piece, &q), per_piece(&piece, &f));
        for k in 0..n {
            if let Some(p) = piece[k] {
                if sum_f[p] > 0.0 {
                    f[k] *= sum_q[p] / sum_f[p];
                }
            }
        }
        let s: Vec<f64> = (0..n).map(|k| pat[k].iter().map(|&a| q[a as usize] * q[a as usize]).sum()).collect();
        let mut big_b = vec![0.0; n];
        let apply = |beta: &[f64], out: &mut [f64]| {
            for (a, bb) in big_b.iter_mut().enumerate() {
                *bb = pat[a].iter().map(|&j| beta[j as usize]).sum::<f64>() * q[a] * q[a] / pat[a].len().max(1) as f64;
            }
            for k in 0..n {
                out[k] = if in_region[k] { s[k] * beta[k] - pat[k].iter().map(|&a| big_b[a as usize]).sum::<f64>() } else { 0.0 };
            }
        };
        // right-hand side, without what round-off leaves of its mean on each piece
        // (L's null space: the constants on a piece)
        let mut b: Vec<f64> = (0..n).map(|k| if in_region[k] { f[k] - q[k] } else { 0.0 }).collect();
        let (sum, count) = (per_piece(&piece, &b), per_piece(&piece, &vec![1.0; n]));
        for k in 0..n {
            if let Some(p) = piece[k] {
                b[k] -= sum[p] / count[p];
            }
        }
        let beta = conjugate_gradients(apply, &b, 1e-14);
        // the columns: M_kA = δ_kA + α_A + β_k q_A on P_A
        let mut offsets = Vec::with_capacity(n + 1);
        let mut entries = Vec::with_capacity(n);
        offsets.push(0u32);
        for a in 0..n {
            if in_region[a] {
                let big_b: f64 = pat[a].iter().map(|&j| beta[j as usize]).sum();
                let alpha = -q[a] * big_b / pat[a].len() as f64;
                for &k in &pat[a] {
                    let m = if k as usize == a { 1.0 } else { 0.0 } + alpha + beta[k as usize] * q[a];
                    entries.push((k, m));
                }
            } else {
                entries.push((a as u32, 1.0));
            }
            offsets.push(entries.len() as u32);
        }
        let mut out = Self { offsets, entries, defect: 0.0, region };
        let mut mq = vec![0.0; n];
        for (a, &qa) in q.iter().enumerate() {
            for &(k, m) in out.column(a) {
                mq[k as usize] += m * qa;
            }
        }
        out.defect = (0..n).map(|k| (mq[k] - f[k]).abs()).fold(0.0, f64::max) / f_max;
        out
    }

    /// Column A of M: the nodes k and their shares M_kA of Q_A.
    pub fn column(&self, a: usize) -> &[(u32, f64)] {
        &self.entries[self.offsets[a] as usize..self.offsets[a + 1] as usize]
    }

    /// The transfer functions T_k = Σ_A M_kA Q_A and their derivatives at a point of
    /// the surface with basis `basis` (net positions), into `out` (cleared).
    pub fn combine(&self, basis: &SurfaceBasis, out: &mut Vec<TransferValue>) {
        out.clear();
        for ((&a, &qa), qa_al) in basis.nodes().iter().zip(basis.q()).zip(basis.q_alpha()) {
            for &(k, m) in self.column(a) {
                let k = k as usize;
                let (v, d) = (m * qa, [m * qa_al[0], m * qa_al[1]]);
                match out.iter_mut().find(|e| e.0 == k) {
                    Some(e) => {
                        e.1 += v;
                        e.2[0] += d[0];
                        e.2[1] += d[1];
                    }
                    None => out.push((k, v, d)),
                }
            }
        }
    }
}

/// q_A = ∫ Q_A dA over the smooth master, by 8 × 8 Gauss points per knot span (one
/// patch) or per chart (an atlas: each chart the unit square).
fn surface_integrals(geometry: &Projector, n: usize) -> Vec<f64> {
    let gauss = gauss_legendre(GAUSS_POINTS);
    let mut q = vec![0.0; n];
    let mut add = |xi: [f64; 2], cell: Option<[usize; 2]>, w: f64| {
        let sp = geometry.evaluate(xi, cell);
        let da = sp.a_alpha[0].cross(&sp.a_alpha[1]).norm() * w;
        for (&a, &qa) in sp.basis.nodes().iter().zip(sp.basis.q()) {
            q[a] += qa * da;
        }
    };
    match geometry {
        Projector::BSpline(pr) => {
            let patch = pr.patch();
            let [na, nb] = patch.n_spans();
            for sb in 0..nb {
                let (b0, b1) = patch.knots(1).span_bounds(sb);
                for sa in 0..na {
                    let (a0, a1) = patch.knots(0).span_bounds(sa);
                    for &(u, wu) in &gauss {
                        for &(v, wv) in &gauss {
                            add([a0 + (a1 - a0) * u, b0 + (b1 - b0) * v], Some([sa, sb]), wu * wv * (a1 - a0) * (b1 - b0));
                        }
                    }
                }
            }
        }
        _ => {
            for c in 0..geometry.n_charts() {
                for &(u, wu) in &gauss {
                    for &(v, wv) in &gauss {
                        add([u, v], Some([c, 0]), wu * wv);
                    }
                }
            }
        }
    }
    q
}

/// f_k = ∫ N^F_k dA over the trace's bilinear facets (corner cycle x_00, x_10, x_11,
/// x_01), 8 × 8 Gauss points per cell.
fn facet_integrals(trace: &Trace, x_net: &[Vec3]) -> Vec<f64> {
    let gauss = gauss_legendre(GAUSS_POINTS);
    let mut f = vec![0.0; x_net.len()];
    for c in 0..trace.n_cells() {
        let k = trace.corners(c);
        let x = k.map(|k| x_net[k as usize]);
        for &(s, ws) in &gauss {
            for &(t, wt) in &gauss {
                let n = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
                let xs = (x[1] - x[0]) * (1.0 - t) + (x[2] - x[3]) * t;
                let xt = (x[3] - x[0]) * (1.0 - s) + (x[2] - x[1]) * s;
                let da = xs.cross(&xt).norm() * ws * wt;
                for l in 0..4 {
                    f[k[l] as usize] += n[l] * da;
                }
            }
        }
    }
    f
}

/// The connected pieces of the region under the pattern (`None` outside it).
fn pieces(pat: &[Vec<u32>], in_region: &[bool]) -> Vec<Option<usize>> {
    let mut piece = vec![None; pat.len()];
    let mut next = 0;
    let mut stack = Vec::new();
    for k0 in 0..pat.len() {
        if !in_region[k0] || piece[k0].is_some() {
            continue;
        }
        piece[k0] = Some(next);
        stack.push(k0);
        while let Some(k) = stack.pop() {
            for &j in &pat[k] {
                if piece[j as usize].is_none() {
                    piece[j as usize] = Some(next);
                    stack.push(j as usize);
                }
            }
        }
        next += 1;
    }
    piece
}

/// The sums of `values` over each connected piece (`piece` as [`pieces`] gives it).
fn per_piece(piece: &[Option<usize>], values: &[f64]) -> Vec<f64> {
    let mut sums = vec![0.0; piece.iter().filter_map(|p| *p).max().map_or(0, |m| m + 1)];
    for (p, v) in piece.iter().zip(values) {
        if let Some(p) = p {
            sums[*p] += v;
        }
    }
    sums
}

/// Conjugate gradients for the symmetric positive semidefinite `apply` with a
/// right-hand side in its range, from zero, to ‖r‖ ≤ `tol` ‖b‖, or until the
/// residual has not fallen for 50 steps (round-off), or n + 100 steps.
fn conjugate_gradients(mut apply: impl FnMut(&[f64], &mut [f64]), b: &[f64], tol: f64) -> Vec<f64> {
    let n = b.len();
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let mut x = vec![0.0; n];
    let mut r = b.to_vec();
    let mut p = r.clone();
    let mut ap = vec![0.0; n];
    let b_norm = dot(b, b).sqrt();
    let mut rr = dot(&r, &r);
    if b_norm == 0.0 {
        return x;
    }
    let (mut best, mut since) = (rr, 0);
    for _ in 0..n + 100 {
        if rr.sqrt() <= tol * b_norm || since > 50 {
            break;
        }
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 {
            break;
        }
        let alpha = rr / pap;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        let rr_new = dot(&r, &r);
        let beta = rr_new / rr;
        rr = rr_new;
        if rr < best {
            (best, since) = (rr, 0);
        } else {
            since += 1;
        }
        for i in 0..n {
            p[i] = r[i] + beta * p[i];
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{MasterNet, NetShape};
    use crate::format::sccontact::MasterKind;

    fn grid(a: usize, b: usize, x: impl Fn(f64, f64) -> Vec3) -> (MasterNet, Vec<Vec3>) {
        let x_net = (0..a * b).map(|k| x((k % a) as f64, (k / a) as f64)).collect();
        (MasterNet { nodes: (0..(a * b) as u32).collect(), shape: NetShape::Grid { a, b } }, x_net)
    }

    /// On flat nets (uniform, and stretched) and a curved one, for orders 3 and 4:
    /// the columns of M sum to 1 and M q = f (the faces' forces of a uniform
    /// pressure) to round-off; on the flat uniform net M is the identity away from
    /// the edges, so T_k = Q_k there.
    #[test]
    fn balanced_basis_gives_the_faces_forces_and_sums_to_one() {
        type Shape = Box<dyn Fn(f64, f64) -> Vec3>;
        let nets: [(&str, Shape); 3] = [
            ("flat", Box::new(|i, j| Vec3::new(0.5 * i, 0.5 * j, 0.0))),
            ("stretched", Box::new(|i, j| Vec3::new(i + 0.05 * i * i, 0.7 * j, 0.0))),
            ("curved", Box::new(|i, j| Vec3::new(i, j, 0.3 * (0.4 * i).sin() * (0.3 * j).cos()))),
        ];
        for (name, x) in &nets {
            for order in [3, 4] {
                let (a, b) = if *name == "flat" { (20, 16) } else { (12, 9) };
                let (net, x_net) = grid(a, b, x);
                let geometry = Projector::for_net(MasterKind::Bspline, [order, order], &net, &x_net).unwrap();
                let trace = Trace::new(&net, &x_net).unwrap();
                let bal = Balance::new(&geometry, &trace, &x_net);
                assert!(bal.defect < 1e-11, "{name} order {order}: M q − f = {:e}", bal.defect);
                let n = x_net.len();
                for a in 0..n {
                    let col = bal.column(a);
                    let s: f64 = col.iter().map(|e| e.1).sum();
                    assert!((s - 1.0).abs() < 1e-13, "{name} order {order}: column {a} sums to {s}");
                }
                // Σ_k T_k = 1 at any point, and the values agree with M and Q
                let sp = geometry.evaluate([0.13, 0.71], None);
                let mut t = Vec::new();
                bal.combine(&sp.basis, &mut t);
                let total: f64 = t.iter().map(|e| e.1).sum();
                let slope: [f64; 2] = [0, 1].map(|al| t.iter().map(|e| e.2[al]).sum());
                assert!((total - 1.0).abs() < 1e-13 && slope[0].abs() < 1e-12 && slope[1].abs() < 1e-12, "{name}: Σ T = {total}, Σ T_α = {slope:?}");
                if *name == "flat" {
                    // the interior is untouched: the open knots' first k − 1 spans are
                    // not affine in x, and their functions reach k − 1 nodes further
                    let m = 2 * order;
                    for j in m..b - m {
                        for i in m..a - m {
                            let k = i + a * j;
                            assert_eq!(bal.column(k), &[(k as u32, 1.0)], "{name} order {order}: node ({i}, {j})");
                        }
                    }
                    assert!(bal.region < n, "{name} order {order}: region {}", bal.region);
                }
            }
        }
        // a flat net with a bump in its middle: the region is two pieces, the edge
        // band and the bump, each balanced on its own (the bump's facets scaled to its
        // smooth area); the flat net between them is untouched
        let (net, x_net) = grid(40, 40, |i, j| {
            let r2 = (i - 19.5) * (i - 19.5) + (j - 19.5) * (j - 19.5);
            Vec3::new(i, j, if r2 < 16.0 { 1.5 * (1.0 - r2 / 16.0).powi(3) } else { 0.0 })
        });
        let geometry = Projector::for_net(MasterKind::Bspline, [4, 4], &net, &x_net).unwrap();
        let bal = Balance::new(&geometry, &Trace::new(&net, &x_net).unwrap(), &x_net);
        assert!(bal.defect < 1e-11, "bump: M q − f = {:e} (region {})", bal.defect, bal.region);
        assert!(bal.region < x_net.len(), "bump: region {} of {}", bal.region, x_net.len());
        assert_eq!(bal.column(10 + 40 * 10), &[(10 + 40 * 10, 1.0)], "bump: node (10, 10), between the band and the bump");
        // a facet master is its own trace: M = I
        let (net, x_net) = grid(5, 4, |i, j| Vec3::new(i, j, 0.1 * i * j));
        let geometry = Projector::for_net(MasterKind::Facet, [2, 2], &net, &x_net).unwrap();
        let bal = Balance::new(&geometry, &Trace::new(&net, &x_net).unwrap(), &x_net);
        assert_eq!(bal.region, 0);
    }
}
