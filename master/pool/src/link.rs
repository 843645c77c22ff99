//! One worker seen from the master: its transport (a TCP channel, or the in-process service
//! called directly), handshake and calls. The only place in the master that touches prost
//! types.

use crate::message::{groups, oversized};
use cosdem_common::micro::{AssemblyInfo, AssemblyRequest, AssemblyState};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_client::MicroSolverClient;
use cosdem_proto::{PROTOCOL_VERSION, from_proto, to_proto};
use cosdem_worker::{AttachToken, MicroModel, Token, WorkerConfig};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tonic::body::Body;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::{Channel, Endpoint};
use tonic::{Code, Request, Status};
use tower::ServiceExt;

/// A transport failure (a concrete type: a boxed error here trips the compiler's
/// higher-ranked lifetime check on the calls' `Send` futures).
#[derive(Debug)]
pub struct TransportError(Box<dyn std::error::Error + Send + Sync>);

impl std::fmt::Display for TransportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for TransportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&*self.0)
    }
}

/// What carries a worker's calls: an HTTP/2 channel, or the in-process service itself.
pub type Transport =
    tower::util::BoxCloneSyncService<http::Request<Body>, http::Response<Body>, TransportError>;

/// The client type of one worker.
pub type Client = MicroSolverClient<InterceptedService<Transport, AttachToken>>;

/// What a worker said at handshake.
#[derive(Clone, Debug, Default)]
pub struct WorkerInfo {
    /// Relaxation threads it runs.
    pub cores: u32,
    /// Its memory (bytes; 0 = unknown).
    pub memory_bytes: u64,
    /// Its build (made printable: [`cosdem_proto::printable`]).
    pub build_id: String,
    /// Its message limit (bytes; 0 = not said).
    pub max_message_bytes: u64,
}

/// A commit held back by the pool to ride on the worker's next SolveBatch (see
/// [`Link::solve`]): the trial (step, iteration) of `ids` becomes their committed state.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PendingCommit {
    /// The load step committed.
    pub step: u64,
    /// The Newton iteration whose trial states are committed.
    pub iteration: u32,
    /// The worker's assemblies committed (never empty).
    pub ids: Vec<GaussPointId>,
}

/// A worker the pool talks to.
#[derive(Clone)]
pub struct Link {
    /// Address or in-process name (for messages).
    pub name: String,
    /// The client.
    pub client: Client,
    /// What it said at handshake.
    pub info: WorkerInfo,
    /// The message limit this side enforces (`PoolConfig::max_message_bytes`).
    max_message: usize,
    /// The disc count of each assembly this worker reported (created, imported, exported):
    /// what an oversized message's error names.
    discs: Arc<Mutex<BTreeMap<GaussPointId, u64>>>,
}

/// Statuses that mean "this worker is gone or unusable": its assemblies move elsewhere.
pub fn is_worker_failure(s: &Status) -> bool {
    matches!(
        s.code(),
        Code::Unavailable
            | Code::DeadlineExceeded
            | Code::Cancelled
            | Code::Unknown
            | Code::Internal
            | Code::NotFound
            | Code::Aborted
            | Code::DataLoss
    )
}

fn over_channel(channel: Channel) -> Transport {
    Transport::new(channel.map_err(|e| TransportError(e.into())))
}

fn client(transport: Transport, token: Option<Token>, max_message: usize) -> Client {
    MicroSolverClient::with_interceptor(transport, AttachToken(token))
        .max_decoding_message_size(max_message)
        .max_encoding_message_size(max_message)
}

/// An HTTP/2 endpoint with the pool's connect timeout and keepalive.
pub fn endpoint(uri: String, connect_timeout: Duration) -> Result<Endpoint, Status> {
    Ok(Endpoint::from_shared(uri)
        .map_err(|e| Status::invalid_argument(e.to_string()))?
        .connect_timeout(connect_timeout)
        .tcp_nodelay(true)
        .http2_keep_alive_interval(Duration::from_secs(10))
        .keep_alive_timeout(Duration::from_secs(20))
        .keep_alive_while_idle(true))
}

/// Connects over TCP (TLS if configured) and shakes hands.
pub async fn connect_tcp(
    addr: std::net::SocketAddr,
    c: &super::PoolConfig,
) -> Result<Link, Status> {
    let scheme = if c.tls.is_some() { "https" } else { "http" };
    #[allow(unused_mut)]
    let mut ep = endpoint(format!("{scheme}://{addr}"), c.connect_timeout)?;
    if let Some(_tls) = &c.tls {
        #[cfg(feature = "tls")]
        {
            use tonic::transport::{Certificate, ClientTlsConfig};
            let tls = ClientTlsConfig::new()
                .ca_certificate(Certificate::from_pem(&_tls.ca_pem))
                .domain_name(_tls.domain.clone());
            ep = ep.tls_config(tls).map_err(|e| Status::invalid_argument(format!("TLS: {e}")))?;
        }
        #[cfg(not(feature = "tls"))]
        return Err(Status::invalid_argument("TLS asked for, but built without the `tls` feature"));
    }
    let channel =
        ep.connect().await.map_err(|e| Status::unavailable(format!("connect {addr}: {e}")))?;
    handshake(
        addr.to_string(),
        client(over_channel(channel), c.token.clone(), c.max_message_bytes),
        c.connect_timeout,
        c.max_message_bytes,
    )
    .await
}

/// A client over in-memory duplex pipes: each (re)connection sends the server half of a new
/// pipe to the worker's `serve_duplex`.
pub async fn connect_duplex(
    name: String,
    connections: tokio::sync::mpsc::UnboundedSender<tokio::io::DuplexStream>,
    token: Option<Token>,
    timeout: Duration,
    max_message: usize,
) -> Result<Link, Status> {
    let connector = tower::service_fn(move |_: tonic::transport::Uri| {
        let (client_end, server_end) = tokio::io::duplex(1 << 20);
        let sent = connections.send(server_end);
        async move {
            sent.map_err(|_| std::io::Error::other("in-process worker has stopped"))?;
            Ok::<_, std::io::Error>(hyper_util::rt::TokioIo::new(client_end))
        }
    });
    let channel = endpoint("http://in-process.invalid".into(), timeout)?
        .connect_with_connector(connector)
        .await
        .map_err(|e| Status::unavailable(format!("connect {name}: {e}")))?;
    handshake(name, client(over_channel(channel), token, max_message), timeout, max_message).await
}

/// A worker inside this process with no transport: its service
/// ([`cosdem_worker::direct`]) is called in the caller's task, so a call hands off
/// to no connection task or runtime thread (a hand-off costs tens of microseconds of wake-up
/// latency on a virtual machine, several per call over a transport). Then the handshake.
pub async fn connect_direct<M: MicroModel>(
    name: String,
    model: M,
    config: &WorkerConfig,
    timeout: Duration,
) -> Result<Link, Status> {
    let service = cosdem_worker::direct(model, config)
        .map_err(|e| Status::internal(format!("{name}: {e}")))?;
    let service = ServiceExt::<http::Request<Body>>::map_response(service, |r| r.map(Body::new));
    let service =
        ServiceExt::<http::Request<Body>>::map_err(service, |e| -> TransportError { match e {} });
    let transport = Transport::new(service);
    let max = config.limits.max_message_bytes;
    handshake(name, client(transport, config.token.clone(), max), timeout, max).await
}

fn with_timeout<T>(msg: T, timeout: Duration) -> Request<T> {
    let mut r = Request::new(msg);
    r.set_timeout(timeout);
    r
}

/// Bounds a call by a local timer as well as the grpc-timeout header (a peer that stops
/// reading must not block us).
async fn bounded<T>(
    timeout: Duration,
    f: impl Future<Output = Result<T, Status>>,
) -> Result<T, Status> {
    match tokio::time::timeout(timeout + Duration::from_millis(250), f).await {
        Ok(r) => r.map_err(from_peer),
        Err(_) => Err(Status::deadline_exceeded(format!("no answer within {timeout:?}"))),
    }
}

/// A status as a peer (or the transport under it) gave it, its message made safe to log and
/// print ([`cosdem_proto::printable`]: a newline or an ANSI escape from a hostile worker must
/// not forge the master's log lines); the code is kept.
fn from_peer(s: Status) -> Status {
    let message = cosdem_proto::printable(s.message());
    if message == s.message() { s } else { Status::new(s.code(), message) }
}

/// The Handshake call, and the check of what the worker answers: its protocol version must
/// be ours (FAILED_PRECONDITION naming both otherwise: a worker of another version refuses our
/// calls, or worse, misreads them).
async fn handshake(
    name: String,
    mut client: Client,
    timeout: Duration,
    max_message: usize,
) -> Result<Link, Status> {
    let req = pb::HandshakeRequest {
        protocol_version: PROTOCOL_VERSION,
        master_build_id: concat!("cosdem-master ", env!("CARGO_PKG_VERSION")).into(),
    };
    let reply = bounded(timeout, client.handshake(with_timeout(req, timeout))).await?.into_inner();
    if reply.protocol_version != PROTOCOL_VERSION {
        return Err(Status::failed_precondition(format!(
            "protocol version mismatch: worker {name} speaks {}, this master speaks \
             {PROTOCOL_VERSION} (build {})",
            reply.protocol_version,
            cosdem_proto::printable(&reply.build_id)
        )));
    }
    let info = WorkerInfo {
        cores: reply.cores.max(1),
        memory_bytes: reply.memory_bytes,
        build_id: cosdem_proto::printable(&reply.build_id),
        max_message_bytes: reply.max_message_bytes,
    };
    Ok(Link { name, client, info, max_message, discs: Arc::default() })
}

fn bad_reply(e: impl std::fmt::Display) -> Status {
    Status::data_loss(format!("malformed reply: {e}"))
}

impl Link {
    /// The largest message both sides take.
    fn limit(&self) -> u64 {
        let ours = self.max_message as u64;
        match self.info.max_message_bytes {
            0 => ours,
            theirs => ours.min(theirs),
        }
    }

    fn lock_discs(&self) -> std::sync::MutexGuard<'_, BTreeMap<GaussPointId, u64>> {
        self.discs.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Remembers the disc counts the worker reported.
    fn record(&self, counts: impl IntoIterator<Item = (GaussPointId, u64)>) {
        self.lock_discs().extend(counts);
    }

    /// The known disc count of each of `ids`.
    fn sizes(&self, ids: &[GaussPointId]) -> Vec<(GaussPointId, Option<u64>)> {
        let d = self.lock_discs();
        ids.iter().map(|id| (*id, d.get(id).copied())).collect()
    }

    /// A bound on the bytes of `id`'s exported state (its disc count unknown: 0 discs).
    fn state_size(&self, id: &GaussPointId) -> u64 {
        cosdem_dem::spec::state_bytes(self.lock_discs().get(id).copied().unwrap_or(0))
    }

    /// `s`, naming the limits and the sizes of `ids` if it is a failure for size.
    fn sized(&self, call: &str, ids: &[GaussPointId], s: Status) -> Status {
        oversized(call, &self.sizes(ids), self.max_message, self.info.max_message_bytes, s)
    }

    /// (assemblies, discs, relaxations in flight).
    pub async fn health(&self, timeout: Duration) -> Result<(u64, u64, u64), Status> {
        let mut c = self.client.clone();
        let r = bounded(timeout, c.health(with_timeout(pb::HealthRequest {}, timeout)))
            .await?
            .into_inner();
        Ok((r.assemblies, r.discs, r.in_flight))
    }

    /// Builds assemblies from one spec.
    pub async fn create(
        &self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
        timeout: Duration,
    ) -> Result<Vec<AssemblyInfo>, Status> {
        let mut c = self.client.clone();
        let req = pb::CreateAssembliesRequest {
            ids: ids.iter().map(|i| (*i).into()).collect(),
            spec: Some(spec.into()),
        };
        let r =
            bounded(timeout, c.create_assemblies(with_timeout(req, timeout))).await?.into_inner();
        let infos: Vec<AssemblyInfo> = r
            .assemblies
            .into_iter()
            .map(|a| a.try_into().map_err(bad_reply))
            .collect::<Result<_, _>>()?;
        self.record(infos.iter().map(|i| (i.id, i.disc_count)));
        Ok(infos)
    }

    /// Solves a batch, collecting the streamed results; a stream that ends before every
    /// Gauss point answered is a worker failure. `commit` (the previous step's, held back by
    /// the pool) is applied by the worker before the batch's relaxations start.
    pub async fn solve(
        &self,
        step: u64,
        iteration: u32,
        items: Vec<(GaussPointId, MacroDeformation)>,
        commit: Option<PendingCommit>,
        timeout: Duration,
    ) -> Result<Vec<(GaussPointId, Result<MicroResponse, String>)>, Status> {
        let mut c = self.client.clone();
        let n = items.len();
        let req = pb::SolveBatchRequest {
            step,
            iteration,
            items: items.into_iter().map(|(id, t)| to_proto::solve_item(id, t)).collect(),
            commit: commit.map(|c| pb::CommitRequest {
                step: c.step,
                iteration: c.iteration,
                ids: c.ids.into_iter().map(Into::into).collect(),
                export_state: false,
            }),
        };
        bounded(timeout, async move {
            let mut stream = c.solve_batch(with_timeout(req, timeout)).await?.into_inner();
            let mut out = Vec::with_capacity(n);
            while let Some(r) = stream.message().await? {
                let (id, outcome) = from_proto::solve_result(r).map_err(bad_reply)?;
                // A failed relaxation's reason is the worker's text: made printable too.
                out.push((id, outcome.map_err(|e| cosdem_proto::printable(&e))));
            }
            if out.len() != n {
                return Err(Status::unavailable(format!(
                    "stream ended after {} of {n} results",
                    out.len()
                )));
            }
            Ok(out)
        })
        .await
    }

    /// Commits trial (step, iteration) of `ids`, returning their new committed states if
    /// `export` (else none). States that would not fit one reply within the message limit
    /// are exported after the commit, in as many ExportState calls as they need (the same
    /// bytes: nothing runs on them in between).
    pub async fn commit(
        &self,
        ids: &[GaussPointId],
        step: u64,
        iteration: u32,
        export: bool,
        timeout: Duration,
    ) -> Result<Vec<AssemblyState>, Status> {
        let total = ids.iter().fold(0u64, |a, id| a.saturating_add(self.state_size(id)));
        let split = export && !ids.is_empty() && total > self.limit();
        let mut c = self.client.clone();
        let req = pb::CommitRequest {
            step,
            iteration,
            ids: ids.iter().map(|i| (*i).into()).collect(),
            export_state: export && !split,
        };
        let r = bounded(timeout, c.commit(with_timeout(req, timeout)))
            .await
            .map_err(|s| self.sized("Commit (exporting)", ids, s))?
            .into_inner();
        if split {
            return self.export(ids, timeout).await;
        }
        self.states(r.states)
    }

    /// Decoded states, their disc counts remembered.
    fn states(&self, states: Vec<pb::AssemblyState>) -> Result<Vec<AssemblyState>, Status> {
        let states: Vec<AssemblyState> = states
            .into_iter()
            .map(|s| s.try_into().map_err(bad_reply))
            .collect::<Result<_, _>>()?;
        self.record(states.iter().map(|s| (s.id, s.disc_count)));
        Ok(states)
    }

    /// Discards trial states of `ids`.
    pub async fn rollback(&self, ids: &[GaussPointId], timeout: Duration) -> Result<(), Status> {
        let mut c = self.client.clone();
        let req = pb::RollbackRequest { ids: ids.iter().map(|i| (*i).into()).collect() };
        bounded(timeout, c.rollback(with_timeout(req, timeout))).await?;
        Ok(())
    }

    /// Committed states of `ids` (all for an empty list), in as many ExportState calls as
    /// the message limit needs (each bounded by `timeout`), by the states' sizes bounded from
    /// their disc counts ([`cosdem_dem::spec::state_bytes`]).
    pub async fn export(
        &self,
        ids: &[GaussPointId],
        timeout: Duration,
    ) -> Result<Vec<AssemblyState>, Status> {
        let parts = if ids.is_empty() {
            vec![Vec::new()]
        } else {
            groups(ids.to_vec(), |id| self.state_size(id), self.limit())
        };
        let mut out = Vec::with_capacity(ids.len());
        for part in parts {
            let mut c = self.client.clone();
            let req = pb::ExportStateRequest { ids: part.iter().map(|i| (*i).into()).collect() };
            let r = bounded(timeout, c.export_state(with_timeout(req, timeout)))
                .await
                .map_err(|s| self.sized("ExportState", &part, s))?
                .into_inner();
            out.extend(self.states(r.states)?);
        }
        Ok(out)
    }

    /// Creates or replaces assemblies from committed states, in as many ImportState calls as
    /// the message limit needs (each bounded by `timeout`).
    pub async fn import(
        &self,
        states: Vec<AssemblyState>,
        timeout: Duration,
    ) -> Result<(), Status> {
        let size = |s: &AssemblyState| {
            (s.state.len() as u64).saturating_add(cosdem_dem::spec::STATE_ENVELOPE_BYTES)
        };
        for part in groups(states, size, self.limit()) {
            let ids: Vec<GaussPointId> = part.iter().map(|s| s.id).collect();
            self.record(part.iter().map(|s| (s.id, s.disc_count)));
            let mut c = self.client.clone();
            let req = pb::ImportStateRequest { states: part.into_iter().map(Into::into).collect() };
            bounded(timeout, c.import_state(with_timeout(req, timeout)))
                .await
                .map_err(|s| self.sized("ImportState", &ids, s))?;
        }
        Ok(())
    }

    /// Frees `ids` (all for an empty list).
    pub async fn drop_assemblies(
        &self,
        ids: &[GaussPointId],
        timeout: Duration,
    ) -> Result<(), Status> {
        let mut c = self.client.clone();
        let req = pb::DropRequest { ids: ids.iter().map(|i| (*i).into()).collect() };
        bounded(timeout, c.drop(with_timeout(req, timeout))).await?;
        let mut d = self.lock_discs();
        if ids.is_empty() {
            d.clear();
        } else {
            ids.iter().for_each(|id| {
                d.remove(id);
            });
        }
        Ok(())
    }

    /// Particle-level snapshot of one assembly.
    pub async fn snapshot(
        &self,
        id: GaussPointId,
        timeout: Duration,
    ) -> Result<cosdem_common::micro::MicroSnapshot, Status> {
        let mut c = self.client.clone();
        let req = pb::SnapshotRequest { id: Some(id.into()) };
        let r = bounded(timeout, c.snapshot(with_timeout(req, timeout)))
            .await
            .map_err(|s| self.sized("Snapshot", &[id], s))?
            .into_inner();
        Ok(r.into())
    }
}
