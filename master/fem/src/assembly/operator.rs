//! The local assembler of the Cosserat (or Cauchy) continuum: B matrix, Gauss-point
//! kinematics, element internal force and tangent, scattered into global arrays.

use super::current::{
    Kinematics, PolarRotation, add_geometric_stiffness, current_gradients, deformation_gradient,
    det, polar_angle_derivative,
};
use super::pattern::NOT_FREE;
use super::{DofMap, Field, GaussData, Pattern};
use crate::material::MaterialInput;
use crate::mesh::Mesh;
use cosdem_common::voigt::{KX, KY, XX, XY, YX, YY};
use cosdem_common::{MacroDeformation, MicroResponse};

/// Largest element dof count (9 nodes x 3 dofs).
const MAX_ND: usize = 27;

/// Largest element node count.
const MAX_NODES: usize = 9;

/// Internal force and the predictor load of one assembly pass.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Assembled {
    /// Internal force `f_int = sum B^T s dA` on every dof (prescribed ones give reactions).
    pub f_int: Vec<f64>,
    /// `K_fc du_c` on the free equations: the tangent times the prescribed increment (only
    /// filled when an increment is given).
    pub k_fc_du: Vec<f64>,
}

/// The physics operator: strain-displacement relation of the chosen [`Field`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CosseratOperator {
    /// Cosserat (`u_x, u_y, w`) or Cauchy (`u_x, u_y`).
    pub field: Field,
    /// Small strain (reference configuration) or updated Lagrangian.
    pub kinematics: Kinematics,
}

impl CosseratOperator {
    /// Fills the 6 x (nodes * ndf) strain-displacement matrix at one Gauss point.
    ///
    /// Cosserat: `e_xx = N,x u_x`, `e_yy = N,y u_y`, `e_xy = N,x u_y - N w`,
    /// `e_yx = N,y u_x + N w`, `k_x = N,x w`, `k_y = N,y w`. Cauchy: see [`Field::Cauchy`].
    pub fn b_matrix(&self, n: &[f64], grad: &[[f64; 2]], b: &mut [[f64; MAX_ND]; 6]) {
        let ndf = self.field.ndf();
        for row in b.iter_mut() {
            row[..n.len() * ndf].fill(0.0);
        }
        for a in 0..n.len() {
            let [gx, gy] = grad[a];
            let (cx, cy) = (a * ndf, a * ndf + 1);
            b[XX][cx] = gx;
            b[YY][cy] = gy;
            match self.field {
                Field::Cosserat => {
                    let cw = a * ndf + 2;
                    b[XY][cy] = gx;
                    b[XY][cw] = -n[a];
                    b[YX][cx] = gy;
                    b[YX][cw] = n[a];
                    b[KX][cw] = gx;
                    b[KY][cw] = gy;
                }
                Field::Cauchy => {
                    b[XY][cx] = 0.5 * gy;
                    b[XY][cy] = 0.5 * gx;
                    b[YX][cx] = 0.5 * gy;
                    b[YX][cy] = 0.5 * gx;
                }
            }
        }
    }

    /// The Cauchy field's B matrix under the updated-Lagrangian option: the strain increment
    /// on the current configuration `de = g - dtheta Z` (`g = grad_x du`), with `dtheta` the
    /// change of the polar angle sent as the rotation (`dtheta[a] = [d/du_ax, d/du_ay]`).
    /// At `F = I` it is [`Field::Cauchy`]'s small-strain matrix.
    fn b_matrix_polar(
        n: &[f64],
        grad: &[[f64; 2]],
        dtheta: &[[f64; 2]],
        b: &mut [[f64; MAX_ND]; 6],
    ) {
        for row in b.iter_mut() {
            row[..n.len() * 2].fill(0.0);
        }
        for a in 0..n.len() {
            let [gx, gy] = grad[a];
            let (cx, cy) = (a * 2, a * 2 + 1);
            b[XX][cx] = gx;
            b[YY][cy] = gy;
            b[XY][cx] = -dtheta[a][0];
            b[XY][cy] = gx - dtheta[a][1];
            b[YX][cx] = gy + dtheta[a][0];
            b[YX][cy] = dtheta[a][1];
        }
    }

    /// Trial kinematics of every Gauss point from the nodal dofs `u` (all dofs).
    pub fn kinematics(&self, mesh: &Mesh, gauss: &GaussData, u: &[f64]) -> Vec<MaterialInput> {
        let ndf = self.field.ndf();
        (0..gauss.len())
            .map(|g| {
                let el = mesh.element_nodes(gauss.element_of(g));
                let (n, grad) = (gauss.shape(g), gauss.gradient(g));
                let mut h = [[0.0; 2]; 2]; // du_a/dx_b
                let (mut w, mut k) = (0.0, [0.0; 2]);
                for (a, &node) in el.iter().enumerate() {
                    let d = &u[node * ndf..node * ndf + ndf];
                    for i in 0..2 {
                        h[i][0] += grad[a][0] * d[i];
                        h[i][1] += grad[a][1] * d[i];
                    }
                    if self.field == Field::Cosserat {
                        w += n[a] * d[2];
                        k[0] += grad[a][0] * d[2];
                        k[1] += grad[a][1] * d[2];
                    }
                }
                if self.field == Field::Cauchy {
                    w = match self.kinematics {
                        Kinematics::Small => 0.5 * (h[1][0] - h[0][1]),
                        Kinematics::UpdatedLagrangian => {
                            MacroDeformation::from_gradient(h, 0.0, [0.0; 2]).polar_angle()
                        }
                    };
                }
                MaterialInput {
                    gauss_point: gauss.id(g),
                    deformation: MacroDeformation::from_gradient(h, w, k),
                }
            })
            .collect()
    }

    /// Assembles `f_int` (all dofs) and, when `values` is given, the free-dof tangent into
    /// the CSC value array of `pattern` (zeroed first). With `du_c` (a full-length vector that
    /// is non-zero only on prescribed dofs) it also returns `K_fc du_c`. `u` is the iterate
    /// the `responses` answer; under [`Kinematics::UpdatedLagrangian`] the integrals are over
    /// its configuration (every `det F` must be positive: the solver checks before the
    /// material is called) and the tangent has the geometric part.
    pub fn assemble(
        &self,
        mesh: &Mesh,
        dofs: &DofMap,
        gauss: &GaussData,
        pattern: &Pattern,
        u: &[f64],
        responses: &[MicroResponse],
        mut values: Option<&mut [f64]>,
        du_c: Option<&[f64]>,
    ) -> Assembled {
        let ndf = self.field.ndf();
        let mut out = Assembled {
            f_int: vec![0.0; dofs.n_dofs()],
            k_fc_du: if du_c.is_some() { vec![0.0; dofs.n_free] } else { Vec::new() },
        };
        if let Some(v) = values.as_deref_mut() {
            v.fill(0.0);
        }
        let want_k = values.is_some() || du_c.is_some();
        let mut b = [[0.0; MAX_ND]; 6];
        let mut cb = [[0.0; MAX_ND]; 6];
        let mut ke = vec![0.0; MAX_ND * MAX_ND];
        let mut gdof = vec![0usize; MAX_ND];
        let ul = self.kinematics == Kinematics::UpdatedLagrangian;
        let cauchy = self.field == Field::Cauchy;
        let mut gc = [[0.0; 2]; MAX_NODES];
        let mut dtheta = [[0.0; 2]; MAX_NODES];
        for e in 0..mesh.n_elements() {
            let el = mesh.element_nodes(e);
            let nn = el.len();
            let nd = nn * ndf;
            for (a, &node) in el.iter().enumerate() {
                for c in 0..ndf {
                    gdof[a * ndf + c] = node * ndf + c;
                }
            }
            ke[..nd * nd].fill(0.0);
            for g in gauss.points(e) {
                let r = &responses[g];
                let (n, grad_ref) = (gauss.shape(g), gauss.gradient(g));
                let mut wt = gauss.weight[g];
                let mut f = [[1.0, 0.0], [0.0, 1.0]];
                if ul {
                    f = deformation_gradient(grad_ref, |a| {
                        let d = el[a] * ndf;
                        [u[d], u[d + 1]]
                    });
                    wt *= det(&f);
                    current_gradients(&f, grad_ref, &mut gc[..nn]);
                    if cauchy {
                        let d = polar_angle_derivative(&f);
                        for (t, gr) in dtheta.iter_mut().zip(grad_ref) {
                            *t = [
                                d[0][0] * gr[0] + d[0][1] * gr[1],
                                d[1][0] * gr[0] + d[1][1] * gr[1],
                            ];
                        }
                        Self::b_matrix_polar(n, &gc[..nn], &dtheta[..nn], &mut b);
                    } else {
                        self.b_matrix(n, &gc[..nn], &mut b);
                    }
                } else {
                    self.b_matrix(n, grad_ref, &mut b);
                }
                for i in 0..nd {
                    let f: f64 = (0..6).map(|s| b[s][i] * r.stress[s]).sum();
                    out.f_int[gdof[i]] += f * wt;
                }
                if want_k {
                    for s in 0..6 {
                        for j in 0..nd {
                            cb[s][j] = (0..6).map(|t| r.tangent[s][t] * b[t][j]).sum::<f64>() * wt;
                        }
                    }
                    for i in 0..nd {
                        for s in 0..6 {
                            let bsi = b[s][i];
                            if bsi != 0.0 {
                                let row = &mut ke[i * nd..(i + 1) * nd];
                                for j in 0..nd {
                                    row[j] += bsi * cb[s][j];
                                }
                            }
                        }
                    }
                    if ul {
                        let polar = cauchy.then_some(PolarRotation {
                            f: &f,
                            grad_ref,
                            dtheta: &dtheta[..nn],
                        });
                        add_geometric_stiffness(
                            &mut ke,
                            nd,
                            ndf,
                            n,
                            &gc[..nn],
                            &r.stress,
                            wt,
                            polar,
                        );
                    }
                }
            }
            if !want_k {
                continue;
            }
            let at = pattern.element_scatter(e);
            for i in 0..nd {
                let ri = dofs.equation[gdof[i]];
                if ri == usize::MAX {
                    continue;
                }
                for j in 0..nd {
                    let k = at[i * nd + j];
                    if k == NOT_FREE {
                        if let Some(du) = du_c {
                            out.k_fc_du[ri] += ke[i * nd + j] * du[gdof[j]];
                        }
                    } else if let Some(v) = values.as_deref_mut() {
                        v[k as usize] += ke[i * nd + j];
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{ElementKind, QuadratureRule};
    use crate::material::{ElasticCosserat, Material, SofteningElastic, TrialId};
    use proptest::prelude::*;

    fn setup(kind: ElementKind, field: Field) -> (Mesh, DofMap, GaussData, Pattern) {
        let mut mesh = Mesh::rectangle(kind, 1.0, 0.7, 2, 1, [0.3, -0.2]).unwrap();
        // a mild curved distortion: every node moves, edges become curved
        for p in &mut mesh.nodes {
            *p = [p[0] + 0.05 * (3.0 * p[1]).sin(), p[1] + 0.04 * (2.0 * p[0]).cos()];
        }
        let dofs = DofMap::new(field, mesh.n_nodes(), &vec![false; mesh.n_nodes() * field.ndf()]);
        let gauss = GaussData::new(&mesh, QuadratureRule::for_kind(kind, true)).unwrap();
        let pattern = Pattern::new(&mesh, &dofs);
        (mesh, dofs, gauss, pattern)
    }

    proptest! {
        /// The B matrix (used for forces and tangents) and the kinematics sent to the material
        /// are coded separately; they must agree: strain(kinematics) = B u_e at every Gauss
        /// point, for any nodal values (round-off tolerance).
        #[test]
        fn b_matrix_agrees_with_kinematics(seed in prop::collection::vec(-1e-2f64..1e-2, 3 * 15)) {
            for field in [Field::Cosserat, Field::Cauchy] {
                for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
                    let (mesh, dofs, gauss, _) = setup(kind, field);
                    let u: Vec<f64> = (0..dofs.n_dofs()).map(|i| seed[i % seed.len()] * (1.0 + i as f64 * 0.01)).collect();
                    let op = CosseratOperator { field, kinematics: Kinematics::Small };
                    let inputs = op.kinematics(&mesh, &gauss, &u);
                    let ndf = field.ndf();
                    let mut b = [[0.0; MAX_ND]; 6];
                    for g in 0..gauss.len() {
                        op.b_matrix(gauss.shape(g), gauss.gradient(g), &mut b);
                        let el = mesh.element_nodes(gauss.element_of(g));
                        let e = inputs[g].deformation.strain();
                        for s in 0..6 {
                            let be: f64 = el.iter().enumerate().flat_map(|(a, &n)| (0..ndf).map(move |c| (a, n, c)))
                                .map(|(a, n, c)| b[s][a * ndf + c] * u[n * ndf + c]).sum();
                            prop_assert!((be - e[s]).abs() < 1e-14, "{field:?} {kind:?} gp {g} comp {s}: {be} vs {}", e[s]);
                        }
                    }
                }
            }
        }
    }

    /// The assembled tangent is the derivative of the assembled internal force: central
    /// differences (h = 1e-7 on dofs ~1e-2) match every entry of a few columns to 1e-6 of the
    /// largest entry (truncation ~h^2, cancellation ~1e-16 |f| / h).
    #[test]
    fn assembled_tangent_is_the_derivative_of_the_internal_force() {
        let mut mat =
            SofteningElastic { elastic: ElasticCosserat::new(1e6, 0.3, 4e5, 0.1), beta: 300.0 };
        for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
            let (mesh, dofs, gauss, pattern) = setup(kind, Field::Cosserat);
            let op = CosseratOperator { field: Field::Cosserat, kinematics: Kinematics::Small };
            let u: Vec<f64> =
                (0..dofs.n_dofs()).map(|i| 1e-2 * ((i * 7 % 11) as f64 / 11.0 - 0.5)).collect();
            let trial = TrialId { step: 1, iteration: 0 };
            let f = |u: &[f64], mat: &mut SofteningElastic| {
                let r = mat.evaluate(trial, &op.kinematics(&mesh, &gauss, u)).unwrap();
                op.assemble(&mesh, &dofs, &gauss, &pattern, u, &r, None, None).f_int
            };
            let r = mat.evaluate(trial, &op.kinematics(&mesh, &gauss, &u)).unwrap();
            let mut values = vec![0.0; pattern.nnz()];
            op.assemble(&mesh, &dofs, &gauss, &pattern, &u, &r, Some(&mut values), None);
            let kmax = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-7;
            for j in [0, 5, 17, 28, dofs.n_dofs() - 1] {
                let (mut up, mut um) = (u.clone(), u.clone());
                up[j] += h;
                um[j] -= h;
                let (fp, fm) = (f(&up, &mut mat), f(&um, &mut mat));
                for i in 0..dofs.n_dofs() {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    let k = match pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]]
                        .binary_search(&i)
                    {
                        Ok(p) => values[pattern.col_ptr[j] + p],
                        Err(_) => 0.0,
                    };
                    assert!((fd - k).abs() < 1e-6 * kmax, "{kind:?} K[{i}][{j}] = {k} vs fd {fd}");
                }
            }
        }
    }
}
