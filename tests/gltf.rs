//! glTF import: small documents written as exporters write them, loaded
//! through the library and the program.

mod common;
#[path = "support/gltf.rs"]
mod support;

use common::{run_in, stderr};
use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::scene::parse_gltf;
use radiosity::scene::{self, CameraSource, GroupKind, LoadError, Scene};
use serde_json::json;
use support::{png_data_uri, Doc};

/// No external files: every test document embeds its data.
fn no_files(name: &str) -> Result<Vec<u8>, String> {
    Err(format!("cannot read {name}: no such file"))
}

fn load(bytes: &[u8]) -> Result<Scene, LoadError> {
    parse_gltf(bytes, "m.glb", &no_files)
}

fn errors(bytes: &[u8]) -> Vec<String> {
    match load(bytes) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.diagnostics.iter().map(|d| d.to_string()).collect(),
    }
}

fn warnings(s: &Scene) -> Vec<String> {
    s.warnings.iter().map(|w| w.to_string()).collect()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

/// A document with one square node of material `m` (a grey one when
/// `None` is given as the material JSON).
fn square_doc(material: Option<serde_json::Value>) -> Doc {
    let mut d = Doc::new();
    let m = material.map(|m| d.material(m));
    let p = d.square(m, true);
    let mesh = d.mesh("Plane", vec![p]);
    let n = d.node(json!({"name": "Plane", "mesh": mesh}));
    d.scene(&[n]);
    d
}

#[test]
fn a_square_under_translated_rotated_scaled_nodes_lands_where_expected() {
    let mut d = Doc::new();
    let p = d.square(None, false);
    let mesh = d.mesh("Plane", vec![p]);
    // Child: scale 2, then 90 degrees about +y, then up by (1, 2, 3).
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let child = d.node(json!({
        "name": "Tile", "mesh": mesh,
        "translation": [1.0, 2.0, 3.0], "rotation": [0.0, s, 0.0, s], "scale": [2.0, 2.0, 2.0],
    }));
    // Parent: a column-major matrix moving by +10 in x.
    let parent = d.node(json!({
        "name": "Floor", "children": [child],
        "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1],
    }));
    d.scene(&[parent]);
    for bytes in [d.glb(), d.gltf()] {
        let s = load(&bytes).unwrap();
        assert_eq!(s.polygons.len(), 2);
        // (x, y, z) -> (10 + 1 + 2z, 2 + 2y, 3 - 2x).
        let t = |x: f32, y: f32, z: f32| Vec3::new(11.0 + 2.0 * z, 2.0 + 2.0 * y, 3.0 - 2.0 * x);
        let expected = [
            [t(0., 0., 0.), t(1., 0., 0.), t(1., 1., 0.)],
            [t(0., 0., 0.), t(1., 1., 0.), t(0., 1., 0.)],
        ];
        for (p, e) in s.polygons.iter().zip(expected) {
            for (v, w) in p.vertices.iter().zip(e) {
                assert!(close(*v, w), "{v} != {w}");
            }
            // +z turned 90 degrees about +y is +x.
            assert!(close(p.normal, Vec3::X), "{}", p.normal);
            assert!((p.area - 2.0).abs() < 1e-5, "area {}", p.area);
        }
        // Named after the node with the mesh, and the mesh.
        let names: Vec<(GroupKind, &str, usize)> = s
            .groups
            .iter()
            .map(|g| (g.kind, g.name.as_str(), g.polygons.len()))
            .collect();
        assert_eq!(
            names,
            [
                (GroupKind::Object, "Tile", 2),
                (GroupKind::Mesh, "Plane", 2)
            ]
        );
    }
}

#[test]
fn a_mirroring_node_keeps_fronts_in_front() {
    let mut d = Doc::new();
    let p = d.square(None, false);
    let mesh = d.mesh("Plane", vec![p]);
    let n = d.node(json!({"mesh": mesh, "scale": [-1.0, 1.0, 1.0]}));
    d.scene(&[n]);
    let s = load(&d.glb()).unwrap();
    for p in &s.polygons {
        assert!(close(p.normal, Vec3::Z), "{}", p.normal);
        assert!(p.vertices.iter().all(|v| v.x <= 0.0));
    }
}

#[test]
fn materials_give_reflectance_emission_and_sides() {
    let mut d = Doc::new();
    let paint = d.material(json!({
        "name": "Paint", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1.0], "metallicFactor": 0.0},
    }));
    let lamp = d.material(json!({
        "name": "Lamp",
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
        "emissiveFactor": [1.0, 0.5, 0.25],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
    }));
    let white =
        d.material(json!({"name": "White", "pbrMetallicRoughness": {"metallicFactor": 0.0}}));
    let chrome = d.material(json!({"name": "Chrome"}));
    let mut prims = Vec::new();
    for (k, m) in [paint, lamp, white, chrome].into_iter().enumerate() {
        prims.push(d.square_at(Some(m), false, 2.0 * k as f32));
    }
    prims.push(d.square_at(None, false, 8.0));
    let mesh = d.mesh("Things", prims);
    let n = d.node(json!({"name": "Things", "mesh": mesh}));
    d.scene(&[n]);
    d.json["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
    let s = load(&d.gltf()).unwrap();
    let m = |i: usize| &s.materials[i];
    assert_eq!(m(0).reflectance(), Rgb::new(0.5, 0.25, 0.125));
    assert!(m(0).emission().is_black());
    assert_eq!(m(1).emission(), Rgb::new(4.0, 2.0, 1.0));
    assert!(m(1).reflectance().is_black());
    // glTF's default white is capped like an MTL's Kd 1.
    assert_eq!(m(2).reflectance(), Rgb::splat(0.95));
    assert_eq!(m(4).name, "(no material)");
    assert_eq!(m(4).reflectance(), Rgb::splat(0.8));
    let sides: Vec<bool> = s
        .polygons
        .iter()
        .step_by(2)
        .map(|p| p.surface.two_sided)
        .collect();
    assert_eq!(sides, [true, false, false, false, false]);
    assert_eq!(
        warnings(&s),
        [
            "m.glb: warning: base colour reflects all light or more in White, Chrome: scaled so \
             the brightest channel is 0.95, keeping the hue",
            "m.glb: warning: treated as diffuse: Chrome (metallic 1)",
        ]
    );
}

#[test]
fn textures_multiply_the_factors_by_their_linear_average() {
    let mut d = Doc::new();
    // Half white, half black: linear average 0.5.
    let uri = png_data_uri(2, &[[255, 255, 255], [0, 0, 0]]);
    d.json["images"] = json!([{"uri": uri}]);
    d.json["textures"] = json!([{"source": 0}]);
    let m = d.material(json!({
        "name": "Tiles",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.75, 0.75, 0.75, 1.0], "metallicFactor": 0.0,
            "baseColorTexture": {"index": 0},
        },
        "emissiveFactor": [2.0, 2.0, 2.0],
        "emissiveTexture": {"index": 0},
    }));
    let p = d.square(Some(m), false);
    let mesh = d.mesh("Plane", vec![p]);
    let n = d.node(json!({"mesh": mesh}));
    d.scene(&[n]);
    let s = load(&d.glb()).unwrap();
    let mat = &s.materials[0];
    assert!(
        (mat.emission().r - 1.0).abs() < 1e-9,
        "{:?}",
        mat.emission()
    );
    // Reflects and emits: the emission's colour, the reflectance's luminance.
    assert!((mat.reflectance().luminance() - 0.375).abs() < 1e-9);
    assert!(warnings(&s).is_empty(), "{:?}", warnings(&s));

    // An unreadable texture keeps the factor, with one warning.
    d.json["images"] = json!([{"uri": "missing.png"}]);
    let s = load(&d.glb()).unwrap();
    assert_eq!(s.materials[0].emission(), Rgb::splat(2.0));
    let w = warnings(&s);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(
            "m.glb: warning: cannot read 2 texture(s), the first materials[0].baseColorTexture: \
             images[0] (material `Tiles`): cannot read missing.png"
        ),
        "{w:?}"
    );
}

#[test]
fn indexed_primitives_with_normals_are_smooth_surfaces_one_per_instance() {
    let mut d = Doc::new();
    let smooth = d.square(None, true);
    let mesh = d.mesh("Smooth", vec![smooth]);
    let faceted = d.square(None, false);
    let flat = d.mesh("Flat", vec![faceted]);
    let a = d.node(json!({"name": "A", "mesh": mesh}));
    let b = d.node(json!({"name": "B", "mesh": mesh, "translation": [2, 0, 0]}));
    let c = d.node(json!({"name": "C", "mesh": flat, "translation": [4, 0, 0]}));
    d.scene(&[a, b, c]);
    let s = load(&d.glb()).unwrap();
    let ids: Vec<Option<u32>> = s
        .polygons
        .iter()
        .map(|p| p.surface.smooth.map(|id| id.0))
        .collect();
    assert_eq!(ids, [Some(0), Some(0), Some(1), Some(1), None, None]);
    // The mesh drawn twice is one name for both instances.
    let smooth_group = s.groups.iter().find(|g| g.name == "Smooth").unwrap();
    assert_eq!(smooth_group.polygons.len(), 4);
}

#[test]
fn the_first_perspective_camera_is_the_camera() {
    let mut d = square_doc(None);
    d.json["cameras"] = json!([
        {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
        {"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}},
    ]);
    let ortho = d.node(json!({"camera": 0}));
    let cam = d.node(json!({"name": "Camera", "camera": 1, "translation": [0.5, 0.5, 4.0]}));
    d.json["scenes"][0]["nodes"] = json!([0, ortho, cam]);
    let s = load(&d.glb()).unwrap();
    assert_eq!(s.camera_source, CameraSource::File);
    assert_eq!(s.camera.fov_y, 0.7);
    assert_eq!((s.camera.width, s.camera.height), (720, 480));
    assert!(close(s.camera.eye, Vec3::new(0.5, 0.5, 4.0)));
    // Looking along -z, at the depth of the square's centre.
    assert!(
        close(s.camera.lookat, Vec3::new(0.5, 0.5, 0.0)),
        "{}",
        s.camera.lookat
    );
    assert!(s.camera.up.dot(Vec3::Y) > 0.99);
    // Without a camera, the automatic one.
    let s = load(&square_doc(None).glb()).unwrap();
    assert_eq!(s.camera_source, CameraSource::AutoFramed);
}

#[test]
fn strips_and_fans_become_triangles_facing_one_way() {
    let mut d = Doc::new();
    // A strip along x: 0 1 / 2 3 zig-zag, and a fan around a centre.
    let strip = d.floats(&[0., 0., 0., 0., 1., 0., 1., 0., 0., 1., 1., 0.], "VEC3");
    let fan = d.floats(
        &[0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1., 1., -1., 0.5, 1.],
        "VEC3",
    );
    // The strip runs clockwise seen from +z at its first triangle, so
    // it faces -z; the fan runs counter-clockwise and faces +z.
    let mesh = d.mesh(
        "Strips",
        vec![
            json!({"attributes": {"POSITION": strip}, "mode": 5}),
            json!({"attributes": {"POSITION": fan}, "mode": 6}),
        ],
    );
    let n = d.node(json!({"mesh": mesh}));
    d.scene(&[n]);
    let s = load(&d.glb()).unwrap();
    let normals: Vec<Vec3> = s.polygons.iter().map(|p| p.normal).collect();
    assert_eq!(normals.len(), 2 + 3);
    assert!(
        normals[..2].iter().all(|n| close(*n, -Vec3::Z)),
        "{normals:?}"
    );
    assert!(
        normals[2..].iter().all(|n| close(*n, Vec3::Z)),
        "{normals:?}"
    );
    let area: f64 = s.polygons.iter().map(|p| p.area).sum();
    assert!((area - (1.0 + 1.0 + 0.5)).abs() < 1e-5, "area {area}");
}

#[test]
fn points_and_lines_are_refused_with_their_json_path() {
    let mut d = Doc::new();
    let pos = d.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    let mesh = d.mesh(
        "Cloud",
        vec![json!({"attributes": {"POSITION": pos}, "mode": 0})],
    );
    let n = d.node(json!({"mesh": mesh}));
    d.scene(&[n]);
    assert_eq!(
        errors(&d.glb()),
        [
            "m.glb: error: meshes[0].primitives[0]: 1 primitive(s) of points or lines skipped \
          (the first meshes[0].primitives[0], mode Points): only triangles are surfaces"
        ]
    );
    // Beside triangles, a line primitive is skipped with a warning.
    let square = d.square(None, false);
    d.json["meshes"][0]["primitives"] =
        json!([{"attributes": {"POSITION": pos}, "mode": 1}, square]);
    let s = load(&d.glb()).unwrap();
    assert_eq!(s.polygons.len(), 2);
    assert_eq!(
        warnings(&s),
        [
            "m.glb: warning: 1 primitive(s) of points or lines skipped (the first \
          meshes[0].primitives[0], mode Lines): only triangles are surfaces"
        ]
    );
}

#[test]
fn punctual_lights_warn_and_say_how_to_light_the_model() {
    let mut d = square_doc(None);
    d.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    d.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"name": "Sun", "type": "directional", "intensity": 3.0},
    ]}});
    let light = d.node(json!({"name": "Sun", "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    d.json["scenes"][0]["nodes"] = json!([0, light]);
    let s = load(&d.glb()).unwrap();
    assert_eq!(
        warnings(&s),
        ["m.glb: warning: 1 KHR_lights_punctual light(s) ignored (the first `Sun` at nodes[1]): \
          a point, spot or sun light is not a polygon and gives no light here; make a surface \
          emit with --emit NAME=VALUE, or light the model from all around with --sky VALUE"]
    );
}

#[test]
fn degenerate_triangles_are_dropped_with_one_warning() {
    let mut d = Doc::new();
    let pos = d.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 2., 0., 0.], "VEC3");
    let idx = d.indices(&[0, 1, 2, 0, 1, 3, 0, 0, 2, 0, 1, 3]);
    let mesh = d.mesh(
        "M",
        vec![json!({"attributes": {"POSITION": pos}, "indices": idx})],
    );
    let n = d.node(json!({"mesh": mesh}));
    d.scene(&[n]);
    let s = load(&d.glb()).unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(
        warnings(&s),
        ["m.glb: warning: dropped 3 degenerate triangle(s) (no area, or a vertex repeated); the \
          first meshes[0].primitives[0] (nodes[0]), triangle 1: polygon has zero area"]
    );
}

#[test]
fn broken_files_are_refused_with_the_json_path() {
    // An index beyond the vertices.
    let mut d = square_doc(None);
    let bad = d.indices(&[0, 1, 7]);
    d.json["meshes"][0]["primitives"][0]["indices"] = json!(bad);
    assert_eq!(
        errors(&d.glb()),
        [
            "m.glb: error: meshes[0].primitives[0].indices: index 7 (element 2) is out of range: \
          POSITION has 4 vertices"
        ]
    );
    // POSITION of the wrong component type.
    let mut d = square_doc(None);
    d.json["accessors"][0]["componentType"] = json!(5123);
    assert_eq!(
        errors(&d.glb()),
        [
            "m.glb: error: meshes[0].primitives[0].attributes[\"POSITION\"]: accessors[0] is Vec3 \
          of U16; expected Vec3 of F32"
        ]
    );
    // No POSITION at all.
    let mut d = square_doc(None);
    d.json["meshes"][0]["primitives"][0]["attributes"] = json!({"NORMAL": 2});
    assert_eq!(
        errors(&d.glb()),
        ["m.glb: error: meshes[0].primitives[0].attributes[\"POSITION\"]: required but missing"]
    );
    // An accessor reaching past its view.
    let mut d = square_doc(None);
    d.json["accessors"][0]["count"] = json!(400);
    assert_eq!(
        errors(&d.glb()),
        [
            "m.glb: error: meshes[0].primitives[0].attributes[\"POSITION\"]: accessors[0]: 400 \
          elements of 12 bytes (stride 12) from byte 0 do not fit in bufferViews[0] (48 bytes)"
        ]
    );
    // A buffer file that is not there.
    let d = square_doc(None);
    let e = errors(&d.gltf_external("model.bin"));
    assert_eq!(
        e,
        [
            "m.glb: error: meshes[0].primitives[0].attributes[\"POSITION\"]: buffers[0]: cannot \
          read model.bin: no such file"
        ]
    );
    // A truncated glb.
    let glb = d.glb();
    assert_eq!(
        errors(&glb[..glb.len() - 10]),
        [format!(
            "m.glb: error: glb, byte 8: the header says {} bytes but the file has {} (truncated?)",
            glb.len(),
            glb.len() - 10
        )]
    );
    // A JSON mistake in a .gltf has its line and column.
    let e = errors(b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [\n");
    assert_eq!(e.len(), 1);
    assert!(
        e[0].starts_with("m.glb:4:1: error: invalid glTF JSON: EOF"),
        "{e:?}"
    );
    // A required extension that cannot be read.
    let mut d = square_doc(None);
    d.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    assert_eq!(
        errors(&d.glb()),
        ["m.glb: error: extensionsRequired[0] = \"KHR_draco_mesh_compression\": not supported"]
    );
    // A node that is its own child.
    let mut d = square_doc(None);
    d.json["nodes"][0]["children"] = json!([0]);
    let e = errors(&d.glb());
    assert!(
        e[0].starts_with("m.glb: error: nodes[0]: the node is reached twice"),
        "{e:?}"
    );
}

#[test]
fn external_buffers_are_read_next_to_the_file_and_extensions_in_any_case() {
    let dir = tempfile::tempdir().unwrap();
    let d = square_doc(None);
    std::fs::write(dir.path().join("my model.bin"), &d.bin).unwrap();
    let path = dir.path().join("Model.GLTF");
    std::fs::write(&path, d.gltf_external("my%20model.bin")).unwrap();
    let s = scene::load(&path).unwrap();
    assert_eq!(s.polygons.len(), 2);
    let glb = dir.path().join("m.GLB");
    std::fs::write(&glb, d.glb()).unwrap();
    assert_eq!(scene::load(&glb).unwrap().polygons, s.polygons);
}

#[test]
fn a_glb_with_an_emissive_material_renders_a_lit_picture() {
    // A floor and a lamp above it, as Blender exports a scene without a
    // camera: the lamp emits through its material.
    let mut d = Doc::new();
    let floor_m = d.material(json!({"name": "Floor", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0}}));
    let lamp_m = d.material(json!({"name": "LampGlow", "emissiveFactor": [1, 1, 1],
        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}));
    let floor_p = d.square(Some(floor_m), true);
    let lamp_p = d.square(Some(lamp_m), true);
    let floor = d.mesh("Floor", vec![floor_p]);
    let lamp = d.mesh("Lamp", vec![lamp_p]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // The floor's square turned to face +y (at y = 0), 4 m wide; the
    // lamp's to face -y at y = 1, 1 m wide, over the floor's middle.
    let a = d.node(json!({"name": "Floor", "mesh": floor,
        "rotation": [-s, 0, 0, s], "scale": [4, 4, 4], "translation": [-2, 0, 2]}));
    let b = d.node(json!({"name": "Lamp", "mesh": lamp,
        "rotation": [s, 0, 0, s], "translation": [-0.5, 1, -0.5]}));
    // A camera 2 m up and 4 m back, looking 25 degrees down at the floor.
    let (sin, cos) = (-12.5f32.to_radians().sin(), 12.5f32.to_radians().cos());
    d.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    let c = d.node(json!({"name": "Camera", "camera": 0,
        "translation": [0, 2, 4], "rotation": [sin, 0, 0, cos]}));
    d.scene(&[a, b, c]);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lamp.glb"), d.glb()).unwrap();
    let out = run_in(dir.path(), &["lamp.glb", "-o", "lamp.png", "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    let img = image::open(dir.path().join("lamp.png")).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 30)).count();
    let fraction = lit as f64 / (img.width() * img.height()) as f64;
    assert!(fraction > 0.1, "only {fraction} of the pixels are lit");

    // Without its emission, the same model says so and names the lamp.
    d.json["materials"][1]["emissiveFactor"] = json!([0, 0, 0]);
    std::fs::write(dir.path().join("dark.glb"), d.glb()).unwrap();
    let out = run_in(dir.path(), &["dark.glb", "-o", "dark.png", "--quiet"]);
    let err = stderr(&out);
    assert!(
        err.contains("object `Lamp`, mesh `Lamp`, material `LampGlow` look like lamps"),
        "{err}"
    );
    // --emit by node name lights it again.
    let out = run_in(
        dir.path(),
        &["dark.glb", "-o", "dark.png", "--quiet", "--emit", "Lamp=1"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn an_exported_glb_reads_back_as_the_same_triangles() {
    use radiosity::mesh::{self, MeshOptions};
    use radiosity::output::write_mesh;
    let scene = scene::load(&common::scene("cornell.sc")).unwrap();
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: 150.0,
            inset: 0.05,
        },
    )
    .unwrap();
    let radiosity = vec![Rgb::splat(0.5); mesh.vertex_count()];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cornell.glb");
    write_mesh(&path, &scene, &mesh, &radiosity, 1.0, "cornell").unwrap();
    let back = scene::load(&path).unwrap();
    let key = |v: [Vec3; 3]| v.map(|p| p.to_array().map(f32::to_bits));
    let mut exported: Vec<_> = mesh
        .elements
        .iter()
        .flat_map(|e| e.triangles())
        .map(|t| key(t.map(|v| mesh.positions[v.0 as usize])))
        .collect();
    let mut imported: Vec<_> = back
        .polygons
        .iter()
        .map(|p| key([p.vertices[0], p.vertices[1], p.vertices[2]]))
        .collect();
    assert!(back.polygons.iter().all(|p| p.vertices.len() == 3));
    exported.sort_unstable();
    imported.sort_unstable();
    assert_eq!(imported.len(), exported.len());
    assert!(imported == exported, "the triangles differ");
}
