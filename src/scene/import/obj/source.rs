//! The OBJ model as its file draws it, for writing it back with baked
//! light ([`crate::output::lightmap`]): the file's faces with what their
//! corners carry, and its materials' colours and textures, as a glTF model
//! ([`SourceModel`]).
//!
//! The faces are the ones the scene import reads ([`super::load_obj`]):
//! the same faces dropped, the same ones split into triangles, the same
//! material for each. Every face is kept whole, as the file has it: the
//! repair passes (cutting along intersections, back copies) change the
//! scene the solver lights, not the model. One primitive per material,
//! in one node. What the import ignores is kept here:
//!
//! - **Texture coordinates.** A corner's `vt` becomes its `TEXCOORD_0`
//!   with `v` flipped to `1 − v`: OBJ's texture origin is the image's
//!   bottom-left corner, glTF's its top-left. A vertex is one distinct
//!   (`v`, `vt`, `vn`) of the file, so a position with two texture
//!   coordinates is two vertices, as glTF needs. In a primitive where
//!   some corners have a `vt` and others none, those get (0, 0).
//! - **Normals.** A corner's `vn`, normalised, is its `NORMAL`; a corner
//!   without one (or with a zero `vn`) gets its face's flat normal.
//! - **Colours and textures.** `Kd` as written (scaled to a brightest
//!   channel of one when above it; 0.8, the import's default, when
//!   absent) is the `baseColorFactor`. The `map_Kd` texture, its path
//!   relative to the MTL's folder as for the import, is the
//!   `baseColorTexture`: a PNG or JPEG file's bytes copied as they are
//!   (glTF holds no other format), the media type taken from the bytes,
//!   read through the run's input rules (a regular file, its size checked
//!   before it is read) and never decoded (only its header is parsed).
//!   Of the `map_Kd` options, `-s` and `-o` are honoured by scaling and
//!   offsetting the texture coordinates of the material's primitive (the
//!   texture is sampled at `s × vt + o`, before the flip) and `-clamp on`
//!   by a clamping sampler; the others are ignored with a warning. A
//!   texture that cannot be read, is neither PNG nor JPEG, whose header
//!   does not parse, or that would take the embedded images past
//!   [`MAX_EMBEDDED_BYTES`] is left out with a warning naming the file and
//!   the material, which keeps its `Kd`.
//!
//! Warnings follow the import's rule: one line for a quirk found many
//! times, with a count and the first position.

use super::mtl::MtlMaterial;
use super::scan::{lines, repaired_text, scan_obj, words};
use super::{
    face_pieces, read_library, read_texture_file, read_with_tobj, Tally, DEFAULT_MATERIAL_NAME,
    DEFAULT_REFLECTANCE,
};
use crate::color::Rgb;
use crate::scene::error::cannot_read;
use crate::scene::import::gltf::source::{SourceImage, SourceModel, SourcePrimitive};
use crate::scene::import::input::{InputKind, InputSet, ModelFolder};
use crate::scene::repair::sides::face_key;
use crate::scene::{Diagnostic, LoadError, MaterialId, SourcePos, Warning};
use glam::Vec3;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// glTF sampler wrap mode `CLAMP_TO_EDGE`, for `-clamp on`.
const CLAMP_TO_EDGE: u32 = 33071;

/// The most bytes of texture files a model embeds, together: 1 GiB, far
/// above any real model's textures and a quarter of the most a `.glb`
/// can hold (its lengths are 32-bit), so the images held in memory and
/// the file written stay bounded however many textures an MTL names.
/// A texture that would go past it is left out, with the warning.
pub const MAX_EMBEDDED_BYTES: u64 = 1 << 30;

/// The model of an OBJ file and what reading it for the model said.
#[derive(Clone, Debug, Default)]
pub struct ObjSource {
    /// The faces, one primitive per material used, in the order of the
    /// materials' first use; one node named by the caller.
    pub model: SourceModel,
    /// Textures left out and `map_Kd` options ignored, one line each
    /// kind (see the module docs).
    pub warnings: Vec<Warning>,
}

/// Reads the OBJ file at `path` (and its libraries and textures, relative
/// to their folders) as an [`ObjSource`] whose primitives are named
/// `name`. The file has been loaded as a scene already, so errors are
/// unlikely; they read as the import's.
pub fn load_obj_source(path: &Path, inputs: &InputSet, name: &str) -> Result<ObjSource, LoadError> {
    let file = path.display().to_string();
    let bytes = inputs
        .read(path, InputKind::Scene)
        .map_err(|e| cannot_read(&file, &e))?;
    let text = String::from_utf8_lossy(&bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let folder = ModelFolder::of(path, inputs);
    let read_mtl = |name: &str| read_library(&folder, name);
    let read_texture = |path: &Path| read_texture_file(&folder, path);
    let scan = scan_obj(text, &file);
    if !scan.diags.is_empty() {
        return Err(LoadError::from_diagnostics(scan.diags));
    }
    let repaired;
    let text = if scan.repairs.is_empty() {
        text
    } else {
        repaired = repaired_text(text, &scan.repairs);
        repaired.as_str()
    };
    let reading = read_with_tobj(text, &file, &scan, &read_mtl);
    if !reading.mtl_diags.is_empty() {
        return Err(LoadError::from_diagnostics(reading.mtl_diags));
    }
    let models = reading
        .loaded
        .map_err(|e| Diagnostic::whole(&file, format!("cannot read OBJ: {e}")))?
        .0;
    let records: Vec<&MtlMaterial> = reading
        .libraries
        .iter()
        .flat_map(|l| &l.materials)
        .collect();
    let corners = Corners::of(text);
    let mut pieces: Vec<Piece> = Vec::new();
    let mut faces = scan.faces.iter();
    for model in &models {
        let mesh = &model.mesh;
        let slot = match mesh.material_id {
            Some(i) if i < records.len() => i,
            _ => records.len(),
        };
        let mut next = 0usize;
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        for arity in arities {
            let Some(indices) = mesh.indices.get(next..next + arity) else {
                break;
            };
            next += arity;
            let Some(face) = faces.next() else {
                break;
            };
            if face.is_line {
                continue;
            }
            let positions: Vec<Vec3> = indices.iter().map(|&i| super::position(mesh, i)).collect();
            // The corners' file indices, when the line has as many as tobj
            // read (it always has: both read the same checked text).
            let refs = corners
                .faces
                .get(&face.pos.line)
                .filter(|r| r.len() == arity);
            // The import drops what gives no polygon; so does the model.
            let Ok(split) = face_pieces(MaterialId(0), positions.clone(), face.pos) else {
                continue;
            };
            for (polygon, corner_ids) in split {
                pieces.push(Piece {
                    slot,
                    corners: corner_ids
                        .iter()
                        .map(|&c| (positions[c], refs.map(|r| r[c])))
                        .collect(),
                    normal: polygon.normal,
                });
            }
        }
    }
    let emits: Vec<bool> = records
        .iter()
        .map(|m| m.to_material().emission().max_channel() > 0.0)
        .collect();
    let mut builder = Builder::default();
    for piece in without_repeats(pieces, &emits) {
        builder.piece(&piece, &corners);
    }
    Ok(builder.finish(&records, &read_texture, name))
}

/// Every face line's corners as file indices (0-based, negative ones
/// resolved), and the file's `vt` and `vn` values.
#[derive(Default)]
struct Corners {
    /// By the face's line number: each corner's `(v, vt, vn)`.
    faces: HashMap<u32, Vec<CornerRef>>,
    /// `vt` values `(u, v)` as written (a missing `v` is 0).
    texcoords: Vec<[f32; 2]>,
    /// `vn` values as written.
    normals: Vec<[f32; 3]>,
}

/// One corner of a face: its position, texture coordinate and normal
/// indices into the file's lists, 0-based (32-bit, as tobj's: a model's
/// every corner is held at once).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct CornerRef {
    v: u32,
    vt: Option<u32>,
    vn: Option<u32>,
}

impl Corners {
    /// Reads the `vt`, `vn` and `f` lines of checked OBJ text (as the
    /// scan passed it: every reference in range).
    fn of(text: &str) -> Corners {
        let mut out = Corners::default();
        // Negative indices count back from the line they are on.
        let mut seen = [0usize; 3];
        for (number, line) in lines(text) {
            let w = words(line);
            let Some(&(keyword, _)) = w.first() else {
                continue;
            };
            let value = |k: usize| {
                w.get(k)
                    .and_then(|(x, _)| x.parse::<f32>().ok())
                    .unwrap_or(0.0)
            };
            match keyword {
                "v" => seen[0] += 1,
                "vt" => {
                    seen[1] += 1;
                    out.texcoords.push([value(1), value(2)]);
                }
                "vn" => {
                    seen[2] += 1;
                    out.normals.push([value(1), value(2), value(3)]);
                }
                "f" => {
                    let refs = w[1..]
                        .iter()
                        .map(|(word, _)| corner_ref(word, &seen))
                        .collect::<Option<Vec<_>>>();
                    if let Some(refs) = refs {
                        out.faces.insert(number, refs);
                    }
                }
                _ => {}
            }
        }
        // A reference past the end of its list is left out (the scan
        // warned of it and the import read the corner without it).
        for refs in out.faces.values_mut() {
            for r in refs {
                r.vt = r.vt.filter(|&i| (i as usize) < out.texcoords.len());
                r.vn = r.vn.filter(|&i| (i as usize) < out.normals.len());
            }
        }
        out
    }
}

/// The indices of a face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`,
/// 0-based; negative ones resolved against the `seen` counts of `v`,
/// `vt` and `vn` lines before it.
fn corner_ref(word: &str, seen: &[usize; 3]) -> Option<CornerRef> {
    let mut parts = word.split('/');
    let resolve = |part: Option<&str>, kind: usize| -> Option<u32> {
        let i = part.filter(|p| !p.is_empty())?.parse::<i64>().ok()?;
        let i = if i > 0 {
            i as usize - 1
        } else {
            seen[kind].checked_sub(i.unsigned_abs() as usize)?
        };
        u32::try_from(i).ok()
    };
    let v = resolve(parts.next(), 0)?;
    let vt = resolve(parts.next(), 1);
    let vn = resolve(parts.next(), 2);
    Some(CornerRef { v, vt, vn })
}

/// One polygon of a face as the import makes it: its material slot, its
/// corners (position, and the file indices when known) in order, its flat
/// normal.
struct Piece {
    slot: usize,
    corners: Vec<(Vec3, Option<CornerRef>)>,
    normal: Vec3,
}

/// `pieces` without the ones that repeat another exactly (the same
/// positions in the same cyclic order), chosen as the import's
/// [`crate::scene::Scene::drop_duplicates`] chooses: the later one,
/// unless only the earlier one emits (`emits`, by material slot), so that
/// the model holds the faces the solver lit.
fn without_repeats(pieces: Vec<Piece>, emits: &[bool]) -> Vec<Piece> {
    let emits = |p: &Piece| emits.get(p.slot).copied().unwrap_or(false);
    let mut kept: HashMap<Vec<[u32; 3]>, usize> = HashMap::new();
    let mut keep = vec![true; pieces.len()];
    for (i, p) in pieces.iter().enumerate() {
        let positions: Vec<Vec3> = p.corners.iter().map(|c| c.0).collect();
        let key = face_key(&positions);
        let Some(&j) = kept.get(&key) else {
            kept.insert(key, i);
            continue;
        };
        if emits(&pieces[j]) && !emits(p) {
            keep[i] = false;
        } else {
            keep[j] = false;
            kept.insert(key, i);
        }
    }
    pieces
        .into_iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(p))
        .collect()
}

/// A primitive as it fills.
#[derive(Default)]
struct Building {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    /// The corner's `vt` as written, if it has one.
    texcoords: Vec<Option<[f32; 2]>>,
    indices: Vec<u32>,
    /// Vertices by what makes them one: the corner's file indices, and
    /// for a corner without a `vn`, the piece whose flat normal it takes.
    vertices: HashMap<(CornerRef, Option<usize>), u32>,
}

/// The primitives by material slot (the libraries' materials in order,
/// then the default material), in the order of first use.
#[derive(Default)]
struct Builder {
    slots: HashMap<usize, usize>,
    primitives: Vec<(usize, Building)>,
    pieces: usize,
}

impl Builder {
    /// Adds `piece` to the primitive of its material, fanned from its
    /// first corner as the scene's polygons are.
    fn piece(&mut self, piece: &Piece, corners: &Corners) {
        let id = self.pieces;
        self.pieces += 1;
        let k = *self.slots.entry(piece.slot).or_insert_with(|| {
            self.primitives.push((piece.slot, Building::default()));
            self.primitives.len() - 1
        });
        let p = &mut self.primitives[k].1;
        let ids: Vec<u32> = piece
            .corners
            .iter()
            .map(|&(position, r)| {
                let vn = r
                    .and_then(|r| r.vn)
                    .map(|i| Vec3::from_array(corners.normals[i as usize]).normalize_or_zero())
                    .filter(|n| n.is_finite() && *n != Vec3::ZERO);
                // A corner is shared by its file indices; one whose normal
                // is its face's is its face's alone.
                let key = match r {
                    Some(r) if vn.is_some() => Some((r, None)),
                    Some(r) => Some((r, Some(id))),
                    None => None,
                };
                if let Some(&i) = key.as_ref().and_then(|k| p.vertices.get(k)) {
                    return i;
                }
                let i = p.positions.len() as u32;
                p.positions.push(position.to_array());
                p.normals.push(vn.unwrap_or(piece.normal).to_array());
                p.texcoords
                    .push(r.and_then(|r| r.vt).map(|t| corners.texcoords[t as usize]));
                if let Some(key) = key {
                    p.vertices.insert(key, i);
                }
                i
            })
            .collect();
        for j in 1..ids.len().saturating_sub(1) {
            p.indices.extend([ids[0], ids[j], ids[j + 1]]);
        }
    }

    /// The model: each primitive with its material, each material's
    /// texture read through `read` (see the module docs).
    fn finish(
        self,
        records: &[&MtlMaterial],
        read: &dyn Fn(&Path) -> Result<Vec<u8>, String>,
        name: &str,
    ) -> ObjSource {
        let mut model = SourceModel::default();
        let mut images: HashMap<PathBuf, usize> = HashMap::new();
        // Bytes of the images embedded so far.
        let mut embedded = 0u64;
        let mut textures: HashMap<(usize, bool), usize> = HashMap::new();
        let mut left_out = Tally::<(String, SourcePos)>::default();
        let mut ignored = Tally::<(String, SourcePos)>::default();
        for (slot, b) in self.primitives {
            let record = records.get(slot).copied();
            let mut material = base_material(record);
            let mut transform = None;
            if let Some((m, (map, pos))) = record.and_then(|m| Some((m, m.map_kd.as_ref()?))) {
                let options = TextureOptions::parse(&m.map_kd_options);
                if !options.ignored.is_empty() {
                    ignored.add((m.file.clone(), *pos), || {
                        format!("`{}` (material `{}`)", options.ignored.join(" "), m.name)
                    });
                }
                let path = Path::new(&m.file)
                    .parent()
                    .map(Path::to_path_buf)
                    .unwrap_or_default()
                    .join(map);
                let image = match images.get(&path) {
                    Some(&i) => Ok(i),
                    None => within_budget(&path, embedded)
                        .and_then(|()| read(&path))
                        .and_then(embeddable)
                        .map(|image| {
                            embedded += image.bytes.len() as u64;
                            model.images.push(image);
                            images.insert(path.clone(), model.images.len() - 1);
                            model.images.len() - 1
                        }),
                };
                match image {
                    Ok(image) => {
                        let texture =
                            *textures.entry((image, options.clamp)).or_insert_with(|| {
                                let mut texture = json!({"source": image});
                                if options.clamp {
                                    model.samplers.push(json!({
                                        "wrapS": CLAMP_TO_EDGE, "wrapT": CLAMP_TO_EDGE,
                                    }));
                                    texture["sampler"] = json!(model.samplers.len() - 1);
                                }
                                model.textures.push(texture);
                                model.textures.len() - 1
                            });
                        material["pbrMetallicRoughness"]["baseColorTexture"] =
                            json!({"index": texture});
                        transform = Some(options);
                    }
                    Err(why) => left_out.add((m.file.clone(), *pos), || {
                        format!("{} (material `{}`): {why}", path.display(), m.name)
                    }),
                }
            }
            model.materials.push(material);
            let uv0 = b.texcoords.iter().any(Option::is_some).then(|| {
                b.texcoords
                    .iter()
                    .map(|t| {
                        let [u, v] = t.unwrap_or([0.0, 0.0]);
                        let [u, v] = match &transform {
                            Some(o) => [u * o.scale[0] + o.offset[0], v * o.scale[1] + o.offset[1]],
                            None => [u, v],
                        };
                        [u, 1.0 - v]
                    })
                    .collect()
            });
            model.primitives.push(SourcePrimitive {
                name: name.to_string(),
                positions: b.positions,
                normals: Some(b.normals),
                uv0,
                uv1: None,
                indices: b.indices,
                material: Some(model.materials.len() - 1),
            });
        }
        let mut warnings = Vec::new();
        if let Some(((file, pos), first)) = left_out.first {
            warnings.push(Warning::at(
                &file,
                pos,
                format!(
                    "the lightmap's model leaves out {} `map_Kd` texture(s), first {first}; \
                     their materials keep `Kd` only",
                    left_out.count
                ),
            ));
        }
        if let Some(((file, pos), first)) = ignored.first {
            warnings.push(Warning::at(
                &file,
                pos,
                format!(
                    "the lightmap's model ignores the `map_Kd` options of {} material(s), \
                     first {first}; only -s, -o and -clamp are read",
                    ignored.count
                ),
            ));
        }
        ObjSource { model, warnings }
    }
}

/// The glTF material of an MTL `record` (`None`: the default material):
/// its name, `Kd` as written as the base colour (scaled so no channel is
/// above one), a rough dielectric.
fn base_material(record: Option<&MtlMaterial>) -> Value {
    let kd = record
        .and_then(|m| m.kd_written)
        .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
    let kd = if kd.max_channel() > 1.0 {
        kd * (1.0 / kd.max_channel())
    } else {
        kd
    };
    let [r, g, b] = kd.to_f32();
    json!({
        "name": record.map_or(DEFAULT_MATERIAL_NAME, |m| m.name.as_str()),
        "pbrMetallicRoughness": {
            "baseColorFactor": [r, g, b, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
    })
}

/// Whether the texture file at `path` fits beside the `embedded` bytes
/// already taken ([`MAX_EMBEDDED_BYTES`]), from its size before it is
/// read; a file whose size cannot be read is let through to the read,
/// which says why.
fn within_budget(path: &Path, embedded: u64) -> Result<(), String> {
    match std::fs::metadata(path) {
        Ok(meta) if embedded.saturating_add(meta.len()) > MAX_EMBEDDED_BYTES => Err(format!(
            "its {} bytes would take the model's embedded images past {} MiB",
            meta.len(),
            MAX_EMBEDDED_BYTES >> 20
        )),
        _ => Ok(()),
    }
}

/// The image of a texture file's `bytes` as a glTF holds it: PNG or JPEG
/// by their signatures, the header parsed (not the pixels); else why not.
fn embeddable(bytes: Vec<u8>) -> Result<SourceImage, String> {
    let mime_type = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        "image/png"
    } else if bytes.starts_with(b"\xff\xd8\xff") {
        "image/jpeg"
    } else {
        return Err("neither PNG nor JPEG, the formats a glTF holds".to_string());
    };
    image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .into_dimensions()
        .map_err(|e| format!("its header does not read as {mime_type}: {e}"))?;
    Ok(SourceImage {
        bytes,
        mime_type: mime_type.to_string(),
    })
}

/// What the options of a `map_Kd` line ask for.
#[derive(Clone, Debug, PartialEq)]
struct TextureOptions {
    /// `-s u v`: the texture coordinates' scale (1 when not given).
    scale: [f32; 2],
    /// `-o u v`: their offset (0 when not given).
    offset: [f32; 2],
    /// `-clamp on`.
    clamp: bool,
    /// The other options, as written.
    ignored: Vec<String>,
}

impl TextureOptions {
    /// Reads the option words of a `map_Kd` line (as
    /// [`super::mtl::map_parts`] splits them off).
    fn parse(words: &[String]) -> TextureOptions {
        let mut out = TextureOptions {
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
            clamp: false,
            ignored: Vec::new(),
        };
        let mut i = 0;
        while i < words.len() {
            let option = words[i].as_str();
            i += 1;
            // The option's arguments: the words up to the next option.
            let start = i;
            while i < words.len() && !is_option(&words[i]) {
                i += 1;
            }
            let args = &words[start..i];
            let numbers: Vec<f32> = args.iter().filter_map(|a| a.parse().ok()).collect();
            match option {
                "-s" | "-o" => {
                    let target = if option == "-s" {
                        &mut out.scale
                    } else {
                        &mut out.offset
                    };
                    for (t, n) in target.iter_mut().zip(&numbers) {
                        *t = *n;
                    }
                }
                "-clamp" => out.clamp = args.first().is_some_and(|a| a == "on"),
                _ => out.ignored.push(
                    std::iter::once(option)
                        .chain(args.iter().map(String::as_str))
                        .collect::<Vec<_>>()
                        .join(" "),
                ),
            }
        }
        out
    }
}

/// Whether a word of a `map_Kd` line starts an option (`-s`), not a
/// negative number (`-0.5`).
fn is_option(word: &str) -> bool {
    word.starts_with('-') && word.parse::<f64>().is_err()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(words: &[&str]) -> Vec<String> {
        words.iter().map(|w| w.to_string()).collect()
    }

    #[test]
    fn map_kd_options_scale_offset_and_clamp_are_read_the_rest_listed() {
        let o = TextureOptions::parse(&strings(&[
            "-s", "2", "3", "1", "-o", "-0.5", "0.25", "-clamp", "on", "-bm", "0.2",
        ]));
        assert_eq!(o.scale, [2.0, 3.0]);
        assert_eq!(o.offset, [-0.5, 0.25]);
        assert!(o.clamp);
        assert_eq!(o.ignored, vec!["-bm 0.2".to_string()]);
        let none = TextureOptions::parse(&[]);
        assert_eq!(
            (none.scale, none.offset, none.clamp),
            ([1.0; 2], [0.0; 2], false)
        );
    }

    #[test]
    fn corners_resolve_negative_and_missing_indices() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\nf 1/1/1 -2/-1 3//-1\n";
        let c = Corners::of(text);
        let refs = &c.faces[&7];
        assert_eq!(
            refs,
            &vec![
                CornerRef {
                    v: 0,
                    vt: Some(0),
                    vn: Some(0)
                },
                CornerRef {
                    v: 1,
                    vt: Some(1),
                    vn: None
                },
                CornerRef {
                    v: 2,
                    vt: None,
                    vn: Some(0)
                },
            ]
        );
        assert_eq!(c.texcoords, vec![[0.0, 0.0], [1.0, 0.0]]);
    }

    #[test]
    fn textures_past_the_embedding_budget_are_refused_by_their_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.png");
        // Sparse: the size without the bytes.
        std::fs::File::create(&path)
            .unwrap()
            .set_len(MAX_EMBEDDED_BYTES + 1)
            .unwrap();
        assert!(within_budget(&path, 0).is_err());
        std::fs::File::create(&path).unwrap().set_len(100).unwrap();
        assert!(within_budget(&path, 0).is_ok());
        assert!(within_budget(&path, MAX_EMBEDDED_BYTES - 100).is_ok());
        assert!(within_budget(&path, MAX_EMBEDDED_BYTES - 99).is_err());
    }

    #[test]
    fn only_png_and_jpeg_are_embedded() {
        let mut png = Vec::new();
        image::RgbImage::new(3, 2)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let image = embeddable(png.clone()).unwrap();
        assert_eq!(
            (image.bytes, image.mime_type.as_str()),
            (png.clone(), "image/png")
        );
        assert!(embeddable(b"BM not a png".to_vec()).is_err());
        // A PNG signature with no header after it.
        assert!(embeddable(png[..8].to_vec()).is_err());
    }
}
