//! The real micro model: a DEM [`Assembly`] per Gauss point behind the service.

use super::model::{MicroModel, ModelError};
use cosdem_common::micro::{AssemblyRequest, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_dem::{Assembly, AssemblySpec};

/// The DEM micro model: builds [`Assembly`]s from the JSON spec of the job's
/// `[material.assembly]` table and relaxes them.
///
/// A relaxation that hits its step cap is a failure of that Gauss point (THEORY.md section 3:
/// the master rolls back and cuts the load step), reported with the ratio it reached.
#[derive(Clone, Copy, Debug, Default)]
pub struct Dem;

impl MicroModel for Dem {
    type Assembly = Assembly;

    fn create(&self, _id: GaussPointId, req: &AssemblyRequest) -> Result<Assembly, ModelError> {
        let spec: AssemblySpec = serde_json::from_slice(&req.spec_json)
            .map_err(|e| ModelError::InvalidSpec(e.to_string()))?;
        Assembly::new(&spec).map_err(|e| ModelError::InvalidSpec(e.to_string()))
    }

    /// The packing's disc count ([`AssemblySpec::disc_count_hint`]: exact for hexagonal
    /// packings, an upper bound at worst), for a spec that reads and validates.
    fn disc_estimate(&self, req: &AssemblyRequest) -> Option<u64> {
        let spec: AssemblySpec = serde_json::from_slice(&req.spec_json).ok()?;
        spec.validate().ok()?;
        Some(spec.disc_count_hint())
    }

    /// [`Assembly::new`] depends on the spec alone (a random packing's seed is in the spec),
    /// so every Gauss point of one spec holds the same specimen.
    fn replicate(&self, assembly: &Assembly, _id: GaussPointId) -> Option<Assembly> {
        Some(assembly.clone())
    }

    fn solve(
        &self,
        assembly: &mut Assembly,
        target: &MacroDeformation,
    ) -> Result<MicroResponse, ModelError> {
        let r = assembly.solve(target).map_err(|e| ModelError::Failed(e.to_string()))?;
        if !r.diagnostics.converged {
            return Err(ModelError::Failed(format!(
                "relaxation hit its step cap: residual ratio {:.3e} after {} steps",
                r.diagnostics.residual_ratio, r.diagnostics.steps
            )));
        }
        Ok(r)
    }

    fn commit(&self, assembly: &mut Assembly) {
        assembly.commit();
    }

    fn rollback(&self, assembly: &mut Assembly) {
        assembly.rollback();
    }

    fn export(&self, assembly: &Assembly) -> Vec<u8> {
        assembly.to_bytes()
    }

    fn import(&self, bytes: &[u8]) -> Result<Assembly, ModelError> {
        Assembly::from_bytes(bytes).map_err(|e| ModelError::InvalidState(e.to_string()))
    }

    fn snapshot(&self, assembly: &Assembly) -> MicroSnapshot {
        assembly.snapshot().into()
    }

    fn disc_count(&self, assembly: &Assembly) -> u64 {
        assembly.disc_count() as u64
    }
}
