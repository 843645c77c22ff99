//! What the cosdem master (Cosserat FE) and workers (disc DEM) share.
//!
//! The conventions are those of `shared/THEORY.md`: strain and stress vectors in the order
//! `[xx, yy, xy, yx, k_x | m_x, k_y | m_y]`, where the first index of `s_ij` is the face normal
//! and `e_kl = u_l,k` (so `e_xy = u_y,x - w`).

/// Identity of a Gauss point across master and workers.
pub mod gauss;
/// The macro deformation sent to a Gauss point and the strain vector derived from it.
pub mod kinematics;
/// Assembly specs, committed states and snapshots exchanged between master and workers.
pub mod micro;
/// The homogenized answer of a micro solve: stress, tangent and diagnostics.
pub mod response;
/// Voigt index order shared by every crate.
pub mod voigt;

pub use gauss::GaussPointId;
pub use kinematics::{KinematicsError, MacroDeformation};
pub use response::{
    Answer, MicroDescriptors, MicroDiagnostics, MicroResponse, StressVector, Tangent,
};
