//! Test 6 of docs/notes/2026-12-05-updated-lagrangian.md: at small strains the
//! updated-Lagrangian option reproduces the small-strain results. `examples/elastic.toml`
//! (the whole run, strains up to 1e-2) and `examples/quick.toml` (DEM, its first two steps,
//! strains ~2e-3) are run in both modes; their platen reactions differ by at most twice the
//! largest displacement gradient times the reaction: the small-strain statement uses the
//! Cauchy stress as the nominal one, whose error `P - s = (tr(H) I - H) s` is first order
//! in `H = grad u`. For the DEM the relaxation tolerance (1e-4) adds to that.

use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_dem::spec::TangentFrame;
use cosdem_fem::assembly::Kinematics;
use cosdem_fem::material::{BiotCosserat, Material};
use cosdem_fem::solve::{SolutionView, Solver, StepControl, StepObserver, StepReport};
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::Pool;

mod common;

/// Records the top reaction and the largest `|F - I|` of each step; stops after `steps`.
struct Watch {
    steps: usize,
    seen: Vec<(f64, f64)>,
}

impl StepObserver for Watch {
    fn on_step(&mut self, r: &StepReport, v: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        // the strain of the state is a displacement gradient to first order
        let h = v
            .gauss_points
            .iter()
            .flat_map(|g| g.strain[..4].to_vec())
            .fold(0.0f64, |m, x| m.max(x.abs()));
        self.seen.push((r.reactions["top"][1], h));
        Ok(())
    }

    fn after_step(&mut self, _: &Solver, _: &mut dyn Material) -> cosdem_fem::Result<StepControl> {
        Ok(if self.seen.len() >= self.steps { StepControl::Stop } else { StepControl::Continue })
    }
}

fn run(name: &str, kinematics: Kinematics, steps: usize) -> Vec<(f64, f64)> {
    let path = format!("{}/../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let mut job = Job::load(std::path::Path::new(&path)).unwrap();
    job.mesh.kinematics = kinematics;
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let mut material: Box<dyn Material> = match &job.material {
        MaterialSection::Elastic { .. } => {
            let e = job.elastic().unwrap();
            match kinematics {
                Kinematics::Small => Box::new(e),
                Kinematics::UpdatedLagrangian => Box::new(BiotCosserat { elastic: e }),
            }
        }
        MaterialSection::Dem { assembly } => {
            let mut spec = (**assembly).clone();
            if kinematics == Kinematics::UpdatedLagrangian {
                spec.frame = TangentFrame::Current;
            }
            let mut pool =
                Pool::in_process(2, common::test_config(), |_| cosdem_worker::Dem).unwrap();
            let ids: Vec<_> = (0..solver.gauss().len()).map(|g| solver.gauss().id(g)).collect();
            let request = AssemblyRequest {
                spec_json: serde_json::to_vec(&spec).unwrap(),
                boundary: BoundaryKind::Unspecified,
                disc_count_hint: spec.disc_count_hint(),
            };
            pool.create_assemblies(&ids, &request).unwrap();
            Box::new(pool)
        }
    };
    let mut watch = Watch { steps, seen: Vec::new() };
    match solver.run(material.as_mut(), &mut watch) {
        Ok(_) | Err(cosdem_fem::Error::Interrupted { .. }) => {}
        Err(e) => panic!("{name} {kinematics:?}: {e}"),
    }
    assert_eq!(watch.seen.len(), steps, "{name} {kinematics:?}");
    watch.seen
}

fn agree(name: &str, steps: usize, noise: f64) {
    let small = run(name, Kinematics::Small, steps);
    let ul = run(name, Kinematics::UpdatedLagrangian, steps);
    for (k, ((rs, h), (ru, _))) in small.iter().zip(&ul).enumerate() {
        let rel = (ru - rs).abs() / rs.abs();
        println!(
            "{name} step {}: reactions {rs:.6e} (small) {ru:.6e} (UL), relative {rel:.1e}, max|H| {h:.1e}",
            k + 1
        );
        assert!(rel <= 2.0 * h + noise, "{name} step {}: {rel:e} vs max|H| {h:e}", k + 1);
    }
}

#[test]
fn the_elastic_example_agrees_to_first_order() {
    agree("elastic", 10, 0.0);
}

#[test]
fn the_quick_example_agrees_to_first_order() {
    agree("quick", 2, 1e-4);
}
