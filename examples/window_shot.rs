//! Turns a screenshot the window wrote (`p`: the screen as shown, panel
//! included, as TIFF) into the PNG the docs show, after checking it is the
//! picture asked for: lit, and with the element mesh drawn over it when
//! `--mesh` is given (none otherwise). `scripts/window_shots.sh` runs it.
//!
//! ```sh
//! cargo run --release --example window_shot -- rtable-001.tiff docs/images/window.png
//! cargo run --release --example window_shot -- rtable-002.tiff docs/images/window-mesh.png --mesh
//! ```

use radiosity::render::{MESH_COLOR, MESH_COLOR_ON_LIGHT};

/// With `--mesh`, at least this share of the pixels are mesh lines
/// (rtable at 640×480 has about 10 %); without, at most a trace.
const MESH_SHARE: (f64, f64) = (0.02, 0.001);

fn fail(message: String) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh = args.iter().any(|a| a == "--mesh");
    let files: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let [input, output] = files[..] else {
        eprintln!("usage: window_shot SCREEN.tiff OUT.png [--mesh]");
        std::process::exit(2);
    };
    let picture = image::open(input)
        .unwrap_or_else(|e| fail(format!("cannot read {input}: {e}")))
        .to_rgb8();
    let pixels = f64::from(picture.width() * picture.height());
    let lit = picture
        .pixels()
        .filter(|p| p.0.iter().any(|&c| c > 30))
        .count() as f64;
    if lit < pixels / 2.0 {
        fail(format!(
            "{input} is mostly black ({:.0} % lit)",
            100.0 * lit / pixels
        ));
    }
    let lines = picture
        .pixels()
        .filter(|p| p.0 == MESH_COLOR || p.0 == MESH_COLOR_ON_LIGHT)
        .count() as f64
        / pixels;
    if mesh && lines < MESH_SHARE.0 {
        fail(format!(
            "{input} shows no mesh ({:.2} % of its pixels are mesh lines)",
            100.0 * lines
        ));
    }
    if !mesh && lines > MESH_SHARE.1 {
        fail(format!(
            "{input} shows the mesh ({:.2} % of its pixels are mesh lines)",
            100.0 * lines
        ));
    }
    picture
        .save(output)
        .unwrap_or_else(|e| fail(format!("cannot write {output}: {e}")));
    println!(
        "wrote {output}: {}x{}, {:.1} % mesh lines",
        picture.width(),
        picture.height(),
        100.0 * lines
    );
}
