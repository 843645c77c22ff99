//! Where a run directory's results come from: `RUN/provenance.json` (one entry per session:
//! the command line, the cosdem version and commit, when, the job's digest and the step it
//! resumed at) and `RUN/job.toml`, a copy of the job the run ran (a resumed session whose job
//! differs, in its `[output]`, `[workers]` or, with `--newton-changed`, `[newton]` table,
//! writes its own copy `job.session-N.toml`).
//!
//! The digest is FNV-1a (64 bits) of the job's canonical JSON (what serde reads from the file,
//! defaults included): two job files that differ only in layout or comments have one digest.
//! It names a job; it is no security measure.

use super::{OutputError, Result, write_atomic};
use cosdem_job::Job;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The provenance file.
pub const FILE: &str = "provenance.json";

/// The copy of the job of the first session.
pub const JOB_COPY: &str = "job.toml";

/// The commit cosdem was built from (`git rev-parse HEAD` at build time), or `unknown`.
pub const COMMIT: &str = match option_env!("COSDEM_COMMIT") {
    Some(c) => c,
    None => "unknown",
};

/// What the caller of a run knows of where the job comes from.
#[derive(Clone, Debug, Default)]
pub struct Origin {
    /// The command line (the process's arguments when not given).
    pub command: Vec<String>,
    /// The job file's text as the user wrote it (else the job is written out as TOML).
    pub job_text: Option<String>,
}

impl Origin {
    /// The process's command line, no job text.
    pub fn of_process() -> Self {
        Self { command: std::env::args().collect(), job_text: None }
    }
}

/// One session of a run: a `cosdem run`, or a `--resume` of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Session {
    /// Seconds since the Unix epoch when the session's setup succeeded.
    pub started_unix: u64,
    /// The command line.
    pub command: Vec<String>,
    /// cosdem's version.
    pub cosdem_version: String,
    /// The commit it was built from (`unknown` outside a git checkout).
    pub commit: String,
    /// FNV-1a 64 of the job's canonical JSON, 16 hex digits.
    pub job_digest: String,
    /// The copy of the job in the run directory.
    pub job_file: String,
    /// The checkpoint step a resumed session went on from (`None`: a new run).
    pub resumed_at_step: Option<u64>,
}

/// `provenance.json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The sessions, oldest first.
    pub sessions: Vec<Session>,
}

impl Provenance {
    /// The provenance of the run directory `dir` (empty if it has none: a run of an older
    /// cosdem).
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(FILE);
        match std::fs::read_to_string(&path) {
            Ok(text) => serde_json::from_str(&text)
                .map_err(|e| OutputError::InvalidData { path, message: e.to_string() }),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Self::default()),
            Err(e) => Err(super::io_err(&path, "read")(e)),
        }
    }
}

/// The job's digest: FNV-1a 64 of its canonical JSON, as 16 hex digits.
pub fn job_digest(job: &Job) -> String {
    let h = crate::checkpoint::fnv1a(&serde_json::to_string(job).unwrap_or_default());
    format!("{h:016x}")
}

/// Records a session of a run of `job` in `dir`: appends it to `provenance.json` and writes
/// the job's copy (`job.toml` for the first session; a resumed session whose job's digest
/// differs from the last one's writes `job.session-N.toml`).
pub fn record(dir: &Path, job: &Job, origin: &Origin, resumed_at_step: Option<u64>) -> Result<()> {
    let mut p = Provenance::read(dir)?;
    let digest = job_digest(job);
    let job_file = match p.sessions.last() {
        None => JOB_COPY.to_string(),
        Some(last) if last.job_digest == digest => last.job_file.clone(),
        Some(_) => format!("job.session-{}.toml", p.sessions.len() + 1),
    };
    if !dir.join(&job_file).exists() {
        let text = match &origin.job_text {
            Some(t) => t.clone(),
            None => toml::to_string(job).map_err(|e| OutputError::InvalidData {
                path: dir.join(&job_file),
                message: format!("the job as TOML: {e}"),
            })?,
        };
        write_atomic(&dir.join(&job_file), text.as_bytes())?;
    }
    let started_unix = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let command = if origin.command.is_empty() {
        Origin::of_process().command
    } else {
        origin.command.clone()
    };
    p.sessions.push(Session {
        started_unix,
        command,
        cosdem_version: env!("CARGO_PKG_VERSION").to_string(),
        commit: COMMIT.to_string(),
        job_digest: digest,
        job_file,
        resumed_at_step,
    });
    let mut text = serde_json::to_string_pretty(&p)
        .map_err(|e| OutputError::InvalidData { path: dir.join(FILE), message: e.to_string() })?;
    text.push('\n');
    write_atomic(&dir.join(FILE), text.as_bytes())
}
