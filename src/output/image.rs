//! Picture files of a rendered [`Frame`].
//!
//! The format follows the file name's extension (case-insensitive):
//!
//! | extension        | format | contents                                         |
//! |------------------|--------|--------------------------------------------------|
//! | `.png`           | PNG    | 8-bit sRGB, tone-mapped with the given exposure  |
//! | `.tif`, `.tiff`  | TIFF   | 8-bit sRGB, tone-mapped with the given exposure  |
//! | `.exr`           | OpenEXR| 32-bit float linear RGB radiosity, as rendered   |
//! | `.pfm`           | PFM    | 32-bit float linear RGB radiosity, as rendered   |
//! | `.hdr`           | Radiance RGBE | linear RGB radiosity, 8-bit mantissas sharing an exponent |
//!
//! The linear formats ignore the exposure: `.exr` and `.pfm` hold the
//! frame's values bit for bit, in the scene's radiosity units, for later
//! processing; `.hdr` holds them to the precision of its shared exponent
//! (about 1 % of a pixel's largest channel), as Radiance's tools read it.
//!
//! Outputs that are 8-bit only (plots, false colour, mesh lines, the
//! window's pictures) take [`PictureFormat::eight_bit`], whose messages
//! list only the formats they accept.

use super::{write_atomically_seekable, OutputError};
use crate::render::{to_srgb8, Exposure, Frame};
use ::image::{ImageFormat, Rgb32FImage, RgbImage};
use std::io::{Cursor, Seek, Write};
use std::path::Path;

/// The picture extensions [`PictureFormat::from_path`] understands, for
/// messages.
pub const SUPPORTED_EXTENSIONS: &str = ".png, .tif, .tiff, .exr, .pfm, .hdr";

/// The 8-bit picture extensions, for the messages of outputs that take
/// only those ([`PictureFormat::eight_bit`]).
pub const EIGHT_BIT_EXTENSIONS: &str = ".png, .tif or .tiff";

/// A picture file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PictureFormat {
    /// PNG, 8-bit sRGB.
    Png,
    /// TIFF, 8-bit sRGB.
    Tiff,
    /// OpenEXR, 32-bit float linear RGB (uncompressed).
    Exr,
    /// Portable float map, 32-bit float linear RGB, little-endian.
    Pfm,
    /// Radiance RGBE (`.hdr`): linear RGB, an 8-bit mantissa per channel
    /// and one shared exponent, run-length encoded.
    Hdr,
}

impl PictureFormat {
    /// The format named by the path's extension, case-insensitive. A missing
    /// or unknown extension is an error listing [`SUPPORTED_EXTENSIONS`].
    pub fn from_path(path: &Path) -> Result<PictureFormat, OutputError> {
        Self::named(path).map_err(|reason| OutputError::UnknownFormat {
            path: path.to_path_buf(),
            reason: format!("{reason}; supported picture formats are {SUPPORTED_EXTENSIONS}"),
        })
    }

    /// The 8-bit format named by the path's extension, for an output that
    /// writes nothing else; `writer` says which (`--plot writes an 8-bit
    /// picture`), and an unknown extension or a linear format is an error
    /// listing [`EIGHT_BIT_EXTENSIONS`] alone.
    pub fn eight_bit(path: &Path, writer: &str) -> Result<PictureFormat, OutputError> {
        let refuse = |reason: String| OutputError::UnknownFormat {
            path: path.to_path_buf(),
            reason,
        };
        let accepted = format!("{writer}: use {EIGHT_BIT_EXTENSIONS}");
        match Self::named(path) {
            Ok(format) if !format.is_linear() => Ok(format),
            Ok(_) => Err(refuse(accepted)),
            Err(reason) => Err(refuse(format!("{reason}; {accepted}"))),
        }
    }

    /// The format of the path's extension, case-insensitive, or what is
    /// wrong with the extension.
    fn named(path: &Path) -> Result<PictureFormat, String> {
        let ext = path
            .extension()
            .ok_or_else(|| "the file name has no extension".to_string())?;
        match ext.to_string_lossy().to_ascii_lowercase().as_str() {
            "png" => Ok(PictureFormat::Png),
            "tif" | "tiff" => Ok(PictureFormat::Tiff),
            "exr" => Ok(PictureFormat::Exr),
            "pfm" => Ok(PictureFormat::Pfm),
            "hdr" => Ok(PictureFormat::Hdr),
            _ => Err(format!("unknown extension .{}", ext.to_string_lossy())),
        }
    }

    /// True for the formats that store linear values rather than
    /// tone-mapped 8-bit ones.
    pub fn is_linear(self) -> bool {
        matches!(
            self,
            PictureFormat::Exr | PictureFormat::Pfm | PictureFormat::Hdr
        )
    }
}

/// Writes `frame` to `path` in the format its extension names (see the
/// module docs), atomically (see [`write_atomically`](super::write_atomically)).
///
/// `exposure` applies to the 8-bit formats only; the float formats store the
/// linear values exactly.
pub fn write_picture(path: &Path, frame: &Frame, exposure: Exposure) -> Result<(), OutputError> {
    let format = PictureFormat::from_path(path)?;
    if !frame.is_consistent() {
        return Err(OutputError::InvalidFrame {
            path: path.to_path_buf(),
            width: frame.width,
            height: frame.height,
        });
    }
    match format {
        PictureFormat::Png | PictureFormat::Tiff => {
            let img = to_srgb8(frame, exposure.resolve(frame));
            // A pass over every pixel done; the next is the encoder's.
            super::check_cancelled(path)?;
            let kind = if format == PictureFormat::Png {
                ImageFormat::Png
            } else {
                ImageFormat::Tiff
            };
            encode_and_write(path, move |mut w| img.write_to(&mut w, kind))
        }
        PictureFormat::Exr | PictureFormat::Hdr => {
            let raw: Vec<f32> = frame.pixels.iter().flatten().copied().collect();
            let img = Rgb32FImage::from_raw(frame.width, frame.height, raw).ok_or_else(|| {
                OutputError::InvalidFrame {
                    path: path.to_path_buf(),
                    width: frame.width,
                    height: frame.height,
                }
            })?;
            let kind = if format == PictureFormat::Exr {
                ImageFormat::OpenExr
            } else {
                ImageFormat::Hdr
            };
            encode_and_write(path, move |mut w| img.write_to(&mut w, kind))
        }
        PictureFormat::Pfm => write_atomically_seekable(path, |w| {
            write_pfm(w, frame).map_err(|error| OutputError::Io {
                path: path.to_path_buf(),
                error,
            })
        }),
    }
}

/// Encodes a picture through `encode` and writes it to `path` atomically.
///
/// Inside [`cancelling_writes`](super::cancelling_writes) the picture is
/// encoded in memory first, on a thread the interrupt abandons
/// ([`crate::cancel::abandonable`]): an encoder compresses the whole
/// picture before it writes a byte, seconds for a large one, and cannot be
/// asked to stop. The bytes are then written as any file is, checking the
/// token per buffer. Outside, `encode` writes to the temporary directly.
fn encode_and_write<E>(path: &Path, encode: E) -> Result<(), OutputError>
where
    E: FnOnce(&mut dyn WriteSeek) -> ::image::ImageResult<()> + Send + 'static,
{
    let encode_error = |error| OutputError::Encode {
        path: path.to_path_buf(),
        error,
    };
    let io_error = |error| OutputError::Io {
        path: path.to_path_buf(),
        error,
    };
    let Some(cancel) = super::write_cancel() else {
        return write_atomically_seekable(path, |w| encode(w).map_err(encode_error));
    };
    let encoded = crate::cancel::abandonable(&cancel, move || {
        let mut bytes = Cursor::new(Vec::new());
        encode(&mut bytes).map(|()| bytes.into_inner())
    })
    .map_err(|c| io_error(std::io::Error::other(c)))?
    .map_err(encode_error)?;
    write_atomically_seekable(path, |w| w.write_all(&encoded).map_err(io_error))
}

/// What an image encoder writes to: a file or a buffer in memory.
trait WriteSeek: Write + Seek {}

impl<T: Write + Seek> WriteSeek for T {}

/// Writes an 8-bit picture that is already tone-mapped (what a window
/// shows) as PNG or TIFF, chosen by the extension, atomically. The float
/// formats need the linear frame ([`write_picture`]) and are refused here.
pub fn write_rgb8(path: &Path, image: &RgbImage) -> Result<(), OutputError> {
    let kind = match PictureFormat::eight_bit(path, "the picture on screen is 8-bit")? {
        PictureFormat::Png => ImageFormat::Png,
        _ => ImageFormat::Tiff,
    };
    if super::write_cancel().is_none() {
        // Not cancellable: encoded straight from the borrowed picture.
        return write_atomically_seekable(path, |w| {
            image
                .write_to(w, kind)
                .map_err(|error| OutputError::Encode {
                    path: path.to_path_buf(),
                    error,
                })
        });
    }
    let image = image.clone();
    encode_and_write(path, move |mut w| image.write_to(&mut w, kind))
}

/// Writes the portable float map: a text header (`PF` for colour, the size,
/// and a negative scale meaning little-endian), then the rows from the
/// BOTTOM of the picture to the top, each pixel three `f32`s.
fn write_pfm(w: &mut dyn Write, frame: &Frame) -> std::io::Result<()> {
    write!(w, "PF\n{} {}\n-1.0\n", frame.width, frame.height)?;
    let width = frame.width as usize;
    if width == 0 {
        return Ok(());
    }
    for row in frame.pixels.chunks_exact(width).rev() {
        for p in row {
            for c in p {
                w.write_all(&c.to_le_bytes())?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb8_pictures_round_trip_and_float_formats_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut img = RgbImage::new(5, 3);
        img.put_pixel(4, 0, ::image::Rgb([10, 200, 30]));
        for name in ["a.tiff", "a.png"] {
            let path = dir.path().join(name);
            write_rgb8(&path, &img).unwrap();
            assert_eq!(::image::open(&path).unwrap().to_rgb8(), img);
        }
        assert!(matches!(
            write_rgb8(&dir.path().join("a.exr"), &img),
            Err(OutputError::UnknownFormat { .. })
        ));
        assert!(!dir.path().join("a.exr").exists());
    }
    use crate::render::srgb8;
    use std::path::PathBuf;

    /// A 5x3 frame with a distinct value in every channel, some above one,
    /// some tiny, so the row order and exact bits are checked.
    fn frame() -> Frame {
        let mut f = Frame::new(5, 3);
        for (i, p) in f.pixels.iter_mut().enumerate() {
            let i = i as f32;
            *p = [i * 0.1, 1.0 / (i + 3.0), (i * 0.37).sin().abs() * 3.0];
        }
        f.pixels[0] = [1e-7, 0.0, 123.456];
        f.covered.fill(true);
        f
    }

    fn only_file(dir: &Path) -> PathBuf {
        let v: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(v.len(), 1, "{v:?}");
        v[0].clone()
    }

    #[test]
    fn formats_from_extensions() {
        let f = |p: &str| PictureFormat::from_path(Path::new(p)).ok();
        assert_eq!(f("a.png"), Some(PictureFormat::Png));
        assert_eq!(f("dir.x/a.PNG"), Some(PictureFormat::Png));
        assert_eq!(f("a.tif"), Some(PictureFormat::Tiff));
        assert_eq!(f("a.TiFF"), Some(PictureFormat::Tiff));
        assert_eq!(f("a.exr"), Some(PictureFormat::Exr));
        assert_eq!(f("a.Pfm"), Some(PictureFormat::Pfm));
        assert_eq!(f("a.hdr"), Some(PictureFormat::Hdr));
        assert_eq!(f("a.jpg"), None);
        assert_eq!(f("png"), None);
    }

    #[test]
    fn unknown_extension_names_the_supported_ones() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["out.jpg", "out"] {
            let path = dir.path().join(name);
            let err = write_picture(&path, &frame(), Exposure::Auto).unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, OutputError::UnknownFormat { .. }));
            assert!(
                msg.contains(name) && msg.contains(SUPPORTED_EXTENSIONS),
                "{msg}"
            );
        }
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    /// An 8-bit-only output names the formats it takes and no other,
    /// whether the extension is unknown or linear.
    #[test]
    fn eight_bit_outputs_list_only_the_8_bit_formats() {
        let f = |p: &str| PictureFormat::eight_bit(Path::new(p), "--plot writes an 8-bit picture");
        assert_eq!(f("a.PNG").ok(), Some(PictureFormat::Png));
        assert_eq!(f("a.tif").ok(), Some(PictureFormat::Tiff));
        for (name, why) in [
            ("a.exr", ""),
            ("a.hdr", ""),
            ("a.pfm", ""),
            ("a.jpg", "unknown extension .jpg; "),
            ("a", "the file name has no extension; "),
        ] {
            let Err(OutputError::UnknownFormat { reason, .. }) = f(name) else {
                panic!("{name} accepted");
            };
            assert_eq!(
                reason,
                format!("{why}--plot writes an 8-bit picture: use .png, .tif or .tiff")
            );
        }
    }

    /// `.hdr` holds the linear values to RGBE's precision: each channel
    /// within one unit of the 8-bit mantissa that the pixel's largest
    /// channel sets (half a unit of rounding, at most a 128th of it).
    #[test]
    fn hdr_holds_the_linear_values_to_rgbe_precision() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.HDR");
        let f = frame();
        write_picture(&path, &f, Exposure::Fixed(7.0)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"#?RADIANCE\n"));
        let img = ::image::open(&path).unwrap().into_rgb32f();
        assert_eq!(img.dimensions(), (5, 3));
        for (got, want) in img.pixels().zip(&f.pixels) {
            let largest = want.iter().copied().fold(0.0f32, f32::max);
            for (g, w) in got.0.iter().zip(want) {
                assert!((g - w).abs() <= largest / 128.0, "{got:?} for {want:?}");
            }
        }
    }

    #[test]
    fn png_holds_the_tone_mapped_frame_top_row_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        let f = frame();
        write_picture(&path, &f, Exposure::Fixed(0.5)).unwrap();
        assert_eq!(only_file(dir.path()), path);
        let img = ::image::open(&path).unwrap().into_rgb8();
        assert_eq!(img, to_srgb8(&f, 0.5));
        // Top-left pixel of the file is the frame's pixel 0.
        let p = f.pixels[0];
        assert_eq!(
            img.get_pixel(0, 0).0,
            [srgb8(p[0], 0.5), srgb8(p[1], 0.5), srgb8(p[2], 0.5)]
        );
    }

    #[test]
    fn tiff_holds_the_tone_mapped_frame() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.TIF");
        let f = frame();
        write_picture(&path, &f, Exposure::Auto).unwrap();
        let img = ::image::open(&path).unwrap().into_rgb8();
        assert_eq!(img, to_srgb8(&f, Exposure::Auto.resolve(&f)));
    }

    #[test]
    fn exr_holds_the_linear_values_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.exr");
        let f = frame();
        write_picture(&path, &f, Exposure::Fixed(7.0)).unwrap();
        let img = ::image::open(&path).unwrap().into_rgb32f();
        assert_eq!(img.dimensions(), (5, 3));
        for (got, want) in img.pixels().zip(&f.pixels) {
            assert_eq!(got.0.map(f32::to_bits), want.map(f32::to_bits));
        }
    }

    #[test]
    fn pfm_holds_the_linear_values_bottom_row_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.pfm");
        let f = frame();
        write_picture(&path, &f, Exposure::Auto).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let header = b"PF\n5 3\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(floats.len(), 5 * 3 * 3);
        for (k, px) in floats.chunks_exact(3).enumerate() {
            let (file_row, x) = (k / 5, k % 5);
            let y = 2 - file_row;
            let want = f.pixels[y * 5 + x];
            assert_eq!(
                [px[0], px[1], px[2]].map(f32::to_bits),
                want.map(f32::to_bits)
            );
        }
    }

    #[test]
    fn missing_directory_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("absent").join("out.png");
        let err = write_picture(&path, &frame(), Exposure::Auto).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    #[test]
    fn inconsistent_frame_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = frame();
        f.pixels.pop();
        for name in ["a.png", "a.exr", "a.pfm"] {
            let err = write_picture(&dir.path().join(name), &f, Exposure::Auto).unwrap_err();
            assert!(matches!(err, OutputError::InvalidFrame { .. }), "{err}");
        }
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }
}
