//! Speed against accuracy, measured: `cosdem bench tradeoff JOB`.
//!
//! Every knob that buys speed is swept one at a time away from the job's own settings (the
//! "default" row, see [`cosdem_tune::knob`]), and every run is compared with a reference run
//! of the same scene with tight settings ([`cosdem_tune::table`]). The sweep writes one run
//! directory per variant, a CSV and a Markdown table and the Pareto plot.

use crate::plot::pareto::{ParetoPanel, ParetoPoint, PointRole, plot_pareto};
use cosdem_app::output::plot::Result as PlotResult;
use cosdem_fem::post::CurveMetrics;
use cosdem_job::{Job, MaterialSection};
pub use cosdem_tune::knob::*;
pub use cosdem_tune::table::*;

/// The role of a row in the plot.
fn role(r: &Row) -> PointRole {
    match r.knob.as_str() {
        "reference" => PointRole::Reference,
        "default" => PointRole::Default,
        _ if !finished(r) => PointRole::Failed,
        _ => PointRole::Other,
    }
}

/// The label of a row in the plot (`tolerance=1e-3`: the `relaxation.` prefix dropped).
fn point_label(r: &Row) -> String {
    let failed = if finished(r) { "" } else { " (failed)" };
    match r.knob.as_str() {
        "reference" => "reference (tight)".into(),
        "default" => "default (job as given)".into(),
        // Combinations name their knobs in the table; the plot says only what they are.
        "cheapest" => format!("cheapest set{failed}"),
        "accuracy" => {
            let target = r.setting.split(':').next().unwrap_or("");
            format!("accuracy {target} pick{failed}")
        }
        // A specimen-averaged row that the sweeps named differently
        // (`cheapest / accuracy 0.2`, see `crate::specimens`).
        k if k.contains(" / ") => {
            let names: Vec<String> = k
                .split(" / ")
                .map(|n| match n {
                    "cheapest" => "cheapest set".into(),
                    n if n.starts_with("accuracy ") => format!("{n} pick"),
                    n => n.into(),
                })
                .collect();
            format!("{}{failed}", names.join(" / "))
        }
        k => {
            let k = k.strip_prefix("relaxation.").unwrap_or(k);
            format!("{k}={}{failed}", r.setting)
        }
    }
}

/// The Pareto plot's panels of a sweep: worst error (see [`Errors::worst_present`]) against
/// wall time, and against DEM steps (left out when no row has any, e.g. an elastic job).
pub fn pareto_panels(rows: &[Row]) -> Vec<ParetoPanel> {
    let panel = |x_label: &str, cost: &dyn Fn(&Row) -> f64| ParetoPanel {
        x_label: x_label.to_string(),
        points: rows
            .iter()
            .map(|r| ParetoPoint {
                label: point_label(r),
                x: cost(r),
                error: r.errors.worst_present(),
                role: role(r),
            })
            .collect(),
        front: pareto_front_by(rows, cost),
    };
    let mut panels = vec![panel("Wall time (s)", &|r: &Row| r.wall_seconds)];
    if rows.iter().any(|r| r.dem_steps > 0) {
        panels.push(panel("DEM steps", &|r: &Row| r.dem_steps as f64));
    }
    panels
}

/// Draws the Pareto plot of a sweep (see [`pareto_panels`]) into `path` (PNG) and the SVG
/// beside it (same name).
pub fn write_pareto(rows: &[Row], title: &str, path: &std::path::Path) -> PlotResult<()> {
    plot_pareto(&pareto_panels(rows), title, path)
}

/// The Pareto plot's file name in a sweep's directory (its SVG: `pareto.svg`).
pub const PARETO_FILE: &str = "pareto.png";

/// Runs the sweep of `base` into `out` (one run directory per variant under `out/runs/`),
/// rewriting `out/tradeoff.csv`, `out/tradeoff.md` and `out/pareto.png` (and `.svg`) after
/// every run so a long sweep can be read as it goes. `progress` hears each finished row. The
/// reference runs first. The job's `accuracy` key, if any, is dropped: it would move the very
/// knobs the sweep measures.
///
/// After the one-knob rows, a DEM job gets the rows that move several knobs at once, planned
/// from this sweep's own rows by [`cosdem_tune::accuracy`]: `accuracy` 0.05, 0.1 and 0.2 (what
/// those targets pick: the measured check of the prediction) and `cheapest` (every knob at
/// its cheapest candidate setting, whatever the predicted error: where the knobs end). A
/// combination that moves no knob, or the same knobs as an earlier one, is not run again.
///
/// With `resume`, a variant whose run directory already holds a run of the same job that
/// ended (see [`ended_run`]) is read back instead of run again: an interrupted sweep goes on
/// where it stopped, and the rows it had keep the wall times measured then.
pub fn sweep(
    base: &Job,
    title: &str,
    out: &std::path::Path,
    workers: &cosdem_app::run::WorkerChoice,
    skip: &[String],
    resume: bool,
    mut progress: impl FnMut(&Row),
) -> Result<Vec<Row>, cosdem_app::run::RunError> {
    let mut base = base.clone();
    base.accuracy = None;
    let mut variants = variants(&base);
    // The reference (first) is the yardstick of every row: never skipped.
    let reference_variant = variants.remove(0);
    variants.retain(|v| !skipped(v, skip));
    variants.insert(0, reference_variant);
    let mut rows: Vec<Row> = Vec::new();
    let mut reference: Option<Reference> = None;
    for v in &variants {
        let row = run_variant(v, out, workers, resume, &mut reference)?;
        progress(&row);
        rows.push(row);
        write_tables(&rows, title, out)?;
    }
    for v in combinations(&base, &rows)? {
        if skipped(&v, skip) {
            continue;
        }
        let row = run_variant(&v, out, workers, resume, &mut reference)?;
        progress(&row);
        rows.push(row);
        write_tables(&rows, title, out)?;
    }
    Ok(rows)
}

/// The reference's metrics, curve and wall time (the sweep's first run).
pub(crate) type Reference = (CurveMetrics, Vec<(f64, f64)>, f64);

/// The file beside each of a sweep's runs that names the job it ran (the variant's whole job
/// as JSON): what `resume` checks before it reuses the run.
pub const VARIANT_FILE: &str = "variant.json";

/// The run in `dir`, if it is a run of `job` that ended: [`VARIANT_FILE`] holds this very
/// job (keys the job schema gained since it was written read as their defaults: the 10 mm
/// sweeps of 2026-12-04 predate `loading.control` and `output.vtk_format`), `summary.json` says `finished` or `failed: ...` (both are the job's deterministic
/// outcome), and `curve.csv` has one row per step the summary counts. A run that was still
/// going or was interrupted, a run of another job (another setting, another scene, a
/// directory of another sweep), or a directory that cannot be read gives `None`: the variant
/// is run again. The solver itself is not checked: the runs must come from the same cosdem.
pub fn ended_run(
    dir: &std::path::Path,
    job: &Job,
) -> Option<(cosdem_app::output::run_dir::Summary, Vec<(f64, f64)>)> {
    // Read back as a job: a key the job gained after the run was recorded takes its default,
    // so a run of the same job by an earlier cosdem is still this job's.
    let recorded: Job =
        serde_json::from_str(&std::fs::read_to_string(dir.join(VARIANT_FILE)).ok()?).ok()?;
    if recorded != *job {
        return None;
    }
    let summary = cosdem_app::output::run_dir::Summary::read(dir).ok()?;
    let ended = summary.status == "finished" || summary.status.starts_with("failed");
    let curve = cosdem_app::output::plot::curve::read_curve(&dir.join("curve.csv")).ok()?;
    (ended && curve.len() as u64 == summary.steps).then_some((summary, curve))
}

/// Runs one variant into `out/runs/<slug>` (or, with `resume`, reads the run that is there
/// if it is this variant's and ended) and compares it with the reference (the first row
/// becomes the reference).
fn run_variant(
    v: &Variant,
    out: &std::path::Path,
    workers: &cosdem_app::run::WorkerChoice,
    resume: bool,
    reference: &mut Option<Reference>,
) -> Result<Row, cosdem_app::run::RunError> {
    let dir = out.join("runs").join(v.slug());
    let (summary, curve) = match resume.then(|| ended_run(&dir, &v.job)).flatten() {
        Some(ended) => {
            tracing::info!(run = %dir.display(), status = %ended.0.status, "reused");
            ended
        }
        None => {
            // A run of the variant that is there did not end (or is another job's): it is kept
            // as `<slug>.old-N` and the variant runs again. The variant file is written once
            // the run has ended, so that only an ended run is ever reused.
            let outcome =
                cosdem_app::run::Run::new(&v.job, &dir).workers(workers.clone()).overwrite(true);
            let outcome = outcome.execute()?;
            let json = serde_json::to_string_pretty(&v.job)?;
            cosdem_app::output::write_atomic(&dir.join(VARIANT_FILE), json.as_bytes())?;
            let summary = outcome.summary.expect("a run with a directory has a summary");
            (summary, outcome.curve)
        }
    };
    let (rm, rc, rt) =
        reference.get_or_insert_with(|| (summary.metrics, curve.clone(), summary.wall_seconds));
    Ok(Row {
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
    })
}

/// Rewrites the sweep's CSV, Markdown table and Pareto plot.
fn write_tables(
    rows: &[Row],
    title: &str,
    out: &std::path::Path,
) -> Result<(), cosdem_app::run::RunError> {
    let write = |name: &str, text: String| {
        let path = out.join(name);
        cosdem_app::output::write_atomic(&path, text.as_bytes())
    };
    write("tradeoff.csv", csv(rows))?;
    write("tradeoff.md", markdown(title, rows))?;
    // A figure that cannot be drawn is a warning, never a failed sweep.
    if let Err(e) = write_pareto(rows, title, &out.join(PARETO_FILE)) {
        tracing::warn!(error = %e, "pareto plot not written");
    }
    Ok(())
}

/// The accuracy targets whose picks the sweep runs.
pub const CHECKED_TARGETS: [f64; 3] = [0.05, 0.1, 0.2];

/// The combination rows of a sweep of `base` from its one-knob `rows` (see [`sweep`]):
/// planned with [`cosdem_tune::accuracy::plan`] and [`cosdem_tune::accuracy::cheapest`] from a
/// trade whose default is `base` itself. None for an analytical material, or when the reference or
/// the default did not finish (there is no trade to plan from).
pub fn combinations(base: &Job, rows: &[Row]) -> Result<Vec<Variant>, cosdem_app::run::RunError> {
    use cosdem_tune::accuracy::{Trade, cheapest, packing_kind, plan};
    let MaterialSection::Dem { assembly } = &base.material else { return Ok(Vec::new()) };
    let kind = packing_kind(&assembly.packing);
    let Ok(trade) = Trade::from_rows(rows.to_vec(), "this sweep", kind, Some((**assembly).clone()))
    else {
        return Ok(Vec::new());
    };
    let mut picks = Vec::new();
    for t in CHECKED_TARGETS {
        let mut job = base.clone();
        job.accuracy = Some(t);
        picks.push(("accuracy", format!("{t}"), plan(&job, &trade, &[])?));
    }
    picks.push(("cheapest", String::new(), cheapest(base, &trade)?));
    let mut seen: Vec<Vec<String>> = Vec::new();
    let mut out = Vec::new();
    for (knob, target, p) in picks {
        let Some(p) = p else { continue };
        let moved: Vec<String> = p.report.knobs.iter().filter_map(|k| k.row.clone()).collect();
        if moved.is_empty() || seen.contains(&moved) {
            continue;
        }
        let setting = if target.is_empty() {
            moved.join("+")
        } else {
            format!("{target}: {}", moved.join("+"))
        };
        seen.push(moved);
        out.push(Variant { knob, setting, job: p.job });
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
