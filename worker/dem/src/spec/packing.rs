//! The reference packing: hexagonal, seeded random or an explicit disc list (a packing file
//! read on the master), and the cap on the disc count.

use crate::error::{Result, invalid, positive};
use crate::packing::explicit::first_overlap;
use crate::packing::formats::{MIN_DISCS, PackingFormat};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Reference arrangement of the discs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PackingSpec {
    /// Dense hexagonal arrangement of equal discs filling a `side` x `side` square (penalty
    /// boundary) or the nearest periodic-compatible rectangle (periodic boundary: `2 r` times
    /// a whole number of columns by `sqrt(3) r` times an even number of rows).
    Hexagonal {
        /// Disc radius (m). Default 5 mm.
        radius: f64,
        /// Side of the reference square (m). Default 0.1 m (V = 0.01 m^2, about 100 discs).
        side: f64,
        /// Which way the lattice runs: rows along x (the default) or turned by 90 degrees.
        #[serde(default, skip_serializing_if = "LatticeOrientation::is_rows")]
        orientation: LatticeOrientation,
        /// Initial overlap of neighbours, a fraction of the diameter: centres `2 r (1 -
        /// overlap)` apart, in `[0, 0.05]`. Default 0 (touching, no force).
        #[serde(default, skip_serializing_if = "is_zero")]
        overlap: f64,
    },
    /// Seeded random polydisperse packing brought to an isotropic confining stress.
    Random {
        /// Smallest radius (m) of the uniform radius distribution.
        r_min: f64,
        /// Largest radius (m).
        r_max: f64,
        /// Explicit radii (m); when non-empty it replaces `r_min`/`r_max` and fixes the count.
        #[serde(default)]
        radii: Vec<f64>,
        /// Target side of the reference square (m); the final side is where the confining
        /// stress is reached (reported by [`crate::Assembly::area`]).
        side: f64,
        /// Seed of the ChaCha8 generator: same seed, same bits.
        seed: u64,
        /// Isotropic confining stress magnitude (Pa, compression positive).
        confining_stress: f64,
    },
    /// An explicit disc list, the reference state as given (no compression, no relaxation
    /// before the first load; see [`crate::packing::explicit`]). What a `file` packing
    /// becomes on the master; may also be written out in a job.
    Explicit {
        /// Centres x (m), in `[0, lx]` give or take one largest diameter.
        x: Vec<f64>,
        /// Centres y (m), in `[0, ly]` give or take one largest diameter.
        y: Vec<f64>,
        /// Radii (m), one per centre.
        radii: Vec<f64>,
        /// Width of the reference region `[0, lx] x [0, ly]` (m): the square of a penalty
        /// boundary, the cell of a periodic one.
        lx: f64,
        /// Height of the reference region (m).
        ly: f64,
    },
    /// A packing file (YADE text or LAMMPS data), read on the master by the job loader into
    /// [`PackingSpec::Explicit`] before the job is validated: a worker never reads a file and
    /// refuses this variant.
    File {
        /// The file; relative to the job file.
        file: PathBuf,
        /// `yade` or `lammps`.
        format: PackingFormat,
    },
}

/// Which way a hexagonal lattice runs in its square.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LatticeOrientation {
    /// Rows of touching discs along x: contact families at 0, 60 and 120 degrees. Under a
    /// vertical load without lateral stress its 60-degree contacts slide (it cannot stand
    /// below a lateral to axial stress ratio of about 0.035).
    #[default]
    Rows,
    /// Turned by 90 degrees: columns along y, contact families at 90, 30 and 150 degrees. A
    /// vertical load is carried by the columns, at any lateral stress down to zero.
    Columns,
}

impl LatticeOrientation {
    fn is_rows(&self) -> bool {
        *self == LatticeOrientation::Rows
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// How a hexagonal packing's lattice is laid: its orientation and initial overlap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lattice {
    /// Rows along x or columns along y.
    pub orientation: LatticeOrientation,
    /// Overlap of neighbours, a fraction of the diameter.
    pub overlap: f64,
}

/// Largest initial overlap of a hexagonal lattice (a fraction of the diameter): beyond it the
/// contacts start far outside the small-overlap range of the linear contact law.
pub const MAX_LATTICE_OVERLAP: f64 = 0.05;

impl Default for PackingSpec {
    fn default() -> Self {
        Self::hexagonal(0.005, 0.1)
    }
}

/// Most discs one assembly may hold (a cap so that a typo in `side` or `radius`, or a hostile
/// request, cannot ask a worker for 10^17 discs). The paper's largest assemblies hold a few
/// thousand; 10^6 discs take about 0.5 GB.
pub const MAX_DISCS: usize = 1_000_000;

impl PackingSpec {
    /// A hexagonal packing of discs of `radius` in a square of `side`, rows along x,
    /// touching.
    pub fn hexagonal(radius: f64, side: f64) -> Self {
        Self::Hexagonal { radius, side, orientation: LatticeOrientation::Rows, overlap: 0.0 }
    }

    /// The number of discs this packing will hold, estimated before anything is allocated
    /// (exact for an explicit radius list; within a few per cent otherwise). May be infinite
    /// for absurd ratios of side to radius.
    pub fn estimated_discs(&self) -> f64 {
        match self {
            PackingSpec::Hexagonal { radius, side, overlap, .. } => {
                let h = radius * (1.0 - overlap);
                (side / (2.0 * h) + 1.0) * (side / (3f64.sqrt() * h) + 1.0)
            }
            PackingSpec::Random { r_min, r_max, radii, side, .. } => {
                if radii.is_empty() {
                    let er2 = (r_min * r_min + r_min * r_max + r_max * r_max) / 3.0;
                    0.84 * side * side / (std::f64::consts::PI * er2)
                } else {
                    radii.len() as f64
                }
            }
            PackingSpec::Explicit { radii, .. } => radii.len() as f64,
            PackingSpec::File { .. } => f64::NAN,
        }
    }

    /// The packing's kind as the job file names it.
    pub fn kind(&self) -> &'static str {
        match self {
            PackingSpec::Hexagonal { .. } => "hexagonal",
            PackingSpec::Random { .. } => "random",
            PackingSpec::Explicit { .. } => "explicit",
            PackingSpec::File { .. } => "file",
        }
    }

    /// The `side` key of a generated packing (hexagonal, random); None for an explicit disc
    /// list or a file, whose region is given.
    pub fn side(&self) -> Option<f64> {
        match self {
            PackingSpec::Hexagonal { side, .. } | PackingSpec::Random { side, .. } => Some(*side),
            PackingSpec::Explicit { .. } | PackingSpec::File { .. } => None,
        }
    }

    /// The `side` key of a generated packing, to change it (None as for [`Self::side`]).
    pub fn side_mut(&mut self) -> Option<&mut f64> {
        match self {
            PackingSpec::Hexagonal { side, .. } | PackingSpec::Random { side, .. } => Some(side),
            PackingSpec::Explicit { .. } | PackingSpec::File { .. } => None,
        }
    }

    /// Side of the square of the reference region's area (m): `side` for a generated
    /// packing, `sqrt(lx ly)` for an explicit disc list, NaN for an unread file.
    pub fn region_side(&self) -> f64 {
        match self {
            PackingSpec::Explicit { lx, ly, .. } => (lx * ly).sqrt(),
            other => other.side().unwrap_or(f64::NAN),
        }
    }

    /// The largest radius the packing can hold (m): `radius`, `r_max` or the largest of an
    /// explicit list; NaN for an unread file.
    pub fn largest_radius(&self) -> f64 {
        match self {
            PackingSpec::Hexagonal { radius, .. } => *radius,
            PackingSpec::Random { r_max, radii, .. } => {
                radii.iter().copied().fold(*r_max, f64::max)
            }
            PackingSpec::Explicit { radii, .. } => radii.iter().copied().fold(0.0, f64::max),
            PackingSpec::File { .. } => f64::NAN,
        }
    }

    /// Checks the packing's fields and that it holds at most [`MAX_DISCS`] discs.
    pub(super) fn validate(&self) -> Result<()> {
        match self {
            PackingSpec::Hexagonal { radius, side, overlap, .. } => {
                positive("packing.radius", *radius)?;
                positive("packing.side", *side)?;
                if !(0.0..=MAX_LATTICE_OVERLAP).contains(overlap) {
                    return Err(invalid(
                        "packing.overlap",
                        overlap,
                        "must be in [0, 0.05] (a fraction of the diameter)",
                    ));
                }
                if *side < 8.0 * radius {
                    return Err(invalid(
                        "packing.side",
                        side,
                        "must be at least four diameters (8 r)",
                    ));
                }
            }
            PackingSpec::Random { r_min, r_max, radii, side, confining_stress, .. } => {
                positive("packing.side", *side)?;
                positive("packing.confining_stress", *confining_stress)?;
                let r_big = if radii.is_empty() {
                    positive("packing.r_min", *r_min)?;
                    positive("packing.r_max", *r_max)?;
                    if r_min > r_max {
                        return Err(invalid(
                            "packing.r_min",
                            format!("{r_min:?} > r_max = {r_max:?}"),
                            "inverted radius range: r_min must be <= r_max",
                        ));
                    }
                    *r_max
                } else {
                    let mut big = 0.0f64;
                    for &r in radii {
                        positive("packing.radii", r)?;
                        big = big.max(r);
                    }
                    if radii.len() < 4 {
                        return Err(invalid("packing.radii", radii.len(), "need at least 4 discs"));
                    }
                    big
                };
                if *side < 8.0 * r_big {
                    return Err(invalid(
                        "packing.side",
                        side,
                        "must be at least four largest diameters (8 r_max)",
                    ));
                }
                if radii.len() > MAX_DISCS {
                    return Err(invalid(
                        "packing.radii",
                        format!("{} radii", radii.len()),
                        "more than MAX_DISCS = 1 000 000 discs in one assembly",
                    ));
                }
            }
            PackingSpec::Explicit { x, y, radii, lx, ly } => {
                validate_explicit(x, y, radii, *lx, *ly)?;
                return Ok(());
            }
            PackingSpec::File { file, .. } => {
                return Err(invalid(
                    "packing.file",
                    file.display().to_string(),
                    "a packing file is read on the master when the job is loaded; an assembly \
                     spec must carry its discs (kind = \"explicit\")",
                ));
            }
        }
        let n = self.estimated_discs();
        if n.is_nan() || n > MAX_DISCS as f64 {
            return Err(invalid(
                "packing.side",
                format!("{:?} (about {n:.3e} discs)", self.side().unwrap_or(f64::NAN)),
                "side / radius too large: more than MAX_DISCS = 1 000 000 discs in one assembly",
            ));
        }
        Ok(())
    }
}

/// The checks of an explicit disc list: equal lengths, [`MIN_DISCS`] to [`MAX_DISCS`] discs,
/// finite centres in the region grown by one largest diameter, radii `> 0`, a region of at least four largest diameters
/// each way, and no overlap beyond [`crate::packing::explicit::OVERLAP_TOLERANCE`] (inside
/// the region; across the faces of a periodic cell when the assembly is built). Errors name
/// the key, the disc's index and the value.
fn validate_explicit(x: &[f64], y: &[f64], radii: &[f64], lx: f64, ly: f64) -> Result<()> {
    let n = radii.len();
    if n > MAX_DISCS {
        return Err(invalid(
            "packing.radii",
            format!("{n} radii"),
            "more than MAX_DISCS = 1 000 000 discs in one assembly",
        ));
    }
    if n < MIN_DISCS {
        return Err(invalid("packing.radii", n, "need at least 4 discs"));
    }
    if x.len() != n {
        return Err(invalid(
            "packing.x",
            format!("{} centres for {n} radii", x.len()),
            "one x per radius",
        ));
    }
    if y.len() != n {
        return Err(invalid(
            "packing.y",
            format!("{} centres for {n} radii", y.len()),
            "one y per radius",
        ));
    }
    positive("packing.lx", lx)?;
    positive("packing.ly", ly)?;
    let mut r_max = 0.0f64;
    for k in 0..n {
        r_max = r_max.max(radii[k]);
    }
    let d = 2.0 * r_max;
    for k in 0..n {
        if !(radii[k].is_finite() && radii[k] > 0.0) {
            return Err(invalid(
                "packing.radii",
                format!("radii[{k}] = {:?}", radii[k]),
                "must be finite and > 0",
            ));
        }
        if !(-d..=lx + d).contains(&x[k]) {
            return Err(invalid(
                "packing.x",
                format!("x[{k}] = {:?}", x[k]),
                "must be finite and in [-2 r_max, lx + 2 r_max]",
            ));
        }
        if !(-d..=ly + d).contains(&y[k]) {
            return Err(invalid(
                "packing.y",
                format!("y[{k}] = {:?}", y[k]),
                "must be finite and in [-2 r_max, ly + 2 r_max]",
            ));
        }
    }
    if lx.min(ly) < 8.0 * r_max {
        return Err(invalid(
            "packing.lx",
            format!("{lx:?} x {ly:?}"),
            "the region must be at least four largest diameters (8 r_max) each way",
        ));
    }
    if let Some(o) = first_overlap(x, y, radii, lx, ly, false) {
        return Err(invalid(
            "packing.radii",
            format!("discs {} and {} overlapping by {:?}", o.i, o.j, o.overlap),
            "two discs overlap by more than 1e-2 of the smaller radius",
        ));
    }
    Ok(())
}
