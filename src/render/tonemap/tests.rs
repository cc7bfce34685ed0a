//! Tone mapping: the sRGB curve and its lookup table, automatic exposure,
//! and back faces painted in stripes.

use super::*;

/// Tolerance of exposure comparisons, relative.
const EXPOSURE_TOLERANCE: f32 = 1e-6;

fn frame(values: &[f32], covered: &[bool]) -> Frame {
    let mut f = Frame::new(values.len() as u32, 1);
    for (i, (&v, &c)) in values.iter().zip(covered).enumerate() {
        f.pixels[i] = [v; 3];
        f.covered[i] = c;
    }
    f
}

#[test]
fn srgb_known_values() {
    assert_eq!(srgb8(0.0, 1.0), 0);
    assert_eq!(srgb8(1.0, 1.0), 255);
    assert_eq!(srgb8(0.5, 1.0), 188);
    assert_eq!(srgb8(2.0, 1.0), 255);
    assert_eq!(srgb8(-1.0, 1.0), 0);
    assert_eq!(srgb8(f32::NAN, 1.0), 0);
    assert_eq!(srgb8(0.25, 2.0), 188);
    // At the joint both pieces give 0.0404500..., i.e. code 10.
    let linear = 12.92 * SRGB_LINEAR_LIMIT;
    let curved = 1.055 * SRGB_LINEAR_LIMIT.powf(1.0 / 2.4) - 0.055;
    assert!((linear - curved).abs() < 1e-7);
    assert_eq!(srgb_encode(SRGB_LINEAR_LIMIT), linear);
    assert_eq!(srgb8(SRGB_LINEAR_LIMIT as f32, 1.0), 10);
    assert_eq!(srgb8(0.001, 1.0), 3); // 12.92e-3 * 255 = 3.29
}

#[test]
fn auto_exposure_of_uniform_frame() {
    let f = frame(&[2.0; 10], &[true; 10]);
    let k = auto_exposure(&f);
    assert!((k - 0.45).abs() < EXPOSURE_TOLERANCE * 0.45, "{k}");
    assert_eq!(Exposure::Auto.resolve(&f), k);
    assert_eq!(Exposure::Fixed(3.0).resolve(&f), 3.0);
    // Stops count from the automatic exposure, as the window's +/- and
    // pfilt -e +2 do: 0 is automatic, +1 twice as bright, -2 a quarter.
    assert_eq!(Exposure::Stops(0.0).resolve(&f), k);
    assert_eq!(Exposure::Stops(1.0).resolve(&f), 2.0 * k);
    assert_eq!(Exposure::Stops(-2.0).resolve(&f), 0.25 * k);
    assert_eq!(Exposure::Stops(-2.0).stops(k), -2.0);
    assert_eq!(Exposure::Fixed(4.0 * k).stops(k), 2.0);
    assert_eq!(Exposure::Auto.stops(k), 0.0);
}

#[test]
fn auto_exposure_ignores_uncovered_and_the_brightest() {
    // 20 covered pixels: 19 at 1.0, one light at 100; 95% rank is a 1.0.
    let mut values = vec![1.0; 20];
    values[7] = 100.0;
    values.push(50.0);
    let mut covered = vec![true; 20];
    covered.push(false);
    let k = auto_exposure(&frame(&values, &covered));
    assert!((k - 0.9).abs() < EXPOSURE_TOLERANCE, "{k}");
}

#[test]
fn dark_frames_do_not_give_nan() {
    let black = frame(&[0.0; 4], &[true; 4]);
    assert_eq!(auto_exposure(&black), FALLBACK_EXPOSURE);
    let empty = frame(&[0.0; 4], &[false; 4]);
    assert_eq!(auto_exposure(&empty), FALLBACK_EXPOSURE);
    assert_eq!(auto_exposure(&Frame::new(0, 0)), FALLBACK_EXPOSURE);
    // Mostly black with one lit pixel: the lit one sets the exposure.
    let mut values = vec![0.0; 100];
    values[3] = 3.0;
    let k = auto_exposure(&frame(&values, &[true; 100]));
    assert!((k - 0.3).abs() < EXPOSURE_TOLERANCE, "{k}");
    let img = to_srgb8(&black, auto_exposure(&black));
    assert!(img.pixels().all(|p| p.0 == [0, 0, 0]));
}

#[test]
fn bucketed_selection_matches_sorting() {
    // Spread over many octaves, with repeats, zeros of both signs and
    // negatives, so ranks fall in crowded and in sparse buckets.
    let values: Vec<f64> = (0..5000u64)
        .map(|k| {
            let x = (k.wrapping_mul(2_654_435_761) % 10_007) as f64;
            match k % 5 {
                0 => x * 1e-3,
                1 => (x / 97.0).exp2(),
                2 => 0.0,
                3 => -x,
                _ => 1.5,
            }
        })
        .chain([-0.0])
        .collect();
    let mut sorted = values.clone();
    sorted.sort_by(f64::total_cmp);
    for rank in (0..values.len()).step_by(37).chain([values.len() - 1]) {
        let got = nth_smallest(
            || values.par_iter().copied(),
            |n| {
                assert_eq!(n, values.len());
                rank
            },
        );
        assert_eq!(
            got.map(f64::to_bits),
            Some(sorted[rank].to_bits()),
            "rank {rank}"
        );
    }
    assert_eq!(nth_smallest(|| values.par_iter().copied(), |n| n), None);
    assert_eq!(nth_smallest(|| [].par_iter().copied(), |_| 0), None);
}

#[test]
fn the_lookup_table_gives_the_curve_bits() {
    let table = Srgb8Table::get();
    // At most one step per bucket, and each step exactly where the
    // curve's code changes.
    for (i, (&b, &at)) in table.base.iter().zip(&table.step).enumerate() {
        let last = f64::from_bits(((i + 1) as f64 / TABLE_BUCKETS as f64).to_bits() - 1);
        assert!(u16::from(code(last)) <= u16::from(b) + 1, "bucket {i}");
        if at.is_finite() {
            assert_eq!(code(at), b + 1, "bucket {i}");
            assert_eq!(code(f64::from_bits(at.to_bits() - 1)), b, "bucket {i}");
        }
    }
    // Every 997th float from 0 to past 1, and the values around each
    // step, under a few exposures.
    let mut values: Vec<f32> = (0..=1.5f32.to_bits())
        .step_by(997)
        .map(f32::from_bits)
        .collect();
    for &at in table.step.iter().filter(|a| a.is_finite()) {
        let v = at as f32;
        values.extend([v, v.next_down(), v.next_up()]);
    }
    values.extend([
        -1.0,
        -0.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MAX,
    ]);
    for exposure in [1.0, 0.37, 3.3, 1e-3] {
        for &v in &values {
            assert_eq!(
                table.code(f64::from(v) * f64::from(exposure)),
                srgb8(v, exposure),
                "{v} at {exposure}"
            );
        }
    }
}

#[test]
fn back_faces_are_dim_blue_grey_stripes_not_black() {
    // A row of back-face pixels, a lit pixel, and a half back-face
    // pixel (an antialiased edge between a back face and black).
    let mut f = Frame::new(12, 2);
    f.covered.fill(true);
    f.back.fill(1.0);
    f.back[8] = 0.0;
    f.pixels[8] = [0.5; 3];
    f.back[9] = 0.5;
    let img = to_srgb8(&f, 1.0);
    for (x, y) in [(0, 0), (3, 0), (4, 0), (7, 0), (3, 1), (11, 1)] {
        let p = img.get_pixel(x, y).0;
        assert_eq!(p, back_face_color(x, y), "({x}, {y})");
        assert_ne!(p, [0, 0, 0]);
        // Dim and bluish: blue the largest channel, all below a third.
        assert!(p[2] > p[0] && p[2] > p[1] && p[2] < 100, "{p:?}");
    }
    assert_ne!(back_face_color(0, 0), back_face_color(4, 0));
    assert_eq!(back_face_color(0, 0), back_face_color(8, 0));
    assert_eq!(back_face_color(1, 0), back_face_color(0, 1));
    // The exposure does not change them.
    assert_eq!(to_srgb8(&f, 50.0).get_pixel(0, 0).0, back_face_color(0, 0));
    assert_eq!(img.get_pixel(8, 0).0, [188; 3]);
    // Half covered: between black and the full colour.
    let half = img.get_pixel(9, 0).0;
    let full = back_face_color(9, 0);
    assert!((0..3).all(|k| half[k] > 0 && half[k] < full[k]), "{half:?}");
}

#[test]
fn auto_exposure_ignores_back_faces() {
    // Half the covered pixels are back faces (0 in the frame): the
    // exposure is that of the lit half alone.
    let mut f = frame(&[2.0, 2.0, 0.0, 0.0], &[true; 4]);
    f.back[2] = 1.0;
    f.back[3] = 1.0;
    let k = auto_exposure(&f);
    assert!((k - 0.45).abs() < EXPOSURE_TOLERANCE * 0.45, "{k}");
}

#[test]
fn to_srgb8_keeps_size_and_order() {
    let mut f = Frame::new(2, 2);
    f.pixels = vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.5],
    ];
    let img = to_srgb8(&f, 1.0);
    assert_eq!(img.dimensions(), (2, 2));
    assert_eq!(img.get_pixel(0, 0).0, [255, 0, 0]);
    assert_eq!(img.get_pixel(1, 0).0, [0, 255, 0]);
    assert_eq!(img.get_pixel(0, 1).0, [0, 0, 255]);
    assert_eq!(img.get_pixel(1, 1).0, [188, 188, 188]);
}

/// A frame of `n` covered pixels, each `[v, v, v]` for `v` from `values`
/// taken in turn.
fn covered(values: &[f32], n: usize) -> Frame {
    let v: Vec<f32> = values.iter().copied().cycle().take(n).collect();
    frame(&v, &vec![true; n])
}

#[test]
fn the_ambient_term_never_sets_the_exposure_of_an_unlit_view() {
    // Seen from outside a room lit from within: the walls hold only the
    // ambient term, a dim estimate (2e-4), and the solution shows nothing.
    let shown = covered(&[2e-4, 2.5e-4, 3e-4], 300);
    let alone = covered(&[0.0], 300);
    let plain = auto_exposure(&shown);
    let k = auto_exposure_beside(&shown, &alone);
    assert!(
        (k - plain * UNLIT_EXPOSURE_SHARE).abs() <= EXPOSURE_TOLERANCE * k,
        "{k}"
    );
    // Exposed for itself, the ambient estimate filled the picture (the
    // 95th percentile at 0.9, 8-bit 243); now it stays dim.
    assert_eq!(srgb8(3e-4, plain), srgb8(0.9, 1.0));
    assert!(srgb8(3e-4, k) < 80, "{}", srgb8(3e-4, k));
}

#[test]
fn where_the_solution_has_light_the_rule_changes_nothing() {
    // The solution lit everywhere in view, the ambient term on top: the
    // picture's own automatic exposure is the smaller, and kept.
    let solution: Vec<f32> = (0..200).map(|i| 0.5 + i as f32 * 0.01).collect();
    let shown: Vec<f32> = solution.iter().map(|v| v + 0.2).collect();
    let all = vec![true; 200];
    let (shown, solution) = (frame(&shown, &all), frame(&solution, &all));
    assert_eq!(
        auto_exposure_beside(&shown, &solution),
        auto_exposure(&shown)
    );
    // A small solution picture (the probe) measures the same.
    assert_eq!(
        auto_exposure_beside(&shown, &covered(&[0.5, 1.0, 2.0], 12)),
        auto_exposure(&shown)
    );
}

#[test]
fn a_bright_lamp_alone_in_an_unlit_view_sets_the_exposure() {
    // A few lamp pixels lit by the solution, the rest ambient only: the
    // exposure is the lamp's (its brightest pixel), not the ambient's.
    let mut shown = vec![1e-3f32; 100];
    let mut solution = vec![0.0f32; 100];
    for k in 0..3 {
        shown[k] = 50.0;
        solution[k] = 50.0;
    }
    let all = vec![true; 100];
    let k = auto_exposure_beside(&frame(&shown, &all), &frame(&solution, &all));
    assert!((k - 0.9 / 50.0).abs() <= EXPOSURE_TOLERANCE * k, "{k}");
}

#[test]
fn the_exposure_probe_keeps_the_shape_and_is_small() {
    assert_eq!(exposure_probe_size(640, 480), (160, 120));
    assert_eq!(exposure_probe_size(100, 50), (100, 50));
    assert_eq!(exposure_probe_size(10000, 1), (160, 1));
    assert_eq!(exposure_probe_size(0, 0), (1, 1));
    let (w, h) = exposure_probe_size(1920, 1080);
    assert!(w == EXPOSURE_PROBE_SIDE && h == 90, "{w}x{h}");
}
