//! The in-situ stress of every Gauss point: what its DEM assembly is consolidated at when the
//! assemblies start from the stress of their place in the ground (issue 28) instead of one
//! uniform stress for all (FEMxDEM's way).
//!
//! The rule: the in-situ stress is that of the first stage's loads (the geostatic stage:
//! gravity, surcharges, supports; for a job without `[[stage]]`, its `[loading]`) solved on
//! the job's mesh with a homogeneous linear-elastic material of Poisson ratio `nu`. The DEM
//! generator consolidates isotropically only, so each point gets its mean stress
//! `p = -(s_xx + s_yy) / 2` (compression positive). That is the in-plane mean: the
//! out-of-plane stress `s_zz = nu (s_xx + s_yy)` of plane strain is not in it, since the 2D
//! assemblies have no z direction.
//!
//! The shear modulus is 1e8 Pa and does not matter: under body forces and tractions, with
//! supports that prescribe displacements of zero, multiplying every modulus of a homogeneous
//! linear body by a factor divides its displacements by that factor and leaves its stresses
//! as they were (the loads and the zero supports are the same), so the stress depends on
//! the ratios of the moduli (`nu`) only. On a Cosserat mesh the other moduli are taken in
//! proportion to `G` (`Gc = G / 2`, the job file's default for an elastic material) with the
//! job's internal length `lc`: they act only through the skew-symmetric stress and the couple
//! stresses, which vanish in a laterally uniform column and stay small where the stress varies
//! slowly over `lc`. (A first stage that prescribes a non-zero displacement would give
//! stresses proportional to `G`: the rule is meant for supports and loads.)
//!
//! The problem is linear: it is solved in one load step, whose predictor is the exact linear
//! solve; the first Newton iteration only checks its residual.

use super::RunError;
use cosdem_common::voigt::{XX, YY};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::solve::Solver;
use cosdem_job::Job;

/// The shear modulus of the elastic solve (Pa): any value gives the same stresses (see the
/// module's doc); 1e8 Pa is a soil's order of magnitude, so that the displacements and the
/// solver's tolerances are of their usual sizes.
pub const SHEAR_MODULUS: f64 = 1e8;

/// The in-situ mean stress `p = -(s_xx + s_yy) / 2` (Pa, compression positive) of every Gauss
/// point of `job`'s mesh, element-major (the order of [`super::gauss_point_ids`]): the first
/// stage's loads (gravity, surcharges, supports) solved with a homogeneous linear-elastic
/// material of Poisson ratio `poisson` (see the [module](self) doc for the rule). Writes
/// nothing and starts no worker; the job's `[material]` is not used (a DEM job works).
///
/// A point that the first stage pulls gets `p <= 0`: what to do with it is the caller's.
///
/// Errors: `poisson` outside (-1, 0.5) ([`cosdem_fem::Error::InvalidSetting`] naming
/// `specimens.poisson`); the job's model or settings; an elastic solve that fails (a mesh the
/// first stage does not support against rigid motion).
pub fn in_situ_mean_stress(job: &Job, poisson: f64) -> Result<Vec<f64>, RunError> {
    let span = tracing::info_span!("in_situ", poisson);
    let _enter = span.enter();
    if !(poisson > -1.0 && poisson < 0.5) {
        return Err(RunError::Solver(cosdem_fem::Error::InvalidSetting {
            field: "specimens.poisson",
            value: format!("{poisson:?}"),
            reason: "the Poisson ratio of the in-situ stress solve must be in (-1, 0.5)".into(),
        }));
    }
    let model = job.model()?;
    // One step: the answer of a linear problem does not depend on how its load is split
    // (every ramp of the first stage reaches its end value at load factor 1). The job's
    // Newton tolerances stay; secant updates would only repeat the constant tangent.
    let settings = cosdem_fem::solve::SolverSettings {
        steps: 1,
        secant_updates: false,
        ..job.solver_settings()?
    };
    let mut solver = Solver::new(model, settings)?;
    let mut material = ElasticCosserat::new(
        SHEAR_MODULUS,
        poisson,
        0.5 * SHEAR_MODULUS,
        super::internal_length(job),
    );
    solver.run(&mut material, &mut ())?;
    let p: Vec<f64> = solver
        .solution()
        .gauss_points
        .iter()
        .map(|g| -0.5 * (g.stress[XX] + g.stress[YY]))
        .collect();
    let (min, max) =
        p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    tracing::info!(gauss_points = p.len(), min, max, "in-situ mean stress");
    Ok(p)
}
