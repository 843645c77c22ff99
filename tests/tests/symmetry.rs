//! Symmetric scenes on a half or quarter mesh (`[mesh] symmetry`, issue 6 item 3d) give the
//! whole panel's load-displacement curve.
//!
//! Elastic panel (the `elastic-panel-confined` fixture: 4 x 4 elements, confined, rough
//! platens): the full problem is exactly mirror-symmetric, so the reduced meshes solve the same
//! linear equations restricted to the kept part; the curves agree to round-off (1e-9 relative:
//! a few hundred dofs, direct solves).
//!
//! DEM panel (the quick job, 2 x 2 elements, three steps): each assembly answers a mirrored
//! deformation only up to its own discreteness and relaxation tolerance (1e-4), and each load
//! step's Newton iteration stops at the quick job's 5e-3 residual on a different system, so
//! the curves agree to the Newton tolerance, not to round-off: 1e-3 relative is asserted
//! (measured: 1.6e-7 on the half mesh, 4e-4 on the quarter).

mod common;

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{Ending, Run, RunObserver};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_fem::symmetry::Symmetry;
use cosdem_job::fixtures;
use cosdem_job::{Job, Moving};

/// `job` on the reduced mesh `symmetry`, validated as a job file would be.
fn with_symmetry(job: &Job, symmetry: Symmetry) -> Job {
    let mut job = job.clone();
    job.mesh.symmetry = symmetry;
    job.validate().unwrap();
    job
}

/// `(displacement, load)` of every step: `load = -scale * R_y(load_set)`.
struct Curve<'j> {
    job: &'j Job,
    points: Vec<(f64, f64)>,
}

impl RunObserver for Curve<'_> {
    fn on_step(
        &mut self,
        r: &StepReport,
        _: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        let ry = r.reactions[&self.job.loading.load_set][1];
        self.points.push((r.load_factor * self.job.shortening(), -self.job.load_scale() * ry));
        Ok(())
    }
}

fn compare(a: &[(f64, f64)], b: &[(f64, f64)], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: step counts differ");
    for (p, q) in a.iter().zip(b) {
        assert_eq!(p.0, q.0, "{what}: displacements differ");
        let rel = (p.1 - q.1).abs() / p.1.abs();
        eprintln!("{what}: d = {:.4e} full {:.6e} reduced {:.6e} rel {rel:.2e}", p.0, p.1, q.1);
        assert!(rel <= tol, "{what}: load {} vs {} ({rel:.2e} > {tol})", q.1, p.1);
    }
}

/// The full elastic panel's load at its last step (1 cm), measured; a direct solve of a few
/// hundred dofs, so 1e-9 relative covers any change of summation order.
const ELASTIC_LAST_LOAD: f64 = 300_000.000_000_000_3;

#[test]
fn elastic_half_and_quarter_meshes_give_the_full_curve() {
    // The job's own material: G = 20 MPa, nu = 0.25, Gc = G / 2, lc = 0.01 m.
    let run = |job: &Job| {
        let mut curve = Curve { job, points: Vec::new() };
        let outcome = Run::without_dir(job).observer(&mut curve).execute().unwrap();
        assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
        curve.points
    };
    let elastic = fixtures::load("elastic-panel-confined");
    let full = run(&elastic);
    let last = full.last().unwrap().1;
    assert!(
        (last - ELASTIC_LAST_LOAD).abs() <= 1e-9 * ELASTIC_LAST_LOAD,
        "compression load {last} N, measured {ELASTIC_LAST_LOAD} N"
    );
    compare(&full, &run(&with_symmetry(&elastic, Symmetry::HalfX)), 1e-9, "elastic half_x");
    compare(&full, &run(&with_symmetry(&elastic, Symmetry::Quarter)), 1e-9, "elastic quarter");
}

#[test]
fn reduced_meshes_need_even_counts_and_a_symmetric_compression() {
    let elastic = fixtures::load("elastic-panel-confined");
    let mut odd = elastic.clone();
    odd.mesh.symmetry = Symmetry::HalfX;
    odd.mesh.nx = Some(3);
    let err = odd.validate().unwrap_err().to_string();
    assert!(err.contains("mesh.nx") && err.contains('3'), "{err}");
    let mut top = elastic;
    top.mesh.symmetry = Symmetry::Quarter;
    top.loading.compression.as_mut().unwrap().moving = Moving::Top;
    let err = top.validate().unwrap_err().to_string();
    assert!(err.contains("mesh.symmetry"), "{err}");
}

fn dem_curve(job: &Job) -> Vec<(f64, f64)> {
    let mut curve = Curve { job, points: Vec::new() };
    common::run_in_process(job, 1, 0, &mut curve);
    curve.points
}

#[test]
fn dem_half_and_quarter_meshes_give_the_full_curve_to_the_newton_tolerance() {
    let quick = common::quick(0.006);
    let full = dem_curve(&quick);
    compare(&full, &dem_curve(&with_symmetry(&quick, Symmetry::HalfX)), 1e-3, "dem half_x");
    compare(&full, &dem_curve(&with_symmetry(&quick, Symmetry::Quarter)), 1e-3, "dem quarter");
}
