//! The run driver ([`cosdem_app::run::Run`]) run end to end: an elastic job and a tiny DEM job
//! give the curves recorded from the runs made before the driver existed (the CLI's `run`
//! loop and `run_job`), byte for byte; `max_steps` stops a run with status `stopped` and a
//! resume from its checkpoint finishes it with the curve of the uninterrupted run, bit for
//! bit; a stop flag stops it with status `interrupted`; a run without a directory with a
//! material of the caller's reports its steps to the caller's observer only.
//!
//! Every comparison is exact: a run is deterministic given the job, and a resume restores
//! every state bit for bit, so any difference is a change of what cosdem computes.

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{Ending, Run, RunObserver, WorkerChoice, run_job};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::Job;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// An example job of the repository.
fn example(name: &str) -> Job {
    Job::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
}

/// `examples/elastic.toml`: the 2 x 2 elastic panel, 10 steps to 1 cm.
fn elastic() -> Job {
    example("elastic.toml")
}

/// `curve.csv` of `cosdem run examples/elastic.toml`, recorded before the run driver.
const ELASTIC_CURVE: &str = "\
step,load_factor,displacement,load,iterations,cuts,dem_steps,unconverged_points
1,0.1,0.001,55363.7621895969,1,0,0,0
2,0.2,0.002,110727.52437918368,1,0,0,0
3,0.30000000000000004,0.0030000000000000005,166091.2865687729,1,0,0,0
4,0.4,0.004,221455.04875837138,1,0,0,0
5,0.5,0.005,276818.8109479645,1,0,0,0
6,0.6,0.006,332182.57313755347,1,0,0,0
7,0.7,0.006999999999999999,387546.33532714314,1,0,0,0
8,0.7999999999999999,0.008,442910.0975167413,1,0,0,0
9,0.8999999999999999,0.009,498273.85970633023,1,0,0,0
10,0.9999999999999999,0.009999999999999998,553637.6218959256,1,0,0,0
";

/// `examples/quick.toml` cut to 4 steps (to 8 mm), with its snapshots and a field plot at
/// 4 mm: 16 DEM assemblies of 105 discs on in-process workers.
fn tiny_dem() -> Job {
    let mut job = example("quick.toml");
    job.loading.compression.as_mut().unwrap().displacement = 0.008;
    job.output.field_plots_at = vec![0.004];
    job.validate().unwrap();
    job
}

/// `curve.csv` of `cosdem run` of [`tiny_dem`], recorded before the run driver (the same
/// with `--max-steps 2` and then `--resume`).
const TINY_DEM_CURVE: &str = "\
step,load_factor,displacement,load,iterations,cuts,dem_steps,unconverged_points
1,0.25,0.002,160687.43840472965,3,0,6790,0
2,0.5,0.004,312251.1841293094,1,0,1970,0
3,0.75,0.006,463608.13777537545,1,0,1920,0
4,1,0.008,614803.9547776841,1,0,1900,0
";

/// A fresh directory for one test.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("run_driver").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn curve_csv(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("curve.csv")).unwrap()
}

/// `(displacement, load)` of every row of a recorded curve.
fn points(csv: &str) -> Vec<(f64, f64)> {
    csv.lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (c[2], c[3])
        })
        .collect()
}

#[test]
fn elastic_job_gives_the_recorded_curve_through_the_driver_and_run_job() {
    let job = elastic();
    let dir = fresh("elastic");
    let outcome = Run::new(&job, &dir).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert_eq!(outcome.summary.as_ref().unwrap().status, "finished");
    assert_eq!(outcome.steps, 10);
    assert_eq!(curve_csv(&dir), ELASTIC_CURVE);
    assert_eq!(outcome.curve, points(ELASTIC_CURVE));

    // The sweep's entry point is the same driver.
    let dir = fresh("elastic-run-job");
    let (summary, curve) = run_job(&job, &dir, &WorkerChoice::default()).unwrap();
    assert_eq!(summary.status, "finished");
    assert_eq!(curve, points(ELASTIC_CURVE));
    assert_eq!(curve_csv(&dir), ELASTIC_CURVE);
    // A plain run writes no checkpoint.
    assert!(!dir.join("checkpoint.bin").exists());
}

/// The options `cosdem run` uses.
fn cli_like<'a>(job: &'a Job, dir: &'a Path) -> Run<'a> {
    Run::new(job, dir).checkpoints(true).snapshots(true)
}

#[test]
fn dem_run_stopped_at_max_steps_resumes_to_the_uninterrupted_curve() {
    let job = tiny_dem();
    let whole = fresh("dem-whole");
    let outcome = cli_like(&job, &whole).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert_eq!(curve_csv(&whole), TINY_DEM_CURVE);
    assert!(whole.join("snapshots").join("e0_p3.pvd").is_file());

    let split = fresh("dem-split");
    let outcome = cli_like(&job, &split).max_steps(Some(2)).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Stopped), "{:?}", outcome.ending);
    assert_eq!(outcome.summary.as_ref().unwrap().status, "stopped");
    assert_eq!(outcome.steps, 2);
    assert!(split.join("checkpoint.bin").is_file());
    let head: String = TINY_DEM_CURVE.split_inclusive('\n').take(3).collect();
    assert_eq!(curve_csv(&split), head);

    let outcome = cli_like(&job, &split).resume(false).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert_eq!(outcome.summary.as_ref().unwrap().status, "finished");
    assert_eq!(curve_csv(&split), curve_csv(&whole));
    assert_eq!(outcome.curve, points(TINY_DEM_CURVE));
    // The per-step outputs of the resumed run are those of the uninterrupted one.
    for file in ["vtk/mesh_00004.vtu", "vtk/gauss_00004.vtu", "fields.pvd"] {
        let (a, b) = (whole.join(file), split.join(file));
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{file}");
    }
}

#[test]
fn a_stop_flag_set_before_the_run_stops_it_after_the_first_step() {
    let job = elastic();
    let dir = fresh("elastic-flag");
    let flag = Arc::new(AtomicBool::new(true));
    let outcome = Run::new(&job, &dir).stop_flag(flag).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Interrupted), "{:?}", outcome.ending);
    let status = outcome.summary.unwrap().status;
    assert!(status.starts_with("interrupted: stop requested after step 1"), "{status}");
    assert_eq!(outcome.steps, 1);
    assert!(dir.join("checkpoint.bin").is_file());
    let head: String = ELASTIC_CURVE.split_inclusive('\n').take(2).collect();
    assert_eq!(curve_csv(&dir), head);
}

/// Counts the steps the driver reports and the order of the hooks.
#[derive(Default)]
struct Seen {
    /// The job's load set and reaction factor.
    load_set: String,
    load_scale: f64,
    started: bool,
    loads: Vec<f64>,
    ended: bool,
}

impl RunObserver for Seen {
    fn on_start(&mut self) -> Result<(), cosdem_app::run::HookError> {
        self.started = true;
        Ok(())
    }

    fn on_step(
        &mut self,
        r: &StepReport,
        _: &SolutionView<'_>,
        record: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        assert!(self.started && record.is_none());
        self.loads.push(-self.load_scale * r.reactions[&self.load_set][1]);
        Ok(())
    }

    fn on_end(&mut self) {
        self.ended = true;
    }
}

#[test]
fn a_run_without_directory_reports_the_steps_of_the_callers_material() {
    let job = elastic();
    let mut seen = Seen {
        load_set: job.loading.load_set.clone(),
        load_scale: job.load_scale(),
        ..Seen::default()
    };
    let outcome = Run::without_dir(&job)
        .material(|_| Ok(Box::new(job.elastic().unwrap())))
        .observer(&mut seen)
        .execute()
        .unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert!(outcome.summary.is_none() && outcome.curve.is_empty());
    assert!(seen.ended);
    let recorded: Vec<f64> = points(ELASTIC_CURVE).iter().map(|p| p.1).collect();
    assert_eq!(seen.loads, recorded);
}

#[test]
fn checkpoints_without_a_run_directory_are_refused() {
    let job = elastic();
    let err = Run::without_dir(&job).max_steps(Some(1)).execute().unwrap_err();
    assert!(matches!(err, cosdem_app::run::RunError::NoRunDirectory), "{err}");
}
