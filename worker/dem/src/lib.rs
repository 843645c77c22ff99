//! The pure DEM core of cosdem: disc assemblies, one per Gauss point (no network, no CLI; the
//! gRPC service around it is `cosdem-worker`).
//!
//! Data path: [`spec`] -> [`packing`] -> [`assembly`] (committed / trial state) ->
//! [`broadphase`] -> [`contact`] -> [`integrate`] (with [`boundary`]) -> [`homogenize`] (and
//! [`descriptors`]) -> `MicroResponse`.
//!
//! # Readings of THEORY.md fixed here
//! - Branch vectors to the contact point (`a_p = r_p - d/2`) in the slip rate and torques,
//!   instead of `r_p`: the printed Eq. 16 gives a spurious slip `-omega d` under a rigid
//!   rotation and torques that do not balance the force couple (see [`contact::pair`]).
//! - `kbar . (X_q - X_c)` in Eq. 24 uses reference coordinates: `kbar` is the gradient of the
//!   micro-rotation over the reference configuration, unchanged by a superposed rigid rotation.
//! - The closed forms of `C_xyxy` and `C_xyyx` separately assume every disc turns with `wbar`;
//!   with Eq. 24 only the boundary layer is pinned, so the measured antisymmetric stiffness is
//!   a few percent of `C_xyxy - C_xyyx` (the symmetric part matches).
//! - Boundary-average stress uses `x_q - X_c` (origin-independent only at equilibrium).
//! - Periodic cells ignore `wbar` and `kbar` (see [`boundary::periodic`]).
//! - Every run starts from rest at the affine image of its start state (the predictor), and
//!   just-touching contacts (gap < 1e-9 of the radii sum) count in the tangent.

/// One DEM assembly: state, solve, commit/rollback, serialization, snapshots.
pub mod assembly;
/// Benchmark workloads (printed figures, not timed tests).
pub mod bench;
/// Penalty (Eq. 24) and periodic boundaries.
pub mod boundary;
/// Cell grid + Verlet pair list with per-contact histories.
pub mod broadphase;
/// Contact law: normal, tangential and rolling sub-models and the force kernel.
pub mod contact;
/// Micro-structure descriptors: porosity, coordination, fabric, sliding, rotation.
pub mod descriptors;
/// The crate's error type.
pub mod error;
/// The fluctuation field (Eq. 35) and the affine fit of a deformed assembly.
pub mod fluctuation;
/// Homogenized stress, tangents and fabric.
pub mod homogenize;
/// Leapfrog integration, time step, Cundall and FIRE relaxation.
pub mod integrate;
/// Reference packings (hexagonal, random).
pub mod packing;
/// The serde specification of an assembly.
pub mod spec;

pub use assembly::{Assembly, ContactForce, Snapshot, State, StepIncrement};
pub use error::{Error, Result};
pub use spec::{
    AssemblySpec, BoundarySpec, ContactParams, Criterion, Driver, NormalModel, PackingSpec,
    RelaxationSpec, RollingModel, TangentKind, TangentialModel,
};

use cosdem_common::{MacroDeformation, MicroResponse};
use rayon::prelude::*;

/// Solves many assemblies in parallel (one rayon task per assembly, never inside one), so the
/// results do not depend on the thread count.
///
/// # Panics
/// When `assemblies` and `targets` differ in length (a caller bug, not user input).
pub fn solve_batch(
    assemblies: &mut [Assembly],
    targets: &[MacroDeformation],
) -> Vec<Result<MicroResponse>> {
    assert_eq!(assemblies.len(), targets.len(), "one target per assembly");
    assemblies.par_iter_mut().zip(targets.par_iter()).map(|(a, t)| a.solve(t)).collect()
}
