//! Helpers shared by the integration tests: meshes, exact fields, error norms.
#![allow(dead_code)]

pub mod panel;

use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, Quadrature, QuadratureRule, shape_at};
use cosdem_fem::mesh::{Mesh, MeshDescription};
use cosdem_fem::solve::{Dirichlet, Loading, SolutionView};

/// The QuadratureRule of each element family in the tests: Q8 reduced 2x2 (the paper),
/// Q9 full 3x3.
pub const ELEMENTS: [(ElementKind, QuadratureRule); 2] =
    [(ElementKind::Q8, QuadratureRule::Gauss2x2), (ElementKind::Q9, QuadratureRule::Gauss3x3)];

/// The 6-node triangle with its reduced (3-point, degree 2) and full (6-point, degree 4)
/// rules.
pub const TRIANGLES: [(ElementKind, QuadratureRule); 2] =
    [(ElementKind::T6, QuadratureRule::Triangle3), (ElementKind::T6, QuadratureRule::Triangle6)];

/// A file of `tests/data/`.
pub fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// Mixed meshes: the quadrilateral of each row of [`ELEMENTS`] with 6-node triangles, and
/// the rule given (the quadrilaterals'; the triangles take its counterpart, `Triangle3` or
/// `Triangle6`).
pub const MIXED: [(ElementKind, QuadratureRule); 2] = ELEMENTS;

/// A unit square of 3x3 elements (cells split in two for triangles) whose interior corner
/// nodes are moved by up to 20 % of the element size (deterministically); edges stay
/// straight: mid-edge nodes at edge midpoints, Q9 centres at the bilinear centre. So the
/// isoparametric map is bilinear (affine for triangles), and the rules integrate the
/// constant-stress element forces exactly (what the patch test needs). The triangles' grid
/// vertices are moved as the quadrilaterals' are (same shifts in the same order).
pub fn distorted_square(kind: ElementKind) -> Mesh {
    let mut m = Mesh::rectangle(kind, 1.0, 1.0, 3, 3, [0.0, 0.0]).unwrap();
    distort(&mut m);
    m
}

/// [`distorted_square`] of a [`mixed_square`] of 3x3 cells: `quad` elements in the left
/// column, pairs of triangles in the other two.
pub fn distorted_mixed_square(quad: ElementKind) -> Mesh {
    let mut m = mixed_square(quad, 3, 1);
    distort(&mut m);
    m
}

/// Moves the interior corner nodes of a unit-square mesh as [`distorted_square`] says and
/// puts every mid-side node (and Q9 centre) back where a straight-sided element has it.
pub fn distort(m: &mut Mesh) {
    let shifts = [[0.06, -0.04], [-0.05, 0.065], [0.045, 0.05], [-0.06, -0.03]];
    let mut k = 0;
    let corners: std::collections::BTreeSet<usize> = (0..m.n_elements())
        .flat_map(|e| m.element_nodes(e)[..m.element_kind(e).corners()].to_vec())
        .collect();
    for &n in &corners {
        let [x, y] = m.nodes[n];
        let interior = x > 1e-9 && x < 1.0 - 1e-9 && y > 1e-9 && y < 1.0 - 1e-9;
        if interior {
            m.nodes[n] = [x + shifts[k % 4][0], y + shifts[k % 4][1]];
            k += 1;
        }
    }
    for e in 0..m.n_elements() {
        let kind = m.element_kind(e);
        let el = m.element_nodes(e).to_vec();
        let c: Vec<[f64; 2]> = el[..kind.corners()].iter().map(|&n| m.nodes[n]).collect();
        let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        for &[a, b, slot] in kind.edges() {
            m.nodes[el[slot]] = mid(c[a], c[b]);
        }
        if kind == ElementKind::Q9 {
            m.nodes[el[8]] = [
                (c[0][0] + c[1][0] + c[2][0] + c[3][0]) / 4.0,
                (c[0][1] + c[1][1] + c[2][1] + c[3][1]) / 4.0,
            ];
        }
    }
}

/// A unit square of `n` x `n` cells: the first `quad_columns` columns of cells are `quad`
/// elements (Q8 or Q9), the others pairs of 6-node triangles split as
/// [`Mesh::rectangle`] splits them. Nodes no element uses (Q8 cell centres) are dropped,
/// the others keep their order. Sets: the rectangle's node and edge sets, and the element
/// sets `quadrilaterals` and `triangles`.
pub fn mixed_square(quad: ElementKind, n: usize, quad_columns: usize) -> Mesh {
    let q = Mesh::rectangle(ElementKind::Q9, 1.0, 1.0, n, n, [0.0, 0.0]).unwrap();
    let t = Mesh::rectangle(ElementKind::T6, 1.0, 1.0, n, n, [0.0, 0.0]).unwrap();
    assert_eq!(q.nodes, t.nodes);
    let (mut elements, mut quads, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..n * n {
        if c % n < quad_columns {
            quads.push(elements.len());
            elements.push(q.element_nodes(c)[..quad.nodes()].to_vec());
        } else {
            for e in [2 * c, 2 * c + 1] {
                triangles.push(elements.len());
                elements.push(t.element_nodes(e).to_vec());
            }
        }
    }
    let used: std::collections::BTreeSet<usize> = elements.iter().flatten().copied().collect();
    let mut index = vec![usize::MAX; q.n_nodes()];
    for (i, &n) in used.iter().enumerate() {
        index[n] = i;
    }
    let keep = |nodes: &[usize]| -> Vec<usize> {
        nodes.iter().filter(|&&n| index[n] != usize::MAX).map(|&n| index[n]).collect()
    };
    let desc = MeshDescription {
        nodes: used.iter().map(|&n| q.nodes[n]).collect(),
        elements: elements.iter().map(|el| keep(el)).collect(),
        node_groups: q.node_sets.iter().map(|(k, v)| (k.clone(), keep(v))).collect(),
        edge_groups: q
            .edge_sets
            .iter()
            .map(|(k, v)| (k.clone(), v.iter().map(|e| e.nodes.map(|n| index[n])).collect()))
            .collect(),
        element_groups: [("quadrilaterals".into(), quads), ("triangles".into(), triangles)]
            .into_iter()
            .collect(),
    };
    Mesh::from_description(desc).unwrap()
}

/// Every node on the boundary of the unit square gets the exact `(u_x, u_y, w)`.
pub fn boundary_values(mesh: &Mesh, field: Field, exact: impl Fn([f64; 2]) -> [f64; 3]) -> Loading {
    boundary_values_on(mesh, &["bottom", "top", "left", "right"], field, exact)
}

/// Every node of the node sets `sides` gets the exact `(u_x, u_y, w)` (`w` for Cosserat only).
pub fn boundary_values_on(
    mesh: &Mesh,
    sides: &[&str],
    field: Field,
    exact: impl Fn([f64; 2]) -> [f64; 3],
) -> Loading {
    let mut loading = Loading::default();
    let mut boundary: Vec<usize> =
        sides.iter().flat_map(|s| mesh.node_set(s).unwrap().to_vec()).collect();
    boundary.sort_unstable();
    boundary.dedup();
    for n in boundary {
        let v = exact(mesh.nodes[n]);
        loading.nodal_dirichlet.push((n, Component::Ux, v[0]));
        loading.nodal_dirichlet.push((n, Component::Uy, v[1]));
        if field == Field::Cosserat {
            loading.nodal_dirichlet.push((n, Component::W, v[2]));
        }
    }
    loading
}

/// `component = 0` on the four sides of a rectangle mesh.
pub fn clamp_all_sides(field: Field) -> Vec<Dirichlet> {
    let comps: &[Component] = match field {
        Field::Cosserat => &[Component::Ux, Component::Uy, Component::W],
        Field::Cauchy => &[Component::Ux, Component::Uy],
    };
    ["bottom", "top", "left", "right"]
        .iter()
        .flat_map(|s| comps.iter().map(|&c| Dirichlet::new(s, c, 0.0)))
        .collect()
}

/// Values, gradient `[d/dx, d/dy]` of the FE field of each component at point `xi` of element `e`.
pub fn fe_field(
    view: &SolutionView<'_>,
    e: usize,
    xi: [f64; 2],
) -> ([f64; 2], [[f64; 3]; 3], [[f64; 2]; 3]) {
    let mesh = view.mesh;
    let s = shape_at(mesh.element_kind(e), e, &mesh.element_coords(e), xi).unwrap();
    let ndf = view.field.ndf();
    let mut val = [0.0; 3];
    let mut grad = [[0.0; 2]; 3];
    for (a, &n) in mesh.element_nodes(e).iter().enumerate() {
        for c in 0..ndf {
            let d = view.dofs[n * ndf + c];
            val[c] += s.n[a] * d;
            grad[c][0] += s.grad[a][0] * d;
            grad[c][1] += s.grad[a][1] * d;
        }
    }
    (s.x, [val, [s.det_j, 0.0, 0.0], [0.0; 3]], grad)
}

/// Integrates `f(x, fe value, fe gradient)` over the mesh with 4x4 Gauss points per element
/// (quadrilaterals) or their collapsed counterpart, exact to degree 6 (triangles).
pub fn integrate(
    view: &SolutionView<'_>,
    f: impl Fn([f64; 2], [f64; 3], [[f64; 2]; 3]) -> f64,
) -> f64 {
    let mut sum = 0.0;
    for e in 0..view.mesh.n_elements() {
        let q = Quadrature::new(QuadratureRule::Gauss4x4.on(view.mesh.element_kind(e)));
        for (p, w) in q.points.iter().zip(&q.weights) {
            let (x, vj, grad) = fe_field(view, e, *p);
            sum += w * vj[1][0] * f(x, vj[0], grad);
        }
    }
    sum
}
