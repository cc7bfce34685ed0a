//! Radiosity of a floor around the point where an object rests on it, in
//! both modes (`docs/accuracy.md`, The contact of a sphere and the floor):
//!
//! ```sh
//! cargo run --release --example sphere_box -- 16 > spheres16.sc
//! cargo run --release --example contact_rings -- spheres16.sc 0 452 0.00001
//! ```
//!
//! Arguments: the scene, the floor polygon, a polygon of the object (its
//! lowest vertex is the contact) and optionally the threshold (default
//! 0.001). Solves at the default mesh without clustering or overshooting
//! (the original algorithm) and with the defaults, and prints per ring of
//! 15 scene units around the contact (distance in the floor's plane,
//! measured across x and z) the mean luminance of the floor's element
//! vertices in each mode, with their count.

use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare;
use radiosity::session::{Session, SessionOptions};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

const RING: f32 = 15.0;
const RINGS: usize = 12;

fn luminance(c: Rgb) -> f64 {
    0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parsed = (
        args.first(),
        args.get(1).and_then(|a| a.parse::<usize>().ok()),
        args.get(2).and_then(|a| a.parse::<usize>().ok()),
    );
    let (Some(scene), Some(floor), Some(object)) = parsed else {
        eprintln!("usage: contact_rings SCENE FLOOR_POLYGON OBJECT_POLYGON [THRESHOLD]");
        std::process::exit(2);
    };
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(scene)));
    if let Some(t) = args.get(3).and_then(|t| t.parse().ok()) {
        config.solver.threshold = t;
    }
    let prepared = match prepare::prepare(&config) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let polygons = &prepared.scene.polygons;
    if floor >= polygons.len() || object >= polygons.len() {
        eprintln!("the scene has {} polygons", polygons.len());
        std::process::exit(2);
    }
    let vertices = &polygons[object].vertices;
    let contact = vertices
        .iter()
        .copied()
        .fold(vertices[0], |a, b| if b.y < a.y { b } else { a });
    println!(
        "# contact at {contact}, threshold {}",
        config.solver.threshold
    );
    println!("| ring | --no-clustering --no-overshoot | default | vertices |");
    println!("|---|---|---|---|");
    let mut columns = Vec::new();
    for clustering in [false, true] {
        let mut c = config.clone();
        c.solver.approximations.clusters = clustering;
        c.solver.approximations.overshoot = clustering;
        let mut session =
            Session::from_prepared(&prepared, SessionOptions::for_run(&c, &prepared, false));
        session
            .run_to_end(&AtomicBool::new(false))
            .expect("an uncancelled solve");
        let mesh = session.mesh();
        let radiosity = session.radiosity();
        let mut rings = vec![(0.0f64, 0usize); RINGS];
        for (l, p) in mesh.vertex_polygon.iter().enumerate() {
            if p.index() != floor {
                continue;
            }
            let x = mesh.positions[l];
            let d = (x.x - contact.x).hypot(x.z - contact.z);
            if let Some(ring) = rings.get_mut((d / RING) as usize) {
                ring.0 += luminance(radiosity[l]);
                ring.1 += 1;
            }
        }
        columns.push(rings);
    }
    let mean = |(sum, n): (f64, usize)| if n > 0 { sum / n as f64 } else { 0.0 };
    for (r, (brute, clustered)) in columns[0].iter().zip(&columns[1]).enumerate() {
        println!(
            "| {}–{} | {:.5} | {:.5} | {} |",
            r as f32 * RING,
            (r + 1) as f32 * RING,
            mean(*brute),
            mean(*clustered),
            brute.1
        );
    }
}
