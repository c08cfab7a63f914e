//! The mortar contact element of one slave node s: the weighted gap ĝ_s over the
//! slave faces around it, its residual and consistent tangent.
//!
//! Unknowns: the current positions of the element's nodes ([`super::Mortar::element_nodes`],
//! sorted mesh ids), 3 per node. At every quadrature point q of the faces around s
//! (weight c_q = w_q N_s(η_q) / A_s), with the slave point x = Σ_l N_l x_l, the
//! master foot point x̄(ξ̄), normal n̄, basis Q_A, and the trace facet N^F_k(ζ̄):
//! ```text
//! ∂g   = [N_l n̄ (slave l);  −Q_A n̄ (master A)]           the gap's gradient (6.2)
//! ∂̃g   = [N_l n̄ (slave l);  −N^F_k n̄ (trace node k)]     the virtual gap (module docs)
//! T_α  = [N_l ā_α; −Q_A ā_α],   N_α = [0; −Q_{A,α} n̄]
//! Δξ̄^α = D^{αβ} (T_β − g N_β)·Δu,   D = (ā_αβ − g b̄_αβ)⁻¹        (as eq. 2.2's Newton)
//! Δn̄   = a^α (N_α − b̄_αβ Δξ̄^β)·Δu,   a^α = ā^{αγ} ā_γ         (−a^α (n̄·Δā_α))
//! Δζ̄^α : the same formula on the trace facet (its gap g_F, metric and twist)
//! ∂(∂̃g) = [N_l Δn̄;  −N^F_k Δn̄ − n̄ ⊗ N^F_{k,α} Δζ̄^α]
//! ```
//! and with ĝ = Σ c_q g_q, G = Σ c_q ∂g_q, V = Σ c_q ∂̃g_q, H = Σ c_q ∂(∂̃g_q):
//! ```text
//! t_s = min(0, λ_s + ε_N ĝ)      r = t_s A_s V      K = ε_N A_s V ⊗ G + t_s A_s H
//! ```
//! For a facet master ∂̃g = ∂g and H is the Hessian of g (symmetric). With
//! `transfer: surface` N^F, ζ̄ are Q, ξ̄; with `transfer: balanced` N^F_k is
//! T_k = Σ_A M_kA Q_A at ξ̄ ([`super::balance`]), M a constant of the model.
//! With friction, the node's tangential force f_T (the node-to-surface friction
//! element's, t_s its Coulomb bound) goes to the slave node with W_s = Σ c and to
//! master node k with W_k = −Σ c N^F_k(ζ̄), the normal force's weights:
//! `r += W f_T`, `K += W ⊗ ∂f_T + ε_N W ∂f_T/∂t_N ⊗ G + f_T ⊗ ∂W`.

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector, DVectorView};

use super::balance::TransferValue;
use super::{Mortar, Transfer};
use crate::contact::element::zero_element;
use crate::contact::friction::tangential_contact;
use crate::contact::law::{ContactElementError, ContactState, FrictionLaw, NormalLaw};
use crate::contact::master::Projector;
use crate::spline::{SurfacePoint, Vec3};

/// Working rows of one quadrature point over the local dofs of its face (see
/// [`Local`]); allocated to the element's `m` dofs, the first `d` in use.
#[derive(Default)]
struct Rows {
    grad: Vec<f64>,
    vgrad: Vec<f64>,
    t: [Vec<f64>; 2],
    na: [Vec<f64>; 2],
    dxi: [Vec<f64>; 2],
    dn: [Vec<f64>; 3],
    dzeta: [Vec<f64>; 2],
    tf: [Vec<f64>; 2],
    nf: [Vec<f64>; 2],
}

/// The dofs one slave face touches: its four corners, then every master node its
/// quadrature points reach, numbered in the order met (3 local dofs per node). A
/// face's points are accumulated over these d dofs, d < m, and the face's sums are
/// added to the element's once per face: the work per point scales with the face,
/// not with the union of the four faces around the slave node.
#[derive(Default)]
struct Local {
    /// Local node of each element node (`u32::MAX`: not touched by this face).
    map: Vec<u32>,
    /// Element dof of each local node's first component.
    dofs: Vec<usize>,
}

impl Local {
    /// The local dof of element dof `dof` (a node's first component), numbering it if new.
    fn of(&mut self, dof: usize) -> usize {
        let e = dof / 3;
        if self.map[e] == u32::MAX {
            self.map[e] = self.dofs.len() as u32;
            self.dofs.push(dof);
        }
        3 * self.map[e] as usize
    }

    /// Element dof of local dof `i`.
    fn dof(&self, i: usize) -> usize {
        self.dofs[i / 3] + i % 3
    }

    fn len(&self) -> usize {
        3 * self.dofs.len()
    }

    fn clear(&mut self) {
        for &d in &self.dofs {
            self.map[d / 3] = u32::MAX;
        }
        self.dofs.clear();
    }
}

/// The element's working storage, kept per thread between calls: it is sized to
/// the element (`m` dofs) at each call without allocating once it has grown to the
/// largest element.
#[derive(Default)]
struct Work {
    rows: Rows,
    local: Local,
    /// G = Σ c ∂g and V = Σ c ∂̃g.
    big_g: Vec<f64>,
    big_v: Vec<f64>,
    /// H = Σ c ∂(∂̃g), row-major m × m.
    h: Vec<f64>,
    /// One face's share of G, V (local dofs) and H (local, row stride m).
    face_g: Vec<f64>,
    face_v: Vec<f64>,
    face_h: Vec<f64>,
    /// Local dof of each master basis node at a point; of each transfer basis node.
    sp_at: Vec<usize>,
    f_at: Vec<usize>,
    /// The transfer basis at a point: net node, N^F_k and N^F_{k,α} (the trace
    /// facet's, the surface's, or the balanced T_k).
    tb: Vec<TransferValue>,
    /// The transfer weights of the tangential traction (friction): per element
    /// node, W_s = Σ c at the slave node s itself and W_k = −Σ c N^F_k at the
    /// master's (transfer basis), and their gradients (row-major, `m / 3` rows of
    /// `m`); one face's share of both (local nodes, row stride m).
    big_w: Vec<f64>,
    dw: Vec<f64>,
    face_w: Vec<f64>,
    face_dw: Vec<f64>,
    /// Element dof of the friction foot point's nodes.
    idx: Vec<usize>,
    /// The node-to-surface tangential element (residual, tangent, ∂r_T/∂t_N).
    rt: DVector<f64>,
    kt: DMatrix<f64>,
    dt: DVector<f64>,
}

impl Work {
    /// Sizes and zeroes the storage for an element of `m` dofs; the friction
    /// weights only `with_friction` (they are not read otherwise).
    fn reset(&mut self, m: usize, with_friction: bool) {
        let zero = |v: &mut Vec<f64>, n: usize| {
            v.clear();
            v.resize(n, 0.0);
        };
        let Rows { grad, vgrad, t, na, dxi, dn, dzeta, tf, nf } = &mut self.rows;
        for v in [grad, vgrad].into_iter().chain(t.iter_mut()).chain(na.iter_mut()).chain(dxi.iter_mut()).chain(dn.iter_mut()).chain(dzeta.iter_mut()).chain(tf.iter_mut()).chain(nf.iter_mut()) {
            zero(v, m);
        }
        for v in [&mut self.big_g, &mut self.big_v, &mut self.face_g, &mut self.face_v] {
            zero(v, m);
        }
        zero(&mut self.h, m * m);
        zero(&mut self.face_h, m * m);
        if with_friction {
            zero(&mut self.big_w, m / 3);
            zero(&mut self.face_w, m / 3);
            zero(&mut self.dw, (m / 3) * m);
            zero(&mut self.face_dw, (m / 3) * m);
        }
        self.local.dofs.clear();
        self.local.map.clear();
        self.local.map.resize(m / 3, u32::MAX);
    }
}

thread_local! {
    static WORK: RefCell<Work> = RefCell::new(Work::default());
}

/// Δξ̄^α = D^{αβ} (T_β − g N_β) for a surface point (rows over the first `d` dofs).
fn foot_variation(sp: &SurfacePoint, g: f64, t: &[Vec<f64>; 2], na: &[Vec<f64>; 2], out: &mut [Vec<f64>; 2], d: usize) -> Result<(), ContactElementError> {
    let inv = (sp.a_ab - sp.b_ab * g).try_inverse().ok_or(ContactElementError::FocalPoint { g_n: g })?;
    for al in 0..2 {
        let (d0, d1) = (inv[(al, 0)], inv[(al, 1)]);
        for (((o, t0), t1), (n0, n1)) in out[al][..d].iter_mut().zip(&t[0][..d]).zip(&t[1][..d]).zip(na[0][..d].iter().zip(&na[1][..d])) {
            *o = d0 * (t0 - g * n0) + d1 * (t1 - g * n1);
        }
    }
    Ok(())
}

/// Coulomb friction of a mortar slave node: the node's own foot point and history.
/// The tangential traction is the node-to-surface one of eqs. 4.5–4.8 at the slave
/// node ([`tangential_contact`]) with the mortar pressure t_s as its Coulomb bound.
pub struct NodeFriction<'a> {
    pub foot: &'a SurfacePoint,
    pub law: &'a FrictionLaw,
}

/// Residual and tangent of slave `s`'s mortar element (see the module docs), over
/// the dofs of [`Mortar::element_nodes`]. `x_slave`: current slave positions;
/// `geometry`: the master at the current configuration. Zero when the node is open.
/// With `friction`, the node's Coulomb traction is added, and its dependence on t_s
/// (slip: ‖t_T‖ = μ|t_s|) chained through ∂t_s/∂u = ε_N ∂ĝ_s.
#[allow(clippy::too_many_arguments)]
pub fn mortar_contact(mortar: &Mortar, s: usize, geometry: &Projector, x_slave: &[Vec3], law: &NormalLaw, friction: Option<NodeFriction<'_>>, r: &mut DVector<f64>, k: &mut DMatrix<f64>) -> Result<ContactState, ContactElementError> {
    WORK.with_borrow_mut(|work| element_in(work, mortar, s, geometry, x_slave, law, friction, r, k))
}

#[allow(clippy::too_many_arguments)]
fn element_in(work: &mut Work, mortar: &Mortar, s: usize, geometry: &Projector, x_slave: &[Vec3], law: &NormalLaw, friction: Option<NodeFriction<'_>>, r: &mut DVector<f64>, k: &mut DMatrix<f64>) -> Result<ContactState, ContactElementError> {
    let nodes = mortar.element_nodes(s);
    let m = 3 * nodes.len();
    zero_element(r, k, m);
    let g_hat = mortar.gap[s];
    let trial = law.lambda_n + law.eps_n * g_hat;
    let touching = trial <= law.eps_n * law.touch;
    if !g_hat.is_finite() || (trial >= 0.0 && !touching) {
        return Ok(ContactState { g_n: g_hat, t_n: 0.0, active: false });
    }
    let net = mortar.net_nodes();
    let slaves = mortar.slave_nodes();
    let at = |node: u32| 3 * nodes.binary_search(&node).expect("element node list holds every node it couples");
    // the master's own basis carries the forces: facets, or `transfer: surface`;
    // `balanced` recombines it (T_k = Σ_A M_kA Q_A at the same ξ̄)
    let own_basis = geometry.is_facets() || mortar.transfer != Transfer::Trace;
    let balance = if geometry.is_facets() { None } else { mortar.balance() };
    let with_friction = friction.is_some();
    work.reset(m, with_friction);
    let Work { rows, local, big_g, big_v, h, face_g, face_v, face_h, big_w, dw, face_w, face_dw, sp_at, f_at, tb, idx, rt, kt, dt } = work;
    for &f in mortar.faces_of(s) {
        let face = mortar.face(f);
        let Some(l_s) = face.iter().position(|&c| c as usize == s) else { continue };
        if mortar.points(f).is_empty() {
            continue; // no point of this face over the master: its corners need not be in the element
        }
        // the corners are local nodes 0..4
        for &c in &face {
            local.of(at(slaves[c as usize]));
        }
        let xf = face.map(|c| x_slave[c as usize]);
        for p in mortar.points(f) {
            let c = p.w * mortar.dual_shape(f, l_s, &p.n) / law.area;
            let x: Vec3 = (0..4).map(|l| xf[l] * p.n[l]).sum();
            let sp = geometry.evaluate(p.xi, p.element);
            // the trace: the facet of the segment's cell at ζ̄
            let spf = if own_basis { sp } else { mortar.trace().evaluate(p.zeta, p.cell) };
            sp_at.clear();
            sp_at.extend(sp.basis.nodes().iter().map(|&kk| local.of(at(net[kk]))));
            match balance {
                Some(b) => b.combine(&sp.basis, tb),
                None => {
                    tb.clear();
                    tb.extend(spf.basis.nodes().iter().zip(spf.basis.q()).zip(spf.basis.q_alpha()).map(|((&kk, &v), &d)| (kk, v, d)));
                }
            }
            f_at.clear();
            f_at.extend(tb.iter().map(|e| local.of(at(net[e.0]))));
            let d = local.len();
            let n = sp.n_bar;
            let g = (x - sp.x_bar).dot(&n);
            let q = sp.basis.q();
            let qa = sp.basis.q_alpha();
            let Rows { grad, vgrad, t, na, dxi, dn, dzeta, tf, nf } = &mut *rows;
            for v in [&mut *grad, &mut *vgrad].into_iter().chain(t.iter_mut()).chain(na.iter_mut()).chain(tf.iter_mut()).chain(nf.iter_mut()) {
                v[..d].fill(0.0);
            }
            for l in 0..4 {
                for cc in 0..3 {
                    let i = 3 * l + cc;
                    grad[i] += p.n[l] * n[cc];
                    vgrad[i] += p.n[l] * n[cc];
                    for al in 0..2 {
                        t[al][i] += p.n[l] * sp.a_alpha[al][cc];
                    }
                }
            }
            for (a, &j) in sp_at.iter().enumerate() {
                for cc in 0..3 {
                    grad[j + cc] -= q[a] * n[cc];
                    for al in 0..2 {
                        t[al][j + cc] -= q[a] * sp.a_alpha[al][cc];
                        na[al][j + cc] -= qa[a][al] * n[cc];
                    }
                }
            }
            foot_variation(&sp, g, t, na, dxi, d)?;
            // Δn̄ = a^α (N_α − b̄_αβ Δξ̄^β)
            let contra = [0, 1].map(|al| sp.a_alpha[0] * sp.a_inv[(al, 0)] + sp.a_alpha[1] * sp.a_inv[(al, 1)]);
            for (cc, dn_c) in dn.iter_mut().enumerate() {
                let (c0, c1) = (contra[0][cc], contra[1][cc]);
                for ((((o, na0), na1), x0), x1) in dn_c[..d].iter_mut().zip(&na[0][..d]).zip(&na[1][..d]).zip(&dxi[0][..d]).zip(&dxi[1][..d]) {
                    let w0 = na0 - sp.b_ab[(0, 0)] * x0 - sp.b_ab[(0, 1)] * x1;
                    let w1 = na1 - sp.b_ab[(1, 0)] * x0 - sp.b_ab[(1, 1)] * x1;
                    *o = c0 * w0 + c1 * w1;
                }
            }
            for (a, &j) in f_at.iter().enumerate() {
                for cc in 0..3 {
                    vgrad[j + cc] -= tb[a].1 * n[cc];
                }
            }
            if own_basis {
                dzeta[0][..d].copy_from_slice(&dxi[0][..d]);
                dzeta[1][..d].copy_from_slice(&dxi[1][..d]);
            } else {
                let nf_bar = spf.n_bar;
                let gf = (x - spf.x_bar).dot(&nf_bar);
                for l in 0..4 {
                    for cc in 0..3 {
                        for al in 0..2 {
                            tf[al][3 * l + cc] += p.n[l] * spf.a_alpha[al][cc];
                        }
                    }
                }
                for (a, &j) in f_at.iter().enumerate() {
                    for cc in 0..3 {
                        for al in 0..2 {
                            tf[al][j + cc] -= tb[a].1 * spf.a_alpha[al][cc];
                            nf[al][j + cc] -= tb[a].2[al] * nf_bar[cc];
                        }
                    }
                }
                foot_variation(&spf, gf, tf, nf, dzeta, d)?;
            }
            // accumulate ĝ's gradient, the virtual gradient and H = Σ c ∂(∂̃g)
            for (((fg, fv), gr), vg) in face_g[..d].iter_mut().zip(&mut face_v[..d]).zip(&grad[..d]).zip(&vgrad[..d]) {
                *fg += c * gr;
                *fv += c * vg;
            }
            for l in 0..4 {
                for cc in 0..3 {
                    let i = 3 * l + cc;
                    let w = c * p.n[l];
                    for (hij, dn_j) in face_h[i * m..i * m + d].iter_mut().zip(&dn[cc][..d]) {
                        *hij += w * dn_j;
                    }
                }
            }
            for (a, &i0) in f_at.iter().enumerate() {
                for cc in 0..3 {
                    let i = i0 + cc;
                    let (w, wn) = (c * tb[a].1, c * n[cc]);
                    let (wa0, wa1) = (wn * tb[a].2[0], wn * tb[a].2[1]);
                    for (((hij, dn_j), z0), z1) in face_h[i * m..i * m + d].iter_mut().zip(&dn[cc][..d]).zip(&dzeta[0][..d]).zip(&dzeta[1][..d]) {
                        *hij -= w * dn_j + wa0 * z0 + wa1 * z1;
                    }
                }
            }
            if with_friction {
                // the tangential traction's transfer weights: W_s += c (slave node
                // s), W_k −= c N^F_k(ζ̄) (master), ∂W_k −= c N^F_{k,α} Δζ̄^α
                face_w[l_s] += c;
                for (a, &i0) in f_at.iter().enumerate() {
                    face_w[i0 / 3] -= c * tb[a].1;
                    let (wa0, wa1) = (c * tb[a].2[0], c * tb[a].2[1]);
                    let row = (i0 / 3) * m;
                    for ((o, z0), z1) in face_dw[row..row + d].iter_mut().zip(&dzeta[0][..d]).zip(&dzeta[1][..d]) {
                        *o -= wa0 * z0 + wa1 * z1;
                    }
                }
            }
        }
        // the face's sums into the element's (and the face's storage back to zero)
        let d = local.len();
        for i in 0..d {
            let ei = local.dof(i);
            big_g[ei] += std::mem::take(&mut face_g[i]);
            big_v[ei] += std::mem::take(&mut face_v[i]);
            let row = &mut face_h[i * m..i * m + d];
            let h_row = &mut h[ei * m..(ei + 1) * m];
            for (j, hij) in row.iter_mut().enumerate() {
                h_row[local.dof(j)] += std::mem::take(hij);
            }
        }
        if with_friction {
            for a in 0..d / 3 {
                let e = local.dof(3 * a) / 3;
                big_w[e] += std::mem::take(&mut face_w[a]);
                let row = &mut face_dw[a * m..a * m + d];
                let w_row = &mut dw[e * m..(e + 1) * m];
                for (j, x) in row.iter_mut().enumerate() {
                    w_row[local.dof(j)] += std::mem::take(x);
                }
            }
        }
        local.clear();
    }
    let a_s = law.area;
    // K = ε_N A_s V ⊗ G (+ t_s A_s H when active)
    k.ger(law.eps_n * a_s, &DVectorView::from_slice(big_v, m), &DVectorView::from_slice(big_g, m), 1.0);
    if trial >= 0.0 {
        return Ok(ContactState { g_n: g_hat, t_n: 0.0, active: false });
    }
    let t_s = trial;
    for i in 0..m {
        for j in 0..m {
            k[(i, j)] += t_s * a_s * h[i * m + j];
        }
        r[i] = t_s * a_s * big_v[i];
    }
    if let Some(fr) = friction {
        tangential_contact(&x_slave[s], fr.foot, t_s, law, fr.law, rt, kt, dt)?;
        idx.clear();
        idx.extend(std::iter::once(at(slaves[s])).chain(fr.foot.basis.nodes().iter().map(|&kk| at(net[kk]))));
        // The slave node's tangential force f_T (r_T's slave rows: A_s t_Tα times
        // the foot's contravariant base vectors) acts where its faces meet the
        // master, as its normal force does: the slave node receives W_s f_T
        // (W_s = Σ c, the covered share of A_s), the master nodes W_k f_T, the
        // node's traction t_T,s Φ_s integrated against the pair's transfer basis
        // (docs/theory/mortar.md, "Friction").
        for e in 0..m / 3 {
            let w = big_w[e];
            let dw_e = &dw[e * m..(e + 1) * m];
            if w == 0.0 && dw_e.iter().all(|&x| x == 0.0) {
                continue;
            }
            for ca in 0..3 {
                let i = 3 * e + ca;
                let f = rt[ca];
                r[i] += w * f;
                for j in 0..m {
                    // W ∂f_T/∂t_N ⊗ ε_N ∂ĝ_s + f_T ⊗ ∂W
                    k[(i, j)] += w * dt[ca] * law.eps_n * big_g[j] + f * dw_e[j];
                }
                for (b, &ib) in idx.iter().enumerate() {
                    for cb in 0..3 {
                        k[(i, ib + cb)] += w * kt[(ca, 3 * b + cb)];
                    }
                }
            }
        }
    }
    Ok(ContactState { g_n: g_hat, t_n: t_s, active: true })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::atlas_fd::{tube, umbrella};
    use crate::contact::element::tests::curved_net;
    use crate::contact::mortar::{Feet, Multipliers, Quadrature, Transfer};
    use crate::contact::{MasterNet, NetShape, PatchNet};
    use crate::fem::fd::{fd_jacobian, rel_err, FdStep};
    use crate::format::sccontact::MasterKind;

    const NA: usize = 7;
    const NB: usize = 6;
    /// Gauss–Legendre, 5 points on [−1, 1] (exact to degree 9): (node, weight).
    const GAUSS5: [(f64, f64); 5] = [(-0.906_179_845_938_664, 0.236_926_885_056_189_1), (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5), (0.0, 0.568_888_888_888_888_9), (0.538_469_310_105_683_1, 0.478_628_670_499_366_5), (0.906_179_845_938_664, 0.236_926_885_056_189_1)];

    /// A master for the check: its net, the kind and orders of its surface, and the
    /// nine nominal slave positions (the 3 × 3 slave patch before it is pressed in).
    struct Master {
        name: String,
        x_net: Vec<Vec3>,
        net: MasterNet,
        kind: MasterKind,
        orders: [usize; 2],
        nominal: Vec<Vec3>,
    }

    impl Master {
        fn projector(&self, x_net: &[Vec3]) -> Projector {
            Projector::for_net(self.kind, self.orders, &self.net, x_net).unwrap()
        }
    }

    /// The point at grid index coordinates (u, v) of an `a`-wide net read bilinearly
    /// (`wrap`: closed along the first index).
    fn grid_point(x: &[Vec3], a: usize, wrap: bool, u: f64, v: f64) -> Vec3 {
        let (i, j) = (u.floor() as usize, v.floor() as usize);
        let (s, t) = (u - i as f64, v - j as f64);
        let at = |i: usize, j: usize| x[(if wrap { i % a } else { i }) + a * j];
        at(i, j) * ((1.0 - s) * (1.0 - t)) + at(i + 1, j) * (s * (1.0 - t)) + at(i + 1, j + 1) * (s * t) + at(i, j + 1) * ((1.0 - s) * t)
    }

    /// The 3 × 3 slave patch (spacing 0.8 cells, rotated against the net) from
    /// (u0, v0) in grid index coordinates.
    fn patch_on_grid(x: &[Vec3], a: usize, wrap: bool, u0: f64, v0: f64) -> Vec<Vec3> {
        (0..9).map(|k| (k % 3, k / 3)).map(|(i, j)| grid_point(x, a, wrap, u0 + 0.8 * i as f64 + 0.15 * j as f64, v0 + 0.8 * j as f64 - 0.1 * i as f64)).collect()
    }

    fn grid_cells(a: usize, b: usize) -> Vec<[u32; 4]> {
        MasterNet { nodes: (0..(a * b) as u32).collect(), shape: NetShape::Grid { a, b } }.cells()
    }

    /// The one-grid masters of the node-to-surface tests: the curved, wavy net as
    /// facets and as B-splines of orders 2–4.
    fn grid_master(order: usize) -> Master {
        let x_net = curved_net(NA, NB);
        let nominal = patch_on_grid(&x_net, NA, false, 2.35, 1.6);
        let net = MasterNet { nodes: (0..(NA * NB) as u32).collect(), shape: NetShape::Grid { a: NA, b: NB } };
        let (kind, orders) = if order == 0 { (MasterKind::Facet, [2, 2]) } else { (MasterKind::Bspline, [order; 2]) };
        Master { name: format!("grid order {order}"), x_net, net, kind, orders, nominal }
    }

    /// The masters of many charts: a periodic B-spline (the slave patch over its
    /// seam), two B-spline patches (the slave over their C⁰ seam), the Catmull–Clark
    /// surface and free facets of the same curved net, and both on a net with an
    /// extraordinary node of valence 5.
    fn atlas_masters() -> Vec<Master> {
        let mut out = Vec::new();
        let (ta, tb) = (10, 6);
        let xt = tube(ta, tb);
        out.push(Master {
            name: "periodic order 3".into(),
            nominal: patch_on_grid(&xt, ta, true, ta as f64 - 1.4, 1.6),
            x_net: xt,
            net: MasterNet { nodes: (0..(ta * tb) as u32).collect(), shape: NetShape::Periodic { a: ta, b: tb } },
            kind: MasterKind::Bspline,
            orders: [3, 3],
        });
        let x_net = curved_net(NA, NB);
        let nominal = patch_on_grid(&x_net, NA, false, 2.35, 1.6);
        // columns 0..=3 and 3..=6: the seam at column 3 runs under the slave patch
        let sheet = |i0: usize| PatchNet { a: 4, b: NB, nodes: (0..4 * NB).map(|k| (i0 + k % 4 + NA * (k / 4)) as u32).collect() };
        out.push(Master {
            name: "two patches order 3".into(),
            x_net: x_net.clone(),
            net: MasterNet { nodes: (0..(NA * NB) as u32).collect(), shape: NetShape::Patches(vec![sheet(0), sheet(3)]) },
            kind: MasterKind::Bspline,
            orders: [3, 3],
            nominal: nominal.clone(),
        });
        for kind in [MasterKind::Subdivision, MasterKind::Facet] {
            out.push(Master {
                name: format!("{kind:?} on the curved net"),
                x_net: x_net.clone(),
                net: MasterNet { nodes: (0..(NA * NB) as u32).collect(), shape: NetShape::Quads(grid_cells(NA, NB)) },
                kind,
                orders: [4, 4],
                nominal: nominal.clone(),
            });
        }
        let (xu, faces) = umbrella(5, 3);
        // around the extraordinary node 0 at the origin
        let nominal_u: Vec<Vec3> = (0..9).map(|k| (k % 3, k / 3)).map(|(i, j)| Vec3::new(-0.7 + 0.75 * i as f64 + 0.1 * j as f64, -0.8 + 0.75 * j as f64 - 0.08 * i as f64, 0.0)).collect();
        for kind in [MasterKind::Subdivision, MasterKind::Facet] {
            out.push(Master {
                name: format!("{kind:?} around a valence-5 node"),
                net: MasterNet { nodes: (0..xu.len() as u32).collect(), shape: NetShape::Quads(faces.clone()) },
                x_net: xu.clone(),
                kind,
                orders: [4, 4],
                nominal: nominal_u.clone(),
            });
        }
        out
    }

    /// The slave patch on `master`: each nominal point moved to its foot point on
    /// the master surface, then 1e-2 to 3e-2 into it (4 faces; mesh nodes: the net
    /// first, then the 9 slaves).
    fn slaves_on(master: &Master) -> (Vec<Vec3>, Vec<[u32; 4]>, Vec<u32>) {
        let pr = master.projector(&master.x_net);
        let x_slave = master
            .nominal
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let (proj, el) = pr.project(p, None);
                assert!(proj.converged && proj.inside, "{}: nominal slave {k} off the master: {proj:?}", master.name);
                let sp = pr.evaluate(proj.xi, el);
                sp.x_bar - sp.n_bar * (0.01 + 0.005 * (k % 3 + 2 * (k / 3)) as f64)
            })
            .collect();
        let n_net = master.x_net.len() as u32;
        let slaves: Vec<u32> = (0..9).map(|s| n_net + s).collect();
        let faces = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]].iter().map(|f: &[u32; 4]| f.map(|s| slaves[s as usize])).collect();
        (x_slave, faces, slaves)
    }

    /// (λ_N, ε_N, friction: None or (ε_T, expected slip)); the node's history ξ̄_n
    /// behind its foot point, t_Tα,n small: ε_T = 1e3 slips (ε_T ā Δξ ≫ μ|t_s|),
    /// ε_T = 5 sticks.
    type Law = (f64, f64, Option<(f64, bool)>);
    const LAWS: [Law; 5] = [(0.0, 1e3, None), (-2.0, 50.0, None), (-1.0, 0.0, None), (-1.0, 50.0, Some((1e3, true))), (-1.0, 50.0, Some((5.0, false)))];
    /// Frictionless and slip (the laws whose terms differ most), where a check costs
    /// a minute under the full set (the Catmull–Clark masters).
    const SHORT: [Law; 2] = [(-2.0, 50.0, None), (-1.0, 50.0, Some((1e3, true)))];

    /// The residual of slave 4's element (the patch centre, coupled to all nine slave
    /// nodes) against central differences with every quadrature point re-projected
    /// (the segmentation held, as the tangent assumes), for the three laws of the
    /// node-to-surface test, frictionless, slip and stick. Returns the worst error.
    /// With `resegmented: Some(bound)` every perturbation segments the faces afresh
    /// (the residual as the solve computes it before the segmentation is held), and
    /// the tangent, which takes the segmentation as fixed, is held to `bound`.
    fn check(master: &Master, multipliers: Multipliers, transfer: Transfer, laws: &[Law]) -> f64 {
        check_with(master, multipliers, transfer, laws, None)
    }

    fn check_with(master: &Master, multipliers: Multipliers, transfer: Transfer, laws: &[Law], resegmented: Option<f64>) -> f64 {
        check_over(master, multipliers, transfer, Quadrature::Cells, laws, resegmented)
    }

    fn check_over(master: &Master, multipliers: Multipliers, transfer: Transfer, quadrature: Quadrature, laws: &[Law], resegmented: Option<f64>) -> f64 {
        let (x_slave, faces, slaves) = slaves_on(master);
        let x_net = &master.x_net;
        let n_net = x_net.len();
        let mut x_all: Vec<Vec3> = x_net.clone();
        x_all.extend(&x_slave);
        let mut pr = master.projector(x_net);
        let mut mortar = Mortar::new(&faces, &slaves, &x_all, &master.net, &pr, multipliers, transfer, f64::INFINITY).unwrap().unwrap().with_quadrature(quadrature);
        let foot: Vec<_> = x_slave.iter().map(|x| pr.project(x, None)).collect();
        let foot_points: Vec<_> = foot.iter().map(|(p, c)| pr.evaluate(p.xi, *c)).collect();
        let (foot, foot_cells): (Vec<_>, Vec<_>) = foot.into_iter().unzip();
        let areas = vec![0.6; 9];
        mortar.integrate(&pr, x_net, &x_slave, Feet { projections: &foot, elements: &foot_cells, points: &foot_points }, &areas).unwrap();
        assert_eq!(mortar.skipped_cells, 0, "{}: cells skipped", master.name);
        // the segments tile each face: their weights sum to its area ∫ dA₀ (Gauss–
        // Legendre 5 × 5 of |x,η₁ × x,η₂| over the square; the 7-point rules
        // integrate the same over the segments). Measured ≤ 6.3e-9 (the tube's curved
        // faces, the rules' error on dA₀); cells carried along their own facets'
        // normals overlapped: 2.7e-2 on the curved grid
        let (gp, gw) = (GAUSS5.map(|g| g.0), GAUSS5.map(|g| g.1));
        for (f, face) in faces.iter().enumerate() {
            let xf = face.map(|n| x_all[n as usize]);
            let area: f64 = (0..25).map(|k| gw[k % 5] * gw[k / 5] * crate::contact::mortar::segment::face_jacobian(&xf, [gp[k % 5], gp[k / 5]])).sum();
            let w: f64 = mortar.points(f as u32).iter().map(|p| p.w).sum();
            assert!((w / area - 1.0).abs() < 1e-7, "{}: face {f}: weights {w} against its area {area}", master.name);
        }
        let s = 4;
        let nodes = mortar.element_nodes(s).to_vec();
        assert!(nodes.len() > 9 + 4, "{}: element nodes {nodes:?}", master.name);
        let m = 3 * nodes.len();
        let (foot_s, cell_s) = pr.project(&x_slave[s], None);
        let xi_n = [foot_s.xi[0] - 0.02 / NA as f64, foot_s.xi[1] + 0.01 / NB as f64];
        let mut worst: f64 = 0.0;
        let t0 = std::time::Instant::now();
        for &(lambda, eps, fric) in laws {
            let law = NormalLaw { lambda_n: lambda, eps_n: eps, area: areas[s], touch: 0.0 };
            let flaw = fric.map(|(eps_t, _)| FrictionLaw { mu: 0.3, eps_t, xi_n, t_t_n: [0.05, -0.02], held_slip: None });
            let node_friction = |foot: &SurfacePoint| flaw.as_ref().map(|l| (*foot, *l));
            let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
            let nf = node_friction(&foot_points[s]);
            let st = mortar_contact(&mortar, s, &pr, &x_slave, &law, nf.as_ref().map(|(f, l)| NodeFriction { foot: f, law: l }), &mut r, &mut k).unwrap();
            if let (Some((_, want_slip)), Some(l)) = (fric, &flaw) {
                let fs = crate::contact::friction::tangential_state(&x_slave[s], &foot_points[s], st.t_n, &law, l).unwrap();
                assert_eq!(fs.slip, want_slip, "{}: {fs:?}", master.name);
            }
            assert!(st.active && st.g_n < 0.0, "{}: {st:?}", master.name);
            let u: Vec<f64> = nodes.iter().flat_map(|&n| x_all[n as usize].iter().copied().collect::<Vec<_>>()).collect();
            let mut mfd = mortar.clone();
            let k_fd = fd_jacobian(
                |v, out| {
                    let mut x = x_all.clone();
                    for (a, &n) in nodes.iter().enumerate() {
                        x[n as usize] = Vec3::new(v[3 * a], v[3 * a + 1], v[3 * a + 2]);
                    }
                    let (xn, xs) = (&x[..n_net], &x[n_net..]);
                    pr.update(xn).unwrap();
                    let feet: Vec<_> = xs.iter().zip(&foot_cells).map(|(x, c)| pr.project(x, *c)).collect();
                    let foot_pts: Vec<_> = feet.iter().map(|(p, c)| pr.evaluate(p.xi, *c)).collect();
                    let (feet, feet_cells): (Vec<_>, Vec<_>) = feet.into_iter().unzip();
                    let feet = Feet { projections: &feet, elements: &feet_cells, points: &foot_pts };
                    if resegmented.is_some() {
                        mfd.integrate(&pr, xn, xs, feet, &areas).unwrap();
                    } else {
                        mfd.refresh(&pr, xn, xs, feet, &areas).unwrap();
                    }
                    assert_eq!(mfd.element_nodes(s), &nodes[..], "{}: perturbation changed the element's nodes", master.name);
                    let (fp, fc) = pr.project(&xs[s], cell_s);
                    let foot = pr.evaluate(fp.xi, fc);
                    assert_eq!(foot.basis.nodes(), foot_points[s].basis.nodes(), "{}: perturbation moved the node's foot to another span", master.name);
                    let nf = node_friction(&foot);
                    let (mut rr, mut kk) = (DVector::zeros(m), DMatrix::zeros(m, m));
                    mortar_contact(&mfd, s, &pr, xs, &law, nf.as_ref().map(|(f, l)| NodeFriction { foot: f, law: l }), &mut rr, &mut kk).unwrap();
                    out.copy_from_slice(rr.as_slice());
                },
                &u,
                m,
                // h = 1e-6: the B-spline foot points converge to ~1e-12 of the
                // scale, whose round-off in n̄ would reach ~1e-6 of K at h = 1e-7;
                // truncation ~h² stays ≪ 1e-6
                FdStep { rel_step: 1e-6, scale: 1.0 },
            );
            pr.update(x_net).unwrap();
            let e = rel_err(k.as_slice(), k_fd.as_slice());
            eprintln!("mortar {} {multipliers:?} {transfer:?} (λ {lambda}, ε {eps}, friction {fric:?}): |K − K_fd| / |K| = {e:.2e}, {} nodes ({:.1} s)", master.name, nodes.len(), t0.elapsed().as_secs_f64());
            assert!(e < resegmented.unwrap_or(1e-6), "{} (λ {lambda}, ε {eps}, friction {fric:?}): relative error {e:e}", master.name);
            if (master.kind == MasterKind::Facet || transfer == Transfer::Surface) && fric.is_none() {
                let asym = (&k - k.transpose()).abs().max() / k.abs().max();
                assert!(asym < 1e-10, "{}: K symmetric (the Hessian of ĝ), found {asym:e}", master.name);
            }
            worst = worst.max(e);
        }
        worst
    }

    /// A slave node whose faces overhang the master's edge carries friction over the
    /// covered share of its faces only, as its normal force: in slip, the slave
    /// side's tangential force is μ times its normal force (exactly, on a flat
    /// master, where both act over the same covered share). The patch: 3 × 3 nodes at
    /// spacing 0.8 over a flat 7 × 6 grid of unit cells, its centre node at x = 5.8
    /// and its right column at 6.6, beyond the master's edge at x = 6: the centre
    /// node's covered share is (1 + 7/16) / 2 = 0.719. Had the node kept its whole
    /// A_s t_T (the transfer at its own foot point), the ratio would be 1 / 0.719 (1.39, measured).
    #[test]
    fn friction_of_an_overhanging_node_respects_coulomb_for_its_forces() {
        let x_net: Vec<Vec3> = (0..NA * NB).map(|k| Vec3::new((k % NA) as f64, (k / NA) as f64, 0.0)).collect();
        let net = MasterNet { nodes: (0..(NA * NB) as u32).collect(), shape: NetShape::Grid { a: NA, b: NB } };
        for (kind, orders, transfer) in [(MasterKind::Facet, [2, 2], Transfer::Trace), (MasterKind::Bspline, [3, 3], Transfer::Trace), (MasterKind::Bspline, [3, 3], Transfer::Surface), (MasterKind::Bspline, [3, 3], Transfer::Balanced)] {
            let pr = Projector::for_net(kind, orders, &net, &x_net).unwrap();
            let (p0, e0) = pr.project(&Vec3::new(5.8, 2.4, 1.0), None);
            let n = pr.evaluate(p0.xi, e0).n_bar;
            let x_slave: Vec<Vec3> = (0..9).map(|k| Vec3::new(5.0 + 0.8 * (k % 3) as f64, 1.6 + 0.8 * (k / 3) as f64, 0.0) - n * 0.01).collect();
            let n_net = x_net.len() as u32;
            let slaves: Vec<u32> = (0..9).map(|s| n_net + s).collect();
            let faces: Vec<[u32; 4]> = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]].iter().map(|f: &[u32; 4]| f.map(|s| slaves[s as usize])).collect();
            let mut x_all = x_net.clone();
            x_all.extend(&x_slave);
            let mut mortar = Mortar::new(&faces, &slaves, &x_all, &net, &pr, Multipliers::Standard, transfer, f64::INFINITY).unwrap().unwrap();
            let foot: Vec<_> = x_slave.iter().map(|x| pr.project(x, None)).collect();
            let foot_points: Vec<_> = foot.iter().map(|(p, c)| pr.evaluate(p.xi, *c)).collect();
            let (foot, foot_cells): (Vec<_>, Vec<_>) = foot.into_iter().unzip();
            let areas = vec![0.64; 9];
            mortar.integrate(&pr, &x_net, &x_slave, Feet { projections: &foot, elements: &foot_cells, points: &foot_points }, &areas).unwrap();
            let s = 4;
            let law = NormalLaw { lambda_n: -1.0, eps_n: 50.0, area: areas[s], touch: 0.0 };
            let xi = foot[s].xi;
            let flaw = FrictionLaw { mu: 0.3, eps_t: 1e3, xi_n: [xi[0] - 0.02 / NA as f64, xi[1] + 0.01 / NB as f64], t_t_n: [0.05, -0.02], held_slip: None };
            let nodes = mortar.element_nodes(s).to_vec();
            // the slave side's force: the sum of the slave nodes' rows
            let slave_force = |friction: Option<NodeFriction<'_>>| {
                let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
                let st = mortar_contact(&mortar, s, &pr, &x_slave, &law, friction, &mut r, &mut k).unwrap();
                let f: Vec3 = nodes.iter().enumerate().filter(|(_, &id)| id >= n_net).map(|(a, _)| Vec3::new(r[3 * a], r[3 * a + 1], r[3 * a + 2])).sum();
                (f, st)
            };
            let (f_n, st) = slave_force(None);
            let (f_all, _) = slave_force(Some(NodeFriction { foot: &foot_points[s], law: &flaw }));
            let fs = crate::contact::friction::tangential_state(&x_slave[s], &foot_points[s], st.t_n, &law, &flaw).unwrap();
            assert!(fs.slip, "{kind:?}: the node slips");
            let cover = f_n.norm() / (st.t_n.abs() * law.area);
            assert!(cover < 0.95, "{kind:?}: the faces overhang the master (covered share {cover})");
            let ratio = (f_all - f_n).norm() / (flaw.mu * f_n.norm());
            assert!((ratio - 1.0).abs() < 1e-9, "{kind:?} {transfer:?}: tangential / (μ normal) force on the slave side = {ratio} (covered share {cover})");
        }
    }

    /// One grid: facets and B-splines of orders 2–4, standard and dual multipliers,
    /// trace and surface transfer. Tolerance 1e-6 as in the node-to-surface test (FD
    /// truncation and round-off ~1e-9).
    #[test]
    fn tangent_matches_finite_differences() {
        for (order, multipliers, transfer) in [
            (0, Multipliers::Standard, Transfer::Trace),
            (2, Multipliers::Standard, Transfer::Trace),
            (3, Multipliers::Standard, Transfer::Trace),
            (4, Multipliers::Standard, Transfer::Trace),
            (0, Multipliers::Dual, Transfer::Trace),
            (3, Multipliers::Dual, Transfer::Trace),
            (3, Multipliers::Standard, Transfer::Surface),
            (4, Multipliers::Dual, Transfer::Surface),
            (3, Multipliers::Standard, Transfer::Balanced),
            (4, Multipliers::Dual, Transfer::Balanced),
        ] {
            check(&grid_master(order), multipliers, transfer, &LAWS);
        }
    }

    /// The tangent takes the segmentation as fixed. On smooth masters (B-spline
    /// orders 3, 4, whose integrand is smooth across the trace cells) what it leaves
    /// out of the re-segmented residual's derivative is a quadrature effect: measured
    /// 3e-4 to 1e-2 of K (the ε_N = 0 law's small K the largest). Bound 3e-2. Each
    /// cell carried onto the slave plane along its own facet's normal, not its nodes'
    /// mean normal, made the images overlap: 5–40 %.
    #[test]
    fn resegmented_residual_on_smooth_masters_is_nearly_the_tangents() {
        for (order, multipliers, transfer) in [(3, Multipliers::Standard, Transfer::Trace), (4, Multipliers::Standard, Transfer::Trace), (3, Multipliers::Standard, Transfer::Surface), (4, Multipliers::Dual, Transfer::Surface)] {
            check_with(&grid_master(order), multipliers, transfer, &LAWS, Some(3e-2));
        }
    }

    /// `quadrature: knot_spans`: the segments cut further by the patch's knot lines
    /// and integrated by 64 points per triangle. The same checks on the curved grid
    /// (order 3; order 4 with dual multipliers measured the same): the pieces tile each face (weights summing to its area; split
    /// in the plane instead of in η they left 2.8e-6 of it uncovered), and the
    /// tangent is the held residual's derivative.
    #[test]
    fn tangent_matches_finite_differences_over_knot_spans() {
        // one case, with friction in slip (a check costs 45 s at 64 points per triangle)
        check_over(&grid_master(3), Multipliers::Standard, Transfer::Balanced, Quadrature::KnotSpans, &SHORT[1..], None);
    }

    /// Masters of many charts (closed, several patches, Catmull–Clark, free facets):
    /// the segments are cut by the trace cells of any quad net, the foot points
    /// found on the atlas. Same tolerance; measured ≤ 2e-7 (slip on the curved
    /// facets), ≤ 4e-8 on the Catmull–Clark surface next to the valence-5 node.
    #[test]
    fn tangent_matches_finite_differences_on_atlas_masters() {
        for master in atlas_masters() {
            // a Catmull–Clark check costs half a minute per combination: one each
            let combos: &[(Multipliers, Transfer)] = match (master.kind, master.name.contains("valence")) {
                (MasterKind::Subdivision, false) => &[(Multipliers::Standard, Transfer::Trace)],
                (MasterKind::Subdivision, true) => &[(Multipliers::Dual, Transfer::Surface)],
                _ => &[(Multipliers::Standard, Transfer::Trace), (Multipliers::Dual, Transfer::Surface), (Multipliers::Standard, Transfer::Balanced)],
            };
            let laws: &[Law] = if master.kind == MasterKind::Subdivision { &SHORT } else { &LAWS };
            for &(multipliers, transfer) in combos {
                check(&master, multipliers, transfer, laws);
            }
        }
    }
}
