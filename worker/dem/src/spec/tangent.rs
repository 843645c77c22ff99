//! The tangent operator an assembly returns with its stress.

use crate::error::{Result, invalid, positive};
use serde::{Deserialize, Serialize};

/// Tangent operator returned by `solve`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentKind {
    /// The paper's contact-stiffness tangent (k_s, k_r on every active contact).
    #[default]
    #[serde(deserialize_with = "super::no_settings")]
    Paper,
    /// As `Paper` but `k_s' = 0` on sliding and `k_r' = 0` on saturated rolling contacts.
    #[serde(deserialize_with = "super::no_settings")]
    SlidingAware,
    /// `Paper` scaled by the assembly's secant ratio since its committed state: `s = (dsigma
    /// . de) / (de . C de)` with `de` the strain (and curvature) increment from the committed
    /// target, `dsigma` the stress (and couple stress) increment from the committed relaxed
    /// answer and `C` the paper tangent, kept in [`SECANT_RANGE`]. The contact tangent
    /// assumes affine motion and sticking contacts, an upper bound the relaxed random
    /// assembly falls below (its contacts slide, its discs move non-affinely); the secant
    /// measures by how much along the step's own path. `s = 1` (the paper tangent) when the
    /// committed state was never relaxed, the increment is nil, or its second-order work is
    /// not positive (`dsigma . de <= 0`, softening past a peak: no positive scale helps
    /// there). Deterministic: it depends on the committed state and the trial only.
    #[serde(deserialize_with = "super::no_settings")]
    Secant,
    /// Central differences of extra relaxations from the trial state, which is restored.
    Perturbation {
        /// Strain perturbation (default 1e-5 in the job file; must be > 0).
        strain: f64,
    },
    /// `Paper` while fewer than `sliding` of the assembly's contacts slide, `Perturbation`
    /// from there on: the contact-stiffness tangent is right while the contacts stick and too
    /// stiff once the assembly slips and softens, where the perturbation tangent follows it.
    /// Only the sliding assemblies pay the twelve extra relaxations (scene B: the band, not
    /// the 400 points). The choice depends on the assembly's own relaxed state only, so it is
    /// the same whatever worker holds the assembly.
    Adaptive {
        /// Sliding fraction (sliding contacts / contacts) from which the perturbation tangent
        /// is used, in [0, 1].
        sliding: f64,
        /// Strain perturbation of the perturbation tangent (> 0).
        strain: f64,
    },
}

/// The configuration an assembly's answer is linearised and extrapolated in (`frame` of the
/// assembly spec; design note 2026-12-05-updated-lagrangian, sections 2.2 and 2.4).
///
/// The deformation sent is the total `F` from the reference in both frames; what changes is
/// the sense of the tangent and the paths between committed and target:
///
/// | | `reference` (small-strain FE) | `current` (updated-Lagrangian FE) |
/// |---|---|---|
/// | perturbation tangent | `F + h E`, `K + h e_i`: `d s / d e` | `(I + h E) F`, `K + h F^T e_i`, minus the transport `E s - tr(E) s + s E^T`: the convected tangent |
/// | sub-step path | straight in `F`, `w`, `K` | polar: the increment's rotation by angle, its stretch linearly |
/// | shortcut | `s_0 + C (e - e_0)` | `R_d [G s_0 G^T / det G + C de] R_d^T`, `G = R_d^T dF`, tangent turned by `R_d` |
/// | secant ratio | on `e - e_0`, `s - s_0` | on `de` and `s - R_d G s_0 G^T R_d^T / det G` (a rotation is no increment) |
///
/// `reference` is the default and is not written (a spec without the key reads as
/// `reference` and a `reference` spec writes the JSON it wrote before the key existed, so
/// checkpoint digests and stored assemblies do not change).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TangentFrame {
    /// Derivatives with respect to the reference deformation gradient (today's behaviour).
    #[default]
    Reference,
    /// Derivatives on the current configuration, objective paths and shortcut.
    Current,
}

impl TangentFrame {
    /// True for the default [`TangentFrame::Reference`] (which the spec does not write).
    pub fn is_reference(&self) -> bool {
        *self == TangentFrame::Reference
    }
}

/// The range of the [`TangentKind::Secant`] scale: never stiffer than the contact tangent,
/// never softer than a twentieth of it (a near-zero secant would hand Newton a singular
/// matrix).
pub const SECANT_RANGE: (f64, f64) = (0.05, 1.0);

/// Largest perturbation strain of a probed tangent: a larger one is no tangent any more (10
/// turns the assembly inside out: a deformation gradient with a negative determinant).
pub const MAX_TANGENT_STRAIN: f64 = 0.01;

/// Checks a perturbation strain: finite, positive and at most [`MAX_TANGENT_STRAIN`].
fn strain(value: f64) -> Result<()> {
    positive("tangent.strain", value)?;
    if value > MAX_TANGENT_STRAIN {
        return Err(invalid("tangent.strain", value, "must be at most 0.01 (MAX_TANGENT_STRAIN)"));
    }
    Ok(())
}

impl TangentKind {
    /// Checks the perturbation strain and the sliding fraction.
    pub(super) fn validate(&self) -> Result<()> {
        match self {
            TangentKind::Perturbation { strain: s } => strain(*s)?,
            TangentKind::Adaptive { sliding, strain: s } => {
                strain(*s)?;
                if !(0.0..=1.0).contains(sliding) {
                    return Err(invalid("tangent.sliding", sliding, "must be in [0, 1]"));
                }
            }
            TangentKind::Paper | TangentKind::SlidingAware | TangentKind::Secant => {}
        }
        Ok(())
    }
}
