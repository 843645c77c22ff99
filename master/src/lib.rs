//! The cosdem master: the Cosserat finite-element macro solver.

/// The constitutive operator at the Gauss points: the trait the FE solver talks to.
pub mod material;
/// The DEM-backed material: a pool of workers (remote or in-process), with failover and balancing.
pub mod pool;
