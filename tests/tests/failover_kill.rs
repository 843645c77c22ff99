//! A worker process killed with SIGKILL in the middle of a step (between Newton iterations,
//! and between the last iteration and the commit): the job completes, bit-identical.

mod common;
use common::*;
use cosdem_pool::PoolConfig;

/// Kills worker 0 mid-step 2 and worker 1 after step 4's last iteration.
fn kill_two(config: PoolConfig) {
    let reference = reference(100, 20);
    let (mut procs, mut pool) = process_pool(3, config);
    create(&mut pool, 100, 20);
    let trace = run_program(&mut pool, &mut |step, iteration| {
        // Mid-step: the next evaluation finds worker 0 gone.
        if (step, iteration) == (2, 1) {
            procs[0].kill();
        }
        // After the last iteration of step 4: with commit calls, the commit finds worker 1
        // gone and its points are re-solved from their stored states elsewhere and
        // committed there; with carried commits, step 5's batch finds it gone and the
        // restore replays the held commit from the history.
        if (step, iteration) == (4, 2) {
            procs[1].kill();
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 2, "{stats:?}");
    assert!(stats.restored > 0 && stats.resolved > 0, "{stats:?}");
    assert_eq!(pool.live_workers(), 1);
}

#[test]
fn killed_workers_are_replaced_and_results_are_bit_identical() {
    kill_two(test_config());
}

#[test]
fn killed_workers_are_replaced_with_commit_calls() {
    kill_two(PoolConfig { defer_commits: false, ..test_config() });
}

#[test]
fn a_killed_worker_during_a_batch_is_replaced() {
    // Slow solves (about 10 ms each) so that the kill lands while the batch is running.
    let reference = reference(1000, 1000);
    let (mut procs, mut pool) = process_pool(2, test_config());
    create(&mut pool, 1000, 1000);
    let mut victim = Some(procs.remove(1));
    let trace = run_program(&mut pool, &mut |step, iteration| {
        if (step, iteration) == (2, 0)
            && let Some(mut p) = victim.take()
        {
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis(15));
                p.kill();
            });
        }
    });
    assert_identical(&reference, &trace);
    assert_eq!(pool.stats().workers_lost, 1);
}
