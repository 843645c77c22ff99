//! `[specimens]`: how many distinct DEM assemblies (specimens) the Gauss points draw from, and
//! at which confining stress each point's assembly is consolidated (the initial state).
//!
//! - Which specimen a Gauss point gets ([`SpecimensSection::specimen_of`]): with `count = K`,
//!   a seeded hash of the point, `splitmix64(seed ^ ((element << 32) | point)) % K`, so that
//!   the K specimens are spread over the mesh without a pattern and the same job always gives
//!   the same assignment; with `count = "per_point"`, every point is its own specimen (its
//!   flat index). Specimen `k` is the material's `random` packing with seed `seed + k`
//!   (wrapping) ([`SpecimensSection::assembly_of`]).
//! - At which stress ([`SpecimensSection::level_of`]): `uniform` consolidates every assembly
//!   at its packing's `confining_stress`; `in_situ` at the mean stress of an elastic estimate
//!   of the initial state, rounded to the nearest level of the geometric ladder
//!   `min_stress * level_ratio^n` (nearest in log scale), so that a few levels serve the whole
//!   mesh.
//!
//! A job without `[specimens]` has one specimen consolidated uniformly: the assembly of its
//! `[material]`, as before.

use crate::schema::{Job, MaterialSection};
use crate::validate::interned;
use cosdem_dem::AssemblySpec;
use cosdem_dem::spec::PackingSpec;
use cosdem_fem::error::{Error, Result};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `specimens.count`: K distinct specimens, or one per Gauss point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecimenCount {
    /// `count = K` (an integer, at least 1; default 1): K specimens assigned by a seeded hash.
    Count(u64),
    /// `count = "per_point"`: every Gauss point its own specimen.
    PerPoint,
}

impl Default for SpecimenCount {
    fn default() -> Self {
        Self::Count(1)
    }
}

impl Serialize for SpecimenCount {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Self::Count(k) => s.serialize_u64(*k),
            Self::PerPoint => s.serialize_str("per_point"),
        }
    }
}

impl<'de> Deserialize<'de> for SpecimenCount {
    /// An integer (`4`) or the string `"per_point"`; anything else is refused naming both
    /// forms (serde's untagged enums only say "did not match any variant").
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = SpecimenCount;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a whole number of specimens (>= 1) or \"per_point\"")
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<Self::Value, E> {
                Ok(SpecimenCount::Count(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<Self::Value, E> {
                u64::try_from(v).map(SpecimenCount::Count).map_err(|_| {
                    E::custom(format!("`specimens.count` = {v}: must be >= 1 or \"per_point\""))
                })
            }
            fn visit_str<E: serde::de::Error>(
                self,
                v: &str,
            ) -> std::result::Result<Self::Value, E> {
                match v {
                    "per_point" => Ok(SpecimenCount::PerPoint),
                    _ => Err(E::custom(format!(
                        "`specimens.count` = {v:?}: must be a whole number >= 1 or \"per_point\""
                    ))),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// `specimens.consolidation`: the stress each Gauss point's assembly is consolidated at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Consolidation {
    /// The packing's own `confining_stress` everywhere (default).
    #[default]
    Uniform,
    /// The mean stress of an elastic estimate of the initial state at the point, rounded to
    /// the ladder of levels ([`SpecimensSection::level_of`]).
    InSitu,
}

/// `[specimens]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpecimensSection {
    /// Distinct specimens: an integer K >= 1 (default 1) or `"per_point"`.
    pub count: SpecimenCount,
    /// Seed of the assignment hash (default 0); the packings' own seeds are untouched by it.
    pub seed: u64,
    /// `uniform` (default) or `in_situ`.
    pub consolidation: Consolidation,
    /// Poisson's ratio of the elastic solve that estimates the in-situ stress (default 0.3),
    /// in (-1, 0.5).
    pub poisson: f64,
    /// Ratio between consecutive consolidation levels (default 1.5), > 1.
    pub level_ratio: f64,
    /// The lowest consolidation level (Pa, default 1e4), finite and > 0.
    pub min_stress: f64,
}

impl Default for SpecimensSection {
    fn default() -> Self {
        Self {
            count: SpecimenCount::default(),
            seed: 0,
            consolidation: Consolidation::default(),
            poisson: 0.3,
            level_ratio: 1.5,
            min_stress: 1e4,
        }
    }
}

/// The SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijection of `u64` whose every output
/// bit depends on every input bit, so consecutive keys give unrelated values.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl SpecimensSection {
    /// Whether the section is the default one (one specimen, uniform consolidation): the job
    /// runs as a job without `[specimens]`.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Whether the assemblies differ from point to point (more than one specimen, or an
    /// in-situ consolidation): the DEM materials then need a `random` packing.
    pub fn varies(&self) -> bool {
        self.count != SpecimenCount::Count(1) || self.consolidation == Consolidation::InSitu
    }

    /// The specimen of Gauss point `point` of `element`, whose index among the mesh's
    /// `n_points_total` points (element-major) is `flat_index`: with `count = K`,
    /// `splitmix64(seed ^ ((element << 32) | point)) % K`; with `"per_point"`, `flat_index`.
    pub fn specimen_of(
        &self,
        n_points_total: usize,
        element: u32,
        point: u32,
        flat_index: usize,
    ) -> u64 {
        debug_assert!(flat_index < n_points_total, "{flat_index} of {n_points_total} points");
        match self.count {
            SpecimenCount::Count(k) => {
                let key = (u64::from(element) << 32) | u64::from(point);
                splitmix64(self.seed ^ key) % k.max(1)
            }
            SpecimenCount::PerPoint => flat_index as u64,
        }
    }

    /// The consolidation level (Pa) of a point whose estimated mean stress (compression
    /// positive) is `mean_stress`: `min_stress * level_ratio^n` with `n` the nearest integer to
    /// `log_ratio(mean_stress / min_stress)` (nearest in log scale, so the level is within a
    /// factor `level_ratio^0.5` of the stress); `min_stress` for a stress at or below it (or
    /// NaN).
    pub fn level_of(&self, mean_stress: f64) -> f64 {
        if mean_stress.is_nan() || mean_stress <= self.min_stress {
            return self.min_stress;
        }
        let n = ((mean_stress / self.min_stress).ln() / self.level_ratio.ln()).round();
        self.min_stress * self.level_ratio.powi(n as i32)
    }

    /// The assembly of specimen `specimen` of `base`, consolidated at `stress` (Pa) if given:
    /// a `random` packing's seed becomes `seed + specimen` (wrapping) and its
    /// `confining_stress` the stress; other packings are returned as they are (validation
    /// refuses them when the specimens vary).
    pub fn assembly_of(
        &self,
        base: &AssemblySpec,
        specimen: u64,
        stress: Option<f64>,
    ) -> AssemblySpec {
        let mut spec = base.clone();
        if let PackingSpec::Random { seed, confining_stress, .. } = &mut spec.packing {
            *seed = seed.wrapping_add(specimen);
            if let Some(s) = stress {
                *confining_stress = s;
            }
        }
        spec
    }
}

fn bad(field: &'static str, value: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

impl Job {
    /// Checks `[specimens]`: the ranges, and that varying specimens have DEM materials with a
    /// `random` packing (its seed and confining stress are what varies), without `accuracy`.
    pub(crate) fn validate_specimens(&self) -> Result<()> {
        let s = &self.specimens;
        if s.count == SpecimenCount::Count(0) {
            return Err(bad("specimens.count", "0", "must be >= 1 or \"per_point\""));
        }
        if !(s.poisson > -1.0 && s.poisson < 0.5) {
            return Err(bad(
                "specimens.poisson",
                format!("{:?}", s.poisson),
                "must be in (-1, 0.5)",
            ));
        }
        if !(s.level_ratio.is_finite() && s.level_ratio > 1.0) {
            return Err(bad(
                "specimens.level_ratio",
                format!("{:?}", s.level_ratio),
                "must be finite and > 1 (the ratio between consecutive levels)",
            ));
        }
        if !(s.min_stress.is_finite() && s.min_stress > 0.0) {
            return Err(bad(
                "specimens.min_stress",
                format!("{:?}", s.min_stress),
                "must be finite and > 0 (Pa)",
            ));
        }
        if s.is_default() {
            return Ok(());
        }
        if let Some(a) = self.accuracy {
            return Err(bad(
                "accuracy",
                format!("{a:?}"),
                "an accuracy target plans one assembly for every point; [specimens] varies them",
            ));
        }
        if !s.varies() {
            return Ok(());
        }
        let what = match s.count {
            SpecimenCount::Count(k) if k > 1 => format!("specimens.count = {k}"),
            SpecimenCount::PerPoint => "specimens.count = \"per_point\"".to_string(),
            SpecimenCount::Count(_) => "specimens.consolidation = \"in_situ\"".to_string(),
        };
        let mut dem = false;
        for (i, m) in self.materials().into_iter().enumerate() {
            let MaterialSection::Dem { assembly } = m else { continue };
            dem = true;
            if matches!(assembly.packing, PackingSpec::Random { .. }) {
                continue;
            }
            let kind = assembly.packing.kind();
            let prefix = if i == 0 { String::new() } else { format!("region[{}].", i - 1) };
            return Err(bad(
                interned(format!("{prefix}material.assembly.packing")),
                kind,
                format!(
                    "{what} needs a `random` packing: each specimen is the packing with its own \
                     seed (seed + k) and confining stress"
                ),
            ));
        }
        if !dem {
            return Err(bad(
                "specimens",
                what,
                "needs a material of kind = \"dem\" (an elastic material has no specimens)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{Consolidation, SpecimenCount, SpecimensSection};
    use crate::{Job, fixtures};

    fn with(count: SpecimenCount, seed: u64) -> SpecimensSection {
        SpecimensSection { count, seed, ..SpecimensSection::default() }
    }

    /// The specimens of 4 points in each of 100 elements, flat index `4 e + p`.
    fn assignment(s: &SpecimensSection) -> Vec<u64> {
        (0..100u32)
            .flat_map(|e| (0..4u32).map(move |p| (e, p)))
            .map(|(e, p)| s.specimen_of(400, e, p, (4 * e + p) as usize))
            .collect()
    }

    /// The hash spreads 400 points (4 per element, 100 elements) over K = 4 near-uniformly,
    /// for several seeds: each specimen gets 60 to 140 points. An ideal random assignment gives
    /// binomial counts of mean 100 and standard deviation sqrt(400 * 1/4 * 3/4) = 8.7, so the
    /// band is +-4.6 standard deviations: a well-mixing hash passes, one that piles points on
    /// a few specimens fails. A patterned assignment (`element % 4`) would pass the counts, so
    /// the test also checks that few elements have all 4 points on one specimen.
    #[test]
    fn the_hash_spreads_points_near_uniformly() {
        for seed in [0, 1, 42, u64::MAX] {
            let a = assignment(&with(SpecimenCount::Count(4), seed));
            for k in 0..4 {
                let n = a.iter().filter(|&&s| s == k).count();
                assert!((60..=140).contains(&n), "seed {seed}: specimen {k} has {n} points");
            }
            // Not constant per element: with 4 points over 4 specimens, an element's points all
            // alike happens with probability 4 / 4^4 = 1/64, so in about 1.6 of 100 elements.
            let alike = a.chunks(4).filter(|c| c.iter().all(|&s| s == c[0])).count();
            assert!(alike < 10, "seed {seed}: {alike} elements with one specimen");
        }
    }

    /// The same seed gives the same assignment; another seed another one (about 3/4 of the
    /// points change for K = 4: at least half of them is asked).
    #[test]
    fn the_seed_decides_the_assignment() {
        let a = assignment(&with(SpecimenCount::Count(4), 7));
        assert_eq!(a, assignment(&with(SpecimenCount::Count(4), 7)));
        let b = assignment(&with(SpecimenCount::Count(4), 8));
        let changed = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        assert!(changed > 200, "{changed} of 400 points changed specimen");
        // One specimen: everything is specimen 0.
        assert!(assignment(&with(SpecimenCount::Count(1), 3)).iter().all(|&s| s == 0));
    }

    /// `per_point` gives every point its own specimen: its flat index.
    #[test]
    fn per_point_gives_distinct_specimens() {
        let a = assignment(&with(SpecimenCount::PerPoint, 5));
        assert_eq!(a, (0..400).collect::<Vec<u64>>());
    }

    /// The ladder is 1e4, 1.5e4, 2.25e4, ... (exact in f64 for these), stresses at or below
    /// `min_stress` get `min_stress`, and rounding is in log scale: 1.23e4 is nearer 1e4 than
    /// 1.5e4 in Pa but above their geometric mean 1.2247e4, so it goes up; 1.22e4 goes down.
    #[test]
    fn levels_form_a_geometric_ladder_rounded_in_log_scale() {
        let s = SpecimensSection::default();
        assert_eq!(s.level_of(1e4), 1e4);
        assert_eq!(s.level_of(1.5e4), 1.5e4);
        assert_eq!(s.level_of(2.25e4), 2.25e4);
        assert_eq!(s.level_of(3.375e4), 3.375e4);
        assert_eq!(s.level_of(1e3), 1e4);
        assert_eq!(s.level_of(-5.0), 1e4);
        assert_eq!(s.level_of(f64::NAN), 1e4);
        assert_eq!(s.level_of(1.23e4), 1.5e4);
        assert_eq!(s.level_of(1.22e4), 1e4);
        // Within a factor sqrt(1.5) (22 %) of the stress, over a wide range.
        for i in 0..200 {
            let p = 1e4 * 1.05f64.powi(i);
            let r = s.level_of(p) / p;
            assert!(r <= 1.5f64.sqrt() * (1.0 + 1e-12) && r >= 1.0 / 1.5f64.sqrt() / (1.0 + 1e-12));
        }
    }

    /// Specimen k's packing seed is the packing's seed + k (wrapping), its confining stress the
    /// level when given; a hexagonal packing is returned unchanged.
    #[test]
    fn a_specimen_is_the_packing_with_its_seed_and_stress() {
        use cosdem_dem::AssemblySpec;
        use cosdem_dem::spec::PackingSpec;
        let random = PackingSpec::Random {
            r_min: 0.004,
            r_max: 0.006,
            radii: Vec::new(),
            side: 0.1,
            seed: u64::MAX,
            confining_stress: 1e5,
        };
        let base = AssemblySpec { packing: random, ..AssemblySpec::default() };
        let s = SpecimensSection::default();
        let PackingSpec::Random { seed, confining_stress, .. } =
            s.assembly_of(&base, 2, Some(3e4)).packing
        else {
            panic!()
        };
        assert_eq!((seed, confining_stress), (1, 3e4));
        let hex = AssemblySpec::default();
        assert_eq!(s.assembly_of(&hex, 3, Some(3e4)), hex);
    }

    /// A DEM job with `[specimens]` appended.
    fn dem_with(specimens: &str, packing: &str) -> String {
        let text = fixtures::text("dem-one-element")
            .replace("{ kind = \"hexagonal\", radius = 0.005, side = 0.1 }", packing);
        format!("{text}\n[specimens]\n{specimens}\n")
    }

    const RANDOM: &str = "{ kind = \"random\", r_min = 0.004, r_max = 0.006, side = 0.1, seed = 1, confining_stress = 1e5 }";
    const HEX: &str = "{ kind = \"hexagonal\", radius = 0.005, side = 0.1 }";

    /// Out-of-range values, a non-random packing with varying specimens, and `accuracy` are
    /// refused naming the key and the value; the valid forms read.
    #[test]
    fn bad_specimens_are_refused_naming_the_key() {
        let job = Job::from_toml(&dem_with("count = 4\nseed = 9", RANDOM), "j").unwrap();
        assert_eq!(job.specimens.count, SpecimenCount::Count(4));
        assert_eq!(job.specimens.seed, 9);
        let job = Job::from_toml(
            &dem_with("count = \"per_point\"\nconsolidation = \"in_situ\"", RANDOM),
            "j",
        )
        .unwrap();
        assert_eq!(job.specimens.count, SpecimenCount::PerPoint);
        assert_eq!(job.specimens.consolidation, Consolidation::InSitu);
        // One specimen on a hexagonal packing is the job as before.
        Job::from_toml(&dem_with("count = 1\nseed = 3", HEX), "j").unwrap();
        for (specimens, packing, key, value) in [
            ("count = 0", RANDOM, "specimens.count", "0"),
            ("count = -2", RANDOM, "specimens.count", "-2"),
            ("count = \"each\"", RANDOM, "specimens.count", "each"),
            ("poisson = 0.5", RANDOM, "specimens.poisson", "0.5"),
            ("poisson = -1.0", RANDOM, "specimens.poisson", "-1.0"),
            ("level_ratio = 1.0", RANDOM, "specimens.level_ratio", "1.0"),
            ("level_ratio = inf", RANDOM, "specimens.level_ratio", "inf"),
            ("min_stress = 0.0", RANDOM, "specimens.min_stress", "0.0"),
            ("min_stress = nan", RANDOM, "specimens.min_stress", "NaN"),
            ("count = 2", HEX, "material.assembly.packing", "hexagonal"),
            ("consolidation = \"in_situ\"", HEX, "material.assembly.packing", "in_situ"),
            ("count = \"per_point\"", HEX, "material.assembly.packing", "per_point"),
            ("zz = 1", RANDOM, "zz", ""),
        ] {
            let err = Job::from_toml(&dem_with(specimens, packing), "j").unwrap_err().to_string();
            assert!(err.contains(key) && err.contains(value), "{specimens}: {err}");
        }
        let err =
            Job::from_toml(&format!("accuracy = 0.05\n{}", dem_with("count = 2", RANDOM)), "j")
                .unwrap_err()
                .to_string();
        assert!(err.contains("accuracy") && err.contains("specimens"), "{err}");
        let elastic = format!("{}\n[specimens]\ncount = 3\n", fixtures::text("elastic-panel"));
        let err = Job::from_toml(&elastic, "j").unwrap_err().to_string();
        assert!(err.contains("specimens") && err.contains("dem"), "{err}");
    }

    /// A job without `[specimens]` writes none (its serialization, and so its digest, is as
    /// before), and a job with one reads back the same.
    #[test]
    fn the_default_section_is_not_written() {
        let job = fixtures::load("dem-one-element");
        assert!(job.specimens.is_default());
        assert!(!toml::to_string(&job).unwrap().contains("specimens"));
        let job = Job::from_toml(&dem_with("count = \"per_point\"\nmin_stress = 2e4", RANDOM), "j")
            .unwrap();
        let text = toml::to_string(&job).unwrap();
        assert_eq!(Job::from_toml(&text, "j").unwrap(), job, "{text}");
    }
}
