//! The contact law's parameters: normal, tangential and rolling sub-models.

use crate::error::{Result, non_negative, positive};
use serde::{Deserialize, Serialize};

/// Contact law of THEORY.md section 2, one sub-model per part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactParams {
    /// Normal sub-model.
    pub normal: NormalModel,
    /// Tangential sub-model.
    pub tangential: TangentialModel,
    /// Rolling-resistance sub-model.
    pub rolling: RollingModel,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            normal: NormalModel::Linear { k_n: 6.7e7 },
            tangential: TangentialModel::Coulomb { k_s: 3.4e7, mu_s: 0.5, c_s: 0.0 },
            rolling: RollingModel::Coulomb { k_r: 25.0, mu_r: 0.2, c_r: 0.0 },
        }
    }
}

/// Normal force `F_n = k_n d + c_n d_dot >= 0` (Eqs. 14-15).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum NormalModel {
    /// Linear spring, no dashpot (the paper; relaxation relies on numerical damping).
    Linear {
        /// Normal stiffness (N/m). Paper: 6.7e7.
        k_n: f64,
    },
    /// Linear spring with a viscous dashpot.
    LinearDashpot {
        /// Normal stiffness (N/m).
        k_n: f64,
        /// Normal damping coefficient (N s/m).
        c_n: f64,
    },
}

/// Tangential force: incremental spring with Coulomb cap (Eqs. 16-19).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum TangentialModel {
    /// Frictionless contacts.
    #[serde(deserialize_with = "super::no_settings")]
    None,
    /// Spring `k_s`, dashpot `c_s`, Coulomb limit `mu_s F_n`.
    Coulomb {
        /// Tangential stiffness (N/m). Paper: 3.4e7.
        k_s: f64,
        /// Sliding friction coefficient. Paper: 0.5.
        mu_s: f64,
        /// Tangential damping (N s/m). Paper: 0.
        #[serde(default)]
        c_s: f64,
    },
}

/// Rolling resistance: incremental spring with cap `mu_r r* F_n` (Eqs. 20-23).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum RollingModel {
    /// No rolling resistance: the kernel skips the rolling history entirely.
    #[serde(deserialize_with = "super::no_settings")]
    None,
    /// Spring `k_r`, dashpot `c_r`, cap `mu_r r* F_n`.
    Coulomb {
        /// Rolling stiffness (N m/rad). Paper: 25.
        k_r: f64,
        /// Rolling friction coefficient. Paper: 0.2.
        mu_r: f64,
        /// Rolling damping (N m s/rad). Paper: 0.
        #[serde(default)]
        c_r: f64,
    },
}

impl ContactParams {
    /// Checks the sub-models' stiffnesses, friction coefficients and dampings.
    pub(super) fn validate(&self) -> Result<()> {
        match &self.normal {
            NormalModel::Linear { k_n } => positive("contact.normal.k_n", *k_n)?,
            NormalModel::LinearDashpot { k_n, c_n } => {
                positive("contact.normal.k_n", *k_n)?;
                non_negative("contact.normal.c_n", *c_n)?;
            }
        }
        if let TangentialModel::Coulomb { k_s, mu_s, c_s } = &self.tangential {
            non_negative("contact.tangential.k_s", *k_s)?;
            non_negative("contact.tangential.mu_s", *mu_s)?;
            non_negative("contact.tangential.c_s", *c_s)?;
        }
        if let RollingModel::Coulomb { k_r, mu_r, c_r } = &self.rolling {
            non_negative("contact.rolling.k_r", *k_r)?;
            non_negative("contact.rolling.mu_r", *mu_r)?;
            non_negative("contact.rolling.c_r", *c_r)?;
        }
        Ok(())
    }
}
