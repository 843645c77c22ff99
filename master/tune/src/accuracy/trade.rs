//! The measured trade: a sweep's rows (the tight reference, the default settings and the
//! one-knob moves) as the planner's model, with the committed tables it is made from
//! (`master/tune/data/`, see its `README.md`: re-measuring a table there changes what an
//! `accuracy` target picks).

use super::{AccuracyError, PropertyErrors, packing_kind};
use crate::table::{Row, finished, read_csv};
use cosdem_dem::AssemblySpec;
use cosdem_dem::spec::PackingSpec;

/// The measured sweep the choice is made from (scene A, V = 0.01 m^2, to 0.03 m).
pub const TABLE: &str = include_str!("../../data/tradeoff-scene-a.csv");

/// The packing kind of [`TABLE`]'s assemblies. A trade does not carry over to another kind:
/// hexagonal crystals hardly feel the load step (0.1-0.3 % at x4 in [`TABLE`]) while random
/// assemblies remember their path (7 % at x4 in [`RANDOM_TABLE`]).
pub const TABLE_PACKING: &str = "hexagonal";

/// Where [`TABLE`] lives in the repository (named in reports).
pub const TABLE_NAME: &str = "master/tune/data/tradeoff-scene-a.csv";

/// The measured sweep for random assemblies: the biaxial example (32 periodic 400-disc
/// random assemblies, 100 kPa) to 1 % axial strain, before its peak, measured with the
/// specimen fixed across the knobs (before that rule the knobs changed the specimen and the
/// table measured specimen scatter: 13-15 % on the test scene). The whole example past its
/// peak, to 5 % (`docs/notes/tradeoff-biaxial-5mm.csv`, every other row's F_res 11-26 % above the
/// reference's, mid-softening) and to its plateau at 10 % (`docs/notes/tradeoff-biaxial-10mm.csv`,
/// 3.2-8.5 % above it, in no order of cost), has F_res but no trend to plan it from: like
/// scene A's post-peak table, a measurement, not a model.
/// The secant tangent is not in this table: it halves the Newton iterations to 1 % strain
/// but stalls from 1.8 % on (20 iterations per step), so it is never picked.
pub const RANDOM_TABLE: &str = include_str!("../../data/tradeoff-biaxial-1mm.csv");

/// Where [`RANDOM_TABLE`] lives in the repository.
pub const RANDOM_TABLE_NAME: &str = "master/tune/data/tradeoff-biaxial-1mm.csv";

/// The measured trade: the sweep's reference, default and one-knob rows.
#[derive(Clone, Debug)]
pub struct Trade {
    /// Where the rows come from.
    pub table: String,
    /// The packing kind of its assemblies (`hexagonal`, `random`): it speaks for those only.
    pub packing: String,
    /// The tight reference run.
    pub reference: Row,
    /// The job as given (the table's default settings).
    pub default: Row,
    /// Every other row.
    pub settings: Vec<Row>,
    /// The default row's knobs: `None` for a committed table, whose default row ran the
    /// worker's defaults (a plan resets the job's knobs to them first); `Some` for a sweep of
    /// the very job being planned ([`Trade::from_rows`]), whose default row ran the job as
    /// given (its tangent, say the perturbation tangent past a peak).
    pub base: Option<AssemblySpec>,
}

impl Trade {
    /// The committed sweep [`TABLE`] (hexagonal assemblies).
    pub fn measured() -> Result<Self, AccuracyError> {
        Self::from_csv(TABLE, TABLE_NAME)
    }

    /// The committed sweep for assemblies of `packing` (`hexagonal`: [`TABLE`], `random`:
    /// [`RANDOM_TABLE`]).
    pub fn for_packing(packing: &PackingSpec) -> Result<Self, AccuracyError> {
        match packing {
            // An explicit packing has no table of its own: its kind differs from this one's,
            // so the plan falls back to the reference settings.
            PackingSpec::Hexagonal { .. }
            | PackingSpec::Explicit { .. }
            | PackingSpec::File { .. } => Self::measured(),
            PackingSpec::Random { .. } => {
                let mut t = Self::from_csv(RANDOM_TABLE, RANDOM_TABLE_NAME)?;
                t.packing = packing_kind(packing).into();
                Ok(t)
            }
        }
    }

    /// A sweep's CSV (`tradeoff.csv`) of hexagonal assemblies (set [`Trade::packing`] for
    /// another kind).
    pub fn from_csv(text: &str, name: &str) -> Result<Self, AccuracyError> {
        Self::from_rows(read_csv(text, name)?, name, TABLE_PACKING, None)
    }

    /// The trade of a sweep's rows (`name` for reports) of `packing` assemblies; `base`: see
    /// [`Trade::base`].
    pub fn from_rows(
        rows: Vec<Row>,
        name: &str,
        packing: &str,
        base: Option<AssemblySpec>,
    ) -> Result<Self, AccuracyError> {
        let model = |message: &str| AccuracyError::Model {
            table: name.to_string(),
            message: message.to_string(),
        };
        let take = |knob: &str| rows.iter().find(|r| r.knob == knob).cloned();
        let reference = take("reference").ok_or_else(|| model("no reference row"))?;
        let default = take("default").ok_or_else(|| model("no default row"))?;
        if !finished(&reference) || !finished(&default) {
            return Err(model("the reference or the default run did not finish"));
        }
        let usable = reference.metrics.peak_load.abs() > 0.0 && default.dem_steps > 0;
        if !usable {
            return Err(model("the reference has no F_u or the default no DEM steps"));
        }
        let settings =
            rows.into_iter().filter(|r| r.knob != "reference" && r.knob != "default").collect();
        Ok(Self {
            table: name.to_string(),
            packing: packing.to_string(),
            reference,
            default,
            settings,
            base,
        })
    }

    /// The default's own error against the reference (the table's error columns).
    pub fn default_error(&self) -> PropertyErrors {
        let e = &self.default.errors;
        PropertyErrors { peak: e.peak, residual: e.residual, stiffness: e.stiffness }
    }

    /// The shift of `row` from the default, relative to the reference: `|x - x_def| /
    /// |x_ref|` per property (`None` where either run or the reference lacks the value). The
    /// table prints values to 7 significant digits, so a shift is known to about 1e-6.
    pub fn shift(&self, row: &Row) -> PropertyErrors {
        let (r, a, b) = (&self.reference.metrics, &self.default.metrics, &row.metrics);
        let rel = |x: Option<f64>, y: Option<f64>, r: Option<f64>| match (x, y, r) {
            (Some(x), Some(y), Some(r)) if r != 0.0 => Some((y - x).abs() / r.abs()),
            _ => None,
        };
        PropertyErrors {
            peak: rel(Some(a.peak_load), Some(b.peak_load), Some(r.peak_load)),
            residual: rel(a.residual_load, b.residual_load, r.residual_load),
            stiffness: rel(a.stiffness, b.stiffness, r.stiffness),
        }
    }

    /// DEM steps of `row` over the default's.
    pub fn cost_ratio(&self, row: &Row) -> f64 {
        row.dem_steps as f64 / self.default.dem_steps as f64
    }
}
