//! What a plan picked and why: one [`KnobChoice`] per planned knob and the [`Report`],
//! printed at the start of a run and written to `RUN/accuracy.json` ([`FILE`]).

use super::PropertyErrors;
use super::size::SizeReport;
use serde::Serialize;

/// One knob of the plan.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KnobChoice {
    /// The knob (the sweep's name).
    pub knob: String,
    /// What the job file said.
    pub was: String,
    /// What the run uses: a measured setting, or the table's default value.
    pub picked: String,
    /// The row of the table the choice rests on (`knob=setting`), `None` for the default.
    pub row: Option<String>,
    /// Predicted added error (the shift from the default; 0 for the default).
    pub shift: PropertyErrors,
    /// Predicted DEM steps over the default's (1 for the default).
    pub dem_steps_ratio: f64,
    /// Why, in words.
    pub why: String,
}

/// What an accuracy target picked and why (also `RUN/accuracy.json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The job's `accuracy` (fraction).
    pub target: f64,
    /// [`MARGIN`](super::MARGIN).
    pub margin: f64,
    /// `margin * target`: what the predicted error must stay within.
    pub budget: f64,
    /// The measured table.
    pub table: String,
    /// The table's default against its reference.
    pub default_error: PropertyErrors,
    /// Predicted error of the picked settings: `default_error + sum of the shifts`.
    pub predicted: PropertyErrors,
    /// Predicted DEM steps over those of the table's default settings.
    pub predicted_dem_steps_ratio: f64,
    /// One entry per knob of [`Knob::PLANNED`](crate::knob::Knob::PLANNED), in its order.
    pub knobs: Vec<KnobChoice>,
    /// Measured settings that were not candidates, with why.
    pub not_candidates: Vec<String>,
    /// The size law's view of the job's assembly size.
    pub size: SizeReport,
    /// Caveats of the prediction and warnings (the target may not be met).
    pub warnings: Vec<String>,
    /// True when the table does not apply to the job (another packing kind) and the tight
    /// reference settings are used instead.
    pub fallback_to_reference: bool,
}

impl Report {
    /// The report in words, one line each (for the log and the terminal).
    pub fn lines(&self) -> Vec<String> {
        let mut l = vec![format!(
            "accuracy target {:.3} % on F_u, F_res, E: predicted error must stay within {:.3} % \
             (margin {}), from {}",
            100.0 * self.target,
            100.0 * self.budget,
            self.margin,
            self.table
        )];
        for k in &self.knobs {
            l.push(format!("  {}: {} -> {} ({})", k.knob, k.was, k.picked, k.why));
        }
        l.push(format!(
            "  predicted: {} (default settings alone: {}); DEM steps x{:.3} of the default \
             settings",
            self.predicted.describe("not measured"),
            self.default_error.describe("not measured"),
            self.predicted_dem_steps_ratio
        ));
        l.push(format!("  assembly size: {}", self.size.note));
        l.extend(self.warnings.iter().map(|w| format!("  warning: {w}")));
        l
    }

    /// The text of `RUN/accuracy.json` ([`FILE`]): pretty JSON ending in a newline.
    pub fn to_json(&self) -> String {
        let json = serde_json::to_string_pretty(self).expect("a report is plain data");
        format!("{json}\n")
    }
}

/// The report's file name in the run directory.
pub const FILE: &str = "accuracy.json";

/// A fraction as a percentage with 3 decimals, `-` when missing.
pub(crate) fn pct(e: Option<f64>) -> String {
    e.map_or("-".into(), |e| format!("{:.3} %", 100.0 * e))
}
