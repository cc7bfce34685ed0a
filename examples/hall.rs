//! Writes the scaling test scene (see `support/hall.rs`) to
//! standard output:
//!
//! ```sh
//! cargo run --release --example hall -- 15 > hall.sc    # about 1,000 polygons
//! ```

#[path = "support/hall.rs"]
mod hall;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(|a| a.parse::<usize>()) {
        Some(Ok(k)) if k >= 1 => print!("{}", hall::hall_sc(k)),
        _ => {
            eprintln!("usage: hall K   (K >= 1 tables with chairs; writes a .sc scene to stdout)");
            std::process::exit(2);
        }
    }
}
