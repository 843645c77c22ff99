//! The run directory is written as the run goes: after every converged step `curve.csv` has one
//! more row, both `.pvd` collections list one more existing `.vtu`, and `summary.json` carries
//! the metrics of the curve so far. Checked on the elastic panel, whose curve is a straight line:
//! the stiffness E and the Fig. 5 stiffness E50 must both equal load / displacement (to 1e-9
//! relative: a least-squares slope of exact multiples, a few roundings).

use cosdem_app::output::run_dir::{RunSettings, RunWriter};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::solve::Solver;
use cosdem_job::Job;

const JOB: &str = r#"
    title = "elastic panel"
    [mesh]
    kind = "rectangle"
    lx = 1.0
    ly = 1.0
    nx = 2
    ny = 2
    [loading]
    steps = 4
    [loading.compression]
    displacement = 0.008
    [material]
    kind = "elastic"
    shear_modulus = 2e7
    poisson = 0.25
"#;

#[test]
fn every_step_is_on_disk_with_its_metrics() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("run_dir_test");
    let _ = std::fs::remove_dir_all(&dir);
    let job = Job::from_toml(JOB, "inline").unwrap();
    let settings = RunSettings {
        title: job.title.clone(),
        shortening: job.shortening(),
        load_set: job.loading.load_set.clone(),
        load_scale: job.load_scale(),
        vtk_every: 1,
        internal_length: 0.01,
        linear_range: 0.01,
    };
    let mut writer = RunWriter::create(&dir, settings).unwrap();
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let mut material = ElasticCosserat::new(2e7, 0.25, 1e7, 0.01);
    solver.run(&mut material, &mut writer).unwrap();
    writer.finish(Ok(())).unwrap();

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
    let (d, f) = *writer.curve().last().unwrap();
    assert!((d - 0.008).abs() < 1e-15);
    let m = &writer.summary().metrics;
    let secant = f / d;
    assert!((m.stiffness.unwrap() - secant).abs() <= 1e-9 * secant);
    assert!((m.stiffness_50.unwrap() - secant).abs() <= 1e-9 * secant);
    assert_eq!(m.peak_load, f);
    assert_eq!(m.residual_load, None, "a rising curve has no residual capacity");
}
