//! Workers given by name: `localhost:PORT` resolves (possibly to several addresses, one
//! worker each); addresses that do not answer are skipped.

mod common;
use common::*;
use cosdem_pool::{Pool, PoolError};

#[test]
fn a_name_resolving_to_addresses_gives_workers() {
    let w = WorkerProcess::start(&[], &[]);
    let name = format!("localhost:{}", w.addr.port());
    let mut pool = Pool::connect(&[name], test_config()).unwrap();
    // 127.0.0.1 answers; ::1 (if localhost also resolves to it) has no worker and is skipped.
    assert_eq!(pool.live_workers(), 1);
    create(&mut pool, 10, 1);
    assert_identical(&reference(10, 1), &run_program(&mut pool, &mut |_, _| {}));
}

#[test]
fn no_reachable_worker_is_an_error() {
    let dead = WorkerProcess::start(&[], &[]);
    let addr = dead.addr.to_string();
    drop(dead);
    let Err(e) = Pool::connect(std::slice::from_ref(&addr), test_config()) else {
        panic!("a pool without a worker was built");
    };
    // The dead address is skipped as unreachable; with none left, the error names it.
    assert!(matches!(&e, PoolError::Unavailable(m) if m.contains(&addr)), "{e}");
}
