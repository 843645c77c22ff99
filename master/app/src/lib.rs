//! The cosdem application: a job run to its end into a run directory.
//!
//! [`run`] is the one run driver ([`run::Run`]: the material for a job, the solver, the
//! writer, one per-step hook for the run directory, checkpoints and the caller's observer),
//! through which the CLI, the sweeps, the studies and the tests run jobs; [`checkpoint`]
//! saves and restores a run; [`output`] writes the run directory (curve, VTK, summary,
//! snapshots) and draws its figures; [`results`] reads a run directory back as plain arrays
//! (for the Python binding); [`stepper`] drives a job's solver one stage at a time for a
//! caller that sets the loads between solves (the Python binding's solver); [`rve`] drives one
//! assembly through a laboratory path (`cosdem rve`, calibration).

/// Checkpoints (`RUN/checkpoint.bin`), resume, and the clean stop on Ctrl-C.
pub mod checkpoint;
/// Writing results: VTK unstructured grids, ParaView collections, CSV curves, plots.
pub mod output;
/// A run directory read back: summary, curve, Gauss-point and mesh fields, snapshots.
pub mod results;
/// One job run to its end into a run directory: the one run driver ([`run::Run`]).
pub mod run;
/// One DEM assembly driven through a laboratory path (biaxial, isotropic, simple shear):
/// `cosdem rve`, for calibrating micro parameters.
pub mod rve;
/// A job's solver driven one stage at a time by a caller ([`stepper::Stepper`]).
pub mod stepper;
