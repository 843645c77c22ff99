//! The workers of a pool and where the assemblies live: building a pool (remote workers by
//! address, or in-process ones), the admission of returned or new workers at load steps, and
//! the placement of new assemblies by expected cost ([`balance`](crate::balance)).

use crate::address::{check_address, resolve, resolve_all};
use crate::balance::{Cost, effective_costs, place};
use crate::fanout::{Job, fan_out};
use crate::link::{self, Link, WorkerInfo};
use crate::{Pool, PoolConfig, PoolError, PoolStats};
use cosdem_common::GaussPointId;
use cosdem_common::micro::AssemblyRequest;
use cosdem_worker::{Limits, MicroModel, WorkerConfig, serve_duplex};
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::time::Duration;
use tonic::{Code, Status};

/// One worker as the pool sees it.
pub(crate) struct Worker {
    /// How to call it.
    pub(crate) link: Link,
    /// Its address (none for an in-process worker): how a returned worker is recognized.
    pub(crate) addr: Option<SocketAddr>,
    /// False once it is lost (until it is admitted again).
    pub(crate) alive: bool,
}

fn runtime(threads: usize) -> Result<tokio::runtime::Runtime, PoolError> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(threads.max(1))
        .thread_name("cosdem-pool")
        .enable_all()
        .build()
        .map_err(|e| PoolError::Config(format!("tokio runtime: {e}")))
}

/// The error for a worker that refused a call while the pool was being set up.
pub(crate) fn refused(worker: &str, s: &Status) -> PoolError {
    PoolError::Refused { worker: worker.into(), code: s.code(), message: s.message().into() }
}

/// Ids per CreateAssemblies request to a worker of `memory` bytes (0: unknown) for
/// assemblies of `discs` discs each: within the worker's per-request caps
/// ([`Limits::MAX_IDS_PER_REQUEST`], [`Limits::request_disc_cap`]), at least one.
fn request_size(discs: u64, memory: u64) -> usize {
    let by_discs = Limits::request_disc_cap((memory > 0).then_some(memory)) / discs.max(1);
    (by_discs.min(Limits::MAX_IDS_PER_REQUEST as u64) as usize).max(1)
}

/// A CreateAssemblies past its deadline, naming the setting and its value.
fn create_deadline_named(
    s: Status,
    ids: usize,
    discs: u64,
    deadline: Duration,
    scaled: bool,
) -> Status {
    if s.code() != Code::DeadlineExceeded {
        return s;
    }
    let how = if scaled {
        format!(
            "create_timeout unset: call_timeout plus {:e} s x discs^1.5 for {discs} discs \
             (PoolConfig::create_deadline)",
            crate::config::CREATE_SECONDS_PER_DISC_POW
        )
    } else {
        "create_timeout".into()
    };
    Status::deadline_exceeded(format!(
        "CreateAssemblies of {ids} assemblies of about {discs} discs: {}; the deadline is \
         {deadline:?} ({how}; set PoolConfig::create_timeout for more)",
        s.message()
    ))
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

/// A status by which a cosdem worker refuses this master on purpose (wrong or missing token,
/// another protocol version): a configuration to fix, so an error, not a worker to skip.
fn is_refusal(s: &Status) -> bool {
    matches!(s.code(), Code::Unauthenticated | Code::PermissionDenied | Code::FailedPrecondition)
}

impl Pool {
    /// Connects to workers given as `host:port` (each name may resolve to several addresses,
    /// one worker each) and shakes hands with each. An address of no such form is an error
    /// naming it. Unreachable addresses are skipped with a warning, and so are endpoints whose
    /// handshake fails (not a cosdem worker: an HTTP server, garbage), naming the address and
    /// the reason; a refusal by a worker (token, protocol version, either side's check) is an
    /// error. With no worker left: the first failed handshake as the error, else "none
    /// answered".
    pub fn connect(addresses: &[String], config: PoolConfig) -> Result<Pool, PoolError> {
        if addresses.is_empty() {
            return Err(PoolError::Config("no worker addresses given".into()));
        }
        for a in addresses {
            check_address(a)?;
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
            let mut failed = None;
            for addr in addrs {
                if pool.workers.iter().any(|w| w.addr == Some(addr)) {
                    continue;
                }
                let c = &pool.config;
                match link::connect_tcp(addr, c).await {
                    Ok(link) => {
                        // One master per worker: whatever a previous master left is stale.
                        let t = c.call_timeout;
                        link.drop_assemblies(&[], t).await.map_err(|s| refused(&link.name, &s))?;
                        pool.workers.push(Worker { link, addr: Some(addr), alive: true });
                    }
                    Err(s) if matches!(s.code(), Code::Unavailable | Code::DeadlineExceeded) => {
                        tracing::warn!(%addr, error = %s.message(), "worker unreachable, skipped");
                    }
                    Err(s) if is_refusal(&s) => return Err(refused(&addr.to_string(), &s)),
                    Err(s) => {
                        tracing::warn!(
                            %addr, code = ?s.code(), error = %s.message(),
                            "not a cosdem worker (its handshake failed), skipped"
                        );
                        failed.get_or_insert_with(|| refused(&addr.to_string(), &s));
                    }
                }
            }
            match failed {
                Some(e) if pool.workers.is_empty() => Err(e),
                _ => Ok(()),
            }
        })?;
        if pool.workers.is_empty() {
            return Err(PoolError::Unavailable(format!("none of {:?} answered", addresses)));
        }
        Ok(pool)
    }

    /// How many in-process workers a job asking for `asked` gets: at most this machine's
    /// cores (`std::thread::available_parallelism`), at least one. More buy nothing (results
    /// do not depend on the worker count, so the cap changes no output), and each holds
    /// threads of its own: `[workers] in_process = 100000` exhausted them. Logs the cap.
    pub fn in_process_workers(asked: usize) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        if asked > cores {
            tracing::info!(asked, cores, "in-process workers capped at this machine's cores");
        }
        asked.clamp(1, cores)
    }

    /// `n` workers inside this process, each a full MicroSolver service (request decoding,
    /// token check, limits, response encoding: the code path of the network without the
    /// network) called directly in the pool's task, or, with
    /// [`PoolConfig::in_process_duplex`], reached over an in-memory `tokio::io::duplex`
    /// HTTP/2 connection. `factory(i)` builds worker `i`'s model. What `cosdem run` uses
    /// without `--workers`, for [`Pool::in_process_workers`] of the job's count. Each worker
    /// runs `in_process_threads` relaxation threads, at most the machine's cores.
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
        // More threads per worker than cores buy nothing (results do not depend on them).
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let asked = pool.config.in_process_threads;
        if asked > cores {
            tracing::info!(
                asked,
                cores,
                "in-process worker threads capped at this machine's cores"
            );
        }
        let threads = if asked > 0 { asked.min(cores) } else { (cores / n).max(1) };
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
            history: Default::default(),
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

    /// The live workers: (index, cores).
    pub(crate) fn alive(&self) -> Vec<(usize, u32)> {
        self.workers
            .iter()
            .enumerate()
            .filter(|(_, w)| w.alive)
            .map(|(i, w)| (i, w.link.info.cores))
            .collect()
    }

    /// The load of each live worker: the costs of its assemblies per core.
    pub(crate) fn loads(&self) -> BTreeMap<usize, f64> {
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

    /// The assemblies worker `w` holds.
    pub(crate) fn owned_by(&self, w: usize) -> Vec<GaussPointId> {
        self.owner.iter().filter(|(_, o)| **o == w).map(|(id, _)| *id).collect()
    }

    async fn create_async(
        &mut self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
    ) -> Result<(), PoolError> {
        if let Some(id) = ids.iter().find(|id| self.owner.contains_key(id)) {
            return Err(PoolError::Config(format!("assembly for {id} already created")));
        }
        let hint = spec.disc_count_hint.max(1);
        let t = self.config.call_timeout;
        let deadline = self.config.create_deadline(spec.disc_count_hint);
        let scaled = self.config.create_timeout.is_none();
        // A worker lost while creating (its CreateAssemblies or the export after it failed
        // with a worker failure: killed, stopped past the deadline, shutting down, garbage)
        // takes the loss path: marked lost, what it held before restored on the others
        // (`Pool::recover`), and its share of this creation placed again on the live workers.
        // Creation is a deterministic function of the spec and the id, so where an assembly
        // is built changes no result.
        let mut todo: Vec<GaussPointId> = ids.to_vec();
        let mut rounds = crate::recovery::Rounds::default();
        // The last worker failure, as the error once no worker is left (a CreateAssemblies
        // past its deadline names the setting: `create_deadline_named`).
        let mut last_loss: Option<PoolError> = None;
        while !todo.is_empty() {
            let alive = self.alive();
            if alive.is_empty() {
                return Err(last_loss
                    .unwrap_or_else(|| PoolError::Unavailable("every worker is lost".into())));
            }
            if let Some(done) = rounds.start(self.workers.len()) {
                return Err(PoolError::Unavailable(format!(
                    "creation of {} assemblies still failing after {done} rounds of worker losses",
                    todo.len()
                )));
            }
            let mut load = self.loads();
            let new: Vec<_> = todo.iter().map(|id| (*id, hint as f64)).collect();
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for (id, w) in place(&new, &alive, &mut load) {
                by_worker.entry(w).or_default().push(id);
            }
            let jobs = by_worker
                .iter()
                .map(|(w, ids)| {
                    let link = self.workers[*w].link.clone();
                    let spec = spec.clone();
                    let ids = ids.clone();
                    let per = request_size(hint, link.info.memory_bytes);
                    let job: Job<_> = Box::pin(async move {
                        let mut infos = Vec::with_capacity(ids.len());
                        for part in ids.chunks(per) {
                            let got = link.create(part, &spec, deadline).await.map_err(|s| {
                                create_deadline_named(
                                    s,
                                    part.len(),
                                    spec.disc_count_hint,
                                    deadline,
                                    scaled,
                                )
                            })?;
                            infos.extend(got);
                        }
                        let states = link.export(&ids, t).await?;
                        Ok((infos, states))
                    });
                    (*w, job)
                })
                .collect();
            let mut lost = crate::recovery::Lost::default();
            for (w, r) in fan_out(jobs).await {
                match r {
                    Err(s) if link::is_worker_failure(&s) => {
                        let why =
                            Status::new(s.code(), format!("{}; every worker is lost", s.message()));
                        last_loss = Some(refused(&self.workers[w].link.name, &why));
                        self.lose(w, &s, &mut lost);
                    }
                    r => {
                        let (infos, states) =
                            r.map_err(|s| refused(&self.workers[w].link.name, &s))?;
                        for i in infos {
                            self.owner.insert(i.id, w);
                            self.costs.insert(i.id, Cost { discs: i.disc_count, seconds: None });
                        }
                        for s in states {
                            self.history.store(s);
                        }
                    }
                }
            }
            // What the lost workers were to build is built again elsewhere; what they held
            // from earlier creations is restored from its committed history.
            todo = lost.workers().iter().flat_map(|w| by_worker[w].iter().copied()).collect();
            if self.alive().is_empty() {
                return Err(last_loss
                    .unwrap_or_else(|| PoolError::Unavailable("every worker is lost".into())));
            }
            self.recover(lost, crate::recovery::Redo::Nothing)
                .await
                .map_err(|e| PoolError::Unavailable(e.to_string()))?;
        }
        Ok(())
    }

    /// Admits returned or new workers: takes up the result of the last admission attempt if
    /// it has finished, else (none running) starts one (re-resolving the worker addresses and
    /// trying every address with no live worker) and waits for it at most
    /// [`PoolConfig::admit_wait`]. An attempt still running goes on in the background.
    pub(crate) async fn admit(&mut self) {
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
