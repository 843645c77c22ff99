//! The `.pvd` time series stays a valid collection listing every finished step, even when
//! the run is killed: the `kill` test aborts a child process halfway through a run.

mod io_support;

use std::path::Path;

use cosdem_app::output::vtk::{VtuPiece, write_vtu};
use cosdem_app::output::{CsvWriter, PvdWriter};
use io_support::{parse, scratch};

/// Parses a `.pvd` and returns its (timestep, part, file) entries.
fn read_pvd(path: &Path) -> Vec<(f64, u32, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let root = parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(root.name, "VTKFile");
    assert_eq!(root.attr("type"), Some("Collection"));
    root.child("Collection")
        .children
        .iter()
        .map(|d| {
            assert_eq!(d.name, "DataSet");
            (
                d.attr("timestep").unwrap().parse().unwrap(),
                d.attr("part").unwrap().parse().unwrap(),
                d.attr("file").unwrap().to_string(),
            )
        })
        .collect()
}

/// One step of a fake run: writes `mesh_NNNN.vtu`, then lists it.
fn step(dir: &Path, pvd: &mut PvdWriter, n: usize, time: f64) {
    let name = format!("mesh_{n:04}.vtu");
    let mut piece = VtuPiece::point_cloud_2d(&[[0.0, 0.0], [time, 1.0]]);
    piece.time = Some(time);
    write_vtu(&dir.join(&name), &piece).unwrap();
    pvd.add(time, Path::new(&name)).unwrap();
}

#[test]
fn every_step_leaves_a_complete_collection() {
    let dir = scratch("pvd-steps");
    let path = dir.join("mesh.pvd");
    let mut pvd = PvdWriter::create(&path).unwrap();
    assert!(read_pvd(&path).is_empty());
    let times = [0.0, 1e-3, 1.0 / 3.0, 2.5e-7 * 4.0, 0.18];
    for (n, &t) in times.iter().enumerate() {
        step(&dir, &mut pvd, n, t);
        // After each step, the file on disk lists exactly the finished steps.
        let listed = read_pvd(&path);
        assert_eq!(listed.len(), n + 1);
        for (k, (time, part, file)) in listed.iter().enumerate() {
            assert_eq!(time.to_bits(), times[k].to_bits());
            assert_eq!(*part, 0);
            assert!(dir.join(file).is_file(), "{file}");
        }
    }
    assert_eq!(pvd.datasets().len(), times.len());
    // Only the .pvd and the .vtu files: no temporary files left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), times.len() + 1);
}

#[test]
fn missing_dataset_is_refused_and_the_collection_kept() {
    let dir = scratch("pvd-missing");
    let path = dir.join("series.pvd");
    let mut pvd = PvdWriter::create(&path).unwrap();
    step(&dir, &mut pvd, 1, 0.5);
    let before = std::fs::read_to_string(&path).unwrap();
    let err = pvd.add(1.0, Path::new("never_written.vtu")).unwrap_err().to_string();
    assert!(err.contains("never_written.vtu") && err.contains("series.pvd"), "{err}");
    let err = pvd.add(f64::NAN, Path::new("mesh_0001.vtu")).unwrap_err().to_string();
    assert!(err.contains("timestep NaN") && err.contains("not finite"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
    assert_eq!(pvd.datasets().len(), 1);

    // An absolute path inside the directory is stored relative to it; parts are kept.
    let abs = dir.join("mesh_0001.vtu");
    pvd.add_part(0.75, 2, &abs).unwrap();
    assert_eq!(read_pvd(&path)[1], (0.75, 2, "mesh_0001.vtu".to_string()));
}

/// A run directory given relative to the working directory (`cosdem run` writes
/// `runs/<job>/` by default): the `.vtu` path through it is stored relative to the `.pvd`.
#[test]
fn paths_relative_to_the_working_directory() {
    let dir = scratch("pvd-relative");
    let cwd = std::env::current_dir().unwrap();
    let ups = "../".repeat(cwd.components().count() - 1);
    let rel = Path::new(&ups).join(dir.strip_prefix("/").unwrap());
    assert!(rel.is_relative() && rel.join(".").exists());
    std::fs::create_dir_all(rel.join("vtk")).unwrap();
    let mut pvd = PvdWriter::create(&rel.join("fields.pvd")).unwrap();
    let vtu = rel.join("vtk/mesh_00001.vtu");
    write_vtu(&vtu, &VtuPiece::point_cloud_2d(&[[0.0, 0.0]])).unwrap();
    pvd.add(0.5, &vtu).unwrap();
    assert_eq!(read_pvd(&dir.join("fields.pvd")), vec![(0.5, 0, "vtk/mesh_00001.vtu".into())]);
}

#[test]
fn resume_continues_and_truncates() {
    let dir = scratch("pvd-resume");
    let path = dir.join("mesh.pvd");
    {
        let mut pvd = PvdWriter::create(&path).unwrap();
        for n in 0..4 {
            step(&dir, &mut pvd, n, n as f64 * 0.1);
        }
    }
    let mut pvd = PvdWriter::resume(&path).unwrap();
    assert_eq!(pvd.datasets().len(), 4);
    assert_eq!(pvd.datasets()[3].timestep, 0.30000000000000004);
    // Restart from the checkpoint at t = 0.1: later steps are dropped, then the run goes on.
    pvd.truncate_after(0.1).unwrap();
    assert_eq!(read_pvd(&path).len(), 2);
    step(&dir, &mut pvd, 9, 0.2);
    let listed = read_pvd(&path);
    assert_eq!(listed.len(), 3);
    assert_eq!(listed[2].2, "mesh_0009.vtu");
    // Resuming a file that does not exist starts an empty collection.
    let fresh = PvdWriter::resume(&dir.join("new.pvd")).unwrap();
    assert!(fresh.datasets().is_empty());
    assert!(read_pvd(&dir.join("new.pvd")).is_empty());
}

const CHILD_ENV: &str = "COSDEM_IO_KILL_TEST_DIR";
const FINISHED_STEPS: usize = 7;

/// The child half of `kill`: runs steps with pvd and csv output, then aborts mid-step (after
/// writing a `.vtu` that never gets listed), like a process killed by a signal.
#[test]
fn kill_child() {
    let Ok(dir) = std::env::var(CHILD_ENV) else { return };
    let dir = Path::new(&dir);
    let mut pvd = PvdWriter::create(&dir.join("mesh.pvd")).unwrap();
    let mut csv =
        CsvWriter::create(&dir.join("load.csv"), &["step", "displacement", "load_top"]).unwrap();
    for n in 0..FINISHED_STEPS {
        let d = 1e-3 * (n + 1) as f64;
        step(dir, &mut pvd, n, d);
        csv.write_row(&[n as f64, d, 1e5 * d / 3.0]).unwrap();
    }
    // Half of the next step: its .vtu is written, but it is never listed.
    write_vtu(&dir.join("mesh_9999.vtu"), &VtuPiece::default()).unwrap();
    std::process::abort();
}

#[test]
fn kill() {
    let dir = scratch("pvd-kill");
    let status = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "kill_child", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, &dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(!status.success(), "the child must die");
    let listed = read_pvd(&dir.join("mesh.pvd"));
    assert_eq!(listed.len(), FINISHED_STEPS);
    for (k, (time, _, file)) in listed.iter().enumerate() {
        assert_eq!(*time, 1e-3 * (k + 1) as f64);
        assert!(dir.join(file).is_file());
    }
    let csv = std::fs::read_to_string(dir.join("load.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "step,displacement,load_top");
    assert_eq!(lines.len(), FINISHED_STEPS + 1);
    for (k, line) in lines[1..].iter().enumerate() {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let d = 1e-3 * (k + 1) as f64;
        assert_eq!(v, [k as f64, d, 1e5 * d / 3.0]);
    }
}
