//! The same loading program gives bit-identical responses with 1 or 3 in-process workers
//! and with 1 or 3 worker processes on 127.0.0.1 (placement and migration do not matter).

mod common;
use common::*;

#[test]
fn in_process_one_and_three_workers_agree() {
    let reference = reference(100, 20);
    let mut pool = standin_pool(3, test_config());
    create(&mut pool, 100, 20);
    let workers: std::collections::BTreeSet<_> = pool.assignment().into_values().collect();
    assert_eq!(workers.len(), 3, "assemblies spread over the three workers");
    let trace = run_program(&mut pool, &mut |_, _| {});
    assert_identical(&reference, &trace);
}

#[test]
fn one_and_three_worker_processes_agree_with_in_process() {
    let reference = reference(100, 20);
    for n in [1, 3] {
        let (_procs, mut pool) = process_pool(n, test_config());
        assert_eq!(pool.live_workers(), n);
        create(&mut pool, 100, 20);
        let trace = run_program(&mut pool, &mut |_, _| {});
        assert_identical(&reference, &trace);
        assert_eq!(pool.stats().workers_lost, 0);
    }
}
