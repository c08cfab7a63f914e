//! Material verification: stress vs energy, tangent vs stress (spatial and material),
//! Hooke limit, validation errors. One macro per model (`material_derivative_tests!`).
#![allow(non_snake_case)]

use super::*;
use crate::fem::fd::{fd_gradient, fd_jacobian, rel_err, rel_err_floor, FdStep};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// A large deformation: stretches ≈ 1.3 / 0.85 / 1.15, shears up to 0.25, rotated by
/// 0.7 rad about (1, 2, 3). J ≈ 1.25.
pub(crate) fn large_F() -> Matrix3<f64> {
    let U = Matrix3::new(1.3, 0.25, 0.1, 0.05, 0.85, -0.2, 0.1, 0.15, 1.15);
    let R = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)), 0.7);
    R.matrix() * U
}

/// A compressive large deformation (J < 1).
pub(crate) fn compressive_F() -> Matrix3<f64> {
    Matrix3::new(0.75, -0.2, 0.05, 0.1, 0.9, 0.15, -0.1, 0.05, 0.8)
}

fn mat_from_slice(x: &[f64]) -> Matrix3<f64> {
    Matrix3::from_column_slice(x)
}

/// P = ∂W/∂F by finite differences; P = J σ F⁻ᵀ (σ for geometrically linear models).
/// Error relative to max(‖P‖, μ), as P vanishes at F = I.
pub(crate) fn check_stress_vs_energy<M: Material>(m: &M, F: &Matrix3<f64>) -> f64 {
    let P_fd = fd_gradient(
        |x| m.energy(&mat_from_slice(x)).unwrap(),
        F.as_slice(),
        FdStep::default(),
    );
    let sigma = m.stress(F).unwrap();
    let P = if m.is_geometrically_linear() {
        sigma
    } else {
        sigma * F.try_inverse().unwrap().transpose() * F.determinant()
    };
    rel_err_floor(P.as_slice(), P_fd.as_slice(), m.shear_modulus())
}

/// Spatial tangent: for F(l) = (I + l) F₀, d/dl τ − l τ − τ lᵀ = J c : l (Truesdell
/// rate of τ = Jσ). Geometrically linear: d/dH σ(F₀ + H) = c : H.
pub(crate) fn check_spatial_tangent_vs_stress<M: Material>(m: &M, F0: &Matrix3<f64>) -> f64 {
    let linear = m.is_geometrically_linear();
    let fd = fd_jacobian(
        |l, out| {
            let L = mat_from_slice(l);
            let s = if linear {
                m.stress(&(F0 + L)).unwrap()
            } else {
                let F = (Matrix3::identity() + L) * F0;
                m.stress(&F).unwrap() * F.determinant()
            };
            out.copy_from_slice(s.as_slice());
        },
        &[0.0; 9],
        9,
        FdStep::default(),
    );
    let (sigma, c) = m.stress_tangent(F0).unwrap();
    let J = F0.determinant();
    let mut ex = nalgebra::DMatrix::zeros(9, 9);
    for col in 0..9 {
        let mut L = Matrix3::zeros();
        L.as_mut_slice()[col] = 1.0;
        let d = if linear {
            tangent_apply(&c, &L)
        } else {
            let tau = sigma * J;
            L * tau + tau * L.transpose() + tangent_apply(&c, &L) * J
        };
        ex.column_mut(col).copy_from_slice(d.as_slice());
    }
    rel_err(ex.as_slice(), fd.as_slice())
}

/// Material tangent: S(F) = J F⁻¹σF⁻ᵀ, d/dF S : δF = ℂ : sym(Fᵀ δF), ℂ the pull-back of c.
pub(crate) fn check_material_tangent_vs_stress<M: Material>(m: &M, F0: &Matrix3<f64>) -> f64 {
    let S_of = |F: &Matrix3<f64>| {
        let Finv = F.try_inverse().unwrap();
        Finv * m.stress(F).unwrap() * Finv.transpose() * F.determinant()
    };
    let fd = fd_jacobian(
        |x, out| out.copy_from_slice(S_of(&mat_from_slice(x)).as_slice()),
        F0.as_slice(),
        9,
        FdStep::default(),
    );
    let (_, c) = m.stress_tangent(F0).unwrap();
    let J = F0.determinant();
    let C = pull_back_tangent(&c, &F0.try_inverse().unwrap(), J);
    let mut ex = nalgebra::DMatrix::zeros(9, 9);
    for col in 0..9 {
        let mut dF = Matrix3::zeros();
        dF.as_mut_slice()[col] = 1.0;
        // ℂ : sym(Fᵀ dF); tangent_apply symmetrises its argument itself.
        let d = tangent_apply(&C, &(F0.transpose() * dF));
        ex.column_mut(col).copy_from_slice(d.as_slice());
    }
    rel_err(ex.as_slice(), fd.as_slice())
}

macro_rules! material_derivative_tests {
    ($name:ident, $mat:expr) => {
        mod $name {
            use super::*;

            fn deformations() -> [Matrix3<f64>; 3] {
                [large_F(), compressive_F(), Matrix3::identity()]
            }

            #[test]
            fn stress_is_derivative_of_energy() {
                for F in deformations() {
                    let e = check_stress_vs_energy(&$mat, &F);
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-6, "rel. error {e:e} at F = {F}");
                }
            }

            #[test]
            fn spatial_tangent_is_derivative_of_stress() {
                for F in deformations() {
                    let e = check_spatial_tangent_vs_stress(&$mat, &F);
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-6, "rel. error {e:e} at F = {F}");
                }
            }

            #[test]
            fn material_tangent_is_derivative_of_stress() {
                if $mat.is_geometrically_linear() {
                    return;
                }
                for F in deformations() {
                    let e = check_material_tangent_vs_stress(&$mat, &F);
                    eprintln!("{}: {e:.1e}", module_path!());
                    assert!(e < 1e-6, "rel. error {e:e} at F = {F}");
                }
            }

            #[test]
            fn tangent_is_major_symmetric_and_hooke_at_identity() {
                let (_, c) = $mat.stress_tangent(&large_F()).unwrap();
                assert!((c - c.transpose()).norm() < 1e-13 * c.norm());
                let (s0, c0) = $mat.stress_tangent(&Matrix3::identity()).unwrap();
                assert!(s0.norm() < 1e-14);
                let mu = $mat.shear_modulus();
                let hooke = identity_outer() * LAMBDA + sym_identity() * (2.0 * mu);
                assert!((c0 - hooke).norm() < 1e-13 * hooke.norm(), "{c0} vs {hooke}");
            }
        }
    };
}

pub(crate) const LAMBDA: f64 = 1.5;
pub(crate) const MU: f64 = 1.0;

pub(crate) fn ciarlet_simo() -> CiarletSimo {
    CiarletSimo::from_lame(LAMBDA, MU).unwrap()
}
pub(crate) fn dev_vol() -> DevVolNeoHookean {
    DevVolNeoHookean::from_lame(LAMBDA, MU).unwrap()
}
pub(crate) fn linear_elastic() -> LinearElastic {
    LinearElastic::from_lame(LAMBDA, MU).unwrap()
}

material_derivative_tests!(ciarlet_simo_derivatives, ciarlet_simo());
material_derivative_tests!(dev_vol_neo_hookean_derivatives, dev_vol());
material_derivative_tests!(linear_elastic_derivatives, linear_elastic());

#[test]
fn closed_forms_at_a_given_F() {
    // Independent re-statement of eq. 3.3 and the deviatoric/volumetric stress.
    let F = large_F();
    let J = F.determinant();
    let b = F * F.transpose();
    let I = Matrix3::identity();
    let cs = ciarlet_simo().stress(&F).unwrap();
    let cs_ex = I * (LAMBDA / (2.0 * J) * (J * J - 1.0)) + (b - I) * (MU / J);
    assert!(rel_err(cs.as_slice(), cs_ex.as_slice()) < 1e-14);
    let K = LAMBDA + 2.0 * MU / 3.0;
    let dv = dev_vol().stress(&F).unwrap();
    let dv_ex = (b - I * (b.trace() / 3.0)) * (MU * J.powf(-5.0 / 3.0)) + I * (K * (J - 1.0));
    assert!(rel_err(dv.as_slice(), dv_ex.as_slice()) < 1e-14);
    // Pressure of the dev/vol form is exactly −K(J − 1).
    assert!((dv.trace() / 3.0 - K * (J - 1.0)).abs() < 1e-14);
}

#[test]
fn constructors_convert_and_validate() {
    let (E, nu) = (210.0, 0.3);
    let m = CiarletSimo::from_young_poisson(E, nu).unwrap();
    assert!((m.mu - E / 2.6).abs() < 1e-12);
    assert!((m.lambda - E * 0.3 / (1.3 * 0.4)).abs() < 1e-12);
    let d = DevVolNeoHookean::from_young_poisson(E, nu).unwrap();
    assert!((d.kappa - E / (3.0 * (1.0 - 2.0 * nu))).abs() < 1e-12);
    let (c10, d1) = d.calculix_c10_d1();
    assert!((c10 - m.mu / 2.0).abs() < 1e-12 && (d1 - 2.0 / d.kappa).abs() < 1e-15);
    assert_eq!(LinearElastic::from_young_poisson(E, nu).unwrap().mu, m.mu);

    let e = CiarletSimo::from_young_poisson(0.0, 0.3).unwrap_err();
    assert_eq!(e, MaterialError::InvalidYoungsModulus { E: 0.0 });
    assert!(e.to_string().contains("must be positive"));
    for nu in [-1.0, 0.5, 0.6, f64::NAN] {
        let e = DevVolNeoHookean::from_young_poisson(1.0, nu).unwrap_err();
        assert!(matches!(e, MaterialError::InvalidPoissonRatio { .. }), "{e}");
        assert!(e.to_string().contains("-1 < nu < 0.5"), "{e}");
    }
    assert!(LinearElastic::from_young_poisson(-5.0, 0.2).is_err());
    assert!(matches!(
        CiarletSimo::from_lame(1.0, 0.0),
        Err(MaterialError::InvalidShearModulus { .. })
    ));
    assert!(matches!(
        CiarletSimo::from_lame(-1.0, 1.0),
        Err(MaterialError::InvalidBulkModulus { .. })
    ));
    assert!(matches!(
        DevVolNeoHookean::new(1.0, 0.0),
        Err(MaterialError::InvalidBulkModulus { .. })
    ));
    // ν just inside the bounds is accepted.
    assert!(CiarletSimo::from_young_poisson(1.0, 0.4999).is_ok());
    assert!(CiarletSimo::from_young_poisson(1.0, -0.999).is_ok());
}

#[test]
fn inverted_F_is_a_typed_error() {
    let F = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -0.5));
    for m in [MaterialModel::from(ciarlet_simo()), dev_vol().into()] {
        assert_eq!(
            m.stress(&F).unwrap_err(),
            MaterialError::NonPositiveJacobian { J: -0.5 }
        );
        assert!(m.stress_tangent(&F).is_err() && m.energy(&F).is_err());
    }
    // The small-strain model has no notion of inversion.
    assert!(MaterialModel::from(linear_elastic()).stress(&F).is_ok());
}

#[test]
fn voigt_helpers_are_consistent() {
    let c = ciarlet_simo().stress_tangent(&large_F()).unwrap().1;
    // tangent_component reads c_ijkl with all minor symmetries.
    let (i, j, k, l) = (0, 1, 2, 1);
    let v = tangent_component(&c, i, j, k, l);
    assert_eq!(v, tangent_component(&c, j, i, k, l));
    assert_eq!(v, tangent_component(&c, i, j, l, k));
    // push-forward inverts pull-back.
    let F = large_F();
    let J = F.determinant();
    let C = pull_back_tangent(&c, &F.try_inverse().unwrap(), J);
    let back = push_forward_tangent(&C, &F, J);
    assert!((back - c).norm() < 1e-13 * c.norm());
    // (A ⊗ B) : H = A (B : H)
    let A = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 5.0, 3.0, 5.0, 6.0);
    let B = Matrix3::new(0.5, 0.1, 0.2, 0.1, -1.0, 0.3, 0.2, 0.3, 2.0);
    let H = Matrix3::new(0.3, 0.7, -0.1, 0.2, 0.9, 0.4, 0.6, -0.5, 1.1);
    let lhs = tangent_apply(&outer(&A, &B), &H);
    assert!((lhs - A * B.dot(&H)).norm() < 1e-13);
}
