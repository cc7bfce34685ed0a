//! Writes the tessellated-sphere test scene (see
//! `support/sphere_box.rs`) to standard output:
//!
//! ```sh
//! cargo run --release --example sphere_box -- 32 > spheres32.sc   # 1,926 polygons
//! ```

#[path = "support/sphere_box.rs"]
mod sphere_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(|a| a.parse::<usize>()) {
        Some(Ok(n)) if n >= 4 => print!("{}", sphere_box::sphere_box_sc(n)),
        _ => {
            eprintln!(
                "usage: sphere_box N   (N >= 4 segments a sphere; writes a .sc scene to stdout)"
            );
            std::process::exit(2);
        }
    }
}
