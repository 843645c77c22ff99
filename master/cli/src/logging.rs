//! The run's log: `RUN/cosdem.log`, filtered by `RUST_LOG` (default `info`).
//!
//! The log is set up before the run directory is known to be the run's: until the run driver
//! has claimed the directory and finished the setup ([`cosdem_app::run::RunObserver::on_dir`]),
//! the events are held in memory, so that a run refused or failed during its setup leaves a
//! previous run's `cosdem.log` as it was. Then the held events go first into the file.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Where the events go: held in memory, then the run's log file.
enum Sink {
    Held(Vec<u8>),
    File(std::fs::File),
}

/// The log's writer, shared by the subscriber and [`LogFile::open`].
#[derive(Clone)]
pub(crate) struct LogFile(Arc<Mutex<Sink>>);

impl LogFile {
    /// Sends the process's `tracing` events to memory until [`LogFile::open`].
    pub(crate) fn init() -> Self {
        let log = Self(Arc::new(Mutex::new(Sink::Held(Vec::new()))));
        let writer = log.clone();
        tracing_subscriber::fmt()
            .with_env_filter(
                tracing_subscriber::EnvFilter::try_from_default_env()
                    .unwrap_or_else(|_| "info".into()),
            )
            .with_writer(move || writer.clone())
            .with_ansi(false)
            .init();
        log
    }

    /// Opens `dir/cosdem.log` (appended to on a resume, else new) and writes the held events
    /// into it first.
    pub(crate) fn open(&self, dir: &Path, append: bool) -> Result<()> {
        let path = dir.join("cosdem.log");
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .write(true)
            .append(append)
            .truncate(!append)
            .open(&path)
            .with_context(|| format!("creating {}", path.display()))?;
        let mut sink = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Sink::Held(held) = &*sink {
            file.write_all(held).with_context(|| format!("writing {}", path.display()))?;
        }
        *sink = Sink::File(file);
        Ok(())
    }
}

impl Write for LogFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut *self.0.lock().unwrap_or_else(|e| e.into_inner()) {
            Sink::Held(held) => {
                held.extend_from_slice(buf);
                Ok(buf.len())
            }
            Sink::File(f) => f.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut *self.0.lock().unwrap_or_else(|e| e.into_inner()) {
            Sink::Held(_) => Ok(()),
            Sink::File(f) => f.flush(),
        }
    }
}
