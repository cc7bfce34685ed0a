//! Files to a [`Scene`]: the `.sc` format (`sc`), Wavefront OBJ with its
//! MTL libraries ([`obj`]), glTF 2.0 ([`gltf`]), and the files that go with
//! a scene: IES photometric data ([`ies`]) and measurement points
//! ([`points`]). [`load`] picks the reader by the file's extension.

pub mod gltf;
pub mod ies;
pub mod obj;
pub mod points;
pub(super) mod sc;
pub mod texture;

use crate::budget::MemoryBudget;
use crate::scene::{LoadError, Scene};
use std::path::Path;

/// Reads and parses a scene file, by its extension in any case:
/// Wavefront OBJ (with its MTL libraries) for `.obj`, glTF 2.0 for
/// `.gltf` and `.glb`, else `.sc`. Errors carry the file name and the
/// line and column (for glTF, the JSON path).
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_within(path, &MemoryBudget::for_machine())
}

/// [`load`] within the memory budget `budget`: OBJ and glTF files whose
/// geometry would take more are refused before it is built, and their
/// textures are decoded within it. (A `.sc` file's polygons are written
/// one by one, so its size bounds them.)
pub fn load_within(path: &Path, budget: &MemoryBudget) -> Result<Scene, LoadError> {
    let is = |ext: &str| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    if is("obj") {
        obj::load_obj_within(path, None, budget)
    } else if is("gltf") || is("glb") {
        gltf::load_gltf_within(path, None, budget)
    } else {
        sc::load_file(path)
    }
}
