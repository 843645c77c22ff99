//! Contact law of THEORY.md section 2: resolved parameters, the pair force of two discs, and
//! the force kernel over a pair list.
//!
//! Sub-models (normal, tangential, rolling) are chosen by [`crate::spec::ContactParams`]; the
//! kernel is monomorphized over "has rolling" and "has dashpots" so a scene without them pays
//! nothing. Branch vectors run from each centre to the middle of the overlap
//! (`a_p = r_p - d/2`), which makes the slip rate vanish under a rigid rotation of the pair;
//! see [`pair`](crate::contact::pair) for the reasoning.

/// Force kernel over a pair list (the hot loop).
pub mod kernel;
/// The law's arithmetic for one pair and for four at once.
pub mod lanes;
/// Normal sub-model: spring-dashpot without tension.
pub mod normal;
/// One pair of discs, as a pure function (the reference the kernel is tested against).
pub mod pair;
/// Rolling sub-model: incremental spring with cap `mu_r r* F_n`.
pub mod rolling;
/// The force kernel four pairs at a time on AVX2.
#[cfg(target_arch = "x86_64")]
pub mod simd;
/// Tangential sub-model: incremental spring with Coulomb cap.
pub mod tangential;

use crate::spec::{ContactParams, NormalModel, RollingModel, TangentialModel};
use serde::{Deserialize, Serialize};

/// Resolved contact coefficients; a disabled sub-model has zero coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Law {
    /// Normal stiffness (N/m).
    pub kn: f64,
    /// Normal dashpot (N s/m).
    pub cn: f64,
    /// Tangential stiffness (N/m).
    pub ks: f64,
    /// Tangential dashpot (N s/m).
    pub cs: f64,
    /// Sliding friction coefficient.
    pub mu_s: f64,
    /// Rolling stiffness (N m/rad).
    pub kr: f64,
    /// Rolling dashpot (N m s/rad).
    pub cr: f64,
    /// Rolling friction coefficient.
    pub mu_r: f64,
}

impl Law {
    /// Resolves the serde sub-models into plain coefficients.
    pub fn from_params(p: &ContactParams) -> Self {
        let (kn, cn) = match p.normal {
            NormalModel::Linear { k_n } => (k_n, 0.0),
            NormalModel::LinearDashpot { k_n, c_n } => (k_n, c_n),
        };
        let (ks, mu_s, cs) = match p.tangential {
            TangentialModel::None => (0.0, 0.0, 0.0),
            TangentialModel::Coulomb { k_s, mu_s, c_s } => (k_s, mu_s, c_s),
        };
        let (kr, mu_r, cr) = match p.rolling {
            RollingModel::None => (0.0, 0.0, 0.0),
            RollingModel::Coulomb { k_r, mu_r, c_r } => (k_r, mu_r, c_r),
        };
        Self { kn, cn, ks, cs, mu_s, kr, cr, mu_r }
    }

    /// True when the rolling sub-model does anything.
    pub fn has_rolling(&self) -> bool {
        self.kr > 0.0 || self.cr > 0.0
    }

    /// True when any dashpot is non-zero.
    pub fn has_damping(&self) -> bool {
        self.cn > 0.0 || self.cs > 0.0 || self.cr > 0.0
    }

    /// The same law without friction (used while a random packing is compressed).
    pub fn frictionless(&self) -> Self {
        Self { ks: 0.0, cs: 0.0, mu_s: 0.0, kr: 0.0, cr: 0.0, mu_r: 0.0, ..*self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sub-model with zero coefficients selects the kernel without it (issue 6, item 3b):
    /// `k_r = 0` and `c_r = 0` through the Coulomb rolling model is the no-rolling kernel, and
    /// zero dashpots are the undamped one, exactly as the `none` models are.
    #[test]
    fn zero_coefficients_select_the_kernel_without_the_sub_model() {
        let off = ContactParams {
            rolling: RollingModel::Coulomb { k_r: 0.0, mu_r: 0.2, c_r: 0.0 },
            ..ContactParams::default()
        };
        let law = Law::from_params(&off);
        assert!(!law.has_rolling(), "k_r = 0, c_r = 0 must skip the rolling work");
        assert!(!law.has_damping(), "c = 0 everywhere must skip the dashpot terms");
        let none = Law::from_params(&ContactParams { rolling: RollingModel::None, ..off });
        assert!(!none.has_rolling());
        let on = Law::from_params(&ContactParams::default());
        assert!(on.has_rolling() && !on.has_damping());
        let damped = Law::from_params(&ContactParams {
            normal: NormalModel::LinearDashpot { k_n: 6.7e7, c_n: 1.0 },
            ..ContactParams::default()
        });
        assert!(damped.has_damping());
    }
}
