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
    /// How the answer was obtained: a relaxation, or a shortcut from the last relaxed state.
    pub answer: Answer,
    /// Size of the deformation increment answered without a relaxation (the skip measure
    /// `max(|dF_ij|, |dw|, l |dk_i|)` since the last relaxation; 0 when relaxed).
    pub unrelaxed_increment: f64,
    /// Estimated bound on the stress error the shortcut adds: the largest component of the
    /// extrapolated stress increment `|C de|` (Pa, or N for couple stresses), 0 when relaxed.
    pub error_bound: f64,
    /// Micro-structure of the assembly that answered (of the last relaxed state for a
    /// shortcut answer); `None` for analytical materials.
    pub descriptors: Option<MicroDescriptors>,
}

/// Micro-structure descriptors of a DEM assembly, as FEMxDEM studies publish them per Gauss
/// point. Computed from the state after the solve, never changing it. Contacts are the active
/// ones of the homogenization (overlapping or touching within 1e-9 of the radii sum).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MicroDescriptors {
    /// Porosity `1 - sum(pi r^2) / A` of the current cell of area `A = det(Fbar) V` (overlaps
    /// counted twice: negligible at the small overlaps of stiff contacts).
    pub porosity: f64,
    /// Void ratio `A / sum(pi r^2) - 1`.
    pub void_ratio: f64,
    /// Coordination number `2 N_c / N` over all discs.
    pub coordination: f64,
    /// Mechanical coordination number `2 (N_c - N_c1) / (N - N_0 - N_1)` without the rattlers
    /// (the `N_0` discs with no contact and the `N_1` with one, whose `N_c1` contacts go with
    /// them; 0 when every disc rattles).
    pub mechanical_coordination: f64,
    /// Contact-normal fabric `F_xx = (1/N_c) sum n_x n_x` (0 without contacts).
    pub fabric_xx: f64,
    /// Contact-normal fabric `F_yy` (`F_xx + F_yy = 1` with contacts).
    pub fabric_yy: f64,
    /// Contact-normal fabric `F_xy`.
    pub fabric_xy: f64,
    /// Fabric anisotropy `a = 2 (f_1 - f_2) / (f_1 + f_2)` from the principal values
    /// `f_1 >= f_2` of the fabric (the `a` of `E(theta) = (1 + a cos 2(theta - theta_a)) /
    /// (2 pi)`); 0 for an isotropic fabric or without contacts.
    pub anisotropy: f64,
    /// Major principal direction `theta_a` of the fabric, radians from x in `(-pi/2, pi/2]`
    /// (meaningless when `anisotropy` is at rounding level).
    pub fabric_direction: f64,
    /// Fraction of the contacts whose tangential force is at the Coulomb limit `mu_s F_n`.
    pub sliding_fraction: f64,
    /// Mean disc rotation (rad, counter-clockwise positive) since the discs were placed, over
    /// the discs whose rotation is finite.
    pub mean_rotation: f64,
}

/// How a material point produced its answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Answer {
    /// A relaxation to the requested deformation (or an analytical material).
    #[default]
    Relaxed,
    /// Not relaxed: the increment since the last relaxation was below `relaxation.skip_below`;
    /// the last relaxed stress plus tangent times the strain increment answered.
    Skipped,
    /// Not relaxed: the increment keeps every contact sticking and none opens or closes
    /// (`relaxation.elastic_shortcut`); answered through the tangent as for `Skipped`.
    Linear,
}

impl Answer {
    /// Wire code (0 relaxed, 1 skipped, 2 linear).
    pub fn code(self) -> u32 {
        match self {
            Answer::Relaxed => 0,
            Answer::Skipped => 1,
            Answer::Linear => 2,
        }
    }

    /// From the wire code; unknown codes read as `Relaxed`.
    pub fn from_code(c: u32) -> Self {
        match c {
            1 => Answer::Skipped,
            2 => Answer::Linear,
            _ => Answer::Relaxed,
        }
    }
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
