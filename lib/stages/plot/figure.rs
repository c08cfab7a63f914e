//! The figure as data, ready to draw: panels of labelled series of points on a
//! shared x axis, sizes and ranges decided.

/// A series ready to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    /// (x, y) in row order.
    pub points: Vec<(f64, f64)>,
}

/// A panel ready to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    pub y_label: Option<String>,
    /// The y axis (lo < hi).
    pub y_range: (f64, f64),
    pub series: Vec<Series>,
}

/// Everything [`render`](super::render) needs: no file names, only numbers and text.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    pub title: Option<String>,
    pub x_label: String,
    pub size: (u32, u32),
    /// The shared x axis (lo < hi).
    pub x_range: (f64, f64),
    pub panels: Vec<Panel>,
}

/// The largest magnitude an axis may reach: near f64::MAX the drawing library's tick
/// arithmetic overflows and loops (a fuzzed CSV with 1e308 hung sc-plot).
pub const DRAWABLE: f64 = 1e300;

/// An axis of a figure that cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{what} reaches {value:e}: beyond what can be drawn (|v| ≤ 1e300; the axes' arithmetic overflows near the largest f64)")]
pub struct Undrawable {
    pub what: String,
    pub value: f64,
}

impl Figure {
    /// Every axis within ±[`DRAWABLE`]: the x axis, then each panel's y axis
    /// (numbered from 1), the first one beyond named.
    pub fn check_drawable(&self) -> Result<(), Undrawable> {
        let axes = std::iter::once(("the x axis".to_string(), self.x_range)).chain(self.panels.iter().enumerate().map(|(i, p)| (format!("panel {}: the y axis", i + 1), p.y_range)));
        for (what, (lo, hi)) in axes {
            if let Some(value) = [lo, hi].into_iter().find(|v| v.is_nan() || v.abs() > DRAWABLE) {
                return Err(Undrawable { what, value });
            }
        }
        Ok(())
    }
}
