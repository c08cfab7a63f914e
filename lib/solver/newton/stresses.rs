//! Cauchy stress σ at the eight Gauss points of every hexahedron at a state u, for
//! the results file (the element's constitutive evaluation, `fem::element`, without
//! the tangent). Elements are independent: evaluated in parallel.

use crate::fem::element::{hex8_gauss_stresses, ElementError};
use crate::solver::problem::Problem;

/// Cauchy stress at the Gauss points of every element (row-major 3×3), in parallel.
pub fn gauss_stresses(p: &Problem, u: &[f64]) -> Result<Vec<[[f64; 9]; 8]>, (usize, ElementError)> {
    use rayon::prelude::*;
    (0..p.hexes.len())
        .into_par_iter()
        .map(|e| {
            let (X, ue) = p.gather(e, u);
            let s = hex8_gauss_stresses(&X, &ue, &p.materials[p.hex_material[e] as usize]).map_err(|err| (e, err))?;
            Ok(std::array::from_fn(|q| std::array::from_fn(|i| s[q][(i / 3, i % 3)])))
        })
        .collect()
}
