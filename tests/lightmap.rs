//! `--lightmap` and `--lightmap-texture` checked as a user checks them:
//! the `.glb` read back (its own accessors, its embedded PNG), the light
//! found on the texels of the lit side, the file through the Khronos glTF
//! validator, the model's own attributes and materials kept, and bad
//! options refused with exit code 2.

mod common;
#[path = "support/gltf.rs"]
mod support;

use common::{run_in, stderr, write};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// A 4 × 2 floor in two halves of different materials (so two charts
/// meeting along x = 0), facing up, and a lamp above its +x end facing
/// down. OBJ faces are two-sided: each gets a back copy of its own.
const FLOOR_OBJ: &str = "\
v -2 0 1
v 0 0 1
v 0 0 -1
v -2 0 -1
v 2 0 1
v 2 0 -1
v 1.2 1 0.3
v 1.8 1 0.3
v 1.8 1 -0.3
v 1.2 1 -0.3
o FloorLeft
usemtl Left
f 1 2 3 4
o FloorRight
usemtl Right
f 2 5 6 3
o Lamp
usemtl Lamp
f 10 9 8 7
";

/// A triangle of the model: its corners' positions and lightmap UVs.
type Triangle = ([[f32; 3]; 3], [[f32; 2]; 3]);

/// A `.glb` read back: its JSON and binary chunk.
struct Glb {
    json: Value,
    bin: Vec<u8>,
}

impl Glb {
    fn read(path: &Path) -> Glb {
        let bytes = std::fs::read(path).expect("the .glb is written");
        assert_eq!(&bytes[0..4], b"glTF");
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        let json = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON chunk");
        let bin_at = 20 + json_len;
        let bin_len = word(bin_at);
        let bin = bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec();
        Glb { json, bin }
    }

    /// The bytes of buffer view `v`.
    fn view(&self, v: usize) -> &[u8] {
        let view = &self.json["bufferViews"][v];
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap() as usize;
        &self.bin[start..start + len]
    }

    /// Accessor `a` as `f32`s (or `u32` indices, as `f32`).
    fn floats(&self, a: u64) -> Vec<f32> {
        let accessor = &self.json["accessors"][a as usize];
        let bytes = self.view(accessor["bufferView"].as_u64().unwrap() as usize);
        let int = accessor["componentType"] == 5125;
        bytes
            .chunks_exact(4)
            .map(|b| {
                let b = [b[0], b[1], b[2], b[3]];
                if int {
                    u32::from_le_bytes(b) as f32
                } else {
                    f32::from_le_bytes(b)
                }
            })
            .collect()
    }

    /// The lightmap image, decoded.
    fn lightmap(&self) -> image::RgbImage {
        let texture = self.json["extras"]["lightmap"]["texture"].as_u64().unwrap() as usize;
        let source = self.json["textures"][texture]["source"].as_u64().unwrap() as usize;
        let image = &self.json["images"][source];
        assert_eq!(image["mimeType"], "image/png");
        let bytes = self.view(image["bufferView"].as_u64().unwrap() as usize);
        image::load_from_memory(bytes).expect("a PNG").to_rgb8()
    }

    /// Every triangle of every primitive: positions and TEXCOORD_1.
    fn triangles(&self) -> Vec<Triangle> {
        let mut out = Vec::new();
        for mesh in self.json["meshes"].as_array().unwrap() {
            for p in mesh["primitives"].as_array().unwrap() {
                let pos = self.floats(p["attributes"]["POSITION"].as_u64().unwrap());
                let uv = self.floats(p["attributes"]["TEXCOORD_1"].as_u64().unwrap());
                let idx = self.floats(p["indices"].as_u64().unwrap());
                for t in idx.chunks_exact(3) {
                    let i = [t[0], t[1], t[2]].map(|i| i as usize);
                    out.push((
                        [0, 1, 2].map(|k| [pos[3 * i[k]], pos[3 * i[k] + 1], pos[3 * i[k] + 2]]),
                        [0, 1, 2].map(|k| [uv[2 * i[k]], uv[2 * i[k] + 1]]),
                    ));
                }
            }
        }
        out
    }

    /// The lightmap UV of the model's point `p` on a face facing +y.
    fn uv_of(&self, p: [f32; 3]) -> [f32; 2] {
        for (pos, uv) in self.triangles() {
            let n = cross(sub(pos[1], pos[0]), sub(pos[2], pos[0]));
            if n[1] <= 0.0 || pos.iter().any(|v| v[1].abs() > 1e-6) {
                continue;
            }
            if let Some(at) = uv_in_xz(&(pos, uv), p) {
                return at;
            }
        }
        panic!("no upward face holds {p:?}");
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The luminance-ish brightness (mean of the 8-bit codes) of `image` at
/// UV `uv`, glTF's way: `(0, 0)` the top-left corner of the image.
fn brightness_at(image: &image::RgbImage, uv: [f32; 2]) -> f32 {
    let x = ((uv[0] * image.width() as f32) as u32).min(image.width() - 1);
    let y = ((uv[1] * image.height() as f32) as u32).min(image.height() - 1);
    let p = image.get_pixel(x, y).0;
    (f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2])) / 3.0
}

/// Bakes [`FLOOR_OBJ`] in a new directory; returns it.
fn baked_floor(extra: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "floor.obj", FLOOR_OBJ);
    let mut args = vec![
        "floor.obj",
        "--emit",
        "Lamp=10",
        "--lenmax",
        "0.2",
        "-o",
        "floor.png",
        "--lightmap",
        "floor.glb",
        "-q",
    ];
    args.extend_from_slice(extra);
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    dir
}

#[test]
fn the_light_is_on_the_texels_of_the_lit_end_not_upside_down() {
    let dir = baked_floor(&["--lightmap-texture", "floor-lightmap.png"]);
    let glb = Glb::read(&dir.path().join("floor.glb"));
    let image = glb.lightmap();
    // The bare texture is the embedded one.
    let bare = image::open(dir.path().join("floor-lightmap.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(bare, image);
    let lit = brightness_at(&image, glb.uv_of([1.5, 0.0, 0.0]));
    let far = brightness_at(&image, glb.uv_of([-1.5, 0.0, 0.0]));
    // Under the lamp the floor receives about 20 times what it does 3
    // units away; in 8-bit sRGB codes that is well over twice as bright.
    assert!(lit > 2.0 * far && far > 5.0, "lit {lit}, far {far}");
    // Read upside down (v from the bottom), the lit point would land
    // elsewhere.
    let uv = glb.uv_of([1.5, 0.0, 0.0]);
    let flipped = brightness_at(&image, [uv[0], 1.0 - uv[1]]);
    assert!((flipped - lit).abs() > 20.0, "lit {lit}, flipped {flipped}");
    // Every material shows it, on texture coordinate 1.
    let texture = &glb.json["extras"]["lightmap"]["texture"];
    for m in glb.json["materials"].as_array().unwrap() {
        assert_eq!(&m["emissiveTexture"]["index"], texture);
        assert_eq!(m["emissiveTexture"]["texCoord"], 1);
    }
}

#[test]
fn the_two_halves_meet_without_a_seam() {
    let dir = baked_floor(&[]);
    let glb = Glb::read(&dir.path().join("floor.glb"));
    let image = glb.lightmap();
    // Just either side of x = 0, on each half's own chart.
    let mut worst = 0.0f32;
    for k in 1..10 {
        let z = -0.9 + 0.18 * k as f32;
        let left = brightness_at(&image, glb.uv_of([-0.001, 0.0, z]));
        let right = brightness_at(&image, glb.uv_of([0.001, 0.0, z]));
        worst = worst.max((left - right).abs());
    }
    // The light changes by well under a code over a texel there.
    assert!(
        worst <= 3.0,
        "the two sides of x = 0 differ by {worst} codes"
    );
}

/// The Khronos glTF validator's module, where `.ci/run` installs it
/// (`npm install --prefix target/npm gltf-validator`), or where
/// `GLTF_VALIDATOR` points.
fn validator() -> Option<std::path::PathBuf> {
    let dir = std::env::var_os("GLTF_VALIDATOR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| common::root().join("target/npm/node_modules/gltf-validator"));
    dir.join("package.json").exists().then_some(dir)
}

/// The validator's report on `glb`.
fn validate(validator: &Path, glb: &Path) -> Value {
    let script = format!(
        "const v = require({:?}); const fs = require('fs');\
         v.validateBytes(new Uint8Array(fs.readFileSync({:?})))\
          .then(r => console.log(JSON.stringify(r.issues)))\
          .catch(e => {{ console.error(e); process.exit(1); }});",
        validator.display().to_string(),
        glb.display().to_string()
    );
    let out = Command::new("node")
        .args(["-e", &script])
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the validator's JSON")
}

#[test]
fn the_files_pass_the_khronos_validator() {
    let Some(validator) = validator() else {
        eprintln!(
            "skipped: the glTF validator is not installed (`npm install --prefix target/npm \
             gltf-validator`, as .ci/run does)"
        );
        return;
    };
    let dir = baked_floor(&[]);
    let model = common::root().join("tests/models/khronos/Box.gltf");
    let out = run_in(
        dir.path(),
        &[
            model.to_str().unwrap(),
            "--sky",
            "1",
            "-o",
            "box.png",
            "--lightmap",
            "box.glb",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for name in ["floor.glb", "box.glb"] {
        let issues = validate(&validator, &dir.path().join(name));
        assert_eq!(issues["numErrors"], 0, "{name}: {issues:#}");
        assert_eq!(issues["numWarnings"], 0, "{name}: {issues:#}");
    }
}

#[test]
fn a_gltf_model_keeps_its_normals_and_materials() {
    let dir = tempfile::tempdir().unwrap();
    let model = common::root().join("tests/models/khronos/Box.gltf");
    let out = run_in(
        dir.path(),
        &[
            model.to_str().unwrap(),
            "--sky",
            "1",
            "-o",
            "box.png",
            "--lightmap",
            "box.glb",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let said = stderr(&out);
    assert!(
        said.contains("lightmap: ") && said.contains("texels per unit"),
        "{said}"
    );
    let glb = Glb::read(&dir.path().join("box.glb"));
    // Box.gltf: 12 triangles with normals, one red material.
    let triangles = glb.triangles();
    assert_eq!(triangles.len(), 12);
    let primitive = &glb.json["meshes"][0]["primitives"][0];
    let normals = glb.floats(primitive["attributes"]["NORMAL"].as_u64().unwrap());
    for n in normals.chunks_exact(3) {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-5, "{n:?}");
        // An axis: the box's faces.
        assert!(n.iter().filter(|c| c.abs() > 0.999).count() == 1, "{n:?}");
    }
    let material = &glb.json["materials"][0];
    assert_eq!(
        material["pbrMetallicRoughness"]["baseColorFactor"][0]
            .as_f64()
            .unwrap() as f32,
        0.8
    );
    // The box's half-size is 0.5, its node turns it: y up becomes z.
    for (pos, _) in &triangles {
        for v in pos {
            assert!(v.iter().all(|c| (c.abs() - 0.5).abs() < 1e-6), "{v:?}");
        }
    }
}

#[test]
fn bad_lightmap_options_are_refused_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "floor.obj", FLOOR_OBJ);
    let cases: [(&[&str], &str); 5] = [
        (&["--lightmap", "out.png"], "a lightmap is written as .glb"),
        (
            &["--lightmap-texture", "out.tif"],
            "a lightmap is written as .png, .exr",
        ),
        (
            &["--lightmap-density", "0", "--lightmap", "a.glb"],
            "positive number",
        ),
        (
            &["--lightmap-density", "5", "-o", "a.png"],
            "give --lightmap",
        ),
        (
            &["--lightmap", "a.glb", "--lightmap-density", "1e6"],
            "--lightmap-density",
        ),
    ];
    for (args, message) in cases {
        let mut all = vec!["floor.obj", "--emit", "Lamp=10", "-q"];
        all.extend_from_slice(args);
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(message), "{args:?}: {}", stderr(&out));
    }
    // Never the input: a baked model baked again onto itself.
    let dir = baked_floor(&[]);
    let out = run_in(
        dir.path(),
        &["floor.glb", "--sky", "1", "--lightmap", "floor.glb"],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--lightmap would overwrite the scene file"),
        "{}",
        stderr(&out)
    );
}

/// A glTF file of one quad (two indexed triangles) with normals,
/// `TEXCOORD_0` and a base colour texture (`png`), drawn by a node moved
/// by `(10, 0, 0)`; everything in `data:` URIs.
fn textured_quad_gltf(png: &[u8]) -> String {
    use base64::Engine as _;
    let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, -1.0],
        [0.0, 0.0, -1.0],
    ];
    let normals = [[0.0f32, 1.0, 0.0]; 4];
    let uv0: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let indices: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin = Vec::new();
    for v in positions
        .iter()
        .flatten()
        .chain(normals.iter().flatten())
        .chain(uv0.iter().flatten())
    {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "Tile", "mesh": 0, "translation": [10.0, 0.0, 0.0]}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "material": 0}]}],
        "materials": [{"name": "Checker", "doubleSided": false,
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728}],
        "images": [{"uri": format!("data:image/png;base64,{}", b64(png))}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, -1.0], "max": [1.0, 0.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 24},
        ],
        "buffers": [{"byteLength": bin.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", b64(&bin))}],
    })
    .to_string()
}

#[test]
fn a_gltf_model_keeps_its_texture_coordinates_and_images() {
    let dir = tempfile::tempdir().unwrap();
    let mut png = Vec::new();
    image::RgbImage::from_fn(2, 2, |x, y| {
        image::Rgb(if (x + y) % 2 == 0 {
            [200, 40, 40]
        } else {
            [40, 40, 200]
        })
    })
    .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
    .unwrap();
    write(dir.path(), "tile.gltf", &textured_quad_gltf(&png));
    let out = run_in(
        dir.path(),
        &[
            "tile.gltf",
            "--sky",
            "1",
            "-o",
            "tile.png",
            "--lightmap",
            "tile.glb",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let glb = Glb::read(&dir.path().join("tile.glb"));
    assert_eq!(glb.json["nodes"][0]["name"], "Tile");
    let material = &glb.json["materials"][0];
    assert_eq!(material["name"], "Checker");
    // The base colour texture is the file's image, byte for byte, with its
    // sampler.
    let texture = material["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        .as_u64()
        .unwrap();
    let texture = &glb.json["textures"][texture as usize];
    assert_eq!(
        glb.json["samplers"][texture["sampler"].as_u64().unwrap() as usize]["magFilter"],
        9728
    );
    let image = &glb.json["images"][texture["source"].as_u64().unwrap() as usize];
    assert_eq!(
        glb.view(image["bufferView"].as_u64().unwrap() as usize),
        &png[..]
    );
    // Every vertex keeps its own position (moved by its node), normal and
    // TEXCOORD_0, whatever the lightmap's seams split.
    let p = &glb.json["meshes"][0]["primitives"][0];
    let pos = glb.floats(p["attributes"]["POSITION"].as_u64().unwrap());
    let nor = glb.floats(p["attributes"]["NORMAL"].as_u64().unwrap());
    let uv0 = glb.floats(p["attributes"]["TEXCOORD_0"].as_u64().unwrap());
    assert_eq!(glb.floats(p["indices"].as_u64().unwrap()).len(), 6);
    for k in 0..pos.len() / 3 {
        let (x, z) = (pos[3 * k], pos[3 * k + 2]);
        assert_eq!(&nor[3 * k..3 * k + 3], &[0.0, 1.0, 0.0]);
        // The file's UVs are u = x, v = 1 + z in the quad's own frame.
        assert_eq!(
            [uv0[2 * k], uv0[2 * k + 1]],
            [x - 10.0, 1.0 + z],
            "vertex {k}"
        );
    }
}

/// A 2 × 1 floor of two quads meeting at x = 1, each with texture
/// coordinates of its own (so the two corners on x = 1 have two `vt`
/// each), material `Tex`, and a lamp above facing down. The left quad's
/// `vt` is `(x / 2, −z)`, the right one's `(1/4 + 3/4 (x − 1), −z)`: `v`
/// grows towards −z, where OBJ's `v = 1`, the top of the image, lies.
const TEXTURED_OBJ: &str = "\
mtllib tex.mtl
v 0 0 0
v 1 0 0
v 2 0 0
v 2 0 -1
v 1 0 -1
v 0 0 -1
v 0.8 1 -0.3
v 1.2 1 -0.3
v 1.2 1 -0.7
v 0.8 1 -0.7
vt 0 0
vt 0.5 0
vt 0.5 1
vt 0 1
vt 0.25 0
vt 1 0
vt 1 1
vt 0.25 1
o Floor
usemtl Tex
f 1/1 2/2 5/3 6/4
f 2/5 3/6 4/7 5/8
o Lamp
usemtl Lamp
f 10 9 8 7
";

/// The `vt` [`TEXTURED_OBJ`] gives the floor's point `(x, z)` on the
/// quad left (`x < 1`) or right of x = 1.
fn obj_vt(left: bool, x: f32, z: f32) -> [f32; 2] {
    if left {
        [x / 2.0, -z]
    } else {
        [0.25 + 0.75 * (x - 1.0), -z]
    }
}

/// A 4 × 4 PNG, its top two rows red and its bottom two blue.
fn red_over_blue_png() -> Vec<u8> {
    let mut png = Vec::new();
    image::RgbImage::from_fn(4, 4, |_, y| {
        image::Rgb(if y < 2 { [200, 40, 40] } else { [40, 40, 200] })
    })
    .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
    .unwrap();
    png
}

impl Glb {
    /// The primitives of material `name`.
    fn primitives_of(&self, name: &str) -> Vec<Value> {
        let materials = self.json["materials"].as_array().unwrap();
        let m = materials.iter().position(|m| m["name"] == name).unwrap();
        self.json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|mesh| mesh["primitives"].as_array().unwrap().clone())
            .filter(|p| p["material"] == m)
            .collect()
    }

    /// The material named `name`.
    fn material(&self, name: &str) -> &Value {
        let materials = self.json["materials"].as_array().unwrap();
        materials.iter().find(|m| m["name"] == name).unwrap()
    }

    /// Every triangle of `primitive`: its corners' positions and
    /// `TEXCOORD_0`.
    fn triangles_uv0(&self, primitive: &Value) -> Vec<Triangle> {
        let pos = self.floats(primitive["attributes"]["POSITION"].as_u64().unwrap());
        let uv = self.floats(primitive["attributes"]["TEXCOORD_0"].as_u64().unwrap());
        let idx = self.floats(primitive["indices"].as_u64().unwrap());
        idx.chunks_exact(3)
            .map(|t| {
                let i = [t[0], t[1], t[2]].map(|i| i as usize);
                (
                    [0, 1, 2].map(|k| [pos[3 * i[k]], pos[3 * i[k] + 1], pos[3 * i[k] + 2]]),
                    [0, 1, 2].map(|k| [uv[2 * i[k]], uv[2 * i[k] + 1]]),
                )
            })
            .collect()
    }

    /// The image texture `index` shows, decoded, and its encoded bytes
    /// and media type.
    fn texture_image(&self, index: &Value) -> (image::RgbImage, Vec<u8>, String) {
        let texture = &self.json["textures"][index.as_u64().unwrap() as usize];
        let image = &self.json["images"][texture["source"].as_u64().unwrap() as usize];
        let bytes = self
            .view(image["bufferView"].as_u64().unwrap() as usize)
            .to_vec();
        let decoded = image::load_from_memory(&bytes).unwrap().to_rgb8();
        (
            decoded,
            bytes,
            image["mimeType"].as_str().unwrap().to_string(),
        )
    }
}

/// The value at the point `(x, z)` of a floor triangle (facing either
/// way) of `triangles`, interpolated from its corners' `uv`.
fn floor_uv_at(triangles: &[Triangle], x: f32, z: f32) -> [f32; 2] {
    triangles
        .iter()
        .find_map(|t| uv_in_xz(t, [x, 0.0, z]))
        .unwrap_or_else(|| panic!("no floor triangle holds ({x}, {z})"))
}

/// The `uv` of triangle `(pos, uv)` at point `p`, interpolated by the
/// barycentrics of `p` in the xz plane; `None` when `p` is outside it.
fn uv_in_xz((pos, uv): &Triangle, p: [f32; 3]) -> Option<[f32; 2]> {
    let area = |a: [f32; 3], b: [f32; 3], c: [f32; 3]| {
        (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2])
    };
    let total = area(pos[0], pos[1], pos[2]);
    let w = [
        area(p, pos[1], pos[2]) / total,
        area(pos[0], p, pos[2]) / total,
        area(pos[0], pos[1], p) / total,
    ];
    w.iter()
        .all(|&x| x >= 0.0)
        .then(|| [0, 1].map(|k| w[0] * uv[0][k] + w[1] * uv[1][k] + w[2] * uv[2][k]))
}

/// Bakes `obj` (with `mtl` as `tex.mtl` and `files` beside it) in a new
/// directory; returns it and what the run said.
fn baked_obj(obj: &str, mtl: &str, files: &[(&str, &[u8])]) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "model.obj", obj);
    write(dir.path(), "tex.mtl", mtl);
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    let out = run_in(
        dir.path(),
        &[
            "model.obj",
            "--emit",
            "Lamp=10",
            "-o",
            "model.png",
            "--lightmap",
            "model.glb",
            "--lightmap-density",
            "64",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    (dir, stderr(&out))
}

#[test]
fn an_obj_keeps_its_texture_coordinates_and_its_map_kd_image_not_upside_down() {
    let png = red_over_blue_png();
    let mut jpeg = Vec::new();
    image::RgbImage::from_pixel(8, 8, image::Rgb([90, 120, 30]))
        .write_to(
            &mut std::io::Cursor::new(&mut jpeg),
            image::ImageFormat::Jpeg,
        )
        .unwrap();
    // The lamp's texture has no extension: its type comes from its bytes.
    let mtl = "newmtl Tex\nKd 0.9 0.8 0.7\nmap_Kd textures/red over blue.png\n\
               newmtl Lamp\nKd 0 0 0\nKe 1 1 1\nmap_Kd lamp-image\n";
    let (dir, said) = baked_obj(
        TEXTURED_OBJ,
        mtl,
        &[("textures/red over blue.png", &png), ("lamp-image", &jpeg)],
    );
    assert!(!said.contains("lightmap's model"), "{said}");
    let glb = Glb::read(&dir.path().join("model.glb"));
    // Kd is the base colour, map_Kd its texture: the file's bytes, its
    // media type read from them.
    let tex = glb.material("Tex");
    let factor: Vec<f32> = tex["pbrMetallicRoughness"]["baseColorFactor"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect();
    assert_eq!(factor, [0.9, 0.8, 0.7, 1.0]);
    let (image, bytes, mime) =
        glb.texture_image(&tex["pbrMetallicRoughness"]["baseColorTexture"]["index"]);
    assert_eq!((bytes, mime.as_str()), (png, "image/png"));
    let lamp = glb.material("Lamp");
    let (_, bytes, mime) =
        glb.texture_image(&lamp["pbrMetallicRoughness"]["baseColorTexture"]["index"]);
    assert_eq!((bytes, mime.as_str()), (jpeg, "image/jpeg"));
    // Every corner of every floor triangle, front or back, has its face's
    // vt with v flipped: the corners on x = 1 are two vertices each.
    let floor = glb.primitives_of("Tex");
    let triangles: Vec<Triangle> = floor.iter().flat_map(|p| glb.triangles_uv0(p)).collect();
    // Two quads, two triangles each, and a back copy of each.
    assert_eq!(triangles.len(), 8);
    for (pos, uv) in &triangles {
        let left = pos.iter().map(|p| p[0]).sum::<f32>() < 3.0;
        for k in 0..3 {
            let [u, v] = obj_vt(left, pos[k][0], pos[k][2]);
            assert_eq!(uv[k], [u, 1.0 - v], "corner {:?}", pos[k]);
        }
    }
    // Sampled the glTF way (v = 0 the image's top row), the far end
    // (OBJ's v = 1, the top of the image) is red and the near end blue,
    // on both quads and both sides.
    let colour_at = |x: f32, z: f32, facing_up: bool| {
        let side: Vec<Triangle> = triangles
            .iter()
            .filter(|(p, _)| {
                let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                (n[1] > 0.0) == facing_up
            })
            .cloned()
            .collect();
        let [u, v] = floor_uv_at(&side, x, z);
        let px = ((u * 4.0) as u32).min(3);
        let py = ((v * 4.0) as u32).min(3);
        image.get_pixel(px, py).0
    };
    for x in [0.5, 1.5] {
        for up in [true, false] {
            assert_eq!(colour_at(x, -0.9, up), [200, 40, 40], "far end at x = {x}");
            assert_eq!(colour_at(x, -0.1, up), [40, 40, 200], "near end at x = {x}");
        }
    }
    if let Some(validator) = validator() {
        let issues = validate(&validator, &dir.path().join("model.glb"));
        assert_eq!(issues["numErrors"], 0, "{issues:#}");
        assert_eq!(issues["numWarnings"], 0, "{issues:#}");
    } else {
        eprintln!("validator skipped: the glTF validator is not installed");
    }
}

#[test]
fn map_kd_options_are_honoured_or_warned_and_a_missing_texture_is_one_warning() {
    let png = red_over_blue_png();
    // The left quad's texture is missing; the right one's is scaled,
    // offset and clamped, and bump-multiplied (which means nothing here).
    let obj = TEXTURED_OBJ.replace("f 2/5", "usemtl Opt\nf 2/5");
    let mtl = "newmtl Tex\nKd 0.5 0.5 0.5\nmap_Kd missing.png\n\
               newmtl Opt\nKd 1 1 1\nmap_Kd -s 2 2 1 -o 0.5 0 0 -clamp on -bm 0.3 tex.png\n\
               newmtl Lamp\nKe 1 1 1\n";
    let (dir, said) = baked_obj(&obj, mtl, &[("tex.png", &png)]);
    let lines: Vec<&str> = said
        .lines()
        .filter(|l| l.contains("lightmap's model"))
        .collect();
    assert_eq!(lines.len(), 2, "{said}");
    assert!(
        lines[0].starts_with("tex.mtl:3:1: warning:")
            && lines[0].contains("missing.png")
            && lines[0].contains("`Tex`")
            && lines[0].contains("keep `Kd` only"),
        "{said}"
    );
    assert!(
        lines[1].starts_with("tex.mtl:6:1: warning:")
            && lines[1].contains("`-bm 0.3`")
            && lines[1].contains("`Opt`"),
        "{said}"
    );
    let glb = Glb::read(&dir.path().join("model.glb"));
    // The material without its texture keeps Kd; its vt are kept.
    let tex = glb.material("Tex");
    assert!(tex["pbrMetallicRoughness"]
        .get("baseColorTexture")
        .is_none());
    assert_eq!(tex["pbrMetallicRoughness"]["baseColorFactor"][0], 0.5);
    for (pos, uv) in glb.triangles_uv0(&glb.primitives_of("Tex")[0]) {
        for k in 0..3 {
            let [u, v] = obj_vt(true, pos[k][0], pos[k][2]);
            assert_eq!(uv[k], [u, 1.0 - v]);
        }
    }
    // -s and -o: the texture is sampled at s × vt + o, then flipped;
    // -clamp on: a clamping sampler; Kd 1 stays 1 as a base colour.
    let opt = glb.material("Opt");
    assert_eq!(opt["pbrMetallicRoughness"]["baseColorFactor"][0], 1.0);
    let index = opt["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        .as_u64()
        .unwrap() as usize;
    let sampler = glb.json["textures"][index]["sampler"].as_u64().unwrap() as usize;
    assert_eq!(glb.json["samplers"][sampler]["wrapS"], 33071);
    assert_eq!(glb.json["samplers"][sampler]["wrapT"], 33071);
    for (pos, uv) in glb.triangles_uv0(&glb.primitives_of("Opt")[0]) {
        for k in 0..3 {
            let [u, v] = obj_vt(false, pos[k][0], pos[k][2]);
            assert_eq!(uv[k], [2.0 * u + 0.5, 1.0 - 2.0 * v]);
        }
    }
}

#[test]
fn a_double_sided_gltf_face_gets_a_back_with_its_own_light() {
    // A 2 × 2 floor at z = 0 facing +z, its material two-sided, under a
    // one-sided lamp at z = 1 facing down: the floor's top is lit, its
    // underside faces nothing.
    let mut doc = support::Doc::new();
    let floor = doc.material(serde_json::json!({"name": "Floor", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}}));
    let lamp = doc.material(serde_json::json!({"name": "Lamp"}));
    let floor_square = doc.square(Some(floor), true);
    let lamp_square = doc.square(Some(lamp), true);
    let floor_mesh = doc.mesh("Floor", vec![floor_square]);
    let lamp_mesh = doc.mesh("Lamp", vec![lamp_square]);
    let nodes = [
        doc.node(serde_json::json!({"name": "Floor", "mesh": floor_mesh,
            "translation": [-1.0, -1.0, 0.0], "scale": [2.0, 2.0, 1.0]})),
        // Half a turn about x: the square faces -z, over [-0.2, 0.2]².
        doc.node(serde_json::json!({"name": "Lamp", "mesh": lamp_mesh,
            "translation": [-0.2, 0.2, 1.0], "rotation": [1.0, 0.0, 0.0, 0.0],
            "scale": [0.4, 0.4, 1.0]})),
    ];
    doc.scene(&nodes);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("floor.glb"), doc.glb()).unwrap();
    let out = run_in(
        dir.path(),
        &[
            "floor.glb",
            "--emit",
            "Lamp=10",
            "-o",
            "floor.png",
            "--lightmap",
            "baked.glb",
            "--lightmap-density",
            "32",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let glb = Glb::read(&dir.path().join("baked.glb"));
    // Each side is drawn by its own triangles, so the material is no
    // longer two-sided; the one-sided lamp gets no back.
    assert!(glb.material("Floor").get("doubleSided").is_none());
    let image = glb.lightmap();
    let mut floor_triangles = Vec::new();
    for p in glb.primitives_of("Floor") {
        let pos = glb.floats(p["attributes"]["POSITION"].as_u64().unwrap());
        let uv = glb.floats(p["attributes"]["TEXCOORD_1"].as_u64().unwrap());
        let idx = glb.floats(p["indices"].as_u64().unwrap());
        for t in idx.chunks_exact(3) {
            let i = [t[0], t[1], t[2]].map(|i| i as usize);
            floor_triangles.push((
                [0, 1, 2].map(|k| [pos[3 * i[k]], pos[3 * i[k] + 1], pos[3 * i[k] + 2]]),
                [0, 1, 2].map(|k| [uv[2 * i[k]], uv[2 * i[k] + 1]]),
            ));
        }
    }
    assert_eq!(floor_triangles.len(), 4);
    let lamp_triangles: usize = glb
        .primitives_of("Lamp")
        .iter()
        .map(|p| glb.floats(p["indices"].as_u64().unwrap()).len() / 3)
        .sum();
    assert_eq!(lamp_triangles, 2);
    // The light at (x, y) on the side facing +z (`up`) or -z.
    let light = |x: f32, y: f32, up: bool| {
        for (pos, uv) in &floor_triangles {
            let n = cross(sub(pos[1], pos[0]), sub(pos[2], pos[0]));
            if (n[2] > 0.0) != up {
                continue;
            }
            let area = |a: [f32; 3], b: [f32; 3], c: [f32; 2]| {
                (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
            };
            let p = [x, y];
            let total = area(pos[0], pos[1], [pos[2][0], pos[2][1]]);
            let w = [
                area(pos[1], pos[2], p) / total,
                area(pos[2], pos[0], p) / total,
                area(pos[0], pos[1], p) / total,
            ];
            if w.iter().all(|&x| x >= 0.0) {
                let at = [0, 1].map(|k| w[0] * uv[0][k] + w[1] * uv[1][k] + w[2] * uv[2][k]);
                return brightness_at(&image, at);
            }
        }
        panic!("no floor triangle facing {up} holds ({x}, {y})");
    };
    for (x, y) in [(0.1, 0.1), (-0.5, 0.3), (0.6, -0.6)] {
        let (top, under) = (light(x, y, true), light(x, y, false));
        assert!(
            top > 50.0 && under < 2.0,
            "({x}, {y}): top {top}, underside {under}"
        );
    }
}
