//! The back sides of two-sided faces, as triangles of their own.
//!
//! The solver lights the two sides of a two-sided face apart (an OBJ
//! face, a glTF material marked `doubleSided`: its back copy, see
//! [`crate::scene::Scene::with_sides`]), so a thin wall lit on one side
//! stays dark on the other. A model triangle has one lightmap texel per
//! point, which would show its front's light on both sides. So every
//! triangle of the model whose back the solver lit gets a **back copy**
//! in its primitive: the same corners in the reverse order, normals
//! negated, every other attribute kept (its `TEXCOORD_0` too: a texture
//! seen from behind is mirrored, as a two-sided material shows it), laid
//! out on charts of its own like any triangle. The materials of the
//! triangles that got one are made single-sided (`doubleSided: false`):
//! each side is now drawn by its own triangle, and a viewer drawing both
//! from either side would show the two coplanar triangles fighting.
//!
//! Whether the back was lit is asked of the solution at the triangle's
//! centroid ([`Locator::lit_side`]), so a face the repair passes left
//! one-sided (a closed solid's, or any under `--one-sided`) gets none. A
//! triangle whose reverse the model already holds (a face written twice,
//! once each way, or the back copies of a model made from the scene's
//! polygons) gets none either.

use super::locate::Locator;
use crate::scene::import::gltf::source::SourceModel;
use glam::Vec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// A triangle's corners as exact bits, from its lowest corner on, in its
/// winding: equal keys are the same triangle facing the same way.
type TriangleKey = [[u32; 3]; 3];

/// The key of the triangle with corners `c` in this order.
fn key(c: [[f32; 3]; 3]) -> TriangleKey {
    let bits = c.map(|v| v.map(f32::to_bits));
    let start = (0..3).min_by_key(|&i| bits[i]).unwrap_or(0);
    [0, 1, 2].map(|k| bits[(start + k) % 3])
}

/// Adds the back copy of every triangle of `model` whose back side the
/// solution `locator` reads was lit (see the module docs); returns how
/// many were added.
pub fn add_backs(model: &mut SourceModel, locator: &Locator<'_>) -> usize {
    let corners = |p: &crate::scene::import::gltf::source::SourcePrimitive, t: &[u32]| {
        [t[0], t[1], t[2]].map(|i| p.positions[i as usize])
    };
    let existing: HashSet<TriangleKey> = model
        .primitives
        .iter()
        .flat_map(|p| p.indices.chunks_exact(3).map(|t| key(corners(p, t))))
        .collect();
    let mut added = 0;
    let mut single_sided = HashSet::new();
    for p in &mut model.primitives {
        let wanted: Vec<bool> = p
            .indices
            .par_chunks_exact(3)
            .map(|t| {
                let [a, b, c] = corners(p, t);
                if existing.contains(&key([a, c, b])) {
                    return false;
                }
                let [a, b, c] = [a, b, c].map(Vec3::from_array);
                let normal = (b - a).cross(c - a).normalize_or_zero();
                normal != Vec3::ZERO && locator.lit_side((a + b + c) / 3.0, -normal)
            })
            .collect();
        if !wanted.contains(&true) {
            continue;
        }
        // Each vertex's back twin, made once for the triangles sharing it.
        let mut twins: HashMap<u32, u32> = HashMap::new();
        let triangles: Vec<[u32; 3]> = p
            .indices
            .chunks_exact(3)
            .zip(&wanted)
            .filter(|(_, &w)| w)
            .map(|(t, _)| [t[0], t[2], t[1]])
            .collect();
        for t in triangles {
            let back = t.map(|i| {
                *twins.entry(i).or_insert_with(|| {
                    let k = i as usize;
                    p.positions.push(p.positions[k]);
                    if let Some(n) = &mut p.normals {
                        n.push(n[k].map(|x| -x));
                    }
                    for uv in [&mut p.uv0, &mut p.uv1].into_iter().flatten() {
                        uv.push(uv[k]);
                    }
                    p.positions.len() as u32 - 1
                })
            });
            p.indices.extend(back);
            added += 1;
        }
        if let Some(m) = p.material {
            single_sided.insert(m);
        }
    }
    for m in single_sided {
        if let Some(object) = model.materials.get_mut(m).and_then(|v| v.as_object_mut()) {
            object.remove("doubleSided");
        }
    }
    added
}
