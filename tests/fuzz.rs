//! Fuzzing the scene loaders inside `cargo test`.
//!
//! A deterministic mutator (seeded PRNG, no external engine) turns a seed
//! corpus — the bundled scenes, the regression cases in `tests/corpus/` and
//! small hand-written scenes — into a fixed number of hostile inputs: byte
//! flips, deleted, duplicated and spliced spans, swapped lines, truncations,
//! inserted keywords and absurd numbers (`1e30`, `nan`, `size 100000
//! 100000`, `scale 0.000001`, …), plus scenes generated from the grammar with
//! random (often extreme) values. Every input must:
//!
//! - never panic (a panic is caught and reported with the input);
//! - never hang: each parse runs under a watchdog and must finish in under
//!   [`PER_INPUT_LIMIT`] (a parse still running after that aborts the test
//!   binary, printing the input);
//! - if rejected, carry at least one diagnostic, each with the file name, a
//!   one-line message and a position inside the input;
//! - if accepted, satisfy every invariant the later stages rely on (valid
//!   polygons within the coordinate limits, materials with reflectance
//!   below one, a camera that makes a view, a mesh size that can be
//!   estimated).
//!
//! Each loader is a [`Target`] with its own test, so the targets run side
//! by side:
//!
//! - `sc`: the `.sc` parser;
//! - `obj`: the OBJ importer (its libraries named `lib.mtl` are a fixed
//!   Blender-style MTL), seeded with Blender, 3ds Max and MeshLab-style
//!   files (normals, texture coordinates, smoothing groups, CRLF);
//! - `mtl`: the MTL reader, through a fixed OBJ whose `mtllib` is the
//!   mutated MTL, seeded with the libraries those tools write;
//! - `gltf`: the glTF importer, on `.gltf` documents with embedded
//!   buffers and on `.glb` files. Most glb mutations change the JSON or
//!   binary chunk and write the container again with correct lengths, so
//!   that they reach the JSON and accessor checks rather than stop at the
//!   header; the rest mutate the raw bytes (truncations, flipped lengths).
//!
//! A rejection is located when each diagnostic names the input's file (or
//! the fixed file beside it) at a line and column inside it, or, for glTF,
//! has no line and starts with a JSON path (`meshes[0].primitives[1]...`),
//! a glb byte offset, or says the file has no triangles.
//!
//! `RADIOSITY_FUZZ_CASES` overrides the number of cases per target and
//! `RADIOSITY_FUZZ_SEED` the seed (to explore beyond the fixed CI run); a
//! failure prints the seed, the case number and the input, and saves the
//! input in the system's temporary directory so it can be added to
//! `tests/corpus/`.

mod common;
#[path = "support/gltf.rs"]
mod gltf_doc;

use common::Rng;
use radiosity::mesh::{self, MeshOptions};
use radiosity::render::View;
use radiosity::scene::import::{gltf, obj};
use radiosity::scene::{self, Diagnostic, Scene, MAX_COORDINATE};
use std::panic::{self, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Cases of the `.sc` target in the CI run: about 12 s on two cores in the
/// test profile (see `docs/reliability.md` for every target's time).
const SC_CASES: u64 = 300_000;

/// Cases of the OBJ target (each load also frames a camera).
const OBJ_CASES: u64 = 60_000;

/// Cases of the MTL target.
const MTL_CASES: u64 = 60_000;

/// Cases of the glTF target.
const GLTF_CASES: u64 = 60_000;

/// The fixed seed of the CI run.
const DEFAULT_SEED: u64 = 0x005e_ed0f_5c3e_u64;

/// Longest a single input may take to load.
const PER_INPUT_LIMIT: Duration = Duration::from_secs(1);

/// The file name the `.sc` parser sees, which its diagnostics must carry.
const FILE: &str = "fuzz.sc";

/// The file names the other targets' inputs are seen as.
const OBJ_FILE: &str = "fuzz.obj";
const MTL_FILE: &str = "fuzz.mtl";
const GLTF_FILE: &str = "fuzz.gltf";

/// A loader under test.
struct Target {
    /// Short name for messages and the corpus folder.
    name: &'static str,
    /// File extensions of its inputs in the corpus.
    extensions: &'static [&'static str],
    /// The name the input is loaded as, which diagnostics about it carry.
    file: &'static str,
    /// Fixed files loaded beside the input (name, text), which
    /// diagnostics may name instead.
    fixed: &'static [(&'static str, &'static str)],
    /// Whether a diagnostic may have no line, locating itself by a JSON
    /// path or byte offset in its message (glTF).
    json_paths: bool,
    /// Cases in the CI run.
    cases: u64,
    /// Loads bytes.
    load: fn(&[u8]) -> Result<Scene, Vec<Diagnostic>>,
    /// Seed inputs besides the corpus directory.
    seeds: fn() -> Vec<Vec<u8>>,
    /// Generates a random input from the grammar.
    generate: fn(&mut Rng) -> Vec<u8>,
    /// Mutates an input (given another input to splice from and the
    /// dictionary).
    mutate: fn(&mut Rng, &mut Vec<u8>, &[u8], &[&str]),
    /// Tokens worth inserting.
    dictionary: Vec<&'static str>,
}

fn targets() -> Vec<Target> {
    vec![
        Target {
            name: "sc",
            extensions: &["sc"],
            file: FILE,
            fixed: &[],
            json_paths: false,
            cases: SC_CASES,
            load: |b| scene::parse_bytes(b, FILE).map_err(|e| e.diagnostics),
            seeds: sc_seeds,
            generate: generate_sc,
            mutate,
            // The parser's keywords, then malformed and extreme fragments.
            dictionary: scene::KEYWORDS
                .iter()
                .chain(SC_FRAGMENTS)
                .copied()
                .collect(),
        },
        Target {
            name: "obj",
            extensions: &["obj"],
            file: OBJ_FILE,
            fixed: &[("lib.mtl", FIXED_MTL)],
            json_paths: false,
            cases: OBJ_CASES,
            load: |b| {
                let read = |name: &str| match name {
                    "lib.mtl" => Ok(("lib.mtl".to_string(), FIXED_MTL.to_string())),
                    other => Err(format!("cannot read material library {other}: not found")),
                };
                let text = String::from_utf8_lossy(b);
                obj::parse_obj(&text, OBJ_FILE, &read).map_err(|e| e.diagnostics)
            },
            seeds: obj_seeds,
            generate: generate_obj,
            mutate,
            dictionary: OBJ_FRAGMENTS.to_vec(),
        },
        Target {
            name: "mtl",
            extensions: &["mtl"],
            file: MTL_FILE,
            fixed: &[(OBJ_FILE, FIXED_OBJ)],
            json_paths: false,
            cases: MTL_CASES,
            load: |b| {
                let text = String::from_utf8_lossy(b).into_owned();
                let read = |name: &str| match name {
                    MTL_FILE => Ok((MTL_FILE.to_string(), text.clone())),
                    other => Err(format!("cannot read material library {other}: not found")),
                };
                obj::parse_obj(FIXED_OBJ, OBJ_FILE, &read).map_err(|e| e.diagnostics)
            },
            seeds: mtl_seeds,
            generate: generate_mtl,
            mutate,
            dictionary: MTL_FRAGMENTS.to_vec(),
        },
        Target {
            name: "gltf",
            extensions: &["gltf", "glb"],
            file: GLTF_FILE,
            fixed: &[],
            json_paths: true,
            cases: GLTF_CASES,
            load: |b| {
                let no_files = |name: &str| Err(format!("cannot read {name}: not found"));
                gltf::parse_gltf(b, GLTF_FILE, &no_files).map_err(|e| e.diagnostics)
            },
            seeds: gltf_seeds,
            generate: generate_gltf,
            mutate: mutate_gltf,
            dictionary: GLTF_FRAGMENTS.to_vec(),
        },
    ]
}

// ------------------------------------------------------------------ rng --

/// The fuzzer's own draws on top of the shared SplitMix64 generator.
impl Rng {
    /// Mostly a number in `lo..hi`, sometimes anything ([`Rng::number`]).
    fn sane(&mut self, lo: f64, hi: f64) -> String {
        if self.chance(85) {
            let x = lo + (hi - lo) * (self.next() as f64 / u64::MAX as f64);
            format!("{x:.3}")
        } else {
            self.number()
        }
    }

    /// A number as a scene file would write it: mostly ordinary, sometimes
    /// absurd.
    fn number(&mut self) -> String {
        if self.chance(15) {
            return self.pick(INTERESTING_NUMBERS).to_string();
        }
        let magnitude = match self.below(4) {
            0 => 1.0,
            1 => 10.0,
            2 => 0.01,
            _ => 1000.0,
        };
        let x = (self.next() as f64 / u64::MAX as f64 * 2.0 - 1.0) * magnitude;
        if self.chance(30) {
            format!("{}", x.round())
        } else {
            format!("{x:.3}")
        }
    }
}

// ------------------------------------------------------------- the .sc --

const INTERESTING_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    ".5",
    "5.",
    "1e30",
    "-1e30",
    "1e12",
    "1.0000001e12",
    "1e-9",
    "1e-12",
    "1e-30",
    "1e-320",
    "3.4e38",
    "3.5e38",
    "1e308",
    "1e999",
    "0.000001",
    "1000000",
    "100000",
    "65536",
    "65537",
    "8192",
    "8193",
    "4294967295",
    "4294967296",
    "179.9999999",
    "180",
    "1e-45",
    "0.9999999",
    "nan",
    "-inf",
    "0x10",
    "1e",
    "--1",
    "99999999999999999999999999999999999999999",
];

const SC_FRAGMENTS: &[&str] = &[
    "scale 0.000001",
    "scale 1e300",
    "scale 1 0.000001 1",
    "rotate 0 0 0 90",
    "rotate 1 1 1 1e300",
    "size 100000 100000",
    "size 65536 65536",
    "size 0 1",
    "vertex 1e30 0 0",
    "vertex 0 0 0",
    "translate 1e12 1e12 1e12",
    "box m 0 0 0 1 1 1",
    "box m 0 0 0 1e-10 1e-10 1e-10",
    "material m color 1 1 1 k_diffrefl 0.5 end",
    "material l k_emission 1e308 end",
    "polygon m vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end",
    "polygon m vertex 0 0 0 vertex 1 0 0 vertex 1 0 0 end",
    "polygon m vertex 0 0 0 vertex 1e-12 0 0 vertex 0 1e-12 0 end",
    "transform",
    "transform transform transform",
    "#",
    "# comment\n",
    "\n",
    "\r\n",
    "\t",
    " ",
    "\u{feff}",
    "é",
    "\u{2028}",
    "\0",
    "m",
    "nan",
    "inf",
    "_",
];

/// Small scenes that reach the deep checks quickly.
fn sc_seeds() -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = ["rtable.sc", "cornell.sc", "table_chair.sc"]
        .iter()
        .map(|n| std::fs::read(common::scene(n)).expect("bundled scene"))
        .collect();
    seeds.extend(
        [
            "material m color 1 1 1 k_diffrefl 0.5 end\n\
             material l color 1 1 1 k_emission 1 end\n\
             polygon l vertex 0 1 0 vertex 1 1 0 vertex 1 1 1 vertex 0 1 1 end\n\
             box m -1 -1 -1 2 0 2\n",
            "camera eye 0 0 -5 lookat 0 0 0 up 0 1 0 fov 60 size 64 48 end\n\
             material m k_diffrefl 0.5 k_emission 0.1 end\n\
             transform translate 1 2 3 rotate 0 1 0 30 scale 2 \n\
               polygon m vertex 0 0 0 vertex 1 0 0 vertex 1.5 1 0 vertex 0.5 1.5 0 vertex -0.5 1 0 end\n\
             end\n",
            "material m k_diffrefl 0.3 end\n\
             transform scale 0.000001\n  transform scale 0.000001\n    box m 0 0 0 1 1 1\n  end\nend\n",
            "material m k_diffrefl 0.3 end\nbox m 0 0 0 1e11 1e11 1e11\n",
        ]
        .iter()
        .map(|s| s.as_bytes().to_vec()),
    );
    seeds
}

/// A scene from the grammar with random values: mostly well-formed, so the
/// geometric and numeric checks behind the syntax get exercised.
fn generate_sc(rng: &mut Rng) -> Vec<u8> {
    let mut s = String::new();
    let mut materials = Vec::new();
    if rng.chance(50) {
        s += "camera\n";
        for field in ["eye", "lookat", "up"] {
            if rng.chance(85) {
                s += &format!(
                    "  {field} {} {} {}\n",
                    rng.number(),
                    rng.number(),
                    rng.number()
                );
            }
        }
        if rng.chance(50) {
            s += &format!("  fov {}\n", rng.sane(1.0, 179.0));
        }
        if rng.chance(50) {
            s += &format!(
                "  size {} {}\n",
                rng.pick(INTERESTING_NUMBERS),
                rng.pick(&["1", "480", "8192", "100000", "65536"])
            );
        }
        s += "end\n";
    }
    for k in 0..1 + rng.below(3) {
        let name = format!("m{k}");
        s += &format!("material {name}\n");
        if rng.chance(70) {
            s += &format!(
                "  color {} {} {}\n",
                rng.sane(0.0, 1.0),
                rng.sane(0.0, 1.0),
                rng.sane(0.0, 1.0)
            );
        }
        s += &format!("  k_diffrefl {}\n", rng.sane(0.0, 0.99));
        if rng.chance(40) {
            s += &format!("  k_emission {}\n", rng.sane(0.0, 10.0));
        }
        s += "end\n";
        materials.push(name);
    }
    let mut depth = 0;
    for _ in 0..1 + rng.below(6) {
        match rng.below(6) {
            0 => {
                s += "transform\n";
                depth += 1;
                for _ in 0..1 + rng.below(3) {
                    s += &match rng.below(3) {
                        0 => format!(
                            "  translate {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                        1 => format!(
                            "  rotate {} {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                        _ if rng.chance(50) => format!("  scale {}\n", rng.number()),
                        _ => format!(
                            "  scale {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                    };
                }
            }
            1 if depth > 0 => {
                s += "end\n";
                depth -= 1;
            }
            2 => {
                s += &format!("box {}", rng.pick(&materials));
                for _ in 0..6 {
                    s += &format!(" {}", rng.number());
                }
                s += "\n";
            }
            _ => {
                // A regular polygon (convex, planar) in a random plane, or
                // random vertices.
                s += &format!("polygon {}\n", rng.pick(&materials));
                let n = 3 + rng.below(6);
                let regular = rng.chance(70);
                let radius: f64 = rng.number().parse().unwrap_or(1.0);
                for i in 0..n {
                    if regular {
                        let a = i as f64 / n as f64 * std::f64::consts::TAU;
                        s += &format!("  vertex {} {} 0\n", radius * a.cos(), radius * a.sin());
                    } else {
                        s += &format!(
                            "  vertex {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        );
                    }
                }
                s += "end\n";
            }
        }
    }
    for _ in 0..depth {
        if rng.chance(90) {
            s += "end\n";
        }
    }
    s.into_bytes()
}

// ------------------------------------------------------- OBJ and MTL --

/// The library every `mtllib lib.mtl` of the OBJ target reads: as
/// Blender writes it, with a lamp, a white of `Kd 1` and a glossy one.
const FIXED_MTL: &str = "# Blender MTL File: 'room.blend'\n# Material Count: 3\n\n\
newmtl Material\nNs 225.000000\nKa 1.000000 1.000000 1.000000\nKd 0.800000 0.800000 0.800000\n\
Ks 0.500000 0.500000 0.500000\nKe 0.000000 0.000000 0.000000\nNi 1.450000\nd 1.000000\nillum 2\n\n\
newmtl white\nKd 1.000000 1.000000 1.000000\n\nnewmtl light\nKd 0.5 0.5 0.5\nKe 10 10 10\n";

/// The OBJ the MTL target loads its input through: it names the
/// materials the MTL seeds define, and one they do not.
const FIXED_OBJ: &str = "# Blender v3.4.1 OBJ File: ''\nmtllib fuzz.mtl\no Room\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nvn 0 0 1\n\
usemtl Material\nf 1//1 2//1 3//1 4//1\nusemtl white\nf 1 2 6 5\nusemtl light\nf 1 3 4\n\
usemtl wire\nf 2 3 6\nusemtl m0\nf 1 2 3\nusemtl Default_OBJ\nf 3 4 1\n";

const OBJ_FRAGMENTS: &[&str] = &[
    "v",
    "vt",
    "vn",
    "f",
    "l",
    "p",
    "o",
    "g",
    "s",
    "s off",
    "s 1",
    "usemtl",
    "mtllib",
    "usemtl white",
    "usemtl light",
    "usemtl nope",
    "mtllib lib.mtl",
    "mtllib missing.mtl",
    "mtllib lib.mtl other.mtl",
    "mtllib sub\\lib.mtl",
    "f 1 2 3",
    "f 1/1/1 2/2/1 3/3/1",
    "f 1//1 2//1 3//1",
    "f -1 -2 -3",
    "f 1 2 3 4 5 6",
    "f 1 1 1",
    "f 0 1 2",
    "f 1/ 2/ 3/",
    "f 99999999999 1 2",
    "v 1e30 0 0",
    "v nan 0 0",
    "v 0 0 0 1",
    "v 1 2 3 0.5 0.5 0.5",
    "vt 0.5 0.5",
    "vn 0 0 1",
    "o Lamp",
    "g walls fixtures",
    "l 1 2 3",
    "#",
    "\r\n",
    "\n",
    "\t",
    "\\\n",
    "\u{feff}",
    "é",
    "\0",
];

const MTL_FRAGMENTS: &[&str] = &[
    "newmtl",
    "newmtl Material",
    "newmtl white",
    "newmtl light",
    "newmtl m0",
    "Kd",
    "Ke",
    "Ks",
    "Ka",
    "Ns",
    "Ni",
    "d",
    "Tr",
    "Tf",
    "illum",
    "Pm",
    "Pr",
    "map_Kd",
    "map_Ks",
    "map_Bump",
    "Kd 1 1 1",
    "Kd 0.5",
    "Kd -1 0 0",
    "Kd spectral x.spd",
    "Kd xyz 1 1 1",
    "Ke 1e30 0 0",
    "Ke 1e400 1 1",
    "Kd 1e-320 0 0",
    "illum 7",
    "illum 99999999999999",
    "d 0",
    "Tr 1",
    "Ni 1.5",
    "Pm 1",
    "Pr 0",
    "map_Kd -s 1 1 1 tex.png",
    "map_Kd -bm",
    "map_Kd tex\\wall.png",
    "map_Kd -o 1 map.jpg",
    "#",
    "\r\n",
    "\n",
    "\t",
    "\u{feff}",
    "é",
];

/// OBJ files as real tools write them.
fn obj_seeds() -> Vec<Vec<u8>> {
    [
        // Blender 2.8+: header, mtllib, objects, texture coordinates,
        // normals, smoothing off, quads.
        "# Blender v2.93.0 OBJ File: ''\n# www.blender.org\nmtllib lib.mtl\no Cube\n\
         v 1.000000 1.000000 -1.000000\nv 1.000000 -1.000000 -1.000000\nv 1.000000 1.000000 1.000000\n\
         v 1.000000 -1.000000 1.000000\nv -1.000000 1.000000 -1.000000\nv -1.000000 -1.000000 -1.000000\n\
         v -1.000000 1.000000 1.000000\nv -1.000000 -1.000000 1.000000\n\
         vt 0.625000 0.500000\nvt 0.875000 0.500000\nvt 0.875000 0.750000\nvt 0.625000 0.750000\n\
         vn 0.0000 1.0000 0.0000\nvn 0.0000 0.0000 1.0000\nvn -1.0000 0.0000 0.0000\n\
         usemtl Material\ns off\nf 1/1/1 5/2/1 7/3/1 3/4/1\nf 4/1/2 3/2/2 7/3/2 8/4/2\n\
         f 8/1/3 7/2/3 5/3/3 6/4/3\nusemtl light\nf 6/1/1 2/2/1 4/3/1 8/4/1\n",
        // A smooth icosphere fragment: `s 1`, shared normals, triangles.
        "# Blender v3.4.1 OBJ File: ''\nmtllib lib.mtl\no Icosphere\n\
         v 0.000000 -1.000000 0.000000\nv 0.723607 -0.447220 0.525725\nv -0.276388 -0.447220 0.850649\n\
         v -0.894426 -0.447216 0.000000\nv -0.276388 -0.447220 -0.850649\nv 0.723607 -0.447220 -0.525725\n\
         vn 0.0000 -1.0000 0.0000\nvn 0.7236 -0.4472 0.5257\nvn -0.2764 -0.4472 0.8506\n\
         vn -0.8944 -0.4472 0.0000\nvn -0.2764 -0.4472 -0.8506\nvn 0.7236 -0.4472 -0.5257\n\
         usemtl white\ns 1\nf 1//1 2//2 3//3\nf 1//1 3//3 4//4\nf 1//1 4//4 5//5\nf 1//1 5//5 6//6\n\
         f 1//1 6//6 2//2\n",
        // 3ds Max: groups, CRLF, a degenerate face at a UV seam.
        "# 3ds Max Wavefront OBJ Exporter v0.97b - (c)2007 guruware\r\n\
         mtllib lib.mtl\r\n\r\n#\r\n# object Box001\r\n#\r\n\r\n\
         v  -10.0 0.0 10.0\r\nv  10.0 0.0 10.0\r\nv  -10.0 0.0 -10.0\r\nv  10.0 0.0 -10.0\r\n\
         v  -10.0 20.0 10.0\r\n# 5 vertices\r\n\r\n\
         vt 0.0 0.0 0.0\r\nvt 1.0 0.0 0.0\r\n# 2 texture coords\r\n\r\n\
         g Box001\r\nusemtl white\r\ns 2\r\nf 1/1 3/2 4/1 \r\nf 4/1 2/2 1/1 \r\nf 1/1 1/1 5/2 \r\n\
         s 4\r\nf 1/1 2/2 5/1 \r\n# 4 faces\r\n",
        // MeshLab: vertex colours, no materials, negative indices.
        "####\n#\n# OBJ File Generated by Meshlab\n#\n####\n# Object room.obj\n#\n\
         # Vertices: 4\n# Faces: 2\n#\n####\nv 0.000000 0.000000 0.000000 0.5 0.5 0.5\n\
         v 4.000000 0.000000 0.000000 0.5 0.5 0.5\nv 4.000000 0.000000 4.000000 0.5 0.5 0.5\n\
         v 0.000000 0.000000 4.000000 0.5 0.5 0.5\nf -4 -2 -3\nf -4 -1 -2\n# 2 faces, 0 coords texture\n\
         \n# End of File\n",
        // A hand-written course file: a lamp under a non-convex floor.
        "# simple room\nmtllib lib.mtl missing.mtl\nv 0 0 0\nv 2 0 0\nv 2 0 2\nv 1 0 1\nv 0 0 2\n\
         v 0.5 1.9 0.5\nv 1.5 1.9 0.5\nv 1.5 1.9 1.5\nv 0.5 1.9 1.5\n\
         g floor\nusemtl Material\nf 1 5 4 3 2\ng lamp\nusemtl light\nf 6 7 8 9\nusemtl undefined\nl 1 2\n",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

/// An OBJ from the grammar with random values.
fn generate_obj(rng: &mut Rng) -> Vec<u8> {
    let mut s = String::new();
    if rng.chance(70) {
        s += "mtllib lib.mtl\n";
    }
    let n = 3 + rng.below(8);
    for _ in 0..n {
        s += &format!(
            "v {} {} {}\n",
            rng.sane(-5.0, 5.0),
            rng.sane(-5.0, 5.0),
            rng.sane(-5.0, 5.0)
        );
    }
    if rng.chance(40) {
        s += "vn 0 0 1\nvt 0 0\n";
    }
    for _ in 0..1 + rng.below(6) {
        match rng.below(8) {
            0 => s += &format!("o {}\n", rng.pick(&["Lamp", "Room", "Cube.001", ""])),
            1 => s += &format!("g {}\n", rng.pick(&["walls", "a b", "Light", ""])),
            2 => {
                s += &format!(
                    "usemtl {}\n",
                    rng.pick(&["white", "light", "Material", "x"])
                )
            }
            3 => s += &format!("s {}\n", rng.pick(&["off", "1", "2", "0"])),
            _ => {
                let k = 3 + rng.below(4);
                s += "f";
                for _ in 0..k {
                    let i = if rng.chance(90) {
                        (1 + rng.below(n)) as i64
                    } else {
                        rng.next() as i64 % (2 * n as i64 + 2) - n as i64
                    };
                    s += &match rng.below(3) {
                        0 => format!(" {i}"),
                        1 => format!(" {i}//1"),
                        _ => format!(" {i}/1/1"),
                    };
                }
                s += if rng.chance(10) { "\r\n" } else { "\n" };
            }
        }
    }
    s.into_bytes()
}

/// MTL libraries as real tools write them.
fn mtl_seeds() -> Vec<Vec<u8>> {
    [
        FIXED_MTL,
        // 3ds Max: tabs, Ka/Kd/Ks/Tf, texture options, CRLF.
        "# 3ds Max Wavefront OBJ Exporter v0.97b - (c)2007 guruware\r\n\
         newmtl white\r\n\tNs 10.0000\r\n\tNi 1.5000\r\n\td 1.0000\r\n\tTr 0.0000\r\n\
         \tTf 1.0000 1.0000 1.0000 \r\n\tillum 2\r\n\tKa 0.5880 0.5880 0.5880\r\n\
         \tKd 0.5880 0.5880 0.5880\r\n\tKs 0.0000 0.0000 0.0000\r\n\tKe 0.0000 0.0000 0.0000\r\n\
         \tmap_Ka -s 1 1 1 maps\\wall.jpg\r\n\tmap_Kd maps\\wall.jpg\r\n\
         newmtl light\r\n\tKd 0.0 0.0 0.0\r\n\tKe 20 18 15\r\n",
        // McGuire's Cornell box style.
        "newmtl leftWall\nKa 0.63 0.065 0.05\nKd 0.63 0.065 0.05\nKs 0 0 0\n\n\
         newmtl light\nKa 0.78 0.78 0.78\nKd 0.78 0.78 0.78\nKs 0 0 0\nKe 17 12 4\n\n\
         newmtl Material\nKd 0.725 0.71 0.68\n",
        // Blender PBR extensions, glass and metal.
        "newmtl Material\nPr 0.5\nPm 1.0\nKd 0.8 0.8 0.8\nd 0.5\nillum 7\nNi 1.45\n\
         newmtl m0\nKd 1.2 0.6 0.3\nmap_Kd -bm 0.5 -o 0 0 0 tex.png\n",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

/// An MTL from the grammar with random values.
fn generate_mtl(rng: &mut Rng) -> Vec<u8> {
    let mut s = String::new();
    for _ in 0..1 + rng.below(3) {
        s += &format!(
            "newmtl {}\n",
            rng.pick(&["Material", "white", "light", "m0", "wire"])
        );
        for _ in 0..rng.below(6) {
            let key = *rng.pick(&["Kd", "Ke", "Ks", "Ka", "d", "Tr", "Ni", "illum", "Pm", "Pr"]);
            let values = if matches!(key, "Kd" | "Ke" | "Ks" | "Ka") && rng.chance(80) {
                format!(
                    "{} {} {}",
                    rng.sane(0.0, 1.2),
                    rng.sane(0.0, 1.2),
                    rng.sane(0.0, 1.2)
                )
            } else {
                rng.sane(0.0, 10.0)
            };
            s += &format!("{key} {values}\n");
        }
    }
    s.into_bytes()
}

// -------------------------------------------------------------- glTF --

const GLTF_FRAGMENTS: &[&str] = &[
    "0", "1", "-1", "4294967295", "4294967296", "1e39", "-1e39", "null", "true", "[]", "{}",
    "\"\"", ",", ":", "[", "]", "{", "}", "\"mode\": 0,", "\"mode\": 5,", "\"mode\": 6,",
    "\"mode\": 7,", "\"count\": 4294967295,", "\"count\": 0,", "\"byteOffset\": 4294967295,",
    "\"byteStride\": 4,", "\"byteStride\": 252,", "\"componentType\": 5121,",
    "\"componentType\": 5123,", "\"componentType\": 5126,", "\"componentType\": 5127,",
    "\"type\": \"VEC2\",", "\"type\": \"MAT4\",", "\"indices\": 0,", "\"indices\": 99,",
    "\"material\": 0,", "\"material\": 99,", "\"mesh\": 0,", "\"camera\": 0,",
    "\"children\": [0],", "\"children\": [1, 1],", "\"scale\": [0, 0, 0],",
    "\"scale\": [-1, 1, 1],", "\"rotation\": [0, 0, 0, 0],", "\"rotation\": [1e30, 0, 0, 1],",
    "\"translation\": [1e30, 0, 0],", "\"matrix\": [0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0],",
    "\"doubleSided\": true,", "\"emissiveFactor\": [1e30, 1, 1],",
    "\"emissiveFactor\": [-1, 0, 0],", "\"baseColorFactor\": [2, 2, 2, 1],",
    "\"metallicFactor\": 1,", "\"yfov\": 0,", "\"yfov\": 3.2,", "\"aspectRatio\": 0,",
    "\"aspectRatio\": 1e9,", "\"uri\": \"missing.bin\",", "\"uri\": \"data:;base64,AAAA\",",
    "\"uri\": \"data:application/octet-stream;base64,@@\",", "\"uri\": \"http://x/y.bin\",",
    "\"uri\": \"%ff.bin\",", "\"scene\": 5,", "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"],",
    "\"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 0, \"componentType\": 5125}, \"values\": {\"bufferView\": 0}},",
    "\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 1e30}",
];

/// A glTF document from the grammar: a few nodes (some nested, some
/// with extreme transforms), meshes of every primitive mode, materials,
/// cameras and lights; as a glb or a `.gltf` with its buffer embedded.
fn random_doc(rng: &mut Rng) -> gltf_doc::Doc {
    use serde_json::json;
    let mut d = gltf_doc::Doc::new();
    let num = |rng: &mut Rng, lo: f64, hi: f64| -> f64 { rng.sane(lo, hi).parse().unwrap_or(1.0) };
    let materials = rng.below(3);
    for k in 0..materials {
        let c = [
            num(rng, 0.0, 1.2),
            num(rng, 0.0, 1.0),
            num(rng, 0.0, 1.0),
            1.0,
        ];
        let mut m =
            json!({"name": format!("m{k}"), "pbrMetallicRoughness": {"baseColorFactor": c}});
        if rng.chance(40) {
            m["emissiveFactor"] = json!([num(rng, 0.0, 2.0), 1.0, 1.0]);
        }
        if rng.chance(30) {
            m["doubleSided"] = json!(true);
        }
        d.material(m);
    }
    let meshes = 1 + rng.below(3);
    for k in 0..meshes {
        let mut prims = Vec::new();
        for _ in 0..1 + rng.below(2) {
            let n = 3 + rng.below(6);
            let values: Vec<f32> = (0..n * 3)
                .map(|i| {
                    if rng.chance(5) {
                        num(rng, -1e3, 1e3) as f32
                    } else if i % 3 == 2 {
                        0.0
                    } else {
                        (rng.below(5) as f32) * 0.5
                    }
                })
                .collect();
            let pos = d.floats(&values, "VEC3");
            let mut p = json!({"attributes": {"POSITION": pos}});
            if rng.chance(60) {
                let idx: Vec<u16> = (0..3 * (1 + rng.below(4)))
                    .map(|_| {
                        if rng.chance(97) {
                            rng.below(n) as u16
                        } else {
                            rng.below(3 * n) as u16
                        }
                    })
                    .collect();
                p["indices"] = json!(d.indices(&idx));
                if rng.chance(50) {
                    p["attributes"]["NORMAL"] = json!(pos);
                }
            }
            if rng.chance(30) {
                p["mode"] = json!(rng.below(7));
            }
            if materials > 0 && rng.chance(80) {
                p["material"] = json!(rng.below(materials));
            }
            prims.push(p);
        }
        d.mesh(&format!("Mesh{k}"), prims);
    }
    let nodes = 1 + rng.below(4);
    for k in 0..nodes {
        let mut node = json!({"name": format!("Node{k}")});
        if rng.chance(85) {
            node["mesh"] = json!(rng.below(meshes));
        }
        match rng.below(4) {
            0 => node["translation"] = json!([num(rng, -5.0, 5.0), num(rng, -5.0, 5.0), 0.0]),
            1 => node["rotation"] = json!([0.0, num(rng, -1.0, 1.0), 0.0, num(rng, -1.0, 1.0)]),
            2 => node["scale"] = json!([num(rng, -2.0, 2.0), num(rng, 0.0, 2.0), 1.0]),
            _ => {}
        }
        if k + 1 < nodes && rng.chance(30) {
            node["children"] = json!([k + 1]);
        }
        d.node(node);
    }
    if rng.chance(30) {
        d.json["cameras"] = json!([{"type": "perspective", "perspective": {
            "yfov": num(rng, 0.1, 3.0), "aspectRatio": num(rng, 0.5, 2.0), "znear": 0.1}}]);
        let cam = d.node(json!({"camera": 0, "translation": [0.0, 0.0, num(rng, -5.0, 5.0)]}));
        let _ = cam;
    }
    if rng.chance(15) {
        d.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        d.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "point"}]}});
        d.node(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}}));
    }
    let total = d.json["nodes"].as_array().map_or(0, Vec::len);
    // Roots: the nodes no earlier node lists as a child.
    let roots: Vec<usize> = (0..total)
        .filter(|&i| {
            !d.json["nodes"].as_array().into_iter().flatten().any(|n| {
                n["children"]
                    .as_array()
                    .is_some_and(|c| c.iter().any(|x| x.as_u64() == Some(i as u64)))
            })
        })
        .collect();
    d.scene(&roots);
    d
}

fn generate_gltf(rng: &mut Rng) -> Vec<u8> {
    let d = random_doc(rng);
    if rng.chance(50) {
        d.glb()
    } else {
        d.gltf()
    }
}

/// Documents as exporters write them: Blender-style nodes with
/// transforms, a textured and an emissive material, a camera and a light;
/// strips and fans; a sparse accessor.
fn gltf_seeds() -> Vec<Vec<u8>> {
    use serde_json::json;
    let mut d = gltf_doc::Doc::new();
    let tex = gltf_doc::png_data_uri(2, &[[200, 180, 160], [20, 40, 60]]);
    d.json["images"] = json!([{"uri": tex}]);
    d.json["textures"] = json!([{"source": 0}]);
    let wall = d.material(json!({"name": "Wall", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}));
    let lamp = d.material(
        json!({"name": "Emission", "emissiveFactor": [1.0, 0.9, 0.8],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5.0}}}),
    );
    let a = d.square(Some(wall), true);
    let b = d.square(Some(lamp), false);
    let room = d.mesh("Plane", vec![a]);
    let light = d.mesh("Lamp", vec![b]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let n0 = d.node(json!({"name": "Floor", "mesh": room, "rotation": [-s, 0.0, 0.0, s], "scale": [3.0, 3.0, 3.0]}));
    let n1 = d.node(json!({"name": "Lamp", "mesh": light, "translation": [0.0, 2.0, 0.0], "rotation": [s, 0.0, 0.0, s]}));
    let n2 = d.node(json!({"name": "Camera", "camera": 0, "translation": [1.5, 1.0, 5.0]}));
    let n3 = d.node(json!({"name": "Light", "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    let parent = d.node(json!({"name": "Collection", "children": [n0, n1],
        "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0.5,0,1]}));
    d.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.7778, "znear": 0.1, "zfar": 100}}]);
    d.json["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_emissive_strength"]);
    d.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"name": "Light", "type": "point", "intensity": 1000}]}});
    d.scene(&[parent, n2, n3]);
    let mut seeds = vec![d.glb(), d.gltf()];

    let mut e = gltf_doc::Doc::new();
    let strip = e.floats(
        &[0., 0., 0., 0., 1., 0., 1., 0., 0., 1., 1., 0., 2., 0., 0.],
        "VEC3",
    );
    let fan = e.floats(&[0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1., 1.], "VEC3");
    let idx = e.indices(&[0, 1, 2, 3]);
    // A sparse copy of the strip moving one vertex up.
    let sparse_idx = e.view(&1u32.to_le_bytes());
    let sparse_val = e.view(&[0f32, 2.0, 0.0].map(f32::to_le_bytes).concat());
    let mut acc = e.json["accessors"][strip].clone();
    acc["sparse"] = json!({"count": 1, "indices": {"bufferView": sparse_idx, "componentType": 5125},
        "values": {"bufferView": sparse_val}});
    e.json["accessors"]
        .as_array_mut()
        .expect("accessors")
        .push(acc);
    let sparse = e.json["accessors"].as_array().map_or(0, Vec::len) - 1;
    let m = e.mesh(
        "Strips",
        vec![
            json!({"attributes": {"POSITION": strip}, "mode": 5}),
            json!({"attributes": {"POSITION": fan}, "indices": idx, "mode": 6}),
            json!({"attributes": {"POSITION": sparse}, "mode": 4}),
            json!({"attributes": {"POSITION": fan}, "mode": 1}),
        ],
    );
    let n = e.node(json!({"mesh": m}));
    e.scene(&[n]);
    seeds.push(e.glb());
    seeds.push(e.gltf());
    seeds
}

/// The chunks of a glb as written, leniently: `None` unless it has a
/// JSON chunk whose length fits.
fn glb_chunks(bytes: &[u8]) -> Option<(Vec<u8>, Vec<u8>)> {
    let word = |at: usize| -> Option<usize> {
        Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?) as usize)
    };
    let json_len = word(12)?;
    let json = bytes.get(20..20 + json_len)?.to_vec();
    let bin = bytes.get(20 + json_len + 8..).unwrap_or_default().to_vec();
    Some((json, bin))
}

/// A glb from its two chunks, with correct lengths.
fn glb_pack(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for word in [
        0x4654_6C67u32,
        2,
        total as u32,
        json.len() as u32,
        0x4E4F_534A,
    ] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(bin);
    out
}

/// Mutates a glb's JSON or binary chunk and writes the container again
/// (most of the time), else the bytes as they are.
fn mutate_gltf(rng: &mut Rng, input: &mut Vec<u8>, other: &[u8], dictionary: &[&str]) {
    if input.starts_with(b"glTF") && rng.chance(75) {
        if let Some((mut json, mut bin)) = glb_chunks(input) {
            if rng.chance(80) {
                let other_json = glb_chunks(other).map_or_else(|| other.to_vec(), |c| c.0);
                mutate(rng, &mut json, &other_json, dictionary);
            } else {
                mutate(rng, &mut bin, other, dictionary);
            }
            *input = glb_pack(&json, &bin);
            return;
        }
    }
    mutate(rng, input, other, dictionary);
}

// -------------------------------------------------------------- mutator --

fn mutate(rng: &mut Rng, input: &mut Vec<u8>, other: &[u8], dictionary: &[&str]) {
    let span = |rng: &mut Rng, len: usize| {
        let a = rng.below(len + 1);
        let b = (a + rng.below(64)).min(len);
        (a, b)
    };
    match rng.below(10) {
        0 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] ^= 1 << rng.below(8);
        }
        1 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] = *rng.pick(b" \n\t#.-+eE019azAZ_\x00\x7f\xc3\xa9\xff\xfe");
        }
        2 => {
            let (a, b) = span(rng, input.len());
            input.drain(a..b);
        }
        3 => {
            let (a, b) = span(rng, input.len());
            let copy = input[a..b].to_vec();
            let at = rng.below(input.len() + 1);
            input.splice(at..at, copy);
        }
        4 => {
            // Splice: our head with the other input's tail.
            let cut = rng.below(input.len() + 1);
            let from = rng.below(other.len() + 1);
            input.truncate(cut);
            input.extend_from_slice(&other[from..]);
        }
        5 => {
            let text = String::from_utf8_lossy(input).into_owned();
            let mut lines: Vec<&str> = text.lines().collect();
            if lines.len() > 1 {
                let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                lines.swap(a, b);
            }
            *input = lines.join("\n").into_bytes();
        }
        6 => input.truncate(rng.below(input.len() + 1)),
        7 => {
            // Replace a whitespace-separated token by an interesting number.
            let text = String::from_utf8_lossy(input).into_owned();
            let tokens: Vec<&str> = text.split(' ').collect();
            let k = rng.below(tokens.len());
            let mut out: Vec<&str> = tokens.clone();
            out[k] = *rng.pick(INTERESTING_NUMBERS);
            *input = out.join(" ").into_bytes();
        }
        _ => {
            let at = rng.below(input.len() + 1);
            let token = format!(" {} ", rng.pick(dictionary));
            input.splice(at..at, token.into_bytes());
        }
    }
}

// --------------------------------------------------------------- checks --

/// Whether a glTF message without a line says where: a JSON path
/// (`meshes[0].primitives[1].indices: ...`), a glb byte offset or JSON
/// chunk position, or that the file has no triangles.
fn locates_itself(message: &str) -> bool {
    if message.starts_with("glb, byte ")
        || message.starts_with("glb JSON chunk, line ")
        || message.starts_with("glTF file has no triangles")
    {
        return true;
    }
    let path = message.split(": ").next().unwrap_or_default();
    // A top-level property, then indices, keys and fields.
    let head = path.split(['[', '.']).next().unwrap_or_default();
    head.starts_with(|c: char| c.is_ascii_lowercase())
        && head.chars().all(|c| c.is_ascii_alphanumeric())
}

/// Why an outcome is wrong, or `None`.
fn check(
    target: &Target,
    input: &[u8],
    outcome: &Result<Scene, Vec<Diagnostic>>,
) -> Option<String> {
    match outcome {
        Err(diags) => {
            if diags.is_empty() {
                return Some("rejected without a diagnostic".into());
            }
            for d in diags {
                let text: &[u8] = if d.file == target.file {
                    input
                } else if let Some((_, t)) = target.fixed.iter().find(|(f, _)| *f == d.file) {
                    t.as_bytes()
                } else {
                    return Some(format!("diagnostic names file `{}`: {d}", d.file));
                };
                if d.message.is_empty() || d.message.contains('\n') {
                    return Some(format!("message is empty or several lines: {d:?}"));
                }
                if d.line == 0 {
                    if !(target.json_paths && d.col == 0 && locates_itself(&d.message)) {
                        return Some(format!("diagnostic is not located: {d}"));
                    }
                    continue;
                }
                let lines: Vec<&[u8]> = text.split(|&b| b == b'\n').collect();
                let line = d.line as usize;
                // Columns count characters, which are never more than bytes;
                // one past the end is where "end of file" problems point.
                let ok = line >= 1
                    && line <= lines.len()
                    && d.col >= 1
                    && d.col as usize <= lines[line - 1].len() + 1;
                if !ok {
                    return Some(format!("position outside the input: {d}"));
                }
            }
            None
        }
        Ok(scene) => {
            if scene.polygons.is_empty() {
                return Some("accepted a scene without polygons".into());
            }
            for (i, p) in scene.polygons.iter().enumerate() {
                if let Err(e) = p.validate() {
                    return Some(format!("accepted polygon {i} is invalid: {e}"));
                }
                if p.vertices
                    .iter()
                    .any(|v| v.abs().max_element() as f64 > MAX_COORDINATE)
                {
                    return Some(format!("polygon {i} is outside the coordinate limit"));
                }
                if p.material.index() >= scene.materials.len() {
                    return Some(format!("polygon {i} names a missing material"));
                }
            }
            for m in &scene.materials {
                let (e, rho) = (m.emission(), m.reflectance());
                let valid = e.is_finite()
                    && e.min_channel() >= 0.0
                    && rho.is_finite()
                    && rho.min_channel() >= 0.0
                    && rho.max_channel() < 1.0;
                if !valid {
                    return Some(format!("accepted material breaks its invariants: {m:?}"));
                }
            }
            if let Err(e) = View::new(&scene.camera) {
                return Some(format!("accepted camera makes no view: {e}"));
            }
            if let Err(e) = mesh::estimate(scene, &MeshOptions::for_scene(scene)) {
                return Some(format!("default mesh options refused: {e}"));
            }
            None
        }
    }
}

// --------------------------------------------------------------- driver --

/// Watches the case in progress and aborts the process when one runs past
/// the limit: a hang would otherwise stall the test run forever.
struct Watchdog {
    started_ms: Arc<AtomicU64>,
    input: Arc<Mutex<Vec<u8>>>,
    stop: Arc<AtomicBool>,
    epoch: Instant,
}

impl Watchdog {
    fn start(target: &'static str) -> Watchdog {
        let dog = Watchdog {
            started_ms: Arc::new(AtomicU64::new(0)),
            input: Arc::new(Mutex::new(Vec::new())),
            stop: Arc::new(AtomicBool::new(false)),
            epoch: Instant::now(),
        };
        let (started, input, stop, epoch) = (
            dog.started_ms.clone(),
            dog.input.clone(),
            dog.stop.clone(),
            dog.epoch,
        );
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50));
                let s = started.load(Ordering::Relaxed);
                let now = epoch.elapsed().as_millis() as u64 + 1;
                if s != 0 && now.saturating_sub(s) > 2 * PER_INPUT_LIMIT.as_millis() as u64 {
                    let bytes = input.lock().map(|b| b.clone()).unwrap_or_default();
                    let saved = save_failure(target, "hang", &bytes);
                    eprintln!(
                        "fuzz {target}: input still loading after {:?}; saved to {}:\n{}",
                        2 * PER_INPUT_LIMIT,
                        saved.display(),
                        String::from_utf8_lossy(&bytes)
                    );
                    std::process::abort();
                }
            }
        });
        dog
    }

    fn begin(&self, input: &[u8]) {
        if let Ok(mut slot) = self.input.lock() {
            slot.clear();
            slot.extend_from_slice(input);
        }
        let now = self.epoch.elapsed().as_millis() as u64 + 1;
        self.started_ms.store(now, Ordering::Relaxed);
    }

    fn end(&self) {
        self.started_ms.store(0, Ordering::Relaxed);
    }
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn save_failure(target: &str, why: &str, input: &[u8]) -> PathBuf {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in input {
        hash = (hash ^ b as u64).wrapping_mul(0x100_0000_01b3);
    }
    let path = std::env::temp_dir().join(format!("radiosity-fuzz-{target}-{why}-{hash:016x}"));
    let _ = std::fs::write(&path, input);
    path
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// What a fuzz run saw.
#[derive(Debug, Default)]
struct Summary {
    cases: u64,
    accepted: u64,
    slowest: Duration,
    failures: Vec<String>,
}

fn corpus(target: &Target) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = common::root()
        .join("tests")
        .join("corpus")
        .join(target.name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| {
        p.extension()
            .is_some_and(|e| target.extensions.iter().any(|x| e == *x))
    });
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).expect("corpus file readable");
            (p, bytes)
        })
        .collect()
}

fn fuzz(target: &Target, cases: u64, seed: u64) -> Summary {
    common::limit_address_space();
    let mut seeds = (target.seeds)();
    seeds.extend(corpus(target).into_iter().map(|(_, b)| b));
    let mut rng = Rng(seed);
    let dog = Watchdog::start(target.name);
    let mut summary = Summary::default();
    for case in 0..cases {
        // A fifth generated as is (mostly valid: the checks on accepted
        // scenes need them), a fifth generated and lightly mutated, the
        // rest mutated seeds.
        let (mut input, mutations) = match rng.below(5) {
            0 => ((target.generate)(&mut rng), 0),
            1 => ((target.generate)(&mut rng), 1 + rng.below(2)),
            _ => (rng.pick(&seeds).clone(), 1 + rng.below(8)),
        };
        let other = rng.pick(&seeds).clone();
        for _ in 0..mutations {
            (target.mutate)(&mut rng, &mut input, &other, &target.dictionary);
        }
        dog.begin(&input);
        let t = Instant::now();
        let outcome = panic::catch_unwind(AssertUnwindSafe(|| (target.load)(&input)));
        let elapsed = t.elapsed();
        dog.end();
        summary.cases += 1;
        summary.slowest = summary.slowest.max(elapsed);
        let problem = match &outcome {
            Err(p) => Some(format!("panicked: {}", common::panic_message(p.as_ref()))),
            Ok(_) if elapsed > PER_INPUT_LIMIT => Some(format!("took {elapsed:?}")),
            Ok(o) => {
                summary.accepted += o.is_ok() as u64;
                check(target, &input, o)
            }
        };
        if let Some(problem) = problem {
            let saved = save_failure(target.name, "fail", &input);
            summary.failures.push(format!(
                "case {case} (seed {seed:#x}): {problem}; input saved to {}:\n{}",
                saved.display(),
                String::from_utf8_lossy(&input[..input.len().min(2000)])
            ));
            if summary.failures.len() >= 5 {
                break;
            }
        }
    }
    summary
}

/// Fuzzes the target named `name` (see [`targets`]).
fn survives_fuzzing(name: &str) {
    let seed = env_u64("RADIOSITY_FUZZ_SEED", DEFAULT_SEED);
    for target in targets().into_iter().filter(|t| t.name == name) {
        let cases = env_u64("RADIOSITY_FUZZ_CASES", target.cases);
        let t = Instant::now();
        let s = fuzz(&target, cases, seed);
        eprintln!(
            "fuzz {}: {} cases ({} accepted) in {:.1} s, slowest input {:.1} ms",
            target.name,
            s.cases,
            s.accepted,
            t.elapsed().as_secs_f64(),
            s.slowest.as_secs_f64() * 1e3
        );
        assert!(s.failures.is_empty(), "{}", s.failures.join("\n\n"));
        assert_eq!(s.cases, cases);
        // A mutator that only ever produced garbage would test little of
        // the validation behind the syntax.
        assert!(
            s.accepted > cases / 100,
            "only {} of {} inputs were valid scenes",
            s.accepted,
            cases
        );
    }
}

#[test]
fn sc_loader_survives_fuzzing() {
    survives_fuzzing("sc");
}

#[test]
fn obj_loader_survives_fuzzing() {
    survives_fuzzing("obj");
}

#[test]
fn mtl_reader_survives_fuzzing() {
    survives_fuzzing("mtl");
}

#[test]
fn gltf_loader_survives_fuzzing() {
    survives_fuzzing("gltf");
}

/// Every file kept in `tests/corpus/<target>/` loads to exactly the
/// outcome recorded next to it in `NAME.expected` (`ok`, or the
/// diagnostics as printed), and passes the same checks as a fuzz case.
#[test]
fn corpus_cases_keep_their_outcome() {
    for target in targets() {
        let files = corpus(&target);
        assert!(!files.is_empty(), "no corpus for {}", target.name);
        for (path, bytes) in files {
            let outcome = (target.load)(&bytes);
            if let Some(problem) = check(&target, &bytes, &outcome) {
                panic!("{}: {problem}", path.display());
            }
            let got = match &outcome {
                Ok(_) => "ok".to_string(),
                Err(diags) => diags
                    .iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join("\n"),
            };
            let expected_path = path.with_extension("expected");
            if std::env::var_os("RADIOSITY_BLESS").is_some() {
                std::fs::write(&expected_path, format!("{got}\n")).expect("bless");
                continue;
            }
            let expected = std::fs::read_to_string(&expected_path).unwrap_or_else(|_| {
                panic!(
                    "{} has no {} (run with RADIOSITY_BLESS=1 to record it)",
                    path.display(),
                    expected_path.display()
                )
            });
            assert_eq!(got, expected.trim_end(), "{}", path.display());
        }
    }
}
