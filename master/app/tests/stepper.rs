//! A job's solver driven one stage at a time from outside ([`Stepper`]) is the job file's
//! stages: the same stages fed one by one give the run's steps bit for bit, a checkpoint and
//! resume change nothing, a stage that fails leaves no trace, and what the caller reads
//! (reactions, displacements, Gauss-point fields, the run directory) is what the closed forms
//! and the run directory's reader say.
//!
//! "Bit for bit" is checked through the `Debug` text of the step reports and Gauss-point
//! states (Rust writes every `f64` in the shortest form that reads back to the same bits, and
//! `-0.0` as such) and through the bytes of the run directories' files.

use cosdem_app::output::run_dir::{RunWriter, comparable_files};
use cosdem_app::results::RunReader;
use cosdem_app::run::{Ending, Run, RunError, RunObserver, WorkerChoice, material_for};
use cosdem_app::stepper::{StageReport, Stepper, StepperOptions, stage_from_toml};
use cosdem_common::MicroResponse;
use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::{Job, MaterialSection, StageSection, fixtures};
use std::path::{Path, PathBuf};

/// A fresh scratch directory path (not created) for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("stepper").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.parent().unwrap()).unwrap();
    dir
}

fn stage(text: &str) -> StageSection {
    stage_from_toml(text).unwrap()
}

/// The elastic panel (1 x 1 m, 2 x 2 Q8, G = 10 MPa) in three stages: compressed by 1 cm in 4
/// steps between rough platens, unloaded by an increment to where it started, reloaded.
const ELASTIC_STAGES: &str = r#"
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
steps = 3
prescribed = [{ set = "top", component = "uy", increment = 5e-3 }]

[[stage]]
name = "reload"
steps = 2
prescribed = [{ set = "top", component = "uy", value = -1.5e-2 }]
"#;

fn elastic_staged() -> Job {
    with_settlement_curve(Job::from_toml(ELASTIC_STAGES, "stages.toml").unwrap())
}

/// `job` with the curve a stepper draws when the job names none (the settlement of `top`
/// against its reaction): a run of the job's stages draws the same, so that the two run
/// directories can be compared.
fn with_settlement_curve(mut job: Job) -> Job {
    let settlement = |set: &str| cosdem_job::CurveQuantity {
        set: set.into(),
        component: cosdem_job::ComponentChoice::Uy,
        scale: -1.0,
    };
    job.output.curve = Some(cosdem_job::CurveSection {
        control: settlement("top"),
        load: settlement("top"),
        reactions: Vec::new(),
    });
    job
}

/// The `dem-one-element` fixture (one Q8 element, 4 hexagonal assemblies of side 0.06 m, 100
/// kPa on its sides) in two stages instead of its `[loading]`: compressed by 2 mm between rough
/// platens in 2 steps, then by 2 mm more in 2 steps, the pressures held.
fn dem_staged() -> Job {
    let mut job = fixtures::load("dem-one-element");
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.06;
    job.loading = Default::default();
    job.stage = vec![
        stage(
            r#"
name = "compress"
steps = 2
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "bottom", component = "ux", value = 0.0 },
  { set = "top", component = "ux", value = 0.0 },
  { set = "top", component = "uy", value = -2e-3 },
]
pressure = [{ set = "left", value = 1e5 }, { set = "right", value = 1e5 }]
"#,
        ),
        stage(
            r#"
name = "more"
steps = 2
prescribed = [{ set = "top", component = "uy", increment = -2e-3 }]
"#,
        ),
    ];
    job.validate().unwrap();
    with_settlement_curve(job)
}

/// A run's step reports.
#[derive(Default)]
struct Reports(Vec<StepReport>);

impl RunObserver for Reports {
    fn on_step(
        &mut self,
        report: &StepReport,
        _: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        self.0.push(report.clone());
        Ok(())
    }
}

fn text<T: std::fmt::Debug + ?Sized>(x: &T) -> String {
    format!("{x:?}")
}

/// The Gauss points' states as text, but for the wall time of their last relaxation (the
/// one thing in them that is not a function of the job).
fn points(stepper: &Stepper) -> String {
    let mut p = stepper.gauss_points().to_vec();
    p.iter_mut().for_each(|g| g.diagnostics.wall_seconds = 0.0);
    text(&p)
}

fn all_steps(reports: &[StageReport]) -> Vec<StepReport> {
    reports.iter().flat_map(|r| r.steps.clone()).collect()
}

fn with_dir(dir: &Path) -> StepperOptions {
    StepperOptions { dir: Some(dir.to_path_buf()), ..StepperOptions::default() }
}

/// (1) A job whose `[[stage]]` list is S, run by `Run`, and the same stages fed one by one to a
/// stepper of that job (whose own stages it does not apply) take the same steps: the step
/// reports (load factors, reactions, iterations, DEM steps) and every file of the two run
/// directories but the summary, the provenance and the lock are equal, bit for bit (no
/// tolerance: the stepper is the job file's stages driven from outside). Elastic (9 steps,
/// a change of prescribed dofs between stages) and DEM (4 steps, held pressures, particle
/// snapshots of one point; the assemblies' states are exported before each stage, which must
/// change nothing).
#[test]
fn a_jobs_stages_fed_one_by_one_are_its_run_bit_for_bit() {
    let mut dem = dem_staged();
    dem.output.snapshots = vec![[0, 2]];
    for (name, job) in [("elastic", elastic_staged()), ("dem", dem)] {
        let snapshots = !job.output.snapshots.is_empty();
        let run_dir = scratch(&format!("same-{name}-run"));
        let mut seen = Reports::default();
        let run = Run::new(&job, &run_dir).observer(&mut seen).snapshots(snapshots);
        let outcome = run.execute().unwrap();
        assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);

        let dir = scratch(&format!("same-{name}-stepper"));
        let options = StepperOptions { snapshots, ..with_dir(&dir) };
        let mut stepper = Stepper::new(&job, options).unwrap();
        assert_eq!((stepper.steps(), stepper.stages().len()), (0, 0));
        let mut reports = Vec::new();
        for (i, s) in job.stage.iter().enumerate() {
            let r = stepper.step(s.clone()).unwrap();
            assert_eq!((r.index, r.steps.len()), (i, s.steps), "{name}: stage {i}");
            reports.push(r);
        }
        assert_eq!(stepper.steps(), outcome.steps);
        assert_eq!(text(&all_steps(&reports)), text(&seen.0), "{name}: step reports");
        assert_eq!(stepper.curve().unwrap(), &outcome.curve[..], "{name}: curve");
        let summary = stepper.finish().unwrap().unwrap();
        assert_eq!(summary.status, "finished");
        let (a, b) = (comparable_files(&run_dir).unwrap(), comparable_files(&dir).unwrap());
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "{name}");
        for (file, bytes) in &a {
            assert!(&b[file] == bytes, "{name}: {file} differs");
        }
        assert!(a.contains_key("curve.csv") && a.contains_key("vtk/gauss_00004.vtu"));
        if snapshots {
            assert!(a.contains_key("snapshots/e0_p2/snap_00004.vtu"), "{:?}", a.keys());
        }
    }
}

/// A stepper can move to another thread (a Python binding's object, behind a lock).
#[test]
fn a_stepper_is_send() {
    fn send<T: Send>() {}
    send::<Stepper>();
}

/// (2) On the elastic panel, a prescribed `uy` on `top` is what `displacement("top", "uy")`
/// reads at every node (to rounding: the value is reached as start + (target - start) at load
/// factor 1, exact from a start of 0, 1e-15 relative for a second stage), and the reaction on
/// `top` balances the one on `bottom` (the only other supports; the free nodes' residual is
/// the round-off of a linear solve of a linear problem, far below 1e-9 of the load). A dof
/// held by the first stage and not named by the second stays where it was (exactly), and the
/// linear material's reaction grows in proportion to the displacement (1e-9: round-off).
#[test]
fn a_prescribed_uy_is_read_back_and_the_reactions_balance() {
    let mut stepper = Stepper::new(&fixtures::load("elastic-panel"), Default::default()).unwrap();
    assert_eq!(stepper.reactions("top").unwrap(), [0.0; 3], "no load before the first stage");
    stepper
        .step(stage(
            r#"
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "bottom", component = "ux", value = 0.0 },
  { set = "top", component = "ux", value = 0.0 },
  { set = "top", component = "uy", value = -1e-2 },
]
"#,
        ))
        .unwrap();
    assert_eq!((stepper.steps(), stepper.load_factor()), (1, 1.0), "one step by default");
    let top = stepper.displacement("top", "uy").unwrap();
    assert_eq!(top.len(), 5, "2 x 2 Q8: 5 nodes on an edge");
    assert!(top.iter().all(|&u| u == -1e-2), "{top:?}");
    assert!(stepper.displacement("bottom", "uy").unwrap().iter().all(|&u| u == 0.0));
    let balance = |s: &Stepper| {
        let (t, b) = (s.reactions("top").unwrap(), s.reactions("bottom").unwrap());
        assert!(t[1].abs() > 1e4, "the platens carry the load: {t:?}");
        for c in 0..2 {
            assert!((t[c] + b[c]).abs() <= 1e-9 * t[1].abs(), "component {c}: {t:?} {b:?}");
        }
        t[1]
    };
    let first = balance(&stepper);

    stepper
        .step(stage("prescribed = [{ set = \"top\", component = \"uy\", increment = -5e-3 }]"))
        .unwrap();
    let top = stepper.displacement("top", "uy").unwrap();
    assert!(top.iter().all(|&u| (u + 1.5e-2).abs() <= 1e-15 * 1.5e-2), "{top:?}");
    assert!(stepper.displacement("bottom", "uy").unwrap().iter().all(|&u| u == 0.0));
    assert!(stepper.displacement("top", "ux").unwrap().iter().all(|&u| u == 0.0));
    let second = balance(&stepper);
    assert!((second - 1.5 * first).abs() <= 1e-9 * second.abs(), "{first} {second}");
    assert_eq!(stepper.displacement("left", "w").unwrap().len(), 5, "a Cosserat mesh has w");
}

/// (3) A checkpoint taken between stages and resumed in a new stepper (new solver, new
/// assemblies, the run directory continued) goes on bit for bit as the stepper that never
/// stopped: the next stage's step reports and Gauss-point states, and every file of the two
/// run directories. Elastic (a change of prescribed dofs after the checkpoint) and DEM (the
/// assemblies' committed states come from the checkpoint).
#[test]
fn checkpoint_and_resume_go_on_bit_for_bit() {
    for (name, job) in [("elastic", elastic_staged()), ("dem", dem_staged())] {
        let straight_dir = scratch(&format!("resume-{name}-straight"));
        let mut straight = Stepper::new(&job, with_dir(&straight_dir)).unwrap();
        let mut expected = Vec::new();
        for s in &job.stage {
            expected.push(straight.step(s.clone()).unwrap());
        }
        let expected_points = points(&straight);
        straight.finish().unwrap();

        let dir = scratch(&format!("resume-{name}-stopped"));
        let checkpoint = scratch(&format!("resume-{name}.bin"));
        let mut first = Stepper::new(&job, with_dir(&dir)).unwrap();
        first.step(job.stage[0].clone()).unwrap();
        first.checkpoint(&checkpoint).unwrap();
        // The checkpoint holds the job the stepper runs: a resume needs nothing else.
        let held = Stepper::job_of(&checkpoint).unwrap();
        assert_eq!(text(&held), text(first.job()), "{name}: the job in the checkpoint");
        drop(first);
        let mut alone = Stepper::resume(&checkpoint, &held, Default::default()).unwrap();
        let alone_reports: Vec<_> =
            job.stage[1..].iter().map(|s| alone.step(s.clone()).unwrap()).collect();
        assert_eq!(
            text(&alone_reports),
            text(&expected[1..]),
            "{name}: resumed from the checkpoint alone"
        );
        let mut resumed = Stepper::resume(&checkpoint, &job, with_dir(&dir)).unwrap();
        assert_eq!(resumed.stages(), &job.stage[..1]);
        assert_eq!(resumed.steps(), job.stage[0].steps as u64);
        let mut got = Vec::new();
        for s in &job.stage[1..] {
            got.push(resumed.step(s.clone()).unwrap());
        }
        assert_eq!(text(&got), text(&expected[1..]), "{name}: the stages after the resume");
        assert_eq!(points(&resumed), expected_points, "{name}: Gauss points");
        resumed.finish().unwrap();
        let (a, b) = (comparable_files(&straight_dir).unwrap(), comparable_files(&dir).unwrap());
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "{name}");
        for (file, bytes) in &a {
            assert!(&b[file] == bytes, "{name}: {file} differs");
        }
    }
}

/// A run's checkpoint is not a stepper's, and the other way round: each is refused naming the
/// file (also when a stepper's job is asked of a run's checkpoint).
#[test]
fn a_runs_checkpoint_and_a_steppers_are_not_mixed_up() {
    let job = elastic_staged();
    let dir = scratch("kinds-run");
    let outcome = Run::new(&job, &dir).max_steps(Some(2)).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Stopped), "{:?}", outcome.ending);
    let file = dir.join(cosdem_app::checkpoint::FILE);
    let e = Stepper::resume(&file, &job, Default::default()).err().unwrap().to_string();
    assert!(e.contains("checkpoint.bin") && e.contains("not by a stepper"), "{e}");
    let e = Stepper::job_of(&file).err().unwrap().to_string();
    assert!(e.contains("checkpoint.bin") && e.contains("not by a stepper"), "{e}");

    let mut stepper = Stepper::new(&job, Default::default()).unwrap();
    stepper.step(job.stage[0].clone()).unwrap();
    stepper.checkpoint(&file).unwrap();
    let e = Run::new(&job, &dir).resume(false).execute().err().unwrap().to_string();
    assert!(e.contains("checkpoint.bin") && e.contains("written by a stepper"), "{e}");
}

/// A material that fails wherever the compressive strain `-e_yy` of a trial exceeds `cap`,
/// before asking the wrapped one (which then never sees the trial): a stage past the cap fails
/// once its steps, cut, cannot get any closer to it, after committing those below it.
struct StrainCap {
    inner: Box<dyn Material>,
    cap: f64,
}

impl Material for StrainCap {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let over: Vec<_> = inputs
            .iter()
            .filter(|i| -i.deformation.strain()[1] > self.cap)
            .map(|i| (i.gauss_point, format!("strain over the cap {}", self.cap)))
            .collect();
        if !over.is_empty() {
            return Err(MaterialError::GaussPoints(over));
        }
        self.inner.evaluate(trial, inputs)
    }
    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        self.inner.commit(step)
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.inner.rollback()
    }
    fn is_symmetric(&self) -> bool {
        self.inner.is_symmetric()
    }
    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        self.inner.committed_states()
    }
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        self.inner.restore_states(states)
    }
    fn snapshot(
        &mut self,
        id: cosdem_common::GaussPointId,
    ) -> Result<Option<MicroSnapshot>, MaterialError> {
        self.inner.snapshot(id)
    }
}

/// `job`'s own material behind a [`StrainCap`] of `cap`.
fn capped(job: &Job, cap: f64, dir: &Path) -> StepperOptions {
    let job = job.clone();
    StepperOptions {
        dir: Some(dir.to_path_buf()),
        material: Some(Box::new(move |ids| {
            let mesh = job.build_mesh()?;
            let built = material_for(&job, &WorkerChoice::default(), &mesh, ids, None)?;
            Ok(Box::new(StrainCap { inner: built.material, cap }) as Box<dyn Material>)
        })),
        ..StepperOptions::default()
    }
}

/// Counts the committed steps a stepper shows its observer.
#[derive(Default)]
struct Count(usize);

impl RunObserver for Count {
    fn on_step(
        &mut self,
        _: &StepReport,
        _: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        self.0 += 1;
        Ok(())
    }
}

/// (4) Bad input leaves the stepper as it was. A stage naming a set the mesh lacks is refused
/// before anything moves, naming the key, the set and the known sets; so are an unknown set
/// in `reactions` and an unknown component in `displacement`. A stage that fails after
/// committing steps (a strain cap past which the material fails) is undone: the error names
/// the stage and the reason, the stepper is back where the stage started, and the next, easier
/// stage gives bit for bit what a stepper that never tried the failed one gives (reports,
/// Gauss points, every file of the run directories: the failed stage's rows and VTK files are
/// gone). Elastic and DEM (the assemblies get their states from before the stage back).
#[test]
fn bad_input_and_a_failed_stage_leave_the_stepper_usable() {
    let job = fixtures::load("elastic-panel");
    let mut stepper = Stepper::new(&job, Default::default()).unwrap();
    let bad = stage("prescribed = [{ set = \"lid\", component = \"uy\", value = -1e-3 }]");
    let e = stepper.step(bad).unwrap_err().to_string();
    assert!(e.contains("stage[0].prescribed[0].set") && e.contains("lid"), "{e}");
    assert!(e.contains("known: ") && e.contains("bottom") && e.contains("top"), "{e}");
    assert_eq!((stepper.steps(), stepper.stages().len()), (0, 0));
    let e = stepper.reactions("lid").unwrap_err();
    assert!(matches!(e, RunError::Unknown { what: "node set", .. }), "{e:?}");
    let e = e.to_string();
    assert!(e.contains("\"lid\"") && e.contains("bottom, ") && e.contains("top"), "{e}");
    let e = stepper.displacement("top", "uz").unwrap_err().to_string();
    assert!(e.contains("component \"uz\"") && e.contains("known: ux, uy, w"), "{e}");
    let e = stage_from_toml("steps = \"two\"").unwrap_err().to_string();
    assert!(e.contains("steps"), "{e}");

    let supports = r#"
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "bottom", component = "ux", value = 0.0 },
  { set = "top", component = "ux", value = 0.0 },
  { set = "top", component = "uy", value = -1e-3 },
]
pressure = [{ set = "left", value = 1e5 }, { set = "right", value = 1e5 }]
"#;
    let dem = {
        let mut j = dem_staged();
        j.stage.clear();
        j
    };
    for (name, job) in [("elastic", job), ("dem", dem)] {
        let dir = scratch(&format!("failed-{name}"));
        let mut stepper = Stepper::new(&job, capped(&job, 3e-3, &dir)).unwrap();
        stepper.step(stage(supports)).unwrap();
        let before = (stepper.steps(), points(&stepper));
        let mut count = Count::default();
        let hard = stage(
            r#"
name = "too far"
steps = 2
prescribed = [{ set = "top", component = "uy", value = -1e-2 }]
"#,
        );
        let e = stepper.step_observed(hard, &mut count).unwrap_err();
        let RunError::StageFailed { index, step, .. } = &e else { panic!("{e:?}") };
        assert_eq!((*index, *step), (1, before.0), "{name}");
        assert!(count.0 > 0, "{name}: the failed stage committed steps before failing");
        let message = e.to_string();
        assert!(message.contains("stage 1 (\"too far\") failed"), "{message}");
        assert!(message.contains("strain over the cap"), "{message}");
        assert_eq!((stepper.steps(), points(&stepper)), before, "{name}: undone");
        assert_eq!(stepper.stages().len(), 1);
        let rows = RunReader::open(&dir).unwrap().curve().unwrap().rows() as u64;
        assert_eq!(rows, before.0, "{name}: the failed stage's rows are gone");

        let easy =
            stage("steps = 2\nprescribed = [{ set = \"top\", component = \"uy\", value = -2e-3 }]");
        let after = stepper.step(easy.clone()).unwrap();
        stepper.finish().unwrap();
        let never_dir = scratch(&format!("failed-{name}-never"));
        let mut never = Stepper::new(&job, capped(&job, 3e-3, &never_dir)).unwrap();
        never.step(stage(supports)).unwrap();
        let expected = never.step(easy).unwrap();
        assert_eq!(text(&after.steps), text(&expected.steps), "{name}");
        never.finish().unwrap();
        let (a, b) = (comparable_files(&never_dir).unwrap(), comparable_files(&dir).unwrap());
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "{name}");
        for (file, bytes) in &a {
            assert!(&b[file] == bytes, "{name}: {file} differs");
        }
    }
}

/// (5) The run directory a stepper writes is a run directory: `RunReader` reads its curve (one
/// row per committed step, numbered 1 to n, the pseudo-time of two stages), its summary
/// (`running` while the stepper holds it, `finished` after), and its last step's Gauss-point
/// file, which holds exactly the stepper's own Gauss-point fields (binary VTK: the values'
/// bytes).
#[test]
fn a_steppers_run_directory_reads_back() {
    let mut job = fixtures::load("elastic-panel");
    job.output.vtk_format = cosdem_job::VtkFormat::Binary;
    let dir = scratch("reads-back");
    let mut stepper = Stepper::new(&job, with_dir(&dir)).unwrap();
    let staged = elastic_staged();
    stepper.step(staged.stage[0].clone()).unwrap();
    stepper.step(staged.stage[1].clone()).unwrap();
    let n = stepper.steps();
    assert_eq!(n, 7);
    let reader = RunReader::open(&dir).unwrap();
    let curve = reader.curve().unwrap();
    assert_eq!(curve.rows() as u64, n);
    let steps: Vec<f64> = (1..=n).map(|k| k as f64).collect();
    assert_eq!(curve.column("step").unwrap(), &steps[..]);
    let time = curve.column("time").unwrap();
    assert_eq!((time[3], time[6]), (1.0, 2.0), "stage ends at pseudo-times 1 and 2");
    assert_eq!(reader.summary().unwrap()["status"], "running");
    assert_eq!(reader.saved_steps().unwrap(), (1..=n).collect::<Vec<_>>());
    assert_eq!(reader.gauss(n).unwrap(), stepper.gauss_fields().unwrap());
    stepper.finish().unwrap();
    assert_eq!(reader.summary().unwrap()["status"], "finished");
    assert_eq!(reader.summary().unwrap()["steps"], n);
}
