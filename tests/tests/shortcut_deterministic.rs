//! Answers without a relaxation (skip threshold and elastic shortcut, issue 6 item 3) depend
//! only on each assembly's committed history: the quick job with both knobs on gives
//! bit-identical reactions, stresses and answer kinds with one and with three in-process
//! workers. No tolerance: determinism is the contract.

use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_common::{Answer, GaussPointId};
use cosdem_fem::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;

#[derive(Default, PartialEq, Debug)]
struct Record {
    bits: Vec<u64>,
    answers: Vec<Answer>,
}

impl StepObserver for Record {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        for v in r.reactions.values() {
            self.bits.extend(v.iter().map(|x| x.to_bits()));
        }
        for g in s.gauss_points {
            self.bits.extend(g.stress.iter().map(|x| x.to_bits()));
            self.answers.push(g.diagnostics.answer);
        }
        Ok(())
    }
}

fn run(workers: usize) -> Record {
    let text = include_str!("../../examples/quick.toml")
        .replace("displacement = 0.02", "displacement = 0.008")
        .replace(
            "tangent = { kind = \"paper\" }",
            "tangent = { kind = \"paper\" }\nrelaxation = { skip_below = 2e-3, elastic_shortcut = true }",
        );
    let job = Job::from_toml(&text, "quick.toml").unwrap();
    let MaterialSection::Dem { assembly } = &job.material else { panic!("quick is a DEM job") };
    let mut solver = Solver::new(job.model().unwrap(), job.solver_settings().unwrap()).unwrap();
    let per = solver.gauss().per_element as u32;
    let ids: Vec<GaussPointId> = (0..solver.model().mesh.n_elements() as u32)
        .flat_map(|e| (0..per).map(move |p| GaussPointId::new(e, p)))
        .collect();
    let mut pool = Pool::in_process(workers, PoolConfig::default(), |_| Dem).unwrap();
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(assembly).unwrap(),
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(&ids, &request).unwrap();
    let mut record = Record::default();
    solver.run(&mut pool, &mut record).unwrap();
    record
}

#[test]
fn shortcut_answers_are_bit_identical_across_worker_counts() {
    let one = run(1);
    assert!(one.answers.iter().any(|a| *a != Answer::Relaxed), "some answers must be shortcuts");
    assert_eq!(one, run(3));
}
