//! How the pool talks to its workers: [`PoolConfig`], its defaults and their validation.

use crate::PoolError;
use cosdem_worker::Token;
use std::time::Duration;

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
    /// Deadline of every call but SolveBatch and CreateAssemblies.
    pub call_timeout: Duration,
    /// Deadline of one CreateAssemblies call. `None` (the default): scaled with the work,
    /// [`PoolConfig::create_deadline`] (building a random packing of 60 000 discs takes
    /// minutes: a fixed 60 s failed it).
    pub create_timeout: Option<Duration>,
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

/// Seconds per `discs^1.5` that building one assembly may take before its CreateAssemblies
/// is given up, when no `create_timeout` is set. A random packing's generation relaxes the
/// specimen through many compression stages, each in steps growing with its side (`n^0.5`)
/// of work proportional to `n`. Measured (2 cores, test profile): 1081 discs in 0.7 s, 4323
/// in 4.7 s, i.e. about `1.7e-5 n^1.5` s; this allows six times that (60 000 discs: about
/// 25 min on top of `call_timeout`). A hexagonal packing builds in milliseconds and gets the
/// `call_timeout` floor.
pub const CREATE_SECONDS_PER_DISC_POW: f64 = 1e-4;

impl PoolConfig {
    /// The deadline of a CreateAssemblies call building assemblies of `discs` discs each (the
    /// spec's hint): `create_timeout` if set, else `call_timeout` plus
    /// [`CREATE_SECONDS_PER_DISC_POW`]` * discs^1.5` (one specimen is built per call and copied
    /// to its Gauss points, so the number of ids barely counts), capped at a day.
    pub fn create_deadline(&self, discs: u64) -> Duration {
        if let Some(t) = self.create_timeout {
            return t;
        }
        let build = CREATE_SECONDS_PER_DISC_POW * (discs as f64).powf(1.5);
        self.call_timeout + Duration::from_secs_f64(build.min(86_400.0))
    }

    /// Refuses values the pool cannot work with, naming the field and the value.
    pub fn validate(&self) -> Result<(), PoolError> {
        if self.export_every == 0 {
            return Err(PoolError::Config("export_every = 0: must be at least 1".into()));
        }
        if self.max_message_bytes == 0 {
            return Err(PoolError::Config("max_message_bytes = 0: must be positive".into()));
        }
        if self.create_timeout == Some(Duration::ZERO) {
            return Err(PoolError::Config("create_timeout = 0 s: must be positive".into()));
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
            create_timeout: None,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_validate_and_zero_export_every_or_message_size_is_refused_by_name() {
        assert!(PoolConfig::default().validate().is_ok());
        let e = PoolConfig { export_every: 0, ..PoolConfig::default() }.validate().unwrap_err();
        assert!(e.to_string().contains("export_every = 0"), "{e}");
        let e =
            PoolConfig { max_message_bytes: 0, ..PoolConfig::default() }.validate().unwrap_err();
        assert!(e.to_string().contains("max_message_bytes = 0"), "{e}");
    }
}
