//! `--info`: what a scene holds, said without meshing or solving, so a
//! user can find the names `--emit` takes, the scale of the model and
//! whether the automatic camera suits it before spending a solve.
//!
//! [`describe`] makes the scene ready as a run would
//! ([`prepare::ready_to_mesh`]: `--emit`, `--sky`, the sides options, the
//! repair passes, the camera and its options, the mesh options) and
//! writes, one section a line or a list:
//! the materials (reflectance, emission, how many polygons use each), the
//! OBJ objects and groups (or glTF nodes and meshes), what emits, the
//! bounds, the camera as command-line options, the lenmax (the default
//! unless `--lenmax` is given), the estimated mesh and every load warning.

use crate::budget::fmt_count;
use crate::camera::{fmt_value, options_text};
use crate::color::Rgb;
use crate::config::RunConfig;
use crate::mesh;
use crate::prepare::{self, PrepareError, ReadyScene};
use crate::scene::{CameraSource, GroupKind, Polygon, Scene};
use std::fmt::Write;

/// The `--info` report of the scene `config` names, as printed (ends with
/// a newline).
pub fn describe(config: &RunConfig) -> Result<String, PrepareError> {
    let ready = prepare::ready_to_mesh(config)?;
    Ok(report(config, &ready))
}

/// A colour as three numbers, each as short as reads back exactly.
fn rgb(c: Rgb) -> String {
    format!(
        "{} {} {}",
        fmt_value(c.r as f32),
        fmt_value(c.g as f32),
        fmt_value(c.b as f32)
    )
}

/// `n polygon` or `n polygons`.
fn polygons(n: usize) -> String {
    let s = if n == 1 { "" } else { "s" };
    format!("{} polygon{s}", fmt_count(n as u64))
}

/// A polygon of the model: neither a back copy made for a two-sided face
/// nor a facet of the sky.
fn of_model(p: &Polygon) -> bool {
    p.surface.back_of.is_none() && !p.surface.sky
}

fn report(config: &RunConfig, ready: &ReadyScene) -> String {
    let scene = &ready.scene;
    let mut out = String::new();
    let model = scene.polygons.iter().filter(|p| of_model(p)).count();
    let backs = scene
        .polygons
        .iter()
        .filter(|p| p.surface.back_of.is_some() && !p.surface.sky)
        .count();
    let _ = write!(
        out,
        "scene: {}, {}",
        config.scene.display_name(),
        polygons(model)
    );
    let mut sides = Vec::new();
    if backs > 0 {
        sides.push(format!(
            "{} of them with a back side",
            fmt_count(backs as u64)
        ));
    }
    if ready.unreached_backs > 0 {
        sides.push(format!(
            "{} two-sided faces without one, as no light reaches their back",
            fmt_count(ready.unreached_backs as u64)
        ));
    }
    if !sides.is_empty() {
        let _ = write!(out, " ({})", sides.join("; "));
    }
    out.push('\n');
    materials(scene, &mut out);
    groups(scene, &mut out);
    emitters(scene, &mut out);
    let (lo, hi) = scene.bounds();
    let size = hi - lo;
    let _ = writeln!(
        out,
        "bounds: {} {} {} to {} {} {} (size {} x {} x {}, diagonal {})",
        fmt_value(lo.x),
        fmt_value(lo.y),
        fmt_value(lo.z),
        fmt_value(hi.x),
        fmt_value(hi.y),
        fmt_value(hi.z),
        fmt_value(size.x),
        fmt_value(size.y),
        fmt_value(size.z),
        fmt_value(scene.extent())
    );
    let mut camera = scene.camera;
    if let Some((width, height)) = config.size {
        camera.width = width;
        camera.height = height;
    }
    let changed = !config.camera_override.is_empty() || config.size.is_some();
    let source = match (scene.camera_source, changed) {
        (CameraSource::File, false) => "from the file",
        (CameraSource::AutoFramed, false) => "automatic",
        (CameraSource::File, true) => "from the file, changed by the options",
        (CameraSource::AutoFramed, true) => "automatic, changed by the options",
    };
    let _ = writeln!(out, "camera ({source}): {}", options_text(&camera));
    let lenmax = ready.mesh_options.lenmax;
    let which = if config.lenmax.is_some() {
        "given by --lenmax"
    } else {
        "the default"
    };
    let _ = writeln!(out, "lenmax: {} ({which})", fmt_value(lenmax));
    match mesh::estimate(scene, &ready.mesh_options) {
        Ok(size) => {
            let _ = writeln!(
                out,
                "estimated mesh: {} elements on {} vertices",
                fmt_count(size.elements),
                fmt_count(size.vertices)
            );
        }
        Err(e) => {
            let _ = writeln!(out, "estimated mesh: none ({e})");
        }
    }
    if scene.warnings.is_empty() {
        out.push_str("warnings: none\n");
    } else {
        let _ = writeln!(out, "warnings ({}):", scene.warnings.len());
        for w in &scene.warnings {
            let _ = writeln!(out, "  {w}");
        }
    }
    out
}

/// `materials (N):` and a line per material.
fn materials(scene: &Scene, out: &mut String) {
    // Polygons of the model using each material, and whether anything
    // else (a back copy, the sky) does: a material only those use is the
    // program's, not the file's.
    let mut used = vec![0usize; scene.materials.len()];
    let mut used_otherwise = vec![false; scene.materials.len()];
    for p in &scene.polygons {
        if of_model(p) {
            used[p.material.index()] += 1;
        } else {
            used_otherwise[p.material.index()] = true;
        }
    }
    let listed: Vec<usize> = (0..scene.materials.len())
        .filter(|&i| used[i] > 0 || !used_otherwise[i])
        .collect();
    let _ = writeln!(out, "materials ({}):", listed.len());
    for i in listed {
        let m = &scene.materials[i];
        let _ = write!(out, "  {}: reflectance {}", m.name, rgb(m.reflectance()));
        if !m.emission().is_black() {
            let _ = write!(out, ", emits {}", rgb(m.emission()));
        }
        match used[i] {
            0 => out.push_str(", unused\n"),
            n => {
                let _ = writeln!(out, ", {}", polygons(n));
            }
        }
    }
}

/// The objects, groups and meshes, a line for each kind that has any.
fn groups(scene: &Scene, out: &mut String) {
    let kinds = [
        (GroupKind::Object, "objects"),
        (GroupKind::Group, "groups"),
        (GroupKind::Mesh, "meshes"),
    ];
    let mut any = false;
    for (kind, word) in kinds {
        let names: Vec<String> = scene
            .groups
            .iter()
            .filter(|g| g.kind == kind)
            .map(|g| {
                let n = g
                    .polygons
                    .iter()
                    .filter(|&&p| of_model(&scene.polygons[p.index()]))
                    .count();
                format!("{} ({})", g.name, polygons(n))
            })
            .collect();
        if !names.is_empty() {
            any = true;
            let _ = writeln!(out, "{word} ({}): {}", names.len(), names.join(", "));
        }
    }
    if !any {
        out.push_str("objects and groups: none (--emit takes material names)\n");
    }
}

/// What emits: each emitting material with its polygons and their area,
/// the sky, or that nothing does.
fn emitters(scene: &Scene, out: &mut String) {
    let mut lines = Vec::new();
    let mut sky = None;
    for (i, m) in scene.materials.iter().enumerate() {
        if m.emission().is_black() {
            continue;
        }
        let (mut n, mut area, mut is_sky) = (0usize, 0.0f64, false);
        for p in scene.polygons.iter().filter(|p| p.material.index() == i) {
            if p.surface.sky {
                is_sky = true;
            } else if p.surface.back_of.is_none() {
                n += 1;
                area += p.area;
            }
        }
        if is_sky {
            // A standard sky's facets each have a material: say its mean.
            sky = scene.sky();
        } else if n > 0 {
            lines.push(format!(
                "  {}: emits {}, {}, area {}",
                m.name,
                rgb(m.emission()),
                polygons(n),
                fmt_value(area as f32)
            ));
        }
    }
    if lines.is_empty() && sky.is_none() && scene.sun.is_none() {
        out.push_str("emitters: none (light a material, object or group with --emit NAME=VALUE, or give --sky)\n");
        return;
    }
    let sun = crate::batch::daylight::sun_stats(scene);
    let _ = writeln!(
        out,
        "emitters ({}):",
        lines.len() + usize::from(sky.is_some()) + usize::from(sun.is_some())
    );
    for line in lines {
        let _ = writeln!(out, "{line}");
    }
    if let Some(s) = sky {
        if scene.sky_pattern.is_some() {
            let _ = writeln!(
                out,
                "  the sky (--sky): a standard sky, its facets' mean radiosity {}",
                rgb(s)
            );
        } else {
            let _ = writeln!(out, "  the sky (--sky): {}", rgb(s));
        }
    }
    if let Some(sun) = sun {
        let _ = writeln!(
            out,
            "  the sun (--sun): azimuth {:.1}, altitude {:.1} degrees, {} lx direct normal, {} lx on open ground",
            sun.azimuth,
            sun.altitude,
            crate::batch::daylight::thousands(sun.normal_lux),
            crate::batch::daylight::thousands(sun.horizontal_lux),
        );
    }
}
