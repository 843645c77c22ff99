//! Speed against accuracy, measured: `cosdem bench tradeoff JOB`.
//!
//! Every knob that buys speed is swept one at a time away from the job's own settings (the
//! "default" row), and every run is compared with a reference run of the same scene with
//! tight settings. The comparison uses what a user reads off the curve (F_u, F_res, E; see
//! [`crate::post::CurveMetrics`]) and the whole load-displacement curve (relative L2 over the
//! displacement range both runs reached). The sweep writes one run directory per variant, a
//! CSV and a Markdown table; the table is what `docs/tradeoff-*.md` commits.
//!
//! The pure parts (variants, errors, Pareto front, table) are separate from the runs so they
//! are tested without running anything.

use crate::job::{Job, MaterialSection};
use crate::post::CurveMetrics;
use cosdem_worker::spec::{Driver, PackingSpec, TangentKind};
use serde::Serialize;

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
        format!("{}_{}", self.knob, self.setting)
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' })
            .collect()
    }
}

/// The result of one variant, compared with the reference.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Knob name.
    pub knob: String,
    /// Knob setting.
    pub setting: String,
    /// `finished` or the reason the run stopped.
    pub status: String,
    /// Displacement reached (m).
    pub displacement: f64,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// DEM steps of the converged evaluations.
    pub dem_steps: u64,
    /// Step cuts.
    pub cuts: u64,
    /// F_u, F_res, E, E50 of this run.
    pub metrics: CurveMetrics,
    /// Relative errors against the reference: F_u, F_res, E, curve (relative L2).
    pub errors: Errors,
    /// Reference wall time / this wall time.
    pub speedup: f64,
}

/// Relative errors of one run against the reference (`None` when either run lacks the value,
/// e.g. a run that stopped before the peak has no F_res).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Errors {
    /// |F_u - F_u,ref| / F_u,ref.
    pub peak: Option<f64>,
    /// |F_res - F_res,ref| / F_res,ref.
    pub residual: Option<f64>,
    /// |E - E_ref| / E_ref.
    pub stiffness: Option<f64>,
    /// Relative L2 distance of the curves (see [`curve_error`]).
    pub curve: Option<f64>,
}

impl Errors {
    /// The largest of the four, `None` if any is missing (an unknown error is not small).
    pub fn worst(&self) -> Option<f64> {
        let all = [self.peak, self.residual, self.stiffness, self.curve];
        all.iter().try_fold(0.0f64, |m, e| e.map(|e| m.max(e)))
    }

    /// The largest of F_u, F_res and E (the accuracy promise), `None` if any is missing.
    pub fn worst_property(&self) -> Option<f64> {
        let all = [self.peak, self.residual, self.stiffness];
        all.iter().try_fold(0.0f64, |m, e| e.map(|e| m.max(e)))
    }
}

fn relative(value: Option<f64>, reference: Option<f64>) -> Option<f64> {
    match (value, reference) {
        (Some(v), Some(r)) if r != 0.0 && v.is_finite() && r.is_finite() => {
            Some((v - r).abs() / r.abs())
        }
        _ => None,
    }
}

/// Linear interpolation of a curve sorted by displacement; `None` outside its range.
fn interpolate(curve: &[(f64, f64)], d: f64) -> Option<f64> {
    let first = curve.first()?;
    if d < first.0 {
        // Every curve starts at (0, 0) before its first step.
        return (d >= 0.0).then(|| first.1 * d / first.0.max(f64::MIN_POSITIVE));
    }
    let i = curve.partition_point(|p| p.0 < d);
    if i == curve.len() {
        return None;
    }
    let (d1, f1) = curve[i];
    if i == 0 || d1 == d {
        return Some(f1);
    }
    let (d0, f0) = curve[i - 1];
    Some(f0 + (f1 - f0) * (d - d0) / (d1 - d0))
}

/// Relative L2 distance of `curve` from `reference` over the reference's points that both
/// reached: `sqrt(sum (F - F_ref)^2 / sum F_ref^2)`, with `F` linearly interpolated at the
/// reference's displacements (the two runs need not take the same steps). `None` if they
/// share no point.
pub fn curve_error(reference: &[(f64, f64)], curve: &[(f64, f64)]) -> Option<f64> {
    let (mut num, mut den, mut n) = (0.0, 0.0, 0usize);
    for &(d, fr) in reference {
        if let Some(f) = interpolate(curve, d) {
            num += (f - fr) * (f - fr);
            den += fr * fr;
            n += 1;
        }
    }
    (n > 0 && den > 0.0).then(|| (num / den).sqrt())
}

/// The errors of a run's metrics and curve against the reference's.
pub fn compare(
    reference: (&CurveMetrics, &[(f64, f64)]),
    run: (&CurveMetrics, &[(f64, f64)]),
) -> Errors {
    let (rm, rc) = reference;
    let (m, c) = run;
    Errors {
        peak: relative(Some(m.peak_load), Some(rm.peak_load)),
        residual: relative(m.residual_load, rm.residual_load),
        stiffness: relative(m.stiffness, rm.stiffness),
        curve: curve_error(rc, c),
    }
}

/// Indices of the rows on the Pareto front of (wall time, worst error): no other row is both
/// faster and more accurate. Rows without a worst error are never on the front.
pub fn pareto_front(rows: &[Row]) -> Vec<usize> {
    let key = |r: &Row| r.errors.worst().map(|e| (r.wall_seconds, e));
    let mut front = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let Some((t, e)) = key(r) else { continue };
        let dominated = rows.iter().enumerate().any(|(j, o)| {
            j != i && key(o).is_some_and(|(to, eo)| to <= t && eo <= e && (to < t || eo < e))
        });
        if !dominated {
            front.push(i);
        }
    }
    front
}

fn assembly_mut(job: &mut Job) -> Option<&mut cosdem_worker::AssemblySpec> {
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
/// safety 0.25, no mass scaling, Cundall damping, the perturbation tangent, half the load
/// step, cold starts). The tangent does not change a converged answer, only whether and how
/// fast Newton gets there; the perturbation tangent is the one that converges past a peak
/// (the paper tangent stays elastic while the assemblies soften and Newton stalls). It is the
/// yardstick of every other row, not a claim of exactness: its own distance from the
/// converged answer is what its settings leave (the sweep shows the trend).
pub fn reference(base: &Job) -> Variant {
    with(base, "reference", "tight", |j| {
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
            a.tangent = TangentKind::Perturbation { strain: 1e-5 };
            a.warm_start = false;
        }
    })
}

/// The sweep: the reference, the job as given, and each speed knob moved alone from the job's
/// setting. A DEM job only (an analytical material has no speed knobs but the load step).
pub fn variants(base: &Job) -> Vec<Variant> {
    let mut v = vec![reference(base), with(base, "default", "as given", |_| {})];
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
    for safety in [0.8, 0.95] {
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
    if let PackingSpec::Random { side, .. } = a.packing {
        for f in [0.5, 0.75] {
            let s = side * f;
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

fn pct(e: Option<f64>) -> String {
    e.map_or("-".into(), |e| format!("{:.2} %", 100.0 * e))
}

/// The Markdown table of a sweep (rows in sweep order; Pareto-front rows marked with `*`).
pub fn markdown(title: &str, rows: &[Row]) -> String {
    let front = pareto_front(rows);
    let mut s = format!(
        "# {title}\n\n| knob | setting | status | wall (s) | speedup | DEM steps | F_u err | \
         F_res err | E err | curve L2 | Pareto |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|:-:|\n"
    );
    for (i, r) in rows.iter().enumerate() {
        s.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.2}x | {} | {} | {} | {} | {} | {} |\n",
            r.knob,
            r.setting,
            r.status,
            r.wall_seconds,
            r.speedup,
            r.dem_steps,
            pct(r.errors.peak),
            pct(r.errors.residual),
            pct(r.errors.stiffness),
            pct(r.errors.curve),
            if front.contains(&i) { "*" } else { "" }
        ));
    }
    s
}

/// The CSV of a sweep (one header, one line per row).
pub fn csv(rows: &[Row]) -> String {
    let f = |e: Option<f64>| e.map_or(String::new(), |e| format!("{e:.6e}"));
    let g = |e: Option<f64>| e.map_or(String::new(), |e| format!("{e:.6e}"));
    let mut s = String::from(
        "knob,setting,status,displacement,wall_seconds,speedup,dem_steps,cuts,peak_load,\
         residual_load,stiffness,err_peak,err_residual,err_stiffness,err_curve\n",
    );
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{:.6e},{:.3},{:.3},{},{},{:.6e},{},{},{},{},{},{}\n",
            r.knob,
            r.setting,
            r.status.replace(',', ";"),
            r.displacement,
            r.wall_seconds,
            r.speedup,
            r.dem_steps,
            r.cuts,
            r.metrics.peak_load,
            g(r.metrics.residual_load),
            g(r.metrics.stiffness),
            f(r.errors.peak),
            f(r.errors.residual),
            f(r.errors.stiffness),
            f(r.errors.curve),
        ));
    }
    s
}

/// Runs the sweep of `base` into `out` (one run directory per variant under `out/runs/`),
/// rewriting `out/tradeoff.csv` and `out/tradeoff.md` after every run so a long sweep can be
/// read as it goes. `progress` hears each finished row. The reference runs first.
pub fn sweep(
    base: &Job,
    title: &str,
    out: &std::path::Path,
    workers: &crate::run::WorkerChoice,
    mut progress: impl FnMut(&Row),
) -> Result<Vec<Row>, crate::run::RunError> {
    let variants = variants(base);
    let mut rows: Vec<Row> = Vec::new();
    // The reference's metrics, curve and wall time (the first run).
    type Reference = (CurveMetrics, Vec<(f64, f64)>, f64);
    let mut reference: Option<Reference> = None;
    for v in &variants {
        let dir = out.join("runs").join(v.slug());
        let (summary, curve) = crate::run::run_job(&v.job, &dir, workers)?;
        let (rm, rc, rt) =
            reference.get_or_insert_with(|| (summary.metrics, curve.clone(), summary.wall_seconds));
        let row = Row {
            knob: v.knob.to_string(),
            setting: v.setting.clone(),
            status: summary.status.clone(),
            displacement: summary.displacement,
            wall_seconds: summary.wall_seconds,
            dem_steps: summary.dem_steps,
            cuts: summary.cuts,
            metrics: summary.metrics,
            errors: compare((rm, rc), (&summary.metrics, &curve)),
            speedup: *rt / summary.wall_seconds.max(1e-9),
        };
        progress(&row);
        rows.push(row);
        let write = |name: &str, text: String| {
            let path = out.join(name);
            crate::output::write_atomic(&path, text.as_bytes())
        };
        write("tradeoff.csv", csv(&rows))?;
        write("tradeoff.md", markdown(title, &rows))?;
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve compared with itself has zero error; a curve scaled by (1 + a) has relative
    /// L2 error exactly a (up to round-off), whatever the steps it was sampled at.
    #[test]
    fn curve_error_of_a_scaled_curve_is_the_scale() {
        let reference: Vec<(f64, f64)> =
            (1..=40).map(|i| (0.001 * i as f64, (0.001 * i as f64 * 300.0).sin())).collect();
        assert_eq!(curve_error(&reference, &reference), Some(0.0));
        // The same function on a coarser grid is exact only at shared points; use a linear
        // function so interpolation is exact, scaled by 1.03.
        let lin: Vec<(f64, f64)> = (1..=40).map(|i| (0.001 * i as f64, 5.0 * i as f64)).collect();
        let coarse: Vec<(f64, f64)> =
            (1..=20).map(|i| (0.002 * i as f64, 1.03 * 10.0 * i as f64)).collect();
        let e = curve_error(&lin, &coarse).unwrap();
        assert!((e - 0.03).abs() < 1e-12, "{e}");
        // A run that stopped halfway is compared on what it reached.
        let half: Vec<(f64, f64)> = lin[..20].to_vec();
        assert_eq!(curve_error(&lin, &half), Some(0.0));
        assert_eq!(curve_error(&lin, &[]), None);
    }

    fn row(t: f64, e: f64) -> Row {
        Row {
            knob: "k".into(),
            setting: format!("{t}"),
            status: "finished".into(),
            displacement: 0.0,
            wall_seconds: t,
            dem_steps: 0,
            cuts: 0,
            metrics: CurveMetrics::default(),
            errors: Errors { peak: Some(e), residual: Some(e), stiffness: Some(e), curve: Some(e) },
            speedup: 1.0,
        }
    }

    /// The front keeps the rows no other row beats on both time and error.
    #[test]
    fn pareto_front_drops_dominated_rows() {
        let rows = vec![row(10.0, 0.0), row(5.0, 0.02), row(6.0, 0.03), row(1.0, 0.2)];
        assert_eq!(pareto_front(&rows), vec![0, 1, 3]);
        let mut missing = row(0.5, 0.0);
        missing.errors.residual = None;
        let rows = vec![row(10.0, 0.0), missing];
        assert_eq!(pareto_front(&rows), vec![0]);
    }

    /// Metric errors are relative and missing values stay missing.
    #[test]
    fn compare_metrics() {
        let r = CurveMetrics {
            peak_load: 100.0,
            peak_displacement: 0.1,
            residual_load: Some(50.0),
            stiffness: Some(1e4),
            stiffness_50: None,
        };
        let m = CurveMetrics { peak_load: 95.0, residual_load: None, stiffness: Some(1.1e4), ..r };
        let e = compare((&r, &[]), (&m, &[]));
        assert!((e.peak.unwrap() - 0.05).abs() < 1e-15);
        assert_eq!(e.residual, None);
        assert!((e.stiffness.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(e.worst(), None);
    }

    /// The sweep of a DEM job moves one knob at a time and keeps the scene.
    #[test]
    fn variants_move_one_knob() {
        let job = Job::from_toml(include_str!("../../examples/quick.toml"), "examples/quick.toml")
            .unwrap();
        let v = variants(&job);
        assert_eq!(v[0].knob, "reference");
        assert_eq!(v[1].job, job);
        let knobs: std::collections::BTreeSet<_> = v.iter().map(|v| v.knob).collect();
        for k in [
            "load_step",
            "relaxation.tolerance",
            "relaxation.safety",
            "relaxation.density_scale",
            "relaxation.driver",
            "tangent",
            "warm_start",
            "assembly.side",
        ] {
            assert!(knobs.contains(k), "{k} missing");
        }
        for x in &v[2..] {
            assert_eq!(x.job.mesh, job.mesh, "{}", x.slug());
            assert_ne!(x.job, job, "{} changes nothing", x.slug());
        }
        let slugs: std::collections::BTreeSet<_> = v.iter().map(Variant::slug).collect();
        assert_eq!(slugs.len(), v.len(), "slugs must be unique (run directories)");
    }
}
