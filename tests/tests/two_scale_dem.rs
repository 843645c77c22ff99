//! The whole two-scale loop with the real DEM behind the pool: the quick example job
//! (`examples/quick.toml`, shortened to three load steps) gives bit-identical reactions and
//! Gauss-point stresses with one and with three in-process workers, and with two threads per
//! worker instead of one. Determinism is the contract (parallelism is across assemblies, never
//! inside one), so the comparison is exact: no tolerance.

use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_fem::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;

#[derive(Default)]
struct Record {
    reactions: Vec<u64>,
    stresses: Vec<u64>,
    steps: u64,
}

impl StepObserver for Record {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        for v in r.reactions.values() {
            self.reactions.extend(v.iter().map(|x| x.to_bits()));
        }
        for g in s.gauss_points {
            self.stresses.extend(g.stress.iter().map(|x| x.to_bits()));
            self.steps += g.diagnostics.steps;
        }
        Ok(())
    }
}

fn run(workers: usize, threads: usize) -> Record {
    let text = include_str!("../../examples/quick.toml")
        .replace("displacement = 0.02", "displacement = 0.006");
    let job = Job::from_toml(&text, "quick.toml").unwrap();
    let MaterialSection::Dem { assembly } = &job.material else { panic!("quick is a DEM job") };
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let per = solver.gauss().per_element as u32;
    let ids: Vec<GaussPointId> = (0..solver.model().mesh.n_elements() as u32)
        .flat_map(|e| (0..per).map(move |p| GaussPointId::new(e, p)))
        .collect();
    let config = PoolConfig { in_process_threads: threads, ..PoolConfig::default() };
    let mut pool = Pool::in_process(workers, config, |_| Dem).unwrap();
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(assembly).unwrap(),
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(&ids, &request).unwrap();
    let mut record = Record::default();
    solver.run(&mut pool, &mut record).unwrap();
    assert_eq!(solver.load_factor(), 1.0, "the job must reach its end");
    record
}

#[test]
fn quick_job_is_bit_identical_across_worker_and_thread_counts() {
    let one = run(1, 1);
    assert!(one.steps > 0, "the DEM must have worked");
    assert!(!one.reactions.is_empty());
    let three = run(3, 1);
    assert_eq!(one.reactions, three.reactions, "reactions differ between 1 and 3 workers");
    assert_eq!(one.stresses, three.stresses, "gauss stresses differ between 1 and 3 workers");
    assert_eq!(one.steps, three.steps);
    let threaded = run(1, 2);
    assert_eq!(one.reactions, threaded.reactions, "reactions differ with 2 threads");
    assert_eq!(one.stresses, threaded.stresses);
}
