//! Checkpoints: the state of a progressive solve as bytes, so that an
//! interrupted run can continue to exactly the result an uninterrupted run
//! gives. This module only encodes and decodes; reading and writing files
//! (atomically) and choosing what to do with a refused checkpoint is the
//! driver's business.
//!
//! A solve's future depends only on its per-vertex radiosity, its unshot
//! radiosity, the interpolation error charged to each vertex
//! ([`super::receivers`]), the unshot fraction its particle tail takes
//! over at (an automatic tail may take over early:
//! [`super::step::tail`]), the state its final gather reads
//! ([`super::step::tail_gather`]), and the fixed inputs (scene, mesh, solver
//! options); the step and ray counters are carried along for the
//! statistics. Every value is
//! stored as its exact `f64` bits, so a resumed solve continues bit for bit.
//!
//! The file format (version 5), all integers little-endian:
//!
//! ```text
//! offset  size        field
//! 0       8           magic "RADCKPT\0"
//! 8       4           version (u32) = 5
//! 12      8           fingerprint (u64) of scene + mesh + solver options
//! 20      8           steps taken (u64)
//! 28      8           shadow rays cast (u64)
//! 36      8           radiosity entries R (u64, one per mesh vertex)
//! 44      8           unshot entries U (u64)
//! 52      8           driver record length X (u64, in bytes)
//! 60      8           charge entries C (u64, 0 or one per mesh vertex)
//! 68      8           tail fraction (f64 bits; NaN when the tail is off)
//! 76      8           tail-began entries T (u64, 0 or three per mesh vertex)
//! 84      24 R        radiosity: r, g, b as f64 bits per vertex
//! ...     24 U        unshot radiosity: r, g, b as f64 bits per entry
//! ...     24 C        interpolation error charged: r, g, b per vertex
//! ...     24 T        the radiosity, then the unshot radiosity, per vertex
//!                     when the particle tail began, then its particles'
//!                     landings per vertex since (r: their count by
//!                     barycentric weight, g: the sum of their deposits'
//!                     squares; its final gather reads them)
//! ...     X           the driver's record, opaque here (the batch run keeps
//!                     its step log there, so a resumed log continues)
//! end-8   8           checksum (u64): FNV-1a of every byte before it
//! ```
//!
//! Version 4 is version 5 without the tail-began entries (its header is
//! 76 bytes); version 3 is version 4 without the tail fraction (68
//! bytes); version 2 is version 3 without the charges (60 bytes); version
//! 1 is version 2 without the record-length field and the record (52
//! bytes). All are still read, with the tail as the options set it, with
//! no charges before version 3, version 1 with an empty record, and no
//! tail-began entries before version 5 (a tail resumed from one gathers
//! from the state it resumed at).
//!
//! The fingerprint covers what decides the solution: polygon geometry and
//! materials (those `--emit` changed, and the facets and radiosity of a
//! `--sky`), the mesh's vertices and sample points, the form-factor
//! options, every approximation switch ([`super::Approximations`]) and
//! every tuning constant ([`super::tuning::INDEX`]). It leaves out the stopping rule (threshold, step limit), so a
//! resumed run may go further than the interrupted one would have. A
//! driver refuses a checkpoint whose fingerprint differs from its solve's;
//! [`decode`] refuses a truncated or corrupted one by its length or
//! checksum, before anything is allocated from its header's counts.

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solver::{FormFactorMethod, ShooterSamples, SolverOptions};

/// The first eight bytes of every checkpoint file.
pub const MAGIC: [u8; 8] = *b"RADCKPT\0";

/// The format version this build writes and reads.
pub const VERSION: u32 = 5;

/// The oldest format version this build still reads.
pub const OLDEST_VERSION: u32 = 1;

/// Bytes before the radiosity data.
const HEADER_LEN: usize = 84;

/// Bytes before the radiosity data in version 4.
const V4_HEADER_LEN: usize = 76;

/// Bytes before the radiosity data in version 3.
const V3_HEADER_LEN: usize = 68;

/// Bytes before the radiosity data in version 2.
const V2_HEADER_LEN: usize = 60;

/// Bytes before the radiosity data in version 1.
const V1_HEADER_LEN: usize = 52;

/// Bytes of one stored [`Rgb`].
const RGB_LEN: usize = 24;

/// Bytes of the trailing checksum.
const CHECKSUM_LEN: usize = 8;

/// The largest magnitude a saved radiosity, unshot radiosity or charge may
/// have, in emission units. No legal scene comes near it: emission is at
/// most [`crate::scene::MAX_EMISSION`] (1e20) and reflectance below one in
/// f32 (at most 1 - 6e-8), so radiosity stays below about 2e27. Refusing
/// larger values keeps a checkpoint with a valid checksum but absurd values
/// from overflowing the next step or the picture (f32, at most 3.4e38).
pub const MAX_STATE_VALUE: f64 = 1e30;

/// Everything a progressive solve needs to continue exactly where it was.
///
/// Invariants a solver checks on restore ([`crate::solver::Method::restore`]):
/// `radiosity` has one entry per mesh vertex, `unshot` one per polygon or
/// per mesh vertex (by [`SolverOptions::unshot`]), every channel finite and
/// `>= 0` (unshot values may be negative) and at most [`MAX_STATE_VALUE`] in
/// magnitude.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverState {
    /// Radiosity per mesh vertex, in the scene's emission units.
    pub radiosity: Vec<Rgb>,
    /// Unshot radiosity, one entry per unit the solver shoots from.
    pub unshot: Vec<Rgb>,
    /// Shooting steps taken.
    pub steps: u64,
    /// Shadow rays cast.
    pub rays: u64,
    /// Per mesh vertex, the interpolation error charged to it as a check
    /// vertex ([`super::receivers::accept`]); empty when none was (a
    /// solve that never interpolated, or a checkpoint before version 3).
    pub charges: Vec<Rgb>,
    /// The unshot fraction at or below which the particle tail takes
    /// over, in `[0, 1]`, as the solve last had it (an automatic tail may
    /// have taken over early); `None` when the tail is off, or the
    /// checkpoint is older than version 4 (the options then decide).
    pub tail_from: Option<f64>,
    /// The radiosity, then the unshot radiosity, per mesh vertex when
    /// the particle tail began, then its particles' landings per vertex
    /// since (`3 ×` the vertices), which its final gather reads ([`crate::solver::step::tail_gather`]); empty when no
    /// tail is under way or it ends without the gather, and in
    /// checkpoints before version 5.
    pub tail_began: Vec<Rgb>,
}

/// Why checkpoint bytes cannot be decoded. The messages read as the end of
/// a sentence about the file ("… is not a usable checkpoint: {this}").
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// The bytes do not start with [`MAGIC`].
    #[error("it does not start like a radiosity checkpoint")]
    NotACheckpoint,
    /// Too short to hold a header and a checksum.
    #[error("it is truncated ({len} bytes)")]
    Truncated {
        /// Its length, in bytes.
        len: usize,
    },
    /// A format version this build does not read (it reads
    /// [`OLDEST_VERSION`] to [`VERSION`]).
    #[error(
        "it is format version {found}; this program reads versions {OLDEST_VERSION} to {VERSION}"
    )]
    Version {
        /// The version in the header.
        found: u32,
    },
    /// The length differs from what the header's entry counts need.
    #[error(
        "its length ({len} bytes) does not match its header ({radiosity} radiosity, \
         {unshot} unshot and {charges} charge entries, {record} record bytes): truncated or damaged"
    )]
    Length {
        /// Its length, in bytes.
        len: usize,
        /// Radiosity entries the header promises.
        radiosity: u64,
        /// Unshot entries the header promises.
        unshot: u64,
        /// Charge entries the header promises.
        charges: u64,
        /// Driver record bytes the header promises.
        record: u64,
    },
    /// The trailing checksum does not match the bytes before it.
    #[error("its checksum does not match: the file is damaged")]
    Checksum,
}

/// A 64-bit FNV-1a style hash, fed whole words for speed. Stable across
/// platforms and Rust versions, unlike `std`'s hasher; not cryptographic
/// (it guards against mistakes, not attacks).
#[derive(Clone, Copy, Debug)]
struct Fnv(u64);

impl Fnv {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new() -> Self {
        Fnv(Self::OFFSET)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(Self::PRIME);
        }
    }

    fn word(&mut self, w: u64) {
        self.bytes(&w.to_le_bytes());
    }
}

/// The fingerprint of what decides a solve's result: the scene's polygons
/// and materials, the mesh's vertices and sample points, and the form-factor
/// options (not the stopping rule).
pub fn fingerprint(scene: &Scene, mesh: &Mesh, options: &SolverOptions) -> u64 {
    let mut h = Fnv::new();
    h.bytes(b"scene");
    h.word(scene.polygons.len() as u64);
    for p in &scene.polygons {
        h.word(p.material.0 as u64);
        // A sky facet (`--sky`) is meshed and sampled as no other polygon.
        h.word(p.surface.sky as u64);
        h.word(p.vertices.len() as u64);
        for v in &p.vertices {
            for c in v.to_array() {
                h.word(c.to_bits() as u64);
            }
        }
    }
    h.word(scene.materials.len() as u64);
    for m in &scene.materials {
        for c in [m.color.r, m.color.g, m.color.b, m.k_diffrefl, m.k_emission] {
            h.word(c.to_bits());
        }
    }
    // A luminaire's distribution shapes its shot (`--ies`); without
    // luminaires the fingerprint is what it was.
    for l in &scene.luminaires {
        h.word(u64::from(l.material.0));
        h.word(u64::from(l.upper));
        for c in l.c0.to_array() {
            h.word(u64::from(c.to_bits()));
        }
        let p = &l.photometry;
        for v in p.vertical.iter().chain(&p.horizontal).chain(&p.candela) {
            h.word(v.to_bits());
        }
    }
    // The sun's light is in the state from the start (`--sun`); without
    // a sun the fingerprint is what it was.
    if let Some(sun) = &scene.sun {
        h.bytes(b"sun");
        for c in sun.direction.to_array() {
            h.word(u64::from(c.to_bits()));
        }
        h.word(sun.normal_illuminance.to_bits());
    }
    // A standard sky spreads its facets' light by its luminance
    // (`--sky cie-...`); without one the fingerprint is what it was.
    if let Some(p) = &scene.sky_pattern {
        h.bytes(b"sky pattern");
        let sky = &p.sky;
        let model = match sky.model {
            crate::scene::SkyModel::CieOvercast => 0,
            crate::scene::SkyModel::Cie(n) => u64::from(n),
        };
        h.word(model);
        let sun = sky.sun.map_or([f64::NAN; 2], |s| [s.azimuth, s.altitude]);
        for v in [sky.zenith, sky.north, sun[0], sun[1]] {
            h.word(v.to_bits());
        }
        for v in [p.frame.east, p.frame.north, p.frame.up, p.centre] {
            for c in v.to_array() {
                h.word(c.to_bits());
            }
        }
        h.word(u64::from(p.facets.0));
        h.word(u64::from(p.facets.1));
    }
    h.bytes(b"mesh");
    h.word(mesh.vertex_count() as u64);
    h.word(mesh.elements.len() as u64);
    for (p, s) in mesh.positions.iter().zip(&mesh.sample_positions) {
        for c in p.to_array().into_iter().chain(s.to_array()) {
            h.word(c.to_bits() as u64);
        }
    }
    for pm in &mesh.polygons {
        h.word(pm.vertices.start as u64);
        h.word(pm.vertices.end as u64);
    }
    // The form-factor rules themselves: a checkpoint from a build that
    // estimated them otherwise would not continue to the same bits.
    h.bytes(b"options: cell quadrature, cells on every shooter");
    h.word(match options.form_factor {
        FormFactorMethod::Wallace => 1,
        FormFactorMethod::Center => 2,
        FormFactorMethod::Hemicube => 3,
    });
    if options.form_factor == FormFactorMethod::Hemicube {
        h.word(u64::from(options.hemicube_res.get()));
    }
    h.word(match options.shooter_samples {
        ShooterSamples::All => u64::MAX,
        ShooterSamples::AtMost(n) => n as u64,
    });
    // Every switch and every tuning constant: a build tuned otherwise
    // would not continue to the same bits.
    h.word(options.approximations.bits());
    h.word(super::tuning::INDEX.len() as u64);
    for tuned in super::tuning::INDEX {
        h.bytes(tuned.name.as_bytes());
        h.word(tuned.value.to_bits());
    }
    h.word(match options.unshot {
        super::UnshotScheme::Polygon => 1,
        super::UnshotScheme::Vertex => 2,
    });
    // When the particle tail takes over, and how many particles it traces.
    h.bytes(b"tail");
    match options.tail {
        super::TailOption::Off => h.word(0),
        super::TailOption::Auto => h.word(1),
        super::TailOption::From(f) => {
            h.word(2);
            h.word(f.to_bits());
        }
    }
    h.word(options.tail_particles.to_bits());
    h.0
}

/// A decoded checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// The [`fingerprint`] of the solve it was saved from.
    pub fingerprint: u64,
    /// The solver's state.
    pub state: SolverState,
    /// The driver's record saved with it (empty if none, or version 1).
    pub record: Vec<u8>,
}

/// The bytes of a checkpoint of `state` (a solver's
/// [`crate::solver::Method::state`]), with the driver's `record` (opaque
/// here).
pub fn encode(fingerprint: u64, state: &SolverState, record: &[u8]) -> Vec<u8> {
    let SolverState {
        radiosity,
        unshot,
        steps,
        rays,
        charges,
        tail_from,
        tail_began,
    } = state;
    let len = HEADER_LEN
        + RGB_LEN * (radiosity.len() + unshot.len() + charges.len() + tail_began.len())
        + record.len()
        + CHECKSUM_LEN;
    let mut out = Vec::with_capacity(len);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    for w in [
        fingerprint,
        *steps,
        *rays,
        radiosity.len() as u64,
        unshot.len() as u64,
        record.len() as u64,
        charges.len() as u64,
        tail_from.unwrap_or(f64::NAN).to_bits(),
        tail_began.len() as u64,
    ] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    for c in radiosity
        .iter()
        .chain(unshot)
        .chain(charges)
        .chain(tail_began)
    {
        for x in [c.r, c.g, c.b] {
            out.extend_from_slice(&x.to_bits().to_le_bytes());
        }
    }
    out.extend_from_slice(record);
    let mut h = Fnv::new();
    h.bytes(&out);
    out.extend_from_slice(&h.0.to_le_bytes());
    debug_assert_eq!(out.len(), len);
    out
}

/// Reads the fingerprint, state and driver record from checkpoint bytes
/// (version 1 to 5), or says what is wrong with them. Never allocates more
/// than the input's size.
pub fn decode(bytes: &[u8]) -> Result<Checkpoint, DecodeError> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(DecodeError::NotACheckpoint);
    }
    if bytes.len() < V1_HEADER_LEN + CHECKSUM_LEN {
        return Err(DecodeError::Truncated { len: bytes.len() });
    }
    let u64_at = |at: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[at..at + 8]);
        u64::from_le_bytes(b)
    };
    let mut v = [0u8; 4];
    v.copy_from_slice(&bytes[8..12]);
    let version = u32::from_le_bytes(v);
    if !(OLDEST_VERSION..=VERSION).contains(&version) {
        return Err(DecodeError::Version { found: version });
    }
    let header_len = match version {
        1 => V1_HEADER_LEN,
        2 => V2_HEADER_LEN,
        3 => V3_HEADER_LEN,
        4 => V4_HEADER_LEN,
        _ => HEADER_LEN,
    };
    if bytes.len() < header_len + CHECKSUM_LEN {
        return Err(DecodeError::Truncated { len: bytes.len() });
    }
    let (fingerprint, steps, rays) = (u64_at(12), u64_at(20), u64_at(28));
    let (n_radiosity, n_unshot) = (u64_at(36), u64_at(44));
    let n_record = if version == 1 { 0 } else { u64_at(52) };
    let n_charges = if version <= 2 { 0 } else { u64_at(60) };
    let tail_from = if version <= 3 {
        None
    } else {
        Some(f64::from_bits(u64_at(68))).filter(|f| !f.is_nan())
    };
    let n_began = if version <= 4 { 0 } else { u64_at(76) };
    let expected = n_radiosity
        .checked_add(n_unshot)
        .and_then(|n| n.checked_add(n_charges))
        .and_then(|n| n.checked_add(n_began))
        .and_then(|n| n.checked_mul(RGB_LEN as u64))
        .and_then(|n| n.checked_add(n_record))
        .and_then(|n| n.checked_add((header_len + CHECKSUM_LEN) as u64));
    if expected != Some(bytes.len() as u64) {
        return Err(DecodeError::Length {
            len: bytes.len(),
            radiosity: n_radiosity,
            unshot: n_unshot,
            charges: n_charges.saturating_add(n_began),
            record: n_record,
        });
    }
    let body = &bytes[..bytes.len() - CHECKSUM_LEN];
    let mut h = Fnv::new();
    h.bytes(body);
    if h.0 != u64_at(bytes.len() - CHECKSUM_LEN) {
        return Err(DecodeError::Checksum);
    }
    let rgb_at = |k: usize| {
        let at = header_len + k * RGB_LEN;
        Rgb::new(
            f64::from_bits(u64_at(at)),
            f64::from_bits(u64_at(at + 8)),
            f64::from_bits(u64_at(at + 16)),
        )
    };
    let (nr, nu, nc) = (n_radiosity as usize, n_unshot as usize, n_charges as usize);
    let nb = n_began as usize;
    let record_start = header_len + (nr + nu + nc + nb) * RGB_LEN;
    Ok(Checkpoint {
        fingerprint,
        state: SolverState {
            radiosity: (0..nr).map(rgb_at).collect(),
            unshot: (nr..nr + nu).map(rgb_at).collect(),
            steps,
            rays,
            charges: (nr + nu..nr + nu + nc).map(rgb_at).collect(),
            tail_from,
            tail_began: (nr + nu + nc..nr + nu + nc + nb).map(rgb_at).collect(),
        },
        record: body[record_start..].to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> SolverState {
        SolverState {
            radiosity: vec![Rgb::new(0.1, 0.2, 0.3), Rgb::new(1.0 / 3.0, 0.0, 5e-324)],
            unshot: vec![Rgb::new(7.0, 8.0, 9.0)],
            steps: 42,
            rays: 1 << 40,
            charges: vec![Rgb::new(0.0, 1e-9, 2.0), Rgb::BLACK],
            tail_from: Some(0.307),
            tail_began: vec![
                Rgb::new(0.5, 0.25, 0.125),
                Rgb::BLACK,
                Rgb::new(-1e-3, 4.0, 1e300),
                Rgb::new(2.0, 2.0, 2.0),
            ],
        }
    }

    #[test]
    fn round_trip_keeps_every_bit() {
        let bytes = encode(0xfeed, &state(), b"log");
        let Checkpoint {
            fingerprint: fp,
            state: back,
            record,
        } = decode(&bytes).unwrap();
        assert_eq!(record, b"log");
        assert_eq!(fp, 0xfeed);
        assert_eq!(back, state());
        assert_eq!(back.radiosity[1].b.to_bits(), 5e-324f64.to_bits());
    }

    /// `state()` without charges, tail fraction or tail-began entries, as
    /// versions 1 and 2 hold it.
    fn uncharged() -> SolverState {
        SolverState {
            charges: Vec::new(),
            tail_from: None,
            tail_began: Vec::new(),
            ..state()
        }
    }

    /// Version `v` bytes made from version 5 bytes of `state` (without
    /// tail-began entries): the header cut to `header` bytes, the record
    /// kept or not.
    fn older_of(state: &SolverState, v: u32, header: usize, record: &[u8]) -> Vec<u8> {
        let state = SolverState {
            tail_began: Vec::new(),
            ..state.clone()
        };
        let v3 = encode(5, &state, record);
        let mut out = v3[..8].to_vec();
        out.extend_from_slice(&v.to_le_bytes());
        out.extend_from_slice(&v3[12..header]);
        let end = if v == 1 {
            v3.len() - CHECKSUM_LEN - record.len()
        } else {
            v3.len() - CHECKSUM_LEN
        };
        out.extend_from_slice(&v3[HEADER_LEN..end]);
        let mut h = Fnv::new();
        h.bytes(&out);
        out.extend_from_slice(&h.0.to_le_bytes());
        out
    }

    /// [`older_of`] an uncharged state.
    fn older(v: u32, header: usize, record: &[u8]) -> Vec<u8> {
        older_of(&uncharged(), v, header, record)
    }

    #[test]
    fn a_tail_that_is_off_round_trips_as_none() {
        let off = SolverState {
            tail_from: None,
            ..state()
        };
        assert_eq!(decode(&encode(3, &off, b"")).unwrap().state, off);
    }

    #[test]
    fn version_1_to_4_files_still_read() {
        // Version 4 is version 5 without the tail-began entries.
        let v4 = SolverState {
            tail_began: Vec::new(),
            ..state()
        };
        let back = decode(&older_of(&state(), 4, V4_HEADER_LEN, b"log")).unwrap();
        assert_eq!(back.state, v4);
        assert_eq!(back.record, b"log");
        // Version 3 is version 4 without the tail fraction: the options
        // decide it.
        let charged = SolverState {
            tail_from: None,
            tail_began: Vec::new(),
            ..state()
        };
        let back = decode(&older_of(&state(), 3, V3_HEADER_LEN, b"log")).unwrap();
        assert_eq!(back.state, charged);
        assert_eq!(back.record, b"log");
        // Version 1 is version 2 without the record-length field.
        let back = decode(&older(1, V1_HEADER_LEN, b"")).unwrap();
        assert_eq!(back.fingerprint, 5);
        assert_eq!(back.state, uncharged());
        assert!(back.record.is_empty());
        // Version 2 is version 3 without the charges.
        let back = decode(&older(2, V2_HEADER_LEN, b"log")).unwrap();
        assert_eq!(back.state, uncharged());
        assert_eq!(back.record, b"log");
    }

    #[test]
    fn damage_of_any_kind_is_refused() {
        let bytes = encode(1, &state(), b"record");
        // Every truncation.
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
        }
        // Every single-bit flip: magic, version, counts, data or checksum.
        for i in 0..bytes.len() {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                assert!(decode(&b).is_err(), "flip at byte {i} bit {bit}");
            }
        }
        // A header promising far more data than there is allocates nothing.
        let mut b = bytes.clone();
        b[36..44].copy_from_slice(&u64::MAX.to_le_bytes());
        let e = decode(&b).unwrap_err().to_string();
        assert!(e.contains("does not match its header"), "{e}");
        let mut b = bytes;
        b[8] = 9;
        assert!(decode(&b).unwrap_err().to_string().contains("version 9"));
        assert!(decode(b"P6\n3 2\n255\n")
            .unwrap_err()
            .to_string()
            .contains("does not start"));
    }
}
