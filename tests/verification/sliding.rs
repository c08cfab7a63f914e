//! What the large-sliding tests (ironing.rs, shallow_ironing.rs) read from a solve:
//! the force history of the sliding body from `<name>.forces.csv`, and the Newton
//! corrections and cutbacks from its results.

use std::path::Path;

use splinecontact::format::csv::Table;
use splinecontact::format::scres::Results;

/// The histories over the sliding: travel s = `travel` · (t − `start`), the vertical
/// force V = −R_vertical and horizontal force H = R_x on the driven set, and
/// |Σ tangential| / |Σ normal| contact force of the pair `contact`.
pub struct History {
    pub s: Vec<f64>,
    pub v: Vec<f64>,
    pub h: Vec<f64>,
    pub t_over_n: Vec<f64>,
}

impl History {
    /// The history up to the travel `s_max` (the travel grows along the rows).
    pub fn until(mut self, s_max: f64) -> Self {
        let n = self.s.iter().take_while(|s| **s <= s_max + 1e-9).count();
        for column in [&mut self.s, &mut self.v, &mut self.h, &mut self.t_over_n] {
            column.truncate(n);
        }
        self
    }
}

/// Reads the rows with t ≥ `start` (the sliding) of the forces CSV at `path`:
/// reactions on `set` (`vertical` is its axis pressed into the other body, "y" or
/// "z"), contact forces of the pair `contact`.
pub fn history(path: &Path, set: &str, vertical: &str, start: f64, travel: f64) -> History {
    let t = Table::read(path).unwrap();
    let col = |n: &str| t.column(n).unwrap_or_else(|| panic!("{}: no column {n}", path.display()));
    let (lf, rv, rx) = (col("load_factor"), col(&format!("reaction:{set}:{vertical}")), col(&format!("reaction:{set}:x")));
    let axes = ["x", "y", "z"];
    let c = [0, 1, 2].map(|k| col(&format!("contact:contact:{}", axes[k])));
    let tg = [0, 1, 2].map(|k| col(&format!("tangential:contact:{}", axes[k])));
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let mut h = History { s: vec![], v: vec![], h: vec![], t_over_n: vec![] };
    for r in t.rows.iter().filter(|r| r[lf] >= start - 1e-9) {
        h.s.push(travel * (r[lf] - start));
        h.v.push(-r[rv]);
        h.h.push(r[rx]);
        let tv = tg.map(|k| r[k]);
        h.t_over_n.push(norm(tv) / norm([0, 1, 2].map(|k| r[c[k]] - tv[k])));
    }
    h
}

/// Newton corrections (iterations after the first residual) and cutbacks over the run.
pub fn newton_and_cutbacks(r: &Results) -> (usize, u32) {
    (r.increments.iter().map(|i| i.info.iterations.len() - 1).sum(), r.increments.iter().map(|i| i.info.cutbacks).sum())
}
