//! The run directory is written as the run goes: after every converged step `curve.csv` has one
//! more row, both `.pvd` collections list one more existing `.vtu`, and `summary.json` carries
//! the metrics of the curve so far. Checked on the elastic panel, whose curve is a straight line:
//! the stiffness E and the Fig. 5 stiffness E50 must both equal load / displacement (to 1e-9
//! relative: a least-squares slope of exact multiples, a few roundings).

use cosdem_app::run::{Ending, Run};
use cosdem_job::{MaterialSection, fixtures};

#[test]
fn every_step_is_on_disk_with_its_metrics() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("run_dir_test");
    let _ = std::fs::remove_dir_all(&dir);
    // The elastic-panel fixture compressed by 8 mm in 4 steps, with G = 20 MPa, nu = 0.25
    // (Gc = G / 2, lc = 0.01 m), VTK every step and the paper's linear range (the defaults).
    let mut job = fixtures::load("elastic-panel");
    job.title = "elastic panel".into();
    job.loading.compression.as_mut().unwrap().displacement = 0.008;
    job.material = MaterialSection::Elastic {
        shear_modulus: 2e7,
        poisson: 0.25,
        cosserat_modulus: None,
        length: None,
    };
    job.validate().unwrap();
    assert_eq!((job.output.vtk_every, job.output.linear_range), (1, 0.01));
    let outcome = Run::new(&job, &dir).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);

    let csv = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 4);
    for pvd in ["fields.pvd", "gauss.pvd"] {
        let text = std::fs::read_to_string(dir.join(pvd)).unwrap();
        let files: Vec<&str> =
            text.split("file=\"").skip(1).map(|s| s.split('"').next().unwrap()).collect();
        assert_eq!(files.len(), 4, "{pvd}");
        for f in files {
            assert!(dir.join(f).exists(), "{pvd} lists {f}, which is missing");
        }
    }
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"finished\""), "{summary}");
    let (d, f) = *outcome.curve.last().unwrap();
    assert!((d - 0.008).abs() < 1e-15);
    let m = &outcome.summary.as_ref().unwrap().metrics;
    let secant = f / d;
    assert!((m.stiffness.unwrap() - secant).abs() <= 1e-9 * secant);
    assert!((m.stiffness_50.unwrap() - secant).abs() <= 1e-9 * secant);
    assert_eq!(m.peak_load, f);
    assert_eq!(m.residual_load, None, "a rising curve has no residual capacity");
}
