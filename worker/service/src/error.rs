//! The service's errors and the one place that maps them to `tonic::Status`.

use super::model::ModelError;
use cosdem_common::GaussPointId;
use tonic::Status;

/// Why a worker call failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ServiceError {
    /// No assembly for this Gauss point on this worker.
    #[error("no assembly for {0} on this worker")]
    NotFound(GaussPointId),
    /// CreateAssemblies for a Gauss point that already has one.
    #[error("an assembly for {0} already exists on this worker")]
    AlreadyExists(GaussPointId),
    /// A malformed request (missing field, NaN, det(F) <= 0, duplicate id, bad enum).
    #[error("{0}")]
    InvalidArgument(String),
    /// Master and worker speak different protocol versions.
    #[error("protocol version mismatch: master speaks {master}, this worker speaks {worker}")]
    VersionMismatch {
        /// The master's version.
        master: u32,
        /// This worker's version.
        worker: u32,
    },
    /// Over a configured limit (assemblies, discs).
    #[error("{0}")]
    ResourceExhausted(String),
    /// The call does not fit the state (commit of a step with no trial, ...).
    #[error("{0}")]
    FailedPrecondition(String),
    /// The model refused a spec or a state.
    #[error("{0}")]
    Model(#[from] ModelError),
    /// An exported state that does not make an assembly (ImportState), with the Gauss point
    /// it was sent for: the decoder names only the part at fault (header, checksum, spec,
    /// body), and one request may carry many states.
    #[error("assembly {id}: {reason}")]
    Import {
        /// The Gauss point the state was sent for.
        id: GaussPointId,
        /// Why the model refused it (in the message, so not a `source()` as well).
        reason: ModelError,
    },
    /// A bug or a lost background task.
    #[error("internal error: {0}")]
    Internal(String),
    /// Configuration that cannot run (e.g. a public address without a token).
    #[error("configuration: {0}")]
    Config(String),
    /// Binding or serving failed.
    #[error("transport: {0}")]
    Transport(String),
}

/// Result of the service crate.
pub type Result<T, E = ServiceError> = std::result::Result<T, E>;

impl From<ServiceError> for Status {
    fn from(e: ServiceError) -> Status {
        let msg = e.to_string();
        match e {
            ServiceError::NotFound(_) => Status::not_found(msg),
            ServiceError::AlreadyExists(_) => Status::already_exists(msg),
            ServiceError::InvalidArgument(_) => Status::invalid_argument(msg),
            ServiceError::VersionMismatch { .. } => Status::failed_precondition(msg),
            ServiceError::ResourceExhausted(_) => Status::resource_exhausted(msg),
            ServiceError::FailedPrecondition(_) => Status::failed_precondition(msg),
            ServiceError::Model(m) | ServiceError::Import { reason: m, .. } => match m {
                ModelError::InvalidSpec(_) | ModelError::InvalidState(_) => {
                    Status::invalid_argument(msg)
                }
                ModelError::Failed(_) => Status::internal(msg),
            },
            ServiceError::Internal(_) | ServiceError::Config(_) | ServiceError::Transport(_) => {
                Status::internal(msg)
            }
        }
    }
}
