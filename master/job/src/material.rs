//! Reading `[material]`: the table as one plain struct whose tag `kind` is a field, turned
//! into the [`MaterialSection`] enum afterwards.
//!
//! serde reads an internally tagged enum (`#[serde(tag = "kind")]`) by buffering the whole
//! table before it knows the variant, and the buffer has no TOML positions: every error inside
//! `[material]`, down to a misspelt key in `[material.assembly]`'s inline tables, then pointed
//! at the `[material]` line. A struct is read straight from the TOML document, so the error of
//! a key deep in `[material.assembly]` points at that key's line.

use crate::schema::MaterialSection;
use cosdem_dem::AssemblySpec;
use serde::Deserialize;

/// `kind` of `[material]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Kind {
    /// [`MaterialSection::Elastic`].
    Elastic,
    /// [`MaterialSection::Dem`].
    Dem,
}

/// Every key `[material]` may hold, whatever its kind; [`MaterialSection`]'s `TryFrom` checks
/// that the keys given belong to the kind.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    kind: Kind,
    shear_modulus: Option<f64>,
    poisson: Option<f64>,
    cosserat_modulus: Option<f64>,
    length: Option<f64>,
    assembly: Option<Box<AssemblySpec>>,
}

/// The keys of `kind = "elastic"`, and of `kind = "dem"`.
const ELASTIC: &str = "`shear_modulus`, `poisson`, `cosserat_modulus`, `length`";
const DEM: &str = "`assembly`";

impl TryFrom<RawMaterial> for MaterialSection {
    type Error = String;

    fn try_from(m: RawMaterial) -> Result<Self, String> {
        let missing = |key: &str, kind: &str| format!("missing field `{key}` (kind = \"{kind}\")");
        let foreign = |key: &str, kind: &str, keys: &str| {
            format!("unknown field `{key}` for kind = \"{kind}\", expected one of `kind`, {keys}")
        };
        match m.kind {
            Kind::Elastic => {
                if m.assembly.is_some() {
                    return Err(foreign("assembly", "elastic", ELASTIC));
                }
                Ok(MaterialSection::Elastic {
                    shear_modulus: m
                        .shear_modulus
                        .ok_or_else(|| missing("shear_modulus", "elastic"))?,
                    poisson: m.poisson.ok_or_else(|| missing("poisson", "elastic"))?,
                    cosserat_modulus: m.cosserat_modulus,
                    length: m.length,
                })
            }
            Kind::Dem => {
                for (key, given) in [
                    ("shear_modulus", m.shear_modulus.is_some()),
                    ("poisson", m.poisson.is_some()),
                    ("cosserat_modulus", m.cosserat_modulus.is_some()),
                    ("length", m.length.is_some()),
                ] {
                    if given {
                        return Err(foreign(key, "dem", DEM));
                    }
                }
                Ok(MaterialSection::Dem {
                    assembly: m.assembly.ok_or_else(|| missing("assembly", "dem"))?,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Job, MaterialSection, fixtures};

    /// The line of the first line of `text` that starts with `start`.
    fn line_of(text: &str, start: &str) -> usize {
        1 + text.lines().position(|l| l.starts_with(start)).unwrap()
    }

    /// An error in one of `[material.assembly]`'s inline tables points at that table's line
    /// and names the key (it pointed at the `[material]` line: serde buffered the tagged
    /// enum's table and lost the positions). In a tagged table of the DEM spec (`contact.normal`
    /// is tagged by `model`), the error points at the table's own header.
    #[test]
    fn errors_inside_the_assembly_point_at_the_offending_line() {
        let base = fixtures::text("dem-one-element");
        let tangent = "tangent = { kind = \"perturbation\", strian = 1e-5 }";
        let density = "density = \"heavy\"";
        let normal = "[material.assembly.contact.normal]\nmodel = \"linear\"\nk_m = 1.0";
        for (added, key) in [
            (tangent, "strian"),
            ("packing2 = 1", "packing2"),
            (density, "density"),
            (normal, "k_m"),
        ] {
            let text = format!("{base}\n{added}\n");
            let line = line_of(&text, added.lines().next().unwrap());
            let err = Job::from_toml(&text, "j.toml").unwrap_err().to_string();
            assert!(err.contains(&format!("line {line},")), "{added}: line {line}: {err}");
            assert!(err.contains(key), "{added}: {err}");
        }
        let text = base.replace("side = 0.1 }", "side = 0.1, sidee = 2 }");
        let err = Job::from_toml(&text, "j.toml").unwrap_err().to_string();
        let line = line_of(&text, "packing");
        assert!(err.contains(&format!("line {line},")) && err.contains("sidee"), "{err}");
    }

    /// The keys of one kind are refused for the other, and each kind's required keys are
    /// required, naming the key.
    #[test]
    fn each_kind_takes_its_own_keys() {
        let dem = fixtures::text("dem-one-element");
        let elastic = fixtures::text("elastic-panel");
        assert!(matches!(fixtures::load("dem-one-element").material, MaterialSection::Dem { .. }));
        for (text, key) in [
            (dem.replace("kind = \"dem\"", "kind = \"dem\"\npoisson = 0.3"), "poisson"),
            (dem.replace("[material.assembly]\npacking", "[material.zz]\npacking"), "zz"),
            (dem.replace("[material.assembly]\npacking = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }", ""), "assembly"),
            (elastic.replace("poisson = 0.3", ""), "poisson"),
            (elastic.replace("shear_modulus = 1e7", "shear_modulus = 1e7\nassembly = {}"), "assembly"),
            (elastic.replace("kind = \"elastic\"", "kind = \"plastic\""), "plastic"),
        ] {
            let err = Job::from_toml(&text, "j.toml").unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{key}: {err}");
        }
    }

    /// A job written back as TOML (the CLI's tests do) reads as the same job, both kinds.
    #[test]
    fn a_job_written_out_reads_back_the_same() {
        for name in ["dem-one-element", "elastic-panel", "elastic-panel-confined"] {
            let job = fixtures::load(name);
            let text = toml::to_string(&job).unwrap();
            assert_eq!(Job::from_toml(&text, name).unwrap(), job, "{name}:\n{text}");
        }
    }
}
