//! Helpers shared by the integration tests: a temporary directory, a
//! runner for the built binary, and a PNG reader; small scenes built in
//! code and the measurements taken of their solutions ([`scenes`]).

#![allow(dead_code)]

pub mod daylight;
pub mod pictures;
pub mod scenes;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The project root (where `scenes/` lives).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A bundled scene's path.
pub fn scene(name: &str) -> PathBuf {
    root().join("scenes").join(name)
}

/// Runs the `radiosity` binary with `args` in `dir`, with no display (so
/// it never opens a window).
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(args)
        .output()
        .expect("the radiosity binary runs")
}

/// Runs the `radiosity` binary with `args` in `dir` with `DISPLAY` set to
/// `display` (a display that need not exist).
pub fn run_with_display(dir: &Path, display: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .current_dir(dir)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .args(args)
        .output()
        .expect("the radiosity binary runs")
}

/// Standard error of a run, as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("fixture written");
    path
}

/// The files in `dir`, sorted by name.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("dir readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The JSON file `name` in `dir` (a `--stats` file), parsed.
pub fn read_json(dir: &Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join(name)).expect("the JSON file exists");
    serde_json::from_str(&text).expect("the file is JSON")
}

/// SplitMix64: tiny, fast, and the same sequence on every machine.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    pub fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The address-space limit a fuzzing test binary runs under: a small input
/// that makes the program allocate without bound then fails the test (an
/// allocation failure aborts it) instead of exhausting the machine.
pub const FUZZ_ADDRESS_SPACE: u64 = 4 << 30;

/// Limits this test process's address space to [`FUZZ_ADDRESS_SPACE`]
/// (once; a lower limit already set is kept). The limit is per process, so
/// it covers every test of the binary that calls it: call it only from
/// test binaries whose tests all stay far below it.
pub fn limit_address_space() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let mut now = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit and setrlimit only read and write the struct
        // passed, which lives for the call.
        unsafe {
            if libc::getrlimit(libc::RLIMIT_AS, &mut now) != 0 {
                return;
            }
            let limit = FUZZ_ADDRESS_SPACE.min(now.rlim_max);
            if now.rlim_cur != libc::RLIM_INFINITY && now.rlim_cur <= limit {
                return;
            }
            let new = libc::rlimit {
                rlim_cur: limit,
                rlim_max: now.rlim_max,
            };
            assert_eq!(
                libc::setrlimit(libc::RLIMIT_AS, &new),
                0,
                "cannot limit the address space"
            );
        }
    });
}

/// Sends `signal` (`INT` as Ctrl-C in a terminal does, `TERM`) to `child`.
pub fn signal(child: &std::process::Child, signal: &str) {
    let ok = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill runs")
        .success();
    assert!(ok, "kill -{signal} failed");
}

/// Waits at most `limit` for `child`; kills it and fails if it hangs.
pub fn wait_at_most(
    child: &mut std::process::Child,
    limit: std::time::Duration,
) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("did not stop within {limit:?} of the interrupt");
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// The message of a caught panic's payload (empty when it is not text).
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

/// Starts the binary in `dir` (no display), without waiting; its standard
/// error is piped, its output dropped.
pub fn spawn_in(dir: &Path, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the radiosity binary starts")
}

/// The program `program` as found on `PATH`, if it is there.
pub fn which(program: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|dir| Path::new(dir).join(program))
        .find(|p| p.is_file())
}
