//! Element-layer verification: element tangent vs residual vs energy (finite
//! differences, one macro per material), TL = UL, homogeneous deformations against
//! closed forms, rigid rotation, small-strain limit, follower pressure.
#![allow(non_snake_case)]

use super::element::*;
use super::fd::{fd_gradient, fd_jacobian, rel_err, FdStep};
use super::pressure::*;
use crate::material::tests::{ciarlet_simo, dev_vol, large_F, linear_elastic, LAMBDA, MU};
use crate::material::{Material, MaterialModel};
use crate::mesh::HEX_FACES;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A distorted (non-parallelepiped, non-planar faces) hexahedron about 1 × 1 × 1.
fn distorted_X() -> [Vector3<f64>; 8] {
    [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.1, 0.05, -0.1),
        Vector3::new(1.2, 0.9, 0.1),
        Vector3::new(-0.1, 1.0, 0.05),
        Vector3::new(0.1, -0.1, 1.0),
        Vector3::new(0.95, 0.1, 1.2),
        Vector3::new(1.05, 1.15, 0.9),
        Vector3::new(0.05, 0.9, 1.1),
    ]
}

/// Affine displacement u = (F − I) X + c.
fn affine_u(X: &[Vector3<f64>; 8], F: &Matrix3<f64>) -> [Vector3<f64>; 8] {
    X.map(|x| (F - Matrix3::identity()) * x + Vector3::new(0.3, -0.2, 0.7))
}

/// Large, non-homogeneous displacement: affine part with `large_F` (stretches ~1.3,
/// shear, 0.7 rad rotation) plus a node-wise non-affine perturbation.
fn large_u(X: &[Vector3<f64>; 8]) -> [Vector3<f64>; 8] {
    let mut u = affine_u(X, &large_F());
    for (a, ua) in u.iter_mut().enumerate() {
        let t = a as f64;
        *ua += Vector3::new((1.3 * t).sin(), (2.1 * t + 0.5).cos(), (0.7 * t + 1.0).sin()) * 0.06;
    }
    u
}

fn to_u(x: &[f64]) -> [Vector3<f64>; 8] {
    std::array::from_fn(|a| Vector3::new(x[3 * a], x[3 * a + 1], x[3 * a + 2]))
}

fn flat(u: &[Vector3<f64>; 8]) -> Vec<f64> {
    u.iter().flat_map(|v| [v.x, v.y, v.z]).collect()
}

fn residual_tangent(
    X: &[Vector3<f64>; 8],
    u: &[Vector3<f64>; 8],
    m: &MaterialModel,
    f: Formulation,
) -> (ElementVector, ElementMatrix) {
    let (mut r, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
    hex8_residual_tangent(X, u, m, f, &mut r, &mut k).unwrap();
    (r, k)
}

const FORMS: [Formulation; 2] = [Formulation::TotalLagrangian, Formulation::UpdatedLagrangian];

macro_rules! element_derivative_tests {
    ($name:ident, $mat:expr) => {
        mod $name {
            use super::*;

            fn model() -> MaterialModel {
                $mat.into()
            }

            #[test]
            fn deformed_element_is_valid() {
                let X = distorted_X();
                let u = large_u(&X);
                let jmin = hex8_min_jacobian(&X, &u).unwrap();
                assert!(jmin > 0.5, "{jmin}");
            }

            #[test]
            fn tangent_is_derivative_of_residual() {
                let X = distorted_X();
                let u0 = flat(&large_u(&X));
                for form in FORMS {
                    let m = model();
                    let fd = fd_jacobian(
                        |x, out| {
                            let mut r = ElementVector::zeros();
                            hex8_residual(&X, &to_u(x), &m, form, &mut r).unwrap();
                            out.copy_from_slice(r.as_slice());
                        },
                        &u0,
                        24,
                        FdStep::default(),
                    );
                    let (_, k) = residual_tangent(&X, &to_u(&u0), &m, form);
                    let e = rel_err(k.as_slice(), fd.as_slice());
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-6, "{form:?}: rel. error {e:e}");
                }
            }

            #[test]
            fn residual_is_derivative_of_energy() {
                let X = distorted_X();
                let u0 = flat(&large_u(&X));
                let m = model();
                let fd = fd_gradient(|x| hex8_energy(&X, &to_u(x), &m).unwrap(), &u0, FdStep::default());
                for form in FORMS {
                    let (r, _) = residual_tangent(&X, &to_u(&u0), &m, form);
                    let e = rel_err(r.as_slice(), fd.as_slice());
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-6, "{form:?}: rel. error {e:e}");
                }
            }

            #[test]
            fn total_and_updated_lagrangian_agree() {
                let X = distorted_X();
                let u = large_u(&X);
                let m = model();
                let (r_tl, k_tl) = residual_tangent(&X, &u, &m, Formulation::TotalLagrangian);
                let (r_ul, k_ul) = residual_tangent(&X, &u, &m, Formulation::UpdatedLagrangian);
                let er = rel_err(r_tl.as_slice(), r_ul.as_slice());
                let ek = rel_err(k_tl.as_slice(), k_ul.as_slice());
                eprintln!("TL/UL residual {er:.1e} tangent {ek:.1e}");
                assert!(er < 1e-12 && ek < 1e-12, "residual {er:e}, tangent {ek:e}");
                // The residual-only path gives the same vector.
                let mut r = ElementVector::zeros();
                hex8_residual(&X, &u, &m, Formulation::UpdatedLagrangian, &mut r).unwrap();
                assert_eq!(r, r_ul);
                // Hyperelastic element tangent is symmetric.
                assert!((k_tl - k_tl.transpose()).norm() < 1e-12 * k_tl.norm());
            }

            /// Affine field on a distorted hex ⇒ the same σ at all 8 Gauss points, and the
            /// nodal internal forces equal the boundary tractions σ n integrated against
            /// N_a over the six faces (using the pressure module's ∫ N_a n da).
            #[test]
            fn affine_field_gives_uniform_stress_and_traction_forces() {
                let X = distorted_X();
                let F = large_F();
                let u = affine_u(&X, &F);
                let m = model();
                let s = hex8_gauss_stresses(&X, &u, &m).unwrap();
                let s_ex = m.stress(&F).unwrap();
                for (q, sq) in s.iter().enumerate() {
                    let e = rel_err(sq.as_slice(), s_ex.as_slice());
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-12, "Gauss point {q}: {e:e}");
                }
                // Faces of the configuration the stress is integrated on.
                let linear = m.is_geometrically_linear();
                let x: [Vector3<f64>; 8] = std::array::from_fn(|a| if linear { X[a] } else { X[a] + u[a] });
                let mut f_traction = ElementVector::zeros();
                for face in HEX_FACES {
                    // follower_pressure_force with p = 1 gives −∫ N_a n da.
                    let fp = follower_pressure_force(&face.map(|a| x[a]), 1.0);
                    for (i, &a) in face.iter().enumerate() {
                        let t = -(s_ex * fp.fixed_rows::<3>(3 * i));
                        let mut dst = f_traction.fixed_rows_mut::<3>(3 * a);
                        dst += t;
                    }
                }
                for form in FORMS {
                    let (r, _) = residual_tangent(&X, &u, &m, form);
                    let e = rel_err(r.as_slice(), f_traction.as_slice());
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-12, "{form:?}: {e:e}");
                }
            }
        }
    };
}

element_derivative_tests!(ciarlet_simo_element, ciarlet_simo());
element_derivative_tests!(dev_vol_neo_hookean_element, dev_vol());
element_derivative_tests!(linear_elastic_element, linear_elastic());

/// Uniaxial stress: F = R diag(a, β, β) with the lateral stretch β solved from
/// σ_yy = 0 by a 1D Newton iteration; closed form σ = R diag(σ_xx, 0, 0) Rᵀ.
/// CiarletSimo: σ_yy = λ/(2J)(J² − 1) + μ/J(β² − 1), σ_xx = μ/J (a² − β²).
/// DevVol: σ_yy = μJ^{-5/3}(β² − (a² + 2β²)/3) + K(J − 1), σ_xx = μJ^{-5/3}(a² − β²).
/// Linear: β = 1 − ν(a − 1), σ_xx = E (a − 1).
#[test]
fn uniaxial_stress_closed_forms_on_distorted_hex() {
    let a = 1.3;
    let K = LAMBDA + 2.0 * MU / 3.0;
    let R = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(-1.0, 0.5, 2.0)), 1.1);
    let newton = |g: &dyn Fn(f64) -> f64| {
        let mut beta: f64 = 1.0;
        for _ in 0..50 {
            let h = 1e-7;
            let d = (g(beta + h) - g(beta - h)) / (2.0 * h);
            let step = g(beta) / d;
            beta -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        assert!(g(beta).abs() < 1e-13, "lateral Newton did not converge");
        beta
    };
    let cs_yy = |b: f64| {
        let J = a * b * b;
        LAMBDA / (2.0 * J) * (J * J - 1.0) + MU / J * (b * b - 1.0)
    };
    let dv_yy = |b: f64| {
        let J = a * b * b;
        MU * J.powf(-5.0 / 3.0) * (b * b - (a * a + 2.0 * b * b) / 3.0) + K * (J - 1.0)
    };
    let b_cs = newton(&cs_yy);
    let b_dv = newton(&dv_yy);
    let nu = LAMBDA / (2.0 * (LAMBDA + MU));
    let E = MU * (3.0 * LAMBDA + 2.0 * MU) / (LAMBDA + MU);
    let cases: [(MaterialModel, f64, f64, bool); 3] = [
        (
            ciarlet_simo().into(),
            b_cs,
            MU / (a * b_cs * b_cs) * (a * a - b_cs * b_cs),
            true,
        ),
        (
            dev_vol().into(),
            b_dv,
            MU * (a * b_dv * b_dv).powf(-5.0 / 3.0) * (a * a - b_dv * b_dv),
            true,
        ),
        (linear_elastic().into(), 1.0 - nu * (a - 1.0), E * (a - 1.0), false),
    ];
    let X = distorted_X();
    for (m, beta, sxx, rotate) in cases {
        let U = Matrix3::from_diagonal(&Vector3::new(a, beta, beta));
        let Rm = if rotate { *R.matrix() } else { Matrix3::identity() };
        let F = Rm * U;
        let s_ex = Rm * Matrix3::from_diagonal(&Vector3::new(sxx, 0.0, 0.0)) * Rm.transpose();
        let s = hex8_gauss_stresses(&X, &affine_u(&X, &F), &m).unwrap();
        for (q, sq) in s.iter().enumerate() {
            let e = rel_err(sq.as_slice(), s_ex.as_slice());
            eprintln!("{}: {e:.1e}", module_path!());
            assert!(e < 1e-12, "{m:?} Gauss point {q}: rel. error {e:e}\n{sq}\nvs\n{s_ex}");
        }
    }
    // The two neo-Hookean forms differ at this stretch, as the paper notes (section 8).
    assert!((b_cs - b_dv).abs() > 1e-3);
}

/// 90° rigid rotation: zero stress and zero internal forces (finite-strain models).
#[test]
fn rigid_rotation_is_stress_free() {
    let X = distorted_X();
    let R = Rotation3::from_axis_angle(
        &Unit::new_normalize(Vector3::new(1.0, 1.0, 0.3)),
        std::f64::consts::FRAC_PI_2,
    );
    let u = X.map(|x| R * x - x + Vector3::new(1.0, 2.0, 3.0));
    for m in [MaterialModel::from(ciarlet_simo()), dev_vol().into()] {
        for s in hex8_gauss_stresses(&X, &u, &m).unwrap() {
            eprintln!("rigid rotation |σ| = {:.1e}", s.norm());
            assert!(s.norm() < 1e-10 * MU, "{m:?}: |σ| = {:e}", s.norm());
        }
        for form in FORMS {
            let (r, _) = residual_tangent(&X, &u, &m, form);
            assert!(r.norm() < 1e-10 * MU, "{m:?} {form:?}: |r| = {:e}", r.norm());
        }
    }
}

/// At a strain of 1e-7 both neo-Hookean tangents equal the Hooke tangent.
#[test]
fn small_strain_limit_matches_linear_elasticity() {
    let X = distorted_X();
    let H = Matrix3::new(0.3, -0.7, 0.2, 0.5, 1.0, -0.4, 0.1, 0.6, -0.8) * 1e-7;
    let u = affine_u(&X, &(Matrix3::identity() + H));
    let lin = MaterialModel::from(linear_elastic());
    let (r_lin, k_lin) = residual_tangent(&X, &u, &lin, Formulation::TotalLagrangian);
    for m in [MaterialModel::from(ciarlet_simo()), dev_vol().into()] {
        for form in FORMS {
            let (r, k) = residual_tangent(&X, &u, &m, form);
            let ek = rel_err(k.as_slice(), k_lin.as_slice());
            let er = rel_err(r.as_slice(), r_lin.as_slice());
            eprintln!("small strain {m:?} {form:?}: tangent {ek:.1e}, residual {er:.1e}");
            assert!(
                ek < 1e-5 && er < 1e-5,
                "{m:?} {form:?}: tangent {ek:e}, residual {er:e}"
            );
        }
    }
}

#[test]
fn inverted_and_degenerate_elements_are_typed_errors() {
    let X = distorted_X();
    // Squash the top face through the bottom one.
    let mut u = [Vector3::zeros(); 8];
    for ua in &mut u[4..] {
        *ua = Vector3::new(0.0, 0.0, -2.5);
    }
    assert!(hex8_min_jacobian(&X, &u).unwrap() < 0.0);
    let (mut r, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
    let m = MaterialModel::from(ciarlet_simo());
    let e = hex8_residual_tangent(&X, &u, &m, Formulation::TotalLagrangian, &mut r, &mut k).unwrap_err();
    match e {
        ElementError::Inverted { gauss_point, J } => assert!(gauss_point < 8 && J <= 0.0),
        other => panic!("expected Inverted, got {other:?}"),
    }
    assert!(e.to_string().contains("inverted element"));
    // The small-strain model evaluates any displacement.
    assert!(hex8_residual(&X, &u, &linear_elastic().into(), Formulation::TotalLagrangian, &mut r).is_ok());
    // Mirrored reference node order.
    let mirrored = [X[4], X[5], X[6], X[7], X[0], X[1], X[2], X[3]];
    let e = hex8_residual(
        &mirrored,
        &[Vector3::zeros(); 8],
        &m,
        Formulation::UpdatedLagrangian,
        &mut r,
    )
    .unwrap_err();
    assert!(
        matches!(e, ElementError::DegenerateReference { gauss_point: 0, .. }),
        "{e:?}"
    );
    assert!(hex8_min_jacobian(&mirrored, &[Vector3::zeros(); 8]).is_err());
    // Undeformed: min J = 1.
    assert!((hex8_min_jacobian(&X, &[Vector3::zeros(); 8]).unwrap() - 1.0).abs() < 1e-14);
}

/// A non-planar current face.
fn warped_face() -> [Vector3<f64>; 4] {
    [
        Vector3::new(0.0, 0.0, 0.1),
        Vector3::new(1.3, 0.1, -0.05),
        Vector3::new(1.1, 1.2, 0.3),
        Vector3::new(-0.2, 0.9, -0.1),
    ]
}

#[test]
fn pressure_stiffness_is_derivative_of_force() {
    let x0: Vec<f64> = warped_face().iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    let p = 2.5;
    let fd = fd_jacobian(
        |x, out| {
            let xf: [Vector3<f64>; 4] = std::array::from_fn(|a| Vector3::new(x[3 * a], x[3 * a + 1], x[3 * a + 2]));
            out.copy_from_slice(follower_pressure_force(&xf, p).as_slice());
        },
        &x0,
        12,
        FdStep::default(),
    );
    let (mut f, mut k) = (FaceVector::zeros(), FaceMatrix::zeros());
    follower_pressure_force_stiffness(&warped_face(), p, &mut f, &mut k);
    assert_eq!(f, follower_pressure_force(&warped_face(), p));
    let e = rel_err(k.as_slice(), fd.as_slice());
    eprintln!("{}: {e:.1e}", module_path!());
    assert!(e < 1e-6, "rel. error {e:e}");
    // One face: not symmetric.
    assert!((k - k.transpose()).norm() > 1e-3 * k.norm());
}

#[test]
fn pressure_on_flat_square_is_p_times_area_outward() {
    // Unit square in z = 0, counter-clockwise seen from +z: normal +z, f_a = −p/4 e_z.
    let x = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(1.0, 1.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
    ];
    let f = follower_pressure_force(&x, 3.0);
    for a in 0..4 {
        assert!((f.fixed_rows::<3>(3 * a) - Vector3::new(0.0, 0.0, -0.75)).norm() < 1e-15);
    }
}

/// Constant pressure on the closed surface of a deformed hex: zero resultant, and the
/// assembled load stiffness is symmetric (the load is conservative).
#[test]
fn pressure_on_closed_surface_is_self_equilibrated_and_symmetric() {
    let X = distorted_X();
    let u = large_u(&X);
    let x: [Vector3<f64>; 8] = std::array::from_fn(|a| X[a] + u[a]);
    let (mut f, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
    for face in HEX_FACES {
        let (mut ff, mut kf) = (FaceVector::zeros(), FaceMatrix::zeros());
        follower_pressure_force_stiffness(&face.map(|a| x[a]), 1.7, &mut ff, &mut kf);
        for (i, &a) in face.iter().enumerate() {
            let mut dst = f.fixed_rows_mut::<3>(3 * a);
            dst += ff.fixed_rows::<3>(3 * i);
            for (j, &b) in face.iter().enumerate() {
                let mut blk = k.fixed_view_mut::<3, 3>(3 * a, 3 * b);
                blk += kf.fixed_view::<3, 3>(3 * i, 3 * j);
            }
        }
    }
    let resultant: Vector3<f64> = (0..8).map(|a| f.fixed_rows::<3>(3 * a).into_owned()).sum();
    assert!(resultant.norm() < 1e-14 * f.norm(), "{resultant}");
    assert!(
        (k - k.transpose()).norm() < 1e-13 * k.norm(),
        "{:e}",
        (k - k.transpose()).norm() / k.norm()
    );
}
