//! The speed knobs: the settings a sweep moves away from a job's own (the variants and the
//! reference), and the same moves applied by name from a trade table's row.

use crate::table::TableError;
use cosdem_dem::spec::{Driver, PackingSpec, TangentKind};
use cosdem_job::{Job, MaterialSection};

/// One setting of the sweep: a label and the job it produces.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Which knob (`reference`, `default`, `relaxation.tolerance`, ...).
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
pub fn assembly_mut(job: &mut Job) -> Option<&mut cosdem_dem::AssemblySpec> {
    match &mut job.material {
        MaterialSection::Dem { assembly } => Some(assembly),
        MaterialSection::Elastic { .. } => None,
    }
}

fn with(base: &Job, knob: &'static str, setting: impl ToString, f: impl Fn(&mut Job)) -> Variant {
    let mut job = base.clone();
    f(&mut job);
    Variant { knob, setting: setting.to_string(), job }
}

/// The reference: the job's scene with tight settings (relaxation tolerance 1e-5, time-step
/// safety 0.25, no mass scaling, Cundall damping, half the load step, cold starts, no
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
        if let Some(inc) = &mut j.loading.increment {
            *inc *= 0.5;
        } else {
            j.loading.steps *= 2;
        }
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
            // Every Gauss point relaxed at every evaluation.
            a.relaxation.skip_below = 0.0;
            a.relaxation.elastic_shortcut = false;
        }
    })
}

/// The stall limit the sweep tries (`newton.stall_iterations`): past the biaxial example's
/// peak a step's residual that has not fallen for 5 iterations no longer falls
/// (docs/notes/load-step-biaxial.md).
pub const STALL: u32 = 5;

/// The affine jump the sweep tries with `relaxation.substep` (half the paper's 1e-3 strain per
/// load step: on the biaxial example's specimen jumps of 5e-4 and below follow the second
/// softening that 6e-4 and above miss, docs/notes/substep-biaxial.md).
pub const SUBSTEP: f64 = 5e-4;

/// The sweep: the reference, the job as given, and each speed knob moved alone from the job's
/// setting. A DEM job only (an analytical material has no speed knobs but the load step).
pub fn variants(base: &Job) -> Vec<Variant> {
    let mut v = vec![reference(base), with(base, "default", "as given", |_| {})];
    // A move to a setting the job already has would run the default again at its full cost.
    v.extend(knob_moves(base).into_iter().filter(|x| x.job != *base));
    v
}

/// Each speed knob moved alone from the job's setting (some may leave the job unchanged).
fn knob_moves(base: &Job) -> Vec<Variant> {
    let mut v = Vec::new();
    let step = |f: f64| {
        move |j: &mut Job| {
            if let Some(inc) = &mut j.loading.increment {
                *inc *= f;
            } else {
                j.loading.steps = ((j.loading.steps as f64 / f).round() as usize).max(1);
            }
        }
    };
    v.push(with(base, "load_step", "x2", step(2.0)));
    v.push(with(base, "load_step", "x4", step(4.0)));
    // The other way round: half the job's step with the job's relaxation. Against the
    // reference (half the step and a tight relaxation) it tells how much of a row's error is
    // the load path and how much the relaxation: on the biaxial example to 10 mm, seed 7,
    // it is 0.8 % from the reference on F_res where the default is 8.5 %
    // (docs/notes/load-step-biaxial.md).
    v.push(with(base, "load_step", "x0.5", step(0.5)));
    // Newton's iteration matrix: Gauss-point secant updates within a step (solve::secant).
    if !base.newton.secant_updates {
        v.push(with(base, "newton.secant_updates", "true", |j| j.newton.secant_updates = true));
    }
    // An attempt whose best residual is tolerated ends after this many iterations without a
    // new smallest one.
    if base.newton.stall_iterations == 0 {
        v.push(with(base, "newton.stall_iterations", STALL, |j| {
            j.newton.stall_iterations = STALL;
        }));
    }
    let Some(a) = (match &base.material {
        MaterialSection::Dem { assembly } => Some(assembly.clone()),
        MaterialSection::Elastic { .. } => None,
    }) else {
        return v;
    };
    for tol in [1e-3, 3e-4] {
        v.push(with(base, "relaxation.tolerance", format!("{tol:e}"), move |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.tolerance = tol;
            }
        }));
    }
    // Larger time steps than the job's (the default is already 0.8).
    for safety in [0.8, 0.95].into_iter().filter(|s| *s > a.relaxation.safety) {
        v.push(with(base, "relaxation.safety", safety, move |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.safety = safety;
            }
        }));
    }
    for scale in [4.0, 16.0] {
        v.push(with(base, "relaxation.density_scale", scale, move |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.density_scale = scale;
            }
        }));
    }
    v.push(with(base, "relaxation.driver", "fire", |j| {
        if let Some(a) = assembly_mut(j) {
            a.relaxation.driver = Driver::fire();
        }
    }));
    for (name, tangent) in [
        ("paper", TangentKind::Paper),
        ("sliding_aware", TangentKind::SlidingAware),
        ("secant", TangentKind::Secant),
        ("perturbation", TangentKind::Perturbation { strain: 1e-5 }),
    ] {
        if std::mem::discriminant(&tangent) != std::mem::discriminant(&a.tangent) {
            v.push(with(base, "tangent", name, move |j| {
                if let Some(a) = assembly_mut(j) {
                    a.tangent = tangent.clone();
                }
            }));
        }
    }
    v.push(with(base, "warm_start", "true", |j| {
        if let Some(a) = assembly_mut(j) {
            a.warm_start = true;
        }
    }));
    // Item 3's skipping: a point deformed less than the threshold since its last relaxation
    // answers from its tangent (1e-3: a tenth to a half of these scenes' strain per step);
    // the elastic shortcut answers from the tangent while every contact sticks.
    if a.relaxation.skip_below == 0.0 {
        v.push(with(base, "relaxation.skip_below", "1e-3", |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.skip_below = 1e-3;
            }
        }));
    }
    if !a.relaxation.elastic_shortcut {
        v.push(with(base, "relaxation.elastic_shortcut", "true", |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.elastic_shortcut = true;
            }
        }));
    }
    // The other way round: smaller affine jumps cost relaxations and buy the micro path's
    // accuracy (the contact histories are path dependent; docs/notes/substep-biaxial.md).
    if a.relaxation.substep == 0.0 || a.relaxation.substep > SUBSTEP {
        v.push(with(base, "relaxation.substep", format!("{SUBSTEP:e}"), |j| {
            if let Some(a) = assembly_mut(j) {
                a.relaxation.substep = SUBSTEP;
            }
        }));
    }
    if let PackingSpec::Hexagonal { radius, side } = a.packing {
        for f in [0.5, 0.75] {
            let s = (side * f).max(8.0 * radius);
            if s < side {
                v.push(with(base, "assembly.side", format!("{s:.3}"), move |j| {
                    if let Some(a) = assembly_mut(j) {
                        a.packing = PackingSpec::Hexagonal { radius, side: s };
                    }
                }));
            }
        }
    }
    if let PackingSpec::Random { side, r_max, ref radii, .. } = a.packing {
        // The worker refuses a side below four largest diameters.
        let largest = radii.iter().copied().fold(r_max, f64::max);
        for f in [0.5, 0.75] {
            let s = (side * f).max(8.0 * largest);
            if s >= side {
                continue;
            }
            v.push(with(base, "assembly.side", format!("{s:.3}"), move |j| {
                if let Some(a) = assembly_mut(j)
                    && let PackingSpec::Random { side, .. } = &mut a.packing
                {
                    *side = s;
                }
            }));
        }
    }
    v
}

/// Whether `--skip` names the variant: by its knob (`relaxation.driver`) or its knob and
/// setting (`relaxation.driver=fire`).
pub fn skipped(v: &Variant, skip: &[String]) -> bool {
    skip.iter().any(|s| *s == v.knob || *s == format!("{}={}", v.knob, v.setting))
}

/// The Markdown table of a sweep (rows in sweep order; Pareto-front rows marked with `*`).

/// Moves one knob of `job` to a setting of the sweep, named as in the table: `load_step`
/// `x2`/`x4` (any `xF`: the load step times F), `relaxation.tolerance`, `relaxation.safety`,
/// `relaxation.density_scale` (numbers), `relaxation.driver` `fire`/`cundall`, `tangent`
/// `sliding_aware`/`paper`/`secant`/`perturbation` (strain 1e-5), `warm_start` `true`/`false`,
/// `relaxation.skip_below` (a number), `relaxation.elastic_shortcut` `true`/`false`,
/// `relaxation.substep` (a number), `newton.secant_updates` `true`/`false`,
/// `newton.stall_iterations` (a count, 0 = off), `assembly.side` (m). The same moves as [`variants`] (a test checks they agree). An
/// analytical material has only the load step.
pub fn apply_setting(job: &mut Job, knob: &str, setting: &str) -> Result<(), TableError> {
    let unknown =
        || TableError::UnknownSetting { knob: knob.to_string(), setting: setting.to_string() };
    let number = || setting.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0);
    if knob == "load_step" {
        let f = setting.strip_prefix('x').and_then(|f| f.parse::<f64>().ok());
        let f = f.filter(|f| f.is_finite() && *f > 0.0).ok_or_else(unknown)?;
        if let Some(inc) = &mut job.loading.increment {
            *inc *= f;
        } else {
            job.loading.steps = ((job.loading.steps as f64 / f).round() as usize).max(1);
        }
        return Ok(());
    }
    if let ("newton.secant_updates", "true" | "false") = (knob, setting) {
        job.newton.secant_updates = setting == "true";
        return Ok(());
    }
    if knob == "newton.stall_iterations" {
        job.newton.stall_iterations = setting.parse().map_err(|_| unknown())?;
        return Ok(());
    }
    let a = assembly_mut(job).ok_or_else(unknown)?;
    match (knob, setting) {
        ("relaxation.substep", _) => a.relaxation.substep = number().ok_or_else(unknown)?,
        ("relaxation.tolerance", _) => a.relaxation.tolerance = number().ok_or_else(unknown)?,
        ("relaxation.safety", _) => a.relaxation.safety = number().ok_or_else(unknown)?,
        ("relaxation.density_scale", _) => {
            a.relaxation.density_scale = number().ok_or_else(unknown)?;
        }
        ("relaxation.driver", "fire") => a.relaxation.driver = Driver::fire(),
        ("relaxation.driver", "cundall") => a.relaxation.driver = Driver::default(),
        ("tangent", "sliding_aware") => a.tangent = TangentKind::SlidingAware,
        ("tangent", "secant") => a.tangent = TangentKind::Secant,
        ("tangent", "paper") => a.tangent = TangentKind::Paper,
        ("tangent", "perturbation") => a.tangent = TangentKind::Perturbation { strain: 1e-5 },
        ("warm_start", "true") => a.warm_start = true,
        ("relaxation.skip_below", _) => a.relaxation.skip_below = number().ok_or_else(unknown)?,
        ("relaxation.elastic_shortcut", "true") => a.relaxation.elastic_shortcut = true,
        ("relaxation.elastic_shortcut", "false") => a.relaxation.elastic_shortcut = false,
        ("warm_start", "false") => a.warm_start = false,
        ("assembly.side", _) => {
            let s = number().ok_or_else(unknown)?;
            match &mut a.packing {
                PackingSpec::Hexagonal { side, .. } | PackingSpec::Random { side, .. } => {
                    *side = s;
                }
            }
        }
        _ => return Err(unknown()),
    }
    Ok(())
}
