//! The glTF model as its file draws it, for writing it back with baked
//! light ([`crate::output::lightmap`]): every triangle primitive of every
//! node instance with its own vertices, indices and attributes, and the
//! file's materials, textures and images as they are.
//!
//! This reads what the scene import ([`super::load_gltf`]) ignores
//! (normals, texture coordinates, texture images, the materials' JSON) and
//! drops what it makes (polygons, averaged reflectances). Node transforms
//! are applied: positions and normals are in world space, so each instance
//! of a mesh drawn twice is its own geometry (it gets its own light).
//! Triangles are kept as they are, degenerate ones too; a mirroring
//! transform reverses their winding, as for the scene.

use super::{index_triangles, parse_glb, validate, Reader};
use crate::scene::import::input::{InputKind, InputSet, ModelFolder};
use crate::scene::{Diagnostic, LoadError};
use ::gltf::json;
use glam::{DMat3, DVec3};
use std::path::Path;

/// One triangle primitive of one node instance, in world space.
///
/// Invariants: `indices.len()` is a multiple of 3 and every index is below
/// `positions.len()`; `normals`, `uv0` and `uv1`, when present, have one
/// entry per position.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourcePrimitive {
    /// The node's name (else its mesh's, else `nodes[N]`).
    pub name: String,
    /// Vertex positions in world (scene) units.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals in world space (`NORMAL`), if the file has them.
    pub normals: Option<Vec<[f32; 3]>>,
    /// `TEXCOORD_0`, as in the file.
    pub uv0: Option<Vec<[f32; 2]>>,
    /// `TEXCOORD_1`, as in the file.
    pub uv1: Option<Vec<[f32; 2]>>,
    /// Triangle list, counter-clockwise from the front in world space.
    pub indices: Vec<u32>,
    /// The glTF material index, if the primitive names one.
    pub material: Option<usize>,
}

/// An image of the file: its encoded bytes and media type.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceImage {
    /// The encoded image (PNG or JPEG as the file holds it).
    pub bytes: Vec<u8>,
    /// `image/png` or `image/jpeg` (from the file, else from the bytes).
    pub mime_type: String,
}

/// What [`load_gltf_source`] reads: the drawn primitives and the file's
/// appearance (materials, textures, samplers, images) as JSON values
/// whose indices still refer to each other as in the file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceModel {
    /// Every triangle primitive of every node instance, depth first in
    /// node order.
    pub primitives: Vec<SourcePrimitive>,
    /// `materials`, as in the file.
    pub materials: Vec<serde_json::Value>,
    /// `textures`, as in the file; empty when an image could not be read
    /// (then `materials` lose their texture references, see
    /// [`SourceModel::textures_dropped`]).
    pub textures: Vec<serde_json::Value>,
    /// `samplers`, as in the file.
    pub samplers: Vec<serde_json::Value>,
    /// `images`, read.
    pub images: Vec<SourceImage>,
    /// Why the textures were dropped, when one of the images could not be
    /// read.
    pub textures_dropped: Option<String>,
    /// `extensionsUsed` of the file.
    pub extensions_used: Vec<String>,
}

/// Reads the `.gltf` or `.glb` file at `path` (and its buffers and images,
/// relative to its folder) as a [`SourceModel`]. The file has been loaded
/// as a scene already, so errors are unlikely; they name the file and the
/// JSON path.
pub fn load_gltf_source(path: &Path, inputs: &InputSet) -> Result<SourceModel, LoadError> {
    let file = path.display().to_string();
    let fail = |message: String| LoadError::from(Diagnostic::whole(&file, message));
    let bytes = inputs
        .read(path, InputKind::Scene)
        .map_err(|e| fail(e.to_string()))?;
    let folder = ModelFolder::of(path, inputs);
    let read_uri = |name: &str| -> Result<Vec<u8>, String> {
        folder
            .read(&folder.join(name), InputKind::GltfData)
            .map_err(|e| e.to_string())
    };
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        let glb = parse_glb(&bytes).map_err(fail)?;
        (glb.json, glb.bin)
    } else {
        (&bytes[..], None)
    };
    let json_bytes = json_bytes
        .strip_prefix(b"\xef\xbb\xbf")
        .unwrap_or(json_bytes);
    let root: json::Root =
        json::deserialize::from_slice(json_bytes).map_err(|e| fail(e.to_string()))?;
    validate(&root, &file, &mut Vec::new())?;
    let document = ::gltf::Document::from_json_without_validation(root);
    let reader = Reader::new(&document, &file, blob, &read_uri);
    read_source(&reader).map_err(fail)
}

/// The model `reader` reads, or the first fault.
fn read_source(reader: &Reader<'_>) -> Result<SourceModel, String> {
    let mut model = SourceModel::default();
    for instance in reader.instances()? {
        let Some(mesh) = instance.node.mesh() else {
            continue;
        };
        let name = instance
            .node
            .name()
            .or(mesh.name())
            .filter(|n| !n.is_empty())
            .map_or_else(
                || format!("nodes[{}]", instance.node.index()),
                str::to_string,
            );
        let world = instance.world;
        let mirrored = world.determinant() < 0.0;
        // Normals go through the inverse transpose, so a non-uniform scale
        // keeps them perpendicular to their surface.
        let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
        for primitive in mesh.primitives() {
            use ::gltf::mesh::Mode;
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                continue;
            }
            let path = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            let attribute = |semantic: ::gltf::Semantic| {
                primitive.get(&semantic).map(|a| (a.index(), semantic))
            };
            let Some((position, _)) = attribute(::gltf::Semantic::Positions) else {
                return Err(format!("{path}: no POSITION attribute"));
            };
            let local = reader
                .read_vec3(position)
                .map_err(|e| format!("{path}.attributes[\"POSITION\"]: {e}"))?;
            let positions: Vec<[f32; 3]> = local
                .iter()
                .map(|p| {
                    world
                        .transform_point3(DVec3::from_array(p.map(f64::from)))
                        .as_vec3()
                        .to_array()
                })
                .collect();
            let normals = match attribute(::gltf::Semantic::Normals) {
                Some((a, _)) => Some(
                    reader
                        .read_vec3(a)
                        .map_err(|e| format!("{path}.attributes[\"NORMAL\"]: {e}"))?
                        .iter()
                        .map(|n| {
                            let n = normal_matrix * DVec3::from_array(n.map(f64::from));
                            n.normalize_or_zero().as_vec3().to_array()
                        })
                        .collect::<Vec<_>>(),
                ),
                None => None,
            };
            let mut uv = [None, None];
            for (k, slot) in uv.iter_mut().enumerate() {
                if let Some((a, _)) = attribute(::gltf::Semantic::TexCoords(k as u32)) {
                    *slot = Some(
                        read_vec2(reader, a)
                            .map_err(|e| format!("{path}.attributes[\"TEXCOORD_{k}\"]: {e}"))?,
                    );
                }
            }
            let [uv0, uv1] = uv;
            let indices: Vec<u32> = match primitive.indices() {
                Some(a) => reader
                    .read_indices(a.index())
                    .map_err(|e| format!("{path}.indices: {e}"))?,
                None => (0..positions.len() as u32).collect(),
            };
            if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(format!(
                    "{path}.indices: index {i} is out of range: POSITION has {} vertices",
                    positions.len()
                ));
            }
            let lengths_agree = [normals.as_ref().map(Vec::len)]
                .into_iter()
                .chain([uv0.as_ref().map(Vec::len), uv1.as_ref().map(Vec::len)])
                .flatten()
                .all(|n| n == positions.len());
            if !lengths_agree {
                return Err(format!(
                    "{path}: its attributes do not all have one element per position"
                ));
            }
            let indices = index_triangles(&indices, mode)
                .into_iter()
                .flat_map(|t| if mirrored { [t[0], t[2], t[1]] } else { t })
                .collect();
            model.primitives.push(SourcePrimitive {
                name: name.clone(),
                positions,
                normals,
                uv0,
                uv1,
                indices,
                material: primitive.material().index(),
            });
        }
    }
    let json = reader.json;
    model.materials = json.materials.iter().map(to_value).collect();
    model.samplers = json.samplers.iter().map(to_value).collect();
    let mut images = Vec::new();
    for (i, image) in json.images.iter().enumerate() {
        let bytes = match reader.image_bytes(i) {
            Ok(b) => b,
            Err(why) => {
                model.textures_dropped = Some(format!("images[{i}]: {why}"));
                break;
            }
        };
        let mime_type = image.mime_type.as_ref().map(|m| m.0.clone());
        let mime_type = mime_type.unwrap_or_else(|| {
            if bytes.starts_with(b"\x89PNG") {
                "image/png".to_string()
            } else {
                "image/jpeg".to_string()
            }
        });
        images.push(SourceImage { bytes, mime_type });
    }
    if model.textures_dropped.is_none() {
        model.images = images;
        model.textures = json.textures.iter().map(to_value).collect();
    } else {
        for m in &mut model.materials {
            strip_textures(m);
        }
    }
    model.extensions_used = json.extensions_used.clone();
    Ok(model)
}

/// A JSON item as a value (serialising a parsed item cannot fail).
fn to_value<T: serde::Serialize>(item: &T) -> serde_json::Value {
    serde_json::to_value(item).unwrap_or(serde_json::Value::Null)
}

/// Removes every texture reference of a material.
fn strip_textures(material: &mut serde_json::Value) {
    if let Some(m) = material.as_object_mut() {
        for key in [
            "normalTexture",
            "occlusionTexture",
            "emissiveTexture",
            "extensions",
        ] {
            m.remove(key);
        }
        if let Some(pbr) = m
            .get_mut("pbrMetallicRoughness")
            .and_then(|p| p.as_object_mut())
        {
            pbr.remove("baseColorTexture");
            pbr.remove("metallicRoughnessTexture");
        }
    }
}

/// A `VEC2` texture coordinate accessor: floats, or normalised unsigned
/// bytes or shorts, as the specification allows.
fn read_vec2(reader: &Reader<'_>, a: usize) -> Result<Vec<[f32; 2]>, String> {
    use json::accessor::{ComponentType, Type};
    let normalized = match reader.json.accessors.get(a).map(|x| x.normalized) {
        Some(n) => n,
        None => return Err(format!("accessors[{a}] does not exist")),
    };
    let allowed: &[ComponentType] = if normalized {
        &[ComponentType::U8, ComponentType::U16]
    } else {
        &[ComponentType::F32]
    };
    reader.read_elements(a, allowed, Type::Vec2, |ct, b| match ct {
        ComponentType::U8 => [f32::from(b[0]) / 255.0, f32::from(b[1]) / 255.0],
        ComponentType::U16 => {
            let f = |k: usize| f32::from(u16::from_le_bytes([b[k], b[k + 1]])) / 65535.0;
            [f(0), f(2)]
        }
        _ => {
            let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
            [f(0), f(4)]
        }
    })
}
