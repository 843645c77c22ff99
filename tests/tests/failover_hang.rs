//! A worker that stops answering (its relaxations hang): the SolveBatch deadline fires, its
//! assemblies are restored on the others, the iteration is redone, the result is the same;
//! the hung worker is not taken back while it is still busy.

mod common;
use common::*;
use cosdem_pool::{Pool, PoolConfig};
use std::time::Duration;

#[test]
fn a_hanging_worker_misses_its_deadline_and_is_replaced() {
    let reference = reference(100, 20);
    let good = WorkerProcess::start(&[], &[]);
    // Hangs from its 10th solve on (step 2 or so), for longer than the test.
    let hung = WorkerProcess::start(&["--hang-after", "10", "--hang-secs", "120"], &[]);
    let addrs = vec![good.addr.to_string(), hung.addr.to_string()];
    let config = PoolConfig { solve_timeout: Duration::from_millis(1500), ..test_config() };
    let mut pool = Pool::connect(&addrs, config).unwrap();
    create(&mut pool, 100, 20);
    let t = std::time::Instant::now();
    let trace = run_program(&mut pool, &mut |_, _| {});
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 1, "{stats:?}");
    assert_eq!(stats.workers_admitted, 0, "a busy worker is not taken back: {stats:?}");
    assert_eq!(pool.live_workers(), 1);
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
}

#[test]
fn a_hanging_in_process_worker_is_replaced() {
    use cosdem_worker::{StandIn, StandInOptions};
    let reference = reference(100, 20);
    let config = PoolConfig { solve_timeout: Duration::from_millis(800), ..test_config() };
    let mut pool = Pool::in_process(3, config, |i| {
        if i == 1 {
            StandIn::with_options(StandInOptions {
                hang_after_solves: Some(6),
                hang_for: Duration::from_secs(30),
            })
        } else {
            StandIn::new()
        }
    })
    .unwrap();
    create(&mut pool, 100, 20);
    let trace = run_program(&mut pool, &mut |_, _| {});
    assert_identical(&reference, &trace);
    assert_eq!(pool.stats().workers_lost, 1);
}
