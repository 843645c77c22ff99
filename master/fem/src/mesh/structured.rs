//! Structured rectangles of quadratic quadrilaterals.

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
    /// `all` and the corners `bottom_left`, `bottom_right`, `top_left`, `top_right`. Nodes are numbered row by row from the bottom-left on the (2 nx + 1) x
    /// (2 ny + 1) grid (Q8 skips element centres); elements row by row.
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
        if nx.checked_mul(ny).is_none_or(|n| n > MAX_ELEMENTS) {
            return Err(Error::InvalidMesh {
                field: "nx * ny",
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
