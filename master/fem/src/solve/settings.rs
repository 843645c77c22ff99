//! Newton-Raphson and step-control parameters, with their limits and checks.

use crate::error::{Error, Result};

/// Most nominal load steps of a run: a cap so that a tiny `increment` cannot ask for 10^300
/// steps (a hang). The paper's runs use tens to hundreds.
pub const MAX_LOAD_STEPS: usize = 1_000_000;

/// Smallest allowed `min_increment_fraction`: with at most [`MAX_LOAD_STEPS`] steps the
/// smallest increment stays above 1e-18, which the load factor (at most 1) can still resolve
/// to within a factor of 10, so a step cut to the minimum still moves the load.
pub const MIN_INCREMENT_FRACTION: f64 = 1e-12;

/// Newton-Raphson and step-control parameters.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverSettings {
    /// Nominal number of equal load steps from `lambda = 0` to 1.
    pub steps: usize,
    /// Newton iterations allowed per attempt before the step is cut.
    pub max_iterations: u32,
    /// Force criterion: `|r_free| <= force_tolerance * max(|f_int|, |f_ext|)`.
    pub force_tolerance: f64,
    /// Displacement criterion: `|du| <= displacement_tolerance * |u - u_n|` (the step's
    /// accumulated increment), `du` the full Newton correction of the last iteration, before
    /// any line-search halving (a damped update is no sign of convergence). Either criterion
    /// ends the iteration (the paper's section 3).
    pub displacement_tolerance: f64,
    /// Backtrack (halve the update) while the residual norm grows.
    pub line_search: bool,
    /// Halvings allowed per line search.
    pub max_line_search: u32,
    /// Smallest increment as a fraction of the nominal `1 / steps`; a step that still fails
    /// below it ends the run with [`Error::StepTooSmall`].
    pub min_increment_fraction: f64,
    /// A step converged within this many iterations lets the increment grow (so does a
    /// step that needed no cut of its own, whatever its iterations).
    pub easy_iterations: u32,
    /// Tolerated relative force residual (0: off). When an attempt uses up `max_iterations` and the
    /// smallest relative residual of its iterates is at or below this value, that iterate is
    /// accepted (evaluated again if it was not the last: its residual is then the step's last) as a
    /// *tolerated* step (reported in [`StepReport::tolerated`](super::StepReport::tolerated),
    /// counted in the summary) instead of cutting the step. Past the peak the DEM assemblies soften
    /// while the paper tangent stays elastic, so Newton converges slowly or stalls above the force
    /// tolerance; this is the engineering codes' "tolerated error" that lets a run reach the
    /// residual plateau with its imbalance shown.
    pub tolerated_residual: f64,
    /// Stall limit (0: off). An attempt whose smallest relative residual is already within
    /// `tolerated_residual` and has not fallen for this many iterations in a row ends there
    /// and accepts that best iterate as tolerated, without running to `max_iterations`.
    /// Past a peak the relaxed assemblies answer a move smaller than their slips with a
    /// residual that wanders around a floor instead of falling (the biaxial example: 84 of
    /// its 113 steps run to the cap at 0.5-5 %), and the iterations after the floor is
    /// reached mostly cost relaxations. An attempt whose best is above the tolerated
    /// residual iterates on: ending it early would cut steps that later iterations bring
    /// within it (tried on the biaxial example: it then failed at 6.85 mm).
    #[serde(default)]
    pub stall_iterations: u32,
    /// Forced residual (0: off). The attempt at the smallest increment (one more halving would go
    /// below `min_increment_fraction`) accepts its best iterate up to this relative residual
    /// instead of ending the run, as a *forced* step (tolerated too: reported in
    /// [`StepReport::forced`](super::StepReport::forced), counted in the summary, logged with its
    /// residual). Past a peak a relaxed assembly can answer moves of 1e-5 of a step with different
    /// slips, so the residual has a floor that no increment gets below (the biaxial example's seed
    /// 9: 6-16 % at 1/1024 of the step, the force residual's, with the iterations' rotation
    /// corrections of 2e-3 rad at every cut). The residual is the total one, so the next step
    /// starts by removing the imbalance this step leaves. Only steps that would otherwise end the
    /// run are changed: a run that finishes without it is the same bits.
    #[serde(default)]
    pub forced_residual: f64,
    /// Growth factor of the increment after an easy or uncut step (capped at the nominal
    /// increment).
    pub growth: f64,
    /// Gauss-point secant updates of the iteration matrix within a step
    /// ([`super::secant`]): every point's matrix, from the material's tangent at the step's
    /// start, is softened along each move of the point to the stiffness that move measured
    /// (a rank-one update), so that a soft mode converges as the secant method instead of a
    /// fixed-point iteration with the elastic slope. Off: the material's tangent of every
    /// answer.
    #[serde(default)]
    pub secant_updates: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            steps: 10,
            max_iterations: 25,
            force_tolerance: 1e-8,
            // Tight by default so that the force criterion decides on smooth problems; the
            // paper's looser displacement criterion is a job-file choice.
            displacement_tolerance: 1e-12,
            line_search: true,
            max_line_search: 5,
            // 1/1024: ten halvings of the nominal increment.
            min_increment_fraction: 1.0 / 1024.0,
            easy_iterations: 4,
            growth: 2.0,
            tolerated_residual: 0.0,
            secant_updates: false,
            stall_iterations: 0,
            forced_residual: 0.0,
        }
    }
}

impl SolverSettings {
    /// Number of nominal steps that moves a boundary by `total` in increments of at most
    /// `increment` (for jobs that give a displacement increment instead of a step count).
    pub fn steps_for_increment(total: f64, increment: f64) -> Result<usize> {
        if !(increment.abs() > 0.0 && increment.is_finite() && total.is_finite()) {
            return Err(Error::InvalidSetting {
                field: "loading.increment",
                value: format!("{increment:?}"),
                reason: format!("must be finite and non-zero (with a total of {total:?})"),
            });
        }
        let steps = ((total / increment).abs() - 1e-9).ceil().max(1.0);
        if steps.is_nan() || steps > MAX_LOAD_STEPS as f64 {
            return Err(Error::InvalidSetting {
                field: "loading.increment",
                value: format!("{increment:?}"),
                reason: format!(
                    "gives {steps:e} load steps for a total of {total:?}: more than MAX_LOAD_STEPS = \
                     {MAX_LOAD_STEPS}"
                ),
            });
        }
        Ok(steps as usize)
    }

    /// Checks every field; an error names the field as the job file's key (`newton.*`,
    /// `loading.steps`) and prints numbers with `{:?}`.
    pub(super) fn check(&self) -> Result<()> {
        let bad = |field: &'static str, value: String, reason: &str| {
            Err(Error::InvalidSetting { field, value, reason: reason.into() })
        };
        if self.steps == 0 || self.steps > MAX_LOAD_STEPS {
            return bad(
                "loading.steps",
                self.steps.to_string(),
                "must be in [1, MAX_LOAD_STEPS = 10^6]",
            );
        }
        if self.max_iterations == 0 {
            return bad("newton.max_iterations", "0".into(), "must be >= 1");
        }
        for (field, v) in [
            ("newton.force_tolerance", self.force_tolerance),
            ("newton.displacement_tolerance", self.displacement_tolerance),
        ] {
            if v.is_nan() || v < 0.0 {
                return bad(field, format!("{v:?}"), "must be >= 0");
            }
        }
        if !(self.min_increment_fraction >= MIN_INCREMENT_FRACTION
            && self.min_increment_fraction <= 1.0)
        {
            return bad(
                "newton.min_increment_fraction",
                format!("{:?}", self.min_increment_fraction),
                "must be in [1e-12, 1]",
            );
        }
        for (field, v) in [
            ("newton.tolerated_residual", self.tolerated_residual),
            ("newton.forced_residual", self.forced_residual),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("{v:?}"), "must be finite and >= 0");
            }
        }
        if self.growth.is_nan() || self.growth < 1.0 {
            return bad("growth", format!("{:?}", self.growth), "must be >= 1");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The errors name the job file's key and print numbers as `{:?}` does (`1e-300`, not 300
    /// zeros; the whole settings struct was printed for a bad tolerance).
    #[test]
    fn errors_name_the_key_and_print_numbers_readably() {
        let err = SolverSettings::steps_for_increment(1e308, 1e-300).unwrap_err().to_string();
        assert!(err.contains("loading.increment = 1e-300") && err.contains("1e308"), "{err}");
        assert!(err.len() < 200, "{err}");
        let err = SolverSettings::steps_for_increment(0.1, 0.0).unwrap_err().to_string();
        assert!(err.contains("loading.increment = 0.0"), "{err}");
        let check = |f: fn(&mut SolverSettings)| {
            let mut s = SolverSettings::default();
            f(&mut s);
            s.check().unwrap_err().to_string()
        };
        let err = check(|s| s.displacement_tolerance = -1e308);
        assert!(err.contains("newton.displacement_tolerance = -1e308"), "{err}");
        assert!(!err.contains("max_iterations"), "the whole settings printed: {err}");
        let err = check(|s| s.min_increment_fraction = 1e-300);
        assert!(err.contains("newton.min_increment_fraction = 1e-300"), "{err}");
        let err = check(|s| s.forced_residual = 1e308 * 10.0);
        assert!(err.contains("newton.forced_residual = inf"), "{err}");
        let err = check(|s| s.steps = 0);
        assert!(err.contains("loading.steps = 0"), "{err}");
    }
}
