//! What a new solve builds from its scene and mesh besides the shooters'
//! samples: the sample set its options ask for, the receiver tiles of
//! shaft culling, and the receiver approximations' tables.

use super::accel::far_shooters::FarShooter;
use super::accel::probes;
use super::accel::receivers::{self, CoarseGrid};
use super::kernel::formfactor::{SampleSet, ShooterSample};
use super::{FormFactorMethod, ShooterSamples, SolverOptions, TILE_VERTICES};
use crate::mesh::Mesh;
use crate::scene::PolygonId;
use crate::visibility::Visibility;
use std::ops::Range;

/// The shooter samples `options` ask for.
pub(super) fn sample_set(options: &SolverOptions) -> SampleSet {
    match (options.form_factor, options.shooter_samples) {
        (FormFactorMethod::Center, _) => SampleSet::Centre,
        (FormFactorMethod::Wallace | FormFactorMethod::Hemicube, ShooterSamples::All) => {
            SampleSet::Vertices
        }
        (FormFactorMethod::Wallace | FormFactorMethod::Hemicube, ShooterSamples::AtMost(n)) => {
            SampleSet::AtMost(n)
        }
    }
}

/// The receiver tiles of `mesh`: runs of at most [`TILE_VERTICES`]
/// consecutive vertices of one polygon, and per vertex its tile.
pub(super) fn tiles(mesh: &Mesh) -> (Vec<Range<u32>>, Vec<u32>) {
    let mut tiles = Vec::new();
    let mut tile_of = vec![0u32; mesh.vertex_count()];
    for pm in &mesh.polygons {
        let mut start = pm.vertices.start;
        while start < pm.vertices.end {
            let end = (start + TILE_VERTICES).min(pm.vertices.end);
            for l in start..end {
                tile_of[l as usize] = tiles.len() as u32;
            }
            tiles.push(start..end);
            start = end;
        }
    }
    (tiles, tile_of)
}

/// Per mesh vertex, whether it is the first corner of a crowded cell of
/// its polygon's `coarse` grid ([`receivers::crowded_cells`]); empty
/// unless the solve `approximate`s receivers.
pub(super) fn crowded(
    mesh: &Mesh,
    visibility: &Visibility,
    coarse: &[Option<CoarseGrid>],
    approximate: bool,
) -> Vec<bool> {
    if approximate {
        receivers::crowded_cells(mesh, coarse, |j, corners, normal, depth| {
            visibility.crowds(PolygonId(j as u32), &corners, normal, depth)
        })
    } else {
        Vec::new()
    }
}

/// Per polygon, a sky facet's probe samples among its `samples` and
/// their regions ([`probes::SkyProbes`]); `None` for every other polygon and unless the solve
/// `approximate`s receivers.
pub(super) fn sky_probes(
    mesh: &Mesh,
    samples: &[Vec<ShooterSample>],
    approximate: bool,
) -> Vec<Option<probes::SkyProbes>> {
    mesh.polygons
        .iter()
        .zip(samples)
        .map(|(pm, own)| {
            (pm.sky && approximate)
                .then(|| probes::SkyProbes::new(own, crate::solver::tuning::SKY_PROBES))
        })
        .collect()
}

/// Per polygon, its far-shooter probes ([`FarShooter`]); `None` for sky
/// facets, polygons of few samples and unless the solve `approximate`s
/// receivers.
pub(super) fn far_shooters(
    mesh: &Mesh,
    samples: &[Vec<ShooterSample>],
    approximate: bool,
) -> Vec<Option<FarShooter>> {
    mesh.polygons
        .iter()
        .zip(samples)
        .map(|(pm, own)| {
            (approximate && !pm.sky)
                .then(|| FarShooter::new(own))
                .flatten()
        })
        .collect()
}
