//! Meshes mixing quadrilaterals and 6-node triangles, read from Gmsh files as a user makes
//! them: `tests/data/plate_hole_mixed.geo` (a plate with a hole, Gmsh 4.15's simple
//! recombination, which leaves 10 of 24 elements triangles) in ASCII 2.2 and 4.1 and binary
//! 4.1 (Q8 + T6), and 4.1 with complete second order (Q9 + T6).
//!
//! What is checked: the formats read the same mesh; the two families join edge to edge (a
//! shared edge has one middle node, and the edges no two elements share are the named
//! boundaries); and the patch test on that unstructured, curved-edged mesh, which is exact
//! here for the reason given at [`patch_test_on_gmsh_mixed_meshes`].

mod common;

use common::{boundary_values_on, data};
use cosdem_fem::assembly::Field;
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::gmsh::{RawMesh, SurfaceKind, read_msh};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::{Mesh, MeshDescription};
use cosdem_fem::solve::{Model, Solver, SolverSettings};
use std::collections::HashMap;

fn count(raw: &RawMesh, kind: SurfaceKind) -> usize {
    raw.elements.iter().filter(|e| e.kind == kind).count()
}

/// The named boundaries of the plate.
const SIDES: [&str; 5] = ["bottom", "right", "top", "left", "hole"];

/// 2.2 and 4.1 ASCII read equal, binary 4.1 within the ASCII files' 16 digits; 14
/// quadrilaterals and 10 triangles in both orders; every element edge is shared by at most
/// two elements with one middle node, and the edges of one element are exactly those of the
/// named boundary sets.
#[test]
fn gmsh_mixed_formats_agree_and_join_edge_to_edge() {
    let v22 = read_msh(&data("plate_hole_mixed_v22.msh")).unwrap();
    let v41 = read_msh(&data("plate_hole_mixed_v41.msh")).unwrap();
    let bin = read_msh(&data("plate_hole_mixed_v41_bin.msh")).unwrap();
    let q9 = read_msh(&data("plate_hole_mixed_q9_v41.msh")).unwrap();
    assert_eq!(v22, v41);
    assert_eq!(bin.elements, v41.elements);
    assert_eq!(bin.node_groups, v41.node_groups);
    for (a, b) in v41.nodes.iter().zip(&bin.nodes) {
        assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15, "{a:?} {b:?}");
    }
    assert_eq!((count(&v41, SurfaceKind::Q8), count(&v41, SurfaceKind::T6)), (14, 10));
    assert_eq!((count(&q9, SurfaceKind::Q9), count(&q9, SurfaceKind::T6)), (14, 10));

    for raw in [v41, q9] {
        let mesh = Mesh::from_description(raw.into()).unwrap();
        assert!(mesh.uniform_kind().is_none() && mesh.kinds.contains(&ElementKind::T6));
        let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for e in 0..mesh.n_elements() {
            let el = mesh.element_nodes(e);
            for &[a, b, m] in mesh.element_kind(e).edges() {
                let (a, b) = (el[a], el[b]);
                edges.entry((a.min(b), a.max(b))).or_default().push(el[m]);
            }
        }
        let mut single: Vec<(usize, usize)> = Vec::new();
        for (ends, middles) in &edges {
            assert!(middles.len() <= 2, "edge {ends:?} in {} elements", middles.len());
            assert!(middles.iter().all(|&m| m == middles[0]), "edge {ends:?}: {middles:?}");
            if middles.len() == 1 {
                single.push(*ends);
            }
        }
        let mut named: Vec<(usize, usize)> = SIDES
            .iter()
            .flat_map(|s| mesh.edge_set(s).unwrap())
            .map(|e| (e.nodes[0].min(e.nodes[1]), e.nodes[0].max(e.nodes[1])))
            .collect();
        single.sort_unstable();
        named.sort_unstable();
        assert_eq!(single, named);
    }
}

/// A linear displacement field (Cauchy), or one with an independent linear micro-rotation and `Gc = 0` (Cosserat), prescribed at every boundary node, comes back at
/// every interior node and Gauss point, with the reduced rules (Q8 2x2 and T6 3-point) and
/// the full ones (Q9 3x3 and T6 6-point).
///
/// Why exact on curved elements: the nodal forces of a constant stress are
/// `sum_g w_g J_g dN_a/dx` at the points; in every isoparametric element `J dN_a/dx` is a
/// cofactor of the map times a shape derivative: of degree 3 in each reference coordinate
/// for Q8 and Q9 (`dN/dxi` is of degree (1, 2), `dy/deta` of degree (2, 1)) and of total
/// degree 2 for T6, which these rules integrate exactly, so the interior forces cancel as
/// they do in the continuum. Tolerance 1e-10 of the field's 1e-3 scale: round-off of a
/// ~300-dof solve.
#[test]
fn patch_test_on_gmsh_mixed_meshes() {
    fn exact(p: [f64; 2]) -> [f64; 3] {
        let [x, y] = p;
        [
            1e-3 * (0.3 + 2.0 * x - 1.1 * y),
            1e-3 * (-0.4 + 0.7 * x + 1.3 * y),
            1e-3 * (0.2 + x - 0.5 * y),
        ]
    }
    let cases = [
        ("plate_hole_mixed_v41.msh", QuadratureRule::Gauss2x2),
        ("plate_hole_mixed_v41.msh", QuadratureRule::Triangle6),
        ("plate_hole_mixed_q9_v41.msh", QuadratureRule::Gauss3x3),
    ];
    for (file, rule) in cases {
        for field in [Field::Cauchy, Field::Cosserat] {
            let mesh = Mesh::from_description(read_msh(&data(file)).unwrap().into()).unwrap();
            assert!(mesh.kinds.contains(&ElementKind::T6));
            let loading = boundary_values_on(&mesh, &SIDES, field, exact);
            let model = Model { mesh, field, rule, loading, kinematics: Default::default() };
            let settings = SolverSettings { steps: 1, ..Default::default() };
            let mut solver = Solver::new(model, settings).unwrap();
            let mut material = ElasticCosserat::new(1.0, 0.25, 0.0, 0.2);
            solver.run(&mut material, &mut ()).unwrap();
            let view = solver.solution();
            let ndf = field.ndf();
            let mut worst = 0.0f64;
            for (n, p) in view.mesh.nodes.iter().enumerate() {
                let v = exact(*p);
                for c in 0..ndf {
                    worst = worst.max((view.dofs[n * ndf + c] - v[c]).abs());
                }
            }
            let s0 = view.gauss_points[0].stress;
            let scale = s0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let spread = view
                .gauss_points
                .iter()
                .flat_map(|g| (0..6).map(move |k| (g.stress[k] - s0[k]).abs()))
                .fold(0.0f64, f64::max);
            println!(
                "{file} {rule:?} {field:?}: nodal error {worst:.2e}, stress spread {spread:.2e}"
            );
            assert!(worst < 1e-10 * 1e-3, "{file} {rule:?} {field:?}: nodal error {worst:e}");
            assert!(spread < 1e-10 * scale, "{file} {rule:?} {field:?}: stress {spread:e}");
        }
    }
}

/// The Gauss data of the mixed plate: 4 points in each quadrilateral and 3 in each triangle
/// with the reduced rule given either way (`Gauss2x2` or `Triangle3`: the same data), numbered
/// element by element. Their areas sum to the mesh's area as the 4x4 rules give it, to
/// round-off: `det J` is of degree 3 in each reference coordinate on a curved Q8 and of total
/// degree 2 on a T6, which the reduced rules integrate exactly. That area is the plate's, the
/// unit square less the hole of radius 0.25, within 1e-3: the hole is bounded by quadratic
/// arcs through nodes on the circle, which fall a little inside it between the nodes (the
/// mesh's area is 4.8e-4 larger).
#[test]
fn gauss_points_follow_each_element_kind() {
    use cosdem_fem::assembly::GaussData;
    let mesh = Mesh::from_description(read_msh(&data("plate_hole_mixed_v41.msh")).unwrap().into())
        .unwrap();
    let gauss = GaussData::new(&mesh, QuadratureRule::Gauss2x2).unwrap();
    assert_eq!(gauss, GaussData::new(&mesh, QuadratureRule::Triangle3).unwrap());
    let counts: Vec<usize> =
        mesh.kinds.iter().map(|k| if k.is_triangle() { 3 } else { 4 }).collect();
    assert_eq!(gauss.counts(), counts);
    assert_eq!(gauss.len(), 14 * 4 + 10 * 3);
    let mut g = 0;
    for (e, &n) in counts.iter().enumerate() {
        assert_eq!(gauss.points(e), g..g + n);
        for p in 0..n {
            assert_eq!((gauss.element_of(g), gauss.id(g).point), (e, p as u32));
            assert_eq!(gauss.shape(g).len(), mesh.element_nodes(e).len());
            g += 1;
        }
    }
    let area: f64 = gauss.weight.iter().sum();
    let fine: f64 =
        GaussData::new(&mesh, QuadratureRule::Gauss4x4).unwrap().weight.iter().sum::<f64>();
    assert!((area - fine).abs() < 1e-14, "area {area} vs {fine} (4x4)");
    let exact = 1.0 - std::f64::consts::PI * 0.25 * 0.25;
    assert!((area - exact).abs() < 1e-3, "area {area} vs {exact}");
}

/// Two elements sharing an edge must share its middle node: a triangle whose mid-side node on
/// the edge it shares with a quadrilateral is a node of its own (at the same place) is
/// refused, naming the nodes.
#[test]
fn an_edge_with_two_middle_nodes_is_refused() {
    let mut desc: MeshDescription = read_msh(&data("plate_hole_mixed_v41.msh")).unwrap().into();
    let mesh = Mesh::from_description(desc.clone()).unwrap();
    let quad = |q: usize| !mesh.element_kind(q).is_triangle();
    // Elements keep the description's order (a clockwise one only has its nodes reordered).
    let (t, old) = (0..mesh.n_elements())
        .filter(|&t| !quad(t))
        .find_map(|t| {
            let el = mesh.element_nodes(t);
            mesh.element_kind(t).edges().iter().find_map(|&[a, b, m]| {
                let shared = (0..mesh.n_elements()).any(|q| {
                    quad(q) && [el[a], el[b]].iter().all(|n| mesh.element_nodes(q).contains(n))
                });
                shared.then_some((t, el[m]))
            })
        })
        .expect("a triangle beside a quadrilateral");
    let copy = desc.nodes.len();
    desc.nodes.push(desc.nodes[old]);
    desc.elements[t].iter_mut().filter(|n| **n == old).for_each(|n| *n = copy);
    let msg = Mesh::from_description(desc).unwrap_err().to_string();
    assert!(msg.contains("middle node"), "{msg}");
    assert!(msg.contains(&format!(" {old}")) && msg.contains(&format!(" {copy}")), "{msg}");
}
