//! The answer of a material point: stress vector, consistent tangent and diagnostics.

use crate::voigt::N;
use serde::{Deserialize, Serialize};

/// `[s_xx, s_yy, s_xy, s_yx, m_x, m_y]` in Pa and N (per metre of thickness), tension positive.
pub type StressVector = [f64; N];

/// 6x6 tangent: `tangent[row][col] = d s_row / d e_col` (row `s_ij`, column `e_kl`).
pub type Tangent = [[f64; N]; N];

/// How a micro solve went. Reported for every Gauss point and every iteration.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MicroDiagnostics {
    /// Explicit DEM steps taken by the relaxation (0 for analytical materials).
    pub steps: u64,
    /// Equilibrium ratio reached (kinetic-energy or unbalanced-force ratio, per the driver).
    pub residual_ratio: f64,
    /// Whether the relaxation reached its tolerance before its step cap.
    pub converged: bool,
    /// Number of active contacts at the end.
    pub contacts: u32,
    /// Fraction of active contacts sliding at the Coulomb limit.
    pub sliding_fraction: f64,
    /// Fraction of active contacts whose rolling moment is saturated.
    pub rolling_fraction: f64,
    /// Wall time of the solve in seconds (not part of any deterministic result).
    pub wall_seconds: f64,
}

/// Homogenized response of one Gauss point for one trial deformation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MicroResponse {
    /// Stress and couple stress.
    pub stress: StressVector,
    /// Tangent operator in the Voigt order of [`crate::voigt`].
    pub tangent: Tangent,
    /// How the solve went.
    pub diagnostics: MicroDiagnostics,
}

impl MicroResponse {
    /// True when every stress and tangent entry is finite.
    pub fn is_finite(&self) -> bool {
        self.stress.iter().all(|v| v.is_finite())
            && self.tangent.iter().flatten().all(|v| v.is_finite())
    }
}
