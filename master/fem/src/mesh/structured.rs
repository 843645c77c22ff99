//! Structured rectangles of quadratic quadrilaterals or triangles.

use super::{Mesh, MeshDescription};
use crate::element::ElementKind;
use crate::error::{Error, Result};

/// Most elements of a structured rectangle: a cap so that a typo (or a hostile job file)
/// cannot ask for 10^18 elements. The paper's largest mesh has 100; a million Q8 elements
/// with one DEM assembly per Gauss point is far beyond any machine this runs on.
pub const MAX_ELEMENTS: usize = 1_000_000;

impl Mesh {
    /// A `lx` x `ly` rectangle with lower-left corner `origin`, split into `nx` x `ny`
    /// elements of `kind`.
    ///
    /// Named sets (nodes and edges): `bottom` (y = y0), `right`, `top`, `left`; node sets
    /// `all` and the corners `bottom_left`, `bottom_right`, `top_left`, `top_right`. Nodes
    /// are numbered row by row from the bottom-left on the (2 nx + 1) x (2 ny + 1) grid (Q8
    /// skips cell centres); cells row by row.
    ///
    /// Quadrilaterals: element `c` is cell `c`. 6-node triangles ([`ElementKind::T6`]): each
    /// cell is split along its diagonal from bottom-left to top-right (all cells alike, the
    /// cell centre being the diagonal's mid-side node): element `2c` is cell `c`'s lower-right
    /// triangle (corners bottom-left, bottom-right, top-right), `2c + 1` its upper-left one
    /// (bottom-left, top-right, top-left). So `nx * ny` cells give `2 nx ny` triangles, and the
    /// sets are those of the quadrilateral meshes.
    pub fn rectangle(
        kind: ElementKind,
        lx: f64,
        ly: f64,
        nx: usize,
        ny: usize,
        origin: [f64; 2],
    ) -> Result<Self> {
        for (field, v) in [("lx", lx), ("ly", ly), ("origin", origin[0]), ("origin", origin[1])] {
            if !(v.is_finite() && (v > 0.0 || field == "origin")) {
                return Err(Error::InvalidMesh {
                    field,
                    value: format!("{v:?}"),
                    reason: "must be finite (and > 0 for lx, ly)".into(),
                });
            }
        }
        for (field, v) in [("nx", nx), ("ny", ny)] {
            if v == 0 {
                return Err(Error::InvalidMesh {
                    field,
                    value: "0".into(),
                    reason: "must be >= 1".into(),
                });
            }
        }
        let per_cell = if kind.is_triangle() { 2 } else { 1 };
        if nx.checked_mul(ny).and_then(|n| n.checked_mul(per_cell)).is_none_or(|n| n > MAX_ELEMENTS)
        {
            return Err(Error::InvalidMesh {
                field: if kind.is_triangle() { "2 * nx * ny" } else { "nx * ny" },
                value: format!("{nx} * {ny}"),
                reason: format!("more than MAX_ELEMENTS = {MAX_ELEMENTS} elements"),
            });
        }
        let (gx, gy) = (2 * nx + 1, 2 * ny + 1);
        let skip = |i: usize, j: usize| kind == ElementKind::Q8 && i % 2 == 1 && j % 2 == 1;
        let mut id = vec![usize::MAX; gx * gy];
        let mut nodes = Vec::new();
        for j in 0..gy {
            for i in 0..gx {
                if !skip(i, j) {
                    id[j * gx + i] = nodes.len();
                    nodes.push([
                        origin[0] + lx * i as f64 / (gx - 1) as f64,
                        origin[1] + ly * j as f64 / (gy - 1) as f64,
                    ]);
                }
            }
        }
        let g = |i: usize, j: usize| id[j * gx + i];
        let mut desc = MeshDescription { nodes, ..Default::default() };
        for ey in 0..ny {
            for ex in 0..nx {
                let (i, j) = (2 * ex, 2 * ey);
                if kind.is_triangle() {
                    let (bl, br, tr, tl) = (g(i, j), g(i + 2, j), g(i + 2, j + 2), g(i, j + 2));
                    let centre = g(i + 1, j + 1);
                    desc.elements.push(vec![bl, br, tr, g(i + 1, j), g(i + 2, j + 1), centre]);
                    desc.elements.push(vec![bl, tr, tl, centre, g(i + 1, j + 2), g(i, j + 1)]);
                    continue;
                }
                let mut el = vec![
                    g(i, j),
                    g(i + 2, j),
                    g(i + 2, j + 2),
                    g(i, j + 2),
                    g(i + 1, j),
                    g(i + 2, j + 1),
                    g(i + 1, j + 2),
                    g(i, j + 1),
                ];
                if kind == ElementKind::Q9 {
                    el.push(g(i + 1, j + 1));
                }
                desc.elements.push(el);
            }
        }
        let bottom = (0..nx).map(|e| [g(2 * e, 0), g(2 * e + 2, 0), g(2 * e + 1, 0)]).collect();
        let top = (0..nx)
            .map(|e| [g(2 * e + 2, gy - 1), g(2 * e, gy - 1), g(2 * e + 1, gy - 1)])
            .collect();
        let left = (0..ny).map(|e| [g(0, 2 * e + 2), g(0, 2 * e), g(0, 2 * e + 1)]).collect();
        let right = (0..ny)
            .map(|e| [g(gx - 1, 2 * e), g(gx - 1, 2 * e + 2), g(gx - 1, 2 * e + 1)])
            .collect();
        desc.edge_groups.insert("bottom".into(), bottom);
        desc.edge_groups.insert("top".into(), top);
        desc.edge_groups.insert("left".into(), left);
        desc.edge_groups.insert("right".into(), right);
        desc.node_groups.insert("all".into(), (0..desc.nodes.len()).collect());
        desc.node_groups.insert("bottom_left".into(), vec![g(0, 0)]);
        desc.node_groups.insert("bottom_right".into(), vec![g(gx - 1, 0)]);
        desc.node_groups.insert("top_left".into(), vec![g(0, gy - 1)]);
        desc.node_groups.insert("top_right".into(), vec![g(gx - 1, gy - 1)]);
        Mesh::from_description(desc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_counts_and_sets() {
        let m = Mesh::rectangle(ElementKind::Q8, 2.0, 1.0, 3, 2, [0.0, 0.0]).unwrap();
        assert_eq!(m.n_elements(), 6);
        assert_eq!(m.n_nodes(), 7 * 5 - 6);
        assert_eq!(m.node_set("top").unwrap().len(), 7);
        assert_eq!(m.node_set("left").unwrap().len(), 5);
        assert_eq!(m.edge_set("top").unwrap().len(), 3);
        for e in m.edge_set("top").unwrap() {
            // counter-clockwise around the element: along -x on the top edge
            assert!(m.nodes[e.nodes[1]][0] < m.nodes[e.nodes[0]][0]);
        }
        let m9 = Mesh::rectangle(ElementKind::Q9, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
        assert_eq!(m9.n_nodes(), 25);
        assert!(m.node_set("nope").unwrap_err().to_string().contains("top"));
    }

    /// The triangle rectangle: two triangles per cell, the full node grid, the quads' sets
    /// (same node sets as Q9, edges owned by the triangle on that side, counter-clockwise),
    /// and the elements' areas summing to the rectangle's (exact: binary fractions).
    #[test]
    fn triangle_rectangle_counts_and_sets() {
        let m = Mesh::rectangle(ElementKind::T6, 2.0, 1.0, 4, 2, [0.0, 0.0]).unwrap();
        let m9 = Mesh::rectangle(ElementKind::Q9, 2.0, 1.0, 4, 2, [0.0, 0.0]).unwrap();
        assert_eq!(m.uniform_kind(), Some(ElementKind::T6));
        assert_eq!(m.n_elements(), 16);
        assert_eq!(m.n_nodes(), 9 * 5);
        assert_eq!(m.nodes, m9.nodes);
        assert_eq!(m.node_sets, m9.node_sets);
        for side in ["bottom", "right", "top", "left"] {
            let (t, q) = (m.edge_set(side).unwrap(), m9.edge_set(side).unwrap());
            assert_eq!(t.len(), q.len());
            for (a, b) in t.iter().zip(q) {
                assert_eq!(a.nodes, b.nodes, "{side}");
                // lower-right triangles (even) own bottom and right, upper-left the others
                let upper = side == "top" || side == "left";
                assert_eq!(a.element % 2 == 1, upper, "{side}");
            }
        }
        let area: f64 = (0..m.n_elements())
            .map(|e| {
                let c = m.element_coords(e);
                let a2 = (c[1][0] - c[0][0]) * (c[2][1] - c[0][1])
                    - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]);
                assert!(a2 > 0.0, "element {e} clockwise");
                a2 / 2.0
            })
            .sum();
        assert_eq!(area, 2.0);
        // element 2c + 1 of cell c = 5 (ex = 1, ey = 1): corners (0.5,0.5), (1,1), (0.5,1)
        let c = m.element_coords(11);
        assert_eq!(&c[..3], &[[0.5, 0.5], [1.0, 1.0], [0.5, 1.0]]);
    }

    /// A described mesh (a Gmsh file) is held to the rectangle's cap too.
    #[test]
    fn a_description_over_max_elements_is_refused() {
        let desc = MeshDescription {
            nodes: vec![[0.0, 0.0]; 8],
            elements: vec![vec![0; 8]; MAX_ELEMENTS + 1],
            ..Default::default()
        };
        let err = Mesh::from_description(desc).unwrap_err().to_string();
        assert!(err.contains("MAX_ELEMENTS") && err.contains("1000001"), "{err}");
    }
}
