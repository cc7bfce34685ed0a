//! Prints the area-weighted mean radiosity of every polygon of a scene
//! after a solve, for accuracy studies (`docs/accuracy.md`):
//!
//! ```sh
//! cargo run --release --example wall_means -- scenes/cornell.sc vertex 12
//! cargo run --release --example wall_means -- scenes/cornell.sc vertex 12 adaptive
//! ```
//!
//! Arguments: the scene, the unshot scheme (`vertex` or `polygon`),
//! `lenmax` in scene units (optional; `-` or absent for the program's
//! default), and `adaptive` to solve with the default adaptive subdivision.

use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::mesh::refine::RefineOptions;
use radiosity::prepare;
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::UnshotScheme;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(scheme)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: wall_means SCENE vertex|polygon [LENMAX|-] [adaptive]");
        std::process::exit(2);
    };
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(path)));
    config.lenmax = args.get(3).and_then(|l| l.parse().ok());
    config.solver.unshot = if scheme == "polygon" {
        UnshotScheme::Polygon
    } else {
        UnshotScheme::Vertex
    };
    if args.get(4).is_some_and(|a| a == "adaptive") {
        config.adaptive = Some(RefineOptions::default());
    }
    let prepared = match prepare::prepare(&config) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let start = std::time::Instant::now();
    let mut session = Session::from_prepared(
        &prepared,
        SessionOptions::for_run(&config, &prepared, false),
    );
    if let Err(e) = session.run_to_end(&AtomicBool::new(false)) {
        eprintln!("{e}");
        std::process::exit(1);
    }
    let mesh = session.mesh();
    let radiosity = session.radiosity();
    let areas = mesh.vertex_areas();
    println!(
        "# {path}: --unshot {scheme}, lenmax {}{}, {} vertices, {} steps, {:.2} s",
        prepared.lenmax,
        if config.adaptive.is_some() {
            ", --adaptive"
        } else {
            ""
        },
        mesh.vertex_count(),
        session.totals().steps,
        start.elapsed().as_secs_f64()
    );
    println!("polygon,line,area,r,g,b");
    for (p, (polygon, pm)) in prepared
        .scene
        .polygons
        .iter()
        .zip(&mesh.polygons)
        .enumerate()
    {
        let mut sum = Rgb::BLACK;
        for l in pm.vertices.clone() {
            sum += radiosity[l as usize] * areas[l as usize];
        }
        let mean = sum / pm.area;
        println!(
            "{p},{},{:.1},{:.5},{:.5},{:.5}",
            polygon.origin.line, pm.area, mean.r, mean.g, mean.b
        );
    }
}
