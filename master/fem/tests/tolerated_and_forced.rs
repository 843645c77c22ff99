//! Tolerated and forced steps: an attempt that runs out of iterations accepts its best iterate
//! within `tolerated_residual`, and the attempt at the smallest increment within
//! `forced_residual`, instead of cutting the step or ending the run.

mod common;

use common::panel::{
    elastic, one_iteration_per_attempt, panel, scaled_tangent, sci, top_pressure_panel,
};
use cosdem_fem::Error;
use cosdem_fem::material::SofteningElastic;
use cosdem_fem::solve::{Solver, SolverSettings, StepReport};

/// `tolerated_residual`: with one iteration allowed and a force tolerance no Newton step on
/// the softening law reaches (1e-14), every attempt runs out of iterations. With the
/// tolerated residual off the run ends in `StepTooSmall`; with it at 1 (any finite residual)
/// every step is accepted at once, flagged `tolerated`, with its last residual above the
/// force tolerance and below the tolerated one; and the accepted state is the last iterate,
/// so the run reaches the full load.
#[test]
fn tolerated_residual_accepts_steps_that_ran_out_of_iterations() {
    let strict = one_iteration_per_attempt();
    let mut mat = SofteningElastic { elastic: elastic(), beta: 400.0 };
    let mut log: Vec<StepReport> = Vec::new();
    let mut solver = Solver::new(panel(-0.04), strict.clone()).unwrap();
    let err = solver.run(&mut mat, &mut log).unwrap_err();
    assert!(matches!(err, Error::StepTooSmall { .. }), "{err}");

    let tolerant = SolverSettings { tolerated_residual: 1.0, ..strict };
    let mut log: Vec<StepReport> = Vec::new();
    let mut solver = Solver::new(panel(-0.04), tolerant).unwrap();
    solver.run(&mut mat, &mut log).unwrap();
    assert_eq!(log.len(), 2);
    for s in &log {
        let last = *s.residuals.last().unwrap();
        assert!(s.tolerated && s.cuts == 0 && last > 1e-14 && last <= 1.0, "{s:?}");
    }
    assert!((solver.load_factor() - 1.0).abs() < 1e-12);
}

/// A tolerated step accepts the best iterate of the attempt, not the last. Without line
/// search, a tangent of 0.4 times the elastic one makes every full update overshoot 2.5
/// times: the error goes x -> -1.5 x per iteration and the iterates grow worse (printed
/// residuals). With two iterations allowed and `tolerated_residual` between the first
/// iterate's residual and the others', the step is tolerated at the first iterate (the
/// predictor, 2.5 times the exact elastic displacement: a linear problem, so up to
/// rounding, 1e-9), evaluated again, with the first iterate's residual as its last (the
/// material answers from its committed state: the same answer, to the last bit).
#[test]
fn a_tolerated_step_accepts_its_best_iterate() {
    let residuals_of = |tolerated_residual: f64| {
        let settings = SolverSettings {
            steps: 1,
            max_iterations: 2,
            line_search: false,
            min_increment_fraction: 1.0,
            tolerated_residual,
            ..Default::default()
        };
        let mut solver = Solver::new(top_pressure_panel(), settings).unwrap();
        let mut log: Vec<StepReport> = Vec::new();
        let result = solver.run(&mut scaled_tangent(0.4, &mut 0), &mut log);
        (result.map(|_| ()), log, solver.solution().dofs.to_vec())
    };
    // Off: the attempt fails; its residuals are in the error.
    let (failed, _, _) = residuals_of(0.0);
    println!("{}", failed.as_ref().unwrap_err());
    assert!(matches!(failed, Err(Error::StepTooSmall { .. })));
    // Probe the residuals with everything tolerated (the best is accepted, whichever).
    let (_, log, _) = residuals_of(10.0);
    let r = log[0].residuals.clone();
    println!("residuals {:?}", sci(&r));
    assert!(r.len() == 4 && r[0] < r[1].min(r[2]), "{r:?}");
    assert_eq!(r[3].to_bits(), r[0].to_bits(), "the re-evaluated best iterate");
    // Tolerated between the first and the last: the first iterate is accepted.
    let (ok, log, u) = residuals_of(0.5 * (r[0] + r[1].min(r[2])));
    ok.unwrap();
    assert!(log[0].tolerated && log[0].residuals.last() == Some(&r[0]), "{:?}", log[0]);
    let mut exact = Solver::new(
        top_pressure_panel(),
        SolverSettings { steps: 1, force_tolerance: 1e-12, ..Default::default() },
    )
    .unwrap();
    exact.run(&mut elastic(), &mut ()).unwrap();
    let v = exact.solution().dofs;
    let size = v.iter().fold(0.0f64, |m, b| m.max(b.abs()));
    for (a, b) in u.iter().zip(v) {
        assert!((a - 2.5 * b).abs() <= 1e-9 * size, "{a} vs 2.5 x {b}");
    }
}

/// `forced_residual`: only the attempt at the smallest increment (one more halving would end
/// the run) accepts its best iterate above `tolerated_residual`, up to the forced residual,
/// as a forced step. The diverging iteration of [`a_tolerated_step_accepts_its_best_iterate`]
/// (a linear problem: from the unloaded state every increment gives the same relative
/// residuals, the first iterate's the best) with the tolerated residual below every
/// iterate's: without the forced residual, or with one below the best iterate's, the run
/// ends; with one between the best and the others, the full step and the half step are cut
/// as before, and the quarter step (the smallest) is forced at its first iterate; the run
/// then goes on to its end. Where the tolerated residual already accepts, a forced residual
/// changes nothing, bit for bit.
#[test]
fn the_smallest_increment_is_forced_through_up_to_the_forced_residual() {
    let run = |tolerated_residual: f64, forced_residual: f64| {
        let settings = SolverSettings {
            steps: 1,
            max_iterations: 2,
            line_search: false,
            min_increment_fraction: 0.25,
            tolerated_residual,
            forced_residual,
            ..Default::default()
        };
        let mut solver = Solver::new(top_pressure_panel(), settings).unwrap();
        let mut log: Vec<StepReport> = Vec::new();
        let result = solver.run(&mut scaled_tangent(0.4, &mut 0), &mut log);
        (result.map(|_| ()), log, solver.solution().dofs.to_vec())
    };
    // Probe: everything tolerated, the best iterate is the first.
    let (_, log, u_tolerated) = run(10.0, 0.0);
    let r = log[0].residuals.clone();
    assert!(r.len() == 4 && r[0] < r[1].min(r[2]), "{r:?}");
    assert!(log.iter().all(|s| s.tolerated && !s.forced && s.cuts == 0), "{log:?}");
    let tolerated = 0.5 * r[0];
    let forced = 0.5 * (r[0] + r[1].min(r[2]));
    for off in [0.0, 0.9 * r[0]] {
        let (ended, log, _) = run(tolerated, off);
        assert!(matches!(ended, Err(Error::StepTooSmall { .. })), "forced {off}: {ended:?}");
        assert!(log.is_empty());
    }
    let (ok, log, _) = run(tolerated, forced);
    ok.unwrap();
    let steps: Vec<_> = log.iter().map(|s| (s.increment, s.cuts, s.forced)).collect();
    println!("(increment, cuts, forced): {steps:?}");
    let first = &log[0];
    assert!(first.tolerated && first.forced && first.increment == 0.25, "{first:?}");
    assert_eq!(first.cuts, 2, "the full step and the half step were cut");
    // Its first iterate, as at the full step (a linear problem: the same relative residual
    // at a quarter of the load, up to rounding).
    let last = *first.residuals.last().unwrap();
    assert!((last - r[0]).abs() <= 1e-12 * r[0], "{last} vs {}", r[0]);
    // The steps after it start loaded, so their residuals relative to the larger forces are
    // smaller: tolerated at larger increments, none forced.
    assert!(log[1..].iter().all(|s| s.tolerated && !s.forced), "{log:?}");
    assert!((log.iter().map(|s| s.increment).sum::<f64>() - 1.0).abs() < 1e-12);
    // A forced residual changes nothing where the tolerated one already accepts.
    let (_, log_both, u_both) = run(10.0, 20.0);
    assert!(log_both.iter().all(|s| !s.forced));
    assert_eq!(
        u_both.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        u_tolerated.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
}
