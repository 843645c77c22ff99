//! A worker that returns is taken back at the next load step and load is rebalanced onto
//! it by migrating committed states; results stay bit-identical.

mod common;
use common::*;
use cosdem_pool::Pool;

#[test]
fn a_returning_worker_is_used_from_the_next_step() {
    let reference = reference(100, 20);
    let a = WorkerProcess::start(&[], &[]);
    let mut b = Some(WorkerProcess::start(&[], &[]));
    let b_addr = b.as_ref().unwrap().addr;
    let addrs = vec![a.addr.to_string(), b_addr.to_string()];
    let mut pool = Pool::connect(&addrs, test_config()).unwrap();
    create(&mut pool, 100, 20);
    let mut back = None;
    let trace = run_program(&mut pool, &mut |step, iteration| {
        if (step, iteration) == (2, 1) {
            b.take().unwrap().kill();
        }
        if (step, iteration) == (3, 0) {
            let listen = b_addr.to_string();
            back = Some(WorkerProcess::start(&["--listen", &listen], &[]));
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 1, "{stats:?}");
    assert_eq!(stats.workers_admitted, 1, "{stats:?}");
    assert!(stats.migrated > 0, "{stats:?}");
    assert_eq!(pool.live_workers(), 2);
    let used: std::collections::BTreeSet<_> = pool.assignment().into_values().collect();
    assert_eq!(used.len(), 2, "both workers hold assemblies again");
    drop(back);
}

#[test]
fn placement_follows_disc_counts() {
    let mut pool = standin_pool(2, test_config());
    // One big assembly and four small ones: the big one gets a worker to itself.
    let big = cosdem_common::GaussPointId::new(0, 0);
    pool.create_assemblies(&[big], &spec(4000, 1)).unwrap();
    let small: Vec<_> = (1..5).map(|e| cosdem_common::GaussPointId::new(e, 0)).collect();
    pool.create_assemblies(&small, &spec(1000, 1)).unwrap();
    let owner = pool.assignment();
    assert!(small.iter().all(|s| owner[s] != owner[&big]), "{owner:?}");
}
