//! Numbers and names that cross into the program: every emission,
//! reflectance, candela value, multiplier and index is checked at load with
//! its position, extreme but legal inputs solve to finite values, and names
//! from model files are printed escaped.

mod common;

use common::{run_in, stderr, write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A floor and a lamp above it, in OBJ (Y up), with the lamp's material
/// `light` and the floor's `wall` taken from `m.mtl`.
const LAMP_OBJ: &str = "mtllib m.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v -0.3 1 -0.3
v 0.3 1 -0.3
v 0.3 1 0.3
v -0.3 1 0.3
usemtl wall
f 4 3 2 1
usemtl light
f 5 6 7 8
";

#[test]
fn thousands_of_threads_are_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let start = Instant::now();
    let out = run_in(dir.path(), &["--threads", "10000", "-o", "x.png"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--threads must be from 1 to 1024, got 10000"),
        "{}",
        stderr(&out)
    );
    // Refused as an option, before any loading or solving.
    assert!(start.elapsed() < Duration::from_secs(10));
    assert!(!dir.path().join("x.png").exists());
}

/// The points file is read once: from a pipe, which can be read only once,
/// the run writes its illuminance (or, where pipes are refused as inputs,
/// refuses it before writing anything). It used to read the file again
/// after the solve, and wait forever for a second writer.
#[cfg(unix)]
#[test]
fn the_points_file_is_read_once() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "f.obj", LAMP_OBJ);
    write(
        dir.path(),
        "m.mtl",
        "newmtl light\nKe 1 1 1\nKd 0 0 0\nnewmtl wall\nKd 0.5 0.5 0.5\n",
    );
    let fifo = dir.path().join("pts.csv");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let writer = std::thread::spawn(move || {
        // Blocks until the run opens the pipe; one reading only. A run
        // that refuses the pipe may close it first (the write then fails)
        // or never open it: then the test's end opens it to let this
        // thread go.
        let _ = std::fs::write(&fifo, "x,y,z,nx,ny,nz\n0,0.5,0,0,1,0\n");
    });
    let mut child = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .current_dir(dir.path())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args([
            "f.obj",
            "-q",
            "--max-steps",
            "3",
            "--lenmax",
            "0.5",
            "-o",
            "f.png",
            "--illuminance-at",
            "pts.csv",
            "--illuminance-out",
            "e.csv",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            child.wait().unwrap();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    // Unblock a writer still waiting for a reader: open the pipe for
    // reading without blocking (a blocking open would wait for ever if
    // the writer finished in between), until it is done.
    while !writer.is_finished() {
        use std::os::unix::fs::OpenOptionsExt;
        if let Ok(mut pipe) = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(dir.path().join("pts.csv"))
        {
            let _ = pipe.read_to_end(&mut Vec::new());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    // The writer may fail once the run has refused the pipe and closed it.
    let _ = writer.join();
    let status = status.expect("the run waited for a second reading of the points pipe");
    if status.success() {
        let csv = std::fs::read_to_string(dir.path().join("e.csv")).unwrap();
        assert_eq!(csv.lines().count(), 2, "{csv}");
    } else {
        assert_eq!(status.code(), Some(2), "{err}");
        assert!(!dir.path().join("f.png").exists(), "{err}");
    }
}

#[test]
fn a_library_named_twice_is_read_once() {
    let dir = tempfile::tempdir().unwrap();
    let obj = LAMP_OBJ.replace("mtllib m.mtl", "mtllib m.mtl m.mtl\nmtllib m.mtl");
    write(dir.path(), "f.obj", &obj);
    write(
        dir.path(),
        "m.mtl",
        "newmtl light\nKe 1 1 1\nKd 0 0 0\nnewmtl wall\nKd 0.5 0.5 0.5\n",
    );
    let out = run_in(
        dir.path(),
        &[
            "f.obj",
            "--max-steps",
            "2",
            "--lenmax",
            "0.5",
            "-o",
            "f.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        !stderr(&out).contains("already defined"),
        "{}",
        stderr(&out)
    );
    // Two different libraries defining one name are still an error.
    write(dir.path(), "n.mtl", "newmtl wall\nKd 0.2 0.2 0.2\n");
    write(
        dir.path(),
        "g.obj",
        &LAMP_OBJ.replace("mtllib m.mtl", "mtllib m.mtl n.mtl"),
    );
    let out = run_in(dir.path(), &["g.obj", "--max-steps", "2", "-o", "g.png"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out)
            .contains("n.mtl:1:1: error: material `wall` is already defined in m.mtl at 4:1"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn mtl_emission_above_the_limit_is_refused_at_its_column() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "f.obj", LAMP_OBJ);
    for (ke, col) in [
        ("1e39 1e39 1e39", 4),
        ("1 1e100 1", 6),
        ("1e20 1e20 2e20", 14),
    ] {
        write(
            dir.path(),
            "m.mtl",
            &format!("newmtl light\nKe {ke}\nKd 0 0 0\nnewmtl wall\nKd 0.5 0.5 0.5\n"),
        );
        let out = run_in(dir.path(), &["f.obj", "--max-steps", "2", "-o", "f.pfm"]);
        assert_eq!(out.status.code(), Some(2), "{ke}: {}", stderr(&out));
        let expected = format!("m.mtl:2:{col}: error: `Ke` channel");
        assert!(stderr(&out).contains(&expected), "{ke}: {}", stderr(&out));
        assert!(stderr(&out).contains("at most 1e20"), "{}", stderr(&out));
        assert!(!dir.path().join("f.pfm").exists());
    }
}

/// The values of a PFM picture (`PF`, little-endian when the scale is
/// negative), in file order.
fn pfm_values(bytes: &[u8]) -> Vec<f32> {
    let mut parts = bytes.splitn(4, |&b| b == b'\n');
    assert_eq!(parts.next(), Some(&b"PF"[..]));
    let size = std::str::from_utf8(parts.next().unwrap()).unwrap();
    let (w, h) = size.split_once(' ').unwrap();
    let n = w.parse::<usize>().unwrap() * h.parse::<usize>().unwrap() * 3;
    let scale: f64 = std::str::from_utf8(parts.next().unwrap())
        .unwrap()
        .parse()
        .unwrap();
    assert!(scale < 0.0, "little-endian");
    let data = parts.next().unwrap();
    data[..4 * n]
        .chunks(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// Emission at the limit, reflectance at its largest, in OBJ+MTL through
/// the whole program: every written value is finite.
#[test]
fn emission_at_the_limit_writes_finite_pictures() {
    let dir = tempfile::tempdir().unwrap();
    for scale in [1e-6f64, 1.0, 1e9] {
        let obj: String = LAMP_OBJ
            .lines()
            .map(|l| match l.strip_prefix("v ") {
                Some(v) => {
                    let c: Vec<String> = v
                        .split(' ')
                        .map(|x| (x.parse::<f64>().unwrap() * scale).to_string())
                        .collect();
                    format!("v {}\n", c.join(" "))
                }
                None => format!("{l}\n"),
            })
            .collect();
        write(dir.path(), "f.obj", &obj);
        write(dir.path(), "m.mtl", "newmtl light\nKe 1e20 1e20 1e20\nKd 0.999 0.999 0.999\nnewmtl wall\nKd 0.999 0.999 0.999\n");
        let out = run_in(
            dir.path(),
            &[
                "f.obj",
                "--max-steps",
                "4",
                "--lenmax",
                &(0.5 * scale).to_string(),
                "-o",
                "f.pfm",
            ],
        );
        assert!(out.status.success(), "scale {scale}: {}", stderr(&out));
        let values = pfm_values(&std::fs::read(dir.path().join("f.pfm")).unwrap());
        assert!(
            values.iter().all(|v| v.is_finite() && *v >= 0.0),
            "scale {scale}"
        );
        assert!(
            values.iter().any(|&v| v > 1e19),
            "scale {scale}: the lamp is seen"
        );
    }
}

/// Names from a model reach the terminal escaped: an object named with
/// ESC, CR and a quote cannot recolour the terminal, overwrite a line or
/// break the suggested `--emit` command out of its quotes.
#[test]
fn names_are_printed_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let obj = LAMP_OBJ
        .replace("mtllib m.mtl\n", "mtllib m.mtl\no Lamp\u{1b}[31m'x\r\n")
        .replace("usemtl light\n", "usemtl light\u{1b}]0;t\u{7}\n");
    write(dir.path(), "f.obj", &obj);
    write(dir.path(), "m.mtl", "newmtl wall\nKd 0.5 0.5 0.5\n");
    let out = run_in(dir.path(), &["f.obj", "--max-steps", "1", "-o", "f.png"]);
    let err = stderr(&out);
    assert!(
        !err.contains('\u{1b}') && !err.contains('\r') && !err.contains('\u{7}'),
        "{err:?}"
    );
    assert!(err.contains(r"Lamp\u{1b}[31m'\''x"), "{err}");
    assert!(err.contains(r"light\u{1b}]0;t\u{7}"), "{err}");
}
