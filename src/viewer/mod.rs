//! The interactive window: shows the solution converging, redrawn after
//! every shooting step (at most every [`REDRAW_INTERVAL`]), lets the user
//! move around it and write pictures.
//!
//! The solver runs on a worker thread and publishes a copy of the vertex
//! radiosities after each step; the window thread renders the latest copy
//! with the same [`Rasterizer`] and tone mapping the batch command uses, so
//! what `w` writes is exactly what is on screen. The window never waits
//! for a step, and a long step comes in parts of about
//! [`WINDOW_PART_BUDGET`](crate::solver::tuning::WINDOW_PART_BUDGET) of
//! solving, each published with the receivers it finished
//! ([`crate::solver::step::parts`]), so the picture moves while a large scene's
//! step runs; quitting cancels the part under way
//! ([`Method::step_cancellable`](crate::solver::Method::step_cancellable)).
//!
//! With adaptive subdivision the worker refines the mesh once a solve
//! converges and solves again on the refined mesh; meanwhile the window
//! keeps showing the last converged solution (the title says which pass
//! is running) and switches to the finer one when it converges.
//!
//! Before the solver's first step the window shows the emitters lit and
//! every other surface with the ambient term ([`crate::solver::first_look`]),
//! never a black picture.
//!
//! A small state panel ([`render::text::draw_panel`], its lines from
//! [`panel`]) in the top-left corner shows the step ("starting" before the
//! first), unshot power, rays per second, whether the solve converged, the
//! exposure, the mesh, the navigation mode and the keys, what `w` asks in
//! the terminal, and what the last key did (a file written, the camera
//! printed); `i` hides it. It is drawn on the screen only: `w` writes the
//! picture without it, `p` writes the screen as shown, panel included.
//!
//! Keys: `q`/Escape quit · `w` write the picture as TIFF · `f` write the
//! view at full quality (`--aa` samples a pixel) as PNG · `p` write the
//! screen · `c` print the camera as options and as a `.sc` block ·
//! Shift+C save it as `<scene>-camera.sc` next to the scene · space pause
//! or resume · `+`/`-` exposure · `m` element mesh · `i` state panel · `r`
//! reset the camera · `o` left-drag mode · `h` help · arrows and `a`/`d`
//! (or Shift+W/A/S/D) walk · `PageUp`/`PageDown` up and down. Mouse:
//! left-drag looks around (or, after `o`, orbits around the surface point
//! under the cursor), right-drag or the wheel moves towards or away from
//! the surface under the cursor, stopping in front of it.

pub mod controls;
pub mod panel;
pub mod pointer;

use crate::color::Rgb;
use crate::config::RunConfig;
use crate::mesh::MeshRef;
use crate::output;
use crate::prepare::Prepared;
use crate::render::{self, antialias, Exposure, Rasterizer, View};
use crate::session::{Event, Session, SessionOptions};
use crate::solver::StopReason;
use controls::CameraControl;
use glam::Vec3;
use image::RgbImage;
use minifb::{InputCallback, Key, MouseButton, MouseMode, Window, WindowOptions};
use pointer::{Buttons, Pointer};
use std::io::{BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Shortest time between two pictures drawn because the solution changed;
/// input (camera, exposure) redraws at once.
pub const REDRAW_INTERVAL: Duration = Duration::from_millis(50);
/// How often the window polls input when nothing changes (about 60 Hz).
pub const FRAME_INTERVAL: Duration = Duration::from_millis(16);

/// A part of a step publishes its picture once the solving since the last
/// picture is this many times what publishing one costs; the window draws
/// a new solution once this many times its last drawing's time has
/// passed.
const PUBLISH_SHARE: u32 = 4;
pub use controls::ORBIT_PER_PIXEL;

/// Radians the view turns per pixel of left-drag when looking around: a
/// drag across a 640-pixel window turns it by about 100 degrees.
pub const LOOK_PER_PIXEL: f32 = 0.003;

/// What a left-drag does in the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Navigation {
    /// Turn the view about the eye (the default: from inside a room, the
    /// view stays in the room).
    Look,
    /// Turn the eye around the surface point under the cursor when the
    /// drag starts (around the look-at point when the cursor is over
    /// background), to inspect an object.
    Orbit,
}

impl Navigation {
    /// How the title and the terminal name the mode.
    pub fn name(self) -> &'static str {
        match self {
            Navigation::Look => "look around",
            Navigation::Orbit => "orbit",
        }
    }
}
/// Zoom factor per pixel of right-drag (`exp` of this times the pixels):
/// the factor by which the distance to the point under the cursor changes.
pub const ZOOM_PER_PIXEL: f32 = 0.01;
/// Zoom factor per notch of the mouse wheel (towards the point under the
/// cursor; its inverse away from it).
pub const ZOOM_PER_NOTCH: f32 = 0.85;
/// How close zooming brings the eye to the surface under the cursor, as a
/// fraction of the scene camera's distance to its look-at point: it stops
/// in front of the surface, never on or through it.
pub const ZOOM_STOP_FRACTION: f32 = 0.02;
/// Walking step per key press, as a fraction of the distance to the
/// look-at point.
pub const WALK_STEP: f32 = 0.05;
/// Exposure factor of one `+` or `-` press (a third of a stop).
pub const EXPOSURE_STEP: f32 = 1.26;

/// The key help printed by `h`.
pub const KEY_HELP: &str = "\
keys:
  q, Escape        quit
  w                write the picture as TIFF (asks for a name on a terminal)
  f                write the view at full quality (--aa samples a pixel) as PNG
  c                print the camera as --eye ... options and as a .sc block
  Shift+C          save the camera as <scene>-camera.sc next to the scene
  space            pause / resume the solver
  + / -            exposure up / down (a third of a stop)
  m                show / hide the element mesh
  i                show / hide the state panel (never in pictures from w)
  p                write the screen as shown, state panel included
  r                reset the camera
  h                this help
  arrows, a, d     walk (Shift+W/A/S/D too); PageUp / PageDown: up / down
  o                switch left-drag between looking around and orbiting
mouse:
  left-drag        look around from the eye (after o: orbit around the
                   surface point under the cursor)
  right-drag, wheel  move towards / away from the surface under the
                   cursor (stops in front of it)";

/// Why the window could not run.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No display, or the display libraries are missing: the caller can
    /// fall back to batch mode.
    #[error("{0}")]
    CannotOpen(String),
    /// The picture could not be made (a bug if it happens).
    #[error("{0}")]
    Render(#[from] render::RenderError),
    /// The view is unusable.
    #[error("{0}")]
    View(#[from] render::ViewError),
}

/// Why no window can be tried at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NoDisplay {
    /// Only a Wayland display: the window needs X11 (XWayland).
    #[error("WAYLAND_DISPLAY is set but DISPLAY is not: the window needs X11 (XWayland)")]
    WaylandOnly,
    /// No display at all.
    #[error("no display (DISPLAY is not set)")]
    Unset,
}

/// Whether a window can be tried at all: `Err` says why not.
pub fn display_available() -> Result<(), NoDisplay> {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") {
        Ok(())
    } else if set("WAYLAND_DISPLAY") {
        Err(NoDisplay::WaylandOnly)
    } else {
        Err(NoDisplay::Unset)
    }
}

/// What the solver thread publishes after each step.
#[derive(Clone, Debug, Default)]
struct Progress<'p> {
    /// The mesh [`Progress::radiosity`] belongs to: the prepared mesh or
    /// its latest adaptive refinement; `None` before the first
    /// publication.
    mesh: Option<MeshRef<'p>>,
    radiosity: Vec<Rgb>,
    /// The solution alone (without the ambient term) when
    /// [`Progress::radiosity`] shows the ambient term, published with it
    /// from the first step on; empty before, and without the ambient term.
    solution: Vec<Rgb>,
    step: u64,
    unshot_fraction: f64,
    rays: u64,
    /// Particles the solve's tail has traced ([`crate::solver::step::tail`]).
    particles: u64,
    /// Seconds spent shooting (pauses excluded).
    solving: f64,
    stopped: Option<StopReason>,
    /// The adaptive pass running (1 for the first solve), and how many
    /// refinements may follow it at most; `(1, 0)` without refinement.
    pass: (u32, u32),
    /// Bumped on every change.
    version: u64,
}

/// Flags the window sets for the solver thread.
struct Control {
    quit: AtomicBool,
    paused: AtomicBool,
}

/// Opens the window and runs until the user quits. Returns an error
/// without side effects when no window can be opened.
pub fn run(prepared: &Prepared, config: &RunConfig) -> Result<(), ViewerError> {
    display_available().map_err(|why| ViewerError::CannotOpen(why.to_string()))?;
    let home = {
        let view = prepared.view(config)?;
        let mut camera = prepared.scene.camera;
        camera.width = view.width();
        camera.height = view.height();
        camera
    };
    let (w, h) = (home.width as usize, home.height as usize);
    let stem = config.scene.stem();
    let mut window = Window::new(
        &format!("radiosity — {stem}"),
        w,
        h,
        WindowOptions::default(),
    )
    .map_err(|e| ViewerError::CannotOpen(format!("cannot open a window: {e}")))?;
    let presses = Arc::new(Mutex::new(Vec::new()));
    window.set_input_callback(Box::new(KeyPresses {
        queue: Arc::clone(&presses),
        shift: [false; 2],
    }));

    let progress = Mutex::new(Progress::default());
    let control = Control {
        quit: AtomicBool::new(false),
        paused: AtomicBool::new(false),
    };

    std::thread::scope(|scope| {
        scope.spawn(|| solve_in_background(prepared, config, &progress, &control));
        let mut ui = Ui {
            prepared,
            window: &mut window,
            camera: {
                let (lo, hi) = prepared.scene.bounds();
                CameraControl::new(home).within(lo, hi)
            },
            exposure: config.exposure,
            exposure_scale: 1.0,
            exposure_used: 1.0,
            aa: config.aa,
            camera_dir: match &config.scene {
                crate::config::SceneSource::File(path) => {
                    path.parent().map(Path::to_path_buf).unwrap_or_default()
                }
                crate::config::SceneSource::Bundled => PathBuf::new(),
            },
            message: None,
            show_mesh: false,
            show_panel: true,
            stem: stem.clone(),
            rasterizer: Rasterizer::new(),
            picture: RgbImage::new(home.width, home.height),
            screen: RgbImage::new(home.width, home.height),
            panel: Vec::new(),
            first_look: None,
            pivot: None,
            writes: Vec::new(),
            buffer: vec![0; w * h],
            radiosity: Vec::new(),
            solution: Vec::new(),
            probe: Rasterizer::new(),
            mesh: None,
            pointer: Pointer::default(),
            written: 0,
            navigation: Navigation::Look,
            presses,
            pending_name: None,
        };
        let result = ui.run(&progress, &control);
        control.quit.store(true, Ordering::Relaxed);
        if config.progress {
            if let Ok(p) = progress.lock() {
                eprintln!(
                    "{}",
                    closing_summary(&stem, &p, prepared.scene.emits(), ui.written)
                );
            }
        }
        result
    })
}

/// The line printed on the terminal when the window closes (unless
/// `--quiet`): how far the solve got, in the words of the batch summary,
/// and how many pictures `w` wrote.
fn closing_summary(stem: &str, p: &Progress, emits: bool, written: u32) -> String {
    let state = match p.stopped {
        Some(_) if !emits => "nothing emits",
        Some(StopReason::Converged) => "converged",
        Some(StopReason::MaxSteps) => "step limit",
        None => "not converged",
    };
    let pictures = match written {
        0 => String::new(),
        1 => ", 1 picture written".into(),
        n => format!(", {n} pictures written"),
    };
    let tail = if p.particles > 0 {
        format!(" (the tail by {:.1} M particles)", p.particles as f64 / 1e6)
    } else {
        String::new()
    };
    format!(
        "{stem}: window closed after {} steps{tail}, {:.2} s solving, {:.1} M rays, {:.3}% unshot, {state}{pictures}",
        p.step,
        p.solving,
        p.rays as f64 / 1e6,
        p.unshot_fraction * 100.0
    )
}

/// The solver thread: runs the solve session (which, with adaptive
/// subdivision, refines and goes on) until it finishes or the window
/// quits, publishing after each step. The first pass is shown as it
/// converges; a refined pass only once it has converged, so the picture
/// never falls back to darkness.
fn solve_in_background<'p>(
    prepared: &'p Prepared,
    config: &RunConfig,
    progress: &Mutex<Progress<'p>>,
    control: &Control,
) {
    // Long steps come in parts, so the picture moves at least every
    // tenth of a second or so of solving.
    let mut options = SessionOptions::for_run(config, prepared, true);
    options.solver.part_budget = Some(crate::solver::tuning::WINDOW_PART_BUDGET);
    let mut session = Session::from_prepared(prepared, options);
    let levels = session.max_refinements();
    if let Ok(mut p) = progress.lock() {
        session.shown(&mut p.radiosity);
        p.mesh = Some(session.mesh_ref());
        p.unshot_fraction = session.unshot_fraction();
        p.pass = (1, levels);
        p.version += 1;
    }
    let mut solving = Duration::ZERO;
    let mut stopped = None;
    // What publishing a picture costs (the ambient term and a copy of
    // every vertex), and when the last was: a part of a step publishes
    // only when that cost stays a fifth of the solving between pictures,
    // so a mesh of millions of vertices is not slowed by its pictures.
    let mut publishing = Duration::ZERO;
    let mut published = Instant::now();
    loop {
        if control.quit.load(Ordering::Relaxed) {
            return;
        }
        if control.paused.load(Ordering::Relaxed) {
            std::thread::sleep(FRAME_INTERVAL);
            continue;
        }
        let t = Instant::now();
        let event = session.advance(&control.quit);
        solving += t.elapsed();
        let Ok(mut p) = progress.lock() else {
            return;
        };
        // Whether the window has something new to draw.
        let mut changed = true;
        match event {
            Ok(Event::Step(report)) => {
                let due = report.complete
                    || published.elapsed() >= REDRAW_INTERVAL.max(publishing * PUBLISH_SHARE);
                changed = due;
                if session.pass() == 1 && due {
                    let t = Instant::now();
                    session.shown(&mut p.radiosity);
                    if session.options().ambient {
                        session.solution(&mut p.solution);
                    }
                    publishing = t.elapsed();
                    published = Instant::now();
                }
                p.step = report.step;
                p.unshot_fraction = report.unshot_fraction;
                p.rays = session.totals().rays;
                p.particles = session.solver().particles();
                p.solving = solving.as_secs_f64();
            }
            Ok(Event::Stopped(reason)) => {
                stopped = Some(reason);
                session.shown(&mut p.radiosity);
                if session.options().ambient && session.totals().steps > 0 {
                    session.solution(&mut p.solution);
                }
                p.mesh = Some(session.mesh_ref());
            }
            Ok(Event::Refined(_)) => {
                p.unshot_fraction = session.unshot_fraction();
                p.pass = (session.pass(), levels);
            }
            Ok(Event::Refused(refused)) => eprintln!("warning: {refused}"),
            Ok(Event::Finished) => {
                p.stopped = stopped;
                p.version += 1;
                break;
            }
            Ok(Event::Cancelled) => return,
            Err(e) => {
                // A refined pass could not take over the last one's state
                // (a bug): keep showing the last solution.
                eprintln!("error: {e}");
                p.stopped = stopped;
                p.version += 1;
                break;
            }
        }
        if changed {
            p.version += 1;
        }
    }
    while !control.quit.load(Ordering::Relaxed) {
        std::thread::sleep(FRAME_INTERVAL);
    }
}

/// The window thread's state.
struct Ui<'a> {
    prepared: &'a Prepared,
    window: &'a mut Window,
    camera: CameraControl,
    exposure: Exposure,
    exposure_scale: f32,
    /// The factor the picture on screen was drawn with: the automatic or
    /// given exposure times `exposure_scale`.
    exposure_used: f32,
    /// Samples per pixel side of the full-quality picture (`f`, `--aa`).
    aa: u32,
    /// Where Shift+C saves the camera: the scene's folder (the current
    /// one for the bundled scene).
    camera_dir: PathBuf,
    /// What the last key did, and when, for the panel.
    message: Option<(String, Instant)>,
    show_mesh: bool,
    /// Whether the state panel is drawn on the screen (`i`).
    show_panel: bool,
    stem: String,
    rasterizer: Rasterizer,
    /// The picture as `w` writes it: the solution, with the mesh when shown.
    picture: RgbImage,
    /// What the window shows: the picture with the state panel.
    screen: RgbImage,
    /// The state panel's lines as last drawn.
    panel: Vec<String>,
    /// What is drawn before the solver's first publication
    /// ([`crate::solver::first_look`]), made on the first frame.
    first_look: Option<Vec<Rgb>>,
    /// The point a drag turns around or moves towards, picked under the
    /// cursor when the button went down (scene units).
    pivot: Option<Vec3>,
    /// Pictures asked for by keys this frame, written once it is drawn.
    writes: Vec<Writing>,
    buffer: Vec<u32>,
    radiosity: Vec<Rgb>,
    /// The solution without the ambient term, per vertex of the same mesh
    /// (see [`Progress::solution`]), for the exposure.
    solution: Vec<Rgb>,
    /// Draws the solution alone, small, for the automatic exposure
    /// ([`render::auto_exposure_beside`]).
    probe: Rasterizer,
    /// The mesh [`Ui::radiosity`] belongs to (`None`: nothing published
    /// yet).
    mesh: Option<MeshRef<'a>>,
    /// The pointer as seen at the last frame, for drags.
    pointer: Pointer,
    written: u32,
    /// What a left-drag does; `o` switches.
    navigation: Navigation,
    presses: Arc<Mutex<Vec<Press>>>,
    /// A `w` waiting for its file name from the terminal, with the picture
    /// as it was when `w` was pressed and the name Enter gives.
    pending_name: Option<(std::sync::mpsc::Receiver<PathBuf>, RgbImage, PathBuf)>,
}

/// A picture a key asked to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Writing {
    /// The picture (`w`): the solution, with the mesh when shown.
    Picture,
    /// The screen as shown (`p`): the picture with the state panel.
    Screen,
    /// The view at full quality (`f`): `--aa` samples a pixel.
    FullQuality,
}

/// A key press, and whether a Shift key was down when it came.
type Press = (Key, bool);

/// Collects every key press as it arrives, with the Shift state of that
/// moment. Polling the key state once a frame would miss a tap shorter
/// than a frame (and a Shift released before the frame that reads the
/// key); the callback sees each press event (auto-repeats included).
struct KeyPresses {
    queue: Arc<Mutex<Vec<Press>>>,
    /// Which Shift keys are down: left, right.
    shift: [bool; 2],
}

impl InputCallback for KeyPresses {
    fn add_char(&mut self, _uni_char: u32) {}

    fn set_key_state(&mut self, key: Key, down: bool) {
        match key {
            Key::LeftShift => self.shift[0] = down,
            Key::RightShift => self.shift[1] = down,
            _ if down => {
                if let Ok(mut q) = self.queue.lock() {
                    q.push((key, self.shift[0] || self.shift[1]));
                }
            }
            _ => {}
        }
    }
}

impl<'a> Ui<'a> {
    fn run(
        &mut self,
        progress: &Mutex<Progress<'a>>,
        control: &Control,
    ) -> Result<(), ViewerError> {
        let mut shown_version = u64::MAX;
        let mut last_draw = Instant::now() - REDRAW_INTERVAL;
        let mut draw_cost = Duration::ZERO;
        let mut dirty = true;
        let mut title = String::new();
        let emits = self.prepared.scene.emits();
        while self.window.is_open() {
            let keys: Vec<Press> = self
                .presses
                .lock()
                .map(|mut q| std::mem::take(&mut *q))
                .unwrap_or_default();
            if keys.iter().any(|(k, _)| matches!(k, Key::Q | Key::Escape)) {
                break;
            }
            dirty |= self.handle_keys(&keys, control);
            self.finish_pending_write();
            dirty |= self.handle_mouse();

            let snapshot = progress.lock().map(|p| {
                (
                    p.version,
                    p.step,
                    p.unshot_fraction,
                    p.rays,
                    p.solving,
                    p.stopped,
                    p.pass,
                )
            });
            let Ok((version, step, unshot, rays, solving, stopped, pass)) = snapshot else {
                break;
            };
            // A new solution is drawn at most every REDRAW_INTERVAL, and
            // no more often than leaves the solver four fifths of the
            // time on a mesh that is slow to draw; input draws at once.
            let fresh = version != shown_version
                && last_draw.elapsed() >= REDRAW_INTERVAL.max(draw_cost * PUBLISH_SHARE);
            let drawn = fresh || dirty;
            if drawn {
                let t = Instant::now();
                if let Ok(p) = progress.lock() {
                    self.radiosity.clone_from(&p.radiosity);
                    self.solution.clone_from(&p.solution);
                    self.mesh.clone_from(&p.mesh);
                }
                shown_version = version;
                self.draw()?;
                last_draw = Instant::now();
                draw_cost = t.elapsed();
                dirty = false;
            }
            let solve = panel::SolveState {
                step,
                unshot,
                mrays_per_second: if solving > 0.0 {
                    rays as f64 / solving / 1e6
                } else {
                    0.0
                },
                stopped,
                emits,
                paused: control.paused.load(Ordering::Relaxed),
                pass,
            };
            let status = panel::status(&solve);
            let new_title = format!(
                "radiosity — {} — {status} · {} · h: help",
                self.stem,
                self.navigation.name()
            );
            if new_title != title {
                self.window.set_title(&new_title);
                title = new_title;
            }
            let panel = if self.show_panel {
                self.panel_lines(status)
            } else {
                Vec::new()
            };
            if drawn || panel != self.panel {
                self.panel = panel;
                self.compose();
            }
            // After the redraw, so a `w` typed right after `m` or a move
            // writes what they asked for.
            for write in std::mem::take(&mut self.writes) {
                match write {
                    Writing::Picture => self.write_picture(),
                    Writing::Screen => self.write_screen(),
                    Writing::FullQuality => self.write_full_quality(),
                }
            }
            let (w, h) = (
                self.picture.width() as usize,
                self.picture.height() as usize,
            );
            if self.window.update_with_buffer(&self.buffer, w, h).is_err() {
                break;
            }
            std::thread::sleep(FRAME_INTERVAL);
        }
        Ok(())
    }

    /// Renders the current solution from the current camera into the
    /// picture and the window buffer.
    fn draw(&mut self) -> Result<(), ViewerError> {
        let view = View::new(self.camera.camera())?;
        let (mesh, radiosity) = shown(
            self.prepared,
            self.mesh.as_deref(),
            &self.radiosity,
            &mut self.first_look,
        );
        let frame = self.rasterizer.render(mesh, radiosity, &view)?;
        // Once light has been shot, the ambient term brightens the picture
        // but does not set its exposure (before, it is all there is).
        let beside = self.solution.len() == radiosity.len();
        let exposure = match self.exposure {
            Exposure::Auto if beside => {
                let camera = self.camera.camera();
                let (pw, ph) = render::exposure_probe_size(view.width(), view.height());
                let probe = View::with_size(camera, pw, ph)?;
                let alone = self.probe.render(mesh, &self.solution, &probe)?;
                render::auto_exposure_beside(frame, alone)
            }
            exposure => exposure.resolve(frame),
        } * self.exposure_scale;
        self.exposure_used = exposure;
        self.picture = render::to_srgb8(frame, exposure);
        if self.show_mesh {
            render::draw_mesh_edges(
                &mut self.picture,
                mesh,
                &view,
                self.rasterizer.inv_depth(),
                render::MESH_LINES,
            );
        }
        Ok(())
    }

    /// The panel's lines (see [`panel`]): `status`, the exposure and the
    /// mesh, the keys, and `w`'s question in the terminal while it waits
    /// or else what the last key did, for [`MESSAGE_SHOWN`].
    fn panel_lines(&self, status: String) -> Vec<String> {
        let elements = self
            .mesh
            .as_deref()
            .map_or(self.prepared.mesh.elements.len(), |m| m.elements.len());
        let mut lines = vec![
            status,
            format!(
                "{} · {}",
                panel::exposure(
                    self.exposure_used,
                    self.exposure == Exposure::Auto,
                    self.exposure_scale,
                ),
                panel::mesh(elements, self.show_mesh)
            ),
            panel::keys(self.navigation),
        ];
        // One line more at most: `w`'s question while it waits, else what
        // the last key did.
        if let Some((_, _, default)) = &self.pending_name {
            lines.push(panel::prompt(default));
        } else if let Some((message, since)) = &self.message {
            if since.elapsed() < MESSAGE_SHOWN {
                lines.push(message.clone());
            }
        }
        lines
    }

    /// Says `message` in the panel, and shows it at once (before a write
    /// that keeps the window busy).
    fn say(&mut self, message: String, now: bool) {
        self.message = Some((message, Instant::now()));
        if now && self.show_panel {
            let status = self.panel.first().cloned().unwrap_or_default();
            self.panel = self.panel_lines(status);
            self.compose();
            let (w, h) = (
                self.picture.width() as usize,
                self.picture.height() as usize,
            );
            let _ = self.window.update_with_buffer(&self.buffer, w, h);
        }
    }

    /// The screen from the picture and the state panel, into the window
    /// buffer.
    fn compose(&mut self) {
        self.screen.clone_from(&self.picture);
        if !self.panel.is_empty() {
            let lines: Vec<&str> = self.panel.iter().map(String::as_str).collect();
            render::text::draw_panel(&mut self.screen, &lines);
        }
        self.buffer.resize(self.screen.pixels().len(), 0);
        for (out, p) in self.buffer.iter_mut().zip(self.screen.pixels()) {
            let [r, g, b] = p.0;
            *out = (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b);
        }
    }

    /// The surface point drawn at window position `(x, y)` (pixels from
    /// the top-left corner), from the last picture's depth buffer; `None`
    /// over background or outside the window.
    fn pick(&self, x: f32, y: f32) -> Option<Vec3> {
        let (w, h) = (self.picture.width(), self.picture.height());
        if !(x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32) {
            return None;
        }
        let depth = *self
            .rasterizer
            .inv_depth()
            .get(y as usize * w as usize + x as usize)?;
        View::new(self.camera.camera()).ok()?.unproject(
            f64::from(x.floor()) + 0.5,
            f64::from(y.floor()) + 0.5,
            depth,
        )
    }

    /// The point a zoom at window position `(x, y)` moves towards: the
    /// surface under the cursor, or over background the point on the
    /// cursor's ray as far away as the look-at point.
    fn zoom_target(&self, x: f32, y: f32) -> Option<Vec3> {
        self.pick(x, y).or_else(|| {
            let view = View::new(self.camera.camera()).ok()?;
            let ray = view.ray_direction(f64::from(x), f64::from(y));
            Some(view.eye() + ray * self.camera.distance())
        })
    }

    /// How far in front of a surface zooming stops, in scene units.
    fn zoom_stop(&self) -> f32 {
        self.camera.home_distance() * ZOOM_STOP_FRACTION
    }

    /// Applies key presses; true when the picture must be redrawn.
    fn handle_keys(&mut self, keys: &[Press], control: &Control) -> bool {
        let mut dirty = false;
        // Shift as it was when each key went down: `c` then Shift+`C`
        // typed within one frame are a print and a save, where the state
        // polled once a frame would make both saves.
        for &(key, shift) in keys {
            match key {
                Key::W if !shift => self.writes.push(Writing::Picture),
                Key::F => self.writes.push(Writing::FullQuality),
                Key::C if shift => self.save_camera(),
                Key::C => self.print_camera(),
                Key::Space => {
                    let paused = !control.paused.load(Ordering::Relaxed);
                    control.paused.store(paused, Ordering::Relaxed);
                }
                Key::Equal | Key::NumPadPlus => {
                    self.exposure_scale *= EXPOSURE_STEP;
                    dirty = true;
                }
                Key::Minus | Key::NumPadMinus => {
                    self.exposure_scale /= EXPOSURE_STEP;
                    dirty = true;
                }
                Key::M => {
                    self.show_mesh = !self.show_mesh;
                    dirty = true;
                }
                Key::I => self.show_panel = !self.show_panel,
                Key::P => self.writes.push(Writing::Screen),
                Key::R => {
                    self.camera.reset();
                    dirty = true;
                }
                Key::H => println!("{KEY_HELP}"),
                Key::O => {
                    self.navigation = match self.navigation {
                        Navigation::Look => Navigation::Orbit,
                        Navigation::Orbit => Navigation::Look,
                    };
                    println!("left-drag: {}", self.navigation.name());
                    dirty = true;
                }
                Key::Up | Key::W => {
                    self.camera.walk(0.0, 0.0, WALK_STEP);
                    dirty = true;
                }
                Key::Down | Key::S => {
                    self.camera.walk(0.0, 0.0, -WALK_STEP);
                    dirty = true;
                }
                Key::Left | Key::A => {
                    self.camera.walk(-WALK_STEP, 0.0, 0.0);
                    dirty = true;
                }
                Key::Right | Key::D => {
                    self.camera.walk(WALK_STEP, 0.0, 0.0);
                    dirty = true;
                }
                Key::PageUp => {
                    self.camera.walk(0.0, WALK_STEP, 0.0);
                    dirty = true;
                }
                Key::PageDown => {
                    self.camera.walk(0.0, -WALK_STEP, 0.0);
                    dirty = true;
                }
                _ => {}
            }
        }
        dirty
    }

    /// Mouse drags and the wheel; true when the camera moved.
    fn handle_mouse(&mut self) -> bool {
        let mut dirty = false;
        let pos = self.window.get_mouse_pos(MouseMode::Pass);
        if let Some((_, dy)) = self.window.get_scroll_wheel() {
            let target = pos.and_then(|(x, y)| self.zoom_target(x, y));
            if let (true, Some(target)) = (dy != 0.0, target) {
                let factor = ZOOM_PER_NOTCH.powf(dy.signum());
                self.camera.dolly(target, factor, self.zoom_stop());
                dirty = true;
            }
        }
        let now = Buttons {
            left: self.window.get_mouse_down(MouseButton::Left),
            right: self.window.get_mouse_down(MouseButton::Right),
        };
        let motion = self.pointer.frame(pos, now);
        if let Some((x, y)) = motion.pressed_at {
            // The drag starts: what it turns around or moves towards is
            // the surface under the point pressed, fixed for the whole
            // drag.
            self.pivot = if now.right {
                self.zoom_target(x, y)
            } else {
                self.pick(x, y)
            };
        }
        let (dx, dy) = motion.delta;
        if dx != 0.0 || dy != 0.0 {
            if motion.buttons.left && self.navigation == Navigation::Look {
                // Drag right turns right; drag up looks up.
                self.camera.look(-dx * LOOK_PER_PIXEL, -dy * LOOK_PER_PIXEL);
            } else if motion.buttons.left {
                let pivot = self.pivot.unwrap_or(self.camera.camera().lookat);
                let k = self.camera.orbit_per_pixel(pivot);
                self.camera.orbit_about(pivot, -dx * k, dy * k);
            } else if let Some(target) = self.pivot {
                // Drag up moves towards the point, down away.
                let stop = self.zoom_stop();
                self.camera.dolly(target, (dy * ZOOM_PER_PIXEL).exp(), stop);
            }
            dirty = true;
        }
        dirty
    }

    /// Writes the screen as shown (the picture with the state panel) as
    /// TIFF under the next automatic name.
    fn write_screen(&mut self) {
        let name = self.next_auto_name("tiff");
        self.save(&name, &self.screen.clone());
    }

    /// Writes the picture on screen as TIFF. When stdin is a terminal it
    /// asks for the name there, on a helper thread so the window keeps
    /// drawing while the user types; the picture is the one on screen when
    /// `w` was pressed. Otherwise it picks `<scene>-NNN.tiff`.
    fn write_picture(&mut self) {
        let default = self.next_auto_name("tiff");
        if !std::io::stdin().is_terminal() {
            self.save(&default, &self.picture.clone());
            return;
        }
        if self.pending_name.is_some() {
            return;
        }
        eprint!("write picture to [{}]: ", default.display());
        let _ = std::io::stderr().flush();
        let (send, receive) = std::sync::mpsc::channel();
        let enter = default.clone();
        std::thread::spawn(move || {
            let mut line = String::new();
            let name = match std::io::stdin().lock().read_line(&mut line) {
                Ok(_) if !line.trim().is_empty() => PathBuf::from(line.trim()),
                _ => enter,
            };
            let _ = send.send(name);
        });
        self.pending_name = Some((receive, self.picture.clone(), default));
    }

    /// Writes the view on screen at full quality: `--aa` × `--aa` samples
    /// a pixel at the window's size (`--size`), averaged as the batch run
    /// does ([`antialias::draw`]), with the exposure on screen and the mesh
    /// when it is shown, as PNG under the next automatic name. The panel
    /// says it is writing, then what it wrote.
    fn write_full_quality(&mut self) {
        let name = self.next_auto_name("png");
        let camera = *self.camera.camera();
        let aa = antialias::factor_for(camera.width, camera.height, self.aa);
        self.say(
            format!("writing {} ({aa}×{aa} samples a pixel) …", name.display()),
            true,
        );
        let (mesh, radiosity) = shown(
            self.prepared,
            self.mesh.as_deref(),
            &self.radiosity,
            &mut self.first_look,
        );
        let mut rasterizer = Rasterizer::new();
        let picture = antialias::draw(
            &mut rasterizer,
            mesh,
            radiosity,
            &camera,
            self.aa,
            &crate::cancel::Cancel::never(),
        )
        .map_err(|e| e.to_string())
        .and_then(|drawn| {
            let mut picture = render::to_srgb8(drawn.frame(&rasterizer), self.exposure_used);
            if self.show_mesh {
                let view = View::new(&camera).map_err(|e| e.to_string())?;
                let depth = antialias::nearest_depth(
                    rasterizer.inv_depth(),
                    camera.width * drawn.aa,
                    drawn.aa,
                );
                render::draw_mesh_edges(&mut picture, mesh, &view, &depth, render::MESH_LINES);
            }
            Ok(picture)
        });
        match picture {
            Ok(picture) => {
                if self.save(&name, &picture) {
                    self.say(
                        format!("wrote {} ({aa}×{aa} samples a pixel)", name.display()),
                        false,
                    );
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                self.say(format!("could not draw {}: {e}", name.display()), false);
            }
        }
    }

    /// Prints the camera on the terminal as command-line options and as a
    /// `.sc` camera block (`c`).
    fn print_camera(&mut self) {
        let camera = self.camera.camera();
        println!(
            "camera, as options:\n  {}\nas a .sc camera block (for --camera FILE.sc):\n{}",
            crate::camera::options_text(camera),
            crate::camera::sc_block(camera)
        );
        self.say(
            "camera printed in the terminal (Shift+C saves it)".to_string(),
            false,
        );
    }

    /// Saves the camera as a `.sc` camera file next to the scene, under the
    /// first free name ([`free_camera_path`]), never over a file (Shift+C).
    fn save_camera(&mut self) {
        let path = free_camera_path(&self.camera_dir, &self.stem);
        let camera = self.camera.camera();
        let text = format!(
            "# A camera saved in the window: render it with --camera {}\n# or with {}\n{}",
            path.display(),
            crate::camera::options_text(camera),
            crate::camera::sc_block(camera)
        );
        match output::write_atomically(&path, |w| w.write_all(text.as_bytes())) {
            Ok(()) => {
                println!("wrote {}", path.display());
                self.say(format!("wrote {}", path.display()), false);
            }
            Err(e) => {
                eprintln!("error: {e}");
                self.say(format!("could not write {}", path.display()), false);
            }
        }
    }

    /// Finishes a write whose name was typed on the terminal.
    fn finish_pending_write(&mut self) {
        let Some((receive, _, _)) = &self.pending_name else {
            return;
        };
        match receive.try_recv() {
            Ok(path) => {
                if let Some((_, picture, _)) = self.pending_name.take() {
                    self.save(&path, &picture);
                }
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => {}
            Err(std::sync::mpsc::TryRecvError::Disconnected) => self.pending_name = None,
        }
    }

    /// Writes `picture` to `path`, says so on the terminal and in the
    /// panel; true when it was written.
    fn save(&mut self, path: &Path, picture: &RgbImage) -> bool {
        match output::write_rgb8(path, picture) {
            Ok(()) => {
                self.written += 1;
                println!("wrote {}", path.display());
                self.say(format!("wrote {}", path.display()), false);
                true
            }
            Err(e) => {
                eprintln!("error: {e}");
                self.say(format!("could not write {}: {e}", path.display()), false);
                false
            }
        }
    }

    /// The first `<scene>-NNN.EXT` (NNN from 001) that does not exist.
    fn next_auto_name(&self, ext: &str) -> PathBuf {
        (self.written + 1..)
            .map(|n| PathBuf::from(format!("{}-{n:03}.{ext}", self.stem)))
            .find(|p| !p.exists())
            .unwrap_or_else(|| PathBuf::from(format!("{}.{ext}", self.stem)))
    }
}

/// How long the panel shows what the last key did.
pub const MESSAGE_SHOWN: Duration = Duration::from_secs(10);

/// The mesh and per-vertex radiosity the window shows: the solver's
/// latest publication (`mesh` with `radiosity`), or before it the first
/// look (the emitters and the ambient term, made once into `first_look`),
/// never a black window.
fn shown<'s>(
    prepared: &'s Prepared,
    mesh: Option<&'s crate::mesh::Mesh>,
    radiosity: &'s [Rgb],
    first_look: &'s mut Option<Vec<Rgb>>,
) -> (&'s crate::mesh::Mesh, &'s [Rgb]) {
    match mesh.filter(|m| radiosity.len() == m.vertex_count()) {
        Some(mesh) => (mesh, radiosity),
        None => {
            let look = first_look
                .get_or_insert_with(|| crate::solver::first_look(&prepared.scene, &prepared.mesh));
            (&prepared.mesh, look)
        }
    }
}

/// Where Shift+C saves the camera: `DIR/<stem>-camera.sc`, or the first of
/// `DIR/<stem>-camera-2.sc`, `-3`, ... that does not exist.
pub fn free_camera_path(dir: &Path, stem: &str) -> PathBuf {
    std::iter::once(dir.join(format!("{stem}-camera.sc")))
        .chain((2u32..).map(|n| dir.join(format!("{stem}-camera-{n}.sc"))))
        .find(|p| !p.exists())
        .unwrap_or_else(|| dir.join(format!("{stem}-camera.sc")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_is_saved_under_a_free_name_next_to_the_scene() {
        let dir = tempfile::tempdir().unwrap();
        let first = free_camera_path(dir.path(), "room");
        assert_eq!(first, dir.path().join("room-camera.sc"));
        std::fs::write(&first, "x").unwrap();
        let second = free_camera_path(dir.path(), "room");
        assert_eq!(second, dir.path().join("room-camera-2.sc"));
        std::fs::write(&second, "x").unwrap();
        assert_eq!(
            free_camera_path(dir.path(), "room"),
            dir.path().join("room-camera-3.sc")
        );
        // The bundled scene's camera goes to the current folder.
        assert_eq!(
            free_camera_path(Path::new(""), "rtable-test-none"),
            PathBuf::from("rtable-test-none-camera.sc")
        );
    }

    #[test]
    fn the_closing_summary_says_how_far_the_solve_got() {
        let progress = |stopped| Progress {
            step: 65,
            unshot_fraction: 0.00097,
            rays: 12_700_000,
            solving: 1.351,
            stopped,
            ..Progress::default()
        };
        let p = progress(Some(StopReason::Converged));
        assert_eq!(
            closing_summary("cornell", &p, true, 2),
            "cornell: window closed after 65 steps, 1.35 s solving, 12.7 M rays, \
             0.097% unshot, converged, 2 pictures written"
        );
        let running = progress(None);
        let line = closing_summary("cornell", &running, true, 0);
        assert!(line.ends_with("unshot, not converged"), "{line}");
        let dark = closing_summary("cornell", &p, false, 1);
        assert!(dark.ends_with("nothing emits, 1 picture written"), "{dark}");
        let tailed = Progress {
            particles: 4_194_304,
            ..progress(Some(StopReason::Converged))
        };
        let line = closing_summary("room", &tailed, true, 0);
        assert!(
            line.starts_with(
                "room: window closed after 65 steps (the tail by 4.2 M particles), 1.35 s"
            ),
            "{line}"
        );
    }
}
