//! The memory budget of a run (`--max-memory`): one number of bytes that
//! every stage which could grow memory far beyond the size of its input
//! checks *before* it allocates — glTF node instancing, the OBJ faces,
//! the splitting of polygons along intersections, the mesh, and the
//! decoding of textures — so that a small hostile file ends with a clear
//! error instead of an out-of-memory abort.
//!
//! The estimates come from one model of a whole run's peak memory
//! ([`run_bytes`]): a fixed base, and bytes per scene polygon, per mesh
//! element and per mesh vertex, measured as the peak resident memory of
//! runs of three shooting steps (see `docs/reliability.md`). A stage that
//! knows only its polygons (a loader, the splitter) counts the least mesh
//! they can have, one element on the corners of each ([`least_run_bytes`]).
//!
//! The default ([`MemoryBudget::for_machine`]) is a fraction of the memory
//! the machine can give the process: the least of three quarters of the
//! physical memory (or of the cgroup's `memory.max`), the memory
//! available now, and half the address-space limit (`ulimit -v`), read
//! on Linux from `/proc` and `/sys`; elsewhere [`FALLBACK_BYTES`].

use std::sync::OnceLock;

/// Resident memory of a run apart from its scene: the program, its
/// threads, the picture and its buffers, in bytes (90 MB measured on the
/// bundled scene of 43 polygons).
pub const BASE_BYTES: u64 = 64_000_000;

/// Bytes held per mesh vertex during a whole run: positions and sample
/// points, the solver's radiosity, unshot and step scratch (its shaft
/// candidates grow with the polygons between shooter and receiver), the
/// rasteriser's projected vertex, a checkpoint's copy and the growth of
/// the arrays that hold them. With [`BYTES_PER_POLYGON`], fitted so that
/// the estimate is within a factor of 2 of the measured peaks of
/// `docs/reliability.md` (from 370 bytes a vertex on a scene of few
/// polygons to 1,270 on intersecting quads split into 52,920 pieces).
pub const BYTES_PER_VERTEX: u64 = 600;

/// Bytes held per mesh element during a run: its corners and owning
/// polygon.
pub const BYTES_PER_ELEMENT: u64 = 24;

/// Bytes held per scene polygon during a run apart from its mesh: the
/// polygon, its bounding boxes in the splitter's and the visibility's
/// BVHs, its plane class and draw layer, its culling group and shaft
/// candidate lists.
pub const BYTES_PER_POLYGON: u64 = 1_000;

/// The budget when the machine's memory cannot be read: 4 GB.
pub const FALLBACK_BYTES: u64 = 4_000_000_000;

/// The least budget `--max-memory` accepts: below it not even the base
/// of a run ([`BASE_BYTES`]) fits.
pub const MIN_BYTES: u64 = 100_000_000;

/// Estimated peak memory of a run, in bytes, for a scene of `polygons`
/// polygons meshed into `elements` elements on `vertices` vertices.
/// Saturates rather than overflows.
pub fn run_bytes(polygons: u64, elements: u64, vertices: u64) -> u64 {
    BASE_BYTES
        .saturating_add(polygons.saturating_mul(BYTES_PER_POLYGON))
        .saturating_add(elements.saturating_mul(BYTES_PER_ELEMENT))
        .saturating_add(vertices.saturating_mul(BYTES_PER_VERTEX))
}

/// [`run_bytes`] for the least mesh `polygons` polygons with `corners`
/// corners in all can have (one element each, on its corners): what a
/// stage that has not meshed yet knows the run will need at least.
pub fn least_run_bytes(polygons: u64, corners: u64) -> u64 {
    run_bytes(polygons, polygons, corners)
}

/// A number of bytes that a run must stay under; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBudget {
    bytes: u64,
}

/// The refusal of a stage whose estimate is over the budget.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "this scene would need about {} ({what}) but --max-memory is {}",
    fmt_bytes(*need),
    fmt_bytes(*budget)
)]
pub struct OverBudget {
    /// The estimate, in bytes.
    pub need: u64,
    /// What made it so large (`30,000,000 triangles from node instancing`).
    pub what: String,
    /// The budget, in bytes.
    pub budget: u64,
}

impl MemoryBudget {
    /// A budget of `bytes` bytes.
    pub const fn new(bytes: u64) -> Self {
        MemoryBudget { bytes }
    }

    /// No limit: for tests and tools that want nothing refused.
    pub const UNLIMITED: MemoryBudget = MemoryBudget { bytes: u64::MAX };

    /// The budget in bytes.
    pub const fn bytes(&self) -> u64 {
        self.bytes
    }

    /// The default budget of this machine (see the module docs), read
    /// once.
    pub fn for_machine() -> Self {
        static DEFAULT: OnceLock<u64> = OnceLock::new();
        MemoryBudget::new(*DEFAULT.get_or_init(machine_default))
    }

    /// Ok when `need` bytes fit; else the refusal, with `what` (called
    /// only then) saying what needs them.
    pub fn check(&self, need: u64, what: impl FnOnce() -> String) -> Result<(), OverBudget> {
        if need <= self.bytes {
            Ok(())
        } else {
            Err(OverBudget {
                need,
                what: what(),
                budget: self.bytes,
            })
        }
    }

    /// True when `need` bytes fit.
    pub fn fits(&self, need: u64) -> bool {
        need <= self.bytes
    }

    /// The most elements, each with a vertex of its own, that fit besides
    /// the base of a run ([`run_bytes`] of no polygons): the limit an
    /// adaptive refinement grows the mesh to.
    pub fn elements_within(&self) -> u64 {
        self.bytes.saturating_sub(BASE_BYTES) / (BYTES_PER_ELEMENT + BYTES_PER_VERTEX)
    }
}

/// The machine's default budget: the least of three quarters of the
/// physical memory and of the cgroup limit, the memory available now and
/// half the address-space limit; [`FALLBACK_BYTES`] when none can be read.
fn machine_default() -> u64 {
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    let field = |name: &str| -> Option<u64> {
        let line = meminfo.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line[name.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb.saturating_mul(1024))
    };
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    let address_space = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|s| address_space_limit(&s));
    let candidates = [
        field("MemTotal:").map(|b| b / 4 * 3),
        cgroup.map(|b| b / 4 * 3),
        field("MemAvailable:"),
        address_space.map(|b| b / 2),
    ];
    candidates
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(FALLBACK_BYTES)
        .max(MIN_BYTES)
}

/// The soft `Max address space` of a `/proc/self/limits` text, in bytes;
/// `None` when unlimited or absent.
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Parses a byte count as `--max-memory` takes it: a whole or decimal
/// number with an optional suffix `K`, `M`, `G` or `T` (powers of 1024,
/// in either case, with or without a trailing `B` or `iB`): `4G`,
/// `512M`, `1.5g`, `2000000000`.
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let upper = t.to_ascii_uppercase();
    let body = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, scale) = match body.char_indices().last() {
        Some((i, c @ ('K' | 'M' | 'G' | 'T'))) => {
            let power = match c {
                'K' => 1,
                'M' => 2,
                'G' => 3,
                _ => 4,
            };
            (&body[..i], 1024f64.powi(power))
        }
        _ => (body, 1.0),
    };
    let value: f64 = number.trim().parse().map_err(|_| {
        format!("`{text}` is not a size: give bytes, or a number with K, M, G or T")
    })?;
    let bytes = value * scale;
    if !bytes.is_finite() || bytes < 0.0 || bytes >= u64::MAX as f64 {
        return Err(format!("`{text}` is not a size in bytes"));
    }
    Ok(bytes.round() as u64)
}

/// `bytes` as `1.5 GB`, `320 MB`, `12 kB` (powers of 1000, as the
/// messages and docs give sizes).
pub fn fmt_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).ceil())
    }
}

/// `n` with thousands separators: `30,000,000`.
pub fn fmt_count(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_suffixes() {
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("512mb"), Ok(512 << 20));
        assert_eq!(parse_bytes("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes("2000000000"), Ok(2_000_000_000));
        assert_eq!(parse_bytes("64k"), Ok(65_536));
        assert!(parse_bytes("lots").is_err());
        assert!(parse_bytes("-1G").is_err());
        assert!(parse_bytes("G").is_err());
        assert!(parse_bytes("1e30T").is_err());
    }

    #[test]
    fn the_refusal_says_the_estimate_what_and_the_budget() {
        let budget = MemoryBudget::new(2_000_000_000);
        assert_eq!(budget.check(2_000_000_000, || unreachable!()), Ok(()));
        let e = budget
            .check(4_200_000_000, || "30,000,000 triangles".to_string())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "this scene would need about 4.2 GB (30,000,000 triangles) but --max-memory is 2.0 GB"
        );
    }

    #[test]
    fn counts_get_thousands_separators() {
        assert_eq!(fmt_count(0), "0");
        assert_eq!(fmt_count(999), "999");
        assert_eq!(fmt_count(1000), "1,000");
        assert_eq!(fmt_count(30_000_000), "30,000,000");
    }

    #[test]
    fn the_address_space_limit_is_read_from_proc_limits() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max cpu time              unlimited            unlimited            seconds   \n\
                      Max address space         4096000000           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(4_096_000_000));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(address_space_limit(unlimited), None);
    }

    #[test]
    fn the_machine_default_is_at_least_the_minimum() {
        assert!(MemoryBudget::for_machine().bytes() >= MIN_BYTES);
    }

    #[test]
    fn the_run_estimate_adds_its_parts() {
        assert_eq!(run_bytes(0, 0, 0), BASE_BYTES);
        assert_eq!(
            least_run_bytes(2, 6),
            BASE_BYTES + 2 * BYTES_PER_POLYGON + 2 * BYTES_PER_ELEMENT + 6 * BYTES_PER_VERTEX
        );
        assert_eq!(run_bytes(u64::MAX, 1, 1), u64::MAX);
    }
}
