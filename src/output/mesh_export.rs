//! The solved element mesh as a 3D model, for other programs: glTF 2.0
//! binary (`.glb`, for Blender and web viewers) and PLY (`.ply`, binary
//! little-endian, for Python, MeshLab, CloudCompare).
//!
//! Both hold every element vertex at its drawn position ([`Mesh::positions`],
//! scene units, as in the scene file: no change of axes or scale) with its
//! solved **radiosity** as 32-bit floats in the scene's radiosity units
//! (exactly the solver's values rounded to `f32`), and a **display colour**
//! tone-mapped with the exposure the picture used, so the model looks like
//! the picture:
//!
//! | | `.glb` | `.ply` |
//! |---|---|---|
//! | positions | `POSITION`, float VEC3, with min/max | `x y z` float |
//! | normals | `NORMAL`, the polygon's unit normal | — |
//! | display colour | `COLOR_0`, float VEC3, *linear*: `clamp(exposure × radiosity, 0, 1)` (glTF colours are linear; the viewer applies the sRGB curve) | `red green blue` uchar, sRGB-encoded: the picture's 8-bit codes |
//! | radiosity | `_RADIOSITY`, float VEC3 | `radiosity_r radiosity_g radiosity_b` float |
//! | faces | triangles (quads split along their `0–2` diagonal, as drawn), `UNSIGNED_INT` indices | elements as they are: triangles and quads, `list uchar uint vertex_indices` |
//!
//! Faces are counter-clockwise seen from the front, as in the scene; the
//! glTF material is unlit (`KHR_materials_unlit`) and single-sided, so a
//! viewer shows the baked light as it is and one can look into a room from
//! outside through its back faces. Vertices are not shared between
//! polygons, as in the solver, but neighbours have vertices at the same
//! positions along their shared edges (the mesh is stitched): the
//! radiosity is discontinuous there, except across a smooth surface's
//! facet edges, where the exported solution is welded to one value.
//!
//! The glTF file follows the layout rules the Khronos validator checks: the
//! JSON chunk is padded with spaces and the binary chunk with zeros to
//! 4 bytes, every buffer view starts on a 4-byte boundary and is exactly as
//! long as its accessor, and `POSITION` carries the exact min/max of its
//! values.

use super::{write_atomically, OutputError};
use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::render::srgb8;
use serde_json::json;
use std::io::{self, Write};
use std::path::Path;

/// The mesh extensions [`MeshFormat::from_path`] understands, for messages.
pub const MESH_EXTENSIONS: &str = ".glb, .ply";

/// The glTF attribute holding the linear radiosity (application-specific
/// attributes start with an underscore).
pub const RADIOSITY_ATTRIBUTE: &str = "_RADIOSITY";

/// `glTF` in little-endian: the first word of a `.glb`.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk (`JSON`).
pub const GLB_CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
pub const GLB_CHUNK_BIN: u32 = 0x004E_4942;

/// glTF component type of 32-bit floats.
const FLOAT: u32 = 5126;
/// glTF component type of 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// Buffer view target of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// Buffer view target of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Primitive mode of triangle lists.
const TRIANGLES: u32 = 4;

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// glTF 2.0 binary.
    Glb,
    /// PLY, binary little-endian.
    Ply,
}

impl MeshFormat {
    /// The format named by the path's extension, case-insensitive.
    pub fn from_path(path: &Path) -> Result<MeshFormat, OutputError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("glb") => Ok(MeshFormat::Glb),
            Some("ply") => Ok(MeshFormat::Ply),
            other => Err(OutputError::Io {
                path: path.to_path_buf(),
                error: io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "{}; supported mesh formats are {MESH_EXTENSIONS}",
                        match other {
                            None => "the file name has no extension".to_string(),
                            Some(e) => format!("unknown extension .{e}"),
                        }
                    ),
                ),
            }),
        }
    }
}

/// Writes the mesh with its radiosity (one value per vertex, scene
/// radiosity units) to `path` in the format its extension names,
/// atomically. `exposure` (dimensionless, `> 0`) makes the display colours,
/// as for 8-bit pictures.
pub fn write_mesh(
    path: &Path,
    mesh: &Mesh,
    radiosity: &[Rgb],
    exposure: f32,
) -> Result<(), OutputError> {
    let format = MeshFormat::from_path(path)?;
    let invalid = |why: &str| OutputError::Io {
        path: path.to_path_buf(),
        error: io::Error::new(io::ErrorKind::InvalidInput, why.to_string()),
    };
    if radiosity.len() != mesh.vertex_count() {
        return Err(invalid("the radiosity has not one value per mesh vertex"));
    }
    if mesh.elements.is_empty() {
        return Err(invalid("the mesh has no elements"));
    }
    if u32::try_from(mesh.vertex_count()).is_err() {
        return Err(invalid("the mesh has too many vertices for 32-bit indices"));
    }
    match format {
        MeshFormat::Glb => {
            let bytes = glb_bytes(mesh, radiosity, exposure);
            write_atomically(path, |w| w.write_all(&bytes))
        }
        MeshFormat::Ply => write_atomically(path, |w| write_ply(w, mesh, radiosity, exposure)),
    }
}

/// The display colour of a radiosity for glTF: linear, exposed, clipped.
fn linear_display(r: Rgb, exposure: f32) -> [f32; 3] {
    r.to_f32().map(|v| {
        let x = v * exposure;
        if x.is_nan() {
            0.0
        } else {
            x.clamp(0.0, 1.0)
        }
    })
}

/// Appends `values` as little-endian `f32`s.
fn put_f32s(buf: &mut Vec<u8>, values: impl IntoIterator<Item = f32>) {
    for v in values {
        buf.extend_from_slice(&v.to_le_bytes());
    }
}

/// The `.glb` file (see the module docs) for the mesh, the radiosity per
/// vertex and the exposure of the display colours.
pub fn glb_bytes(mesh: &Mesh, radiosity: &[Rgb], exposure: f32) -> Vec<u8> {
    let n = mesh.vertex_count();
    let triangles: Vec<[u32; 3]> = mesh
        .elements
        .iter()
        .flat_map(|e| e.triangles())
        .map(|t| t.map(|v| v.0))
        .collect();

    let mut bin = Vec::with_capacity(n * 48 + triangles.len() * 12);
    // (offset, length) of each view in `bin`; every length is a multiple
    // of 4, so every view starts aligned.
    let mut views = Vec::new();
    let mut view = |bin: &mut Vec<u8>, fill: &dyn Fn(&mut Vec<u8>)| {
        let start = bin.len();
        fill(bin);
        views.push((start, bin.len() - start));
    };
    view(&mut bin, &|b| {
        put_f32s(b, mesh.positions.iter().flat_map(|p| p.to_array()))
    });
    view(&mut bin, &|b| {
        put_f32s(
            b,
            mesh.vertex_polygon
                .iter()
                .flat_map(|p| mesh.polygons[p.index()].normal.to_array()),
        )
    });
    view(&mut bin, &|b| {
        put_f32s(
            b,
            radiosity.iter().flat_map(|&r| linear_display(r, exposure)),
        )
    });
    view(&mut bin, &|b| {
        put_f32s(b, radiosity.iter().flat_map(|r| r.to_f32()))
    });
    view(&mut bin, &|b| {
        for i in triangles.iter().flatten() {
            b.extend_from_slice(&i.to_le_bytes());
        }
    });

    let (lo, hi) = mesh.positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            let p = p.to_array();
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        },
    );
    // Written as the f64 equal to each f32, so a reader compares exactly.
    let exact = |v: [f32; 3]| v.map(f64::from);
    let buffer_views: Vec<_> = views
        .iter()
        .enumerate()
        .map(|(i, &(offset, length))| {
            json!({
                "buffer": 0,
                "byteOffset": offset,
                "byteLength": length,
                "target": if i == 4 { ELEMENT_ARRAY_BUFFER } else { ARRAY_BUFFER },
            })
        })
        .collect();
    let vec3 = |view: usize| json!({"bufferView": view, "componentType": FLOAT, "count": n, "type": "VEC3"});
    let mut position = vec3(0);
    position["min"] = json!(exact(lo));
    position["max"] = json!(exact(hi));
    let doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION")),
            "extras": {
                "radiosity_attribute": RADIOSITY_ATTRIBUTE,
                "radiosity_units": "the scene's emission units (exitance)",
                "color_exposure": f64::from(exposure),
            },
        },
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "radiosity"}],
        "meshes": [{
            "name": "radiosity",
            "primitives": [{
                "attributes": {
                    "POSITION": 0,
                    "NORMAL": 1,
                    "COLOR_0": 2,
                    RADIOSITY_ATTRIBUTE: 3,
                },
                "indices": 4,
                "material": 0,
                "mode": TRIANGLES,
            }],
        }],
        "materials": [{
            "name": "baked radiosity (unlit vertex colours)",
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
            "extensions": {"KHR_materials_unlit": {}},
        }],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": buffer_views,
        "accessors": [
            position,
            vec3(1),
            vec3(2),
            vec3(3),
            {
                "bufferView": 4,
                "componentType": UNSIGNED_INT,
                "count": triangles.len() * 3,
                "type": "SCALAR",
            },
        ],
    });
    // A `Value` always serialises.
    let mut json_chunk = serde_json::to_vec(&doc).unwrap_or_default();
    while !json_chunk.len().is_multiple_of(4) {
        json_chunk.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total as u32] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&(json_chunk.len() as u32).to_le_bytes());
    out.extend_from_slice(&GLB_CHUNK_JSON.to_le_bytes());
    out.extend_from_slice(&json_chunk);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&GLB_CHUNK_BIN.to_le_bytes());
    out.extend_from_slice(&bin);
    out
}

/// Writes the PLY file (see the module docs).
pub fn write_ply(
    w: &mut dyn Write,
    mesh: &Mesh,
    radiosity: &[Rgb],
    exposure: f32,
) -> io::Result<()> {
    write!(
        w,
        "ply\n\
         format binary_little_endian 1.0\n\
         comment radiosity {}: element mesh, positions in scene units\n\
         comment radiosity_r/g/b: linear radiosity in the scene's emission units\n\
         comment red/green/blue: sRGB display colour, exposure {exposure}\n\
         element vertex {}\n\
         property float x\n\
         property float y\n\
         property float z\n\
         property float radiosity_r\n\
         property float radiosity_g\n\
         property float radiosity_b\n\
         property uchar red\n\
         property uchar green\n\
         property uchar blue\n\
         element face {}\n\
         property list uchar uint vertex_indices\n\
         end_header\n",
        env!("CARGO_PKG_VERSION"),
        mesh.vertex_count(),
        mesh.elements.len()
    )?;
    let mut record = Vec::with_capacity(27);
    for (p, r) in mesh.positions.iter().zip(radiosity) {
        record.clear();
        put_f32s(&mut record, p.to_array());
        let rf = r.to_f32();
        put_f32s(&mut record, rf);
        record.extend(rf.map(|v| srgb8(v, exposure)));
        w.write_all(&record)?;
    }
    for e in &mesh.elements {
        let corners = e.corners();
        record.clear();
        record.push(corners.len() as u8);
        for c in corners {
            record.extend_from_slice(&c.0.to_le_bytes());
        }
        w.write_all(&record)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{self, MeshOptions};
    use crate::scene::parse_str;

    fn small() -> (Mesh, Vec<Rgb>) {
        let scene = parse_str(
            "material m color 0.5 0.5 0.5 k_diffrefl 1 k_emission 1 end\n\
             polygon m vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 end\n\
             polygon m vertex 0 0 1 vertex 0.5 0 1 vertex 0 0.5 1 end\n",
            "t.sc",
        )
        .unwrap();
        let mesh = mesh::build(
            &scene,
            &MeshOptions {
                lenmax: 0.4,
                inset: 0.0,
            },
        )
        .unwrap();
        let rad = (0..mesh.vertex_count())
            .map(|i| Rgb::new(i as f64 * 0.1, 0.3, 2.0))
            .collect();
        (mesh, rad)
    }

    fn u32_at(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
    }

    #[test]
    fn glb_chunks_are_aligned_and_sized() {
        let (mesh, rad) = small();
        let b = glb_bytes(&mesh, &rad, 0.5);
        assert_eq!(u32_at(&b, 0), GLB_MAGIC);
        assert_eq!(u32_at(&b, 4), 2);
        assert_eq!(u32_at(&b, 8) as usize, b.len());
        let json_len = u32_at(&b, 12) as usize;
        assert_eq!(u32_at(&b, 16), GLB_CHUNK_JSON);
        assert_eq!(json_len % 4, 0);
        let doc: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        let bin_len = u32_at(&b, bin_at) as usize;
        assert_eq!(u32_at(&b, bin_at + 4), GLB_CHUNK_BIN);
        assert_eq!(bin_at + 8 + bin_len, b.len());
        assert_eq!(doc["buffers"][0]["byteLength"], bin_len);
        let n = mesh.vertex_count();
        let tris: usize = mesh.elements.iter().map(|e| e.triangles().count()).sum();
        assert_eq!(doc["accessors"][0]["count"], n);
        assert_eq!(doc["accessors"][4]["count"], 3 * tris);
        for (i, v) in doc["bufferViews"].as_array().unwrap().iter().enumerate() {
            assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0, "view {i}");
        }
        // Display colours are exposed and clipped: 2.0 × 0.5 = 1.0.
        let color_at = bin_at + 8 + doc["bufferViews"][2]["byteOffset"].as_u64().unwrap() as usize;
        let blue = f32::from_le_bytes(b[color_at + 8..color_at + 12].try_into().unwrap());
        assert_eq!(blue, 1.0);
    }

    #[test]
    fn ply_header_counts_and_record_sizes_add_up() {
        let (mesh, rad) = small();
        let mut out = Vec::new();
        write_ply(&mut out, &mesh, &rad, 1.0).unwrap();
        let end = out.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let header = std::str::from_utf8(&out[..end]).unwrap();
        assert!(header.contains(&format!("element vertex {}\n", mesh.vertex_count())));
        assert!(header.contains(&format!("element face {}\n", mesh.elements.len())));
        let faces: usize = mesh
            .elements
            .iter()
            .map(|e| 1 + 4 * e.corners().len())
            .sum();
        assert_eq!(out.len() - end, mesh.vertex_count() * 27 + faces);
    }

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a.GLB")).unwrap(),
            MeshFormat::Glb
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("a.ply")).unwrap(),
            MeshFormat::Ply
        );
        let e = MeshFormat::from_path(Path::new("a.obj")).unwrap_err();
        assert!(e.to_string().contains("unknown extension .obj"), "{e}");
        let (mesh, rad) = small();
        let dir = tempfile::tempdir().unwrap();
        let e = write_mesh(&dir.path().join("x.glb"), &mesh, &rad[1..], 1.0).unwrap_err();
        assert!(e.to_string().contains("one value per mesh vertex"), "{e}");
    }
}
