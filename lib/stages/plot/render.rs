//! Drawing a [`Figure`] into PNG bytes with plotters' bitmap backend.
//!
//! Text uses DejaVu Sans embedded in the binary (`assets/fonts/DejaVuSans.ttf`,
//! licence beside it), registered with plotters' `ab_glyph` feature for the layout
//! and drawn by [`TextBackend`](super::text::TextBackend), so no system font and no
//! fontconfig is needed. plotters draws into an RGB buffer in memory; the `png`
//! crate encodes it, and the caller writes the bytes atomically.
//!
//! Layout: the title on top, then the panels stacked with equal heights, each with
//! its own y axis and legend; the x axis label only under the bottom panel. Text
//! sizes and line widths scale with the image width (1000 px = 1; at least 0.8 so
//! small images keep readable text).

use std::collections::HashMap;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use super::text::TextBackend;
use super::figure::{Figure, Panel};

/// DejaVu Sans 2.37, unmodified (Bitstream Vera / Arev licence in `assets/fonts/`).
static DEJAVU_SANS: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// The family name the font is registered under (plotters' `FontFamily::SansSerif`).
const FAMILY: &str = "sans-serif";

/// Tableau 10: distinct, colour-blind-friendlier than plotters' primaries. Labels
/// beyond ten reuse the colours in order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Series with at most this many points also get a dot per point (one per
/// converged increment: a short history reads better with its samples shown).
pub const MARKER_MAX_POINTS: usize = 60;

fn register_embedded_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).map_err(|_| "the embedded DejaVu Sans font is not a valid TrueType font".to_string()))
        .clone()
}

/// Draw the figure and encode it as an 8-bit RGB PNG.
pub fn render_png(fig: &Figure) -> Result<Vec<u8>, String> {
    // a figure built by hand (not by `figure`) is checked too: near the largest f64
    // the axes' arithmetic overflows and the drawing loops
    fig.check_drawable().map_err(|e| e.to_string())?;
    register_embedded_font()?;
    let (w, h) = fig.size;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    draw(fig, &mut rgb)?;
    let mut png = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Balanced);
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    Ok(png)
}

/// A colour per distinct label, in order of first appearance over the panels, so
/// one run keeps its colour in every panel.
fn colours(fig: &Figure) -> HashMap<&str, RGBColor> {
    let mut map = HashMap::new();
    for s in fig.panels.iter().flat_map(|p| &p.series) {
        let next = PALETTE[map.len() % PALETTE.len()];
        map.entry(s.label.as_str()).or_insert(next);
    }
    map
}

fn draw(fig: &Figure, rgb: &mut [u8]) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (w, h) = fig.size;
    let k = (w as f64 / 1000.0).clamp(0.8, 3.0);
    let font = ab_glyph::FontRef::try_from_slice(DEJAVU_SANS).map_err(|e| format!("the embedded DejaVu Sans: {e}"))?;
    let root = TextBackend { inner: BitMapBackend::with_buffer(rgb, (w, h)), font }.into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let body = match &fig.title {
        Some(t) => root.titled(t, (FAMILY, 26.0 * k).into_font()).map_err(|e| err(&e))?,
        None => root.clone(),
    };
    let colours = colours(fig);
    let areas = body.split_evenly((fig.panels.len(), 1));
    for (i, (area, panel)) in areas.iter().zip(&fig.panels).enumerate() {
        let last = i + 1 == fig.panels.len();
        draw_panel(fig, panel, area, last, &colours, k).map_err(|e| format!("panel {}: {e}", i + 1))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

fn draw_panel(fig: &Figure, panel: &Panel, area: &DrawingArea<TextBackend<'_>, Shift>, last: bool, colours: &HashMap<&str, RGBColor>, k: f64) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let px = |v: f64| (v * k).round() as u32;
    let (x0, x1) = fig.x_range;
    let (y0, y1) = panel.y_range;
    let mut chart = ChartBuilder::on(area)
        .margin(px(12.0))
        .margin_right(px(30.0))
        .x_label_area_size(px(if last { 62.0 } else { 34.0 }))
        .y_label_area_size(px(100.0))
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    let fx = |v: &f64| tick_label(*v, fig.x_range);
    let fy = |v: &f64| tick_label(*v, panel.y_range);
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(10)
        .y_labels(8)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style((FAMILY, 16.0 * k).into_font())
        .axis_desc_style((FAMILY, 19.0 * k).into_font())
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(205, 205, 205))
        .axis_style(BLACK.stroke_width(1));
    if let Some(y) = &panel.y_label {
        mesh.y_desc(y.as_str());
    }
    if last {
        mesh.x_desc(fig.x_label.as_str());
    }
    mesh.draw().map_err(|e| err(&e))?;

    let line = px(2.0).max(1);
    let legend_len = px(30.0) as i32;
    for s in &panel.series {
        let colour = colours.get(s.label.as_str()).copied().unwrap_or(BLACK);
        let style = colour.stroke_width(line);
        let pieces = clip_polyline(&s.points, fig.x_range, panel.y_range);
        // the first piece (or an empty one) carries the legend entry
        let first = pieces.first().cloned().unwrap_or_default();
        chart
            .draw_series(LineSeries::new(first, style))
            .map_err(|e| err(&e))?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + legend_len, y)], colour.stroke_width(line + 1)));
        for piece in pieces.into_iter().skip(1) {
            chart.draw_series(LineSeries::new(piece, style)).map_err(|e| err(&e))?;
        }
        if s.points.len() <= MARKER_MAX_POINTS {
            let r = px(3.5).max(2);
            let inside = s.points.iter().filter(|&&(x, y)| x0 <= x && x <= x1 && y0 <= y && y <= y1);
            chart.draw_series(inside.map(|&p| Circle::new(p, r, colour.filled()))).map_err(|e| err(&e))?;
        }
    }
    chart
        .configure_series_labels()
        .position(legend_corner(panel, fig.x_range))
        .margin(px(12.0))
        .legend_area_size(px(44.0))
        .label_font((FAMILY, 16.0 * k).into_font())
        .background_style(WHITE.mix(0.88))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(|e| err(&e))?;
    Ok(())
}

/// The parts of the polyline through `points` inside the box [x0, x1] × [y0, y1]
/// (each segment clipped by Liang–Barsky): plotters would otherwise pin points
/// outside a fixed axis range onto the frame and draw a false line along it. A
/// polyline leaving and re-entering the box gives several pieces; a lone point
/// inside gives a one-point piece.
pub fn clip_polyline(points: &[(f64, f64)], (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let inside = |(x, y): (f64, f64)| x0 <= x && x <= x1 && y0 <= y && y <= y1;
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    if let [p] = points {
        if inside(*p) {
            pieces.push(vec![*p]);
        }
        return pieces;
    }
    let mut open = false; // whether the last piece ends where the next segment starts
    for w in points.windows(2) {
        let ((xa, ya), (xb, yb)) = (w[0], w[1]);
        let (dx, dy) = (xb - xa, yb - ya);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let mut visible = true;
        for (p, q) in [(-dx, xa - x0), (dx, x1 - xa), (-dy, ya - y0), (dy, y1 - ya)] {
            if p == 0.0 {
                if q < 0.0 {
                    visible = false;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
        if !visible || t0 > t1 {
            open = false;
            continue;
        }
        let a = (xa + t0 * dx, ya + t0 * dy);
        let b = (xa + t1 * dx, ya + t1 * dy);
        match pieces.last_mut() {
            Some(piece) if open && t0 == 0.0 => piece.push(b),
            _ => pieces.push(vec![a, b]),
        }
        open = t1 == 1.0;
    }
    pieces
}

/// The corner of the panel that the curves cross least (points and points
/// interpolated along each segment, counted in the outer 45 % × 40 % of each
/// corner): where the legend hides the least data. Ties go to upper right, upper
/// left, lower right, lower left, in that order.
pub fn legend_corner(panel: &Panel, (x0, x1): (f64, f64)) -> SeriesLabelPosition {
    let (y0, y1) = panel.y_range;
    let mut counts = [0usize; 4]; // UR, UL, LR, LL
    let mut count = |x: f64, y: f64| {
        let (u, v) = ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0));
        let (right, left, upper, lower) = (u > 0.55, u < 0.45, v > 0.6, v < 0.4);
        for (c, inside) in counts.iter_mut().zip([upper && right, upper && left, lower && right, lower && left]) {
            *c += inside as usize;
        }
    };
    const SUB: usize = 8;
    for s in &panel.series {
        for pair in s.points.windows(2) {
            let ((xa, ya), (xb, yb)) = (pair[0], pair[1]);
            for j in 0..SUB {
                let t = j as f64 / SUB as f64;
                count(xa + t * (xb - xa), ya + t * (yb - ya));
            }
        }
        if let Some(&(x, y)) = s.points.last() {
            count(x, y);
        }
    }
    let best = (0..4).min_by_key(|&c| counts[c]).unwrap_or(0);
    [SeriesLabelPosition::UpperRight, SeriesLabelPosition::UpperLeft, SeriesLabelPosition::LowerRight, SeriesLabelPosition::LowerLeft][best].clone()
}

/// A tick label for `v` on an axis spanning `range`: as many decimals as ticks
/// 1/20 of the span apart need, trailing zeros dropped, scientific (`1.5e5`) when
/// the axis' magnitude is ≥ 1e5 or < 1e-3, and `0` for round-off around zero.
pub fn tick_label(v: f64, (lo, hi): (f64, f64)) -> String {
    let step = (hi - lo) / 20.0;
    let mag = lo.abs().max(hi.abs());
    if v.abs() <= step * 1e-6 || !v.is_finite() || step <= 0.0 {
        return if v.is_finite() { "0".into() } else { v.to_string() };
    }
    if !(1e-3..1e5).contains(&mag) {
        let p = (mag.log10().floor() - step.log10().floor()).clamp(0.0, 6.0) as usize;
        let s = format!("{v:.p$e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim_zeros(m)),
            None => s,
        }
    } else {
        let d = (-step.log10().floor()).clamp(0.0, 10.0) as usize;
        trim_zeros(&format!("{v:.d$}")).to_string()
    }
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::super::Series;
    use super::*;

    #[test]
    fn tick_labels_are_short_and_exact_enough() {
        assert_eq!(tick_label(0.30000000000000004, (0.0, 1.0)), "0.3");
        assert_eq!(tick_label(0.25, (0.5, 2.0)), "0.25");
        assert_eq!(tick_label(1.0, (0.5, 2.0)), "1");
        assert_eq!(tick_label(-400.0, (-420.0, 0.0)), "-400");
        assert_eq!(tick_label(1e-17, (-1.0, 1.0)), "0");
        assert_eq!(tick_label(1.5e6, (0.0, 2e6)), "1.5e6");
        assert_eq!(tick_label(2e6, (0.0, 2e6)), "2e6");
        assert_eq!(tick_label(-7.96e-10, (-8e-10, 0.0)), "-8e-10");
        assert_eq!(tick_label(0.32, (0.3, 0.34)), "0.32");
    }

    #[test]
    fn clipping_cuts_lines_at_the_frame() {
        let b = ((0.0, 10.0), (0.0, 1.0));
        // inside: one piece, unchanged
        assert_eq!(clip_polyline(&[(0.0, 0.5), (5.0, 0.5), (10.0, 0.2)], b.0, b.1), vec![vec![(0.0, 0.5), (5.0, 0.5), (10.0, 0.2)]]);
        // leaves through the top at x = 2 and comes back at x = 8: two pieces
        let p = clip_polyline(&[(0.0, 0.0), (4.0, 2.0), (6.0, 2.0), (10.0, 0.0)], b.0, b.1);
        assert_eq!(p, vec![vec![(0.0, 0.0), (2.0, 1.0)], vec![(8.0, 1.0), (10.0, 0.0)]]);
        // entirely below the frame: nothing (plotters would draw it along y = 0)
        assert!(clip_polyline(&[(0.0, -0.2), (10.0, -0.3)], b.0, b.1).is_empty());
        // a lone point
        assert_eq!(clip_polyline(&[(1.0, 0.5)], b.0, b.1), vec![vec![(1.0, 0.5)]]);
        assert!(clip_polyline(&[(1.0, 5.0)], b.0, b.1).is_empty());
    }

    #[test]
    fn legend_goes_where_the_curves_are_not() {
        // a rising line from lower left to upper right: the upper left is free
        let rising = Panel { y_label: None, y_range: (0.0, 1.0), series: vec![Series { label: "a".into(), points: vec![(0.0, 0.0), (1.0, 1.0)] }] };
        assert!(matches!(legend_corner(&rising, (0.0, 1.0)), SeriesLabelPosition::UpperLeft));
        // a curve high everywhere: a lower corner
        let high = Panel { y_label: None, y_range: (0.0, 1.0), series: vec![Series { label: "a".into(), points: vec![(0.0, 0.9), (1.0, 0.95)] }] };
        assert!(matches!(legend_corner(&high, (0.0, 1.0)), SeriesLabelPosition::LowerRight));
    }

    #[test]
    fn same_label_same_colour() {
        let s = |l: &str| Series { label: l.into(), points: vec![(0.0, 0.0)] };
        let p = |v: Vec<Series>| Panel { y_label: None, y_range: (0.0, 1.0), series: v };
        let fig = Figure { title: None, x_label: "x".into(), size: (400, 300), x_range: (0.0, 1.0), panels: vec![p(vec![s("facet"), s("b3")]), p(vec![s("b3"), s("facet")])] };
        let c = colours(&fig);
        assert_eq!(c.len(), 2);
        assert_eq!(c["facet"], PALETTE[0]);
        assert_eq!(c["b3"], PALETTE[1]);
    }
}
