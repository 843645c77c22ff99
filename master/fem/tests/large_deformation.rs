//! Large deformation end to end with the elastic law (tests 3 and 5 of
//! docs/notes/2026-12-05-updated-lagrangian.md): a patch rotated rigidly by 90 degrees in 10
//! steps gains no stress under the updated-Lagrangian option (and does under small strain:
//! the control), and a large simple shear matches the closed form of the objective
//! (Biot-type) elastic law.

use cosdem_fem::Result;
use cosdem_fem::assembly::{Component, Field, Kinematics};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{BiotCosserat, ElasticCosserat, Material};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{
    Loading, Model, SolutionView, Solver, SolverSettings, StepObserver, StepReport,
};

/// Calls a closure on every converged step.
struct Each<F>(F);

impl<F: FnMut(&StepReport, &SolutionView<'_>)> StepObserver for Each<F> {
    fn on_step(&mut self, report: &StepReport, state: &SolutionView<'_>) -> Result<()> {
        (self.0)(report, state);
        Ok(())
    }
}

const G: f64 = 2e7;

fn elastic() -> ElasticCosserat {
    ElasticCosserat::new(G, 0.25, 1e7, 0.05)
}

/// A 2 x 2 Q8 (or T6) patch of the unit square, its interior node moved off-centre so the
/// elements are not parallelograms.
fn patch(kind: ElementKind) -> Mesh {
    let mut mesh = Mesh::rectangle(kind, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
    for p in &mut mesh.nodes {
        if (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12 {
            *p = [0.56, 0.47];
        }
    }
    mesh
}

fn on_boundary(p: [f64; 2]) -> bool {
    p[0].abs() < 1e-12
        || p[1].abs() < 1e-12
        || (p[0] - 1.0).abs() < 1e-12
        || (p[1] - 1.0).abs() < 1e-12
}

/// Every boundary node prescribed at `u = (R(a) - I)(X - X0)` and `w = a` (the rigid rotation
/// by `a` about the patch centre).
fn rotation_loading(mesh: &Mesh, a: f64) -> Loading {
    let (c, s) = (a.cos(), a.sin());
    let mut loading = Loading::default();
    for (n, p) in mesh.nodes.iter().enumerate() {
        if on_boundary(*p) {
            let d = [p[0] - 0.5, p[1] - 0.5];
            let x = [c * d[0] - s * d[1], s * d[0] + c * d[1]];
            loading.nodal_dirichlet.push((n, Component::Ux, x[0] - d[0]));
            loading.nodal_dirichlet.push((n, Component::Uy, x[1] - d[1]));
            loading.nodal_dirichlet.push((n, Component::W, a));
        }
    }
    loading
}

fn settings() -> SolverSettings {
    SolverSettings {
        steps: 1,
        force_tolerance: 1e-12,
        displacement_tolerance: 1e-12,
        max_iterations: 30,
        ..Default::default()
    }
}

/// Rotates the patch by `k pi / 20` at stage `k` (one step each, 10 stages: 90 degrees) and
/// returns, per step, the largest |stress| over the Gauss points and the largest error of the
/// interior micro-rotation.
fn rotate(kinematics: Kinematics, material: &mut dyn Material) -> Vec<(f64, f64)> {
    let mesh = patch(ElementKind::Q8);
    let interior: Vec<usize> =
        (0..mesh.n_nodes()).filter(|&n| !on_boundary(mesh.nodes[n])).collect();
    let step_angle = std::f64::consts::PI / 20.0;
    let model = Model {
        loading: rotation_loading(&mesh, step_angle),
        mesh: mesh.clone(),
        field: Field::Cosserat,
        rule: QuadratureRule::Gauss2x2,
        kinematics,
    };
    let mut solver = Solver::new(model, settings()).unwrap();
    let mut out = Vec::new();
    for k in 1..=10 {
        if k > 1 {
            solver.begin_stage(rotation_loading(&mesh, k as f64 * step_angle), 1).unwrap();
        }
        let a = k as f64 * step_angle;
        let mut watch = Each(|_: &StepReport, v: &SolutionView<'_>| {
            let s =
                v.gauss_points.iter().flat_map(|g| g.stress).fold(0.0f64, |m, x| m.max(x.abs()));
            let w = v.rotations();
            let dw = interior.iter().map(|&n| (w[n] - a).abs()).fold(0.0f64, f64::max);
            out.push((s, dw));
        });
        solver.run(material, &mut watch).unwrap();
    }
    out
}

/// Test 3. Under the updated-Lagrangian option with the objective elastic law, a rigid
/// rotation in 10 steps to 90 degrees leaves every Gauss point without stress: |s| <= 1e-8 G
/// (the exact solution is representable and Newton converges to 1e-12 of the force scale,
/// which is the stress of the first iterates), and the interior micro-rotation equals the
/// rotation to 1e-10. Under small strain the same motion strains the patch: at 90 degrees
/// `e_xx = e_yy = cos(a) - 1 = -1`, `s_xx = -2 (lam + G)` (the control: the test can fail;
/// 1e-6 for Newton's tolerance).
#[test]
fn a_rigid_rotation_gains_no_stress() {
    let mut biot = BiotCosserat { elastic: elastic() };
    let ul = rotate(Kinematics::UpdatedLagrangian, &mut biot);
    assert_eq!(ul.len(), 10);
    for (k, (s, dw)) in ul.iter().enumerate() {
        println!("UL step {}: max |s| / G = {:.1e}, interior |w - a| = {:.1e}", k + 1, s / G, dw);
        assert!(*s <= 1e-8 * G, "step {}: |s| = {s:e}", k + 1);
        assert!(*dw <= 1e-10, "step {}: |w - a| = {dw:e}", k + 1);
    }
    // The control without the coupling modulus: then the small-strain answer is homogeneous
    // (no skew stress, w = a balances the moments) and exactly `s_xx = s_yy = -2 (lam + G)`.
    let e = ElasticCosserat { coupling: 0.0, ..elastic() };
    let mut small = e;
    let sm = rotate(Kinematics::Small, &mut small);
    let expected = 2.0 * (e.lambda + e.shear);
    println!("small strain at 90 degrees: max |s| / G = {:.4}", sm[9].0 / G);
    assert!((sm[9].0 - expected).abs() < 1e-6 * expected, "{} vs {expected}", sm[9].0);
}

/// The closed form of the Biot law in simple shear `F = [[1, g], [0, 1]]` with the polar
/// rotation `w = -atan(g / 2)`: `s = lam (r - 2) V + 2 G (B - V)`, `r = sqrt(4 + g^2)`.
fn simple_shear(g: f64, lam: f64, mu: f64) -> [f64; 4] {
    let r = (4.0 + g * g).sqrt();
    let v = [[(2.0 + g * g) / r, g / r], [g / r, 2.0 / r]];
    let b = [[1.0 + g * g, g], [g, 1.0]];
    let s = |i: usize, j: usize| lam * (r - 2.0) * v[i][j] + 2.0 * mu * (b[i][j] - v[i][j]);
    [s(0, 0), s(1, 1), s(0, 1), s(1, 0)]
}

/// Test 5. A 1 x 1 patch with every boundary node at `u_x = gamma y`, `u_y = 0` (w free in
/// the Cosserat field), gamma to 1 in 10 steps: at every step and Gauss point the stress
/// matches the closed form to 1e-9 relative (the field is homogeneous and the interpolation
/// exact; the error is Newton's tolerance) and, for the Cosserat field, `w = -atan(gamma/2)`
/// at every node to 1e-10. For Q8 and T6, Cosserat and Cauchy.
#[test]
fn a_large_simple_shear_matches_the_closed_form() {
    for kind in [ElementKind::Q8, ElementKind::T6] {
        for field in [Field::Cosserat, Field::Cauchy] {
            let mesh = patch(kind);
            let mut loading = Loading::default();
            for (n, p) in mesh.nodes.iter().enumerate() {
                if on_boundary(*p) {
                    loading.nodal_dirichlet.push((n, Component::Ux, p[1]));
                    loading.nodal_dirichlet.push((n, Component::Uy, 0.0));
                }
            }
            let rule = QuadratureRule::for_kind(kind, false);
            let model =
                Model { mesh, field, rule, loading, kinematics: Kinematics::UpdatedLagrangian };
            let settings = SolverSettings { steps: 10, ..settings() };
            let mut solver = Solver::new(model, settings).unwrap();
            let e = elastic();
            let mut biot = BiotCosserat { elastic: e };
            let mut steps = 0;
            let mut watch = Each(|r: &StepReport, v: &SolutionView<'_>| {
                let g = r.load_factor;
                let exact = simple_shear(g, e.lambda, e.shear);
                let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for p in v.gauss_points {
                    for k in 0..4 {
                        let err = (p.stress[k] - exact[k]).abs();
                        assert!(
                            err <= 1e-9 * scale,
                            "{kind:?} {field:?} gamma {g}: s[{k}] = {} vs {}",
                            p.stress[k],
                            exact[k]
                        );
                    }
                }
                if field == Field::Cosserat {
                    for w in v.rotations() {
                        assert!(
                            (w + (g / 2.0).atan()).abs() <= 1e-10,
                            "{kind:?} gamma {g}: w = {w}"
                        );
                    }
                }
                steps += 1;
            });
            solver.run(&mut biot, &mut watch).unwrap();
            assert_eq!(steps, 10);
        }
    }
}
