//! The whole two-scale loop with the real DEM behind the pool: the quick example job
//! (`examples/quick.toml`, shortened to three load steps) run through the run driver gives
//! bit-identical reactions and Gauss-point stresses with one and with three in-process
//! workers, and with two threads per worker instead of one. Determinism is the contract
//! (parallelism is across assemblies, never inside one), so the comparison is exact: no
//! tolerance.

mod common;

use common::StepBits;

fn run(workers: usize, threads: usize) -> StepBits {
    let job = common::quick(0.006);
    let mut record = StepBits::default();
    let outcome = common::run_in_process(&job, workers, threads, &mut record);
    assert_eq!(outcome.steps, 3, "the job must reach its end");
    record
}

/// DEM steps of the relaxations that answered the 16 Gauss points at the three committed
/// steps, measured; a count of a deterministic computation, so exact.
const DEM_STEPS: u64 = 6190;

#[test]
fn quick_job_is_bit_identical_across_worker_and_thread_counts() {
    let one = run(1, 1);
    assert_eq!(one.steps, DEM_STEPS, "the DEM must have worked as it did");
    assert!(!one.reactions.is_empty());
    let three = run(3, 1);
    assert_eq!(one.reactions, three.reactions, "reactions differ between 1 and 3 workers");
    assert_eq!(one.stresses, three.stresses, "gauss stresses differ between 1 and 3 workers");
    assert_eq!(one.steps, three.steps);
    let threaded = run(1, 2);
    assert_eq!(one.reactions, threaded.reactions, "reactions differ with 2 threads");
    assert_eq!(one.stresses, threaded.stresses);
}
