//! `--sky`: a model with no light of its own, lit from all around.

mod common;

use common::*;

/// An open courtyard as Blender writes it: a 10 × 10 floor and four walls
/// 3 high facing in, no roof, no emitter, CRLF line ends.
const COURTYARD: &str = "# Blender v2.93.1 OBJ File: 'courtyard.blend'\r\n\
# www.blender.org\r\n\
mtllib courtyard.mtl\r\n\
o Floor\r\n\
v 0.000000 0.000000 0.000000\r\n\
v 10.000000 0.000000 0.000000\r\n\
v 10.000000 0.000000 -10.000000\r\n\
v 0.000000 0.000000 -10.000000\r\n\
vn 0.0000 1.0000 0.0000\r\n\
usemtl Stone\r\n\
s off\r\n\
f 1//1 2//1 3//1 4//1\r\n\
o Walls\r\n\
v 0.000000 3.000000 0.000000\r\n\
v 10.000000 3.000000 0.000000\r\n\
v 10.000000 3.000000 -10.000000\r\n\
v 0.000000 3.000000 -10.000000\r\n\
usemtl Plaster\r\n\
f 2 1 5 6\r\n\
f 3 2 6 7\r\n\
f 4 3 7 8\r\n\
f 1 4 8 5\r\n";

const MTL: &str = "# Blender MTL File: 'courtyard.blend'\r\n\
newmtl Plaster\r\nNs 225.000000\r\nKa 1.000000 1.000000 1.000000\r\n\
Kd 0.600000 0.600000 0.600000\r\nKs 0.500000 0.500000 0.500000\r\nNi 1.450000\r\nd 1.000000\r\nillum 2\r\n\
newmtl Stone\r\nNs 225.000000\r\nKa 1.000000 1.000000 1.000000\r\n\
Kd 0.400000 0.400000 0.400000\r\nKs 0.500000 0.500000 0.500000\r\nNi 1.450000\r\nd 1.000000\r\nillum 2\r\n";

/// A camera inside the courtyard looking down at the far wall.
const CAMERA: &str =
    "camera\n  eye 5 2.5 -1\n  lookat 5 0 -7\n  up 0 1 0\n  fov 60\n  size 96 72\nend\n";

fn courtyard(dir: &std::path::Path) {
    write(dir, "courtyard.obj", COURTYARD);
    write(dir, "courtyard.mtl", MTL);
    write(dir, "cam.sc", CAMERA);
}

#[test]
fn a_courtyard_with_no_light_is_lit_by_the_sky() {
    let dir = tempfile::tempdir().unwrap();
    courtyard(dir.path());
    let args = [
        "courtyard.obj",
        "--camera",
        "cam.sc",
        "--lenmax",
        "0.5",
        "-o",
        "out.png",
        "--stats",
        "s.json",
        "--export",
        "out.glb",
    ];
    let out = run_in(dir.path(), &[&args[..], &["--sky", "1"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(!err.contains("nothing emits"), "{err}");
    assert!(!err.contains("nearly black"), "{err}");
    assert!(err.contains("under a sky of 1:"), "{err}");

    let stats = read_json(dir.path(), "s.json");
    assert_eq!(stats["sky"], serde_json::json!([1.0, 1.0, 1.0]));
    // Five faces, each two-sided (an OBJ face is): the sky is not counted.
    assert_eq!(stats["polygons"], 10);
    assert_eq!(stats["converged"], true);
    assert!(stats.get("warnings").is_none(), "{stats}");

    // Lit: the floor and the walls in view, the sky above them left as
    // background. The floor's middle sees most of the sky: about 0.4 · 1.
    let img = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 0)).count();
    let total = (img.width() * img.height()) as usize;
    assert!(lit > total * 3 / 4, "{lit} of {total} pixels lit");
    let top = img.get_pixel(48, 0).0;
    assert_eq!(top, [0, 0, 0], "the sky is not drawn");

    // The export holds the courtyard and nothing else: as many vertices as
    // the stats count, every one within the courtyard's bounds.
    let glb = std::fs::read(dir.path().join("out.glb")).unwrap();
    let doc = gltf::Gltf::from_slice(&glb).unwrap();
    let mut vertices = 0;
    for mesh in doc.meshes() {
        for primitive in mesh.primitives() {
            let bounds = primitive.bounding_box();
            for k in 0..3 {
                assert!(
                    bounds.min[k] >= -10.0 && bounds.max[k] <= 10.0,
                    "{bounds:?}"
                );
            }
            let position = primitive.get(&gltf::Semantic::Positions).unwrap();
            vertices += position.count();
        }
    }
    assert_eq!(serde_json::json!(vertices), stats["vertices"]);

    // Without a sky nothing emits, and the warning says how to light it.
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("nothing emits light"),
        "{}",
        stderr(&out)
    );
    assert!(stderr(&out).contains("--sky VALUE"), "{}", stderr(&out));
}

#[test]
fn a_bad_sky_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    courtyard(dir.path());
    for bad in ["--sky=-1", "--sky=1,2", "--sky=bright"] {
        let out = run_in(dir.path(), &["courtyard.obj", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        assert!(
            stderr(&out).contains("--sky must look like 1 or 0.8,0.9,1.2"),
            "{}",
            stderr(&out)
        );
    }
}
