//! The baked model as a glTF 2.0 binary: the model's triangles with their
//! own attributes, `TEXCOORD_1`, the file's materials and images, and the
//! lightmap as every material's `emissiveTexture` on texture coordinate 1.
//!
//! Layout rules the Khronos validator checks are kept as in
//! [`crate::output::mesh_export`]: chunks padded to 4 bytes, every buffer
//! view 4-byte aligned and exactly as long as its accessor, `POSITION`
//! with its exact min/max, images in buffer views without a target.

use crate::scene::import::gltf::source::SourceModel;
use serde_json::{json, Value};

/// glTF component type of 32-bit floats.
const FLOAT: u32 = 5126;
/// glTF component type of 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// Buffer view target of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// Buffer view target of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Sampler filter `LINEAR`.
const LINEAR: u32 = 9729;
/// Sampler wrap mode `CLAMP_TO_EDGE`.
const CLAMP_TO_EDGE: u32 = 33071;

/// The name of the material given to primitives that name none (glTF's
/// default material, which has nowhere to hold a texture).
pub const DEFAULT_MATERIAL_NAME: &str = "(no material)";

/// What the writer says about the lightmap in the file's `extras`.
#[derive(Clone, Debug)]
pub struct LightmapInfo {
    /// The exposure the emissive texture was encoded with
    /// (dimensionless): texel = sRGB(clamp(exposure × radiosity, 0, 1)).
    pub exposure: f32,
    /// Texels per scene unit.
    pub texels_per_unit: f32,
}

/// The binary chunk as it fills, with its buffer views and accessors.
#[derive(Default)]
struct Buffer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Appends `bytes` (padded to 4) as one buffer view; returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let start = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": start, "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends float vectors as a view and its accessor; returns the
    /// accessor's index. `bounds` adds the exact min/max.
    fn floats<const N: usize>(&mut self, values: &[[f32; N]], bounds: bool) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes, Some(ARRAY_BUFFER));
        let ty = match N {
            2 => "VEC2",
            3 => "VEC3",
            _ => "SCALAR",
        };
        let mut accessor = json!({
            "bufferView": view, "componentType": FLOAT, "count": values.len(), "type": ty,
        });
        if bounds {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for v in values {
                for k in 0..N {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            // Written as the f64 equal to each f32, so a reader compares
            // exactly.
            accessor["min"] = json!(lo.map(f64::from).to_vec());
            accessor["max"] = json!(hi.map(f64::from).to_vec());
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends triangle indices; returns the accessor's index.
    fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT, "count": indices.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

/// The `.glb` bytes of `model` (every primitive with `uv1`) with `png` (the
/// encoded emissive lightmap) embedded; `name` names the glTF scene.
pub fn glb_bytes(model: &SourceModel, png: &[u8], info: &LightmapInfo, name: &str) -> Vec<u8> {
    let mut buffer = Buffer::default();
    // The file's images first, so its textures' `source` indices hold.
    let mut images: Vec<Value> = model
        .images
        .iter()
        .map(|image| {
            let view = buffer.view(&image.bytes, None);
            json!({"bufferView": view, "mimeType": image.mime_type})
        })
        .collect();
    let lightmap_view = buffer.view(png, None);
    images.push(json!({"name": "lightmap", "bufferView": lightmap_view, "mimeType": "image/png"}));
    let mut samplers = model.samplers.clone();
    samplers.push(json!({
        "magFilter": LINEAR, "minFilter": LINEAR,
        "wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE,
    }));
    let mut textures = model.textures.clone();
    textures.push(json!({"name": "lightmap", "sampler": samplers.len() - 1,
                         "source": images.len() - 1}));
    let lightmap_texture = textures.len() - 1;

    let mut materials: Vec<Value> = model.materials.clone();
    let mut default_material = None;
    let mut nodes = Vec::new();
    let mut meshes: Vec<Value> = Vec::new();
    let mut last_name: Option<&str> = None;
    for p in &model.primitives {
        let Some(uv1) = &p.uv1 else { continue };
        let material = match p.material {
            Some(m) if m < materials.len() => m,
            _ => *default_material.get_or_insert_with(|| {
                materials.push(json!({"name": DEFAULT_MATERIAL_NAME}));
                materials.len() - 1
            }),
        };
        let mut attributes = json!({"POSITION": buffer.floats(&p.positions, true)});
        if let Some(n) = &p.normals {
            attributes["NORMAL"] = json!(buffer.floats(n, false));
        }
        let lightmap_uv = buffer.floats(uv1, false);
        // glTF numbers texture coordinates from 0 without gaps: a
        // primitive without its own TEXCOORD_0 gets the lightmap's there
        // too (nothing of the model samples it).
        attributes["TEXCOORD_0"] = match &p.uv0 {
            Some(uv) => json!(buffer.floats(uv, false)),
            None => json!(lightmap_uv),
        };
        attributes["TEXCOORD_1"] = json!(lightmap_uv);
        let primitive = json!({
            "attributes": attributes,
            "indices": buffer.indices(&p.indices),
            "material": material,
        });
        // Consecutive primitives of one node make one mesh, as in the file.
        if last_name == Some(p.name.as_str()) {
            if let Some(mesh) = meshes.last_mut() {
                if let Some(list) = mesh["primitives"].as_array_mut() {
                    list.push(primitive);
                }
            }
            continue;
        }
        last_name = Some(p.name.as_str());
        nodes.push(json!({"name": p.name, "mesh": meshes.len()}));
        meshes.push(json!({"name": p.name, "primitives": [primitive]}));
    }
    for m in &mut materials {
        bake_into(m, lightmap_texture);
    }
    let mut document = json!({
        "asset": {"version": "2.0", "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "textures": textures,
        "samplers": samplers,
        "images": images,
        "accessors": buffer.accessors,
        "bufferViews": buffer.views,
        "buffers": [{"byteLength": buffer.bin.len()}],
        "extras": {"lightmap": {
            "texture": lightmap_texture,
            "texCoord": 1,
            "holds": "radiosity as drawn: sRGB(clamp(exposure * radiosity, 0, 1))",
            "exposure": info.exposure,
            "texelsPerUnit": info.texels_per_unit,
        }},
    });
    // The file's extensions that its copied materials and textures still
    // use.
    let text = serde_json::to_string(&document).unwrap_or_default();
    let used: Vec<&String> = model
        .extensions_used
        .iter()
        .filter(|e| text.contains(&format!("\"{e}\"")))
        .collect();
    if !used.is_empty() {
        document["extensionsUsed"] = json!(used);
    }
    let json_chunk = serde_json::to_vec(&document).unwrap_or_default();
    crate::output::mesh_export::glb_container(json_chunk, buffer.bin)
}

/// Makes material `m` show the lightmap: its `emissiveTexture` (texture
/// `lightmap` on texture coordinate 1) at `emissiveFactor` 1, replacing
/// the emission it had (the baked radiosity includes it) and its
/// `KHR_materials_emissive_strength`.
fn bake_into(m: &mut Value, lightmap: usize) {
    let Some(object) = m.as_object_mut() else {
        return;
    };
    object.insert(
        "emissiveTexture".to_string(),
        json!({"index": lightmap, "texCoord": 1}),
    );
    object.insert("emissiveFactor".to_string(), json!([1.0, 1.0, 1.0]));
    if let Some(ext) = object.get_mut("extensions").and_then(Value::as_object_mut) {
        ext.remove("KHR_materials_emissive_strength");
        if ext.is_empty() {
            object.remove("extensions");
        }
    }
}
