//! The local assembler of the Cosserat (or Cauchy) continuum: B matrix, Gauss-point
//! kinematics, element internal force and tangent, scattered into global arrays.

use super::{DofMap, Field, GaussData, Pattern};
use crate::material::MaterialInput;
use crate::mesh::Mesh;
use cosdem_common::voigt::{KX, KY, XX, XY, YX, YY};
use cosdem_common::{MacroDeformation, MicroResponse};

/// Largest element dof count (9 nodes x 3 dofs).
const MAX_ND: usize = 27;

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

    /// Trial kinematics of every Gauss point from the nodal dofs `u` (all dofs).
    pub fn kinematics(&self, mesh: &Mesh, gauss: &GaussData, u: &[f64]) -> Vec<MaterialInput> {
        let ndf = self.field.ndf();
        (0..gauss.len())
            .map(|g| {
                let el = mesh.element_nodes(g / gauss.per_element);
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
                    w = 0.5 * (h[1][0] - h[0][1]);
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
    /// is non-zero only on prescribed dofs) it also returns `K_fc du_c`.
    pub fn assemble(
        &self,
        mesh: &Mesh,
        dofs: &DofMap,
        gauss: &GaussData,
        pattern: &Pattern,
        responses: &[MicroResponse],
        mut values: Option<&mut [f64]>,
        du_c: Option<&[f64]>,
    ) -> Assembled {
        let ndf = self.field.ndf();
        let nn = gauss.nodes_per_element;
        let nd = nn * ndf;
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
        let mut ke = vec![0.0; nd * nd];
        let mut gdof = vec![0usize; nd];
        for e in 0..mesh.n_elements() {
            let el = mesh.element_nodes(e);
            for (a, &node) in el.iter().enumerate() {
                for c in 0..ndf {
                    gdof[a * ndf + c] = node * ndf + c;
                }
            }
            ke.fill(0.0);
            for g in e * gauss.per_element..(e + 1) * gauss.per_element {
                let r = &responses[g];
                let wt = gauss.weight[g];
                self.b_matrix(gauss.shape(g), gauss.gradient(g), &mut b);
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
                }
            }
            if !want_k {
                continue;
            }
            for i in 0..nd {
                let ri = dofs.equation[gdof[i]];
                if ri == usize::MAX {
                    continue;
                }
                for j in 0..nd {
                    let cj = dofs.equation[gdof[j]];
                    if cj == usize::MAX {
                        if let Some(du) = du_c {
                            out.k_fc_du[ri] += ke[i * nd + j] * du[gdof[j]];
                        }
                    } else if let Some(v) = values.as_deref_mut() {
                        v[pattern.position(ri, cj)] += ke[i * nd + j];
                    }
                }
            }
        }
        out
    }
}
