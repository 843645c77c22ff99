//! Answers without a relaxation (skip threshold and elastic shortcut, issue 6 item 3) depend
//! only on each assembly's committed history: the quick job with both knobs on gives
//! bit-identical reactions, stresses and answer kinds with one and with three in-process
//! workers. No tolerance: determinism is the contract.

mod common;

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::RunObserver;
use cosdem_common::Answer;
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::MaterialSection;

#[derive(Default, PartialEq, Debug)]
struct Record {
    bits: Vec<u64>,
    answers: Vec<Answer>,
}

impl RunObserver for Record {
    fn on_step(
        &mut self,
        r: &StepReport,
        s: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
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
    let mut job = common::quick(0.008);
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("quick is DEM") };
    assembly.relaxation.skip_below = 2e-3;
    assembly.relaxation.elastic_shortcut = true;
    let mut record = Record::default();
    common::run_in_process(&job, workers, 0, &mut record);
    record
}

#[test]
fn shortcut_answers_are_bit_identical_across_worker_counts() {
    let one = run(1);
    assert!(one.answers.iter().any(|a| *a != Answer::Relaxed), "some answers must be shortcuts");
    assert_eq!(one, run(3));
}
