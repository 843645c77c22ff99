//! Claiming a run directory: the run directory is a transaction log, and a run never destroys
//! a previous run's results.
//!
//! - One writer at a time: an advisory lock (`flock`) on `RUN/.cosdem.lock`, held for the whole
//!   run and released by the operating system when the process ends, however it ends. A second
//!   run into the directory is refused naming the process that holds it.
//! - A new run goes into an absent or empty directory. A directory holding anything else is
//!   refused unless the run overwrites ([`Mode::Overwrite`]: once its setup has succeeded the old
//!   directory is renamed `RUN.old-N` and the run starts in a fresh `RUN`) or resumes
//!   ([`Mode::Resume`]: the run goes on in it from its checkpoint).
//! - A run whose setup fails (a worker down, an unknown set, a bad snapshot index) leaves the
//!   directory as it found it: [`Claim`] is committed only after the setup, and a claim dropped
//!   before removes the directory it created.
//! - Temporary files (`*.tmp` of [`super::write_atomic`] cut short by a kill) are removed when
//!   the claim is committed.

use super::{OutputError, io_err};
use std::fs::File;
use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};

/// The lock file inside a run directory.
pub const LOCK_FILE: &str = ".cosdem.lock";

/// Why a run directory cannot be claimed.
#[derive(Debug, thiserror::Error)]
pub enum ClaimError {
    /// Another process holds the directory's lock.
    #[error(
        "{} is being written by another cosdem run ({holder}); wait for it to end or choose another --out",
        dir.display()
    )]
    Locked {
        /// The run directory.
        dir: PathBuf,
        /// What the lock file says of its holder (`pid N on HOST`).
        holder: String,
    },
    /// A new run into a directory that holds a previous run (or anything else).
    #[error(
        "{} already holds {what}; use --overwrite to keep it as {}.old-N and start again, --resume to go on from its checkpoint, or another --out",
        dir.display(), dir.display()
    )]
    NotEmpty {
        /// The run directory.
        dir: PathBuf,
        /// What is there (`a finished run of 200 steps`, `3 files`).
        what: String,
    },
    /// `--resume` of a directory that does not exist.
    #[error("{}: no run directory to resume (is --out the one the run used?)", dir.display())]
    Missing {
        /// The run directory.
        dir: PathBuf,
    },
    /// The file system refused.
    #[error(transparent)]
    Io(#[from] OutputError),
}

/// How a run takes its directory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// A new run: the directory must be absent or empty.
    Fresh,
    /// A new run that keeps a previous one as `RUN.old-N` once its setup has succeeded.
    Overwrite,
    /// The run goes on in the directory from its checkpoint.
    Resume,
}

/// The advisory lock of one run directory, held until dropped.
#[derive(Debug)]
pub struct RunLock {
    _file: File,
}

impl RunLock {
    /// Takes the lock of `dir` (which must exist), writing this process's id into the lock
    /// file for the message a second writer gets.
    pub fn acquire(dir: &Path) -> Result<Self, ClaimError> {
        let path = dir.join(LOCK_FILE);
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true)
            .open(&path)
            .map_err(io_err(&path, "open the lock file"))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = match holder.trim() {
                    "" => "holder unknown".to_string(),
                    h => h.to_string(),
                };
                return Err(ClaimError::Locked { dir: dir.to_path_buf(), holder });
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(io_err(&path, "lock")(e).into());
            }
        }
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().to_string())
            .unwrap_or_else(|_| "this host".into());
        let me = format!("pid {} on {host}\n", std::process::id());
        let write = |f: &mut File| -> std::io::Result<()> {
            f.set_len(0)?;
            f.rewind()?;
            f.write_all(me.as_bytes())
        };
        write(&mut file).map_err(io_err(&path, "write the lock file"))?;
        Ok(Self { _file: file })
    }
}

/// Whether a process holds the lock of `dir` now: a `running` summary whose lock is free was
/// left by a process that ended without writing its status (killed).
pub fn is_locked(dir: &Path) -> bool {
    let Ok(file) = File::open(dir.join(LOCK_FILE)) else { return false };
    matches!(file.try_lock_shared(), Err(std::fs::TryLockError::WouldBlock))
}

/// A run directory claimed by a run whose setup has not finished: locked, and committed
/// ([`Claim::commit`]) once the setup has succeeded. Dropped uncommitted, it leaves the
/// directory as it was (a directory it created is removed).
#[derive(Debug)]
pub struct Claim {
    dir: PathBuf,
    mode: Mode,
    lock: Option<RunLock>,
    /// The directory did not exist: the claim created it.
    created: bool,
    /// The directory holds a previous run that [`Mode::Overwrite`] moves aside.
    occupied: bool,
}

impl Claim {
    /// Claims `dir` for a run of `mode`: creates it if needed (not for a resume), takes its
    /// lock, and refuses a new run into a directory that holds anything.
    pub fn take(dir: &Path, mode: Mode) -> Result<Self, ClaimError> {
        let exists = dir.is_dir();
        if !exists && mode == Mode::Resume {
            return Err(ClaimError::Missing { dir: dir.to_path_buf() });
        }
        if !exists {
            std::fs::create_dir_all(dir).map_err(io_err(dir, "create directory"))?;
        }
        let mut claim =
            Self { dir: dir.to_path_buf(), mode, lock: None, created: !exists, occupied: false };
        claim.lock = Some(RunLock::acquire(dir)?);
        let entries = contents(dir)?;
        claim.occupied = !entries.is_empty();
        if claim.occupied && mode == Mode::Fresh {
            return Err(ClaimError::NotEmpty {
                dir: dir.to_path_buf(),
                what: describe(dir, &entries),
            });
        }
        Ok(claim)
    }

    /// The setup has succeeded: the run writes into the returned directory (the claimed path)
    /// under the returned lock. A [`Mode::Overwrite`] of an occupied directory renames it to
    /// `RUN.old-N` (the smallest free N) and starts a fresh one; temporary files left by a
    /// kill are removed.
    pub fn commit(mut self) -> Result<RunLock, ClaimError> {
        let lock = if self.mode == Mode::Overwrite && self.occupied {
            self.move_aside()?
        } else {
            remove_temporaries(&self.dir)?;
            self.lock.take().expect("a claim holds its lock until committed")
        };
        self.created = false;
        Ok(lock)
    }

    /// Builds the fresh directory beside the old one (locked), then renames the old one to
    /// `RUN.old-N` and the new one to `RUN`: a second writer never finds `RUN` unlocked.
    fn move_aside(&mut self) -> Result<RunLock, ClaimError> {
        let dir = &self.dir;
        let name = dir.file_name().map_or("run".into(), |n| n.to_string_lossy().into_owned());
        let sibling = |suffix: String| dir.with_file_name(format!("{name}{suffix}"));
        let staging = sibling(format!(".new-{}", std::process::id()));
        std::fs::create_dir_all(&staging).map_err(io_err(&staging, "create directory"))?;
        let lock = RunLock::acquire(&staging)?;
        let old = (1..)
            .map(|n| sibling(format!(".old-{n}")))
            .find(|p| !p.exists())
            .expect("some N is free");
        std::fs::rename(dir, &old).map_err(io_err(dir, "rename the previous run"))?;
        std::fs::rename(&staging, dir).map_err(io_err(&staging, "rename into place"))?;
        tracing::info!(previous = %old.display(), "the previous run is kept");
        self.lock = None;
        Ok(lock)
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        if self.created {
            // Only the lock file is in a directory this claim created and did not commit.
            let _ = std::fs::remove_file(self.dir.join(LOCK_FILE));
            let _ = std::fs::remove_dir(&self.dir);
        }
    }
}

/// The entries of `dir` other than the lock file.
fn contents(dir: &Path) -> Result<Vec<String>, ClaimError> {
    let read = std::fs::read_dir(dir).map_err(io_err(dir, "list"))?;
    let mut names = Vec::new();
    for entry in read {
        let entry = entry.map_err(io_err(dir, "list"))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name != LOCK_FILE {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// What a directory holds, for [`ClaimError::NotEmpty`].
fn describe(dir: &Path, entries: &[String]) -> String {
    match super::run_dir::Summary::read(dir) {
        Ok(s) => format!("a run with status `{}` after {} steps", s.status, s.steps),
        Err(_) => match entries {
            [one] => format!("the file {one:?}"),
            _ => format!("{} files ({:?}, ...)", entries.len(), entries[0]),
        },
    }
}

/// Removes the `*.tmp` files [`super::write_atomic`] leaves when killed between writing and
/// renaming, in the run directory and its subdirectories (one level down, and the snapshot
/// series' directories two levels down).
pub fn remove_temporaries(dir: &Path) -> Result<(), ClaimError> {
    fn walk(dir: &Path, depth: u32) -> Result<(), ClaimError> {
        let Ok(read) = std::fs::read_dir(dir) else { return Ok(()) };
        for entry in read.flatten() {
            let path = entry.path();
            let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
            if is_dir && depth > 0 {
                walk(&path, depth - 1)?;
            } else if !is_dir && path.extension().is_some_and(|e| e == "tmp") {
                std::fs::remove_file(&path).map_err(io_err(&path, "remove temporary file"))?;
            }
        }
        Ok(())
    }
    walk(dir, 2)
}

#[cfg(test)]
mod tests;
