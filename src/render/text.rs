//! Text drawn into pictures: the window's state panel, and the font every
//! picture with text uses.
//!
//! The font is Noto Mono, bundled in the binary (SIL Open Font License,
//! `assets/fonts/OFL.txt`), so no system font library is needed and the
//! text looks the same on every machine. Text is rasterized by `plotters`
//! (through `ab_glyph`) straight into the picture's RGB bytes.

use image::RgbImage;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::sync::Once;

/// The family name the bundled font is registered under with `plotters`.
pub const FONT_FAMILY: &str = "sans-serif";

/// The bundled font (Noto Mono Regular, a monospaced TrueType font).
pub static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/NotoMono-Regular.ttf");

/// Width of one character of the bundled monospaced font, as a fraction
/// of the font size (Noto Mono advances 0.6 em).
const ADVANCE_EM: f64 = 0.6;

/// Registers the bundled font with `plotters` under [`FONT_FAMILY`], once
/// per process. Call before drawing text.
pub fn register_bundled_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // The bytes are a valid font, checked by the tests; a failure here
        // only means text is not drawn.
        let _ = register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES);
    });
}

/// Font size, in pixels, of the state panel in a picture `height` pixels
/// tall: about 1/40 of the height, from 11 to 18 pixels, so the panel is
/// readable in a small window and stays small in a large one.
pub fn panel_font_px(height: u32) -> u32 {
    (height / 40).clamp(11, 18)
}

/// How much of the picture behind the panel still shows through its
/// backing (the rest is darkened to black), so the text reads on any
/// surface while the scene stays visible.
pub const PANEL_SHOW_THROUGH: f32 = 0.35;

/// Draws `lines` of text in the top-left corner of `image`: white text on
/// a darkened backing box, font size [`panel_font_px`]. Lines longer than
/// the picture are cut at its edge. Returns the box drawn, `(x, y, width,
/// height)` in pixels, clipped to the picture (all zero when nothing is
/// drawn).
pub fn draw_panel(image: &mut RgbImage, lines: &[&str]) -> (u32, u32, u32, u32) {
    let (w, h) = (image.width(), image.height());
    let longest = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    if w == 0 || h == 0 || longest == 0 {
        return (0, 0, 0, 0);
    }
    register_bundled_font();
    let size = panel_font_px(h);
    let line_height = size + size / 4;
    let margin = size / 2;
    let box_w = ((longest as f64 * ADVANCE_EM * f64::from(size)).ceil() as u32 + 2 * margin).min(w);
    let box_h = (lines.len() as u32 * line_height + 2 * margin).min(h);
    for y in 0..box_h {
        for x in 0..box_w {
            let p = image.get_pixel_mut(x, y);
            for c in &mut p.0 {
                *c = (f32::from(*c) * PANEL_SHOW_THROUGH).round() as u8;
            }
        }
    }
    let buffer: &mut [u8] = image.as_mut();
    let root = BitMapBackend::with_buffer(buffer, (w, h)).into_drawing_area();
    let style = TextStyle::from((FONT_FAMILY, size as f64).into_font()).color(&WHITE);
    for (i, line) in lines.iter().enumerate() {
        let y = (margin + i as u32 * line_height) as i32;
        // A failed glyph only leaves a gap in the panel: nothing to report.
        let _ = root.draw_text(line, &style, (margin as i32, y));
    }
    let _ = root.present();
    (0, 0, box_w, box_h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    #[test]
    fn the_bundled_font_is_a_font() {
        assert!(register_font("test-font", FontStyle::Normal, FONT_BYTES).is_ok());
    }

    #[test]
    fn the_panel_writes_light_text_on_a_dark_box_in_the_corner() {
        let grey = Rgb([128, 128, 128]);
        let mut image = RgbImage::from_pixel(320, 240, grey);
        let (x, y, bw, bh) = draw_panel(&mut image, &["step 12 · unshot 3.2%", "h: help"]);
        assert_eq!((x, y), (0, 0));
        assert!(bw > 100 && bw < 320 && bh > 20 && bh < 80, "{bw}×{bh}");
        // Inside the box: darkened backing and white-ish text pixels.
        let inside: Vec<&Rgb<u8>> = (0..bh)
            .flat_map(|y| (0..bw).map(move |x| (x, y)))
            .map(|(x, y)| image.get_pixel(x, y))
            .collect();
        let dark = inside.iter().filter(|p| p.0[0] < 60).count();
        let light = inside.iter().filter(|p| p.0[0] > 200).count();
        assert!(dark > inside.len() / 2, "{dark} dark of {}", inside.len());
        assert!(light > 50, "only {light} text pixels");
        // Outside the box the picture is untouched.
        assert_eq!(*image.get_pixel(bw + 1, bh + 1), grey);
        assert_eq!(*image.get_pixel(319, 239), grey);
    }

    #[test]
    fn a_panel_in_a_tiny_picture_is_clipped_not_a_panic() {
        let mut image = RgbImage::new(20, 10);
        let (_, _, bw, bh) = draw_panel(&mut image, &["a line far longer than the picture"]);
        assert_eq!((bw, bh), (20, 10));
        let mut empty = RgbImage::new(0, 0);
        assert_eq!(draw_panel(&mut empty, &["x"]), (0, 0, 0, 0));
        let mut image = RgbImage::new(20, 10);
        assert_eq!(draw_panel(&mut image, &[]), (0, 0, 0, 0));
    }
}
