//! Wavefront OBJ + MTL import: a model exported from Blender (or taken from
//! a public OBJ collection) becomes a [`Scene`].
//!
//! What is read:
//!
//! - every `f` line is one face; a face that [`Polygon::new`] accepts as it
//!   is (a planar convex triangle, quad or n-gon) stays one polygon, any
//!   other face with four or more vertices (non-planar, non-convex) is
//!   split into triangles by ear clipping in its best-fit plane. The front
//!   of a face is the side from which its vertices run counter-clockwise,
//!   as in the OBJ convention;
//! - `usemtl NAME` picks the material of the faces that follow; materials
//!   come from the `mtllib` files named in the OBJ, relative to its folder.
//!   A `mtllib` line may name several files (`mtllib a.mtl b.mtl`); a name
//!   that is one existing file is read as one, even with spaces in it;
//! - in a material, `Kd` is the diffuse reflectance (`k_diffrefl` 1 × Kd)
//!   and `Ke` the emitted radiosity (`k_emission` 1 × Ke), in the scene's
//!   radiosity units. A material with both a non-black `Kd` and a
//!   non-black `Ke` keeps the colour of `Ke` exactly and the luminance of
//!   `Kd` (a [`Material`] has one colour): its reflectance is
//!   `Ke × lum(Kd) / lum(Ke)`, capped below one;
//! - `map_Kd FILE` (options such as `-s 1 1 1` skipped, the path relative
//!   to the MTL's folder): the average colour of the texture multiplies
//!   `Kd`. The average is of linear values: 8- and 16-bit images (png,
//!   jpg, tga, ppm/pnm, bmp) are sRGB-decoded before averaging, float
//!   images are taken as linear; alpha is ignored. A radiosity solution
//!   has one reflectance per polygon, so the texture's mean is what a
//!   face reflects on average.
//!
//! What is changed, each with a warning (`FILE:LINE:COL: warning: ...`,
//! one line; a quirk found many times is one warning with a count and the
//! first position) — the model still loads:
//!
//! - a `Kd` with a channel at or above one is scaled so its brightest
//!   channel is [`MAX_MTL_REFLECTANCE`], keeping its hue (one warning per
//!   material);
//! - a material without `Kd` gets [`DEFAULT_REFLECTANCE`] (one warning per
//!   MTL file naming them);
//! - a `map_Kd` texture that cannot be read leaves `Kd` as it is;
//! - `\` in `mtllib` and `map_Kd` paths is read as `/`;
//! - a `mtllib` file that cannot be read defines nothing, and a `usemtl`
//!   of a material no library defines gives its faces the default material
//!   (one warning per name, up to [`MAX_UNDEFINED_WARNINGS`]);
//! - faces of no area, with a repeated vertex, or smaller than the
//!   smallest polygon are dropped (3ds Max writes such faces at UV seams).
//!   A face of four or more vertices keeps the triangles of it that have
//!   an area, silently.
//!
//! Every face is **two-sided** ([`crate::scene::Surface::two_sided`]), as Blender
//! shades it: each side receives, reflects and emits on its own once
//! [`Scene::with_sides`] has added the back copies (`--one-sided` keeps
//! the fronts only). A face that repeats an earlier one exactly is
//! dropped with one warning ([`Scene::drop_duplicates`]).
//!
//! Object (`o`) and group (`g`) names are recorded in [`Scene::groups`],
//! for `--emit` and the warning when nothing emits.
//!
//! **Smooth surfaces** ([`crate::scene::Surface::smooth`]): faces in one smoothing
//! group (`s N`, `N` neither `0` nor `off`, counted within one `o` object
//! so that two objects never join) form one smooth surface, and so do
//! faces that share a corner with the same position and the same normal
//! index (`f a//n`: Blender writes a shared `vn` for the faces of a mesh
//! shaded smooth and a `vn` of its own for each flat face), joined
//! transitively. A face with neither is faceted. The normals' directions
//! are not used: shading follows the geometric normals, and the picture
//! is made continuous across a smooth surface's facet edges (see
//! `mesh::weld`). A face split into triangles gives each its
//! surface.
//!
//! What is ignored (by the scene: the model `--lightmap` writes keeps
//! texture coordinates, normals and `map_Kd` textures, see [`source`]):
//! texture coordinates, the directions of normals, lines
//! (`l`) and points (`p`), `Ka`, `Ns`, other maps,
//! and what makes a material specular, a mirror, glass or metal: non-black
//! `Ks` above [`DIFFUSE_SHEEN_LIMIT`] (Blender's default 0.5 is not), `illum` 3 to 9, `d`
//! below 1 or `Tr` above 0, `Ni` (with `illum` 4, 6 or 7), `Pm` above 0
//! and `Pr` below [`DIFFUSE_SHEEN_LIMIT`]. Such materials are treated
//! as diffuse, named in one warning per MTL file. Faces before any
//! `usemtl` get the built-in material [`DEFAULT_MATERIAL_NAME`] with
//! reflectance [`DEFAULT_REFLECTANCE`] (Blender's default base colour).
//!
//! What is refused (errors with positions): numbers that do not parse or
//! are not finite, out-of-range indices, faces with fewer than three
//! vertices, faces that overlap themselves, negative `Kd`/`Ke` channels,
//! a material defined twice or used before the `mtllib` that defines it,
//! and a file with no faces left.
//!
//! The geometry is parsed by the `tobj` crate with `triangulate: false`, so
//! quads stay quads. `tobj` reports no positions, so this module checks
//! every `v` and `f` line itself first (numbers, index ranges, vertex
//! counts), giving `FILE:LINE:COL` for each mistake, locates any error
//! `tobj` still finds by the line it stopped reading at, and matches the
//! n-th face `tobj` returns to the n-th `f` line of the file (`tobj` keeps
//! file order). MTL files are read here (they are a handful of lines) so
//! that each `Kd` and `Ke` has its position for messages.
//!
//! The camera is framed by [`crate::scene::frame_camera`] (from inside a room,
//! from outside an object), or comes from a
//! sidecar `.sc` file (see [`Scene::with_camera_from`]).

mod mtl;
mod scan;
pub mod source;

use mtl::{parse_mtl, read_textures, Library, MtlMaterial};
use scan::{
    first_word_col, line_at, repaired_text, scan_obj, smooth_surfaces, CountingReader, Scan,
};

use crate::budget::{fmt_count, least_run_bytes, MemoryBudget};
use crate::color::Rgb;
use crate::scene::error::{cannot_read, FILE_START, MAX_DIAGNOSTICS};
use crate::scene::import::input::{read_file, InputKind, InputSet, ModelFolder};
use crate::scene::lighting::emit::GroupScan;
use crate::scene::{
    CameraSource, Diagnostic, Group, LoadError, Material, MaterialId, Polygon, PolygonError, Scene,
    SmoothId, SourcePos, Warning,
};
use glam::{DVec2, DVec3, Vec3};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;

/// The name of the material given to faces that come before any `usemtl`.
pub const DEFAULT_MATERIAL_NAME: &str = "(no usemtl)";

/// Reflectance of [`DEFAULT_MATERIAL_NAME`], every channel, dimensionless:
/// 0.8, the default base colour of a new Blender material.
pub const DEFAULT_REFLECTANCE: f64 = 0.8;

/// The material of faces that name none, called `name`: grey
/// [`DEFAULT_REFLECTANCE`], emitting nothing.
pub(super) fn default_material(name: &str) -> Material {
    Material {
        name: name.to_string(),
        color: Rgb::splat(DEFAULT_REFLECTANCE),
        k_diffrefl: 1.0,
        k_emission: 0.0,
    }
}

/// The largest `Ks` channel (and, for `Pr`, the smallest roughness) that
/// still reads as a diffuse material without a warning, dimensionless:
/// Blender writes `Ks 0.5 0.5 0.5` and `Pr 0.5` for every material of
/// default specular and roughness, a dielectric's faint sheen (4 %
/// reflection head-on), not a shiny one. Above `Ks` 0.5 or below `Pr` 0.5
/// the material was made glossy on purpose, and the warning names it.
pub const DIFFUSE_SHEEN_LIMIT: f64 = 0.5;

/// The brightest diffuse reflectance taken from an MTL file, dimensionless.
/// A `Kd` with a channel at or above one (many exporters write `Kd 1 1 1`
/// for "white") is scaled so that its brightest channel is this, keeping
/// the ratios between channels (its hue). 0.95 is about the whitest real
/// paint or plaster; closer to one, light bounces for ever and the solve
/// converges slowly, and at one it never loses energy.
pub const MAX_MTL_REFLECTANCE: f64 = 0.95;

/// A warning that lists names (materials) lists at most this many, then
/// says how many more, so that it stays one readable line.
pub const MAX_NAMES_IN_WARNING: usize = 8;

/// At most this many undefined material names get a warning each; the
/// rest share one more warning.
pub const MAX_UNDEFINED_WARNINGS: usize = 10;

/// In ear clipping, a corner whose doubled signed area (in the face's
/// plane) is at most this fraction of the face's extent squared counts as
/// straight, not as an ear: it would make a sliver of no area.
pub const EAR_AREA_TOLERANCE: f64 = 1e-9;

/// Reads the OBJ file at `path`, its material libraries, and the camera:
/// framed around the model ([`crate::scene::frame_camera`]), or from the `.sc` file
/// `camera` when given (see [`Scene::with_camera_from`]).
///
/// Errors name the file (the OBJ, an MTL, or the camera file), the line
/// and the column, and every problem found is reported (up to
/// [`MAX_DIAGNOSTICS`]).
pub fn load_obj(path: &Path, camera: Option<&Path>, inputs: &InputSet) -> Result<Scene, LoadError> {
    load_obj_with(path, camera, inputs, &MemoryBudget::for_machine())
}

/// [`load_obj`] within the memory budget `budget`: a file whose faces
/// alone would take more is refused before they are built, and textures
/// are decoded within it.
pub fn load_obj_with(
    path: &Path,
    camera: Option<&Path>,
    inputs: &InputSet,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = inputs
        .read(path, InputKind::Scene)
        .map_err(|e| cannot_read(&file, &e))?;
    // Lossy: a stray Latin-1 byte in a comment must not refuse the model;
    // names are decoded the same way in the OBJ and in its MTL files.
    let text = String::from_utf8_lossy(&bytes);
    let folder = ModelFolder::of(path, inputs);
    let read_mtl = |name: &str| read_library(&folder, name);
    let read_texture = |path: &Path| read_texture_file(&folder, path);
    let scene = parse_obj_reading(&text, &file, &read_mtl, &read_texture, budget);
    // A library or texture refused for what it is or where it lies ends
    // the load, though one that is missing is only warned about.
    if let Some(refused) = folder.refused() {
        return Err(Diagnostic::whole(&file, refused).into());
    }
    scene?.with_camera_read(camera, inputs)
}

/// Turns a `mtllib` name into the library's name for messages and its
/// text, or says why it cannot.
pub type ReadMtl<'a> = dyn Fn(&str) -> Result<(String, String), String> + 'a;

/// Parses OBJ text named `file`: [`load_obj`] without reading the OBJ
/// and its libraries from files. `read_mtl` turns a `mtllib` name into
/// the library's name for messages and its text, or says why it cannot;
/// `map_Kd` textures are still read from the file system, relative to the
/// folder of the library's name (each through
/// [`input::read_file`](crate::scene::import::input::read_file), a regular
/// file within its size limit). The camera frames the model.
pub fn parse_obj(text: &str, file: &str, read_mtl: &ReadMtl<'_>) -> Result<Scene, LoadError> {
    parse_obj_within(text, file, read_mtl, &MemoryBudget::for_machine())
}

/// [`parse_obj`] within the memory budget `budget`, as
/// [`load_obj_with`].
pub fn parse_obj_within(
    text: &str,
    file: &str,
    read_mtl: &ReadMtl<'_>,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let read_texture = |path: &Path| {
        read_file(path, InputKind::Texture)
            .map(|(bytes, _)| bytes)
            .map_err(|e| e.to_string())
    };
    parse_obj_reading(text, file, read_mtl, &read_texture, budget)
}

/// Reads a texture's bytes from its path (the library's folder joined to
/// its `map_Kd` name), or says why it cannot.
pub type ReadTexture<'a> = dyn Fn(&Path) -> Result<Vec<u8>, String> + 'a;

/// [`parse_obj_within`], reading `map_Kd` textures through `read_texture`.
fn parse_obj_reading(
    text: &str,
    file: &str,
    read_mtl: &ReadMtl<'_>,
    read_texture: &ReadTexture<'_>,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut scan = scan_obj(text, file);
    // Each face becomes at least one polygon of three corners, meshed at
    // least into one element: refused here, before `tobj` and the
    // polygons, when even that is over the budget.
    let faces = scan.faces.iter().filter(|f| !f.is_line).count() as u64;
    budget
        .check(least_run_bytes(faces, faces.saturating_mul(3)), || {
            format!("{} faces", fmt_count(faces))
        })
        .map_err(|e| Diagnostic::whole(file, e.to_string()))?;
    smooth_surfaces(&mut scan.faces);
    let mut diags = scan.diags.clone();
    if diags.len() >= MAX_DIAGNOSTICS {
        return Err(LoadError::from_diagnostics(diags));
    }
    let repaired;
    let text = if scan.repairs.is_empty() || !diags.is_empty() {
        text
    } else {
        repaired = repaired_text(text, &scan.repairs);
        repaired.as_str()
    };
    let reading = read_with_tobj(text, file, &scan, read_mtl);
    diags.extend(reading.mtl_diags);
    let mut libraries = reading.libraries;
    let mut warnings = reading_warnings(
        &mut libraries,
        read_texture,
        reading.unreadable,
        reading.mtllib_backslashes,
        &scan,
        file,
        budget,
    );
    let models = placed_models(
        reading.loaded,
        reading.consumed,
        text,
        &scan,
        file,
        &mut diags,
    )?;
    let records: Vec<&MtlMaterial> = libraries.iter().flat_map(|l| &l.materials).collect();
    let defined = defined_materials(&libraries, &mut diags);
    check_usemtls(&scan, &defined, file, &mut diags, &mut warnings);
    let mut materials: Vec<Material> = records.iter().map(|m| m.to_material()).collect();
    let mut groups = scan.names.groups();
    let polygons = face_polygons_of(
        &models,
        &scan,
        &mut materials,
        &mut groups,
        file,
        &mut diags,
        &mut warnings,
    );
    if diags.is_empty() && polygons.is_empty() {
        diags.push(Diagnostic::new(file, FILE_START, "OBJ file has no faces"));
    }
    if !diags.is_empty() {
        return Err(LoadError::from_diagnostics(diags));
    }
    Ok(two_sided_scene(polygons, materials, warnings, groups, file))
}

/// What `tobj` and the MTL reader made of an OBJ text.
struct Reading {
    /// `tobj`'s models, or its error.
    loaded: tobj::LoadResult,
    /// How many bytes of the text `tobj` had read when it stopped.
    consumed: usize,
    /// The libraries that could be read, in the order they were named.
    libraries: Vec<Library>,
    /// The errors in those libraries, in order.
    mtl_diags: Vec<Diagnostic>,
    /// One warning for each library that could not be read.
    unreadable: Vec<Warning>,
    /// `mtllib` paths written with `\`.
    mtllib_backslashes: Tally,
}

/// Has `tobj` read the (checked, repaired) `text`, reading each library a
/// `mtllib` line names through `read_mtl` as `tobj` asks for it.
fn read_with_tobj(text: &str, file: &str, scan: &Scan, read_mtl: &ReadMtl<'_>) -> Reading {
    // tobj reads the text through a reader that remembers how far it got,
    // so an error it reports can be placed on its line.
    let consumed = Rc::new(Cell::new(0usize));
    let libraries: RefCell<Vec<Library>> = RefCell::new(Vec::new());
    let mtl_diags: RefCell<Vec<Diagnostic>> = RefCell::new(Vec::new());
    let obj_warnings: RefCell<Vec<Warning>> = RefCell::new(Vec::new());
    let mtllib_backslashes = RefCell::new(Tally::default());
    let read_once: RefCell<std::collections::HashSet<String>> = RefCell::default();
    let mut reader = CountingReader {
        bytes: text.as_bytes(),
        pos: consumed.clone(),
    };
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = tobj::load_obj_buf(&mut reader, &options, |mtl: &Path| {
        let at = line_at(text, consumed.get());
        let name = mtl.to_string_lossy();
        let pos = scan
            .mtllibs
            .iter()
            .find(|m| m.line == at)
            .map_or(SourcePos { line: at, col: 1 }, |m| m.pos);
        let name = if name.contains('\\') {
            mtllib_backslashes
                .borrow_mut()
                .add(pos, || name.to_string());
            name.replace('\\', "/")
        } else {
            name.to_string()
        };
        // One file (its name may hold spaces), else several names.
        let reads = match read_mtl(&name) {
            Err(_) if name.split_whitespace().nth(1).is_some() => {
                name.split_whitespace().map(read_mtl).collect()
            }
            read => vec![read],
        };
        let mut materials: Vec<tobj::Material> = Vec::new();
        let mut map = HashMap::new();
        for read in reads {
            let (mtl_file, mtl_text) = match read {
                // A library named again (`mtllib m.mtl m.mtl`, or on a
                // later line) is read once: its materials are not
                // redefinitions of themselves.
                Ok((mtl_file, _)) if !read_once.borrow_mut().insert(mtl_file.clone()) => continue,
                Ok(x) => x,
                Err(message) => {
                    obj_warnings.borrow_mut().push(Warning::at(
                        file,
                        pos,
                        format!("{message}; faces using its materials get the default material"),
                    ));
                    continue;
                }
            };
            let library = parse_mtl(&mtl_text, &mtl_file, at);
            mtl_diags.borrow_mut().extend(library.diags.iter().cloned());
            // Names map to indices into the concatenation of every
            // library, as tobj offsets them, so its material ids are ours.
            for m in &library.materials {
                map.insert(m.name.clone(), materials.len());
                materials.push(tobj::Material {
                    name: m.name.clone(),
                    ..Default::default()
                });
            }
            libraries.borrow_mut().push(library);
        }
        Ok((materials, map))
    });
    Reading {
        loaded,
        consumed: consumed.get(),
        libraries: libraries.into_inner(),
        mtl_diags: mtl_diags.into_inner(),
        unreadable: obj_warnings.into_inner(),
        mtllib_backslashes: mtllib_backslashes.into_inner(),
    }
}

/// Reads the libraries' textures, and gives the warnings of reading in
/// their order: each library's, the libraries that could not be read, the
/// face corners that lost a reference, the `mtllib` paths with `\`.
fn reading_warnings(
    libraries: &mut [Library],
    read_texture: &ReadTexture<'_>,
    unreadable: Vec<Warning>,
    backslashes: Tally,
    scan: &Scan,
    file: &str,
    budget: &MemoryBudget,
) -> Vec<Warning> {
    let mut warnings = Vec::new();
    for lib in libraries {
        read_textures(lib, read_texture, budget);
        warnings.append(&mut lib.warnings);
    }
    warnings.extend(unreadable);
    for (tally, what, why) in [
        (
            &scan.dropped[0],
            "texture coordinate",
            "texture coordinates serve only the --lightmap model",
        ),
        (
            &scan.dropped[1],
            "normal",
            "normals only join smooth surfaces",
        ),
    ] {
        if let Some((pos, first)) = &tally.first {
            warnings.push(Warning::at(
                file,
                *pos,
                format!(
                    "{} face corner(s) name a {what} that does not exist (first `{first}`); \
                     read without it ({why})",
                    tally.count
                ),
            ));
        }
    }
    if let Some((pos, first)) = backslashes.first {
        warnings.push(Warning::at(
            file,
            pos,
            format!(
                "{} `mtllib` path(s) written with `\\` (first `{first}`), read with `/`",
                backslashes.count
            ),
        ));
    }
    warnings
}

/// `tobj`'s models, or the error that stopped it: the scan's, which has
/// found the mistake already with its column, else `tobj`'s own, placed on
/// the line it had read up to (`consumed` bytes of `text`). On an error,
/// `diags` (with it) is the result.
fn placed_models(
    loaded: tobj::LoadResult,
    consumed: usize,
    text: &str,
    scan: &Scan,
    file: &str,
    diags: &mut Vec<Diagnostic>,
) -> Result<Vec<tobj::Model>, LoadError> {
    match loaded {
        Ok((models, _)) => Ok(models),
        // The scan found the mistake already, with its column.
        Err(_) if !scan.diags.is_empty() => Err(LoadError::from_diagnostics(std::mem::take(diags))),
        Err(e) => {
            let line = line_at(text, consumed);
            diags.push(Diagnostic::new(
                file,
                SourcePos {
                    line,
                    col: first_word_col(text, line),
                },
                format!("cannot read OBJ: {e}"),
            ));
            Err(LoadError::from_diagnostics(std::mem::take(diags)))
        }
    }
}

/// The materials of every library by name, with the OBJ line of the
/// `mtllib` that loaded each, for the `usemtl` checks; a name defined
/// twice is an error at its second definition.
fn defined_materials<'a>(
    libraries: &'a [Library],
    diags: &mut Vec<Diagnostic>,
) -> HashMap<&'a str, (u32, &'a MtlMaterial)> {
    let mut defined: HashMap<&str, (u32, &MtlMaterial)> = HashMap::new();
    for (lib, m) in libraries
        .iter()
        .flat_map(|l| l.materials.iter().map(move |m| (l, m)))
    {
        match defined.get(m.name.as_str()) {
            Some((_, first)) => diags.push(Diagnostic::new(
                &lib.file,
                m.pos,
                format!(
                    "material `{}` is already defined in {} at {}:{}",
                    m.name, first.file, first.pos.line, first.pos.col
                ),
            )),
            None => {
                defined.insert(&m.name, (lib.loaded_at, m));
            }
        }
    }
    defined
}

/// Checks every `usemtl`: a material used before the `mtllib` that
/// defines it is an error; undefined names warn (the first `usemtl` of
/// each, with how many there are, up to [`MAX_UNDEFINED_WARNINGS`], then
/// one warning for the rest).
fn check_usemtls(
    scan: &Scan,
    defined: &HashMap<&str, (u32, &MtlMaterial)>,
    file: &str,
    diags: &mut Vec<Diagnostic>,
    warnings: &mut Vec<Warning>,
) {
    // Undefined names: the first `usemtl` of each, and how many there are.
    let mut undefined: Vec<(&str, SourcePos, usize)> = Vec::new();
    let mut undefined_index: HashMap<&str, usize> = HashMap::new();
    for u in &scan.usemtls {
        match defined.get(u.name.as_str()) {
            Some((loaded_at, _)) if *loaded_at < u.pos.line => {}
            Some((loaded_at, _)) => diags.push(Diagnostic::new(
                file,
                u.pos,
                format!(
                    "material `{}` is used before the `mtllib` that defines it (line {loaded_at})",
                    u.name
                ),
            )),
            None => match undefined_index.get(u.name.as_str()) {
                Some(&i) => undefined[i].2 += 1,
                None => {
                    undefined_index.insert(&u.name, undefined.len());
                    undefined.push((&u.name, u.pos, 1));
                }
            },
        }
    }
    for &(name, pos, count) in undefined.iter().take(MAX_UNDEFINED_WARNINGS) {
        warnings.push(Warning::at(
            file,
            pos,
            format!(
                "undefined material `{name}` ({count} `usemtl` line(s), the first here): no \
                 `mtllib` defines it; its faces get the default material"
            ),
        ));
    }
    if let Some(&(_, pos, _)) = undefined.get(MAX_UNDEFINED_WARNINGS) {
        let rest = &undefined[MAX_UNDEFINED_WARNINGS..];
        warnings.push(Warning::at(
            file,
            pos,
            format!(
                "{} more undefined materials (the first here): their faces get the default material",
                rest.len()
            ),
        ));
    }
}

/// The polygons of `tobj`'s faces, matched in order to the scan's face
/// lines for their positions, objects, groups and smooth surfaces; faces
/// of no material get the default one (added to `materials` at first
/// use). Degenerate faces are dropped with one warning; faces that cannot
/// be polygons are errors in `diags`.
fn face_polygons_of(
    models: &[tobj::Model],
    scan: &Scan,
    materials: &mut Vec<Material>,
    groups: &mut [Group],
    file: &str,
    diags: &mut Vec<Diagnostic>,
    warnings: &mut Vec<Warning>,
) -> Vec<Polygon> {
    let mut default_id = None;
    let mut polygons = Vec::new();
    let mut faces = scan.faces.iter();
    let mut degenerate = Tally::default();
    for model in models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(i) if i < materials.len() => MaterialId(i as u32),
            _ => *default_id.get_or_insert_with(|| {
                materials.push(default_material(DEFAULT_MATERIAL_NAME));
                MaterialId(materials.len() as u32 - 1)
            }),
        };
        let mut next = 0usize;
        let arities = mesh.face_arities.iter().copied().map(|a| a as usize);
        let all_triangles = std::iter::repeat_n(3, mesh.indices.len() / 3);
        let arities: Box<dyn Iterator<Item = usize>> = if mesh.face_arities.is_empty() {
            Box::new(all_triangles)
        } else {
            Box::new(arities)
        };
        for arity in arities {
            let Some(indices) = mesh.indices.get(next..next + arity) else {
                break;
            };
            next += arity;
            let Some(face) = faces.next() else {
                diags.push(Diagnostic::new(
                    file,
                    FILE_START,
                    "internal error: the OBJ reader returned more faces than the file has `f` lines",
                ));
                return polygons;
            };
            if face.is_line {
                // An `l` line with three or more vertices comes out of
                // tobj as a face: a polyline, not a surface.
                continue;
            }
            let vertices: Vec<Vec3> = indices.iter().map(|&i| position(mesh, i)).collect();
            match face_polygons(material, vertices, face.pos) {
                Ok(mut ps) => {
                    for p in &mut ps {
                        p.surface.smooth = face.smooth.map(SmoothId);
                    }
                    let first = polygons.len();
                    polygons.extend(ps);
                    scan.names.assign(groups, face.names, first..polygons.len());
                }
                Err(FaceError::Degenerate(why)) => degenerate.add(face.pos, || why),
                Err(FaceError::Bad(message)) => {
                    diags.push(Diagnostic::new(file, face.pos, message))
                }
            }
        }
    }
    if let Some((pos, why)) = degenerate.first {
        warnings.push(Warning::at(
            file,
            pos,
            format!(
                "dropped {} degenerate face(s) (no area, or a vertex repeated); the first here: {why}",
                degenerate.count
            ),
        ));
    }
    polygons
}

/// The scene of the read faces, every one two-sided, the camera framing
/// them, repeated faces dropped with one warning.
fn two_sided_scene(
    mut polygons: Vec<Polygon>,
    materials: Vec<Material>,
    warnings: Vec<Warning>,
    groups: Vec<Group>,
    file: &str,
) -> Scene {
    // Blender shades both sides of a face: so does an OBJ face here.
    for p in &mut polygons {
        p.surface.two_sided = true;
    }
    let mut scene = Scene {
        camera: crate::scene::frame_camera(&polygons),
        polygons,
        materials,
        camera_source: CameraSource::AutoFramed,
        warnings,
        groups: GroupScan::finish(groups),
        luminaires: Vec::new(),
        sun: None,
        sky_pattern: None,
    };
    if let Some(warning) = scene.drop_duplicates(file) {
        scene.warnings.push(warning);
    }
    scene
}

// ------------------------------------------------------------ faces --

/// Why a face gives no polygon.
pub(super) enum FaceError {
    /// No area, a repeated vertex, or smaller than the smallest polygon:
    /// the face is dropped with a warning. The reason, for the message.
    Degenerate(String),
    /// Anything else (it overlaps itself, a coordinate out of range): an
    /// error.
    Bad(String),
}

/// Whether a polygon error means "nothing there" (a face to drop) rather
/// than a face that cannot be read.
pub(super) fn is_degenerate(e: &PolygonError) -> bool {
    matches!(
        e,
        PolygonError::ZeroArea
            | PolygonError::EqualVertices { .. }
            | PolygonError::TooSmall { .. }
            | PolygonError::Sliver { .. }
    )
}

/// The polygons of one face: itself when it is a valid polygon, else
/// (four or more vertices) its ear-clipped triangles. Triangles of no area
/// (from collinear or repeated vertices) are dropped; a face with nothing
/// left is [`FaceError::Degenerate`].
fn face_polygons(
    material: MaterialId,
    vertices: Vec<Vec3>,
    origin: SourcePos,
) -> Result<Vec<Polygon>, FaceError> {
    face_pieces(material, vertices, origin).map(|pieces| pieces.into_iter().map(|p| p.0).collect())
}

/// [`face_polygons`], each polygon with the face's corners it is made of
/// (indices into `vertices`, in the polygon's order), so that what the
/// corners carry besides a position (texture coordinates, normals) can
/// follow them.
pub(super) fn face_pieces(
    material: MaterialId,
    vertices: Vec<Vec3>,
    origin: SourcePos,
) -> Result<Vec<(Polygon, Vec<usize>)>, FaceError> {
    let whole = match Polygon::new(material, vertices.clone(), origin) {
        Ok(p) => return Ok(vec![(p, (0..vertices.len()).collect())]),
        Err(e) => e,
    };
    let fail = |e: &PolygonError| {
        if is_degenerate(e) {
            FaceError::Degenerate(e.to_string())
        } else {
            FaceError::Bad(format!("bad face: {e}"))
        }
    };
    if vertices.len() < 4
        || !matches!(
            whole,
            PolygonError::NotPlanar { .. }
                | PolygonError::NotConvex { .. }
                | PolygonError::SelfOverlapping { .. }
                | PolygonError::ZeroArea
                | PolygonError::EqualVertices { .. }
        )
    {
        return Err(fail(&whole));
    }
    let triangles = match ear_clip(&vertices) {
        Some(t) => t,
        None if is_degenerate(&whole) => return Err(fail(&whole)),
        None => {
            return Err(FaceError::Bad(format!(
                "bad face: it overlaps itself and cannot be split into triangles ({whole})"
            )))
        }
    };
    let mut out = Vec::with_capacity(triangles.len());
    for [a, b, c] in triangles {
        match Polygon::new(
            material,
            vec![vertices[a], vertices[b], vertices[c]],
            origin,
        ) {
            Ok(p) => out.push((p, vec![a, b, c])),
            Err(e) if is_degenerate(&e) => {}
            Err(e) => return Err(fail(&e)),
        }
    }
    if out.is_empty() {
        Err(fail(&whole))
    } else {
        Ok(out)
    }
}

/// Triangulates a simple polygon (possibly non-convex, possibly slightly
/// non-planar) by ear clipping in the plane of its Newell normal. The
/// triangles are index triples into `vertices`, counter-clockwise about
/// that normal, like the face. Straight corners are clipped last and come
/// out as zero-area triangles, which the caller drops. `None` when the
/// polygon has no area or overlaps itself.
fn ear_clip(vertices: &[Vec3]) -> Option<Vec<[usize; 3]>> {
    let p: Vec<DVec3> = vertices.iter().map(|v| v.as_dvec3()).collect();
    let n = p.len();
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let normal = normal.normalize_or_zero();
    if normal == DVec3::ZERO {
        return None;
    }
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let q: Vec<DVec2> = p.iter().map(|x| DVec2::new(x.dot(u), x.dot(v))).collect();
    let extent = q
        .iter()
        .flat_map(|a| q.iter().map(move |b| a.distance(*b)))
        .fold(0.0, f64::max);
    let eps = EAR_AREA_TOLERANCE * extent * extent;
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let mut left: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            if cross(q[a], q[b], q[c]) <= eps {
                return false;
            }
            // No other corner inside or on the triangle.
            left.iter().all(|&o| {
                o == a
                    || o == b
                    || o == c
                    || q[o] == q[a]
                    || q[o] == q[b]
                    || q[o] == q[c]
                    || !(cross(q[a], q[b], q[o]) >= -eps
                        && cross(q[b], q[c], q[o]) >= -eps
                        && cross(q[c], q[a], q[o]) >= -eps)
            })
        });
        let k = match ear {
            Some(k) => k,
            // Only straight corners left: clip one; it has no area.
            None if (0..m).all(|k| {
                let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
                cross(q[a], q[b], q[c]).abs() <= eps
            }) =>
            {
                0
            }
            None => return None,
        };
        out.push([left[(k + m - 1) % m], left[k], left[(k + 1) % m]]);
        left.remove(k);
    }
    out.push([left[0], left[1], left[2]]);
    Some(out)
}

/// How often one kind of quirk was seen, and where first (`P` is a
/// [`SourcePos`] for text formats, a JSON path for glTF).
pub(super) struct Tally<P = SourcePos> {
    pub(super) count: usize,
    pub(super) first: Option<(P, String)>,
}

impl<P> Default for Tally<P> {
    fn default() -> Self {
        Tally {
            count: 0,
            first: None,
        }
    }
}

impl<P> Tally<P> {
    /// Counts one more, remembering `what` at `pos` if it is the first.
    pub(super) fn add(&mut self, pos: P, what: impl FnOnce() -> String) {
        self.count += 1;
        if self.first.is_none() {
            self.first = Some((pos, what()));
        }
    }
}

/// `names` as a list for a one-line message: at most
/// [`MAX_NAMES_IN_WARNING`], then how many more.
pub(super) fn name_list(names: &[String]) -> String {
    let mut s = names
        .iter()
        .take(MAX_NAMES_IN_WARNING)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > MAX_NAMES_IN_WARNING {
        s.push_str(&format!(" and {} more", names.len() - MAX_NAMES_IN_WARNING));
    }
    s
}

/// Reads the material library `name` (as an `mtllib` line names it) from
/// the model's `folder`: its path as messages show it and its text
/// (decoded lossily, as the OBJ is), or why it cannot be read.
fn read_library(folder: &ModelFolder, name: &str) -> Result<(String, String), String> {
    let mtl_path = folder.join(name);
    let display = mtl_path.display().to_string();
    match folder.read(&mtl_path, InputKind::Material) {
        Ok(bytes) => Ok((display, String::from_utf8_lossy(&bytes).into_owned())),
        Err(e) => Err(e.to_string()),
    }
}

/// Reads a texture file a material names, from the model's `folder`, or
/// says why it cannot be read.
fn read_texture_file(folder: &ModelFolder, path: &Path) -> Result<Vec<u8>, String> {
    folder
        .read(path, InputKind::Texture)
        .map_err(|e| e.to_string())
}
/// The position of vertex `i` of a mesh tobj read (its `positions`, three
/// floats a vertex; `i` one of its `indices`).
fn position(mesh: &tobj::Mesh, i: u32) -> Vec3 {
    let i = i as usize * 3;
    Vec3::new(
        mesh.positions[i],
        mesh.positions[i + 1],
        mesh.positions[i + 2],
    )
}

#[cfg(test)]
mod tests;
