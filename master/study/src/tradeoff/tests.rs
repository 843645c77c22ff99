//! Tests of the sweep: errors, Pareto front, tables, combinations, the committed tables.

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
            include_str!("../../../../docs/notes/tradeoff-scene-a.csv"),
            19,
            1,
            false,
        ),
        (
            "tradeoff-scene-a-0.06.csv",
            include_str!("../../../../docs/notes/tradeoff-scene-a-0.06.csv"),
            15,
            1,
            false,
        ),
        (
            "tradeoff-biaxial-5mm.csv",
            include_str!("../../../../docs/notes/tradeoff-biaxial-5mm.csv"),
            15,
            0,
            true,
        ),
        (
            "tradeoff-biaxial-10mm.csv",
            include_str!("../../../../docs/notes/tradeoff-biaxial-10mm.csv"),
            8,
            1,
            true,
        ),
        (
            "tradeoff-biaxial-10mm-specimens.csv",
            include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-specimens.csv"),
            6,
            0,
            true,
        ),
        (
            "tradeoff-biaxial-10mm-seed-8.csv",
            include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-seed-8.csv"),
            8,
            0,
            true,
        ),
        (
            "tradeoff-biaxial-1mm.csv",
            include_str!("../../../../docs/notes/tradeoff-biaxial-1mm.csv"),
            18,
            0,
            false,
        ),
        (
            "tradeoff-scene-a-post-peak.csv",
            include_str!("../../../../docs/notes/tradeoff-scene-a-post-peak.csv"),
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
    let rows = read_csv(include_str!("../../../../docs/notes/tradeoff-scene-a.csv"), "t").unwrap();
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
    // The same figure as SVG beside it, as wide as the PNG (two panels).
    let svg = std::fs::read_to_string(dir.join("pareto.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains(&format!("width=\"{}\"", img.width())), "{}", &svg[..120]);
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
    let run: Vec<(f64, f64)> = [(1.0, 100.0), (2.0, 80.0), (3.0, 60.0), (4.0, 70.0), (5.0, 40.0)]
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
        Job::from_toml(include_str!("../../../../examples/rve-size.toml"), "rve-size").unwrap();
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
            ("accuracy", "0.1: relaxation.tolerance=1e-3+relaxation.safety=0.8+warm_start=true"),
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
        Job::from_toml(include_str!("../../../../examples/elastic.toml"), "elastic").unwrap();
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
    let job = Job::from_toml(include_str!("../../../../examples/elastic.toml"), "elastic").unwrap();
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
        assert_eq!((a.metrics, a.dem_steps, a.cuts), (b.metrics, b.dem_steps, b.cuts), "row {i}");
        // Every speedup is against the reference's planted wall time now.
        assert_eq!(b.speedup, 1234.5 / b.wall_seconds, "row {i}");
        assert_eq!(a.errors, b.errors, "row {i}");
        // Every row's directory holds its own job's ended run, the re-run ones included.
        assert!(ended_run(&run(i), &jobs[i]).is_some(), "row {i}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// A run recorded by an earlier cosdem, whose job lacked keys added since (written without
/// them, as the committed 10 mm sweeps are), is still its job's: the committed seed-9
/// reference run of `docs/notes/tradeoff-biaxial-10mm-fixed/` is recognized as the
/// reference of the biaxial example with seed 9, and not as the default's nor as another
/// seed's reference.
#[test]
fn a_run_recorded_before_keys_were_added_is_still_its_jobs() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/notes/tradeoff-biaxial-10mm-fixed/seed-9/runs/reference_tight"
    );
    let recorded = std::fs::read_to_string(format!("{dir}/{VARIANT_FILE}")).unwrap();
    assert!(!recorded.contains("vtk_format"), "the committed run predates the key");
    let example = include_str!("../../../../examples/biaxial.toml");
    let seeded = |n: u32| {
        let toml = example.replace("seed = 7", &format!("seed = {n}"));
        Job::from_toml(&toml, "biaxial").unwrap()
    };
    let seed9 = seeded(9);
    let (summary, curve) = ended_run(std::path::Path::new(dir), &reference(&seed9).job)
        .expect("the committed reference is the seed-9 reference");
    assert_eq!(summary.dem_steps, 670_679_280);
    assert_eq!(curve.len() as u64, summary.steps);
    assert!(ended_run(std::path::Path::new(dir), &seed9).is_none(), "not the default's run");
    assert!(ended_run(std::path::Path::new(dir), &reference(&seeded(8)).job).is_none());
}

fn assembly_of(job: &Job) -> Option<&cosdem_dem::AssemblySpec> {
    match &job.material {
        MaterialSection::Dem { assembly } => Some(assembly),
        MaterialSection::Elastic { .. } => None,
    }
}
