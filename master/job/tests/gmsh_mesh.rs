//! A Gmsh file written by Gmsh gives the same answer as the structured mesh of the same
//! geometry: the 1 x 1 m square, 2 x 2 Q8 (`master/fem/tests/data/square_q8.geo`, meshed by
//! Gmsh 4.8.4) and 3 x 2 Q9, compressed between rough platens with a pressure on the left edge,
//! elastic Cosserat material: the job of the fixture `gmsh-square`, on each mesh.
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
