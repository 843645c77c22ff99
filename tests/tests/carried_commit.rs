//! A commit carried on the next SolveBatch (protocol 2, `PoolConfig::defer_commits`) is the
//! same commit: the worker applies it before the batch relaxes, a retry does not apply it
//! twice, a bad one is refused with the right status, and a pool that carries its commits
//! gives bit-identical results to one that sends every commit as a call, also when a worker
//! dies while holding a commit that was never sent.

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_pool::PoolConfig;
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_client::MicroSolverClient;
use cosdem_worker::{StandIn, WorkerConfig};
use tonic::Code;
use tonic::transport::Channel;

fn ids() -> Vec<pb::GaussPoint> {
    (0..3).map(|k| GaussPointId::new(k, 0).into()).collect()
}

fn commit(step: u64, export_state: bool) -> pb::CommitRequest {
    pb::CommitRequest { step, iteration: 0, ids: ids(), export_state }
}

/// Solves the three assemblies at strain `e` (step, iteration 0), with an optional carried
/// commit; the results sorted, wall times zeroed.
async fn solve(
    c: &mut MicroSolverClient<Channel>,
    step: u64,
    e: f64,
    carried: Option<pb::CommitRequest>,
) -> Result<Vec<pb::SolveResult>, tonic::Status> {
    let target = MacroDeformation::from_strain(&[e, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0);
    let items =
        ids().into_iter().map(|id| pb::SolveItem { id: Some(id), target: Some(target.into()) });
    let req = pb::SolveBatchRequest { step, iteration: 0, items: items.collect(), commit: carried };
    let mut s = c.solve_batch(req).await?.into_inner();
    let mut out = Vec::new();
    while let Some(mut r) = s.message().await? {
        if let Some(pb::solve_result::Outcome::Response(resp)) = &mut r.outcome {
            resp.diagnostics.as_mut().unwrap().wall_seconds = 0.0;
        }
        out.push(r);
    }
    out.sort_by_key(|r| r.id.unwrap().element);
    Ok(out)
}

async fn worker() -> MicroSolverClient<Channel> {
    let mut c = client(start_worker(WorkerConfig::default(), StandIn::new()).await).await;
    c.create_assemblies(pb::CreateAssembliesRequest {
        ids: ids(),
        spec: Some((&spec(50, 5)).into()),
    })
    .await
    .unwrap();
    c
}

#[tokio::test]
async fn a_carried_commit_is_the_commit_call() {
    // Worker a commits step 1 with a call; worker b carries the commit on step 2's batch.
    // The stand-in's damage makes step 2 depend on what was committed, so a commit b
    // skipped or applied after relaxing would change its step-2 answer.
    let (mut a, mut b) = (worker().await, worker().await);
    let first_a = solve(&mut a, 1, 0.01, None).await.unwrap();
    let first_b = solve(&mut b, 1, 0.01, None).await.unwrap();
    assert_eq!(first_a, first_b);
    a.commit(commit(1, false)).await.unwrap();
    let second_a = solve(&mut a, 2, 0.0005, None).await.unwrap();
    let second_b = solve(&mut b, 2, 0.0005, Some(commit(1, false))).await.unwrap();
    assert_eq!(second_a, second_b, "the carried commit was applied before relaxing");
    // Against a worker that never committed: step 2 differs (the test can fail).
    let mut fresh = worker().await;
    let uncommitted = solve(&mut fresh, 2, 0.0005, None).await.unwrap();
    assert_ne!(uncommitted, second_b, "the committed damage shows in step 2");

    // A retry of the same batch with the same carried commit: the cached answer, no second
    // commit (step 1 is already committed, so it is skipped).
    assert_eq!(solve(&mut b, 2, 0.0005, Some(commit(1, false))).await.unwrap(), second_b);
    let sa = a.export_state(pb::ExportStateRequest { ids: ids() }).await.unwrap().into_inner();
    let sb = b.export_state(pb::ExportStateRequest { ids: ids() }).await.unwrap().into_inner();
    assert_eq!(sa, sb, "the same committed states");
    assert!(sb.states.iter().all(|s| s.committed_step == 1));
}

#[tokio::test]
async fn a_bad_carried_commit_is_refused_before_any_relaxation() {
    let mut c = worker().await;
    solve(&mut c, 1, 0.01, None).await.unwrap();
    // Exporting is for the Commit call only (a SolveBatch has nowhere to return states).
    let e = solve(&mut c, 2, 0.0005, Some(commit(1, true))).await.unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument, "{e:?}");
    assert!(e.message().contains("commit"), "{}", e.message());
    // A commit of a step that was never solved.
    let e = solve(&mut c, 2, 0.0005, Some(commit(7, false))).await.unwrap_err();
    assert_eq!(e.code(), Code::FailedPrecondition, "{e:?}");
    assert!(e.message().contains("step 7"), "{}", e.message());
    // An unknown Gauss point in the carried commit.
    let mut bad = commit(1, false);
    bad.ids.push(GaussPointId::new(99, 0).into());
    let e = solve(&mut c, 2, 0.0005, Some(bad)).await.unwrap_err();
    assert_eq!(e.code(), Code::NotFound, "{e:?}");
    // Nothing of the refused batches happened: step 1's trial still commits.
    let r = c.commit(commit(1, false)).await.unwrap().into_inner();
    assert_eq!((r.committed, r.already_committed), (3, 0));
}

/// No rebalancing: a migration sends the held commits as calls first, and timing noise
/// must not change the count below.
fn config(defer_commits: bool) -> PoolConfig {
    PoolConfig { defer_commits, rebalance_threshold: f64::INFINITY, ..test_config() }
}

/// Also the two in-process transports: the service called directly (the default) and the
/// in-memory HTTP/2 connection (`in_process_duplex`).
#[test]
fn carried_commits_give_bit_identical_runs() {
    let run = |defer: bool, workers: usize, duplex: bool| {
        let c = PoolConfig { in_process_duplex: duplex, ..config(defer) };
        let mut pool = standin_pool(workers, c);
        create(&mut pool, 100, 20);
        let trace = run_program(&mut pool, &mut |_, _| {});
        (trace, pool.stats())
    };
    let (calls, calls_stats) = run(false, 1, true);
    assert_eq!(calls_stats.carried_commits, 0, "{calls_stats:?}");
    for (workers, duplex) in [(1, false), (3, false), (2, true)] {
        let (carried, stats) = run(true, workers, duplex);
        assert_identical(&calls, &carried);
        // 6 steps, none exporting (export_every 10): steps 1-5 ride on the next step's
        // first batch, step 6 has no next batch (held until a call needs it): 5 per worker.
        assert_eq!(stats.carried_commits, 5 * workers as u64, "{stats:?}");
    }
}

#[test]
fn a_worker_killed_while_holding_an_unsent_commit_is_restored_identically() {
    let reference = reference(100, 20);
    let (mut procs, mut pool) = process_pool(2, config(true));
    create(&mut pool, 100, 20);
    let mut killed = false;
    let trace = run_program(&mut pool, &mut |step, iteration| {
        // After step 4's last iteration: its commit is held back for worker 0's next batch;
        // worker 0 dies before that batch, so step 5 finds it gone and restores its
        // assemblies from the master's history, which holds the unsent commit.
        if (step, iteration) == (4, 2) && !killed {
            procs[0].kill();
            killed = true;
        }
    });
    assert_identical(&reference, &trace);
    let stats = pool.stats();
    assert_eq!(stats.workers_lost, 1, "{stats:?}");
    assert!(stats.restored > 0 && stats.replayed > 0, "{stats:?}");
}
