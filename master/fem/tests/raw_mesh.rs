//! A mesh built through the generic raw-description constructor (what the Gmsh reader fills)
//! gives the same answer as the structured generator: here the same 3 x 2 Q8 panel with its
//! nodes renumbered in reverse, elements listed clockwise and rotated (a different first
//! corner), edges given in arbitrary orientation. Loading: compression by the top platen and
//! a pressure on the right side (exercises edge orientation). Tolerance: 1e-12 relative
//! (same equations in a different order; only round-off differs).

use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::{Mesh, MeshDescription};
use cosdem_fem::solve::{
    Dirichlet, EdgeLoad, EdgeLoadKind, Loading, Model, Ramp, Solver, SolverSettings,
};
use std::collections::BTreeMap;

fn loading() -> Loading {
    Loading {
        dirichlet: vec![
            Dirichlet::new("bottom", Component::Ux, 0.0),
            Dirichlet::new("bottom", Component::Uy, 0.0),
            Dirichlet::new("top", Component::Ux, 0.0),
            Dirichlet::new("top", Component::Uy, -0.01),
        ],
        edge_loads: vec![EdgeLoad {
            set: "right".into(),
            kind: EdgeLoadKind::Pressure(2e4),
            ramp: Ramp::Constant,
        }],
        ..Default::default()
    }
}

fn solve(mesh: Mesh) -> Solver {
    let model = Model {
        mesh,
        field: Field::Cosserat,
        rule: QuadratureRule::Gauss2x2,
        loading: loading(),
        kinematics: Default::default(),
    };
    let mut s = Solver::new(model, SolverSettings { steps: 2, ..Default::default() }).unwrap();
    s.run(&mut ElasticCosserat::new(1e7, 0.3, 5e6, 0.05), &mut ()).unwrap();
    s
}

#[test]
fn raw_description_and_structured_mesh_agree() {
    let structured = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, 3, 2, [0.0, 0.0]).unwrap();
    let nn = structured.n_nodes();
    let new = |old: usize| nn - 1 - old; // reverse numbering
    let mut nodes = vec![[0.0; 2]; nn];
    for (i, p) in structured.nodes.iter().enumerate() {
        nodes[new(i)] = *p;
    }
    // clockwise with another first corner: corners (0,3,2,1) rotated -> (3,2,1,0), edges follow
    let cw = [3, 2, 1, 0, 6, 5, 4, 7];
    let elements = (0..structured.n_elements())
        .map(|e| cw.iter().map(|&k| new(structured.element_nodes(e)[k])).collect())
        .collect();
    let mut edge_groups = BTreeMap::new();
    for (name, edges) in &structured.edge_sets {
        let list = edges
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let [a, b, m] = e.nodes.map(new);
                if i % 2 == 0 { [b, a, m] } else { [a, b, m] }
            })
            .collect();
        edge_groups.insert(name.clone(), list);
    }
    let desc = MeshDescription { nodes, elements, edge_groups, ..Default::default() };
    let raw = Mesh::from_description(desc).unwrap();

    let (a, b) = (solve(structured), solve(raw));
    let scale = 0.01;
    for i in 0..nn {
        for c in 0..3 {
            let (x, y) = (a.solution().dofs[3 * i + c], b.solution().dofs[3 * new(i) + c]);
            assert!((x - y).abs() < 1e-12 * scale, "node {i} comp {c}: {x} vs {y}");
        }
    }
    for name in ["top", "bottom", "left", "right"] {
        let (ra, rb) = (a.reactions()[name], b.reactions()[name]);
        for c in 0..3 {
            assert!(
                (ra[c] - rb[c]).abs() < 1e-9 * ra[1].abs().max(1.0),
                "{name}: {ra:?} vs {rb:?}"
            );
        }
    }
}
