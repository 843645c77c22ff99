//! Retries are harmless: the same SolveBatch returns the same answer, Commit twice never
//! commits twice, and solving again after a rollback is deterministic.

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_proto::v1 as pb;
use cosdem_worker::{StandIn, WorkerConfig};

async fn solve(
    c: &mut cosdem_proto::v1::micro_solver_client::MicroSolverClient<tonic::transport::Channel>,
    step: u64,
    iteration: u32,
    e: f64,
) -> Vec<pb::SolveResult> {
    let ids: Vec<pb::GaussPoint> = (0..3).map(|k| GaussPointId::new(k, 0).into()).collect();
    let items = ids
        .iter()
        .map(|id| pb::SolveItem {
            id: Some(*id),
            target: Some(MacroDeformation::from_strain(&[e, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0).into()),
        })
        .collect();
    let mut s = c
        .solve_batch(pb::SolveBatchRequest { step, iteration, items, commit: None })
        .await
        .unwrap()
        .into_inner();
    let mut out = Vec::new();
    while let Some(r) = s.message().await.unwrap() {
        out.push(r);
    }
    out.sort_by_key(|r| r.id.unwrap().element);
    out
}

#[tokio::test]
async fn solve_batch_and_commit_retries_are_idempotent() {
    let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
    let mut c = client(addr).await;
    let ids: Vec<pb::GaussPoint> = (0..3).map(|k| GaussPointId::new(k, 0).into()).collect();
    c.create_assemblies(pb::CreateAssembliesRequest { ids, spec: Some((&spec(50, 5)).into()) })
        .await
        .unwrap();

    // The same trial twice: the very same answer, wall time included (it is the cache).
    let a = solve(&mut c, 1, 0, 0.01).await;
    let b = solve(&mut c, 1, 0, 0.01).await;
    assert_eq!(a, b);
    // Rollback then solve again: deterministic from the committed state.
    c.rollback(pb::RollbackRequest { ids: vec![] }).await.unwrap();
    let again_raw = solve(&mut c, 1, 0, 0.01).await;
    let mut again = again_raw.clone();
    let mut a2 = a.clone();
    for r in again.iter_mut().chain(a2.iter_mut()) {
        if let Some(pb::solve_result::Outcome::Response(resp)) = &mut r.outcome {
            resp.diagnostics.as_mut().unwrap().wall_seconds = 0.0;
        }
    }
    assert_eq!(a2, again);

    let first = c
        .commit(pb::CommitRequest { step: 1, iteration: 0, ids: vec![], export_state: true })
        .await
        .unwrap()
        .into_inner();
    assert_eq!((first.committed, first.already_committed), (3, 0));
    let second = c
        .commit(pb::CommitRequest { step: 1, iteration: 0, ids: vec![], export_state: true })
        .await
        .unwrap()
        .into_inner();
    assert_eq!((second.committed, second.already_committed), (0, 3));
    assert_eq!(first.states, second.states, "no double commit: the state did not move");
    assert!(first.states.iter().all(|s| s.committed_step == 1));

    // A retry of the committed trial still gets its cached answer.
    assert_eq!(solve(&mut c, 1, 0, 0.01).await, again_raw);
    let _ = b;
    // The committed damage shows: the same small strain now meets a softer material.
    let before = solve(&mut c, 2, 0, 0.0005).await;
    let fresh = {
        let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
        let mut f = client(addr).await;
        let ids: Vec<pb::GaussPoint> = (0..3).map(|k| GaussPointId::new(k, 0).into()).collect();
        f.create_assemblies(pb::CreateAssembliesRequest { ids, spec: Some((&spec(50, 5)).into()) })
            .await
            .unwrap();
        solve(&mut f, 1, 0, 0.0005).await
    };
    let s = |r: &pb::SolveResult| match &r.outcome {
        Some(pb::solve_result::Outcome::Response(x)) => x.stress[0],
        _ => panic!("failed"),
    };
    assert!(s(&before[0]) < s(&fresh[0]));
}

#[test]
fn pool_commit_twice_is_a_no_op() {
    use cosdem_fem::material::{Material, MaterialInput, TrialId};
    // Export at every commit, so that the stored states show the commit.
    let config = cosdem_pool::PoolConfig { export_every: 1, ..test_config() };
    let mut pool = standin_pool(2, config);
    create(&mut pool, 10, 1);
    let inputs: Vec<_> = gauss_points()
        .into_iter()
        .map(|gp| MaterialInput {
            gauss_point: gp,
            deformation: MacroDeformation::from_strain(&[0.01, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0),
        })
        .collect();
    pool.evaluate(TrialId { step: 1, iteration: 0 }, &inputs).unwrap();
    pool.commit(1).unwrap();
    let states = pool.committed_states().clone();
    pool.commit(1).unwrap();
    assert_eq!(&states, pool.committed_states());
    assert!(states.values().all(|s| s.committed_step == 1));
}
