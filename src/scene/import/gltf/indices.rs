//! glTF indices are checked before the `gltf` crate reads them: the crate
//! keeps an index in a `u32` and casts a larger JSON integer down, so
//! `"scene": 4294967296` would become scene 0 and material 4294967297
//! material 1. Every integer of the JSON above `u32::MAX` is refused with
//! its JSON path, but for the byte counts and element counts
//! (`byteLength`, `byteOffset`, `count`), which are not indices.

use serde_json::Value;

/// Keys whose integers are sizes, not indices.
const SIZES: [&str; 3] = ["byteLength", "byteOffset", "count"];

/// The JSON path (`materials[0].pbrMetallicRoughness.baseColorTexture.index`)
/// and the value of the first integer in `json` above `u32::MAX` that is
/// not a size; `None` when every index fits (or `json` is not JSON, which
/// the crate's own parse reports).
pub(super) fn first_wrapping_index(json: &[u8]) -> Option<(String, u64)> {
    let value: Value = serde_json::from_slice(json).ok()?;
    let mut path = String::new();
    find(&value, &mut path)
}

fn find(value: &Value, path: &mut String) -> Option<(String, u64)> {
    match value {
        Value::Number(n) => n
            .as_u64()
            .filter(|&n| n > u64::from(u32::MAX))
            .map(|n| (path.clone(), n)),
        Value::Array(items) => items.iter().enumerate().find_map(|(i, item)| {
            let len = path.len();
            path.push_str(&format!("[{i}]"));
            let found = find(item, path);
            path.truncate(len);
            found
        }),
        Value::Object(fields) => fields.iter().find_map(|(key, item)| {
            if SIZES.contains(&key.as_str()) {
                return None;
            }
            let len = path.len();
            if !path.is_empty() {
                path.push('.');
            }
            path.push_str(key);
            let found = find(item, path);
            path.truncate(len);
            found
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_above_u32_are_found_with_their_path() {
        assert_eq!(
            first_wrapping_index(br#"{"scene": 4294967296}"#),
            Some(("scene".to_string(), 4_294_967_296))
        );
        assert_eq!(
            first_wrapping_index(
                br#"{"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":4294967297}]}]}"#
            ),
            Some(("meshes[0].primitives[0].material".to_string(), 4_294_967_297))
        );
        assert_eq!(first_wrapping_index(br#"{"scene": 4294967295}"#), None);
        assert_eq!(
            first_wrapping_index(br#"{"buffers":[{"byteLength": 5000000000}]}"#),
            None
        );
    }
}
