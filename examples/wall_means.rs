//! Prints the area-weighted mean radiosity of every polygon of a scene
//! after a solve, for accuracy studies (`docs/accuracy.md`):
//!
//! ```sh
//! cargo run --release --example wall_means -- scenes/cornell.sc vertex 12
//! ```
//!
//! Arguments: the scene, the unshot scheme (`vertex` or `polygon`), and
//! `lenmax` in scene units (optional; default as the program's).

use radiosity::color::Rgb;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene;
use radiosity::solver::{Progressive, SolverOptions, UnshotScheme};
use radiosity::visibility::Visibility;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(scheme)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: wall_means SCENE vertex|polygon [LENMAX]");
        std::process::exit(2);
    };
    let scene = match scene::load(Path::new(path)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut options = MeshOptions::for_scene(&scene);
    if let Some(l) = args.get(3).and_then(|l| l.parse().ok()) {
        options.lenmax = l;
    }
    let unshot = if scheme == "polygon" {
        UnshotScheme::Polygon
    } else {
        UnshotScheme::Vertex
    };
    let mesh = match mesh::build(&scene, &options) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let visibility = Visibility::new(&scene);
    let mut solver = Progressive::new(
        &scene,
        &mesh,
        &visibility,
        SolverOptions {
            unshot,
            ..Default::default()
        },
    );
    let start = std::time::Instant::now();
    while !solver.is_done() && solver.step().is_some() {}
    let areas = mesh.vertex_areas();
    println!(
        "# {path}: --unshot {scheme}, lenmax {}, {} vertices, {} steps, {:.2} s",
        options.lenmax,
        mesh.vertex_count(),
        solver.steps(),
        start.elapsed().as_secs_f64()
    );
    println!("polygon,line,area,r,g,b");
    for (p, (polygon, pm)) in scene.polygons.iter().zip(&mesh.polygons).enumerate() {
        let mut sum = Rgb::BLACK;
        for l in pm.vertices.clone() {
            sum += solver.radiosity()[l as usize] * areas[l as usize];
        }
        let mean = sum / pm.area;
        println!(
            "{p},{},{:.1},{:.5},{:.5},{:.5}",
            polygon.origin.line, pm.area, mean.r, mean.g, mean.b
        );
    }
}
