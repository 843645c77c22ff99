//! 6-node triangles: meshes described directly and read from Gmsh files (ASCII 2.2 and 4.1,
//! written inline), their sets, and the errors on bad input, each naming the element.
//!
//! The file meshes are the unit square split along its diagonal (0,0)-(1,1) into two
//! triangles: tags 4 (lower-right, physical surface `lower`) and 5 (upper-left, `upper`),
//! with a `bottom` and a `top` 3-node line and a `corner` point at the origin.

use cosdem_fem::assembly::Field;
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::gmsh::{GmshError, SurfaceKind, parse_msh, parse_msh_bytes};
use cosdem_fem::mesh::{Mesh, MeshDescription};
use cosdem_fem::solve::{Loading, Model, Solver, SolverSettings};

const V22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n\
    0 3 \"corner\"\n1 1 \"bottom\"\n1 2 \"top\"\n2 10 \"lower\"\n2 11 \"upper\"\n\
    $EndPhysicalNames\n$Nodes\n9\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0.5 0 0\n6 1 0.5 0\n\
    7 0.5 1 0\n8 0 0.5 0\n9 0.5 0.5 0\n$EndNodes\n$Elements\n5\n1 15 2 3 1 1\n\
    2 8 2 1 1 1 2 5\n3 8 2 2 3 3 4 7\n4 9 2 10 1 1 2 3 5 6 9\n5 9 2 11 2 1 3 4 9 7 8\n\
    $EndElements\n";

const V41: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n\
    0 3 \"corner\"\n1 1 \"bottom\"\n1 2 \"top\"\n2 10 \"lower\"\n2 11 \"upper\"\n\
    $EndPhysicalNames\n$Entities\n1 2 2 0\n1 0 0 0 1 3\n\
    1 0 0 0 1 0 0 1 1 0\n2 0 1 0 1 1 0 1 2 0\n\
    1 0 0 0 1 1 0 1 10 0\n2 0 0 0 1 1 0 1 11 0\n$EndEntities\n\
    $Nodes\n1 9 1 9\n2 1 0 9\n1\n2\n3\n4\n5\n6\n7\n8\n9\n\
    0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0 0\n1 0.5 0\n0.5 1 0\n0 0.5 0\n0.5 0.5 0\n$EndNodes\n\
    $Elements\n5 5 1 5\n0 1 15 1\n1 1\n1 1 8 1\n2 1 2 5\n1 2 8 1\n3 3 4 7\n\
    2 1 9 1\n4 1 2 3 5 6 9\n2 2 9 1\n5 1 3 4 9 7 8\n$EndElements\n";

/// Both formats read the same two triangles, counter-clockwise, with their groups; the mesh
/// built from them has the node, edge and element sets (edges owned by the triangle on that
/// side, counter-clockwise around it).
#[test]
fn gmsh_t6_formats_22_and_41_agree_and_keep_their_sets() {
    let v22 = parse_msh(V22).unwrap();
    let v41 = parse_msh(V41).unwrap();
    assert_eq!(v22, v41);
    assert_eq!(v22.elements.len(), 2);
    assert!(v22.elements.iter().all(|e| e.kind == SurfaceKind::T6 && e.nodes.len() == 6));
    assert_eq!(v22.elements[0].physicals, ["lower"]);
    assert_eq!(v22.elements[1].physicals, ["upper"]);
    let mesh = Mesh::from_description(v22.into()).unwrap();
    assert_eq!(mesh.uniform_kind(), Some(ElementKind::T6));
    assert_eq!(mesh.n_elements(), 2);
    assert_eq!(mesh.element_set("lower").unwrap(), [0]);
    assert_eq!(mesh.element_set("upper").unwrap(), [1]);
    assert_eq!(mesh.node_set("corner").unwrap(), [0]);
    assert_eq!(mesh.node_set("bottom").unwrap(), [0, 1, 4]);
    let bottom = mesh.edge_set("bottom").unwrap();
    assert_eq!((bottom[0].element, bottom[0].nodes), (0, [0, 1, 4]));
    let top = mesh.edge_set("top").unwrap();
    // counter-clockwise around the upper triangle: from (1,1) to (0,1)
    assert_eq!((top[0].element, top[0].nodes), (1, [2, 3, 6]));
}

/// The mesh of [`V41`] in binary 4.1 (little-endian), written field by field.
fn binary_v41() -> Vec<u8> {
    fn int(d: &mut Vec<u8>, v: i32) {
        d.extend_from_slice(&v.to_le_bytes());
    }
    fn size(d: &mut Vec<u8>, v: u64) {
        d.extend_from_slice(&v.to_le_bytes());
    }
    fn dbl(d: &mut Vec<u8>, v: f64) {
        d.extend_from_slice(&v.to_le_bytes());
    }
    let mut d = b"$MeshFormat\n4.1 1 8\n".to_vec();
    int(&mut d, 1);
    d.extend_from_slice(b"\n$EndMeshFormat\n$PhysicalNames\n5\n0 3 \"corner\"\n1 1 \"bottom\"\n");
    d.extend_from_slice(b"1 2 \"top\"\n2 10 \"lower\"\n2 11 \"upper\"\n$EndPhysicalNames\n");
    d.extend_from_slice(b"$Entities\n");
    for n in [1, 2, 2, 0] {
        size(&mut d, n);
    }
    int(&mut d, 1);
    for _ in 0..3 {
        dbl(&mut d, 0.0);
    }
    size(&mut d, 1);
    int(&mut d, 3);
    for (tag, phys) in [(1, 1), (2, 2), (1, 10), (2, 11)] {
        int(&mut d, tag);
        for _ in 0..6 {
            dbl(&mut d, 0.0);
        }
        size(&mut d, 1);
        int(&mut d, phys);
        size(&mut d, 0);
    }
    d.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
    for n in [1, 9, 1, 9] {
        size(&mut d, n);
    }
    for v in [2, 1, 0] {
        int(&mut d, v);
    }
    size(&mut d, 9);
    for t in 1..=9 {
        size(&mut d, t);
    }
    let xy = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.0], [1.0, 0.5]];
    for p in xy.iter().chain(&[[0.5, 1.0], [0.0, 0.5], [0.5, 0.5]]) {
        for v in [p[0], p[1], 0.0] {
            dbl(&mut d, v);
        }
    }
    d.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    for n in [5, 5, 1, 5] {
        size(&mut d, n);
    }
    let blocks: [(i32, i32, i32, u64, &[u64]); 5] = [
        (0, 1, 15, 1, &[1]),
        (1, 1, 8, 2, &[1, 2, 5]),
        (1, 2, 8, 3, &[3, 4, 7]),
        (2, 1, 9, 4, &[1, 2, 3, 5, 6, 9]),
        (2, 2, 9, 5, &[1, 3, 4, 9, 7, 8]),
    ];
    for (dim, entity, gmsh_type, tag, nodes) in blocks {
        for v in [dim, entity, gmsh_type] {
            int(&mut d, v);
        }
        size(&mut d, 1);
        size(&mut d, tag);
        for &n in nodes {
            size(&mut d, n);
        }
    }
    d.extend_from_slice(b"\n$EndElements\n");
    d
}

/// Binary 4.1 reads the same mesh as ASCII (the coordinates are exact binary fractions, so
/// the whole `RawMesh` compares equal).
#[test]
fn gmsh_t6_binary_41_matches_ascii() {
    assert_eq!(parse_msh_bytes(&binary_v41()).unwrap(), parse_msh(V22).unwrap());
}

/// A triangle listed clockwise is mirrored (corners 0 2 1, mid-sides 5 4 3) into the same
/// element as the counter-clockwise listing.
#[test]
fn clockwise_triangle_is_reoriented() {
    let cw = V22.replace("4 9 2 10 1 1 2 3 5 6 9", "4 9 2 10 1 1 3 2 9 6 5");
    assert_eq!(parse_msh(&cw).unwrap(), parse_msh(V22).unwrap());
    // The same through a mesh description: element 0 given clockwise.
    let mut desc: MeshDescription = parse_msh(V22).unwrap().into();
    let ccw = Mesh::from_description(desc.clone()).unwrap();
    desc.elements[0] = [0, 2, 1, 5, 4, 3].map(|k| desc.elements[0][k]).to_vec();
    assert_eq!(Mesh::from_description(desc).unwrap(), ccw);
}

/// Bad elements are errors naming the element (its Gmsh tag and line in a file, its index
/// in a description): corners on a line, a mid-side node far off its edge, an element of
/// a node count no kind has, a first-order triangle (with the hint to mesh second order).
#[test]
fn bad_triangles_are_named() {
    // Node 3 at (2, 0): element 4's corners (0,0), (1,0), (2,0) are collinear.
    let err = parse_msh(&V22.replace("3 1 1 0\n", "3 2 0 0\n")).unwrap_err();
    assert!(matches!(err, GmshError::DegenerateElement { element: 4, line: 29, .. }), "{err}");

    // Mid-side node 5 (of edge 1-2) lifted by 0.4 of the edge length.
    let err = parse_msh(&V22.replace("5 0.5 0 0\n", "5 0.5 0.4 0\n")).unwrap_err();
    assert!(matches!(err, GmshError::DistortedElement { element: 4, .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains(":29: element 4 is distorted: mid-side node 3"), "{msg}");

    // First order.
    let linear = V22.replace("4 9 2 10 1 1 2 3 5 6 9", "4 2 2 10 1 1 2 3");
    let err = parse_msh(&linear).unwrap_err();
    assert!(matches!(err, GmshError::UnsupportedElement { element: 4, element_type: 2, .. }));
    assert!(err.to_string().contains("Mesh.ElementOrder = 2"), "{err}");

    // The same checks on a described mesh name the element's index.
    let desc: MeshDescription = parse_msh(V22).unwrap().into();
    let mut far = desc.clone();
    far.nodes[5] = [1.4, 0.5]; // mid-side node of edge (1,0)-(1,1), 0.4 off
    let msg = Mesh::from_description(far).unwrap_err().to_string();
    assert!(msg.contains("elements = 0") && msg.contains("mid-side node 4"), "{msg}");
    let mut flat = desc.clone();
    flat.nodes[2] = [2.0, 0.0];
    let msg = Mesh::from_description(flat).unwrap_err().to_string();
    assert!(msg.contains("elements = 0: zero area"), "{msg}");
    let mut seven = desc;
    seven.elements.push(vec![0, 1, 2, 3, 4, 5, 6]);
    let msg = Mesh::from_description(seven).unwrap_err().to_string();
    assert!(msg.contains("elements = 2: 7 nodes; expected 8 (Q8), 9 (Q9) or 6 (T6)"), "{msg}");
}

/// A quadrilateral rule on a triangle mesh (and the reverse) is refused, naming the rule
/// and the kind's own rules, never integrated wrongly.
#[test]
fn a_rule_of_the_other_family_is_refused() {
    for (kind, rule) in
        [(ElementKind::T6, QuadratureRule::Gauss2x2), (ElementKind::Q8, QuadratureRule::Triangle3)]
    {
        let mesh = Mesh::rectangle(kind, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
        let model = Model {
            mesh,
            field: Field::Cosserat,
            rule,
            loading: Loading::default(),
            kinematics: Default::default(),
        };
        let msg = match Solver::new(model, SolverSettings::default()) {
            Ok(_) => panic!("{kind:?} with {rule:?} accepted"),
            Err(e) => e.to_string(),
        };
        let own = QuadratureRule::for_kind(kind, false);
        assert!(msg.contains(&format!("{rule:?}")) && msg.contains(&format!("{own:?}")), "{msg}");
    }
}
