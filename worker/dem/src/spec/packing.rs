//! The reference packing: hexagonal or seeded random, and the cap on the disc count.

use crate::error::{Result, invalid, positive};
use serde::{Deserialize, Serialize};

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
}

impl Default for PackingSpec {
    fn default() -> Self {
        Self::Hexagonal { radius: 0.005, side: 0.1 }
    }
}

/// Most discs one assembly may hold (a cap so that a typo in `side` or `radius`, or a hostile
/// request, cannot ask a worker for 10^17 discs). The paper's largest assemblies hold a few
/// thousand; 10^6 discs take about 0.5 GB.
pub const MAX_DISCS: usize = 1_000_000;

impl PackingSpec {
    /// The number of discs this packing will hold, estimated before anything is allocated
    /// (exact for an explicit radius list; within a few per cent otherwise). May be infinite
    /// for absurd ratios of side to radius.
    pub fn estimated_discs(&self) -> f64 {
        match self {
            PackingSpec::Hexagonal { radius, side } => {
                (side / (2.0 * radius) + 1.0) * (side / (3f64.sqrt() * radius) + 1.0)
            }
            PackingSpec::Random { r_min, r_max, radii, side, .. } => {
                if radii.is_empty() {
                    let er2 = (r_min * r_min + r_min * r_max + r_max * r_max) / 3.0;
                    0.84 * side * side / (std::f64::consts::PI * er2)
                } else {
                    radii.len() as f64
                }
            }
        }
    }

    /// Checks the packing's fields and that it holds at most [`MAX_DISCS`] discs.
    pub(super) fn validate(&self) -> Result<()> {
        match self {
            PackingSpec::Hexagonal { radius, side } => {
                positive("packing.radius", *radius)?;
                positive("packing.side", *side)?;
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
        }
        let n = self.estimated_discs();
        if n.is_nan() || n > MAX_DISCS as f64 {
            return Err(invalid(
                "packing.side",
                format!("{:?} (about {n:.3e} discs)", self.side()),
                "side / radius too large: more than MAX_DISCS = 1 000 000 discs in one assembly",
            ));
        }
        Ok(())
    }

    /// Side of the reference square (m).
    fn side(&self) -> f64 {
        match self {
            PackingSpec::Hexagonal { side, .. } | PackingSpec::Random { side, .. } => *side,
        }
    }
}
