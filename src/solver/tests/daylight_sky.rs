//! A standard sky (`--sky cie-...`) against closed forms: its facets
//! spread their light over their sample directions by the sky's own
//! luminance ([`super::formfactor::polygon_samples`]), so a small card at
//! the enclosure's centre receives the sky's illuminance on its plane,
//! whichever way it faces, both as the solver lights it and as the final
//! gather reads it.

use super::final_gather::FinalGather;
use super::*;
use crate::scene::{DaylightSky, Polygon, SkyLevel, SkyModel, SunPosition, GROUND_REFLECTANCE};
use crate::testutil::{grey, polygon, scene};
use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// A card's side, m: small enough that the cards neither shade nor
/// light one another measurably.
const CARD: f32 = 0.02;

/// The card's reflectance.
const RHO: f64 = 0.5;

/// A `CARD`-wide square of material 0 centred at `c`, facing `n` (unit).
fn card(c: Vec3, n: Vec3) -> Polygon {
    let (t1, t2) = n.any_orthonormal_pair();
    let h = CARD / 2.0;
    let mut corners = [-t1 - t2, t1 - t2, t1 + t2, -t1 + t2].map(|d| (c + d * h).to_array());
    if t1.cross(t2).dot(n) < 0.0 {
        corners.reverse();
    }
    let p = polygon(0, &corners);
    assert!(p.normal.dot(n) > 0.99);
    p
}

/// `∫ L(d) max(0, d·n) dω` over the upper hemisphere (local frame, `z`
/// up) on a 1,000 × 2,000 (zenith angle, azimuth) grid by the midpoint
/// rule: an integration apart from the program's facets and samples.
fn sky_on_plane(l: impl Fn(DVec3) -> f64, n: DVec3) -> f64 {
    let (nz, na) = (1000, 2000);
    let (dz, da) = (FRAC_PI_2 / nz as f64, 2.0 * PI / na as f64);
    let mut sum = 0.0;
    for i in 0..nz {
        let (sz, cz) = ((i as f64 + 0.5) * dz).sin_cos();
        for j in 0..na {
            let (sa, ca) = ((j as f64 + 0.5) * da).sin_cos();
            let d = DVec3::new(sz * sa, sz * ca, cz);
            sum += l(d) * d.dot(n).max(0.0) * sz * dz * da;
        }
    }
    sum
}

/// Five cards (up, east, west, south, north) within 5 cm of the origin,
/// each behind the plane of every other,
/// under `sky`, solved to convergence: per card its normal (scene), the
/// mean radiosity the solver gave its vertices over `RHO`, and the final
/// gather's irradiance just in front of its centre.
///
/// Two black cards 50 m either side widen the scene, so that the sky's
/// enclosure is a thousand times farther than the cards are from its
/// centre: a point off the centre sees the sky's patches bigger on one
/// side and smaller on the other, which at a hundredth of the radius
/// moved the clear sky's illuminance by up to 0.7 %.
fn cards_under(sky: &DaylightSky) -> Vec<(Vec3, f64, f64)> {
    // Up is +y, so north is −z and east +x (HorizonFrame).
    let cards = [
        (Vec3::new(0.0, 0.05, 0.0), Vec3::Y),
        (Vec3::new(0.05, 0.0, 0.0), Vec3::X),
        (Vec3::new(-0.05, 0.0, 0.0), -Vec3::X),
        (Vec3::new(0.0, 0.0, 0.05), Vec3::Z),
        (Vec3::new(0.0, 0.0, -0.05), -Vec3::Z),
    ];
    let mut polygons: Vec<Polygon> = cards.iter().map(|&(c, n)| card(c, n)).collect();
    for x in [-50.0, 50.0] {
        let mut anchor = card(Vec3::new(x, 0.0, 0.0), Vec3::Y);
        anchor.material = crate::scene::MaterialId(1);
        polygons.push(anchor);
    }
    let mut s = scene(
        polygons,
        vec![grey("card", 0.0, RHO), grey("black", 0.0, 0.0)],
    );
    s.add_daylight_sky(sky, 0.0).unwrap();
    let mesh = mesh::build(&s, &MeshOptions::for_scene(&s)).unwrap();
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, SolverOptions::default());
    while !solver.is_done() {
        if solver.step().is_none() {
            break;
        }
    }
    let radiosity = solver.radiosity().to_vec();
    let gather = FinalGather::new(&s, &mesh, &vis, &radiosity, true);
    cards
        .iter()
        .enumerate()
        .map(|(i, &(c, n))| {
            let pm = &mesh.polygons[i];
            let b: f64 = pm
                .vertices
                .clone()
                .map(|l| radiosity[l as usize].mean())
                .sum::<f64>()
                / pm.vertex_count() as f64;
            let e = gather.irradiance(c + n * 1e-3, n).mean();
            (n, b / RHO, e)
        })
        .collect()
}

/// The local direction (`x` east, `y` north, `z` up) of a scene
/// direction, for a `+y` up and no `--north`.
fn local(n: Vec3) -> DVec3 {
    DVec3::new(f64::from(n.x), f64::from(-n.z), f64::from(n.y))
}

/// Under the CIE overcast sky a card facing up receives `7π Lz / 9`, and
/// one standing on edge, whichever way it faces, the sky's
/// `Lz (π/6 + 4/9)` (the integral of `Lz (1 + 2 cos Z) / 3 · sin Z cos φ`
/// over the quarter sphere in front of it) and half the ground's
/// `ρ_g · 7π Lz / 9`. Measured: within 0.04 %, solved and gathered.
/// Were each facet to emit one luminance in every direction, the cards
/// would miss by percents: by its `cos Z`-weighted mean (which makes
/// the horizontal exact) the cards on edge read 5.3 % high, by its mean
/// over its area the card facing up 1.8 % low.
#[test]
fn cards_under_the_overcast_sky_receive_its_closed_forms() {
    let lz = 1000.0;
    let sky =
        DaylightSky::new(SkyModel::CieOvercast, Some(SkyLevel::Zenith(lz)), None, 0.0).unwrap();
    let horizontal = 7.0 * PI / 9.0 * lz;
    let vertical = lz * (PI / 6.0 + 4.0 / 9.0) + GROUND_REFLECTANCE * horizontal / 2.0;
    for (n, solved, gathered) in cards_under(&sky) {
        let want = if n == Vec3::Y { horizontal } else { vertical };
        for (how, got) in [("solved", solved), ("gathered", gathered)] {
            let error = got / want - 1.0;
            println!("{n} {how}: {got:.2} vs {want:.2} ({:+.3} %)", 100.0 * error);
            assert!(error.abs() < 0.001, "{n} {how}: {got} vs {want}");
        }
    }
}

/// Under the CIE clear sky, whose luminance gathers about the sun (here
/// due south, 35° high), the cards receive the sky's illuminance on
/// their planes as a fine grid integrates it, and half the ground's
/// (no sun: the sky alone lights the ground). Measured: within 0.05 %.
/// Were each facet to emit its `cos Z`-weighted mean luminance in every
/// direction, the cards on edge would read 3 % to 10 % low.
#[test]
fn cards_under_the_clear_sky_receive_its_integral() {
    let sun = SunPosition::from_degrees(180.0, 35.0);
    let sky = DaylightSky::new(
        SkyModel::CLEAR,
        Some(SkyLevel::Zenith(1000.0)),
        Some(sun),
        0.0,
    )
    .unwrap();
    let ground = GROUND_REFLECTANCE * sky.horizontal_illuminance();
    for (n, solved, gathered) in cards_under(&sky) {
        let nl = local(n);
        let want = sky_on_plane(|d| sky.luminance(d), nl) + ground * (1.0 - nl.z) / 2.0;
        for (how, got) in [("solved", solved), ("gathered", gathered)] {
            let error = got / want - 1.0;
            println!("{n} {how}: {got:.2} vs {want:.2} ({:+.3} %)", 100.0 * error);
            assert!(error.abs() < 0.001, "{n} {how}: {got} vs {want}");
        }
    }
}
