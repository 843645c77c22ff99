//! The assembly specification: what a job file (or the gRPC service) says about one DEM
//! assembly. Every struct is serde-derived with `deny_unknown_fields`; defaults are the paper's
//! values (Chu et al. 2015, section 3) unless a comment says otherwise.
//!
//! Every field may be omitted (defaults); a full spec in JSON reads:
//! ```json
//! {
//!   "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.1},
//!   "contact": {
//!     "normal": {"model": "linear", "k_n": 6.7e7},
//!     "tangential": {"model": "coulomb", "k_s": 3.4e7, "mu_s": 0.5, "c_s": 0.0},
//!     "rolling": {"model": "coulomb", "k_r": 25.0, "mu_r": 0.2, "c_r": 0.0}
//!   },
//!   "density": 2650.0,
//!   "boundary": {"kind": "penalty", "eps_f": 6.7e6, "eps_c": 1000.0},
//!   "relaxation": {"driver": {"kind": "cundall", "alpha": 0.7}, "criterion": "unbalanced_force",
//!                  "tolerance": 1e-4, "max_steps": 400000, "check_every": 10, "safety": 0.8,
//!                  "density_scale": 1.0, "skin": 0.5},
//!   "tangent": {"kind": "paper"},
//!   "warm_start": false
//! }
//! ```
//! A random packing: `{"kind": "random", "r_min": 0.004, "r_max": 0.006, "side": 0.1,
//! "seed": 1, "confining_stress": 1e5}`; a periodic boundary: `{"kind": "periodic"}`; FIRE:
//! `{"kind": "fire", "alpha_start": 0.1, "f_inc": 1.1, "f_dec": 0.5, "f_alpha": 0.99,
//! "n_min": 5, "dt_max": 1.8}`; the perturbation tangent: `{"kind": "perturbation",
//! "strain": 1e-5}`.

use crate::error::{Result, invalid, non_negative, positive};
use serde::{Deserialize, Serialize};

/// Everything needed to build and drive one assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AssemblySpec {
    /// How the discs are arranged in the reference state.
    pub packing: PackingSpec,
    /// The contact law (normal, tangential and rolling sub-models).
    pub contact: ContactParams,
    /// Solid density in kg/m^3 (default 2650: quartz; the paper does not give one).
    pub density: f64,
    /// Penalty (Miehe, Eq. 24) or periodic boundary.
    pub boundary: BoundarySpec,
    /// Time step, relaxation driver and convergence criterion.
    pub relaxation: RelaxationSpec,
    /// Which tangent operator `solve` returns.
    pub tangent: TangentKind,
    /// Start each trial solve from the last trial state (since the last commit or rollback)
    /// instead of the committed state: fewer steps per Newton iteration, but the answer then
    /// depends on the iteration history. Default false.
    pub warm_start: bool,
}

impl Default for AssemblySpec {
    fn default() -> Self {
        Self {
            packing: PackingSpec::default(),
            contact: ContactParams::default(),
            density: 2650.0,
            boundary: BoundarySpec::default(),
            relaxation: RelaxationSpec::default(),
            tangent: TangentKind::default(),
            warm_start: false,
        }
    }
}

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

/// Contact law of THEORY.md section 2, one sub-model per part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactParams {
    /// Normal sub-model.
    pub normal: NormalModel,
    /// Tangential sub-model.
    pub tangential: TangentialModel,
    /// Rolling-resistance sub-model.
    pub rolling: RollingModel,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            normal: NormalModel::Linear { k_n: 6.7e7 },
            tangential: TangentialModel::Coulomb { k_s: 3.4e7, mu_s: 0.5, c_s: 0.0 },
            rolling: RollingModel::Coulomb { k_r: 25.0, mu_r: 0.2, c_r: 0.0 },
        }
    }
}

/// Normal force `F_n = k_n d + c_n d_dot >= 0` (Eqs. 14-15).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum NormalModel {
    /// Linear spring, no dashpot (the paper; relaxation relies on numerical damping).
    Linear {
        /// Normal stiffness (N/m). Paper: 6.7e7.
        k_n: f64,
    },
    /// Linear spring with a viscous dashpot.
    LinearDashpot {
        /// Normal stiffness (N/m).
        k_n: f64,
        /// Normal damping coefficient (N s/m).
        c_n: f64,
    },
}

/// Tangential force: incremental spring with Coulomb cap (Eqs. 16-19).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentialModel {
    /// Frictionless contacts.
    None,
    /// Spring `k_s`, dashpot `c_s`, Coulomb limit `mu_s F_n`.
    Coulomb {
        /// Tangential stiffness (N/m). Paper: 3.4e7.
        k_s: f64,
        /// Sliding friction coefficient. Paper: 0.5.
        mu_s: f64,
        /// Tangential damping (N s/m). Paper: 0.
        #[serde(default)]
        c_s: f64,
    },
}

/// Rolling resistance: incremental spring with cap `mu_r r* F_n` (Eqs. 20-23).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum RollingModel {
    /// No rolling resistance: the kernel skips the rolling history entirely.
    None,
    /// Spring `k_r`, dashpot `c_r`, cap `mu_r r* F_n`.
    Coulomb {
        /// Rolling stiffness (N m/rad). Paper: 25.
        k_r: f64,
        /// Rolling friction coefficient. Paper: 0.2.
        mu_r: f64,
        /// Rolling damping (N m s/rad). Paper: 0.
        #[serde(default)]
        c_r: f64,
    },
}

/// Boundary conditions of the assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BoundarySpec {
    /// Miehe's penalty constraints on the boundary layer (Eq. 24, THEORY.md reading).
    Penalty {
        /// Force penalty `eps_f` (N m); the spring stiffness is `eps_f / V`. Paper: 6.7e6.
        eps_f: f64,
        /// Moment penalty `eps_c` (N m^3/rad); the spring is `eps_c / V`. Paper: 1e3.
        eps_c: f64,
    },
    /// Periodic cell that follows Fbar (see [`crate::boundary::periodic`] for how `wbar` and
    /// `kbar` are treated).
    Periodic,
}

impl Default for BoundarySpec {
    fn default() -> Self {
        Self::Penalty { eps_f: 6.7e6, eps_c: 1.0e3 }
    }
}

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
        }
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

/// Tangent operator returned by `solve`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentKind {
    /// The paper's contact-stiffness tangent (k_s, k_r on every active contact).
    #[default]
    Paper,
    /// As `Paper` but `k_s' = 0` on sliding and `k_r' = 0` on saturated rolling contacts.
    SlidingAware,
    /// `Paper` scaled by the assembly's secant ratio since its committed state: `s = (dsigma
    /// . de) / (de . C de)` with `de` the strain (and curvature) increment from the committed
    /// target, `dsigma` the stress (and couple stress) increment from the committed relaxed
    /// answer and `C` the paper tangent, kept in [`SECANT_RANGE`]. The contact tangent
    /// assumes affine motion and sticking contacts, an upper bound the relaxed random
    /// assembly falls below (its contacts slide, its discs move non-affinely); the secant
    /// measures by how much along the step's own path. `s = 1` (the paper tangent) when the
    /// committed state was never relaxed, the increment is nil, or its second-order work is
    /// not positive (`dsigma . de <= 0`, softening past a peak: no positive scale helps
    /// there). Deterministic: it depends on the committed state and the trial only.
    Secant,
    /// Central differences of extra relaxations from the trial state, which is restored.
    Perturbation {
        /// Strain perturbation (default 1e-5 in the job file; must be > 0).
        strain: f64,
    },
    /// `Paper` while fewer than `sliding` of the assembly's contacts slide, `Perturbation`
    /// from there on: the contact-stiffness tangent is right while the contacts stick and too
    /// stiff once the assembly slips and softens, where the perturbation tangent follows it.
    /// Only the sliding assemblies pay the twelve extra relaxations (scene B: the band, not
    /// the 400 points). The choice depends on the assembly's own relaxed state only, so it is
    /// the same whatever worker holds the assembly.
    Adaptive {
        /// Sliding fraction (sliding contacts / contacts) from which the perturbation tangent
        /// is used, in [0, 1].
        sliding: f64,
        /// Strain perturbation of the perturbation tangent (> 0).
        strain: f64,
    },
}

/// FIRE's largest step as a fraction of the critical step `2 / omega_max`, whatever its
/// `dt_max` and the safety factor: a step above the critical one makes the stiffest
/// oscillator grow (FIRE at safety 0.8 with the uncapped 1.8 base steps, 1.44 critical
/// steps, stalled every relaxation of `tests/tests/accuracy.rs`'s scene at a residual ratio
/// of 0.4). 0.9 is where the default 1.8 base steps of safety 0.5 always ended.
pub const FIRE_CEILING: f64 = 0.9;

/// The range of the [`TangentKind::Secant`] scale: never stiffer than the contact tangent,
/// never softer than a twentieth of it (a near-zero secant would hand Newton a singular
/// matrix).
pub const SECANT_RANGE: (f64, f64) = (0.05, 1.0);

/// Most discs one assembly may hold (a cap so that a typo in `side` or `radius`, or a hostile
/// request, cannot ask a worker for 10^17 discs). The paper's largest assemblies hold a few
/// thousand; 10^6 discs take about 0.5 GB.
pub const MAX_DISCS: usize = 1_000_000;

/// Most steps one relaxation may be given (`relaxation.max_steps`): at the measured 2-3e7
/// particle-steps per second, 10^8 steps of even 100 discs are several minutes for one Gauss
/// point of one Newton iteration, which is a hang, not a solve.
pub const MAX_RELAXATION_STEPS: u64 = 100_000_000;

/// Most sub-increments one relaxation is split into (`relaxation.substep`): a tiny `substep`
/// against a large increment (a hostile request, or a Newton iterate far off) must not turn one
/// answer into millions of relaxations. At the paper's load steps (1e-3 strain) and a substep
/// of 1e-4 a relaxation is split into about ten.
pub const MAX_SUBSTEPS: u64 = 1_000;

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
}

impl AssemblySpec {
    /// Checks every field; errors name the field and value.
    pub fn validate(&self) -> Result<()> {
        match &self.packing {
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
                            format!("{r_min} > r_max = {r_max}"),
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
        let n = self.packing.estimated_discs();
        if n.is_nan() || n > MAX_DISCS as f64 {
            return Err(invalid(
                "packing.side",
                format!("{} (about {n:.3e} discs)", self.packing_side()),
                "side / radius too large: more than MAX_DISCS = 1 000 000 discs in one assembly",
            ));
        }
        match &self.contact.normal {
            NormalModel::Linear { k_n } => positive("contact.normal.k_n", *k_n)?,
            NormalModel::LinearDashpot { k_n, c_n } => {
                positive("contact.normal.k_n", *k_n)?;
                non_negative("contact.normal.c_n", *c_n)?;
            }
        }
        if let TangentialModel::Coulomb { k_s, mu_s, c_s } = &self.contact.tangential {
            non_negative("contact.tangential.k_s", *k_s)?;
            non_negative("contact.tangential.mu_s", *mu_s)?;
            non_negative("contact.tangential.c_s", *c_s)?;
        }
        if let RollingModel::Coulomb { k_r, mu_r, c_r } = &self.contact.rolling {
            non_negative("contact.rolling.k_r", *k_r)?;
            non_negative("contact.rolling.mu_r", *mu_r)?;
            non_negative("contact.rolling.c_r", *c_r)?;
        }
        positive("density", self.density)?;
        if let BoundarySpec::Penalty { eps_f, eps_c } = &self.boundary {
            positive("boundary.eps_f", *eps_f)?;
            non_negative("boundary.eps_c", *eps_c)?;
        }
        let r = &self.relaxation;
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
        match &self.tangent {
            TangentKind::Perturbation { strain } => positive("tangent.strain", *strain)?,
            TangentKind::Adaptive { sliding, strain } => {
                positive("tangent.strain", *strain)?;
                if !(0.0..=1.0).contains(sliding) {
                    return Err(invalid("tangent.sliding", sliding, "must be in [0, 1]"));
                }
            }
            TangentKind::Paper | TangentKind::SlidingAware | TangentKind::Secant => {}
        }
        Ok(())
    }

    fn packing_side(&self) -> f64 {
        match &self.packing {
            PackingSpec::Hexagonal { side, .. } | PackingSpec::Random { side, .. } => *side,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A driver named by its kind alone takes the default parameters; a given one is kept.
    #[test]
    fn a_driver_by_its_kind_alone_has_the_defaults() {
        let fire: Driver = serde_json::from_str(r#"{"kind": "fire"}"#).unwrap();
        assert_eq!(fire, Driver::fire());
        let cundall: Driver = serde_json::from_str(r#"{"kind": "cundall"}"#).unwrap();
        assert_eq!(cundall, Driver::default());
        let tuned: Driver = serde_json::from_str(r#"{"kind": "fire", "n_min": 3}"#).unwrap();
        assert!(matches!(tuned, Driver::Fire { n_min: 3, f_inc, .. } if f_inc == 1.1));
        assert!(serde_json::from_str::<Driver>(r#"{"kind": "fire", "nmin": 3}"#).is_err());
    }
}
