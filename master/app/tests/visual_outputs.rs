//! The outputs people look at, end to end: a tiny two-scale job with real DEM assemblies writes
//! particle snapshots of its chosen Gauss points (a `.pvd` series of `.vtu` files whose discs
//! and contacts are those of the assembly) and the field data of its chosen displacements, and
//! `plot_run` draws every figure from the run directory alone. An elastic job (no particles)
//! writes field data and plots but no snapshot series.

use cosdem_app::output::field_data::FieldData;
use cosdem_app::output::plot::plot_run;
use cosdem_app::output::read_pvd;
use cosdem_app::output::snapshots::read_snapshot;
use cosdem_app::run::{Ending, Run, WorkerChoice, material_for};
use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MicroResponse};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_job::{Job, MaterialSection, fixtures};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The `dem-one-element` fixture (one Q8 element, 4 hexagonal assemblies, 2 steps of 2 mm)
/// with smaller assemblies (side 0.05 m), a snapshot series of point 3, no VTK fields and
/// field data at 2 mm.
fn dem_job() -> Job {
    let mut job = fixtures::load("dem-one-element");
    job.title = "tiny two-scale panel".into();
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.05;
    job.output.vtk_every = 0;
    job.output.snapshots = vec![[0, 3]];
    job.output.field_plots_at = vec![0.002];
    job.validate().unwrap();
    job
}

/// A material shared between the run and the test, so that the test can look at the
/// assemblies once the run is over: every call goes to the material inside.
struct Shared(Arc<Mutex<Box<dyn Material>>>);

impl Material for Shared {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        self.0.lock().unwrap().evaluate(trial, inputs)
    }
    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        self.0.lock().unwrap().commit(step)
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.0.lock().unwrap().rollback()
    }
    fn is_symmetric(&self) -> bool {
        self.0.lock().unwrap().is_symmetric()
    }
    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        self.0.lock().unwrap().committed_states()
    }
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        self.0.lock().unwrap().restore_states(states)
    }
    fn snapshot(&mut self, id: GaussPointId) -> Result<Option<MicroSnapshot>, MaterialError> {
        self.0.lock().unwrap().snapshot(id)
    }
}

/// Runs `job` into `dir` as `cosdem run` does (particle snapshots and field data on).
fn run(job: &Job, dir: &Path, material: Option<Box<dyn Material>>) {
    let run = Run::new(job, dir).snapshots(true);
    let run = match material {
        Some(m) => run.material(move |_| Ok(m)),
        None => run,
    };
    let outcome = run.execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
}

/// The largest contact normal force (N) of point 3's assembly after the last step, measured.
const LARGEST_NORMAL_FORCE: f64 = 2_534.677_380_152_291;

fn png_size(path: &Path) -> (u32, u32) {
    image::image_dimensions(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn dem_run_writes_snapshots_fields_and_plots() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("visual_outputs_dem");
    let _ = std::fs::remove_dir_all(&dir);
    let job = dem_job();
    // The job's material (one in-process worker), kept by the test to compare with the files.
    let ids: Vec<GaussPointId> = (0..4).map(|p| GaussPointId::new(0, p)).collect();
    let mesh = job.build_mesh().unwrap();
    let material =
        material_for(&job, &WorkerChoice::default(), &mesh, &ids, None).unwrap().material;
    let pool = Arc::new(Mutex::new(material));
    run(&job, &dir, Some(Box::new(Shared(pool.clone()))));

    // Snapshots at 0.002 m (field_plots_at) and at the last step, none without a reason
    // (vtk_every = 0), listed by the series with their displacement as time.
    let pvd = read_pvd(&dir.join("snapshots/e0_p3.pvd")).unwrap();
    let listed: Vec<(f64, &str)> = pvd.iter().map(|d| (d.timestep, d.file.as_str())).collect();
    assert_eq!(listed, vec![(0.002, "e0_p3/snap_00001.vtu"), (0.004, "e0_p3/snap_00002.vtu")]);
    let last = read_snapshot(&dir.join("snapshots/e0_p3/snap_00002.vtu")).unwrap();
    let direct = pool.lock().unwrap().snapshot(GaussPointId::new(0, 3)).unwrap().unwrap();
    assert_eq!(last.radius, direct.radii, "the file holds the assembly's discs");
    assert_eq!(last.contacts.len() * 4, direct.contacts.len());
    // The file's normal forces are the assembly's, and the compressed discs carry them: the
    // largest is the measured value (a deterministic relaxation: 1e-9 relative).
    let normal: Vec<f64> = last.contacts.iter().map(|c| c.2).collect();
    let direct_normal: Vec<f64> = direct.contacts.chunks(4).map(|c| c[2]).collect();
    assert_eq!(normal, direct_normal, "the file holds the assembly's contact forces");
    let largest = normal.iter().fold(0.0_f64, |a, &f| a.max(f));
    assert!((largest - LARGEST_NORMAL_FORCE).abs() <= 1e-9 * LARGEST_NORMAL_FORCE, "{largest} N");
    assert_eq!(last.displacement, Some(0.004));
    assert!(!dir.join("snapshots/e0_p0.pvd").exists(), "only the chosen points");

    let f1 = FieldData::read(&dir.join("fields/field_00001.json")).unwrap();
    assert_eq!((f1.step, f1.displacement, f1.gauss_points[0]), (1, 0.002, 4));
    assert!(dir.join("fields/field_00002.json").exists(), "the last step has its field");

    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for name in [
        "load_displacement.png",
        "equivalent_strain_00001.png",
        "equivalent_strain_00002.png",
        "force_chains_e0_p3_00001.png",
        "fluctuations_e0_p3_00002.png",
    ] {
        assert_eq!(png_size(&dir.join("plots").join(name)), (1000, 750), "{name}");
    }
    assert_eq!(report.written.len(), 7);
}

#[test]
fn elastic_run_plots_without_snapshots() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("visual_outputs_elastic");
    let _ = std::fs::remove_dir_all(&dir);
    // The same panel, linear elastic (G = 20 MPa, nu = 0.25, Gc = G / 2, lc = 0.01 m).
    let mut job = dem_job();
    job.material = MaterialSection::Elastic {
        shear_modulus: 2e7,
        poisson: 0.25,
        cosserat_modulus: None,
        length: None,
    };
    job.output.field_plots_at = vec![0.0015, 0.0016, 9.0];
    job.validate().unwrap();
    run(&job, &dir, None);
    // 0.0015 and 0.0016 are both first reached at step 1; 9 m never is.
    let mut fields: Vec<String> = std::fs::read_dir(dir.join("fields"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    fields.sort();
    assert_eq!(fields, ["field_00001.json", "field_00002.json"]);
    assert!(!dir.join("snapshots").exists());
    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    assert_eq!(report.written.len(), 3);
    let e = plot_run(&dir.join("nowhere")).unwrap_err().to_string();
    assert!(e.contains("curve.csv"), "{e}");
}
