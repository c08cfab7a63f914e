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
//! For a facet master ∂̃g = ∂g and H is the Hessian of g (symmetric).

use nalgebra::{DMatrix, DVector};

use super::{Mortar, Transfer};
use crate::contact::element::zero_element;
use crate::contact::friction::tangential_contact;
use crate::contact::law::{ContactElementError, ContactState, FrictionLaw, NormalLaw};
use crate::contact::master::Projector;
use crate::spline::{SurfacePoint, Vec3};

/// Working rows of one quadrature point, length `m` each (reused between points).
struct Rows {
    grad: DVector<f64>,
    vgrad: DVector<f64>,
    t: [DVector<f64>; 2],
    na: [DVector<f64>; 2],
    dxi: [DVector<f64>; 2],
    dn: [DVector<f64>; 3],
    dzeta: [DVector<f64>; 2],
    tf: [DVector<f64>; 2],
    nf: [DVector<f64>; 2],
}

impl Rows {
    fn new(m: usize) -> Self {
        let z = || DVector::zeros(m);
        Self { grad: z(), vgrad: z(), t: [z(), z()], na: [z(), z()], dxi: [z(), z()], dn: [z(), z(), z()], dzeta: [z(), z()], tf: [z(), z()], nf: [z(), z()] }
    }
}

/// Δξ̄^α = D^{αβ} (T_β − g N_β) for a surface point (rows over the element's dofs).
fn foot_variation(sp: &SurfacePoint, g: f64, t: &[DVector<f64>; 2], na: &[DVector<f64>; 2], out: &mut [DVector<f64>; 2]) -> Result<(), ContactElementError> {
    let d = (sp.a_ab - sp.b_ab * g).try_inverse().ok_or(ContactElementError::FocalPoint { g_n: g })?;
    for al in 0..2 {
        for j in 0..out[al].len() {
            let w0 = t[0][j] - g * na[0][j];
            let w1 = t[1][j] - g * na[1][j];
            out[al][j] = d[(al, 0)] * w0 + d[(al, 1)] * w1;
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
    // the master's own basis carries the forces: facets, or `transfer: surface`
    let own_basis = matches!(geometry, Projector::Facet(_)) || mortar.transfer == Transfer::Surface;
    let mut rows = Rows::new(m);
    let (mut big_g, mut big_v) = (DVector::zeros(m), DVector::zeros(m));
    let mut h = DMatrix::zeros(m, m);
    for &f in mortar.faces_of(s) {
        let face = mortar.face(f);
        let Some(l_s) = face.iter().position(|&c| c as usize == s) else { continue };
        if mortar.points(f).is_empty() {
            continue; // no point of this face over the master: its corners need not be in the element
        }
        let slave_at = face.map(|c| at(slaves[c as usize]));
        let xf = face.map(|c| x_slave[c as usize]);
        for p in mortar.points(f) {
            let c = p.w * mortar.dual_shape(f, l_s, &p.n) / law.area;
            let x: Vec3 = (0..4).map(|l| xf[l] * p.n[l]).sum();
            let sp = geometry.evaluate(p.xi, Some(p.cell));
            let n = sp.n_bar;
            let g = (x - sp.x_bar).dot(&n);
            let q = sp.basis.q();
            let qa = sp.basis.q_alpha();
            let Rows { grad, vgrad, t, na, dxi, dn, dzeta, tf, nf } = &mut rows;
            for v in [&mut *grad, &mut *vgrad].into_iter().chain(t.iter_mut()).chain(na.iter_mut()).chain(tf.iter_mut()).chain(nf.iter_mut()) {
                v.fill(0.0);
            }
            for l in 0..4 {
                for cc in 0..3 {
                    let i = slave_at[l] + cc;
                    grad[i] += p.n[l] * n[cc];
                    vgrad[i] += p.n[l] * n[cc];
                    for al in 0..2 {
                        t[al][i] += p.n[l] * sp.a_alpha[al][cc];
                    }
                }
            }
            for (a, &kk) in sp.basis.nodes().iter().enumerate() {
                let j = at(net[kk]);
                for cc in 0..3 {
                    grad[j + cc] -= q[a] * n[cc];
                    for al in 0..2 {
                        t[al][j + cc] -= q[a] * sp.a_alpha[al][cc];
                        na[al][j + cc] -= qa[a][al] * n[cc];
                    }
                }
            }
            foot_variation(&sp, g, t, na, dxi)?;
            // Δn̄ = a^α (N_α − b̄_αβ Δξ̄^β)
            let contra = [0, 1].map(|al| sp.a_alpha[0] * sp.a_inv[(al, 0)] + sp.a_alpha[1] * sp.a_inv[(al, 1)]);
            for (cc, dn_c) in dn.iter_mut().enumerate() {
                for j in 0..m {
                    let mut v = 0.0;
                    for al in 0..2 {
                        let w = na[al][j] - sp.b_ab[(al, 0)] * dxi[0][j] - sp.b_ab[(al, 1)] * dxi[1][j];
                        v += contra[al][cc] * w;
                    }
                    dn_c[j] = v;
                }
            }
            // the trace: the facet of the segment's cell at ζ̄
            let spf = if own_basis { sp } else { mortar.trace().evaluate_in_cell(p.zeta, p.cell) };
            let qf = spf.basis.q();
            let qfa = spf.basis.q_alpha();
            let f_at: Vec<usize> = spf.basis.nodes().iter().map(|&kk| at(net[kk])).collect();
            for (a, &j) in f_at.iter().enumerate() {
                for cc in 0..3 {
                    vgrad[j + cc] -= qf[a] * n[cc];
                }
            }
            if own_basis {
                dzeta[0].copy_from(&dxi[0]);
                dzeta[1].copy_from(&dxi[1]);
            } else {
                let nf_bar = spf.n_bar;
                let gf = (x - spf.x_bar).dot(&nf_bar);
                for l in 0..4 {
                    for cc in 0..3 {
                        for al in 0..2 {
                            tf[al][slave_at[l] + cc] += p.n[l] * spf.a_alpha[al][cc];
                        }
                    }
                }
                for (a, &j) in f_at.iter().enumerate() {
                    for cc in 0..3 {
                        for al in 0..2 {
                            tf[al][j + cc] -= qf[a] * spf.a_alpha[al][cc];
                            nf[al][j + cc] -= qfa[a][al] * nf_bar[cc];
                        }
                    }
                }
                foot_variation(&spf, gf, tf, nf, dzeta)?;
            }
            // accumulate ĝ's gradient, the virtual gradient and H = Σ c ∂(∂̃g)
            big_g.axpy(c, grad, 1.0);
            big_v.axpy(c, vgrad, 1.0);
            for l in 0..4 {
                for cc in 0..3 {
                    let i = slave_at[l] + cc;
                    let w = c * p.n[l];
                    for j in 0..m {
                        h[(i, j)] += w * dn[cc][j];
                    }
                }
            }
            for (a, &i0) in f_at.iter().enumerate() {
                for cc in 0..3 {
                    let i = i0 + cc;
                    for j in 0..m {
                        h[(i, j)] -= c * (qf[a] * dn[cc][j] + n[cc] * (qfa[a][0] * dzeta[0][j] + qfa[a][1] * dzeta[1][j]));
                    }
                }
            }
        }
    }
    let a_s = law.area;
    // K = ε_N A_s V ⊗ G (+ t_s A_s H when active)
    k.ger(law.eps_n * a_s, &big_v, &big_g, 1.0);
    if trial >= 0.0 {
        return Ok(ContactState { g_n: g_hat, t_n: 0.0, active: false });
    }
    let t_s = trial;
    *k += &h * (t_s * a_s);
    r.axpy(t_s * a_s, &big_v, 0.0);
    if let Some(fr) = friction {
        let (mut rt, mut kt, mut dt) = (DVector::zeros(0), DMatrix::zeros(0, 0), DVector::zeros(0));
        tangential_contact(&x_slave[s], fr.foot, t_s, law, fr.law, &mut rt, &mut kt, &mut dt)?;
        let idx: Vec<usize> = std::iter::once(at(slaves[s])).chain(fr.foot.basis.nodes().iter().map(|&kk| at(net[kk]))).collect();
        for (a, &ia) in idx.iter().enumerate() {
            for ca in 0..3 {
                let i = ia + ca;
                r[i] += rt[3 * a + ca];
                // ∂r_T/∂t_N ⊗ ε_N ∂ĝ_s
                for j in 0..m {
                    k[(i, j)] += dt[3 * a + ca] * law.eps_n * big_g[j];
                }
                for (b, &ib) in idx.iter().enumerate() {
                    for cb in 0..3 {
                        k[(i, ib + cb)] += kt[(3 * a + ca, 3 * b + cb)];
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
    use crate::contact::element::tests::curved_net;
    use crate::contact::mortar::{Multipliers, Transfer};
    use crate::fem::fd::{fd_jacobian, rel_err, FdStep};
    use crate::spline::{BSplinePatch, BSplineProjector, FacetProjector, FacetSurface};

    const NA: usize = 7;
    const NB: usize = 6;

    fn projector(order: usize, x_net: &[Vec3]) -> Projector {
        if order == 0 {
            Projector::Facet(FacetProjector::new(FacetSurface::new(NA, NB).unwrap(), x_net).unwrap())
        } else {
            Projector::BSpline(BSplineProjector::new(BSplinePatch::new(NA, NB, order, order).unwrap(), x_net).unwrap())
        }
    }

    /// A 3 × 3-node slave patch (4 faces, spacing 0.8 in parameter, rotated against
    /// the net) pressed 1e-2 to 3e-2 into the curved, wavy net of the node-to-surface
    /// tests; mesh nodes: net 0..42, slaves 42..51.
    fn setup(order: usize) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 4]>, Vec<u32>, Vec<u32>) {
        let x_net = curved_net(NA, NB);
        let pr = projector(order, &x_net);
        let mut x_slave = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let (u, v) = (2.35 + 0.8 * i as f64 + 0.15 * j as f64, 1.6 + 0.8 * j as f64 - 0.1 * i as f64);
                let xi = [u / (NA - 1) as f64, v / (NB - 1) as f64];
                let sp = pr.evaluate(xi, None);
                x_slave.push(sp.x_bar - sp.n_bar * (0.01 + 0.005 * (i + 2 * j) as f64));
            }
        }
        let net: Vec<u32> = (0..(NA * NB) as u32).collect();
        let slaves: Vec<u32> = (0..9).map(|s| (NA * NB) as u32 + s).collect();
        let faces = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]].iter().map(|f: &[u32; 4]| f.map(|s| slaves[s as usize])).collect();
        (x_net, x_slave, faces, net, slaves)
    }

    /// The residual of slave 4's element (the patch centre, coupled to all nine slave
    /// nodes) against central differences with every quadrature point re-projected
    /// (the segmentation held, as the tangent assumes), for facets and B-splines of
    /// orders 2–4 and the three laws of the node-to-surface test. Tolerance 1e-6 as
    /// there (FD truncation and round-off ~1e-9).
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
        ] {
            let (x_net, x_slave, faces, net, slaves) = setup(order);
            let mut x_all: Vec<Vec3> = x_net.clone();
            x_all.extend(&x_slave);
            let mut pr = projector(order, &x_net);
            let mut mortar = Mortar::new(&faces, &slaves, &x_all, [NA, NB], &net, multipliers, transfer).unwrap().unwrap();
            let foot: Vec<_> = x_slave.iter().map(|x| pr.project(x, None)).collect();
            let foot_points: Vec<_> = foot.iter().map(|(p, c)| pr.evaluate(p.xi, *c)).collect();
            let foot: Vec<_> = foot.into_iter().map(|(p, _)| p).collect();
            let areas = vec![0.6; 9];
            mortar.integrate(&pr, &x_net, &x_slave, &foot, &foot_points, &areas).unwrap();
            let s = 4;
            let nodes = mortar.element_nodes(s).to_vec();
            assert!(nodes.len() > 9 + 4, "order {order}: element nodes {nodes:?}");
            let m = 3 * nodes.len();
            // (λ_N, ε_N, friction: None or (ε_T, expected slip)); the node's history
            // ξ̄_n 0.02/na behind its foot point, t_Tα,n small: ε_T = 1e3 slips
            // (ε_T ā Δξ ≈ 20 ≫ μ|t_s|), ε_T = 5 sticks
            let (foot_s, cell_s) = pr.project(&x_slave[s], None);
            let xi_n = [foot_s.xi[0] - 0.02 / NA as f64, foot_s.xi[1] + 0.01 / NB as f64];
            for (lambda, eps, fric) in [(0.0, 1e3, None), (-2.0, 50.0, None), (-1.0, 0.0, None), (-1.0, 50.0, Some((1e3, true))), (-1.0, 50.0, Some((5.0, false)))] {
                let law = NormalLaw { lambda_n: lambda, eps_n: eps, area: areas[s], touch: 0.0 };
                let flaw = fric.map(|(eps_t, _)| FrictionLaw { mu: 0.3, eps_t, xi_n, t_t_n: [0.05, -0.02], held_slip: None });
                let node_friction = |foot: &SurfacePoint| flaw.as_ref().map(|l| (*foot, *l));
                let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
                let nf = node_friction(&foot_points[s]);
                let st = mortar_contact(&mortar, s, &pr, &x_slave, &law, nf.as_ref().map(|(f, l)| NodeFriction { foot: f, law: l }), &mut r, &mut k).unwrap();
                if let (Some((_, want_slip)), Some(l)) = (fric, &flaw) {
                    let fs = crate::contact::friction::tangential_state(&x_slave[s], &foot_points[s], st.t_n, &law, l).unwrap();
                    assert_eq!(fs.slip, want_slip, "order {order}: {fs:?}");
                }
                assert!(st.active && st.g_n < 0.0, "order {order}: {st:?}");
                let u: Vec<f64> = nodes.iter().flat_map(|&n| x_all[n as usize].iter().copied().collect::<Vec<_>>()).collect();
                let mut mfd = mortar.clone();
                let k_fd = fd_jacobian(
                    |v, out| {
                        let mut x = x_all.clone();
                        for (a, &n) in nodes.iter().enumerate() {
                            x[n as usize] = Vec3::new(v[3 * a], v[3 * a + 1], v[3 * a + 2]);
                        }
                        let (xn, xs) = (&x[..NA * NB], &x[NA * NB..]);
                        pr.update(xn).unwrap();
                        let feet: Vec<_> = xs.iter().map(|x| pr.project(x, None)).collect();
                        let foot_pts: Vec<_> = feet.iter().map(|(p, c)| pr.evaluate(p.xi, *c)).collect();
                        let feet: Vec<_> = feet.into_iter().map(|(p, _)| p).collect();
                        mfd.refresh(&pr, xn, xs, &feet, &foot_pts, &areas).unwrap();
                        assert_eq!(mfd.element_nodes(s), &nodes[..], "perturbation changed the element's nodes");
                        let (fp, fc) = pr.project(&xs[s], cell_s);
                        let foot = pr.evaluate(fp.xi, fc);
                        assert_eq!(foot.basis.nodes(), foot_points[s].basis.nodes(), "perturbation moved the node's foot to another span");
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
                pr.update(&x_net).unwrap();
                let e = rel_err(k.as_slice(), k_fd.as_slice());
                eprintln!("mortar order {order} {multipliers:?} {transfer:?} (λ {lambda}, ε {eps}, friction {fric:?}): |K − K_fd| / |K| = {e:.2e}, {} nodes", nodes.len());
                assert!(e < 1e-6, "order {order} (λ {lambda}, ε {eps}, friction {fric:?}): relative error {e:e}");
                if (order == 0 || transfer == Transfer::Surface) && fric.is_none() {
                    let asym = (&k - k.transpose()).abs().max() / k.abs().max();
                    assert!(asym < 1e-10, "facet master: K symmetric (the Hessian of ĝ), found {asym:e}");
                }
            }
        }
    }
}
