//! The workers of a pool and where the assemblies live: building a pool (remote workers by
//! address, or in-process ones), the admission of returned or new workers at load steps, and
//! the placement of new assemblies by expected cost ([`balance`](crate::balance)).

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
