//! The assembly's boundary: penalty constraints or a periodic cell.

use crate::error::{Result, non_negative, positive};
use serde::{Deserialize, Serialize};

/// Boundary conditions of the assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BoundarySpec {
    /// Miehe's penalty constraints on the boundary layer (Eq. 24, THEORY.md reading).
    Penalty {
        /// Force penalty `eps_f` (N m); the spring stiffness is `eps_f / V`. Paper: 6.7e6.
        eps_f: f64,
        /// Moment penalty `eps_c` (N m^3/rad); the spring is `eps_c / V`. Paper: 1e3.
        eps_c: f64,
    },
    /// Periodic cell that follows Fbar (see [`crate::boundary::periodic`] for how `wbar` and
    /// `kbar` are treated).
    #[serde(deserialize_with = "super::no_settings")]
    Periodic,
}

impl Default for BoundarySpec {
    fn default() -> Self {
        Self::Penalty { eps_f: 6.7e6, eps_c: 1.0e3 }
    }
}

impl BoundarySpec {
    /// Checks the penalty coefficients.
    pub(super) fn validate(&self) -> Result<()> {
        if let BoundarySpec::Penalty { eps_f, eps_c } = self {
            positive("boundary.eps_f", *eps_f)?;
            non_negative("boundary.eps_c", *eps_c)?;
        }
        Ok(())
    }
}
