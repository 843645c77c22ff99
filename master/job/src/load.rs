//! Reading a job: TOML text or a file. Parse errors (unknown keys, wrong types) carry the
//! line and column from the TOML parser and name the file ([`Error::JobFile`]); every job read
//! here is validated. Only a regular file of at most [`MAX_JOB_FILE_BYTES`] is read: a device
//! (`/dev/zero`), a FIFO or a directory is refused naming it.

use crate::schema::Job;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::gmsh::{GmshError, read_regular};
use std::path::Path;

/// Largest job file read (16 MiB): a job is a few kB of TOML; the largest legitimate one (a
/// long explicit `radii` list of [`cosdem_dem::spec::MAX_DISCS`] radii) stays below it.
pub const MAX_JOB_FILE_BYTES: u64 = 16 << 20;

/// The text of the regular file `path`, at most [`MAX_JOB_FILE_BYTES`] bytes of it
/// ([`read_regular`], the mesh reader's check).
fn read_job_file(path: &Path) -> Result<String> {
    let err = |message: String| Error::JobFile { file: path.display().to_string(), message };
    let bytes = read_regular(path, MAX_JOB_FILE_BYTES).map_err(|e| match e {
        GmshError::NotAFile { kind, .. } => {
            err(format!("it is {kind}, not a regular file: a job file must be a plain file"))
        }
        GmshError::TooLarge { size, .. } => err(format!(
            "{size} bytes ({:.1} MiB) is more than the {} MiB (MAX_JOB_FILE_BYTES) a job file may hold",
            size as f64 / f64::from(1 << 20),
            MAX_JOB_FILE_BYTES >> 20
        )),
        GmshError::Io { source, .. } => err(source.to_string()),
        other => err(other.to_string()),
    })?;
    String::from_utf8(bytes).map_err(|e| err(format!("not UTF-8 text: {e}")))
}

impl Job {
    /// Parses a job from TOML text; `origin` names the file in errors.
    /// A packing file it names is read relative to the working directory.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        Self::parse(text, origin, Path::new(""))
    }

    /// Parses `text`, reads its packing file (relative to `base`) and validates.
    fn parse(text: &str, origin: &str, base: &Path) -> Result<Self> {
        let mut job: Job = toml::from_str(text)
            .map_err(|e| Error::JobFile { file: origin.to_string(), message: e.to_string() })?;
        crate::packing_file::resolve(&mut job, base, origin)?;
        job.validate()?;
        Ok(job)
    }

    /// Reads and validates a job file; relative paths inside it (`mesh.file`, a packing
    /// `file`) are resolved against it.
    pub fn load(path: &Path) -> Result<Self> {
        let text = read_job_file(path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut job = Self::parse(&text, &path.display().to_string(), base)?;
        if let Some(file) = &job.mesh.file
            && file.is_relative()
        {
            let base = path.parent().unwrap_or(Path::new("."));
            job.mesh.file = Some(base.join(file));
        }
        Ok(job)
    }
}

#[cfg(test)]
mod tests {
    use super::MAX_JOB_FILE_BYTES;
    use crate::{Job, fixtures};

    /// A misspelt key is refused with its name, the file and where it is (line 7 of the
    /// fixture with the key added after `nx`).
    #[test]
    fn unknown_keys_are_errors_naming_the_key_and_where_it_is() {
        let text = fixtures::text("elastic-panel").replace("nx = 2", "nx = 2\nnz = 3");
        let line = 1 + text.lines().position(|l| l == "nz = 3").unwrap();
        let err = Job::from_toml(&text, "job.toml").unwrap_err().to_string();
        assert!(err.contains("nz") && err.contains("job.toml"), "{err}");
        assert!(err.contains(&format!("line {line}, column 1")), "{err}");
    }

    /// A job file's relative mesh file is found beside the job file, not in the working
    /// directory.
    #[test]
    fn a_relative_mesh_file_is_resolved_against_the_job_file() {
        let job = fixtures::load("gmsh-square");
        let file = job.mesh.file.as_deref().unwrap();
        assert!(file.starts_with(fixtures::dir()), "{}", file.display());
        assert!(file.is_file(), "{}", file.display());
    }

    /// A file that cannot be read is an error naming it.
    #[test]
    fn a_missing_file_is_an_error_naming_it() {
        let err = Job::load(&fixtures::path("no-such-job")).unwrap_err().to_string();
        assert!(err.contains("no-such-job.toml"), "{err}");
    }

    /// A fresh directory for one test.
    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("cosdem-job-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// `/dev/zero` as a job or mesh file was read until memory ran out: a device, a directory
    /// and a FIFO are refused naming the path and what it is.
    #[cfg(unix)]
    #[test]
    fn a_device_a_fifo_or_a_directory_is_refused_as_a_job_file() {
        let dir = scratch("kinds");
        let fifo = dir.join("job.toml");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        let mut cases = vec![
            (std::path::PathBuf::from("/dev/zero"), "a character device"),
            (dir.clone(), "a directory"),
        ];
        if made.is_ok_and(|s| s.success()) {
            cases.push((fifo, "a FIFO"));
        }
        for (path, kind) in cases {
            let err = Job::load(&path).unwrap_err().to_string();
            assert!(err.contains(&path.display().to_string()) && err.contains(kind), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
        // The mesh file a job names is held to the mesh reader's rules.
        let mut job = fixtures::load("gmsh-square");
        job.mesh.file = Some("/dev/zero".into());
        let err = job.model().unwrap_err().to_string();
        assert!(
            err.contains("mesh.file = \"/dev/zero\"") && err.contains("character device"),
            "{err}"
        );
    }

    /// A job file over 16 MiB is refused with its size and the limit, before it is read (a
    /// sparse file: nothing is written to disk).
    #[test]
    fn a_job_file_over_the_limit_is_refused_and_the_mesh_file_is_checked() {
        let dir = scratch("size");
        let path = dir.join("huge.toml");
        std::fs::File::create(&path).unwrap().set_len(MAX_JOB_FILE_BYTES + 1).unwrap();
        let err = Job::load(&path).unwrap_err().to_string();
        assert!(err.contains("huge.toml") && err.contains("16 MiB"), "{err}");
        assert!(err.contains(&format!("{} bytes", MAX_JOB_FILE_BYTES + 1)), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
