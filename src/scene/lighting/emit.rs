//! Light by name, and the warning when there is none.
//!
//! Most OBJ collections keep their lights outside the model: the lamp is a
//! mesh named `Lamp` whose material does not emit, and the picture comes
//! out black. [`Scene::set_emission`] makes a material, an OBJ object
//! (`o`) or an OBJ group (`g`) emit by its name (what `--emit NAME=VALUE`
//! does), and [`Scene::nothing_emits_warning`] says when nothing emits,
//! naming what looks like a lamp ([`LAMP_SUBSTRINGS`], [`LAMP_WORDS`]).
//!
//! Objects and groups are kept in [`Scene::groups`], beside the polygons
//! rather than on them: each [`Group`] lists its polygons, so a polygon can
//! belong to an object and to several groups at once, and the scenes and
//! importers that have no such names (`.sc`) leave the list empty.

use crate::color::Rgb;
use crate::scene::error::{escape_controls, Warning};
use crate::scene::{Material, MaterialId, PolygonId, Scene};
use std::collections::HashMap;
use std::fmt;

/// Parts of a name that suggest a lamp, matched case-insensitively
/// anywhere in the name (`CeilingLight`, `Lamp.001`, `lightbulb`).
pub const LAMP_SUBSTRINGS: &[&str] = &[
    "light",
    "lamp",
    "emit",
    "emiss",
    "bulb",
    "neon",
    "glow",
    "lantern",
    "candle",
    "chandelier",
    "sconce",
    "luminaire",
    "flame",
];

/// Short words that suggest a lamp, matched case-insensitively as whole
/// words only (the name split at anything not a letter or digit and
/// between a lower-case and an upper-case letter): `LED_strip`, `Sun`,
/// `spotLED`, but not `tiled` or `Sunday`.
pub const LAMP_WORDS: &[&str] = &["led", "leds", "sun"];

/// At most this many names of each kind are listed in an [`UnknownName`]
/// message, and at most this many lamp-like names in the warning; the rest
/// are counted.
pub const MAX_LISTED_NAMES: usize = 12;

/// What kind of name a scene file gave a [`Group`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum GroupKind {
    /// An object: OBJ `o NAME`, or a glTF node with a mesh (what Blender
    /// calls an object and exports as a node).
    Object,
    /// An OBJ group, `g NAME …`.
    Group,
    /// A glTF mesh, by its name: every node that draws it.
    Mesh,
}

impl GroupKind {
    /// The word for it in messages: `object` or `group`.
    pub fn word(self) -> &'static str {
        match self {
            GroupKind::Object => "object",
            GroupKind::Group => "group",
            GroupKind::Mesh => "mesh",
        }
    }
}

/// A named set of polygons from the scene file: an OBJ object or group,
/// a glTF node or mesh.
///
/// Invariants: `name` is not empty; `polygons` is strictly ascending and
/// every id is below the scene's polygon count. The same `(kind, name)`
/// appears once in [`Scene::groups`] even when the file opens it again.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Group {
    /// The name as written.
    pub name: String,
    /// Object or group.
    pub kind: GroupKind,
    /// The polygons made from the faces written under it, ascending.
    pub polygons: Vec<PolygonId>,
}

/// A name given to [`Scene::set_emission`] that no material, object or
/// group has. Its message lists the names the scene does have, at most
/// [`MAX_LISTED_NAMES`] of each kind.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct UnknownName {
    /// The name asked for.
    pub name: String,
    /// Every material name, in scene order.
    pub materials: Vec<String>,
    /// Every object name, in file order.
    pub objects: Vec<String>,
    /// Every group name, in file order.
    pub groups: Vec<String>,
    /// Every mesh name (glTF), in file order.
    pub meshes: Vec<String>,
}

impl fmt::Display for UnknownName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kinds = match (
            self.objects.is_empty() && self.groups.is_empty(),
            self.meshes.is_empty(),
        ) {
            (true, true) => "material",
            (false, true) => "material, object or group",
            (_, false) if self.groups.is_empty() => "material, object or mesh",
            (_, false) => "material, object, mesh or group",
        };
        let name = escape_controls(&self.name);
        write!(f, "no {kinds} is named `{name}`; the scene has ")?;
        let lists = [
            ("material", "materials", &self.materials),
            ("object", "objects", &self.objects),
            ("mesh", "meshes", &self.meshes),
            ("group", "groups", &self.groups),
        ];
        let mut first = true;
        for (one, many, names) in lists {
            if names.is_empty() {
                continue;
            }
            if !first {
                write!(f, "; ")?;
            }
            first = false;
            let word = if names.len() == 1 { one } else { many };
            write!(f, "{word} {}", list_names(names.iter().map(String::as_str)))?;
        }
        Ok(())
    }
}

/// The names quoted and joined by commas, at most [`MAX_LISTED_NAMES`],
/// then how many more there are.
fn list_names<'a>(names: impl ExactSizeIterator<Item = &'a str>) -> String {
    let total = names.len();
    let mut out: Vec<String> = names
        .take(MAX_LISTED_NAMES)
        .map(|n| format!("`{}`", escape_controls(n)))
        .collect();
    if total > MAX_LISTED_NAMES {
        out.push(format!("and {} more", total - MAX_LISTED_NAMES));
    }
    out.join(", ")
}

/// True when `name` suggests a lamp: it contains one of
/// [`LAMP_SUBSTRINGS`] or has one of [`LAMP_WORDS`] as a whole word,
/// ignoring case.
pub fn looks_like_lamp(name: &str) -> bool {
    let lower = name.to_lowercase();
    if LAMP_SUBSTRINGS.iter().any(|s| lower.contains(s)) {
        return true;
    }
    // Words: split at non-alphanumerics and at lower→upper case changes.
    let mut words: Vec<String> = Vec::new();
    let mut current = String::new();
    let mut prev_lower = false;
    for c in name.chars() {
        if !c.is_alphanumeric() {
            words.push(std::mem::take(&mut current));
            prev_lower = false;
            continue;
        }
        if c.is_uppercase() && prev_lower {
            words.push(std::mem::take(&mut current));
        }
        prev_lower = c.is_lowercase() || c.is_ascii_digit();
        current.extend(c.to_lowercase());
    }
    words.push(current);
    words.iter().any(|w| LAMP_WORDS.contains(&w.as_str()))
}

impl Material {
    /// The material emitting `emission` (radiosity in the scene's units,
    /// every channel finite, `>= 0` and at most
    /// [`MAX_EMISSION`](crate::scene::MAX_EMISSION)) instead of what it emitted.
    ///
    /// Its reflectance is kept exactly when it is black, when the emission
    /// is black, or when the two have the same hue. Otherwise (a
    /// [`Material`] has one colour) the material takes the colour of the
    /// emission and keeps the luminance of its reflectance, capped so that
    /// no channel exceeds its old largest one: the rule the OBJ importer
    /// follows for a material with both `Kd` and `Ke`.
    pub fn with_emission(&self, emission: Rgb) -> Material {
        let rho = self.reflectance();
        let (color, k_diffrefl, k_emission) = if emission.is_black() {
            (self.color, self.k_diffrefl, 0.0)
        } else if rho.is_black() {
            (emission, 0.0, 1.0)
        } else {
            let lum = |c: Rgb| c.luminance().max(f64::MIN_POSITIVE);
            let k = (lum(rho) / lum(emission)).min(rho.max_channel() / emission.max_channel());
            (emission, k, 1.0)
        };
        Material {
            name: self.name.clone(),
            color,
            k_diffrefl,
            k_emission,
        }
    }
}

impl Scene {
    /// True when some polygon's material emits (its emission is not
    /// black), or the scene has a sun ([`Scene::sun`]). Unused emitting
    /// materials do not count.
    pub fn emits(&self) -> bool {
        if self.sun.is_some() {
            return true;
        }
        let emitting: Vec<bool> = self
            .materials
            .iter()
            .map(|m| !m.emission().is_black())
            .collect();
        self.polygons
            .iter()
            .any(|p| emitting.get(p.material.index()).copied().unwrap_or(false))
    }

    /// Makes everything named `name` emit `emission` (radiosity in the
    /// scene's units, every channel finite, `>= 0` and at most
    /// [`MAX_EMISSION`](crate::scene::MAX_EMISSION)), keeping its reflectance as
    /// [`Material::with_emission`] says; returns how many polygons it
    /// covers.
    ///
    /// `name` is matched exactly (case matters) against the materials,
    /// then the objects and groups of [`Scene::groups`]; every match
    /// counts. A material named `name` is changed in place. The polygons
    /// of an object or group get a material of their own, a copy named
    /// `MATERIAL (NAME)` appended to [`Scene::materials`], when their
    /// material is also used by polygons outside it, so that only the
    /// object or group emits; when it covers every polygon of that
    /// material, the material is changed in place. Calls apply in order, a
    /// later one replacing what an earlier one set.
    pub fn set_emission(&mut self, name: &str, emission: Rgb) -> Result<usize, UnknownName> {
        let named_materials: Vec<usize> = (0..self.materials.len())
            .filter(|&i| self.materials[i].name == name)
            .collect();
        let mut members: Vec<PolygonId> = self
            .groups
            .iter()
            .filter(|g| g.name == name)
            .flat_map(|g| g.polygons.iter().copied())
            .collect();
        if named_materials.is_empty() && !self.groups.iter().any(|g| g.name == name) {
            return Err(self.unknown_name(name));
        }
        members.sort_unstable();
        members.dedup();

        let mut covered = vec![false; self.polygons.len()];
        for &m in &named_materials {
            self.materials[m] = self.materials[m].with_emission(emission);
        }
        for (flag, p) in covered.iter_mut().zip(&self.polygons) {
            *flag = named_materials.contains(&p.material.index());
        }
        // The members' polygons whose material was not named, by material.
        let mut per_material = vec![0usize; self.materials.len()];
        for p in &self.polygons {
            if let Some(count) = per_material.get_mut(p.material.index()) {
                *count += 1;
            }
        }
        let mut by_material: std::collections::BTreeMap<MaterialId, Vec<PolygonId>> =
            Default::default();
        for &id in &members {
            let Some(p) = self.polygons.get(id.index()) else {
                continue;
            };
            if !covered[id.index()] {
                by_material.entry(p.material).or_default().push(id);
            }
        }
        for (material, ids) in by_material {
            let Some(old) = self.materials.get(material.index()) else {
                continue;
            };
            let mut new = old.with_emission(emission);
            let target = if ids.len() == per_material[material.index()] {
                self.materials[material.index()] = new;
                material
            } else {
                new.name = format!("{} ({name})", old.name);
                self.materials.push(new);
                MaterialId(self.materials.len() as u32 - 1)
            };
            for id in ids {
                self.polygons[id.index()].material = target;
                covered[id.index()] = true;
            }
        }
        Ok(covered.iter().filter(|&&c| c).count())
    }

    /// The error for a name nothing has: every name the scene has.
    pub(super) fn unknown_name(&self, name: &str) -> UnknownName {
        let of = |kind: GroupKind| {
            self.groups
                .iter()
                .filter(|g| g.kind == kind)
                .map(|g| g.name.clone())
                .collect()
        };
        UnknownName {
            name: name.to_string(),
            materials: self.materials.iter().map(|m| m.name.clone()).collect(),
            objects: of(GroupKind::Object),
            groups: of(GroupKind::Group),
            meshes: of(GroupKind::Mesh),
        }
    }

    /// The used materials, objects and groups whose names suggest a lamp
    /// ([`looks_like_lamp`]), as `(kind word, name)`: objects, then
    /// groups, then materials, each in scene order, without repeats.
    pub fn lamp_like_names(&self) -> Vec<(&'static str, &str)> {
        let mut used = vec![false; self.materials.len()];
        for p in &self.polygons {
            if let Some(u) = used.get_mut(p.material.index()) {
                *u = true;
            }
        }
        let mut out: Vec<(&'static str, &str)> = Vec::new();
        let groups = [GroupKind::Object, GroupKind::Group, GroupKind::Mesh]
            .into_iter()
            .flat_map(|k| {
                self.groups
                    .iter()
                    .filter(move |g| g.kind == k && !g.polygons.is_empty())
                    .map(|g| (g.kind.word(), g.name.as_str()))
            });
        let materials = self
            .materials
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(m, _)| ("material", m.name.as_str()));
        let mut seen = std::collections::HashSet::new();
        for (kind, name) in groups.chain(materials) {
            if looks_like_lamp(name) && seen.insert((kind, name)) {
                out.push((kind, name));
            }
        }
        out
    }

    /// The warning for a scene in which nothing emits (see
    /// [`Scene::emits`]), about `file` as the user named it: one line
    /// saying the picture will be black, naming what looks like a lamp,
    /// and the options that give it light (`--emit`, `--sky`). `None` when
    /// something emits, a sky ([`Scene::add_sky`]) included.
    pub fn nothing_emits_warning(&self, file: &str) -> Option<Warning> {
        if self.emits() {
            return None;
        }
        let hints = self.lamp_like_names();
        let fix = match hints.first() {
            Some((_, name)) => {
                let listed = hints.len().min(MAX_LISTED_NAMES);
                let mut named: Vec<String> = hints[..listed]
                    .iter()
                    .map(|(kind, name)| format!("{kind} `{name}`"))
                    .collect();
                if hints.len() > listed {
                    named.push(format!("and {} more", hints.len() - listed));
                }
                format!(
                    "{} {}: make {} emit with --emit NAME=VALUE \
                     (radiosity in the scene's units, V or R,G,B), for instance --emit '{}=10'",
                    named.join(", "),
                    if hints.len() == 1 {
                        "looks like a lamp"
                    } else {
                        "look like lamps"
                    },
                    if hints.len() == 1 { "it" } else { "them" },
                    // Inside single quotes for a POSIX shell: a quote in
                    // the name ends them, is written escaped, and reopens.
                    name.replace('\'', r"'\''"),
                )
            }
            None => {
                let what = if self.groups.is_empty() {
                    "a material"
                } else {
                    "a material, object or group"
                };
                format!(
                    "make {what} emit with --emit NAME=VALUE \
                     (radiosity in the scene's units, V or R,G,B)"
                )
            }
        };
        Some(Warning::file(
            file,
            format!(
                "nothing emits light, so the picture will be black; {fix}; \
                 or light it from all around with --sky VALUE (a sky of that radiosity)"
            ),
        ))
    }
}

/// The `o` and `g` statements of an OBJ file, as its line scan meets
/// them: which objects and groups the faces written next belong to. Each
/// face notes [`GroupScan::current`]; once the polygons are made,
/// [`GroupScan::assign`] files them under their names.
#[derive(Debug, Default)]
pub(crate) struct GroupScan {
    /// Every `(kind, name)`, in order of first appearance.
    names: Vec<(GroupKind, String)>,
    /// The index of each `(kind, name)` in `names` (files with many
    /// thousands of objects are common).
    name_index: HashMap<(GroupKind, String), u32>,
    /// Each distinct membership faces have had, as indices into `names`.
    sets: Vec<Vec<u32>>,
    /// The index of each membership in `sets`.
    set_index: HashMap<Vec<u32>, u32>,
    /// The object named last, as an index into `names`.
    object: Option<u32>,
    /// The groups named last, as indices into `names`.
    groups: Vec<u32>,
    /// The index in `sets` of the current membership, once one was asked
    /// for since the last statement.
    current: Option<u32>,
}

impl GroupScan {
    /// Reads an `o` (`keyword` is `"o"`: `rest`, trimmed, is one name) or
    /// `g` statement (`rest` is names separated by white space; none
    /// means no group). `rest` is the line after the keyword.
    pub(crate) fn statement(&mut self, keyword: &str, rest: &str) {
        self.current = None;
        if keyword == "o" {
            let name = rest.trim();
            self.object = (!name.is_empty()).then(|| self.intern(GroupKind::Object, name));
        } else {
            let names: Vec<&str> = rest.split_whitespace().collect();
            self.groups = names
                .into_iter()
                .map(|n| self.intern(GroupKind::Group, n))
                .collect();
        }
    }

    fn intern(&mut self, kind: GroupKind, name: &str) -> u32 {
        let next = self.names.len() as u32;
        let index = *self
            .name_index
            .entry((kind, name.to_string()))
            .or_insert(next);
        if index == next {
            self.names.push((kind, name.to_string()));
        }
        index
    }

    /// The membership of a face written now, for [`GroupScan::assign`].
    pub(crate) fn current(&mut self) -> u32 {
        if let Some(c) = self.current {
            return c;
        }
        let set: Vec<u32> = self
            .object
            .into_iter()
            .chain(self.groups.iter().copied())
            .collect();
        let next = self.sets.len() as u32;
        let index = *self.set_index.entry(set.clone()).or_insert(next);
        if index == next {
            self.sets.push(set);
        }
        self.current = Some(index);
        index
    }

    /// One [`Group`] per name, with no polygons yet.
    pub(crate) fn groups(&self) -> Vec<Group> {
        self.names
            .iter()
            .map(|(kind, name)| Group {
                name: name.clone(),
                kind: *kind,
                polygons: Vec::new(),
            })
            .collect()
    }

    /// Files the polygons `ids` (made from one face, in ascending order)
    /// under the names of `membership`.
    pub(crate) fn assign(
        &self,
        groups: &mut [Group],
        membership: u32,
        ids: std::ops::Range<usize>,
    ) {
        for &g in self.sets.get(membership as usize).into_iter().flatten() {
            if let Some(group) = groups.get_mut(g as usize) {
                group
                    .polygons
                    .extend(ids.clone().map(|i| PolygonId(i as u32)));
            }
        }
    }

    /// The groups that received polygons: names with no faces (a camera,
    /// an empty object) are dropped.
    pub(crate) fn finish(mut groups: Vec<Group>) -> Vec<Group> {
        groups.retain(|g| !g.polygons.is_empty());
        groups
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{CameraSource, Polygon, SourcePos};
    use crate::testutil;
    use glam::Vec3;

    fn material(name: &str, rho: f64, e: f64) -> Material {
        testutil::grey(name, e, rho)
    }

    fn square(material: u32, x: f32) -> Polygon {
        let v = vec![
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 0.0, 0.0),
            Vec3::new(x + 1.0, 1.0, 0.0),
            Vec3::new(x, 1.0, 0.0),
        ];
        Polygon::new(MaterialId(material), v, SourcePos::default()).unwrap()
    }

    /// Four squares: 0 and 1 of object `Room` (material `white`), 2 of
    /// object `Lamp` (also `white`, and group `fixtures`), 3 of object
    /// `Shade` (material `shade`, and group `fixtures`). Nothing emits.
    fn room() -> Scene {
        let mut s = testutil::scene(
            vec![
                square(0, 0.0),
                square(0, 2.0),
                square(0, 4.0),
                square(1, 6.0),
            ],
            vec![material("white", 0.5, 0.0), material("shade", 0.3, 0.0)],
        );
        let group = |name: &str, kind, ids: &[u32]| Group {
            name: name.to_string(),
            kind,
            polygons: ids.iter().map(|&i| PolygonId(i)).collect(),
        };
        s.groups = vec![
            group("Room", GroupKind::Object, &[0, 1]),
            group("Lamp", GroupKind::Object, &[2]),
            group("Shade", GroupKind::Object, &[3]),
            group("fixtures", GroupKind::Group, &[2, 3]),
        ];
        s
    }

    fn emitting(s: &Scene) -> Vec<u32> {
        (0..s.polygons.len() as u32)
            .filter(|&i| !s.material_of(PolygonId(i)).emission().is_black())
            .collect()
    }

    #[test]
    fn a_material_name_changes_the_material_in_place() {
        let mut s = room();
        assert!(!s.emits());
        assert_eq!(s.set_emission("white", Rgb::splat(10.0)), Ok(3));
        assert_eq!(s.materials.len(), 2);
        assert_eq!(s.materials[0].emission(), Rgb::splat(10.0));
        assert_eq!(s.materials[0].reflectance(), Rgb::splat(0.5));
        assert_eq!(emitting(&s), [0, 1, 2]);
        assert!(s.emits());
    }

    #[test]
    fn an_object_sharing_a_material_gets_a_copy_of_its_own() {
        let mut s = room();
        let e = Rgb::new(10.0, 8.0, 6.0);
        assert_eq!(s.set_emission("Lamp", e), Ok(1));
        assert_eq!(emitting(&s), [2]);
        assert_eq!(s.materials.len(), 3);
        assert_eq!(s.materials[2].name, "white (Lamp)");
        assert_eq!(s.materials[2].emission(), e);
        assert_eq!(s.polygons[2].material, MaterialId(2));
        // The original is untouched; the copy reflects in the emission's
        // colour, no channel above the old reflectance 0.5.
        assert_eq!(s.materials[0], material("white", 0.5, 0.0));
        let rho = s.materials[2].reflectance();
        assert!((rho.r - 0.5).abs() < 1e-9, "{rho:?}");
        assert!((rho.g / rho.r - 0.8).abs() < 1e-9, "{rho:?}");
    }

    #[test]
    fn an_object_covering_its_material_changes_it_in_place() {
        let mut s = room();
        assert_eq!(s.set_emission("Shade", Rgb::splat(2.0)), Ok(1));
        assert_eq!(s.materials.len(), 2);
        assert_eq!(emitting(&s), [3]);
        assert_eq!(s.materials[1].reflectance(), Rgb::splat(0.3));
    }

    #[test]
    fn a_group_spans_materials_and_later_calls_replace_earlier_ones() {
        let mut s = room();
        assert_eq!(s.set_emission("fixtures", Rgb::splat(5.0)), Ok(2));
        assert_eq!(emitting(&s), [2, 3]);
        // Turning the shade off again keeps its reflectance.
        assert_eq!(s.set_emission("Shade", Rgb::BLACK), Ok(1));
        assert_eq!(emitting(&s), [2]);
        assert_eq!(s.material_of(PolygonId(3)).reflectance(), Rgb::splat(0.3));
    }

    #[test]
    fn an_unknown_name_lists_the_names_there_are() {
        let mut s = room();
        let before = s.clone();
        let e = s.set_emission("lamp", Rgb::splat(1.0)).unwrap_err();
        assert_eq!(s, before, "nothing changes");
        assert_eq!(e.objects, ["Room", "Lamp", "Shade"]);
        assert_eq!(
            e.to_string(),
            "no material, object or group is named `lamp`; the scene has materials \
             `white`, `shade`; objects `Room`, `Lamp`, `Shade`; group `fixtures`"
        );
        // A scene without objects and groups (.sc) speaks of materials only,
        // and long lists are cut short.
        let mut s = testutil::scene(
            vec![square(0, 0.0)],
            (0..20)
                .map(|i| material(&format!("m{i}"), 0.5, 0.0))
                .collect(),
        );
        let e = s.set_emission("x", Rgb::splat(1.0)).unwrap_err();
        let message = e.to_string();
        assert!(
            message.starts_with("no material is named `x`; the scene has materials `m0`, `m1`"),
            "{message}"
        );
        assert!(message.ends_with("`m11`, and 8 more"), "{message}");
    }

    #[test]
    fn lamp_names_are_recognised_by_parts_and_whole_words() {
        for lamp in [
            "Lamp",
            "Lamp.001",
            "CeilingLight",
            "light_bulb",
            "EMITTER",
            "Neon sign",
            "LED_strip",
            "spotLED",
            "Sun",
            "sun.002",
            "Candle",
            "Material.Emission",
        ] {
            assert!(looks_like_lamp(lamp), "{lamp}");
        }
        for other in ["Room", "tiled_floor", "Sunday", "Cube.001", "sled", "Wall"] {
            assert!(!looks_like_lamp(other), "{other}");
        }
    }

    #[test]
    fn the_warning_names_the_lamps_and_the_option() {
        let s = room();
        let w = s.nothing_emits_warning("room.obj").unwrap();
        assert_eq!(
            w.to_string(),
            "room.obj: warning: nothing emits light, so the picture will be black; \
             object `Lamp` looks like a lamp: make it emit with --emit NAME=VALUE \
             (radiosity in the scene's units, V or R,G,B), for instance --emit 'Lamp=10'; \
             or light it from all around with --sky VALUE (a sky of that radiosity)"
        );
        let mut two = room();
        two.materials[1].name = "Glow".to_string();
        let message = two.nothing_emits_warning("room.obj").unwrap().to_string();
        assert!(
            message.contains("object `Lamp`, material `Glow` look like lamps: make them emit"),
            "{message}"
        );
        let mut lit = room();
        lit.set_emission("Lamp", Rgb::splat(1.0)).unwrap();
        assert_eq!(lit.nothing_emits_warning("room.obj"), None);
        // A sky lights it too.
        let mut sky = room();
        sky.add_sky(Rgb::splat(1.0)).unwrap();
        assert_eq!(sky.nothing_emits_warning("room.obj"), None);
        // No hint: the option alone.
        let dark = testutil::scene(vec![square(0, 0.0)], vec![material("m", 0.5, 0.0)]);
        assert_eq!(dark.camera_source, CameraSource::File);
        let message = dark.nothing_emits_warning("a.sc").unwrap().to_string();
        assert!(
            message.ends_with(
                "black; make a material emit with --emit NAME=VALUE (radiosity in the \
                 scene's units, V or R,G,B); or light it from all around with --sky VALUE \
                 (a sky of that radiosity)"
            ),
            "{message}"
        );
    }

    #[test]
    fn obj_objects_and_groups_are_recorded_per_polygon() {
        let obj = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
f 2 3 4\n\
o Room\n\
f 1 2 3 4\n\
g walls fixtures\n\
v 0 1 0.5\n\
f 1 2 3 5\n\
o Camera\n\
o Lamp\n\
g fixtures\n\
v 0.5 0.5 2\n\
f 1 2 -1\n\
o Room\n\
g\n\
f 1 3 4\n";
        let read = |name: &str| Err(format!("no {name}"));
        let s = crate::scene::import::obj::parse_obj(obj, "m.obj", &read).unwrap();
        // The folded quad under `walls` became two triangles.
        assert_eq!(s.polygons.len(), 6);
        let listed: Vec<(GroupKind, &str, Vec<u32>)> = s
            .groups
            .iter()
            .map(|g| {
                let ids = g.polygons.iter().map(|p| p.0).collect();
                (g.kind, g.name.as_str(), ids)
            })
            .collect();
        assert_eq!(
            listed,
            vec![
                (GroupKind::Object, "Room", vec![1, 2, 3, 5]),
                (GroupKind::Group, "walls", vec![2, 3]),
                (GroupKind::Group, "fixtures", vec![2, 3, 4]),
                (GroupKind::Object, "Lamp", vec![4]),
            ]
        );
    }
}
