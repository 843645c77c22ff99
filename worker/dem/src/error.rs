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
    /// A packing file cannot be read, or does not map onto a 2D specimen.
    #[error("packing file {file}{}: {value}: {reason}", at_line(*.line))]
    PackingFile {
        /// The file, as the job names it.
        file: String,
        /// Line of the offending value (1-based; 0: the file as a whole).
        line: usize,
        /// The offending value, formatted.
        value: String,
        /// What a valid file holds.
        reason: String,
    },
    /// The explicit integration produced non-finite values or a runaway spin
    /// ([`crate::integrate::blown_up`]).
    #[error("relaxation diverged after {steps} steps (non-finite state or runaway spin)")]
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

/// `, line N` (nothing for line 0: the file as a whole).
fn at_line(line: usize) -> String {
    if line == 0 { String::new() } else { format!(", line {line}") }
}

/// Result alias of the worker crate.
pub type Result<T> = std::result::Result<T, Error>;

/// A refused value as a message shows it: numbers in their shortest form (`1e308`, not 309
/// digits), text as it is.
pub(crate) trait Shown {
    /// The value's text.
    fn shown(&self) -> String;
}

impl Shown for f64 {
    fn shown(&self) -> String {
        format!("{self:?}")
    }
}

impl Shown for String {
    fn shown(&self) -> String {
        self.clone()
    }
}

impl Shown for str {
    fn shown(&self) -> String {
        self.to_string()
    }
}

impl<T: Shown + ?Sized> Shown for &T {
    fn shown(&self) -> String {
        (**self).shown()
    }
}

macro_rules! shown_as_display {
    ($($t:ty),*) => {$(
        impl Shown for $t {
            fn shown(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
shown_as_display!(u32, u64, usize, i32, i64);

/// Builds an [`Error::InvalidSpec`].
pub(crate) fn invalid(field: &'static str, value: impl Shown, reason: &'static str) -> Error {
    Error::InvalidSpec { field, value: value.shown(), reason }
}

/// Checks `value` is finite and `> 0` (a refused value prints as `1e308`, not in full).
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A refused 1e308 reads `1e308` (Display would print 309 digits), 1e-300 `1e-300`.
    #[test]
    fn refused_numbers_print_short() {
        let e = positive("packing.radius", -1e308).unwrap_err().to_string();
        assert!(e.contains("-1e308") && e.len() < 120, "{e}");
        let e = invalid("relaxation.safety", 1e-300, "must be in (0, 1]").to_string();
        assert!(e.contains("= 1e-300:"), "{e}");
        assert!(invalid("packing.radii", 3usize, "x").to_string().contains("= 3:"));
    }
}
