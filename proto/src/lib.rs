//! The gRPC contract between master and workers, generated from `proto/cosdem.proto`.
//!
//! Nothing outside the RPC layers (the worker's service and the master's pool) should pass
//! these prost types around: they convert to the domain types of `cosdem-common` at the edge,
//! with the conversions of this crate, shared by both sides.

/// Generated messages, client and server of package `cosdem.v1`.
#[allow(missing_docs, clippy::all)]
pub mod v1 {
    tonic::include_proto!("cosdem.v1");
}

/// Wire -> domain conversions, validating as they go.
pub mod from_proto;
/// A peer's text made safe to log ([`printable`]).
pub mod text;
/// Domain -> wire conversions.
pub mod to_proto;

pub use from_proto::ConvertError;
pub use text::printable;

/// The protocol version a master and a worker must agree on at handshake. 2: a SolveBatch
/// may carry the commit of the previous step (a worker of protocol 1 would ignore it). 3: the
/// assembly spec has `relaxation.substep` (a worker of protocol 2 refuses the spec with an
/// unknown field; the handshake says so first, naming both versions). 4: the diagnostics of
/// every answer carry the micro descriptors (porosity, coordination, fabric, sliding, mean
/// rotation; a master of protocol 3 would drop them without a word, so it is refused). 5: the
/// assembly spec may have `relaxation.predictor`, and the state of an `extrapolated` assembly
/// carries its last step's increment (a worker of protocol 4 refuses the spec by name).
pub const PROTOCOL_VERSION: u32 = 5;

/// Default limit on one gRPC message, both directions (256 MiB): large assemblies'
/// exported states and snapshots must pass.
pub const DEFAULT_MAX_MESSAGE_BYTES: usize = 256 * 1024 * 1024;

/// Metadata key carrying the shared secret (`Bearer <token>`).
pub const AUTHORIZATION: &str = "authorization";
