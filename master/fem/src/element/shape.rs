//! Quadratic quadrilateral shape functions and the isoparametric map.

use crate::error::{Error, Result};

/// The element families of the macro mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ElementKind {
    /// 8-node serendipity quadrilateral (Gmsh type 16), the paper's element.
    Q8,
    /// 9-node Lagrange quadrilateral (Gmsh type 10).
    Q9,
}

/// Reference coordinates of the nodes, in Gmsh order.
const REFERENCE_NODES: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];

/// The three nodes (start, end, middle) of each edge, counter-clockwise.
const EDGES: [[usize; 3]; 4] = [[0, 1, 4], [1, 2, 5], [2, 3, 6], [3, 0, 7]];

impl ElementKind {
    /// Nodes per element.
    pub const fn nodes(self) -> usize {
        match self {
            Self::Q8 => 8,
            Self::Q9 => 9,
        }
    }

    /// The Gmsh element type number.
    pub const fn gmsh_type(self) -> u32 {
        match self {
            Self::Q8 => 16,
            Self::Q9 => 10,
        }
    }

    /// The element kind of a Gmsh element type number, if it is one of ours.
    pub const fn from_gmsh_type(t: u32) -> Option<Self> {
        match t {
            16 => Some(Self::Q8),
            10 => Some(Self::Q9),
            _ => None,
        }
    }

    /// Reference coordinates of the nodes, in Gmsh order.
    pub fn reference_nodes(self) -> &'static [[f64; 2]] {
        &REFERENCE_NODES[..self.nodes()]
    }

    /// Local node indices (start, end, middle) of the four edges, counter-clockwise.
    pub const fn edges() -> [[usize; 3]; 4] {
        EDGES
    }

    /// Shape function values and reference derivatives `[dN/dxi, dN/deta]` at `xi`.
    pub fn shape(self, xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
        let [x, y] = xi;
        match self {
            Self::Q8 => {
                for (a, p) in REFERENCE_NODES[..8].iter().enumerate() {
                    let [xa, ya] = *p;
                    if a < 4 {
                        n[a] = 0.25 * (1.0 + x * xa) * (1.0 + y * ya) * (x * xa + y * ya - 1.0);
                        dn[a] = [
                            0.25 * xa * (1.0 + y * ya) * (2.0 * x * xa + y * ya),
                            0.25 * ya * (1.0 + x * xa) * (x * xa + 2.0 * y * ya),
                        ];
                    } else if xa == 0.0 {
                        n[a] = 0.5 * (1.0 - x * x) * (1.0 + y * ya);
                        dn[a] = [-x * (1.0 + y * ya), 0.5 * (1.0 - x * x) * ya];
                    } else {
                        n[a] = 0.5 * (1.0 + x * xa) * (1.0 - y * y);
                        dn[a] = [0.5 * xa * (1.0 - y * y), -y * (1.0 + x * xa)];
                    }
                }
            }
            Self::Q9 => {
                let l = |t: f64, ta: f64| -> (f64, f64) {
                    if ta < -0.5 {
                        (0.5 * t * (t - 1.0), t - 0.5)
                    } else if ta > 0.5 {
                        (0.5 * t * (t + 1.0), t + 0.5)
                    } else {
                        (1.0 - t * t, -2.0 * t)
                    }
                };
                for (a, p) in REFERENCE_NODES.iter().enumerate() {
                    let (lx, dlx) = l(x, p[0]);
                    let (ly, dly) = l(y, p[1]);
                    n[a] = lx * ly;
                    dn[a] = [dlx * ly, lx * dly];
                }
            }
        }
    }
}

/// Shape functions mapped to one physical point of one element.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeAt {
    /// Values `N_a`.
    pub n: Vec<f64>,
    /// Physical gradients `[dN_a/dx, dN_a/dy]`.
    pub grad: Vec<[f64; 2]>,
    /// Jacobian determinant `det(dx/dxi)`.
    pub det_j: f64,
    /// Physical position of the point.
    pub x: [f64; 2],
}

/// Evaluates the isoparametric map of element `element` (nodes `coords`) at `xi`.
///
/// Fails when the Jacobian determinant is not positive (inverted or degenerate element).
pub fn shape_at(
    kind: ElementKind,
    element: usize,
    coords: &[[f64; 2]],
    xi: [f64; 2],
) -> Result<ShapeAt> {
    let nn = kind.nodes();
    debug_assert_eq!(coords.len(), nn);
    let mut n = vec![0.0; nn];
    let mut dn = vec![[0.0; 2]; nn];
    kind.shape(xi, &mut n, &mut dn);
    // J[i][j] = dx_i / dxi_j
    let mut j = [[0.0; 2]; 2];
    let mut x = [0.0; 2];
    for a in 0..nn {
        for i in 0..2 {
            x[i] += n[a] * coords[a][i];
            for k in 0..2 {
                j[i][k] += coords[a][i] * dn[a][k];
            }
        }
    }
    let det_j = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    if det_j.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::InvertedElement { element, det_j, xi });
    }
    // dN/dx_i = dN/dxi_k (J^-1)_{k i}
    let inv = [[j[1][1] / det_j, -j[0][1] / det_j], [-j[1][0] / det_j, j[0][0] / det_j]];
    let grad = dn
        .iter()
        .map(|d| [d[0] * inv[0][0] + d[1] * inv[1][0], d[0] * inv[0][1] + d[1] * inv[1][1]])
        .collect();
    Ok(ShapeAt { n, grad, det_j, x })
}

/// The 3-node edge (start, end, middle) at `t` in [-1, 1]: values and `d/dt`.
pub fn edge_shape(t: f64) -> ([f64; 3], [f64; 3]) {
    ([0.5 * t * (t - 1.0), 0.5 * t * (t + 1.0), 1.0 - t * t], [t - 0.5, t + 0.5, -2.0 * t])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kronecker property at the nodes, partition of unity and zero-sum derivatives, and
    /// derivatives equal to central finite differences (h = 1e-6: truncation ~1e-12,
    /// round-off ~1e-10).
    #[test]
    fn shape_functions_are_interpolatory_and_consistent() {
        for kind in [ElementKind::Q8, ElementKind::Q9] {
            let nn = kind.nodes();
            let mut n = vec![0.0; nn];
            let mut dn = vec![[0.0; 2]; nn];
            for (b, p) in kind.reference_nodes().iter().enumerate() {
                kind.shape(*p, &mut n, &mut dn);
                for a in 0..nn {
                    let expect = if a == b { 1.0 } else { 0.0 };
                    assert!((n[a] - expect).abs() < 1e-15, "{kind:?} N{a} at node {b}");
                }
            }
            let xi = [0.31, -0.57];
            kind.shape(xi, &mut n, &mut dn);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            let h = 1e-6;
            let (mut np, mut nm) = (vec![0.0; nn], vec![0.0; nn]);
            let mut scratch = vec![[0.0; 2]; nn];
            for k in 0..2 {
                let mut xp = xi;
                let mut xm = xi;
                xp[k] += h;
                xm[k] -= h;
                kind.shape(xp, &mut np, &mut scratch);
                kind.shape(xm, &mut nm, &mut scratch);
                for a in 0..nn {
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!((fd - dn[a][k]).abs() < 1e-9, "{kind:?} dN{a}/dxi{k}");
                }
            }
        }
    }
}
