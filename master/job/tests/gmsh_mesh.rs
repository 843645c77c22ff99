//! A Gmsh file written by Gmsh gives the same answer as the structured mesh of the same
//! geometry: the 1 x 1 m square, 2 x 2 Q8 (`tests/data/square_q8.geo`, meshed by Gmsh 4.8.4)
//! and 3 x 2 Q9, compressed between rough platens with a pressure on the left edge, elastic
//! Cosserat material.
//!
//! Node and element numbering differ between the two meshes, so the comparison is of
//! numbering-free quantities: the reactions of the named sets and the Gauss-point stresses
//! matched by position. Both discretize the same problem with the same elements, so they agree
//! to round-off of the linear solves (1e-9 relative, far above 1e-16 times the condition number
//! of these 100-dof systems, far below any discretization error).

use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_job::Job;

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

fn run(mesh_table: &str) -> Last {
    let text = format!(
        r#"
        [mesh]
        {mesh_table}
        [loading]
        steps = 2
        [loading.compression]
        displacement = 0.002
        [[loading.pressure]]
        set = "left"
        value = 5e4
        [material]
        kind = "elastic"
        shear_modulus = 1e7
        poisson = 0.25
        length = 0.05
        "#
    );
    let mut job = Job::from_toml(&text, "inline").unwrap();
    if let Some(f) = &job.mesh.file {
        // The committed test meshes are the FE core's.
        job.mesh.file =
            Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fem").join(f));
    }
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let mut material = ElasticCosserat::new(1e7, 0.25, 5e6, 0.05);
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
    let structured = run("kind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2");
    for file in ["square_q8_v22.msh", "square_q8_v41.msh", "square_q8_v41_bin.msh"] {
        let gmsh = run(&format!("kind = \"gmsh\"\nfile = \"tests/data/{file}\""));
        compare(&structured, &gmsh);
    }
}

#[test]
fn gmsh_q9_square_matches_the_structured_mesh() {
    let structured = run(
        "kind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 3\nny = 2\nelement = \"q9\"\nintegration = \"full\"",
    );
    let gmsh =
        run("kind = \"gmsh\"\nfile = \"tests/data/square_q9_v41.msh\"\nintegration = \"full\"");
    compare(&structured, &gmsh);
}
