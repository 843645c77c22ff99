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
//! # Limits
//! An address of no `host:port` form is an error naming it; an endpoint whose handshake fails
//! (not a cosdem worker) is skipped with a warning, a worker of another protocol version or
//! with another token is refused. A worker's share of a creation goes in requests within its
//! per-request caps ([`cosdem_worker::Limits::MAX_IDS_PER_REQUEST`], the disc cap of its
//! memory), each bounded by [`PoolConfig::create_deadline`]; calls that carry assembly states
//! are split to stay within the message limit ([`PoolConfig::max_message_bytes`] and the
//! worker's), and a state that cannot fit is an error naming the limit and the sizes. A
//! job's in-process workers are at most the machine's cores ([`Pool::in_process_workers`]).
//! Text from a worker (its build id, its statuses) is made printable before it is logged.
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

/// Worker addresses: their form checked, their names resolved.
mod address;
/// Placement and rebalancing of assemblies: pure functions on costs and capacities.
mod balance;
/// Commit, rollback, export and import of the committed states.
mod commit;
/// [`PoolConfig`], its defaults and validation.
mod config;
/// DEM assemblies solved in the caller's thread, with no pool.
mod direct;
/// One call per worker at once; the evaluation of one Newton iteration.
mod fanout;
/// One worker seen from the master: transport, handshake, calls.
mod link;
/// The workers: building a pool, admission, placement of new assemblies.
mod membership;
/// Calls carrying states split within the message limit; failures for size named.
mod message;
/// The step boundary: admission, rebalancing, migration.
mod migration;
/// The one worker-loss path: mark dead, restore, redo.
mod recovery;
pub mod replay;

pub use balance::Cost;
pub use config::{CREATE_SECONDS_PER_DISC_POW, ClientTls, PoolConfig};
pub use direct::DirectDem;
pub use link::WorkerInfo;

use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use link::{Link, PendingCommit};
use membership::Worker;
use replay::History;
use std::collections::BTreeMap;
use std::net::SocketAddr;
use tonic::Code;

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

/// The DEM-backed material: a set of workers holding one assembly per Gauss point.
pub struct Pool {
    /// The pool's own runtime (taken when the pool is dropped).
    rt: Option<tokio::runtime::Runtime>,
    /// Where the pool's calls run.
    handle: tokio::runtime::Handle,
    config: PoolConfig,
    /// The worker addresses as given (re-resolved at admission); empty in process.
    sources: Vec<String>,
    /// Every worker ever used, by index (a lost one stays, marked dead).
    workers: Vec<Worker>,
    /// Which worker holds each assembly.
    owner: BTreeMap<GaussPointId, usize>,
    /// The committed history of each assembly, for failover.
    history: History,
    /// What each assembly costs, for placement.
    costs: BTreeMap<GaussPointId, Cost>,
    /// The last trial evaluated and its targets (what a commit commits).
    last: Option<(TrialId, BTreeMap<GaussPointId, MacroDeformation>)>,
    /// The load step of the last evaluation.
    current_step: Option<u64>,
    /// The last step committed.
    committed_step: u64,
    stats: PoolStats,
    /// An admission attempt still running in the background.
    admission: Option<tokio::task::JoinHandle<Vec<(SocketAddr, Link)>>>,
    /// When the last admission attempt started.
    admitted_at: Option<std::time::Instant>,
    /// Commits held back per worker, to ride on its next SolveBatch
    /// ([`PoolConfig::defer_commits`]).
    deferred: BTreeMap<usize, PendingCommit>,
    /// Stop signals of the in-process duplex servers.
    _stops: Vec<tokio::sync::oneshot::Sender<()>>,
}

impl Pool {
    /// Counters of failures, restorations and migrations.
    pub fn stats(&self) -> PoolStats {
        self.stats
    }
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
