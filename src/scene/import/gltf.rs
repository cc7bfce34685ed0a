//! glTF 2.0 import: a `.gltf` file (with its buffers external or embedded
//! as `data:` URIs) or a `.glb` file becomes a [`Scene`].
//!
//! glTF lengths are metres and the scene takes them as they are: nothing
//! is converted (a scene's unit of length is whatever its file uses). The
//! `gltf` crate parses and validates the JSON; buffers, accessors and
//! images are read here, with every length and index checked, so a broken
//! file gives an error naming the file and the JSON path of the fault
//! (`m.glb: error: meshes[3].primitives[0].indices: ...`), never a panic.
//!
//! What is read:
//!
//! - the nodes of the default scene (else the first; a file without
//!   scenes: every node that is nobody's child), depth first, each with
//!   its `matrix` or `translation`/`rotation`/`scale` composed with its
//!   parents'. A node whose transform mirrors (negative determinant) has
//!   its triangles' winding reversed, as the glTF specification says, so
//!   fronts stay fronts;
//! - every primitive of a node's mesh: `TRIANGLES`, and `TRIANGLE_STRIP`
//!   and `TRIANGLE_FAN` converted to triangles (with the specification's
//!   winding); `POSITION` (float `VEC3`) and `indices` (unsigned byte,
//!   short or int), with sparse accessors. Each triangle is one polygon;
//! - a primitive with `indices` and `NORMAL` is one smooth surface: its
//!   triangles share their indexed vertices as Blender's Shade Smooth does,
//!   so its polygons get one [`SmoothId`] (per primitive and node);
//! - materials: reflectance `baseColorFactor` × the average colour of
//!   `baseColorTexture` (linear, after the sRGB decoding, as OBJ's
//!   `map_Kd`), emitted radiosity `emissiveFactor` ×
//!   `KHR_materials_emissive_strength` × the average of
//!   `emissiveTexture`, in the scene's radiosity units; a material that
//!   both reflects and emits follows [`Material::with_emission`];
//!   `doubleSided` sets [`Surface::two_sided`](crate::scene::Surface);
//! - the first perspective camera met in the node order: its node's eye,
//!   looking along its −z with its +y up, `yfov`, and a picture 480 pixels
//!   high and `aspectRatio` times as wide (the default size without one);
//!   without a camera the view is framed as for OBJ
//!   ([`crate::scene::frame_camera`]);
//! - node and mesh names, as [`Scene::groups`] (objects and meshes), for
//!   `--emit` and the warning when nothing emits; material names as they
//!   are (an unnamed material is `materials[N]`).
//!
//! What is changed, each with one warning line (`FILE: warning: ...`,
//! counts and the first JSON path when repeated) — the model still loads:
//!
//! - a reflectance with a channel at or above one is scaled so its
//!   brightest channel is [`MAX_MTL_REFLECTANCE`], keeping its hue (one
//!   warning naming the materials);
//! - metallic (`metallicFactor` above 0; note that it is 1 when the file
//!   says nothing), transmitting (`KHR_materials_transmission`) and
//!   alpha-blended materials are treated as diffuse (one warning naming
//!   them);
//! - degenerate triangles (no area, a repeated vertex, a sliver whose
//!   angle vanishes) are dropped;
//! - a point or line primitive is not a surface and is skipped (when
//!   nothing else is left the file is refused, naming it);
//! - a texture that cannot be read leaves its factor alone;
//! - `KHR_lights_punctual` lights are points, spots and suns, not
//!   polygons, so they give no light: the warning says how to light the
//!   model (`--emit NAME=VALUE`, `--sky VALUE`);
//! - a camera that cannot be used (orthographic, or degenerate) is
//!   replaced by the automatic one;
//! - a `POSITION` accessor without `min`/`max` (which the specification
//!   requires) is read all the same.
//!
//! What is ignored: texture coordinates and sampling (a radiosity solution
//! has one reflectance per polygon, so a texture's mean is what a face
//! reflects on average), vertex colours, normal, occlusion and
//! metallic-roughness textures, `KHR_materials_unlit`, `KHR_texture_transform`,
//! skins, morph targets and animations (the rest pose is drawn).
//!
//! What is refused: files that are not glTF 2.0 JSON or glb, truncated
//! glb files, anything the glTF validation refuses (indices out of range,
//! missing required properties, unsupported required extensions such as
//! Draco compression), unreadable or short buffers, accessors of the wrong
//! type or reaching outside their buffer views, vertex indices out of
//! range, non-finite or negative colour factors, emission above
//! [`MAX_EMISSION`], node graphs that are not trees, triangles that no
//! [`Polygon`] may be (coordinates beyond [`crate::scene::MAX_COORDINATE`]), and
//! a file with no triangles.
//!
//! glTF polygons have no line in a file: their [`Polygon::origin`] is
//! `0:0`.

mod glb;
mod indices;
pub mod source;

use super::obj::{is_degenerate, name_list, Tally, MAX_MTL_REFLECTANCE};
use super::texture;
use crate::budget::{fmt_count, least_run_bytes, MemoryBudget, OverBudget};
use crate::camera::{Camera, DEFAULT_SIZE, MAX_PICTURE_SIDE};
use crate::color::Rgb;
use crate::scene::error::{cannot_read, fmt_num, MAX_DIAGNOSTICS};
use crate::scene::import::input::{InputKind, InputSet, ModelFolder};
use crate::scene::{
    CameraSource, Diagnostic, Group, GroupKind, LoadError, Material, MaterialId, Polygon, Scene,
    SmoothId, SourcePos, Warning, MAX_EMISSION,
};
use ::gltf::json;
use base64::Engine as _;
use glam::{DMat4, DQuat, DVec3, Vec3};
use glb::parse_glb;
use json::validation::{Checked, Validate};
use std::collections::HashMap;
use std::path::Path;

/// The name of the material of primitives that name none, with the
/// reflectance [`super::obj::DEFAULT_REFLECTANCE`] of faces without a material in OBJ
/// files (Blender's default base colour) rather than glTF's white, which
/// would reflect everything.
pub const DEFAULT_MATERIAL_NAME: &str = "(no material)";

/// Picture height of a glTF camera, in pixels: the default picture's, so
/// that a camera with the default aspect ratio gives the default picture.
pub const CAMERA_HEIGHT: u32 = DEFAULT_SIZE.1;

/// Reads a named URI (a path relative to the glTF file, percent-decoding
/// done) into bytes, or says why it cannot.
pub type ReadUri<'a> = dyn Fn(&str) -> Result<Vec<u8>, String> + 'a;

/// Reads the `.gltf` or `.glb` file at `path`, its buffers and textures
/// (relative to its folder), and the camera: the file's, else framed
/// around the model, or from the `.sc` file `camera` when given (see
/// [`Scene::with_camera_from`]).
///
/// Errors name the file and the JSON path (or byte offset in a glb) of
/// each problem, up to [`MAX_DIAGNOSTICS`].
pub fn load_gltf(
    path: &Path,
    camera: Option<&Path>,
    inputs: &InputSet,
) -> Result<Scene, LoadError> {
    load_gltf_with(path, camera, inputs, &MemoryBudget::for_machine())
}

/// [`load_gltf`] within the memory budget `budget`: the triangles of
/// every node instance are counted from the accessors before any is
/// built, and a scene over the budget is refused; textures are decoded
/// within it.
pub fn load_gltf_with(
    path: &Path,
    camera: Option<&Path>,
    inputs: &InputSet,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = inputs
        .read(path, InputKind::Scene)
        .map_err(|e| Diagnostic::whole(&file, cannot_read(&file, &e).message))?;
    let folder = ModelFolder::of(path, inputs);
    let read_uri = |name: &str| -> Result<Vec<u8>, String> {
        folder
            .read(&folder.join(name), InputKind::GltfData)
            .map_err(|e| e.to_string())
    };
    let scene = parse_gltf_within(&bytes, &file, &read_uri, budget);
    // An image refused for what it is or where it lies ends the load,
    // though one that is missing is only warned about.
    if let Some(refused) = folder.refused() {
        return Err(Diagnostic::whole(&file, refused).into());
    }
    scene?.with_camera_read(camera, inputs)
}

/// Parses glTF bytes (a glb, or the JSON of a `.gltf`) named `file`;
/// `read_uri` reads the external files the JSON names. The entry point
/// of [`load_gltf`] without the file system.
pub fn parse_gltf(bytes: &[u8], file: &str, read_uri: &ReadUri<'_>) -> Result<Scene, LoadError> {
    parse_gltf_within(bytes, file, read_uri, &MemoryBudget::for_machine())
}

/// [`parse_gltf`] within the memory budget `budget`, as
/// [`load_gltf_with`].
pub fn parse_gltf_within(
    bytes: &[u8],
    file: &str,
    read_uri: &ReadUri<'_>,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let fail = |message: String| LoadError::from(Diagnostic::whole(file, message));
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        let glb = parse_glb(bytes).map_err(fail)?;
        (glb.json, glb.bin)
    } else {
        (bytes, None)
    };
    let json_bytes = json_bytes
        .strip_prefix(b"\xef\xbb\xbf")
        .unwrap_or(json_bytes);
    let root: json::Root = match json::deserialize::from_slice(json_bytes) {
        Ok(root) => root,
        Err(e) => {
            return Err(json_error(
                file,
                &e,
                blob.is_some() || bytes.starts_with(b"glTF"),
            ))
        }
    };
    if let Some((path, index)) = indices::first_wrapping_index(json_bytes) {
        return Err(fail(format!(
            "{path}: index {index} is out of range (glTF indices are at most {})",
            u32::MAX
        )));
    }
    let mut warnings = Vec::new();
    validate(&root, file, &mut warnings)?;
    let document = ::gltf::Document::from_json_without_validation(root);
    let mut reader = Reader::new(&document, file, blob, read_uri);
    reader.warnings = warnings;
    reader.budget = *budget;
    reader.read()
}

/// The diagnostic for JSON that does not parse: at its line and column in
/// a `.gltf`, by line and column of the JSON chunk in a glb.
fn json_error(file: &str, e: &serde_json::Error, in_glb: bool) -> LoadError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = full.strip_suffix(&suffix).unwrap_or(&full);
    let (line, col) = (e.line().max(1) as u32, e.column().max(1) as u32);
    if in_glb {
        Diagnostic::whole(
            file,
            format!("glb JSON chunk, line {line} column {col}: invalid glTF JSON: {message}"),
        )
    } else {
        Diagnostic::new(
            file,
            SourcePos { line, col },
            format!("invalid glTF JSON: {message}"),
        )
    }
    .into()
}

// --------------------------------------------------------- validation --

/// Runs the glTF validation of the `gltf` crate, turning each problem
/// into a diagnostic with its JSON path; a `POSITION` accessor's missing
/// `min`/`max` is a warning instead.
fn validate(root: &json::Root, file: &str, warnings: &mut Vec<Warning>) -> Result<(), LoadError> {
    // The crate's own check of `POSITION` indexes the accessors without a
    // bounds check: out-of-range indices are caught here first.
    let mut diags = Vec::new();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "?".to_string(),
                    };
                    diags.push(Diagnostic::whole(
                        file,
                        format!(
                            "meshes[{m}].primitives[{p}].attributes[\"{name}\"]: accessor {} is \
                             out of range: the file has {} accessors",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    if !diags.is_empty() {
        return Err(LoadError::from_diagnostics(diags));
    }
    let mut min_max: Tally<String> = Tally::default();
    root.validate(root, json::Path::new, &mut |path, error| {
        let path = path().to_string();
        let tolerated = error == json::validation::Error::Missing
            && (path.ends_with("[\"POSITION\"].min") || path.ends_with("[\"POSITION\"].max"));
        if tolerated {
            min_max.add(path, String::new);
            return;
        }
        if diags.len() < MAX_DIAGNOSTICS {
            let what = match error {
                json::validation::Error::IndexOutOfBounds => "index out of range",
                json::validation::Error::Invalid => "invalid value",
                json::validation::Error::Missing => "required but missing",
                json::validation::Error::Oversize => "too large",
                json::validation::Error::Unsupported => "not supported",
            };
            diags.push(Diagnostic::whole(file, format!("{path}: {what}")));
        }
    });
    if !diags.is_empty() {
        return Err(LoadError::from_diagnostics(diags));
    }
    if let Some((path, _)) = min_max.first {
        warnings.push(Warning::file(
            file,
            format!(
                "{} `POSITION` bound(s) missing (the first {path}), which glTF requires; the \
                 positions are read all the same",
                min_max.count
            ),
        ));
    }
    Ok(())
}

// ------------------------------------------------------------ reading --

/// What the walk over the scene's nodes gathers, in node order.
#[derive(Default)]
struct Gathered {
    polygons: Vec<Polygon>,
    /// The named nodes and meshes, in order of first appearance.
    groups: Vec<Group>,
    group_index: HashMap<(GroupKind, String), usize>,
    degenerate: Tally<String>,
    /// Primitives of points or lines.
    skipped: Tally<String>,
    /// The material added for primitives that name none, once needed.
    default_material: Option<MaterialId>,
    next_smooth: u32,
    /// The first camera of a node that could be read.
    camera: Option<Camera>,
    /// Why the first camera that could not be read could not.
    camera_problem: Option<String>,
    /// `KHR_lights_punctual` lights, which are not read.
    lights: Tally<String>,
}

impl Gathered {
    /// Counts a light on `instance`'s node, and takes its camera when no
    /// camera has been read yet.
    fn note_light_and_camera(&mut self, instance: &Instance<'_>) {
        let node = &instance.node;
        if let Some(light) = node.light() {
            self.lights.add(format!("nodes[{}]", node.index()), || {
                light
                    .name()
                    .map_or_else(|| format!("lights[{}]", light.index()), str::to_string)
            });
        }
        if let Some(cam) = node.camera() {
            if self.camera.is_none() {
                match make_camera(&cam, &instance.world) {
                    Ok(c) => self.camera = Some(c),
                    Err(why) => {
                        self.camera_problem.get_or_insert(format!(
                            "nodes[{}]: camera `cameras[{}]` {why}",
                            node.index(),
                            cam.index()
                        ));
                    }
                }
            }
        }
    }

    /// Adds the polygons from `first_polygon` on (those `instance` drew of
    /// `mesh`) to the groups of the node's and the mesh's names.
    fn group(&mut self, instance: &Instance<'_>, mesh: &::gltf::Mesh<'_>, first_polygon: usize) {
        let ids = first_polygon..self.polygons.len();
        if ids.is_empty() {
            return;
        }
        let names = [
            (GroupKind::Object, instance.node.name()),
            (GroupKind::Mesh, mesh.name()),
        ];
        for (kind, name) in names {
            let Some(name) = name.filter(|n| !n.is_empty()) else {
                continue;
            };
            let g = *self
                .group_index
                .entry((kind, name.to_string()))
                .or_insert_with(|| {
                    self.groups.push(Group {
                        name: name.to_string(),
                        kind,
                        polygons: Vec::new(),
                    });
                    self.groups.len() - 1
                });
            self.groups[g]
                .polygons
                .extend(ids.clone().map(|i| crate::scene::PolygonId(i as u32)));
        }
    }
}

/// One glTF document being read into a scene.
struct Reader<'a> {
    doc: &'a ::gltf::Document,
    json: &'a json::Root,
    file: &'a str,
    read_uri: &'a ReadUri<'a>,
    /// Each buffer's bytes, or why they cannot be had (said when used).
    buffers: Vec<Result<Vec<u8>, String>>,
    diags: Vec<Diagnostic>,
    warnings: Vec<Warning>,
    /// Each glTF material's average texture colours, read once.
    textures: HashMap<usize, Result<Rgb, String>>,
    /// The memory the scene may take.
    budget: MemoryBudget,
}

/// A failure to read part of the file: the message, starting with its
/// JSON path.
type Fault = String;

impl<'a> Reader<'a> {
    fn new(
        doc: &'a ::gltf::Document,
        file: &'a str,
        blob: Option<&[u8]>,
        read_uri: &'a ReadUri<'a>,
    ) -> Self {
        let json = doc.as_json();
        let buffers = json
            .buffers
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let path = format!("buffers[{i}]");
                let data = match &b.uri {
                    None => blob
                        .map(<[u8]>::to_vec)
                        .ok_or_else(|| format!("{path}: no `uri` and no glb BIN chunk")),
                    Some(uri) => read_data_uri(uri, read_uri).map_err(|e| format!("{path}: {e}")),
                }?;
                let declared = b.byte_length.0;
                if (data.len() as u64) < declared {
                    return Err(format!(
                        "{path}: `byteLength` is {declared} but the data has {} bytes",
                        data.len()
                    ));
                }
                Ok(data)
            })
            .collect();
        Reader {
            doc,
            json,
            file,
            read_uri,
            buffers,
            diags: Vec::new(),
            warnings: Vec::new(),
            textures: HashMap::new(),
            budget: MemoryBudget::for_machine(),
        }
    }

    fn error(&mut self, message: String) {
        if self.diags.len() < MAX_DIAGNOSTICS {
            self.diags.push(Diagnostic::whole(self.file, message));
        }
    }

    /// The whole document: nodes, then materials, camera and warnings.
    fn read(mut self) -> Result<Scene, LoadError> {
        let file = self.file;
        let instances = match self.instances() {
            Ok(i) => i,
            Err(message) => {
                return Err(Diagnostic::whole(file, message).into());
            }
        };
        self.check_budget(&instances)
            .map_err(|e| Diagnostic::whole(file, e.to_string()))?;
        let (mut materials, non_diffuse, bright) = self.materials();
        let mut gathered = Gathered::default();
        for instance in &instances {
            gathered.note_light_and_camera(instance);
            let Some(mesh) = instance.node.mesh() else {
                continue;
            };
            let first_polygon = gathered.polygons.len();
            self.mesh_polygons(instance, &mesh, &mut materials, &mut gathered);
            gathered.group(instance, &mesh, first_polygon);
        }
        self.finish(gathered, materials, non_diffuse, bright)
    }

    /// Refuses a scene whose triangles, counted over every node instance
    /// from the accessors' counts (a mesh drawn by many nodes counts once
    /// for each), would take more than the budget ([`least_run_bytes`]):
    /// before any triangle is built, so that a small file whose nodes
    /// reuse large meshes ends with an error instead of gigabytes.
    fn check_budget(&self, instances: &[Instance<'a>]) -> Result<(), OverBudget> {
        let mut triangles = 0u64;
        let mut once = 0u64;
        let mut seen = std::collections::HashSet::new();
        for instance in instances {
            let Some(mesh) = instance.node.mesh() else {
                continue;
            };
            let first = seen.insert(mesh.index());
            for primitive in mesh.primitives() {
                let corners = match primitive.indices() {
                    Some(a) => a.count() as u64,
                    None => primitive
                        .get(&::gltf::Semantic::Positions)
                        .map_or(0, |a| a.count() as u64),
                };
                use ::gltf::mesh::Mode;
                let n = match primitive.mode() {
                    Mode::Triangles => corners / 3,
                    Mode::TriangleStrip | Mode::TriangleFan => corners.saturating_sub(2),
                    _ => 0,
                };
                triangles = triangles.saturating_add(n);
                if first {
                    once = once.saturating_add(n);
                }
            }
        }
        let need = least_run_bytes(triangles, triangles.saturating_mul(3));
        self.budget.check(need, || {
            if triangles > once {
                format!(
                    "{} triangles from node instancing, {} in the meshes themselves",
                    fmt_count(triangles),
                    fmt_count(once)
                )
            } else {
                format!("{} triangles", fmt_count(triangles))
            }
        })
    }

    /// The triangles of every primitive of `mesh` drawn by `instance`, in
    /// world space, into `gathered`; the default material is added to
    /// `materials` when a primitive first needs it. Primitives of points
    /// or lines are skipped (and counted), degenerate triangles dropped
    /// (and counted); other bad ones are errors.
    fn mesh_polygons(
        &mut self,
        instance: &Instance<'a>,
        mesh: &::gltf::Mesh<'a>,
        materials: &mut Vec<Material>,
        gathered: &mut Gathered,
    ) {
        let node = &instance.node;
        let mirrored = instance.world.determinant() < 0.0;
        for primitive in mesh.primitives() {
            let path = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            use ::gltf::mesh::Mode;
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                gathered.skipped.add(path.clone(), || format!("{mode:?}"));
                continue;
            }
            let material = match primitive.material().index() {
                Some(i) => MaterialId(i as u32),
                None => *gathered.default_material.get_or_insert_with(|| {
                    materials.push(super::obj::default_material(DEFAULT_MATERIAL_NAME));
                    MaterialId(materials.len() as u32 - 1)
                }),
            };
            let two_sided = primitive.material().double_sided();
            let triangles = match self.triangles(&primitive, &path) {
                Ok(t) => t,
                Err(message) => {
                    self.error(message);
                    continue;
                }
            };
            let smooth = (primitive.indices().is_some()
                && primitive.get(&::gltf::Semantic::Normals).is_some())
            .then(|| {
                gathered.next_smooth += 1;
                SmoothId(gathered.next_smooth - 1)
            });
            for (k, corners) in triangles.iter().enumerate() {
                let mut v: Vec<Vec3> = corners
                    .iter()
                    .map(|p| instance.world.transform_point3(p.as_dvec3()).as_vec3())
                    .collect();
                if mirrored {
                    v.swap(1, 2);
                }
                match Polygon::new(material, v, SourcePos::default()) {
                    Ok(mut p) => {
                        p.surface.two_sided = two_sided;
                        p.surface.smooth = smooth;
                        gathered.polygons.push(p);
                    }
                    Err(e) if is_degenerate(&e) => gathered.degenerate.add(
                        format!("{path} (nodes[{}]), triangle {k}", node.index()),
                        || e.to_string(),
                    ),
                    Err(e) => {
                        self.error(format!(
                            "{path} (nodes[{}]), triangle {k}: {e}",
                            node.index()
                        ));
                        break;
                    }
                }
            }
        }
    }

    /// The scene from what the walk over the nodes gathered: the errors,
    /// else the warnings in their order (skipped primitives, degenerate
    /// triangles, bright and non-diffuse materials, lights, animations,
    /// the camera), the camera aimed or framed, repeated faces dropped.
    fn finish(
        mut self,
        gathered: Gathered,
        materials: Vec<Material>,
        non_diffuse: Vec<String>,
        bright: Vec<String>,
    ) -> Result<Scene, LoadError> {
        let file = self.file;
        if let Some((path, mode)) = gathered.skipped.first {
            let message = format!(
                "{} primitive(s) of points or lines skipped (the first {path}, mode {mode}): \
                 only triangles are surfaces",
                gathered.skipped.count
            );
            if gathered.polygons.is_empty() && self.diags.is_empty() {
                return Err(Diagnostic::whole(file, format!("{path}: {message}")).into());
            }
            self.warnings.push(Warning::file(file, message));
        }
        if let Some((path, why)) = gathered.degenerate.first {
            self.warnings.push(Warning::file(
                file,
                format!(
                    "dropped {} degenerate triangle(s) (no area, or a vertex repeated); the \
                     first {path}: {why}",
                    gathered.degenerate.count
                ),
            ));
        }
        if self.diags.is_empty() && gathered.polygons.is_empty() {
            self.error(
                "glTF file has no triangles in its scene (no node of it draws a mesh)".to_string(),
            );
        }
        if !self.diags.is_empty() {
            return Err(LoadError::from_diagnostics(self.diags));
        }
        if !bright.is_empty() {
            self.warnings.push(Warning::file(
                file,
                format!(
                    "base colour reflects all light or more in {}: scaled so the brightest \
                     channel is {}, keeping the hue",
                    name_list(&bright),
                    fmt_num(MAX_MTL_REFLECTANCE)
                ),
            ));
        }
        if !non_diffuse.is_empty() {
            self.warnings.push(Warning::file(
                file,
                format!("treated as diffuse: {}", name_list(&non_diffuse)),
            ));
        }
        if let Some((path, name)) = gathered.lights.first {
            self.warnings.push(Warning::file(
                file,
                format!(
                    "{} KHR_lights_punctual light(s) ignored (the first `{name}` at {path}): a \
                     point, spot or sun light is not a polygon and gives no light here; make a \
                     surface emit with --emit NAME=VALUE, or light the model from all around \
                     with --sky VALUE",
                    gathered.lights.count
                ),
            ));
        }
        if self.doc.animations().next().is_some() || self.doc.skins().next().is_some() {
            self.warnings.push(Warning::file(
                file,
                "animations and skins are ignored: the model is read in its rest pose",
            ));
        }
        let Gathered {
            polygons,
            groups,
            mut camera,
            camera_problem,
            ..
        } = gathered;
        if let Some(c) = camera.as_mut() {
            aim_at_the_model(c, &polygons);
        }
        let camera_source = if camera.is_some() {
            CameraSource::File
        } else {
            CameraSource::AutoFramed
        };
        if camera.is_none() {
            if let Some(problem) = camera_problem {
                self.warnings.push(Warning::file(
                    file,
                    format!("{problem}; the camera is framed automatically"),
                ));
            }
        }
        let mut scene = Scene {
            camera: camera.unwrap_or_else(|| crate::scene::frame_camera(&polygons)),
            camera_source,
            polygons,
            materials,
            warnings: self.warnings,
            groups,
            luminaires: Vec::new(),
            sun: None,
            sky_pattern: None,
        };
        if let Some(warning) = scene.drop_duplicates(file) {
            scene.warnings.push(warning);
        }
        Ok(scene)
    }

    /// Every node of the scene to draw, depth first, with its world
    /// transform; an error when the nodes are not a forest.
    fn instances(&self) -> Result<Vec<Instance<'a>>, Fault> {
        let nodes: Vec<::gltf::Node<'a>> = self.doc.nodes().collect();
        let roots: Vec<usize> = match self
            .doc
            .default_scene()
            .or_else(|| self.doc.scenes().next())
        {
            Some(scene) => scene.nodes().map(|n| n.index()).collect(),
            None => {
                let mut child = vec![false; nodes.len()];
                for n in &nodes {
                    for c in n.children() {
                        child[c.index()] = true;
                    }
                }
                (0..nodes.len()).filter(|&i| !child[i]).collect()
            }
        };
        let mut seen = vec![false; nodes.len()];
        let mut out = Vec::new();
        // Children are pushed in reverse so they come out in file order.
        let mut stack: Vec<(usize, DMat4)> =
            roots.iter().rev().map(|&i| (i, DMat4::IDENTITY)).collect();
        while let Some((i, parent)) = stack.pop() {
            if std::mem::replace(&mut seen[i], true) {
                return Err(format!(
                    "nodes[{i}]: the node is reached twice from the scene's roots (a node has \
                     at most one parent and the nodes form no cycle)"
                ));
            }
            let node = nodes[i].clone();
            let world = parent * local_transform(&node)?;
            for c in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((c.index(), world));
            }
            out.push(Instance { node, world });
        }
        Ok(out)
    }

    /// The triangles of a primitive in its mesh's coordinates.
    fn triangles(
        &self,
        primitive: &::gltf::Primitive<'_>,
        path: &str,
    ) -> Result<Vec<[Vec3; 3]>, Fault> {
        let Some(position) = primitive.get(&::gltf::Semantic::Positions) else {
            return Err(format!("{path}: no POSITION attribute"));
        };
        let positions = self
            .read_vec3(position.index())
            .map_err(|e| format!("{path}.attributes[\"POSITION\"]: {e}"))?;
        let indices: Vec<u32> = match primitive.indices() {
            Some(a) => {
                let indices = self
                    .read_indices(a.index())
                    .map_err(|e| format!("{path}.indices: {e}"))?;
                if let Some((k, &i)) = indices
                    .iter()
                    .enumerate()
                    .find(|&(_, &i)| i as usize >= positions.len())
                {
                    return Err(format!(
                        "{path}.indices: index {i} (element {k}) is out of range: POSITION has \
                         {} vertices",
                        positions.len()
                    ));
                }
                indices
            }
            None => (0..positions.len() as u32).collect(),
        };
        let corners = index_triangles(&indices, primitive.mode());
        Ok(corners
            .into_iter()
            .map(|t| t.map(|i| Vec3::from_array(positions[i as usize])))
            .collect())
    }

    /// The glTF materials as scene materials (same order, so a glTF
    /// material index is its [`MaterialId`]), the names of those treated
    /// as diffuse (with why), and the names of those scaled below one.
    fn materials(&mut self) -> (Vec<Material>, Vec<String>, Vec<String>) {
        let mut out = Vec::new();
        let mut non_diffuse = Vec::new();
        let mut bright = Vec::new();
        let mut unread: Tally<String> = Tally::default();
        for m in self.doc.materials() {
            let i = m.index().unwrap_or(0);
            let name = m
                .name()
                .filter(|n| !n.is_empty())
                .map_or_else(|| format!("materials[{i}]"), str::to_string);
            let pbr = m.pbr_metallic_roughness();
            let base = pbr.base_color_factor();
            let mut rho = Rgb::new(base[0].into(), base[1].into(), base[2].into());
            let strength = m.emissive_strength().unwrap_or(1.0);
            let e = m.emissive_factor();
            let mut emission =
                Rgb::new(e[0].into(), e[1].into(), e[2].into()) * f64::from(strength);
            let checks = [
                ("pbrMetallicRoughness.baseColorFactor", rho),
                ("emissiveFactor × KHR_materials_emissive_strength", emission),
            ];
            let mut bad = false;
            for (what, c) in checks {
                if !c.is_finite() || c.min_channel() < 0.0 {
                    self.error(format!(
                        "materials[{i}] `{name}`: {what} {} has a negative or infinite channel",
                        show(c)
                    ));
                    bad = true;
                }
            }
            if emission.max_channel() > MAX_EMISSION {
                self.error(format!(
                    "materials[{i}] `{name}`: emission {} is above the largest allowed, {}",
                    show(emission),
                    fmt_num(MAX_EMISSION)
                ));
                bad = true;
            }
            if bad {
                out.push(Material {
                    name,
                    color: Rgb::BLACK,
                    k_diffrefl: 0.0,
                    k_emission: 0.0,
                });
                continue;
            }
            let textures = [
                ("baseColorTexture", pbr.base_color_texture()),
                ("emissiveTexture", m.emissive_texture()),
            ];
            for (k, (what, info)) in textures.into_iter().enumerate() {
                let Some(info) = info else {
                    continue;
                };
                let image = info.texture().source().index();
                match self.texture_average(image) {
                    Ok(avg) if k == 0 => rho = rho * avg,
                    Ok(avg) => emission = emission * avg,
                    Err(why) => unread.add(format!("materials[{i}].{what}"), || {
                        format!("images[{image}] (material `{name}`): {why}")
                    }),
                }
            }
            if rho.max_channel() >= 1.0 {
                rho = rho * (MAX_MTL_REFLECTANCE / rho.max_channel());
                bright.push(name.clone());
            }
            let mut why = Vec::new();
            if pbr.metallic_factor() > 0.0 {
                why.push(format!(
                    "metallic {}",
                    fmt_num(pbr.metallic_factor().into())
                ));
            }
            if let Some(t) = m.transmission().filter(|t| t.transmission_factor() > 0.0) {
                why.push(format!(
                    "transmission {}",
                    fmt_num(t.transmission_factor().into())
                ));
            }
            if m.alpha_mode() == ::gltf::material::AlphaMode::Blend && base[3] < 1.0 {
                why.push(format!("alpha {}", fmt_num(base[3].into())));
            }
            if !why.is_empty() {
                non_diffuse.push(format!("{name} ({})", why.join(", ")));
            }
            let diffuse = Material {
                name,
                color: rho,
                k_diffrefl: 1.0,
                k_emission: 0.0,
            };
            out.push(diffuse.with_emission(emission));
        }
        if let Some((path, first)) = unread.first {
            self.warnings.push(Warning::file(
                self.file,
                format!(
                    "cannot read {} texture(s), the first {path}: {first}; their materials keep \
                     their factors",
                    unread.count
                ),
            ));
        }
        (out, non_diffuse, bright)
    }

    /// The average linear colour of image `index`, read once.
    fn texture_average(&mut self, index: usize) -> Result<Rgb, String> {
        if let Some(r) = self.textures.get(&index) {
            return r.clone();
        }
        let result = self
            .image_bytes(index)
            .and_then(|bytes| texture::average_bytes(&bytes, None, &self.budget));
        self.textures.insert(index, result.clone());
        result
    }

    /// The encoded bytes of image `index`.
    fn image_bytes(&self, index: usize) -> Result<Vec<u8>, String> {
        let image = &self.json.images[index];
        match (&image.uri, &image.buffer_view) {
            (Some(uri), _) => read_data_uri(uri, self.read_uri),
            (None, Some(view)) => self.view_bytes(view.value()).map(<[u8]>::to_vec),
            (None, None) => Err("no `uri` and no `bufferView`".to_string()),
        }
    }

    /// The bytes of buffer view `v`, checked against its buffer.
    fn view_bytes(&self, v: usize) -> Result<&[u8], String> {
        let view = &self.json.buffer_views[v];
        let b = view.buffer.value();
        let data = match &self.buffers[b] {
            Ok(d) => d,
            Err(e) => return Err(e.clone()),
        };
        let start = view.byte_offset.map_or(0, |o| o.0);
        let end = start.checked_add(view.byte_length.0);
        end.and_then(|end| data.get(usize::try_from(start).ok()?..usize::try_from(end).ok()?))
            .ok_or_else(|| {
                format!(
                    "bufferViews[{v}]: bytes {start} to {} are outside buffers[{b}] ({} bytes)",
                    end.map_or_else(|| "beyond".to_string(), |e| e.to_string()),
                    data.len()
                )
            })
    }

    /// Reads accessor `a` as `dims` components of `component` each,
    /// decoding one element with `decode`; sparse values applied.
    fn read_elements<T: Copy + Default>(
        &self,
        a: usize,
        allowed: &[json::accessor::ComponentType],
        dims: json::accessor::Type,
        decode: impl Fn(json::accessor::ComponentType, &[u8]) -> T,
    ) -> Result<Vec<T>, String> {
        let accessor = &self.json.accessors[a];
        let prefix = format!("accessors[{a}]");
        let (Checked::Valid(ct), Checked::Valid(ty)) = (accessor.component_type, accessor.type_)
        else {
            return Err(format!("{prefix}: invalid componentType or type"));
        };
        let ct = ct.0;
        if ty != dims || !allowed.contains(&ct) {
            return Err(format!(
                "{prefix} is {ty:?} of {ct:?}; expected {dims:?} of {}",
                allowed
                    .iter()
                    .map(|c| format!("{c:?}"))
                    .collect::<Vec<_>>()
                    .join(" or ")
            ));
        }
        let count = accessor.count.0;
        let size = ct.size() * ty.multiplicity();
        let mut out: Vec<T> = match accessor.buffer_view {
            Some(view) => {
                let bytes = self.view_bytes(view.value())?;
                let stride = self.json.buffer_views[view.value()]
                    .byte_stride
                    .map_or(size, |s| s.0)
                    .max(1);
                if stride < size {
                    return Err(format!(
                        "{prefix}: the byte stride {stride} is shorter than an element ({size} \
                         bytes)"
                    ));
                }
                let offset = accessor.byte_offset.map_or(0, |o| o.0);
                let needed = match count {
                    0 => Some(0),
                    n => (n - 1)
                        .checked_mul(stride as u64)
                        .and_then(|x| x.checked_add(size as u64))
                        .and_then(|x| x.checked_add(offset)),
                };
                match needed {
                    Some(n) if n <= bytes.len() as u64 => {}
                    _ => {
                        return Err(format!(
                            "{prefix}: {count} elements of {size} bytes (stride {stride}) from \
                             byte {offset} do not fit in bufferViews[{}] ({} bytes)",
                            view.value(),
                            bytes.len()
                        ))
                    }
                }
                (0..count as usize)
                    .map(|k| {
                        let at = offset as usize + k * stride;
                        decode(ct, &bytes[at..at + size])
                    })
                    .collect()
            }
            None => {
                // Zeros, which only sparse values make anything of: more
                // of them than the file has bytes describe nothing more.
                let limit = self.buffers.iter().flatten().map(Vec::len).sum::<usize>() as u64;
                if count > limit.max(1) {
                    return Err(format!(
                        "{prefix}: {count} elements without a bufferView, more than the file's \
                         buffers have bytes ({limit})"
                    ));
                }
                vec![T::default(); count as usize]
            }
        };
        if let Some(sparse) = &accessor.sparse {
            let n = sparse.count.0;
            let index_type = match sparse.indices.component_type {
                Checked::Valid(t) => t.0,
                Checked::Invalid => {
                    return Err(format!("{prefix}.sparse.indices: invalid componentType"))
                }
            };
            let isize_ = index_type.size();
            let ibytes = self.view_bytes(sparse.indices.buffer_view.value())?;
            let vbytes = self.view_bytes(sparse.values.buffer_view.value())?;
            let ioff = sparse.indices.byte_offset.0;
            let voff = sparse.values.byte_offset.0;
            let fits = |off: u64, each: usize, bytes: &[u8]| {
                n.checked_mul(each as u64)
                    .and_then(|x| x.checked_add(off))
                    .is_some_and(|end| end <= bytes.len() as u64)
            };
            if !fits(ioff, isize_, ibytes) || !fits(voff, size, vbytes) {
                return Err(format!(
                    "{prefix}.sparse: {n} indices or values do not fit in their buffer views"
                ));
            }
            for k in 0..n as usize {
                let at = ioff as usize + k * isize_;
                let i = read_uint(index_type, &ibytes[at..at + isize_]) as usize;
                let Some(slot) = out.get_mut(i) else {
                    return Err(format!(
                        "{prefix}.sparse: index {i} is out of range: the accessor has {count} \
                         elements"
                    ));
                };
                let at = voff as usize + k * size;
                *slot = decode(ct, &vbytes[at..at + size]);
            }
        }
        Ok(out)
    }

    /// A float `VEC3` accessor.
    fn read_vec3(&self, a: usize) -> Result<Vec<[f32; 3]>, String> {
        use json::accessor::{ComponentType, Type};
        self.read_elements(a, &[ComponentType::F32], Type::Vec3, |_, b| {
            let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
            [f(0), f(4), f(8)]
        })
    }

    /// An index accessor: unsigned byte, short or int scalars.
    fn read_indices(&self, a: usize) -> Result<Vec<u32>, String> {
        use json::accessor::{ComponentType, Type};
        self.read_elements(
            a,
            &[ComponentType::U8, ComponentType::U16, ComponentType::U32],
            Type::Scalar,
            read_uint,
        )
    }
}

/// An unsigned little-endian integer of component type `ct` (`u8`, `u16`
/// or `u32`; anything else reads the first four bytes it is given).
fn read_uint(ct: json::accessor::ComponentType, b: &[u8]) -> u32 {
    use json::accessor::ComponentType;
    match ct {
        ComponentType::U8 | ComponentType::I8 => u32::from(b[0]),
        ComponentType::U16 | ComponentType::I16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// A node to draw and its transform to world space.
struct Instance<'a> {
    node: ::gltf::Node<'a>,
    world: DMat4,
}

/// A node's own transform: its `matrix`, or `translation` × `rotation` ×
/// `scale`. The rotation is normalised (writers round it); a rotation of
/// no length or a non-finite value is an error.
fn local_transform(node: &::gltf::Node<'_>) -> Result<DMat4, Fault> {
    let i = node.index();
    let m = match node.transform() {
        ::gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
        }
        ::gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let q = DQuat::from_array(rotation.map(f64::from));
            if q.length() <= 0.0 || !q.is_finite() {
                return Err(format!(
                    "nodes[{i}].rotation: {rotation:?} is not a rotation (a unit quaternion)"
                ));
            }
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q.normalize(),
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    };
    if !m.is_finite() {
        return Err(format!("nodes[{i}]: the transform is not finite"));
    }
    Ok(m)
}

/// The triangles of a primitive's vertex list, as the specification reads
/// each mode; other modes give none.
fn index_triangles(indices: &[u32], mode: ::gltf::mesh::Mode) -> Vec<[u32; 3]> {
    use ::gltf::mesh::Mode;
    let n = indices.len();
    match mode {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        // Every other triangle of a strip runs backwards, so all face the
        // same way: {v_i, v_(i+1+i%2), v_(i+2-i%2)}.
        Mode::TriangleStrip if n >= 3 => (0..n - 2)
            .map(|i| {
                let odd = i % 2;
                [indices[i], indices[i + 1 + odd], indices[i + 2 - odd]]
            })
            .collect(),
        // {v_(i+1), v_(i+2), v_0}.
        Mode::TriangleFan if n >= 3 => (0..n - 2)
            .map(|i| [indices[i + 1], indices[i + 2], indices[0]])
            .collect(),
        _ => Vec::new(),
    }
}

/// The camera of a perspective glTF camera at `world` (its node's
/// transform): the eye at the node's origin, looking along its −z, up its
/// +y; or why it cannot be used.
fn make_camera(camera: &::gltf::Camera<'_>, world: &DMat4) -> Result<Camera, String> {
    let ::gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return Err("is orthographic, which a perspective picture cannot show".to_string());
    };
    let eye = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
    let up = world.transform_vector3(DVec3::Y);
    let (width, height) = match p.aspect_ratio() {
        Some(a) if a.is_finite() && a > 0.0 => {
            let w = (f64::from(CAMERA_HEIGHT) * f64::from(a)).round();
            if (1.0..=f64::from(MAX_PICTURE_SIDE)).contains(&w) {
                (w as u32, CAMERA_HEIGHT)
            } else {
                DEFAULT_SIZE
            }
        }
        _ => DEFAULT_SIZE,
    };
    let c = Camera {
        eye: eye.as_vec3(),
        lookat: (eye + forward).as_vec3(),
        up: up.as_vec3(),
        fov_y: p.yfov(),
        width,
        height,
    };
    c.check().map_err(|e| format!("cannot be used: {e}"))?;
    Ok(c)
}

/// Moves a file camera's look-at point along its view to the depth of
/// the model's centre, so that the window orbits the model; the view
/// itself does not change. Left alone when the centre is behind the eye.
fn aim_at_the_model(camera: &mut Camera, polygons: &[Polygon]) {
    let (lo, hi) = crate::scene::polygon_bounds(polygons);
    let centre = (0.5 * (lo + hi)).as_dvec3();
    let eye = camera.eye.as_dvec3();
    let forward = (camera.lookat - camera.eye).as_dvec3().normalize_or_zero();
    let depth = (centre - eye).dot(forward);
    if depth.is_finite() && depth > 0.0 {
        let mut moved = *camera;
        moved.lookat = (eye + forward * depth).as_vec3();
        if moved.check().is_ok() {
            *camera = moved;
        }
    }
}

/// The bytes a glTF URI names: a `data:` URI's base64 payload, or a file
/// (percent-decoded, relative to the glTF file) read by `read_uri`.
fn read_data_uri(uri: &str, read_uri: &ReadUri<'_>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("a `data:` URI that is not base64".to_string());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(payload.trim_end())
            .map_err(|e| format!("the `data:` URI's base64 is invalid: {e}"));
    }
    if uri.contains("://") {
        return Err(format!(
            "`{uri}` is not a relative path or a `data:` URI (nothing is downloaded)"
        ));
    }
    let path = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|_| format!("`{uri}` percent-decodes to something that is not UTF-8"))?;
    read_uri(&path)
}

/// A colour for a message: `r g b` with three significant digits.
fn show(c: Rgb) -> String {
    c.to_array().map(fmt_num).join(" ")
}

#[cfg(test)]
mod tests;
