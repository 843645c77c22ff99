//! How an assembly is relaxed to equilibrium: the damping driver, the criterion, the step and
//! its caps.

use crate::error::{Result, invalid, non_negative, positive};
use serde::{Deserialize, Serialize};

/// How the assembly is brought to equilibrium.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RelaxationSpec {
    /// Numerical damping driver.
    pub driver: Driver,
    /// Which equilibrium ratio is compared with `tolerance`.
    pub criterion: Criterion,
    /// Equilibrium tolerance on the ratio (default 1e-4).
    pub tolerance: f64,
    /// Step cap of one relaxation (default 400 000); hitting it is reported, not an error.
    pub max_steps: u64,
    /// Steps between two evaluations of the criterion (default 10).
    pub check_every: u32,
    /// Fraction of the critical step `2 / omega_max` used (default 0.8, YADE's
    /// `GlobalStiffnessTimeStepper` default). `omega_max` is a Gershgorin bound that already
    /// includes six contacts per disc, so 0.8 of it is about 0.24 of the single-spring step
    /// `2 sqrt(m/k)`. Measured (`docs/notes/tradeoff-*.md`): 0.8 moves no error column against
    /// 0.5 on any committed table and saves a third of the DEM steps; 0.95 failed on scene A.
    pub safety: f64,
    /// Density (mass) scaling factor >= 1 used for the relaxation only (default 1). The
    /// equilibrium reached does not depend on the masses; scaling them makes the step larger
    /// but slows the dynamics by the same factor, so it pays off only with dashpots or for
    /// polydisperse packings where the smallest disc sets the step.
    pub density_scale: f64,
    /// Verlet skin as a fraction of the smallest radius (default 0.5).
    pub skin: f64,
    /// Skip threshold (default 0 = off): a solve whose deformation since the last relaxation
    /// measures below it, `max(|dF_ij|, |dw|, (sqrt(V)/2) |dk_i|)`, is not relaxed; the last
    /// relaxed stress plus tangent times the strain increment answers (see
    /// [`crate::assembly`]'s `shortcut` module).
    pub skip_below: f64,
    /// Elastic shortcut (default false): answer through the tangent, without a relaxation,
    /// while the increment since the last relaxation keeps every contact sticking and none
    /// opens or closes (checked on the affine jump with a 10 % margin).
    pub elastic_shortcut: bool,
    /// Largest deformation increment of one affine jump (default 0 = off), in the measure of
    /// `skip_below`. A relaxation whose increment from its start is larger is split into
    /// `n = ceil(size / substep)` equal sub-increments (at most [`MAX_SUBSTEPS`]) along the
    /// straight path in `F`, `w` and `kappa`, each jumped and relaxed to the tolerance in
    /// turn: the micro path of a load step then follows the loading gradually, as a
    /// strain-rate-driven DEM test does, instead of in one jump. The contact histories are
    /// path dependent, so past a peak the answer depends on the size of the jumps: on the
    /// biaxial example's specimen, jumps of 1e-3 strain miss the second softening that
    /// jumps of 5e-4 and below follow (F_res 19.6e3 against 15.8-16.9e3 N, docs/notes/substep-biaxial.md).
    pub substep: f64,
    /// Where a relaxation from the committed state starts (default `affine`): the affine jump
    /// alone, or with the last committed step's non-affine increment added, scaled to this
    /// increment (`extrapolated`, see [`Predictor`]). Left out of the spec's serialized form
    /// at its default, so the states and checkpoints of jobs that do not set it encode to the
    /// same bytes as before it existed.
    #[serde(skip_serializing_if = "Predictor::is_affine")]
    pub predictor: Predictor,
}

impl Default for RelaxationSpec {
    fn default() -> Self {
        Self {
            driver: Driver::default(),
            criterion: Criterion::UnbalancedForce,
            tolerance: 1e-4,
            max_steps: 400_000,
            check_every: 10,
            safety: 0.8,
            density_scale: 1.0,
            skin: 0.5,
            skip_below: 0.0,
            elastic_shortcut: false,
            substep: 0.0,
            predictor: Predictor::Affine,
        }
    }
}

/// The initial guess of a relaxation from the committed state (issue 30, item 1: fewer DEM
/// steps per answer).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Predictor {
    /// Every disc follows the macro deformation affinely (Eq. 26's jump); the relaxation finds
    /// the whole non-affine part.
    #[default]
    Affine,
    /// The affine jump plus the non-affine displacements and rotations of the last committed
    /// step, times the projection of this increment on that step's (clamped to [0, 2]): on a
    /// smooth path the fluctuation field of the next increment is close to the last one's, so
    /// the relaxation starts near its equilibrium. The contact histories follow the
    /// predicted relative motion as they follow the affine jump's.
    Extrapolated,
}

impl Predictor {
    /// Whether this is the default, [`Predictor::Affine`].
    pub fn is_affine(&self) -> bool {
        *self == Self::Affine
    }
}

/// Numerical damping used by the relaxation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Driver {
    /// Cundall's local non-viscous damping: `F_i <- F_i (1 - alpha sign(F_i v_i))`.
    Cundall {
        /// Damping coefficient in [0, 1) (default 0.7).
        #[serde(default = "defaults::alpha")]
        alpha: f64,
    },
    /// FIRE (Bitzek et al. 2006) with the usual parameters.
    Fire {
        /// Initial velocity-mixing factor (default 0.1).
        #[serde(default = "defaults::alpha_start")]
        alpha_start: f64,
        /// Step growth factor after `n_min` downhill steps (default 1.1).
        #[serde(default = "defaults::f_inc")]
        f_inc: f64,
        /// Step shrink factor on an uphill step (default 0.5).
        #[serde(default = "defaults::f_dec")]
        f_dec: f64,
        /// Mixing decay (default 0.99).
        #[serde(default = "defaults::f_alpha")]
        f_alpha: f64,
        /// Downhill steps before the step may grow (default 5).
        #[serde(default = "defaults::n_min")]
        n_min: u32,
        /// Largest step as a multiple of the base step (default 1.8), never above
        /// [`FIRE_CEILING`] of the critical step: at the default safety 0.8 the step grows to
        /// 0.9 of the critical step (1.125 base steps), at safety 0.5 to 0.9 (1.8).
        #[serde(default = "defaults::dt_max")]
        dt_max: f64,
    },
}

/// The defaults of the drivers' parameters (a job may give `{ kind = "fire" }` alone).
mod defaults {
    pub fn alpha() -> f64 {
        0.7
    }
    pub fn alpha_start() -> f64 {
        0.1
    }
    pub fn f_inc() -> f64 {
        1.1
    }
    pub fn f_dec() -> f64 {
        0.5
    }
    pub fn f_alpha() -> f64 {
        0.99
    }
    pub fn n_min() -> u32 {
        5
    }
    pub fn dt_max() -> f64 {
        1.8
    }
}

impl Default for Driver {
    fn default() -> Self {
        Self::Cundall { alpha: defaults::alpha() }
    }
}

impl Driver {
    /// FIRE with its default parameters.
    pub fn fire() -> Self {
        Self::Fire {
            alpha_start: defaults::alpha_start(),
            f_inc: defaults::f_inc(),
            f_dec: defaults::f_dec(),
            f_alpha: defaults::f_alpha(),
            n_min: defaults::n_min(),
            dt_max: defaults::dt_max(),
        }
    }
}

/// Equilibrium measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    /// Mean |net force| over mean contact normal force.
    UnbalancedForce,
    /// Kinetic energy over stored elastic energy.
    KineticEnergy,
}

/// FIRE's largest step as a fraction of the critical step `2 / omega_max`, whatever its
/// `dt_max` and the safety factor: a step above the critical one makes the stiffest
/// oscillator grow (FIRE at safety 0.8 with the uncapped 1.8 base steps, 1.44 critical
/// steps, stalled every relaxation of `tests/tests/accuracy.rs`'s scene at a residual ratio
/// of 0.4). 0.9 is where the default 1.8 base steps of safety 0.5 always ended.
pub const FIRE_CEILING: f64 = 0.9;

/// Most steps one relaxation may be given (`relaxation.max_steps`): at the measured 2-3e7
/// particle-steps per second, 10^8 steps of even 100 discs are several minutes for one Gauss
/// point of one Newton iteration, which is a hang, not a solve.
pub const MAX_RELAXATION_STEPS: u64 = 100_000_000;

/// Most sub-increments one relaxation is split into (`relaxation.substep`): a tiny `substep`
/// against a large increment (a hostile request, or a Newton iterate far off) must not turn one
/// answer into millions of relaxations. At the paper's load steps (1e-3 strain) and a substep
/// of 1e-4 a relaxation is split into about ten.
pub const MAX_SUBSTEPS: u64 = 1_000;

impl RelaxationSpec {
    /// Checks the tolerance, the step caps, the step and skin fractions and the driver.
    pub(super) fn validate(&self) -> Result<()> {
        let r = self;
        positive("relaxation.tolerance", r.tolerance)?;
        if r.max_steps == 0 || r.max_steps > MAX_RELAXATION_STEPS {
            return Err(invalid(
                "relaxation.max_steps",
                r.max_steps,
                "must be in [1, 100 000 000] (MAX_RELAXATION_STEPS)",
            ));
        }
        if r.check_every == 0 {
            return Err(invalid("relaxation.check_every", 0, "must be >= 1"));
        }
        if !(r.safety > 0.0 && r.safety <= 1.0) {
            return Err(invalid("relaxation.safety", r.safety, "must be in (0, 1]"));
        }
        if !(r.density_scale.is_finite() && r.density_scale >= 1.0) {
            return Err(invalid("relaxation.density_scale", r.density_scale, "must be >= 1"));
        }
        if !(r.skin > 0.0 && r.skin <= 2.0) {
            return Err(invalid(
                "relaxation.skin",
                r.skin,
                "must be in (0, 2] (fraction of r_min)",
            ));
        }
        non_negative("relaxation.skip_below", r.skip_below)?;
        non_negative("relaxation.substep", r.substep)?;
        match &r.driver {
            Driver::Cundall { alpha } => {
                if !(*alpha >= 0.0 && *alpha < 1.0) {
                    return Err(invalid("relaxation.driver.alpha", alpha, "must be in [0, 1)"));
                }
            }
            Driver::Fire { alpha_start, f_inc, f_dec, f_alpha, dt_max, .. } => {
                if !(*alpha_start > 0.0 && *alpha_start < 1.0) {
                    return Err(invalid("relaxation.driver.alpha_start", alpha_start, "in (0, 1)"));
                }
                if !(*f_inc >= 1.0 && f_inc.is_finite()) {
                    return Err(invalid("relaxation.driver.f_inc", f_inc, "must be >= 1"));
                }
                if !(*f_dec > 0.0 && *f_dec < 1.0) {
                    return Err(invalid("relaxation.driver.f_dec", f_dec, "must be in (0, 1)"));
                }
                if !(*f_alpha > 0.0 && *f_alpha <= 1.0) {
                    return Err(invalid("relaxation.driver.f_alpha", f_alpha, "in (0, 1]"));
                }
                if !(*dt_max >= 1.0 && dt_max.is_finite()) {
                    return Err(invalid(
                        "relaxation.driver.dt_max",
                        dt_max,
                        "must be a finite multiple >= 1 of the base step",
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A driver named by its kind alone takes the default parameters; a given one is kept, and
    /// a misspelt one is refused by name.
    #[test]
    fn a_driver_by_its_kind_alone_has_the_defaults() {
        let fire: Driver = serde_json::from_str(r#"{"kind": "fire"}"#).unwrap();
        assert_eq!(fire, Driver::fire());
        let cundall: Driver = serde_json::from_str(r#"{"kind": "cundall"}"#).unwrap();
        assert_eq!(cundall, Driver::default());
        let tuned: Driver = serde_json::from_str(r#"{"kind": "fire", "n_min": 3}"#).unwrap();
        assert!(matches!(tuned, Driver::Fire { n_min: 3, f_inc, .. } if f_inc == 1.1));
        let err = serde_json::from_str::<Driver>(r#"{"kind": "fire", "nmin": 3}"#).unwrap_err();
        assert!(err.to_string().contains("unknown field `nmin`"), "{err}");
    }
}
