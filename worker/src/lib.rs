//! The cosdem worker: disc DEM assemblies, one per Gauss point.

/// The gRPC service (`cosdem.v1.MicroSolver`) around a micro model: serve, limits, token.
pub mod service;
