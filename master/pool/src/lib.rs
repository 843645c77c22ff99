//! The worker pool: the DEM-backed [`Material`], one assembly per Gauss point on a set of
//! stateful workers (remote over gRPC, or in-process over in-memory pipes).
//!
//! # Life cycle
//! [`Pool::connect`] (addresses `host:port`; a DNS name resolving to several addresses gives
//! one worker per address) or [`Pool::in_process`], then [`Pool::create_assemblies`], then the
//! FE solver drives it through [`Material`]: `evaluate` (one `SolveBatch` per worker per Newton
//! iteration, all workers concurrently, each bounded by [`PoolConfig::solve_timeout`]),
//! `commit`, `rollback`. A commit that exports nothing is held back and carried on the
//! worker's next `SolveBatch` ([`PoolConfig::defer_commits`]): one round trip per load step
//! instead of two.
//!
//! # Runtime
//! `Material` is synchronous; the pool owns a small multi-threaded tokio runtime and blocks
//! on it. So its methods must not be called from inside an async context (call them from a
//! plain thread, or from `tokio::task::spawn_blocking`).
//!
//! # Fault tolerance
//! The master keeps every assembly's committed history ([`replay`]): a committed state
//! exported by its worker every [`PoolConfig::export_every`] steps (`Commit` with
//! `export_state`, which costs one copy of the state over the network and in master memory:
//! for the DEM, positions, rotations and contact history of every disc, tens of bytes per
//! disc), and the committed increments since (step, iteration, macro deformation: a few
//! dozen bytes per step). When a worker fails (transport error, deadline, lost assemblies),
//! it is marked dead, its assemblies are imported on the remaining workers from the stored
//! states and brought to the last committed step by solving and committing each recorded
//! increment again, and the Gauss points it owed are solved again there; a worker lost
//! during `commit` has its points re-solved at the last trial and committed on their new
//! owner. Because a solve is deterministic given (committed state, target), the results are
//! bit-identical to a run without failure (diagnostics' `wall_seconds` aside). A failure
//! costs up to `export_every - 1` replayed steps of the lost worker's assemblies. A worker
//! that comes back, or a new address behind a DNS name, is admitted at a load step once it
//! answers and is idle: the attempt (name resolution, connection, health) runs in the
//! background and a step waits for it at most [`PoolConfig::admit_wait`]; attempts are made
//! at every load step while a worker is lost, else at most every
//! [`PoolConfig::admit_interval`]. A commit held back for the next `SolveBatch` is recorded in
//! the history at once, so a worker lost before it was sent is restored with it.
//!
//! # Balance
//! Assemblies are placed by expected cost (disc count, then measured solve time) per core;
//! at each new load step, if the most loaded worker exceeds the mean by
//! [`PoolConfig::rebalance_threshold`], assemblies migrate (import of the stored committed
//! state on the new owner, drop on the old one).

mod balance;
mod direct;
mod link;
pub mod replay;

pub use balance::Cost;
pub use direct::DirectDem;
pub use link::WorkerInfo;

use balance::{effective_costs, place, rebalance};
use cosdem_common::micro::{AssemblyRequest, AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_worker::{Limits, MicroModel, Token, WorkerConfig, serve_duplex};
use link::{Link, PendingCommit, is_worker_failure};
use replay::{History, Increment, ReplayPlan};
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::time::Duration;
use tonic::{Code, Status};

/// Why a pool could not be built or set up.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PoolError {
    /// Bad configuration (no workers, unparsable address, ...).
    #[error("pool configuration: {0}")]
    Config(String),
    /// A worker refused us (wrong token, protocol version, limits).
    #[error("worker {worker} refused: {code:?}: {message}")]
    Refused {
        /// Its address or name.
        worker: String,
        /// The status code.
        code: Code,
        /// The status message.
        message: String,
    },
    /// No worker could be used.
    #[error("no worker available: {0}")]
    Unavailable(String),
}

/// TLS towards remote workers (needs the `tls` feature).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClientTls {
    /// CA certificate(s) that sign the workers' certificates (PEM).
    pub ca_pem: Vec<u8>,
    /// Name the workers' certificates are issued for (checked against them).
    pub domain: String,
}

/// How the pool talks to its workers.
#[derive(Clone, Debug)]
pub struct PoolConfig {
    /// Shared secret sent on every call (`COSDEM_TOKEN` / `--token-file` on the CLI).
    pub token: Option<Token>,
    /// Connect and handshake timeout.
    pub connect_timeout: Duration,
    /// Deadline of every call but SolveBatch.
    pub call_timeout: Duration,
    /// Deadline of one SolveBatch (all of a worker's Gauss points for one iteration). A worker
    /// that misses it is treated as dead. Default 600 s: set it from the expected cost.
    pub solve_timeout: Duration,
    /// Largest message either way.
    pub max_message_bytes: usize,
    /// Migrate at a step boundary when max load / mean load exceeds this (INFINITY: never).
    pub rebalance_threshold: f64,
    /// Threads of the pool's own tokio runtime.
    pub runtime_threads: usize,
    /// Relaxation threads of each in-process worker (0 = cores / workers, at least 1).
    pub in_process_threads: usize,
    /// TLS to remote workers (needs the `tls` feature; in-process workers never use it).
    pub tls: Option<ClientTls>,
    /// Export the committed states to the master at every `export_every`-th commit (>= 1);
    /// in between the master records the committed increments and a failover replays them.
    /// 1 ships every state at every commit; larger values save that traffic and cost up to
    /// `export_every - 1` replayed steps per lost assembly when a worker fails. Default 10
    /// (see `docs/notes/2026-12-01-measured-performance.md` for the measurement behind it).
    pub export_every: u64,
    /// How long a load step waits for the admission of returned or new workers (name
    /// resolution, connection, health check; each bounded by `connect_timeout`). An attempt
    /// not finished by then goes on in the background and is taken up at a later step.
    pub admit_wait: Duration,
    /// Least time between two admission attempts while every worker is alive (new addresses
    /// behind a name are looked for this often); with a worker lost, every load step tries.
    /// An attempt costs a name lookup and a hand-off to the runtime even when it finds
    /// nothing, which short load steps would otherwise pay each time.
    pub admit_interval: Duration,
    /// Carry a commit that exports nothing on the worker's next SolveBatch instead of a Commit
    /// call of its own (one round trip fewer per load step; protocol 2). The commit is taken
    /// as done by the master at once (its increment is recorded for failover), and is sent
    /// on its own before any other call that needs the committed states (rollback, export,
    /// migration, snapshot). Default true; false sends every commit at once.
    pub defer_commits: bool,
    /// In-process workers over an in-memory HTTP/2 connection (`tokio::io::duplex`) instead
    /// of their service called directly: the transport's framing and its connection tasks
    /// included, as over TCP. Default false (measured: `cosdem bench floor`).
    pub in_process_duplex: bool,
}

impl PoolConfig {
    /// Refuses values the pool cannot work with, naming the field and the value.
    pub fn validate(&self) -> Result<(), PoolError> {
        if self.export_every == 0 {
            return Err(PoolError::Config("export_every = 0: must be at least 1".into()));
        }
        if self.max_message_bytes == 0 {
            return Err(PoolError::Config("max_message_bytes = 0: must be positive".into()));
        }
        Ok(())
    }
}

impl Default for PoolConfig {
    fn default() -> Self {
        Self {
            token: None,
            connect_timeout: Duration::from_secs(5),
            call_timeout: Duration::from_secs(60),
            solve_timeout: Duration::from_secs(600),
            max_message_bytes: cosdem_proto::DEFAULT_MAX_MESSAGE_BYTES,
            rebalance_threshold: 1.25,
            runtime_threads: 2,
            in_process_threads: 0,
            tls: None,
            export_every: 10,
            admit_wait: Duration::from_secs(1),
            admit_interval: Duration::from_secs(1),
            defer_commits: true,
            in_process_duplex: false,
        }
    }
}

/// Counters of what happened (for logs and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PoolStats {
    /// Workers declared dead.
    pub workers_lost: u64,
    /// Workers admitted after the start (returned or new).
    pub workers_admitted: u64,
    /// Assemblies restored from the master's committed states after a failure.
    pub restored: u64,
    /// Assemblies migrated by rebalancing.
    pub migrated: u64,
    /// Gauss point solves redone after a failure.
    pub resolved: u64,
    /// Committed increments solved and committed again to restore assemblies.
    pub replayed: u64,
    /// Commits that also exported the committed states.
    pub exports: u64,
    /// Commits (one per worker and step) carried on the worker's next SolveBatch instead of
    /// a Commit call ([`PoolConfig::defer_commits`]).
    pub carried_commits: u64,
}

struct Worker {
    link: Link,
    addr: Option<SocketAddr>,
    alive: bool,
}

/// The DEM-backed material: a set of workers holding one assembly per Gauss point.
pub struct Pool {
    rt: Option<tokio::runtime::Runtime>,
    handle: tokio::runtime::Handle,
    config: PoolConfig,
    sources: Vec<String>,
    workers: Vec<Worker>,
    owner: BTreeMap<GaussPointId, usize>,
    history: History,
    costs: BTreeMap<GaussPointId, Cost>,
    last: Option<(TrialId, BTreeMap<GaussPointId, MacroDeformation>)>,
    current_step: Option<u64>,
    committed_step: u64,
    stats: PoolStats,
    admission: Option<tokio::task::JoinHandle<Vec<(SocketAddr, Link)>>>,
    /// When the last admission attempt started.
    admitted_at: Option<std::time::Instant>,
    /// Commits held back per worker, to ride on its next SolveBatch
    /// ([`PoolConfig::defer_commits`]).
    deferred: BTreeMap<usize, PendingCommit>,
    _stops: Vec<tokio::sync::oneshot::Sender<()>>,
}

impl Drop for Pool {
    fn drop(&mut self) {
        // Free the assemblies on remote workers (best effort, bounded), unless dropped
        // inside an async context where blocking is not allowed.
        if tokio::runtime::Handle::try_current().is_err() && !self.sources.is_empty() {
            self.release();
        }
        // Do not wait for relaxations still running in in-process workers.
        if let Some(rt) = self.rt.take() {
            rt.shutdown_background();
        }
    }
}

fn runtime(threads: usize) -> Result<tokio::runtime::Runtime, PoolError> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(threads.max(1))
        .thread_name("cosdem-pool")
        .enable_all()
        .build()
        .map_err(|e| PoolError::Config(format!("tokio runtime: {e}")))
}

fn refused(worker: &str, s: &Status) -> PoolError {
    PoolError::Refused { worker: worker.into(), code: s.code(), message: s.message().into() }
}

/// The addresses `source` resolves to, within `timeout` (a name whose DNS server does not
/// answer must not stall the run: the lookup itself goes on in a blocking thread, abandoned).
async fn resolve(source: &str, timeout: Duration) -> Vec<SocketAddr> {
    match tokio::time::timeout(timeout, tokio::net::lookup_host(source)).await {
        Ok(Ok(addrs)) => {
            let mut v: Vec<_> = addrs.collect();
            v.sort();
            v.dedup();
            v
        }
        Ok(Err(e)) => {
            tracing::warn!(source, error = %e, "cannot resolve worker address");
            Vec::new()
        }
        Err(_) => {
            tracing::warn!(source, ?timeout, "worker address not resolved in time");
            Vec::new()
        }
    }
}

/// Resolves every source concurrently, each within `timeout`; sorted, without duplicates.
async fn resolve_all(sources: &[String], timeout: Duration) -> Vec<SocketAddr> {
    let mut set = tokio::task::JoinSet::new();
    for s in sources {
        let s = s.clone();
        set.spawn(async move { resolve(&s, timeout).await });
    }
    let mut out = Vec::new();
    while let Some(r) = set.join_next().await {
        out.extend(r.unwrap_or_default());
    }
    out.sort();
    out.dedup();
    out
}

/// Tries the addresses in `candidates` concurrently: those that answer the handshake, report
/// no relaxation in flight and accept a drop of whatever they hold (one master per worker).
/// Every step is bounded by the connect timeout.
async fn try_admit(candidates: Vec<SocketAddr>, config: PoolConfig) -> Vec<(SocketAddr, Link)> {
    let mut set = tokio::task::JoinSet::new();
    for addr in candidates {
        let c = config.clone();
        set.spawn(async move {
            let link = link::connect_tcp(addr, &c).await.ok()?;
            match link.health(c.connect_timeout).await {
                Ok((_, _, 0)) => {}
                _ => return None,
            }
            link.drop_assemblies(&[], c.connect_timeout).await.ok()?;
            Some((addr, link))
        });
    }
    let mut out = Vec::new();
    while let Some(r) = set.join_next().await {
        if let Ok(Some(x)) = r {
            out.push(x);
        }
    }
    out.sort_by_key(|(a, _)| *a);
    out
}

/// One worker's share of a fan-out.
type Job<T> = std::pin::Pin<Box<dyn Future<Output = Result<T, Status>> + Send>>;

type Outcomes = BTreeMap<GaussPointId, Result<MicroResponse, String>>;

/// Runs one job per worker concurrently, polled on the calling task (the thread blocked in
/// `block_on`): no task is spawned per job, so a call costs no hand-off to a runtime thread
/// and back (two thread wake-ups per call, which a loaded machine makes slow). The jobs only
/// await the network; their results are sorted by worker.
async fn fan_out<T>(jobs: Vec<(usize, Job<T>)>) -> Vec<(usize, Result<T, Status>)> {
    let mut pending = jobs;
    let mut out = Vec::with_capacity(pending.len());
    std::future::poll_fn(|cx| {
        let mut i = 0;
        while i < pending.len() {
            match pending[i].1.as_mut().poll(cx) {
                std::task::Poll::Ready(r) => {
                    let (w, _) = pending.swap_remove(i);
                    out.push((w, r));
                }
                std::task::Poll::Pending => i += 1,
            }
        }
        if pending.is_empty() { std::task::Poll::Ready(()) } else { std::task::Poll::Pending }
    })
    .await;
    out.sort_by_key(|(w, _)| *w);
    out
}

/// Runs a replay plan on one worker: each batch solved, then committed at its trial (no
/// export). Returns the number of increments replayed, or the first Gauss point whose replayed
/// solve failed.
async fn replay_on(
    link: &Link,
    plan: ReplayPlan,
    solve_timeout: Duration,
    call_timeout: Duration,
) -> Result<Result<u64, (GaussPointId, String)>, Status> {
    let mut replayed = 0;
    for batch in plan.batches {
        let ids: Vec<_> = batch.items.iter().map(|(id, _)| *id).collect();
        replayed += ids.len() as u64;
        let results =
            link.solve(batch.step, batch.iteration, batch.items, None, solve_timeout).await?;
        if let Some((id, e)) = results.into_iter().find_map(|(id, r)| r.err().map(|e| (id, e))) {
            return Ok(Err((id, e)));
        }
        link.commit(&ids, batch.step, batch.iteration, false, call_timeout).await?;
    }
    Ok(Ok(replayed))
}

impl Pool {
    /// Connects to workers given as `host:port` (each name may resolve to several addresses,
    /// one worker each) and shakes hands with each. Unreachable addresses are skipped with a
    /// warning; a refusal (token, protocol version) is an error; no worker at all is an error.
    pub fn connect(addresses: &[String], config: PoolConfig) -> Result<Pool, PoolError> {
        if addresses.is_empty() {
            return Err(PoolError::Config("no worker addresses given".into()));
        }
        config.validate()?;
        let rt = runtime(config.runtime_threads)?;
        let handle = rt.handle().clone();
        let mut pool = Pool::empty(rt, handle, config);
        pool.sources = addresses.to_vec();
        let public = |a: &SocketAddr| !a.ip().is_loopback();
        let h = pool.handle.clone();
        h.block_on(async {
            let mut addrs = Vec::new();
            for s in &pool.sources {
                let found = resolve(s, pool.config.connect_timeout).await;
                if found.is_empty() {
                    tracing::warn!(source = %s, "no address for worker");
                }
                addrs.extend(found);
            }
            if pool.config.token.is_none()
                && let Some(a) = addrs.iter().find(|a| public(a))
            {
                return Err(PoolError::Config(format!(
                    "worker {a} is not on loopback: a token is required (COSDEM_TOKEN or --token-file)"
                )));
            }
            for addr in addrs {
                if pool.workers.iter().any(|w| w.addr == Some(addr)) {
                    continue;
                }
                let c = &pool.config;
                match link::connect_tcp(addr, c).await
                {
                    Ok(link) => {
                        // One master per worker: whatever a previous master left is stale.
                        let t = c.call_timeout;
                        link.drop_assemblies(&[], t).await.map_err(|s| refused(&link.name, &s))?;
                        pool.workers.push(Worker { link, addr: Some(addr), alive: true });
                    }
                    Err(s) if matches!(s.code(), Code::Unavailable | Code::DeadlineExceeded) => {
                        tracing::warn!(%addr, error = %s.message(), "worker unreachable, skipped");
                    }
                    Err(s) => return Err(refused(&addr.to_string(), &s)),
                }
            }
            Ok(())
        })?;
        if pool.workers.is_empty() {
            return Err(PoolError::Unavailable(format!("none of {:?} answered", addresses)));
        }
        Ok(pool)
    }

    /// `n` workers inside this process, each a full MicroSolver service (request decoding,
    /// token check, limits, response encoding: the code path of the network without the
    /// network) called directly in the pool's task, or, with
    /// [`PoolConfig::in_process_duplex`], reached over an in-memory `tokio::io::duplex`
    /// HTTP/2 connection. `factory(i)` builds worker `i`'s model. What `cosdem run` uses
    /// without `--workers`.
    pub fn in_process<M: MicroModel>(
        n: usize,
        config: PoolConfig,
        factory: impl Fn(usize) -> M,
    ) -> Result<Pool, PoolError> {
        if n == 0 {
            return Err(PoolError::Config("in-process pool needs at least one worker".into()));
        }
        config.validate()?;
        let rt = runtime(config.runtime_threads)?;
        let handle = rt.handle().clone();
        let mut pool = Pool::empty(rt, handle, config);
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let threads = if pool.config.in_process_threads > 0 {
            pool.config.in_process_threads
        } else {
            (cores / n).max(1)
        };
        for i in 0..n {
            let wc = WorkerConfig {
                token: pool.config.token.clone(),
                threads,
                limits: Limits {
                    max_message_bytes: pool.config.max_message_bytes,
                    ..Limits::default()
                },
                ..WorkerConfig::default()
            };
            let model = factory(i);
            let name = format!("in-process worker {i}");
            let link = if pool.config.in_process_duplex {
                pool.spawn_duplex_worker(i, name.clone(), model, wc)
            } else {
                let timeout = pool.config.connect_timeout;
                pool.handle.block_on(link::connect_direct(name.clone(), model, &wc, timeout))
            }
            .map_err(|s| refused(&name, &s))?;
            pool.workers.push(Worker { link, addr: None, alive: true });
        }
        Ok(pool)
    }

    /// Serves `model` on the pool's runtime over in-memory HTTP/2 connections
    /// ([`PoolConfig::in_process_duplex`]) and connects to it; the server stops with the pool.
    fn spawn_duplex_worker<M: MicroModel>(
        &mut self,
        i: usize,
        name: String,
        model: M,
        wc: WorkerConfig,
    ) -> Result<Link, Status> {
        let (conn_tx, conn_rx) = tokio::sync::mpsc::unbounded_channel();
        let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
        self.handle.spawn(async move {
            if let Err(e) = serve_duplex(conn_rx, wc, model, async {
                let _ = stop_rx.await;
            })
            .await
            {
                tracing::error!("in-process worker {i}: {e}");
            }
        });
        self._stops.push(stop_tx);
        let c = &self.config;
        self.handle.block_on(link::connect_duplex(
            name,
            conn_tx,
            c.token.clone(),
            c.connect_timeout,
            c.max_message_bytes,
        ))
    }

    fn empty(
        rt: tokio::runtime::Runtime,
        handle: tokio::runtime::Handle,
        config: PoolConfig,
    ) -> Pool {
        Pool {
            rt: Some(rt),
            handle,
            config,
            sources: Vec::new(),
            workers: Vec::new(),
            owner: BTreeMap::new(),
            history: History::default(),
            costs: BTreeMap::new(),
            last: None,
            current_step: None,
            committed_step: 0,
            deferred: BTreeMap::new(),
            admitted_at: None,
            stats: PoolStats::default(),
            admission: None,
            _stops: Vec::new(),
        }
    }

    /// Workers in use now.
    pub fn live_workers(&self) -> usize {
        self.workers.iter().filter(|w| w.alive).count()
    }

    /// What each live worker said at handshake, by name.
    pub fn workers(&self) -> Vec<(String, WorkerInfo)> {
        self.workers
            .iter()
            .filter(|w| w.alive)
            .map(|w| (w.link.name.clone(), w.link.info.clone()))
            .collect()
    }

    /// Which worker (by name) holds each assembly.
    pub fn assignment(&self) -> BTreeMap<GaussPointId, String> {
        self.owner.iter().map(|(id, w)| (*id, self.workers[*w].link.name.clone())).collect()
    }

    /// Counters of failures, restorations and migrations.
    pub fn stats(&self) -> PoolStats {
        self.stats
    }

    /// The master's copy of each assembly's last exported committed state (taken every
    /// [`PoolConfig::export_every`] commits; see [`Pool::unexported_commits`]).
    pub fn committed_states(&self) -> &BTreeMap<GaussPointId, AssemblyState> {
        self.history.states()
    }

    /// Commits of `id` since its stored state was exported (what a failover would replay).
    pub fn unexported_commits(&self, id: &GaussPointId) -> usize {
        self.history.pending(id)
    }

    /// Builds one assembly per Gauss point from `spec`, placed by expected cost, and stores
    /// their initial committed states (step 0) for failover.
    pub fn create_assemblies(
        &mut self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
    ) -> Result<(), PoolError> {
        let h = self.handle.clone();
        h.block_on(self.create_async(ids, spec))
    }

    /// Frees every assembly on the live workers (best effort, one call timeout at most).
    /// Called when the pool is dropped; the pool holds no assemblies afterwards.
    pub fn release(&mut self) {
        let t = self.config.connect_timeout;
        let links: Vec<_> =
            self.workers.iter().filter(|w| w.alive).map(|w| w.link.clone()).collect();
        self.handle.block_on(async move {
            for l in links {
                let _ = l.drop_assemblies(&[], t).await;
            }
        });
        self.owner.clear();
        self.history.clear();
        self.costs.clear();
        self.deferred.clear();
        self.last = None;
    }

    /// Particle-level snapshot of one assembly (committed state).
    pub fn snapshot(&mut self, id: GaussPointId) -> Result<MicroSnapshot, PoolError> {
        let h = self.handle.clone();
        h.block_on(self.flush_deferred()).map_err(|e| PoolError::Unavailable(e.to_string()))?;
        let w = *self
            .owner
            .get(&id)
            .ok_or_else(|| PoolError::Config(format!("no assembly for {id}")))?;
        let link = self.workers[w].link.clone();
        let t = self.config.call_timeout;
        self.handle.block_on(link.snapshot(id, t)).map_err(|s| refused(&link.name, &s))
    }

    fn alive(&self) -> Vec<(usize, u32)> {
        self.workers
            .iter()
            .enumerate()
            .filter(|(_, w)| w.alive)
            .map(|(i, w)| (i, w.link.info.cores))
            .collect()
    }

    fn loads(&self) -> BTreeMap<usize, f64> {
        let costs = effective_costs(&self.costs);
        let mut load: BTreeMap<usize, f64> = self.alive().iter().map(|&(w, _)| (w, 0.0)).collect();
        for (id, w) in &self.owner {
            if let Some(l) = load.get_mut(w) {
                *l += costs.get(id).copied().unwrap_or(1.0)
                    / self.workers[*w].link.info.cores.max(1) as f64;
            }
        }
        load
    }

    fn owned_by(&self, w: usize) -> Vec<GaussPointId> {
        self.owner.iter().filter(|(_, o)| **o == w).map(|(id, _)| *id).collect()
    }

    /// The error for a worker that answered with a status that is not a worker failure.
    fn unavailable(&self, w: usize, call: &str, status: &Status) -> MaterialError {
        MaterialError::Unavailable(format!(
            "{call} on {}: {:?}: {}",
            self.workers[w].link.name,
            status.code(),
            status.message()
        ))
    }

    fn mark_dead(&mut self, w: usize, why: &Status) {
        if self.workers[w].alive {
            tracing::warn!(worker = %self.workers[w].link.name, code = ?why.code(), error = %why.message(), "worker lost");
            self.workers[w].alive = false;
            self.stats.workers_lost += 1;
        }
        // Its held-back commit is in the history: the restore replays it.
        self.deferred.remove(&w);
    }

    async fn create_async(
        &mut self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
    ) -> Result<(), PoolError> {
        if let Some(id) = ids.iter().find(|id| self.owner.contains_key(id)) {
            return Err(PoolError::Config(format!("assembly for {id} already created")));
        }
        let alive = self.alive();
        if alive.is_empty() {
            return Err(PoolError::Unavailable("every worker is lost".into()));
        }
        let hint = spec.disc_count_hint.max(1);
        let mut load = self.loads();
        let new: Vec<_> = ids.iter().map(|id| (*id, hint as f64)).collect();
        let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for (id, w) in place(&new, &alive, &mut load) {
            by_worker.entry(w).or_default().push(id);
        }
        let t = self.config.call_timeout;
        let jobs = by_worker
            .into_iter()
            .map(|(w, ids)| {
                let link = self.workers[w].link.clone();
                let spec = spec.clone();
                let job: Job<_> = Box::pin(async move {
                    let infos = link.create(&ids, &spec, t).await?;
                    let states = link.export(&ids, t).await?;
                    Ok((infos, states))
                });
                (w, job)
            })
            .collect();
        for (w, r) in fan_out(jobs).await {
            let (infos, states) = r.map_err(|s| refused(&self.workers[w].link.name, &s))?;
            for i in infos {
                self.owner.insert(i.id, w);
                self.costs.insert(i.id, Cost { discs: i.disc_count, seconds: None });
            }
            for s in states {
                self.history.store(s);
            }
        }
        Ok(())
    }

    /// Exports every assembly's committed state from its owner now (a checkpoint needs the
    /// states of the last committed step, not those of the last periodic export), storing
    /// them as the failover copies. A worker that fails here is an error: the checkpoint is
    /// not written and the next step's failover handles the loss.
    async fn export_all(&mut self) -> Result<(), MaterialError> {
        self.flush_deferred().await?;
        let t = self.config.call_timeout;
        let jobs = (0..self.workers.len())
            .filter(|w| self.workers[*w].alive)
            .filter_map(|w| {
                let ids = self.owned_by(w);
                if ids.is_empty() {
                    return None;
                }
                let link = self.workers[w].link.clone();
                let job: Job<_> = Box::pin(async move { link.export(&ids, t).await });
                Some((w, job))
            })
            .collect();
        for (w, r) in fan_out(jobs).await {
            match r {
                Ok(states) => {
                    for s in states {
                        self.history.store(s);
                    }
                }
                Err(s) => return Err(self.unavailable(w, "export for a checkpoint", &s)),
            }
        }
        Ok(())
    }

    /// Places saved committed states (a checkpoint) on the live workers: the pool then holds
    /// exactly those assemblies, committed at the saved step. Ids must not have assemblies yet.
    async fn import_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        let mut ids = Vec::with_capacity(states.len());
        for s in states {
            if self.owner.contains_key(&s.id) {
                return Err(MaterialError::Unavailable(format!(
                    "restoring {}: the pool already holds an assembly for it",
                    s.id
                )));
            }
            self.committed_step = self.committed_step.max(s.committed_step);
            self.costs.insert(s.id, Cost { discs: s.disc_count, seconds: None });
            ids.push(s.id);
            self.history.store(s);
        }
        self.last = None;
        self.restore(&ids).await?;
        // Not a failover: the restorations above are the resume, not a recovery.
        self.stats.restored = self.stats.restored.saturating_sub(ids.len() as u64);
        Ok(())
    }

    /// Imports the stored committed states of `ids` on live workers (by cost) and replays the
    /// increments committed since ([`replay`]), so that each assembly is back at its last
    /// committed step with no trial; retries on other workers when a target fails.
    async fn restore(&mut self, ids: &[GaussPointId]) -> Result<(), MaterialError> {
        let mut todo: Vec<GaussPointId> = ids.to_vec();
        // Ends: every pass that leaves work marks at least one worker dead, and no worker
        // returns inside this loop (re-admission happens at step boundaries).
        let mut rounds = 0usize;
        while !todo.is_empty() {
            rounds += 1;
            if rounds > self.workers.len() + 1 {
                return Err(MaterialError::Unavailable(format!(
                    "restore of {} assemblies still failing after {} rounds of worker losses",
                    todo.len(),
                    rounds - 1
                )));
            }
            let alive = self.alive();
            if alive.is_empty() {
                return Err(MaterialError::Unavailable("every worker is lost".into()));
            }
            // Loads without the assemblies being moved.
            for id in &todo {
                self.owner.remove(id);
            }
            let costs = effective_costs(&self.costs);
            let mut load = self.loads();
            let new: Vec<_> =
                todo.iter().map(|id| (*id, costs.get(id).copied().unwrap_or(1.0))).collect();
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for (id, w) in place(&new, &alive, &mut load) {
                by_worker.entry(w).or_default().push(id);
            }
            let (t, ts) = (self.config.call_timeout, self.config.solve_timeout);
            let mut jobs = Vec::new();
            for (w, ids) in &by_worker {
                let mut states = Vec::with_capacity(ids.len());
                for id in ids {
                    let s = self.history.state(id).ok_or_else(|| {
                        MaterialError::Unavailable(format!("no stored state for {id}"))
                    })?;
                    states.push(s.clone());
                }
                let plan = self.history.plan(ids);
                let link = self.workers[*w].link.clone();
                let job: Job<_> = Box::pin(async move {
                    link.import(states, t).await?;
                    replay_on(&link, plan, ts, t).await
                });
                jobs.push((*w, job));
            }
            todo.clear();
            for (w, r) in fan_out(jobs).await {
                let ids = &by_worker[&w];
                match r {
                    Ok(Ok(replayed)) => {
                        for id in ids {
                            self.owner.insert(*id, w);
                        }
                        self.stats.restored += ids.len() as u64;
                        self.stats.replayed += replayed;
                        tracing::info!(worker = %self.workers[w].link.name, n = ids.len(), replayed, "assemblies restored");
                    }
                    // Deterministic solves that succeeded once cannot fail on replay: a
                    // model that does is not replayable, say which point.
                    Ok(Err((id, e))) => {
                        return Err(MaterialError::GaussPoints(vec![(
                            id,
                            format!("replay of a committed increment failed: {e}"),
                        )]));
                    }
                    Err(s) if is_worker_failure(&s) || s.code() == Code::ResourceExhausted => {
                        self.mark_dead(w, &s);
                        todo.extend(self.owned_by(w));
                        todo.extend(ids);
                    }
                    Err(s) => {
                        return Err(MaterialError::Unavailable(format!(
                            "restore on {}: {}",
                            self.workers[w].link.name,
                            s.message()
                        )));
                    }
                }
            }
            todo.sort();
            todo.dedup();
        }
        Ok(())
    }

    /// Solves `targets` at `trial` wherever their assemblies are, moving the assemblies of
    /// failed workers and solving them again until every Gauss point has an answer.
    async fn solve_all(
        &mut self,
        trial: TrialId,
        targets: &BTreeMap<GaussPointId, MacroDeformation>,
    ) -> Result<Outcomes, MaterialError> {
        let mut pending: Vec<GaussPointId> = targets.keys().copied().collect();
        let mut out = Outcomes::new();
        let mut first = true;
        // Ends: a pass that leaves work lost at least one worker (see `restore`).
        let mut rounds = 0usize;
        while !pending.is_empty() {
            rounds += 1;
            if rounds > self.workers.len() + 1 {
                return Err(MaterialError::Unavailable(format!(
                    "solve of {} gauss points still failing after {} rounds of worker losses",
                    pending.len(),
                    rounds - 1
                )));
            }
            if !first {
                self.stats.resolved += pending.len() as u64;
            }
            first = false;
            let mut by_worker: BTreeMap<usize, Vec<(GaussPointId, MacroDeformation)>> =
                BTreeMap::new();
            for id in &pending {
                by_worker.entry(self.owner[id]).or_default().push((*id, targets[id]));
            }
            let t = self.config.solve_timeout;
            let jobs = by_worker
                .into_iter()
                .map(|(w, items)| {
                    let link = self.workers[w].link.clone();
                    // A held-back commit is applied by the worker before this batch; if the
                    // worker fails instead, the restore replays it from the history.
                    let commit = self.deferred.remove(&w);
                    self.stats.carried_commits += u64::from(commit.is_some());
                    let job: Job<_> = Box::pin(async move {
                        link.solve(trial.step, trial.iteration, items, commit, t).await
                    });
                    (w, job)
                })
                .collect();
            let mut lost = Vec::new();
            for (w, r) in fan_out(jobs).await {
                match r {
                    Ok(results) => out.extend(results),
                    Err(s) if is_worker_failure(&s) => {
                        self.mark_dead(w, &s);
                        lost.extend(self.owned_by(w));
                    }
                    Err(s) => {
                        return Err(self.unavailable(w, "solve", &s));
                    }
                }
            }
            if lost.is_empty() {
                break;
            }
            self.restore(&lost).await?;
            // Everything that lived on a lost worker has lost its trial: solve it again.
            pending = lost.into_iter().filter(|id| targets.contains_key(id)).collect();
        }
        Ok(out)
    }

    async fn evaluate_async(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut targets = BTreeMap::new();
        let mut bad = Vec::new();
        for input in inputs {
            let id = input.gauss_point;
            if !self.owner.contains_key(&id) {
                return Err(MaterialError::Unavailable(format!(
                    "no assembly for {id}: call Pool::create_assemblies first"
                )));
            }
            if let Err(e) = input.deformation.validate() {
                bad.push((id, e.to_string()));
            }
            if targets.insert(id, input.deformation).is_some() {
                return Err(MaterialError::Unavailable(format!(
                    "{id} appears twice in one evaluation"
                )));
            }
        }
        if !bad.is_empty() {
            return Err(MaterialError::GaussPoints(bad));
        }
        if self.current_step != Some(trial.step) {
            self.step_boundary().await?;
            self.current_step = Some(trial.step);
        }
        let mut out = self.solve_all(trial, &targets).await?;
        self.last = Some((trial, targets));
        let mut responses = Vec::with_capacity(inputs.len());
        let mut failed = Vec::new();
        for input in inputs {
            match out.remove(&input.gauss_point) {
                Some(Ok(r)) => {
                    if let Some(c) = self.costs.get_mut(&input.gauss_point) {
                        // Smoothed, so that timing noise does not shuffle assemblies.
                        let t = r.diagnostics.wall_seconds;
                        c.seconds = Some(c.seconds.map_or(t, |old| 0.5 * (old + t)));
                    }
                    responses.push(r);
                }
                Some(Err(e)) => failed.push((input.gauss_point, e)),
                None => failed.push((input.gauss_point, "no answer from its worker".into())),
            }
        }
        if failed.is_empty() { Ok(responses) } else { Err(MaterialError::GaussPoints(failed)) }
    }

    async fn commit_async(&mut self, step: u64) -> Result<(), MaterialError> {
        let Some((trial, targets)) = self.last.clone() else {
            if step <= self.committed_step {
                return Ok(());
            }
            return Err(MaterialError::Unavailable(format!(
                "commit of step {step} without an evaluation"
            )));
        };
        if trial.step != step {
            return Err(MaterialError::Unavailable(format!(
                "commit of step {step}, but the last trial is of step {}",
                trial.step
            )));
        }
        self.flush_deferred().await?;
        let mut pending: Vec<GaussPointId> = targets.keys().copied().collect();
        // Ends: a pass that leaves work lost at least one worker (see `restore`).
        let mut rounds = 0usize;
        let every = self.config.export_every;
        while !pending.is_empty() {
            rounds += 1;
            if rounds > self.workers.len() + 1 {
                return Err(MaterialError::Unavailable(format!(
                    "commit of step {step} still failing after {} rounds of worker losses",
                    rounds - 1
                )));
            }
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for id in &pending {
                by_worker.entry(self.owner[id]).or_default().push(*id);
            }
            // Those that export nothing ride on their worker's next SolveBatch: taken as
            // committed here (the increments recorded for failover, as after an acknowledged
            // commit), sent with the next batch or before another call.
            let defer = self.config.defer_commits;
            let (held, by_worker): (BTreeMap<_, _>, BTreeMap<_, _>) = by_worker
                .into_iter()
                .partition(|(_, ids)| defer && !self.history.export_due(ids, every));
            for (w, ids) in held {
                for id in &ids {
                    self.history.record(
                        *id,
                        Increment { step, iteration: trial.iteration, target: targets[id] },
                    );
                }
                // The only commit held for `w` (flushed above): ids of a later round
                // (re-solved after a loss) join it.
                self.deferred
                    .entry(w)
                    .or_insert(PendingCommit { step, iteration: trial.iteration, ids: vec![] })
                    .ids
                    .extend(ids);
            }
            let t = self.config.call_timeout;
            let jobs = by_worker
                .iter()
                .map(|(w, ids)| {
                    let link = self.workers[*w].link.clone();
                    let ids = ids.clone();
                    let export = self.history.export_due(&ids, every);
                    let job: Job<_> = Box::pin(async move {
                        link.commit(&ids, step, trial.iteration, export, t).await
                    });
                    (*w, job)
                })
                .collect();
            let mut lost = Vec::new();
            for (w, r) in fan_out(jobs).await {
                match r {
                    Ok(states) => {
                        if !states.is_empty() {
                            self.stats.exports += 1;
                        }
                        let mut exported: BTreeMap<_, _> =
                            states.into_iter().map(|s| (s.id, s)).collect();
                        for id in &by_worker[&w] {
                            match exported.remove(id) {
                                Some(s) => self.history.store(s),
                                None => self.history.record(
                                    *id,
                                    Increment {
                                        step,
                                        iteration: trial.iteration,
                                        target: targets[id],
                                    },
                                ),
                            }
                        }
                    }
                    Err(s) if is_worker_failure(&s) => {
                        self.mark_dead(w, &s);
                        lost.extend(self.owned_by(w));
                    }
                    Err(s) => {
                        return Err(self.unavailable(w, "commit", &s));
                    }
                }
            }
            if lost.is_empty() {
                break;
            }
            // Back at their last committed step as the master knows it (those whose commit
            // was acknowledged before their worker died are at `step` already).
            self.restore(&lost).await?;
            // Those not committed yet lost their trial with their worker: solve it again.
            let redo: BTreeMap<_, _> = lost
                .iter()
                .filter(|id| self.history.committed_step(id).is_some_and(|s| s < step))
                .filter_map(|id| targets.get(id).map(|t| (*id, *t)))
                .collect();
            let again = self.solve_all(trial, &redo).await?;
            if let Some((id, e)) =
                again.iter().find_map(|(id, r)| r.as_ref().err().map(|e| (id, e)))
            {
                return Err(MaterialError::GaussPoints(vec![(
                    *id,
                    format!("re-solve after worker loss failed: {e}"),
                )]));
            }
            pending = redo.keys().copied().collect();
        }
        self.committed_step = step;
        self.last = None;
        Ok(())
    }

    /// Sends the held-back commits ([`PoolConfig::defer_commits`]) now, as Commit calls of
    /// their own: before any call that reads or discards states. A worker lost here is
    /// restored from the history, which holds the commit already.
    async fn flush_deferred(&mut self) -> Result<(), MaterialError> {
        if self.deferred.is_empty() {
            return Ok(());
        }
        let t = self.config.call_timeout;
        let jobs = std::mem::take(&mut self.deferred)
            .into_iter()
            .filter(|(w, _)| self.workers[*w].alive)
            .map(|(w, c)| {
                let link = self.workers[w].link.clone();
                let job: Job<_> =
                    Box::pin(
                        async move { link.commit(&c.ids, c.step, c.iteration, false, t).await },
                    );
                (w, job)
            })
            .collect();
        let mut lost = Vec::new();
        for (w, r) in fan_out(jobs).await {
            match r {
                Ok(_) => {}
                Err(s) if is_worker_failure(&s) => {
                    self.mark_dead(w, &s);
                    lost.extend(self.owned_by(w));
                }
                Err(s) => return Err(self.unavailable(w, "commit", &s)),
            }
        }
        self.restore(&lost).await
    }

    async fn rollback_async(&mut self) -> Result<(), MaterialError> {
        self.flush_deferred().await?;
        self.last = None;
        let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for (id, w) in &self.owner {
            by_worker.entry(*w).or_default().push(*id);
        }
        let t = self.config.call_timeout;
        let jobs = by_worker
            .into_iter()
            .map(|(w, ids)| {
                let link = self.workers[w].link.clone();
                let job: Job<_> = Box::pin(async move { link.rollback(&ids, t).await });
                (w, job)
            })
            .collect();
        let mut lost = Vec::new();
        for (w, r) in fan_out(jobs).await {
            match r {
                Ok(()) => {}
                Err(s) if is_worker_failure(&s) => {
                    self.mark_dead(w, &s);
                    lost.extend(self.owned_by(w));
                }
                Err(s) => {
                    return Err(MaterialError::Unavailable(format!(
                        "rollback on {}: {}",
                        self.workers[w].link.name,
                        s.message()
                    )));
                }
            }
        }
        // A restored assembly holds its committed state only: exactly a rollback.
        self.restore(&lost).await
    }

    /// At a new load step: admit returned or new workers, then rebalance.
    async fn step_boundary(&mut self) -> Result<(), MaterialError> {
        self.admit().await;
        let costs = effective_costs(&self.costs);
        let moves = rebalance(&self.owner, &costs, &self.alive(), self.config.rebalance_threshold);
        if moves.is_empty() {
            return Ok(());
        }
        // Migration exports committed states: the sources must hold them.
        self.flush_deferred().await?;
        let mut by_dest: BTreeMap<usize, Vec<(GaussPointId, usize)>> = BTreeMap::new();
        for (id, from, to) in moves {
            by_dest.entry(to).or_default().push((id, from));
        }
        let t = self.config.call_timeout;
        let mut lost = Vec::new();
        // Fresh committed states from the current owners (exact, and no replay needed on the
        // destination); a source that fails is restored with the others at the end.
        let mut by_source: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for list in by_dest.values() {
            for (id, from) in list {
                by_source.entry(*from).or_default().push(*id);
            }
        }
        let jobs = by_source
            .iter()
            .map(|(from, ids)| {
                let link = self.workers[*from].link.clone();
                let ids = ids.clone();
                let job: Job<_> = Box::pin(async move { link.export(&ids, t).await });
                (*from, job)
            })
            .collect();
        for (from, r) in fan_out(jobs).await {
            match r {
                Ok(states) => {
                    for s in states {
                        self.history.store(s);
                    }
                }
                Err(s) => {
                    if is_worker_failure(&s) {
                        self.mark_dead(from, &s);
                        lost.extend(self.owned_by(from));
                    } else {
                        tracing::warn!(worker = %self.workers[from].link.name, error = %s.message(), "export for migration refused");
                    }
                    for list in by_dest.values_mut() {
                        list.retain(|(_, f)| *f != from);
                    }
                }
            }
        }
        by_dest.retain(|_, list| !list.is_empty());
        let mut jobs = Vec::new();
        for (to, list) in &by_dest {
            let mut states = Vec::with_capacity(list.len());
            for (id, _) in list {
                let s = self.history.state(id).ok_or_else(|| {
                    MaterialError::Unavailable(format!("no stored state for {id}"))
                })?;
                states.push(s.clone());
            }
            let link = self.workers[*to].link.clone();
            let job: Job<_> = Box::pin(async move { link.import(states, t).await });
            jobs.push((*to, job));
        }
        let mut drops: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for (to, r) in fan_out(jobs).await {
            match r {
                Ok(()) => {
                    for (id, from) in &by_dest[&to] {
                        self.owner.insert(*id, to);
                        drops.entry(*from).or_default().push(*id);
                        self.stats.migrated += 1;
                    }
                }
                Err(s) if is_worker_failure(&s) => {
                    self.mark_dead(to, &s);
                    lost.extend(self.owned_by(to));
                }
                // A full destination keeps nothing new; the assemblies stay where they are.
                Err(s) => {
                    tracing::warn!(worker = %self.workers[to].link.name, error = %s.message(), "migration refused")
                }
            }
        }
        for (from, ids) in drops {
            if let Err(s) = self.workers[from].link.drop_assemblies(&ids, t).await {
                tracing::warn!(worker = %self.workers[from].link.name, error = %s.message(), "drop after migration failed");
            }
        }
        self.restore(&lost).await
    }

    /// Admits returned or new workers: takes up the result of the last admission attempt if
    /// it has finished, else (none running) starts one (re-resolving the worker addresses and
    /// trying every address with no live worker) and waits for it at most
    /// [`PoolConfig::admit_wait`]. An attempt still running goes on in the background.
    async fn admit(&mut self) {
        if self.sources.is_empty() {
            return;
        }
        let task = match self.admission.take() {
            Some(t) => t,
            None => {
                let all_alive = self.workers.iter().all(|w| w.alive);
                let recent =
                    self.admitted_at.is_some_and(|t| t.elapsed() < self.config.admit_interval);
                if all_alive && recent {
                    return;
                }
                self.admitted_at = Some(std::time::Instant::now());
                let live: Vec<SocketAddr> =
                    self.workers.iter().filter(|w| w.alive).filter_map(|w| w.addr).collect();
                let (sources, config) = (self.sources.clone(), self.config.clone());
                self.handle.spawn(async move {
                    let addrs = resolve_all(&sources, config.connect_timeout).await;
                    let candidates = addrs.into_iter().filter(|a| !live.contains(a)).collect();
                    try_admit(candidates, config).await
                })
            }
        };
        let mut task = task;
        let found = match tokio::time::timeout(self.config.admit_wait, &mut task).await {
            Ok(Ok(found)) => found,
            Ok(Err(e)) => {
                tracing::warn!("worker admission task lost: {e}");
                return;
            }
            Err(_) => {
                tracing::debug!("worker admission still running: taken up at a later step");
                self.admission = Some(task);
                return;
            }
        };
        for (addr, link) in found {
            if self.workers.iter().any(|w| w.alive && w.addr == Some(addr)) {
                continue;
            }
            tracing::info!(%addr, "worker admitted");
            self.stats.workers_admitted += 1;
            match self.workers.iter_mut().find(|w| w.addr == Some(addr)) {
                Some(w) => {
                    w.link = link;
                    w.alive = true;
                }
                None => self.workers.push(Worker { link, addr: Some(addr), alive: true }),
            }
        }
    }
}

impl Material for Pool {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let h = self.handle.clone();
        h.block_on(self.evaluate_async(trial, inputs))
    }

    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        let h = self.handle.clone();
        h.block_on(self.commit_async(step))
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        let h = self.handle.clone();
        h.block_on(self.rollback_async())
    }

    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        let h = self.handle.clone();
        h.block_on(self.export_all())?;
        Ok(Some(self.history.states().values().cloned().collect()))
    }

    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        let h = self.handle.clone();
        h.block_on(self.import_states(states))
    }

    fn snapshot(&mut self, id: GaussPointId) -> Result<Option<MicroSnapshot>, MaterialError> {
        Pool::snapshot(self, id).map(Some).map_err(|e| MaterialError::Unavailable(e.to_string()))
    }
}
