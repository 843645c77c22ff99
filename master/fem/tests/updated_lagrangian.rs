//! The updated-Lagrangian assembler: its tangent is the derivative of its internal force
//! (test 1 of docs/notes/2026-12-05-updated-lagrangian.md), for the Cosserat and the Cauchy
//! field, on curved Q8, Q9 and T6 patches at large displacement gradients and rotations,
//! with an objective law whose stress is not symmetric (so that every geometric term is
//! exercised).
//!
//! The law is given by its stress only; its convected tangent (what a material reports under
//! the option) is formed here by central differences of the law along `F' = (I + h E) F` minus
//! the stress's transport `E s - tr(E) s + s E^T`. That is well defined only for an objective
//! law, which this one is (it depends on `R(w)^T F` and the reference curvature only).

use cosdem_common::{MacroDeformation, MicroDiagnostics, MicroResponse};
use cosdem_fem::assembly::{CosseratOperator, DofMap, Field, GaussData, Kinematics, Pattern};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_fem::mesh::Mesh;

type M2 = [[f64; 2]; 2];

fn mul(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

fn transpose(a: &M2) -> M2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}

fn rot(a: f64) -> M2 {
    [[a.cos(), -a.sin()], [a.sin(), a.cos()]]
}

/// An objective, nonlinear Cosserat law with a skew stress in the micro-rotated frame:
/// `U = R(w)^T F`, `E = U - I`, `tau = C0 e + beta tr(E)^2 Z` (Voigt as the code's strain),
/// `s = F tau R^T / det F`, `m = F (b K + c |K|^2 K) / det F`.
fn law(d: &MacroDeformation) -> [f64; 6] {
    let (lam, g, gc, beta) = (1.3e6, 1.0e6, 4.0e5, 7.0e5);
    let (b, c) = (2.0e4, 3.0e5);
    let r = rot(d.w);
    let u = mul(&transpose(&r), &d.f);
    let e = [[u[0][0] - 1.0, u[0][1]], [u[1][0], u[1][1] - 1.0]];
    let tr = e[0][0] + e[1][1];
    // tau[i][j]: s_xy = tau[0][1] is conjugate to the strain (y, x) entry e[1][0]
    let tau = [
        [
            (lam + 2.0 * g) * e[0][0] + lam * e[1][1],
            (g + gc) * e[1][0] + (g - gc) * e[0][1] - beta * tr * tr,
        ],
        [
            (g - gc) * e[1][0] + (g + gc) * e[0][1] + beta * tr * tr,
            lam * e[0][0] + (lam + 2.0 * g) * e[1][1],
        ],
    ];
    let j = d.det();
    let s = mul(&mul(&d.f, &tau), &transpose(&r));
    let k = d.kappa;
    let kk = k[0] * k[0] + k[1] * k[1];
    let mm = [b * k[0] + c * kk * k[0], b * k[1] + c * kk * k[1]];
    let m = [d.f[0][0] * mm[0] + d.f[0][1] * mm[1], d.f[1][0] * mm[0] + d.f[1][1] * mm[1]];
    [s[0][0] / j, s[1][1] / j, s[0][1] / j, s[1][0] / j, m[0] / j, m[1] / j]
}

/// The convected tangent of [`law`] by central differences (h = 1e-6: truncation h^2 and
/// cancellation 1e-16 / h both ~1e-10 of the entries).
fn convected_tangent(d: &MacroDeformation) -> [[f64; 6]; 6] {
    let s0 = law(d);
    let sm: M2 = [[s0[0], s0[2]], [s0[3], s0[1]]];
    let m0 = [s0[4], s0[5]];
    let h = 1e-6;
    let mut c = [[0.0; 6]; 6];
    // strain columns XX, YY, XY (the (y, x) entry of g), YX (the (x, y) entry)
    for (col, (i, j)) in [(0, 0), (1, 1), (1, 0), (0, 1)].into_iter().enumerate() {
        let mut e = [[0.0; 2]; 2];
        e[i][j] = 1.0;
        let at = |t: f64| {
            let ge = [[1.0 + t * e[0][0], t * e[0][1]], [t * e[1][0], 1.0 + t * e[1][1]]];
            law(&MacroDeformation { f: mul(&ge, &d.f), ..*d })
        };
        let (p, q) = (at(h), at(-h));
        let tr = e[0][0] + e[1][1];
        let es = mul(&e, &sm);
        let se = mul(&sm, &transpose(&e));
        let t = [
            es[0][0] - tr * sm[0][0] + se[0][0],
            es[1][1] - tr * sm[1][1] + se[1][1],
            es[0][1] - tr * sm[0][1] + se[0][1],
            es[1][0] - tr * sm[1][0] + se[1][0],
            e[0][0] * m0[0] + e[0][1] * m0[1] - tr * m0[0],
            e[1][0] * m0[0] + e[1][1] * m0[1] - tr * m0[1],
        ];
        for row in 0..6 {
            c[row][col] = (p[row] - q[row]) / (2.0 * h) - t[row];
        }
    }
    // curvature columns: grad_x(dw) = unit vector, the reference curvature changes by F^T of it
    for (col, k) in [(4, 0), (5, 1)] {
        let at = |t: f64| {
            let mut kappa = d.kappa;
            kappa[0] += t * d.f[k][0];
            kappa[1] += t * d.f[k][1];
            law(&MacroDeformation { kappa, ..*d })
        };
        let (p, q) = (at(h), at(-h));
        for row in 0..6 {
            c[row][col] = (p[row] - q[row]) / (2.0 * h);
        }
    }
    c
}

struct Objective;

impl Material for Objective {
    fn evaluate(
        &mut self,
        _: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        Ok(inputs
            .iter()
            .map(|i| MicroResponse {
                stress: law(&i.deformation),
                tangent: convected_tangent(&i.deformation),
                diagnostics: MicroDiagnostics { converged: true, ..Default::default() },
            })
            .collect())
    }
    fn commit(&mut self, _: u64) -> Result<(), MaterialError> {
        Ok(())
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }
}

fn setup(kind: ElementKind, field: Field) -> (Mesh, DofMap, GaussData, Pattern) {
    let mut mesh = Mesh::rectangle(kind, 1.0, 0.7, 2, 1, [0.3, -0.2]).unwrap();
    for p in &mut mesh.nodes {
        *p = [p[0] + 0.05 * (3.0 * p[1]).sin(), p[1] + 0.04 * (2.0 * p[0]).cos()];
    }
    let dofs = DofMap::new(field, mesh.n_nodes(), &vec![false; mesh.n_nodes() * field.ndf()]);
    let gauss = GaussData::new(&mesh, QuadratureRule::for_kind(kind, true)).unwrap();
    let pattern = Pattern::new(&mesh, &dofs);
    (mesh, dofs, gauss, pattern)
}

/// A large displacement: a rotation by 0.5 rad, a stretch and a smooth shear (|grad u| up to
/// ~0.5), micro-rotations near 0.5 rad plus a gradient (curvature).
fn large_dofs(mesh: &Mesh, field: Field) -> Vec<f64> {
    let r = rot(0.5);
    let mut u = Vec::new();
    for (n, p) in mesh.nodes.iter().enumerate() {
        let y = [1.1 * p[0] + 0.2 * p[1] * p[1], 0.9 * p[1] + 0.1 * (2.0 * p[0]).sin()];
        let x = [r[0][0] * y[0] + r[0][1] * y[1], r[1][0] * y[0] + r[1][1] * y[1]];
        u.push(x[0] - p[0]);
        u.push(x[1] - p[1]);
        if field == Field::Cosserat {
            u.push(0.45 + 0.1 * p[0] - 0.2 * p[1] + 0.01 * (n % 3) as f64);
        }
    }
    u
}

/// Entry (i, j) of the free-dof CSC matrix.
fn entry(pattern: &Pattern, values: &[f64], i: usize, j: usize) -> f64 {
    match pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]].binary_search(&i) {
        Ok(p) => values[pattern.col_ptr[j] + p],
        Err(_) => 0.0,
    }
}

/// Under the updated-Lagrangian option the assembled tangent (material part on the current
/// configuration plus the geometric stiffness) is the derivative of the internal force:
/// central differences (h = 1e-7 on dofs ~0.5) match every entry of every column to 1e-6 of
/// the largest entry (truncation ~h^2, cancellation ~1e-16 |f| / h, and the tangent's own
/// difference error ~1e-10). The largest mismatch is printed; without the geometric stiffness
/// it is of the order of the stress over the modulus, ~1e-1 here (checked by hand).
#[test]
fn updated_lagrangian_tangent_is_the_derivative_of_the_internal_force() {
    for field in [Field::Cosserat, Field::Cauchy] {
        for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
            let (mesh, dofs, gauss, pattern) = setup(kind, field);
            let op = CosseratOperator { field, kinematics: Kinematics::UpdatedLagrangian };
            let u = large_dofs(&mesh, field);
            let mut mat = Objective;
            let trial = TrialId { step: 1, iteration: 0 };
            let f = |u: &[f64], mat: &mut Objective| {
                let r = mat.evaluate(trial, &op.kinematics(&mesh, &gauss, u)).unwrap();
                op.assemble(&mesh, &dofs, &gauss, &pattern, u, &r, None, None).f_int
            };
            let r = mat.evaluate(trial, &op.kinematics(&mesh, &gauss, &u)).unwrap();
            let mut values = vec![0.0; pattern.nnz()];
            op.assemble(&mesh, &dofs, &gauss, &pattern, &u, &r, Some(&mut values), None);
            let kmax = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-7;
            let mut worst = 0.0f64;
            for j in 0..dofs.n_dofs() {
                let (mut up, mut um) = (u.clone(), u.clone());
                up[j] += h;
                um[j] -= h;
                let (fp, fm) = (f(&up, &mut mat), f(&um, &mut mat));
                for i in 0..dofs.n_dofs() {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    let k = entry(&pattern, &values, i, j);
                    worst = worst.max((fd - k).abs() / kmax);
                    assert!(
                        (fd - k).abs() < 1e-6 * kmax,
                        "{field:?} {kind:?} K[{i}][{j}] = {k} vs fd {fd}"
                    );
                }
            }
            println!("{field:?} {kind:?}: largest |K - fd| / max|K| = {worst:.1e}");
        }
    }
}
