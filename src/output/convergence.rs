//! How the solve converged: a CSV log of every shooting step (`--log`) and
//! a plot of the unshot power against the step (`--plot`).
//!
//! The CSV has a header line and one row per step, in order:
//!
//! | column | meaning |
//! |---|---|
//! | `step` | the step, from 1 |
//! | `shooter` | the polygon that shot: its index in the scene, from 0 |
//! | `shooter_line` | the line of the scene file where that polygon is written |
//! | `shot_power` | the power it shot, radiosity × area (scene units); negative for a step of negative light, which takes back what overshooting sent ahead |
//! | `unshot_fraction` | unshot power left after the step (its magnitude: light still to shoot and light sent ahead) ÷ emitted power |
//! | `rays` | shadow rays cast in the step |
//! | `seconds` | wall-clock seconds from the start of the solve to the end of the step (a resumed solve's clock continues the saved one's) |
//!
//! Numbers are written in Rust's shortest round-trip form, so reading them
//! back gives the very values of the run.
//!
//! The plot is a PNG drawn with `plotters`: the unshot fraction on a log
//! axis against the step, starting from 1 at step 0, with the stopping
//! threshold as a horizontal line. Its text uses the Noto Mono font bundled
//! in the binary (SIL Open Font License, `assets/fonts/OFL.txt`), so no
//! system font is needed.

use super::{write_rgb8, OutputError, PictureFormat};
use image::RgbImage;
use plotters::prelude::*;
use std::io::{self, Write};
use std::path::Path;

/// The plot's size in pixels (width, height).
pub const PLOT_SIZE: (u32, u32) = (900, 560);

/// The CSV header line (without the line break).
pub const LOG_HEADER: &str = "step,shooter,shooter_line,shot_power,unshot_fraction,rays,seconds";

/// The lowest value the plot's log axis reaches: an unshot fraction or a
/// threshold below it (a `--threshold 1e-307`, a subnormal fraction) is
/// drawn on the axis' floor. Thirty decades hold any solve an `f64` sum can
/// tell apart from zero (its unshot fractions stop near `1e-16`), while a
/// log axis spanning subnormal numbers would need hundreds of decades and
/// its tick arithmetic loses precision there.
pub const PLOT_FLOOR: f64 = 1e-30;

/// The font family the plot's text is drawn with (the bundled font).
const FONT: &str = crate::render::text::FONT_FAMILY;

/// One shooting step as logged (see the module docs for each column).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRecord {
    /// Which step this was, from 1.
    pub step: u64,
    /// The polygon that shot: its index in the scene, from 0.
    pub shooter: u32,
    /// The power it shot, radiosity × area (scene units); negative for a
    /// step of negative light.
    pub shot_power: f64,
    /// Unshot power left after the step ÷ emitted power.
    pub unshot_fraction: f64,
    /// Shadow rays cast in the step.
    pub rays: u64,
    /// The line of the scene file where the shooter is written.
    pub shooter_line: u32,
    /// Seconds from the start of the solve to the end of this step.
    pub seconds: f64,
}

/// Writes the CSV log (see the module docs) of `steps`.
pub fn write_log(w: &mut dyn Write, steps: &[StepRecord]) -> io::Result<()> {
    writeln!(w, "{LOG_HEADER}")?;
    for s in steps {
        writeln!(
            w,
            "{},{},{},{},{},{},{}",
            s.step, s.shooter, s.shooter_line, s.shot_power, s.unshot_fraction, s.rays, s.seconds
        )?;
    }
    Ok(())
}

/// Writes the CSV log to `path`, atomically.
pub fn write_log_file(path: &Path, steps: &[StepRecord]) -> Result<(), OutputError> {
    super::write_atomically(path, |w| write_log(w, steps))
}

/// Checks that `path` names a picture format the plot can be written in
/// (8-bit: `.png`, `.tif`, `.tiff`).
pub fn check_plot_path(path: &Path) -> Result<(), OutputError> {
    PictureFormat::eight_bit(path, "a plot is an 8-bit picture").map(|_| ())
}

/// Draws the convergence plot of `steps` (see the module docs) for a solve
/// that stops at `threshold` (a fraction of the emitted power); `title`
/// names the scene.
pub fn plot(steps: &[StepRecord], threshold: f64, title: &str) -> Result<RgbImage, String> {
    crate::render::text::register_bundled_font();
    let (w, h) = PLOT_SIZE;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let points: Vec<(f64, f64)> = std::iter::once((0.0, 1.0))
            .chain(steps.iter().map(|s| (s.step as f64, s.unshot_fraction)))
            .filter(|&(_, y)| y > 0.0 && y.is_finite())
            .map(|(x, y)| (x, y.max(PLOT_FLOOR)))
            .collect();
        let last_step = points.last().map_or(1.0, |p| p.0).max(1.0);
        let threshold_drawn =
            (threshold > 0.0 && threshold.is_finite()).then_some(threshold.max(PLOT_FLOOR));
        let lowest = points
            .iter()
            .map(|p| p.1)
            .chain(threshold_drawn)
            .fold(1.0, f64::min);
        // A decade of room below the lowest value (down to the floor), and
        // some above 1.
        let y_range = (lowest / 10.0).max(PLOT_FLOOR)..2.0;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("convergence of {title}"), (FONT, 22).into_font())
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..last_step, y_range.log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("shooting step")
            .y_desc("unshot power / emitted power")
            .label_style((FONT, 14).into_font())
            .axis_desc_style((FONT, 16).into_font())
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(LineSeries::new(points, BLUE.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label("unshot fraction")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        if let Some(drawn) = threshold_drawn {
            chart
                .draw_series(LineSeries::new(
                    vec![(0.0, drawn), (last_step, drawn)],
                    RED.stroke_width(1),
                ))
                .map_err(|e| e.to_string())?
                .label(format!("threshold {threshold}"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14).into_font())
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    RgbImage::from_raw(w, h, buf).ok_or_else(|| "plot buffer has the wrong size".to_string())
}

/// Draws the plot and writes it to `path` (`.png`, `.tif`, `.tiff`),
/// atomically.
pub fn write_plot_file(
    path: &Path,
    steps: &[StepRecord],
    threshold: f64,
    title: &str,
) -> Result<(), OutputError> {
    write_plot_image(path, plot(steps, threshold, title))
}

/// Writes a plot drawn by [`plot`] (or its error) to `path`, atomically:
/// [`write_plot_file`] for a caller that draws the plot itself (on a
/// thread it can abandon).
pub fn write_plot_image(path: &Path, plotted: Result<RgbImage, String>) -> Result<(), OutputError> {
    check_plot_path(path)?;
    let image = plotted.map_err(|e| OutputError::Io {
        path: path.to_path_buf(),
        error: io::Error::other(format!("cannot draw the plot: {e}")),
    })?;
    write_rgb8(path, &image)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(n: u64) -> Vec<StepRecord> {
        (1..=n)
            .map(|i| StepRecord {
                step: i,
                shooter: i as u32 % 3,
                shot_power: 1.0 / i as f64,
                unshot_fraction: 0.5f64.powi(i as i32),
                rays: 100 * i,
                shooter_line: 7,
                seconds: 0.1 * i as f64,
            })
            .collect()
    }

    #[test]
    fn log_has_a_header_and_one_exact_row_per_step() {
        let s = steps(3);
        let mut out = Vec::new();
        write_log(&mut out, &s).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0], LOG_HEADER);
        assert_eq!(lines[2], "2,2,7,0.5,0.25,200,0.2");
        let third: Vec<f64> = lines[3].split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(third[4], s[2].unshot_fraction);
        assert_eq!(third[6], s[2].seconds);
    }

    #[test]
    fn plot_draws_the_curve_and_text() {
        let img = plot(&steps(20), 1e-3, "test").unwrap();
        assert_eq!(img.dimensions(), PLOT_SIZE);
        let blue = img.pixels().filter(|p| p.0 == [0, 0, 255]).count();
        let red = img.pixels().filter(|p| p.0 == [255, 0, 0]).count();
        assert!(blue > 500, "curve pixels: {blue}");
        assert!(red > 300, "threshold pixels: {red}");
        // Text is drawn in black anti-aliased strokes: many grey pixels in
        // the caption band at the top, which has no lines.
        let caption_ink = (0..40)
            .flat_map(|y| (0..PLOT_SIZE.0).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 128)
            .count();
        assert!(caption_ink > 100, "caption pixels: {caption_ink}");
        // No steps at all (nothing emits): still a plot.
        assert!(plot(&[], 1e-3, "dark").is_ok());
    }

    #[test]
    fn plot_of_tiny_subnormal_and_zero_values_finishes() {
        // A subnormal threshold once made the log axis loop forever: draw
        // on another thread and give it far more time than a plot takes.
        let mut s = steps(4);
        s[1].unshot_fraction = 1e-200;
        s[2].unshot_fraction = 5e-324;
        s[3].unshot_fraction = 0.0;
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for threshold in [1e-307, 5e-324, f64::MIN_POSITIVE, 0.0, 1e-40] {
                tx.send(plot(&s, threshold, "tiny").map(|i| i.dimensions()))
                    .unwrap();
            }
        });
        for _ in 0..5 {
            let drawn = rx
                .recv_timeout(std::time::Duration::from_secs(60))
                .expect("the plot did not finish");
            assert_eq!(drawn, Ok(PLOT_SIZE));
        }
    }

    #[test]
    fn plot_paths_must_be_8_bit_pictures() {
        assert!(check_plot_path(Path::new("p.png")).is_ok());
        assert!(check_plot_path(Path::new("p.exr")).is_err());
        assert!(check_plot_path(Path::new("p.txt")).is_err());
    }
}
