//! Committed states exported every k steps (k > 1) with the increments in between replayed
//! on failover: workers killed between two exports (mid-step, and between the last iteration
//! and the commit) are replaced and the job stays bit-identical to the run without failure;
//! with k = 1 nothing is replayed.

mod common;
use common::*;
use cosdem_pool::{Pool, PoolConfig};

/// Three worker processes and a pool over them exporting every `k` commits (no rebalancing:
/// a migration exports fresh states, which would shorten what a failover replays).
fn pool(k: u64) -> (Vec<WorkerProcess>, Pool) {
    let config =
        PoolConfig { export_every: k, rebalance_threshold: f64::INFINITY, ..test_config() };
    let (procs, mut pool) = process_pool(3, config);
    create(&mut pool, 100, 20);
    (procs, pool)
}

#[test]
fn kills_between_exports_replay_the_committed_increments_bit_identically() {
    let reference = reference(100, 20);
    // k = 3: states exported at the commits of steps 3 and 6, so in step 5 the stored states
    // are those of step 3 and step 4 exists only as a recorded increment.
    let (mut procs, mut pool) = pool(3);
    let trace = run_program(&mut pool, &mut |step, iteration| {
        if (step, iteration) == (5, 1) {
            procs[0].kill();
        }
        // After the last iteration of step 5: the commit finds worker 1 gone; its points
        // (some of them restored from worker 0 just before) are restored again, replayed,
        // re-solved and committed elsewhere.
        if (step, iteration) == (5, 2) {
            procs[1].kill();
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 2, "{stats:?}");
    assert!(stats.restored > 0 && stats.resolved > 0, "{stats:?}");
    // Every restored assembly replayed step 4 (stored state of step 3).
    assert!(stats.replayed >= stats.restored, "{stats:?}");
    assert_eq!(pool.live_workers(), 1);
    // Step 6 exported again: nothing left to replay, and the stored states are of step 6.
    assert!(pool.committed_states().values().all(|s| s.committed_step == 6));
    assert!(pool.committed_states().keys().all(|id| pool.unexported_commits(id) == 0));
}

#[test]
fn a_kill_after_unexported_commits_replays_them_all() {
    // k larger than the run: only the creation states (step 0) are ever stored, a kill in
    // step 6 replays the five committed steps 1-5 (step 3 after its cut).
    let reference = reference(100, 20);
    let (mut procs, mut pool) = pool(100);
    let trace = run_program(&mut pool, &mut |step, iteration| {
        if (step, iteration) == (6, 0) {
            procs[2].kill();
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 1, "{stats:?}");
    assert_eq!(stats.exports, 0, "{stats:?}");
    assert_eq!(stats.replayed, 5 * stats.restored, "{stats:?}");
}

#[test]
fn with_export_at_every_commit_nothing_is_replayed() {
    let reference = reference(100, 20);
    let (mut procs, mut pool) = pool(1);
    let trace = run_program(&mut pool, &mut |step, iteration| {
        if (step, iteration) == (4, 1) {
            procs[0].kill();
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 1, "{stats:?}");
    assert!(stats.restored > 0, "{stats:?}");
    assert_eq!(stats.replayed, 0, "{stats:?}");
}

#[test]
fn export_every_zero_is_refused() {
    let config = PoolConfig { export_every: 0, ..test_config() };
    let err =
        Pool::in_process(1, config, |_| cosdem_worker::StandIn::new()).err().expect("refused");
    assert!(err.to_string().contains("export_every = 0"), "{err}");
}
