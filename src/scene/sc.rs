//! The `.sc` parser. (placeholder; being written)
use super::{LoadError, Scene};
use std::path::Path;

/// Parses `.sc` source text; `file` names it in diagnostics.
pub fn parse_str(_source: &str, _file: &str) -> Result<Scene, LoadError> {
    Err(LoadError {
        diagnostics: vec![],
    })
}

pub(crate) fn load_file(_path: &Path) -> Result<Scene, LoadError> {
    Err(LoadError {
        diagnostics: vec![],
    })
}
