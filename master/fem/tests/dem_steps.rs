//! The DEM-step count of a run: every evaluation the solver asks for is counted once, in the
//! step's report or, for the step that ended the run, as uncommitted steps.

mod common;

use common::panel::{
    Adjusted, elastic, one_iteration_per_attempt, panel, soft_tangent, top_pressure_panel,
};
use cosdem_common::MicroResponse;
use cosdem_fem::Error;
use cosdem_fem::material::{MaterialInput, SofteningElastic, TrialId};
use cosdem_fem::solve::{Solver, SolverSettings, StepReport};

/// A step's `dem_steps` is the cost of every relaxation of the step: each evaluation the
/// solver asks for (the predictor's, every Newton iteration, every line-search trial), not
/// only the converged one. [`soft_tangent`] reports 7 DEM steps per Gauss point per
/// evaluation and counts them; its soft tangent makes each step take line-search halvings
/// and several iterations (a count of the converged evaluation alone
/// would be 7 x points per step, far below the sum).
#[test]
fn dem_steps_count_every_evaluation() {
    let model = top_pressure_panel();
    let settings = SolverSettings { steps: 2, max_iterations: 40, ..Default::default() };
    let mut solver = Solver::new(model, settings).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    let mut asked = 0;
    solver.run(&mut soft_tangent(&mut asked), &mut log).unwrap();
    let points = solver.solution().gauss_points.len() as u64;
    let reported: u64 = log.iter().map(|s| s.dem_steps).sum();
    assert_eq!(reported, asked);
    assert!(log.iter().all(|s| s.line_search_halvings > 0 && s.iterations > 2));
    assert!(reported > 2 * 7 * points * 3, "{reported} for {points} points");
}

/// A step that ends the run (cut below the minimum increment) still cost its relaxations:
/// none of its attempts reaches a [`StepReport`], so the solver keeps them as
/// `uncommitted_dem_steps` for the run's summary (a failed biaxial reference lost about 11
/// minutes of attempts from its count). Every evaluation is counted once: the reports' sum
/// plus the uncommitted ones is what the material was asked for, and the failed step did
/// cost some (a first step that runs out of its one iteration at every cut).
#[test]
fn a_failed_step_keeps_its_dem_steps() {
    let settings = one_iteration_per_attempt();
    let mut solver = Solver::new(panel(-0.04), settings).unwrap();
    let mut asked = 0;
    let mut mat = Adjusted(
        SofteningElastic { elastic: elastic(), beta: 400.0 },
        |_: TrialId, _: &[MaterialInput], r: &mut [MicroResponse]| {
            for x in r.iter_mut() {
                x.diagnostics.steps = 7;
            }
            asked += 7 * r.len() as u64;
        },
    );
    let mut log: Vec<StepReport> = Vec::new();
    let err = solver.run(&mut mat, &mut log).unwrap_err();
    assert!(matches!(err, Error::StepTooSmall { .. }), "{err}");
    let reported: u64 = log.iter().map(|s| s.dem_steps).sum();
    let pending = solver.uncommitted_dem_steps();
    assert!(pending > 0, "the failed step's attempts were not kept");
    assert_eq!(reported + pending, asked);
}
