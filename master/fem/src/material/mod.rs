//! The constitutive operator at the Gauss points, seen from the finite-element side.
//!
//! The FE solver talks to its material only through [`Material`]: one batched call per Newton
//! iteration with every Gauss point's trial kinematics, then `commit` or `rollback`. An
//! analytical material and the DEM-backed worker pool are both implementations.
//!
//! [`Material`]: crate::material::Material

use cosdem_common::micro::AssemblyState;
use cosdem_common::micro::MicroSnapshot;
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};

mod biot;
mod elastic;
mod failing;
mod regions;
mod softening;

pub use biot::BiotCosserat;
pub use elastic::ElasticCosserat;
pub use failing::FailureInjector;
pub use regions::{Regions, RegionsError};
pub use softening::SofteningElastic;

/// Identifies one trial evaluation: load step and Newton iteration within it.
///
/// Workers use it to answer retries idempotently: the same id always gets the same answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TrialId {
    /// Load step being solved (the first step is 1; step 0 is the reference state).
    pub step: u64,
    /// Newton iteration within the step (0-based); attempts after a cut keep counting up.
    pub iteration: u32,
}

/// The trial kinematics of one Gauss point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialInput {
    /// Which Gauss point.
    pub gauss_point: GaussPointId,
    /// Its trial deformation gradient, micro-rotation and curvature.
    pub deformation: MacroDeformation,
}

/// Why a material could not answer.
#[derive(Debug, Clone, thiserror::Error)]
pub enum MaterialError {
    /// One or more Gauss points failed (relaxation hit its cap, bad kinematics, ...).
    /// The solver cuts the load step; below the minimum step it reports these points.
    #[error("{} gauss point(s) failed: {}", .0.len(), describe(.0))]
    GaussPoints(Vec<(GaussPointId, String)>),
    /// The material as a whole is unavailable (every worker lost, transport failure, ...).
    #[error("material unavailable: {0}")]
    Unavailable(String),
}

fn describe(points: &[(GaussPointId, String)]) -> String {
    let mut s: Vec<String> =
        points.iter().take(8).map(|(id, why)| format!("{id}: {why}")).collect();
    if points.len() > 8 {
        s.push(format!("and {} more", points.len() - 8));
    }
    s.join("; ")
}

/// A constitutive operator evaluated at all Gauss points at once.
pub trait Material: Send {
    /// Evaluates every Gauss point at its trial kinematics, starting from the last committed
    /// state (never from a previous trial unless the material documents a warm start).
    /// Returns one response per input, in the order of `inputs`.
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError>;

    /// Makes the last evaluated trial state the committed state of every Gauss point.
    fn commit(&mut self, step: u64) -> Result<(), MaterialError>;

    /// Discards trial states: the next evaluation starts from the committed state again.
    fn rollback(&mut self) -> Result<(), MaterialError>;

    /// True when the tangent is symmetric (the solver may then use Cholesky).
    fn is_symmetric(&self) -> bool {
        false
    }

    /// The committed state of every Gauss point, for a checkpoint; `None` for a material
    /// without state (analytical laws).
    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        Ok(None)
    }

    /// Puts back committed states saved by [`Material::committed_states`] (resume from a
    /// checkpoint, or a caller going back to states it saved before committing more steps:
    /// the assemblies of those points are replaced). Stateless materials ignore them.
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        let _ = states;
        Ok(())
    }

    /// Particle-level picture of one Gauss point's committed state, for output; `None` when
    /// the material has no particles (the analytical materials: the default).
    fn snapshot(&mut self, _id: GaussPointId) -> Result<Option<MicroSnapshot>, MaterialError> {
        Ok(None)
    }
}
