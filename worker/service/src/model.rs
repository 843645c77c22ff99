//! The micro model a worker serves: one stateful assembly per Gauss point.
//!
//! The service only talks to [`MicroModel`], so the stand-in ([`super::StandIn`]) and the DEM
//! `Assembly` plug in the same way. The DEM adapter is a handful of one-line forwards:
//!
//! ```ignore
//! pub struct Dem;
//! impl MicroModel for Dem {
//!     type Assembly = cosdem_dem::Assembly;
//!     fn create(&self, _id: GaussPointId, req: &AssemblyRequest) -> Result<Assembly, ModelError> {
//!         let spec: AssemblySpec = serde_json::from_slice(&req.spec_json)
//!             .map_err(|e| ModelError::InvalidSpec(e.to_string()))?;
//!         Assembly::new(&spec).map_err(|e| ModelError::InvalidSpec(e.to_string()))
//!     }
//!     fn solve(&self, a: &mut Assembly, t: &MacroDeformation) -> Result<MicroResponse, ModelError> {
//!         a.solve(t).map_err(|e| ModelError::Failed(e.to_string()))
//!     }
//!     fn commit(&self, a: &mut Assembly) { a.commit() }
//!     fn rollback(&self, a: &mut Assembly) { a.rollback() }
//!     fn export(&self, a: &Assembly) -> Vec<u8> { a.to_bytes() }
//!     fn import(&self, b: &[u8]) -> Result<Assembly, ModelError> {
//!         Assembly::from_bytes(b).map_err(|e| ModelError::InvalidState(e.to_string()))
//!     }
//!     fn snapshot(&self, a: &Assembly) -> MicroSnapshot { a.snapshot().into() }
//!     fn disc_count(&self, a: &Assembly) -> u64 { a.disc_count() as u64 }
//! }
//! ```

use cosdem_common::micro::{AssemblyRequest, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};

/// Why a model operation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The spec cannot build an assembly (bad JSON, unknown field, impossible packing).
    #[error("invalid assembly spec: {0}")]
    InvalidSpec(String),
    /// Exported bytes that do not make an assembly.
    #[error("invalid assembly state: {0}")]
    InvalidState(String),
    /// A relaxation failed (step cap, blow-up): reported in-band for that Gauss point.
    #[error("{0}")]
    Failed(String),
}

/// A stateful micro model: the operations a worker needs on one assembly.
///
/// Contract (what makes retries, migration and failover bit-identical):
/// - `solve` starts from the committed state and is deterministic given
///   (committed state, target); it leaves the result as the trial state;
/// - `commit` makes the trial state committed; `rollback` discards it;
/// - `export` returns the committed state only; `import(export(a))` behaves exactly as `a`
///   after a rollback.
pub trait MicroModel: Send + Sync + 'static {
    /// One assembly (the DEM `Assembly`).
    type Assembly: Send + 'static;

    /// Builds the assembly of Gauss point `id` from a spec.
    fn create(
        &self,
        id: GaussPointId,
        spec: &AssemblyRequest,
    ) -> Result<Self::Assembly, ModelError>;
    /// Relaxes from the committed state to `target`; the result becomes the trial state.
    fn solve(
        &self,
        assembly: &mut Self::Assembly,
        target: &MacroDeformation,
    ) -> Result<MicroResponse, ModelError>;
    /// Trial -> committed.
    fn commit(&self, assembly: &mut Self::Assembly);
    /// Discards the trial state.
    fn rollback(&self, assembly: &mut Self::Assembly);
    /// The committed state as bytes.
    fn export(&self, assembly: &Self::Assembly) -> Vec<u8>;
    /// An assembly from exported bytes.
    fn import(&self, bytes: &[u8]) -> Result<Self::Assembly, ModelError>;
    /// Particle-level picture (what the model has).
    fn snapshot(&self, assembly: &Self::Assembly) -> MicroSnapshot;
    /// Number of discs (limits, load balancing).
    fn disc_count(&self, assembly: &Self::Assembly) -> u64;
    /// A copy of a freshly created `assembly` for Gauss point `id`, if `create` does not
    /// depend on the Gauss point (one spec builds one specimen). Then the points of one
    /// `CreateAssemblies` call are built once and copied: the copies are the very bits `create`
    /// would build, at none of its cost (a random packing's compression and equilibration).
    /// `None` (the default): every point is built by `create`.
    fn replicate(&self, _assembly: &Self::Assembly, _id: GaussPointId) -> Option<Self::Assembly> {
        None
    }
    /// The disc count an assembly of `spec` will have, read from the spec before anything is
    /// built (an upper bound is fine), for the limits a worker checks first: the service takes
    /// the larger of this and the master's `disc_count_hint`. `None` (the default): the hint
    /// alone. A spec the model cannot read gives `None` (`create` then refuses it by name).
    fn disc_estimate(&self, _spec: &AssemblyRequest) -> Option<u64> {
        None
    }
    /// Relative cost of one relaxation; the disc count unless the model knows better.
    fn cost_hint(&self, assembly: &Self::Assembly) -> f64 {
        self.disc_count(assembly) as f64
    }
}
