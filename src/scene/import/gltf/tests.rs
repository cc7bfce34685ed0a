use super::*;
use ::gltf::mesh::Mode;

#[test]
fn strips_and_fans_follow_the_specification() {
    let v = [10, 11, 12, 13, 14];
    assert_eq!(
        index_triangles(&v, Mode::TriangleStrip),
        [[10, 11, 12], [11, 13, 12], [12, 13, 14]]
    );
    assert_eq!(
        index_triangles(&v, Mode::TriangleFan),
        [[11, 12, 10], [12, 13, 10], [13, 14, 10]]
    );
    // A trailing partial triangle of a list is not a triangle.
    assert_eq!(index_triangles(&v, Mode::Triangles), [[10, 11, 12]]);
    assert!(index_triangles(&v[..2], Mode::TriangleStrip).is_empty());
    assert!(index_triangles(&v, Mode::Lines).is_empty());
}

fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut chunks = Vec::new();
    chunks.extend_from_slice(&(json.len() as u32).to_le_bytes());
    chunks.extend_from_slice(b"JSON");
    chunks.extend_from_slice(json);
    if let Some(bin) = bin {
        chunks.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        chunks.extend_from_slice(b"BIN\0");
        chunks.extend_from_slice(bin);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(12 + chunks.len() as u32).to_le_bytes());
    out.extend_from_slice(&chunks);
    out
}

#[test]
fn glb_chunks_are_split_and_every_fault_has_its_byte() {
    let ok = glb(b"{}  ", Some(&[1, 2, 3, 4]));
    let g = parse_glb(&ok).unwrap();
    assert_eq!((g.json, g.bin), (&b"{}  "[..], Some(&[1u8, 2, 3, 4][..])));
    assert_eq!(
        parse_glb(b"glTF\x02\0").err().unwrap(),
        "glb, byte 0: the file has 6 bytes, less than a glb header (12)"
    );
    let mut v1 = ok.clone();
    v1[4] = 1;
    assert_eq!(
        parse_glb(&v1).err().unwrap(),
        "glb, byte 4: glb version 1; only glTF 2.0 is read"
    );
    // A chunk longer than what follows it.
    let mut long = ok.clone();
    long[12] = 200;
    assert_eq!(
        parse_glb(&long).err().unwrap(),
        "glb, byte 12: a chunk of 200 bytes runs past the end of the file (16 bytes left)"
    );
    // A BIN chunk first.
    let mut swapped = ok.clone();
    swapped[16..20].copy_from_slice(b"BIN\0");
    assert_eq!(
        parse_glb(&swapped).err().unwrap(),
        "glb, byte 12: the first chunk is not JSON"
    );
    // A header length below the header's own.
    let mut short = ok;
    short[8] = 3;
    assert_eq!(
        parse_glb(&short).err().unwrap(),
        "glb, byte 12: the file has no JSON chunk"
    );
}

#[test]
fn uris_are_data_or_relative_paths() {
    let read = |name: &str| -> Result<Vec<u8>, String> {
        match name {
            "my model.bin" => Ok(vec![7]),
            other => Err(format!("no {other}")),
        }
    };
    assert_eq!(
        read_data_uri("data:application/octet-stream;base64,AQID", &read),
        Ok(vec![1, 2, 3])
    );
    assert_eq!(read_data_uri("my%20model.bin", &read), Ok(vec![7]));
    assert!(
        read_data_uri("data:application/octet-stream;base64,@@", &read)
            .unwrap_err()
            .starts_with("the `data:` URI's base64 is invalid")
    );
    assert_eq!(
        read_data_uri("https://example.com/m.bin", &read).unwrap_err(),
        "`https://example.com/m.bin` is not a relative path or a `data:` URI (nothing is \
         downloaded)"
    );
    assert_eq!(
        read_data_uri("data:text/plain,hello", &read).unwrap_err(),
        "a `data:` URI that is not base64"
    );
}

#[test]
fn indices_beyond_u32_are_refused_not_wrapped() {
    let no_uri = |_: &str| -> Result<Vec<u8>, String> { Err("no files".into()) };
    for (json, path) in [
        (
            r#"{"asset":{"version":"2.0"},"scene":4294967296,"scenes":[{"nodes":[]}]}"#,
            "scene",
        ),
        (
            r#"{"asset":{"version":"2.0"},"materials":[{},{}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":4294967297}]}]}"#,
            "meshes[0].primitives[0].material",
        ),
    ] {
        let e = parse_gltf(json.as_bytes(), "w.gltf", &no_uri).unwrap_err();
        let expected = format!("w.gltf: error: {path}: index ");
        assert!(e.to_string().contains(&expected), "{e}");
        assert!(e.to_string().contains("out of range"), "{e}");
    }
}
