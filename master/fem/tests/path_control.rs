//! Path control (`solve/control.rs`) follows a snap-back: a bar pulled at its top, whose
//! bottom element softens while the rest unloads elastically. Under the top's displacement
//! the equilibrium path turns back (the top has to move down while the soft element goes on
//! stretching); controlled by the soft element's own elongation it does not, and every
//! step is checked against the closed form.
//!
//! The bar: 1 x 4 Q8 elements (0.1 x 1 m, Cauchy), `u_x = 0` everywhere (the side sets and
//! the ends), `u_y = 0` at the bottom and `u_y = lambda U` at the top. The material is
//! uniaxial and decoupled (every stress component its own strain's, a diagonal tangent): the
//! bottom element's `s_yy = E e exp(-e / e0)` (peak at `e = e0`, softening after), the
//! others' `s_yy = E_s e` with `E_s = E / 4`. The exact discrete solution has a uniform
//! strain in each element (Q8 holds a piecewise-linear `u_y` exactly): with the control
//! quantity `tau` = the mean `u_y` of the nodes at the top of the soft element,
//! `e_w = tau / h`, `s = f(e_w)` and the top's displacement `tau + (L - h) s / E_s`.

use cosdem_common::{MicroDiagnostics, MicroResponse};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{
    Dirichlet, Loading, Model, PathControl, SolutionView, Solver, SolverSettings, SolverState,
    StepControl, StepObserver, StepReport,
};

const E: f64 = 1e6;
const E0: f64 = 0.01;
const E_S: f64 = E / 4.0;
const L: f64 = 1.0;
const H: f64 = 0.25;
const WIDTH: f64 = 0.1;

/// The soft element's law and its slope.
fn soft(e: f64) -> (f64, f64) {
    let x = (-e / E0).exp();
    (E * e * x, E * (1.0 - e / E0) * x)
}

/// The uniaxial, decoupled bar material; `weak[element]` marks the soft element.
struct Bar {
    weak: Vec<bool>,
}

impl Material for Bar {
    fn evaluate(
        &mut self,
        _trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        Ok(inputs
            .iter()
            .map(|i| {
                let e = i.deformation.strain();
                let (s_yy, c_yy) = if self.weak[i.gauss_point.element as usize] {
                    soft(e[1])
                } else {
                    (E_S * e[1], E_S)
                };
                let moduli = [E_S, c_yy, 0.4 * E_S, 0.4 * E_S, 1.0, 1.0];
                let mut stress = [0.0; 6];
                let mut tangent = [[0.0; 6]; 6];
                for k in 0..6 {
                    stress[k] = moduli[k] * e[k];
                    tangent[k][k] = moduli[k];
                }
                stress[1] = s_yy;
                MicroResponse {
                    stress,
                    tangent,
                    diagnostics: MicroDiagnostics { converged: true, ..Default::default() },
                }
            })
            .collect())
    }
    fn commit(&mut self, _step: u64) -> Result<(), MaterialError> {
        Ok(())
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }
}

/// The bar's model: the top pulled to `top_uy`, controlled by `control` if any; a node set
/// `interface` holds the nodes at the top of the soft element.
fn bar(top_uy: f64, control: Option<f64>) -> (Model, Bar) {
    let mut mesh = Mesh::rectangle(ElementKind::Q8, WIDTH, L, 1, 4, [0.0, 0.0]).unwrap();
    let interface: Vec<usize> =
        (0..mesh.n_nodes()).filter(|&n| (mesh.nodes[n][1] - H).abs() < 1e-12).collect();
    assert_eq!(interface.len(), 3, "two corners and a mid-side node");
    mesh.node_sets.insert("interface".into(), interface);
    let weak: Vec<bool> = (0..mesh.n_elements())
        .map(|e| mesh.element_nodes(e).iter().all(|&n| mesh.nodes[n][1] <= H + 1e-12))
        .collect();
    assert_eq!(weak.iter().filter(|&&w| w).count(), 1);
    let mut dirichlet: Vec<Dirichlet> = ["left", "right", "bottom", "top"]
        .iter()
        .map(|s| Dirichlet::new(s, Component::Ux, 0.0))
        .collect();
    dirichlet.push(Dirichlet::new("bottom", Component::Uy, 0.0));
    dirichlet.push(Dirichlet::new("top", Component::Uy, top_uy));
    let control = control.map(|value| PathControl {
        plus: Vec::new(),
        set: "interface".into(),
        component: Component::Uy,
        value,
    });
    let loading = Loading { dirichlet, control, ..Default::default() };
    let model = Model {
        mesh,
        field: Field::Cauchy,
        rule: QuadratureRule::Gauss2x2,
        loading,
        kinematics: Default::default(),
    };
    (model, Bar { weak })
}

/// The controlled bar's settings: 24 steps, solved to a relative residual of 1e-12.
fn controlled_settings() -> SolverSettings {
    SolverSettings { steps: 24, force_tolerance: 1e-12, max_iterations: 30, ..Default::default() }
}

/// Runs a controlled bar with [`controlled_settings`].
fn run_controlled(model: Model, material: &mut Bar) -> (Solver, Vec<StepReport>) {
    let mut solver = Solver::new(model, controlled_settings()).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    solver.run(material, &mut log).unwrap();
    (solver, log)
}

/// The closed form at control value `tau`: the stress and the top's displacement.
fn closed_form(tau: f64) -> (f64, f64) {
    let (s, _) = soft(tau / H);
    (s, tau + (L - H) * s / E_S)
}

/// Controlled by the soft element's elongation to 5 e0 (past the peak at e0 and the turn of
/// the path at about 1.3 e0) in 24 steps (no step lands on the peak itself, where the soft
/// element's tangent is zero and its inner nodes' stiffness singular), every step meets the
/// closed form: the stress to 1e-9 of the peak stress and the top's displacement to 1e-12 m
/// (the equations are solved to a relative residual of 1e-12, and the constraint, linear,
/// is met to round-off), and the top's displacement rises and then falls (the path the
/// top's own displacement cannot follow).
#[test]
fn the_controlled_path_follows_the_snap_back_of_a_softening_bar() {
    let u_top = 0.02; // the top's displacement at lambda = 1 (the path never reaches it)
    let tau_end = 5.0 * E0 * H;
    let (model, mut material) = bar(u_top, Some(tau_end));
    let (solver, log) = run_controlled(model, &mut material);
    assert_eq!(log.len(), 24, "no cuts expected on the smooth law");
    let peak = E * E0 / std::f64::consts::E;
    let mut tops = Vec::new();
    for (k, step) in log.iter().enumerate() {
        let tau = tau_end * (k + 1) as f64 / 24.0;
        let (s, top) = closed_form(tau);
        let reaction = step.reactions["top"][1] / WIDTH;
        let top_fe = step.load_factor * u_top;
        assert!((reaction - s).abs() <= 1e-9 * peak, "step {}: {reaction} vs {s}", step.step);
        assert!((top_fe - top).abs() <= 1e-12, "step {}: {top_fe} vs {top}", step.step);
        tops.push(top_fe);
    }
    // The top's displacement peaks inside the path and falls by more than a tenth after it
    // (the closed form: 0.01387 m at e_w = 1.25 e0 down to 0.01190 m at 3.3 e0, then up
    // again as the soft element's stress tends to zero).
    let (turn, max) =
        tops.iter().enumerate().fold((0, f64::MIN), |a, (k, &t)| if t > a.1 { (k, t) } else { a });
    let after = tops[turn..].iter().copied().fold(f64::MAX, f64::min);
    assert!(turn > 0 && turn < 23, "the top's displacement peaks inside the path: {tops:?}");
    assert!(after < 0.9 * max, "the path turns back: {tops:?}");
    assert_eq!(solver.load_factor() * u_top, tops[23]);
}

/// A combined control quantity (`plus`): the soft element's top plus the bar's top, whose
/// sum grows all along the path (its slope in the soft strain, `2 h + (L - h) f'(e) / E_s`,
/// stays above 0.09 m). Every step meets the constraint (the sum at its target to 1e-12 m)
/// and the equilibrium of the closed form (the soft element's strain from the top and the
/// stress, and its law, agree to 1e-9 of the peak stress), through the turn of the top.
#[test]
fn a_combined_control_quantity_follows_the_snap_back_too() {
    use cosdem_fem::solve::ControlTerm;
    let u_top = 0.02;
    let tau_end = 5.0 * E0 * H + closed_form(5.0 * E0 * H).1;
    let (mut model, mut material) = bar(u_top, Some(tau_end));
    let control = model.loading.control.as_mut().unwrap();
    control.plus = vec![ControlTerm { set: "top".into(), component: Component::Uy, weight: 1.0 }];
    let (_, log) = run_controlled(model, &mut material);
    let peak = E * E0 / std::f64::consts::E;
    let mut tops = Vec::new();
    for (k, step) in log.iter().enumerate() {
        let tau = tau_end * step.time;
        let top = step.load_factor * u_top;
        let s = step.reactions["top"][1] / WIDTH;
        let e_w = (top - (L - H) * s / E_S) / H;
        assert!((H * e_w + top - tau).abs() <= 1e-12, "step {}: constraint", k + 1);
        assert!((soft(e_w).0 - s).abs() <= 1e-9 * peak, "step {}: {s} vs {}", k + 1, soft(e_w).0);
        tops.push(top);
    }
    assert!(tops.windows(2).any(|w| w[1] < w[0]), "the top turns back: {tops:?}");
}

/// Stops a run after a given step, keeping the solver's state there (what a checkpoint
/// saves; the bar's material has no state of its own).
struct StopAfter {
    step: u64,
    saved: Option<SolverState>,
}

impl StepObserver for StopAfter {
    fn on_step(&mut self, _: &StepReport, _: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        Ok(())
    }
    fn after_step(
        &mut self,
        solver: &Solver,
        _: &mut dyn Material,
    ) -> cosdem_fem::Result<StepControl> {
        if solver.step() < self.step {
            return Ok(StepControl::Continue);
        }
        self.saved = Some(solver.state());
        Ok(StepControl::Stop)
    }
}

/// A controlled run stopped after step 10 (past the peak, before the turn's end) and
/// restored into a new solver goes on bit for bit as the uninterrupted run: the same load
/// factors and dofs at every step to the end (the control's progress is part of the state).
#[test]
fn a_controlled_run_resumes_bit_for_bit() {
    let tau_end = 5.0 * E0 * H;
    let settings = controlled_settings();
    let (model, mut material) = bar(0.02, Some(tau_end));
    let (whole, whole_log) = run_controlled(model.clone(), &mut material);

    let mut first = Solver::new(model.clone(), settings.clone()).unwrap();
    let mut stop = StopAfter { step: 10, saved: None };
    let err = first.run(&mut material, &mut stop).unwrap_err();
    assert!(err.to_string().contains("10"), "{err}");
    let saved = stop.saved.expect("the state after step 10");
    assert!(saved.progress > 0.4 && saved.progress < 0.42, "{}", saved.progress);

    let mut resumed = Solver::new(model, settings).unwrap();
    resumed.restore(saved).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    resumed.run(&mut material, &mut log).unwrap();
    assert_eq!(log.len(), 14);
    for (a, b) in log.iter().zip(&whole_log[10..]) {
        assert_eq!(a.load_factor.to_bits(), b.load_factor.to_bits(), "step {}", a.step);
        assert_eq!(a.time.to_bits(), b.time.to_bits(), "step {}", a.step);
    }
    let bits = |s: &Solver| s.solution().dofs.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&resumed), bits(&whole));
}

/// The same bar pulled by the top's displacement past the turn of the path: there is no
/// equilibrium near the last one once the top passes the turn, and Newton lands on the far
/// branch, where the soft element has stretched far past its peak: the stress drops by more
/// than half the peak stress in one step (on the controlled path it falls by at most 8 % of
/// the peak per step at this step size: the steepest softening slope, 0.135 E at 2 e0, times
/// the step's 0.21 e0). The path between is lost: what the path control
/// follows.
#[test]
fn displacement_control_jumps_over_the_snap_back() {
    let turn_top =
        (0..1000).map(|k| closed_form(5.0 * E0 * H * k as f64 / 1000.0).1).fold(f64::MIN, f64::max);
    let u_top = 1.5 * turn_top; // past the turn
    let (model, mut material) = bar(u_top, None);
    let settings = SolverSettings { steps: 24, force_tolerance: 1e-12, ..Default::default() };
    let mut solver = Solver::new(model, settings).unwrap();
    let mut log: Vec<StepReport> = Vec::new();
    solver.run(&mut material, &mut log).unwrap();
    let stresses: Vec<f64> = log.iter().map(|s| s.reactions["top"][1] / WIDTH).collect();
    let drop = stresses.windows(2).map(|w| w[0] - w[1]).fold(0.0, f64::max);
    let peak = E * E0 / std::f64::consts::E;
    assert!(drop > 0.5 * peak, "{stresses:?}");
}

/// Bad path controls are refused, naming the field and the value.
#[test]
fn a_bad_path_control_is_refused_by_name() {
    for (value, set, expect) in [
        (0.0, "interface", "control.value"),
        (f64::NAN, "interface", "control.value"),
        (0.01, "nowhere", "nowhere"),
    ] {
        let (mut model, _) = bar(0.01, Some(value));
        model.loading.control.as_mut().unwrap().set = set.into();
        let err = Solver::new(model, SolverSettings::default()).err().expect("refused");
        assert!(err.to_string().contains(expect), "{err}");
    }
}
