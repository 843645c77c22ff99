//! Quadratic quadrilateral and triangle shape functions and the isoparametric map.

use crate::error::{Error, Result};

/// The element families of the macro mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ElementKind {
    /// 8-node serendipity quadrilateral (Gmsh type 16), the paper's element.
    Q8,
    /// 9-node Lagrange quadrilateral (Gmsh type 10).
    Q9,
    /// 6-node quadratic triangle (Gmsh type 9).
    T6,
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

/// Reference coordinates of the 6-node triangle's nodes, in Gmsh order: corners (0,0),
/// (1,0), (0,1), then the mid-sides of 0-1, 1-2, 2-0.
const TRIANGLE_NODES: [[f64; 2]; 6] =
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]];

/// The three nodes (start, end, middle) of each quadrilateral edge, counter-clockwise.
const QUAD_EDGES: [[usize; 3]; 4] = [[0, 1, 4], [1, 2, 5], [2, 3, 6], [3, 0, 7]];

/// The three nodes (start, end, middle) of each triangle edge, counter-clockwise.
const TRIANGLE_EDGES: [[usize; 3]; 3] = [[0, 1, 3], [1, 2, 4], [2, 0, 5]];

/// Node permutation that reverses the orientation of a quadratic quadrilateral (Gmsh order):
/// corners 1 and 3 swap, and with them the mid-edge nodes.
const QUAD_FLIP: [usize; 9] = [0, 3, 2, 1, 7, 6, 5, 4, 8];

/// Node permutation that reverses the orientation of a 6-node triangle: corners 1 and 2
/// swap, mid-sides 3 (0-1) and 5 (2-0) swap, 4 (1-2) stays.
const TRIANGLE_FLIP: [usize; 6] = [0, 2, 1, 5, 4, 3];

impl ElementKind {
    /// Nodes per element.
    pub const fn nodes(self) -> usize {
        match self {
            Self::Q8 => 8,
            Self::Q9 => 9,
            Self::T6 => 6,
        }
    }

    /// The Gmsh element type number.
    pub const fn gmsh_type(self) -> u32 {
        match self {
            Self::Q8 => 16,
            Self::Q9 => 10,
            Self::T6 => 9,
        }
    }

    /// The element kind of a Gmsh element type number, if it is one of ours.
    pub const fn from_gmsh_type(t: u32) -> Option<Self> {
        match t {
            16 => Some(Self::Q8),
            10 => Some(Self::Q9),
            9 => Some(Self::T6),
            _ => None,
        }
    }

    /// True for the triangle families (reference triangle `xi, eta >= 0, xi + eta <= 1`);
    /// false for the quadrilaterals (reference square `[-1, 1]^2`).
    pub const fn is_triangle(self) -> bool {
        matches!(self, Self::T6)
    }

    /// Corner nodes per element (they come first in Gmsh order): 3 or 4.
    pub const fn corners(self) -> usize {
        match self {
            Self::Q8 | Self::Q9 => 4,
            Self::T6 => 3,
        }
    }

    /// Reference coordinates of the nodes, in Gmsh order.
    pub fn reference_nodes(self) -> &'static [[f64; 2]] {
        match self {
            Self::Q8 | Self::Q9 => &REFERENCE_NODES[..self.nodes()],
            Self::T6 => &TRIANGLE_NODES,
        }
    }

    /// Local node indices (start, end, middle) of the element's edges (4 for a
    /// quadrilateral, 3 for a triangle), counter-clockwise.
    pub fn edges(self) -> &'static [[usize; 3]] {
        match self {
            Self::Q8 | Self::Q9 => &QUAD_EDGES,
            Self::T6 => &TRIANGLE_EDGES,
        }
    }

    /// The node permutation (`new[k] = old[flip[k]]`) that turns a clockwise element
    /// counter-clockwise, keeping node 0.
    pub fn flip(self) -> &'static [usize] {
        match self {
            Self::Q8 | Self::Q9 => &QUAD_FLIP[..self.nodes()],
            Self::T6 => &TRIANGLE_FLIP,
        }
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
            Self::T6 => {
                // Area coordinates L0 = 1 - xi - eta, L1 = xi, L2 = eta.
                let l0 = 1.0 - x - y;
                n[0] = l0 * (2.0 * l0 - 1.0);
                n[1] = x * (2.0 * x - 1.0);
                n[2] = y * (2.0 * y - 1.0);
                n[3] = 4.0 * l0 * x;
                n[4] = 4.0 * x * y;
                n[5] = 4.0 * y * l0;
                let d0 = 1.0 - 4.0 * l0;
                dn[0] = [d0, d0];
                dn[1] = [4.0 * x - 1.0, 0.0];
                dn[2] = [0.0, 4.0 * y - 1.0];
                dn[3] = [4.0 * (l0 - x), -4.0 * x];
                dn[4] = [4.0 * y, 4.0 * x];
                dn[5] = [-4.0 * y, 4.0 * (l0 - y)];
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
        for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
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
            let xi = if kind.is_triangle() { [0.23, 0.41] } else { [0.31, -0.57] };
            kind.shape(xi, &mut n, &mut dn);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            for k in 0..2 {
                assert!(dn.iter().map(|d| d[k]).sum::<f64>().abs() < 1e-14, "{kind:?} sum dN");
            }
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

#[cfg(test)]
mod triangle_tests {
    use super::*;

    /// The 6-node triangle's tables: corner nodes first, each edge's middle node at the mean
    /// of its ends (reference coordinates are exact binary fractions), the edges turn
    /// counter-clockwise (positive cross product of consecutive edge vectors), and the flip
    /// reverses the orientation keeping node 0 and the edge structure.
    #[test]
    fn triangle_tables_are_consistent() {
        for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
            let r = kind.reference_nodes();
            assert_eq!(r.len(), kind.nodes());
            assert_eq!(kind.edges().len(), kind.corners());
            for (k, ed) in kind.edges().iter().enumerate() {
                assert_eq!(ed[0], k);
                assert_eq!(ed[1], (k + 1) % kind.corners());
                let mid = [(r[ed[0]][0] + r[ed[1]][0]) / 2.0, (r[ed[0]][1] + r[ed[1]][1]) / 2.0];
                assert_eq!(mid, r[ed[2]], "{kind:?} edge {k}");
            }
            let area2: f64 = (0..kind.corners())
                .map(|k| {
                    let (a, b) = (r[k], r[(k + 1) % kind.corners()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum();
            assert!(area2 > 0.0);
            // Flipped: the flipped node list of a counter-clockwise element is clockwise and
            // its edges are edges of the original, reversed.
            let f = kind.flip();
            assert_eq!(f.len(), kind.nodes());
            assert_eq!(f[0], 0);
            for ed in kind.edges() {
                let (s, e, m) = (f[ed[0]], f[ed[1]], f[ed[2]]);
                assert!(kind.edges().iter().any(|o| o == &[e, s, m]), "{kind:?} flip {ed:?}");
            }
        }
        assert_eq!(ElementKind::from_gmsh_type(9), Some(ElementKind::T6));
        assert_eq!(ElementKind::T6.gmsh_type(), 9);
    }

    /// On the reference triangle the 6-node shape functions reproduce every quadratic:
    /// `sum N_a p(x_a) = p(x)` for `p` = 1, x, y, x^2, xy, y^2 at an interior point, and
    /// their derivatives those of `p` (exact arithmetic up to round-off: 1e-14).
    #[test]
    fn triangle_reproduces_quadratics() {
        let kind = ElementKind::T6;
        let mut n = [0.0; 6];
        let mut dn = [[0.0; 2]; 6];
        let x = [0.17, 0.52];
        kind.shape(x, &mut n, &mut dn);
        type Poly = fn([f64; 2]) -> (f64, [f64; 2]);
        let polys: [Poly; 6] = [
            |_| (1.0, [0.0, 0.0]),
            |p| (p[0], [1.0, 0.0]),
            |p| (p[1], [0.0, 1.0]),
            |p| (p[0] * p[0], [2.0 * p[0], 0.0]),
            |p| (p[0] * p[1], [p[1], p[0]]),
            |p| (p[1] * p[1], [0.0, 2.0 * p[1]]),
        ];
        for (i, poly) in polys.iter().enumerate() {
            let (v, g) = poly(x);
            let r = kind.reference_nodes();
            let fv: f64 = (0..6).map(|a| n[a] * poly(r[a]).0).sum();
            assert!((fv - v).abs() < 1e-14, "poly {i}");
            for k in 0..2 {
                let fg: f64 = (0..6).map(|a| dn[a][k] * poly(r[a]).0).sum();
                assert!((fg - g[k]).abs() < 1e-14, "poly {i} d/dx{k}");
            }
        }
    }
}
