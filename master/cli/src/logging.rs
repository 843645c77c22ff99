//! The run's log: `RUN/cosdem.log`, filtered by `RUST_LOG` (default `info`).

use anyhow::{Context, Result};
use std::path::Path;

/// Sends the process's `tracing` events to `dir/cosdem.log` (appended to on a resume).
pub(crate) fn init_logging(dir: &Path, append: bool) -> Result<()> {
    let file = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(dir.join("cosdem.log"))
        .with_context(|| format!("creating {}", dir.join("cosdem.log").display()))?;
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::sync::Mutex::new(file))
        .with_ansi(false)
        .init();
    Ok(())
}
