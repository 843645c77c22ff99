//! Why a run directory or one of its files cannot be read back: every message names the
//! directory or file and, for a step or point that was not saved, what was.

use crate::output::OutputError;
use std::fmt::Display;
use std::path::PathBuf;

/// Lists longer than this are shown as their first and last few entries.
const LONG_LIST: usize = 12;
/// Entries shown at each end of a long list.
const LIST_ENDS: usize = 5;

/// Why [`super::RunReader`] cannot give what was asked.
#[derive(Debug, thiserror::Error)]
pub enum ResultsError {
    /// The path is not a run directory: missing, not a directory, or holding neither
    /// `summary.json` nor `curve.csv`.
    #[error("{}: not a run directory: {reason}", path.display())]
    NotARun {
        /// The path given.
        path: PathBuf,
        /// Why, naming what the path is or holds.
        reason: String,
    },
    /// The step asked for has no file of this kind.
    #[error("step {step} has no {what} in {}; {}", dir.display(), saved_steps(*step, saved))]
    StepNotSaved {
        /// The run directory.
        dir: PathBuf,
        /// What was asked: `Gauss-point fields`, `mesh` or `snapshot eE_pP`.
        what: String,
        /// The step asked for.
        step: u64,
        /// The steps that have this kind of file, ascending.
        saved: Vec<u64>,
    },
    /// The Gauss point asked for has no snapshot series.
    #[error(
        "no snapshots of element {element}, Gauss point {point} in {}; snapshot points: {}",
        dir.display(),
        snapshot_points(saved)
    )]
    PointNotSaved {
        /// The run directory.
        dir: PathBuf,
        /// The element asked for.
        element: u32,
        /// The Gauss point (within the element) asked for.
        point: u32,
        /// The `(element, point)` pairs that have snapshots, ascending.
        saved: Vec<(u32, u32)>,
    },
    /// A file could not be read or is not what the writer writes (the error names the file:
    /// the operating system's refusal, or the line, array or value that is wrong).
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// `saved steps: 1, 2, 5, 10`; a long list abbreviated to its ends, with the saved steps
/// nearest to `step`; `saved steps: none` for an empty one.
fn saved_steps(step: u64, saved: &[u64]) -> String {
    if saved.is_empty() {
        return "saved steps: none".into();
    }
    let mut s = format!("saved steps: {}", abbreviated(saved, |v| v.to_string()));
    if saved.len() > LONG_LIST {
        let after = saved.partition_point(|&s| s < step);
        let near: Vec<String> = saved[after.saturating_sub(1)..(after + 1).min(saved.len())]
            .iter()
            .map(u64::to_string)
            .collect();
        s.push_str(&format!(" ({} in all; nearest to {step}: {})", saved.len(), near.join(", ")));
    }
    s
}

/// `[e0 p0, e1 p2]`, or why there is none.
fn snapshot_points(saved: &[(u32, u32)]) -> String {
    if saved.is_empty() {
        return "none: the job's [output] snapshots is empty (or its material has no particles)"
            .into();
    }
    let list = abbreviated(saved, |(e, p)| format!("e{e} p{p}"));
    if saved.len() > LONG_LIST {
        format!("[{list}] ({} in all)", saved.len())
    } else {
        format!("[{list}]")
    }
}

/// The entries joined by `, `; a list longer than [`LONG_LIST`] as its first and last
/// [`LIST_ENDS`] entries around `...`.
pub(super) fn abbreviated<T: Copy, S: Display>(items: &[T], show: impl Fn(T) -> S) -> String {
    let join =
        |part: &[T]| part.iter().map(|&i| show(i).to_string()).collect::<Vec<_>>().join(", ");
    if items.len() <= LONG_LIST {
        join(items)
    } else {
        format!("{}, ..., {}", join(&items[..LIST_ENDS]), join(&items[items.len() - LIST_ENDS..]))
    }
}
