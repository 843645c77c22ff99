//! A run directory read back as plain arrays (for the Python binding's numpy arrays, and for
//! anyone scripting over results): the summary, the load curve, the Gauss-point and mesh
//! fields of every saved step and the particle snapshots. See
//! `docs/reference/run-directory.md` for the files.
//!
//! A [`RunReader`] reads whatever the directory holds when asked: a finished run, one stopped
//! (`--max-steps`), interrupted or failed, or one still being written (every file is written
//! atomically, and `curve.csv` row by row: a row being appended is left out). Nothing is
//! cached, so a later call sees later steps. The `.vtu` files are read by
//! [`crate::output::vtu_read`] (ASCII and zlib-compressed binary alike).
//!
//! Component orders, as the writers write them ([`crate::output::pieces`]):
//! - Gauss points (`vtk/gauss_NNNNN.vtu`): `strain` 4 (xx, yy, xy, yx), `curvature` 2
//!   (x, y), `stress` 4 (xx, yy, xy, yx), `couple_stress` 2 (x, y), `equivalent_strain` 1;
//!   with a DEM material also `porosity`, `void_ratio`, `coordination`,
//!   `mechanical_coordination` 1 each, `fabric` 3 (xx, yy, xy), `fabric_anisotropy`,
//!   `fabric_direction`, `sliding_fraction`, `mean_rotation` 1 each.
//! - Mesh (`vtk/mesh_NNNNN.vtu`): `displacement` 3 (u_x, u_y, 0), `rotation` 1 (the
//!   micro-rotation w), `stress` 4 and `couple_stress` 2 (Gauss-point values averaged to the
//!   nodes); no cell arrays.
//! - Snapshots: `fluctuation` is written with 3 components (x, y, 0); [`Snapshot`] keeps x, y.

mod error;
mod fields;
mod files;

pub use error::ResultsError;
pub use fields::{Array, Curve, GaussFields, MeshFields, Snapshot};

use crate::output::snapshots::read_snapshot;
use crate::output::visuals::series_name;
use crate::output::vtu_read::read_vtu;
use crate::output::{invalid, io_err, run_dir::Summary};
use cosdem_common::GaussPointId;
use files::step_file;
use std::path::{Path, PathBuf};

/// A run directory, read on demand.
#[derive(Clone, Debug)]
pub struct RunReader {
    dir: PathBuf,
}

impl RunReader {
    /// Opens a run directory: finished, stopped, failed or still being written. Refuses a path
    /// that is not a directory or holds no run (no summary.json and no curve.csv), naming it.
    pub fn open(dir: &Path) -> Result<Self, ResultsError> {
        let refuse = |reason: String| ResultsError::NotARun { path: dir.to_path_buf(), reason };
        match std::fs::metadata(dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(refuse("it does not exist".into()));
            }
            Err(e) => return Err(refuse(format!("it cannot be read: {e}"))),
            Ok(m) if !m.is_dir() => {
                return Err(refuse(
                    "it is a file; give the directory that holds summary.json and curve.csv".into(),
                ));
            }
            Ok(_) => {}
        }
        if !dir.join("summary.json").is_file() && !dir.join("curve.csv").is_file() {
            let mut held: Vec<String> = std::fs::read_dir(dir)
                .map_err(|e| refuse(format!("it cannot be listed: {e}")))?
                .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
                .collect();
            held.sort();
            return Err(refuse(if held.is_empty() {
                "it is empty: no summary.json and no curve.csv".into()
            } else {
                let names: Vec<&str> = held.iter().map(String::as_str).collect();
                format!(
                    "it holds no summary.json and no curve.csv, only {}",
                    error::abbreviated(&names, |n| n)
                )
            }));
        }
        Ok(Self { dir: dir.to_path_buf() })
    }

    /// The run directory, as given to [`Self::open`].
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// summary.json as a JSON value, the status reinterpreted as [`Summary::read`] does (a
    /// `running` whose writer no longer holds the lock is `interrupted: ...`). Every field
    /// of the file is kept as written.
    pub fn summary(&self) -> Result<serde_json::Value, ResultsError> {
        let status = Summary::read(&self.dir)?.status;
        let path = self.dir.join("summary.json");
        let text = std::fs::read_to_string(&path).map_err(io_err(&path, "read"))?;
        let mut value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| invalid(&path, e.to_string()))?;
        let object =
            value.as_object_mut().ok_or_else(|| invalid(&path, "not a JSON object".into()))?;
        // Only a `running` is reinterpreted (the file may have been rewritten in between).
        if object.get("status").is_some_and(|s| s == "running") {
            object.insert("status".into(), status.into());
        }
        Ok(value)
    }

    /// curve.csv; a run with no converged step yet gives the header's columns, empty.
    pub fn curve(&self) -> Result<Curve, ResultsError> {
        Ok(files::read_curve(&self.dir.join("curve.csv"))?)
    }

    /// Steps with Gauss-point / mesh files, ascending: those with both (the mesh file of a
    /// step is written first: a step whose Gauss-point file is being written is not listed).
    pub fn saved_steps(&self) -> Result<Vec<u64>, ResultsError> {
        let gauss = files::steps(&self.vtk(), "gauss")?;
        let mut mesh = files::steps(&self.vtk(), "mesh")?;
        mesh.retain(|s| gauss.binary_search(s).is_ok());
        Ok(mesh)
    }

    /// The Gauss-point fields of `step` (`vtk/gauss_NNNNN.vtu`).
    pub fn gauss(&self, step: u64) -> Result<GaussFields, ResultsError> {
        let path = self.step_path("gauss", "Gauss-point fields", step)?;
        Ok(GaussFields::from_piece(step, &read_vtu(&path)?, &path)?)
    }

    /// The mesh and nodal fields of `step` (`vtk/mesh_NNNNN.vtu`).
    pub fn mesh(&self, step: u64) -> Result<MeshFields, ResultsError> {
        let path = self.step_path("mesh", "mesh fields", step)?;
        Ok(MeshFields::from_piece(step, &read_vtu(&path)?, &path)?)
    }

    /// The (element, point) pairs that have snapshots, ascending.
    pub fn snapshot_points(&self) -> Result<Vec<(u32, u32)>, ResultsError> {
        Ok(files::series(&self.dir.join("snapshots"))?)
    }

    /// Steps saved for one snapshot point, ascending.
    pub fn snapshot_steps(&self, element: u32, point: u32) -> Result<Vec<u64>, ResultsError> {
        let steps = files::steps(&self.series_dir(element, point), "snap")?;
        if steps.is_empty() {
            let saved = self.snapshot_points()?;
            return Err(ResultsError::PointNotSaved {
                dir: self.dir.clone(),
                element,
                point,
                saved,
            });
        }
        Ok(steps)
    }

    /// The snapshot of Gauss point `point` of element `element` at `step`.
    pub fn snapshot(&self, element: u32, point: u32, step: u64) -> Result<Snapshot, ResultsError> {
        let series = self.series_dir(element, point);
        let path = step_file(&series, "snap", step);
        if !path.is_file() {
            let saved = self.snapshot_steps(element, point)?;
            let what = format!("snapshot {}", series_name(GaussPointId::new(element, point)));
            return Err(ResultsError::StepNotSaved { dir: self.dir.clone(), what, step, saved });
        }
        let id = GaussPointId::new(element, point);
        Ok(Snapshot::from_particles(id, step, read_snapshot(&path)?, &path)?)
    }

    fn vtk(&self) -> PathBuf {
        self.dir.join("vtk")
    }

    fn series_dir(&self, element: u32, point: u32) -> PathBuf {
        self.dir.join("snapshots").join(series_name(GaussPointId::new(element, point)))
    }

    /// The file `vtk/{prefix}_NNNNN.vtu` of `step`, or the error naming the steps that have
    /// one (`what`: what the files hold).
    fn step_path(&self, prefix: &str, what: &str, step: u64) -> Result<PathBuf, ResultsError> {
        let path = step_file(&self.vtk(), prefix, step);
        if path.is_file() {
            return Ok(path);
        }
        let saved = files::steps(&self.vtk(), prefix)?;
        Err(ResultsError::StepNotSaved { dir: self.dir.clone(), what: what.into(), step, saved })
    }
}
