//! The window, end to end, under a virtual X server: start the program on
//! a small scene, let it take a few steps, press `w` (stdin is not a
//! terminal, so the picture gets an automatic name), check the TIFF, press
//! `q`, and check the program exits 0 promptly.
//!
//! Needs `Xvfb` and `xdotool` (`.ci/run` installs them). Without them, or
//! when no X server can be started, the test says loudly that it skipped.

mod common;

use common::which;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn skip(why: &str) {
    eprintln!("\n**************** SKIPPED: window end-to-end test: {why} ****************\n");
}

/// Stops a child process when dropped, so a failed assertion never leaves
/// an X server or a window behind: SIGTERM first, so that an X server
/// removes its socket and lock file, then SIGKILL if it lingers.
struct Reaper(Child);

impl Reaper {
    /// Everything the exited program printed on its standard output.
    fn stdout(&mut self) -> String {
        use std::io::Read;
        let mut text = String::new();
        if let Some(mut out) = self.0.stdout.take() {
            out.read_to_string(&mut text).unwrap();
        }
        text
    }

    /// Everything the exited program printed on its standard error.
    fn stderr(&mut self) -> String {
        use std::io::Read;
        let mut text = String::new();
        if let Some(mut err) = self.0.stderr.take() {
            err.read_to_string(&mut text).unwrap();
        }
        text
    }
}

impl Drop for Reaper {
    fn drop(&mut self) {
        let terminated = Command::new("kill")
            .arg(self.0.id().to_string())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if terminated
            && wait_for(Duration::from_secs(2), || self.0.try_wait().ok().flatten()).is_some()
        {
            return;
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Polls `f` every 50 ms until it returns `Some` or `limit` passes.
fn wait_for<T>(limit: Duration, mut f: impl FnMut() -> Option<T>) -> Option<T> {
    let start = Instant::now();
    while start.elapsed() < limit {
        if let Some(v) = f() {
            return Some(v);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    None
}

fn xdotool(display: &str, args: &[&str]) -> Option<String> {
    let out = Command::new("xdotool")
        .env("DISPLAY", display)
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// Starts Xvfb on a free display number from 90 on; `None` if none
/// starts. A number whose lock file exists is in use; a socket without a
/// lock file is what a killed server left behind, and is removed.
fn start_xvfb() -> Option<(Reaper, String)> {
    for n in 90..130 {
        if Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            continue;
        }
        let socket = format!("/tmp/.X11-unix/X{n}");
        let _ = std::fs::remove_file(&socket);
        let display = format!(":{n}");
        let child = Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "800x600x24",
                "-nolisten",
                "tcp",
                // By default the server resets when its last client leaves,
                // and a program connecting during the reset fails
                // XOpenDisplay (seen on a loaded machine between two
                // windows of one test).
                "-noreset",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .ok()?;
        let mut xvfb = Reaper(child);
        let up = wait_for(Duration::from_secs(10), || {
            if let Ok(Some(_)) = xvfb.0.try_wait() {
                return Some(false);
            }
            Path::new(&socket).exists().then_some(true)
        });
        // The socket can appear before the server takes connections (seen
        // on a loaded machine: the program's XOpenDisplay failed): wait
        // until a client gets an answer.
        let answers = || {
            wait_for(Duration::from_secs(10), || {
                xdotool(&display, &["getdisplaygeometry"]).map(|_| ())
            })
        };
        if up == Some(true) && answers().is_some() {
            return Some((xvfb, display));
        }
    }
    None
}

/// Held by each window test for its whole run.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// An X server for a test, or `None` (having said loudly why the test is
/// skipped) when Xvfb or xdotool is missing or no server starts.
///
/// The window tests run one at a time (they hold [`ONE_AT_A_TIME`]): two
/// servers starting at once would race for the same display number.
fn x_server() -> Option<(Reaper, String)> {
    if which("Xvfb").is_none() || which("xdotool").is_none() {
        skip("Xvfb or xdotool is not installed");
        return None;
    }
    let server = start_xvfb();
    if server.is_none() {
        skip("no X server could be started");
    }
    server
}

/// Starts the program on `cornell.sc` (a coarse mesh, a small window) in
/// `dir` on `display` with `extra` arguments, and waits for its window.
/// Returns the program (stdout piped) and the window's id.
fn open_cornell(dir: &Path, display: &str, extra: &[&str]) -> (Reaper, String) {
    let mut args = vec!["--lenmax", "80"];
    args.extend_from_slice(extra);
    open_scene("cornell", dir, display, &args)
}

/// Starts the program on the bundled scene `name` (`scenes/NAME.sc`) in a
/// 160×120 window in `dir` on `display` with `extra` arguments, and waits
/// for its window. Returns the program (stdout piped) and the window's id.
fn open_scene(name: &str, dir: &Path, display: &str, extra: &[&str]) -> (Reaper, String) {
    open_file(&common::scene(&format!("{name}.sc")), dir, display, extra)
}

/// [`open_scene`] for the scene file `scene`, its window found by the
/// file's stem.
fn open_file(scene: &Path, dir: &Path, display: &str, extra: &[&str]) -> (Reaper, String) {
    let name = scene.file_stem().unwrap().to_str().unwrap().to_string();
    let mut args = vec![scene.to_str().unwrap(), "--size", "160x120"];
    args.extend_from_slice(extra);
    let child = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(&args)
        .current_dir(dir)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut program = Reaper(child);
    let window = wait_for(Duration::from_secs(20), || {
        xdotool(
            display,
            &["search", "--name", &format!("^radiosity.*{name}")],
        )
        .and_then(|ids| ids.lines().next().map(str::to_string))
    });
    let Some(window) = window else {
        let _ = program.0.kill();
        let mut said = String::new();
        if let Some(mut err) = program.0.stderr.take() {
            use std::io::Read;
            let _ = err.read_to_string(&mut said);
        }
        panic!("no window appeared on {display}; the program said: {said}");
    };
    (program, window)
}

#[test]
fn window_writes_a_picture_and_quits_on_keys() {
    // A failed test poisons the lock; the next one may still run.
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let Some((_xvfb, display)) = x_server() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (mut program, window) = open_cornell(dir.path(), &display, &[]);
    // A few steps, read from the title.
    let title = wait_for(Duration::from_secs(30), || {
        let title = xdotool(&display, &["getwindowname", &window])?;
        let step: u64 = title
            .split("step ")
            .nth(1)?
            .split_whitespace()
            .next()?
            .parse()
            .ok()?;
        (step >= 3).then_some(title)
    })
    .expect("the solver takes steps and the title shows them");
    assert!(
        title.contains("unshot") && title.contains("Mrays/s"),
        "{title}"
    );

    xdotool(&display, &["windowfocus", "--sync", &window]).expect("focus");
    xdotool(&display, &["key", "w"]).expect("key w");
    let tiff = dir.path().join("cornell-001.tiff");
    wait_for(Duration::from_secs(10), || tiff.exists().then_some(()))
        .expect("w writes cornell-001.tiff");
    let img = image::open(&tiff).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (160, 120));
    let lit = img
        .enumerate_pixels()
        .filter(|&(x, y, p)| {
            p.0.iter().any(|&c| c > 30) && p.0 != radiosity::render::back_face_color(x, y)
        })
        .count();
    assert!(
        lit > 160 * 120 / 2,
        "the picture is mostly black ({lit} lit pixels)"
    );

    xdotool(&display, &["key", "q"]).expect("key q");
    let status = wait_for(Duration::from_secs(5), || {
        program.0.try_wait().ok().flatten()
    })
    .expect("the program exits within 5 s of q");
    let stdout = program.stdout();
    assert!(status.success(), "exit status {status}");
    assert!(
        stdout.contains("wrote cornell-001.tiff"),
        "stdout: {stdout}"
    );
    // One summary line on the terminal when the window closes.
    let stderr = program.stderr();
    let summary: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("window closed after"))
        .collect();
    assert_eq!(summary.len(), 1, "stderr: {stderr}");
    assert!(
        summary[0].contains("% unshot") && summary[0].contains("1 picture written"),
        "{}",
        summary[0]
    );
}

#[test]
fn window_refines_adaptively_and_shows_the_refined_mesh() {
    // A failed test poisons the lock; the next one may still run.
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let Some((_xvfb, display)) = x_server() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let run = |adaptive: bool| {
        let extra: &[&str] = if adaptive { &["--adaptive"] } else { &[] };
        let (mut program, window) = open_cornell(dir.path(), &display, extra);
        let title = wait_for(Duration::from_secs(60), || {
            let title = xdotool(&display, &["getwindowname", &window])?;
            title.contains("converged").then_some(title)
        })
        .expect("the solve converges");
        xdotool(&display, &["windowfocus", "--sync", &window]).expect("focus");
        xdotool(&display, &["key", "m"]).expect("key m");
        xdotool(&display, &["key", "w"]).expect("key w");
        let tiff = dir.path().join("cornell-001.tiff");
        wait_for(Duration::from_secs(10), || tiff.exists().then_some(()))
            .expect("w writes cornell-001.tiff");
        let img = image::open(&tiff).unwrap().to_rgb8();
        std::fs::remove_file(&tiff).unwrap();
        xdotool(&display, &["key", "q"]).expect("key q");
        let status = wait_for(Duration::from_secs(5), || {
            program.0.try_wait().ok().flatten()
        })
        .expect("the program exits within 5 s of q");
        assert!(status.success(), "exit status {status}");
        let lines = img
            .pixels()
            .filter(|p| {
                p.0 == radiosity::render::MESH_COLOR
                    || p.0 == radiosity::render::MESH_COLOR_ON_LIGHT
            })
            .count();
        (title, lines)
    };
    let (plain_title, plain_lines) = run(false);
    let (title, lines) = run(true);
    assert!(!plain_title.contains("refinement"), "{plain_title}");
    assert!(
        title.contains("converged after 2 refinements"),
        "the title says the refinements: {title}"
    );
    // The refined mesh has more edges on screen than the regular one.
    assert!(
        lines > plain_lines + plain_lines / 10,
        "mesh line pixels: {lines} refined, {plain_lines} regular"
    );
}

/// Waits until `file` exists and reads it as an 8-bit RGB picture.
fn read_written(file: &Path) -> image::RgbImage {
    wait_for(Duration::from_secs(10), || file.exists().then_some(()))
        .unwrap_or_else(|| panic!("{} was not written", file.display()));
    // The file is renamed into place when complete, so it reads whole.
    image::open(file).unwrap().to_rgb8()
}

/// Presses `q` and checks the program exits 0 within 5 s.
fn quit(display: &str, program: &mut Reaper) {
    xdotool(display, &["key", "q"]).expect("key q");
    let status = wait_for(Duration::from_secs(5), || {
        program.0.try_wait().ok().flatten()
    })
    .expect("the program exits within 5 s of q");
    assert!(status.success(), "exit status {status}");
}

/// The title the guide gives as its example is the one rtable's window
/// shows once converged, rays per second aside (they vary with the
/// machine).
#[test]
fn the_guides_title_example_is_rtables_converged_title() {
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let guide = std::fs::read_to_string(common::root().join("docs/guide.md")).unwrap();
    let example = guide
        .split('`')
        .find(|span| span.starts_with("radiosity — rtable — "))
        .expect("the guide gives a title example");
    // The number before ` Mrays/s` varies: a snapbox wildcard.
    let (before, after) = example.split_once(" Mrays/s").expect("Mrays/s");
    let pattern = format!(
        "{}[..] Mrays/s{after}",
        &before[..before.rfind(' ').unwrap() + 1]
    );
    let Some((_xvfb, display)) = x_server() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (mut program, window) = open_scene("rtable", dir.path(), &display, &[]);
    let title = wait_for(Duration::from_secs(120), || {
        let title = xdotool(&display, &["getwindowname", &window])?;
        title.contains("converged").then_some(title)
    })
    .expect("rtable converges in the window");
    snapbox::Assert::new()
        .try_eq(Some(&"the window's title"), title.into(), pattern.into())
        .unwrap_or_else(|e| panic!("docs/guide.md's title example:\n{e}"));
    quit(&display, &mut program);
}

/// From the camera of every bundled scene, dragging with the left button
/// (150 px right and 80 px up, then back to the start) looks around
/// from the eye: the view stays in the room and the picture `w` writes is
/// not black. The state panel is on the screen but not in that picture:
/// `p` writes the screen with it, and after `i` without it.
#[test]
fn looking_around_stays_in_every_bundled_room_and_the_panel_toggles() {
    // A failed test poisons the lock; the next one may still run.
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let Some((_xvfb, display)) = x_server() else {
        return;
    };
    // A few thousand vertices each: `cornell` is 550 units wide, the
    // others a few metres (at 0.5 `cornell` would have 9 million vertices
    // and take most of a minute for its four steps).
    for (name, lenmax) in [("cornell", "20"), ("rtable", "0.5"), ("table_chair", "0.5")] {
        let dir = tempfile::tempdir().unwrap();
        // A few steps, then a still picture, so the files can be compared.
        let (mut program, window) = open_scene(
            name,
            dir.path(),
            &display,
            &["--max-steps", "4", "--lenmax", lenmax],
        );
        wait_for(Duration::from_secs(60), || {
            let title = xdotool(&display, &["getwindowname", &window])?;
            title.contains("step limit").then_some(())
        })
        .unwrap_or_else(|| panic!("{name}: the solve reaches its step limit"));
        xdotool(&display, &["windowfocus", "--sync", &window]).expect("focus");
        xdotool(&display, &["mousemove", "--window", &window, "80", "60"]).expect("move");
        // Each event given time to arrive on its own: a press that lands
        // together with the first motion may start the drag a step late.
        std::thread::sleep(Duration::from_millis(100));
        xdotool(&display, &["mousedown", "1"]).expect("press");
        std::thread::sleep(Duration::from_millis(100));
        // Out and back to the very point pressed: a drag turns the view by
        // the way from where the pointer was before the press was seen to
        // where it was after the release was seen, so the turn is nil
        // however late a busy machine notices either (the camera of
        // `cornell` is outside its open box: turned far, it sees the
        // void).
        for (dx, dy) in [(30, -16); 5].into_iter().chain([(-30, 16); 5]) {
            xdotool(
                &display,
                &["mousemove_relative", "--", &dx.to_string(), &dy.to_string()],
            )
            .expect("drag");
            std::thread::sleep(Duration::from_millis(60));
        }
        std::thread::sleep(Duration::from_millis(100));
        xdotool(&display, &["mouseup", "1"]).expect("release");
        std::thread::sleep(Duration::from_millis(200));
        xdotool(&display, &["key", "w"]).expect("key w");
        let picture = read_written(&dir.path().join(format!("{name}-001.tiff")));
        // Lit surfaces: not dark, and not the stripes back faces are drawn
        // in (which would mean the eye left the room).
        let lit = picture
            .enumerate_pixels()
            .filter(|&(x, y, p)| {
                p.0.iter().any(|&c| c > 30) && p.0 != radiosity::render::back_face_color(x, y)
            })
            .count();
        if lit <= 160 * 120 / 3 {
            let keep = std::env::temp_dir().join(format!("viewer-{name}-looked-around.png"));
            let _ = picture.save(&keep);
            panic!(
                "{name}: after looking around the picture is mostly black ({lit} lit pixels; \
                 kept as {})",
                keep.display()
            );
        }
        xdotool(&display, &["key", "p"]).expect("key p");
        let screen = read_written(&dir.path().join(format!("{name}-002.tiff")));
        xdotool(&display, &["key", "i"]).expect("key i");
        std::thread::sleep(Duration::from_millis(200));
        xdotool(&display, &["key", "p"]).expect("key p");
        let bare = read_written(&dir.path().join(format!("{name}-003.tiff")));
        quit(&display, &mut program);
        // The panel covers the top-left corner of the screen only.
        let differ: Vec<(u32, u32)> = picture
            .enumerate_pixels()
            .filter(|&(x, y, p)| screen.get_pixel(x, y) != p)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert!(differ.len() > 200, "{name}: the panel is not on the screen");
        // Four lines at most: the solve, the exposure and mesh, the keys,
        // and what the last key did (here `w`'s file).
        assert!(
            differ.iter().all(|&(x, y)| x < 160 && y < 64),
            "{name}: the screen differs from the picture outside the panel"
        );
        assert_eq!(bare, picture, "{name}: i hides the panel");
    }
}

/// `c` prints the camera as options and as a `.sc` block, Shift+C saves
/// it next to the scene (a second press under a new name), and `f` writes
/// the view at `--aa` samples a pixel: the same view and exposure as `w`'s
/// picture, with smoother edges. The saved camera renders the same view.
#[test]
fn camera_keys_print_and_save_the_view_and_f_writes_it_at_full_quality() {
    // A failed test poisons the lock; the next one may still run.
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let Some((_xvfb, display)) = x_server() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("box.sc");
    std::fs::copy(common::scene("cornell.sc"), &scene).unwrap();
    let (mut program, window) = open_file(
        &scene,
        dir.path(),
        &display,
        &["--lenmax", "80", "--max-steps", "4", "--aa", "3"],
    );
    wait_for(Duration::from_secs(60), || {
        let title = xdotool(&display, &["getwindowname", &window])?;
        title.contains("step limit").then_some(())
    })
    .expect("the solve reaches its step limit");
    xdotool(&display, &["windowfocus", "--sync", &window]).expect("focus");
    xdotool(&display, &["key", "c"]).expect("key c");
    xdotool(&display, &["key", "shift+c"]).expect("key C");
    let saved = dir.path().join("box-camera.sc");
    wait_for(Duration::from_secs(10), || saved.exists().then_some(()))
        .expect("Shift+C saves box-camera.sc next to the scene");
    xdotool(&display, &["key", "shift+c"]).expect("key C");
    let again = dir.path().join("box-camera-2.sc");
    wait_for(Duration::from_secs(10), || again.exists().then_some(()))
        .expect("a second Shift+C saves box-camera-2.sc");
    xdotool(&display, &["key", "f"]).expect("key f");
    let full = read_written(&dir.path().join("box-001.png"));
    xdotool(&display, &["key", "w"]).expect("key w");
    let plain = read_written(&dir.path().join("box-002.tiff"));
    quit(&display, &mut program);
    let stdout = program.stdout();

    // The printed options and block, and the saved file, are one camera.
    let options = stdout
        .lines()
        .skip_while(|l| *l != "camera, as options:")
        .nth(1)
        .unwrap_or_else(|| panic!("no camera printed: {stdout}"))
        .trim()
        .to_string();
    assert!(
        options.starts_with("--eye ") && options.ends_with("--size 160x120"),
        "{options}"
    );
    assert!(stdout.contains("camera\n  eye "), "{stdout}");
    assert!(
        stdout.contains(&format!("wrote {}", saved.display())),
        "{stdout}"
    );
    let info = common::run_in(
        dir.path(),
        &["box.sc", "--camera", saved.to_str().unwrap(), "--info"],
    );
    let info = String::from_utf8(info.stdout).unwrap();
    assert!(
        info.contains(&format!("camera (from the file): {options}\n")),
        "{options}\n{info}"
    );
    let words: Vec<&str> = options.split_whitespace().collect();
    let mut args = vec!["box.sc", "--info"];
    args.extend_from_slice(&words);
    let info = common::run_in(dir.path(), &args);
    let info = String::from_utf8(info.stdout).unwrap();
    assert!(
        info.contains(&format!("): {options}\n")),
        "{options}\n{info}"
    );

    // `f`: the window's size, the same picture as `w`'s but for its edges.
    assert_eq!((full.width(), full.height()), (160, 120));
    let diffs: Vec<i32> = full
        .as_raw()
        .iter()
        .zip(plain.as_raw())
        .map(|(&a, &b)| (i32::from(a) - i32::from(b)).abs())
        .collect();
    let changed = diffs.iter().filter(|&&d| d > 0).count();
    let mean = diffs.iter().sum::<i32>() as f64 / diffs.len() as f64;
    assert!(
        changed > 100,
        "f drew the same pixels as w ({changed} differ)"
    );
    assert!(
        mean < 6.0,
        "f's picture is not w's view: mean difference {mean}"
    );
}
