//! Resume is bit-identical: a small DEM job (the quick panel reduced to one element, 4 Gauss
//! points, 4 steps) run straight through, and the same job stopped after step 2 (as Ctrl-C
//! does) and resumed from its checkpoint in fresh solver, pool and writer objects, write
//! byte-identical `curve.csv` and `.pvd` series. The file format: a bit-exact round trip, every
//! flipped bit refused with the file named, older and foreign files refused by name.

use super::*;
use crate::output::run_dir::{RunSettings, RunWriter};
use crate::run::{WorkerChoice, gauss_point_ids, material_for};
use cosdem_job::{MaterialSection, fixtures};
use cosdem_pool::PoolConfig;
use std::collections::BTreeMap;

/// The `dem-one-element` fixture (one Q8 element, 4 hexagonal assemblies) compressed by 8 mm
/// in 4 steps, with smaller assemblies (side 0.06 m).
fn small_job() -> Job {
    let mut job = fixtures::load("dem-one-element");
    job.loading.steps = 4;
    job.loading.compression.as_mut().unwrap().displacement = 0.008;
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.06;
    job.validate().unwrap();
    job
}

/// `small_job` with another compression: another job to a checkpoint.
fn displaced(displacement: f64) -> Job {
    let mut job = small_job();
    job.loading.compression.as_mut().unwrap().displacement = displacement;
    job
}

fn settings(job: &Job) -> RunSettings {
    RunSettings {
        title: String::new(),
        shortening: job.shortening(),
        load_set: "top".into(),
        load_scale: 1.0,
        vtk_every: 1,
        internal_length: 0.01,
        linear_range: 0.01,
        curve: None,
        pvd_time: crate::output::run_dir::PvdTime::Displacement,
        vtk_encoding: crate::output::Encoding::Ascii,
        packings: Default::default(),
    }
}

/// The job's material on one in-process worker of one thread: new assemblies, or `states`.
fn dem_material(
    job: &Job,
    ids: &[GaussPointId],
    states: Option<Vec<AssemblyState>>,
) -> Box<dyn Material> {
    let config = PoolConfig { in_process_threads: 1, ..PoolConfig::default() };
    let workers = WorkerChoice { addresses: Vec::new(), config };
    let mesh = job.build_mesh().unwrap();
    material_for(job, &workers, &mesh, ids, states).unwrap().material
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
    let ids = gauss_point_ids(&solver);
    let (mut writer, mut material) = if resume {
        let c = Checkpoint::read(&dir.join(FILE))?;
        c.check_job(job, dir, newton_changed)?;
        let states = c.assembly_states();
        let step = c.solver.step;
        solver.restore(c.solver)?;
        (
            RunWriter::resume(dir, settings(job), step).unwrap(),
            dem_material(job, &ids, Some(states)),
        )
    } else {
        (RunWriter::create(dir, settings(job)).unwrap(), dem_material(job, &ids, None))
    };
    let flag = Arc::new(AtomicBool::new(false));
    let inner = StopAt { writer: &mut writer, at: stop_at, flag: flag.clone() };
    let mut obs = Checkpointer::new(inner, dir, 1, job, flag);
    solver.run(material.as_mut(), &mut obs).map(|_| ())
}

#[test]
fn stopped_and_resumed_run_is_bit_identical() {
    let job = small_job();
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
    let other = displaced(0.009);
    let c = Checkpoint::read(&resumed.join(FILE)).unwrap();
    assert!(c.check_job(&other, &resumed, true).unwrap_err().to_string().contains("another job"));
    // A real checkpoint (four assembly states): a deterministic sample of 400 single-bit flips
    // spread over the whole file (a stride prime to its length in bits) is refused.
    let path = resumed.join(FILE);
    let good = std::fs::read(&path).unwrap();
    let n = 8 * good.len();
    for k in 0..400 {
        let bit = (k * 7919 + k / 3) % n;
        let mut b = good.clone();
        b[bit / 8] ^= 1 << (bit % 8);
        std::fs::write(&path, &b).unwrap();
        let e = Checkpoint::read(&path).unwrap_err().to_string();
        assert!(e.contains("damaged") && e.contains(FILE), "bit {bit} of {n}: {e}");
    }
    std::fs::remove_dir_all(&base).unwrap();
}

/// A resume with changed `[newton]` settings is refused unless asked for; asked for, the steps
/// done stay as they were and the steps to come are solved with the new settings: here the
/// force tolerance tightened by 10^3, so they take more iterations than the straight run's.
#[test]
fn a_resume_may_change_the_newton_settings_when_asked() {
    let job = small_job();
    let mut tight = small_job();
    tight.newton.force_tolerance = 5.0e-6;
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

/// A small checkpoint whose floats are the awkward ones: signed zeros, a subnormal, the
/// extremes, an infinity and a NaN with a payload (a lossy float encoding would change them).
fn awkward() -> Checkpoint {
    let u = vec![
        0.0,
        -0.0,
        1.0 / 3.0,
        f64::MIN_POSITIVE / 3.0,
        f64::MAX,
        f64::NEG_INFINITY,
        f64::from_bits(0x7ff8_dead_beef_0001),
        -1e-300,
    ];
    Checkpoint {
        digests: Digests { job: 0x0123_4567_89ab_cdef, newton: u64::MAX },
        solver: SolverState {
            u,
            lambda: 0.1 + 0.2,
            step: 3,
            increment: 1e-3,
            committed: None,
            gauss_points: Vec::new(),
            reactions: BTreeMap::from([("top".to_string(), [1.5, -0.0, 7e-310])]),
            stage: 2,
            stage_start: Some(vec![-0.0, 1e-3, f64::MIN_POSITIVE]),
            progress: 0.1 + 0.7,
        },
        assemblies: vec![SavedAssembly {
            id: GaussPointId::new(0, 3),
            committed_step: 3,
            disc_count: 2,
            state: (0u8..40).collect(),
        }],
        stages: None,
        job: None,
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cosdem-ckpt-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Written and read back, a checkpoint is the same bit for bit (no tolerance: postcard writes
/// each f64 as its 8 bytes; compared through the bit patterns, as a NaN is not equal to
/// itself).
#[test]
fn round_trip_is_bit_exact() {
    let dir = scratch("roundtrip");
    let path = dir.join(FILE);
    let c = awkward();
    c.write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"CDEMCKP8");
    let back = Checkpoint::read(&path).unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.solver.u), bits(&c.solver.u));
    assert_eq!(back.solver.lambda.to_bits(), c.solver.lambda.to_bits());
    assert_eq!(
        back.solver.reactions["top"].map(f64::to_bits),
        [1.5, -0.0, 7e-310].map(f64::to_bits)
    );
    assert_eq!((back.digests, back.solver.step, &back.assemblies), (c.digests, 3, &c.assemblies));
    back.write(&path).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), bytes, "re-encoding gives the same bytes");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every single-bit flip of a small checkpoint is refused with the file named: in the header
/// as a damaged or foreign header (never as an older format: version 7 is two bits from each
/// older ones), in the body and in the checksum itself by the checksum. All bits are tried.
#[test]
fn every_flipped_bit_is_refused_naming_the_file() {
    let dir = scratch("flips");
    let path = dir.join(FILE);
    awkward().write(&path).unwrap();
    let good = std::fs::read(&path).unwrap();
    for bit in 0..8 * good.len() {
        let mut b = good.clone();
        b[bit / 8] ^= 1 << (bit % 8);
        std::fs::write(&path, &b).unwrap();
        let e = Checkpoint::read(&path).unwrap_err().to_string();
        assert!(e.contains(&path.display().to_string()), "bit {bit}: {e}");
        if bit < 64 {
            assert!(e.contains("no CDEMCKP8 header") && e.contains("damaged"), "bit {bit}: {e}");
        } else {
            assert!(e.contains("damaged: the CRC-32"), "bit {bit}: {e}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A checkpoint of an older format, or a file that is none of ours, is refused with
/// an error that says which.
#[test]
fn old_and_foreign_files_are_refused_by_name() {
    let dir = scratch("format");
    let path = dir.join(FILE);
    for old in ["CDEMCKP1", "CDEMCKP2", "CDEMCKP4", "CDEMCKP7"] {
        std::fs::write(&path, format!("{old} and whatever bincode followed")).unwrap();
        let e = Checkpoint::read(&path).unwrap_err().to_string();
        assert!(
            e.contains(old)
                && e.contains("an older format of an earlier cosdem")
                && e.contains("must be restarted")
                && e.contains(FILE),
            "{e}"
        );
    }
    std::fs::write(&path, b"PK\x03\x04 a zip file").unwrap();
    let foreign = Checkpoint::read(&path).unwrap_err().to_string();
    assert!(foreign.contains("not a cosdem checkpoint"), "{foreign}");
    std::fs::write(&path, b"CDEMCKP8").unwrap();
    let short = Checkpoint::read(&path).unwrap_err().to_string();
    assert!(short.contains("truncated"), "{short}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A run's checkpoint is the format as it was before stepper checkpoints: the header, the
/// postcard checkpoint and the CRC, nothing else (so a run's `checkpoint.bin` keeps its bytes
/// and older ones read). A stepper's checkpoint adds its caller's stages, which read back
/// equal, every number bit for bit (compared through the bit patterns: `-0.0 == 0.0`), and
/// each kind is refused where the other is expected, naming the file.
#[test]
fn a_stepper_checkpoint_keeps_its_stages_and_a_runs_keeps_its_bytes() {
    use cosdem_job::{ComponentChoice, StageGravity, StagePrescribed, StagePressure, StageRamp};
    let dir = scratch("stages");
    let path = dir.join(FILE);
    let run = awkward();
    run.write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let body = postcard::to_allocvec(&run).unwrap();
    assert_eq!(&bytes[8..bytes.len() - 4], &body[..], "header, postcard body, CRC: nothing more");
    let back = Checkpoint::read(&path).unwrap();
    assert_eq!(back.stages, None);
    back.check_kind(&path, false).unwrap();
    let e = back.check_kind(&path, true).unwrap_err().to_string();
    assert!(e.contains(FILE) && e.contains("not by a stepper"), "{e}");

    let awkward_values = [0.1 + 0.2, -0.0, 1e-300, f64::MIN_POSITIVE / 3.0, -1.0 / 3.0];
    let stage = |i: usize| StageSection {
        name: format!("stage {i}"),
        steps: 3,
        repeat: 1,
        prescribed: vec![StagePrescribed {
            set: "top".into(),
            component: ComponentChoice::Uy,
            value: (i == 0).then_some(awkward_values[0]),
            increment: (i == 1).then_some(awkward_values[1]),
            path: if i == 2 { awkward_values.to_vec() } else { Vec::new() },
            free: false,
        }],
        pressure: vec![StagePressure {
            set: "left".into(),
            value: awkward_values[2],
            ramp: StageRamp::Linear,
        }],
        traction: Vec::new(),
        gravity: (i == 1).then_some(StageGravity {
            acceleration: [awkward_values[3], awkward_values[4]],
            density: None,
            ramp: StageRamp::Constant,
        }),
        control: (i == 2).then(|| cosdem_job::ControlSection {
            set: "left".into(),
            component: ComponentChoice::Ux,
            value: awkward_values[4],
            plus: vec![cosdem_job::ControlTermSection {
                set: "top".into(),
                component: ComponentChoice::Uy,
                weight: awkward_values[3],
            }],
        }),
    };
    let stepper = Checkpoint { stages: Some((0..3).map(stage).collect()), ..awkward() };
    stepper.write(&path).unwrap();
    let back = Checkpoint::read(&path).unwrap();
    assert_eq!(back.stages, stepper.stages);
    let numbers = |c: &Checkpoint| -> Vec<u64> {
        let mut v = Vec::new();
        for s in c.stages.as_ref().unwrap() {
            let p = &s.prescribed[0];
            v.extend(p.value.iter().chain(&p.increment).chain(&p.path).map(|x| x.to_bits()));
            v.push(s.pressure[0].value.to_bits());
            v.extend(s.gravity.iter().flat_map(|g| g.acceleration.map(f64::to_bits)));
        }
        v
    };
    assert_eq!(numbers(&back), numbers(&stepper));
    assert_eq!(numbers(&back).len(), 1 + 1 + 5 + 3 + 2);
    back.check_kind(&path, true).unwrap();
    let e = back.check_kind(&path, false).unwrap_err().to_string();
    assert!(e.contains(FILE) && e.contains("written by a stepper"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A Gmsh mesh enters the physics digest by its content, not its path: the footing example
/// copied with its mesh into two directories has one digest, so a checkpoint written in one
/// resumes the other; the mesh changed by one byte in the second is refused as another job.
/// A checkpoint holding the path digest of earlier cosdems still resumes where its job and
/// mesh stayed, and only there.
#[test]
fn a_job_moved_with_its_mesh_resumes_and_an_edited_mesh_is_refused() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let base = scratch("moved-mesh");
    let (a, b) = (base.join("a"), base.join("b"));
    for dir in [&a, &b] {
        std::fs::create_dir_all(dir).unwrap();
        for f in ["footing.toml", "footing.msh"] {
            std::fs::copy(examples.join(f), dir.join(f)).unwrap();
        }
    }
    let job_a = Job::load(&a.join("footing.toml")).unwrap();
    let job_b = Job::load(&b.join("footing.toml")).unwrap();
    assert_ne!(job_a.mesh.file, job_b.mesh.file, "the two jobs name different files");
    assert_eq!(job_digest(&job_a), job_digest(&job_b));
    let mut c = awkward();
    c.digests = Digests::of(&job_a);
    c.check_job(&job_b, &b, false).unwrap();
    // Earlier cosdems' digest: accepted in place, refused for the moved job.
    c.digests.job = path_job_digest(&job_a);
    c.check_job(&job_a, &a, false).unwrap();
    assert!(c.check_job(&job_b, &b, false).unwrap_err().to_string().contains("another job"));
    // One byte more in the moved mesh (a trailing newline) is another mesh.
    let mesh_b = b.join("footing.msh");
    let mut bytes = std::fs::read(&mesh_b).unwrap();
    bytes.push(b'\n');
    std::fs::write(&mesh_b, bytes).unwrap();
    c.digests = Digests::of(&job_a);
    let e = c.check_job(&job_b, &b, false).unwrap_err().to_string();
    assert!(e.contains("another job"), "{e}");
    std::fs::remove_dir_all(&base).unwrap();
}
