//! The solved element mesh as a 3D model, for other programs: glTF 2.0
//! binary (`.glb`, for Blender and web viewers) and PLY (`.ply`, binary
//! little-endian, for Python, MeshLab, CloudCompare).
//!
//! Both hold every element vertex at its drawn position ([`Mesh::positions`],
//! scene units, as in the scene file: no change of axes or scale) with its
//! solved **radiosity** as 32-bit floats in the scene's radiosity units
//! (exactly the solver's values rounded to `f32`), and a **display colour**
//! tone-mapped with the exposure the picture used, so that shown alone the
//! model's colours look like the picture:
//!
//! | | `.glb` | `.ply` |
//! |---|---|---|
//! | positions | `POSITION`, float VEC3, with min/max | `x y z` float |
//! | normals | `NORMAL`, the polygon's unit normal | — |
//! | display colour | `COLOR_0`, float VEC3, *linear*: `clamp(exposure × radiosity, 0, 1)` (glTF colours are linear; the viewer applies the sRGB curve) | `red green blue` uchar, sRGB-encoded: the picture's 8-bit codes |
//! | radiosity | `_RADIOSITY`, float VEC3 | `radiosity_r radiosity_g radiosity_b` float |
//! | faces | triangles (quads split along their `0–2` diagonal, as drawn), `UNSIGNED_INT` indices | elements as they are: triangles and quads, `list uchar uint vertex_indices` |
//!
//! Faces are counter-clockwise seen from the front, as in the scene.
//! Vertices are not shared between polygons, as in the solver, but
//! neighbours have vertices at the same positions along their shared edges
//! (the mesh is stitched): the radiosity is discontinuous there, except
//! across a smooth surface's facet edges, where the exported solution is
//! welded to one value.
//!
//! **The model's structure (glTF).** The `.glb` keeps what the scene file
//! named, so a model re-imported into Blender comes back as the objects
//! it was modelled as, with their names and materials ([`export_nodes`]):
//!
//! - one node (with a mesh of the same name) per OBJ object (`o`); when
//!   the file has groups (`g`) but no objects, one per group (a face in
//!   several groups goes to the first of them that lists it); faces in no
//!   object (or group) go to one node named after the scene file
//!   ([`DEFAULT_NODE_NAME`] when there is no name);
//! - a scene that names nothing but materials (`.sc`, an OBJ without `o`
//!   or `g`) gets one node per material, named after it, in the order
//!   the polygons first use them: lamps, walls and furniture stay
//!   selectable apart;
//! - the back copy of a two-sided face (`surface.back_of`) goes with its
//!   front;
//! - each node's mesh has one primitive per material, in the scene's
//!   material order; each primitive has its own vertices.
//!
//! Each glTF material is named as the scene's material and describes it
//! as a surface, for a renderer: `baseColorFactor` is the reflectance
//! (linear), `emissiveFactor` the emission × the picture's exposure (the
//! scale of `COLOR_0`), divided by its largest channel with
//! `KHR_materials_emissive_strength` holding that channel when it is
//! above 1; metallic 0, roughness 1, single-sided (each side of a
//! two-sided face is its own polygon). The exact reflectance and emission
//! in scene units are in the material's `extras` (Blender shows them as
//! custom properties). The baked light is in `COLOR_0`: glTF multiplies
//! it into the base colour, so a viewer that follows the rule shows
//! reflectance × baked light under its own lighting; to see the baked
//! light as the picture shows it, display the colour attribute alone
//! (the user guide says how in Blender).
//!
//! PLY has no nodes or named materials: the `.ply` stays one list of
//! vertices and faces in scene polygon order (a reader that wants the
//! objects takes them from the `.glb`).
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
use crate::scene::{Group, GroupKind, Material, MaterialId, PolygonId, Scene};
use serde_json::json;
use std::collections::BTreeMap;
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
/// atomically. `scene` is the scene the mesh was built from (one mesh
/// polygon per scene polygon): its objects, groups and materials give the
/// glTF nodes and materials (see the module docs). `name` (the scene
/// file's stem) names the glTF scene and the node of polygons in no
/// object. `exposure` (dimensionless, `> 0`) makes the display colours, as
/// for 8-bit pictures.
pub fn write_mesh(
    path: &Path,
    scene: &Scene,
    mesh: &Mesh,
    radiosity: &[Rgb],
    exposure: f32,
    name: &str,
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
            if mesh.polygons.len() != scene.polygons.len() {
                return Err(invalid("the mesh was not built from this scene"));
            }
            let bytes = glb_bytes(scene, mesh, radiosity, exposure, name);
            write_atomically(path, |w| w.write_all(&bytes))
        }
        MeshFormat::Ply => write_atomically(path, |w| write_ply(w, mesh, radiosity, exposure)),
    }
}

/// The name of the node holding the polygons in no object (or group) when
/// the export is given no name.
pub const DEFAULT_NODE_NAME: &str = "default";

/// One glTF node of an export: a name and its polygons, by material.
///
/// Invariants: `primitives` is not empty, ascending by material, each
/// material once; each polygon list is ascending and not empty.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExportNode {
    /// The node's (and its mesh's) name.
    pub name: String,
    /// One glTF primitive per material: the material and the polygons
    /// drawn with it.
    pub primitives: Vec<(MaterialId, Vec<PolygonId>)>,
}

/// How the scene's polygons are split into glTF nodes (see the module
/// docs): every polygon lands in exactly one node; a back copy
/// (`surface.back_of`) lands in its front's. `name` names the node of
/// polygons in no object or group ([`DEFAULT_NODE_NAME`] when empty).
pub fn export_nodes(scene: &Scene, name: &str) -> Vec<ExportNode> {
    let n = scene.polygons.len();
    let mut names: Vec<String> = Vec::new();
    let mut owner: Vec<Option<usize>> = vec![None; n];
    let is_back = |p: usize| scene.polygons[p].surface.back_of.is_some();
    let objects: Vec<&Group> = scene
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Object)
        .collect();
    let sets: Vec<&Group> = if objects.is_empty() {
        scene.groups.iter().collect()
    } else {
        objects
    };
    if sets.is_empty() {
        // No names but the materials' (`.sc`): one node per material.
        let mut node_of_material = vec![None; scene.materials.len()];
        for (p, polygon) in scene.polygons.iter().enumerate() {
            if is_back(p) {
                continue;
            }
            let m = polygon.material.index();
            let node = *node_of_material[m].get_or_insert_with(|| {
                names.push(scene.materials[m].name.clone());
                names.len() - 1
            });
            owner[p] = Some(node);
        }
    } else {
        for set in sets {
            let node = names.len();
            let mut used = false;
            for &p in &set.polygons {
                let p = p.index();
                if p < n && !is_back(p) && owner[p].is_none() {
                    owner[p] = Some(node);
                    used = true;
                }
            }
            if used {
                names.push(set.name.clone());
            }
        }
    }
    // Back copies follow their front; what is left goes to one node. The
    // sky's facets light the model but are no part of it: no node.
    let mut rest = None;
    for p in 0..n {
        if owner[p].is_some() || scene.polygons[p].surface.sky {
            continue;
        }
        let front = scene.polygons[p]
            .surface
            .back_of
            .map(|f| f.index())
            .filter(|&f| f < n && !is_back(f));
        owner[p] = match front.and_then(|f| owner[f]) {
            Some(node) => Some(node),
            None => Some(*rest.get_or_insert_with(|| {
                names.push(if name.is_empty() {
                    DEFAULT_NODE_NAME.to_string()
                } else {
                    name.to_string()
                });
                names.len() - 1
            })),
        };
    }
    let mut per_node: Vec<BTreeMap<MaterialId, Vec<PolygonId>>> =
        vec![BTreeMap::new(); names.len()];
    for (p, node) in owner.iter().enumerate() {
        if let Some(node) = node {
            per_node[*node]
                .entry(scene.polygons[p].material)
                .or_default()
                .push(PolygonId(p as u32));
        }
    }
    names
        .into_iter()
        .zip(per_node)
        .filter(|(_, prims)| !prims.is_empty())
        .map(|(name, prims)| ExportNode {
            name,
            primitives: prims.into_iter().collect(),
        })
        .collect()
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

/// The glTF material of a scene material: named as it, its reflectance as
/// `baseColorFactor`, its emission × `exposure` as `emissiveFactor` (with
/// `KHR_materials_emissive_strength` above 1), the exact values in
/// `extras`. Returns the JSON and whether the strength extension is used.
fn material_json(m: &Material, exposure: f32) -> (serde_json::Value, bool) {
    let rho = m.reflectance();
    let e = m.emission();
    let scaled = (e * f64::from(exposure)).to_f32();
    let top = scaled.iter().copied().fold(0.0f32, f32::max);
    let channels = |c: Rgb| [c.r, c.g, c.b];
    let mut json = json!({
        "name": m.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [rho.r, rho.g, rho.b, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "extras": {
            "reflectance": channels(rho),
            "emission": channels(e),
        },
    });
    let strong = top.is_finite() && top > 1.0;
    if top.is_finite() && top > 0.0 {
        let factor = if strong {
            scaled.map(|v| v / top)
        } else {
            scaled
        };
        json["emissiveFactor"] = json!(factor.map(|v| f64::from(v.clamp(0.0, 1.0))));
        if strong {
            json["extensions"] = json!({
                "KHR_materials_emissive_strength": {"emissiveStrength": f64::from(top)}
            });
        }
    }
    (json, strong)
}

/// One primitive's vertices and triangles, in its own numbering.
struct PrimitiveData {
    /// Mesh vertex of each local vertex, in order of first use.
    vertices: Vec<u32>,
    /// The polygon whose normal each local vertex takes.
    normal_of: Vec<PolygonId>,
    /// Local indices, three per triangle.
    indices: Vec<u32>,
}

/// Collects the elements of `polygons` with their vertices renumbered from
/// 0 in order of first use. `local` (one entry per mesh vertex) and
/// `stamp` are scratch space shared between calls; `id` must differ on
/// every call.
fn collect_primitive(
    mesh: &Mesh,
    polygons: &[PolygonId],
    id: u32,
    local: &mut [u32],
    stamp: &mut [u32],
) -> PrimitiveData {
    let mut data = PrimitiveData {
        vertices: Vec::new(),
        normal_of: Vec::new(),
        indices: Vec::new(),
    };
    for &p in polygons {
        let pm = &mesh.polygons[p.index()];
        for e in &mesh.elements[pm.elements.start as usize..pm.elements.end as usize] {
            for tri in e.triangles() {
                for v in tri {
                    let v = v.index();
                    if stamp[v] != id {
                        stamp[v] = id;
                        local[v] = data.vertices.len() as u32;
                        data.vertices.push(v as u32);
                        data.normal_of.push(p);
                    }
                    data.indices.push(local[v]);
                }
            }
        }
    }
    data
}

/// The `.glb` file (see the module docs) for the scene, the mesh built from
/// it, the radiosity per vertex and the exposure of the display colours;
/// `name` as for [`write_mesh`]. The inputs must agree as [`write_mesh`]
/// checks (one radiosity per vertex, one mesh polygon per scene polygon,
/// fewer than 2³² vertices); this function does not check again.
pub fn glb_bytes(
    scene: &Scene,
    mesh: &Mesh,
    radiosity: &[Rgb],
    exposure: f32,
    name: &str,
) -> Vec<u8> {
    let nodes = export_nodes(scene, name);
    let mut buffer = GlbBuffer {
        bin: Vec::with_capacity(mesh.vertex_count() * 48 + mesh.elements.len() * 24),
        views: Vec::new(),
        accessors: Vec::new(),
    };

    let mut gltf_material = vec![None; scene.materials.len()];
    let mut materials = Vec::new();
    let mut strength_used = false;
    let mut local = vec![0u32; mesh.vertex_count()];
    let mut stamp = vec![u32::MAX; mesh.vertex_count()];
    let mut next_id = 0u32;
    let mut meshes = Vec::with_capacity(nodes.len());
    for node in &nodes {
        let mut primitives = Vec::with_capacity(node.primitives.len());
        for (material, polygons) in &node.primitives {
            let data = collect_primitive(mesh, polygons, next_id, &mut local, &mut stamp);
            next_id += 1;
            let (attributes, indices) =
                push_primitive(&mut buffer, mesh, radiosity, exposure, &data);
            let m = material.index();
            let index = *gltf_material[m].get_or_insert_with(|| {
                let (json, strong) = material_json(&scene.materials[m], exposure);
                strength_used |= strong;
                materials.push(json);
                materials.len() - 1
            });
            primitives.push(json!({
                "attributes": attributes,
                "indices": indices,
                "material": index,
                "mode": TRIANGLES,
            }));
        }
        meshes.push(json!({"name": node.name, "primitives": primitives}));
    }

    let GlbBuffer {
        bin,
        views,
        accessors,
    } = buffer;
    let scene_name = if name.is_empty() { "radiosity" } else { name };
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION")),
            "extras": {
                "radiosity_attribute": RADIOSITY_ATTRIBUTE,
                "radiosity_units": "the scene's emission units (exitance)",
                "color_exposure": f64::from(exposure),
            },
        },
        "scene": 0,
        "scenes": [{"name": scene_name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes
            .iter()
            .enumerate()
            .map(|(i, n)| json!({"name": n.name, "mesh": i}))
            .collect::<Vec<_>>(),
        "meshes": meshes,
        "materials": materials,
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    if strength_used {
        doc["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
    }
    // A `Value` always serialises.
    let json_chunk = serde_json::to_vec(&doc).unwrap_or_default();
    glb_container(json_chunk, bin)
}

/// The binary chunk of a `.glb` file as it fills, with the buffer views
/// and accessors that describe its parts.
struct GlbBuffer {
    /// The binary chunk's bytes.
    bin: Vec<u8>,
    /// One buffer view a part of `bin`.
    views: Vec<serde_json::Value>,
    /// One accessor a view, in the same order.
    accessors: Vec<serde_json::Value>,
}

impl GlbBuffer {
    /// Appends one tightly packed view and its accessor; returns the
    /// accessor's index. Every length is a multiple of 4, so every view
    /// starts aligned.
    fn push(
        &mut self,
        bytes: &dyn Fn(&mut Vec<u8>),
        mut accessor: serde_json::Value,
        target: u32,
    ) -> usize {
        let start = self.bin.len();
        bytes(&mut self.bin);
        accessor["bufferView"] = json!(self.views.len());
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": start,
            "byteLength": self.bin.len() - start,
            "target": target,
        }));
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

/// Appends one primitive's positions, normals, display colours, radiosity
/// and triangle indices to `buffer`; returns its `attributes` object and
/// the accessor of its indices.
fn push_primitive(
    buffer: &mut GlbBuffer,
    mesh: &Mesh,
    radiosity: &[Rgb],
    exposure: f32,
    data: &PrimitiveData,
) -> (serde_json::Value, usize) {
    // Written as the f64 equal to each f32, so a reader compares exactly.
    let exact = |v: [f32; 3]| v.map(f64::from);
    let count = data.vertices.len();
    let vec3 = json!({"componentType": FLOAT, "count": count, "type": "VEC3"});
    let (lo, hi) = data.vertices.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), &v| {
            let p = mesh.positions[v as usize].to_array();
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        },
    );
    let mut position = vec3.clone();
    position["min"] = json!(exact(lo));
    position["max"] = json!(exact(hi));
    let position = buffer.push(
        &|b| {
            put_f32s(
                b,
                data.vertices
                    .iter()
                    .flat_map(|&v| mesh.positions[v as usize].to_array()),
            )
        },
        position,
        ARRAY_BUFFER,
    );
    let normal = buffer.push(
        &|b| {
            put_f32s(
                b,
                data.normal_of
                    .iter()
                    .flat_map(|p| mesh.polygons[p.index()].normal.to_array()),
            )
        },
        vec3.clone(),
        ARRAY_BUFFER,
    );
    let color = buffer.push(
        &|b| {
            put_f32s(
                b,
                data.vertices
                    .iter()
                    .flat_map(|&v| linear_display(radiosity[v as usize], exposure)),
            )
        },
        vec3.clone(),
        ARRAY_BUFFER,
    );
    let raw = buffer.push(
        &|b| {
            put_f32s(
                b,
                data.vertices
                    .iter()
                    .flat_map(|&v| radiosity[v as usize].to_f32()),
            )
        },
        vec3,
        ARRAY_BUFFER,
    );
    let indices = buffer.push(
        &|b| {
            for i in &data.indices {
                b.extend_from_slice(&i.to_le_bytes());
            }
        },
        json!({
            "componentType": UNSIGNED_INT,
            "count": data.indices.len(),
            "type": "SCALAR",
        }),
        ELEMENT_ARRAY_BUFFER,
    );
    let attributes = json!({
        "POSITION": position,
        "NORMAL": normal,
        "COLOR_0": color,
        RADIOSITY_ATTRIBUTE: raw,
    });
    (attributes, indices)
}

/// The `.glb` container: its header, then the JSON chunk padded with
/// spaces and the binary chunk `bin` padded with zeros, each to a multiple
/// of 4 bytes.
pub(crate) fn glb_container(mut json_chunk: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
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
mod tests;
