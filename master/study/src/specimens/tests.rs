use super::*;
use crate::tradeoff::{Errors, Row};

fn row(knob: &str, setting: &str, wall: f64, fu: f64, fres: Option<f64>, e: f64) -> Row {
    Row {
        knob: knob.into(),
        setting: setting.into(),
        status: "finished".into(),
        displacement: 0.01,
        wall_seconds: wall,
        dem_steps: 1000,
        cuts: 1,
        metrics: CurveMetrics {
            peak_load: fu,
            residual_load: fres,
            stiffness: Some(e),
            ..CurveMetrics::default()
        },
        errors: Errors::default(),
        speedup: 1.0,
    }
}

/// A straight line of slope `k` sampled every `h` up to `n * h`.
fn line(k: f64, h: f64, n: usize) -> Vec<(f64, f64)> {
    (1..=n).map(|i| (h * i as f64, k * h * i as f64)).collect()
}

fn specimen(label: &str, rows: Vec<Row>, curves: Vec<Vec<(f64, f64)>>) -> Specimen {
    Specimen { label: label.into(), rows, curves }
}

/// Two specimens whose references differ (F_res 100 and 120) and whose default rows are
/// 115 on both: the averaged error compares the means (|115 - 110| / 110), and the paired
/// differences (+15 and -5, over the mean 110) have mean 5/110 and standard error
/// sd / sqrt(2) = (10 sqrt(2) / 110) / sqrt(2) = 10/110. Wall time, DEM steps and cuts add
/// up; the speedup is the ratio of the totals. Exact up to a few roundings (1e-12).
#[test]
fn averaged_errors_compare_the_specimen_means() {
    let a = specimen(
        "seed-1",
        vec![
            row("reference", "tight", 100.0, 1000.0, Some(100.0), 2e7),
            row("default", "as given", 10.0, 1010.0, Some(115.0), 2e7),
        ],
        vec![line(1e5, 1e-3, 10), line(1.1e5, 1e-3, 10)],
    );
    let b = specimen(
        "seed-2",
        vec![
            row("reference", "tight", 200.0, 1200.0, Some(120.0), 3e7),
            row("default", "as given", 20.0, 1170.0, Some(115.0), 3e7),
        ],
        vec![line(3e5, 1e-3, 10), line(2.9e5, 2e-3, 5)],
    );
    let avg = average(&[a, b]).unwrap();
    assert_eq!(avg.labels, ["seed-1", "seed-2"]);
    assert!(avg.dropped.is_empty());
    let (r, d) = (&avg.rows[0], &avg.rows[1]);
    assert_eq!(r.metrics.residual_load, Some(110.0));
    assert_eq!(d.metrics.peak_load, 1090.0);
    assert_eq!(d.wall_seconds, 30.0);
    assert_eq!(d.dem_steps, 2000);
    assert_eq!(d.cuts, 2);
    assert!((d.speedup - 10.0).abs() < 1e-12);
    assert_eq!(r.errors.residual, Some(0.0));
    let close = |x: Option<f64>, y: f64| (x.unwrap() - y).abs() < 1e-12;
    assert!(close(d.errors.residual, 5.0 / 110.0), "{:?}", d.errors);
    assert!(close(d.errors.stiffness, 0.0));
    // Mean curves: slopes (1 + 3)/2 = 2e5 and (1.1 + 2.9)/2 = 2e5, the second sampled on a
    // coarser grid: linear interpolation is exact, so the curves agree.
    assert!(close(d.errors.curve, 0.0));
    let res = avg.spread[1].residual.unwrap();
    assert!((res.mean - 5.0 / 110.0).abs() < 1e-12, "{res:?}");
    assert!((res.standard_error - 10.0 / 110.0).abs() < 1e-12, "{res:?}");
    // The F_u differences +10/1100 and -30/1100: mean -10/1100 while the averaged error is
    // its magnitude.
    let pk = avg.spread[1].peak.unwrap();
    assert!((pk.mean + 10.0 / 1100.0).abs() < 1e-12, "{pk:?}");
    assert!(close(d.errors.peak, 10.0 / 1100.0), "{:?}", d.errors);
    // The reference's own differences are zero.
    assert_eq!(avg.spread[0].residual, Some(Difference { mean: 0.0, standard_error: 0.0 }));
}

/// A row that one specimen did not run is dropped and named; a row that failed on one
/// specimen is failed, names that specimen, and has no mean F_res when that specimen has
/// none (a mean over fewer specimens would compare different sets).
#[test]
fn missing_and_failed_rows() {
    let mut failed = row("warm_start", "true", 5.0, 900.0, None, 2e7);
    failed.status = "failed: load step 3".into();
    let a = specimen(
        "s1",
        vec![
            row("reference", "tight", 100.0, 1000.0, Some(100.0), 2e7),
            row("cheapest", "a+b", 1.0, 1000.0, Some(100.0), 2e7),
            failed,
        ],
        vec![line(1e5, 1e-3, 10), line(1e5, 1e-3, 10), line(1e5, 1e-3, 3)],
    );
    let b = specimen(
        "s2",
        vec![
            row("reference", "tight", 100.0, 1000.0, Some(100.0), 2e7),
            row("warm_start", "true", 5.0, 1000.0, Some(104.0), 2e7),
            row("cheapest", "a+c", 1.0, 1000.0, Some(100.0), 2e7),
        ],
        vec![line(1e5, 1e-3, 10), line(1e5, 1e-3, 10), line(1e5, 1e-3, 10)],
    );
    let avg = average(&[a, b]).unwrap();
    assert_eq!(avg.dropped, ["cheapest = a+b"]);
    assert_eq!(avg.rows.len(), 2);
    let w = &avg.rows[1];
    assert_eq!(w.status, "specimen s1: failed: load step 3");
    assert_eq!(w.metrics.residual_load, None);
    assert_eq!(w.errors.residual, None);
    assert_eq!(avg.spread[1].residual, None);
    // The curve is compared where both specimens' curves reach (3 points): equal there.
    assert_eq!(w.errors.curve, Some(0.0));
}

/// Rows are matched by the settings they ran, not by their names: a sweep runs a
/// combination once, so seed-2's cheapest set (`b=2+a=1`, the same as its `accuracy 0.2`
/// pick) is its `accuracy` row while seed-1 calls it `cheapest`. The averaged row names
/// both and lists the settings; the per-specimen table keeps each sweep's own name. Seed-1's
/// `accuracy 0.1` pick repeats its one-knob row `a = 1` (the same run again) and is left out
/// rather than averaged with seed-2's `a = 1`, which is counted once already.
#[test]
fn rows_are_matched_by_what_they_ran() {
    let a = specimen(
        "seed-1",
        vec![
            row("reference", "tight", 100.0, 1000.0, Some(100.0), 2e7),
            row("a", "1", 10.0, 1000.0, Some(100.0), 2e7),
            row("accuracy", "0.1: a=1", 10.0, 1000.0, Some(100.0), 2e7),
            row("cheapest", "a=1+b=2", 2.0, 1010.0, Some(104.0), 2e7),
        ],
        Vec::new(),
    );
    let b = specimen(
        "seed-2",
        vec![
            row("reference", "tight", 100.0, 1000.0, Some(100.0), 2e7),
            row("a", "1", 10.0, 1000.0, Some(100.0), 2e7),
            row("accuracy", "0.2: b=2+a=1", 3.0, 1030.0, Some(96.0), 2e7),
        ],
        Vec::new(),
    );
    let avg = average(&[a, b]).unwrap();
    assert!(avg.dropped.is_empty(), "{:?}", avg.dropped);
    let names: Vec<(&str, &str)> =
        avg.rows.iter().map(|r| (r.knob.as_str(), r.setting.as_str())).collect();
    assert_eq!(names, [("reference", "tight"), ("a", "1"), ("cheapest / accuracy 0.2", "a=1+b=2")]);
    let c = &avg.rows[2];
    assert_eq!((c.wall_seconds, c.metrics.peak_load), (5.0, 1020.0));
    assert!((c.errors.peak.unwrap() - 0.02).abs() < 1e-12, "{:?}", c.errors);
    assert_eq!(c.errors.residual, Some(0.0));
    let md = markdown("t", &avg);
    assert!(md.contains("| cheapest | a=1+b=2 | seed-1 |"), "{md}");
    assert!(md.contains("| accuracy | 0.2: b=2+a=1 | seed-2 |"), "{md}");
}

/// One specimen, the same specimen twice, or a sweep whose first row is not its reference,
/// is refused by name.
#[test]
fn too_few_specimens_or_no_reference_are_refused() {
    let a = specimen("s1", vec![row("reference", "tight", 1.0, 1.0, None, 1.0)], vec![vec![]]);
    let e = average(std::slice::from_ref(&a)).unwrap_err();
    assert!(e.to_string().contains("at least 2 sweeps, got 1"), "{e}");
    // Curves missing altogether are empty curves, not a panic.
    let no_curves = specimen("s3", a.rows.clone(), Vec::new());
    let avg = average(&[a.clone(), no_curves]).unwrap();
    assert_eq!(avg.rows[0].errors.curve, None);
    let e = average(&[a.clone(), a.clone()]).unwrap_err();
    assert_eq!(e.to_string(), "specimen s1 is given twice");
    let b = specimen("s2", vec![row("default", "as given", 1.0, 1.0, None, 1.0)], vec![vec![]]);
    let e = average(&[a, b]).unwrap_err();
    assert!(e.to_string().contains("specimen s2") && e.to_string().contains("\"default\""));
}

/// The mean curve stops at the first displacement one curve does not reach.
#[test]
fn mean_curve_stops_where_a_curve_ends() {
    let long = line(2.0, 1.0, 10);
    let short = line(4.0, 1.0, 4);
    let m = mean_curve(&[&long, &short], &long);
    assert_eq!(m, (1..=4).map(|i| (i as f64, 3.0 * i as f64)).collect::<Vec<_>>());
}

/// A sweep directory reads back: rows from its CSV, each row's curve from its run
/// directory (named by the knob's slug), the peak's displacement from the curve, and an
/// empty curve for a row without a run directory. The Markdown names every specimen.
#[test]
fn sweeps_read_back_and_print() {
    let root = std::env::temp_dir().join(format!("cosdem-specimens-{}", std::process::id()));
    let mut specimens = Vec::new();
    for (seed, k) in [("seed-1", 1.0), ("seed-2", 1.2)] {
        let dir = root.join(seed);
        let rows = vec![
            row("reference", "tight", 10.0, 50.0 * k, Some(30.0 * k), 1e4 * k),
            row("relaxation.tolerance", "1e-3", 1.0, 49.0 * k, Some(31.0 * k), 1e4 * k),
        ];
        let run = dir.join("runs").join("reference_tight");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(dir.join("tradeoff.csv"), tradeoff::csv(&rows)).unwrap();
        let curve: String = [(0.001, 10.0), (0.002, 50.0), (0.003, 30.0)]
            .iter()
            .map(|(d, f)| format!("{d},{}\n", f * k))
            .collect();
        std::fs::write(run.join("curve.csv"), format!("displacement,load\n{curve}")).unwrap();
        let s = read_sweep(&dir).unwrap();
        assert_eq!(s.label, seed);
        assert_eq!(s.rows.len(), 2);
        assert_eq!(s.curves[0].len(), 3);
        assert!(s.curves[1].is_empty());
        assert_eq!(s.rows[0].metrics.peak_displacement, 0.002);
        specimens.push(s);
    }
    let avg = average(&specimens).unwrap();
    // Row 1 has no curve: no curve error, but its metrics compare: F_res 31 * 1.1 against
    // 30 * 1.1.
    assert_eq!(avg.rows[1].errors.curve, None);
    assert!((avg.rows[1].errors.residual.unwrap() - 1.0 / 30.0).abs() < 1e-12);
    let md = markdown("t", &avg);
    assert!(md.contains("Averaged over 2 specimens (seed-1, seed-2)"), "{md}");
    assert!(md.contains("| relaxation.tolerance | 1e-3 | seed-2 | finished |"), "{md}");
    let missing = read_sweep(&root.join("nowhere")).unwrap_err();
    assert!(missing.to_string().contains("tradeoff.csv"), "{missing}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// The committed specimen-averaged table of the biaxial example to 10 mm is what
/// [`average`] makes of its three committed sweeps (seeds 7, 8, 9): F_u, F_res and E are the
/// specimen means, wall time and DEM steps the totals, and the errors compare the means.
/// The curve column needs the runs' curves, which are not committed, so it is not checked.
/// Tolerances from the CSVs' printing: loads with 7 significant digits (relative 1e-6), wall
/// times with 3 decimals (3 summed: 2e-3 s), errors recomputed from 7-digit loads (absolute
/// 1e-5 on errors of a few percent).
#[test]
fn the_committed_specimen_table_is_the_mean_of_its_sweeps() {
    let read = |name: &str, text: &str| tradeoff::read_csv(text, name).unwrap();
    let seeds = [
        read("seed 7", include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-seed-7.csv")),
        read("seed 8", include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-seed-8.csv")),
        read("seed 9", include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-seed-9.csv")),
    ];
    let committed =
        read("avg", include_str!("../../../../docs/notes/tradeoff-biaxial-10mm-specimens.csv"));
    let specimens: Vec<Specimen> = seeds
        .iter()
        .enumerate()
        .map(|(i, rows)| Specimen {
            label: format!("seed-{}", 7 + i),
            rows: rows.clone(),
            curves: vec![Vec::new(); rows.len()],
        })
        .collect();
    let avg = average(&specimens).unwrap();
    assert_eq!(avg.rows.len(), committed.len());
    let load = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-6 * b.abs(),
        (a, b) => a.is_none() && b.is_none(),
    };
    let error = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-5,
        (a, b) => a.is_none() && b.is_none(),
    };
    for (a, c) in avg.rows.iter().zip(&committed) {
        let k = format!("{} {}", a.knob, a.setting);
        assert_eq!((&a.knob, &a.setting, &a.status), (&c.knob, &c.setting, &c.status));
        assert_eq!(a.dem_steps, c.dem_steps, "{k}");
        assert!((a.wall_seconds - c.wall_seconds).abs() <= 2e-3, "{k}");
        assert!(load(Some(a.metrics.peak_load), Some(c.metrics.peak_load)), "{k}");
        assert!(load(a.metrics.residual_load, c.metrics.residual_load), "{k}");
        assert!(load(a.metrics.stiffness, c.metrics.stiffness), "{k}");
        assert!(error(a.errors.peak, c.errors.peak), "{k}");
        assert!(error(a.errors.residual, c.errors.residual), "{k}");
        assert!(error(a.errors.stiffness, c.errors.stiffness), "{k}");
    }
}

/// The committed specimen table of the re-sweep with the fixed Newton criterion
/// (`docs/notes/tradeoff-biaxial-10mm-fixed/specimens/`) is what [`average`] and [`markdown`] make
/// of the three committed sweep directories beside it, curves included: the CSV and the
/// Markdown are byte for byte the tool's output on the committed inputs (the same pure
/// arithmetic on the same decimal inputs gives the same bits, so no tolerance is needed).
#[test]
fn the_committed_fixed_specimen_table_is_the_mean_of_its_sweeps() {
    let dir =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/notes/tradeoff-biaxial-10mm-fixed");
    let sweeps: Vec<Specimen> =
        ["seed-7", "seed-8", "seed-9"].iter().map(|s| read_sweep(&dir.join(s)).unwrap()).collect();
    assert!(sweeps.iter().all(|s| s.curves.iter().all(|c| !c.is_empty())), "a curve is missing");
    let avg = average(&sweeps).unwrap();
    let committed = |name: &str| std::fs::read_to_string(dir.join("specimens").join(name)).unwrap();
    assert_eq!(tradeoff::csv(&avg.rows), committed("tradeoff.csv"));
    let md = committed("tradeoff.md");
    let title = md.lines().next().unwrap().trim_start_matches("# ");
    assert_eq!(markdown(title, &avg), md);
}
