//! From nodal fields to Gauss-point kinematics, and from Gauss-point responses to the global
//! residual and sparse tangent.
//!
//! Three concerns, fenris-style: [`crate::element`] knows reference shapes; [`GaussData`]
//! holds the mapped shape functions of every Gauss point (computed once); [`CosseratOperator`]
//! is the local assembler (B matrix, element force and stiffness) and [`Pattern`] scatters into
//! a CSC matrix whose structure is built once.
//!
//! [`GaussData`]: crate::assembly::GaussData
//! [`CosseratOperator`]: crate::assembly::CosseratOperator
//! [`Pattern`]: crate::assembly::Pattern

mod current;
mod dofs;
mod gauss;
mod operator;
mod pattern;

pub use current::Kinematics;
pub use dofs::{Component, DofMap, Field};
pub use gauss::GaussData;
pub use operator::{Assembled, CosseratOperator};
pub use pattern::Pattern;
