//! Mesh export: the glb container and its chunks, nodes by object, group or
//! material, materials with their emission, PLY records, and formats by
//! extension.

use super::*;
use crate::mesh::{self, MeshOptions};
use crate::scene::{parse_str, Group, GroupKind, PolygonId};

fn small() -> (Scene, Mesh, Vec<Rgb>) {
    let scene = parse_str(
        "material m color 0.5 0.5 0.5 k_diffrefl 1 k_emission 1 end\n\
         polygon m vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 end\n\
         polygon m vertex 0 0 1 vertex 0.5 0 1 vertex 0 0.5 1 end\n",
        "t.sc",
    )
    .unwrap();
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: 0.4,
            inset: 0.0,
        },
    )
    .unwrap();
    let rad = (0..mesh.vertex_count())
        .map(|i| Rgb::new(i as f64 * 0.1, 0.3, 2.0))
        .collect();
    (scene, mesh, rad)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

#[test]
fn glb_chunks_are_aligned_and_sized() {
    let (scene, mesh, rad) = small();
    let b = glb_bytes(&scene, &mesh, &rad, 0.5, "t");
    assert_eq!(u32_at(&b, 0), GLB_MAGIC);
    assert_eq!(u32_at(&b, 4), 2);
    assert_eq!(u32_at(&b, 8) as usize, b.len());
    let json_len = u32_at(&b, 12) as usize;
    assert_eq!(u32_at(&b, 16), GLB_CHUNK_JSON);
    assert_eq!(json_len % 4, 0);
    let doc: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(&b, bin_at) as usize;
    assert_eq!(u32_at(&b, bin_at + 4), GLB_CHUNK_BIN);
    assert_eq!(bin_at + 8 + bin_len, b.len());
    assert_eq!(doc["buffers"][0]["byteLength"], bin_len);
    let n = mesh.vertex_count();
    let tris: usize = mesh.elements.iter().map(|e| e.triangles().count()).sum();
    assert_eq!(doc["accessors"][0]["count"], n);
    assert_eq!(doc["accessors"][4]["count"], 3 * tris);
    for (i, v) in doc["bufferViews"].as_array().unwrap().iter().enumerate() {
        assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0, "view {i}");
    }
    // Display colours are exposed and clipped: 2.0 × 0.5 = 1.0.
    let color_at = bin_at + 8 + doc["bufferViews"][2]["byteOffset"].as_u64().unwrap() as usize;
    let blue = f32::from_le_bytes(b[color_at + 8..color_at + 12].try_into().unwrap());
    assert_eq!(blue, 1.0);
}

/// Four unit squares side by side along x, materials a, b, a, b.
fn four() -> Scene {
    let mut sc = String::from(
        "material a color 0.5 0.5 0.5 k_diffrefl 1 k_emission 0 end\n\
         material b color 0.2 0.4 0.6 k_diffrefl 1 k_emission 3 end\n",
    );
    for (i, m) in ["a", "b", "a", "b"].iter().enumerate() {
        let x = i as f32 * 2.0;
        sc.push_str(&format!(
            "polygon {m} vertex {x} 0 0 vertex {} 0 0 vertex {} 1 0 vertex {x} 1 0 end\n",
            x + 1.0,
            x + 1.0
        ));
    }
    parse_str(&sc, "t.sc").unwrap()
}

fn group(name: &str, kind: GroupKind, polygons: &[u32]) -> Group {
    Group {
        name: name.into(),
        kind,
        polygons: polygons.iter().map(|&p| PolygonId(p)).collect(),
    }
}

/// (name, [(material, [polygon])]) of each node, for comparisons.
type Shape = Vec<(String, Vec<(u32, Vec<u32>)>)>;

fn shape(nodes: &[ExportNode]) -> Shape {
    nodes
        .iter()
        .map(|n| {
            let prims = n
                .primitives
                .iter()
                .map(|(m, ps)| (m.0, ps.iter().map(|p| p.0).collect()))
                .collect();
            (n.name.clone(), prims)
        })
        .collect()
}

#[test]
fn scenes_without_names_get_one_node_per_material() {
    let nodes = export_nodes(&four(), "t");
    assert_eq!(
        shape(&nodes),
        [
            ("a".to_string(), vec![(0, vec![0, 2])]),
            ("b".to_string(), vec![(1, vec![1, 3])]),
        ]
    );
}

#[test]
fn objects_make_nodes_and_the_rest_goes_to_the_file_node() {
    let mut scene = four();
    scene.groups = vec![
        group("walls", GroupKind::Group, &[0, 1, 2, 3]),
        group("Cube", GroupKind::Object, &[1, 2]),
        group("Lamp", GroupKind::Object, &[3]),
    ];
    // Objects win over groups; polygon 0 is in no object.
    assert_eq!(
        shape(&export_nodes(&scene, "room")),
        [
            ("Cube".to_string(), vec![(0, vec![2]), (1, vec![1])]),
            ("Lamp".to_string(), vec![(1, vec![3])]),
            ("room".to_string(), vec![(0, vec![0])]),
        ]
    );
    assert_eq!(export_nodes(&scene, "")[2].name, DEFAULT_NODE_NAME);
}

#[test]
fn groups_make_nodes_when_there_are_no_objects() {
    let mut scene = four();
    // Polygon 1 is in both groups: the first one takes it; a group
    // left with nothing of its own makes no node.
    scene.groups = vec![
        group("left", GroupKind::Group, &[0, 1]),
        group("right", GroupKind::Group, &[1, 2, 3]),
        group("again", GroupKind::Group, &[0]),
    ];
    assert_eq!(
        shape(&export_nodes(&scene, "t")),
        [
            ("left".to_string(), vec![(0, vec![0]), (1, vec![1])]),
            ("right".to_string(), vec![(0, vec![2]), (1, vec![3])]),
        ]
    );
}

#[test]
fn back_copies_join_their_fronts_node() {
    let mut scene = four();
    for front in [1u32, 3] {
        let mut back = scene.polygons[front as usize].clone();
        back.vertices.reverse();
        back.normal = -back.normal;
        back.surface.back_of = Some(PolygonId(front));
        scene.polygons.push(back);
    }
    // Polygon 4 is the back of 1 and 5 the back of 3; the group lists
    // the back of 3 too, which does not move it.
    scene.groups = vec![
        group("Cube", GroupKind::Object, &[0, 1]),
        group("Lamp", GroupKind::Object, &[2, 3]),
        group("Stray", GroupKind::Object, &[5]),
    ];
    assert_eq!(
        shape(&export_nodes(&scene, "t")),
        [
            ("Cube".to_string(), vec![(0, vec![0]), (1, vec![1, 4])]),
            ("Lamp".to_string(), vec![(0, vec![2]), (1, vec![3, 5])]),
        ]
    );
    // .sc-like scene: the back copies follow their front's material node.
    scene.groups.clear();
    assert_eq!(
        shape(&export_nodes(&scene, "t")),
        [
            ("a".to_string(), vec![(0, vec![0, 2])]),
            ("b".to_string(), vec![(1, vec![1, 3, 4, 5])]),
        ]
    );
}

#[test]
fn materials_carry_reflectance_and_scaled_emission() {
    let scene = four();
    let (a, strong) = material_json(&scene.materials[0], 0.5);
    assert!(!strong);
    assert_eq!(a["name"], "a");
    assert_eq!(
        a["pbrMetallicRoughness"]["baseColorFactor"],
        json!([0.5, 0.5, 0.5, 1.0])
    );
    assert!(a.get("emissiveFactor").is_none(), "a does not emit");
    // b emits 3 × (0.2, 0.4, 0.6) = (0.6, 1.2, 1.8); × 0.5 exposure =
    // (0.3, 0.6, 0.9): within [0, 1], no strength needed.
    let (b, strong) = material_json(&scene.materials[1], 0.5);
    assert!(!strong);
    let f: Vec<f64> = b["emissiveFactor"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (got, want) in f.iter().zip([0.3, 0.6, 0.9]) {
        assert!((got - want).abs() < 1e-6, "{f:?}");
    }
    // × 2: (1.2, 2.4, 3.6) = 3.6 × (1/3, 2/3, 1).
    let (b, strong) = material_json(&scene.materials[1], 2.0);
    assert!(strong);
    let s = b["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
        .as_f64()
        .unwrap();
    assert!((s - 3.6).abs() < 1e-5, "{s}");
    let f = b["emissiveFactor"].as_array().unwrap();
    assert!((f[0].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-6);
    assert_eq!(f[2].as_f64().unwrap(), 1.0);
    // The exact values, unscaled, in the extras.
    let e = scene.materials[1].emission();
    assert_eq!(b["extras"]["emission"], json!([e.r, e.g, e.b]));
    assert_eq!(b["extras"]["emission"][1].as_f64().unwrap(), 3.0 * 0.4);
}

#[test]
fn ply_header_counts_and_record_sizes_add_up() {
    let (_, mesh, rad) = small();
    let mut out = Vec::new();
    write_ply(&mut out, &mesh, &rad, 1.0).unwrap();
    let end = out.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&out[..end]).unwrap();
    assert!(header.contains(&format!("element vertex {}\n", mesh.vertex_count())));
    assert!(header.contains(&format!("element face {}\n", mesh.elements.len())));
    let faces: usize = mesh
        .elements
        .iter()
        .map(|e| 1 + 4 * e.corners().len())
        .sum();
    assert_eq!(out.len() - end, mesh.vertex_count() * 27 + faces);
}

#[test]
fn formats_follow_the_extension() {
    assert_eq!(
        MeshFormat::from_path(Path::new("a.GLB")).unwrap(),
        MeshFormat::Glb
    );
    assert_eq!(
        MeshFormat::from_path(Path::new("a.ply")).unwrap(),
        MeshFormat::Ply
    );
    let e = MeshFormat::from_path(Path::new("a.obj")).unwrap_err();
    assert!(e.to_string().contains("unknown extension .obj"), "{e}");
    let (scene, mesh, rad) = small();
    let dir = tempfile::tempdir().unwrap();
    let e = write_mesh(
        &dir.path().join("x.glb"),
        &scene,
        &mesh,
        &rad[1..],
        1.0,
        "x",
    )
    .unwrap_err();
    assert!(e.to_string().contains("one value per mesh vertex"), "{e}");
}
