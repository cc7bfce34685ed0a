//! Game levels, a room and a house of 48,000 to 71,000 triangles, as
//! their exporters wrote them (`tests/models/sauerbraten/`, `godot/`,
//! `redeclipse/`, `xeogl/`; where each comes from, its licence and the
//! tool that wrote it are in `tests/models/README.md`), loaded and solved
//! as a user would:
//!
//! - through the library, each loads whole (never refused): every
//!   triangle the file holds, counted here from the file itself, is
//!   either kept or dropped as degenerate, with the exact count said in
//!   one warning; the warnings a user must see are there, no others; the
//!   repair passes under `--sky 1` keep every polygon finite, and the
//!   element mesh every vertex; the share of the level open to the sky
//!   straight above is the one `tests/models/README.md` gives;
//! - through the program, a short solve under `--sky 1` on a coarse mesh
//!   (one element a triangle) gives a picture that is not black, with
//!   finite radiosity everywhere;
//! - every figure and quote `tests/models/README.md` gives of the models
//!   is one checked here or counted from the file.
//!
//! A full solve of one of these takes minutes (`docs/performance.md`);
//! two steps (each the light of one of the sky's 80 facets) are what
//! fits in seconds.

mod common;

use common::{read_json, root, run_in, stderr};
use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::repair::{self, RepairOptions};
use radiosity::scene::{self, GroupKind, Scene, Sides};
use radiosity::visibility::Visibility;
use std::path::{Path, PathBuf};

/// What a model is known to hold and how the tests solve it.
struct Model {
    /// The file, under `tests/models/`.
    rel: &'static str,
    /// Triangles in the file: `f` lines of three vertices (an OBJ), or the
    /// index counts over 3 of the triangle lists the nodes draw (a glTF),
    /// as `tests/models/README.md` gives them.
    triangles: usize,
    /// Triangles the loader drops as degenerate (a vertex repeated, no
    /// area within the polygon tolerances, or a sliver): the count its
    /// warning gives.
    dropped: usize,
    /// Each warning the library gives on loading it and on repairing it
    /// under `--sky 1` at the default sides, in order. The path it starts
    /// with varies with the checkout, and an operating system's wording
    /// of a missing file is not compared: see [`Expected`].
    warnings: &'static [Expected],
    /// Materials after loading: one a texture slot (an OBJ of a Cube 2
    /// engine game), the file's own (`room.glb`), or the one a glTF
    /// without materials gets.
    materials: usize,
    /// Whether every face is two-sided (an OBJ's default) rather than
    /// none (a glTF material without `doubleSided`).
    two_sided: bool,
    /// The size of the bounding box, in the file's units, to the nearest
    /// tenth.
    size: [f32; 3],
    /// Per cent of the area of the upward-facing polygons (normal within
    /// 26° of straight up) from which a ray straight up leaves the scene.
    open_up_percent: f64,
    /// The coarse `--lenmax` of the mesh and the solve: longer than any
    /// of the file's triangles, so the mesh is as coarse as its polygons
    /// allow.
    lenmax: &'static str,
    /// Eye, look-at point and vertical field of view (degrees) of a
    /// camera straight above the level looking down, or `None` for the
    /// program's own framing.
    camera: Option<([f32; 3], [f32; 3], f32)>,
    /// The least fraction of the picture with radiosity of at least
    /// [`LIT_RADIOSITY`] after the short solve: about half of what was
    /// measured.
    min_lit: f64,
}

/// One expected warning: the path of the file it names, then
/// [`Expected::starts`], then anything, then [`Expected::ends`].
struct Expected {
    /// The file it names, relative to `tests/models/`.
    file: &'static str,
    /// What follows the path (`:LINE:COL: warning: ...` or `: warning:
    /// ...`), up to the text that may vary.
    starts: &'static str,
    /// How the warning ends.
    ends: &'static str,
}

/// A pixel is lit when its brightest channel reaches this radiosity: a
/// hundredth of the sky's 1, well above nothing.
const LIT_RADIOSITY: f32 = 0.01;

/// The warning an OBJ of a Cube 2 engine game gets for its MTL: every
/// material is a `map_Kd` texture, no `Kd`. `first` is the text after the
/// path up to the count of materials not named.
const fn no_kd(mtl: &'static str, first: &'static str) -> Expected {
    Expected {
        file: mtl,
        starts: first,
        ends: "more: reflectance 0.8 (the default)",
    }
}

/// The warning for the textures that are not shipped.
const fn no_textures(mtl: &'static str, count_and_first: &'static str) -> Expected {
    Expected {
        file: mtl,
        starts: count_and_first,
        ends: "; their materials keep `Kd`",
    }
}

const PANDORA: Model = Model {
    rel: "sauerbraten/pandora.obj",
    triangles: 60_810,
    dropped: 116,
    warnings: &[
        no_kd(
            "sauerbraten/pandora.mtl",
            ": warning: no `Kd` in slot2, slot3, slot6, slot7, slot8, slot10, slot12, slot14 and 198 ",
        ),
        no_textures(
            "sauerbraten/pandora.mtl",
            ":4:1: warning: cannot read 206 `map_Kd` texture(s), first ",
        ),
        Expected {
            file: "sauerbraten/pandora.obj",
            starts: ":72311:1: warning: dropped 116 degenerate face(s) (no area, or a vertex \
                     repeated); the first here: vertices 1 and 2 are equal",
            ends: "",
        },
    ],
    materials: 206,
    two_sided: true,
    size: [1472.0, 448.0, 832.0],
    open_up_percent: 17.5,
    lenmax: "1000",
    camera: Some(([0.0, 1300.0, 0.0], [0.0, 0.0, 0.0], 40.0)),
    // Measured 0.061: seen from above, pandora is mostly roofs, whose
    // backs face up.
    min_lit: 0.03,
};

const ZDM2_OBJ: Model = Model {
    rel: "sauerbraten/zdm2.obj",
    triangles: 70_754,
    dropped: 63,
    warnings: &[
        no_kd(
            "sauerbraten/zdm2.mtl",
            ": warning: no `Kd` in slot1, slot21, slot27, slot92, slot108, slot113, slot115, \
             slot119 and 76 ",
        ),
        no_textures(
            "sauerbraten/zdm2.mtl",
            ":4:1: warning: cannot read 84 `map_Kd` texture(s), first ",
        ),
        Expected {
            file: "sauerbraten/zdm2.obj",
            starts: ":76726:1: warning: dropped 63 degenerate face(s) (no area, or a vertex \
                     repeated); the first here: vertices 1 and 2 are equal",
            ends: "",
        },
        Expected {
            file: "sauerbraten/zdm2.obj",
            starts: ": warning: 10 closed object(s) (128 faces) faced inward with nothing inside \
                     them: turned to face out, as solids lit from outside",
            ends: "",
        },
    ],
    materials: 84,
    two_sided: true,
    size: [868.0, 324.0, 608.0],
    open_up_percent: 67.6,
    lenmax: "1000",
    camera: Some(([0.0, 900.0, 0.0], [0.0, 0.0, 0.0], 45.0)),
    // Measured 0.89: courtyards and roofs.
    min_lit: 0.45,
};

const ROOM_GLB: Model = Model {
    rel: "godot/room.glb",
    triangles: 63_720,
    dropped: 0,
    warnings: &[],
    // The roof's top, outside; the floor inside is under the roof.
    materials: 2,
    two_sided: false,
    size: [10.0, 5.0, 10.0],
    open_up_percent: 49.6,
    lenmax: "100",
    camera: None,
    // Measured 0.21: the room from outside, through its door.
    min_lit: 0.1,
};

const ZDM2_GLB: Model = Model {
    rel: "godot/zdm2.glb",
    triangles: 58_772,
    dropped: 1178,
    warnings: &[Expected {
        file: "godot/zdm2.glb",
        starts: ": warning: dropped 1178 degenerate triangle(s) (no area, or a vertex repeated); \
                 the first meshes[0].primitives[0] (nodes[0]), triangle 30: polygon has zero area",
        ends: "",
    }],
    materials: 1,
    two_sided: false,
    size: [77.2, 36.0, 59.6],
    open_up_percent: 66.2,
    lenmax: "100",
    camera: Some(([5.0, 60.0, 0.0], [5.0, 0.0, 0.0], 80.0)),
    // Measured 0.38.
    min_lit: 0.19,
};

const FORTITUDE: Model = Model {
    rel: "redeclipse/fortitude.obj",
    triangles: 48_358,
    dropped: 37,
    warnings: &[
        no_kd(
            "redeclipse/fortitude.mtl",
            ": warning: no `Kd` in slot1, slot2, slot3, slot5, slot6, slot7, slot8, slot9 and 111 ",
        ),
        no_textures(
            "redeclipse/fortitude.mtl",
            ":4:1: warning: cannot read 119 `map_Kd` texture(s), first ",
        ),
        Expected {
            file: "redeclipse/fortitude.obj",
            starts: ":69029:1: warning: dropped 37 degenerate face(s) (no area, or a vertex \
                     repeated); the first here: vertices 1 and 2 are equal",
            ends: "",
        },
        Expected {
            file: "redeclipse/fortitude.obj",
            starts: ": warning: 1 closed object(s) (12 faces) faced inward with nothing inside \
                     them: turned to face out, as solids lit from outside",
            ends: "",
        },
    ],
    materials: 119,
    two_sided: true,
    size: [2048.0, 996.0, 2048.0],
    open_up_percent: 43.5,
    lenmax: "3000",
    camera: Some(([0.0, 2600.0, 0.0], [0.0, 0.0, 0.0], 45.0)),
    // Measured 0.21.
    min_lit: 0.1,
};

const VIANNEY_HOUSE: Model = Model {
    rel: "xeogl/vianney_house_2/scene.gltf",
    triangles: 56_674,
    dropped: 1,
    warnings: &[
        Expected {
            file: "xeogl/vianney_house_2/scene.gltf",
            starts: ": warning: cannot read 2 texture(s), the first \
                     materials[8].baseColorTexture: images[1] (material `floor`): cannot read \
                     the glTF buffer or image ",
            ends: "; their materials keep their factors",
        },
        Expected {
            file: "xeogl/vianney_house_2/scene.gltf",
            starts: ": warning: dropped 1 degenerate triangle(s) (no area, or a vertex repeated); \
                     the first meshes[0].primitives[7] (nodes[3]), triangle 26549: polygon has \
                     zero area",
            ends: "",
        },
        Expected {
            file: "xeogl/vianney_house_2/scene.gltf",
            starts: ": warning: base colour reflects all light or more in Mtl6, Mtlb, \
                     darker_glass, floor, glass, starirs_steps: scaled so the brightest channel \
                     is 0.95, keeping the hue",
            ends: "",
        },
        Expected {
            file: "xeogl/vianney_house_2/scene.gltf",
            starts: ": warning: treated as diffuse: darker_glass (metallic 0.4, alpha 0.85), \
                     glass (metallic 0.8, alpha 0.4)",
            ends: "",
        },
    ],
    materials: 14,
    two_sided: true,
    size: [121.1, 150.0, 42.6],
    // The house's up is the file's +z, not glTF's +y: it lies on its
    // side, a glazed front facing straight up.
    open_up_percent: 52.3,
    lenmax: "1000",
    // From +x, level with the house: its glazed end wall.
    camera: Some(([300.0, 0.0, 21.3], [0.0, 0.0, 21.3], 45.0)),
    // Measured 0.093.
    min_lit: 0.045,
};

/// `room.glb`: the triangles of material `Room` (walls, floor, roof).
const ROOM_WALLS: usize = 232;
/// `room.glb`: its spheres, and the triangles of each.
const SPHERES: usize = 16;
/// See [`SPHERES`].
const SPHERE_TRIANGLES: usize = 3968;
/// The house's polygons the intersection pass cuts, and their pieces.
const VIANNEY_CUT: (usize, usize) = (696, 2034);

/// The path of a collected model, `tests/models/<rel>`.
fn model(rel: &str) -> PathBuf {
    root().join("tests").join("models").join(rel)
}

// ---------------------------------------------------------------------------
// Counting the file's triangles, independently of the loader.

/// The triangles of an OBJ: its `f` lines, each checked to have three
/// vertices (every face of these exports is a triangle).
fn obj_triangles(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
    for f in &faces {
        assert_eq!(f.split_whitespace().count(), 4, "a triangle: {f}");
    }
    faces.len()
}

/// The JSON of a `.gltf` file, or the JSON chunk of a `.glb`.
fn gltf_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().is_some_and(|e| e == "gltf") {
        return serde_json::from_slice(&bytes).unwrap();
    }
    assert_eq!(&bytes[..4], b"glTF");
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(word(16), 0x4E4F_534A, "the JSON chunk comes first");
    serde_json::from_slice(&bytes[20..20 + word(12)]).unwrap()
}

/// The triangles of a `.glb` or `.gltf`: over every node of its scene
/// that draws a mesh, the index count over 3 of each triangle-list
/// primitive.
fn gltf_triangles(path: &Path) -> usize {
    let json = gltf_json(path);
    let index = |v: &serde_json::Value| v.as_u64().unwrap() as usize;
    let mesh_triangles = |mesh: usize| -> usize {
        json["meshes"][mesh]["primitives"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                assert!(p["mode"].is_null() || p["mode"] == 4, "triangle lists");
                let count = index(&json["accessors"][index(&p["indices"])]["count"]);
                assert_eq!(count % 3, 0);
                count / 3
            })
            .sum()
    };
    let scene = index(&json["scene"]);
    let mut stack: Vec<usize> = json["scenes"][scene]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(index)
        .collect();
    let mut total = 0;
    while let Some(n) = stack.pop() {
        let node = &json["nodes"][n];
        if !node["mesh"].is_null() {
            total += mesh_triangles(index(&node["mesh"]));
        }
        if let Some(children) = node["children"].as_array() {
            stack.extend(children.iter().map(index));
        }
    }
    total
}

// ---------------------------------------------------------------------------
// Through the library: loading, repair, mesh.

/// Asserts that every vertex of every polygon is finite, its normal a finite
/// unit vector and its area positive and finite.
fn assert_polygons_finite(s: &Scene, what: &str) {
    for (i, p) in s.polygons.iter().enumerate() {
        assert!(
            p.vertices.iter().all(|v| v.is_finite())
                && p.normal.is_finite()
                && (p.normal.length() - 1.0).abs() < 1e-4
                && p.area.is_finite()
                && p.area > 0.0,
            "{what}: polygon {i}: {p:?}"
        );
    }
}

/// Per cent of the area of the polygons facing up (normal's y above 0.9)
/// from whose centre a ray straight up leaves the scene.
fn open_up_percent(s: &Scene) -> f64 {
    let vis = Visibility::new(s);
    let lift = 1e-4 * s.extent();
    let (mut up, mut open) = (0.0, 0.0);
    for p in s.polygons.iter().filter(|p| p.normal.y > 0.9) {
        let centre = p.vertices.iter().copied().sum::<Vec3>() / p.vertices.len() as f32;
        up += p.area;
        if vis.first_hit(centre + p.normal * lift, Vec3::Y).is_none() {
            open += p.area;
        }
    }
    100.0 * open / up
}

/// Loads `m` through the library and checks what [`Model`] says of the
/// loaded scene: the file's triangles, each kept or dropped; triangles
/// kept as triangles; the materials, the sides and the size; polygons
/// finite; the share open to the sky.
fn load(m: &Model) -> Scene {
    let path = model(m.rel);
    let counted = if m.rel.ends_with(".obj") {
        obj_triangles(&path)
    } else {
        gltf_triangles(&path)
    };
    assert_eq!(counted, m.triangles, "{}: triangles in the file", m.rel);

    let s = scene::load(&path).unwrap_or_else(|e| panic!("{}: refused: {e}", m.rel));
    assert_eq!(
        s.polygons.len() + m.dropped,
        m.triangles,
        "{}: every triangle kept or dropped",
        m.rel
    );
    assert!(
        s.polygons.iter().all(|p| p.vertices.len() == 3),
        "{}: triangles stay triangles",
        m.rel
    );
    assert_eq!(s.materials.len(), m.materials, "{}: materials", m.rel);
    assert!(
        s.polygons
            .iter()
            .all(|p| p.surface.two_sided == m.two_sided),
        "{}: every face two-sided: {}",
        m.rel,
        m.two_sided
    );
    let (lo, hi) = s.bounds();
    let size = ((hi - lo) * 10.0).round() / 10.0;
    assert_eq!(size.to_array(), m.size, "{}: size", m.rel);
    assert_polygons_finite(&s, m.rel);
    let open = open_up_percent(&s);
    assert!(
        (open - m.open_up_percent).abs() < 0.05,
        "{}: {open:.2} % of the upward-facing area is open straight up",
        m.rel
    );
    s
}

/// Runs the repair passes on `loaded` as the program does under `--sky 1`
/// at the default sides, checks the warnings of loading and repair
/// against [`Model::warnings`] and that every polygon stays finite, and
/// meshes the result at the coarse lenmax: every element vertex finite.
/// Returns what the intersection pass cut: polygons and their pieces.
fn repair_and_mesh(m: &Model, loaded: Scene) -> (usize, usize) {
    let name = model(m.rel).display().to_string();
    let options = RepairOptions {
        sides: Sides::AsLoaded,
        sky: Some(radiosity::scene::SkyLight::Uniform(Rgb::splat(1.0))),
        file: &name,
        budget: radiosity::budget::MemoryBudget::UNLIMITED,
    };
    let (repaired, report) = repair::run(loaded, &options, Visibility::new).unwrap();
    let warnings: Vec<String> = repaired.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(warnings.len(), m.warnings.len(), "{}: {warnings:#?}", m.rel);
    for (got, want) in warnings.iter().zip(m.warnings) {
        let starts = format!("{}{}", model(want.file).display(), want.starts);
        assert!(
            got.starts_with(&starts) && got.ends_with(want.ends),
            "{}:\n  got  {got}\n  want {starts} ... {}",
            m.rel,
            want.ends
        );
    }
    assert!(
        repaired.polygons.iter().any(|p| p.surface.sky),
        "{}: the sky",
        m.rel
    );
    assert_polygons_finite(&repaired, m.rel);

    let options = MeshOptions {
        lenmax: m.lenmax.parse().unwrap(),
        ..MeshOptions::for_scene(&repaired)
    };
    let mesh = mesh::build(&repaired, &options).unwrap();
    assert!(mesh.positions.len() >= 3 * repaired.polygons.len());
    assert!(
        mesh.positions.iter().all(|v| v.is_finite())
            && mesh.sample_positions.iter().all(|v| v.is_finite()),
        "{}: element vertices finite",
        m.rel
    );
    (report.split.polygons_cut, report.split.pieces)
}

/// [`load`] then [`repair_and_mesh`].
fn loads_whole(m: &Model) -> (usize, usize) {
    let loaded = load(m);
    repair_and_mesh(m, loaded)
}

// ---------------------------------------------------------------------------
// Through the program: a short solve under a sky.

/// Runs the program on `m` under `--sky 1` at its coarse lenmax for one
/// step (the whole sky, gathered at once), with its camera, writing `out.exr` (linear radiosity) and
/// `stats.json`; checks the exit, the stats, that the radiosity in the
/// picture is finite and that at least [`Model::min_lit`] of it is lit.
/// OBJ faces are solved one-sided: a back copy of every face would double
/// the vertices each sky facet lights, and the time.
fn lit_under_a_sky(m: &Model) {
    let dir = tempfile::tempdir().unwrap();
    let path = model(m.rel);
    let mut args = vec![
        path.to_str().unwrap(),
        "--sky",
        "1",
        "--lenmax",
        m.lenmax,
        // The sky's one step (gathered at once).
        "--max-steps",
        "1",
        "--size",
        "160x120",
        "-o",
        "out.exr",
        "--stats",
        "stats.json",
    ];
    if m.rel.ends_with(".obj") {
        args.push("--one-sided");
    }
    if let Some((eye, at, fov)) = m.camera {
        let text = format!(
            "camera\n eye {} {} {}\n lookat {} {} {}\n up 0 0 -1\n fov {fov}\nend\n",
            eye[0], eye[1], eye[2], at[0], at[1], at[2]
        );
        common::write(dir.path(), "above.sc", &text);
        args.extend_from_slice(&["--camera", "above.sc"]);
    }
    let out = run_in(dir.path(), &args);
    let err = stderr(&out);
    assert!(out.status.success(), "{}: {err}", m.rel);
    assert!(!err.contains("error:"), "{}: {err}", m.rel);
    assert!(!err.contains("nothing emits"), "{}: {err}", m.rel);
    if m.dropped > 0 {
        assert!(
            err.contains(&format!("warning: dropped {} degenerate", m.dropped)),
            "{}: {err}",
            m.rel
        );
    }

    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["steps"], 1, "{}: {stats}", m.rel);
    let unshot = stats["unshot_fraction"].as_f64().unwrap();
    assert!(unshot > 0.0 && unshot < 1.0, "{}: {stats}", m.rel);

    let img = image::open(dir.path().join("out.exr")).unwrap().to_rgb32f();
    assert!(
        img.pixels()
            .all(|p| p.0.iter().all(|c| c.is_finite() && *c >= 0.0)),
        "{}: radiosity finite",
        m.rel
    );
    let lit = img
        .pixels()
        .filter(|p| p.0.iter().any(|&c| c >= LIT_RADIOSITY))
        .count() as f64
        / (img.width() * img.height()) as f64;
    assert!(lit >= m.min_lit, "{}: lit fraction {lit}", m.rel);
}

// ---------------------------------------------------------------------------
// The models.

#[test]
fn sauerbraten_pandora_loads_whole() {
    loads_whole(&PANDORA);
}

#[test]
fn sauerbraten_pandora_is_lit_under_a_sky() {
    lit_under_a_sky(&PANDORA);
}

#[test]
fn sauerbraten_zdm2_loads_whole() {
    loads_whole(&ZDM2_OBJ);
}

#[test]
fn sauerbraten_zdm2_is_lit_under_a_sky() {
    lit_under_a_sky(&ZDM2_OBJ);
}

#[test]
fn godot_room_loads_whole() {
    let s = load(&ROOM_GLB);
    // The room (one node, `Cube`) and sixteen spheres (`Sphere` to
    // `Sphere.015`) of 3,968 triangles each, all of material `Glass`.
    let triangles_of = |material: &str| {
        s.polygons
            .iter()
            .filter(|p| s.materials[p.material.index()].name == material)
            .count()
    };
    assert_eq!(triangles_of("Room"), ROOM_WALLS);
    assert_eq!(triangles_of("Glass"), SPHERES * SPHERE_TRIANGLES);
    let spheres: Vec<usize> = s
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Object && g.name.starts_with("Sphere"))
        .map(|g| g.polygons.len())
        .collect();
    assert_eq!(spheres, [SPHERE_TRIANGLES; SPHERES]);
    repair_and_mesh(&ROOM_GLB, s);
}

#[test]
fn godot_room_is_lit_under_a_sky() {
    lit_under_a_sky(&ROOM_GLB);
}

#[test]
fn godot_zdm2_loads_whole() {
    let s = load(&ZDM2_GLB);
    // No material in the file: every triangle gets the default grey.
    assert_eq!(s.materials[0].reflectance(), Rgb::splat(0.8));
    repair_and_mesh(&ZDM2_GLB, s);
}

#[test]
fn godot_zdm2_is_lit_under_a_sky() {
    lit_under_a_sky(&ZDM2_GLB);
}

#[test]
fn redeclipse_fortitude_loads_whole() {
    loads_whole(&FORTITUDE);
}

#[test]
fn redeclipse_fortitude_is_lit_under_a_sky() {
    lit_under_a_sky(&FORTITUDE);
}

#[test]
fn xeogl_vianney_house_loads_whole() {
    // Walls, floors and frames pass through each other: cut where they
    // cross, as `tests/models/README.md` says.
    assert_eq!(loads_whole(&VIANNEY_HOUSE), VIANNEY_CUT);
}

#[test]
fn xeogl_vianney_house_is_lit_under_a_sky() {
    lit_under_a_sky(&VIANNEY_HOUSE);
}

// ---------------------------------------------------------------------------
// What tests/models/README.md says of the models.

/// `n` with a comma between thousands, as the README writes counts.
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `N closed object(s) (M faces)` of a model's warnings, as `N of M faces`.
fn turned_out(m: &Model) -> Option<String> {
    m.warnings.iter().find_map(|w| {
        let (n, rest) = w.starts.split_once(" closed object(s) (")?;
        let n = n.rsplit(' ').next()?;
        let faces = rest.split_once(" faces)")?.0;
        Some(format!("{n} of {faces} faces"))
    })
}

/// The size the README gives: each side to the nearest whole unit.
fn size_text(m: &Model) -> String {
    m.size.map(|x| format!("{}", x.round())).join(" × ")
}

/// Every figure `tests/models/README.md` gives of the collected models is
/// the one the tests above check (the constants, each checked against the
/// model itself) or one counted here from the file: the README cannot
/// drift from the models.
#[test]
fn the_models_readme_gives_what_the_models_hold() {
    let text = std::fs::read_to_string(root().join("tests/models/README.md")).unwrap();
    // Figures run across line breaks: compare with single spaces.
    let readme = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let says = |what: &str| {
        assert!(
            readme.contains(what),
            "tests/models/README.md does not say `{what}`"
        )
    };
    // The table's triangle column.
    for m in [
        &PANDORA,
        &ZDM2_OBJ,
        &ROOM_GLB,
        &ZDM2_GLB,
        &VIANNEY_HOUSE,
        &FORTITUDE,
    ] {
        let dropped = match m.dropped {
            0 => "none".to_string(),
            n => thousands(n),
        };
        says(&format!("| {} ({dropped} dropped)", thousands(m.triangles)));
    }
    // The Cube 2 levels, in the README's order.
    let levels = [&PANDORA, &ZDM2_OBJ, &FORTITUDE];
    let [a, b, c] = levels.map(|m| m.materials);
    says(&format!("texture ({a}, {b} and {c} of them)"));
    let [a, b, c] = levels.map(|m| m.dropped);
    says(&format!("a vertex written twice ({a}, {b} and {c},"));
    let [a, b, c] = levels.map(|m| turned_out(m).unwrap_or("none".into()));
    says(&format!("under the default two sides ({a}, {b}, {c})"));
    let [a, b, c] = levels.map(size_text);
    says(&format!(
        "Cube units, {a} (pandora), {b} (zdm2), {c} (fortitude)"
    ));
    let [a, b, c] = levels.map(|m| m.open_up_percent);
    says(&format!("pandora {a} % (mostly roofed), zdm2 {b} %"));
    says(&format!("fortitude {c} %."));
    // The room.
    let nodes = gltf_json(&model(ROOM_GLB.rel))["nodes"]
        .as_array()
        .unwrap()
        .len();
    says(&format!("a closed room of {} m", size_text(&ROOM_GLB)));
    says(&format!(
        "{SPHERES} spheres of {} triangles each",
        thousands(SPHERE_TRIANGLES)
    ));
    says(&format!("the room's {ROOM_WALLS} triangles"));
    says(&format!(
        "all {} triangles of the spheres",
        thousands(SPHERES * SPHERE_TRIANGLES)
    ));
    says(&format!("{nodes} nodes, each a mesh of its own"));
    says(&format!(
        "Of its upward-facing area {} % is open",
        ROOM_GLB.open_up_percent
    ));
    // zdm2 through Blender.
    let first = ZDM2_GLB.warnings[0].starts;
    let at = first.split("triangle ").nth(1).unwrap().split(':').next();
    says(&format!(
        "{} degenerate triangles, zero-area ones and slivers (the first is triangle {})",
        thousands(ZDM2_GLB.dropped),
        at.unwrap()
    ));
    says(&format!("metres, {}", size_text(&ZDM2_GLB)));
    says(&format!(
        "{} % of the upward-facing area open",
        ZDM2_GLB.open_up_percent
    ));
    // The house: its triangles by material, from the file.
    let house = gltf_json(&model(VIANNEY_HOUSE.rel));
    let mesh = &house["meshes"][0]["primitives"];
    let of = |names: &[&str]| -> usize {
        mesh.as_array()
            .unwrap()
            .iter()
            .filter(|p| {
                let material = &house["materials"][p["material"].as_u64().unwrap() as usize];
                names.contains(&material["name"].as_str().unwrap())
            })
            .map(|p| {
                house["accessors"][p["indices"].as_u64().unwrap() as usize]["count"]
                    .as_u64()
                    .unwrap() as usize
                    / 3
            })
            .sum()
    };
    says(&format!(
        "One mesh of {} primitives",
        mesh.as_array().unwrap().len()
    ));
    says(&format!(
        "{} of its triangles are `door_handle` and {} window and door frames \
         (`metal_frame`, `mid-frame`), against {} of `wall`",
        thousands(of(&["door_handle"])),
        thousands(of(&["metal_frame", "mid-frame"])),
        of(&["wall"])
    ));
    assert_eq!(VIANNEY_HOUSE.dropped, 1);
    says("one zero-area triangle (dropped)");
    says(&format!(
        "{} polygons cut into {} pieces",
        thousands(VIANNEY_CUT.0),
        thousands(VIANNEY_CUT.1)
    ));
    says(&format!(
        "a house with glazed walls, {} in",
        size_text(&VIANNEY_HOUSE)
    ));
    says(&format!(
        "{} % of the upward-facing area open",
        VIANNEY_HOUSE.open_up_percent
    ));
}

/// What `tests/models/README.md` quotes from the small models' files is in
/// them, and the counts it gives are theirs.
#[test]
fn the_models_readme_quotes_the_small_models() {
    let text = std::fs::read_to_string(root().join("tests/models/README.md")).unwrap();
    let readme = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let file = |rel: &str| std::fs::read_to_string(model(rel)).unwrap();
    let lines = |rel: &str, start: &str| file(rel).lines().filter(|l| l.starts_with(start)).count();
    let sphere = "mcguire/CornellBox-Sphere.obj";
    for (rel, quotes) in [
        ("mcguire/CornellBox-Original.mtl", &["Ke 17 12 4"][..]),
        (
            "mcguire/CornellBox-Original.obj",
            &["f -12 -11 -10 -9", "f -8 -7 -6 -5"],
        ),
        (sphere, &["# 546 vertices", "s 1"]),
        (
            "mcguire/CornellBox-Sphere.mtl",
            &[
                "Ks 0.95",
                "illum 5",
                "illum 7",
                "Ni 2.5",
                "Kd 0.01",
                "v 0.2 0 0",
            ],
        ),
        ("tinyobjloader/cornell_box.mtl", &["Kd 1", "Ka 20 20 20"]),
        ("raylib/plane.obj", &["# Blender v2.90.0 OBJ File"]),
    ] {
        let text = file(rel);
        for quote in quotes {
            assert!(text.contains(quote), "{rel} has no `{quote}`");
            assert!(readme.contains(&format!("`{quote}")), "README: {quote}");
        }
    }
    assert!(readme.contains(&format!("{} faces", lines(sphere, "f "))));
    let vt = lines("threejs/verify.obj", "vt ");
    assert_eq!(vt, 4, "the README says four `vt` lines");
    assert!(readme.contains("beyond the four `vt` lines"));
    // The glTF files' generators, as the README quotes them.
    for (rel, generator) in [
        ("raylib/greenman.glb", "Khronos glTF Blender I/O v3.6.27"),
        ("khronos/Box.gltf", "COLLADA2GLTF"),
        (ROOM_GLB.rel, "Khronos glTF Blender I/O v3.3.27"),
        (ZDM2_GLB.rel, "Khronos glTF Blender I/O v1.6.16"),
        (VIANNEY_HOUSE.rel, "Sketchfab (OSG glTF plugin)"),
    ] {
        assert_eq!(gltf_json(&model(rel))["asset"]["generator"], generator);
        assert!(
            readme.contains(&format!("`{generator}`")),
            "README: {generator}"
        );
    }
    // room.glb's two colours, to two decimals.
    let room = gltf_json(&model(ROOM_GLB.rel));
    let colour = |name: &str| -> String {
        let m = room["materials"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == name)
            .unwrap();
        let c = m["pbrMetallicRoughness"]["baseColorFactor"]
            .as_array()
            .unwrap();
        c[..3]
            .iter()
            .map(|x| format!("{}", (x.as_f64().unwrap() * 100.0).round() / 100.0))
            .collect::<Vec<_>>()
            .join(", ")
    };
    assert_eq!(colour("Room"), "0.8, 0.8, 0.8");
    assert!(readme.contains("`Room` (0.8 grey"));
    assert!(readme.contains(&format!("`Glass` ({}, all", colour("Glass"))));
    // zdm2.glb's one node turns it a quarter about x.
    let zdm2 = gltf_json(&model(ZDM2_GLB.rel));
    let q: Vec<f64> = zdm2["nodes"][0]["rotation"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let half = std::f64::consts::FRAC_1_SQRT_2;
    assert!((q[0] - half).abs() < 1e-6 && q[1] == 0.0 && q[2] == 0.0 && (q[3] - half).abs() < 1e-6);
    assert!(readme.contains("one mesh in one node, rotated 90° about x"));
    // The one level under 50,000 triangles.
    assert!(FORTITUDE.triangles < 50_000 && readme.contains("just under 50,000"));
    // The pictures' size is the script's.
    let script = std::fs::read_to_string(root().join("docs/images/render_models.sh")).unwrap();
    assert!(script.contains("--size 480x360") && readme.contains("(480x360;"));
}

/// `scripts/side_by_side.py`, which builds the quarter-million-triangle
/// model of `docs/performance.md` from these levels, keeps every face of
/// each model it is given, keeps their materials apart by a prefix (two
/// copies, two sets), and places each copy clear of the one before along
/// `+x`. Skipped where `python3` is missing.
#[test]
fn side_by_side_keeps_every_face_and_keeps_the_models_apart() {
    let python = std::process::Command::new("python3")
        .arg("--version")
        .output();
    if !python.is_ok_and(|o| o.status.success()) {
        eprintln!("skipped: no python3");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("two.obj");
    let one = model("mcguire/CornellBox-Original.obj");
    let ran = std::process::Command::new("python3")
        .arg(root().join("scripts/side_by_side.py"))
        .args([&out, &one, &one])
        .output()
        .unwrap();
    assert!(
        ran.status.success(),
        "{}",
        String::from_utf8_lossy(&ran.stderr)
    );
    let single = scene::load(&one).unwrap();
    let both = scene::load(&out).unwrap();
    let n = single.polygons.len();
    assert_eq!(both.polygons.len(), 2 * n);
    assert_eq!(both.materials.len(), 2 * single.materials.len());
    for (copy, prefix) in [(0, "CornellBox-Original_"), (1, "CornellBox-Original2_")] {
        for (p, q) in both.polygons[copy * n..(copy + 1) * n]
            .iter()
            .zip(&single.polygons)
        {
            let name = &both.materials[p.material.index()].name;
            assert_eq!(
                *name,
                format!("{prefix}{}", single.materials[q.material.index()].name)
            );
            assert_eq!(p.vertices.len(), q.vertices.len());
        }
    }
    let x_range = |polygons: &[radiosity::scene::Polygon]| {
        polygons
            .iter()
            .flat_map(|p| &p.vertices)
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v.x), hi.max(v.x))
            })
    };
    let (first, second) = (x_range(&both.polygons[..n]), x_range(&both.polygons[n..]));
    assert!(second.0 > first.1, "{first:?} then {second:?}");
}
