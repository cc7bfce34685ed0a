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
//! What is ignored: texture coordinates, the directions of normals, lines
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

use crate::color::Rgb;
use crate::scene::error::{cannot_read, fmt_num, negative_channel, FILE_START, MAX_DIAGNOSTICS};
use crate::scene::lighting::emit::GroupScan;
use crate::scene::{
    CameraSource, Diagnostic, LoadError, Material, MaterialId, Polygon, PolygonError, Scene,
    SmoothId, SourcePos, Warning,
};
use glam::{DVec2, DVec3, Vec3};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::io::{self, BufRead, Read};
use std::path::{Path, PathBuf};
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
pub fn load_obj(path: &Path, camera: Option<&Path>) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| cannot_read(&file, &e))?;
    // Lossy: a stray Latin-1 byte in a comment must not refuse the model;
    // names are decoded the same way in the OBJ and in its MTL files.
    let text = String::from_utf8_lossy(&bytes);
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let read_mtl = |name: &str| -> Result<(String, String), String> {
        let mtl_path: PathBuf = dir.join(name);
        let display = mtl_path.display().to_string();
        match std::fs::read(&mtl_path) {
            Ok(bytes) => Ok((display, String::from_utf8_lossy(&bytes).into_owned())),
            Err(e) => Err(format!("cannot read material library {display}: {e}")),
        }
    };
    parse_obj(&text, &file, &read_mtl)?.with_camera_from(camera)
}

/// Turns a `mtllib` name into the library's name for messages and its
/// text, or says why it cannot.
pub type ReadMtl<'a> = dyn Fn(&str) -> Result<(String, String), String> + 'a;

/// Parses OBJ text named `file`: [`load_obj`] without reading the OBJ
/// and its libraries from files. `read_mtl` turns a `mtllib` name into
/// the library's name for messages and its text, or says why it cannot;
/// `map_Kd` textures are still read from the file system, relative to the
/// folder of the library's name. The camera frames the model.
pub fn parse_obj(text: &str, file: &str, read_mtl: &ReadMtl<'_>) -> Result<Scene, LoadError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut scan = scan_obj(text, file);
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

    // tobj reads the text through a reader that remembers how far it got,
    // so an error it reports can be placed on its line.
    let consumed = Rc::new(Cell::new(0usize));
    let libraries: RefCell<Vec<Library>> = RefCell::new(Vec::new());
    let mtl_diags: RefCell<Vec<Diagnostic>> = RefCell::new(Vec::new());
    let obj_warnings: RefCell<Vec<Warning>> = RefCell::new(Vec::new());
    let mtllib_backslashes = RefCell::new(Tally::default());
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
    diags.extend(mtl_diags.into_inner());
    let mut libraries = libraries.into_inner();
    let mut warnings = Vec::new();
    for lib in &mut libraries {
        read_textures(lib);
        warnings.append(&mut lib.warnings);
    }
    warnings.extend(obj_warnings.into_inner());
    for (tally, what, why) in [
        (
            &scan.dropped[0],
            "texture coordinate",
            "texture coordinates are not used",
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
    let backslashes = mtllib_backslashes.into_inner();
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
    let models = match loaded {
        Ok((models, _)) => models,
        // The scan found the mistake already, with its column.
        Err(_) if !scan.diags.is_empty() => return Err(LoadError::from_diagnostics(diags)),
        Err(e) => {
            let line = line_at(text, consumed.get());
            diags.push(Diagnostic::new(
                file,
                SourcePos {
                    line,
                    col: first_word_col(text, line),
                },
                format!("cannot read OBJ: {e}"),
            ));
            return Err(LoadError::from_diagnostics(diags));
        }
    };

    // Materials, in library order, by name for `usemtl` checks.
    let records: Vec<&MtlMaterial> = libraries.iter().flat_map(|l| &l.materials).collect();
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

    let mut materials: Vec<Material> = records.iter().map(|m| m.to_material()).collect();
    let mut default_id = None;
    let mut polygons = Vec::new();
    let mut faces = scan.faces.iter();
    let mut groups = scan.names.groups();
    let mut degenerate = Tally::default();
    for model in &models {
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
                return Err(LoadError::from_diagnostics(diags));
            };
            if face.is_line {
                // An `l` line with three or more vertices comes out of
                // tobj as a face: a polyline, not a surface.
                continue;
            }
            let vertices: Vec<Vec3> = indices
                .iter()
                .map(|&i| {
                    let i = i as usize * 3;
                    Vec3::new(
                        mesh.positions[i],
                        mesh.positions[i + 1],
                        mesh.positions[i + 2],
                    )
                })
                .collect();
            match face_polygons(material, vertices, face.pos) {
                Ok(mut ps) => {
                    for p in &mut ps {
                        p.surface.smooth = face.smooth.map(SmoothId);
                    }
                    let first = polygons.len();
                    polygons.extend(ps);
                    scan.names
                        .assign(&mut groups, face.names, first..polygons.len());
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
    if diags.is_empty() && polygons.is_empty() {
        diags.push(Diagnostic::new(file, FILE_START, "OBJ file has no faces"));
    }
    if !diags.is_empty() {
        return Err(LoadError::from_diagnostics(diags));
    }
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
    };
    if let Some(warning) = scene.drop_duplicates(file) {
        scene.warnings.push(warning);
    }
    Ok(scene)
}

// ------------------------------------------------------------ faces --

/// Why a face gives no polygon.
enum FaceError {
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
        PolygonError::ZeroArea | PolygonError::EqualVertices { .. } | PolygonError::TooSmall { .. }
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
    let whole = match Polygon::new(material, vertices.clone(), origin) {
        Ok(p) => return Ok(vec![p]),
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
            Ok(p) => out.push(p),
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

// ------------------------------------------------------------- scan --

/// What the OBJ pre-scan finds.
struct Scan {
    diags: Vec<Diagnostic>,
    /// Every `f` line, and every `l` line with three or more vertices, in
    /// file order.
    faces: Vec<FaceLine>,
    usemtls: Vec<Named>,
    mtllibs: Vec<MtlLib>,
    /// The `o` and `g` statements.
    names: GroupScan,
    /// Face and line statements rewritten without the texture coordinate
    /// or normal references that point at nothing: `(line number, the
    /// line as tobj must read it)`.
    repairs: Vec<(u32, String)>,
    /// Corners whose texture coordinate `[0]` or normal `[1]` index is out
    /// of range (both are dropped, see [`check_reference`]).
    dropped: [Tally; 2],
}

struct FaceLine {
    pos: SourcePos,
    is_line: bool,
    /// Its objects and groups, for [`GroupScan::assign`].
    names: u32,
    /// The smoothing group it is in, `(object, s number)`: the object
    /// counts `o` statements, so two objects never share one.
    smoothing: Option<(u32, u64)>,
    /// Its corners that name a normal: `(position, normal)`, both
    /// 1-based file indices (negative ones resolved).
    normals: Vec<(u64, u64)>,
    /// Its smooth surface, from [`smooth_surfaces`].
    smooth: Option<u32>,
}

struct Named {
    name: String,
    pos: SourcePos,
}

struct MtlLib {
    line: u32,
    pos: SourcePos,
}

/// The words of a line (split on whitespace, as `tobj` splits them) with
/// their 1-based columns in characters.
fn words(line: &str) -> Vec<(&str, u32)> {
    let mut out = Vec::new();
    let mut start: Option<(usize, u32)> = None;
    let mut col = 0u32;
    for (i, c) in line.char_indices() {
        col += 1;
        if c.is_whitespace() {
            if let Some((s, sc)) = start.take() {
                out.push((&line[s..i], sc));
            }
        } else if start.is_none() {
            start = Some((i, col));
        }
    }
    if let Some((s, sc)) = start {
        out.push((&line[s..], sc));
    }
    out
}

/// Lines as `tobj` reads them (split at LF, a CR before it dropped), with
/// their 1-based numbers.
fn lines(text: &str) -> impl Iterator<Item = (u32, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i as u32 + 1, l.strip_suffix('\r').unwrap_or(l)))
}

/// Checks every `v`, `vt`, `vn`, `f` and `l` line, and notes where the
/// faces, `usemtl` and `mtllib` lines are.
fn scan_obj(text: &str, file: &str) -> Scan {
    let mut scan = Scan {
        diags: Vec::new(),
        faces: Vec::new(),
        usemtls: Vec::new(),
        mtllibs: Vec::new(),
        names: GroupScan::default(),
        repairs: Vec::new(),
        dropped: [Tally::default(), Tally::default()],
    };
    // Positive indices may refer to any vertex of the file (tobj resolves
    // them at the end), negative ones count back from the current line.
    let mut totals = [0usize; 3];
    for (_, line) in lines(text) {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    let mut object = 0u32;
    let mut smoothing: Option<u64> = None;
    for (number, line) in lines(text) {
        if scan.diags.len() >= MAX_DIAGNOSTICS {
            break;
        }
        let w = words(line);
        let Some(&(keyword, col)) = w.first() else {
            continue;
        };
        let at = |col: u32| SourcePos { line: number, col };
        let mut error = |col: u32, message: String| {
            scan.diags.push(Diagnostic::new(file, at(col), message));
        };
        match keyword {
            "v" | "vt" | "vn" => {
                let (kind, need) = match keyword {
                    "v" => (0, 3),
                    "vt" => (1, 1),
                    _ => (2, 3),
                };
                seen[kind] += 1;
                if w.len() - 1 < need {
                    error(
                        col,
                        format!(
                            "`{keyword}` needs at least {need} numbers, found {}",
                            w.len() - 1
                        ),
                    );
                    continue;
                }
                for &(word, c) in &w[1..] {
                    match word.parse::<f32>() {
                        Ok(x) if x.is_finite() => {}
                        Ok(_) => error(
                            c,
                            format!("`{word}` is not allowed: numbers must be finite"),
                        ),
                        Err(_) => error(c, format!("invalid number `{word}`")),
                    }
                }
            }
            "f" | "l" => {
                let is_line = keyword == "l";
                let count = w.len() - 1;
                if !is_line && count < 3 {
                    error(
                        col,
                        format!("face has {count} vertices; at least 3 are needed"),
                    );
                    continue;
                }
                let mut ok = true;
                // The corners as tobj gets them: out-of-range texture
                // coordinate and normal references dropped.
                let mut corners: Vec<String> = Vec::with_capacity(count);
                for &(word, c) in &w[1..] {
                    match check_reference(word, &seen, &totals) {
                        Ok(bad) => {
                            for (k, tally) in scan.dropped.iter_mut().enumerate() {
                                if bad[k] {
                                    tally.add(at(c), || word.to_string());
                                }
                            }
                            corners.push(without_references(word, bad));
                        }
                        Err(message) => {
                            error(c, message);
                            ok = false;
                        }
                    }
                }
                if ok && corners.iter().zip(&w[1..]).any(|(a, b)| a != b.0) {
                    scan.repairs
                        .push((number, format!("{keyword} {}", corners.join(" "))));
                }
                if ok && count >= 3 {
                    let normals = if is_line {
                        Vec::new()
                    } else {
                        corners
                            .iter()
                            .filter_map(|word| corner_normal(word, &seen))
                            .collect()
                    };
                    scan.faces.push(FaceLine {
                        pos: at(col),
                        is_line,
                        names: scan.names.current(),
                        smoothing: smoothing.map(|s| (object, s)),
                        normals,
                        smooth: None,
                    });
                }
            }
            "usemtl" => {
                // tobj takes everything after the first space, trimmed.
                let name = line.split_once(' ').map_or("", |x| x.1.trim());
                if name.is_empty() {
                    error(col, "`usemtl` needs a material name".into());
                } else {
                    scan.usemtls.push(Named {
                        name: name.to_string(),
                        pos: at(col),
                    });
                }
            }
            "o" | "g" => {
                if keyword == "o" {
                    object += 1;
                }
                scan.names
                    .statement(keyword, &line.trim_start()[keyword.len()..])
            }
            // `s off` and `s 0` end smoothing; any other number (or
            // name) starts or continues that group.
            "s" => {
                smoothing = match w.get(1).map(|x| x.0) {
                    None | Some("off") | Some("0") => None,
                    Some(word) => Some(word.parse::<u64>().unwrap_or_else(|_| {
                        // A non-numeric group name: a stable number for it.
                        use std::hash::{Hash, Hasher};
                        let mut h = std::collections::hash_map::DefaultHasher::new();
                        word.hash(&mut h);
                        h.finish()
                    })),
                }
            }
            "mtllib" => {
                if line.split_once(' ').map_or("", |x| x.1.trim()).is_empty() {
                    error(col, "`mtllib` needs a file name".into());
                } else {
                    scan.mtllibs.push(MtlLib {
                        line: number,
                        pos: at(col),
                    });
                }
            }
            _ => {}
        }
    }
    scan
}

/// The `(position, normal)` file indices (1-based, negative ones resolved
/// against `seen`) of a checked face corner `v//vn` or `v/vt/vn`; `None`
/// for a corner without a normal.
fn corner_normal(word: &str, seen: &[usize; 3]) -> Option<(u64, u64)> {
    let mut parts = word.split('/');
    let v = parts.next()?;
    let n = parts.nth(1)?;
    let resolve = |part: &str, kind: usize| -> Option<u64> {
        let i = part.parse::<i64>().ok()?;
        if i > 0 {
            Some(i as u64)
        } else {
            (seen[kind] as u64 + 1).checked_sub(i.unsigned_abs())
        }
    };
    Some((resolve(v, 0)?, resolve(n, 2)?))
}

/// Gives each face its smooth surface (union-find over faces): faces of
/// one smoothing group (`s N` within one `o` object) are one surface, and
/// so are faces with a corner of the same position and the same normal
/// (`f a//n`; Blender writes one shared `vn` per vertex of a face shaded
/// smooth, and its own `vn` per flat face). A face with neither stays
/// faceted (`None`). Surfaces are numbered from 0 in order of their first
/// face.
fn smooth_surfaces(faces: &mut [FaceLine]) {
    let n = faces.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut joined = vec![false; n];
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut union = |parent: &mut Vec<usize>, a: usize, b: usize| {
        joined[a] = true;
        joined[b] = true;
        let (ra, rb) = (find(parent, a), find(parent, b));
        parent[ra.max(rb)] = ra.min(rb);
    };
    let mut first_in_group: HashMap<(u32, u64), usize> = HashMap::new();
    let mut first_with_corner: HashMap<(u64, u64), usize> = HashMap::new();
    for (i, face) in faces.iter().enumerate() {
        if face.is_line {
            continue;
        }
        if let Some(g) = face.smoothing {
            let first = *first_in_group.entry(g).or_insert(i);
            union(&mut parent, first, i);
        }
        for &corner in &face.normals {
            let first = *first_with_corner.entry(corner).or_insert(i);
            if first != i {
                union(&mut parent, first, i);
            }
        }
    }
    let mut ids: HashMap<usize, u32> = HashMap::new();
    for i in 0..n {
        if joined[i] {
            let r = find(&mut parent, i);
            let next = ids.len() as u32;
            faces[i].smooth = Some(*ids.entry(r).or_insert(next));
        }
    }
}

/// Checks one face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` against the
/// counts of vertices, texture coordinates and normals (`seen` so far for
/// negative indices, `totals` in the file for positive ones).
///
/// A malformed corner or a vertex index out of range is an error. A
/// texture coordinate or normal index out of range is not: texture
/// coordinates are never used and normals only join smooth surfaces, so
/// the corner has one sensible reading without them (exporters and hand
/// edits leave such indices behind). The result says which of the two
/// (`[texture coordinate, normal]`) must be dropped.
fn check_reference(
    word: &str,
    seen: &[usize; 3],
    totals: &[usize; 3],
) -> Result<[bool; 2], String> {
    let mut dropped = [false; 2];
    const WHAT: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    const PLURAL: [&str; 3] = ["vertices", "texture coordinates", "normals"];
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(format!(
            "invalid face vertex `{word}`: expected v, v/vt, v//vn or v/vt/vn"
        ));
    }
    for (k, part) in parts.iter().enumerate() {
        if part.is_empty() {
            continue;
        }
        let Ok(i) = part.parse::<i64>() else {
            return Err(format!(
                "invalid face vertex `{word}`: `{part}` is not a whole number"
            ));
        };
        let ok = match i {
            0 => false,
            i if i > 0 => i as u64 <= totals[k] as u64,
            i => i.unsigned_abs() <= seen[k] as u64,
        };
        if !ok && k > 0 {
            dropped[k - 1] = true;
        } else if !ok {
            return Err(format!(
                "{} index {i} in `{word}` is out of range: {} {} {}",
                WHAT[k],
                if i < 0 { seen[k] } else { totals[k] },
                PLURAL[k],
                if i < 0 {
                    "are defined above this line"
                } else {
                    "are defined in the file (indices count from 1)"
                }
            ));
        }
    }
    Ok(dropped)
}

/// The corner `word` (checked by [`check_reference`]) without its texture
/// coordinate (`drop[0]`) or normal (`drop[1]`) reference: `7/9/2` becomes
/// `7//2`, `7/2` or `7`.
fn without_references(word: &str, drop: [bool; 2]) -> String {
    if drop == [false, false] {
        return word.to_string();
    }
    let mut parts = word.split('/');
    let v = parts.next().unwrap_or_default();
    let vt = parts.next().filter(|p| !p.is_empty() && !drop[0]);
    let vn = parts.next().filter(|p| !p.is_empty() && !drop[1]);
    match (vt, vn) {
        (None, None) => v.to_string(),
        (Some(t), None) => format!("{v}/{t}"),
        (None, Some(n)) => format!("{v}//{n}"),
        (Some(t), Some(n)) => format!("{v}/{t}/{n}"),
    }
}

/// `text` with the lines the scan rewrote ([`Scan::repairs`], in line
/// order) put in place; every line keeps its number.
fn repaired_text(text: &str, repairs: &[(u32, String)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut next = repairs.iter().peekable();
    for (i, line) in text.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        match next.peek() {
            Some((number, repaired)) if *number as usize == i + 1 => {
                out.push_str(repaired);
                if line.ends_with('\r') {
                    out.push('\r');
                }
                next.next();
            }
            _ => out.push_str(line),
        }
    }
    out
}

/// The 1-based number of the line that ends at byte `pos` (the last line
/// read when a reader has consumed `pos` bytes).
fn line_at(text: &str, pos: usize) -> u32 {
    let end = pos.min(text.len()).saturating_sub(1);
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count() as u32
        + 1
}

/// The column of the first word of line `line`, or 1.
fn first_word_col(text: &str, line: u32) -> u32 {
    lines(text)
        .find(|(n, _)| *n == line)
        .and_then(|(_, l)| words(l).first().map(|w| w.1))
        .unwrap_or(1)
}

/// A `BufRead` over the text that records how many bytes were consumed.
struct CountingReader<'a> {
    bytes: &'a [u8],
    pos: Rc<Cell<usize>>,
}

impl Read for CountingReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let rest = self.fill_buf()?;
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for CountingReader<'_> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        Ok(&self.bytes[self.pos.get().min(self.bytes.len())..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos.set((self.pos.get() + amt).min(self.bytes.len()));
    }
}

// -------------------------------------------------------------- mtl --

/// One material library as read.
struct Library {
    file: String,
    /// The OBJ line of the `mtllib` that loaded it.
    loaded_at: u32,
    materials: Vec<MtlMaterial>,
    diags: Vec<Diagnostic>,
    warnings: Vec<Warning>,
    /// `map_Kd` paths written with `\`: how many, and the first.
    backslashes: Tally,
}

/// One `newmtl` block: the values that matter here, with positions.
struct MtlMaterial {
    name: String,
    file: String,
    pos: SourcePos,
    /// `Kd` as used (clamped below one), `None` when the block has none.
    kd: Option<Rgb>,
    ke: Rgb,
    /// The `map_Kd` file (with `/` for `\`) and where it is named.
    map_kd: Option<(String, SourcePos)>,
    /// The average linear colour of the `map_Kd` texture, once read.
    texture: Option<Rgb>,
    /// Statements asking for more than diffuse reflection, as written
    /// (`Ks 0.5`, `illum 7`, ...).
    non_diffuse: Vec<String>,
    /// `illum` and `Ni` are only known together at the end of the block.
    illum: Option<i64>,
    ni: Option<f64>,
}

impl MtlMaterial {
    /// The diffuse reflectance used: `Kd` (or [`DEFAULT_REFLECTANCE`]),
    /// times the average of the `map_Kd` texture when it was read.
    fn reflectance(&self) -> Rgb {
        let kd = self.kd.unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
        match self.texture {
            Some(t) => kd * t,
            None => kd,
        }
    }

    /// The scene material: see the module docs for the mapping.
    fn to_material(&self) -> Material {
        let kd = self.reflectance();
        let (color, k_diffrefl, k_emission) = if self.ke.is_black() {
            (kd, 1.0, 0.0)
        } else if kd.is_black() {
            (self.ke, 0.0, 1.0)
        } else {
            let lum = |c: Rgb| c.luminance().max(f64::MIN_POSITIVE);
            let k = lum(kd) / lum(self.ke);
            // Below one in every channel, like Kd itself.
            let k = k.min(kd.max_channel() / self.ke.max_channel());
            (self.ke, k, 1.0)
        };
        Material {
            name: self.name.clone(),
            color,
            k_diffrefl,
            k_emission,
        }
    }

    /// Notes what the block's `illum` and `Ni` ask for, once it is read.
    fn finish(&mut self) {
        if let Some(illum) = self.illum.filter(|i| (3..=9).contains(i)) {
            self.non_diffuse.push(format!("illum {illum}"));
            if let Some(ni) = self.ni.filter(|_| matches!(illum, 4 | 6 | 7)) {
                self.non_diffuse.push(format!("Ni {}", fmt_num(ni)));
            }
        }
    }
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

/// The first number after the keyword, if it is one (MTL statements this
/// module only warns about are never errors).
fn number(w: &[(&str, u32)]) -> Option<f64> {
    w.get(1)
        .and_then(|(x, _)| x.parse::<f64>().ok())
        .filter(|x| x.is_finite())
}

/// The file named by a `map_Kd` line: the rest of the line after the
/// options (`-s 1 1 1`, `-bm 0.5`, ...), so names with spaces are kept.
fn map_file<'a>(line: &'a str, w: &[(&'a str, u32)]) -> Option<&'a str> {
    let mut i = 1;
    while let Some(&(word, _)) = w.get(i) {
        let args = match word {
            "-o" | "-s" | "-t" => 3,
            "-mm" => 2,
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan"
            | "-texres" | "-type" => 1,
            _ => break,
        };
        i += 1;
        // `-o`, `-s` and `-t` take one to three numbers.
        for _ in 0..args {
            match w.get(i) {
                Some((x, _)) if args < 3 || x.parse::<f64>().is_ok() => i += 1,
                _ => break,
            }
        }
    }
    let &(_, col) = w.get(i)?;
    let start = line.char_indices().nth(col as usize - 1)?.0;
    Some(line[start..].trim())
}

/// Reads an MTL library: `newmtl`, `Kd`, `Ke` and `map_Kd`, and notes the
/// statements of non-diffuse materials (see the module docs). `loaded_at`
/// is the OBJ line that names it.
fn parse_mtl(text: &str, file: &str, loaded_at: u32) -> Library {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lib = Library {
        file: file.to_string(),
        loaded_at,
        materials: Vec::new(),
        diags: Vec::new(),
        warnings: Vec::new(),
        backslashes: Tally::default(),
    };
    for (number_, line) in lines(text) {
        let w = words(line);
        let Some(&(keyword, col)) = w.first() else {
            continue;
        };
        let at = |col: u32| SourcePos { line: number_, col };
        if keyword == "newmtl" {
            // As tobj reads it: everything after the keyword, trimmed.
            let name = line.trim_start()["newmtl".len()..].trim();
            if name.is_empty() {
                lib.diags.push(Diagnostic::new(
                    file,
                    at(col),
                    "`newmtl` needs a material name",
                ));
                continue;
            }
            if let Some(m) = lib.materials.last_mut() {
                m.finish();
            }
            lib.materials.push(MtlMaterial {
                name: name.to_string(),
                file: file.to_string(),
                pos: at(col),
                kd: None,
                ke: Rgb::BLACK,
                map_kd: None,
                texture: None,
                non_diffuse: Vec::new(),
                illum: None,
                ni: None,
            });
            continue;
        }
        let Some(m) = lib.materials.last_mut() else {
            if matches!(keyword, "Kd" | "Ke") {
                lib.diags.push(Diagnostic::new(
                    file,
                    at(col),
                    format!("`{keyword}` before any `newmtl`"),
                ));
            }
            continue;
        };
        match keyword {
            "Kd" | "Ke" => match color(&w) {
                Err((c, message)) => lib.diags.push(Diagnostic::new(file, at(c), message)),
                Ok(rgb) if keyword == "Ke" => m.ke = rgb,
                Ok(rgb) if rgb.max_channel() >= 1.0 => {
                    // Same hue, brightest channel at the cap.
                    let clamped = rgb * (MAX_MTL_REFLECTANCE / rgb.max_channel());
                    let show = |c: Rgb| c.to_array().map(fmt_num).join(" ");
                    lib.warnings.push(Warning::at(
                        file,
                        at(col),
                        format!(
                            "material `{}`: `Kd {}` reflects all light or more; scaled to {} (brightest channel {})",
                            m.name,
                            show(rgb),
                            show(clamped),
                            fmt_num(MAX_MTL_REFLECTANCE)
                        ),
                    ));
                    m.kd = Some(clamped);
                }
                Ok(rgb) => m.kd = Some(rgb),
            },
            "map_Kd" => {
                if let Some(name) = map_file(line, &w).filter(|n| !n.is_empty()) {
                    let path = if name.contains('\\') {
                        lib.backslashes.add(at(col), || name.to_string());
                        name.replace('\\', "/")
                    } else {
                        name.to_string()
                    };
                    m.map_kd = Some((path, at(col)));
                }
            }
            "Ks" => {
                if let Ok(ks) = color(&w) {
                    if ks.max_channel() > DIFFUSE_SHEEN_LIMIT {
                        m.non_diffuse
                            .push(format!("Ks {}", fmt_num(ks.max_channel())));
                    }
                }
            }
            "illum" => m.illum = w.get(1).and_then(|(x, _)| x.parse().ok()),
            "Ni" => m.ni = number(&w),
            "d" => {
                if let Some(d) = number(&w).filter(|&d| d < 1.0) {
                    m.non_diffuse.push(format!("d {}", fmt_num(d)));
                }
            }
            "Tr" => {
                if let Some(tr) = number(&w).filter(|&t| t > 0.0) {
                    m.non_diffuse.push(format!("Tr {}", fmt_num(tr)));
                }
            }
            "Pm" => {
                if let Some(pm) = number(&w).filter(|&p| p > 0.0) {
                    m.non_diffuse.push(format!("Pm {}", fmt_num(pm)));
                }
            }
            "Pr" => {
                if let Some(pr) = number(&w).filter(|&p| p < DIFFUSE_SHEEN_LIMIT) {
                    m.non_diffuse.push(format!("Pr {}", fmt_num(pr)));
                }
            }
            _ => {}
        }
    }
    if let Some(m) = lib.materials.last_mut() {
        m.finish();
    }
    let no_kd: Vec<String> = lib
        .materials
        .iter()
        .filter(|m| m.kd.is_none())
        .map(|m| m.name.clone())
        .collect();
    if !no_kd.is_empty() {
        lib.warnings.push(Warning::file(
            file,
            format!(
                "no `Kd` in {}: reflectance {} (the default)",
                name_list(&no_kd),
                fmt_num(DEFAULT_REFLECTANCE)
            ),
        ));
    }
    let shiny: Vec<String> = lib
        .materials
        .iter()
        .filter(|m| !m.non_diffuse.is_empty())
        .map(|m| format!("{} ({})", m.name, m.non_diffuse.join(", ")))
        .collect();
    if !shiny.is_empty() {
        lib.warnings.push(Warning::file(
            file,
            format!("treated as diffuse: {}", name_list(&shiny)),
        ));
    }
    lib
}

/// Reads each `map_Kd` texture of `lib` (relative to the library's folder)
/// and records its average colour; one warning for those that cannot be
/// read (they keep their `Kd`), one for paths written with `\`.
fn read_textures(lib: &mut Library) {
    let dir = Path::new(&lib.file)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut failed = Tally::default();
    for m in &mut lib.materials {
        let Some((name, pos)) = &m.map_kd else {
            continue;
        };
        let path = dir.join(name);
        match average_texture(&path) {
            Ok(rgb) => m.texture = Some(rgb),
            Err(e) => failed.add(*pos, || {
                format!("{} (material `{}`): {e}", path.display(), m.name)
            }),
        }
    }
    if let Some((pos, first)) = failed.first {
        lib.warnings.push(Warning::at(
            &lib.file,
            pos,
            format!(
                "cannot read {} `map_Kd` texture(s), first {first}; their materials keep `Kd`",
                failed.count
            ),
        ));
    }
    if let Some((pos, first)) = lib.backslashes.first.take() {
        lib.warnings.push(Warning::at(
            &lib.file,
            pos,
            format!(
                "{} `map_Kd` path(s) written with `\\` (first `{first}`), read with `/`",
                lib.backslashes.count
            ),
        ));
    }
}

/// The average colour of the image at `path`, in linear values (8- and
/// 16-bit images are sRGB-decoded first; float images are linear
/// already), alpha ignored. Each channel is in `[0, 1]`.
pub(crate) fn average_texture(path: &Path) -> Result<Rgb, String> {
    let image = image::open(path).map_err(|e| e.to_string())?;
    average_image(&image)
}

/// The average colour of `image`, as [`average_texture`] says.
pub(super) fn average_image(image: &image::DynamicImage) -> Result<Rgb, String> {
    let linear = matches!(
        image,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let pixels = image.to_rgb32f();
    let n = u64::from(pixels.width()) * u64::from(pixels.height());
    if n == 0 {
        return Err("the image has no pixels".to_string());
    }
    let mut sum = [0.0f64; 3];
    for p in pixels.pixels() {
        for (s, &c) in sum.iter_mut().zip(&p.0) {
            let c = f64::from(c).clamp(0.0, 1.0);
            *s += if linear { c } else { srgb_to_linear(c) };
        }
    }
    let [r, g, b] = sum.map(|s| s / n as f64);
    Ok(Rgb::new(r, g, b))
}

/// The sRGB transfer function undone: an encoded value in `[0, 1]` to
/// linear light in `[0, 1]` (IEC 61966-2-1).
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The colour of a `Kd`/`Ke` line: `r g b`, or one value for grey (as the
/// MTL format allows). Each finite and `>= 0`. Errors carry the column.
fn color(w: &[(&str, u32)]) -> Result<Rgb, (u32, String)> {
    let (keyword, col) = w[0];
    let values = &w[1..];
    if let Some(&(word, c)) = values
        .first()
        .filter(|(x, _)| *x == "spectral" || *x == "xyz")
    {
        return Err((
            c,
            format!("`{keyword} {word}` is not supported: give r g b values"),
        ));
    }
    if values.len() != 1 && values.len() != 3 {
        return Err((
            col,
            format!(
                "`{keyword}` takes 3 numbers (r g b) or 1 (grey), found {}",
                values.len()
            ),
        ));
    }
    let mut out = [0.0f64; 3];
    for (slot, &(word, c)) in out.iter_mut().zip(values) {
        let x = match word.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            Ok(_) => {
                return Err((
                    c,
                    format!("`{word}` is not allowed: numbers must be finite"),
                ))
            }
            Err(_) => return Err((c, format!("invalid number `{word}`"))),
        };
        if x < 0.0 {
            return Err((c, negative_channel(keyword, word)));
        }
        *slot = x;
    }
    if values.len() == 1 {
        out = [out[0]; 3];
    }
    Ok(Rgb::new(out[0], out[1], out[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Shape;

    const MTL: &str = "\
# two materials
newmtl white
Kd 0.5 0.5 0.5
Ks 0.8 0.8 0.8
newmtl lamp
Kd 0 0 0
Ke 10 8 6
newmtl grey
Kd 0.25
";

    /// Parses `obj` with `lib.mtl` = [`MTL`] and nothing else readable.
    fn parse(obj: &str) -> Result<Scene, LoadError> {
        parse_with(obj, MTL)
    }

    fn parse_with(obj: &str, mtl: &str) -> Result<Scene, LoadError> {
        let read = |name: &str| match name {
            "lib.mtl" => Ok(("lib.mtl".to_string(), mtl.to_string())),
            other => Err(format!("cannot read material library {other}: not found")),
        };
        parse_obj(obj, "m.obj", &read)
    }

    fn messages(e: &LoadError) -> Vec<String> {
        e.diagnostics.iter().map(|d| d.to_string()).collect()
    }

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    #[test]
    fn quads_stay_quads_and_materials_map() {
        let obj =
            format!("mtllib lib.mtl\n{SQUARE}usemtl white\nf 1 2 3 4\nusemtl lamp\nf -4 -2 -1\n");
        let s = parse(&obj).unwrap();
        assert_eq!(s.polygons.len(), 2);
        assert_eq!(s.polygons[0].shape, Shape::Parallelogram);
        assert_eq!(s.polygons[0].vertices.len(), 4);
        assert_eq!(s.polygons[0].origin, SourcePos { line: 7, col: 1 });
        assert_eq!(
            s.polygons[1].vertices,
            vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]
        );
        assert_eq!(s.polygons[1].origin.line, 9);
        let white = s.material_of(crate::scene::PolygonId(0));
        assert_eq!(white.name, "white");
        assert_eq!(white.reflectance(), Rgb::splat(0.5));
        assert_eq!(white.emission(), Rgb::BLACK);
        let lamp = s.material_of(crate::scene::PolygonId(1));
        assert_eq!(lamp.emission(), Rgb::new(10.0, 8.0, 6.0));
        assert_eq!(lamp.reflectance(), Rgb::BLACK);
        // `Kd 0.25` is grey; unused materials are kept, in library order.
        assert_eq!(s.materials[2].reflectance(), Rgb::splat(0.25));
        assert_eq!(s.materials.len(), 3);
        // Facing +z (counter-clockwise seen from +z); auto-framed.
        assert_eq!(s.polygons[0].normal, Vec3::Z);
        assert_eq!(s.camera_source, CameraSource::AutoFramed);
    }

    #[test]
    fn faces_without_usemtl_get_the_default_material() {
        let s = parse(&format!(
            "{SQUARE}f 1/1/1 2//2 3/3 4\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 1\n"
        ))
        .unwrap();
        assert_eq!(s.materials.len(), 1);
        assert_eq!(s.materials[0].name, DEFAULT_MATERIAL_NAME);
        assert_eq!(
            s.materials[0].reflectance(),
            Rgb::splat(DEFAULT_REFLECTANCE)
        );
    }

    #[test]
    fn non_planar_and_non_convex_faces_are_triangulated() {
        // A quad folded along its diagonal: two triangles.
        let s = parse("v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(s.polygons.len(), 2);
        assert!(s
            .polygons
            .iter()
            .all(|p| p.shape == Shape::Triangle && p.normal.z > 0.0));
        let area: f64 = s.polygons.iter().map(|p| p.area).sum();
        assert!(area > 1.0 && area < 1.2, "{area}");
        // An L-shaped hexagon (area 3): four triangles covering it exactly.
        let l = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n";
        let s = parse(l).unwrap();
        assert_eq!(s.polygons.len(), 4);
        let area: f64 = s.polygons.iter().map(|p| p.area).sum();
        assert!((area - 3.0).abs() < 1e-6, "{area}");
        assert!(s
            .polygons
            .iter()
            .all(|p| (p.normal - Vec3::Z).length() < 1e-6));
        // A pentagon with a straight corner is a valid convex polygon.
        let s = parse("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4 5\n").unwrap();
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(s.polygons[0].shape, Shape::Convex);
        // A quad with a repeated vertex keeps its one real triangle.
        let s = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2 3\n").unwrap();
        assert_eq!(s.polygons.len(), 1);
        assert!((s.polygons[0].area - 0.5).abs() < 1e-9);
    }

    /// The warnings of a scene, as printed.
    fn warning_lines(s: &Scene) -> Vec<String> {
        s.warnings.iter().map(|w| w.to_string()).collect()
    }

    #[test]
    fn degenerate_faces_are_dropped_with_one_summary_warning() {
        // As 3ds Max writes them at UV seams: zero-area slivers and
        // repeated indices, between real faces; CRLF line ends.
        let obj = "# 3ds Max Wavefront OBJ Exporter v0.97b\r\n\
                   v 0 0 0\r\nv 1 0 0\r\nv 2 0 0\r\nv 0 1 0\r\n\
                   vt 0 0\r\nvn 0 0 1\r\ng Box001\r\ns 1\r\n\
                   f 1/1/1 2/1/1 3/1/1\r\nf 1 2 4\r\n  f 1 1 2 2\r\nf 2 2 4\r\nf 1 2 3\r\n";
        let s = parse(obj).unwrap();
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(s.polygons[0].origin.line, 11);
        assert_eq!(
            warning_lines(&s),
            vec![
                "m.obj:10:1: warning: dropped 4 degenerate face(s) (no area, or a vertex \
                 repeated); the first here: polygon has zero area"
            ]
        );
        // Syntax stays an error; a file with nothing left has no faces.
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n").unwrap_err();
        assert_eq!(
            messages(&e),
            vec!["m.obj:5:1: error: face has 2 vertices; at least 3 are needed"]
        );
        let e = parse("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            messages(&e),
            vec!["m.obj:1:1: error: OBJ file has no faces"]
        );
    }

    #[test]
    fn bad_numbers_and_indices_are_errors_with_columns() {
        let obj = "v 0 0 0\nv 1 0 x\nv 1 1\nv 0 1 nan\nf 1 2 5\nf 1 -5 2\nf 1 0 2\nf 1/7 2 3\nf 1//x 2 3\n";
        let e = parse(obj).unwrap_err();
        assert_eq!(
            messages(&e),
            vec![
                "m.obj:2:7: error: invalid number `x`",
                "m.obj:3:1: error: `v` needs at least 3 numbers, found 2",
                "m.obj:4:7: error: `nan` is not allowed: numbers must be finite",
                "m.obj:5:7: error: vertex index 5 in `5` is out of range: 4 vertices are defined in the file (indices count from 1)",
                "m.obj:6:5: error: vertex index -5 in `-5` is out of range: 4 vertices are defined above this line",
                "m.obj:7:5: error: vertex index 0 in `0` is out of range: 4 vertices are defined in the file (indices count from 1)",
                "m.obj:9:3: error: invalid face vertex `1//x`: `x` is not a whole number",
            ]
        );
    }

    #[test]
    fn texture_coordinates_and_normals_that_do_not_exist_are_dropped_with_a_warning() {
        // As three.js's verify.obj: four `vt`, corners naming 7 to 10;
        // and a normal index past the two `vn`. CRLF line ends.
        let obj = "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nv 0 0 1\r\n\
                   vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\nvn 0 0 1\r\nvn 0 1 0\r\n\
                   f 1/7/1 2/8/1 3/9/1\r\n\
                   f 1/1/1   3/10/1 4/4/9\r\n\
                   f 1//2 2//2 5/3/2\r\n";
        let s = parse(obj).unwrap();
        assert_eq!(s.polygons.len(), 3, "every face loads");
        assert_eq!(
            warning_lines(&s),
            [
                "m.obj:12:3: warning: 4 face corner(s) name a texture coordinate that does not \
                 exist (first `1/7/1`); read without it (texture coordinates are not used)",
                "m.obj:13:18: warning: 1 face corner(s) name a normal that does not exist \
                 (first `4/4/9`); read without it (normals only join smooth surfaces)",
            ]
        );
        // The corners kept their valid normals: the first two faces share
        // `1//1` and `3//1`, one smooth surface; the third has its own.
        let ids: Vec<_> = s.polygons.iter().map(|p| p.surface.smooth).collect();
        assert_eq!(ids[0], ids[1]);
        assert!(ids[0].is_some() && ids[2] != ids[0], "{ids:?}");
        // A vertex that does not exist stays an error.
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 4/5\n").unwrap_err();
        assert_eq!(
            messages(&e),
            vec!["m.obj:5:11: error: vertex index 4 in `4/5` is out of range: 3 vertices are defined in the file (indices count from 1)"]
        );
    }

    #[test]
    fn without_references_keeps_what_exists() {
        assert_eq!(without_references("7/9/2", [true, false]), "7//2");
        assert_eq!(without_references("7/9/2", [false, true]), "7/9");
        assert_eq!(without_references("7/9/2", [true, true]), "7");
        assert_eq!(without_references("7//2", [false, true]), "7");
        assert_eq!(without_references("-3/-1", [true, false]), "-3");
        assert_eq!(without_references("5", [false, false]), "5");
    }

    #[test]
    fn errors_the_reader_finds_are_placed_on_their_line() {
        // Five numbers on a `v` line: neither w nor a colour.
        let e = parse(&format!("{SQUARE}\n  v 1 2 3 4 5\nf 1 2 3\n")).unwrap_err();
        let m = messages(&e);
        assert_eq!(m.len(), 1, "{m:?}");
        assert!(
            m[0].starts_with("m.obj:6:3: error: cannot read OBJ: "),
            "{m:?}"
        );
    }

    #[test]
    fn material_problems_name_the_mtl_file() {
        // `Kd` 1 and an undefined material are warnings now (see the
        // tests below); these stay errors.
        let mtl =
            "newmtl a\nKd 0.5 1.0 0.2\nnewmtl b\nKe 1 -2 3\nKd 1 2\nnewmtl a\nKd spectral x.spd\n";
        let obj = format!("mtllib lib.mtl\n{SQUARE}usemtl a\nf 1 2 3\nusemtl nope\nf 1 3 4\n");
        let e = parse_with(&obj, mtl).unwrap_err();
        assert_eq!(
            messages(&e),
            vec![
                "lib.mtl:4:6: error: `Ke` channel -2 is negative; channels must be >= 0",
                "lib.mtl:5:1: error: `Kd` takes 3 numbers (r g b) or 1 (grey), found 2",
                "lib.mtl:6:1: error: material `a` is already defined in lib.mtl at 1:1",
                "lib.mtl:7:4: error: `Kd spectral` is not supported: give r g b values",
            ]
        );
        // A material used before its library.
        let obj = format!("usemtl white\nmtllib lib.mtl\n{SQUARE}f 1 2 3\n");
        let e = parse(&obj).unwrap_err();
        assert_eq!(
            messages(&e),
            vec![
                "m.obj:1:1: error: material `white` is used before the `mtllib` that defines it (line 2)",
            ]
        );
    }

    #[test]
    fn emitters_that_also_reflect_keep_ke_and_the_luminance_of_kd() {
        let mtl = "newmtl glow\nKd 0.5 0.5 0.5\nKe 4 2 2\n";
        let s = parse_with(
            &format!("mtllib lib.mtl\nusemtl glow\n{SQUARE}f 1 2 3\n"),
            mtl,
        )
        .unwrap();
        let m = &s.materials[0];
        assert_eq!(m.emission(), Rgb::new(4.0, 2.0, 2.0));
        let rho = m.reflectance();
        assert!((rho.luminance() - 0.5).abs() < 1e-9 || rho.max_channel() <= 0.5 + 1e-12);
        assert!(rho.max_channel() < 1.0);
        assert!((rho.r / rho.g - 2.0).abs() < 1e-9, "{rho:?}");
    }

    #[test]
    fn polylines_and_points_are_not_faces() {
        let s = parse(&format!("{SQUARE}l 1 2 3 4\np 1\nl 1 2\nf 1 2 3\n")).unwrap();
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(s.polygons[0].origin.line, 8);
        let e = parse(&format!("{SQUARE}l 1 2 3\n")).unwrap_err();
        assert_eq!(
            messages(&e),
            vec!["m.obj:1:1: error: OBJ file has no faces"]
        );
    }

    #[test]
    fn load_obj_reads_libraries_next_to_the_file_and_a_sidecar_camera() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("lib.mtl"), MTL).unwrap();
        let obj = dir.path().join("m.obj");
        std::fs::write(
            &obj,
            format!("mtllib lib.mtl\nusemtl lamp\n{SQUARE}f 1 2 3 4\n"),
        )
        .unwrap();
        let cam = dir.path().join("cam.sc");
        std::fs::write(
            &cam,
            "camera eye 0.5 0.5 3 lookat 0.5 0.5 0 size 32 24 end\n",
        )
        .unwrap();
        let s = load_obj(&obj, Some(&cam)).unwrap();
        assert_eq!(s.camera_source, CameraSource::File);
        assert_eq!((s.camera.width, s.camera.height), (32, 24));
        assert_eq!(s.materials[s.polygons[0].material.index()].name, "lamp");
        // The dispatch by extension, and the camera override for .sc too.
        assert_eq!(crate::scene::load(&obj).unwrap().polygons, s.polygons);
        let missing = dir.path().join("none.obj");
        let e = load_obj(&missing, None).unwrap_err();
        assert!(
            messages(&e)[0].contains("none.obj:1:1: error: cannot read file"),
            "{e}"
        );
        let e = load_obj(&obj, Some(&dir.path().join("nocam.sc"))).unwrap_err();
        assert!(
            messages(&e)[0].contains("nocam.sc:1:1: error: cannot read file"),
            "{e}"
        );
    }

    /// A Blender 2.93 export: header, object, normals, texture
    /// coordinates, smoothing off, and the material it writes.
    const BLENDER_OBJ: &str = "# Blender v2.93.0 OBJ File: ''\n# www.blender.org\n\
        mtllib lib.mtl\no Plane\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n";

    /// A `newmtl` block as Blender writes it, with `extra` lines after `Kd`.
    fn blender_block(name: &str, kd: &str, extra: &str) -> String {
        format!(
            "newmtl {name}\nNs 225.000000\nKa 1.000000 1.000000 1.000000\n{kd}\
             {extra}Ke 0.000000 0.000000 0.000000\nNi 1.450000\nd 1.000000\nillum 1\n"
        )
    }

    #[test]
    fn kd_at_or_above_one_is_scaled_below_one_with_one_warning_per_material() {
        let mtl = format!(
            "# Blender MTL File: 'None'\n# Material Count: 3\n\n{}\n{}\n{}",
            blender_block("white", "Kd 1.000000 1.000000 1.000000\n", ""),
            blender_block("orange", "Kd 1.2 0.6 0.3\n", ""),
            blender_block("grey", "Kd 0.5 0.5 0.5\n", ""),
        );
        let obj = format!("{BLENDER_OBJ}usemtl white\ns off\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
        let s = parse_with(&obj, &mtl).unwrap();
        assert_eq!(
            s.materials[0].reflectance(),
            Rgb::splat(MAX_MTL_REFLECTANCE)
        );
        let orange = s.materials[1].reflectance();
        assert!((orange.r - MAX_MTL_REFLECTANCE).abs() < 1e-12);
        assert!((orange.g - MAX_MTL_REFLECTANCE / 2.0).abs() < 1e-12);
        assert!((orange.b - MAX_MTL_REFLECTANCE / 4.0).abs() < 1e-12);
        assert_eq!(s.materials[2].reflectance(), Rgb::splat(0.5));
        assert_eq!(
            warning_lines(&s),
            vec![
                "lib.mtl:7:1: warning: material `white`: `Kd 1 1 1` reflects all light or more; scaled to 0.95 0.95 0.95 (brightest channel 0.95)",
                "lib.mtl:16:1: warning: material `orange`: `Kd 1.2 0.6 0.3` reflects all light or more; scaled to 0.95 0.475 0.237 (brightest channel 0.95)",
            ]
        );
    }

    #[test]
    fn a_material_without_kd_gets_the_default_reflectance_with_a_warning() {
        let mtl = "newmtl bare\nNs 10\nnewmtl lamp\nKe 5 5 5\nnewmtl red\nKd 0.6 0.1 0.1\n";
        let obj = format!("{BLENDER_OBJ}usemtl bare\nf 1 2 3\nusemtl red\nf 1 3 4\n");
        let s = parse_with(&obj, mtl).unwrap();
        assert_eq!(
            s.material_of(crate::scene::PolygonId(0)).reflectance(),
            Rgb::splat(DEFAULT_REFLECTANCE)
        );
        assert_eq!(
            s.material_of(crate::scene::PolygonId(1)).reflectance(),
            Rgb::new(0.6, 0.1, 0.1)
        );
        assert_eq!(
            warning_lines(&s),
            vec!["lib.mtl: warning: no `Kd` in bare, lamp: reflectance 0.8 (the default)"]
        );
    }

    #[test]
    fn specular_glass_and_metal_are_treated_as_diffuse_in_one_warning_per_file() {
        let mtl = format!(
            "{}{}{}{}{}newmtl chrome\nKd 0.5 0.5 0.5\nPm 1.0\nPr 0.1\n",
            blender_block("matte", "Kd 0.5 0.5 0.5\n", "Ks 0 0 0\n"),
            blender_block("plastic", "Kd 0.5 0.5 0.5\n", "Ks 0.9 0.9 0.9\n"),
            blender_block("default", "Kd 0.5 0.5 0.5\n", "Ks 0.5 0.5 0.5\nPr 0.5\n"),
            "newmtl glass\nKd 0.1 0.1 0.1\nNi 1.5\nd 0.2\nillum 7\n",
            "newmtl tinted\nKd 0.2 0.2 0.2\nTr 0.4\n",
        );
        let obj = format!("{BLENDER_OBJ}usemtl glass\nf 1 2 3\n");
        let s = parse_with(&obj, &mtl).unwrap();
        assert_eq!(s.materials[3].reflectance(), Rgb::splat(0.1));
        assert_eq!(
            warning_lines(&s),
            vec![
                "lib.mtl: warning: treated as diffuse: plastic (Ks 0.9), glass (d 0.2, illum 7, \
                 Ni 1.5), tinted (Tr 0.4), chrome (Pm 1, Pr 0.1)"
            ]
        );
    }

    #[test]
    fn unreadable_libraries_and_undefined_materials_warn_and_use_the_default() {
        // CRLF; two names on one `mtllib` line, one missing; a `\` path.
        let read = |name: &str| match name {
            "lib.mtl" => Ok(("lib.mtl".to_string(), MTL.to_string())),
            "sub/more.mtl" => Ok((
                "sub/more.mtl".to_string(),
                "newmtl blue\r\nKd 0.1 0.1 0.7\r\n".to_string(),
            )),
            other => Err(format!("cannot read material library {other}: not found")),
        };
        let obj = "# Blender v2.93.0 OBJ File: ''\r\nmtllib lib.mtl gone.mtl\r\n\
                   mtllib sub\\more.mtl\r\no Plane\r\n\
                   v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n\
                   usemtl white\r\nf 1 2 3\r\nusemtl blue\r\nf 1 3 4\r\n\
                   usemtl nope\r\nf 1 2 4\r\nusemtl nope\r\nf 2 3 4\r\nusemtl gone_red\r\nf 1 4 2\r\n";
        let s = parse_obj(obj, "m.obj", &read).unwrap();
        let names: Vec<&str> = (0..5)
            .map(|i| {
                s.material_of(crate::scene::PolygonId(i as u32))
                    .name
                    .as_str()
            })
            .collect();
        assert_eq!(
            names,
            [
                "white",
                "blue",
                DEFAULT_MATERIAL_NAME,
                DEFAULT_MATERIAL_NAME,
                DEFAULT_MATERIAL_NAME
            ]
        );
        assert_eq!(
            s.material_of(crate::scene::PolygonId(1)).reflectance(),
            Rgb::new(0.1, 0.1, 0.7)
        );
        assert_eq!(
            warning_lines(&s),
            vec![
                "lib.mtl: warning: treated as diffuse: white (Ks 0.8)",
                "m.obj:2:1: warning: cannot read material library gone.mtl: not found; faces using its materials get the default material",
                "m.obj:3:1: warning: 1 `mtllib` path(s) written with `\\` (first `sub\\more.mtl`), read with `/`",
                "m.obj:13:1: warning: undefined material `nope` (2 `usemtl` line(s), the first here): no `mtllib` defines it; its faces get the default material",
                "m.obj:17:1: warning: undefined material `gone_red` (1 `usemtl` line(s), the first here): no `mtllib` defines it; its faces get the default material",
            ]
        );
    }

    #[test]
    fn many_undefined_materials_give_a_bounded_number_of_warnings() {
        let mut obj = SQUARE.to_string();
        for i in 0..MAX_UNDEFINED_WARNINGS + 5 {
            // A face of its own each time: repeated faces are dropped.
            obj.push_str(&format!("v 0 0 {}\nusemtl m{i}\nf 1 2 -1\n", i + 1));
        }
        let s = parse(&obj).unwrap();
        let w = warning_lines(&s);
        assert_eq!(w.len(), MAX_UNDEFINED_WARNINGS + 1);
        assert!(
            w[MAX_UNDEFINED_WARNINGS].ends_with(
                "warning: 5 more undefined materials (the first here): their faces get the default material"
            ),
            "{w:?}"
        );
    }

    #[test]
    fn map_kd_multiplies_kd_by_the_linear_average_of_the_texture() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("tex")).unwrap();
        // Half white, half black: linear average 0.5 (sRGB 188 would look
        // like it, but the average of encoded values would be 127.5/255).
        let mut img = image::RgbImage::new(2, 2);
        img.put_pixel(0, 0, image::Rgb([255, 255, 255]));
        img.put_pixel(1, 0, image::Rgb([255, 255, 255]));
        img.save(dir.path().join("tex/wall.png")).unwrap();
        // One sRGB grey of 188 everywhere: linear 0.5029.
        let grey = image::RgbImage::from_pixel(3, 1, image::Rgb([188, 188, 188]));
        grey.save(dir.path().join("grey.bmp")).unwrap();
        std::fs::write(
            dir.path().join("lib.mtl"),
            "newmtl wall\nKd 0.8 0.8 0.8\nmap_Kd -s 1 1 1 tex\\wall.png\n\
             newmtl floor\nKd 0.5 0.5 0.5\nmap_Kd grey.bmp\n\
             newmtl lost\nKd 0.3 0.3 0.3\nmap_Kd missing.jpg\n\
             newmtl lost2\nKd 0.3 0.3 0.3\nmap_Kd missing.tga\n",
        )
        .unwrap();
        let obj = dir.path().join("m.obj");
        std::fs::write(
            &obj,
            format!("mtllib lib.mtl\n{SQUARE}usemtl wall\nf 1 2 3 4\n"),
        )
        .unwrap();
        let s = load_obj(&obj, None).unwrap();
        let rho = |i: usize| s.materials[i].reflectance();
        assert!((rho(0).g - 0.4).abs() < 1e-6, "{:?}", rho(0));
        let srgb188 = srgb_to_linear(188.0 / 255.0);
        assert!((srgb188 - 0.5029).abs() < 1e-4);
        assert!((rho(1).r - 0.5 * srgb188).abs() < 1e-6, "{:?}", rho(1));
        assert_eq!(rho(2), Rgb::splat(0.3));
        let w = warning_lines(&s);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].ends_with(":9:1: warning: cannot read 2 `map_Kd` texture(s), first ")
                || w[0].contains(":9:1: warning: cannot read 2 `map_Kd` texture(s), first "),
            "{w:?}"
        );
        assert!(w[0].contains("missing.jpg (material `lost`)"), "{w:?}");
        assert!(w[0].ends_with("; their materials keep `Kd`"), "{w:?}");
        assert!(
            w[1].ends_with(
                ":3:1: warning: 1 `map_Kd` path(s) written with `\\` (first `tex\\wall.png`), read with `/`"
            ),
            "{w:?}"
        );
    }

    #[test]
    fn smoothing_groups_and_shared_normals_make_smooth_surfaces() {
        // Faces 7 to 12 stand apart from faces 1 to 6: a face that
        // repeated an earlier one would be dropped.
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
                   v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nv 0 0 3\nv 1 0 3\n\
                   vn 0 0 1\nvn 0 0 1\nvn 0 1 0\n\
                   o A\ns 1\nf 1 2 3\nf 1 3 4\n\
                   o B\ns 1\nf 1 2 6\ns off\n\
                   f 7//1 8//1 9//1\nf 7//1 9//1 10//1\nf 7//3 8//3 11//3\n\
                   f 7//2 8//2 12//2\ns 0\nf 9 10 12\n";
        let s = parse(obj).unwrap();
        let ids: Vec<Option<u32>> = s
            .polygons
            .iter()
            .map(|p| p.surface.smooth.map(|i| i.0))
            .collect();
        // `s 1` in A, `s 1` in B (another object: another surface), two
        // faces sharing `1//1` and `3//1`, then a face whose normals
        // nobody shares, one with a normal of its own, one with none.
        assert_eq!(
            ids,
            [
                Some(0),
                Some(0),
                Some(1),
                Some(2),
                Some(2),
                None,
                None,
                None
            ]
        );
    }
}
