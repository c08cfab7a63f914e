//! The material of one body, one of the models, as the solver configuration holds
//! it: [`MaterialModel`] dispatches to the model it names.
#![allow(non_snake_case)]

use nalgebra::Matrix3;

use super::linear::LinearElastic;
use super::neo_hookean::{CiarletSimo, DevVolNeoHookean};
use super::{Material, MaterialError, Tangent};

/// The material of one body, as the solver configuration holds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MaterialModel {
    CiarletSimo(CiarletSimo),
    DevVolNeoHookean(DevVolNeoHookean),
    LinearElastic(LinearElastic),
}

impl MaterialModel {
    fn inner(&self) -> &dyn Material {
        match self {
            MaterialModel::CiarletSimo(m) => m,
            MaterialModel::DevVolNeoHookean(m) => m,
            MaterialModel::LinearElastic(m) => m,
        }
    }
}

impl MaterialModel {
    /// Cauchy stress σ and the coefficients of an isotropic spatial tangent
    /// `c = α (1 ⊗ 1) + β 𝕀` (𝕀 the symmetric fourth-order identity), for the models
    /// whose tangent is one (`None` otherwise: the deviatoric/volumetric
    /// neo-Hookean's holds `b`); the element then contracts it without Voigt
    /// products. The same σ and c as [`Material::stress_tangent`].
    #[inline]
    pub fn isotropic_stress_tangent(&self, F: &Matrix3<f64>) -> Option<Result<(Matrix3<f64>, f64, f64), MaterialError>> {
        match self {
            MaterialModel::CiarletSimo(m) => Some(m.isotropic_stress_tangent(F)),
            MaterialModel::LinearElastic(m) => Some(m.isotropic_stress_tangent(F)),
            MaterialModel::DevVolNeoHookean(_) => None,
        }
    }
}

impl From<CiarletSimo> for MaterialModel {
    fn from(m: CiarletSimo) -> Self {
        MaterialModel::CiarletSimo(m)
    }
}
impl From<DevVolNeoHookean> for MaterialModel {
    fn from(m: DevVolNeoHookean) -> Self {
        MaterialModel::DevVolNeoHookean(m)
    }
}
impl From<LinearElastic> for MaterialModel {
    fn from(m: LinearElastic) -> Self {
        MaterialModel::LinearElastic(m)
    }
}

impl Material for MaterialModel {
    #[inline]
    fn stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        match self {
            MaterialModel::CiarletSimo(m) => m.stress_tangent(F),
            MaterialModel::DevVolNeoHookean(m) => m.stress_tangent(F),
            MaterialModel::LinearElastic(m) => m.stress_tangent(F),
        }
    }
    #[inline]
    fn stress(&self, F: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        match self {
            MaterialModel::CiarletSimo(m) => m.stress(F),
            MaterialModel::DevVolNeoHookean(m) => m.stress(F),
            MaterialModel::LinearElastic(m) => m.stress(F),
        }
    }
    fn energy(&self, F: &Matrix3<f64>) -> Result<f64, MaterialError> {
        self.inner().energy(F)
    }
    fn is_geometrically_linear(&self) -> bool {
        self.inner().is_geometrically_linear()
    }
    fn shear_modulus(&self) -> f64 {
        self.inner().shear_modulus()
    }
}
