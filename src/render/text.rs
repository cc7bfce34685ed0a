//! Text drawn into pictures: the window's state panel, and the font every
//! picture with text uses.
//!
//! The font is Noto Mono, bundled in the binary (SIL Open Font License,
//! `assets/fonts/OFL.txt`), so no system font library is needed and the
//! text looks the same on every machine. The panel's text is laid out
//! here ([`draw_text`]) with `ab_glyph`: each glyph at a whole pixel of
//! its pen position, with its own side bearing, advancing by the font's
//! advance rounded to whole pixels, so every character cell of the
//! monospaced font is as wide as every other and the gaps between letters
//! are even. (Drawn by `plotters`, which the legends and plots use, each
//! glyph's ink started at its pen position, so narrow glyphs sat at the
//! left of their cells: "0. 082%", "ar ound".)

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use image::RgbImage;
use plotters::style::{register_font, FontStyle};
use std::sync::{Once, OnceLock};

/// The family name the bundled font is registered under with `plotters`.
pub const FONT_FAMILY: &str = "sans-serif";

/// The bundled font (Noto Mono Regular, a monospaced TrueType font).
pub static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/NotoMono-Regular.ttf");

/// The bundled font, parsed once; `None` only if the bytes were no font
/// (the tests check they are), and then no text is drawn.
fn font() -> Option<&'static FontRef<'static>> {
    static FONT: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).ok())
        .as_ref()
}

/// The width of one character cell of the bundled monospaced font at
/// `size_px` pixels (ascent to descent), in whole pixels: the advance
/// [`draw_text`] moves by.
pub fn cell_width(size_px: u32) -> u32 {
    font().map_or(size_px.div_ceil(2), |f| {
        let scaled = f.as_scaled(PxScale::from(size_px as f32));
        (scaled.h_advance(f.glyph_id('0')).round() as u32).max(1)
    })
}

/// Draws `text` into `image` in `color`, its line's top at `top` and its
/// first character cell at `left` (pixels), at `size_px` pixels from the
/// font's ascent to its descent; coverage is blended over the picture.
/// Each character takes one [`cell_width`] (the font is monospaced), and
/// its glyph sits in its cell as the font places it; what falls outside
/// the picture is cut. Returns the pen position after the text.
pub fn draw_text(
    image: &mut RgbImage,
    text: &str,
    (left, top): (i32, i32),
    size_px: u32,
    color: [u8; 3],
) -> i32 {
    let Some(font) = font() else {
        return left;
    };
    let scale = PxScale::from(size_px as f32);
    let scaled = font.as_scaled(scale);
    let baseline = top as f32 + scaled.ascent().round();
    let advance = cell_width(size_px) as i32;
    let (w, h) = (image.width() as i32, image.height() as i32);
    let mut pen = left;
    for c in text.chars() {
        let glyph = font
            .glyph_id(c)
            .with_scale_and_position(scale, point(pen as f32, baseline));
        if let Some(outlined) = font.outline_glyph(glyph) {
            let bounds = outlined.px_bounds();
            let (x0, y0) = (bounds.min.x as i32, bounds.min.y as i32);
            outlined.draw(|gx, gy, coverage| {
                let (x, y) = (x0 + gx as i32, y0 + gy as i32);
                if x < 0 || y < 0 || x >= w || y >= h {
                    return;
                }
                let a = coverage.clamp(0.0, 1.0);
                let p = image.get_pixel_mut(x as u32, y as u32);
                for (channel, &ink) in p.0.iter_mut().zip(&color) {
                    *channel = (f32::from(*channel) * (1.0 - a) + f32::from(ink) * a).round() as u8;
                }
            });
        }
        pen += advance;
    }
    pen
}

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
    let size = panel_font_px(h);
    let line_height = size + size / 4;
    let margin = size / 2;
    let box_w = (longest as u32 * cell_width(size) + 2 * margin).min(w);
    let box_h = (lines.len() as u32 * line_height + 2 * margin).min(h);
    for y in 0..box_h {
        for x in 0..box_w {
            let p = image.get_pixel_mut(x, y);
            for c in &mut p.0 {
                *c = (f32::from(*c) * PANEL_SHOW_THROUGH).round() as u8;
            }
        }
    }
    for (i, line) in lines.iter().enumerate() {
        let y = (margin + i as u32 * line_height) as i32;
        draw_text(image, line, (margin as i32, y), size, [255, 255, 255]);
    }
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

    /// The runs of columns of `image` that hold ink (a channel above
    /// half), as `(first, last)` column pairs, left to right.
    fn ink_runs(image: &RgbImage) -> Vec<(u32, u32)> {
        let inked: Vec<bool> = (0..image.width())
            .map(|x| (0..image.height()).any(|y| image.get_pixel(x, y).0[0] > 128))
            .collect();
        let mut runs = Vec::new();
        let mut start = None;
        for (x, &ink) in inked.iter().chain([&false]).enumerate() {
            match (ink, start) {
                (true, None) => start = Some(x as u32),
                (false, Some(s)) => {
                    runs.push((s, x as u32 - 1));
                    start = None;
                }
                _ => {}
            }
        }
        runs
    }

    /// `text` drawn white on black at `size` pixels, from x = 4.
    fn rendered(text: &str, size: u32) -> RgbImage {
        let mut image = RgbImage::new(8 + text.len() as u32 * 2 * size, 2 * size);
        draw_text(&mut image, text, (4, 2), size, [255, 255, 255]);
        image
    }

    #[test]
    fn the_gaps_between_glyphs_are_even() {
        for size in [11, 12, 14, 15, 18] {
            // '0' and '.' are both centred in their cells: the gap from a
            // zero's ink to a dot's equals the gap from the dot's to the
            // next zero's (drawn at their pen positions, the dots sat
            // against the zero before them: "0. 0").
            let runs = ink_runs(&rendered("0.0.0.0", size));
            assert_eq!(runs.len(), 7, "size {size}: {runs:?}");
            let gaps: Vec<i64> = runs
                .windows(2)
                .map(|p| i64::from(p[1].0) - i64::from(p[0].1))
                .collect();
            let (min, max) = (gaps.iter().min().unwrap(), gaps.iter().max().unwrap());
            assert!(max - min <= 1, "size {size}: gaps {gaps:?}");
            // Equal glyphs repeat at exactly one cell.
            let zeros: Vec<u32> = runs.iter().step_by(2).map(|r| r.0).collect();
            let cell = cell_width(size);
            assert!(
                zeros.windows(2).all(|p| p[1] - p[0] == 2 * cell),
                "{zeros:?}"
            );
        }
    }

    #[test]
    fn every_glyph_sits_in_its_own_cell() {
        // The ink of each character lies within its character cell, so no
        // letter leans on its neighbour ("ar ound", "0. 082%").
        for size in [11, 14, 18] {
            let cell = cell_width(size) as i64;
            for text in ["around", "0.082%", "unshot", "il1.,;:"] {
                for (k, c) in text.chars().enumerate() {
                    let image = rendered(&format!("{}{c}", " ".repeat(k)), size);
                    let left = 4 + k as i64 * cell;
                    for (a, b) in ink_runs(&image) {
                        assert!(
                            i64::from(a) >= left - 1 && i64::from(b) < left + cell + 1,
                            "{c:?} of {text:?} at size {size}: ink {a}..{b}, cell {left}..{}",
                            left + cell
                        );
                    }
                    // And it is centred within a pixel or so when symmetric.
                    if ".0o:".contains(c) {
                        let runs = ink_runs(&image);
                        let (a, b) = (runs[0].0 as i64, runs.last().unwrap().1 as i64);
                        let (before, after) = (a - left, left + cell - 1 - b);
                        assert!((before - after).abs() <= 1, "{c:?}: {before} | {after}");
                    }
                }
            }
        }
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
