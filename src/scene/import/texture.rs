//! The average colour of a texture within the memory budget: what an
//! OBJ `map_Kd` or a glTF base-colour texture contributes to its
//! material's reflectance.
//!
//! A texture is a small file that can decode to gigabytes (a 48 kB PNG of
//! 20000 × 20000 one-bit pixels is 1.2 GB as 8-bit RGB), so nothing here
//! holds more than one copy of an image in its own pixel format, and
//! never converts a whole image to floats:
//!
//! - a PNG is decoded row by row with the `png` crate's streaming reader,
//!   so its average costs one row of memory whatever its size;
//! - any other format's size is read from its header first, and refused
//!   when its decoded pixels would be over the budget (or over
//!   [`MAX_SIDE`] a side); it is then decoded in its own format, with
//!   `image::Limits` set to the same bound, and averaged from that buffer.
//!
//! 8- and 16-bit values are sRGB-decoded through a lookup table (a
//! `powf` per channel of 400 million pixels would take seconds); float
//! images are linear already. Alpha is ignored.

use crate::budget::{fmt_bytes, MemoryBudget};
use crate::color::Rgb;
use std::io::{BufRead, Cursor, Seek};
use std::sync::OnceLock;

/// The largest side of a texture decoded whole (not a PNG), in pixels:
/// enough for any real texture (16k × 16k).
pub const MAX_SIDE: u32 = 16_384;

/// The most bytes a texture decoded whole may take, whatever the budget:
/// 1 GiB (a 16k × 16k RGBA image of 8 bits is 1 GiB).
pub const MAX_DECODED_BYTES: u64 = 1 << 30;

/// The average colour of the encoded image `bytes`, in linear values, each
/// channel in `[0, 1]`. The format is found from the bytes, else it is
/// `hint` (the file name's extension: TGA has no magic bytes).
pub fn average_bytes(
    bytes: &[u8],
    hint: Option<image::ImageFormat>,
    budget: &MemoryBudget,
) -> Result<Rgb, String> {
    let reader = reader(bytes, hint)?;
    if reader.format() == Some(image::ImageFormat::Png) {
        return average_png(Cursor::new(bytes));
    }
    average_whole(bytes, hint, budget)
}

/// A reader of `bytes` in the format they show, else `hint`.
fn reader(
    bytes: &[u8],
    hint: Option<image::ImageFormat>,
) -> Result<image::ImageReader<Cursor<&[u8]>>, String> {
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    if reader.format().is_none() {
        if let Some(format) = hint {
            reader.set_format(format);
        }
    }
    Ok(reader)
}

/// A non-PNG image decoded whole in its own pixel format, after its
/// header's size was checked against the budget.
fn average_whole(
    bytes: &[u8],
    hint: Option<image::ImageFormat>,
    budget: &MemoryBudget,
) -> Result<Rgb, String> {
    let guess = || reader(bytes, hint);
    let (w, h) = guess()?.into_dimensions().map_err(|e| e.to_string())?;
    let limit = MAX_DECODED_BYTES.min(budget.bytes() / 2);
    // Up to 16 bytes a pixel (RGBA of 32-bit floats) in the decoded buffer.
    let need = u64::from(w) * u64::from(h) * 16;
    if w > MAX_SIDE || h > MAX_SIDE || need > limit {
        return Err(format!(
            "the image is {w} × {h} pixels, up to {} decoded; textures other than PNG are \
             decoded whole, at most {MAX_SIDE} pixels a side and {}",
            fmt_bytes(need),
            fmt_bytes(limit)
        ));
    }
    let mut reader = guess()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(limit);
    reader.limits(limits);
    let image = reader.decode().map_err(|e| e.to_string())?;
    average_image(&image)
}

/// The average colour of a decoded image, from its own buffer.
pub fn average_image(image: &image::DynamicImage) -> Result<Rgb, String> {
    use image::DynamicImage as D;
    let mut sum = Sum::default();
    match image {
        D::ImageLuma8(i) => sum.grey8(i.as_raw(), 1),
        D::ImageLumaA8(i) => sum.grey8(i.as_raw(), 2),
        D::ImageRgb8(i) => sum.rgb8(i.as_raw(), 3),
        D::ImageRgba8(i) => sum.rgb8(i.as_raw(), 4),
        D::ImageLuma16(i) => sum.grey16(i.as_raw(), 1),
        D::ImageLumaA16(i) => sum.grey16(i.as_raw(), 2),
        D::ImageRgb16(i) => sum.rgb16(i.as_raw(), 3),
        D::ImageRgba16(i) => sum.rgb16(i.as_raw(), 4),
        D::ImageRgb32F(i) => sum.rgb32f(i.as_raw(), 3),
        D::ImageRgba32F(i) => sum.rgb32f(i.as_raw(), 4),
        // A format added to `image` later: converted, as it must be rare.
        other => sum.rgb32f(other.to_rgb32f().as_raw(), 3),
    }
    sum.mean()
}

/// A PNG's average, decoded one row at a time.
fn average_png<R: BufRead + Seek>(source: R) -> Result<Rgb, String> {
    let mut decoder = png::Decoder::new(source);
    // Palettes to RGB, bit depths below 8 to 8, transparency to alpha;
    // 16-bit samples stay 16-bit.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let (color, depth) = reader.output_color_type();
    let channels = color.samples();
    let mut sum = Sum::default();
    while let Some(row) = reader.next_row().map_err(|e| e.to_string())? {
        let data = row.data();
        let grey = matches!(
            color,
            png::ColorType::Grayscale | png::ColorType::GrayscaleAlpha
        );
        match (depth, grey) {
            (png::BitDepth::Sixteen, true) => sum.grey16_be(data, channels),
            (png::BitDepth::Sixteen, false) => sum.rgb16_be(data, channels),
            (_, true) => sum.grey8(data, channels),
            (_, false) => sum.rgb8(data, channels),
        }
    }
    sum.mean()
}

/// A running sum of linear colours.
#[derive(Default)]
struct Sum {
    rgb: [f64; 3],
    pixels: u64,
}

impl Sum {
    fn grey8(&mut self, data: &[u8], stride: usize) {
        let t = table8();
        let mut s = 0.0;
        for p in data.chunks_exact(stride) {
            s += t[usize::from(p[0])];
        }
        self.add_grey(s, data.len() / stride);
    }

    fn rgb8(&mut self, data: &[u8], stride: usize) {
        let t = table8();
        for p in data.chunks_exact(stride) {
            for c in 0..3 {
                self.rgb[c] += t[usize::from(p[c])];
            }
        }
        self.pixels += (data.len() / stride) as u64;
    }

    fn grey16(&mut self, data: &[u16], stride: usize) {
        let t = table16();
        let s: f64 = data
            .chunks_exact(stride)
            .map(|p| t[usize::from(p[0])])
            .sum();
        self.add_grey(s, data.len() / stride);
    }

    fn rgb16(&mut self, data: &[u16], stride: usize) {
        let t = table16();
        for p in data.chunks_exact(stride) {
            for c in 0..3 {
                self.rgb[c] += t[usize::from(p[c])];
            }
        }
        self.pixels += (data.len() / stride) as u64;
    }

    /// 16-bit samples as a PNG row holds them: big-endian byte pairs.
    fn grey16_be(&mut self, data: &[u8], stride: usize) {
        let t = table16();
        let s: f64 = data
            .chunks_exact(2 * stride)
            .map(|p| t[usize::from(u16::from_be_bytes([p[0], p[1]]))])
            .sum();
        self.add_grey(s, data.len() / (2 * stride));
    }

    fn rgb16_be(&mut self, data: &[u8], stride: usize) {
        let t = table16();
        for p in data.chunks_exact(2 * stride) {
            for (sum, v) in self.rgb.iter_mut().zip(p.chunks_exact(2)) {
                *sum += t[usize::from(u16::from_be_bytes([v[0], v[1]]))];
            }
        }
        self.pixels += (data.len() / (2 * stride)) as u64;
    }

    /// Float samples: linear already, clamped to `[0, 1]`.
    fn rgb32f(&mut self, data: &[f32], stride: usize) {
        for p in data.chunks_exact(stride) {
            for (sum, &v) in self.rgb.iter_mut().zip(p) {
                *sum += f64::from(v).clamp(0.0, 1.0);
            }
        }
        self.pixels += (data.len() / stride) as u64;
    }

    fn add_grey(&mut self, s: f64, pixels: usize) {
        for c in &mut self.rgb {
            *c += s;
        }
        self.pixels += pixels as u64;
    }

    fn mean(&self) -> Result<Rgb, String> {
        if self.pixels == 0 {
            return Err("the image has no pixels".to_string());
        }
        let [r, g, b] = self.rgb.map(|s| (s / self.pixels as f64).clamp(0.0, 1.0));
        Ok(Rgb::new(r, g, b))
    }
}

/// Linear values of the 256 sRGB-encoded 8-bit values.
fn table8() -> &'static [f64; 256] {
    static T: OnceLock<[f64; 256]> = OnceLock::new();
    T.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f64 / 255.0)))
}

/// Linear values of the 65,536 sRGB-encoded 16-bit values.
fn table16() -> &'static [f64] {
    static T: OnceLock<Vec<f64>> = OnceLock::new();
    T.get_or_init(|| {
        (0..=u16::MAX)
            .map(|i| srgb_to_linear(f64::from(i) / 65535.0))
            .collect()
    })
}

/// The sRGB transfer function undone: an encoded value in `[0, 1]` to
/// linear light in `[0, 1]` (IEC 61966-2-1).
pub(crate) fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PNG bytes of a `w` × `h` one-bit grey image, white where
    /// `white(row)` holds and black elsewhere, compressed at best: a
    /// 20000 × 20000 one is tens of kB.
    pub(crate) fn one_bit_png(w: u32, h: u32, white: impl Fn(u32) -> bool) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(Cursor::new(&mut out), w, h);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::One);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().unwrap();
        let mut stream = writer.stream_writer().unwrap();
        let row_bytes = w.div_ceil(8) as usize;
        let (ones, zeros) = (vec![0xffu8; row_bytes], vec![0u8; row_bytes]);
        for y in 0..h {
            use std::io::Write;
            stream
                .write_all(if white(y) { &ones } else { &zeros })
                .unwrap();
        }
        stream.finish().unwrap();
        drop(writer);
        out
    }

    #[test]
    fn a_png_bomb_is_averaged_row_by_row() {
        // Half its rows white: 1.2 GB as 8-bit RGB, 4.8 GB as floats.
        let bytes = one_bit_png(20_000, 20_000, |y| y % 2 == 0);
        assert!(bytes.len() < 200_000, "{} bytes", bytes.len());
        let avg = average_bytes(&bytes, None, &MemoryBudget::new(100_000_000)).unwrap();
        for c in avg.to_array() {
            assert!((c - 0.5).abs() < 1e-12, "{avg:?}");
        }
    }

    #[test]
    fn the_average_is_of_linear_values() {
        // Two pixels: sRGB 255 and 0 average to 0.5 in linear light; a
        // grey of sRGB 188 is linear 0.5029.
        let mut img = image::RgbImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgb([255, 255, 255]));
        let mut png = Vec::new();
        image::DynamicImage::ImageRgb8(img)
            .write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let avg = average_bytes(&png, None, &MemoryBudget::UNLIMITED).unwrap();
        assert!((avg.r - 0.5).abs() < 1e-12, "{avg:?}");
        let grey = image::DynamicImage::ImageRgb16(image::ImageBuffer::from_pixel(
            3,
            1,
            image::Rgb([188 * 257u16; 3]),
        ));
        let mut tiff = Vec::new();
        grey.write_to(&mut Cursor::new(&mut tiff), image::ImageFormat::Tiff)
            .unwrap();
        let avg = average_bytes(&tiff, None, &MemoryBudget::UNLIMITED).unwrap();
        assert!(
            (avg.g - srgb_to_linear(188.0 / 255.0)).abs() < 1e-9,
            "{avg:?}"
        );
    }

    /// A TGA has no magic bytes: its format comes from the file name's
    /// extension, given as the hint.
    #[test]
    fn a_tga_is_read_by_its_extension() {
        let grey =
            image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(4, 2, image::Rgb([188; 3])));
        let mut tga = Vec::new();
        grey.write_to(&mut Cursor::new(&mut tga), image::ImageFormat::Tga)
            .unwrap();
        let hint = image::ImageFormat::from_path("wood.tga").ok();
        let avg = average_bytes(&tga, hint, &MemoryBudget::UNLIMITED).unwrap();
        assert!(
            (avg.r - srgb_to_linear(188.0 / 255.0)).abs() < 1e-9,
            "{avg:?}"
        );
    }

    #[test]
    fn an_image_too_large_to_decode_whole_is_refused_from_its_header() {
        // A BMP header claiming 20000 × 20000 pixels, with no pixels.
        let mut bmp = Vec::new();
        let (w, h) = (20_000i32, 20_000i32);
        bmp.extend_from_slice(b"BM");
        bmp.extend_from_slice(&(54u32).to_le_bytes());
        bmp.extend_from_slice(&[0; 4]);
        bmp.extend_from_slice(&(54u32).to_le_bytes());
        bmp.extend_from_slice(&(40u32).to_le_bytes());
        bmp.extend_from_slice(&w.to_le_bytes());
        bmp.extend_from_slice(&h.to_le_bytes());
        bmp.extend_from_slice(&1u16.to_le_bytes());
        bmp.extend_from_slice(&24u16.to_le_bytes());
        bmp.extend_from_slice(&[0; 24]);
        let e = average_bytes(&bmp, None, &MemoryBudget::UNLIMITED).unwrap_err();
        assert!(e.starts_with("the image is 20000 × 20000 pixels"), "{e}");
    }
}
