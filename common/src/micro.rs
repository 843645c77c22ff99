//! What master and workers exchange about assemblies besides kinematics and responses:
//! how to build one, its committed state as bytes, and its particle-level snapshot.
//!
//! These are the domain types behind the gRPC messages of `cosdem-proto`; the conversions
//! live in that crate (`from_proto.rs`, `to_proto.rs`).

use crate::GaussPointId;
use serde::{Deserialize, Serialize};

/// Boundary condition of a DEM assembly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BoundaryKind {
    /// Not said (the spec's own `boundary` field decides).
    #[default]
    Unspecified,
    /// Miehe-type penalty boundary.
    Penalty,
    /// Periodic cell.
    Periodic,
}

/// How to build an assembly: the DEM spec as JSON plus hints readable without parsing it.
///
/// v1 carries the DEM spec as JSON; the schema is the job file's `[assembly]` table
/// (`cosdem_dem::AssemblySpec`). The JSON is authoritative; the hints serve limits and
/// load balancing.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AssemblyRequest {
    /// JSON of the spec.
    pub spec_json: Vec<u8>,
    /// Boundary type (must agree with the spec).
    pub boundary: BoundaryKind,
    /// Expected disc count (0 = unknown).
    pub disc_count_hint: u64,
}

/// What a worker reports about an assembly it holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AssemblyInfo {
    /// The Gauss point it backs.
    pub id: GaussPointId,
    /// Number of discs.
    pub disc_count: u64,
    /// Relative cost of one relaxation (model units).
    pub cost_hint: f64,
}

/// The committed state of one assembly, as opaque model bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AssemblyState {
    /// The Gauss point it backs.
    pub id: GaussPointId,
    /// Last committed load step (0 = as created).
    pub committed_step: u64,
    /// Model bytes (`Assembly::to_bytes`).
    pub state: Vec<u8>,
    /// Number of discs.
    pub disc_count: u64,
}

/// Particle-level picture of an assembly. A model fills what it has; arrays are flattened.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MicroSnapshot {
    /// Disc centres `[x0, y0, x1, y1, ...]` (m).
    pub positions: Vec<f64>,
    /// Disc radii (m).
    pub radii: Vec<f64>,
    /// Disc rotations (rad).
    pub rotations: Vec<f64>,
    /// Contacts `[i, j, f_n, f_t, ...]`: disc indices (as numbers) and forces (N).
    pub contacts: Vec<f64>,
    /// Fluctuation displacements `[ux0, uy0, ...]` (m).
    pub fluctuations: Vec<f64>,
}
