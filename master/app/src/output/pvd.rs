//! ParaView `.pvd` collections: the list of `.vtu` files of a time series.
//!
//! [`PvdWriter`] rewrites the whole `.pvd` atomically after every added dataset, so the file
//! on disk is always a complete, valid collection listing every finished step; a run killed
//! at any moment leaves it readable. A dataset can only be added once its file exists, so the
//! collection never points at a missing file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::vtk::escape;
use super::{Result, invalid, io_err, push_f64, unescape, write_atomic};

/// One entry of the collection.
#[derive(Clone, Debug, PartialEq)]
pub struct PvdDataset {
    /// Time (or load-step parameter) of the dataset.
    pub timestep: f64,
    /// Part number: several files at one time step form a multiblock (0 when alone).
    pub part: u32,
    /// File name, relative to the directory of the `.pvd` (absolute if outside it).
    pub file: String,
}

/// Maintains a `.pvd` time-series file.
#[derive(Debug)]
pub struct PvdWriter {
    path: PathBuf,
    datasets: Vec<PvdDataset>,
}

impl PvdWriter {
    /// Starts a new, empty collection at `path`, replacing any existing file.
    pub fn create(path: &Path) -> Result<Self> {
        let w = PvdWriter { path: path.to_path_buf(), datasets: Vec::new() };
        w.flush()?;
        Ok(w)
    }

    /// Continues the collection at `path` (a restarted run): keeps the datasets it lists, or
    /// starts an empty one if the file does not exist. Only files written by this writer (one
    /// `<DataSet .../>` element per line) are understood.
    pub fn resume(path: &Path) -> Result<Self> {
        let datasets = match read_pvd(path) {
            Ok(d) => d,
            Err(super::OutputError::Io { source, .. })
                if source.kind() == std::io::ErrorKind::NotFound =>
            {
                return Self::create(path);
            }
            Err(e) => return Err(e),
        };
        let w = PvdWriter { path: path.to_path_buf(), datasets };
        w.flush()?;
        Ok(w)
    }

    /// Adds `file` (part 0) at `timestep` and rewrites the `.pvd`. See [`Self::add_part`].
    pub fn add(&mut self, timestep: f64, file: &Path) -> Result<()> {
        self.add_part(timestep, 0, file)
    }

    /// Adds `file` at `timestep` as part `part` and rewrites the `.pvd` atomically.
    ///
    /// `file` is relative to the directory of the `.pvd`, or absolute, or relative to the
    /// working directory through the `.pvd`'s directory (both stored relative to it). It must
    /// already exist: write the `.vtu` first.
    pub fn add_part(&mut self, timestep: f64, part: u32, file: &Path) -> Result<()> {
        if !timestep.is_finite() {
            return Err(invalid(
                &self.path,
                format!("timestep {timestep} of {file:?} is not finite"),
            ));
        }
        let dir = self.dir();
        // A relative path that goes through the `.pvd`'s own (relative) directory, such as
        // `runs/quick/vtk/mesh_00001.vtu` for `runs/quick/fields.pvd`, is taken as relative to
        // the working directory, like the `.pvd`'s own path.
        let through_dir = file.is_relative() && dir != Path::new(".") && file.starts_with(&dir);
        let on_disk =
            if file.is_absolute() || through_dir { file.to_path_buf() } else { dir.join(file) };
        if !on_disk.is_file() {
            return Err(invalid(
                &self.path,
                format!("dataset {} does not exist; write it before adding it", on_disk.display()),
            ));
        }
        let stored = match file.strip_prefix(&dir) {
            Ok(rel) if file.is_absolute() || through_dir => rel,
            _ => file,
        };
        let stored = stored.to_string_lossy().replace('\\', "/");
        self.datasets.push(PvdDataset { timestep, part, file: stored });
        if let Err(e) = self.flush() {
            self.datasets.pop();
            return Err(e);
        }
        Ok(())
    }

    /// Drops every dataset with a timestep greater than `timestep` (restart from an earlier
    /// checkpoint) and rewrites the `.pvd`.
    pub fn truncate_after(&mut self, timestep: f64) -> Result<()> {
        self.datasets.retain(|d| d.timestep <= timestep);
        self.flush()
    }

    /// The datasets listed so far, in the order they were added.
    pub fn datasets(&self) -> &[PvdDataset] {
        &self.datasets
    }

    /// The `.pvd` file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The collection's XML text.
    pub fn to_xml(&self) -> String {
        let mut s = String::with_capacity(128 + 80 * self.datasets.len());
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
        s.push_str("  <Collection>\n");
        for d in &self.datasets {
            s.push_str("    <DataSet timestep=\"");
            push_f64(&mut s, d.timestep);
            let _ = writeln!(s, "\" group=\"\" part=\"{}\" file=\"{}\"/>", d.part, escape(&d.file));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }

    fn dir(&self) -> PathBuf {
        match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }

    fn flush(&self) -> Result<()> {
        write_atomic(&self.path, self.to_xml().as_bytes())
    }
}

/// The datasets listed by a `.pvd` written by [`PvdWriter`] (one `<DataSet .../>` element per
/// line), in file order; `file` as stored (relative to the `.pvd`'s directory).
pub fn read_pvd(path: &Path) -> Result<Vec<PvdDataset>> {
    let text = std::fs::read_to_string(path).map_err(io_err(path, "read"))?;
    let mut datasets = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if !line.starts_with("<DataSet") {
            continue;
        }
        let bad = |what: &str| invalid(path, format!("line {}: {what} in {line:?}", i + 1));
        let timestep = attribute(line, "timestep")
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| bad("no numeric timestep"))?;
        let part = match attribute(line, "part") {
            Some(v) => v.parse::<u32>().map_err(|_| bad("a non-integer part"))?,
            None => 0,
        };
        let file = attribute(line, "file").ok_or_else(|| bad("no file"))?;
        datasets.push(PvdDataset { timestep, part, file });
    }
    Ok(datasets)
}

/// The unescaped value of attribute `name` in one XML start tag written by [`PvdWriter`].
fn attribute(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = start + tag[start..].find('"')?;
    Some(unescape(&tag[start..end]))
}
