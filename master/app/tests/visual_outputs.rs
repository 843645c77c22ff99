//! The outputs people look at, end to end: a tiny two-scale job with real DEM assemblies writes
//! particle snapshots of its chosen Gauss points (a `.pvd` series of `.vtu` files whose discs
//! and contacts are those of the assembly) and the field data of its chosen displacements, and
//! `plot_run` draws every figure from the run directory alone. An elastic job (no particles)
//! writes field data and plots but no snapshot series.

use cosdem_app::output::field_data::FieldData;
use cosdem_app::output::plot::plot_run;
use cosdem_app::output::read_pvd;
use cosdem_app::output::run_dir::{RunSettings, RunWriter};
use cosdem_app::output::snapshots::{read_snapshot, resolve_snapshot_ids};
use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_fem::material::{ElasticCosserat, Material};
use cosdem_fem::solve::Solver;
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;
use std::path::Path;

/// Two steps of 2 mm on one Q8 element backed by 4 small hexagonal assemblies.
const DEM_JOB: &str = r#"
    title = "tiny two-scale panel"
    [mesh]
    kind = "rectangle"
    lx = 1.0
    ly = 1.0
    nx = 1
    ny = 1
    [loading]
    increment = 0.002
    [loading.compression]
    displacement = 0.004
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
    packing = { kind = "hexagonal", radius = 0.005, side = 0.05 }
    [output]
    vtk_every = 0
    snapshots = [[0, 3]]
    field_plots_at = [0.002]
"#;

fn settings(job: &Job) -> RunSettings {
    cosdem_app::run::run_settings(job)
}

fn run(job: &Job, dir: &Path, material: &mut dyn Material, solver: &mut Solver) {
    let mut writer = RunWriter::create(dir, settings(job)).unwrap();
    let per = solver.gauss().per_element;
    let ids =
        resolve_snapshot_ids(&job.output.snapshots, solver.model().mesh.n_elements(), per).unwrap();
    let mut tapped = writer.watch(material, ids, &job.output.field_plots_at);
    solver.run(&mut tapped, &mut writer).unwrap();
    writer.finish(Ok(())).unwrap();
}

fn png_size(path: &Path) -> (u32, u32) {
    image::image_dimensions(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn dem_run_writes_snapshots_fields_and_plots() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("visual_outputs_dem");
    let _ = std::fs::remove_dir_all(&dir);
    let job = Job::from_toml(DEM_JOB, "inline").unwrap();
    let MaterialSection::Dem { assembly } = &job.material else { panic!("a DEM job") };
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let ids: Vec<GaussPointId> = (0..4).map(|p| GaussPointId::new(0, p)).collect();
    let mut pool = Pool::in_process(1, PoolConfig::default(), |_| Dem).unwrap();
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(assembly).unwrap(),
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(&ids, &request).unwrap();
    run(&job, &dir, &mut pool, &mut solver);

    // Snapshots at 0.002 m (field_plots_at) and at the last step, none without a reason
    // (vtk_every = 0), listed by the series with their displacement as time.
    let pvd = read_pvd(&dir.join("snapshots/e0_p3.pvd")).unwrap();
    let listed: Vec<(f64, &str)> = pvd.iter().map(|d| (d.timestep, d.file.as_str())).collect();
    assert_eq!(listed, vec![(0.002, "e0_p3/snap_00001.vtu"), (0.004, "e0_p3/snap_00002.vtu")]);
    let last = read_snapshot(&dir.join("snapshots/e0_p3/snap_00002.vtu")).unwrap();
    let direct = pool.snapshot(GaussPointId::new(0, 3)).unwrap();
    assert_eq!(last.radius, direct.radii, "the file holds the assembly's discs");
    assert_eq!(last.contacts.len() * 4, direct.contacts.len());
    assert!(last.contacts.iter().any(|c| c.2 > 0.0), "compressed discs carry forces");
    assert_eq!(last.displacement, Some(0.004));
    assert!(!dir.join("snapshots/e0_p0.pvd").exists(), "only the chosen points");

    let f1 = FieldData::read(&dir.join("fields/field_00001.json")).unwrap();
    assert_eq!((f1.step, f1.displacement, f1.gauss_per_element), (1, 0.002, 4));
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
    let text = DEM_JOB
        .replace("kind = \"dem\"", "kind = \"elastic\"\nshear_modulus = 2e7\npoisson = 0.25")
        .replace("[material.assembly]\n", "")
        .replace("    packing = { kind = \"hexagonal\", radius = 0.005, side = 0.05 }\n", "")
        .replace("field_plots_at = [0.002]", "field_plots_at = [0.0015, 0.0016, 9.0]");
    let job = Job::from_toml(&text, "inline").unwrap();
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let mut material = ElasticCosserat::new(2e7, 0.25, 1e7, 0.01);
    run(&job, &dir, &mut material, &mut solver);
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
