//! The one error type of the master crate.

use crate::material::MaterialError;
use cosdem_common::GaussPointId;

/// Result alias of the master crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong in meshing, assembly and the nonlinear solve.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A mesh description is inconsistent (bad node index, wrong node count, ...).
    #[error("invalid mesh: {field} = {value}: {reason}")]
    InvalidMesh {
        /// Which part of the description.
        field: &'static str,
        /// The offending value.
        value: String,
        /// Why it is invalid.
        reason: String,
    },
    /// A named node or edge set does not exist in the mesh.
    #[error("unknown {kind} set `{name}` (known: {known})")]
    UnknownSet {
        /// `node`, `edge` or `element`.
        kind: &'static str,
        /// The requested name.
        name: String,
        /// The names the mesh has.
        known: String,
    },
    /// An element maps to a non-positive area at a quadrature point.
    #[error("element {element}: Jacobian determinant {det_j:?} <= 0 at reference point {xi:?}")]
    InvertedElement {
        /// Element index.
        element: usize,
        /// The determinant found.
        det_j: f64,
        /// Reference coordinates of the point.
        xi: [f64; 2],
    },
    /// A job file cannot be read or parsed (the message has the line, column and key).
    #[error("job file {file}: {message}")]
    JobFile {
        /// The file (or the origin given to the parser).
        file: String,
        /// What went wrong.
        message: String,
    },
    /// A checkpoint cannot be read, written or used (the message says why: checksum,
    /// format, another job).
    #[error("checkpoint {file}: {message}")]
    Checkpoint {
        /// The checkpoint file.
        file: String,
        /// What went wrong.
        message: String,
    },
    /// A solver or load setting is out of range.
    #[error("invalid setting {field} = {value}: {reason}")]
    InvalidSetting {
        /// Setting name.
        field: &'static str,
        /// The offending value.
        value: String,
        /// The allowed range.
        reason: String,
    },
    /// The material answered with the wrong number of responses.
    #[error("material returned {got} responses for {expected} gauss points")]
    ResponseCount {
        /// Responses expected (one per Gauss point).
        expected: usize,
        /// Responses received.
        got: usize,
    },
    /// The material cannot be reached at all (no step cutting helps).
    #[error("material error: {0}")]
    Material(#[from] MaterialError),
    /// The sparse linear solver failed outside the Newton loop (symbolic analysis, memory).
    #[error("linear solver: {0}")]
    LinearSolver(String),
    /// The load increment was cut below the minimum and the step still fails.
    #[error(
        "load step {step} failed from load factor {load_factor:.6e} with increment \
         {increment:.3e} (largest prescribed displacement of the attempt {displacement:.6e} m), \
         and halving it would go below the minimum {min_increment:.3e}: {reason}{}",
        describe_points(gauss_points)
    )]
    StepTooSmall {
        /// Load step being solved.
        step: u64,
        /// Last converged load factor.
        load_factor: f64,
        /// The largest magnitude of a prescribed dof value in the last failed attempt (the
        /// platen displacement of a compression; m, or rad for a prescribed rotation).
        displacement: f64,
        /// Increment of the last failed attempt.
        increment: f64,
        /// The minimum increment allowed.
        min_increment: f64,
        /// Why the last attempt failed.
        reason: String,
        /// Gauss points that failed in the last attempt (empty for a pure divergence).
        gauss_points: Vec<(GaussPointId, String)>,
    },
    /// A DEM assembly driven alone (`cosdem rve`, the size study) failed at a step.
    #[error("RVE test step {step}: {message}")]
    Rve {
        /// The load step.
        step: u64,
        /// What went wrong.
        message: String,
    },
    /// The run was asked to stop (Ctrl-C) and stopped cleanly after this committed step.
    #[error("interrupted after step {step}")]
    Interrupted {
        /// The last committed step.
        step: u64,
    },
    /// An observer refused a converged step (e.g. output failed).
    #[error("step observer: {0}")]
    Observer(String),
}

fn describe_points(points: &[(GaussPointId, String)]) -> String {
    if points.is_empty() {
        return String::new();
    }
    let list: Vec<String> = points.iter().map(|(id, why)| format!("{id} ({why})")).collect();
    format!("; failed gauss points: {}", list.join(", "))
}
