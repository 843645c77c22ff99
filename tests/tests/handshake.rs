//! Handshake: capacity and limits reported; a protocol version mismatch is refused with
//! FAILED_PRECONDITION naming both versions; handshake and health answer while computing.

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_proto::PROTOCOL_VERSION;
use cosdem_proto::v1 as pb;
use cosdem_worker::{Limits, StandIn, StandInOptions, WorkerConfig};
use std::time::{Duration, Instant};
use tonic::Code;

#[tokio::test]
async fn handshake_reports_capacity_and_refuses_other_versions() {
    let limits = Limits { max_assemblies: 7, ..Limits::default() };
    let addr =
        start_worker(WorkerConfig { threads: 2, limits, ..Default::default() }, StandIn::new())
            .await;
    let mut c = client(addr).await;
    let r = c
        .handshake(pb::HandshakeRequest {
            protocol_version: PROTOCOL_VERSION,
            master_build_id: "test".into(),
        })
        .await
        .unwrap()
        .into_inner();
    assert_eq!((r.protocol_version, r.cores, r.max_assemblies), (PROTOCOL_VERSION, 2, 7));
    assert!(r.build_id.starts_with("cosdem-worker"));
    let e = c
        .handshake(pb::HandshakeRequest { protocol_version: 999, master_build_id: "future".into() })
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::FailedPrecondition);
    assert!(
        e.message().contains("999") && e.message().contains(&format!("speaks {PROTOCOL_VERSION}")),
        "{}",
        e.message()
    );
}

#[tokio::test]
async fn handshake_and_health_answer_while_relaxations_run() {
    let model = StandIn::with_options(StandInOptions {
        hang_after_solves: Some(0),
        hang_for: Duration::from_secs(3),
    });
    let addr = start_worker(WorkerConfig { threads: 1, ..Default::default() }, model).await;
    let mut c = client(addr).await;
    let ids: Vec<pb::GaussPoint> = (0..2).map(|e| GaussPointId::new(e, 0).into()).collect();
    c.create_assemblies(pb::CreateAssembliesRequest {
        ids: ids.clone(),
        spec: Some((&spec(10, 1)).into()),
    })
    .await
    .unwrap();
    let items = ids
        .iter()
        .map(|id| pb::SolveItem { id: Some(*id), target: Some(MacroDeformation::IDENTITY.into()) })
        .collect();
    let mut busy = c.clone();
    let solving = tokio::spawn(async move {
        let mut s = busy
            .solve_batch(pb::SolveBatchRequest { step: 1, iteration: 0, items, commit: None })
            .await
            .unwrap()
            .into_inner();
        while s.message().await.unwrap().is_some() {}
    });
    tokio::time::sleep(Duration::from_millis(200)).await;
    let t = Instant::now();
    c.handshake(pb::HandshakeRequest {
        protocol_version: PROTOCOL_VERSION,
        master_build_id: String::new(),
    })
    .await
    .unwrap();
    let h = c.health(pb::HealthRequest {}).await.unwrap().into_inner();
    assert!(h.in_flight >= 1, "{h:?}");
    let channel = tonic::transport::Endpoint::from_shared(format!("http://{addr}"))
        .unwrap()
        .connect()
        .await
        .unwrap();
    let mut probe = tonic_health::pb::health_client::HealthClient::new(channel);
    let s = probe
        .check(tonic_health::pb::HealthCheckRequest { service: "cosdem.v1.MicroSolver".into() })
        .await
        .unwrap()
        .into_inner();
    assert_eq!(s.status(), tonic_health::pb::health_check_response::ServingStatus::Serving);
    assert!(t.elapsed() < Duration::from_secs(2), "answered in {:?}", t.elapsed());
    assert!(!solving.is_finished());
    solving.abort();
}
