//! Parameter studies over whole two-scale runs: `cosdem study rve-size` (THEORY.md section 4,
//! the paper's Figs. 3-5).
//!
//! The RVE-size study runs the job (scene A) once per assembly size `V`, with the packing's
//! `side = sqrt(V)` (and optionally another disc radius), reads F_u, F_res, E and E50 off
//! each load-displacement curve ([`CurveMetrics`]) and fits the size law of Eqs. 30-32 to
//! each property ([`fit`]). Each run goes through the run driver ([`Run`], without a run
//! directory) and is single-threaded ([`DirectDem`]: the assemblies are solved one after the
//! other on the run's thread), and the runs go side by side on a rayon pool: every figure but
//! the wall time is independent of the thread count.
//!
//! Output (`DIR`): `study.csv` (one row per size), `study.json` (the rows and the fits, for
//! plots of Figs. 4-5), `curves/curve_<V>.csv` (each size's load-displacement curve, Fig. 3).

/// Nonlinear least-squares fit of the size law, with confidence intervals.
pub mod fit;

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::output::{CsvWriter, fmt_f64, write_atomic};
use cosdem_app::run::{HookError, Run, RunError, RunObserver};
use cosdem_dem::PackingSpec;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::post::CurveMetrics;
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::DirectDem;
use fit::{SizeLawFit, fit_size_law};
use rayon::prelude::*;
use serde::Serialize;
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the RVE-size study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct RveSizeSettings {
    /// Assembly sizes V (m^2), each run once.
    pub sizes: Vec<f64>,
    /// Disc radius (m) replacing the job's (hexagonal packings only).
    pub radius: Option<f64>,
    /// Tolerance that defines V^cr (fraction: 0.01 = within 1 % of the representative value).
    pub tolerance: f64,
    /// Runs side by side (0: one per core).
    pub threads: usize,
    /// Read a size's curve from `curves/curve_<V>.csv` when that file exists instead of
    /// running it again ([`reused_size`]).
    pub reuse: bool,
}

impl Default for RveSizeSettings {
    fn default() -> Self {
        Self { sizes: Vec::new(), radius: None, tolerance: 0.01, threads: 0, reuse: false }
    }
}

/// One run of the study.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct SizeRun {
    /// Assembly size V (m^2).
    pub size: f64,
    /// Packing side sqrt(V) (m).
    pub side: f64,
    /// Disc radius (m) (the largest for random packings).
    pub radius: f64,
    /// Discs per assembly.
    pub discs: usize,
    /// Converged load steps.
    pub steps: u64,
    /// F_u, F_res, E, E50 of the curve.
    pub metrics: CurveMetrics,
    /// DEM steps of all accepted relaxations.
    pub dem_steps: u64,
    /// Wall time of the run (s); not deterministic.
    pub wall_seconds: f64,
    /// `finished`, or `failed: <reason>` (the metrics are then those of the finished steps).
    pub status: String,
}

/// The fit of one property, or why there is none.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(untagged)]
pub enum FitOutcome {
    /// The fitted law.
    Fitted(Box<SizeLawFit>),
    /// Why no fit.
    Failed {
        /// The reason.
        error: String,
    },
}

/// The whole study (also `study.json`).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct RveSizeStudy {
    /// Tolerance defining V^cr.
    pub tolerance: f64,
    /// One run per size, in the order of the sizes.
    pub runs: Vec<SizeRun>,
    /// Eq. 30: F_u (k = 2).
    pub peak_load: FitOutcome,
    /// Eq. 31: F_res (k = 3).
    pub residual_load: FitOutcome,
    /// Eq. 32: E, the slope in the linear range (k = 1).
    pub stiffness: FitOutcome,
    /// Eq. 32 with the Fig. 5 stiffness E50 (k = 1).
    pub stiffness_50: FitOutcome,
}

/// The job with the assembly size `size` (and radius).
pub fn job_for_size(job: &Job, size: f64, radius: Option<f64>) -> Result<Job> {
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::InvalidSetting {
            field: "sizes",
            value: size.to_string(),
            reason: "every size must be finite and > 0 (m^2)".into(),
        });
    }
    let mut job = job.clone();
    let MaterialSection::Dem { assembly } = &mut job.material else {
        return Err(Error::InvalidSetting {
            field: "material.kind",
            value: "elastic".into(),
            reason: "the RVE-size study needs kind = \"dem\"".into(),
        });
    };
    let side = size.sqrt();
    match &mut assembly.packing {
        PackingSpec::Hexagonal { radius: r, side: s, .. } => {
            *s = side;
            if let Some(new) = radius {
                *r = new;
            }
        }
        PackingSpec::Random { side: s, .. } => {
            if let Some(new) = radius {
                return Err(Error::InvalidSetting {
                    field: "radius",
                    value: new.to_string(),
                    reason: "only for hexagonal packings (a random packing has r_min, r_max)"
                        .into(),
                });
            }
            *s = side;
        }
        PackingSpec::Explicit { .. } | PackingSpec::File { .. } => {
            return Err(Error::InvalidSetting {
                field: "material.assembly.packing.kind",
                value: assembly.packing.kind().into(),
                reason: "the RVE-size study varies the side of a generated packing (hexagonal \
                         or random); an explicit packing has a given size"
                    .into(),
            });
        }
    }
    job.validate()?;
    Ok(job)
}

/// Collects the curve of one run and writes it (`curves/curve_<V>.csv`, opened when the
/// first step is about to be solved).
struct Curve<'p> {
    shortening: f64,
    /// Reaction multiplier of a symmetric mesh (2 for a half or quarter: the reaction of the
    /// kept part of `load_set` is half the platen force).
    load_scale: f64,
    load_set: String,
    points: Vec<(f64, f64)>,
    dem_steps: u64,
    path: Option<&'p Path>,
    csv: Option<CsvWriter>,
}

impl RunObserver for Curve<'_> {
    fn on_start(&mut self) -> std::result::Result<(), HookError> {
        if let Some(p) = self.path {
            let csv = CsvWriter::create(p, &["step", "displacement", "load", "dem_steps"])
                .map_err(|e| Error::Observer(e.to_string()))?;
            self.csv = Some(csv);
        }
        Ok(())
    }

    fn on_step(
        &mut self,
        r: &StepReport,
        view: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> Result<()> {
        let d = r.load_factor * self.shortening;
        let load = -self.load_scale * r.reactions.get(&self.load_set).map_or(0.0, |x| x[1]);
        let dem: u64 = view.gauss_points.iter().map(|g| g.diagnostics.steps).sum();
        self.dem_steps += dem;
        self.points.push((d, load));
        if let Some(csv) = &mut self.csv {
            csv.write_row(&[r.step as f64, d, load, dem as f64])
                .map_err(|e| Error::Observer(e.to_string()))?;
        }
        Ok(())
    }
}

/// The solver's error behind a run driver's error (the error of a hook of [`Curve`] included).
fn solver_error(e: RunError) -> Error {
    match e {
        RunError::Solver(e) => e,
        RunError::Observer(e) => match e.downcast::<Error>() {
            Ok(e) => *e,
            Err(e) => Error::Observer(e.to_string()),
        },
        other => Error::Observer(other.to_string()),
    }
}

/// The disc radius of a hexagonal packing, the largest of a random one.
fn largest_radius(packing: &PackingSpec) -> f64 {
    packing.largest_radius()
}

/// Runs the job at one size; `curve` is where its curve is written (if any).
pub fn run_size(
    job: &Job,
    size: f64,
    settings: &RveSizeSettings,
    curve: Option<&Path>,
) -> Result<SizeRun> {
    let t0 = Instant::now();
    let mut job = job_for_size(job, size, settings.radius)?;
    // The study sets the assembly size itself: an accuracy target, which would pick one, is
    // not planned.
    job.accuracy = None;
    let MaterialSection::Dem { assembly } = &job.material else { unreachable!("checked") };
    let radius = largest_radius(&assembly.packing);
    let mut obs = Curve {
        shortening: job.shortening(),
        load_scale: job.load_scale(),
        load_set: job.loading.load_set.clone(),
        points: Vec::new(),
        dem_steps: 0,
        path: curve,
        csv: None,
    };
    let discs = Cell::new(0);
    let outcome = Run::without_dir(&job)
        .material(|ids| {
            let m = DirectDem::new(assembly, ids).map_err(Error::from)?;
            discs.set(m.disc_count());
            Ok(Box::new(m))
        })
        .observer(&mut obs)
        .execute()
        .map_err(solver_error)?;
    Ok(SizeRun {
        size,
        side: size.sqrt(),
        radius,
        discs: discs.get(),
        steps: obs.points.len() as u64,
        metrics: CurveMetrics::from_curve(&obs.points, job.output.linear_range),
        // The failed attempts of a step that ended the run cost DEM steps too.
        dem_steps: obs.dem_steps + outcome.uncommitted_dem_steps,
        wall_seconds: t0.elapsed().as_secs_f64(),
        status: outcome.ending.status(),
    })
}

/// The run of size `size` rebuilt from its curve file `curve` (columns `step, displacement,
/// load, dem_steps`, as [`run_size`] writes them): the metrics and DEM steps from the curve,
/// the disc count from the packing; status `finished` when the curve reaches the job's
/// displacement, else `incomplete: ...`. The wall time of a reused run is unknown (0).
pub fn reused_size(
    job: &Job,
    size: f64,
    settings: &RveSizeSettings,
    curve: &Path,
) -> Result<SizeRun> {
    let job = job_for_size(job, size, settings.radius)?;
    let MaterialSection::Dem { assembly } = &job.material else { unreachable!("checked") };
    let bad = |m: String| Error::Observer(format!("{}: {m}", curve.display()));
    let text = std::fs::read_to_string(curve).map_err(|e| bad(e.to_string()))?;
    let (mut points, mut dem_steps) = (Vec::new(), 0u64);
    for (i, line) in text.lines().enumerate().skip(1).filter(|(_, l)| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').collect();
        let num = |c: usize| cells.get(c).and_then(|v| v.trim().parse::<f64>().ok());
        match (num(1), num(2), num(3)) {
            (Some(d), Some(f), Some(n)) => {
                points.push((d, f));
                dem_steps += n as u64;
            }
            _ => {
                return Err(bad(format!(
                    "line {}: expected step,displacement,load,dem_steps",
                    i + 1
                )));
            }
        }
    }
    let reached = points.last().map_or(0.0, |p| p.0);
    let target = job.shortening();
    let status = if reached >= target * (1.0 - 1e-9) {
        "finished".to_string()
    } else {
        format!("incomplete: the reused curve ends at {reached} m of {target} m")
    };
    let radius = largest_radius(&assembly.packing);
    let discs =
        cosdem_dem::Assembly::new(assembly).map_err(|e| bad(format!("packing: {e}")))?.disc_count();
    Ok(SizeRun {
        size,
        side: size.sqrt(),
        radius,
        discs,
        steps: points.len() as u64,
        metrics: CurveMetrics::from_curve(&points, job.output.linear_range),
        dem_steps,
        wall_seconds: 0.0,
        status,
    })
}

fn fit_of(
    runs: &[SizeRun],
    value: impl Fn(&CurveMetrics) -> Option<f64>,
    k: i32,
    tol: f64,
) -> FitOutcome {
    let (v, f): (Vec<f64>, Vec<f64>) =
        runs.iter().filter_map(|r| value(&r.metrics).map(|x| (r.size, x))).unzip();
    match fit_size_law(&v, &f, k, tol) {
        Ok(fit) => FitOutcome::Fitted(Box::new(fit)),
        Err(e) => FitOutcome::Failed { error: e.to_string() },
    }
}

/// Fits Eqs. 30-32 to finished runs.
pub fn fit_runs(runs: Vec<SizeRun>, tolerance: f64) -> RveSizeStudy {
    let peak = |m: &CurveMetrics| (m.peak_load > 0.0).then_some(m.peak_load);
    RveSizeStudy {
        tolerance,
        peak_load: fit_of(&runs, peak, 2, tolerance),
        residual_load: fit_of(&runs, |m| m.residual_load, 3, tolerance),
        stiffness: fit_of(&runs, |m| m.stiffness, 1, tolerance),
        stiffness_50: fit_of(&runs, |m| m.stiffness_50, 1, tolerance),
        runs,
    }
}

/// Runs the whole study and writes `study.csv`, `study.json` and the curves into `dir`.
pub fn rve_size(job: &Job, settings: &RveSizeSettings, dir: &Path) -> Result<RveSizeStudy> {
    if settings.sizes.is_empty() {
        return Err(Error::InvalidSetting {
            field: "sizes",
            value: "[]".into(),
            reason: "give at least one size (at least 3 to fit)".into(),
        });
    }
    if !(settings.tolerance > 0.0 && settings.tolerance < 1.0) {
        return Err(Error::InvalidSetting {
            field: "tolerance",
            value: settings.tolerance.to_string(),
            reason: "must be in (0, 1)".into(),
        });
    }
    for &v in &settings.sizes {
        job_for_size(job, v, settings.radius)?;
    }
    let curves = dir.join("curves");
    std::fs::create_dir_all(&curves)
        .map_err(|e| Error::Observer(format!("{}: {e}", curves.display())))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(settings.threads)
        .build()
        .map_err(|e| Error::Observer(format!("thread pool: {e}")))?;
    let runs: Vec<Result<SizeRun>> = pool.install(|| {
        settings
            .sizes
            .par_iter()
            .map(|&v| {
                let path: PathBuf = curves.join(format!("curve_{}.csv", fmt_f64(v)));
                if settings.reuse && path.is_file() {
                    reused_size(job, v, settings, &path)
                } else {
                    run_size(job, v, settings, Some(&path))
                }
            })
            .collect()
    });
    let runs = runs.into_iter().collect::<Result<Vec<_>>>()?;
    let study = fit_runs(runs, settings.tolerance);
    write_study(&study, dir)?;
    let sizes: Vec<String> = settings.sizes.iter().map(|v| fmt_f64(*v)).collect();
    let source = format!("cosdem study rve-size ({}) --sizes {}", job.title, sizes.join(","));
    if let Some(fit) = size_fit(&study, job, source) {
        let json =
            serde_json::to_string_pretty(&fit).map_err(|e| Error::Observer(e.to_string()))?;
        let path = dir.join(SIZE_FIT_FILE);
        write_atomic(&path, format!("{json}\n").as_bytes())
            .map_err(|e| Error::Observer(format!("{}: {e}", path.display())))?;
    }
    for (figure, e) in plot_study(&study, dir, &job.title) {
        tracing::warn!(figure, error = %e, "study figure not drawn");
    }
    Ok(study)
}

/// One figure of [`plot_study`]: file stem, name, unit, fit, and the value of a run.
type Property<'a> = (&'a str, &'a str, &'a str, &'a FitOutcome, fn(&CurveMetrics) -> Option<f64>);

/// Draws the study's figures into `dir/plots/`: `curves.png` (every size's load-displacement
/// curve, Fig. 3) and `size_<property>.png` (F_u, F_res, E, E50 against V with the fitted law,
/// Figs. 4-5), each with its SVG beside it (same name). Returns the figures that could not be
/// drawn (a property without values, e.g. no F_res before a peak) with why; none of them
/// stops the study.
pub fn plot_study(
    study: &RveSizeStudy,
    dir: &Path,
    title: &str,
) -> Vec<(String, cosdem_app::output::plot::PlotError)> {
    use crate::plot::rve_size::{plot_size_law, plot_study_curves};
    use cosdem_app::output::plot::{PlotError, curve::read_curve};
    let plots = dir.join("plots");
    let mut failed = Vec::new();
    if let Err(e) = std::fs::create_dir_all(&plots) {
        let err = PlotError::NoData { path: plots.clone(), message: e.to_string() };
        return vec![("plots".into(), err)];
    }
    let mut curves = Vec::new();
    for r in &study.runs {
        let path = dir.join("curves").join(format!("curve_{}.csv", fmt_f64(r.size)));
        match read_curve(&path) {
            Ok(c) => curves.push((r.size, c)),
            Err(e) => failed.push((path.display().to_string(), e)),
        }
    }
    if let Err(e) = plot_study_curves(&curves, title, &plots.join("curves.png")) {
        failed.push(("curves.png".into(), e));
    }
    let properties: [Property<'_>; 4] = [
        ("peak_load", "F_u", "N/m", &study.peak_load, |m| {
            (m.peak_load > 0.0).then_some(m.peak_load)
        }),
        ("residual_load", "F_res", "N/m", &study.residual_load, |m| m.residual_load),
        ("stiffness", "E", "N/m per m", &study.stiffness, |m| m.stiffness),
        ("stiffness_50", "E50", "N/m per m", &study.stiffness_50, |m| m.stiffness_50),
    ];
    for (file, name, unit, fit, value) in properties {
        let points: Vec<(f64, f64)> =
            study.runs.iter().filter_map(|r| value(&r.metrics).map(|x| (r.size, x))).collect();
        let fit = match fit {
            FitOutcome::Fitted(f) => Some(f.as_ref()),
            FitOutcome::Failed { .. } => None,
        };
        let figure = format!("size_{file}.png");
        if let Err(e) = plot_size_law(&points, fit, name, unit, &plots.join(&figure)) {
            failed.push((figure, e));
        }
    }
    failed
}

/// The file of [`size_fit`] in a study's directory.
pub const SIZE_FIT_FILE: &str = "size-fit.json";

/// The study's fits in the form an accuracy target reads them ([`cosdem_tune::accuracy::SizeFit`],
/// committed under `docs/` and listed in [`cosdem_tune::accuracy::SIZE_FITS`]): per fitted
/// property its `k`, `a`, `b*` and the upper end of `b*`'s 95 % interval, with the job's
/// assembly and the sizes run. `None` for a job without a DEM material.
pub fn size_fit(
    study: &RveSizeStudy,
    job: &Job,
    source: String,
) -> Option<cosdem_tune::accuracy::SizeFit> {
    use cosdem_tune::accuracy::{LawParams, SizeFit};
    let MaterialSection::Dem { assembly } = &job.material else { return None };
    let law = |f: &FitOutcome| match f {
        FitOutcome::Fitted(f) => Some(LawParams {
            k: f.k,
            a: f.a.value,
            b_star: f.b_star.value,
            b_star_high: f.b_star.high,
        }),
        FitOutcome::Failed { .. } => None,
    };
    Some(SizeFit {
        source,
        assembly: (**assembly).clone(),
        sizes: study.runs.iter().map(|r| r.size).collect(),
        peak_load: law(&study.peak_load),
        residual_load: law(&study.residual_load),
        stiffness: law(&study.stiffness),
    })
}

/// Reads a study's `study.json` back (for redrawing its figures).
pub fn read_study(dir: &Path) -> Result<RveSizeStudy> {
    let path = dir.join("study.json");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| Error::Observer(format!("{}: {e}", path.display())))?;
    serde_json::from_str(&text).map_err(|e| Error::Observer(format!("{}: {e}", path.display())))
}

/// Writes `study.csv` and `study.json`.
pub fn write_study(study: &RveSizeStudy, dir: &Path) -> Result<()> {
    let opt = |x: Option<f64>| x.map_or(String::new(), fmt_f64);
    let mut csv = String::from(
        "size,side,radius,discs,steps,peak_load,peak_displacement,residual_load,stiffness,\
         stiffness_50,dem_steps,wall_seconds,status\n",
    );
    for r in &study.runs {
        let m = &r.metrics;
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"\n",
            fmt_f64(r.size),
            fmt_f64(r.side),
            fmt_f64(r.radius),
            r.discs,
            r.steps,
            fmt_f64(m.peak_load),
            fmt_f64(m.peak_displacement),
            opt(m.residual_load),
            opt(m.stiffness),
            opt(m.stiffness_50),
            r.dem_steps,
            fmt_f64(r.wall_seconds),
            r.status.replace('"', "\"\"")
        ));
    }
    let io = |e: cosdem_app::output::OutputError| Error::Observer(e.to_string());
    write_atomic(&dir.join("study.csv"), csv.as_bytes()).map_err(io)?;
    let json = serde_json::to_string_pretty(study).map_err(|e| Error::Observer(e.to_string()))?;
    write_atomic(&dir.join("study.json"), format!("{json}\n").as_bytes()).map_err(io)
}

#[cfg(test)]
mod tests;
