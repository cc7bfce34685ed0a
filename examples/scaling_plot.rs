//! Draws the scaling study: solve time against polygon count on log–log
//! axes, with the least-squares exponent, from a CSV with the columns
//! `k,polygons,vertices,steps,seconds,rays,pairs` (a header line first).
//!
//! ```sh
//! cargo run --release --example scaling_plot -- docs/scaling.csv docs/images/scaling.png
//! ```

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

const FONT: &str = "scaling-plot-font";

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(input), Some(output)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: scaling_plot SCALING.csv OUT.png");
        std::process::exit(2);
    };
    let text = std::fs::read_to_string(input).unwrap_or_else(|e| {
        eprintln!("error: cannot read {input}: {e}");
        std::process::exit(2)
    });
    let rows: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Some((
                f.get(1)?.trim().parse().ok()?,
                f.get(4)?.trim().parse().ok()?,
            ))
        })
        .collect();
    if rows.len() < 2 {
        eprintln!("error: {input} needs at least two data rows");
        std::process::exit(2);
    }
    // Least squares on the logs: seconds ≈ c · polygons^exponent.
    let n = rows.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = rows.iter().map(|&(p, s)| (p.ln(), s.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    let exponent = sxy / sxx;
    let c = (my - exponent * mx).exp();
    println!("exponent {exponent:.2}");

    let _ = register_font(
        FONT,
        FontStyle::Normal,
        include_bytes!("../assets/fonts/NotoMono-Regular.ttf"),
    );
    let (w, h) = (800u32, 560u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error>> {
        root.fill(&WHITE)?;
        let (p0, p1) = (
            rows.iter().map(|r| r.0).fold(f64::INFINITY, f64::min),
            rows.iter().map(|r| r.0).fold(0.0, f64::max),
        );
        let (s0, s1) = (
            rows.iter().map(|r| r.1).fold(f64::INFINITY, f64::min),
            rows.iter().map(|r| r.1).fold(0.0, f64::max),
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("hall scaling: time ~ polygons^{exponent:.2}"),
                (FONT, 22).into_font(),
            )
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (p0 / 1.5..p1 * 1.5).log_scale(),
                (s0 / 2.0..s1 * 2.0).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_labels(6)
            .y_labels(6)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y}"))
            .x_desc("polygons")
            .y_desc("seconds to 0.1 % unshot")
            .label_style((FONT, 14).into_font())
            .axis_desc_style((FONT, 16).into_font())
            .draw()?;
        chart
            .draw_series(
                rows.iter()
                    .map(|&(p, s)| Circle::new((p, s), 5, BLUE.filled())),
            )?
            .label("measured")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLUE.filled()));
        let fit: Vec<(f64, f64)> = (0..=50)
            .map(|i| {
                let p = p0 * (p1 / p0).powf(i as f64 / 50.0);
                (p, c * p.powf(exponent))
            })
            .collect();
        chart
            .draw_series(LineSeries::new(fit, RED.stroke_width(2)))?
            .label(format!("fit, exponent {exponent:.2}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        chart
            .configure_series_labels()
            .label_font((FONT, 14).into_font())
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()?;
        root.present()?;
        Ok(())
    };
    if let Err(e) = draw() {
        eprintln!("error: cannot draw {output}: {e}");
        std::process::exit(1);
    }
    drop(root);
    let saved = image::RgbImage::from_raw(w, h, buf).map(|img| img.save(output));
    if !matches!(saved, Some(Ok(()))) {
        eprintln!("error: cannot write {output}");
        std::process::exit(1);
    }
}
