//! Amplitudes: how a prescribed displacement or a load scales with the load factor
//! ("time") t — the ramp a(t) = t by default, or a named piecewise-linear curve of the
//! setup (`curves:`), constant beyond its ends. Two curves make a load path: press,
//! then slide.

/// a(t).
#[derive(Debug, Clone, PartialEq)]
pub enum Amplitude {
    /// a(t) = t.
    Ramp,
    /// Piecewise linear through (t_i, a_i), t increasing; constant outside.
    Table(Vec<[f64; 2]>),
}

impl Amplitude {
    /// A table, checked: at least one point, finite, t strictly increasing.
    pub fn table(points: &[[f64; 2]]) -> Result<Self, String> {
        if points.is_empty() {
            return Err("needs at least one point [t, a]".into());
        }
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err("has a point that is not finite".into());
        }
        if let Some(w) = points.windows(2).find(|w| w[1][0] <= w[0][0]) {
            return Err(format!("t must increase strictly: {} follows {}", w[1][0], w[0][0]));
        }
        Ok(Self::Table(points.to_vec()))
    }

    pub fn at(&self, t: f64) -> f64 {
        match self {
            Self::Ramp => t,
            Self::Table(p) => {
                let first = p[0];
                let last = p[p.len() - 1];
                if t <= first[0] {
                    return first[1];
                }
                if t >= last[0] {
                    return last[1];
                }
                let k = p.partition_point(|q| q[0] <= t); // p[k-1][0] <= t < p[k][0]
                let (a, b) = (p[k - 1], p[k]);
                a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_linear_and_constant_outside() {
        let a = Amplitude::table(&[[0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [3.0, -1.0]]).unwrap();
        for (t, v) in [(-1.0, 0.0), (0.0, 0.0), (0.25, 0.25), (1.0, 1.0), (1.5, 1.0), (2.5, 0.0), (3.0, -1.0), (9.0, -1.0)] {
            assert!((a.at(t) - v).abs() < 1e-15, "a({t}) = {} ≠ {v}", a.at(t));
        }
        assert_eq!(Amplitude::Ramp.at(0.7), 0.7);
        assert!(Amplitude::table(&[[0.0, 0.0], [0.0, 1.0]]).unwrap_err().contains("increase"));
        assert!(Amplitude::table(&[]).is_err());
    }
}
