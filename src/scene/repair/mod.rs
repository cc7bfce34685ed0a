//! The passes that make real exports solvable: closed solids keep their
//! outside ([`solids`]), polygons are cut where others pass through them
//! ([`split`]), two-sided faces get their back copies ([`sides`]), a lamp's
//! side trapped under a ceiling falls silent ([`trapped`]), and coplanar
//! overlapping faces are ranked for drawing ([`coplanar`]).

pub(super) mod coplanar;
pub(super) mod sides;
pub(super) mod solids;
pub(super) mod split;
pub(super) mod trapped;
