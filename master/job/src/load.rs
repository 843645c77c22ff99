//! Reading a job: TOML text or a file. Parse errors (unknown keys, wrong types) carry the
//! line and column from the TOML parser and name the file ([`Error::JobFile`]); every job read
//! here is validated.

use crate::schema::Job;
use cosdem_fem::error::{Error, Result};
use std::path::Path;

impl Job {
    /// Parses a job from TOML text; `origin` names the file in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        let job: Job = toml::from_str(text)
            .map_err(|e| Error::JobFile { file: origin.to_string(), message: e.to_string() })?;
        job.validate()?;
        Ok(job)
    }

    /// Reads and validates a job file; relative paths inside it are resolved against it.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::JobFile {
            file: path.display().to_string(),
            message: e.to_string(),
        })?;
        let mut job = Self::from_toml(&text, &path.display().to_string())?;
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
}
