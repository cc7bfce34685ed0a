//! Splitting along intersections: which configurations cut, what the
//! pieces are, what is kept, and the cost on a large scene.

use super::*;
use crate::scene::{Group, GroupKind, MaterialId, SmoothId, SourcePos, Surface};
use crate::testutil::{grey, polygon, scene};
use glam::Vec3;
use std::time::Instant;

/// The floor `[x0, x1] × {y} × [z0, z1]`, facing up.
fn floor(x0: f32, x1: f32, z0: f32, z1: f32, y: f32) -> Polygon {
    polygon(0, &[[x0, y, z0], [x0, y, z1], [x1, y, z1], [x1, y, z0]])
}

/// The wall `{x} × [y0, y1] × [z0, z1]`, facing +x.
fn wall(x: f32, y0: f32, y1: f32, z0: f32, z1: f32) -> Polygon {
    polygon(0, &[[x, y0, z0], [x, y1, z0], [x, y1, z1], [x, y0, z1]])
}

/// The six outward faces of the box `[lo, hi]`, in the order -x, +x, -y,
/// +y, -z, +z.
fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> Vec<Polygon> {
    let [a, b, c] = lo;
    let [d, e, f] = hi;
    vec![
        polygon(0, &[[a, b, c], [a, b, f], [a, e, f], [a, e, c]]),
        polygon(0, &[[d, b, c], [d, e, c], [d, e, f], [d, b, f]]),
        polygon(0, &[[a, b, c], [d, b, c], [d, b, f], [a, b, f]]),
        polygon(0, &[[a, e, c], [a, e, f], [d, e, f], [d, e, c]]),
        polygon(0, &[[a, b, c], [a, e, c], [d, e, c], [d, b, c]]),
        polygon(0, &[[a, b, f], [d, b, f], [d, e, f], [a, e, f]]),
    ]
}

fn make(polygons: Vec<Polygon>) -> Scene {
    scene(polygons, vec![grey("white", 0.0, 0.5)])
}

/// Lowest and highest coordinate `axis` of a polygon's vertices.
fn span(p: &Polygon, axis: usize) -> (f32, f32) {
    p.vertices.iter().fold((f32::MAX, f32::MIN), |(lo, hi), v| {
        (lo.min(v[axis]), hi.max(v[axis]))
    })
}

fn total_area(s: &Scene) -> f64 {
    s.polygons.iter().map(|p| p.area).sum()
}

/// Splits `s` and checks what every split must keep: valid pieces, the
/// total area, and nothing more to cut on a second pass.
fn split_checked(s: &mut Scene) -> SplitStats {
    let area = total_area(s);
    let count = s.polygons.len();
    let stats = s.split_intersections();
    assert_eq!(s.polygons.len(), count - stats.polygons_cut + stats.pieces);
    for p in &s.polygons {
        assert_eq!(p.validate(), Ok(()), "{p:?}");
    }
    assert!((total_area(s) - area).abs() < 1e-6 * area, "area changed");
    let again = s.clone().split_intersections();
    assert_eq!(again, SplitStats::default(), "a second pass cut again");
    stats
}

/// A wall's single polygon continuing 0.5 below a floor that ends at it
/// is cut at the floor into its visible and its buried part; the floor
/// is not cut, and each piece keeps the wall's material, origin, surface
/// and front.
#[test]
fn a_sunk_wall_is_cut_at_the_floor() {
    let mut w = wall(0.0, -0.5, 2.0, 0.0, 2.0);
    w.material = MaterialId(1);
    w.origin = SourcePos { line: 7, col: 1 };
    w.surface = Surface {
        two_sided: true,
        back_of: None,
        smooth: Some(SmoothId(3)),
        ..Surface::default()
    };
    let mut s = scene(
        vec![floor(0.0, 2.0, 0.0, 2.0, 0.0), w.clone()],
        vec![grey("floor", 0.0, 0.5), grey("wall", 0.0, 0.5)],
    );
    let stats = split_checked(&mut s);
    assert_eq!(
        stats,
        SplitStats {
            polygons_cut: 1,
            pieces: 2
        }
    );
    assert_eq!(s.polygons.len(), 3);
    assert_eq!(s.polygons[0], floor(0.0, 2.0, 0.0, 2.0, 0.0));
    let (visible, buried) = (&s.polygons[1], &s.polygons[2]);
    assert_eq!(span(visible, 1), (0.0, 2.0));
    assert_eq!(span(buried, 1), (-0.5, 0.0));
    assert!((visible.area - 4.0).abs() < 1e-6 && (buried.area - 1.0).abs() < 1e-6);
    for piece in [visible, buried] {
        assert_eq!(piece.material, w.material);
        assert_eq!(piece.origin, w.origin);
        assert_eq!(piece.surface, w.surface);
        assert!((piece.normal - Vec3::X).length() < 1e-6);
        assert_eq!(span(piece, 2), (0.0, 2.0));
    }
}

/// A wall standing on the floor at its edge, and a box standing on a
/// table, merely touch: nothing is cut.
#[test]
fn touching_polygons_are_not_cut() {
    let mut s = make(vec![
        floor(0.0, 2.0, 0.0, 2.0, 0.0),
        wall(0.0, 0.0, 2.0, 0.0, 2.0),
    ]);
    let before = s.clone();
    assert_eq!(split_checked(&mut s), SplitStats::default());
    assert_eq!(s, before);

    let mut polygons = vec![floor(0.0, 2.0, 0.0, 2.0, 1.0)];
    polygons.extend(cuboid([0.5, 1.0, 0.5], [1.5, 1.5, 1.5]));
    // A box at the table's corner, flush with two of its edges.
    polygons.extend(cuboid([0.0, 1.0, 0.0], [0.3, 1.2, 0.3]));
    // A block as wide as the table, standing on it face to face (a chair's
    // backrest on its seat): its sides span the table, yet only touch it.
    polygons.extend(cuboid([0.0, 1.0, 1.7], [2.0, 1.5, 1.9]));
    let mut s = make(polygons);
    let before = s.clone();
    assert_eq!(split_checked(&mut s), SplitStats::default());
    assert_eq!(s, before);
}

/// A box sunk halfway into a floor: its four sides are cut at the floor,
/// its top and bottom are not, and the floor is cut into the buried
/// footprint and four pieces around it (not into a 3 × 3 grid).
#[test]
fn a_box_sunk_into_the_floor_cuts_out_its_footprint() {
    let mut polygons = vec![floor(0.0, 4.0, 0.0, 4.0, 0.0)];
    polygons.extend(cuboid([1.0, -0.5, 1.0], [2.0, 0.5, 2.0]));
    let mut s = make(polygons);
    let stats = split_checked(&mut s);
    assert_eq!(
        stats,
        SplitStats {
            polygons_cut: 5,
            pieces: 13
        }
    );
    assert_eq!(s.polygons.len(), 15);
    // The floor's five pieces come first, in its place.
    let floor_pieces = &s.polygons[..5];
    assert!(floor_pieces
        .iter()
        .all(|p| p.vertices.iter().all(|v| v.y == 0.0)));
    let footprint: Vec<&Polygon> = floor_pieces
        .iter()
        .filter(|p| span(p, 0) == (1.0, 2.0) && span(p, 2) == (1.0, 2.0))
        .collect();
    assert_eq!(footprint.len(), 1);
    assert!((footprint[0].area - 1.0).abs() < 1e-6);
    // Every side piece lies wholly above or wholly below the floor.
    for p in &s.polygons[5..] {
        let (lo, hi) = span(p, 1);
        assert!(lo >= 0.0 || hi <= 0.0, "{p:?}");
    }
}

/// A floor made of tiles meets a sunk wall along several segments that
/// together run across it: the wall is cut once, the tiles not at all.
#[test]
fn a_tiled_floor_cuts_a_sunk_wall_once() {
    let mut polygons = Vec::new();
    for i in 0..4 {
        for k in 0..4 {
            let (x, z) = (i as f32 * 0.5, k as f32 * 0.5);
            polygons.push(floor(x, x + 0.5, z, z + 0.5, 0.0));
        }
    }
    polygons.push(wall(0.0, -0.5, 2.0, 0.0, 2.0));
    let mut s = make(polygons);
    let stats = split_checked(&mut s);
    assert_eq!(
        stats,
        SplitStats {
            polygons_cut: 1,
            pieces: 2
        }
    );
    assert_eq!(span(&s.polygons[16], 1), (0.0, 2.0));
    assert_eq!(span(&s.polygons[17], 1), (-0.5, 0.0));
}

/// A partition standing on a floor and spanning it from edge to edge is
/// the geometry of a floor ending at a sunk wall, turned over: the floor
/// is cut under it. A shorter partition is a box on a table: not cut.
#[test]
fn a_partition_across_the_floor_cuts_it_and_a_shorter_one_does_not() {
    let mut s = make(vec![
        floor(0.0, 2.0, 0.0, 2.0, 0.0),
        wall(1.0, 0.0, 1.0, 0.0, 2.0),
    ]);
    assert_eq!(split_checked(&mut s).pieces, 2);
    assert_eq!(span(&s.polygons[0], 0), (1.0, 2.0));
    assert_eq!(span(&s.polygons[1], 0), (0.0, 1.0));

    let mut s = make(vec![
        floor(0.0, 2.0, 0.0, 2.0, 0.0),
        wall(1.0, 0.0, 1.0, 0.5, 1.5),
    ]);
    assert_eq!(split_checked(&mut s), SplitStats::default());
}

/// Two quads crossing each other along a line that runs across both (a
/// cross of two billboards) are both cut.
#[test]
fn crossing_quads_cut_each_other() {
    let a = polygon(
        0,
        &[
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 2.0, 0.0],
            [-1.0, 2.0, 0.0],
        ],
    );
    let b = wall(0.0, 0.0, 2.0, -1.0, 1.0);
    let mut s = make(vec![a, b]);
    let stats = split_checked(&mut s);
    assert_eq!(
        stats,
        SplitStats {
            polygons_cut: 2,
            pieces: 4
        }
    );
    for p in &s.polygons {
        assert!((p.area - 2.0).abs() < 1e-6);
    }
}

/// Groups list the pieces of their polygons in place of them, ascending,
/// and the ids of later polygons shift by the pieces added.
#[test]
fn groups_follow_the_pieces() {
    let mut s = make(vec![
        floor(0.0, 2.0, 0.0, 2.0, 0.0),
        wall(0.0, -0.5, 2.0, 0.0, 2.0),
        polygon(
            0,
            &[
                [0.0, 2.0, 0.0],
                [2.0, 2.0, 0.0],
                [2.0, 2.0, 2.0],
                [0.0, 2.0, 2.0],
            ],
        ),
    ]);
    let group = |name: &str, ids: &[u32]| Group {
        name: name.into(),
        kind: GroupKind::Object,
        polygons: ids.iter().map(|&i| PolygonId(i)).collect(),
    };
    s.groups = vec![
        group("Floor", &[0]),
        group("Wall", &[1]),
        group("Room", &[0, 1, 2]),
        group("Ceiling", &[2]),
    ];
    split_checked(&mut s);
    assert_eq!(
        s.groups,
        vec![
            group("Floor", &[0]),
            group("Wall", &[1, 2]),
            group("Room", &[0, 1, 2, 3]),
            group("Ceiling", &[3]),
        ]
    );
}

/// A scene whose back copies were already made is left alone: the pieces
/// could not say which piece's back they are.
#[test]
fn a_scene_with_back_copies_is_left_unchanged() {
    let mut back = wall(0.0, -0.5, 2.0, 0.0, 2.0);
    back.vertices.reverse();
    back.normal = -back.normal;
    back.surface.back_of = Some(PolygonId(1));
    let mut s = make(vec![
        floor(0.0, 2.0, 0.0, 2.0, 0.0),
        wall(0.0, -0.5, 2.0, 0.0, 2.0),
        back,
    ]);
    let before = s.clone();
    assert_eq!(s.split_intersections(), SplitStats::default());
    assert_eq!(s, before);
}

/// The bundled scenes are built of contacts (walls on floors, blocks on
/// floors, a backrest on a seat): the pass changes none of them, except
/// where the Cornell box's data really pass through each other — its
/// ceiling and back wall reach 3.2 units past the slanted red wall at one
/// corner (see the scene's notes). Those two are cut along the red wall,
/// into the room's part and a thin hidden sliver behind the wall.
#[test]
fn the_bundled_scenes_change_only_where_polygons_pass_through() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for name in ["rtable.sc", "table_chair.sc"] {
        let mut s = crate::scene::load(&dir.join(name)).unwrap();
        let before = s.clone();
        assert_eq!(s.split_intersections(), SplitStats::default(), "{name}");
        assert_eq!(s, before, "{name}");
    }

    let mut s = crate::scene::load(&dir.join("cornell.sc")).unwrap();
    let before = s.clone();
    let red = before
        .polygons
        .iter()
        .find(|p| before.materials[p.material.index()].name == "red")
        .unwrap();
    let red_plane = Plane::of(
        &red.vertices
            .iter()
            .map(|v| v.as_dvec3())
            .collect::<Vec<_>>(),
        red.normal.as_dvec3(),
    );
    let stats = split_checked(&mut s);
    assert_eq!(
        stats,
        SplitStats {
            polygons_cut: 2,
            pieces: 4
        }
    );
    // Polygons 2 (ceiling) and 3 (back wall) became 2..4 and 4..6.
    assert_eq!(&s.polygons[..2], &before.polygons[..2]);
    assert_eq!(&s.polygons[6..], &before.polygons[4..]);
    for (old, pieces) in [(2, &s.polygons[2..4]), (3, &s.polygons[4..6])] {
        let whole = &before.polygons[old];
        let (room, hidden) = if pieces[0].area > pieces[1].area {
            (&pieces[0], &pieces[1])
        } else {
            (&pieces[1], &pieces[0])
        };
        // The red wall faces into the room: the room's piece is in front.
        let eps = 0.01;
        assert!(room
            .vertices
            .iter()
            .all(|v| red_plane.distance(v.as_dvec3()) > -eps));
        assert!(hidden
            .vertices
            .iter()
            .all(|v| red_plane.distance(v.as_dvec3()) < eps));
        // A sliver 3.2 wide at one end, nothing at the other.
        assert!(hidden.area < 0.01 * whole.area, "{}", hidden.area);
        assert_eq!(hidden.shape, crate::scene::Shape::Triangle);
    }
}

/// A large scene: a floor of `n × n` unit tiles, each with a small box on
/// it, every other box sunk halfway into its tile. Each sunk box adds
/// exactly eight polygons (four sides in two, its tile in five); resting
/// boxes add none. Prints the time (run with `--nocapture`).
#[test]
fn a_hundred_thousand_polygons_split_as_counted() {
    let n = 130;
    let mut polygons = Vec::with_capacity(n * n * 7);
    let mut sunk = 0;
    for i in 0..n {
        for k in 0..n {
            let (x, z) = (i as f32, k as f32);
            polygons.push(floor(x, x + 1.0, z, z + 1.0, 0.0));
            let y = if (i + k) % 2 == 0 {
                sunk += 1;
                -0.25
            } else {
                0.0
            };
            polygons.extend(cuboid(
                [x + 0.25, y, z + 0.25],
                [x + 0.75, y + 0.5, z + 0.75],
            ));
        }
    }
    let mut s = make(polygons);
    let before = s.polygons.len();
    let t = Instant::now();
    let stats = s.split_intersections();
    let seconds = t.elapsed().as_secs_f64();
    eprintln!("split_intersections: {before} polygons in {seconds:.3} s, {stats:?}");
    assert_eq!(s.polygons.len(), before + 8 * sunk);
    assert_eq!(stats.polygons_cut, 5 * sunk);
    assert!(before >= 100_000);
}
