//! A Gmsh file written by Gmsh gives the same answer as the structured mesh of the same
//! geometry: the 1 x 1 m square, 2 x 2 Q8 (`master/fem/tests/data/square_q8.geo`, meshed by
//! Gmsh 4.8.4) and 3 x 2 Q9, compressed between rough platens with a pressure on the left edge,
//! elastic Cosserat material: the job of the fixture `gmsh-square`, on each mesh. And 2 x 2
//! cells of T6, from a Gmsh 2.2 file the test writes from the structured mesh.
//!
//! Node and element numbering differ between the two meshes, so the comparison is of
//! numbering-free quantities: the reactions of the named sets and the Gauss-point stresses
//! matched by position. Both discretize the same problem with the same elements, so they agree
//! to round-off of the linear solves (1e-9 relative, far above 1e-16 times the condition number
//! of these 100-dof systems, far below any discretization error).

use cosdem_fem::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_job::{Integration, Job, fixtures};

#[derive(Default)]
struct Last {
    report: Option<StepReport>,
    gauss: Vec<([f64; 2], [f64; 6])>,
}

impl StepObserver for Last {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        self.report = Some(r.clone());
        self.gauss = s.gauss_points.iter().map(|g| (g.position, g.stress)).collect();
        Ok(())
    }
}

/// The `gmsh-square` fixture on the Gmsh file `file` (beside the fixture's own) with the
/// Gauss rule `integration`.
fn gmsh(file: &str, integration: Integration) -> Job {
    let mut job = fixtures::load("gmsh-square");
    job.mesh.file = job.mesh.file.map(|f| f.with_file_name(file));
    job.mesh.integration = integration;
    job.validate().unwrap();
    job
}

/// The `gmsh-square` fixture on the structured mesh of the `[mesh]` table `mesh`.
fn structured(mesh: &str) -> Job {
    let mut job = fixtures::load("gmsh-square");
    job.mesh = toml::from_str(mesh).unwrap();
    job.validate().unwrap();
    job
}

fn run(job: &Job) -> Last {
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let mut material = job.elastic().unwrap();
    let mut last = Last::default();
    solver.run(&mut material, &mut last).unwrap();
    last
}

fn compare(a: &Last, b: &Last) {
    let (ra, rb) = (&a.report.as_ref().unwrap().reactions, &b.report.as_ref().unwrap().reactions);
    for set in ["top", "bottom", "left", "right"] {
        for k in 0..3 {
            let (x, y) = (ra[set][k], rb[set][k]);
            let scale = ra["top"][1].abs();
            assert!((x - y).abs() <= 1e-9 * scale, "{set}[{k}]: {x} vs {y}");
        }
    }
    assert_eq!(a.gauss.len(), b.gauss.len());
    let smax = a.gauss.iter().flat_map(|g| g.1).fold(0.0f64, |m, v| m.max(v.abs()));
    for (pos, s) in &a.gauss {
        let (_, t) = b
            .gauss
            .iter()
            .find(|(p, _)| (p[0] - pos[0]).abs() < 1e-9 && (p[1] - pos[1]).abs() < 1e-9)
            .unwrap_or_else(|| panic!("no gauss point at {pos:?}"));
        for k in 0..6 {
            assert!((s[k] - t[k]).abs() <= 1e-9 * smax, "{pos:?}[{k}]: {} vs {}", s[k], t[k]);
        }
    }
}

#[test]
fn gmsh_q8_square_matches_the_structured_mesh() {
    let structured = run(&structured("kind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2"));
    for file in ["square_q8_v22.msh", "square_q8_v41.msh", "square_q8_v41_bin.msh"] {
        compare(&structured, &run(&gmsh(file, Integration::Reduced)));
    }
}

#[test]
fn gmsh_q9_square_matches_the_structured_mesh() {
    let structured = run(&structured(
        "kind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 3\nny = 2\nelement = \"q9\"\nintegration = \"full\"",
    ));
    compare(&structured, &run(&gmsh("square_q9_v41.msh", Integration::Full)));
}

/// The structured T6 mesh of `[mesh]` table `mesh` written as a Gmsh 2.2 file (6-node
/// triangles, type 9, in physical surface `panel`; the sides' 3-node lines, type 8, in the
/// physical lines `bottom`, `right`, `top`, `left`), the way Gmsh writes one.
fn t6_msh(mesh: &str) -> std::path::PathBuf {
    let m = structured(mesh).build_mesh().unwrap();
    let sides = ["bottom", "right", "top", "left"];
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n");
    for (i, side) in sides.iter().enumerate() {
        s += &format!("1 {} \"{side}\"\n", i + 1);
    }
    s += &format!("2 5 \"panel\"\n$EndPhysicalNames\n$Nodes\n{}\n", m.n_nodes());
    for (i, p) in m.nodes.iter().enumerate() {
        s += &format!("{} {:?} {:?} 0\n", i + 1, p[0], p[1]);
    }
    let mut elements = Vec::new();
    for (i, side) in sides.iter().enumerate() {
        for e in m.edge_set(side).unwrap() {
            let [a, b, c] = e.nodes.map(|n| n + 1);
            elements.push(format!("8 2 {} {} {a} {b} {c}", i + 1, i + 1));
        }
    }
    for el in m.connectivity.chunks(6) {
        let nodes: Vec<String> = el.iter().map(|n| (n + 1).to_string()).collect();
        elements.push(format!("9 2 5 1 {}", nodes.join(" ")));
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", elements.len());
    for (i, e) in elements.iter().enumerate() {
        s += &format!("{} {e}\n", i + 1);
    }
    s += "$EndElements\n";
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("square_t6_v22.msh");
    std::fs::write(&path, s).unwrap();
    path
}

/// A Gmsh file of 6-node triangles takes the triangle rules (3 points `reduced`, 6 `full`:
/// the rule follows the mesh's elements, not the `element` key, which a Gmsh job ignores) and
/// gives the answer of the structured T6 mesh it was written from, 2 x 2 cells (8 triangles).
#[test]
fn gmsh_t6_square_matches_the_structured_mesh() {
    let table = "kind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2\nelement = \"t6\"";
    let file = t6_msh(table);
    for (integration, points) in [(Integration::Reduced, 3), (Integration::Full, 6)] {
        let structured =
            structured(&format!("{table}\nintegration = \"{integration:?}\"").to_lowercase());
        let mut gmsh = gmsh("square_q8_v22.msh", integration);
        gmsh.mesh.file = Some(file.clone());
        let (a, b) = (run(&structured), run(&gmsh));
        assert_eq!(b.gauss.len(), 8 * points, "{integration:?}");
        compare(&a, &b);
    }
}
