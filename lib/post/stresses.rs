//! Stress measures for output: element and nodal averages of the Cauchy stress at
//! the Gauss points, von Mises stress, and principal stresses (the paper's
//! figures 4, 9, 10 show the maximum and minimum principal stress).

use nalgebra::{Matrix3, SymmetricEigen};

use crate::mesh::Mesh;

/// Row-major 3×3 as 9 numbers.
pub type Tensor9 = [f64; 9];

/// von Mises stress √(3/2 s:s), s = dev σ.
pub fn von_mises(s: &Tensor9) -> f64 {
    let p = (s[0] + s[4] + s[8]) / 3.0;
    let d = [s[0] - p, s[4] - p, s[8] - p];
    let off = s[1] * s[1] + s[3] * s[3] + s[2] * s[2] + s[6] * s[6] + s[5] * s[5] + s[7] * s[7];
    (1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + off)).sqrt()
}

/// Principal stresses (eigenvalues of the symmetric part), ascending.
pub fn principal(s: &Tensor9) -> [f64; 3] {
    let m = Matrix3::from_row_slice(s);
    let sym = (m + m.transpose()) * 0.5;
    let mut ev: [f64; 3] = SymmetricEigen::new(sym).eigenvalues.into();
    ev.sort_by(|a, b| a.total_cmp(b));
    ev
}

/// Average of the 8 Gauss-point tensors of each element.
pub fn element_average(stress: &[[Tensor9; 8]]) -> Vec<Tensor9> {
    stress
        .iter()
        .map(|q| {
            let mut a = [0.0; 9];
            for t in q {
                for i in 0..9 {
                    a[i] += t[i] / 8.0;
                }
            }
            a
        })
        .collect()
}

/// Nodal average: each node gets the mean of the element averages of the elements
/// around it (unweighted, per body boundaries ignored).
pub fn nodal_average(mesh: &Mesh, element_avg: &[Tensor9]) -> Vec<Tensor9> {
    let mut sum = vec![[0.0; 9]; mesh.nodes.len()];
    let mut count = vec![0u32; mesh.nodes.len()];
    for (h, s) in mesh.hexes.iter().zip(element_avg) {
        for &n in h {
            let n = n as usize;
            count[n] += 1;
            for i in 0..9 {
                sum[n][i] += s[i];
            }
        }
    }
    for (s, c) in sum.iter_mut().zip(&count) {
        if *c > 0 {
            s.iter_mut().for_each(|v| *v /= *c as f64);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniaxial_von_mises_and_principal() {
        let s = [5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((von_mises(&s) - 5.0).abs() < 1e-14);
        assert_eq!(principal(&s), [0.0, 0.0, 5.0]);
    }

    #[test]
    fn pure_shear() {
        let t = 2.0;
        let s = [0.0, t, 0.0, t, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((von_mises(&s) - 3f64.sqrt() * t).abs() < 1e-14);
        let p = principal(&s);
        assert!((p[0] + t).abs() < 1e-14 && p[1].abs() < 1e-14 && (p[2] - t).abs() < 1e-14);
    }
}
