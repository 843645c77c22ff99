//! Resume is bit-identical: a small DEM job (the quick panel reduced to one element, 4 Gauss
//! points, 4 steps) run straight through, and the same job stopped after step 2 (as Ctrl-C
//! does) and resumed from its checkpoint in fresh solver, pool and writer objects, write
//! byte-identical `curve.csv` and `.pvd` series.

use super::*;
use crate::output::run_dir::{RunSettings, RunWriter};
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;

const JOB: &str = r#"
    [mesh]
    kind = "rectangle"
    lx = 1.0
    ly = 1.0
    nx = 1
    ny = 1
    [loading]
    steps = 4
    [loading.compression]
    displacement = 0.008
    [[loading.pressure]]
    set = "left"
    value = 1.0e5
    [[loading.pressure]]
    set = "right"
    value = 1.0e5
    [newton]
    force_tolerance = 5.0e-3
    displacement_tolerance = 5.0e-3
    max_iterations = 20
    [material]
    kind = "dem"
    [material.assembly]
    packing = { kind = "hexagonal", radius = 0.005, side = 0.06 }
"#;

fn settings(job: &Job) -> RunSettings {
    RunSettings {
        title: String::new(),
        shortening: job.shortening(),
        load_set: "top".into(),
        load_scale: 1.0,
        vtk_every: 1,
        internal_length: 0.01,
        linear_range: 0.01,
    }
}

fn pool(job: &Job, ids: &[GaussPointId], states: Option<Vec<AssemblyState>>) -> Pool {
    let config = PoolConfig { in_process_threads: 1, ..PoolConfig::default() };
    let mut pool = Pool::in_process(1, config, |_| Dem).unwrap();
    match states {
        Some(s) => pool.restore_states(s).unwrap(),
        None => {
            let cosdem_job::MaterialSection::Dem { assembly } = &job.material else { panic!() };
            let req = AssemblyRequest {
                spec_json: serde_json::to_vec(assembly).unwrap(),
                boundary: BoundaryKind::Unspecified,
                disc_count_hint: 0,
            };
            pool.create_assemblies(ids, &req).unwrap();
        }
    }
    pool
}

fn ids(solver: &Solver) -> Vec<GaussPointId> {
    let per = solver.gauss().per_element as u32;
    (0..solver.model().mesh.n_elements() as u32)
        .flat_map(|e| (0..per).map(move |p| GaussPointId::new(e, p)))
        .collect()
}

/// Sets the stop flag once step `at` is observed (what Ctrl-C during that step does).
struct StopAt<'a> {
    writer: &'a mut RunWriter,
    at: u64,
    flag: Arc<AtomicBool>,
}

impl StepObserver for StopAt<'_> {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> Result<()> {
        self.writer.on_step(r, s)?;
        if r.step == self.at {
            self.flag.store(true, Ordering::SeqCst);
        }
        Ok(())
    }
}

fn run(dir: &Path, job: &Job, stop_at: u64, resume: bool) -> Result<()> {
    run_with(dir, job, stop_at, resume, false)
}

fn run_with(dir: &Path, job: &Job, stop_at: u64, resume: bool, newton_changed: bool) -> Result<()> {
    let mut solver = Solver::new(job.model()?, job.solver_settings()?)?;
    let ids = ids(&solver);
    let (mut writer, mut material) = if resume {
        let c = Checkpoint::read(&dir.join(FILE))?;
        c.check_job(job, dir, newton_changed)?;
        let states = c.assembly_states();
        let step = c.solver.step;
        solver.restore(c.solver)?;
        (RunWriter::resume(dir, settings(job), step).unwrap(), pool(job, &ids, Some(states)))
    } else {
        (RunWriter::create(dir, settings(job)).unwrap(), pool(job, &ids, None))
    };
    let flag = Arc::new(AtomicBool::new(false));
    let inner = StopAt { writer: &mut writer, at: stop_at, flag: flag.clone() };
    let mut obs = Checkpointer::new(inner, dir, 1, job, flag);
    solver.run(&mut material, &mut obs).map(|_| ())
}

#[test]
fn stopped_and_resumed_run_is_bit_identical() {
    let job = Job::from_toml(JOB, "small").unwrap();
    let base = std::env::temp_dir().join(format!("cosdem-ckpt-{}", std::process::id()));
    let (straight, resumed) = (base.join("straight"), base.join("resumed"));
    run(&straight, &job, u64::MAX, false).unwrap();
    let e = run(&resumed, &job, 2, false).unwrap_err();
    assert!(matches!(e, Error::Interrupted { step: 2 }), "{e}");
    let half = std::fs::read_to_string(resumed.join("curve.csv")).unwrap();
    assert_eq!(half.lines().count(), 3, "{half}");
    run(&resumed, &job, u64::MAX, true).unwrap();
    for f in ["curve.csv", "fields.pvd", "gauss.pvd", "vtk/gauss_00004.vtu", "vtk/mesh_00003.vtu"] {
        let a = std::fs::read(straight.join(f)).unwrap();
        let b = std::fs::read(resumed.join(f)).unwrap();
        assert!(a == b, "{f} differs after resume");
    }
    assert_eq!(std::fs::read_to_string(straight.join("curve.csv")).unwrap().lines().count(), 5);
    // A changed job is refused.
    let other = Job::from_toml(&JOB.replace("0.008", "0.009"), "other").unwrap();
    let c = Checkpoint::read(&resumed.join(FILE)).unwrap();
    assert!(c.check_job(&other, &resumed, true).unwrap_err().to_string().contains("another job"));
    std::fs::remove_dir_all(&base).unwrap();
}

/// A resume with changed `[newton]` settings is refused unless asked for; asked for, the steps
/// done stay as they were and the steps to come are solved with the new settings: here the
/// force tolerance tightened by 10^3, so they take more iterations than the straight run's.
#[test]
fn a_resume_may_change_the_newton_settings_when_asked() {
    let job = Job::from_toml(JOB, "small").unwrap();
    let tight = Job::from_toml(
        &JOB.replace("force_tolerance = 5.0e-3", "force_tolerance = 5.0e-6"),
        "tight",
    )
    .unwrap();
    assert_eq!(job_digest(&job), job_digest(&tight), "newton is not the physics digest's");
    let base = std::env::temp_dir().join(format!("cosdem-ckpt-newton-{}", std::process::id()));
    let (straight, resumed) = (base.join("straight"), base.join("resumed"));
    run(&straight, &job, u64::MAX, false).unwrap();
    let e = run(&resumed, &job, 2, false).unwrap_err();
    assert!(matches!(e, Error::Interrupted { step: 2 }), "{e}");
    let refused = run(&resumed, &tight, u64::MAX, true).unwrap_err().to_string();
    assert!(refused.contains("[newton]") && refused.contains("--newton-changed"), "{refused}");
    run_with(&resumed, &tight, u64::MAX, true, true).unwrap();
    let rows = |d: &Path| -> Vec<String> {
        std::fs::read_to_string(d.join("curve.csv")).unwrap().lines().map(String::from).collect()
    };
    let (a, b) = (rows(&straight), rows(&resumed));
    assert_eq!(a.len(), b.len());
    assert_eq!(a[..3], b[..3], "the header and the two steps done before the stop are kept");
    // curve.csv's fifth column: the step's Newton iterations.
    let iterations = |d: &Path| -> u64 {
        rows(d)[3..].iter().map(|r| r.split(',').nth(4).unwrap().parse::<u64>().unwrap()).sum()
    };
    assert!(
        iterations(&resumed) > iterations(&straight),
        "steps 3 and 4 under the tighter tolerance iterate more: {} vs {}",
        iterations(&resumed),
        iterations(&straight)
    );
    std::fs::remove_dir_all(&base).unwrap();
}

/// A file of the first format, or none of ours, is refused with an error that says which.
#[test]
fn old_and_foreign_files_are_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("cosdem-ckpt-format-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(FILE);
    std::fs::write(&path, b"CDEMCKP1 and whatever followed").unwrap();
    let old = Checkpoint::read(&path).unwrap_err().to_string();
    assert!(old.contains("first format") && old.contains("CDEMCKP1"), "{old}");
    std::fs::write(&path, b"PK\x03\x04 a zip file").unwrap();
    let foreign = Checkpoint::read(&path).unwrap_err().to_string();
    assert!(foreign.contains("not a cosdem checkpoint"), "{foreign}");
    std::fs::remove_dir_all(&dir).unwrap();
}
