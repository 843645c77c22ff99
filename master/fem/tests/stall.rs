//! `stall_iterations`: an attempt whose best residual is within the tolerated residual and no
//! longer falls ends early; a contracting one is not changed.

mod common;

use common::panel::{elastic, panel, scaled_tangent, top_pressure_panel};
use cosdem_fem::Error;
use cosdem_fem::material::SofteningElastic;
use cosdem_fem::solve::{Solver, SolverSettings, StepReport};

/// `stall_iterations`: an attempt whose smallest residual is within `tolerated_residual`
/// and has not fallen for that many iterations ends there, tolerated. On the diverging
/// iteration of `a_tolerated_step_accepts_its_best_iterate` (`tolerated_and_forced.rs`;
/// residuals 0.43, 1.29, 0.55, ..., none below the first), a limit of 2 ends the attempt at
/// iteration 3 and tolerates the first iterate, where without it the attempt runs to its 20
/// iterations; with the tolerated residual below the first iterate's, the stall does not end
/// it early (it runs to 20 iterations and fails). On the contracting iteration of
/// `newton_converges_quadratically_with_exact_tangent` (`newton_convergence.rs`) every
/// iteration is a new best, so even a limit of 1 changes nothing (the same dofs, bit for bit).
#[test]
fn a_stalled_attempt_ends_early_a_contracting_one_does_not() {
    let diverging = |stall_iterations: u32, tolerated_residual: f64| {
        let settings = SolverSettings {
            steps: 1,
            max_iterations: 20,
            line_search: false,
            min_increment_fraction: 1.0,
            tolerated_residual,
            stall_iterations,
            ..Default::default()
        };
        let mut solver = Solver::new(top_pressure_panel(), settings).unwrap();
        let mut log: Vec<StepReport> = Vec::new();
        let result = solver.run(&mut scaled_tangent(0.4, &mut 0), &mut log);
        (result.map(|_| ()), log)
    };
    let (off, on) = (diverging(0, 10.0).1.remove(0), diverging(2, 10.0).1.remove(0));
    println!("off: {} iterations; on: {} iterations", off.iterations, on.iterations);
    assert_eq!(off.iterations, 21);
    assert_eq!(on.iterations, 3);
    assert!(on.tolerated && on.residuals.last() == Some(&on.residuals[0]), "{on:?}");
    // Tolerated below the best (0.43): no early end, the attempt fails after 20 iterations.
    match diverging(2, 0.1).0 {
        Err(Error::StepTooSmall { reason, .. }) => {
            assert!(reason.contains("20 iterations"), "{reason}");
        }
        other => panic!("{other:?}"),
    }

    let contracting = |stall_iterations: u32| {
        let settings = SolverSettings {
            steps: 2,
            force_tolerance: 1e-13,
            stall_iterations,
            ..Default::default()
        };
        let mut solver = Solver::new(panel(-0.04), settings).unwrap();
        solver.run(&mut SofteningElastic { elastic: elastic(), beta: 400.0 }, &mut ()).unwrap();
        solver.solution().dofs.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    };
    assert_eq!(contracting(0), contracting(1));
}
