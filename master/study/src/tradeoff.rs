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

/// Draws the Pareto plot of a sweep (see [`pareto_panels`]) into `path` (PNG).
pub fn write_pareto(rows: &[Row], title: &str, path: &std::path::Path) -> PlotResult<()> {
    plot_pareto(&pareto_panels(rows), title, path)
}

/// The Pareto plot's file name in a sweep's directory.
pub const PARETO_FILE: &str = "pareto.png";

/// Runs the sweep of `base` into `out` (one run directory per variant under `out/runs/`),
/// rewriting `out/tradeoff.csv`, `out/tradeoff.md` and `out/pareto.png` after every run so a
/// long sweep can be read as it goes. `progress` hears each finished row. The reference runs
/// first. The job's `accuracy` key, if any, is dropped: it would move the very knobs the
/// sweep measures.
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
/// job, `summary.json` says `finished` or `failed: ...` (both are the job's deterministic
/// outcome), and `curve.csv` has one row per step the summary counts. A run that was still
/// going or was interrupted, a run of another job (another setting, another scene, a
/// directory of another sweep), or a directory that cannot be read gives `None`: the variant
/// is run again. The solver itself is not checked: the runs must come from the same cosdem.
pub fn ended_run(
    dir: &std::path::Path,
    job: &Job,
) -> Option<(cosdem_app::output::run_dir::Summary, Vec<(f64, f64)>)> {
    let recorded = std::fs::read_to_string(dir.join(VARIANT_FILE)).ok()?;
    if recorded != serde_json::to_string_pretty(job).ok()? {
        return None;
    }
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let summary: cosdem_app::output::run_dir::Summary = serde_json::from_str(&text).ok()?;
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
            std::fs::create_dir_all(&dir)
                .map_err(cosdem_app::output::io_err(&dir, "create directory"))?;
            let json = serde_json::to_string_pretty(&v.job)?;
            cosdem_app::output::write_atomic(&dir.join(VARIANT_FILE), json.as_bytes())?;
            cosdem_app::run::run_job(&v.job, &dir, workers)?
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
mod tests {
    use super::*;
    use cosdem_dem::spec::{Driver, TangentKind};

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

    /// The plot names a combination by what it is, also when specimens named it differently
    /// (`cheapest / accuracy 0.2`, from `crate::specimens::average`), and marks a failed run.
    #[test]
    fn point_labels_name_combinations() {
        let named = |knob: &str, setting: &str, status: &str| {
            let mut r = row(1.0, 0.0);
            (r.knob, r.setting, r.status) = (knob.into(), setting.into(), status.into());
            point_label(&r)
        };
        assert_eq!(named("cheapest", "a=1+b=2", "finished"), "cheapest set");
        assert_eq!(named("accuracy", "0.2: a=1", "finished"), "accuracy 0.2 pick");
        assert_eq!(
            named("cheapest / accuracy 0.2", "a=1+b=2", "finished"),
            "cheapest set / accuracy 0.2 pick"
        );
        assert_eq!(named("relaxation.tolerance", "1e-3", "failed: x"), "tolerance=1e-3 (failed)");
    }

    /// The front keeps the rows no other row beats on both time and error.
    #[test]
    fn pareto_front_drops_dominated_rows() {
        let rows = vec![row(10.0, 0.0), row(5.0, 0.02), row(6.0, 0.03), row(1.0, 0.2)];
        assert_eq!(pareto_front(&rows), vec![0, 1, 3]);
        // A row without F_res is ranked on the errors it has (here 0.01 < 0.02: it beats
        // row 1 and joins the front), and a failed row never takes part.
        let mut missing = row(4.0, 0.01);
        missing.errors.residual = None;
        let mut failed = row(0.1, 0.0);
        failed.status = "failed: step 3".into();
        let rows = vec![row(10.0, 0.0), row(5.0, 0.02), missing, failed];
        assert_eq!(pareto_front(&rows), vec![0, 2]);
        // By DEM steps instead of wall time: row 1 is now the cheapest.
        let by_steps = pareto_front_by(&rows, |r| if r.wall_seconds == 5.0 { 1.0 } else { 9.0 });
        assert_eq!(by_steps, vec![0, 1]);
    }

    /// The worst present error ignores missing values; with none present there is none.
    #[test]
    fn worst_present_is_the_largest_existing_error() {
        let e = Errors { peak: Some(0.01), residual: None, stiffness: Some(0.03), curve: None };
        assert_eq!(e.worst(), None);
        assert_eq!(e.worst_present(), Some(0.03));
        assert_eq!(Errors::default().worst_present(), None);
    }

    /// The committed sweeps read back: every row, the failed ones included, and a non-empty
    /// Pareto front, with or without F_res (a pre-peak table has an empty column).
    #[test]
    fn committed_tables_read_back_with_a_front() {
        // (name, text, rows, failed rows, has F_res)
        for (name, text, count, failed, has_residual) in [
            (
                "tradeoff-scene-a.csv",
                include_str!("../../../docs/notes/tradeoff-scene-a.csv"),
                19,
                1,
                false,
            ),
            (
                "tradeoff-scene-a-0.06.csv",
                include_str!("../../../docs/notes/tradeoff-scene-a-0.06.csv"),
                15,
                1,
                false,
            ),
            (
                "tradeoff-biaxial-5mm.csv",
                include_str!("../../../docs/notes/tradeoff-biaxial-5mm.csv"),
                15,
                0,
                true,
            ),
            (
                "tradeoff-biaxial-10mm.csv",
                include_str!("../../../docs/notes/tradeoff-biaxial-10mm.csv"),
                8,
                1,
                true,
            ),
            (
                "tradeoff-biaxial-10mm-specimens.csv",
                include_str!("../../../docs/notes/tradeoff-biaxial-10mm-specimens.csv"),
                6,
                0,
                true,
            ),
            (
                "tradeoff-biaxial-10mm-seed-8.csv",
                include_str!("../../../docs/notes/tradeoff-biaxial-10mm-seed-8.csv"),
                8,
                0,
                true,
            ),
            (
                "tradeoff-biaxial-1mm.csv",
                include_str!("../../../docs/notes/tradeoff-biaxial-1mm.csv"),
                18,
                0,
                false,
            ),
            (
                "tradeoff-scene-a-post-peak.csv",
                include_str!("../../../docs/notes/tradeoff-scene-a-post-peak.csv"),
                13,
                2,
                true,
            ),
        ] {
            let rows = read_csv(text, name).unwrap();
            assert_eq!(rows.len(), count, "{name}");
            assert_eq!(rows[0].knob, "reference");
            assert_eq!(rows[0].errors.peak, Some(0.0));
            assert!(rows.iter().all(|r| r.errors.residual.is_some() == has_residual), "{name}");
            assert_eq!(rows.iter().filter(|r| !finished(r)).count(), failed, "{name}");
            let front = pareto_front(&rows);
            // The reference (zero error) is on the front where it finished (past the peak
            // it stopped at 0.1166 of 0.12 m: the yardstick of the rows all the same).
            assert_eq!(front.contains(&0), finished(&rows[0]), "{name}");
            assert!(front.len() >= 2, "{name}: {front:?}");
            assert!(front.iter().all(|&i| finished(&rows[i])));
            // Writing and reading again gives the same rows (up to the CSV's precision).
            let again = read_csv(&csv(&rows), name).unwrap();
            assert_eq!(again.len(), rows.len());
            for (a, b) in rows.iter().zip(&again) {
                assert_eq!((&a.knob, &a.setting, &a.status), (&b.knob, &b.setting, &b.status));
                assert_eq!(a.dem_steps, b.dem_steps);
                assert_eq!(a.errors, b.errors);
            }
        }
        let e = read_csv("knob,setting\nx,y\n", "t").unwrap_err().to_string();
        assert!(e.contains("status"), "{e}");
    }

    /// The Pareto plot of a committed sweep is drawn (two panels) with ink on it.
    #[test]
    fn pareto_plot_of_a_committed_sweep() {
        let rows = read_csv(include_str!("../../../docs/notes/tradeoff-scene-a.csv"), "t").unwrap();
        let panels = pareto_panels(&rows);
        assert_eq!(panels.len(), 2);
        assert_eq!(panels[0].points.len(), rows.len());
        let dir = std::env::temp_dir().join(format!("cosdem-pareto-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("pareto.png");
        write_pareto(&rows, "test", &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        let ink = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(ink > 10_000, "only {ink} non-white pixels");
        std::fs::remove_dir_all(&dir).unwrap();
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
        assert!((e.worst_present().unwrap() - 0.1).abs() < 1e-12);
    }

    /// A reference that stopped early is compared over its own range: the run's F_u and
    /// F_res are taken from its points up to the reference's last displacement, so a lower
    /// minimum the run reaches later does not count; a reference that went as far as the run
    /// leaves the run's metrics as they are.
    #[test]
    fn an_early_reference_compares_over_its_range() {
        // Peak 100 at 1, then 60 at 3 (within the reference's range) and 40 at 5 (beyond).
        let run: Vec<(f64, f64)> =
            [(1.0, 100.0), (2.0, 80.0), (3.0, 60.0), (4.0, 70.0), (5.0, 40.0)]
                .map(|(d, f)| (d * 1e-3, f))
                .to_vec();
        let m = CurveMetrics::from_curve(&run, 1e-3);
        assert_eq!(m.residual_load, Some(40.0));
        let reference = [(1e-3, 100.0), (2e-3, 70.0), (3e-3, 60.0), (4e-3, 75.0)];
        let rm = CurveMetrics::from_curve(&reference, 1e-3);
        assert_eq!(rm.residual_load, Some(60.0));
        let e = compare((&rm, &reference), (&m, &run));
        assert_eq!(e.residual, Some(0.0), "the run's minimum up to 4 mm is 60, as the reference's");
        assert_eq!(e.peak, Some(0.0));
        // The same reference run to the end: the run's whole-path minimum counts (40 vs 60).
        let longer = [reference.to_vec(), vec![(5e-3, 60.0)]].concat();
        let e = compare((&rm, &longer), (&m, &run));
        assert!((e.residual.unwrap() - 1.0 / 3.0).abs() < 1e-15);
    }

    /// The combination rows of a sweep are planned from the sweep's own rows, with the job
    /// itself as the default (its perturbation tangent is kept, not reset to the worker's
    /// paper tangent). Shifts from the default (F_u): x4 4 %, tolerance 1 %, safety 0.8 0,
    /// FIRE 10 %, warm start 2 %, on a default 0.5 % off. A 5 % target (budget 2.5 %) moves
    /// tolerance and safety (1.5 %), 10 % (5 %) adds warm start (3.5 %, DEM steps x0.135,
    /// cheaper than x4 with safety at x0.144), 20 % (10 %) adds x4 (7.5 %), and the cheapest
    /// set swaps safety for FIRE (17.5 %: within no budget but its own) and never takes both
    /// (they set the same time step). Safety 0.95 is never a candidate. A combination that
    /// moves no knob, or the same knobs as an earlier one, is not run.
    #[test]
    fn combinations_are_planned_from_the_sweep() {
        let mut job =
            Job::from_toml(include_str!("../../../examples/rve-size.toml"), "rve-size").unwrap();
        job.accuracy = Some(0.3);
        // The made-up sweep's job ran at safety 0.5 (it has a 0.8 row).
        assembly_mut(&mut job).unwrap().relaxation.safety = 0.5;
        let csv = "knob,setting,status,displacement,wall_seconds,speedup,dem_steps,cuts,\
                   peak_load,residual_load,stiffness,err_peak,err_residual,err_stiffness,err_curve\n\
                   reference,tight,finished,1,1,1,1000,0,100,5,10,0,0,0,0\n\
                   default,as given,finished,1,1,1,100,0,100.5,5,10,0.005,0,0,0\n\
                   load_step,x4,finished,1,1,1,32,0,104.5,5,10,0.045,0,0,0\n\
                   relaxation.tolerance,1e-3,finished,1,1,1,50,0,101.5,5,10,0.015,0,0,0\n\
                   relaxation.safety,0.95,finished,1,1,1,20,0,100.5,5,10,0.005,0,0,0\n\
                   relaxation.safety,0.8,finished,1,1,1,45,0,100.5,5,10,0.005,0,0,0\n\
                   relaxation.driver,fire,finished,1,1,1,40,0,110.5,5,10,0.105,0,0,0\n\
                   warm_start,true,finished,1,1,1,60,0,102.5,5,10,0.025,0,0,0\n";
        let rows = read_csv(csv, "made-up").unwrap();
        let v = combinations(&job, &rows).unwrap();
        let names: Vec<_> = v.iter().map(|v| (v.knob, v.setting.as_str())).collect();
        assert_eq!(
            names,
            [
                ("accuracy", "0.05: relaxation.tolerance=1e-3+relaxation.safety=0.8"),
                (
                    "accuracy",
                    "0.1: relaxation.tolerance=1e-3+relaxation.safety=0.8+warm_start=true"
                ),
                (
                    "accuracy",
                    "0.2: load_step=x4+relaxation.tolerance=1e-3+relaxation.safety=0.8+warm_start=true"
                ),
                (
                    "cheapest",
                    "load_step=x4+relaxation.tolerance=1e-3+relaxation.driver=fire+warm_start=true"
                ),
            ]
        );
        for c in &v {
            assert_eq!(c.job.accuracy, None, "a planned job is run as planned");
            assert_eq!(c.job.mesh, job.mesh);
            let Some(a) = assembly_of(&c.job) else { panic!("DEM job") };
            assert!(matches!(a.tangent, TangentKind::Perturbation { .. }), "{:?}", a.tangent);
            let fire = matches!(a.relaxation.driver, Driver::Fire { .. });
            assert!(a.relaxation.safety <= 0.8 && !(fire && a.relaxation.safety != 0.5));
        }
        let inc = |j: &Job| j.loading.increment.unwrap();
        assert_eq!(inc(&v[2].job), 4.0 * inc(&job));
        assert_eq!(inc(&v[0].job), inc(&job));
        // Only the reference and the default: nothing to move, nothing run. No reference:
        // no trade. An analytical material: no knobs.
        assert!(combinations(&job, &rows[..2]).unwrap().is_empty());
        assert!(combinations(&job, &rows[2..]).unwrap().is_empty());
        let elastic =
            Job::from_toml(include_str!("../../../examples/elastic.toml"), "elastic").unwrap();
        assert!(combinations(&elastic, &rows).unwrap().is_empty());
    }

    /// `--resume` goes on with a stopped sweep: the runs that ended are read back (a wall
    /// time planted in one proves it was read, not run), and a run that was interrupted, a
    /// run of another job and a missing run are run again, so every row ends as it did in the
    /// uninterrupted sweep. The elastic panel: its seven rows take milliseconds.
    #[test]
    fn a_resumed_sweep_reads_the_ended_runs_and_runs_the_rest() {
        let out = std::env::temp_dir().join(format!("cosdem-resume-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let job =
            Job::from_toml(include_str!("../../../examples/elastic.toml"), "elastic").unwrap();
        let workers = cosdem_app::run::WorkerChoice::default();
        let first = sweep(&job, "t", &out, &workers, &[], false, |_| {}).unwrap();
        // An analytical material has no combinations: every row is one of the variants.
        let jobs: Vec<Job> = first
            .iter()
            .map(|r| {
                let s = slug(&r.knob, &r.setting);
                variants(&job).into_iter().find(|v| v.slug() == s).unwrap().job
            })
            .collect();
        assert!(jobs.len() >= 5, "{} rows", jobs.len());
        let run = |i: usize| out.join("runs").join(slug(&first[i].knob, &first[i].setting));
        let set = |i: usize, key: &str, value: serde_json::Value| {
            let path = run(i).join("summary.json");
            let mut s: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            s[key] = value;
            std::fs::write(&path, serde_json::to_string_pretty(&s).unwrap()).unwrap();
        };
        // The reference ended: plant a wall time that no run measures.
        set(0, "wall_seconds", 1234.5.into());
        // Row 2 was interrupted, row 3 holds a run of another job (row 4's), row 4 never
        // started.
        set(2, "status", "interrupted".into());
        std::fs::copy(run(4).join(VARIANT_FILE), run(3).join(VARIANT_FILE)).unwrap();
        std::fs::remove_dir_all(run(4)).unwrap();
        assert!(ended_run(&run(0), &job).is_none(), "the reference's run is not the job's");
        assert!(ended_run(&run(2), &jobs[2]).is_none(), "an interrupted run is no result");
        assert!(ended_run(&run(3), &jobs[3]).is_none(), "row 3 holds another job's run");
        let mut heard = 0;
        let second = sweep(&job, "t", &out, &workers, &[], true, |_| heard += 1).unwrap();
        assert_eq!(heard, first.len());
        assert_eq!(second[0].wall_seconds, 1234.5, "the reference was run again");
        assert_eq!(second[1].wall_seconds, first[1].wall_seconds, "the default was run again");
        for (i, (a, b)) in first.iter().zip(&second).enumerate() {
            assert_eq!((&a.knob, &a.setting, &a.status), (&b.knob, &b.setting, &b.status));
            assert_eq!(
                (a.metrics, a.dem_steps, a.cuts),
                (b.metrics, b.dem_steps, b.cuts),
                "row {i}"
            );
            // Every speedup is against the reference's planted wall time now.
            assert_eq!(b.speedup, 1234.5 / b.wall_seconds, "row {i}");
            assert_eq!(a.errors, b.errors, "row {i}");
            // Every row's directory holds its own job's ended run, the re-run ones included.
            assert!(ended_run(&run(i), &jobs[i]).is_some(), "row {i}");
        }
        std::fs::remove_dir_all(&out).unwrap();
    }

    fn assembly_of(job: &Job) -> Option<&cosdem_dem::AssemblySpec> {
        match &job.material {
            MaterialSection::Dem { assembly } => Some(assembly),
            MaterialSection::Elastic { .. } => None,
        }
    }
}
