//! The OBJ and MTL readers' tests.

use super::scan::without_references;
use super::*;
use crate::color::Rgb;
use crate::scene::import::texture::srgb_to_linear;
use crate::scene::Shape;

const MTL: &str = "\
# two materials
newmtl white
Kd 0.5 0.5 0.5
Ks 0.8 0.8 0.8
newmtl lamp
Kd 0 0 0
Ke 10 8 6
newmtl grey
Kd 0.25
";

/// Parses `obj` with `lib.mtl` = [`MTL`] and nothing else readable.
fn parse(obj: &str) -> Result<Scene, LoadError> {
    parse_with(obj, MTL)
}

fn parse_with(obj: &str, mtl: &str) -> Result<Scene, LoadError> {
    let read = |name: &str| match name {
        "lib.mtl" => Ok(("lib.mtl".to_string(), mtl.to_string())),
        other => Err(format!("cannot read material library {other}: not found")),
    };
    parse_obj(obj, "m.obj", &read)
}

fn messages(e: &LoadError) -> Vec<String> {
    e.diagnostics.iter().map(|d| d.to_string()).collect()
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn quads_stay_quads_and_materials_map() {
    let obj = format!("mtllib lib.mtl\n{SQUARE}usemtl white\nf 1 2 3 4\nusemtl lamp\nf -4 -2 -1\n");
    let s = parse(&obj).unwrap();
    assert_eq!(s.polygons.len(), 2);
    assert_eq!(s.polygons[0].shape, Shape::Parallelogram);
    assert_eq!(s.polygons[0].vertices.len(), 4);
    assert_eq!(s.polygons[0].origin, SourcePos { line: 7, col: 1 });
    assert_eq!(
        s.polygons[1].vertices,
        vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]
    );
    assert_eq!(s.polygons[1].origin.line, 9);
    let white = s.material_of(crate::scene::PolygonId(0));
    assert_eq!(white.name, "white");
    assert_eq!(white.reflectance(), Rgb::splat(0.5));
    assert_eq!(white.emission(), Rgb::BLACK);
    let lamp = s.material_of(crate::scene::PolygonId(1));
    assert_eq!(lamp.emission(), Rgb::new(10.0, 8.0, 6.0));
    assert_eq!(lamp.reflectance(), Rgb::BLACK);
    // `Kd 0.25` is grey; unused materials are kept, in library order.
    assert_eq!(s.materials[2].reflectance(), Rgb::splat(0.25));
    assert_eq!(s.materials.len(), 3);
    // Facing +z (counter-clockwise seen from +z); auto-framed.
    assert_eq!(s.polygons[0].normal, Vec3::Z);
    assert_eq!(s.camera_source, CameraSource::AutoFramed);
}

#[test]
fn faces_without_usemtl_get_the_default_material() {
    let s = parse(&format!(
        "{SQUARE}f 1/1/1 2//2 3/3 4\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 1\n"
    ))
    .unwrap();
    assert_eq!(s.materials.len(), 1);
    assert_eq!(s.materials[0].name, DEFAULT_MATERIAL_NAME);
    assert_eq!(
        s.materials[0].reflectance(),
        Rgb::splat(DEFAULT_REFLECTANCE)
    );
}

#[test]
fn non_planar_and_non_convex_faces_are_triangulated() {
    // A quad folded along its diagonal: two triangles.
    let s = parse("v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    assert_eq!(s.polygons.len(), 2);
    assert!(s
        .polygons
        .iter()
        .all(|p| p.shape == Shape::Triangle && p.normal.z > 0.0));
    let area: f64 = s.polygons.iter().map(|p| p.area).sum();
    assert!(area > 1.0 && area < 1.2, "{area}");
    // An L-shaped hexagon (area 3): four triangles covering it exactly.
    let l = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n";
    let s = parse(l).unwrap();
    assert_eq!(s.polygons.len(), 4);
    let area: f64 = s.polygons.iter().map(|p| p.area).sum();
    assert!((area - 3.0).abs() < 1e-6, "{area}");
    assert!(s
        .polygons
        .iter()
        .all(|p| (p.normal - Vec3::Z).length() < 1e-6));
    // A pentagon with a straight corner is a valid convex polygon.
    let s = parse("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4 5\n").unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(s.polygons[0].shape, Shape::Convex);
    // A quad with a repeated vertex keeps its one real triangle.
    let s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2 3\n").unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert!((s.polygons[0].area - 0.5).abs() < 1e-9);
}

/// The faces of [`non_planar_and_non_convex_faces_are_triangulated`]
/// scaled to a ten-thousandth of a unit and to a hundred thousand units,
/// and turned off the axes so that their coordinates carry `f32` noise,
/// are kept or split alike: the tolerances follow each face's size.
#[test]
fn faces_are_kept_or_split_alike_at_any_size() {
    // Each face, the shape it is kept as (`None`: split into triangles),
    // and its area at scale 1 (`None`: not flat).
    type Face<'a> = (&'a [[f64; 3]], Option<Shape>, Option<f64>);
    let faces: [Face; 4] = [
        (
            &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
            Some(Shape::Parallelogram),
            Some(1.0),
        ),
        // A straight corner.
        (
            &[
                [0., 0., 0.],
                [1., 0., 0.],
                [2., 0., 0.],
                [2., 1., 0.],
                [0., 1., 0.],
            ],
            Some(Shape::Convex),
            Some(2.0),
        ),
        // Folded along its diagonal.
        (
            &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.5], [0., 1., 0.]],
            None,
            None,
        ),
        // An L.
        (
            &[
                [0., 0., 0.],
                [2., 0., 0.],
                [2., 1., 0.],
                [1., 1., 0.],
                [1., 2., 0.],
                [0., 2., 0.],
            ],
            None,
            Some(3.0),
        ),
    ];
    let turn = glam::DMat3::from_rotation_z(0.3) * glam::DMat3::from_rotation_x(0.7);
    for scale in [1e-4, 1.0, 1e5] {
        for (face, kept, flat_area) in &faces {
            let mut obj = String::new();
            for p in face.iter() {
                let q = turn * glam::DVec3::from_array(*p) * scale;
                obj += &format!("v {:e} {:e} {:e}\n", q.x as f32, q.y as f32, q.z as f32);
            }
            let indices: Vec<String> = (1..=face.len()).map(|k| k.to_string()).collect();
            obj += &format!("f {}\n", indices.join(" "));
            let s = parse(&obj).unwrap();
            let shapes: Vec<Shape> = s.polygons.iter().map(|p| p.shape).collect();
            match kept {
                Some(shape) => assert_eq!(shapes, vec![*shape], "{face:?} × {scale:e}"),
                None => assert!(
                    shapes.len() >= 2 && shapes.iter().all(|&s| s == Shape::Triangle),
                    "{face:?} × {scale:e}: {shapes:?}"
                ),
            }
            if let Some(flat_area) = flat_area {
                let area: f64 = s.polygons.iter().map(|p| p.area).sum::<f64>() / (scale * scale);
                assert!(
                    (area - flat_area).abs() < 1e-5,
                    "{face:?} × {scale:e}: {area}"
                );
            }
        }
    }
}

/// The warnings of a scene, as printed.
fn warning_lines(s: &Scene) -> Vec<String> {
    s.warnings.iter().map(|w| w.to_string()).collect()
}

/// A sliver (three nearly collinear vertices enclosing a little area, as
/// exporters write at seams) is dropped as a degenerate face, not refused
/// as "not convex".
#[test]
fn sliver_triangles_are_dropped_not_refused() {
    let obj = "v 0 0 0\nv 1000 0 0\nv 2000 0.0009 0\nv 0 1000 0\n\
               f 1 2 4\nf 1 2 3\n";
    let s = parse(obj).unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(
        warning_lines(&s),
        vec![
            "m.obj:6:1: warning: dropped 1 degenerate face(s) (no area, or a vertex \
                 repeated); the first here: triangle is a sliver: its angle at vertex 1 is \
                 almost zero"
        ]
    );
}

#[test]
fn degenerate_faces_are_dropped_with_one_summary_warning() {
    // As 3ds Max writes them at UV seams: zero-area slivers and
    // repeated indices, between real faces; CRLF line ends.
    let obj = "# 3ds Max Wavefront OBJ Exporter v0.97b\r\n\
                   v 0 0 0\r\nv 1 0 0\r\nv 2 0 0\r\nv 0 1 0\r\n\
                   vt 0 0\r\nvn 0 0 1\r\ng Box001\r\ns 1\r\n\
                   f 1/1/1 2/1/1 3/1/1\r\nf 1 2 4\r\n  f 1 1 2 2\r\nf 2 2 4\r\nf 1 2 3\r\n";
    let s = parse(obj).unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(s.polygons[0].origin.line, 11);
    assert_eq!(
        warning_lines(&s),
        vec![
            "m.obj:10:1: warning: dropped 4 degenerate face(s) (no area, or a vertex \
                 repeated); the first here: polygon has zero area"
        ]
    );
    // Syntax stays an error; a file with nothing left has no faces.
    let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n").unwrap_err();
    assert_eq!(
        messages(&e),
        vec!["m.obj:5:1: error: face has 2 vertices; at least 3 are needed"]
    );
    let e = parse("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap_err();
    assert_eq!(
        messages(&e),
        vec!["m.obj:1:1: error: OBJ file has no faces"]
    );
}

#[test]
fn bad_numbers_and_indices_are_errors_with_columns() {
    let obj =
        "v 0 0 0\nv 1 0 x\nv 1 1\nv 0 1 nan\nf 1 2 5\nf 1 -5 2\nf 1 0 2\nf 1/7 2 3\nf 1//x 2 3\n";
    let e = parse(obj).unwrap_err();
    assert_eq!(
            messages(&e),
            vec![
                "m.obj:2:7: error: invalid number `x`",
                "m.obj:3:1: error: `v` needs at least 3 numbers, found 2",
                "m.obj:4:7: error: `nan` is not allowed: numbers must be finite",
                "m.obj:5:7: error: vertex index 5 in `5` is out of range: 4 vertices are defined in the file (indices count from 1)",
                "m.obj:6:5: error: vertex index -5 in `-5` is out of range: 4 vertices are defined above this line",
                "m.obj:7:5: error: vertex index 0 in `0` is out of range: 4 vertices are defined in the file (indices count from 1)",
                "m.obj:9:3: error: invalid face vertex `1//x`: `x` is not a whole number",
            ]
        );
}

#[test]
fn texture_coordinates_and_normals_that_do_not_exist_are_dropped_with_a_warning() {
    // As three.js's verify.obj: four `vt`, corners naming 7 to 10;
    // and a normal index past the two `vn`. CRLF line ends.
    let obj = "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv 0 0 1\r\n\
                   vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\nvn 0 0 1\r\nvn 0 1 0\r\n\
                   f 1/7/1 2/8/1 3/9/1\r\n\
                   f 1/1/1   3/10/1 4/4/9\r\n\
                   f 1//2 2//2 5/3/2\r\n";
    let s = parse(obj).unwrap();
    assert_eq!(s.polygons.len(), 3, "every face loads");
    assert_eq!(
        warning_lines(&s),
        [
            "m.obj:12:3: warning: 4 face corner(s) name a texture coordinate that does not \
                 exist (first `1/7/1`); read without it (texture coordinates serve only the --lightmap model)",
            "m.obj:13:18: warning: 1 face corner(s) name a normal that does not exist \
                 (first `4/4/9`); read without it (normals only join smooth surfaces)",
        ]
    );
    // The corners kept their valid normals: the first two faces share
    // `1//1` and `3//1`, one smooth surface; the third has its own.
    let ids: Vec<_> = s.polygons.iter().map(|p| p.surface.smooth).collect();
    assert_eq!(ids[0], ids[1]);
    assert!(ids[0].is_some() && ids[2] != ids[0], "{ids:?}");
    // A vertex that does not exist stays an error.
    let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 4/5\n").unwrap_err();
    assert_eq!(
            messages(&e),
            vec!["m.obj:5:11: error: vertex index 4 in `4/5` is out of range: 3 vertices are defined in the file (indices count from 1)"]
        );
}

#[test]
fn without_references_keeps_what_exists() {
    assert_eq!(without_references("7/9/2", [true, false]), "7//2");
    assert_eq!(without_references("7/9/2", [false, true]), "7/9");
    assert_eq!(without_references("7/9/2", [true, true]), "7");
    assert_eq!(without_references("7//2", [false, true]), "7");
    assert_eq!(without_references("-3/-1", [true, false]), "-3");
    assert_eq!(without_references("5", [false, false]), "5");
}

#[test]
fn errors_the_reader_finds_are_placed_on_their_line() {
    // Five numbers on a `v` line: neither w nor a colour.
    let e = parse(&format!("{SQUARE}\n  v 1 2 3 4 5\nf 1 2 3\n")).unwrap_err();
    let m = messages(&e);
    assert_eq!(m.len(), 1, "{m:?}");
    assert!(
        m[0].starts_with("m.obj:6:3: error: cannot read OBJ: "),
        "{m:?}"
    );
}

#[test]
fn material_problems_name_the_mtl_file() {
    // `Kd` 1 and an undefined material are warnings now (see the
    // tests below); these stay errors.
    let mtl =
        "newmtl a\nKd 0.5 1.0 0.2\nnewmtl b\nKe 1 -2 3\nKd 1 2\nnewmtl a\nKd spectral x.spd\n";
    let obj = format!("mtllib lib.mtl\n{SQUARE}usemtl a\nf 1 2 3\nusemtl nope\nf 1 3 4\n");
    let e = parse_with(&obj, mtl).unwrap_err();
    assert_eq!(
        messages(&e),
        vec![
            "lib.mtl:4:6: error: `Ke` channel -2 is negative; channels must be >= 0",
            "lib.mtl:5:1: error: `Kd` takes 3 numbers (r g b) or 1 (grey), found 2",
            "lib.mtl:6:1: error: material `a` is already defined in lib.mtl at 1:1",
            "lib.mtl:7:4: error: `Kd spectral` is not supported: give r g b values",
        ]
    );
    // A material used before its library.
    let obj = format!("usemtl white\nmtllib lib.mtl\n{SQUARE}f 1 2 3\n");
    let e = parse(&obj).unwrap_err();
    assert_eq!(
            messages(&e),
            vec![
                "m.obj:1:1: error: material `white` is used before the `mtllib` that defines it (line 2)",
            ]
        );
}

#[test]
fn emitters_that_also_reflect_keep_ke_and_the_luminance_of_kd() {
    let mtl = "newmtl glow\nKd 0.5 0.5 0.5\nKe 4 2 2\n";
    let s = parse_with(
        &format!("mtllib lib.mtl\nusemtl glow\n{SQUARE}f 1 2 3\n"),
        mtl,
    )
    .unwrap();
    let m = &s.materials[0];
    assert_eq!(m.emission(), Rgb::new(4.0, 2.0, 2.0));
    let rho = m.reflectance();
    assert!((rho.luminance() - 0.5).abs() < 1e-9 || rho.max_channel() <= 0.5 + 1e-12);
    assert!(rho.max_channel() < 1.0);
    assert!((rho.r / rho.g - 2.0).abs() < 1e-9, "{rho:?}");
}

#[test]
fn polylines_and_points_are_not_faces() {
    let s = parse(&format!("{SQUARE}l 1 2 3 4\np 1\nl 1 2\nf 1 2 3\n")).unwrap();
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(s.polygons[0].origin.line, 8);
    let e = parse(&format!("{SQUARE}l 1 2 3\n")).unwrap_err();
    assert_eq!(
        messages(&e),
        vec!["m.obj:1:1: error: OBJ file has no faces"]
    );
}

#[test]
fn load_obj_reads_libraries_next_to_the_file_and_a_sidecar_camera() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lib.mtl"), MTL).unwrap();
    let obj = dir.path().join("m.obj");
    std::fs::write(
        &obj,
        format!("mtllib lib.mtl\nusemtl lamp\n{SQUARE}f 1 2 3 4\n"),
    )
    .unwrap();
    let cam = dir.path().join("cam.sc");
    std::fs::write(
        &cam,
        "camera eye 0.5 0.5 3 lookat 0.5 0.5 0 size 32 24 end\n",
    )
    .unwrap();
    let s = load_obj(&obj, Some(&cam), &InputSet::default()).unwrap();
    assert_eq!(s.camera_source, CameraSource::File);
    assert_eq!((s.camera.width, s.camera.height), (32, 24));
    assert_eq!(s.materials[s.polygons[0].material.index()].name, "lamp");
    // The dispatch by extension, and the camera override for .sc too.
    assert_eq!(crate::scene::load(&obj).unwrap().polygons, s.polygons);
    let missing = dir.path().join("none.obj");
    let e = load_obj(&missing, None, &InputSet::default()).unwrap_err();
    assert!(
        messages(&e)[0].contains("none.obj: error: cannot read: "),
        "{e}"
    );
    let e = load_obj(
        &obj,
        Some(&dir.path().join("nocam.sc")),
        &InputSet::default(),
    )
    .unwrap_err();
    assert!(
        messages(&e)[0].contains("nocam.sc: error: cannot read: "),
        "{e}"
    );
}

/// A Blender 2.93 export: header, object, normals, texture
/// coordinates, smoothing off, and the material it writes.
const BLENDER_OBJ: &str = "# Blender v2.93.0 OBJ File: ''\n# www.blender.org\n\
        mtllib lib.mtl\no Plane\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n";

/// A `newmtl` block as Blender writes it, with `extra` lines after `Kd`.
fn blender_block(name: &str, kd: &str, extra: &str) -> String {
    format!(
        "newmtl {name}\nNs 225.000000\nKa 1.000000 1.000000 1.000000\n{kd}\
             {extra}Ke 0.000000 0.000000 0.000000\nNi 1.450000\nd 1.000000\nillum 1\n"
    )
}

#[test]
fn kd_at_or_above_one_is_scaled_below_one_with_one_warning_per_material() {
    let mtl = format!(
        "# Blender MTL File: 'None'\n# Material Count: 3\n\n{}\n{}\n{}",
        blender_block("white", "Kd 1.000000 1.000000 1.000000\n", ""),
        blender_block("orange", "Kd 1.2 0.6 0.3\n", ""),
        blender_block("grey", "Kd 0.5 0.5 0.5\n", ""),
    );
    let obj = format!("{BLENDER_OBJ}usemtl white\ns off\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
    let s = parse_with(&obj, &mtl).unwrap();
    assert_eq!(
        s.materials[0].reflectance(),
        Rgb::splat(MAX_MTL_REFLECTANCE)
    );
    let orange = s.materials[1].reflectance();
    assert!((orange.r - MAX_MTL_REFLECTANCE).abs() < 1e-12);
    assert!((orange.g - MAX_MTL_REFLECTANCE / 2.0).abs() < 1e-12);
    assert!((orange.b - MAX_MTL_REFLECTANCE / 4.0).abs() < 1e-12);
    assert_eq!(s.materials[2].reflectance(), Rgb::splat(0.5));
    assert_eq!(
            warning_lines(&s),
            vec![
                "lib.mtl:7:1: warning: material `white`: `Kd 1 1 1` reflects all light or more; scaled to 0.95 0.95 0.95 (brightest channel 0.95)",
                "lib.mtl:16:1: warning: material `orange`: `Kd 1.2 0.6 0.3` reflects all light or more; scaled to 0.95 0.475 0.237 (brightest channel 0.95)",
            ]
        );
}

#[test]
fn a_material_without_kd_gets_the_default_reflectance_with_a_warning() {
    let mtl = "newmtl bare\nNs 10\nnewmtl lamp\nKe 5 5 5\nnewmtl red\nKd 0.6 0.1 0.1\n";
    let obj = format!("{BLENDER_OBJ}usemtl bare\nf 1 2 3\nusemtl red\nf 1 3 4\n");
    let s = parse_with(&obj, mtl).unwrap();
    assert_eq!(
        s.material_of(crate::scene::PolygonId(0)).reflectance(),
        Rgb::splat(DEFAULT_REFLECTANCE)
    );
    assert_eq!(
        s.material_of(crate::scene::PolygonId(1)).reflectance(),
        Rgb::new(0.6, 0.1, 0.1)
    );
    assert_eq!(
        warning_lines(&s),
        vec!["lib.mtl: warning: no `Kd` in bare, lamp: reflectance 0.8 (the default)"]
    );
}

#[test]
fn specular_glass_and_metal_are_treated_as_diffuse_in_one_warning_per_file() {
    let mtl = format!(
        "{}{}{}{}{}newmtl chrome\nKd 0.5 0.5 0.5\nPm 1.0\nPr 0.1\n",
        blender_block("matte", "Kd 0.5 0.5 0.5\n", "Ks 0 0 0\n"),
        blender_block("plastic", "Kd 0.5 0.5 0.5\n", "Ks 0.9 0.9 0.9\n"),
        blender_block("default", "Kd 0.5 0.5 0.5\n", "Ks 0.5 0.5 0.5\nPr 0.5\n"),
        "newmtl glass\nKd 0.1 0.1 0.1\nNi 1.5\nd 0.2\nillum 7\n",
        "newmtl tinted\nKd 0.2 0.2 0.2\nTr 0.4\n",
    );
    let obj = format!("{BLENDER_OBJ}usemtl glass\nf 1 2 3\n");
    let s = parse_with(&obj, &mtl).unwrap();
    assert_eq!(s.materials[3].reflectance(), Rgb::splat(0.1));
    assert_eq!(
        warning_lines(&s),
        vec![
            "lib.mtl: warning: treated as diffuse: plastic (Ks 0.9), glass (d 0.2, illum 7, \
                 Ni 1.5), tinted (Tr 0.4), chrome (Pm 1, Pr 0.1)"
        ]
    );
}

#[test]
fn unreadable_libraries_and_undefined_materials_warn_and_use_the_default() {
    // CRLF; two names on one `mtllib` line, one missing; a `\` path.
    let read = |name: &str| match name {
        "lib.mtl" => Ok(("lib.mtl".to_string(), MTL.to_string())),
        "sub/more.mtl" => Ok((
            "sub/more.mtl".to_string(),
            "newmtl blue\r\nKd 0.1 0.1 0.7\r\n".to_string(),
        )),
        other => Err(format!("cannot read material library {other}: not found")),
    };
    let obj = "# Blender v2.93.0 OBJ File: ''\r\nmtllib lib.mtl gone.mtl\r\n\
                   mtllib sub\\more.mtl\r\no Plane\r\n\
                   v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n\
                   usemtl white\r\nf 1 2 3\r\nusemtl blue\r\nf 1 3 4\r\n\
                   usemtl nope\r\nf 1 2 4\r\nusemtl nope\r\nf 2 3 4\r\nusemtl gone_red\r\nf 1 4 2\r\n";
    let s = parse_obj(obj, "m.obj", &read).unwrap();
    let names: Vec<&str> = (0..5)
        .map(|i| {
            s.material_of(crate::scene::PolygonId(i as u32))
                .name
                .as_str()
        })
        .collect();
    assert_eq!(
        names,
        [
            "white",
            "blue",
            DEFAULT_MATERIAL_NAME,
            DEFAULT_MATERIAL_NAME,
            DEFAULT_MATERIAL_NAME
        ]
    );
    assert_eq!(
        s.material_of(crate::scene::PolygonId(1)).reflectance(),
        Rgb::new(0.1, 0.1, 0.7)
    );
    assert_eq!(
            warning_lines(&s),
            vec![
                "lib.mtl: warning: treated as diffuse: white (Ks 0.8)",
                "m.obj:2:1: warning: cannot read material library gone.mtl: not found; faces using its materials get the default material",
                "m.obj:3:1: warning: 1 `mtllib` path(s) written with `\\` (first `sub\\more.mtl`), read with `/`",
                "m.obj:13:1: warning: undefined material `nope` (2 `usemtl` line(s), the first here): no `mtllib` defines it; its faces get the default material",
                "m.obj:17:1: warning: undefined material `gone_red` (1 `usemtl` line(s), the first here): no `mtllib` defines it; its faces get the default material",
            ]
        );
}

#[test]
fn many_undefined_materials_give_a_bounded_number_of_warnings() {
    let mut obj = SQUARE.to_string();
    for i in 0..MAX_UNDEFINED_WARNINGS + 5 {
        // A face of its own each time: repeated faces are dropped.
        obj.push_str(&format!("v 0 0 {}\nusemtl m{i}\nf 1 2 -1\n", i + 1));
    }
    let s = parse(&obj).unwrap();
    let w = warning_lines(&s);
    assert_eq!(w.len(), MAX_UNDEFINED_WARNINGS + 1);
    assert!(
            w[MAX_UNDEFINED_WARNINGS].ends_with(
                "warning: 5 more undefined materials (the first here): their faces get the default material"
            ),
            "{w:?}"
        );
}

#[test]
fn map_kd_multiplies_kd_by_the_linear_average_of_the_texture() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("tex")).unwrap();
    // Half white, half black: linear average 0.5 (sRGB 188 would look
    // like it, but the average of encoded values would be 127.5/255).
    let mut img = image::RgbImage::new(2, 2);
    img.put_pixel(0, 0, image::Rgb([255, 255, 255]));
    img.put_pixel(1, 0, image::Rgb([255, 255, 255]));
    img.save(dir.path().join("tex/wall.png")).unwrap();
    // One sRGB grey of 188 everywhere: linear 0.5029.
    let grey = image::RgbImage::from_pixel(3, 1, image::Rgb([188, 188, 188]));
    grey.save(dir.path().join("grey.bmp")).unwrap();
    std::fs::write(
        dir.path().join("lib.mtl"),
        "newmtl wall\nKd 0.8 0.8 0.8\nmap_Kd -s 1 1 1 tex\\wall.png\n\
             newmtl floor\nKd 0.5 0.5 0.5\nmap_Kd grey.bmp\n\
             newmtl lost\nKd 0.3 0.3 0.3\nmap_Kd missing.jpg\n\
             newmtl lost2\nKd 0.3 0.3 0.3\nmap_Kd missing.tga\n",
    )
    .unwrap();
    let obj = dir.path().join("m.obj");
    std::fs::write(
        &obj,
        format!("mtllib lib.mtl\n{SQUARE}usemtl wall\nf 1 2 3 4\n"),
    )
    .unwrap();
    let s = load_obj(&obj, None, &InputSet::default()).unwrap();
    let rho = |i: usize| s.materials[i].reflectance();
    assert!((rho(0).g - 0.4).abs() < 1e-6, "{:?}", rho(0));
    let srgb188 = srgb_to_linear(188.0 / 255.0);
    assert!((srgb188 - 0.5029).abs() < 1e-4);
    assert!((rho(1).r - 0.5 * srgb188).abs() < 1e-6, "{:?}", rho(1));
    assert_eq!(rho(2), Rgb::splat(0.3));
    let w = warning_lines(&s);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].ends_with(":9:1: warning: cannot read 2 `map_Kd` texture(s), first ")
            || w[0].contains(":9:1: warning: cannot read 2 `map_Kd` texture(s), first "),
        "{w:?}"
    );
    assert!(w[0].contains("missing.jpg (material `lost`)"), "{w:?}");
    assert!(w[0].ends_with("; their materials keep `Kd`"), "{w:?}");
    assert!(
            w[1].ends_with(
                ":3:1: warning: 1 `map_Kd` path(s) written with `\\` (first `tex\\wall.png`), read with `/`"
            ),
            "{w:?}"
        );
}

#[test]
fn smoothing_groups_and_shared_normals_make_smooth_surfaces() {
    // Faces 7 to 12 stand apart from faces 1 to 6: a face that
    // repeated an earlier one would be dropped.
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
                   v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nv 0 0 3\nv 1 0 3\n\
                   vn 0 0 1\nvn 0 0 1\nvn 0 1 0\n\
                   o A\ns 1\nf 1 2 3\nf 1 3 4\n\
                   o B\ns 1\nf 1 2 6\ns off\n\
                   f 7//1 8//1 9//1\nf 7//1 9//1 10//1\nf 7//3 8//3 11//3\n\
                   f 7//2 8//2 12//2\ns 0\nf 9 10 12\n";
    let s = parse(obj).unwrap();
    let ids: Vec<Option<u32>> = s
        .polygons
        .iter()
        .map(|p| p.surface.smooth.map(|i| i.0))
        .collect();
    // `s 1` in A, `s 1` in B (another object: another surface), two
    // faces sharing `1//1` and `3//1`, then a face whose normals
    // nobody shares, one with a normal of its own, one with none.
    assert_eq!(
        ids,
        [
            Some(0),
            Some(0),
            Some(1),
            Some(2),
            Some(2),
            None,
            None,
            None
        ]
    );
}
