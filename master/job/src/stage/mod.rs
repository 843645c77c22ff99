//! `[[stage]]`: a job's loading as a list of stages, and what each stage hands the solver.
//!
//! A stage moves node sets (a target, an increment, or a path of targets), applies, holds or
//! removes pressures, tractions and gravity, in its own number of steps, possibly repeated.
//! What an earlier stage set stays in force until a later one changes it:
//! - a prescribed dof is held where the last stage left it (`free = true` releases it);
//! - a pressure or traction stays at its value (a new value is reached over the stage with
//!   `ramp = "linear"`, at once with `"constant"`; `"remove"` takes it away over the stage);
//! - gravity likewise (`[stage.gravity]`, with the same ramps).
//!
//! A job without `[[stage]]` is the one stage of its `[loading]`, exactly as before stages.
//! Keys in errors name a stage by its index in the file, from 0: `stage[1].prescribed[0].set`.
//!
//! This file holds the tables and their validation; `expand` turns them into the solver's
//! stages ([`Job::stages`], [`Job::next_stages`]).

use crate::schema::{ComponentChoice, Job};
use crate::validate::interned;
use cosdem_fem::assembly::Component;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::solve::Loading;
use serde::{Deserialize, Serialize};

/// Most stages a job expands to (repetitions and path points counted): a cyclic test of a
/// few hundred cycles fits; a typo of `repeat = 1e9` does not.
pub const MAX_STAGES: usize = 100_000;

/// How a load of a stage follows the stage's load factor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StageRamp {
    /// Full from the stage's first step (default).
    Constant,
    /// From its value before the stage (0 if none) to the new value over the stage.
    Linear,
    /// From its value before the stage to zero over the stage.
    Remove,
}

fn default_ramp() -> StageRamp {
    StageRamp::Constant
}

/// `[[stage.prescribed]]`: a dof of a node set in this stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StagePrescribed {
    /// Node set.
    pub set: String,
    /// `ux`, `uy` or `w`.
    pub component: ComponentChoice,
    /// The value reached at the end of the stage (m or rad).
    pub value: Option<f64>,
    /// The change over the stage from where the dofs are (negative to unload; 0 holds).
    pub increment: Option<f64>,
    /// Targets reached one after the other, each over `steps` steps (a path table: a cyclic
    /// loading is `[a, b, a, b]`); the stage becomes one stage per target.
    #[serde(default)]
    pub path: Vec<f64>,
    /// Releases the dof prescribed by an earlier stage.
    #[serde(default)]
    pub free: bool,
}

/// `[[stage.pressure]]`: a pressure on an edge set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StagePressure {
    /// Edge set.
    pub set: String,
    /// Pressure (Pa, positive pushes into the body); not needed with `ramp = "remove"`.
    #[serde(default)]
    pub value: f64,
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[[stage.traction]]`: a traction vector on an edge set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageTraction {
    /// Edge set.
    pub set: String,
    /// `[t_x, t_y]` (Pa); not needed with `ramp = "remove"`.
    #[serde(default)]
    pub value: [f64; 2],
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[stage.gravity]`: self-weight, the bulk density times the acceleration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageGravity {
    /// Acceleration `[g_x, g_y]` (m/s^2), e.g. `[0, -9.81]`.
    pub acceleration: [f64; 2],
    /// Bulk density of the material (kg/m^3 of the continuum: the solid density times the
    /// solid fraction for a dry granular material); an element of a `[[region]]` with
    /// `bulk_density` takes the region's instead. Left out, a DEM material weighs its
    /// assembly's solid density times solid fraction ([`crate::bulk`]); an elastic one needs
    /// its region's `bulk_density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// `constant` (default), `linear` or `remove`.
    #[serde(default = "default_ramp")]
    pub ramp: StageRamp,
}

/// `[[stage]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSection {
    /// Free text (logs).
    #[serde(default)]
    pub name: String,
    /// Equal load steps of the stage (default 10).
    #[serde(default = "default_steps")]
    pub steps: usize,
    /// The stage this many times in a row (default 1): with increments, a cyclic loading.
    #[serde(default = "one")]
    pub repeat: usize,
    /// Prescribed dofs.
    #[serde(default)]
    pub prescribed: Vec<StagePrescribed>,
    /// Pressures.
    #[serde(default)]
    pub pressure: Vec<StagePressure>,
    /// Tractions.
    #[serde(default)]
    pub traction: Vec<StageTraction>,
    /// Self-weight.
    pub gravity: Option<StageGravity>,
    /// Path control: the stage's steps advance a set's mean displacement, its load factor
    /// follows (`[loading.control]`'s meaning).
    pub control: Option<crate::schema::ControlSection>,
}

fn default_steps() -> usize {
    10
}
fn one() -> usize {
    1
}

/// One stage as the solver runs it.
#[derive(Clone, Debug)]
pub struct SolverStage {
    /// The stage's loading (what is held from earlier stages included).
    pub loading: Loading,
    /// Its nominal steps.
    pub steps: usize,
    /// Its name, with the repetition or path point (`unload`, `cycle 3/10`).
    pub name: String,
}

mod expand;

pub use expand::StagesSoFar;

pub(super) fn component(c: ComponentChoice) -> Component {
    c.into()
}

pub(super) fn key(i: usize, rest: &str) -> &'static str {
    interned(format!("stage[{i}]{rest}"))
}

pub(super) fn bad(
    field: &'static str,
    value: impl Into<String>,
    reason: impl Into<String>,
) -> Error {
    Error::InvalidSetting { field, value: value.into(), reason: reason.into() }
}

impl Job {
    /// Checks `[[stage]]`: steps, repeat, one of value / increment / path / free per
    /// prescribed entry, finite numbers, a density for gravity, and no `[loading]` loads
    /// beside stages.
    pub(crate) fn validate_stages(&self) -> Result<()> {
        if !self.is_staged() {
            return Ok(());
        }
        self.validate_staged_job()?;
        for (i, s) in self.stage.iter().enumerate() {
            self.validate_stage(i, s)?;
        }
        Ok(())
    }

    /// What a job in stages may not have: `[loading]` loads.
    fn validate_staged_job(&self) -> Result<()> {
        let l = &self.loading;
        if l.compression.is_some()
            || !l.prescribed.is_empty()
            || !l.pressure.is_empty()
            || l.increment.is_some()
        {
            return Err(bad(
                "loading",
                "[loading] with loads",
                "a job in [[stage]] puts its loads in its stages; [loading] keeps only load_set",
            ));
        }
        Ok(())
    }

    /// [`Job::validate_stages`] of stage `i`, `s`.
    fn validate_stage(&self, i: usize, s: &StageSection) -> Result<()> {
        if s.steps == 0 || s.steps > cosdem_fem::solve::MAX_LOAD_STEPS {
            return Err(bad(
                key(i, ".steps"),
                s.steps.to_string(),
                format!("must be 1 to {}", cosdem_fem::solve::MAX_LOAD_STEPS),
            ));
        }
        if s.repeat == 0 || s.repeat > MAX_STAGES {
            return Err(bad(
                key(i, ".repeat"),
                s.repeat.to_string(),
                format!("must be 1 to {MAX_STAGES}"),
            ));
        }
        let mut paths = None;
        for (j, p) in s.prescribed.iter().enumerate() {
            let at = |k: &str| key(i, &format!(".prescribed[{j}]{k}"));
            let given = [p.value.is_some(), p.increment.is_some(), !p.path.is_empty(), p.free];
            if given.iter().filter(|g| **g).count() != 1 {
                return Err(bad(
                    at(""),
                    format!("set = {:?}", p.set),
                    "give exactly one of value, increment, path or free = true",
                ));
            }
            for v in p.value.iter().chain(&p.increment).chain(&p.path) {
                if !v.is_finite() {
                    return Err(bad(at(""), format!("{v:?}"), "must be finite"));
                }
            }
            if !p.path.is_empty() {
                match paths {
                    Some(n) if n != p.path.len() => {
                        return Err(bad(
                            at(".path"),
                            format!("{} points", p.path.len()),
                            format!("the stage's other path has {n}: paths of a stage go together"),
                        ));
                    }
                    _ => paths = Some(p.path.len()),
                }
            }
        }
        for (j, p) in s.pressure.iter().enumerate() {
            if !p.value.is_finite() {
                return Err(bad(
                    key(i, &format!(".pressure[{j}].value")),
                    format!("{:?}", p.value),
                    "must be finite",
                ));
            }
        }
        for (j, t) in s.traction.iter().enumerate() {
            if !t.value.iter().all(|v| v.is_finite()) {
                return Err(bad(
                    key(i, &format!(".traction[{j}].value")),
                    format!("{:?}", t.value),
                    "must be finite",
                ));
            }
        }
        if let Some(g) = &s.gravity {
            if !g.acceleration.iter().all(|v| v.is_finite()) {
                return Err(bad(
                    key(i, ".gravity.acceleration"),
                    format!("{:?}", g.acceleration),
                    "must be finite",
                ));
            }
            match g.density {
                Some(rho) if !(rho.is_finite() && rho > 0.0) => {
                    return Err(bad(
                        key(i, ".gravity.density"),
                        format!("{rho:?}"),
                        "a body force needs the material's bulk density (kg/m^3, finite and > 0)",
                    ));
                }
                None if g.ramp != StageRamp::Remove && !self.weighs_without_stage_density() => {
                    return Err(bad(
                        key(i, ".gravity.density"),
                        "missing",
                        "a body force needs the material's bulk density (kg/m^3, finite and > 0); it may be left out only when every material is DEM (weighed from its assembly) or its [[region]] gives a bulk_density, or with ramp = \"remove\"",
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }
}
