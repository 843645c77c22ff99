//! The speed knobs: [`Knob`](crate::knob::Knob), the one catalogue of the settings that trade
//! accuracy for speed (each knob's name in the tables, its value in a job, the moves a sweep tries,
//! how a table row's setting is applied and how a plan resets it), and the sweep built from them
//! (the reference, the job as given and each knob moved alone:
//! [`variants`](crate::knob::variants)).

use crate::table::TableError;
use cosdem_dem::AssemblySpec;
use cosdem_dem::spec::{Driver, Predictor, TangentKind};
use cosdem_job::{Job, MaterialSection};

/// One setting of the sweep: a label and the job it produces.
#[derive(Clone, Debug)]
pub struct Variant {
    /// The row's knob: a [`Knob`]'s name, or a row that is no single knob (`reference`,
    /// `default`, the combinations `accuracy` and `cheapest`).
    pub knob: &'static str,
    /// The knob's value in words (`1e-3`, `fire`, ...).
    pub setting: String,
    /// The job to run.
    pub job: Job,
}

impl Variant {
    /// A file-system-safe name (`relaxation.tolerance=1e-3` -> `relaxation.tolerance_1e-3`).
    pub fn slug(&self) -> String {
        slug(self.knob, &self.setting)
    }
}

/// The run directory's name of a knob and setting (`relaxation.tolerance`, `1e-3` ->
/// `relaxation.tolerance_1e-3`): what `out/runs/` holds for each row.
pub fn slug(knob: &str, setting: &str) -> String {
    format!("{knob}_{setting}")
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' })
        .collect()
}

/// The DEM assembly of a job, if it has one (`None` for an analytical material).
pub fn assembly_mut(job: &mut Job) -> Option<&mut AssemblySpec> {
    match &mut job.material {
        MaterialSection::Dem { assembly } => Some(assembly),
        MaterialSection::Elastic { .. } => None,
    }
}

fn assembly_of(job: &Job) -> Option<&AssemblySpec> {
    match &job.material {
        MaterialSection::Dem { assembly } => Some(assembly),
        MaterialSection::Elastic { .. } => None,
    }
}

/// The stall limit the sweep tries (`newton.stall_iterations`): past the biaxial example's
/// peak a step's residual that has not fallen for 5 iterations no longer falls
/// (docs/notes/load-step-biaxial.md).
pub const STALL: u32 = 5;

/// The affine jump the sweep tries with `relaxation.substep` (half the paper's 1e-3 strain per
/// load step: on the biaxial example's specimen jumps of 5e-4 and below follow the second
/// softening that 6e-4 and above miss, docs/notes/substep-biaxial.md).
pub const SUBSTEP: f64 = 5e-4;

/// The tangents a sweep and a table row name, with the operator each name sets (the
/// perturbation tangent with the job file's default strain).
const TANGENTS: [(&str, TangentKind); 4] = [
    ("paper", TangentKind::Paper),
    ("sliding_aware", TangentKind::SlidingAware),
    ("secant", TangentKind::Secant),
    ("perturbation", TangentKind::Perturbation { strain: 1e-5 }),
];

/// A speed knob: a setting of a job that buys speed with accuracy (or, moved the other way,
/// accuracy with speed). [`Knob::ALL`] is the catalogue; a knob's name ([`Knob::name`],
/// [`std::fmt::Display`], [`std::str::FromStr`]) is the `knob` column of a trade table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Knob {
    /// `load_step`: the load increment (or step count), relative to the job's (`x4`: four
    /// times the job's step).
    LoadStep,
    /// `newton.secant_updates`: Gauss-point secant updates of Newton's iteration matrix within
    /// a step.
    NewtonSecantUpdates,
    /// `newton.stall_iterations`: an attempt whose best residual is tolerated ends after this
    /// many iterations without a new smallest one (0: off).
    NewtonStallIterations,
    /// `relaxation.tolerance`: the relaxation's equilibrium tolerance.
    RelaxationTolerance,
    /// `relaxation.safety`: the time step's fraction of the critical step.
    RelaxationSafety,
    /// `relaxation.density_scale`: mass scaling.
    RelaxationDensityScale,
    /// `relaxation.driver`: Cundall damping or FIRE.
    RelaxationDriver,
    /// `tangent`: the tangent operator the assemblies return.
    Tangent,
    /// `warm_start`: trial relaxations start from the last trial state.
    WarmStart,
    /// `relaxation.skip_below`: a point deformed less than this since its last relaxation
    /// answers from its tangent.
    RelaxationSkipBelow,
    /// `relaxation.elastic_shortcut`: the tangent answers while every contact sticks.
    RelaxationElasticShortcut,
    /// `relaxation.substep`: the largest affine jump of one relaxation.
    RelaxationSubstep,
    /// `relaxation.predictor`: the affine jump alone, or with the last step's non-affine
    /// increment extrapolated.
    RelaxationPredictor,
    /// `assembly.side`: the assembly's side (m), so its size V.
    AssemblySide,
}

impl Knob {
    /// Every speed knob, in the order a sweep moves them (so the order of a table's rows).
    pub const ALL: [Knob; 14] = [
        Knob::LoadStep,
        Knob::NewtonSecantUpdates,
        Knob::NewtonStallIterations,
        Knob::RelaxationTolerance,
        Knob::RelaxationSafety,
        Knob::RelaxationDensityScale,
        Knob::RelaxationDriver,
        Knob::Tangent,
        Knob::WarmStart,
        Knob::RelaxationSkipBelow,
        Knob::RelaxationElasticShortcut,
        Knob::RelaxationSubstep,
        Knob::RelaxationPredictor,
        Knob::AssemblySide,
    ];

    /// The knobs an accuracy target sets ([`Knob::planned`]), in [`Knob::ALL`]'s order (the
    /// order of a plan's report).
    pub const PLANNED: [Knob; 9] = {
        let mut out = [Knob::LoadStep; 9];
        let (mut i, mut n) = (0, 0);
        while i < Knob::ALL.len() {
            if Knob::ALL[i].planned() {
                out[n] = Knob::ALL[i];
                n += 1;
            }
            i += 1;
        }
        assert!(n == out.len(), "PLANNED's length is the number of planned knobs");
        out
    };

    /// The name in trade tables, `--skip` and reports (`relaxation.tolerance`).
    pub const fn name(self) -> &'static str {
        match self {
            Knob::LoadStep => "load_step",
            Knob::NewtonSecantUpdates => "newton.secant_updates",
            Knob::NewtonStallIterations => "newton.stall_iterations",
            Knob::RelaxationTolerance => "relaxation.tolerance",
            Knob::RelaxationSafety => "relaxation.safety",
            Knob::RelaxationDensityScale => "relaxation.density_scale",
            Knob::RelaxationDriver => "relaxation.driver",
            Knob::Tangent => "tangent",
            Knob::WarmStart => "warm_start",
            Knob::RelaxationSkipBelow => "relaxation.skip_below",
            Knob::RelaxationElasticShortcut => "relaxation.elastic_shortcut",
            Knob::RelaxationSubstep => "relaxation.substep",
            Knob::RelaxationPredictor => "relaxation.predictor",
            Knob::AssemblySide => "assembly.side",
        }
    }

    /// The knob of a name ([`Knob::name`]); `None` for any other string (a table's
    /// `reference`, `default` and combination rows included).
    pub fn from_name(name: &str) -> Option<Knob> {
        Knob::ALL.into_iter().find(|k| k.name() == name)
    }

    /// True for the knobs an accuracy target sets (to a measured setting or to the table's
    /// default value). Not: `relaxation.substep` (it trades the other way, cost for a more
    /// accurate micro path), Newton's `secant_updates` and `stall_iterations` and
    /// `relaxation.predictor` (no committed table has a row of them), and the assembly side (the user's physical choice: a smaller
    /// assembly shifts every property).
    pub const fn planned(self) -> bool {
        matches!(
            self,
            Knob::LoadStep
                | Knob::RelaxationTolerance
                | Knob::RelaxationSafety
                | Knob::RelaxationDensityScale
                | Knob::RelaxationDriver
                | Knob::Tangent
                | Knob::WarmStart
                | Knob::RelaxationSkipBelow
                | Knob::RelaxationElasticShortcut
        )
    }

    /// True for the knobs that set the relaxation's time step (safety scales it, FIRE grows
    /// it from the base step that safety sets, mass scaling lengthens it). A plan moves at
    /// most one of them: moved together their effects multiply into time steps no row of a
    /// table measured. Measured before FIRE's step was capped at
    /// [`cosdem_dem::spec::FIRE_CEILING`] of the critical step: FIRE with safety 0.8 (each
    /// stable alone) stalled every relaxation of the scene of `tests/tests/accuracy.rs` at a
    /// residual ratio of 0.4 after 400 000 steps.
    pub const fn sets_time_step(self) -> bool {
        matches!(
            self,
            Knob::RelaxationSafety | Knob::RelaxationDriver | Knob::RelaxationDensityScale
        )
    }

    /// What `job` says for this knob, in words (for a plan's report): `increment 0.002 m`,
    /// `1e-4`, `cundall (alpha 0.7)`, the tangent's kind, ... An assembly's knob of a job
    /// without a DEM material is `-`.
    pub fn value(self, job: &Job) -> String {
        match self {
            Knob::LoadStep => {
                if job.is_staged() {
                    let steps: Vec<String> =
                        job.stage.iter().map(|s| s.steps.to_string()).collect();
                    return format!("stage steps [{}]", steps.join(", "));
                }
                return match job.loading.increment {
                    Some(inc) => format!("increment {inc} m"),
                    None => format!("{} steps", job.loading.steps),
                };
            }
            Knob::NewtonSecantUpdates => return job.newton.secant_updates.to_string(),
            Knob::NewtonStallIterations => return job.newton.stall_iterations.to_string(),
            _ => {}
        }
        let Some(a) = assembly_of(job) else { return "-".into() };
        match self {
            Knob::RelaxationTolerance => format!("{:e}", a.relaxation.tolerance),
            Knob::RelaxationSafety => format!("{}", a.relaxation.safety),
            Knob::RelaxationDensityScale => format!("{}", a.relaxation.density_scale),
            Knob::RelaxationDriver => match a.relaxation.driver {
                Driver::Cundall { alpha } => format!("cundall (alpha {alpha})"),
                Driver::Fire { .. } => "fire".into(),
            },
            // The job file's name of the kind (serde), so a new tangent kind needs no change
            // here.
            Knob::Tangent => serde_json::to_value(&a.tangent)
                .ok()
                .and_then(|v| v.get("kind").and_then(|k| k.as_str()).map(str::to_string))
                .unwrap_or_else(|| format!("{:?}", a.tangent)),
            Knob::WarmStart => a.warm_start.to_string(),
            Knob::RelaxationSkipBelow => format!("{:e}", a.relaxation.skip_below),
            Knob::RelaxationElasticShortcut => a.relaxation.elastic_shortcut.to_string(),
            Knob::RelaxationSubstep => format!("{:e}", a.relaxation.substep),
            Knob::RelaxationPredictor => predictor_name(a.relaxation.predictor),
            Knob::AssemblySide => match a.packing.side() {
                Some(side) => format!("{side} m"),
                None => format!("given ({} packing)", a.packing.kind()),
            },
            Knob::LoadStep | Knob::NewtonSecantUpdates | Knob::NewtonStallIterations => {
                unreachable!("answered above")
            }
        }
    }

    /// Moves this knob of `job` to `setting`, named as in a table: `load_step` `xF` (the
    /// load step times F, F > 0), `relaxation.tolerance`, `relaxation.safety`,
    /// `relaxation.density_scale`, `relaxation.skip_below`, `relaxation.substep` (positive
    /// numbers), `relaxation.driver` `fire`/`cundall`, `tangent`
    /// `paper`/`sliding_aware`/`secant`/`perturbation` (strain 1e-5), `warm_start`,
    /// `relaxation.elastic_shortcut` and `newton.secant_updates` `true`/`false`,
    /// `relaxation.predictor` `affine`/`extrapolated`,
    /// `newton.stall_iterations` (a count, 0 = off), `assembly.side` (m). The moves of
    /// [`Knob::moves`] are these (a test checks they agree). A job without a DEM material has
    /// only the load step and Newton's knobs.
    pub fn apply(self, job: &mut Job, setting: &str) -> Result<(), TableError> {
        let unknown = || TableError::UnknownSetting {
            knob: self.name().to_string(),
            setting: setting.to_string(),
        };
        let number = || setting.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0);
        let flag = || match setting {
            "true" => Ok(true),
            "false" => Ok(false),
            _ => Err(unknown()),
        };
        match self {
            Knob::LoadStep => {
                let f = setting.strip_prefix('x').and_then(|f| f.parse::<f64>().ok());
                let f = f.filter(|f| f.is_finite() && *f > 0.0).ok_or_else(unknown)?;
                scale_load_step(job, f);
                return Ok(());
            }
            Knob::NewtonSecantUpdates => {
                job.newton.secant_updates = flag()?;
                return Ok(());
            }
            Knob::NewtonStallIterations => {
                job.newton.stall_iterations = setting.parse().map_err(|_| unknown())?;
                return Ok(());
            }
            _ => {}
        }
        let a = assembly_mut(job).ok_or_else(unknown)?;
        match self {
            Knob::RelaxationTolerance => a.relaxation.tolerance = number().ok_or_else(unknown)?,
            Knob::RelaxationSafety => a.relaxation.safety = number().ok_or_else(unknown)?,
            Knob::RelaxationDensityScale => {
                a.relaxation.density_scale = number().ok_or_else(unknown)?;
            }
            Knob::RelaxationDriver => {
                a.relaxation.driver = match setting {
                    "fire" => Driver::fire(),
                    "cundall" => Driver::default(),
                    _ => return Err(unknown()),
                };
            }
            Knob::Tangent => {
                let (_, t) = TANGENTS.iter().find(|(n, _)| *n == setting).ok_or_else(unknown)?;
                a.tangent = t.clone();
            }
            Knob::WarmStart => a.warm_start = flag()?,
            Knob::RelaxationSkipBelow => a.relaxation.skip_below = number().ok_or_else(unknown)?,
            Knob::RelaxationElasticShortcut => a.relaxation.elastic_shortcut = flag()?,
            Knob::RelaxationSubstep => a.relaxation.substep = number().ok_or_else(unknown)?,
            Knob::RelaxationPredictor => {
                // The job file's name of the value (serde), as for the tangent.
                let named = serde_json::Value::String(setting.to_string());
                a.relaxation.predictor = serde_json::from_value(named).map_err(|_| unknown())?;
            }
            Knob::AssemblySide => {
                let s = number().ok_or_else(unknown)?;
                *a.packing.side_mut().ok_or_else(unknown)? = s;
            }
            Knob::LoadStep | Knob::NewtonSecantUpdates | Knob::NewtonStallIterations => {
                unreachable!("applied above")
            }
        }
        Ok(())
    }

    /// Sets this knob of assembly `a` to its value in `to` (a plan resets the planned knobs
    /// to the table's default settings before it applies the picked ones). The load step and
    /// Newton's knobs are the job's, not the assembly's: nothing to reset here (the load step
    /// is relative to the job's own).
    pub fn reset(self, a: &mut AssemblySpec, to: &AssemblySpec) {
        match self {
            Knob::LoadStep | Knob::NewtonSecantUpdates | Knob::NewtonStallIterations => {}
            Knob::RelaxationTolerance => a.relaxation.tolerance = to.relaxation.tolerance,
            Knob::RelaxationSafety => a.relaxation.safety = to.relaxation.safety,
            Knob::RelaxationDensityScale => {
                a.relaxation.density_scale = to.relaxation.density_scale;
            }
            Knob::RelaxationDriver => a.relaxation.driver = to.relaxation.driver.clone(),
            Knob::Tangent => a.tangent = to.tangent.clone(),
            Knob::WarmStart => a.warm_start = to.warm_start,
            Knob::RelaxationSkipBelow => a.relaxation.skip_below = to.relaxation.skip_below,
            Knob::RelaxationElasticShortcut => {
                a.relaxation.elastic_shortcut = to.relaxation.elastic_shortcut;
            }
            Knob::RelaxationSubstep => a.relaxation.substep = to.relaxation.substep,
            Knob::RelaxationPredictor => a.relaxation.predictor = to.relaxation.predictor,
            Knob::AssemblySide => {
                if let (Some(s), Some(side)) = (to.packing.side(), a.packing.side_mut()) {
                    *side = s;
                }
            }
        }
    }

    /// The sweep's moves of this knob away from `base`'s setting, each a [`Variant`] (some may
    /// leave the job unchanged; [`variants`] drops those). An assembly's knob has none for a
    /// job without a DEM material.
    pub fn moves(self, base: &Job) -> Vec<Variant> {
        let named = |settings: Vec<String>| -> Vec<Variant> {
            settings
                .into_iter()
                .map(|setting| {
                    let mut job = base.clone();
                    self.apply(&mut job, &setting).expect("every sweep setting applies");
                    Variant { knob: self.name(), setting, job }
                })
                .collect()
        };
        match self {
            // The other way round too: half the job's step with the job's relaxation. Against
            // the reference (half the step and a tight relaxation) it tells how much of a
            // row's error is the load path and how much the relaxation: on the biaxial
            // example to 10 mm, seed 7, it is 0.8 % from the reference on F_res where the
            // default is 8.5 % (docs/notes/load-step-biaxial.md).
            Knob::LoadStep => return named(vec!["x2".into(), "x4".into(), "x0.5".into()]),
            Knob::NewtonSecantUpdates if !base.newton.secant_updates => {
                return named(vec!["true".into()]);
            }
            Knob::NewtonStallIterations if base.newton.stall_iterations == 0 => {
                return named(vec![STALL.to_string()]);
            }
            Knob::NewtonSecantUpdates | Knob::NewtonStallIterations => return Vec::new(),
            _ => {}
        }
        let Some(a) = assembly_of(base) else { return Vec::new() };
        let settings: Vec<String> = match self {
            Knob::RelaxationTolerance => [1e-3, 3e-4].iter().map(|t| format!("{t:e}")).collect(),
            // Larger time steps than the job's (the default is already 0.8).
            Knob::RelaxationSafety => [0.8, 0.95]
                .into_iter()
                .filter(|s| *s > a.relaxation.safety)
                .map(|s| s.to_string())
                .collect(),
            Knob::RelaxationDensityScale => [4.0, 16.0].map(|s: f64| s.to_string()).to_vec(),
            Knob::RelaxationDriver => vec!["fire".into()],
            Knob::Tangent => TANGENTS
                .iter()
                .filter(|(_, t)| std::mem::discriminant(t) != std::mem::discriminant(&a.tangent))
                .map(|(n, _)| n.to_string())
                .collect(),
            Knob::WarmStart => vec!["true".into()],
            // Item 3's skipping: a point deformed less than the threshold since its last
            // relaxation answers from its tangent (1e-3: a tenth to a half of these scenes'
            // strain per step); the elastic shortcut answers from the tangent while every
            // contact sticks.
            Knob::RelaxationSkipBelow if a.relaxation.skip_below == 0.0 => vec!["1e-3".into()],
            Knob::RelaxationElasticShortcut if !a.relaxation.elastic_shortcut => {
                vec!["true".into()]
            }
            // The other way round: smaller affine jumps cost relaxations and buy the micro
            // path's accuracy (the contact histories are path dependent;
            // docs/notes/substep-biaxial.md).
            Knob::RelaxationSubstep
                if a.relaxation.substep == 0.0 || a.relaxation.substep > SUBSTEP =>
            {
                vec![format!("{SUBSTEP:e}")]
            }
            // The initial guess of issue 30, item 1 (docs/notes/2026-12-08-extrapolated-predictor.md).
            Knob::RelaxationPredictor if a.relaxation.predictor == Predictor::Affine => {
                vec![predictor_name(Predictor::Extrapolated)]
            }
            Knob::AssemblySide => return side_moves(base, a),
            _ => Vec::new(),
        };
        named(settings)
    }
}

impl std::fmt::Display for Knob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Knob {
    type Err = TableError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Knob::from_name(s).ok_or_else(|| TableError::UnknownKnob { knob: s.to_string() })
    }
}

/// The job file's name of a predictor (`affine`, `extrapolated`): its serde name, so a new
/// predictor needs no change here.
fn predictor_name(p: Predictor) -> String {
    serde_json::to_value(p)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| format!("{p:?}"))
}

/// Multiplies the job's load step by `f` (a job given by its step count takes `1/f` as many,
/// at least one; a job in stages, each stage: its loads are totals, so its steps change).
fn scale_load_step(job: &mut Job, f: f64) {
    if job.is_staged() {
        for s in &mut job.stage {
            s.steps = ((s.steps as f64 / f).round() as usize).max(1);
        }
    } else if let Some(inc) = &mut job.loading.increment {
        *inc *= f;
    } else {
        job.loading.steps = ((job.loading.steps as f64 / f).round() as usize).max(1);
    }
}

/// The smaller assemblies a sweep tries: half and three quarters of the side, never below
/// four largest diameters (the worker refuses a smaller side). The setting prints the side to
/// 3 decimals; the job takes it unrounded.
fn side_moves(base: &Job, a: &AssemblySpec) -> Vec<Variant> {
    // An explicit disc list (a packing file) has no side to shrink.
    let Some(side) = a.packing.side() else { return Vec::new() };
    let smallest = 8.0 * a.packing.largest_radius();
    let mut v = Vec::new();
    for f in [0.5, 0.75] {
        let s = (side * f).max(smallest);
        if s < side {
            let mut job = base.clone();
            if let Some(side) = assembly_mut(&mut job).and_then(|a| a.packing.side_mut()) {
                *side = s;
            }
            v.push(Variant { knob: Knob::AssemblySide.name(), setting: format!("{s:.3}"), job });
        }
    }
    v
}

fn with(base: &Job, knob: &'static str, setting: &str, f: impl Fn(&mut Job)) -> Variant {
    let mut job = base.clone();
    f(&mut job);
    Variant { knob, setting: setting.to_string(), job }
}

/// The reference: the job's scene with tight settings (relaxation tolerance 1e-5, time-step
/// safety 0.25, no mass scaling, Cundall damping, half the load step, cold affine starts, no
/// skipped or linear answers, no Newton secant updates, the job's substeps) and the
/// job's tangent (the paper's for a sliding-aware one): a job past a peak needs the
/// perturbation or adaptive tangent to converge at all (the paper tangent stays elastic while
/// the assemblies soften and Newton stalls), a pre-peak job keeps the paper tangent. The
/// tangent changes where Newton stops within its tolerances: on the 68-disc scene of
/// `tests/tests/accuracy.rs` the settings picked for 5 % (paper tangent) are 0.04 % off the
/// paper-tangent reference but 9.7 % off a perturbation-tangent one, so a reference is only
/// comparable with runs of its own tangent. It is the yardstick of every other row, not a
/// claim of exactness: its own distance from the converged answer is what its settings leave
/// (the sweep shows the trend).
pub fn reference(base: &Job) -> Variant {
    with(base, "reference", "tight", |j| {
        // Newton with the material's own tangents (the paper's method); a job's
        // `relaxation.substep` is kept (smaller jumps are the more accurate micro path).
        j.newton.secant_updates = false;
        // Every attempt iterates to its cap: no early end on a stalled residual.
        j.newton.stall_iterations = 0;
        scale_load_step(j, 0.5);
        if let Some(a) = assembly_mut(j) {
            a.relaxation.tolerance = 1e-5;
            a.relaxation.safety = 0.25;
            a.relaxation.density_scale = 1.0;
            a.relaxation.driver = Driver::default();
            // Keep a tangent that follows softening (perturbation, adaptive); else the paper's.
            if matches!(a.tangent, TangentKind::SlidingAware | TangentKind::Secant) {
                a.tangent = TangentKind::Paper;
            }
            a.warm_start = false;
            a.relaxation.predictor = Predictor::Affine;
            // Every Gauss point relaxed at every evaluation.
            a.relaxation.skip_below = 0.0;
            a.relaxation.elastic_shortcut = false;
        }
    })
}

/// The sweep: the reference, the job as given, and each speed knob of [`Knob::ALL`] moved
/// alone from the job's setting ([`Knob::moves`]). A job without a DEM material has only the
/// load step and Newton's knobs.
pub fn variants(base: &Job) -> Vec<Variant> {
    let mut v = vec![reference(base), with(base, "default", "as given", |_| {})];
    // A move to a setting the job already has would run the default again at its full cost.
    v.extend(Knob::ALL.into_iter().flat_map(|k| k.moves(base)).filter(|x| x.job != *base));
    v
}

/// Whether `--skip` names the variant: by its knob (`relaxation.driver`) or its knob and
/// setting (`relaxation.driver=fire`).
pub fn skipped(v: &Variant, skip: &[String]) -> bool {
    skip.iter().any(|s| *s == v.knob || *s == format!("{}={}", v.knob, v.setting))
}

/// Moves the knob named `knob` of `job` to `setting` ([`Knob::apply`] of the knob
/// [`Knob::from_name`] finds): a table row's setting applied by name.
pub fn apply_setting(job: &mut Job, knob: &str, setting: &str) -> Result<(), TableError> {
    knob.parse::<Knob>()?.apply(job, setting)
}

#[cfg(test)]
mod tests;
