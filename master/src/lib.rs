//! The cosdem master: the Cosserat finite-element macro solver.
//!
//! Data path: [`mesh::Mesh`] -> [`assembly::GaussData`] (Gauss points) -> [`material::Material`]
//! (one batched evaluation per Newton iteration) -> [`assembly::CosseratOperator`] (residual,
//! sparse tangent) -> [`solve::Solver`] (faer solve, Newton, step cutting, commit) ->
//! [`solve::StepObserver`] (output).

/// From nodal fields to Gauss-point kinematics and back to global residual and tangent.
pub mod assembly;
/// Reference elements: Q8/Q9 shape functions and Gauss rules.
pub mod element;
/// The crate's error type.
pub mod error;
/// The constitutive operator at the Gauss points: the trait the FE solver talks to.
pub mod material;
/// The macro mesh: structured rectangles and the generic raw-description constructor.
pub mod mesh;
/// Derived quantities for plots (equivalent strain, Eq. 34).
pub mod post;
/// Loading, linear solves, Newton-Raphson with step cutting, step observers.
pub mod solve;

pub use error::{Error, Result};
