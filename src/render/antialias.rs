//! Antialiased pictures: a picture rendered at `n × n` samples a pixel
//! and averaged back to its size, so polygon edges are not stair-stepped.
//!
//! Each sample is a pixel centre of the `n`-times larger picture, so the
//! samples of one output pixel form a regular `n × n` grid inside it; the
//! output pixel is their plain mean (a box filter), in linear radiosity.
//! So a high-dynamic-range picture (`.exr`, `.pfm`) keeps exact linear
//! values, averaged; 8-bit pictures are tone-mapped after averaging. A
//! pixel counts as covered when any of its samples is, and its back-face
//! fraction ([`Frame::back`]) is the fraction of its samples on back faces.

use super::raster::{Frame, Rasterizer, RenderError};
use super::view::{View, ViewError};
use crate::camera::Camera;
use crate::cancel::Cancel;
use crate::color::Rgb;
use crate::mesh::Mesh;

/// Why [`draw`] could not make its picture.
#[derive(Debug, thiserror::Error)]
pub enum DrawError {
    /// The camera, or the sampled picture's size, is unusable.
    #[error("{0}")]
    View(#[from] ViewError),
    /// Rendering failed or was cancelled.
    #[error("{0}")]
    Render(#[from] RenderError),
}

/// A picture [`draw`] made: its samples are in the rasterizer.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// Samples a pixel along each side actually used ([`factor_for`]).
    pub aa: u32,
    /// The sampled frame averaged to the camera's size; `None` when `aa`
    /// is 1 (the rasterizer's frame is the picture).
    pub downsampled: Option<Frame>,
}

impl Drawn {
    /// The picture's linear frame at the camera's size, from the
    /// `rasterizer` that drew it.
    pub fn frame<'a>(&'a self, rasterizer: &'a Rasterizer) -> &'a Frame {
        self.downsampled.as_ref().unwrap_or(rasterizer.frame())
    }
}

/// Draws `radiosity` (per vertex of `mesh`) through `camera` at its
/// picture size with `aa × aa` samples a pixel (fewer for a very large
/// picture, [`factor_for`]), averaged in linear radiosity: the one way
/// antialiased pictures are made, by the batch run and by the window's
/// full-quality key. The samples stay in `rasterizer` (its depths and
/// front faces at the sampled size); stops with
/// [`RenderError::Cancelled`] once `cancel` is set.
pub fn draw(
    rasterizer: &mut Rasterizer,
    mesh: &Mesh,
    radiosity: &[Rgb],
    camera: &Camera,
    aa: u32,
    cancel: &Cancel,
) -> Result<Drawn, DrawError> {
    let (width, height) = (camera.width, camera.height);
    let aa = factor_for(width, height, aa);
    let view = View::with_size(camera, width * aa, height * aa)?;
    rasterizer.render_cancellable(mesh, radiosity, &view, cancel)?;
    cancel.check().map_err(RenderError::Cancelled)?;
    let downsampled = (aa > 1).then(|| downsample(rasterizer.frame(), aa));
    Ok(Drawn { aa, downsampled })
}

/// Default samples per pixel side for written pictures (`--aa`): 9 samples
/// a pixel make edges smooth; `table_chair`'s picture (30,000 triangles)
/// then renders in 0.16 s instead of 0.02 s (2 cores). The window draws
/// one sample a pixel.
pub const DEFAULT_AA: u32 = 3;

/// Most samples per pixel side `--aa` accepts.
pub const MAX_AA: u32 = 8;

/// Most samples a supersampled picture may have (about 1.5 GB of buffers
/// at 24 bytes a sample): a larger picture is rendered with fewer samples
/// a pixel ([`factor_for`]).
pub const MAX_SAMPLES: u64 = 64 << 20;

/// The samples per pixel side to use for a `width × height` picture when
/// `n` are asked for: `n`, or the largest factor below it whose picture
/// stays within [`MAX_SAMPLES`] (at least 1).
pub fn factor_for(width: u32, height: u32, n: u32) -> u32 {
    let pixels = u64::from(width) * u64::from(height);
    let mut f = n.max(1);
    while f > 1 && pixels * u64::from(f) * u64::from(f) > MAX_SAMPLES {
        f -= 1;
    }
    f
}

/// The `width × height` picture whose pixels are the means of the `n × n`
/// blocks of `frame` (which must be `n · width × n · height`).
pub fn downsample(frame: &Frame, n: u32) -> Frame {
    assert!(n >= 1 && frame.width.is_multiple_of(n) && frame.height.is_multiple_of(n));
    let (w, h) = (frame.width / n, frame.height / n);
    let mut out = Frame::new(w, h);
    let scale = 1.0 / f64::from(n * n);
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f64; 3];
            let mut back = 0.0f64;
            let mut covered = false;
            for sy in 0..n {
                let row = ((y * n + sy) * frame.width + x * n) as usize;
                for k in row..row + n as usize {
                    let p = frame.pixels[k];
                    for c in 0..3 {
                        sum[c] += f64::from(p[c]);
                    }
                    covered |= frame.covered[k];
                    back += f64::from(frame.back[k]);
                }
            }
            let k = (y * w + x) as usize;
            out.pixels[k] = sum.map(|s| (s * scale) as f32);
            out.covered[k] = covered;
            out.back[k] = (back * scale) as f32;
        }
    }
    out
}

/// Per pixel of the downsampled picture, the nearest surface's `1 / z`
/// among its samples (the largest; 0 where none was drawn), from the
/// supersampled picture's `inv_depth` of width `width`: what overlays
/// drawn at the output size test their depth against.
pub fn nearest_depth(inv_depth: &[f64], width: u32, n: u32) -> Vec<f64> {
    let height = inv_depth.len() as u32 / width.max(1);
    let (w, h) = (width / n, height / n);
    let mut out = vec![0.0; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let mut best = 0.0f64;
            for sy in 0..n {
                let row = ((y * n + sy) * width + x * n) as usize;
                for &d in &inv_depth[row..row + n as usize] {
                    best = best.max(d);
                }
            }
            out[(y * w + x) as usize] = best;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::mesh::{self, MeshOptions};
    use crate::render::{Rasterizer, View};
    use crate::testutil::{grey, polygon, scene};

    #[test]
    fn downsampling_averages_each_block_exactly() {
        let mut f = Frame::new(4, 2);
        for (k, p) in f.pixels.iter_mut().enumerate() {
            *p = [k as f32, 2.0 * k as f32, 0.5];
        }
        f.covered[5] = true;
        let d = downsample(&f, 2);
        assert_eq!((d.width, d.height), (2, 1));
        // Block of pixels 0, 1, 4, 5 and block 2, 3, 6, 7.
        assert_eq!(d.pixels[0], [2.5, 5.0, 0.5]);
        assert_eq!(d.pixels[1], [4.5, 9.0, 0.5]);
        assert_eq!(d.covered, vec![true, false]);
        let depth = nearest_depth(&[0.0, 0.5, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0], 4, 2);
        assert_eq!(depth, vec![0.5, 0.0]);
    }

    #[test]
    fn the_factor_shrinks_only_for_huge_pictures() {
        assert_eq!(factor_for(640, 480, 3), 3);
        assert_eq!(factor_for(640, 480, 8), 8);
        assert_eq!(factor_for(8192, 8192, 3), 1);
        assert_eq!(factor_for(4096, 4096, 3), 2);
        assert_eq!(factor_for(2048, 2048, 8), 4);
        assert_eq!(factor_for(10, 10, 0), 1);
    }

    /// A lit square tilted in the picture: with one sample a pixel its
    /// edge pixels are either lit or black; with 3 × 3 some are between,
    /// and the picture's total light is that of many more samples.
    #[test]
    fn edges_get_intermediate_values_and_the_light_is_kept() {
        let square = polygon(
            0,
            &[
                [0.1, 0.3, 0.0],
                [0.7, 0.1, 0.0],
                [0.9, 0.7, 0.0],
                [0.3, 0.9, 0.0],
            ],
        );
        let s = scene(vec![square], vec![grey("lit", 1.0, 0.0)]);
        let m = mesh::build(
            &s,
            &MeshOptions {
                lenmax: 1.0,
                inset: mesh::DEFAULT_INSET,
            },
        )
        .unwrap();
        let radiosity = vec![Rgb::splat(1.0); m.vertex_count()];
        let picture = |n: u32| {
            let view = View::with_size(&s.camera, 64 * n, 48 * n).unwrap();
            let mut r = Rasterizer::new();
            let frame = r.render(&m, &radiosity, &view).unwrap().clone();
            downsample(&frame, n)
        };
        let (one, three) = (picture(1), picture(3));
        let between = |f: &Frame| {
            f.pixels
                .iter()
                .filter(|p| p[0] > 0.01 && p[0] < 0.99)
                .count()
        };
        assert_eq!(between(&one), 0);
        assert!(between(&three) > 10, "{} edge pixels", between(&three));
        let total = |f: &Frame| f.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>();
        // The square's light converges with the samples: 3 × 3 is within
        // 2 % of 8 × 8 (1 × 1 was 10 % off here, 28 pixel centres of 31).
        let (a, b) = (total(&three), total(&picture(8)));
        assert!((a - b).abs() < 0.02 * b, "{a} against {b}");
        // Full values stay exact: a pixel whose samples are all lit is 1.
        assert!(three.pixels.iter().any(|p| p[0] == 1.0));
    }
}
