//! Two pictures of one view compared as the browser and Blender checks
//! compare them: over 4 × 4-pixel blocks, in linear light.

/// Mean absolute difference of 4 × 4-pixel block means over the blocks
/// either picture lights, relative to the first picture's mean there, in
/// linear light (sRGB codes decoded), the three channels together.
/// Pixels past the last whole block are left out.
pub fn block_error(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let linear = |code: u8| {
        let e = f64::from(code) / 255.0;
        if e <= 0.04045 {
            e / 12.92
        } else {
            ((e + 0.055) / 1.055).powf(2.4)
        }
    };
    let (w, h) = a.dimensions();
    let (mut diff, mut sum) = (0.0, 0.0);
    for by in 0..h / 4 {
        for bx in 0..w / 4 {
            let mut block = [0.0f64; 2];
            for (k, picture) in [a, b].into_iter().enumerate() {
                for y in by * 4..by * 4 + 4 {
                    for x in bx * 4..bx * 4 + 4 {
                        block[k] += picture
                            .get_pixel(x, y)
                            .0
                            .iter()
                            .map(|&c| linear(c))
                            .sum::<f64>();
                    }
                }
            }
            diff += (block[0] - block[1]).abs();
            sum += block[0];
        }
    }
    diff / sum
}

/// The largest relative block error accepted between the program's
/// picture and a viewer's of the same file and view. Two rasterisers
/// differ only at polygon edges (which pixel an edge's centre falls in)
/// and in rounding; a picture upside down, mirrored, shifted by a pixel or
/// exposed differently is well over it (tests/browser.rs checks that).
pub const MAX_BLOCK_ERROR: f64 = 0.01;

/// The Cornell box's own camera (`scenes/cornell.sc`) at 320 × 240, as
/// the program's options (`render.mjs` and the Blender script take the
/// same).
pub const CORNELL_VIEW: [&str; 10] = [
    "--eye",
    "278,273,-800",
    "--look-at",
    "278,273,0",
    "--up",
    "0,1,0",
    "--fov",
    "39.31",
    "--size",
    "320x240",
];

/// The round table's own camera (`scenes/rtable.sc`) at 320 × 240.
pub const RTABLE_VIEW: [&str; 10] = [
    "--eye",
    "2.5,1.7,0.35",
    "--look-at",
    "2.5,0.75,3",
    "--up",
    "0,1,0",
    "--fov",
    "55",
    "--size",
    "320x240",
];
