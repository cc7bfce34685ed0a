//! Unit tests of the `.sc` loader: every statement, every diagnostic with
//! its position, and the file entry points.

use super::lexer::is_number;
use super::*;
use crate::camera::{DEFAULT_FOV_DEG, DEFAULT_SIZE};
use crate::color::Rgb;
use crate::scene::{CameraSource, MaterialId, Polygon, Shape, SourcePos, MAX_DIAGNOSTICS};
use glam::Vec3;

/// The example at the end of the format's contract.
const EXAMPLE: &str = "\
# a white room lit by one square lamp, with a red box on the floor
camera
  eye 2.5 1.5 -4
  lookat 2.5 1.5 2.5
  up 0 1 0
  fov 50
  size 640 480
end

material white
  color 1 1 1
  k_diffrefl 0.75
end
material red
  color 0.9 0.1 0.1
  k_diffrefl 0.8
end
material lamp
  color 1 0.9 0.8
  k_emission 20
end

# floor, seen from above: counter-clockwise from +y
polygon white
  vertex 0 0 0
  vertex 0 0 5
  vertex 5 0 5
  vertex 5 0 0
end
# lamp under the ceiling, facing down
polygon lamp
  vertex 2 2.99 2
  vertex 3 2.99 2
  vertex 3 2.99 3
  vertex 2 2.99 3
end
transform
  translate 1 0 1
  rotate 0 1 0 30
  box red 0 0 0 1 1 1
end
";

/// A material and nothing else, to put in front of shapes.
const WHITE: &str = "material white k_diffrefl 0.5 end\n";
/// A valid triangle, for files that need some polygon.
const TRIANGLE: &str = "polygon white vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end\n";

fn parse(src: &str) -> Scene {
    match parse_str(src, "t.sc") {
        Ok(s) => {
            for p in &s.polygons {
                assert_eq!(p.validate(), Ok(()));
            }
            s
        }
        Err(e) => panic!("expected the scene to load, got:\n{e}"),
    }
}

/// Every diagnostic as `LINE:COL: MESSAGE`.
fn errors(src: &str) -> Vec<String> {
    match parse_str(src, "t.sc") {
        Ok(_) => panic!("expected an error for:\n{src}"),
        Err(e) => {
            assert!(!e.diagnostics.is_empty());
            e.diagnostics
                .iter()
                .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
                .collect()
        }
    }
}

fn first_error(src: &str) -> String {
    errors(src).swap_remove(0)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

fn has_vertex(p: &Polygon, v: Vec3) -> bool {
    p.vertices.iter().any(|&w| close(w, v))
}

// ------------------------------------------------------------ valid --

#[test]
fn the_contract_example_loads() {
    let s = parse(EXAMPLE);
    assert_eq!(s.polygons.len(), 8, "1 floor + 1 lamp + 6 box faces");
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["white", "red", "lamp"]);
    assert_eq!(s.camera_source, CameraSource::File);
    assert_eq!(s.camera.eye, Vec3::new(2.5, 1.5, -4.0));
    assert_eq!(s.camera.lookat, Vec3::new(2.5, 1.5, 2.5));
    assert!((s.camera.fov_y - 50f32.to_radians()).abs() < 1e-7);
    assert_eq!((s.camera.width, s.camera.height), (640, 480));

    let floor = &s.polygons[0];
    assert_eq!(floor.normal, Vec3::Y);
    assert_eq!(floor.shape, Shape::Parallelogram);
    assert_eq!(floor.origin, SourcePos { line: 24, col: 1 });
    let lamp = &s.polygons[1];
    assert!(close(lamp.normal, -Vec3::Y), "the lamp faces down");
    assert_eq!(s.material_of(crate::scene::PolygonId(1)).name, "lamp");
    let lamp_m = &s.materials[lamp.material.index()];
    assert_eq!(lamp_m.emission(), Rgb::new(20.0, 18.0, 16.0));

    // The box is rotated 30° about +y first, then moved by (1, 0, 1).
    let (sin, cos) = 30f32.to_radians().sin_cos();
    let rotate = |v: Vec3| Vec3::new(cos * v.x + sin * v.z, v.y, -sin * v.x + cos * v.z);
    let place = |v: Vec3| rotate(v) + Vec3::new(1.0, 0.0, 1.0);
    let faces = &s.polygons[2..];
    for corner in [
        Vec3::ZERO,
        Vec3::X,
        Vec3::Z,
        Vec3::ONE,
        Vec3::new(1.0, 0.0, 1.0),
    ] {
        assert!(
            faces.iter().any(|p| has_vertex(p, place(corner))),
            "box corner {corner} should be at {}",
            place(corner)
        );
    }
    // The -x face's normal is the rotated -x axis.
    assert!(close(faces[0].normal, rotate(-Vec3::X)));
    for f in faces {
        assert_eq!(f.material, MaterialId(1));
        assert_eq!(f.shape, Shape::Parallelogram);
        assert!((f.area - 1.0).abs() < 1e-5);
    }
}

#[test]
fn camera_defaults() {
    let s = parse(&format!(
        "camera eye 0 0 -5 lookat 0 0 0 end\n{WHITE}{TRIANGLE}"
    ));
    assert_eq!(s.camera_source, CameraSource::File);
    assert_eq!(s.camera.up, Vec3::Y);
    assert_eq!(s.camera.fov_y, DEFAULT_FOV_DEG.to_radians());
    assert_eq!((s.camera.width, s.camera.height), DEFAULT_SIZE);
}

#[test]
fn camera_every_field() {
    let s = parse(&format!(
        "camera\n size 320 200\n fov 90\n up 0 0 1\n lookat 1 2 3\n eye 4 5 6\nend\n{WHITE}{TRIANGLE}"
    ));
    let c = s.camera;
    assert_eq!(c.eye, Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(c.up, Vec3::Z);
    assert!((c.fov_y - std::f32::consts::FRAC_PI_2).abs() < 1e-7);
    assert_eq!((c.width, c.height), (320, 200));
}

#[test]
fn no_camera_frames_the_scene() {
    let s = parse(&format!("{WHITE}box white -1 0 2 3 4 7\n"));
    assert_eq!(s.camera_source, CameraSource::AutoFramed);
    let c = s.camera;
    assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 4.5));
    assert_eq!(c.up, Vec3::Y);
    assert_eq!((c.width, c.height), DEFAULT_SIZE);
    assert!(c.eye.z < -0.5, "eye on the -z side of the scene");
    // Every vertex is inside the vertical field of view.
    let forward = (c.lookat - c.eye).normalize();
    for p in &s.polygons {
        for &v in &p.vertices {
            let angle = (v - c.eye).normalize().dot(forward).acos();
            assert!(angle <= 0.5 * c.fov_y + 1e-5, "{v} is outside the view");
        }
    }
}

#[test]
fn materials_defaults_and_fields() {
    let s = parse(
        &format!(
            "material plain end\n\
         material glow color 1 0.5 0.25 k_emission 4 k_diffrefl 0.5 end\n\
         {TRIANGLE}"
        )
        .replace("polygon white", "polygon glow"),
    );
    let plain = &s.materials[0];
    assert_eq!(plain.name, "plain");
    assert_eq!(plain.color, Rgb::WHITE);
    assert_eq!((plain.k_diffrefl, plain.k_emission), (0.0, 0.0));
    let glow = &s.materials[1];
    assert_eq!(glow.emission(), Rgb::new(4.0, 2.0, 1.0));
    assert_eq!(glow.reflectance(), Rgb::new(0.5, 0.25, 0.125));
    assert_eq!(s.polygons[0].material, MaterialId(1));
}

#[test]
fn polygon_shapes_are_classified() {
    let s = parse(&format!(
        "{WHITE}{TRIANGLE}\
         polygon white vertex 0 0 0 vertex 2 0 0 vertex 3 1 0 vertex 1 1 0 end\n\
         polygon white vertex 0 0 0 vertex 3 0 0 vertex 2 1 0 vertex 1 1 0 end\n\
         polygon white vertex 0 0 0 vertex 2 0 0 vertex 3 1 0 vertex 1 2 0 vertex -1 1 0 end\n"
    ));
    let shapes: Vec<Shape> = s.polygons.iter().map(|p| p.shape).collect();
    assert_eq!(
        shapes,
        [
            Shape::Triangle,
            Shape::Parallelogram,
            Shape::Quad,
            Shape::Convex
        ]
    );
    assert!(s.polygons.iter().all(|p| p.normal == Vec3::Z));
}

#[test]
fn box_faces_point_outward_with_the_right_areas() {
    // Corners given max-first: the order does not matter.
    for src in [
        "box white 1 2 3 4 6 8",
        "box white 4 6 8 1 2 3",
        "box white 4 2 8 1 6 3",
    ] {
        let s = parse(&format!("{WHITE}{src}\n"));
        assert_eq!(s.polygons.len(), 6);
        let centre = Vec3::new(2.5, 4.0, 5.5);
        let expected_normals = [-Vec3::X, Vec3::X, -Vec3::Y, Vec3::Y, -Vec3::Z, Vec3::Z];
        // Extents 3 × 4 × 5.
        let expected_areas = [20.0, 20.0, 15.0, 15.0, 12.0, 12.0];
        for ((p, n), area) in s.polygons.iter().zip(expected_normals).zip(expected_areas) {
            assert_eq!(p.normal, n);
            let face_centre = p.vertices.iter().sum::<Vec3>() / 4.0;
            assert!((face_centre - centre).dot(p.normal) > 0.0);
            assert!((p.area - area).abs() < 1e-9);
            assert_eq!(p.shape, Shape::Parallelogram);
            assert_eq!(p.origin, SourcePos { line: 2, col: 1 });
        }
    }
}

#[test]
fn transform_lines_act_last_first() {
    // Rotate first, then translate: the corner (1,0,0) turns to -z
    // under a 90° turn about +y and then moves by (10, 0, 0).
    let s = parse(&format!(
        "{WHITE}transform translate 10 0 0 rotate 0 1 0 90 {TRIANGLE} end\n"
    ));
    let p = &s.polygons[0];
    assert!(close(p.vertices[0], Vec3::new(10.0, 0.0, 0.0)));
    assert!(close(p.vertices[1], Vec3::new(10.0, 0.0, -1.0)));
    assert!(close(p.vertices[2], Vec3::new(10.0, 1.0, 0.0)));
    assert!(close(p.normal, Vec3::X));

    // The other order: translate first, then rotate the result.
    let s = parse(&format!(
        "{WHITE}transform rotate 0 1 0 90 translate 10 0 0 {TRIANGLE} end\n"
    ));
    assert!(close(s.polygons[0].vertices[0], Vec3::new(0.0, 0.0, -10.0)));
}

#[test]
fn scale_uniform_and_per_axis() {
    let s = parse(&format!(
        "{WHITE}transform scale 2 {TRIANGLE} scale 1 3 1 {TRIANGLE} end\n"
    ));
    assert!(close(s.polygons[0].vertices[1], Vec3::new(2.0, 0.0, 0.0)));
    assert!((s.polygons[0].area - 2.0).abs() < 1e-9);
    // Both lines act on the second triangle: (0,1,0) → (0,3,0) → (0,6,0).
    assert!(close(s.polygons[1].vertices[2], Vec3::new(0.0, 6.0, 0.0)));
}

#[test]
fn a_line_acts_only_on_what_follows_it() {
    let s = parse(&format!(
        "{WHITE}transform {TRIANGLE} translate 0 0 7 {TRIANGLE} end {TRIANGLE}"
    ));
    assert_eq!(s.polygons[0].vertices[0], Vec3::ZERO);
    assert_eq!(s.polygons[1].vertices[0], Vec3::new(0.0, 0.0, 7.0));
    assert_eq!(s.polygons[2].vertices[0], Vec3::ZERO);
}

#[test]
fn nested_blocks_act_inner_first() {
    let s = parse(&format!(
        "{WHITE}transform\n translate 10 0 0\n transform\n  rotate 0 0 1 90\n  {TRIANGLE} end\n {TRIANGLE}end\n"
    ));
    // Inner: (1,0,0) rotates to (0,1,0), then the outer moves it.
    assert!(close(s.polygons[0].vertices[1], Vec3::new(10.0, 1.0, 0.0)));
    // After the inner block only the outer line applies.
    assert!(close(s.polygons[1].vertices[1], Vec3::new(11.0, 0.0, 0.0)));
}

#[test]
fn mirroring_keeps_fronts_on_the_physical_side() {
    let floor = "polygon white vertex 0 0 0 vertex 0 0 5 vertex 5 0 5 vertex 5 0 0 end";
    // Mirrored left-right, a floor still faces up.
    let s = parse(&format!("{WHITE}transform scale -1 1 1 {floor} end\n"));
    let p = &s.polygons[0];
    assert_eq!(p.normal, Vec3::Y);
    assert_eq!(p.vertices[0], Vec3::ZERO, "the first vertex stays first");
    assert!(has_vertex(p, Vec3::new(-5.0, 0.0, 5.0)));
    // Mirrored upside down, it faces down, as its mirror image does.
    let s = parse(&format!("{WHITE}transform scale 1 -1 1 {floor} end\n"));
    assert_eq!(s.polygons[0].normal, -Vec3::Y);
    // A mirrored box stays closed with outward fronts.
    let s = parse(&format!(
        "{WHITE}transform scale -2 1 1 box white 0 0 0 1 1 1 end\n"
    ));
    let centre = Vec3::new(-1.0, 0.5, 0.5);
    for p in &s.polygons {
        let face_centre = p.vertices.iter().sum::<Vec3>() / 4.0;
        assert!((face_centre - centre).dot(p.normal) > 0.0);
    }
}

#[test]
fn comments_end_tokens_anywhere() {
    let s = parse(
        "material wh#comment right in the name\n k_diffrefl 0.5#and here\n end#\n\
         polygon wh vertex 0 0 0 vertex 1# 2 3\n 0 0 vertex 0 1 0 end # done",
    );
    assert_eq!(s.materials[0].name, "wh");
    assert_eq!(s.materials[0].k_diffrefl, 0.5);
    assert_eq!(s.polygons[0].vertices[1], Vec3::X);
}

#[test]
fn byte_order_mark_is_skipped() {
    let s = parse(&format!("\u{feff}{WHITE}{TRIANGLE}"));
    assert_eq!(s.polygons.len(), 1);
    // Columns on line 1 do not count the mark.
    assert_eq!(first_error("\u{feff}bogus"), "1:1: unknown keyword `bogus`");
}

#[test]
fn every_number_form() {
    let s = parse(&format!(
        "camera eye 1 -0.5 .5 lookat 5. +2 2.5E-3 up 0 1e0 0 fov 4.5e+1 end\n{WHITE}{TRIANGLE}"
    ));
    assert_eq!(s.camera.eye, Vec3::new(1.0, -0.5, 0.5));
    assert_eq!(s.camera.lookat, Vec3::new(5.0, 2.0, 0.0025));
    assert_eq!(s.camera.fov_y, 45f32.to_radians());
}

#[test]
fn number_grammar() {
    for ok in [
        "1", "-0.5", ".5", "5.", "+2", "2.5E-3", "1e5", "0", "-.5e+2",
    ] {
        assert!(is_number(ok), "{ok}");
    }
    for bad in [
        "", ".", "+", "-.", "1e", "1e+", "e5", "1.2.3", "0x10", "1_000", "5.e", "1f",
    ] {
        assert!(!is_number(bad), "{bad}");
    }
}

#[test]
fn name_charset() {
    let s = parse(&format!(
        "material A_b.c-1 end material _ end material Inf2 end {WHITE}{TRIANGLE}"
    ));
    let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["A_b.c-1", "_", "Inf2", "white"]);
    assert_eq!(
        first_error("material 2x end"),
        "1:10: `material` needs a name, found `2x`; names start with a letter or `_`"
    );
    assert_eq!(
        first_error("material nan end"),
        "1:10: `nan` cannot be used as a name"
    );
}

#[test]
fn columns_count_characters_and_tabs_are_one() {
    // `ééé` is 6 bytes but 3 columns; a tab is one column.
    assert_eq!(
        errors("ééé foo\n\tbar"),
        [
            "1:1: unexpected `ééé`: not a keyword, a name or a number",
            "1:5: unknown keyword `foo`",
            "2:2: unknown keyword `bar`",
        ]
    );
}

#[test]
fn crlf_line_ends() {
    let s = parse(&format!("{WHITE}{TRIANGLE}").replace('\n', "\r\n"));
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(
        first_error("\r\n\r\n  bogus\r\n"),
        "3:3: unknown keyword `bogus`"
    );
}

#[test]
fn unused_materials_are_kept() {
    let s = parse(&format!("material spare end {WHITE}{TRIANGLE}"));
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.polygons[0].material, MaterialId(1));
}

// ----------------------------------------------------------- errors --

#[test]
fn diagnostics_name_the_file() {
    match parse_str("bogus", "scenes/room.sc") {
        Err(e) => assert_eq!(
            e.to_string(),
            "scenes/room.sc:1:1: error: unknown keyword `bogus`"
        ),
        Ok(_) => panic!("should fail"),
    }
}

#[test]
fn unknown_keyword() {
    assert_eq!(
        first_error(&format!("{WHITE}\n  lights 1 2 3\n{TRIANGLE}")),
        "3:3: unknown keyword `lights`"
    );
    assert_eq!(
        first_error("camera\n  eye 0 0 0 lookat 0 0 1\n  colour 1 1 1\nend"),
        "3:3: unknown keyword `colour` in camera block \
         (expected `eye`, `lookat`, `up`, `fov`, `size` or `end`)"
    );
    assert_eq!(
        first_error("material m\n  vertex 1 1 1\nend"),
        "2:3: `vertex` is not allowed in a material block \
         (expected `color`, `k_diffrefl`, `k_emission` or `end`)"
    );
    assert_eq!(
        first_error("vertex 0 0 0"),
        "1:1: `vertex` is only allowed inside a polygon block"
    );
    assert_eq!(
        first_error("Camera eye 0 0 0 end"),
        "1:1: unknown keyword `Camera`"
    );
}

#[test]
fn missing_number() {
    assert_eq!(
        first_error("camera\n  eye 1 2\n  lookat 0 0 0\nend"),
        "2:3: missing number: `eye` takes 3 numbers, found 2"
    );
    assert_eq!(
        first_error(&format!("{WHITE}polygon white vertex 0 0 0 vertex 1 0 end")),
        "2:28: missing number: `vertex` takes 3 numbers, found 2"
    );
    assert_eq!(
        first_error(&format!("{WHITE}box white 0 0 0 1 1 end")),
        "2:1: missing number: `box` takes a material name and 6 numbers, found 5"
    );
    assert_eq!(
        first_error(&format!("{WHITE}transform scale 1 2 {TRIANGLE} end")),
        "2:11: missing number: `scale` takes 1 or 3 numbers, found 2"
    );
}

#[test]
fn extra_number() {
    assert_eq!(
        first_error("camera\n  eye 1 2 3 4\n  lookat 0 0 0\nend"),
        "2:13: extra number `4`: `eye` takes 3 numbers"
    );
    assert_eq!(
        first_error(&format!("{WHITE}box white 0 0 0 1 1 1 1")),
        "2:23: extra number `1`: `box` takes a material name and 6 numbers"
    );
    assert_eq!(
        first_error("5 camera"),
        "1:1: unexpected number `5`; expected a keyword"
    );
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white 1 vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"
        )),
        "2:15: extra number `1`: `polygon` takes a material name and no numbers \
         (vertices go on `vertex` lines)"
    );
}

#[test]
fn bad_number_forms() {
    let at_fov = |v: &str| first_error(&format!("camera fov {v} end"));
    assert_eq!(
        at_fov("nan"),
        "1:12: `nan` is not allowed: numbers must be finite decimals"
    );
    assert_eq!(
        at_fov("inf"),
        "1:12: `inf` is not allowed: numbers must be finite decimals"
    );
    assert_eq!(
        at_fov("-Infinity"),
        "1:12: `-Infinity` is not allowed: numbers must be finite decimals"
    );
    assert_eq!(
        at_fov("0x10"),
        "1:12: invalid number `0x10`: numbers are decimal, like 1, -0.5, .5 or 2.5e-3"
    );
    assert_eq!(
        at_fov("1e999"),
        "1:12: number `1e999` is out of range (it overflows to infinity)"
    );
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white vertex 1e39 0 0 vertex 1 0 0 vertex 0 1 0 end"
        )),
        "2:22: number `1e39` is too large for a coordinate (at most 1e12 in magnitude)"
    );
}

#[test]
fn size_must_be_whole_positive_pixels() {
    let at_size = |v: &str| first_error(&format!("camera\n  size {v}\nend"));
    assert_eq!(
        at_size("640.0 480"),
        "2:8: `size` needs whole numbers of pixels (digits only), found `640.0`"
    );
    assert_eq!(
        at_size("640 +480"),
        "2:12: `size` needs whole numbers of pixels (digits only), found `+480`"
    );
    assert_eq!(
        at_size("640 0"),
        "2:12: `size` must be at least 1 pixel, found `0`"
    );
    assert_eq!(
        at_size("99999999999 1"),
        "2:8: `size` `99999999999` is too large (at most 4294967295)"
    );
    assert_eq!(
        at_size("100000 100000"),
        "2:8: `size` 100000x100000 is too large: each side may be at most 65536 pixels \
         and the picture at most 67108864 pixels (8192x8192)"
    );
    assert!(at_size("65536 1025").contains("too large"));
    assert!(
        parse_str("camera eye 0 0 -1 lookat 0 0 0 size 8192 8192 end", "a.sc")
            .unwrap_err()
            .to_string()
            .contains("no polygons")
    );
}

#[test]
fn fov_out_of_range() {
    for (v, col) in [("0", 12), ("180", 12), ("-5", 12), ("1000", 12)] {
        assert_eq!(
            first_error(&format!("camera fov {v} end")),
            format!(
                "1:{col}: `fov` {v} is out of range; it must be more than 0 and less than 180 degrees"
            )
        );
    }
}

#[test]
fn negative_color_and_coefficients() {
    assert_eq!(
        first_error("material m\n  color 1 -0.5 1\nend"),
        "2:11: `color` channel -0.5 is negative; channels must be >= 0"
    );
    assert_eq!(
        first_error("material m k_emission -1 end"),
        "1:23: `k_emission` -1 is negative; it must be >= 0"
    );
    assert_eq!(
        first_error("material m k_diffrefl -0.1 end"),
        "1:23: `k_diffrefl` -0.1 is negative; it must be >= 0"
    );
}

#[test]
fn reflectance_must_stay_below_one() {
    assert_eq!(
        first_error("material m\n  color 0.5 1.25 1\n  k_diffrefl 0.8\nend"),
        "3:3: reflectance `k_diffrefl` × `color` is 1 in the green channel; \
         every channel must be below 1"
    );
    // Emission may be as large as it likes.
    parse(&format!(
        "material m color 2 2 2 k_emission 100 k_diffrefl 0.49 end {}",
        TRIANGLE.replace("white", "m")
    ));
}

#[test]
fn duplicate_field() {
    assert_eq!(
        first_error("camera\n  eye 0 0 0\n  lookat 0 0 1\n  eye 1 1 1\nend"),
        "4:3: duplicate `eye` in camera block (first at 2:3)"
    );
    assert_eq!(
        first_error("material m color 1 1 1 color 0 0 0 end"),
        "1:24: duplicate `color` in material block (first at 1:12)"
    );
}

#[test]
fn duplicate_material() {
    assert_eq!(
        first_error(&format!("{WHITE}\nmaterial white end {TRIANGLE}")),
        "3:10: material `white` is already defined at 1:1"
    );
}

#[test]
fn undefined_material() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon black vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"
        )),
        "2:9: undefined material `black`"
    );
    assert_eq!(
        first_error("box black 0 0 0 1 1 1"),
        "1:5: undefined material `black`"
    );
}

#[test]
fn material_used_before_its_definition() {
    assert_eq!(
        errors(&format!("{TRIANGLE}{WHITE}")),
        ["1:9: material `white` is used before its definition at 2:1"]
    );
}

#[test]
fn keyword_as_name() {
    assert_eq!(
        first_error("material box end"),
        "1:10: `box` is a keyword and cannot be used as a name"
    );
    assert_eq!(
        first_error("material color 1 1 1 end"),
        "1:10: missing name: `material` needs a name before `color`"
    );
    assert_eq!(
        first_error("polygon vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"),
        "1:9: missing name: `polygon` needs a material name before `vertex`"
    );
}

#[test]
fn fewer_than_three_vertices() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}\npolygon white\n  vertex 0 0 0\n  vertex 1 0 0\nend"
        )),
        "3:1: polygon has 2 vertices; at least 3 are needed"
    );
    assert_eq!(
        first_error(&format!("{WHITE}polygon white end")),
        "2:1: polygon has 0 vertices; at least 3 are needed"
    );
}

#[test]
fn equal_consecutive_vertices() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white vertex 0 0 0 vertex 1 0 0 vertex 1 0 0 vertex 0 1 0 end"
        )),
        "2:1: vertices 2 and 3 are equal"
    );
}

#[test]
fn non_planar_polygon() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0.5 end"
        )),
        "2:1: polygon is not planar: vertex 1 is 0.118 units from the plane (tolerance 0.0015)"
    );
}

#[test]
fn non_convex_polygon() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white vertex 0 0 0 vertex 2 0 0 vertex 1 0.5 0 \
             vertex 2 2 0 vertex 0 2 0 end"
        )),
        "2:1: polygon is not convex at vertex 3"
    );
}

#[test]
fn zero_area_polygon() {
    assert_eq!(
        first_error(&format!(
            "{WHITE}polygon white vertex 0 0 0 vertex 1 1 1 vertex 2 2 2 end"
        )),
        "2:1: polygon has zero area"
    );
}

#[test]
fn zero_extent_box() {
    assert_eq!(
        first_error(&format!("{WHITE}\n  box white 0 1 0 1 1 1")),
        "3:3: box has zero extent along y; it would be flat"
    );
}

#[test]
fn zero_scale_and_zero_axis() {
    assert_eq!(
        first_error(&format!("{WHITE}transform scale 1 0 1 {TRIANGLE} end")),
        "2:19: scale factor `0` is zero; factors must be non-zero"
    );
    assert_eq!(
        first_error(&format!("{WHITE}transform scale -0.0 {TRIANGLE} end")),
        "2:17: scale factor `-0.0` is zero; factors must be non-zero"
    );
    assert_eq!(
        first_error(&format!("{WHITE}transform rotate 0 0 0 45 {TRIANGLE} end")),
        "2:18: rotation axis is zero; it must give a direction"
    );
}

#[test]
fn transform_lines_outside_a_transform() {
    assert_eq!(
        first_error("translate 1 2 3"),
        "1:1: `translate` is only allowed inside a transform block"
    );
}

#[test]
fn unterminated_blocks() {
    assert_eq!(
        errors(&format!("{WHITE}\n  polygon white\n  vertex 0 0 0\n")),
        ["3:3: unterminated `polygon` block: end of file before its `end`"]
    );
    assert_eq!(
        errors(&format!("{WHITE}transform\n transform\n{TRIANGLE}end\n")),
        ["2:1: unterminated `transform` block: end of file before its `end`"]
    );
    // A statement keyword inside a block means its `end` is missing;
    // the statement itself is still read.
    assert_eq!(
        errors(&format!(
            "camera eye 0 0 -1 lookat 0 0 0\n{WHITE}{TRIANGLE}"
        )),
        ["1:1: unterminated `camera` block: `material` at 2:1 comes before its `end`"]
    );
}

#[test]
fn end_without_a_block() {
    assert_eq!(
        first_error(&format!("{WHITE}{TRIANGLE}end")),
        "3:1: `end` without an open block"
    );
}

#[test]
fn second_camera() {
    let cam = "camera eye 0 0 -1 lookat 0 0 0 end\n";
    assert_eq!(
        errors(&format!("{cam}{cam}{WHITE}{TRIANGLE}")),
        ["2:1: second `camera` block; the first is at 1:1"]
    );
}

#[test]
fn camera_and_material_inside_transform() {
    assert_eq!(
        errors(&format!(
            "transform\n  camera eye 0 0 -1 lookat 0 0 0 end\nend\n{WHITE}{TRIANGLE}"
        )),
        ["2:3: `camera` is not allowed inside a transform block"]
    );
    assert_eq!(
        errors(&format!("transform\n  {WHITE}end\n{TRIANGLE}")),
        ["2:3: `material` is not allowed inside a transform block"]
    );
}

#[test]
fn camera_geometry_errors() {
    assert_eq!(
        first_error("camera\n  lookat 0 0 0\nend"),
        "1:1: camera block has no `eye`"
    );
    assert_eq!(
        errors("camera end"),
        [
            "1:1: camera block has no `eye`",
            "1:1: camera block has no `lookat`"
        ]
    );
    assert_eq!(
        first_error("camera\n  eye 1 2 3\n  lookat 1 2 3\nend"),
        "3:3: `lookat` equals `eye`; the camera has no view direction"
    );
    assert_eq!(
        first_error("camera eye 0 0 0 lookat 0 5 0 end"),
        "1:1: `up` (0 1 0) is parallel to the view direction; \
         the picture's up would be undefined"
    );
    assert_eq!(
        first_error("camera eye 0 0 0 lookat 0 0 1 up 0 0 -2 end"),
        "1:31: `up` (0 0 -2) is parallel to the view direction; \
         the picture's up would be undefined"
    );
    assert_eq!(
        first_error("camera eye 0 0 0 lookat 0 0 1 up 0 0 0 end"),
        "1:31: `up` is zero; it must give a direction"
    );
}

#[test]
fn empty_scene() {
    assert_eq!(errors(""), ["1:1: scene has no polygons"]);
    assert_eq!(
        errors(&format!("# just a material\n{WHITE}")),
        ["1:1: scene has no polygons"]
    );
}

#[test]
fn independent_errors_are_all_reported_in_file_order() {
    let src = format!(
        "{TRIANGLE}\
         material m color 1 1 -1 end\n\
         bogus 1 2\n\
         camera fov 200 end\n\
         {WHITE}"
    );
    assert_eq!(
        errors(&src),
        [
            "1:9: material `white` is used before its definition at 5:1",
            "2:22: `color` channel -1 is negative; channels must be >= 0",
            "3:1: unknown keyword `bogus`",
            "4:12: `fov` 200 is out of range; it must be more than 0 and less than 180 degrees",
        ]
    );
}

#[test]
fn diagnostics_are_capped() {
    let src = "bogus\n".repeat(3 * MAX_DIAGNOSTICS);
    assert_eq!(errors(&src).len(), MAX_DIAGNOSTICS);
}

#[test]
fn never_panics_on_damaged_input() {
    // Every prefix of the example, and the example with bytes replaced
    // by a fixed pseudo-random sequence: each must load or fail cleanly.
    let chars: Vec<char> = EXAMPLE.chars().collect();
    for n in 0..chars.len() {
        let prefix: String = chars[..n].iter().collect();
        let _ = parse_str(&prefix, "t.sc");
    }
    let alphabet: Vec<char> = " \n#-+.e0159abxyz_\u{e9}endvertexboxtransform"
        .chars()
        .collect();
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..2000 {
        let mut damaged = chars.clone();
        for _ in 0..(next() % 6 + 1) {
            let i = (next() % damaged.len() as u64) as usize;
            damaged[i] = alphabet[(next() % alphabet.len() as u64) as usize];
        }
        let text: String = damaged.into_iter().collect();
        let _ = parse_str(&text, "t.sc");
    }
}

#[test]
fn deep_nesting_does_not_overflow_the_stack() {
    let src = format!(
        "{WHITE}{}{TRIANGLE}{}",
        "transform translate 0 0 1\n".repeat(100_000),
        "end\n".repeat(100_000)
    );
    let s = parse(&src);
    assert_eq!(s.polygons[0].vertices[0], Vec3::new(0.0, 0.0, 100_000.0));
}

// ------------------------------------------------------------ files --

/// A file in the system's temporary directory, removed when dropped.
struct TempFile(std::path::PathBuf);

impl TempFile {
    fn new(name: &str, bytes: &[u8]) -> Self {
        let path =
            std::env::temp_dir().join(format!("radiosity-sc-test-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).expect("write a temporary file");
        TempFile(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn load_file_reads_and_parses() {
    let f = TempFile::new("ok.sc", format!("\u{feff}{WHITE}{TRIANGLE}").as_bytes());
    match load_file(&f.0, &InputSet::default()) {
        Ok(s) => assert_eq!(s.polygons.len(), 1),
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn load_file_reports_the_first_bad_utf8_byte() {
    let f = TempFile::new("bad.sc", b"\xEF\xBB\xBFmaterial m\n  color \xff 1 1\nend\n");
    match load_file(&f.0, &InputSet::default()) {
        Ok(_) => panic!("should fail"),
        Err(e) => {
            let d = &e.diagnostics[0];
            assert_eq!(e.diagnostics.len(), 1);
            assert_eq!((d.line, d.col), (2, 9));
            assert_eq!(d.message, "file is not valid UTF-8");
            assert_eq!(d.file, f.0.display().to_string());
        }
    }
    // A truncated multi-byte character at the very end.
    match decode(
        "é\nab\u{e9}"
            .as_bytes()
            .split_last()
            .map_or(&[][..], |x| x.1),
        "t.sc",
    ) {
        Ok(_) => panic!("should fail"),
        Err(e) => assert_eq!(e.to_string(), "t.sc:2:3: error: file is not valid UTF-8"),
    }
}

#[test]
fn load_file_reports_unreadable_files() {
    let path = std::env::temp_dir().join("radiosity-sc-test-does-not-exist.sc");
    match load_file(&path, &InputSet::default()) {
        Ok(_) => panic!("should fail"),
        Err(e) => {
            let d = &e.diagnostics[0];
            // No position: there is no text to point into.
            assert_eq!((d.line, d.col), (0, 0));
            assert!(d.message.starts_with("cannot read: "), "{}", d.message);
        }
    }
}

#[test]
fn camera_files_need_a_camera_but_no_polygons() {
    let cam = "camera\n  eye 1 2 3\n  lookat 1 2 4\n  fov 30\n  size 64 48\nend\n";
    let c = parse_camera_str(cam, "cam.sc").unwrap();
    assert_eq!(c.eye, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 4.0));
    assert_eq!((c.width, c.height), (64, 48));
    assert!((c.fov_y - 30f32.to_radians()).abs() < 1e-6);
    // A whole scene is accepted too; its camera is taken.
    let with_scene =
        format!("{cam}material m color 0.5 0.5 0.5 k_diffrefl 1 end box m 0 0 0 1 1 1\n");
    assert_eq!(parse_camera_str(&with_scene, "s.sc").unwrap(), c);
    // No camera block: an error at the start of the file.
    let e = parse_camera_str("# nothing\n", "empty.sc").unwrap_err();
    assert_eq!(
        e.to_string(),
        "empty.sc:1:1: error: camera file has no `camera` block"
    );
    // Mistakes are reported as in any scene file.
    let e = parse_camera_str("camera\n  eye 0 0 0\n  lookat 0 0 0\nend\n", "bad.sc").unwrap_err();
    assert_eq!(e.first().map(|d| (d.line, d.col)), Some((3, 3)), "{e}");
}
