//! Answers without a relaxation (skip threshold and elastic shortcut, issue 6 item 3) depend
//! only on each assembly's committed history: the quick job with both knobs on gives
//! bit-identical reactions, stresses, answer kinds and DEM step counts with one and with
//! three in-process workers. No tolerance: determinism is the contract.

mod common;

use common::StepBits;
use cosdem_common::Answer;
use cosdem_job::MaterialSection;

fn run(workers: usize) -> StepBits {
    let mut job = common::quick(0.008);
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("quick is DEM") };
    assembly.relaxation.skip_below = 2e-3;
    assembly.relaxation.elastic_shortcut = true;
    let mut record = StepBits::default();
    common::run_in_process(&job, workers, 0, &mut record);
    record
}

#[test]
fn shortcut_answers_are_bit_identical_across_worker_counts() {
    let one = run(1);
    assert!(one.answers.iter().any(|a| *a != Answer::Relaxed), "some answers must be shortcuts");
    assert_eq!(one, run(3));
}
