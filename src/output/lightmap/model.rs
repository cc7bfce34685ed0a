//! The model a lightmap is baked for when the scene file is neither glTF
//! nor OBJ (whose own models are read back from the file, see
//! [`crate::scene::import::gltf::source`] and
//! [`crate::scene::import::obj::source`]): a `.sc` scene's faces, as
//! loaded, written as a glTF model.
//!
//! Each face keeps its corners (a convex polygon, fanned into triangles
//! from its first corner) and its flat normal; faces are grouped into one
//! primitive per material, in a single node. A two-sided face is two
//! faces, its front and its back copy, as the solver lit them: each side
//! gets its own texels, so a viewer that culls back faces shows each side
//! with its own light ([`super::backs`] finds every back there and adds
//! none). The sky's facets are left out.

use super::glb::DEFAULT_MATERIAL_NAME;
use crate::scene::import::gltf::source::{SourceModel, SourcePrimitive};
use crate::scene::Scene;
use serde_json::json;

/// The scene's faces as a model of one node named `name`, one primitive
/// per material in the scene's material order.
pub fn scene_model(scene: &Scene, name: &str) -> SourceModel {
    let mut primitives: Vec<SourcePrimitive> = (0..scene.materials.len())
        .map(|m| SourcePrimitive {
            name: name.to_string(),
            normals: Some(Vec::new()),
            material: Some(m),
            ..SourcePrimitive::default()
        })
        .collect();
    for polygon in scene.polygons.iter().filter(|p| !p.surface.sky) {
        let p = &mut primitives[polygon.material.index()];
        let first = p.positions.len() as u32;
        for v in &polygon.vertices {
            p.positions.push(v.to_array());
        }
        if let Some(n) = &mut p.normals {
            n.extend(std::iter::repeat_n(
                polygon.normal.to_array(),
                polygon.vertices.len(),
            ));
        }
        for k in 1..polygon.vertices.len() as u32 - 1 {
            p.indices.extend([first, first + k, first + k + 1]);
        }
    }
    let materials = scene
        .materials
        .iter()
        .map(|m| {
            let rho = m.reflectance().to_f32();
            let name = if m.name.is_empty() {
                DEFAULT_MATERIAL_NAME
            } else {
                &m.name
            };
            json!({
                "name": name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": [rho[0].min(1.0), rho[1].min(1.0), rho[2].min(1.0), 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                },
            })
        })
        .collect();
    SourceModel {
        primitives: primitives
            .into_iter()
            .filter(|p| !p.indices.is_empty())
            .collect(),
        materials,
        ..SourceModel::default()
    }
}
