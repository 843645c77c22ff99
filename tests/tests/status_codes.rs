//! Malformed and over-limit requests get the right status, naming what is wrong.

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_proto::v1 as pb;
use cosdem_worker::{Limits, StandIn, WorkerConfig};
use tonic::Code;

fn gp(e: u32) -> pb::GaussPoint {
    GaussPointId::new(e, 0).into()
}

fn spec(discs: u64) -> Option<pb::AssemblySpec> {
    Some((&common::spec(discs, 1)).into())
}

fn create(ids: Vec<pb::GaussPoint>, discs: u64) -> pb::CreateAssembliesRequest {
    pb::CreateAssembliesRequest { ids, spec: spec(discs) }
}

fn solve(items: Vec<pb::SolveItem>) -> pb::SolveBatchRequest {
    pb::SolveBatchRequest { step: 1, iteration: 0, items, commit: None }
}

#[tokio::test]
async fn bad_kinematics_are_invalid_argument_naming_field_and_value() {
    let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
    let mut c = client(addr).await;
    c.create_assemblies(create(vec![gp(0)], 10)).await.unwrap();

    let mut m = pb::MacroDeformation::from(MacroDeformation::IDENTITY);
    m.k_x = f64::NAN;
    let e = c
        .solve_batch(solve(vec![pb::SolveItem { id: Some(gp(0)), target: Some(m) }]))
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("k_x") && e.message().contains("NaN"), "{}", e.message());
    assert!(e.message().contains("element 0 gauss point 0"), "{}", e.message());

    let mut m = pb::MacroDeformation::from(MacroDeformation::IDENTITY);
    m.f_yy = -0.5;
    let e = c
        .solve_batch(solve(vec![pb::SolveItem { id: Some(gp(0)), target: Some(m) }]))
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("det(F) = -0.5"), "{}", e.message());

    let e = c
        .solve_batch(solve(vec![pb::SolveItem { id: Some(gp(0)), target: None }]))
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("target"), "{}", e.message());

    let item = pb::SolveItem { id: Some(gp(0)), target: Some(MacroDeformation::IDENTITY.into()) };
    let e = c.solve_batch(solve(vec![item, item])).await.unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("twice"), "{}", e.message());
}

#[tokio::test]
async fn unknown_assembly_is_not_found_naming_it() {
    let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
    let mut c = client(addr).await;
    c.create_assemblies(create(vec![gp(0)], 10)).await.unwrap();
    let item = pb::SolveItem { id: Some(gp(7)), target: Some(MacroDeformation::IDENTITY.into()) };
    let e = c.solve_batch(solve(vec![item])).await.unwrap_err();
    assert_eq!(e.code(), Code::NotFound);
    assert!(e.message().contains("element 7 gauss point 0"), "{}", e.message());
    let e = c.export_state(pb::ExportStateRequest { ids: vec![gp(3)] }).await.unwrap_err();
    assert_eq!(e.code(), Code::NotFound);
    let e = c.snapshot(pb::SnapshotRequest { id: Some(gp(3)) }).await.unwrap_err();
    assert_eq!(e.code(), Code::NotFound);
}

#[tokio::test]
async fn bad_spec_and_duplicate_create_are_refused() {
    let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
    let mut c = client(addr).await;
    let bad = pb::AssemblySpec {
        spec_json: br#"{"discs": 10, "colour": "red"}"#.to_vec(),
        ..Default::default()
    };
    let e = c
        .create_assemblies(pb::CreateAssembliesRequest { ids: vec![gp(0)], spec: Some(bad) })
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    assert!(e.message().contains("colour"), "{}", e.message());
    let e = c
        .create_assemblies(pb::CreateAssembliesRequest { ids: vec![gp(0)], spec: None })
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
    c.create_assemblies(create(vec![gp(0)], 10)).await.unwrap();
    let e = c.create_assemblies(create(vec![gp(0)], 10)).await.unwrap_err();
    assert_eq!(e.code(), Code::AlreadyExists);
    let e = c
        .import_state(pb::ImportStateRequest {
            states: vec![pb::AssemblyState {
                id: Some(gp(1)),
                committed_step: 0,
                state: vec![1, 2],
                disc_count: 1,
            }],
        })
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::InvalidArgument);
}

#[tokio::test]
async fn commit_without_a_trial_is_failed_precondition() {
    let addr = start_worker(WorkerConfig::default(), StandIn::new()).await;
    let mut c = client(addr).await;
    c.create_assemblies(create(vec![gp(0)], 10)).await.unwrap();
    let e = c
        .commit(pb::CommitRequest { step: 1, iteration: 0, ids: vec![], export_state: false })
        .await
        .unwrap_err();
    assert_eq!(e.code(), Code::FailedPrecondition);
    assert!(e.message().contains("no trial"), "{}", e.message());
}

#[tokio::test]
async fn over_the_limits_is_resource_exhausted() {
    let limits = Limits { max_assemblies: 3, max_discs: 100, max_message_bytes: 64 * 1024 };
    let addr = start_worker(WorkerConfig { limits, ..Default::default() }, StandIn::new()).await;
    let mut c = client(addr).await;
    let e = c.create_assemblies(create((0..4).map(gp).collect(), 10)).await.unwrap_err();
    assert_eq!(e.code(), Code::ResourceExhausted);
    assert!(e.message().contains("limit of 3"), "{}", e.message());
    let e = c.create_assemblies(create(vec![gp(0), gp(1)], 60)).await.unwrap_err();
    assert_eq!(e.code(), Code::ResourceExhausted);
    assert!(e.message().contains("120 discs"), "{}", e.message());
    // Nothing was created by the refused calls.
    c.create_assemblies(create((0..3).map(gp).collect(), 10)).await.unwrap();
    let h = c.health(pb::HealthRequest {}).await.unwrap().into_inner();
    assert_eq!((h.assemblies, h.discs), (3, 30));

    // An oversized message is refused by the transport before the service (OUT_OF_RANGE is
    // tonic's code for a frame over the limit).
    let big = pb::ImportStateRequest {
        states: vec![pb::AssemblyState {
            id: Some(gp(9)),
            committed_step: 0,
            state: vec![0; 100 * 1024],
            disc_count: 1,
        }],
    };
    let e = c.import_state(big).await.unwrap_err();
    assert_eq!(e.code(), Code::OutOfRange, "{e:?}");
}
