//! Files to a [`Scene`]: the `.sc` format (`sc`), Wavefront OBJ with its
//! MTL libraries ([`obj`]), glTF 2.0 ([`gltf`]), and the files that go with
//! a scene: IES photometric data ([`ies`]) and measurement points
//! ([`points`]). [`load`] picks the reader by the file's extension.
//! Every file is opened through [`input`], which refuses what is not a
//! regular file, bounds the read and records what was read.

pub mod gltf;
pub mod ies;
pub mod input;
pub mod obj;
pub mod points;
pub(super) mod sc;
pub mod texture;

use crate::budget::MemoryBudget;
use crate::scene::{LoadError, Scene};
use input::InputSet;
use std::path::Path;

/// Reads and parses a scene file, by its extension in any case:
/// Wavefront OBJ (with its MTL libraries) for `.obj`, glTF 2.0 for
/// `.gltf` and `.glb`, else `.sc`. Errors carry the file name and the
/// line and column (for glTF, the JSON path). The files a model names
/// must lie inside its folder; [`load_with`] can allow otherwise.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with(path, &InputSet::default(), &MemoryBudget::for_machine())
}

/// [`load`], recording every file read (the scene, its material libraries,
/// textures and buffers) in `inputs`, whose
/// [`allow_outside_paths`](InputSet::allow_outside_paths) says whether a
/// model may name files outside its folder, within the memory budget
/// `budget`: OBJ and glTF files whose geometry would take more are refused
/// before it is built, and their textures are decoded within it. (A `.sc`
/// file's polygons are written one by one, so its size bounds them.)
pub fn load_with(
    path: &Path,
    inputs: &InputSet,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let is = |ext: &str| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    if is("obj") {
        obj::load_obj_with(path, None, inputs, budget)
    } else if is("gltf") || is("glb") {
        gltf::load_gltf_with(path, None, inputs, budget)
    } else {
        sc::load_file(path, inputs)
    }
}
