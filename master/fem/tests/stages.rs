//! Loading in stages ([`Solver::begin_stage`]): unloading by a negative increment, a support
//! released, a load ramped down, a body force, and a resume in the middle of a later stage.
//!
//! The material is linear elastic, so every check has a closed form: a path that returns to
//! the start returns the body to zero displacement and zero reaction, and a stage's state
//! depends only on its end targets, not on the way there. The tolerances are those of the
//! linear solve (about 1e-12 of the largest value; 1e-9 leaves room for the Newton stop,
//! which for a linear material is reached after the first, exact, correction).

mod common;

use common::panel::{elastic, panel, top_pressure_panel};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{
    BodyLoad, Dirichlet, Loading, Model, Platens, Ramp, Solver, SolverSettings, StepReport,
};

fn settings(steps: usize) -> SolverSettings {
    SolverSettings { steps, ..Default::default() }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// The top's reaction `R_y` after the last step.
fn top_load(solver: &Solver) -> f64 {
    solver.reactions()["top"][1]
}

/// The compression panel's loading with every dof it prescribes held where it is, except the
/// top's `u_y`, moved by `du`.
fn moved_top(du: f64) -> Loading {
    let mut l = Loading::compression(0.0, 0.0, Platens::Rough);
    for d in &mut l.dirichlet {
        d.relative = true;
        if d.set == "top" && d.component == Component::Uy {
            d.value = du;
        }
    }
    l
}

/// A compression to 1 mm and back by a negative increment ends where it started: zero
/// displacement and zero load; half way back the load is half the peak (linearity).
#[test]
fn unloading_by_a_negative_increment_returns_to_the_start() {
    let mut solver = Solver::new(panel(-1e-3), settings(2)).unwrap();
    let mut mat = elastic();
    let mut log: Vec<StepReport> = Vec::new();
    solver.run(&mut mat, &mut log).unwrap();
    let peak = top_load(&solver);
    assert!(peak.abs() > 1e3, "the compression loads the top: {peak}");
    solver.begin_stage(moved_top(1e-3), 2).unwrap();
    solver.run(&mut mat, &mut log).unwrap();
    assert_eq!(solver.stage(), 1);
    let half = &log[2];
    assert_eq!((half.stage, half.load_factor, half.time), (1, 0.5, 1.5));
    assert!((half.reactions["top"][1] - 0.5 * peak).abs() < 1e-9 * peak.abs(), "{half:?}");
    let u = solver.state().u;
    assert!(max_abs(&u) < 1e-9 * 1e-3, "back at zero: {}", max_abs(&u));
    assert!(top_load(&solver).abs() < 1e-9 * peak.abs(), "{}", top_load(&solver));
    // The pseudo-time increases over the whole run.
    assert!(log.windows(2).all(|w| w[1].time > w[0].time), "{log:?}");
}

/// A support released in the next stage (the top no longer prescribed) lets the elastic
/// panel spring back to zero: the dof numbering is rebuilt with the top's u_y free.
#[test]
fn a_released_support_lets_the_body_spring_back() {
    let mut solver = Solver::new(panel(-1e-3), settings(1)).unwrap();
    let mut mat = elastic();
    solver.run(&mut mat, &mut ()).unwrap();
    let free_before = solver.dofs().n_free;
    let mut released = moved_top(0.0);
    released.dirichlet.retain(|d| d.set == "bottom");
    solver.begin_stage(released, 1).unwrap();
    assert!(solver.dofs().n_free > free_before, "the top's dofs are free now");
    solver.run(&mut mat, &mut ()).unwrap();
    let u = solver.state().u;
    assert!(max_abs(&u) < 1e-9 * 1e-3, "sprung back: {}", max_abs(&u));
}

/// A pressure held (constant) keeps the state; ramped down it is removed and the panel comes
/// back to zero displacement.
#[test]
fn a_pressure_held_keeps_the_state_and_ramped_down_removes_it() {
    let model = top_pressure_panel();
    let loading = model.loading.clone();
    let mut solver = Solver::new(model, settings(2)).unwrap();
    let mut mat = elastic();
    solver.run(&mut mat, &mut ()).unwrap();
    let loaded = solver.state().u;
    assert!(max_abs(&loaded) > 0.0);
    let with = |ramp: Ramp| {
        let mut l = loading.clone();
        l.edge_loads[0].ramp = ramp;
        for d in &mut l.dirichlet {
            d.relative = true;
        }
        l
    };
    solver.begin_stage(with(Ramp::Constant), 1).unwrap();
    solver.run(&mut mat, &mut ()).unwrap();
    let held = solver.state().u;
    let diff: Vec<f64> = held.iter().zip(&loaded).map(|(a, b)| a - b).collect();
    assert!(max_abs(&diff) < 1e-9 * max_abs(&loaded), "held: {}", max_abs(&diff));
    solver.begin_stage(with(Ramp::Down), 2).unwrap();
    solver.run(&mut mat, &mut ()).unwrap();
    let u = solver.state().u;
    assert!(max_abs(&u) < 1e-9 * max_abs(&loaded), "removed: {}", max_abs(&u));
}

/// Two stages to 0.5 mm then to 1 mm (absolute targets) reach the state of one stage to
/// 1 mm: an elastic state depends on the end targets only.
#[test]
fn a_stage_to_an_absolute_target_reaches_the_one_stage_state() {
    let mut one = Solver::new(panel(-1e-3), settings(1)).unwrap();
    one.run(&mut elastic(), &mut ()).unwrap();
    let mut two = Solver::new(panel(-5e-4), settings(1)).unwrap();
    let mut mat = elastic();
    two.run(&mut mat, &mut ()).unwrap();
    two.begin_stage(Loading::compression(-1e-3, 0.0, Platens::Rough), 1).unwrap();
    two.run(&mut mat, &mut ()).unwrap();
    let (a, b) = (one.state().u, two.state().u);
    let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    assert!(max_abs(&diff) < 1e-9 * max_abs(&a), "{}", max_abs(&diff));
}

/// A stage cannot start before the one before it is finished.
#[test]
fn a_stage_starts_only_after_the_last_step_of_the_one_before() {
    let mut solver = Solver::new(panel(-1e-3), settings(2)).unwrap();
    let err = solver.begin_stage(moved_top(0.0), 1).unwrap_err().to_string();
    assert!(err.contains("stage 0 is not finished"), "{err}");
}

/// Self-weight of an elastic column of height H between smooth walls (u_x = 0 on the sides,
/// u_y = 0 at the bottom) under a unit weight gamma: sigma_yy = gamma (y - H) and
/// u_y(y) = gamma / M (y^2 / 2 - H y), M = lambda + 2 G the constrained modulus; the top
/// settles by gamma H^2 / (2 M). The displacement is quadratic in y, which Q8 elements
/// represent exactly (and 2x2 Gauss points integrate exactly for it), so the match is to
/// round-off.
#[test]
fn self_weight_settles_a_column_as_the_closed_form() {
    let (h, gamma) = (2.0, 2.0e4);
    let mesh = Mesh::rectangle(ElementKind::Q8, 0.5, h, 1, 4, [0.0, 0.0]).unwrap();
    let loading = Loading {
        dirichlet: vec![
            Dirichlet::new("bottom", Component::Uy, 0.0),
            Dirichlet::new("left", Component::Ux, 0.0),
            Dirichlet::new("right", Component::Ux, 0.0),
        ],
        body: Some(BodyLoad::new(move |_, _| [0.0, -gamma, 0.0])),
        body_ramp: Ramp::Linear,
        ..Default::default()
    };
    let model = Model {
        mesh,
        field: Field::Cosserat,
        rule: QuadratureRule::Gauss2x2,
        loading,
        kinematics: Default::default(),
    };
    let mut solver = Solver::new(model, settings(1)).unwrap();
    let mat = elastic();
    solver.run(&mut mat.clone(), &mut ()).unwrap();
    let m = mat.lambda + 2.0 * mat.shear;
    let view = solver.solution();
    let u = view.displacements();
    for (node, x) in solver.model().mesh.nodes.iter().enumerate() {
        let y = x[1];
        let exact = gamma / m * (0.5 * y * y - h * y);
        let settle = gamma * h * h / (2.0 * m);
        assert!((u[node][1] - exact).abs() < 1e-9 * settle, "node {node} at y = {y}");
        assert!(u[node][0].abs() < 1e-9 * settle, "node {node}: u_x {}", u[node][0]);
    }
    // The bottom carries the column's weight, gamma H per metre of width times 0.5 m.
    let r = solver.reactions()["bottom"][1];
    assert!((r - gamma * h * 0.5).abs() < 1e-9 * gamma * h, "{r}");
}

/// A resume in the middle of the second stage (state saved, a new solver restored and given
/// the stage's loading) goes on bit-identically.
#[test]
fn a_resume_in_a_later_stage_is_bit_identical() {
    let run = |stop_after: Option<usize>| {
        let mut solver = Solver::new(panel(-1e-3), settings(2)).unwrap();
        let mut mat = elastic();
        solver.run(&mut mat, &mut ()).unwrap();
        solver.begin_stage(moved_top(4e-4), 4).unwrap();
        let Some(k) = stop_after else {
            solver.run(&mut mat, &mut ()).unwrap();
            return solver.state();
        };
        // Stop after k steps of the stage: an observer that interrupts.
        struct StopAt(usize);
        impl cosdem_fem::solve::StepObserver for StopAt {
            fn on_step(
                &mut self,
                _: &StepReport,
                _: &cosdem_fem::solve::SolutionView<'_>,
            ) -> cosdem_fem::Result<()> {
                Ok(())
            }
            fn after_step(
                &mut self,
                _: &Solver,
                _: &mut dyn cosdem_fem::material::Material,
            ) -> cosdem_fem::Result<cosdem_fem::solve::StepControl> {
                self.0 -= 1;
                Ok(if self.0 == 0 {
                    cosdem_fem::solve::StepControl::Stop
                } else {
                    cosdem_fem::solve::StepControl::Continue
                })
            }
        }
        assert!(solver.run(&mut mat, &mut StopAt(k)).is_err(), "interrupted");
        let saved = solver.state();
        let mut again = Solver::new(panel(-1e-3), settings(2)).unwrap();
        again.restore(saved).unwrap();
        again.resume_stage(moved_top(4e-4), 4).unwrap();
        again.run(&mut mat, &mut ()).unwrap();
        again.state()
    };
    let whole = run(None);
    let resumed = run(Some(2));
    assert_eq!(whole.stage, 1);
    assert_eq!(
        whole.u.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        resumed.u.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    assert_eq!(whole, resumed);
}
