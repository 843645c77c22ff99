//! The cosdem worker: disc DEM assemblies, one per Gauss point.
//!
//! Data path: [`spec`] -> [`packing`] -> [`assembly`] (committed / trial state) ->
//! [`broadphase`] -> [`contact`] -> [`integrate`] (with [`boundary`]) -> [`homogenize`] ->
//! `MicroResponse`.

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
/// The crate's error type.
pub mod error;
/// Homogenized stress, tangents and fabric.
pub mod homogenize;
/// Leapfrog integration, time step, Cundall and FIRE relaxation.
pub mod integrate;
/// Reference packings (hexagonal, random).
pub mod packing;
/// The serde specification of an assembly.
pub mod spec;

pub use assembly::{Assembly, ContactForce, Snapshot, State};
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
