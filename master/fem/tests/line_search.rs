//! The line search on the panel under a top pressure: it halves an update that makes the
//! residual grow, and a damped update cannot end a step through the displacement criterion.

mod common;

use common::panel::{elastic, scaled_tangent, sci, soft_tangent, top_pressure_panel};
use cosdem_fem::solve::{Solver, SolverSettings, StepReport};

/// Elastic stresses but a tangent scaled by 0.4: each full Newton update on a pressure load
/// overshoots 2.5 times, so the residual grows (r -> -1.5 r); the line search halves the
/// update (r -> -0.25 r) and the run converges, linearly. Printed: halvings and iterations.
#[test]
fn line_search_engages_when_the_residual_grows() {
    let model = top_pressure_panel();
    let settings = SolverSettings { steps: 1, max_iterations: 40, ..Default::default() };
    let mut solver = Solver::new(model, settings).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    solver.run(&mut soft_tangent(&mut 0), &mut log).unwrap();
    let s = &log[0];
    println!(
        "halvings {} iterations {} residuals {:?}",
        s.line_search_halvings,
        s.iterations,
        sci(&s.residuals)
    );
    assert!(s.line_search_halvings > 0 && s.cuts == 0);
    // the top reaction balances the pressure: 1e5 Pa on 1 m
    assert!((log[0].reactions["bottom"][1] - 1e5).abs() < 1e-6 * 1e5, "{:?}", log[0].reactions);
}

/// The displacement criterion measures the full Newton correction, not the part the line
/// search let through. The tangent here is a tenth of the elastic one, so every full update
/// overshoots 10 times; three halvings (alpha = 1/8) give 1.25 times the exact correction,
/// and the error contracts by -0.25 per iteration. With the force criterion off the step can
/// only end on `|du| <= t |u - u_n|`, t = 0.05. Measured on the full correction (10 times
/// the exact one, e) that means |e| <= t / 10 of the step, and after the damped update the
/// error is 0.25 |e| <= 0.125 % of the step; measured on the damped update (1.25 e) it
/// would mean |e| <= t / 1.25 and an error of up to 1 % of the step. Measured: 0.055 % of
/// the step after 8 iterations; the damped measure ended the step after 6, at 0.88 %.
/// Checked: the accepted displacement is within 0.2 % of the step of the exact elastic
/// answer (a linear problem: the exact answer is one elastic solve, tolerance 1e-12), and
/// the step backtracked.
#[test]
fn a_line_search_damped_update_cannot_end_a_step() {
    let settings = SolverSettings {
        steps: 1,
        max_iterations: 60,
        force_tolerance: 0.0,
        displacement_tolerance: 0.05,
        ..Default::default()
    };
    let mut solver = Solver::new(top_pressure_panel(), settings).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    solver.run(&mut scaled_tangent(0.1, &mut 0), &mut log).unwrap();
    let mut exact = Solver::new(
        top_pressure_panel(),
        SolverSettings { steps: 1, force_tolerance: 1e-12, ..Default::default() },
    )
    .unwrap();
    exact.run(&mut elastic(), &mut ()).unwrap();
    let (u, v) = (solver.solution().dofs, exact.solution().dofs);
    let error = u.iter().zip(v).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
    let step = v.iter().map(|b| b * b).sum::<f64>().sqrt();
    let s = &log[0];
    println!(
        "halvings {} iterations {} residuals {:?}; error {:.3e} of the step",
        s.line_search_halvings,
        s.iterations,
        sci(&s.residuals),
        error / step
    );
    assert!(s.line_search_halvings >= 3 && s.cuts == 0, "{s:?}");
    assert!(error <= 2e-3 * step, "error {error:e} of a step of {step:e}");
}
