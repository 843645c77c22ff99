//! SIGTERM drains a worker process within its grace period: the call in flight finishes and
//! answers, a new call is answered UNAVAILABLE "worker shutting down" (what the master takes
//! as a lost worker), and the process exits 0; a call still running when the grace period is
//! over does not keep it alive.

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_proto::v1 as pb;
use std::time::{Duration, Instant};
use tonic::Code;

fn sigterm(w: &WorkerProcess) {
    let pid = w.child.id().to_string();
    let status = std::process::Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(status.success());
}

/// Waits at most `limit` for the process to exit; returns how long it took.
fn exit_within(w: &mut WorkerProcess, since: Instant, limit: Duration) -> Duration {
    loop {
        if let Some(code) = w.child.try_wait().unwrap() {
            assert!(code.success(), "exit status {code:?}");
            return since.elapsed();
        }
        assert!(since.elapsed() < limit, "worker still running {limit:?} after SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A SolveBatch of one Gauss point at step 1 on a fresh stand-in assembly, started now.
async fn start_solve(
    c: &mut pb::micro_solver_client::MicroSolverClient<tonic::transport::Channel>,
) -> tonic::Streaming<pb::SolveResult> {
    let id: pb::GaussPoint = GaussPointId::new(0, 0).into();
    let spec = Some((&spec(10, 1)).into());
    c.create_assemblies(pb::CreateAssembliesRequest { ids: vec![id], spec }).await.unwrap();
    let item = pb::SolveItem { id: Some(id), target: Some(MacroDeformation::IDENTITY.into()) };
    let req = pb::SolveBatchRequest { step: 1, iteration: 0, items: vec![item], commit: None };
    c.solve_batch(req).await.unwrap().into_inner()
}

#[test]
fn sigterm_finishes_the_call_in_flight_refuses_new_ones_and_exits() {
    // Every solve takes 2 s; the grace period (5 s) covers it.
    let mut w = WorkerProcess::start(
        &["--hang-after", "0", "--hang-secs", "2", "--grace-period", "5"],
        &[],
    );
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let (answered, refused, t0) = rt.block_on(async {
        let mut c = client(w.addr).await;
        let mut stream = start_solve(&mut c).await;
        tokio::time::sleep(Duration::from_millis(300)).await;
        sigterm(&w);
        let t0 = Instant::now();
        tokio::time::sleep(Duration::from_millis(300)).await;
        let refused = c.health(pb::HealthRequest {}).await.unwrap_err();
        let answered = stream.message().await;
        (answered, refused, t0)
    });
    // The client's connection lives on `rt`: a runtime no longer driven cannot answer the
    // server's graceful-shutdown GOAWAY/PING, so the worker would wait for it to the end of
    // its grace period (5 s), racing this test's 5 s limit. A master's runtime stays driven;
    // here the runtime is dropped, which closes the connection as a departing master would.
    drop(rt);
    assert_eq!(refused.code(), Code::Unavailable, "{refused:?}");
    assert_eq!(refused.message(), cosdem_worker::SHUTTING_DOWN);
    let r = answered.expect("the solve in flight answers").expect("one result");
    assert_eq!(r.id, Some(GaussPointId::new(0, 0).into()));
    let took = exit_within(&mut w, t0, Duration::from_secs(5));
    // The call ends about 1.7 s after SIGTERM; the worker exits then, well before its grace.
    assert!(took < Duration::from_millis(4500), "the worker waited for its grace period: {took:?}");
    assert!(took >= Duration::from_millis(1000), "exited before its call finished: {took:?}");
}

#[test]
fn a_call_longer_than_the_grace_period_does_not_keep_the_worker_alive() {
    // A solve of 60 s, a grace period of 1 s: the worker exits after about 1 s.
    let mut w = WorkerProcess::start(
        &["--hang-after", "0", "--hang-secs", "60", "--grace-period", "1"],
        &[],
    );
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    rt.block_on(async {
        let mut c = client(w.addr).await;
        let _stream = start_solve(&mut c).await;
        tokio::time::sleep(Duration::from_millis(300)).await;
    });
    sigterm(&w);
    let took = exit_within(&mut w, Instant::now(), Duration::from_secs(6));
    assert!(took >= Duration::from_millis(900), "exited before its grace period: {took:?}");
}
