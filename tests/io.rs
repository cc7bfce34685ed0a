//! Whole-program tests of the model formats: OBJ + MTL import, glTF and
//! PLY export of the solved mesh, and the convergence log and plot.

mod common;

use common::{listing, read_json, run_in, scene, stderr, write};
use radiosity::color::Rgb;
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::output::convergence::{LOG_HEADER, PLOT_SIZE};
use radiosity::output::mesh_export::RADIOSITY_ATTRIBUTE;
use radiosity::output::write_mesh;
use radiosity::render::srgb8;
use radiosity::scene::{self, Scene};
use radiosity::solver::{Progressive, SolverOptions};
use radiosity::visibility::Visibility;
use std::collections::BTreeSet;
use std::path::Path;

/// The Cornell box of `scenes/cornell.sc` as Blender would export it: one
/// object per wall with its own vertices, the blocks with shared vertices
/// (the tall one by negative indices), normals and smoothing lines that
/// the importer ignores.
const CORNELL_OBJ: &str = "\
# Blender 4.1.1
# www.blender.org
mtllib cornell.mtl
o floor
v 552.800000 0.000000 0.000000
v 0.000000 0.000000 0.000000
v 0.000000 0.000000 559.200000
v 549.600000 0.000000 559.200000
vn 0.0000 1.0000 0.0000
s 0
usemtl white
f 1//1 2//1 3//1 4//1
o light
v 343.000000 548.300000 227.000000
v 343.000000 548.300000 332.000000
v 213.000000 548.300000 332.000000
v 213.000000 548.300000 227.000000
vn 0.0000 1.0000 0.0000
s 0
usemtl light
f 5//2 6//2 7//2 8//2
o ceiling
v 556.000000 548.800000 0.000000
v 556.000000 548.800000 559.200000
v 0.000000 548.800000 559.200000
v 0.000000 548.800000 0.000000
vn 0.0000 1.0000 0.0000
s 0
usemtl white
f 9//3 10//3 11//3 12//3
o back_wall
v 549.600000 0.000000 559.200000
v 0.000000 0.000000 559.200000
v 0.000000 548.800000 559.200000
v 556.000000 548.800000 559.200000
vn 0.0000 1.0000 0.0000
s 0
usemtl white
f 13//4 14//4 15//4 16//4
o green_wall
v 0.000000 0.000000 559.200000
v 0.000000 0.000000 0.000000
v 0.000000 548.800000 0.000000
v 0.000000 548.800000 559.200000
vn 0.0000 1.0000 0.0000
s 0
usemtl green
f 17//5 18//5 19//5 20//5
o red_wall
v 552.800000 0.000000 0.000000
v 549.600000 0.000000 559.200000
v 552.800000 548.800000 559.200000
v 556.000000 548.800000 0.000000
vn 0.0000 1.0000 0.0000
s 0
usemtl red
f 21//6 22//6 23//6 24//6
o short_block
v 130.000000 165.000000 65.000000
v 82.000000 165.000000 225.000000
v 240.000000 165.000000 272.000000
v 290.000000 165.000000 114.000000
v 290.000000 0.000000 114.000000
v 240.000000 0.000000 272.000000
v 130.000000 0.000000 65.000000
v 82.000000 0.000000 225.000000
usemtl white
f 25 26 27 28
f 29 28 27 30
f 31 25 28 29
f 32 26 25 31
f 30 27 26 32
o tall_block
v 423.000000 330.000000 247.000000
v 265.000000 330.000000 296.000000
v 314.000000 330.000000 456.000000
v 472.000000 330.000000 406.000000
v 423.000000 0.000000 247.000000
v 472.000000 0.000000 406.000000
v 314.000000 0.000000 456.000000
v 265.000000 0.000000 296.000000
usemtl white
f -8 -7 -6 -5
f -4 -8 -5 -3
f -3 -5 -6 -2
f -2 -6 -7 -1
f -1 -7 -8 -4
";

const CORNELL_MTL: &str = "\
# Blender 4.1.1 MTL File: 'cornell.blend'
# Material Count: 4

newmtl white
Ns 250.000000
Ka 1.000000 1.000000 1.000000
Kd 0.73 0.73 0.73
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
Ni 1.450000
d 1.000000
illum 2

newmtl red
Ns 250.000000
Kd 0.63 0.065 0.05
Ks 0.500000 0.500000 0.500000
illum 2

newmtl green
Kd 0.14 0.45 0.091
illum 2

newmtl light
Kd 0.000000 0.000000 0.000000
Ke 17 11.9 4.25
illum 2
";

/// Relative tolerance of comparisons between quantities computed from the
/// same decimal input along two paths (f32 vertices, f64 sums).
const SAME_VALUE_TOLERANCE: f64 = 1e-9;

fn write_cornell_obj(dir: &Path) -> std::path::PathBuf {
    write(dir, "cornell.mtl", CORNELL_MTL);
    write(dir, "cornell.obj", CORNELL_OBJ)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME_VALUE_TOLERANCE * a.abs().max(b.abs()).max(1.0)
}

fn close_rgb(a: Rgb, b: Rgb) -> bool {
    a.to_array()
        .iter()
        .zip(b.to_array())
        .all(|(&x, y)| close(x, y))
}

#[test]
fn cornell_obj_loads_to_the_polygons_and_materials_of_cornell_sc() {
    let dir = tempfile::tempdir().unwrap();
    let obj = scene::load(&write_cornell_obj(dir.path())).unwrap();
    let sc = scene::load(&scene("cornell.sc")).unwrap();
    assert_eq!(obj.polygons.len(), sc.polygons.len());
    for (i, (a, b)) in obj.polygons.iter().zip(&sc.polygons).enumerate() {
        assert_eq!(a.vertices, b.vertices, "polygon {i}");
        assert_eq!(a.shape, b.shape, "polygon {i}");
        assert!(
            close(a.area, b.area),
            "polygon {i}: {} vs {}",
            a.area,
            b.area
        );
        assert!((a.normal - b.normal).length() < 1e-6, "polygon {i}");
        let (ma, mb) = (
            &obj.materials[a.material.index()],
            &sc.materials[b.material.index()],
        );
        assert_eq!(ma.name, mb.name, "polygon {i}");
        assert!(
            close_rgb(ma.reflectance(), mb.reflectance()),
            "polygon {i}: {ma:?} vs {mb:?}"
        );
        assert!(
            close_rgb(ma.emission(), mb.emission()),
            "polygon {i}: {ma:?} vs {mb:?}"
        );
    }
    let emitters = |s: &Scene| -> BTreeSet<usize> {
        (0..s.polygons.len())
            .filter(|&i| {
                !s.materials[s.polygons[i].material.index()]
                    .emission()
                    .is_black()
            })
            .collect()
    };
    assert_eq!(emitters(&obj), BTreeSet::from([1]));
    assert_eq!(emitters(&obj), emitters(&sc));
    let total = |s: &Scene| s.polygons.iter().map(|p| p.area).sum::<f64>();
    assert!(close(total(&obj), total(&sc)));
    // No camera in an OBJ: framed around the model.
    assert_eq!(obj.camera_source, scene::CameraSource::AutoFramed);
}

/// A small solved Cornell box: the scene, its mesh and radiosity after a
/// few steps.
fn solved_cornell() -> (Scene, Mesh, Vec<Rgb>) {
    let scene = scene::load(&scene("cornell.sc")).unwrap();
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: 60.0,
            inset: 0.05,
        },
    )
    .unwrap();
    let visibility = Visibility::new(&scene);
    let mut solver = Progressive::new(
        &scene,
        &mesh,
        &visibility,
        SolverOptions {
            max_steps: Some(6),
            ..SolverOptions::default()
        },
    );
    while !solver.is_done() {
        solver.step();
    }
    assert_eq!(solver.steps(), 6);
    let radiosity = solver.radiosity().to_vec();
    (scene, mesh, radiosity)
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// The checks of the Khronos glTF validator that concern a file like
/// ours, done offline: the GLB container, buffer and view bounds and
/// alignment, accessor sizes, POSITION min/max equal to the data, index
/// range, colour range. Returns the JSON and the binary chunk.
fn validate_glb(bytes: &[u8]) -> (serde_json::Value, Vec<u8>) {
    assert!(
        bytes.len() >= 28 && bytes.len().is_multiple_of(4),
        "GLB length {}",
        bytes.len()
    );
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32_at(bytes, 4), 2, "GLB version");
    assert_eq!(u32_at(bytes, 8) as usize, bytes.len(), "header length");
    let json_len = u32_at(bytes, 12) as usize;
    assert_eq!(&bytes[16..20], b"JSON", "first chunk is JSON");
    assert_eq!(json_len % 4, 0, "JSON chunk padded to 4 bytes");
    let json = &bytes[20..20 + json_len];
    assert!(std::str::from_utf8(json).is_ok(), "JSON chunk is UTF-8");
    let doc: serde_json::Value = serde_json::from_slice(json).unwrap();
    let at = 20 + json_len;
    let bin_len = u32_at(bytes, at) as usize;
    assert_eq!(&bytes[at + 4..at + 8], b"BIN\0", "second chunk is BIN");
    assert_eq!(bin_len % 4, 0, "BIN chunk padded to 4 bytes");
    assert_eq!(at + 8 + bin_len, bytes.len(), "nothing after the BIN chunk");
    let bin = bytes[at + 8..].to_vec();

    assert_eq!(doc["asset"]["version"], "2.0");
    let buffers = doc["buffers"].as_array().unwrap();
    assert_eq!(buffers.len(), 1);
    assert!(buffers[0].get("uri").is_none(), "GLB buffer has no uri");
    let buffer_len = buffers[0]["byteLength"].as_u64().unwrap() as usize;
    assert!(
        buffer_len <= bin_len && bin_len - buffer_len < 4,
        "BIN chunk vs buffer"
    );

    let views = doc["bufferViews"].as_array().unwrap();
    for (i, v) in views.iter().enumerate() {
        let offset = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        let length = v["byteLength"].as_u64().unwrap() as usize;
        assert!(length > 0, "view {i} is empty");
        assert_eq!(offset % 4, 0, "view {i} is aligned");
        assert!(offset + length <= buffer_len, "view {i} fits its buffer");
        assert!(v.get("byteStride").is_none(), "view {i} is tightly packed");
    }
    let accessors = doc["accessors"].as_array().unwrap();
    let data = |a: &serde_json::Value| -> Vec<u8> {
        let view = &views[a["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let components = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC3" => 3,
            t => panic!("unexpected accessor type {t}"),
        };
        assert!(matches!(a["componentType"].as_u64(), Some(5126 | 5125)));
        let len = a["count"].as_u64().unwrap() as usize * components * 4;
        assert!(a["count"].as_u64().unwrap() >= 1);
        assert!(
            a["byteOffset"].as_u64().unwrap_or(0) as usize + len
                <= view["byteLength"].as_u64().unwrap() as usize,
            "accessor fits its view"
        );
        assert_eq!(offset % 4, 0, "accessor aligned to its component size");
        bin[offset..offset + len].to_vec()
    };
    // Every node names a mesh, every scene lists nodes, every primitive
    // has a material.
    let meshes = doc["meshes"].as_array().unwrap();
    let materials = doc["materials"].as_array().unwrap();
    let nodes = doc["nodes"].as_array().unwrap();
    for node in nodes {
        assert!(node["mesh"].as_u64().unwrap() < meshes.len() as u64);
        assert!(node["name"].as_str().is_some_and(|n| !n.is_empty()));
    }
    for n in doc["scenes"][0]["nodes"].as_array().unwrap() {
        assert!(n.as_u64().unwrap() < nodes.len() as u64);
    }
    for primitive in meshes
        .iter()
        .flat_map(|m| m["primitives"].as_array().unwrap())
    {
        assert!(primitive["material"].as_u64().unwrap() < materials.len() as u64);
        assert_eq!(primitive["mode"], 4);
        let attributes = primitive["attributes"].as_object().unwrap();
        let vertex_count = accessors[attributes["POSITION"].as_u64().unwrap() as usize]["count"]
            .as_u64()
            .unwrap();
        for (name, index) in attributes {
            let a = &accessors[index.as_u64().unwrap() as usize];
            assert_eq!(a["count"].as_u64().unwrap(), vertex_count, "{name} count");
            assert_eq!(a["type"], "VEC3", "{name}");
            assert_eq!(a["componentType"], 5126, "{name}");
            let view = &views[a["bufferView"].as_u64().unwrap() as usize];
            assert_eq!(view["target"], 34962, "{name} view is a vertex buffer");
            let values = f32s(&data(a));
            assert!(values.iter().all(|v| v.is_finite()), "{name} finite");
            if name == "COLOR_0" {
                assert!(
                    values.iter().all(|v| (0.0..=1.0).contains(v)),
                    "COLOR_0 in [0, 1]"
                );
            }
            if name == "NORMAL" {
                for n in values.chunks(3) {
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    assert!((len - 1.0).abs() < 5e-4, "NORMAL is unit length");
                }
            }
            if name == "POSITION" {
                let mut lo = [f32::INFINITY; 3];
                let mut hi = [f32::NEG_INFINITY; 3];
                for p in values.chunks(3) {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                let read = |key: &str| -> Vec<f32> {
                    a[key]
                        .as_array()
                        .unwrap_or_else(|| panic!("POSITION has {key}"))
                        .iter()
                        .map(|x| x.as_f64().unwrap() as f32)
                        .collect()
                };
                assert_eq!(read("min"), lo.to_vec(), "POSITION min equals the data");
                assert_eq!(read("max"), hi.to_vec(), "POSITION max equals the data");
            }
        }
        let indices = &accessors[primitive["indices"].as_u64().unwrap() as usize];
        assert_eq!(indices["componentType"], 5125);
        assert_eq!(indices["type"], "SCALAR");
        assert_eq!(indices["count"].as_u64().unwrap() % 3, 0);
        let view = &views[indices["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(view["target"], 34963, "index view is an element buffer");
        let idx = data(indices);
        assert!(idx
            .chunks_exact(4)
            .all(|c| (u32::from_le_bytes(c.try_into().unwrap()) as u64) < vertex_count));
    }
    (doc, bin)
}

#[test]
fn glb_reads_back_bit_for_bit() {
    let (scene, mesh, radiosity) = solved_cornell();
    let exposure = 0.37;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cornell.glb");
    write_mesh(&path, &scene, &mesh, &radiosity, exposure, "cornell").unwrap();
    let bytes = std::fs::read(&path).unwrap();
    validate_glb(&bytes);

    // Read with an independent glTF reader (which validates the JSON).
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    let doc = &gltf.document;
    assert_eq!(doc.scenes().count(), 1);
    assert_eq!(doc.default_scene().unwrap().name(), Some("cornell"));

    // A `.sc` scene names only materials: one node per material, in the
    // order the polygons first use them, each one primitive.
    let mut names: Vec<&str> = Vec::new();
    for p in &scene.polygons {
        let name = scene.materials[p.material.index()].name.as_str();
        if !names.contains(&name) {
            names.push(name);
        }
    }
    let nodes: Vec<_> = doc.default_scene().unwrap().nodes().collect();
    assert_eq!(
        nodes.iter().map(|n| n.name().unwrap()).collect::<Vec<_>>(),
        names
    );

    // Every element triangle of the solver's mesh, by its corners'
    // position bits: normal, display colour, radiosity and material of
    // each corner, to be found once in the file.
    type Corner = ([u32; 3], [u32; 3], [u32; 3]);
    type Triangles<'a> = Vec<(Vec<Corner>, &'a str)>;
    let mut expected: std::collections::HashMap<[[u32; 3]; 3], Triangles> =
        std::collections::HashMap::new();
    for (e, p) in mesh.elements.iter().zip(&mesh.element_polygon) {
        let material = scene.materials[scene.polygons[p.index()].material.index()]
            .name
            .as_str();
        for t in e.triangles() {
            let key = t.map(|v| mesh.positions[v.index()].to_array().map(f32::to_bits));
            let corners = t
                .iter()
                .map(|v| {
                    let r = radiosity[v.index()].to_f32();
                    (
                        mesh.polygons[p.index()].normal.to_array().map(f32::to_bits),
                        r.map(|c| (c * exposure).clamp(0.0, 1.0).to_bits()),
                        r.map(f32::to_bits),
                    )
                })
                .collect();
            expected.entry(key).or_default().push((corners, material));
        }
    }
    let total: usize = expected.values().map(Vec::len).sum();
    let mut found = 0;
    let radiosity_semantic =
        gltf::Semantic::Extras(RADIOSITY_ATTRIBUTE.trim_start_matches('_').to_string());
    for node in &nodes {
        let primitives: Vec<_> = node.mesh().unwrap().primitives().collect();
        assert_eq!(primitives.len(), 1, "{:?}", node.name());
        let primitive = &primitives[0];
        let material = primitive.material();
        assert_eq!(
            material.name(),
            node.name(),
            "material named as in the scene"
        );
        assert!(!material.unlit());
        let m = scene
            .materials
            .iter()
            .find(|m| Some(m.name.as_str()) == material.name())
            .unwrap();
        let rho = m.reflectance();
        let base = material.pbr_metallic_roughness().base_color_factor();
        assert_eq!(
            base,
            [rho.r as f32, rho.g as f32, rho.b as f32, 1.0],
            "baseColorFactor is the reflectance"
        );
        assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
        let reader = primitive.reader(|_| Some(blob));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let colors: Vec<[f32; 3]> = reader.read_colors(0).unwrap().into_rgb_f32().collect();
        let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        // The custom attribute, read through its accessor and view.
        let accessor = primitive.get(&radiosity_semantic).unwrap();
        assert_eq!(accessor.data_type(), gltf::accessor::DataType::F32);
        assert_eq!(accessor.dimensions(), gltf::accessor::Dimensions::Vec3);
        let view = accessor.view().unwrap();
        let start = view.offset() + accessor.offset();
        let raw = f32s(&blob[start..start + accessor.count() * 12]);
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        for t in indices.chunks(3) {
            let key = [0, 1, 2].map(|k| positions[t[k] as usize].map(f32::to_bits));
            let corners: Vec<Corner> = t
                .iter()
                .map(|&i| {
                    let i = i as usize;
                    (
                        normals[i].map(f32::to_bits),
                        colors[i].map(f32::to_bits),
                        [raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]].map(f32::to_bits),
                    )
                })
                .collect();
            let list = expected.get_mut(&key).expect("a triangle of the mesh");
            let at = list
                .iter()
                .position(|(c, name)| *c == corners && Some(*name) == material.name())
                .expect("same values and material as in the mesh");
            list.swap_remove(at);
            found += 1;
        }
    }
    assert_eq!(found, total, "every triangle once");
}

/// Two objects as Blender 3.x writes them: a cube whose top face has a
/// material of its own, and a lamp panel under the ceiling; shared
/// vertices, `vn`, `s off`.
const TWO_OBJECTS_OBJ: &str = "\
# Blender 3.6.5
# www.blender.org
mtllib two.mtl
o Cube
v 1.000000 1.000000 -1.000000
v 1.000000 -1.000000 -1.000000
v 1.000000 1.000000 1.000000
v 1.000000 -1.000000 1.000000
v -1.000000 1.000000 -1.000000
v -1.000000 -1.000000 -1.000000
v -1.000000 1.000000 1.000000
v -1.000000 -1.000000 1.000000
vn -0.0000 1.0000 -0.0000
vn -0.0000 -0.0000 1.0000
vn -1.0000 -0.0000 -0.0000
vn -0.0000 -1.0000 -0.0000
vn 1.0000 -0.0000 -0.0000
vn -0.0000 -0.0000 -1.0000
s off
usemtl Top
f 1//1 5//1 7//1 3//1
usemtl Material
f 4//2 3//2 7//2 8//2
f 8//3 7//3 5//3 6//3
f 6//4 2//4 4//4 8//4
f 2//5 1//5 3//5 4//5
f 6//6 5//6 1//6 2//6
o Lamp
v -0.500000 3.000000 0.500000
v 0.500000 3.000000 0.500000
v -0.500000 3.000000 -0.500000
v 0.500000 3.000000 -0.500000
vn -0.0000 -1.0000 -0.0000
s off
usemtl LampShade
f 9//7 11//7 12//7 10//7
";

const TWO_OBJECTS_MTL: &str = "\
# Blender 3.6.5 MTL File: 'None'
# www.blender.org

newmtl LampShade
Ns 250.000000
Ka 1.000000 1.000000 1.000000
Kd 0.800000 0.800000 0.800000
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
Ni 1.450000
d 1.000000
illum 2

newmtl Material
Ns 250.000000
Ka 1.000000 1.000000 1.000000
Kd 0.600000 0.300000 0.200000
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
Ni 1.450000
d 1.000000
illum 2

newmtl Top
Ns 250.000000
Ka 1.000000 1.000000 1.000000
Kd 0.100000 0.500000 0.100000
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
Ni 1.450000
d 1.000000
illum 2
";

/// (node name, [(material name, triangles)]) of a `.glb`, read with the
/// `gltf` crate, in node and primitive order.
fn glb_structure(bytes: &[u8]) -> Vec<(String, Vec<(String, usize)>)> {
    let gltf = gltf::Gltf::from_slice(bytes).unwrap();
    let scene = gltf.document.default_scene().unwrap();
    scene
        .nodes()
        .map(|node| {
            let prims = node
                .mesh()
                .unwrap()
                .primitives()
                .map(|p| {
                    let count = p.indices().unwrap().count();
                    assert_eq!(count % 3, 0);
                    (p.material().name().unwrap().to_string(), count / 3)
                })
                .collect();
            (node.name().unwrap().to_string(), prims)
        })
        .collect()
}

#[test]
fn glb_keeps_the_objects_and_materials_of_an_obj() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "two.obj", TWO_OBJECTS_OBJ);
    write(dir.path(), "two.mtl", TWO_OBJECTS_MTL);
    let mut scene = scene::load(&dir.path().join("two.obj")).unwrap();
    scene
        .set_emission("Lamp", Rgb::new(10.0, 10.0, 10.0))
        .unwrap();
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: 0.3,
            inset: 0.05,
        },
    )
    .unwrap();
    let radiosity: Vec<Rgb> = (0..mesh.vertex_count())
        .map(|i| Rgb::new(0.01 * (i % 97) as f64, 0.5, 2.0))
        .collect();
    let path = dir.path().join("baked.glb");
    write_mesh(&path, &scene, &mesh, &radiosity, 0.8, "two").unwrap();
    let bytes = std::fs::read(&path).unwrap();
    validate_glb(&bytes);

    // The triangles of each (object, material), counted from the mesh's
    // elements: a back copy counts with its front.
    let object_of = |p: usize| -> &str {
        let p = scene.polygons[p].surface.back_of.map_or(p, |f| f.index());
        let id = radiosity::scene::PolygonId(p as u32);
        scene
            .groups
            .iter()
            .find(|g| g.kind == scene::GroupKind::Object && g.polygons.contains(&id))
            .map(|g| g.name.as_str())
            .unwrap()
    };
    let mut expected: std::collections::BTreeMap<(&str, &str), usize> = Default::default();
    for (e, p) in mesh.elements.iter().zip(&mesh.element_polygon) {
        let material = scene.materials[scene.polygons[p.index()].material.index()]
            .name
            .as_str();
        *expected
            .entry((object_of(p.index()), material))
            .or_default() += e.triangles().count();
    }
    let got = glb_structure(&bytes);
    let names: Vec<&str> = got.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["Cube", "Lamp"], "one node per object, named");
    let materials: Vec<Vec<&str>> = got
        .iter()
        .map(|(_, prims)| prims.iter().map(|(m, _)| m.as_str()).collect())
        .collect();
    // Primitives in the order of the scene's materials (the MTL's order).
    assert_eq!(materials, [vec!["Material", "Top"], vec!["LampShade"]]);
    let mut counted: std::collections::BTreeMap<(&str, &str), usize> = Default::default();
    for (node, prims) in &got {
        for (material, triangles) in prims {
            counted.insert((node.as_str(), material.as_str()), *triangles);
        }
    }
    assert_eq!(counted, expected);
    // A 2 × 2 face at lenmax 0.3 is 7 × 7 quads, 98 triangles; the lamp
    // 4 × 4 quads, 32 triangles: on each side of a two-sided face.
    let sides = if scene.polygons.iter().any(|p| p.surface.back_of.is_some()) {
        2
    } else {
        1
    };
    assert_eq!(counted[&("Cube", "Top")], 98 * sides);
    assert_eq!(counted[&("Cube", "Material")], 5 * 98 * sides);
    assert_eq!(counted[&("Lamp", "LampShade")], 32 * sides);

    // The materials: reflectance as base colour, the lamp's emission
    // (10 × exposure 0.8 = 8) as emissive colour 1 × strength 8.
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    for m in gltf.document.materials() {
        let name = m.name().unwrap();
        let rho = scene
            .materials
            .iter()
            .find(|s| s.name == name)
            .unwrap()
            .reflectance();
        assert_eq!(
            m.pbr_metallic_roughness().base_color_factor(),
            [rho.r as f32, rho.g as f32, rho.b as f32, 1.0],
            "{name}"
        );
        let emissive = m.emissive_factor();
        if name == "LampShade" {
            assert_eq!(emissive, [1.0, 1.0, 1.0]);
        } else {
            assert_eq!(emissive, [0.0, 0.0, 0.0], "{name}");
        }
    }
    let (doc, _) = validate_glb(&bytes);
    let lamp = doc["materials"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "LampShade")
        .unwrap();
    assert_eq!(
        lamp["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"],
        8.0
    );
    assert!(doc["extensionsUsed"]
        .as_array()
        .unwrap()
        .contains(&serde_json::json!("KHR_materials_emissive_strength")));
}

#[test]
fn exported_obj_round_trips_through_the_program() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "model.obj",
        &TWO_OBJECTS_OBJ.replace("two.mtl", "model.mtl"),
    );
    write(dir.path(), "model.mtl", TWO_OBJECTS_MTL);
    let out = run_in(
        dir.path(),
        &[
            "model.obj",
            "--emit",
            "Lamp=10",
            "--max-steps",
            "20",
            "--size",
            "64x64",
            "--export",
            "baked.glb",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(dir.path().join("baked.glb")).unwrap();
    validate_glb(&bytes);
    let got = glb_structure(&bytes);
    let names: Vec<&str> = got.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["Cube", "Lamp"]);
    assert_eq!(got[0].1.len(), 2, "the cube's two materials");
    assert_eq!(got[1].1[0].0, "LampShade");
    // The cube is lit by the lamp above it (its top, reflectance 0.5 in
    // green, 2 units under a unit lamp of 10, gets about 0.4 in green), and
    // the lamp shows its own light, clipped to 1.
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    for node in gltf.document.nodes() {
        let mesh = node.mesh().unwrap();
        let brightest = mesh
            .primitives()
            .flat_map(|p| {
                p.reader(|_| Some(blob))
                    .read_colors(0)
                    .unwrap()
                    .into_rgb_f32()
                    .collect::<Vec<_>>()
            })
            .map(|c| c[0] + c[1] + c[2])
            .fold(0.0f32, f32::max);
        assert!(brightest > 0.1, "{:?} is lit: {brightest}", node.name());
    }
}

fn bits1(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A PLY file as read by [`read_ply`].
struct Ply {
    vertex_properties: Vec<(String, String)>,
    vertices: Vec<Vec<u8>>,
    faces: Vec<Vec<u32>>,
}

/// A small reader for binary little-endian PLY files, independent of the
/// writer: it follows the header's declarations.
fn read_ply(bytes: &[u8]) -> Ply {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("end_header")
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let mut lines = header.lines();
    assert_eq!(lines.next(), Some("ply"));
    assert_eq!(lines.next(), Some("format binary_little_endian 1.0"));
    let size = |t: &str| match t {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        t => panic!("unknown PLY type {t}"),
    };
    let mut elements: Vec<(String, usize, Vec<Vec<String>>)> = Vec::new();
    for line in lines {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w[0] {
            "comment" | "end_header" => {}
            "element" => elements.push((w[1].into(), w[2].parse().unwrap(), Vec::new())),
            "property" => elements
                .last_mut()
                .unwrap()
                .2
                .push(w[1..].iter().map(|s| s.to_string()).collect()),
            other => panic!("unexpected header line {other}"),
        }
    }
    let mut at = end;
    let mut ply = Ply {
        vertex_properties: Vec::new(),
        vertices: Vec::new(),
        faces: Vec::new(),
    };
    for (name, count, props) in &elements {
        for _ in 0..*count {
            if name == "vertex" {
                let len: usize = props.iter().map(|p| size(&p[0])).sum();
                ply.vertices.push(bytes[at..at + len].to_vec());
                at += len;
            } else {
                assert_eq!(name, "face");
                assert_eq!(props[0][..4], ["list", "uchar", "uint", "vertex_indices"]);
                let n = bytes[at] as usize;
                at += 1;
                ply.faces
                    .push((0..n).map(|k| u32_at(bytes, at + 4 * k)).collect());
                at += 4 * n;
            }
        }
        if name == "vertex" {
            ply.vertex_properties = props.iter().map(|p| (p[0].clone(), p[1].clone())).collect();
        }
    }
    assert_eq!(at, bytes.len(), "no bytes after the last element");
    ply
}

#[test]
fn ply_reads_back_bit_for_bit() {
    let (scene, mesh, radiosity) = solved_cornell();
    let exposure = 0.37;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cornell.ply");
    write_mesh(&path, &scene, &mesh, &radiosity, exposure, "cornell").unwrap();
    let ply = read_ply(&std::fs::read(&path).unwrap());
    let names: Vec<String> = ply
        .vertex_properties
        .iter()
        .map(|(t, n)| format!("{t} {n}"))
        .collect();
    assert_eq!(
        names,
        [
            "float x",
            "float y",
            "float z",
            "float radiosity_r",
            "float radiosity_g",
            "float radiosity_b",
            "uchar red",
            "uchar green",
            "uchar blue"
        ]
    );
    assert_eq!(ply.vertices.len(), mesh.vertex_count());
    for (i, v) in ply.vertices.iter().enumerate() {
        let f = f32s(&v[..24]);
        assert_eq!(
            bits1(&f[..3]),
            bits1(&mesh.positions[i].to_array()),
            "vertex {i}"
        );
        assert_eq!(bits1(&f[3..6]), bits1(&radiosity[i].to_f32()), "vertex {i}");
        let rgb = radiosity[i].to_f32().map(|c| srgb8(c, exposure));
        assert_eq!(v[24..27], rgb, "vertex {i}");
    }
    let faces: Vec<Vec<u32>> = mesh
        .elements
        .iter()
        .map(|e| e.corners().iter().map(|c| c.0).collect())
        .collect();
    assert_eq!(ply.faces, faces);
}

#[test]
fn obj_scene_runs_with_camera_export_log_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    write_cornell_obj(dir.path());
    // The camera block of cornell.sc, alone in a sidecar file.
    write(
        dir.path(),
        "camera.sc",
        "camera\n  eye 278 273 -800\n  lookat 278 273 0\n  up 0 1 0\n  fov 39.31\n  size 96 96\nend\n",
    );
    let out = run_in(
        dir.path(),
        &[
            "cornell.obj",
            "--camera",
            "camera.sc",
            "--lenmax",
            "80",
            "--max-steps",
            "12",
            "--export",
            "cornell.glb",
            "--log",
            "steps.csv",
            "--plot",
            "convergence.png",
            "--stats",
            "stats.json",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        listing(dir.path()),
        [
            "camera.sc",
            "convergence.png",
            "cornell.glb",
            "cornell.mtl",
            "cornell.obj",
            "cornell.png",
            "stats.json",
            "steps.csv"
        ]
    );
    let stats: serde_json::Value = read_json(dir.path(), "stats.json");
    let steps = stats["steps"].as_u64().unwrap();
    assert_eq!(steps, 12);
    let picture = image::open(dir.path().join("cornell.png")).unwrap();
    assert_eq!(
        (picture.width(), picture.height()),
        (96, 96),
        "camera from camera.sc"
    );

    // CSV: the header and one well-formed row per step.
    let csv = std::fs::read_to_string(dir.path().join("steps.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(LOG_HEADER));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect();
    assert_eq!(rows.len() as u64, steps);
    let columns = LOG_HEADER.split(',').count();
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), columns);
        assert_eq!(r[0], (i + 1) as f64, "step column");
        assert!(
            // 18 faces, each with its back.
            r[1] >= 0.0 && r[1] < 36.0 && r[1].fract() == 0.0,
            "shooter index"
        );
        assert!(r[2] >= 1.0, "shooter line");
        assert!(r[3] > 0.0, "shot power");
        assert!(r[4] > 0.0 && r[4] < 1.0, "unshot fraction");
        // A shooter with nothing in front of it casts no ray: the back of
        // a two-sided lamp in the ceiling's plane, whose light leaves.
        assert!(r[5] >= 0.0 && r[5].fract() == 0.0, "rays");
        assert!(r[6] > 0.0, "seconds");
        if i > 0 {
            assert!(r[6] >= rows[i - 1][6], "seconds grow");
        }
    }
    assert!(rows.iter().map(|r| r[5]).sum::<f64>() > 0.0, "rays");
    // The light shoots first: polygon 1, its face on line 21 of the OBJ.
    assert_eq!((rows[0][1], rows[0][2]), (1.0, 21.0));
    let last = rows.last().unwrap();
    // serde_json's default float parser may be one unit in the last
    // place off the value written (it is not correctly rounded).
    let unshot = stats["unshot_fraction"].as_f64().unwrap();
    assert!((last[4] - unshot).abs() <= 4.0 * f64::EPSILON * unshot);

    let plot = image::open(dir.path().join("convergence.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(plot.dimensions(), PLOT_SIZE);
    assert!(
        plot.pixels().filter(|p| p.0 == [0, 0, 255]).count() > 200,
        "curve drawn"
    );

    validate_glb(&std::fs::read(dir.path().join("cornell.glb")).unwrap());
}

#[test]
fn batch_outputs_are_checked_before_solving() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    let cornell = cornell.to_str().unwrap();
    for (args, message) in [
        (
            vec!["--export", "mesh.obj"],
            "supported mesh formats are .glb, .ply",
        ),
        (vec!["--export", "nowhere/mesh.glb"], "does not exist"),
        (vec!["--plot", "plot.exr"], "a plot is an 8-bit picture"),
        (
            vec!["--log", "same.csv", "--stats", "same.csv"],
            "two outputs",
        ),
        (
            vec!["--camera", "missing.sc"],
            "missing.sc: error: cannot read: ",
        ),
    ] {
        let mut all = vec![cornell, "-o", "x.png", "-q"];
        all.extend(args.iter().copied());
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(message), "{args:?}: {}", stderr(&out));
        assert!(listing(dir.path()).is_empty(), "{args:?} wrote files");
    }
}

#[test]
fn bad_obj_files_are_refused_with_positions() {
    // `Kd` 1.2 and zero-area faces are warnings now (see
    // `exported_obj_quirks_load_with_one_line_warnings`); negative
    // channels and out-of-range indices stay errors.
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "bad.mtl", "newmtl shiny\nKd 1.2 -0.5 0.5\n");
    write(
        dir.path(),
        "bad.obj",
        "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 2 0 0\nusemtl shiny\nf 1 2 9\n",
    );
    let out = run_in(dir.path(), &["bad.obj", "-o", "bad.png"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    for expected in [
        "bad.mtl:2:8: error: `Kd` channel -0.5 is negative; channels must be >= 0",
        "bad.obj:6:7: error: vertex index 9 in `9` is out of range: 3 vertices are defined in the file (indices count from 1)",
    ] {
        assert!(err.contains(expected), "missing {expected:?} in:\n{err}");
    }
    assert_eq!(listing(dir.path()), ["bad.mtl", "bad.obj"]);
}

/// A room as Blender 2.93 writes it (CRLF, as when saved on Windows):
/// a white floor (`Kd 1 1 1`), a lamp, a glass pane, a textured wall whose
/// texture was not shipped, a sliver face and a material nobody defined.
const QUIRKY_OBJ: &str = "# Blender v2.93.0 OBJ File: ''\r\n# www.blender.org\r\n\
mtllib room.mtl\r\no Floor\r\nv 0 0 0\r\nv 0 0 1\r\nv 1 0 1\r\nv 1 0 0\r\n\
vt 0 0\r\nvn 0 1 0\r\nusemtl white\r\ns off\r\nf 1/1/1 2/1/1 3/1/1 4/1/1\r\n\
f 1/1/1 3/1/1 3/1/1\r\no Lamp\r\nv 0 1 0\r\nv 1 1 0\r\nv 1 1 1\r\nv 0 1 1\r\n\
vn 0 -1 0\r\nusemtl lamp\r\ns off\r\nf 5//2 6//2 7//2 8//2\r\n\
o Pane\r\nusemtl glass\r\nf 1 4 6 5\r\no Wall\r\nusemtl brick\r\nf 1 5 8 2\r\n\
o Extra\r\nusemtl Material.001\r\nf 4 3 7 6\r\n";

const QUIRKY_MTL: &str = "# Blender MTL File: 'room.blend'\r\n# Material Count: 4\r\n\r\n\
newmtl white\r\nNs 225.000000\r\nKa 1.000000 1.000000 1.000000\r\nKd 1.000000 1.000000 1.000000\r\n\
Ks 0.000000 0.000000 0.000000\r\nKe 0.000000 0.000000 0.000000\r\nNi 1.450000\r\nd 1.000000\r\nillum 1\r\n\r\n\
newmtl lamp\r\nNs 0.000000\r\nKa 1.000000 1.000000 1.000000\r\nKd 0.000000 0.000000 0.000000\r\n\
Ks 0.000000 0.000000 0.000000\r\nKe 10.000000 10.000000 10.000000\r\nNi 1.000000\r\nd 1.000000\r\nillum 1\r\n\r\n\
newmtl glass\r\nNs 900.000000\r\nKa 1.000000 1.000000 1.000000\r\nKd 0.800000 0.800000 0.800000\r\n\
Ks 0.500000 0.500000 0.500000\r\nKe 0.000000 0.000000 0.000000\r\nNi 1.500000\r\nd 0.300000\r\nillum 7\r\n\r\n\
newmtl brick\r\nNs 225.000000\r\nKd 0.600000 0.600000 0.600000\r\nillum 1\r\nmap_Kd textures\\brick.png\r\n";

#[test]
fn exported_obj_quirks_load_with_one_line_warnings() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.obj", QUIRKY_OBJ);
    write(dir.path(), "room.mtl", QUIRKY_MTL);
    let out = run_in(
        dir.path(),
        &["room.obj", "-o", "room.png", "--max-steps", "4", "-q"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let picture = image::open(dir.path().join("room.png")).unwrap();
    assert!(picture.width() > 0 && picture.height() > 0);
    let err = stderr(&out);
    // The loader's warnings (the picture may get one of its own: this
    // model's lamp faces away from the automatic camera).
    let warnings: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("room.") && l.contains("warning:"))
        .collect();
    let expected = [
        "room.mtl:7:1: warning: material `white`: `Kd 1 1 1` reflects all light or more; scaled to 0.95 0.95 0.95 (brightest channel 0.95)",
        "room.mtl: warning: treated as diffuse: glass (d 0.3, illum 7, Ni 1.5)",
        "room.mtl:38:1: warning: cannot read 1 `map_Kd` texture(s), first textures/brick.png (material `brick`): ",
        "room.mtl:38:1: warning: 1 `map_Kd` path(s) written with `\\` (first `textures\\brick.png`), read with `/`",
        "room.obj:31:1: warning: undefined material `Material.001` (1 `usemtl` line(s), the first here): no `mtllib` defines it; its faces get the default material",
        "room.obj:14:1: warning: dropped 1 degenerate face(s) (no area, or a vertex repeated); the first here: ",
    ];
    for e in expected {
        assert!(
            warnings.iter().any(|w| w.starts_with(e)),
            "missing {e:?} in:\n{err}"
        );
    }
    assert_eq!(warnings.len(), expected.len(), "{err}");
}

#[test]
fn help_documents_the_model_options() {
    let out = run_in(&common::root(), &["--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for option in ["--camera", "--export", "--log", "--plot", ".obj"] {
        assert!(help.contains(option), "--help lacks {option}");
    }
}

/// A closed room 6 × 3 × 4 as Blender 2.93 exports it, every wall facing
/// inwards, with a lamp (`Ke`) just under the ceiling, facing down. With
/// `outward`, every face is wound the other way: a closed box seen from
/// outside.
fn room_obj(outward: bool) -> String {
    let faces = [
        [1, 4, 3, 2],    // floor, +y
        [5, 6, 7, 8],    // ceiling, -y
        [1, 2, 6, 5],    // z = 0, +z
        [4, 8, 7, 3],    // z = 4, -z
        [1, 5, 8, 4],    // x = 0, +x
        [2, 3, 7, 6],    // x = 6, -x
        [9, 10, 11, 12], // lamp, -y
    ];
    let mut s = String::from(
        "# Blender v2.93.0 OBJ File: ''\n# www.blender.org\nmtllib room.mtl\no Room\n\
         v 0.000000 0.000000 0.000000\nv 6.000000 0.000000 0.000000\n\
         v 6.000000 0.000000 4.000000\nv 0.000000 0.000000 4.000000\n\
         v 0.000000 3.000000 0.000000\nv 6.000000 3.000000 0.000000\n\
         v 6.000000 3.000000 4.000000\nv 0.000000 3.000000 4.000000\n\
         v 2.500000 2.990000 1.500000\nv 3.500000 2.990000 1.500000\n\
         v 3.500000 2.990000 2.500000\nv 2.500000 2.990000 2.500000\n\
         vn 0.0000 1.0000 0.0000\nusemtl Wall\ns off\n",
    );
    for (k, f) in faces.iter().enumerate() {
        if k == 6 {
            s.push_str("usemtl Lamp\n");
        }
        let mut f = *f;
        if outward {
            f.reverse();
        }
        s.push_str(&format!(
            "f {}//1 {}//1 {}//1 {}//1\n",
            f[0], f[1], f[2], f[3]
        ));
    }
    s
}

const ROOM_MTL: &str = "\
# Blender MTL File: 'room.blend'
# Material Count: 2

newmtl Lamp
Ns 225.000000
Ka 1.000000 1.000000 1.000000
Kd 0.000000 0.000000 0.000000
Ks 0.500000 0.500000 0.500000
Ke 10.000000 10.000000 10.000000
Ni 1.450000
d 1.000000
illum 2

newmtl Wall
Ns 225.000000
Ka 1.000000 1.000000 1.000000
Kd 0.800000 0.800000 0.800000
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
Ni 1.450000
d 1.000000
illum 2
";

/// The line of `--stats`' warnings and stderr about a nearly black picture.
const DARK_WARNING: &str = "the picture is nearly black";

#[test]
fn an_auto_framed_obj_room_is_seen_from_inside_and_lit() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", ROOM_MTL);
    let obj = write(dir.path(), "room.obj", &room_obj(false));
    // The camera is inside the room (framed from outside, every pixel
    // was the black back of a wall).
    let loaded = scene::load(&obj).unwrap();
    assert_eq!(loaded.camera_source, scene::CameraSource::AutoFramed);
    let (lo, hi) = loaded.bounds();
    let eye = loaded.camera.eye;
    assert!(eye.cmpgt(lo).all() && eye.cmplt(hi).all(), "{eye}");
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "--size",
            "64x48",
            "--lenmax",
            "1",
            "--max-steps",
            "20",
            "-q",
            "-o",
            "room.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains(DARK_WARNING), "{}", stderr(&out));
    let picture = image::open(dir.path().join("room.png")).unwrap().to_rgb8();
    let values: Vec<f64> = picture.pixels().flat_map(|p| p.0).map(f64::from).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    assert!(mean > 40.0, "mean brightness {mean} of 255");
    // Back faces are not black but striped: none may show.
    assert!(picture
        .enumerate_pixels()
        .all(|(x, y, p)| p.0 != radiosity::render::back_face_color(x, y)));
}

#[test]
fn a_picture_of_back_faces_warns_once() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", ROOM_MTL);
    write(dir.path(), "box.obj", &room_obj(true));
    // The eye forced inside a box whose faces point outwards, read
    // one-sided (as Blender shows them with backface culling).
    write(
        dir.path(),
        "inside.sc",
        "camera\n  eye 3 1.5 1\n  lookat 3 1.5 4\n  up 0 1 0\n  fov 60\n  size 64 48\nend\n",
    );
    let out = run_in(
        dir.path(),
        &[
            "box.obj",
            "--camera",
            "inside.sc",
            "--one-sided",
            "--lenmax",
            "1",
            "--max-steps",
            "5",
            "-q",
            "-o",
            "box.png",
            "--stats",
            "stats.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains(DARK_WARNING)).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].starts_with("warning: "), "{err}");
    assert!(lines[0].contains("backs of polygons"), "{err}");
    // The picture shows them in the documented stripes, not black.
    let picture = image::open(dir.path().join("box.png")).unwrap().to_rgb8();
    for (x, y) in [(32, 24), (10, 10), (13, 10)] {
        let p = picture.get_pixel(x, y).0;
        assert_eq!(p, radiosity::render::back_face_color(x, y), "({x}, {y})");
        assert_ne!(p, [0, 0, 0]);
    }
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["warnings"][0].as_str(), Some(lines[0]));
}

/// A room and a lamp as Blender exports them, the lamp a mesh whose
/// material does not emit (the light itself is not in the file).
const DARK_ROOM_OBJ: &str = "\
# Blender v2.93.0 OBJ File: ''
# www.blender.org
mtllib room.mtl
o Room
v 0 0 0
v 4 0 0
v 4 0 4
v 0 0 4
v 0 3 0
v 4 3 0
v 4 3 4
v 0 3 4
vn 0 1 0
usemtl Wall
s off
f 1//1 4//1 3//1 2//1
f 5//1 6//1 7//1 8//1
f 1//1 2//1 6//1 5//1
f 2//1 3//1 7//1 6//1
f 3//1 4//1 8//1 7//1
f 4//1 1//1 5//1 8//1
o Lamp
v 1.5 2.9 1.5
v 2.5 2.9 1.5
v 2.5 2.9 2.5
v 1.5 2.9 2.5
usemtl Wall
f 9 10 11 12
";

const DARK_ROOM_MTL: &str = "\
# Blender MTL File: 'None'
newmtl Wall
Ns 225.000000
Ka 1.000000 1.000000 1.000000
Kd 0.700000 0.700000 0.700000
Ks 0.500000 0.500000 0.500000
Ke 0.000000 0.000000 0.000000
illum 2
";

/// Writes the dark room into `dir`, with a camera inside it.
fn write_dark_room(dir: &Path) {
    write(dir, "room.obj", DARK_ROOM_OBJ);
    write(dir, "room.mtl", DARK_ROOM_MTL);
    write(
        dir,
        "camera.sc",
        "camera\n  eye 2 1.5 3.9\n  lookat 2 1.5 0\n  up 0 1 0\n  fov 70\n  size 48 36\nend\n",
    );
}

/// Runs the dark room with `extra` options, writing `room.png` and
/// `stats.json`.
fn run_dark_room(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "room.obj",
        "--camera",
        "camera.sc",
        "--lenmax",
        "0.5",
        "-o",
        "room.png",
        "--stats",
        "stats.json",
    ];
    args.extend_from_slice(extra);
    run_in(dir, &args)
}

/// Mean of the 8-bit channels of `dir/name`, from 0 to 255.
fn mean_brightness(dir: &Path, name: &str) -> f64 {
    let img = image::open(dir.join(name)).unwrap().to_rgb8();
    let sum: u64 = img.as_raw().iter().map(|&c| c as u64).sum();
    sum as f64 / img.as_raw().len() as f64
}

#[test]
fn a_model_with_nothing_emitting_says_so_and_names_the_lamp() {
    let dir = tempfile::tempdir().unwrap();
    write_dark_room(dir.path());
    let out = run_dark_room(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].starts_with("room.obj: warning: nothing emits light"),
        "{err}"
    );
    assert!(warnings[0].contains("`Lamp`"), "{err}");
    assert!(warnings[0].contains("--emit"), "{err}");
    assert!(!warnings[0].contains("`Room`"), "{err}");
    assert!(
        err.contains("nothing emits, nothing solved → room.png"),
        "{err}"
    );
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["converged"], false);
    assert_eq!(stats["nothing_emits"], true);
    assert_eq!(stats["steps"], 0);
    assert_eq!(stats["warnings"].as_array().map(Vec::len), Some(1));
    assert!(mean_brightness(dir.path(), "room.png") < 1.0);
}

#[test]
fn emit_lights_the_lamp_object_alone() {
    let dir = tempfile::tempdir().unwrap();
    write_dark_room(dir.path());
    let out = run_dark_room(dir.path(), &["--emit", "Lamp=10", "-q"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning:"), "{}", stderr(&out));
    let stats = read_json(dir.path(), "stats.json");
    assert!(stats["steps"].as_u64().unwrap() > 0, "{stats}");
    assert_eq!(stats["converged"], true);
    assert!(stats.get("nothing_emits").is_none(), "{stats}");
    assert!(stats.get("warnings").is_none(), "{stats}");
    let lit = mean_brightness(dir.path(), "room.png");
    assert!(lit > 40.0, "mean brightness {lit}");

    // The lamp shares `Wall` with the room, so only the lamp emits: the
    // whole room emitting instead would light the picture evenly.
    let scene = radiosity::scene::load(&dir.path().join("room.obj")).unwrap();
    let mut lamp_only = scene.clone();
    assert_eq!(lamp_only.set_emission("Lamp", Rgb::splat(10.0)), Ok(1));
    let emitting = |s: &Scene| {
        (0..s.polygons.len())
            .filter(|&i| {
                !s.material_of(scene::PolygonId(i as u32))
                    .emission()
                    .is_black()
            })
            .count()
    };
    assert_eq!(emitting(&lamp_only), 1);
    assert_eq!(lamp_only.materials.len(), scene.materials.len() + 1);
}

#[test]
fn emit_refuses_unknown_names_and_bad_values() {
    let dir = tempfile::tempdir().unwrap();
    write_dark_room(dir.path());
    let out = run_dark_room(dir.path(), &["--emit", "Nope=1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("error: --emit: no material, object or group is named `Nope`"),
        "{err}"
    );
    assert!(err.contains("`Lamp`") && err.contains("`Room`"), "{err}");
    assert!(err.contains("`Wall`"), "{err}");
    for bad in ["Lamp=-1", "Lamp=a,b"] {
        let out = run_dark_room(dir.path(), &["--emit", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(stderr(&out).contains("--emit must look like"), "{bad}");
    }
    // Nothing was written by any of them.
    assert_eq!(listing(dir.path()), ["camera.sc", "room.mtl", "room.obj"]);
}

#[test]
fn a_checkpoint_is_refused_when_the_emission_changed() {
    let dir = tempfile::tempdir().unwrap();
    write_dark_room(dir.path());
    let save = run_dark_room(
        dir.path(),
        &[
            "--emit",
            "Lamp=10",
            "--max-steps",
            "2",
            "--checkpoint",
            "c.bin",
            "-q",
        ],
    );
    assert!(save.status.success(), "{}", stderr(&save));
    let same = run_dark_room(
        dir.path(),
        &["--emit", "Lamp=10", "--resume", "c.bin", "-q"],
    );
    assert!(same.status.success(), "{}", stderr(&same));
    let other = run_dark_room(
        dir.path(),
        &["--emit", "Lamp=20", "--resume", "c.bin", "-q"],
    );
    assert_eq!(other.status.code(), Some(2), "{}", stderr(&other));
    assert!(
        stderr(&other).contains("was saved for a different scene"),
        "{}",
        stderr(&other)
    );
}
