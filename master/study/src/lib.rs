//! Everything in cosdem that runs many jobs: the speed/accuracy sweep ([`tradeoff`]) and its
//! average over specimens ([`specimens`]), the RVE-size study ([`rve_size`]), and the coupling
//! benchmarks ([`bench`]).

/// Benchmarks of the coupling (RPC overhead, worker scaling, FE versus DEM cost): `cosdem bench`.
pub mod bench;
/// The figures of the sweeps and studies (Pareto front, RVE-size laws).
pub mod plot;
/// Parameter studies over whole runs: the RVE-size study (Eqs. 30-32), `cosdem study`.
pub mod rve_size;
/// Speed against accuracy averaged over specimens (packing seeds):
/// `cosdem bench tradeoff-specimens`.
pub mod specimens;
/// Speed against accuracy: the knob sweep of `cosdem bench tradeoff`.
pub mod tradeoff;
