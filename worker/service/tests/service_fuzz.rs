//! Property tests: random and hostile RPC requests fed to the worker's service handlers
//! directly (in-process, no transport): sequences of CreateAssemblies, SolveBatch, Commit,
//! Rollback, Export/ImportState, Snapshot, Drop, Health and Handshake with random fields
//! (NaN, inf, huge numbers, det(F) <= 0, unknown or duplicate ids, missing messages, empty
//! or garbage spec_json, huge disc-count hints, corrupted states). Every call must answer:
//! either a reply or a gRPC status with a clear message, never a panic, never INTERNAL or
//! UNKNOWN (those mean a bug), and every streamed response is finite.
//!
//! The real DEM model serves, on small assemblies (14 discs, at most 3 000 relaxation
//! steps), so each sequence takes milliseconds. Deterministic: fixed-seed runner.

use cosdem_proto::PROTOCOL_VERSION;
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::MicroSolver;
use cosdem_worker::{Dem, Limits, WorkerConfig, WorkerService};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tokio_stream::StreamExt;
use tonic::{Code, Request, Status};

fn runner(cases: u32) -> TestRunner {
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

const SMALL: &str = r#"{"packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.04},
                        "relaxation": {"max_steps": 3000}}"#;
const PERIODIC: &str = r#"{"packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.04},
                          "boundary": {"kind": "periodic"}, "relaxation": {"max_steps": 3000}}"#;

fn spec_json() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        4 => Just(SMALL.as_bytes().to_vec()),
        2 => Just(PERIODIC.as_bytes().to_vec()),
        1 => Just(Vec::new()),
        1 => Just(b"{}x".to_vec()),
        1 => Just(b"null".to_vec()),
        1 => Just(br#"{"packing": {"kind": "hexagonal", "radius": 1e-9, "side": 1e3}}"#.to_vec()),
        1 => Just(br#"{"packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.04},
                      "contact": {"normal": {"model": "linear", "k_n": 1e300}}}"#.to_vec()),
        1 => Just(br#"{"relaxation": {"max_steps": 18446744073709551615}}"#.to_vec()),
        1 => prop::collection::vec(any::<u8>(), 0..64),
    ]
}

/// Ids from a small range, so that creations collide and lookups sometimes miss.
fn id() -> impl Strategy<Value = pb::GaussPoint> {
    prop_oneof![
        4 => (0u32..3, 0u32..2).prop_map(|(element, point)| pb::GaussPoint { element, point }),
        1 => any::<(u32, u32)>().prop_map(|(element, point)| pb::GaussPoint { element, point }),
    ]
}

fn ids() -> impl Strategy<Value = Vec<pb::GaussPoint>> {
    prop::collection::vec(id(), 0..4)
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -2e-3f64..2e-3,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(1e300),
        1 => Just(-1.0),
        1 => Just(1e-300),
        1 => any::<f64>(),
    ]
}

/// Mostly near the identity, sometimes hostile in any component.
fn target() -> impl Strategy<Value = pb::MacroDeformation> {
    (prop::array::uniform4(number()), number(), number(), number()).prop_map(|(f, w, kx, ky)| {
        pb::MacroDeformation {
            f_xx: 1.0 + f[0],
            f_xy: f[1],
            f_yx: f[2],
            f_yy: 1.0 + f[3],
            w,
            k_x: kx,
            k_y: ky,
        }
    })
}

fn step() -> impl Strategy<Value = u64> {
    prop_oneof![4 => 1u64..4, 1 => Just(0), 1 => Just(u64::MAX)]
}

#[derive(Clone, Debug)]
enum Op {
    Handshake(u32),
    Create {
        ids: Vec<pb::GaussPoint>,
        spec: Option<(Vec<u8>, i32, u64)>,
    },
    Solve {
        step: u64,
        iteration: u32,
        items: Vec<(Option<pb::GaussPoint>, Option<pb::MacroDeformation>)>,
        /// A commit carried on the batch: (step, iteration, ids, export).
        commit: Option<(u64, u32, Vec<pb::GaussPoint>, bool)>,
    },
    Commit {
        step: u64,
        iteration: u32,
        ids: Vec<pb::GaussPoint>,
        export: bool,
    },
    Rollback(Vec<pb::GaussPoint>),
    Export(Vec<pb::GaussPoint>),
    /// Export, corrupt (`edit` = (position, byte, truncate?)), import under `id`.
    Reimport {
        id: Option<pb::GaussPoint>,
        edit: Option<(usize, u8, bool)>,
        garbage: bool,
    },
    Snapshot(Option<pb::GaussPoint>),
    Drop(Vec<pb::GaussPoint>),
    Health,
}

fn op() -> impl Strategy<Value = Op> {
    let hint = prop_oneof![Just(0u64), Just(14), Just(u64::MAX), any::<u64>()];
    let boundary = prop_oneof![Just(0i32), Just(1), Just(2), any::<i32>()];
    prop_oneof![
        1 => prop_oneof![Just(PROTOCOL_VERSION), any::<u32>()].prop_map(Op::Handshake),
        4 => (ids(), prop::option::weighted(0.9, (spec_json(), boundary, hint)))
            .prop_map(|(ids, spec)| Op::Create { ids, spec }),
        5 => (
            step(),
            prop_oneof![Just(0u32), any::<u32>()],
            prop::collection::vec(
                (prop::option::weighted(0.9, id()), prop::option::weighted(0.9, target())),
                0..4
            ),
            prop::option::weighted(
                0.3,
                (step(), prop_oneof![Just(0u32), any::<u32>()], ids(), prop::bool::weighted(0.1))
            )
        )
            .prop_map(|(step, iteration, items, commit)| Op::Solve {
                step,
                iteration,
                items,
                commit
            }),
        3 => (step(), prop_oneof![Just(0u32), any::<u32>()], ids(), any::<bool>())
            .prop_map(|(step, iteration, ids, export)| Op::Commit { step, iteration, ids, export }),
        1 => ids().prop_map(Op::Rollback),
        1 => ids().prop_map(Op::Export),
        2 => (
            prop::option::weighted(0.9, id()),
            prop::option::of((any::<usize>(), any::<u8>(), any::<bool>())),
            prop::bool::weighted(0.2)
        )
            .prop_map(|(id, edit, garbage)| Op::Reimport { id, edit, garbage }),
        1 => prop::option::weighted(0.9, id()).prop_map(Op::Snapshot),
        1 => ids().prop_map(Op::Drop),
        1 => Just(Op::Health),
    ]
}

/// A status is acceptable when it is a client-side code with a message.
fn check_status(what: &str, s: &Status) -> Result<(), TestCaseError> {
    prop_assert!(!s.message().is_empty(), "{what}: empty message ({:?})", s.code());
    prop_assert!(
        !matches!(s.code(), Code::Internal | Code::Unknown),
        "{what}: {:?} {}",
        s.code(),
        s.message()
    );
    Ok(())
}

fn check<T>(what: &str, r: Result<tonic::Response<T>, Status>) -> Result<Option<T>, TestCaseError> {
    match r {
        Ok(r) => Ok(Some(r.into_inner())),
        Err(s) => {
            check_status(what, &s)?;
            Ok(None)
        }
    }
}

async fn apply(svc: &WorkerService<Dem>, op: Op) -> Result<(), TestCaseError> {
    match op {
        Op::Handshake(v) => {
            let req = pb::HandshakeRequest { protocol_version: v, master_build_id: "fuzz".into() };
            check("Handshake", svc.handshake(Request::new(req)).await)?;
        }
        Op::Create { ids, spec } => {
            let spec = spec.map(|(spec_json, boundary, disc_count_hint)| pb::AssemblySpec {
                spec_json,
                boundary,
                disc_count_hint,
            });
            let req = pb::CreateAssembliesRequest { ids, spec };
            check("CreateAssemblies", svc.create_assemblies(Request::new(req)).await)?;
        }
        Op::Solve { step, iteration, items, commit } => {
            let items = items
                .into_iter()
                .map(|(id, target)| pb::SolveItem { id, target })
                .collect::<Vec<_>>();
            let n = items.len();
            let commit = commit.map(|(step, iteration, ids, export_state)| pb::CommitRequest {
                step,
                iteration,
                ids,
                export_state,
            });
            let req = pb::SolveBatchRequest { step, iteration, items, commit };
            if let Some(mut stream) = check("SolveBatch", svc.solve_batch(Request::new(req)).await)?
            {
                let mut got = 0;
                while let Some(item) = stream.next().await {
                    let r = item.map_err(|s| TestCaseError::fail(format!("stream: {s:?}")))?;
                    got += 1;
                    prop_assert!(r.id.is_some());
                    match r.outcome {
                        Some(pb::solve_result::Outcome::Response(resp)) => {
                            prop_assert!(resp.stress.len() == 6 && resp.tangent.len() == 36);
                            prop_assert!(
                                resp.stress.iter().chain(&resp.tangent).all(|v| v.is_finite()),
                                "non-finite response {resp:?}"
                            );
                        }
                        Some(pb::solve_result::Outcome::Error(e)) => prop_assert!(!e.is_empty()),
                        None => prop_assert!(false, "result without outcome"),
                    }
                }
                prop_assert_eq!(got, n, "every item answers once");
            }
        }
        Op::Commit { step, iteration, ids, export } => {
            let req = pb::CommitRequest { step, iteration, ids, export_state: export };
            check("Commit", svc.commit(Request::new(req)).await)?;
        }
        Op::Rollback(ids) => {
            check("Rollback", svc.rollback(Request::new(pb::RollbackRequest { ids })).await)?;
        }
        Op::Export(ids) => {
            let req = pb::ExportStateRequest { ids };
            check("ExportState", svc.export_state(Request::new(req)).await)?;
        }
        Op::Reimport { id, edit, garbage } => {
            let req = pb::ExportStateRequest { ids: vec![] };
            let states = check("ExportState", svc.export_state(Request::new(req)).await)?
                .map(|r| r.states)
                .unwrap_or_default();
            let mut bytes = states.first().map(|s| s.state.clone()).unwrap_or_default();
            if garbage {
                bytes = b"CDEMASM1\xff\xff\xff\xff\xff\xff\xff\x7f".to_vec();
            }
            if let Some((pos, byte, truncate)) = edit
                && !bytes.is_empty()
            {
                let p = pos % bytes.len();
                if truncate {
                    bytes.truncate(p);
                } else {
                    bytes[p] ^= byte;
                }
            }
            let state =
                pb::AssemblyState { id, committed_step: 0, state: bytes, disc_count: u64::MAX };
            let req = pb::ImportStateRequest { states: vec![state] };
            check("ImportState", svc.import_state(Request::new(req)).await)?;
        }
        Op::Snapshot(id) => {
            check("Snapshot", svc.snapshot(Request::new(pb::SnapshotRequest { id })).await)?;
        }
        Op::Drop(ids) => {
            check("Drop", svc.drop(Request::new(pb::DropRequest { ids })).await)?;
        }
        Op::Health => {
            check("Health", svc.health(Request::new(pb::HealthRequest {})).await)?;
        }
    }
    Ok(())
}

/// Random sequences of calls on a fresh worker with limits (64 assemblies, 10 000 discs).
#[test]
fn hostile_request_sequences_get_replies_or_clear_statuses() {
    let rt =
        tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
    let config = WorkerConfig {
        threads: 1,
        limits: Limits { max_assemblies: 64, max_discs: 10_000, ..Limits::default() },
        ..WorkerConfig::default()
    };
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let solved = std::sync::atomic::AtomicUsize::new(0);
    runner(256)
        .run(&prop::collection::vec(op(), 1..10), |ops| {
            calls.fetch_add(ops.len(), std::sync::atomic::Ordering::Relaxed);
            solved.fetch_add(
                ops.iter().filter(|o| matches!(o, Op::Solve { .. })).count(),
                std::sync::atomic::Ordering::Relaxed,
            );
            let svc = WorkerService::new(Dem, config.clone()).unwrap();
            rt.block_on(async {
                for op in ops {
                    apply(&svc, op).await?;
                }
                Ok(())
            })
        })
        .unwrap();
    eprintln!("{calls:?} calls, {solved:?} SolveBatch");
}

/// The statuses of the hostile single requests are the documented ones, and name the
/// problem.
#[test]
fn hostile_requests_have_the_documented_statuses() {
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build().unwrap();
    let config = WorkerConfig {
        threads: 1,
        limits: Limits { max_assemblies: 8, max_discs: 1_000, ..Limits::default() },
        ..WorkerConfig::default()
    };
    let svc = WorkerService::new(Dem, config).unwrap();
    let gp = |e| pb::GaussPoint { element: e, point: 0 };
    let create = |ids: Vec<pb::GaussPoint>, json: &[u8], hint: u64| pb::CreateAssembliesRequest {
        ids,
        spec: Some(pb::AssemblySpec {
            spec_json: json.to_vec(),
            boundary: 0,
            disc_count_hint: hint,
        }),
    };
    rt.block_on(async {
        let expect = |r: Result<(), Status>, code: Code, needle: &str| {
            let s = r.expect_err(needle);
            assert_eq!(s.code(), code, "{}", s.message());
            assert!(s.message().contains(needle), "`{needle}` not in: {}", s.message());
        };
        let c = |req| async { svc.create_assemblies(Request::new(req)).await.map(|_| ()) };
        expect(c(create(vec![gp(0)], b"", 0)).await, Code::InvalidArgument, "EOF");
        expect(
            c(create(vec![gp(0)], b"{\"densty\": 1}", 0)).await,
            Code::InvalidArgument,
            "densty",
        );
        let huge = br#"{"packing": {"kind": "hexagonal", "radius": 1e-9, "side": 1e3}}"#;
        expect(c(create(vec![gp(0)], huge, 0)).await, Code::InvalidArgument, "packing.side");
        expect(
            c(create(vec![gp(0), gp(1)], SMALL.as_bytes(), u64::MAX)).await,
            Code::ResourceExhausted,
            "discs",
        );
        expect(
            c(create(vec![gp(0), gp(0)], SMALL.as_bytes(), 0)).await,
            Code::InvalidArgument,
            "twice",
        );
        let none = pb::CreateAssembliesRequest { ids: vec![gp(0)], spec: None };
        expect(c(none).await, Code::InvalidArgument, "spec");
        c(create(vec![gp(0)], SMALL.as_bytes(), 14)).await.unwrap();
        expect(c(create(vec![gp(0)], SMALL.as_bytes(), 14)).await, Code::AlreadyExists, "exists");

        let solve = |items: Vec<pb::SolveItem>| async {
            svc.solve_batch(Request::new(pb::SolveBatchRequest {
                step: 1,
                iteration: 0,
                items,
                commit: None,
            }))
            .await
            .map(|_| ())
        };
        let ident = pb::MacroDeformation { f_xx: 1.0, f_yy: 1.0, ..Default::default() };
        let item = |id, t| pb::SolveItem { id: Some(id), target: Some(t) };
        let nan = pb::MacroDeformation { k_y: f64::NAN, ..ident };
        expect(solve(vec![item(gp(0), nan)]).await, Code::InvalidArgument, "k_y");
        let inv = pb::MacroDeformation { f_xx: -1.0, ..ident };
        expect(solve(vec![item(gp(0), inv)]).await, Code::InvalidArgument, "det(F)");
        let inf = pb::MacroDeformation { f_xy: f64::INFINITY, ..ident };
        expect(solve(vec![item(gp(0), inf)]).await, Code::InvalidArgument, "F_xy");
        expect(solve(vec![item(gp(7), ident)]).await, Code::NotFound, "element 7");
        let missing = pb::SolveItem { id: Some(gp(0)), target: None };
        expect(solve(vec![missing]).await, Code::InvalidArgument, "target");

        let import = |bytes: Vec<u8>| async {
            let s = pb::AssemblyState {
                id: Some(gp(5)),
                committed_step: 0,
                state: bytes,
                disc_count: 0,
            };
            svc.import_state(Request::new(pb::ImportStateRequest { states: vec![s] }))
                .await
                .map(|_| ())
        };
        expect(import(b"garbage".to_vec()).await, Code::InvalidArgument, "header");
        let snap = svc.snapshot(Request::new(pb::SnapshotRequest { id: None })).await.map(|_| ());
        expect(snap, Code::InvalidArgument, "id");
        let hs = pb::HandshakeRequest { protocol_version: 999, master_build_id: String::new() };
        expect(svc.handshake(Request::new(hs)).await.map(|_| ()), Code::FailedPrecondition, "999");
    });
}
