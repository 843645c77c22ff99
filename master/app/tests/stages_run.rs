//! A job in stages run end to end by the driver: an elastic panel compressed, unloaded
//! by a negative increment back to where it started, and reloaded. Linear elasticity gives
//! the checks their closed forms: the load comes back to zero with the displacement, and the
//! reload repeats the first loading. A run stopped in the middle of the second stage resumes
//! to the uninterrupted run's files, byte for byte.

use cosdem_app::run::{Ending, Run};
use cosdem_job::Job;
use std::path::{Path, PathBuf};

const JOB: &str = r#"
[mesh]
kind = "rectangle"
lx = 1.0
ly = 1.0
nx = 2
ny = 2

[material]
kind = "elastic"
shear_modulus = 1e7
poisson = 0.3

[[stage]]
name = "load"
steps = 4
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "bottom", component = "ux", value = 0.0 },
  { set = "top", component = "ux", value = 0.0 },
  { set = "top", component = "uy", value = -1e-2 },
]

[[stage]]
name = "unload"
steps = 4
prescribed = [{ set = "top", component = "uy", increment = 1e-2 }]

[[stage]]
name = "reload"
steps = 4
prescribed = [{ set = "top", component = "uy", value = -1e-2 }]
"#;

fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("stages_run").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Every data row of `curve.csv`, split into fields.
fn rows(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    text.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect()
}

/// The load of each step, read through the driver's own curve.
fn loads(curve: &[(f64, f64)]) -> Vec<f64> {
    curve.iter().map(|p| p.1).collect()
}

/// Load, unload to the start, reload: the unloading's loads retrace the loading's (step 4 + k
/// of the unloading has the load of step 4 - k), the last unloading step carries no load, and
/// the reload repeats the loading. Tolerance 1e-9 of the peak: linear solves of a linear
/// material, round-off only.
#[test]
fn an_elastic_load_unload_reload_retraces_its_path() {
    let job = Job::from_toml(JOB, "stages.toml").unwrap();
    let dir = fresh("whole");
    let outcome = Run::new(&job, &dir).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert_eq!(outcome.steps, 12);
    let l = loads(&outcome.curve);
    let peak = l[3];
    assert!(peak.abs() > 1e4, "the loading loads the top: {l:?}");
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * peak.abs();
    for k in 1..4 {
        assert!(close(l[3 + k], l[3 - k]), "unloading step {k}: {l:?}");
    }
    assert!(close(l[7], 0.0), "unloaded: {l:?}");
    for k in 0..4 {
        assert!(close(l[8 + k], l[k]), "reloading step {k}: {l:?}");
    }
    assert_eq!(rows(&dir).len(), 12);
}

/// Stopped after step 6 (the middle of the unloading stage) and resumed: the same files as
/// the uninterrupted run, byte for byte.
#[test]
fn a_run_stopped_in_a_later_stage_resumes_to_the_same_files() {
    let job = Job::from_toml(JOB, "stages.toml").unwrap();
    let whole = fresh("ckpt-whole");
    Run::new(&job, &whole).checkpoints(true).execute().unwrap();
    let split = fresh("ckpt-split");
    let stopped = Run::new(&job, &split).checkpoints(true).max_steps(Some(6)).execute().unwrap();
    assert!(matches!(stopped.ending, Ending::Stopped), "{:?}", stopped.ending);
    let resumed = Run::new(&job, &split).checkpoints(true).resume(false).execute().unwrap();
    assert!(matches!(resumed.ending, Ending::Finished), "{:?}", resumed.ending);
    for file in ["curve.csv", "fields.pvd", "gauss.pvd", "vtk/mesh_00012.vtu", "checkpoint.bin"] {
        let (a, b) = (whole.join(file), split.join(file));
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{file}");
    }
}
