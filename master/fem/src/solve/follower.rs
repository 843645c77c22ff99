//! Pressures that follow the deformed boundary (updated-Lagrangian option): a confining
//! pressure pushes normal to the current edge with the current length, so its nodal forces
//! depend on the displacements and add a (non-symmetric) load stiffness to the tangent.
//!
//! On an edge with nodes `x_a = X_a + u_a` (3-node line, parameter `t`),
//! `f_ext,a = -p int N_a [x_,t y, -x_,t x] dt`: the dead load's formula
//! ([`Loading::vectors_from`]) on `x` instead of `X`. With `r = f_int - f_ext`,
//! `K(a x, b y) = p int N_a N_b,t dt` and `K(a y, b x) = -p int N_a N_b,t dt`.

use super::loading::{EdgeLoadKind, Loading, Ramp};
use crate::assembly::{DofMap, Pattern};
use crate::element::{edge_shape, gauss_1d};
use crate::error::Result;
use crate::mesh::Mesh;

/// One pressure-loaded boundary edge.
#[derive(Clone, Debug, PartialEq)]
struct Edge {
    nodes: [usize; 3],
    /// Pressure at full load (Pa).
    pressure: f64,
    /// The ramp's `(constant, linear)` factors: the pressure at load factor `lambda` is
    /// `pressure * (constant + linear * lambda)`.
    ramp: (f64, f64),
}

/// The follower pressures of a stage (empty under small strain, where pressures are dead
/// loads).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Followers {
    edges: Vec<Edge>,
}

impl Followers {
    /// The pressure loads of `loading` as follower loads.
    pub(crate) fn new(loading: &Loading, mesh: &Mesh) -> Result<Self> {
        let mut edges = Vec::new();
        for load in &loading.edge_loads {
            let EdgeLoadKind::Pressure(p) = load.kind else { continue };
            let ramp = match load.ramp {
                Ramp::Linear => (0.0, 1.0),
                Ramp::Constant => (1.0, 0.0),
                Ramp::Down => (1.0, -1.0),
            };
            for edge in mesh.edge_set(&load.set)? {
                let nodes = [edge.nodes[0], edge.nodes[1], edge.nodes[2]];
                edges.push(Edge { nodes, pressure: p, ramp });
            }
        }
        Ok(Self { edges })
    }

    /// True when there is no follower load.
    pub(crate) fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Adds the follower forces at displacements `u` and load factor `lambda` to `f_ext`.
    pub(crate) fn add_force(
        &self,
        mesh: &Mesh,
        ndf: usize,
        u: &[f64],
        lambda: f64,
        f_ext: &mut [f64],
    ) {
        let (t1, w1) = gauss_1d(3);
        for e in &self.edges {
            let p = e.pressure * (e.ramp.0 + e.ramp.1 * lambda);
            let x: [[f64; 2]; 3] = e.nodes.map(|n| {
                let x0 = mesh.nodes[n];
                [x0[0] + u[n * ndf], x0[1] + u[n * ndf + 1]]
            });
            for (t, w) in t1.iter().zip(&w1) {
                let (n, dn) = edge_shape(*t);
                let dx = [0, 1].map(|i| (0..3).map(|a| dn[a] * x[a][i]).sum::<f64>());
                let tr = [-p * dx[1], p * dx[0]];
                for a in 0..3 {
                    for i in 0..2 {
                        f_ext[e.nodes[a] * ndf + i] += n[a] * tr[i] * w;
                    }
                }
            }
        }
    }

    /// Adds the load stiffness `-d f_ext / d u` at load factor `lambda` to the free-dof
    /// tangent `values` (CSC of `pattern`) and, with a prescribed increment `du_c`, its
    /// `K_fc du_c` part to `k_fc_du`.
    pub(crate) fn add_stiffness(
        &self,
        dofs: &DofMap,
        pattern: &Pattern,
        lambda: f64,
        mut values: Option<&mut [f64]>,
        du_c: Option<&[f64]>,
        k_fc_du: &mut [f64],
    ) {
        let ndf = dofs.field.ndf();
        let (t1, w1) = gauss_1d(3);
        for e in &self.edges {
            let p = e.pressure * (e.ramp.0 + e.ramp.1 * lambda);
            // m[a][b] = int N_a N_b,t dt
            let mut m = [[0.0; 3]; 3];
            for (t, w) in t1.iter().zip(&w1) {
                let (n, dn) = edge_shape(*t);
                for a in 0..3 {
                    for b in 0..3 {
                        m[a][b] += n[a] * dn[b] * w;
                    }
                }
            }
            for a in 0..3 {
                for b in 0..3 {
                    let k = p * m[a][b];
                    for (i, j, v) in [(0, 1, k), (1, 0, -k)] {
                        let row = dofs.equation[e.nodes[a] * ndf + i];
                        if row == usize::MAX {
                            continue;
                        }
                        let cd = e.nodes[b] * ndf + j;
                        let col = dofs.equation[cd];
                        if col == usize::MAX {
                            if let Some(du) = du_c {
                                k_fc_du[row] += v * du[cd];
                            }
                        } else if let Some(vals) = values.as_deref_mut() {
                            vals[pattern.position(row, col)] += v;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Field;
    use crate::element::ElementKind;
    use crate::solve::EdgeLoad;

    /// 2 kPa on the right and top edges.
    fn pressures() -> Loading {
        Loading {
            edge_loads: ["right", "top"]
                .map(|s| EdgeLoad {
                    set: s.into(),
                    kind: EdgeLoadKind::Pressure(2e3),
                    ramp: Ramp::Linear,
                })
                .to_vec(),
            ..Default::default()
        }
    }

    fn setup() -> (Mesh, DofMap, Pattern, Followers) {
        let mut mesh = Mesh::rectangle(ElementKind::Q8, 1.0, 0.7, 2, 1, [0.0, 0.0]).unwrap();
        for p in &mut mesh.nodes {
            *p = [p[0] + 0.05 * (3.0 * p[1]).sin(), p[1] + 0.04 * (2.0 * p[0]).cos()];
        }
        let dofs = DofMap::new(Field::Cosserat, mesh.n_nodes(), &vec![false; mesh.n_nodes() * 3]);
        let pattern = Pattern::new(&mesh, &dofs);
        let loading = pressures();
        let f = Followers::new(&loading, &mesh).unwrap();
        (mesh, dofs, pattern, f)
    }

    /// At `u = 0` the follower force is the dead load of the same pressure, to round-off
    /// (same formula, same points).
    #[test]
    fn at_the_reference_it_is_the_dead_load() {
        let (mesh, dofs, _, f) = setup();
        let loading = pressures();
        let rule = crate::element::QuadratureRule::Gauss2x2;
        let gauss = crate::assembly::GaussData::new(&mesh, rule).unwrap();
        let dead = loading.vectors(&mesh, &dofs, &gauss).unwrap().f_ext(0.6);
        let mut fol = vec![0.0; dofs.n_dofs()];
        f.add_force(&mesh, 3, &vec![0.0; dofs.n_dofs()], 0.6, &mut fol);
        for (a, b) in dead.iter().zip(&fol) {
            assert!((a - b).abs() < 1e-12 * 2e3, "{a} vs {b}");
        }
    }

    /// The load stiffness is `-d f_ext / d u`: central differences (h = 1e-6 on u ~ 0.1;
    /// f_ext is quadratic in u, so the difference is exact up to cancellation ~1e-16 |f| / h)
    /// match every entry to 1e-8 of the largest.
    #[test]
    fn load_stiffness_is_minus_the_derivative_of_the_force() {
        let (mesh, dofs, pattern, f) = setup();
        let u: Vec<f64> =
            (0..dofs.n_dofs()).map(|i| 0.1 * ((i * 7 % 11) as f64 / 11.0 - 0.5)).collect();
        let mut values = vec![0.0; pattern.nnz()];
        f.add_stiffness(&dofs, &pattern, 0.6, Some(&mut values), None, &mut []);
        let kmax = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(kmax > 0.0);
        let force = |u: &[f64]| {
            let mut out = vec![0.0; dofs.n_dofs()];
            f.add_force(&mesh, 3, u, 0.6, &mut out);
            out
        };
        let h = 1e-6;
        for j in 0..dofs.n_dofs() {
            let (mut up, mut um) = (u.clone(), u.clone());
            up[j] += h;
            um[j] -= h;
            let (fp, fm) = (force(&up), force(&um));
            for i in 0..dofs.n_dofs() {
                let fd = -(fp[i] - fm[i]) / (2.0 * h);
                let k = match pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]]
                    .binary_search(&i)
                {
                    Ok(p) => values[pattern.col_ptr[j] + p],
                    Err(_) => 0.0,
                };
                assert!((fd - k).abs() < 1e-8 * kmax, "K[{i}][{j}] = {k} vs fd {fd}");
            }
        }
    }
}
