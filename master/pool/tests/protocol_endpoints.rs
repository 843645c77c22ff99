//! The worker endpoints a pool is given: an endpoint that is not a cosdem worker (garbage, an
//! HTTP/1 server) is skipped with a warning while good workers are listed; an address of no
//! `host:port` form is an error naming it; a worker of another protocol version is refused
//! naming both versions; a peer's text (its build id, its status messages) reaches the
//! master's messages without newlines or ANSI escapes. Loopback only, deadlines of seconds.

use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_pool::{Pool, PoolConfig, PoolError};
use cosdem_proto::PROTOCOL_VERSION;
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::{MicroSolver, MicroSolverServer};
use cosdem_worker::{StandIn, WorkerConfig, WorkerService};
use std::net::SocketAddr;
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tonic::{Code, Request, Response, Status};

fn config() -> PoolConfig {
    PoolConfig {
        connect_timeout: Duration::from_secs(3),
        call_timeout: Duration::from_secs(5),
        solve_timeout: Duration::from_secs(5),
        ..PoolConfig::default()
    }
}

/// Servers on loopback, on a runtime of their own (the pool blocks on its own).
struct Servers(tokio::runtime::Runtime);

impl Servers {
    fn new() -> Self {
        Servers(
            tokio::runtime::Builder::new_multi_thread()
                .worker_threads(1)
                .enable_all()
                .build()
                .unwrap(),
        )
    }

    /// A real (stand-in) worker.
    fn worker(&self) -> SocketAddr {
        self.0.block_on(async {
            let config = WorkerConfig::default();
            let listener = cosdem_worker::bind(&config).await.unwrap();
            let addr = listener.local_addr().unwrap();
            tokio::spawn(cosdem_worker::serve_listener(
                listener,
                config,
                StandIn::new(),
                std::future::pending(),
            ));
            addr
        })
    }

    /// A TCP listener that reads what comes and answers `answer`, then hangs up.
    fn garbage(&self, answer: &'static [u8]) -> SocketAddr {
        self.0.block_on(async {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            let addr = listener.local_addr().unwrap();
            tokio::spawn(async move {
                while let Ok((mut s, _)) = listener.accept().await {
                    tokio::spawn(async move {
                        let mut buf = [0u8; 1024];
                        let _ =
                            tokio::time::timeout(Duration::from_secs(1), s.read(&mut buf)).await;
                        let _ = s.write_all(answer).await;
                        let _ = s.shutdown().await;
                    });
                }
            });
            addr
        })
    }

    /// A worker whose handshake says `version` and `build_id`, and whose CreateAssemblies
    /// fails with `create_error` (if any); every other call is a real stand-in worker's.
    fn fake(&self, version: u32, build_id: &str, create_error: Option<&str>) -> SocketAddr {
        let fake = Fake {
            inner: WorkerService::new(StandIn::new(), WorkerConfig::default()).unwrap(),
            version,
            build_id: build_id.into(),
            create_error: create_error.map(Into::into),
        };
        self.0.block_on(async {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            let addr = listener.local_addr().unwrap();
            let incoming = tonic::transport::server::TcpIncoming::from(listener);
            tokio::spawn(
                tonic::transport::Server::builder()
                    .add_service(MicroSolverServer::new(fake))
                    .serve_with_incoming(incoming),
            );
            addr
        })
    }
}

struct Fake {
    inner: WorkerService<StandIn>,
    version: u32,
    build_id: String,
    create_error: Option<String>,
}

#[tonic::async_trait]
impl MicroSolver for Fake {
    async fn handshake(
        &self,
        r: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        let mut reply = self.inner.handshake(r).await?.into_inner();
        reply.protocol_version = self.version;
        reply.build_id = self.build_id.clone();
        Ok(Response::new(reply))
    }
    async fn create_assemblies(
        &self,
        r: Request<pb::CreateAssembliesRequest>,
    ) -> Result<Response<pb::CreateAssembliesReply>, Status> {
        match &self.create_error {
            Some(e) => Err(Status::invalid_argument(e.clone())),
            None => self.inner.create_assemblies(r).await,
        }
    }
    type SolveBatchStream = <WorkerService<StandIn> as MicroSolver>::SolveBatchStream;
    async fn solve_batch(
        &self,
        r: Request<pb::SolveBatchRequest>,
    ) -> Result<Response<Self::SolveBatchStream>, Status> {
        self.inner.solve_batch(r).await
    }
    async fn commit(
        &self,
        r: Request<pb::CommitRequest>,
    ) -> Result<Response<pb::CommitReply>, Status> {
        self.inner.commit(r).await
    }
    async fn rollback(
        &self,
        r: Request<pb::RollbackRequest>,
    ) -> Result<Response<pb::RollbackReply>, Status> {
        self.inner.rollback(r).await
    }
    async fn export_state(
        &self,
        r: Request<pb::ExportStateRequest>,
    ) -> Result<Response<pb::ExportStateReply>, Status> {
        self.inner.export_state(r).await
    }
    async fn import_state(
        &self,
        r: Request<pb::ImportStateRequest>,
    ) -> Result<Response<pb::ImportStateReply>, Status> {
        self.inner.import_state(r).await
    }
    async fn snapshot(
        &self,
        r: Request<pb::SnapshotRequest>,
    ) -> Result<Response<pb::SnapshotReply>, Status> {
        self.inner.snapshot(r).await
    }
    async fn health(
        &self,
        r: Request<pb::HealthRequest>,
    ) -> Result<Response<pb::HealthReply>, Status> {
        self.inner.health(r).await
    }
    async fn drop(&self, r: Request<pb::DropRequest>) -> Result<Response<pb::DropReply>, Status> {
        MicroSolver::drop(&self.inner, r).await
    }
}

fn spec() -> AssemblyRequest {
    AssemblyRequest {
        spec_json: br#"{"discs": 10, "work_per_disc": 1}"#.to_vec(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: 10,
    }
}

const HTTP1: &[u8] =
    b"HTTP/1.1 400 Bad Request\r\ncontent-length: 11\r\nconnection: close\r\n\r\nBad Request";
const GARBAGE: &[u8] = b"\x00\x17SSH-2.0-OpenSSH_9.6 not a worker\r\n\xff\xfe garbage garbage";

/// An endpoint that answers garbage, or plain HTTP/1, among good workers: skipped (it made
/// the whole run fail with `h2 protocol error`); the pool runs on the good ones. Alone, it is
/// an error naming its address.
#[test]
fn an_endpoint_that_is_not_a_worker_is_skipped() {
    let servers = Servers::new();
    let good = servers.worker().to_string();
    let garbage = servers.garbage(GARBAGE).to_string();
    let http = servers.garbage(HTTP1).to_string();
    let list = vec![garbage.clone(), good.clone(), http.clone()];
    let mut pool = Pool::connect(&list, config()).unwrap();
    assert_eq!(pool.live_workers(), 1);
    assert_eq!(pool.workers()[0].0, good);
    let ids: Vec<_> = (0..3).map(|e| GaussPointId::new(e, 0)).collect();
    pool.create_assemblies(&ids, &spec()).unwrap();
    drop(pool);
    for bad in [garbage, http] {
        let Err(e) = Pool::connect(std::slice::from_ref(&bad), config()) else {
            panic!("a pool with no worker at {bad}");
        };
        assert!(matches!(&e, PoolError::Refused { worker, .. } if *worker == bad), "{e}");
    }
}

/// An address that is no `host:port` is refused by name before anything is looked up (it
/// read "none of [...] answered").
#[test]
fn an_unparsable_address_is_an_error_naming_it() {
    for bad in ["host:notaport", ":::", "", "localhost", ":7700", "a b:7700", "::1:7700", "h:99999"]
    {
        let list = vec![bad.to_string()];
        let Err(e) = Pool::connect(&list, config()) else {
            panic!("{bad:?} accepted");
        };
        let m = e.to_string();
        assert!(matches!(e, PoolError::Config(_)), "{bad:?}: {m}");
        assert!(m.contains(&format!("{bad:?}")) && m.contains("host:port"), "{bad:?}: {m}");
    }
}

/// A worker that reports another protocol version is refused, naming both versions, however
/// well the rest of its handshake went (it was ignored).
#[test]
fn another_protocol_version_is_refused_naming_both() {
    let servers = Servers::new();
    let addr = servers.fake(PROTOCOL_VERSION + 7, "cosdem-worker future", None).to_string();
    let Err(e) = Pool::connect(std::slice::from_ref(&addr), config()) else {
        panic!("a worker of protocol {} accepted", PROTOCOL_VERSION + 7);
    };
    let m = e.to_string();
    assert!(
        matches!(&e, PoolError::Refused { worker, code: Code::FailedPrecondition, .. } if *worker == addr),
        "{m}"
    );
    assert!(m.contains(&format!("speaks {}", PROTOCOL_VERSION + 7)), "{m}");
    assert!(m.contains(&format!("master speaks {PROTOCOL_VERSION}")), "{m}");
}

/// A worker's build id and status messages reach the master's logs and errors with their
/// newlines and ANSI escapes escaped: a peer cannot forge a log line.
#[test]
fn a_peers_text_cannot_forge_log_lines() {
    let servers = Servers::new();
    let forged = "w1\n2026-12-05T00:00:00Z  INFO cosdem: run finished\x1b[2K\r";
    let addr = servers.fake(PROTOCOL_VERSION, forged, Some(forged)).to_string();
    let mut pool = Pool::connect(std::slice::from_ref(&addr), config()).unwrap();
    let build = &pool.workers()[0].1.build_id;
    assert!(!build.chars().any(char::is_control), "{build:?}");
    assert!(build.contains("w1\\n2026") && build.contains("\\u{1b}[2K\\r"), "{build:?}");
    let e = pool.create_assemblies(&[GaussPointId::new(0, 0)], &spec()).unwrap_err().to_string();
    assert!(!e.chars().any(char::is_control), "{e:?}");
    assert!(e.contains("w1\\n2026"), "{e:?}");
}
