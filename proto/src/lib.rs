//! The gRPC contract between master and workers, generated from `proto/cosdem.proto`.
//!
//! Nothing outside the RPC layers (the worker's service and the master's pool) should pass
//! these prost types around: they convert to the domain types of `cosdem-common` at the edge.

/// Generated messages, client and server of package `cosdem.v1`.
#[allow(missing_docs, clippy::all)]
pub mod v1 {
    tonic::include_proto!("cosdem.v1");
}

/// The protocol version a master and a worker must agree on at handshake.
pub const PROTOCOL_VERSION: u32 = 1;
