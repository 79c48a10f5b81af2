//! Text on the bitmap (PNG) charts, each glyph drawn where the font puts it.
//!
//! plotters 0.3.7 rasterises a glyph of its `ab_glyph` font at the caret without the glyph's
//! left side bearing (it shifts the outline's pixels by the caret alone, ignoring
//! `px_bounds().min.x`), and on whole pixels: a narrow letter after a wide one sits too far
//! left, a round one too far right, and words fall apart ("back ward", "search ed"). The
//! SVG charts are unaffected (their text is `<text>`). [`GlyphTextBitMapBackend`] is the
//! bitmap backend with its text drawn again: the same layout box, anchor and rotation as
//! plotters' own `draw_text`, and each glyph outlined at its fractional caret position, so
//! its pixels land where its bearing says. Everything else is the bitmap backend's own.

use std::sync::OnceLock;

use ab_glyph::{point, Font, FontRef, ScaleFont};
use plotters::prelude::BitMapBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// The embedded face every chart's text is drawn with ([`crate::fonts`]).
fn face() -> &'static FontRef<'static> {
    static FACE: OnceLock<FontRef<'static>> = OnceLock::new();
    FACE.get_or_init(|| {
        FontRef::try_from_slice(crate::fonts::DEJAVU_SANS).expect("the embedded font parses")
    })
}

/// plotters' bitmap backend with each glyph of its text placed by the font's own metrics
/// (see the module documentation); every other drawing call is passed through unchanged.
/// Its type name contains `BitMapBackend`, which [`crate::render`] reads to tell a raster
/// chart from a vector one.
pub struct GlyphTextBitMapBackend<'a>(pub BitMapBackend<'a>);

impl<'a> DrawingBackend for GlyphTextBitMapBackend<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.blit_bitmap(pos, size, src)
    }

    /// plotters' `draw_text` (layout box, anchor, rotation, clipping to the image), with
    /// the glyphs rasterised at their fractional caret positions, bearings included.
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
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
        let (w, h) = self.get_size();
        let size = style.size() as f32;
        let font = face().as_scaled(size);
        let mut caret = 0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                caret += font.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(size, point(caret, 0.0));
            caret += font.h_advance(id);
            let Some(outline) = font.outline_glyph(glyph) else {
                continue; // a space
            };
            let bounds = outline.px_bounds();
            // The vertical placement is plotters' (the baseline half a size down), so the
            // layout boxes it measured still hold the text.
            let (x0, y0) = (bounds.min.x as i32, (size / 2.0 + bounds.min.y) as i32);
            let mut result = Ok(());
            outline.draw(|x, y, coverage| {
                if result.is_err() {
                    return;
                }
                let (x, y) =
                    trans.transform(x as i32 + x0 + dx - min_x, y as i32 + y0 + dy - min_y);
                let (x, y) = (pos.0 + x, pos.1 + y);
                if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                    let mixed = BackendColor {
                        alpha: color.alpha * f64::from(coverage),
                        rgb: color.rgb,
                    };
                    result = self.0.draw_pixel((x, y), mixed);
                }
            });
            result?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};

    /// The first and last columns with ink of `text` drawn at the left of a white image.
    fn ink_columns(text: &str, size: f64) -> (usize, usize) {
        crate::fonts::register_embedded_fonts().unwrap();
        let (w, h) = (400_usize, 100_usize);
        let mut buf = vec![255_u8; w * h * 3];
        {
            let backend = BitMapBackend::with_buffer(&mut buf, (w as u32, h as u32));
            let root = GlyphTextBitMapBackend(backend).into_drawing_area();
            let style = TextStyle::from((crate::fonts::FONT_FAMILY, size).into_font())
                .pos(Pos::new(HPos::Left, VPos::Top));
            root.draw_text(text, &style, (0, 10)).unwrap();
            root.present().unwrap();
        }
        let inked: Vec<usize> = (0..w)
            .filter(|&x| (0..h).any(|y| buf[(y * w + x) * 3] < 128))
            .collect();
        (inked[0], *inked.last().unwrap())
    }

    #[test]
    fn a_glyph_starts_at_its_left_bearing_and_a_word_keeps_its_advances() {
        let size = 40.0;
        let font = face().as_scaled(size as f32);
        // 'o' starts about 2 px right of its caret (plotters drew it at the caret).
        let bearing = font.h_side_bearing(font.glyph_id('o'));
        assert!(bearing > 1.5, "{bearing}");
        let (first, _) = ink_columns("o", size);
        assert!(
            (first as f32 - bearing).abs() <= 1.0,
            "ink from {first}, bearing {bearing}"
        );
        // The word's ink ends where the font puts its last glyph's right edge: the sum of
        // the advances and kerning before it, plus its own outline's extent.
        let word = "backward";
        let ids: Vec<_> = word.chars().map(|c| font.glyph_id(c)).collect();
        let mut caret = 0.0;
        for pair in ids.windows(2) {
            caret += font.h_advance(pair[0]) + font.kern(pair[0], pair[1]);
        }
        let last_glyph = ids[ids.len() - 1].with_scale_and_position(size as f32, point(caret, 0.0));
        let right = font.outline_glyph(last_glyph).unwrap().px_bounds().max.x;
        let (_, last) = ink_columns(word, size);
        assert!(
            (last as f32 - (right - 1.0)).abs() <= 1.0,
            "ink to {last}, the font's right edge {right}"
        );
    }
}
