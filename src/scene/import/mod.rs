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

use crate::scene::{LoadError, Scene};
use input::InputSet;
use std::path::Path;

/// Reads and parses a scene file, by its extension in any case:
/// Wavefront OBJ (with its MTL libraries) for `.obj`, glTF 2.0 for
/// `.gltf` and `.glb`, else `.sc`. Errors carry the file name and the
/// line and column (for glTF, the JSON path). The files a model names
/// must lie inside its folder; [`load_into`] can allow otherwise.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_into(path, &InputSet::default())
}

/// [`load`], recording every file read (the scene, its material libraries,
/// textures and buffers) in `inputs`, whose
/// [`allow_outside_paths`](InputSet::allow_outside_paths) says whether a
/// model may name files outside its folder.
pub fn load_into(path: &Path, inputs: &InputSet) -> Result<Scene, LoadError> {
    let is = |ext: &str| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    if is("obj") {
        obj::load_obj(path, None, inputs)
    } else if is("gltf") || is("glb") {
        gltf::load_gltf(path, None, inputs)
    } else {
        sc::load_file(path, inputs)
    }
}
