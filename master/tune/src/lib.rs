//! Speed against accuracy: the speed knobs ([`knob`]), the measured trade tables ([`table`]),
//! and the accuracy planner ([`accuracy`]), a pure function of a job and a table. The tables
//! the planner reads are committed beside this crate (`data/`, with a note of how each was
//! made), so re-measuring a table under `docs/notes/` changes nothing a job picks.

/// Accuracy target: the cheapest speed settings the measured trade predicts to stay within
/// a job's `accuracy` (what was picked and why: `RUN/accuracy.json`).
pub mod accuracy;
/// The speed knobs: [`knob::Knob`], their one catalogue, and the sweep built from it.
pub mod knob;
/// The trade table: rows, errors against a reference, Pareto front, CSV and Markdown.
pub mod table;
