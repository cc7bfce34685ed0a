//! Builds small glTF documents in code, as exporters write them: a JSON
//! document with one binary buffer, saved as a `.glb` or as a `.gltf`
//! with the buffer embedded as a base64 `data:` URI.

#![allow(dead_code)]

use base64::Engine as _;
use serde_json::{json, Value};

/// A glTF document under construction.
pub struct Doc {
    /// The JSON; `buffers` is filled in when written.
    pub json: Value,
    /// The one binary buffer.
    pub bin: Vec<u8>,
}

impl Default for Doc {
    fn default() -> Self {
        Doc::new()
    }
}

impl Doc {
    /// An empty document (asset only), as Blender's exporter heads it.
    pub fn new() -> Doc {
        Doc {
            json: json!({
                "asset": {"generator": "Khronos glTF Blender I/O v3.6.28", "version": "2.0"},
                "accessors": [],
                "bufferViews": [],
            }),
            bin: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        if self.json.get(key).is_none() {
            self.json[key] = json!([]);
        }
        let array = self.json[key].as_array_mut().expect("an array");
        array.push(value);
        array.len() - 1
    }

    /// Appends `bytes` (padded to 4) as a buffer view; its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.push(
            "bufferViews",
            json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}),
        )
    }

    /// A float accessor of `kind` (`VEC3`, ...) over `values`; with
    /// min/max for `VEC3`, as `POSITION` needs. Its index.
    pub fn floats(&mut self, values: &[f32], kind: &str) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let dims = match kind {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let mut accessor = json!({
            "bufferView": view, "componentType": 5126,
            "count": values.len() / dims, "type": kind,
        });
        if dims == 3 {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in values.chunks(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.push("accessors", accessor)
    }

    /// A `u16` index accessor. Its index.
    pub fn indices(&mut self, values: &[u16]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.push(
            "accessors",
            json!({"bufferView": view, "componentType": 5123, "count": values.len(), "type": "SCALAR"}),
        )
    }

    /// A mesh named `name` with the given primitives. Its index.
    pub fn mesh(&mut self, name: &str, primitives: Vec<Value>) -> usize {
        self.push("meshes", json!({"name": name, "primitives": primitives}))
    }

    /// A material. Its index.
    pub fn material(&mut self, material: Value) -> usize {
        self.push("materials", material)
    }

    /// A node. Its index.
    pub fn node(&mut self, node: Value) -> usize {
        self.push("nodes", node)
    }

    /// The scene of root nodes `roots`, made the default.
    pub fn scene(&mut self, roots: &[usize]) {
        let i = self.push("scenes", json!({"name": "Scene", "nodes": roots}));
        self.json["scene"] = json!(i);
    }

    /// A unit square in the z = 0 plane facing +z, as two indexed
    /// triangles, with `NORMAL` when `normals`; a primitive of material
    /// `material` (if any).
    pub fn square(&mut self, material: Option<usize>, normals: bool) -> Value {
        self.square_at(material, normals, 0.0)
    }

    /// [`Doc::square`] moved by `dx` along x, for primitives that must not
    /// repeat each other (exact repeats are dropped on import).
    pub fn square_at(&mut self, material: Option<usize>, normals: bool, dx: f32) -> Value {
        let position = self.floats(
            &[dx, 0., 0., dx + 1., 0., 0., dx + 1., 1., 0., dx, 1., 0.],
            "VEC3",
        );
        let indices = self.indices(&[0, 1, 2, 0, 2, 3]);
        let mut p = json!({"attributes": {"POSITION": position}, "indices": indices});
        if normals {
            let n = self.floats(&[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.], "VEC3");
            p["attributes"]["NORMAL"] = json!(n);
        }
        if let Some(m) = material {
            p["material"] = json!(m);
        }
        p
    }

    fn with_buffer(&self, uri: Option<String>) -> Value {
        let mut json = self.json.clone();
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        json["buffers"] = json!([buffer]);
        json
    }

    /// The document as a `.glb`: JSON chunk padded with spaces, BIN chunk
    /// with zeros.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.with_buffer(None)).expect("JSON");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        for word in [0x4654_6C67u32, 2, total as u32] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    /// The document as a `.gltf` with the buffer embedded.
    pub fn gltf(&self) -> Vec<u8> {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        serde_json::to_vec_pretty(&self.with_buffer(Some(uri))).expect("JSON")
    }

    /// The document as a `.gltf` whose buffer is the external file `uri`
    /// (the caller writes [`Doc::bin`] there).
    pub fn gltf_external(&self, uri: &str) -> Vec<u8> {
        serde_json::to_vec_pretty(&self.with_buffer(Some(uri.to_string()))).expect("JSON")
    }
}

/// A PNG of `pixels` (8-bit sRGB), `width` wide, as a `data:` URI.
pub fn png_data_uri(width: u32, pixels: &[[u8; 3]]) -> String {
    let height = pixels.len() as u32 / width;
    let img = image::RgbImage::from_fn(width, height, |x, y| {
        image::Rgb(pixels[(y * width + x) as usize])
    });
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png)
        .expect("PNG");
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png.into_inner())
    )
}
