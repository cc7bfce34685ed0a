//! Inputs are a set: every file a run reads is a regular file read within
//! its size limit, a model's files stay in its folder, and no output is
//! any input or anything but a regular file. Each case is one the program
//! once got wrong (an input overwritten, a FIFO that blocked the run for
//! ever, `/dev/zero` read to gigabytes, a glTF buffer read from
//! `/etc/passwd`).

mod common;

use common::{listing, stderr, write};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A lit triangle as OBJ, with a library and a texture.
const OBJ: &str = "mtllib model.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const MTL: &str = "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd model.png\n";

/// A one-pixel grey PNG.
fn png() -> Vec<u8> {
    let mut bytes = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
    image::ImageEncoder::write_image(
        encoder,
        &[128, 128, 128],
        1,
        1,
        image::ColorType::Rgb8.into(),
    )
    .unwrap();
    bytes
}

/// Writes the OBJ model (model.obj, model.mtl, model.png) into `dir`.
fn obj_model(dir: &Path) {
    write(dir, "model.obj", OBJ);
    write(dir, "model.mtl", MTL);
    std::fs::write(dir.join("model.png"), png()).unwrap();
}

/// A glTF triangle whose positions are the buffer `buffer` and whose base
/// colour is the image `image` when given.
fn gltf(buffer: &str, image: Option<&str>) -> String {
    let material = match image {
        Some(uri) => format!(
            r#","images":[{{"uri":"{uri}"}}],"textures":[{{"source":0}}],
            "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},
            "emissiveFactor":[1,1,1]}}]"#
        ),
        None => String::new(),
    };
    let prim_material = if image.is_some() {
        r#","material":0"#
    } else {
        ""
    };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{buffer}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
        "max":[1,1,0],"min":[0,0,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}{prim_material}}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]{material}}}"#
    )
}

/// The 36 bytes of the glTF triangle's positions.
fn triangle_bin() -> Vec<u8> {
    [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect()
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs")
        .success();
    assert!(ok, "mkfifo {}", path.display());
}

/// Runs the binary in `dir` with `args`, killing it and failing if it
/// takes more than 60 s (a read that blocks on a FIFO would never end).
fn run(dir: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the radiosity binary starts");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("{args:?} still runs after 60 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

/// Runs `args` in `dir` and checks it fails with exit code 2 and a
/// message holding `expected`.
fn refused(dir: &Path, args: &[&str], expected: &str) -> String {
    let out = run(dir, args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(expected),
        "{args:?}: expected `{expected}` in {err}"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    err
}

#[test]
fn the_default_picture_never_overwrites_the_models_own_texture() {
    let dir = tempfile::tempdir().unwrap();
    obj_model(dir.path());
    // `model.obj` writes `model.png` by default: its own `map_Kd`.
    let err = refused(
        dir.path(),
        &["model.obj", "-q", "--no-window"],
        "would overwrite the texture",
    );
    assert!(err.contains("model.png"), "{err}");
    assert_eq!(std::fs::read(dir.path().join("model.png")).unwrap(), png());
    // Nor the library, nor the model.
    refused(
        dir.path(),
        &["model.obj", "-q", "-o", "out.png", "--stats", "model.mtl"],
        "would overwrite the material library",
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("model.mtl")).unwrap(),
        MTL
    );
    assert_eq!(listing(dir.path()), ["model.mtl", "model.obj", "model.png"]);
    // Another output is fine.
    let out = run(dir.path(), &["model.obj", "-q", "-o", "out.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn no_output_overwrites_an_ies_points_or_checkpoint_input() {
    let dir = tempfile::tempdir().unwrap();
    obj_model(dir.path());
    let panel = common::scene("luminaires/panel.ies");
    std::fs::copy(&panel, dir.path().join("panel.ies")).unwrap();
    write(dir.path(), "pts.csv", "0.2,0.2,0.1,0,0,1\n");
    let base = ["model.obj", "-q", "--units", "m", "-o", "out.png"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(extra).copied().collect()
    };
    refused(
        dir.path(),
        &with(&["--ies", "lamp=panel.ies", "--stats", "panel.ies"]),
        "--stats would overwrite the IES file",
    );
    refused(
        dir.path(),
        &with(&[
            "--illuminance-at",
            "pts.csv",
            "--illuminance-out",
            "pts.csv",
        ]),
        "--illuminance-out would overwrite the points file",
    );
    refused(
        dir.path(),
        &with(&[
            "--illuminance-at",
            "pts.csv",
            "--illuminance-out",
            "e.csv",
            "--log",
            "pts.csv",
        ]),
        "--log would overwrite the points file",
    );
    // A checkpoint to resume from, even through a symbolic link.
    write(dir.path(), "c.ckpt", "not read before the refusal");
    refused(
        dir.path(),
        &with(&["--resume", "c.ckpt", "--stats", "c.ckpt"]),
        "--stats would overwrite the checkpoint",
    );
    std::os::unix::fs::symlink("c.ckpt", dir.path().join("link.json")).unwrap();
    refused(
        dir.path(),
        &with(&["--resume", "c.ckpt", "--stats", "link.json"]),
        "--stats would overwrite the checkpoint c.ckpt",
    );
    std::fs::remove_file(dir.path().join("link.json")).unwrap();
    assert_eq!(
        std::fs::read(dir.path().join("panel.ies")).unwrap(),
        std::fs::read(&panel).unwrap()
    );
    assert_eq!(
        listing(dir.path()),
        [
            "c.ckpt",
            "model.mtl",
            "model.obj",
            "model.png",
            "panel.ies",
            "pts.csv"
        ]
    );
}

#[test]
fn outputs_are_regular_files_that_can_be_created_before_the_solve() {
    let dir = tempfile::tempdir().unwrap();
    obj_model(dir.path());
    let base = ["model.obj", "-q", "-o", "out.png"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(extra).copied().collect()
    };
    // A device node stays one. Where a device node can be made (as the
    // superuser, who could also replace `/dev/null`), a copy of
    // `/dev/null` in the test's folder stands in for it, so that a
    // regression could only replace the copy.
    let made = Command::new("mknod")
        .arg(dir.path().join("null"))
        .args(["c", "1", "3"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    let null = if made { "null" } else { "/dev/null" };
    refused(
        dir.path(),
        &with(&["--stats", null]),
        "--stats names a character device, not a regular file",
    );
    let node = if made {
        dir.path().join("null")
    } else {
        null.into()
    };
    assert!(!std::fs::metadata(&node).unwrap().is_file());
    if made {
        std::fs::remove_file(&node).unwrap();
    }
    std::fs::create_dir(dir.path().join("d.png")).unwrap();
    refused(
        dir.path(),
        &["model.obj", "-q", "-o", "d.png"],
        "-o names a directory, not a regular file",
    );
    mkfifo(&dir.path().join("p.csv"));
    refused(
        dir.path(),
        &(with(&["--log", "p.csv"])),
        "--log names a FIFO",
    );
    // A name longer than the file system allows is found before solving.
    let long = format!("{}.png", "a".repeat(296));
    refused(
        dir.path(),
        &["model.obj", "-q", "-o", &long],
        "File name too long",
    );
    // Two outputs in one file: the message names every output option.
    let err = refused(
        dir.path(),
        &(with(&["--log", "out.png"])),
        "two outputs would write this same file (-o and --log)",
    );
    for option in ["--illuminance-out", "--workplane-out", "--falsecolor"] {
        assert!(err.contains(option), "{err}");
    }
    assert_eq!(
        listing(dir.path()),
        ["d.png", "model.mtl", "model.obj", "model.png", "p.csv"]
    );
}

#[test]
fn a_read_only_directory_is_refused_before_the_solve() {
    let dir = tempfile::tempdir().unwrap();
    obj_model(dir.path());
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // The superuser writes anyway: there is nothing to refuse then.
    if std::fs::write(ro.join("probe"), b"").is_ok() {
        return;
    }
    refused(
        dir.path(),
        &["model.obj", "-q", "-o", "ro/out.png"],
        "Permission denied",
    );
}

#[test]
fn fifos_and_devices_named_anywhere_are_refused_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    obj_model(d);
    mkfifo(&d.join("pipe"));
    // Files a model names.
    write(d, "fifo_mtl.obj", &OBJ.replace("model.mtl", "pipe"));
    write(d, "tex.mtl", &MTL.replace("model.png", "pipe"));
    write(d, "fifo_tex.obj", &OBJ.replace("model.mtl", "tex.mtl"));
    std::fs::write(d.join("tri.bin"), triangle_bin()).unwrap();
    write(d, "fifo_buf.gltf", &gltf("pipe", None));
    write(d, "fifo_img.gltf", &gltf("tri.bin", Some("pipe")));
    for model in [
        "fifo_mtl.obj",
        "fifo_tex.obj",
        "fifo_buf.gltf",
        "fifo_img.gltf",
    ] {
        refused(
            d,
            &[model, "-q", "-o", "out.png"],
            "pipe: it is a FIFO (named pipe)",
        );
    }
    // Files the options name, as a FIFO and as /dev/zero.
    for special in ["pipe", "/dev/zero"] {
        let what = if special == "pipe" {
            "a FIFO (named pipe)"
        } else {
            "a character device"
        };
        let ies = format!("lamp={special}");
        let cases: [&[&str]; 5] = [
            &[special],
            &["model.obj", "--camera", special],
            &["model.obj", "--units", "m", "--ies", &ies],
            &[
                "model.obj",
                "--illuminance-at",
                special,
                "--illuminance-out",
                "e.csv",
            ],
            &["model.obj", "--resume", special],
        ];
        for case in cases {
            let mut args = case.to_vec();
            args.extend(["-q", "-o", "out.png"]);
            refused(d, &args, what);
        }
    }
    assert!(!d.join("out.png").exists());
}

#[test]
fn a_models_files_stay_in_its_folder_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let secret = "root:x:0:0:the bytes of a file outside";
    write(dir.path(), "secret.bin", secret);
    std::fs::write(dir.path().join("tri.bin"), triangle_bin()).unwrap();
    let model = dir.path().join("model");
    std::fs::create_dir(&model).unwrap();
    std::fs::write(model.join("tri.bin"), triangle_bin()).unwrap();
    write(&model, "up.gltf", &gltf("../secret.bin", None));
    let abs = dir.path().join("secret.bin");
    write(&model, "abs.gltf", &gltf(abs.to_str().unwrap(), None));
    write(&model, "img.gltf", &gltf("tri.bin", Some("../secret.bin")));
    write(&model, "up.obj", &OBJ.replace("model.mtl", "../x.mtl"));
    write(dir.path(), "x.mtl", MTL);
    write(&model, "tex.mtl", &MTL.replace("model.png", "/etc/passwd"));
    write(&model, "tex.obj", &OBJ.replace("model.mtl", "tex.mtl"));
    for name in ["up.gltf", "abs.gltf", "up.obj"] {
        let err = refused(
            dir.path(),
            &[&format!("model/{name}"), "-q", "-o", "out.png"],
            "outside the model's folder model",
        );
        assert!(err.contains("--allow-outside-paths"), "{err}");
        assert!(!err.contains("root:x"), "{name}: quotes the file: {err}");
    }
    // A texture outside is skipped with a warning, as a missing one is:
    // real exports name `../textures/...`, and a texture only tints.
    for name in ["img.gltf", "tex.obj"] {
        let out = run(
            dir.path(),
            &[&format!("model/{name}"), "-q", "-o", "out.png"],
        );
        let err = stderr(&out);
        assert!(out.status.success(), "{name}: {err}");
        assert!(err.contains("outside the model's folder model"), "{err}");
        assert!(!err.contains("root:x"), "{name}: quotes the file: {err}");
    }
    // Inside the folder, through a subfolder and back, is fine.
    std::fs::create_dir(model.join("sub")).unwrap();
    write(&model, "in.gltf", &gltf("./sub/../tri.bin", None));
    let out = run(dir.path(), &["model/in.gltf", "-q", "-o", "out.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The option allows it: the buffer outside is read.
    write(&model, "up2.gltf", &gltf("../tri.bin", None));
    refused(
        dir.path(),
        &["model/up2.gltf", "-q", "-o", "out2.png"],
        "outside the model's folder",
    );
    let out = run(
        dir.path(),
        &[
            "model/up2.gltf",
            "-q",
            "-o",
            "out2.png",
            "--allow-outside-paths",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}
