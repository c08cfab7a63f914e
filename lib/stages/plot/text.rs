//! A drawing backend that is plotters' bitmap backend with its own text: every
//! glyph placed at its pen position plus its left side bearing, on a common
//! baseline.
//!
//! Why: plotters 0.3.7's `ab_glyph` text drawing starts each glyph's bitmap at the
//! pen position, ignoring the glyph's side bearing, and puts the baseline at half
//! the font size. Narrow letters then sit at the left of their advance ("th e",
//! "Shallow ironing" with a gap after the w) and text rides high beside a legend
//! line. Layout stays plotters' (its `ab_glyph` width estimate, the sum of the
//! advances with kerning, is right); only the rasterising of the glyphs inside the
//! same box is done here:
//!
//! ```text
//! box (from plotters): width W = Σ advances + kerning, height H = size / 1.24
//! baseline b = (H + cap height) / 2     capitals and digits centred in the box
//! glyph k at x = pen_k + bearing_k, pen_{k+1} = pen_k + advance_k + kern(k, k+1)
//! ```
//! then the anchor and the rotation exactly as plotters' default `draw_text`.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use plotters::prelude::BitMapBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind};

type Error = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

/// plotters' bitmap backend, drawing text with `font`.
pub struct TextBackend<'a> {
    pub inner: BitMapBackend<'a>,
    pub font: FontRef<'static>,
}

impl TextBackend<'_> {
    /// Call `pixel(x, y, coverage)` for every pixel of `text` at `size`, in the
    /// layout box's frame (top left (0, 0), `height` tall).
    fn raster(&self, text: &str, size: f64, height: f64, mut pixel: impl FnMut(i32, i32, f32)) {
        let scale = PxScale::from(size as f32);
        let font = self.font.as_scaled(scale);
        let cap = font.outline_glyph(font.scaled_glyph('H')).map_or(0.7 * size as f32, |g| g.px_bounds().height());
        let baseline = (height as f32 + cap) / 2.0;
        let mut pen = 0.0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                pen += font.kern(p, id);
            }
            let glyph = id.with_scale_and_position(scale, ab_glyph::point(pen, baseline));
            if let Some(outline) = font.outline_glyph(glyph) {
                let min = outline.px_bounds().min;
                outline.draw(|x, y, c| pixel(min.x as i32 + x as i32, min.y as i32 + y as i32, c));
            }
            pen += font.h_advance(id);
            prev = Some(id);
        }
    }
}

impl DrawingBackend for TextBackend<'_> {
    type ErrorType = Error;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.present()
    }
    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(&mut self, from: BackendCoord, to: BackendCoord, style: &S) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(&mut self, upper_left: BackendCoord, bottom_right: BackendCoord, style: &S, fill: bool) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(&mut self, path: I, style: &S) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(&mut self, center: BackendCoord, radius: u32, style: &S, fill: bool) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(&mut self, vert: I, style: &S) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Result<(), DrawingErrorKind<Error>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(&mut self, text: &str, style: &S, pos: BackendCoord) -> Result<(), DrawingErrorKind<Error>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style.layout_box(text).map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let trans = style.transform();
        let mut pixels = Vec::new();
        self.raster(text, style.size(), height as f64, |x, y, c| {
            let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
            pixels.push(((pos.0 + x, pos.1 + y), c));
        });
        for (p, c) in pixels {
            self.inner.draw_pixel(p, BackendColor { alpha: color.alpha * c.clamp(0.0, 1.0) as f64, rgb: color.rgb })?;
        }
        Ok(())
    }
}
