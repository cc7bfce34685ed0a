//! [`MeshRef`]: a mesh either borrowed or shared, so that a solver can
//! work on the prepared mesh (borrowed from whoever built it) or on an
//! adaptive refinement that the solve session owns and hands to other
//! threads (the window draws it while the solver goes on).

use super::Mesh;
use std::ops::Deref;
use std::sync::Arc;

/// A read-only mesh, borrowed for `'a` or shared by reference count.
/// Cloning is cheap in both cases (a copy of the reference, or a count
/// increment), never a copy of the mesh.
#[derive(Clone, Debug)]
pub enum MeshRef<'a> {
    /// Borrowed from its owner, which outlives the user.
    Borrowed(&'a Mesh),
    /// Shared: lives as long as its last holder.
    Shared(Arc<Mesh>),
}

impl Deref for MeshRef<'_> {
    type Target = Mesh;

    fn deref(&self) -> &Mesh {
        match self {
            MeshRef::Borrowed(mesh) => mesh,
            MeshRef::Shared(mesh) => mesh,
        }
    }
}

impl<'a> From<&'a Mesh> for MeshRef<'a> {
    fn from(mesh: &'a Mesh) -> Self {
        MeshRef::Borrowed(mesh)
    }
}

impl From<Arc<Mesh>> for MeshRef<'_> {
    fn from(mesh: Arc<Mesh>) -> Self {
        MeshRef::Shared(mesh)
    }
}
