//! The lightmap against closed forms: a radiosity linear in position,
//! which the element mesh's Gouraud interpolation reproduces exactly, so
//! every texel's value is known from the point it stands for.

use super::fill::{fill, nearest_on_triangle, REACH};
use super::locate::{barycentric, Locator};
use super::model::scene_model;
use super::uv::{lay_out, PADDING};
use crate::cancel::{Cancel, Cancelled};
use crate::color::Rgb;
use crate::scene::import::gltf::source::{SourceModel, SourcePrimitive};
use crate::testutil::{cuboid, grey, polygon, regular_mesh, scene};
use crate::visibility::Visibility;
use glam::{Vec2, Vec3};

/// The radiosity the tests give every point: linear in position, grey.
fn light_at(p: Vec3) -> f64 {
    2.0 + 0.5 * f64::from(p.x) - 0.25 * f64::from(p.z) + 0.125 * f64::from(p.y)
}

/// `scene`'s mesh at `lenmax` with [`light_at`] at every element vertex.
fn linear_solution(s: &crate::scene::Scene, lenmax: f32) -> (crate::mesh::Mesh, Vec<Rgb>) {
    let mesh = regular_mesh(s, lenmax);
    let radiosity = mesh
        .positions
        .iter()
        .map(|&p| {
            let v = light_at(p);
            Rgb::new(v, v, v)
        })
        .collect();
    (mesh, radiosity)
}

/// The value of `texture` (one channel) at texel-space point `p`, filtered
/// bilinearly as a GPU does (texel centres at half-integers).
fn bilinear(frame: &crate::render::Frame, p: Vec2) -> f32 {
    let (w, h) = (frame.width as i64, frame.height as i64);
    let q = p - Vec2::splat(0.5);
    let (x0, y0) = (q.x.floor() as i64, q.y.floor() as i64);
    let (fx, fy) = (q.x - x0 as f32, q.y - y0 as f32);
    let at = |x: i64, y: i64| frame.pixels[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize][0];
    let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
    let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// A floor 4 × 2 facing up, as two triangles of one scene polygon, whose
/// lightmap charts are laid out by hand apart from each other in a 256²
/// texture: triangle A upright on the left, triangle B turned a quarter on
/// the right, so their shared diagonal runs differently in each chart.
fn two_chart_floor() -> SourceModel {
    let corners = [
        [-2.0, 0.0, 1.0],
        [2.0, 0.0, 1.0],
        [2.0, 0.0, -1.0],
        [-2.0, 0.0, -1.0],
    ];
    let a = SourcePrimitive {
        name: "a".into(),
        positions: vec![corners[0], corners[1], corners[2]],
        uv1: Some(vec![[0.05, 0.45], [0.45, 0.45], [0.45, 0.25]]),
        indices: vec![0, 1, 2],
        material: Some(0),
        ..SourcePrimitive::default()
    };
    let b = SourcePrimitive {
        name: "b".into(),
        positions: vec![corners[0], corners[2], corners[3]],
        uv1: Some(vec![[0.9, 0.9], [0.6, 0.5], [0.6, 0.9]]),
        indices: vec![0, 1, 2],
        material: Some(0),
        ..SourcePrimitive::default()
    };
    SourceModel {
        primitives: vec![a, b],
        materials: vec![serde_json::json!({"name": "floor"})],
        ..SourceModel::default()
    }
}

/// The floor of [`two_chart_floor`] as one scene polygon.
fn floor_scene() -> crate::scene::Scene {
    scene(
        vec![polygon(
            0,
            &[
                [-2.0, 0.0, 1.0],
                [2.0, 0.0, 1.0],
                [2.0, 0.0, -1.0],
                [-2.0, 0.0, -1.0],
            ],
        )],
        vec![grey("floor", 0.0, 0.5)],
    )
}

/// The point of `p`'s triangle `t` at barycentric weights `w`, and its
/// texel-space UV in a `size` texture.
fn point_and_uv(p: &SourcePrimitive, t: usize, w: [f32; 3], size: Vec2) -> (Vec3, Vec2) {
    let ids = [0, 1, 2].map(|k| p.indices[3 * t + k] as usize);
    let uv1 = p.uv1.as_ref().unwrap();
    let mut point = Vec3::ZERO;
    let mut uv = Vec2::ZERO;
    for k in 0..3 {
        point += Vec3::from_array(p.positions[ids[k]]) * w[k];
        uv += Vec2::from_array(uv1[ids[k]]) * size * w[k];
    }
    (point, uv)
}

#[test]
fn every_texel_holds_the_light_of_the_point_it_stands_for() {
    let s = floor_scene();
    let (mesh, radiosity) = linear_solution(&s, 0.25);
    let visibility = Visibility::new(&s);
    let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
    let model = two_chart_floor();
    let texture = fill(&model, 256, 256, &locator, &s, &Cancel::never()).unwrap();
    assert_eq!(texture.unmatched, 0);
    let size = Vec2::splat(256.0);
    let mut inside = 0;
    for (k, p) in model.primitives.iter().enumerate() {
        let uv: Vec<Vec2> = p
            .uv1
            .as_ref()
            .unwrap()
            .iter()
            .map(|&u| Vec2::from_array(u) * size)
            .collect();
        let tri = [uv[0], uv[1], uv[2]];
        for y in 0..256 {
            for x in 0..256 {
                let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = barycentric(centre, &tri).unwrap();
                if w.iter().any(|&c| c < 0.0) {
                    continue;
                }
                inside += 1;
                // Row y of the texture is v = (y + 0.5) / 256: glTF's
                // top-left origin, the image's first row.
                let texel = y * 256 + x;
                assert_eq!(texture.owner[texel], k as u32 + 1, "texel {x},{y}");
                let (point, _) = point_and_uv(p, 0, w, size);
                let want = light_at(point) as f32;
                let got = texture.shown.pixels[texel][0];
                assert!(
                    (got - want).abs() < 1e-4 * want,
                    "texel {x},{y}: {got} vs {want}"
                );
                // Irradiance = radiosity / reflectance (nothing emits).
                let e = texture.irradiance.pixels[texel][0];
                assert!(
                    (e - want / 0.5).abs() < 2e-4 * want,
                    "{e} vs {}",
                    want / 0.5
                );
            }
        }
    }
    assert!(inside > 2000, "{inside}");
}

#[test]
fn both_sides_of_a_seam_show_the_same_light() {
    let s = floor_scene();
    let (mesh, radiosity) = linear_solution(&s, 0.25);
    let visibility = Visibility::new(&s);
    let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
    let model = two_chart_floor();
    let texture = fill(&model, 256, 256, &locator, &s, &Cancel::never()).unwrap();
    let size = Vec2::splat(256.0);
    let (a, b) = (&model.primitives[0], &model.primitives[1]);
    // The shared edge runs from corner 0 to corner 2 of A, corner 0 to
    // corner 1 of B. One texel is 0.4 × 4 / 102 ≈ 0.04 units on A; the
    // light's gradient is 0.56 per unit.
    let texel_units = 4.0 / (0.4 * 256.0);
    let gradient = (0.5f32 * 0.5 + 0.25 * 0.25).sqrt();
    let tolerance = 1.5 * gradient * texel_units;
    let mut worst = 0.0f32;
    for k in 1..40 {
        let s = k as f32 / 40.0;
        let (pa, uva) = point_and_uv(a, 0, [1.0 - s, 0.0, s], size);
        let (pb, uvb) = point_and_uv(b, 0, [1.0 - s, s, 0.0], size);
        assert!((pa - pb).length() < 1e-5);
        let (va, vb) = (bilinear(&texture.shown, uva), bilinear(&texture.shown, uvb));
        let want = light_at(pa) as f32;
        worst = worst.max((va - vb).abs());
        assert!((va - vb).abs() < tolerance, "at {pa}: {va} vs {vb}");
        assert!((va - want).abs() < tolerance && (vb - want).abs() < tolerance);
    }
    // The seam is far closer than the tolerance: both sides sample the
    // same edge.
    assert!(worst < tolerance / 2.0, "{worst} vs {tolerance}");
}

/// Charts of `model`: triangles joined across edges whose two UVs match
/// exactly, one label per triangle in [`fill`]'s triangle order.
fn chart_labels(model: &SourceModel) -> Vec<usize> {
    let mut tris: Vec<[[u32; 2]; 3]> = Vec::new();
    for p in &model.primitives {
        let uv = p.uv1.as_ref().unwrap();
        for t in p.indices.chunks_exact(3) {
            tris.push([0, 1, 2].map(|k| uv[t[k] as usize].map(f32::to_bits)));
        }
    }
    let mut label: Vec<usize> = (0..tris.len()).collect();
    fn root(label: &mut [usize], mut i: usize) -> usize {
        while label[i] != i {
            label[i] = label[label[i]];
            i = label[i];
        }
        i
    }
    let mut edges = std::collections::HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = if a < b { (a, b) } else { (b, a) };
            if let Some(&j) = edges.get(&key) {
                let (ri, rj) = (root(&mut label, i), root(&mut label, j));
                label[ri] = rj;
            } else {
                edges.insert(key, i);
            }
        }
    }
    (0..tris.len()).map(|i| root(&mut label, i)).collect()
}

#[test]
fn no_chart_reads_a_texel_of_another() {
    // A box seen from inside, its walls at right angles: a chart each.
    let s = scene(
        cuboid([0.0, 0.0, 0.0], [2.0, 1.0, 1.5], true),
        vec![grey("wall", 0.0, 0.5)],
    );
    let (mesh, radiosity) = linear_solution(&s, 0.2);
    let visibility = Visibility::new(&s);
    let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
    let mut model = scene_model(&s, "box");
    let layout = lay_out(&mut model, Some(24.0)).unwrap();
    assert!(layout.generated && layout.charts >= 6, "{layout:?}");
    let texture = fill(
        &model,
        layout.width,
        layout.height,
        &locator,
        &s,
        &Cancel::never(),
    )
    .unwrap();
    assert_eq!(texture.unmatched, 0);
    let labels = chart_labels(&model);
    let size = Vec2::new(layout.width as f32, layout.height as f32);
    let (w, h) = (layout.width as i64, layout.height as i64);
    let mut read = 0;
    let mut t = 0;
    for p in &model.primitives {
        let uv1 = p.uv1.as_ref().unwrap();
        for tri in p.indices.chunks_exact(3) {
            let uv = [0, 1, 2].map(|k| Vec2::from_array(uv1[tri[k] as usize]) * size);
            let lo = uv[0].min(uv[1]).min(uv[2]);
            let hi = uv[0].max(uv[1]).max(uv[2]);
            // Every texel whose centre is less than a texel from the
            // triangle along both axes is read by bilinear filtering
            // somewhere on it: it must hold a point of the same chart.
            for y in (lo.y.floor() as i64 - 2).max(0)..(hi.y.ceil() as i64 + 2).min(h) {
                for x in (lo.x.floor() as i64 - 2).max(0)..(hi.x.ceil() as i64 + 2).min(w) {
                    let c = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let near = chebyshev_to_triangle(c, &uv) < 1.0;
                    if !near {
                        continue;
                    }
                    read += 1;
                    let owner = texture.owner[(y * w + x) as usize];
                    assert!(
                        owner > 0,
                        "texel {x},{y} read by triangle {t} holds no point"
                    );
                    assert_eq!(
                        labels[owner as usize - 1],
                        labels[t],
                        "texel {x},{y}, read by triangle {t}, holds a point of another chart"
                    );
                }
            }
            t += 1;
        }
    }
    assert!(read > 1000, "{read}");
    // What keeps them apart: the padding exceeds the reach twice over.
    assert!(2.0 * PADDING as f32 > 2.0 * REACH);
}

/// An upper bound of the Chebyshev (largest axis) distance from `p` to
/// triangle `t`: the least over its Euclidean-nearest point and its
/// corners (so the test checks a subset of the texels filtering reads).
fn chebyshev_to_triangle(p: Vec2, t: &[Vec2; 3]) -> f32 {
    let (w, d) = nearest_on_triangle(p, t);
    if d == 0.0 {
        return 0.0;
    }
    let q = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
    let nearest = (q - p).abs().max_element();
    // A corner of the triangle may be nearer along the axes than its
    // Euclidean-nearest point.
    t.iter()
        .map(|c| (*c - p).abs().max_element())
        .fold(nearest, f32::min)
}

#[test]
fn probes_are_sized_by_the_model_not_by_the_sky_around_it() {
    // The floor, a slab 5 cm above part of it (a table top's underside),
    // and a sky facet 1000 units away: probes start a thousandth of the
    // model's diagonal above the floor, below the slab.
    let mut polygons = floor_scene().polygons;
    polygons.push(polygon(
        0,
        &[
            [0.0, 0.05, -0.5],
            [1.0, 0.05, -0.5],
            [1.0, 0.05, 0.5],
            [0.0, 0.05, 0.5],
        ],
    ));
    let mut sky = polygon(
        0,
        &[
            [-1000.0, 1000.0, -1000.0],
            [1000.0, 1000.0, -1000.0],
            [1000.0, 1000.0, 1000.0],
        ],
    );
    sky.surface.sky = true;
    polygons.push(sky);
    let s = scene(polygons, vec![grey("floor", 0.0, 0.5)]);
    let (mesh, radiosity) = linear_solution(&s, 0.25);
    let visibility = Visibility::new(&s);
    let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
    for x in [0.1f32, 0.5, 0.9] {
        let p = Vec3::new(x, 0.0, 0.1);
        let sample = locator
            .sample(p, Vec3::Y)
            .expect("the floor under the slab");
        assert_eq!(sample.polygon.index(), 0);
        let want = light_at(p);
        assert!((sample.radiosity.r - want).abs() < 1e-4 * want, "{x}");
    }
}

/// A bake whose cancel is set stops filling and says so, and the same
/// bake not cancelled fills every texel it lays out: the fill consults
/// the token, so an interrupt during a large bake is honoured within a
/// texel's work rather than after the whole texture.
#[test]
fn a_cancelled_fill_stops_and_says_so() {
    let s = floor_scene();
    let (mesh, radiosity) = linear_solution(&s, 0.25);
    let visibility = Visibility::new(&s);
    let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
    let model = two_chart_floor();
    let cancel = Cancel::new();
    cancel.set();
    assert_eq!(
        fill(&model, 256, 256, &locator, &s, &cancel).err(),
        Some(Cancelled)
    );
    let whole = fill(&model, 256, 256, &locator, &s, &Cancel::new()).unwrap();
    assert!(whole.shown.covered.iter().any(|&c| c));
}

/// Back copies follow the solution: none on a one-sided floor, one per
/// triangle on a two-sided one, with their corners reversed and normals
/// negated, the material made single-sided; none for a model that holds
/// the backs already (the `.sc` model of the same two-sided floor).
#[test]
fn a_triangle_gets_a_back_where_the_solver_lit_one() {
    use super::backs::add_backs;
    use crate::scene::Sides;
    let with_normals = || {
        let mut m = two_chart_floor();
        for p in &mut m.primitives {
            p.normals = Some(vec![[0.0, 1.0, 0.0]; 3]);
            p.uv1 = None;
        }
        m.materials = vec![serde_json::json!({"name": "floor", "doubleSided": true})];
        m
    };
    for (sides, want) in [(Sides::One, 0), (Sides::Two, 2)] {
        let s = floor_scene().with_sides(sides);
        let (mesh, radiosity) = linear_solution(&s, 0.25);
        let visibility = Visibility::new(&s);
        let locator = Locator::new(&s, &mesh, &visibility, &radiosity, &radiosity);
        let mut model = with_normals();
        assert_eq!(add_backs(&mut model, &locator), want, "{sides:?}");
        assert_eq!(
            model.materials[0].get("doubleSided").is_none(),
            want > 0,
            "{sides:?}"
        );
        for p in model.primitives.iter().filter(|_| want > 0) {
            assert_eq!(p.indices.len(), 6);
            let (front, back) = (&p.indices[..3], &p.indices[3..]);
            for k in 0..3 {
                let (f, b) = (front[k] as usize, back[(3 - k) % 3] as usize);
                assert_eq!(p.positions[f], p.positions[b]);
                assert_eq!(p.normals.as_ref().unwrap()[b], [-0.0, -1.0, -0.0]);
            }
        }
        let mut own = scene_model(&s, "floor");
        let triangles: usize = own.primitives.iter().map(|p| p.indices.len() / 3).sum();
        assert_eq!(add_backs(&mut own, &locator), 0, "{sides:?}");
        let after: usize = own.primitives.iter().map(|p| p.indices.len() / 3).sum();
        assert_eq!(triangles, after);
    }
}
