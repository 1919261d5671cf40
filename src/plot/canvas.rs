//! The canvas every figure draws on: the SVG backend at [`SCALE`] drawing units per output
//! pixel, shown at its nominal size through the SVG's `viewBox`, so lines fall between pixels
//! instead of on whole ones. Line widths and font sizes scale by themselves; layout lengths
//! given by the figures (margins, label areas, offsets) go through [`px`].

use plotters::prelude::*;
use plotters_backend::{
    text_anchor, BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind, FontFamily, FontStyle,
    FontTransform,
};

/// Drawing units per output pixel.
pub(crate) const SCALE: u32 = 4;

/// `pixels` output pixels in drawing units.
pub(crate) const fn px(pixels: u32) -> u32 {
    pixels * SCALE
}

/// The same for signed offsets.
pub(crate) const fn pxi(pixels: i32) -> i32 {
    pixels * SCALE as i32
}

/// The SVG backend drawn at [`SCALE`]: strokes and fonts scaled, coordinates passed through.
pub(crate) struct Canvas<'a> {
    inner: SVGBackend<'a>,
}

/// A style whose stroke is [`SCALE`] times wider.
struct Stroke<'s, S>(&'s S);

impl<S: BackendStyle> BackendStyle for Stroke<'_, S> {
    fn color(&self) -> BackendColor {
        self.0.color()
    }
    fn stroke_width(&self) -> u32 {
        self.0.stroke_width() * SCALE
    }
}

/// A text style [`SCALE`] times larger.
struct Font<'s, T>(&'s T);

impl<T: BackendTextStyle> BackendTextStyle for Font<'_, T> {
    type FontError = T::FontError;
    fn color(&self) -> BackendColor {
        self.0.color()
    }
    fn size(&self) -> f64 {
        self.0.size() * f64::from(SCALE)
    }
    fn transform(&self) -> FontTransform {
        self.0.transform()
    }
    fn style(&self) -> FontStyle {
        self.0.style()
    }
    fn anchor(&self) -> text_anchor::Pos {
        self.0.anchor()
    }
    fn family(&self) -> FontFamily<'_> {
        self.0.family()
    }
    fn layout_box(&self, text: &str) -> Result<((i32, i32), (i32, i32)), Self::FontError> {
        let ((x0, y0), (x1, y1)) = self.0.layout_box(text)?;
        Ok(((pxi(x0), pxi(y0)), (pxi(x1), pxi(y1))))
    }
    fn draw<E, DrawFunc: FnMut(i32, i32, BackendColor) -> Result<(), E>>(
        &self,
        text: &str,
        pos: BackendCoord,
        draw: DrawFunc,
    ) -> Result<Result<(), E>, Self::FontError> {
        self.0.draw(text, pos, draw)
    }
}

impl DrawingBackend for Canvas<'_> {
    type ErrorType = <SVGBackend<'static> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, &Stroke(style))
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, &Stroke(style), fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, &Stroke(style))
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, &Stroke(style), fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, &Stroke(style))
    }
    fn draw_text<T: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &T,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_text(text, &Font(style), pos)
    }
    fn estimate_text_size<T: BackendTextStyle>(
        &self,
        text: &str,
        style: &T,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        self.inner.estimate_text_size(text, &Font(style))
    }
}

/// A drawing area of `size` output pixels writing into `svg`.
pub(crate) fn canvas(svg: &mut String, size: (u32, u32)) -> DrawingArea<Canvas<'_>, plotters::coord::Shift> {
    Canvas {
        inner: SVGBackend::with_string(svg, (px(size.0), px(size.1))),
    }
    .into_drawing_area()
}

/// The finished SVG, shown at its size in output pixels (its `viewBox` keeps the drawing
/// units).
pub(crate) fn shown_at(svg: String) -> String {
    let header = |text: &str, key: &str| -> Option<u32> {
        let start = text.find(&format!("{key}=\""))? + key.len() + 2;
        text[start..].split('"').next()?.parse().ok()
    };
    let head = &svg[..svg.find('>').unwrap_or(svg.len())];
    match (header(head, "width"), header(head, "height")) {
        (Some(w), Some(h)) => svg.replacen(
            &format!("<svg width=\"{w}\" height=\"{h}\""),
            &format!("<svg width=\"{}\" height=\"{}\"", w / SCALE, h / SCALE),
            1,
        ),
        _ => svg,
    }
}

#[cfg(test)]
mod tests {
    use super::{canvas, pxi, shown_at, SCALE};
    use plotters::prelude::*;

    /// A line drawn on the canvas lands between output pixels, its width and the text's size
    /// keep their output-pixel meaning, and the SVG shows at the nominal size.
    #[test]
    fn lines_fall_between_pixels_at_the_nominal_size() {
        let mut svg = String::new();
        {
            let root = canvas(&mut svg, (100, 50));
            root.draw(&PathElement::new(
                vec![(0, 0), (pxi(33) + 1, pxi(10) + 2)],
                BLACK.stroke_width(2),
            ))
            .unwrap();
            root.draw(&Text::new("label", (pxi(10), pxi(10)), ("sans-serif", 12)))
                .unwrap();
            root.present().unwrap();
        }
        let svg = shown_at(svg);
        assert!(
            svg.starts_with("<svg width=\"100\" height=\"50\" viewBox=\"0 0 400 200\""),
            "{svg}"
        );
        // 133/4 = 33.25 output pixels: a quarter pixel the integer backend could not place.
        assert!(svg.contains("133,42"), "{svg}");
        assert!(svg.contains("stroke-width=\"8\""), "{svg}");
        let font = format!("font-size=\"{}\"", 12.0 * f64::from(SCALE) / 1.24);
        assert!(svg.contains(&font), "{svg}");
    }
}
