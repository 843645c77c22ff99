//! The figures of the sweeps and studies, drawn with the run figures' helpers
//! ([`cosdem_app::output::plot`]).

/// The Pareto front of a speed/accuracy sweep.
pub mod pareto;
/// The RVE-size study's figures (Figs. 3-5).
pub mod rve_size;
