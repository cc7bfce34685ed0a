//! The raw arguments: clap's view of the command line, one field per
//! option, parsed but not yet checked against each other or against the
//! ranges their meaning needs (that is [`super::invocation`]'s job).
//!
//! Each option's doc comment is its help: the first paragraph is the one
//! line `-h` shows, the whole comment is what `--help` shows.

use super::values::{
    parse_emit, parse_eye, parse_fov, parse_hemicube_res, parse_ies, parse_look_at, parse_north,
    parse_number, parse_shooter_samples, parse_size, parse_sky, parse_sun, parse_tail,
    parse_tail_particles, parse_up, parse_whole, parse_workplane, SkyArg, SunArg,
};
use crate::color::Rgb;
use crate::config;
use crate::mesh::refine;
use crate::mesh::DEFAULT_INSET;
use crate::render::antialias;
use crate::solver::hemicube::HemicubeRes;
use crate::solver::tuning::{DEFAULT_SETTLE, DEFAULT_THRESHOLD};
use crate::solver::{FormFactorMethod, Heuristic, ShooterSamples, TailOption, UnshotScheme};
use std::path::PathBuf;

/// The exit codes, shown after both the short and the long help.
pub const EXIT_CODES: &str =
    "Exit codes: 0 success, 1 a result could not be written, 2 bad input or usage, \
     130 interrupted (Ctrl-C; the message names the files written).";

/// The headings `-h` and `--help` group the options under, in the order
/// their first option is declared (clap shows headings in that order).
/// Every option has one; a unit test keeps it so.
pub mod heading {
    /// The scene and how its files are read.
    pub const INPUT: &str = "Input";
    /// The files a run writes, and what it says while it runs.
    pub const OUTPUT: &str = "Output";
    /// The mesh, the solver and its limits.
    pub const SOLVER: &str = "Mesh and solver";
    /// Where the camera stands and how the picture is drawn.
    pub const PICTURE: &str = "Camera and picture";
    /// What emits light besides the scene's own emitters.
    pub const LIGHT: &str = "Light";
    /// The window.
    pub const WINDOW: &str = "Window";
    /// Checkpoints of long solves.
    pub const LONG: &str = "Long solves";
    /// Physical units, measurements and false colour.
    pub const PHOTOMETRY: &str = "Photometry";
}

/// Progressive-refinement radiosity renderer (ray-traced form factors after
/// Wallace, Elmquist and Haines 1989).
///
/// Reads a .sc, .obj or glTF scene, meshes every polygon into elements, shoots
/// light from the polygon with the most unshot power until the unshot power
/// falls below the threshold, and writes a Gouraud-shaded picture.
// The field docs are plain help text, where `<scene-name>` is a
// placeholder, not an HTML tag.
#[allow(rustdoc::invalid_html_tags)]
#[derive(clap::Parser, Clone, Debug, PartialEq)]
#[command(name = "radiosity", version, about, allow_negative_numbers = true)]
pub struct Args {
    /// Scene file: .sc, .obj (with its MTL materials), .gltf or .glb (glTF 2).
    ///
    /// Without it, the bundled scenes/rtable.sc.
    #[arg(help_heading = heading::INPUT, display_order = 0)]
    pub(crate) scene: Option<PathBuf>,

    /// Picture to write: .png or .tif/.tiff, .exr, .pfm or .hdr.
    ///
    /// .png and .tif/.tiff are 8-bit and tone-mapped; .exr and .pfm hold
    /// 32-bit float linear radiosity, .hdr (Radiance RGBE) the same to
    /// about 1 %. Default: <scene-name>.png in the current directory.
    #[arg(short, long, value_name = "FILE")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) output: Option<PathBuf>,

    /// Longest element edge, in scene units.
    ///
    /// Default: 1/80 of the scene's bounding-box diagonal, or coarser when
    /// that mesh would have more than about 470,000 vertices (a line then
    /// says which lenmax was chosen).
    #[arg(long, value_name = "L", value_parser = parse_number::<f32>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) lenmax: Option<f32>,

    /// Inset of boundary vertices, as a fraction of lenmax.
    ///
    /// Boundary vertices are evaluated this far inside their polygon, so
    /// room corners do not come out dark; 0 disables it. A polygon that
    /// is a single element has its corners evaluated 3 times as far in,
    /// at most half the way across it.
    #[arg(long, value_name = "F", default_value_t = DEFAULT_INSET, value_parser = parse_number::<f32>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) inset: f32,

    /// Stop when the unshot power falls below this fraction of the emitted
    /// power.
    ///
    /// 0 means: run until --max-steps, or until nothing is left to shoot
    /// (the unshot power is exactly zero; the run then ends as converged,
    /// exit 0). Without --max-steps that can take many thousands of steps.
    #[arg(long, value_name = "T", default_value_t = DEFAULT_THRESHOLD, value_parser = parse_number::<f64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) threshold: f64,

    /// Past the threshold, go on until every point has settled.
    ///
    /// A point has settled when it holds less than this fraction of its
    /// radiosity still to send. Light trapped in a pocket (a gap under a
    /// lamp, a sphere's underside over the floor) is a small share of the
    /// scene's power but most of the pocket's own; the threshold alone
    /// would leave such places too dark. 0 stops at the threshold alone.
    #[arg(long, value_name = "F", default_value_t = DEFAULT_SETTLE, value_parser = parse_number::<f64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) settle: f64,

    /// Stop after this many shooting steps at most.
    #[arg(long, value_name = "N", value_parser = parse_whole::<u64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) max_steps: Option<u64>,

    /// Form factor estimate.
    #[arg(long, value_name = "METHOD", value_enum, default_value_t = FormFactorMethod::Wallace)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) form_factor: FormFactorMethod,

    /// Shooter sample points per shooter: at most N, or `all`.
    ///
    /// Each shooter shoots from a regular grid of at most N cells (no more
    /// than it has element vertices), one shadow ray each; `all` uses every
    /// element vertex as a point sample (the original scheme, without the
    /// near field; slow on fine meshes). Unit-square form factors are
    /// within 0.06 % of exact at 16 or more; more points sample penumbrae
    /// more finely.
    // The literal is crate::solver::tuning::DEFAULT_SHOOTER_SAMPLES (ShooterSamples has no
    // Display for `default_value_t`); a unit test keeps the two equal.
    #[arg(long, value_name = "N|all", default_value = "64", value_parser = parse_shooter_samples)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) shooter_samples: ShooterSamples,

    /// When particles carry the light left unshot: `auto`, `off` or an
    /// unshot fraction.
    ///
    /// Once the unshot power falls to the fraction, the light left is shot
    /// from every surface at once by tracing particles through all their
    /// bounces, in four steps, instead of by thousands of shooting steps
    /// each carrying one cluster's sliver of it. It adds noise in the
    /// share of each point's light that was left (the fraction over one
    /// minus the reflectance, spread over the model). `auto` (the
    /// default) turns it on from 0.3 on meshes of 100,000 element
    /// vertices or more, or from up to 0.5 right after a shooting step
    /// that cost 5 times more rays for its light than the particles
    /// would; `off` shoots to the end.
    // The literals are crate::solver::tuning::TAIL_AUTO_FROM,
    // TAIL_AUTO_VERTICES, TAIL_EARLY_FROM and TAIL_COSTLY_RATIO; a test
    // keeps them equal.
    #[arg(long, value_name = "F|auto|off", default_value = "auto", value_parser = parse_tail)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) tail: TailOption,

    /// Particles per element vertex the tail traces over four steps.
    ///
    /// The noise of the light they carry falls as one over the square root
    /// of this. The tail ends with a final gather, in which every vertex
    /// gathers one more bounce of their light over 64 directions: where
    /// few particles landed (small elements) its answer replaces theirs,
    /// which takes most of their noise out (`--without tail-gather` keeps
    /// the particles' own).
    // The literal is crate::solver::tuning::TAIL_PARTICLES_PER_VERTEX.
    #[arg(long, value_name = "N", default_value = "16", value_parser = parse_tail_particles)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) tail_particles: f64,

    /// Pixels across a hemicube's top face (--form-factor hemicube).
    ///
    /// An even number from 8 to 4096; the side faces have N × N/2 pixels.
    /// One hemicube stands at each shooter sample (--shooter-samples).
    // The literal is crate::solver::tuning::DEFAULT_HEMICUBE_RES; a unit test
    // keeps the two equal.
    #[arg(long, value_name = "N", default_value = "128", value_parser = parse_hemicube_res)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) hemicube_res: HemicubeRes,

    /// Use the disc approximation however near the receiver.
    // The long help quotes tuning constants: it is written from them in
    // `cli/help.rs`.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) no_near_field: bool,

    /// Test shadow rays against the whole scene (slower, same result).
    ///
    /// By default a shadow ray is tested only against the polygons in the
    /// shaft between shooter and receiver; this is for comparison.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) no_shaft_culling: bool,

    /// Shoot every polygon alone (the solver without clusters).
    // The long help quotes tuning constants: it is written from them in
    // `cli/help.rs`.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) no_clustering: bool,

    /// Evaluate every receiving vertex exactly, in every step.
    // The long help quotes tuning constants: it is written from them in
    // `cli/help.rs`.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) exact_receivers: bool,

    /// Shoot exactly the unshot light, never more.
    // The long help quotes tuning constants: it is written from them in
    // `cli/help.rs`.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) no_overshoot: bool,

    /// Turn these heuristics of the solver off (comma-separated).
    ///
    /// Each is one switch, measured against its twin: emitters-first,
    /// overshoot, settling, near-field, shaft-culling, clusters, strata,
    /// receiver-interpolation, weak-strata, crowded-cells, facet-rays,
    /// sky-probes, far-shooters, shared-receivers, sky-at-once, hat-centroids,
    /// tail-gather.
    /// `docs/accuracy.md` gives what each costs and buys.
    #[arg(long, value_name = "NAME,...", value_enum, value_delimiter = ',')]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) without: Vec<Heuristic>,

    /// Solve with no heuristic: the brute-force twin (slow).
    ///
    /// Every polygon shoots alone from all its cells in plain power order,
    /// exactly the light it holds, to every receiving vertex with its own
    /// shadow rays, each tested against the whole scene. The exact near
    /// field and settling stay.
    #[arg(long)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) exact: bool,

    /// Where unshot radiosity is kept between shooting steps.
    #[arg(long, value_name = "SCHEME", value_enum, default_value_t = UnshotScheme::Vertex)]
    #[arg(help_heading = heading::SOLVER, hide_short_help = true)]
    pub(crate) unshot: UnshotScheme,

    /// Refine the mesh where the light changes sharply, and go on solving.
    ///
    /// Once the solve converges, split the elements whose vertex
    /// luminances differ by more than --adaptive-threshold (relative to the
    /// largest), keep the mesh crack-free, and continue the solve on the
    /// refined mesh (new vertices gather the light shot so far); repeat up
    /// to --adaptive-levels times. Sharpens shadow boundaries where the
    /// regular mesh blurs them.
    #[arg(long, conflicts_with_all = ["checkpoint", "resume"])]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) adaptive: bool,

    /// Never refine the mesh, not even once after a coarsened default mesh.
    ///
    /// Without --lenmax, a model whose default mesh would pass the vertex
    /// budget is meshed coarser, solved, then refined once where the light
    /// changes most (up to 5,000 elements) and solved
    /// again. This keeps the coarser mesh as it is. A run that writes or
    /// resumes a checkpoint never refines.
    #[arg(long, conflicts_with = "adaptive")]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) no_adaptive: bool,

    /// Relative luminance difference that splits an element (--adaptive).
    ///
    /// An element is split when its vertex luminances differ by more than
    /// this fraction of the largest of them.
    #[arg(long, value_name = "T", default_value_t = refine::DEFAULT_THRESHOLD, value_parser = parse_number::<f64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) adaptive_threshold: f64,

    /// Split each initial element at most this many times (--adaptive).
    ///
    /// Each split halves the element's edges.
    #[arg(long, value_name = "N", default_value_t = refine::DEFAULT_LEVELS, value_parser = parse_whole::<u32>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) adaptive_levels: u32,

    /// Split at most N elements per refinement (--adaptive).
    ///
    /// When more differ by more than --adaptive-threshold, those with the
    /// most light to gain are split: their luminance difference times
    /// their area. On a real level a refinement marks tens of thousands of
    /// small elements; the few thousand largest take almost all the error
    /// for a fraction of the time.
    #[arg(long, value_name = "N", default_value_t = refine::DEFAULT_MAX_SPLITS, value_parser = parse_whole::<u64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) adaptive_max_splits: u64,

    /// Samples per pixel side for written pictures (1 to 8).
    ///
    /// The picture is rendered at N × N samples a pixel and averaged in
    /// linear radiosity, so polygon edges are smooth; .exr, .pfm and .hdr keep
    /// the averaged linear values. 1 draws one sample a pixel, as the
    /// window does. Very large pictures use fewer samples (at most 64 M).
    #[arg(long, value_name = "N", default_value_t = antialias::DEFAULT_AA,
          value_parser = clap::value_parser!(u32).range(1..=antialias::MAX_AA as i64))]
    #[arg(help_heading = heading::PICTURE)]
    pub(crate) aa: u32,

    /// Draw the element mesh over the written picture.
    ///
    /// As the window's `m` key does; 8-bit pictures only (.png or .tiff).
    #[arg(long)]
    #[arg(help_heading = heading::PICTURE)]
    pub(crate) mesh_lines: bool,

    /// Picture size in pixels, overriding the scene's camera.
    #[arg(long, value_name = "WxH", value_parser = parse_size, allow_hyphen_values = true)]
    #[arg(help_heading = heading::PICTURE)]
    pub(crate) size: Option<(u32, u32)>,

    /// Exposure in stops from the automatic one (+1 is twice as bright).
    ///
    /// 8-bit pictures and exported colours are scaled by the automatic
    /// exposure (the 95th-percentile luminance maps to 0.9) times
    /// 2^STOPS, as the window's + and - keys and Radiance's `pfilt -e +2`
    /// count; 0 is the automatic exposure, the default. The summary line
    /// and --stats give the automatic value. From -40 to 40.
    #[arg(long, value_name = "STOPS", value_parser = parse_number::<f32>)]
    #[arg(help_heading = heading::PICTURE)]
    pub(crate) exposure: Option<f32>,

    /// Write counts and seconds per phase as JSON to this file.
    #[arg(long, value_name = "FILE")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) stats: Option<PathBuf>,

    /// Make a material, OBJ object or group emit light (repeatable).
    ///
    /// NAME=V or NAME=R,G,B: the material, the object (`o`) or the group
    /// (`g`) named NAME (case matters) emits this radiosity, in the
    /// scene's units, instead of what it emitted; its reflectance is kept
    /// (in the emission's colour when the two differ). An object or group
    /// that shares its material with other polygons gets a copy of its
    /// own, so only it emits. For models whose lights are not in the file:
    /// when nothing emits, a warning names what looks like a lamp. An
    /// unknown NAME is an error listing the names there are.
    #[arg(long, value_name = "NAME=VALUE", value_parser = parse_emit)]
    #[arg(help_heading = heading::LIGHT)]
    pub(crate) emit: Vec<(String, Rgb)>,

    /// Every polygon reflects and emits from its front only.
    ///
    /// OBJ faces are two-sided by default (each side receives, reflects
    /// and emits on its own, as Blender shades them); glTF follows each
    /// material's doubleSided; .sc polygons are one-sided.
    #[arg(long, conflicts_with = "two_sided")]
    #[arg(help_heading = heading::INPUT)]
    pub(crate) one_sided: bool,

    /// Every polygon is two-sided.
    ///
    /// Each side receives, reflects and emits on its own, with its own
    /// radiosity (the default for OBJ faces).
    #[arg(long)]
    #[arg(help_heading = heading::INPUT)]
    pub(crate) two_sided: bool,
    /// Light the scene from all around with a uniform or standard sky.
    ///
    /// V or R,G,B: a diffuse sky of this radiosity, in the scene's units,
    /// surrounds the scene (as Blender's world colour) and lights it
    /// through every opening; closed rooms stay dark inside. An unoccluded
    /// floor of reflectance rho under a sky V comes out rho * V. The sky is
    /// not drawn and not exported: the picture's background stays black.
    ///
    /// cie-overcast, cie-clear or cie:N (the CIE standard general sky of
    /// type N, 1 to 15; cie-clear is type 12), optionally with ,Elx (the
    /// sky's unobstructed horizontal illuminance) or ,Lcd (its zenith
    /// luminance in cd/m²): a sky whose luminance varies over the dome as
    /// the CIE defines it, above a ground of reflectance 0.2. Default
    /// 10000 lx; cie-clear's default is gensky's zenith luminance for the
    /// sun's altitude. Needs --units; all but cie-overcast, cie:1, cie:3
    /// and cie:5 need --sun.
    #[arg(long, value_name = "VALUE", value_parser = parse_sky, allow_hyphen_values = true)]
    #[arg(help_heading = heading::LIGHT)]
    pub(crate) sky: Option<SkyArg>,

    /// Light the scene with the sun, placed by angles or by a date and place.
    ///
    /// AZ,ALT: degrees clockwise from north (90 is east), degrees above
    /// the horizon (0 to 90). DATE,TIME,LAT,LON: a date YYYY-MM-DD, the
    /// local standard time HH:MM[:SS] (no daylight saving), latitude and
    /// longitude in degrees (north and east positive), optionally ZONE, the
    /// hours from UTC (default: the longitude's nominal zone, LON/15
    /// rounded); the position by NOAA's solar calculator. Nlx is the direct
    /// normal illuminance, lux on a plane facing the sun (default: the IES
    /// clear-sky formula 127500 lx * exp(-0.21 / sin ALT), corrected for
    /// the earth-sun distance when a date is given). The sun is a parallel
    /// light with a disc of 0.53 degrees whose direct light, shadows and
    /// penumbrae included, the solver starts from; it shines alone or with
    /// --sky V, cie-clear and cie:6 to cie:15. Under the overcast skies
    /// (cie-overcast, cie:1 to cie:5) there is no sun: --sun only shapes
    /// cie:2 and cie:4, and an Nlx is refused. Needs --units. A date that
    /// puts the sun below the horizon gives a warning and no sun light.
    #[arg(
        long,
        value_name = "AZ,ALT|DATE,...",
        value_parser = parse_sun,
        allow_hyphen_values = true
    )]
    #[arg(help_heading = heading::LIGHT)]
    pub(crate) sun: Option<SunArg>,

    /// Where true north is: DEG clockwise from the model's north.
    ///
    /// The model's north is -z when up is +y (+y when up is +z); up is the
    /// camera's, snapped to an axis. Default 0.
    #[arg(long, value_name = "DEG", value_parser = parse_north, allow_hyphen_values = true)]
    #[arg(help_heading = heading::LIGHT)]
    pub(crate) north: Option<f64>,

    /// Take the camera from this .sc file.
    ///
    /// Its `camera` block is used (for .obj scenes, which have none; it
    /// also overrides a .sc scene's camera). Without it an .obj scene is
    /// framed automatically.
    #[arg(long, value_name = "FILE.sc")]
    #[arg(help_heading = heading::PICTURE)]
    pub(crate) camera: Option<PathBuf>,

    /// Write the solved element mesh (.glb or .ply).
    ///
    /// .glb is glTF 2.0 binary (one node per OBJ object, or per material
    /// for .sc, materials named as in the scene; display colours as
    /// COLOR_0, linear radiosity as _RADIOSITY); .ply is binary
    /// little-endian (float radiosity and 8-bit colour per vertex). Runs
    /// in batch mode, as -o does.
    #[arg(long, value_name = "FILE")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) export: Option<PathBuf>,

    /// Write the model with its baked light as a lightmap (.glb).
    ///
    /// The scene's own model (a glTF's primitives, normals, TEXCOORD_0 and
    /// materials; an OBJ's faces with their vt, vn, Kd and map_Kd
    /// textures), not the element mesh, with a second UV
    /// set (TEXCOORD_1: the model's own, else made by chart packing) and
    /// the lightmap embedded as every material's emissiveTexture: the
    /// radiosity tone-mapped as the picture is, so three.js, Blender and
    /// Godot show the picture's light with no extra code. Runs in batch
    /// mode, as -o does.
    #[arg(long, value_name = "FILE.glb")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) lightmap: Option<PathBuf>,

    /// Write the bare lightmap texture (.png or .exr).
    ///
    /// .png: the 8-bit emissive texture --lightmap embeds. .exr: the
    /// irradiance (light arriving: (radiosity - emission) / reflectance),
    /// linear 32-bit float in the scene's radiosity units, for engines
    /// that multiply a lightmap by their own albedo. Same UVs as
    /// --lightmap. Runs in batch mode, as -o does.
    #[arg(long, value_name = "FILE")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) lightmap_texture: Option<PathBuf>,

    /// Lightmap texels per scene unit of length.
    ///
    /// Default: the highest density whose charts fit one 2048x2048
    /// texture (printed). The texture may be at most 4096 texels a side.
    #[arg(long, value_name = "D", value_parser = parse_lightmap_density)]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) lightmap_density: Option<f32>,

    /// Write one CSV row per shooting step.
    ///
    /// Columns: step, shooter, unshot fraction, rays, seconds. Runs in batch
    /// mode, as -o does.
    #[arg(long, value_name = "FILE.csv")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) log: Option<PathBuf>,

    /// Plot the unshot fraction per step as a PNG.
    ///
    /// The unshot fraction against the step, on a log axis. Runs in batch
    /// mode, as -o does.
    #[arg(long, value_name = "FILE.png")]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) plot: Option<PathBuf>,

    /// Worker threads for the solver and renderer.
    ///
    /// Default: all cores.
    #[arg(long, value_name = "N", value_parser = parse_whole::<usize>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) threads: Option<usize>,

    /// Do not open a window even when a display is available.
    ///
    /// Solve and write the picture, as with -o.
    #[arg(long)]
    #[arg(help_heading = heading::WINDOW)]
    pub(crate) no_window: bool,

    /// Show the ambient term on top of the solution.
    ///
    /// The ambient term (Cohen et al. 1988) is the unshot power spread
    /// evenly and reflected; shown on top of the solution it keeps early
    /// pictures from being too dark, fades as the solve converges and never
    /// enters the solution. Default: on in the window, off for files.
    #[arg(long, conflicts_with = "no_ambient")]
    #[arg(help_heading = heading::WINDOW)]
    pub(crate) ambient: bool,

    /// Never show the ambient term (see --ambient).
    #[arg(long)]
    #[arg(help_heading = heading::WINDOW)]
    pub(crate) no_ambient: bool,

    /// Refuse meshes with more elements than this.
    ///
    /// The mesh is refused before it is built, and the message says which
    /// --lenmax fits. The default allows meshes of up to about 12 GB
    /// (estimated), which --max-memory may refuse first.
    #[arg(long, value_name = "N", default_value_t = config::DEFAULT_MAX_ELEMENTS, value_parser = parse_whole::<u64>)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) max_elements: u64,

    /// Refuse scenes whose estimated memory is over this many bytes.
    ///
    /// A size in bytes, or with K, M, G or T (powers of 1024): 4G, 512M.
    /// Checked before anything large is built: the triangles of glTF
    /// node instancing and of OBJ faces, the pieces of polygons split
    /// along intersections, the mesh and decoded textures; the error says
    /// the estimate and what makes it. Default: three quarters of the
    /// machine's memory (or of the cgroup's memory.max), at most the
    /// memory available now and half the address-space limit (ulimit
    /// -v); 4G where these cannot be read.
    #[arg(long, value_name = "BYTES", value_parser = parse_max_memory)]
    #[arg(help_heading = heading::SOLVER)]
    pub(crate) max_memory: Option<u64>,

    /// Save the solver state to this file, to resume it later.
    ///
    /// It is saved every --checkpoint-every seconds, on Ctrl-C and at the
    /// end, so an interrupted solve can be resumed. Implies a batch run (no
    /// window).
    #[arg(long, value_name = "FILE")]
    #[arg(help_heading = heading::LONG)]
    pub(crate) checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints.
    #[arg(long, value_name = "SECS", default_value_t = config::DEFAULT_CHECKPOINT_EVERY.as_secs_f64(), value_parser = parse_number::<f64>)]
    #[arg(help_heading = heading::LONG)]
    pub(crate) checkpoint_every: f64,

    /// Continue the solve saved in this checkpoint.
    ///
    /// Give the same scene and mesh and form-factor options; the result is
    /// that of an uninterrupted run. Implies a batch run (no window).
    #[arg(long, value_name = "FILE")]
    #[arg(help_heading = heading::LONG)]
    pub(crate) resume: Option<PathBuf>,

    /// Let a model read files outside its folder.
    ///
    /// By default the files an OBJ or glTF names (mtllib, map_Kd, buffer
    /// and image URIs) must lie in the model's folder or below it: a name
    /// that is an absolute path or climbs out with `..` is refused, so a
    /// downloaded model cannot read other files of the machine.
    #[arg(long)]
    #[arg(help_heading = heading::INPUT)]
    pub(crate) allow_outside_paths: bool,

    /// No progress bar and no summary line.
    #[arg(short, long)]
    #[arg(help_heading = heading::OUTPUT)]
    pub(crate) quiet: bool,

    /// What one scene unit is, for photometric results: m, cm, mm, in, ft.
    ///
    /// With a unit, emission and radiosity are luminous exitance in lm/m²,
    /// luminance (radiosity/π) is in cd/m² and illuminance in lux. glTF
    /// scenes are in metres by their specification; OBJ and .sc scenes
    /// need this for lux (without it, results are in the scene's radiosity
    /// units) and for --ies.
    #[arg(long, value_name = "UNIT", value_enum)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) units: Option<crate::scene::Units>,

    /// Make polygons emit as an IES luminaire (repeatable).
    ///
    /// NAME=FILE.ies: each polygon of the material, object or group NAME
    /// (named as for --emit) becomes one luminaire with the light
    /// distribution of the IESNA LM-63 file (type C, TILT=NONE), its
    /// photometric nadir along the polygon's front normal and its C0 plane
    /// along the polygon's first edge. It emits the file's flux below its
    /// plane and reflects nothing. Needs --units for OBJ and .sc scenes.
    #[arg(long, value_name = "NAME=FILE", value_parser = parse_ies)]
    #[arg(help_heading = heading::LIGHT)]
    pub(crate) ies: Vec<(String, PathBuf)>,

    /// Compute the illuminance at the points of this CSV file.
    ///
    /// One point a line, `x,y,z,nx,ny,nz` (position in scene units, the
    /// normal of the surface the light falls on), a header line allowed;
    /// each point by a final gather over the converged solution. Written
    /// to --illuminance-out.
    #[arg(long, value_name = "POINTS.csv")]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) illuminance_at: Option<PathBuf>,

    /// Where --illuminance-at writes its values (CSV).
    ///
    /// Header `x,y,z,nx,ny,nz,e_r,e_g,e_b,e`; `e` weights the channels by
    /// the Rec. 709 luminance weights; lux with --units.
    #[arg(long, value_name = "VALUES.csv")]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) illuminance_out: Option<PathBuf>,

    /// Compute a horizontal work plane: HEIGHT[,SPACING] in scene units.
    ///
    /// A grid of points over the floor of the scene's bounds, HEIGHT above
    /// it (up is the camera's up axis), SPACING apart (default
    /// 0.2 × 5^log10(d) metres for a floor d metres long, as EN 12464-1
    /// suggests). Writes PREFIX.csv and PREFIX.png (a false-colour plan
    /// with isolux lines; see --workplane-out) and prints Eavg, Emin, Emax
    /// and Emin/Eavg.
    #[arg(long, value_name = "HEIGHT[,SPACING]", value_parser = parse_workplane,
          allow_hyphen_values = true)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) workplane: Option<(f32, Option<f32>)>,

    /// Give the work plane's daylight factors under the overcast sky.
    ///
    /// DF = E_inside / E_outside: each --workplane point's illuminance over
    /// the sky's unobstructed horizontal illuminance, in %. Prints the mean
    /// and the minimum and the EN 17037 figures (the share of the plane at
    /// DF >= 2 % and at DF >= 0.7 %), and writes PREFIX-df.png, the plan
    /// in false colour with those two target lines. Needs --workplane and
    /// --sky cie-overcast (or cie:1).
    #[arg(long)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) daylight_factor: bool,

    /// File name prefix of the --workplane results.
    ///
    /// Default: <scene-name>-workplane in the current directory.
    #[arg(long, value_name = "PREFIX")]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) workplane_out: Option<PathBuf>,

    /// Write the view in false colour, with a legend (.png or .tiff).
    #[arg(long, value_name = "FILE.png")]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) falsecolor: Option<PathBuf>,

    /// What --falsecolor shows.
    ///
    /// luminance (radiosity/π of the surface seen, cd/m² with --units) or
    /// illuminance (light falling on it: its reflected radiosity over its
    /// reflectance, lux with --units; 0 on black surfaces).
    #[arg(long, value_name = "QUANTITY", value_enum,
          default_value_t = crate::render::falsecolor::Quantity::Luminance)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) falsecolor_of: crate::render::falsecolor::Quantity,

    /// The scale of --falsecolor and of the --workplane plan.
    #[arg(long, value_name = "SCALE", value_enum,
          default_value_t = crate::render::falsecolor::Scale::Log)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) falsecolor_scale: crate::render::falsecolor::Scale,

    /// The value shown red by --falsecolor and the plan.
    ///
    /// Default: the largest value, rounded up to 1, 2 or 5 times a power of 10.
    #[arg(long, value_name = "V", value_parser = parse_number::<f64>)]
    #[arg(help_heading = heading::PHOTOMETRY)]
    pub(crate) falsecolor_max: Option<f64>,

    // The camera from the command line and --info: kept together.
    /// Camera position X,Y,Z in scene units (as Radiance's -vp).
    ///
    /// Replaces the eye of the scene's camera (its own, --camera's or the
    /// automatic one) and keeps the rest: with --eye alone the camera
    /// still looks at the same point. The window's `c` key prints the
    /// current camera as these options.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_eye, allow_hyphen_values = true, help_heading = heading::PICTURE)]
    pub(crate) eye: Option<glam::Vec3>,

    /// The point the camera looks at, X,Y,Z in scene units.
    ///
    /// Radiance's -vd gives a direction instead: the look-at point is the
    /// eye plus that direction.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_look_at, allow_hyphen_values = true, help_heading = heading::PICTURE)]
    pub(crate) look_at: Option<glam::Vec3>,

    /// The camera's up direction X,Y,Z (as Radiance's -vu).
    ///
    /// Need not be at right angles to the view, nor of unit length, but
    /// must not be parallel to it. Default: the scene camera's (0,1,0 for
    /// the automatic camera).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_up, allow_hyphen_values = true, help_heading = heading::PICTURE)]
    pub(crate) up: Option<glam::Vec3>,

    /// Vertical field of view in degrees, more than 0 and below 180.
    ///
    /// As Radiance's -vv (its -vh is the horizontal one).
    #[arg(long, value_name = "DEG", value_parser = parse_fov, allow_hyphen_values = true, help_heading = heading::PICTURE)]
    pub(crate) fov: Option<f32>,

    /// Describe the scene and exit, without solving.
    ///
    /// Prints its materials, OBJ objects and groups, what emits, the
    /// bounds, the camera (as --eye ... options), the default --lenmax,
    /// the estimated element count and the warnings of loading, after
    /// --emit, --sky and the sides options are applied.
    #[arg(long, help_heading = heading::INPUT, conflicts_with_all = [
        "output", "export", "lightmap", "lightmap_texture", "log", "plot", "stats", "checkpoint", "resume",
        "falsecolor", "workplane", "illuminance_at", "mesh_lines", "no_window",
    ])]
    pub(crate) info: bool,
}

/// `--max-memory`: a size ([`crate::budget::parse_bytes`]) of at least
/// [`crate::budget::MIN_BYTES`].
fn parse_max_memory(text: &str) -> Result<u64, String> {
    let bytes = crate::budget::parse_bytes(text)?;
    if bytes < crate::budget::MIN_BYTES {
        return Err(format!(
            "{} is too little: a run needs at least {}",
            crate::budget::fmt_bytes(bytes),
            crate::budget::fmt_bytes(crate::budget::MIN_BYTES)
        ));
    }
    Ok(bytes)
}

/// `--lightmap-density`: a positive, finite number of texels per unit.
fn parse_lightmap_density(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(d) if d.is_finite() && d > 0.0 => Ok(d),
        _ => Err(format!(
            "expected a positive number of texels per scene unit, got `{text}`"
        )),
    }
}
