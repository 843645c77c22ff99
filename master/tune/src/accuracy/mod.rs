//! Accuracy target: `accuracy = 0.05` in a job picks the cheapest speed settings that the measured
//! speed/accuracy trade predicts to stay within 5 % on F_u, F_res and E, and says what it picked
//! and why.
//!
//! # The measured trade
//! The model is data ([`trade`](crate::accuracy::trade)): the committed sweep
//! `master/tune/data/tradeoff-scene-a.csv` (`cosdem bench tradeoff`, scene A at V = 0.01 m^2 to
//! 0.03 m, pre-peak; `data/README.md` says how each committed table was made), embedded with
//! `include_str!` and read by [`crate::table::read_csv`]. Its "default" row is the job's own
//! settings (the worker's defaults: relaxation tolerance 1e-4, time-step safety 0.8, no mass
//! scaling, Cundall damping, paper tangent, cold starts) and every other row moves one knob.
//!
//! # The prediction, and why it is conservative (and where it is not)
//! For each property `p` (F_u, F_res, E) the table gives the default's error against the reference,
//! `e_def`, and each setting's shift from the default, `s_k = |x_k - x_def| / |x_ref|`. A
//! combination of settings is predicted to be off by at most `e_def + sum_k s_k`. If the knobs'
//! effects add (first order, independent knobs), the combined value is `x_def + sum_k (x_k -
//! x_def)`, and the triangle inequality bounds its distance from the reference by exactly that sum:
//! effects of opposite sign that cancel are counted as adding. It is NOT an upper bound when knobs
//! interact (two settings harmless alone can together destabilise a relaxation, e.g. a large time
//! step with FIRE's step growth), when the scene differs from the table's (post-peak the errors are
//! larger: in `docs/notes/tradeoff-scene-a-0.06.md` the default alone is 9 % off on F_u), and it
//! says nothing of the reference's own distance from the converged answer. Hence the margin: the
//! prediction must stay within [`MARGIN`](crate::accuracy::MARGIN) times the target. The table's
//! scene never passed its peak, so it measured no F_res: F_res's error is reported as not measured,
//! not guessed.
//!
//! # The choice
//! Cost is the table's DEM steps (deterministic and machine-independent; the table's wall times
//! were taken on a shared machine and move by tens of percent between repeats). A setting is a
//! candidate only if its run finished (`relaxation.safety = 0.95` failed on scene A), is no
//! time-step safety above [`MAX_SAFETY`](crate::accuracy::MAX_SAFETY), it saved at least
//! [`MIN_SAVING`](crate::accuracy::MIN_SAVING) of the default's DEM steps (mass scaling and the
//! sliding-aware tangent saved none), and the table measured its shift on every property the
//! default has. Every combination of candidates (at most one setting per knob) is scored by the
//! product of the settings' DEM-step ratios to the default, and the cheapest one whose prediction
//! fits is picked (ties: the smaller predicted error). Knobs that all set the relaxation's time
//! step (safety, driver, mass scaling: [`Knob::sets_time_step`](crate::knob::Knob::sets_time_step))
//! are not moved together: the table measured each alone, and together their effects multiply. The
//! search is in [`choice`](crate::accuracy::choice).
//!
//! # Which jobs a table speaks for
//! Each table speaks for assemblies of its packing kind: [`TABLE`](crate::accuracy::TABLE) (scene
//! A) for hexagonal ones, [`RANDOM_TABLE`](crate::accuracy::RANDOM_TABLE) (the biaxial example) for
//! random ones ([`Trade::for_packing`](crate::accuracy::Trade::for_packing)). A job is never
//! planned from a table of another kind: it then runs with the tight reference settings, with a
//! warning. No table speaks for F_res: the post-peak sweep
//! (`docs/notes/tradeoff-scene-a-post-peak.md`, scene A to 0.12 m) found the collapse itself
//! unconverged in the load step (the default 435 % off the tight reference on F_res, load step x4
//! 85x, the reference failing at 0.1166 m), and so did the whole biaxial example to 5 %,
//! mid-softening (`docs/notes/tradeoff-biaxial-5mm.md`: the tight reference's F_res 13 % below the
//! default's, the load step moving it without a trend). On its residual plateau at 10 %
//! (`docs/notes/tradeoff-biaxial-10mm.md`) every row is within 3.2-8.5 % of the reference, cheaper
//! rows closer than the default: scatter of the plateau minimum, no knob's trend to plan from.
//! Averaged over three specimens (`docs/notes/tradeoff-biaxial-10mm-specimens.md`) the scatter has
//! a size (the default's paired differences: 5 % standard deviation) and the load step a bias (+3-7
//! % for every row at the job's step), but the knobs' own effects on F_res stay within two standard
//! errors. That bias is the load step's (`docs/notes/load-step-biaxial.md`: at half the job's step,
//! with the job's relaxation, the three specimens are within 2.6 % of the reference on F_res), and
//! a plan only ever saves steps (a candidate must save
//! [`MIN_SAVING`](crate::accuracy::MIN_SAVING)), never halves the load step. So a plan predicts F_u
//! and E and warns that F_res is not covered.
//!
//! # What it takes over, and the assembly size
//! With `accuracy`, the knobs of [`Knob::PLANNED`](crate::knob::Knob::PLANNED) are set by the
//! choice (to a measured setting or to the table's default value): what the job file said for them
//! is replaced and listed in the report ([`report`](crate::accuracy::report)). The load step is
//! relative (`x4`: four times the job's). Other relaxation keys (`max_steps`, `skin`, `substep`,
//! ...) stay as written. The assembly size is never changed: the side is a physical choice of the
//! user (the RVE), and a smaller one shifts every property (27 % at half the side in the table).
//! The size law of Eqs. 30-32 ([`size`](crate::accuracy::size)), where a committed study fit
//! matches the job's assembly ([`SIZE_FITS`](crate::accuracy::SIZE_FITS)), predicts the size error
//! `|F(V) / F^cr - 1|` of the job's V; it is reported, with a warning when it alone exceeds the
//! target, and is not part of the promise (which is against a tight run of the same V).

/// The search: candidates per knob, every allowed combination, the cheapest that fits.
pub mod choice;
/// What a plan picked and why, in words and as `RUN/accuracy.json`.
pub mod report;
/// The size law of Eqs. 30-32: committed RVE-size study fits and the size error of a job's V.
pub mod size;
/// The measured trade: a sweep's rows as the planner's model (the committed tables).
pub mod trade;

#[cfg(test)]
mod tests;

pub use report::{FILE, KnobChoice, Report};
pub use size::{LawParams, SIZE_FITS, SizeFit, SizeReport, size_fits};
pub use trade::{RANDOM_TABLE, RANDOM_TABLE_NAME, TABLE, TABLE_NAME, TABLE_PACKING, Trade};

use crate::table::TableError;
use cosdem_dem::spec::PackingSpec;
use cosdem_job::{Job, MaterialSection};
use serde::{Deserialize, Serialize};

/// The predicted combined error must stay within this fraction of the target (the rest is
/// left for what the prediction does not cover: other scenes, interactions of knobs).
pub const MARGIN: f64 = 0.5;

/// A setting must save at least this fraction of the default's DEM steps to be a candidate.
pub const MIN_SAVING: f64 = 0.05;

/// The largest time-step safety factor ever picked. The critical step is a bound computed
/// for the stiffest oscillator of the reference state; how close to it a relaxation stays
/// stable depends on the scene: safety 0.95 failed on scene A's table, finished on the
/// biaxial sweep, and on the random accuracy test scene (penalty boundary) ran through
/// tolerated steps 26 % off. 0.8 was stable on all three.
pub const MAX_SAFETY: f64 = 0.8;

/// Why no plan could be made.
#[derive(Debug, thiserror::Error)]
pub enum AccuracyError {
    /// The embedded table is unreadable or a setting in it unknown.
    #[error("accuracy: {0}")]
    Table(#[from] TableError),
    /// The table lacks its reference or default row, or the reference has no value to
    /// compare with.
    #[error("accuracy: the measured table {table}: {message}")]
    Model {
        /// The table.
        table: String,
        /// What is missing.
        message: String,
    },
    /// A committed size fit is unreadable.
    #[error("accuracy: size fit {name}: {message}")]
    SizeFit {
        /// The fit's name.
        name: String,
        /// The JSON error.
        message: String,
    },
    /// The tuned job is invalid (a bug: every setting comes from the sweep).
    #[error(transparent)]
    Job(#[from] cosdem_fem::Error),
}

/// Relative errors (fractions) of F_u, F_res and E; `None`: not measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PropertyErrors {
    /// F_u.
    pub peak: Option<f64>,
    /// F_res.
    pub residual: Option<f64>,
    /// E.
    pub stiffness: Option<f64>,
}

impl PropertyErrors {
    /// The largest of the measured ones (0 when none is).
    pub fn worst(&self) -> f64 {
        [self.peak, self.residual, self.stiffness].into_iter().flatten().fold(0.0, f64::max)
    }

    pub(crate) fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let z = |a: Option<f64>, b: Option<f64>| a.zip(b).map(|(a, b)| f(a, b));
        Self {
            peak: z(self.peak, o.peak),
            residual: z(self.residual, o.residual),
            stiffness: z(self.stiffness, o.stiffness),
        }
    }

    /// In words; a missing value is `missing` (`not measured` for the table's errors, `not
    /// predicted` for the size law's).
    pub(crate) fn describe(&self, missing: &str) -> String {
        let f = |name: &str, e: Option<f64>| match e {
            Some(e) => format!("{name} {:.3} %", 100.0 * e),
            None => format!("{name} {missing}"),
        };
        format!(
            "{}, {}, {}",
            f("F_u", self.peak),
            f("E", self.stiffness),
            f("F_res", self.residual)
        )
    }
}

/// The tuned job and the report.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The job to run: the picked settings, `accuracy` removed (tuning it again would move
    /// the relative load step again).
    pub job: Job,
    /// What was picked and why.
    pub report: Report,
}

/// Knobs of rows that move several knobs at once (the sweep's checks of the prediction,
/// `cosdem_study::tradeoff::sweep`): never candidates themselves.
pub const COMBINATIONS: [&str; 2] = ["accuracy", "cheapest"];

/// The plan for `job` from the committed table and size fits; `None` when the job has no
/// `accuracy` (it then runs exactly as written).
pub fn tune(job: &Job) -> Result<Option<Plan>, AccuracyError> {
    if job.accuracy.is_none() {
        return Ok(None);
    }
    let trade = match &job.material {
        MaterialSection::Dem { assembly } => Trade::for_packing(&assembly.packing)?,
        MaterialSection::Elastic { .. } => Trade::measured()?,
    };
    plan(job, &trade, &size_fits()?)
}

/// The plan for `job` from `trade` and `fits` (see the module documentation); `None` when
/// the job has no `accuracy`. Pure: the same inputs give the same plan.
pub fn plan(job: &Job, trade: &Trade, fits: &[SizeFit]) -> Result<Option<Plan>, AccuracyError> {
    let Some(target) = job.accuracy else { return Ok(None) };
    choice::plan_within(job, trade, fits, target, MARGIN * target)
}

/// The cheapest combination of `trade`'s candidate settings for `job`, whatever its
/// predicted error (the sweep's "cheapest" row: where the measured knobs end); `None` for
/// a job without a DEM material or of another packing kind than `trade`'s.
pub fn cheapest(job: &Job, trade: &Trade) -> Result<Option<Plan>, AccuracyError> {
    let kind = match &job.material {
        MaterialSection::Dem { assembly } => packing_kind(&assembly.packing),
        MaterialSection::Elastic { .. } => return Ok(None),
    };
    if kind != trade.packing {
        return Ok(None);
    }
    choice::plan_within(job, trade, &[], f64::INFINITY, f64::INFINITY)
}

/// `hexagonal`, `random` or `explicit` (a packing file).
pub fn packing_kind(p: &PackingSpec) -> &'static str {
    p.kind()
}
