//! The one error type of the worker crate.

use cosdem_common::KinematicsError;

/// Everything that can go wrong in the DEM micro-solver.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A specification field has a value the solver cannot use.
    #[error("invalid `{field}` = {value}: {reason}")]
    InvalidSpec {
        /// Dotted path of the field (`contact.k_n`, `packing.radius`, ...).
        field: &'static str,
        /// The offending value, formatted.
        value: String,
        /// What a valid value looks like.
        reason: &'static str,
    },
    /// The macro deformation sent to the assembly is unusable.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// The packing request cannot be satisfied (e.g. the confining stress was not reached).
    #[error("packing failed: {0}")]
    Packing(String),
    /// The explicit integration produced non-finite values.
    #[error("relaxation diverged after {steps} steps (non-finite state)")]
    Diverged {
        /// Steps taken when the blow-up was detected.
        steps: u64,
    },
    /// The relaxed state is finite but its homogenized answer is not (e.g. a target whose
    /// det(F) underflows the current area to zero).
    #[error("non-finite homogenized {what} at det(F) = {det:e}")]
    NonFinite {
        /// `stress` or `tangent`.
        what: &'static str,
        /// det(Fbar) of the target.
        det: f64,
    },
    /// A serialized assembly could not be decoded.
    #[error("cannot decode assembly state: {0}")]
    Decode(String),
}

/// Result alias of the worker crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Builds an [`Error::InvalidSpec`].
pub(crate) fn invalid(
    field: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> Error {
    Error::InvalidSpec { field, value: value.to_string(), reason }
}

/// Checks `value` is finite and `> 0`.
pub(crate) fn positive(field: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and > 0"))
    }
}

/// Checks `value` is finite and `>= 0`.
pub(crate) fn non_negative(field: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and >= 0"))
    }
}
