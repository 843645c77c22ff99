//! Writing results: VTK XML unstructured grids, ParaView `.pvd` time series and CSV curves.
//!
//! Writers take plain data (coordinates, connectivity, named arrays of `f64`), never the
//! solver's types. Whole files are written atomically (a temporary file in the same directory,
//! then a rename), and the series files (`.pvd`, `.csv`) are kept valid after every step, so a
//! run killed at any moment leaves readable output listing every finished step.
//!
//! Numbers are printed by [`fmt_f64`](crate::output::fmt_f64): the shortest text that parses
//! back to the same `f64`.

/// Claiming a run directory: lock, empty-or-overwrite, `RUN.old-N`, temporary files.
pub mod claim;
/// CSV curves (load-displacement), one flushed row per converged step.
pub mod csv;
/// The curve of any boundary-value job: control displacement, load, extra reactions.
pub mod curve_axes;
/// The equivalent-strain field of chosen steps as JSON, for the Fig. 9 plot.
pub mod field_data;
/// Gauss-point values averaged to the mesh's nodes (the mesh `.vtu`'s nodal stress).
pub mod nodal_stress;
/// Packing files (YADE, LAMMPS, VTU) of snapshots and of checkpointed assemblies.
pub mod packing;
/// VTK XML unstructured grids (`.vtu`): meshes, Gauss-point clouds, particle snapshots.
/// The pieces written: the mesh with its solution, the Gauss points, a DEM snapshot.
pub mod pieces;
/// PNG figures of a run directory (plotters, embedded font): Figs. 3, 9, 10-12.
pub mod plot;
/// Where a run's results come from: `provenance.json` and the copy of the job.
pub mod provenance;
/// ParaView `.pvd` collections: the time series of `.vtu` files.
pub mod pvd;
/// A run directory cut back to its checkpoint's step on a resume.
pub mod restart;
/// The run directory written as the run goes: curve, VTK series, summary.
pub mod run_dir;
/// Particle snapshots of chosen Gauss points: fetched after each commit, VTK out and back.
pub mod snapshots;
/// Snapshots and field data written by the run writer at chosen steps.
pub mod visuals;
pub mod vtk;
/// zlib-compressed binary arrays of `.vtu` files (`vtkZLibDataCompressor`).
pub mod vtk_zlib;
/// Reading back the `.vtu` files this crate writes.
pub mod vtu_read;

pub use csv::CsvWriter;
pub use pieces::{add_micro_descriptors, gauss_point_piece, nodal_piece, particle_piece};
pub use pvd::{PvdDataset, PvdWriter, read_pvd};
pub use vtk::{Cell, CellType, DataArray, Encoding, VtuPiece, write_vtu, write_vtu_encoded};

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Why output could not be written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The operating system refused a read, write or rename.
    #[error("{}: {action}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What was being done ("write", "rename", ...).
        action: &'static str,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The data handed to a writer is inconsistent (array lengths, node indices, ...).
    #[error("{}: {message}", path.display())]
    InvalidData {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong, naming the array, cell or column and the offending value.
        message: String,
    },
    /// A value is NaN or infinite (VTK's ASCII reader cannot read those back).
    #[error("{}: array {array:?} has the non-finite value {value} at index {index}", path.display())]
    NonFinite {
        /// The file that was to be written.
        path: PathBuf,
        /// The array (or CSV column) holding the value.
        array: String,
        /// Index of the value within the flat array (or the CSV row).
        index: usize,
        /// The value.
        value: f64,
    },
}

/// Result of the output writers.
pub type Result<T> = std::result::Result<T, OutputError>;

pub(crate) fn invalid(path: &Path, message: String) -> OutputError {
    OutputError::InvalidData { path: path.to_path_buf(), message }
}

/// The text of an XML attribute value written with [`vtk::escape`]: the entities it writes
/// turned back into characters (`&amp;` last, so an escaped entity stays literal).
pub(crate) fn unescape(text: &str) -> String {
    text.replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&#10;", "\n")
        .replace("&#13;", "\r")
        .replace("&#9;", "\t")
        .replace("&amp;", "&")
}

/// An I/O error on `path`, named in the error.
pub fn io_err(path: &Path, action: &'static str) -> impl FnOnce(std::io::Error) -> OutputError {
    let path = path.to_path_buf();
    move |source| OutputError::Io { path, action, source }
}

/// Formats an `f64` as the shortest decimal text that parses back to exactly the same value:
/// plain notation for magnitudes in `[1e-5, 1e16)` and zero, scientific (`1.5e-7`) otherwise.
/// Integral values print without a fraction (`3`). NaN and infinities print as Rust does
/// (`NaN`, `inf`, `-inf`); the VTK writer rejects them.
pub fn fmt_f64(x: f64) -> String {
    let mut s = String::new();
    push_f64(&mut s, x);
    s
}

pub(crate) fn push_f64(out: &mut String, x: f64) {
    let a = x.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) || !x.is_finite() {
        let _ = write!(out, "{x}");
    } else {
        let _ = write!(out, "{x:e}");
    }
}

/// Writes `bytes` to `path` atomically: into a temporary file in the same directory, synced,
/// then renamed over `path`. Readers see either the old or the new file, never a torn one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| invalid(path, "the path names no file".to_string()))?
        .to_string_lossy()
        .into_owned();
    // Unique per process and call, so concurrent writers never share a temporary file.
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.{}-{n}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io_err(&tmp, "create temporary file"))?;
        f.write_all(bytes).map_err(io_err(&tmp, "write temporary file"))?;
        f.sync_all().map_err(io_err(&tmp, "sync temporary file"))?;
        drop(f);
        std::fs::rename(&tmp, path).map_err(io_err(path, "rename temporary file over"))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The equivalent strain of Eq. 34, defined once in [`cosdem_fem::post`].
pub use cosdem_fem::post::equivalent_strain;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_f64_round_trips() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -3.0,
            0.1,
            1.0 / 3.0,
            -2.5e-7,
            1e-5,
            9.99e-6,
            1e16,
            123456789.123,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            std::f64::consts::PI * 1e200,
        ];
        for v in values {
            let s = fmt_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{v} -> {s}");
            assert!(s.len() <= 25, "{s}");
        }
        assert_eq!(fmt_f64(3.0), "3");
        assert_eq!(fmt_f64(0.25), "0.25");
        assert_eq!(fmt_f64(1.5e-7), "1.5e-7");
        // A deterministic sweep over many magnitudes and mantissas.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                assert_eq!(fmt_f64(v).parse::<f64>().unwrap().to_bits(), v.to_bits());
            }
        }
    }

    #[test]
    fn atomic_write_replaces_whole_file() {
        let dir = std::env::temp_dir().join(format!("cosdem-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        write_atomic(&p, b"first version, long").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "second");
        let leftovers: Vec<_> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(leftovers.len(), 1, "{leftovers:?}");
        let err = write_atomic(&dir.join("missing").join("x.vtu"), b"x").unwrap_err();
        assert!(err.to_string().contains("missing"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
