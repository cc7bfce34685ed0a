//! The glb container, glTF 2.0's binary format: a 12-byte header, then
//! chunks, of which the JSON chunk comes first and a BIN chunk may follow.

/// The chunks of a glb file.
pub(super) struct Glb<'a> {
    pub(super) json: &'a [u8],
    pub(super) bin: Option<&'a [u8]>,
}

/// A little-endian `u32` at `at`, if the bytes reach that far.
fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Splits a glb into its JSON and BIN chunks (unknown chunks are skipped,
/// as the specification says); errors give the byte offset.
pub(super) fn parse_glb(bytes: &[u8]) -> Result<Glb<'_>, String> {
    let at = |offset: usize, message: String| format!("glb, byte {offset}: {message}");
    let n = bytes.len();
    let (Some(version), Some(length)) = (u32_at(bytes, 4), u32_at(bytes, 8)) else {
        return Err(at(
            0,
            format!("the file has {n} bytes, less than a glb header (12)"),
        ));
    };
    if version != 2 {
        return Err(at(
            4,
            format!("glb version {version}; only glTF 2.0 is read"),
        ));
    }
    let length = length as usize;
    if length > n {
        return Err(at(
            8,
            format!("the header says {length} bytes but the file has {n} (truncated?)"),
        ));
    }
    let data = &bytes[..length];
    let mut chunks: Vec<(usize, u32, &[u8])> = Vec::new();
    let mut offset = 12;
    while offset < data.len() {
        let (Some(len), Some(kind)) = (u32_at(data, offset), u32_at(data, offset + 4)) else {
            return Err(at(offset, "a chunk header is cut off".to_string()));
        };
        let start = offset + 8;
        let Some(chunk) = start
            .checked_add(len as usize)
            .and_then(|end| data.get(start..end))
        else {
            return Err(at(
                offset,
                format!(
                    "a chunk of {len} bytes runs past the end of the file ({} bytes left)",
                    data.len() - start.min(data.len())
                ),
            ));
        };
        chunks.push((offset, kind, chunk));
        // Chunks are 4-byte aligned; a writer that did not pad is read
        // as written.
        offset = start + len as usize;
    }
    const JSON: u32 = 0x4E4F_534A;
    const BIN: u32 = 0x004E_4942;
    match chunks.first() {
        Some(&(_, JSON, json)) => Ok(Glb {
            json,
            bin: chunks.get(1).filter(|c| c.1 == BIN).map(|c| c.2),
        }),
        Some(&(offset, _, _)) => Err(at(offset, "the first chunk is not JSON".to_string())),
        None => Err(at(12, "the file has no JSON chunk".to_string())),
    }
}
