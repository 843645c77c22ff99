//! Worker configuration: the address, token, threads, limits and TLS identity [`super::serve`]
//! needs. (The `cosdem-worker listen` arguments that build it live in `cosdem-worker-cli`.)

use super::auth::Token;
use super::error::{Result, ServiceError};
use std::net::SocketAddr;

/// Limits a worker enforces (RESOURCE_EXHAUSTED beyond them, naming the limit and the value;
/// 0 = unlimited). Besides these settings, every worker refuses, before building anything, a
/// CreateAssemblies request of more than [`Limits::MAX_IDS_PER_REQUEST`] ids or of more discs
/// than [`Limits::request_disc_cap`] of its memory, and (with `max_discs = 0`) more discs held
/// in all than [`Limits::memory_disc_cap`] of its memory: past those the allocator would abort the worker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Assemblies held at once.
    pub max_assemblies: u64,
    /// Discs summed over all assemblies held (0: as many as the machine's memory holds,
    /// [`Limits::memory_disc_cap`]).
    pub max_discs: u64,
    /// Largest gRPC message in either direction (bytes). Beyond it tonic answers
    /// OUT_OF_RANGE (its code for an oversized frame), before the service sees the call.
    pub max_message_bytes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_assemblies: 0,
            max_discs: 0,
            max_message_bytes: cosdem_proto::DEFAULT_MAX_MESSAGE_BYTES,
        }
    }
}

impl Limits {
    /// Most Gauss points one CreateAssemblies request may name. Fixed (not a setting), so
    /// that a master knows it without asking: `cosdem_pool` sends a worker's share of a
    /// creation in requests of at most this many ids. 16 384 assemblies of the default
    /// hexagonal packing (105 discs) take about 0.4 GB; one request of 100 000 took 2.1 GB.
    pub const MAX_IDS_PER_REQUEST: usize = 16_384;

    /// Memory one disc held by a worker may take, in bytes, for the caps derived from the
    /// machine's memory: its assembly's committed state (about 200 bytes a disc measured on
    /// assemblies of the default packing, with the Verlet list and contact histories), a trial
    /// state of the same size while a step is open, and the relaxation's scratch arrays. A
    /// conservative figure: about twice what was measured.
    pub const BYTES_PER_DISC_HELD: u64 = 1024;

    /// This machine's memory in bytes (`MemTotal` of `/proc/meminfo`); `None` where unknown.
    pub fn machine_memory() -> Option<u64> {
        let text = std::fs::read_to_string("/proc/meminfo").ok()?;
        let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib.saturating_mul(1024))
    }

    /// Discs a worker with `memory` bytes may hold in all when no `max_discs` is set: what
    /// its memory holds at [`Limits::BYTES_PER_DISC_HELD`] a disc (`u64::MAX` when the memory
    /// is unknown).
    pub fn memory_disc_cap(memory: Option<u64>) -> u64 {
        memory.map_or(u64::MAX, |m| (m / Self::BYTES_PER_DISC_HELD).max(1))
    }

    /// Discs one CreateAssemblies request may ask a worker with `memory` bytes to build (disc
    /// count hint times ids): half of [`Limits::memory_disc_cap`], so that a single request
    /// cannot take the machine (`u64::MAX` when the memory is unknown).
    pub fn request_disc_cap(memory: Option<u64>) -> u64 {
        memory.map_or(u64::MAX, |m| (m / 2 / Self::BYTES_PER_DISC_HELD).max(1))
    }
}

/// A TLS identity for the listener: certificate chain and private key, PEM. Only used when
/// the crate is built with the `tls` feature; `Debug` never shows the key.
#[derive(Clone, PartialEq, Eq)]
pub struct TlsIdentity {
    /// Certificate chain (PEM).
    pub cert_pem: Vec<u8>,
    /// Private key (PEM).
    pub key_pem: Vec<u8>,
}

impl std::fmt::Debug for TlsIdentity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TlsIdentity(<redacted>)")
    }
}

impl TlsIdentity {
    /// Reads the certificate and key files.
    pub fn load(cert: &std::path::Path, key: &std::path::Path) -> Result<Self> {
        let read = |p: &std::path::Path| {
            std::fs::read(p).map_err(|e| ServiceError::Config(format!("{}: {e}", p.display())))
        };
        Ok(TlsIdentity { cert_pem: read(cert)?, key_pem: read(key)? })
    }
}

/// Everything [`super::serve`] needs.
#[derive(Clone, Debug)]
pub struct WorkerConfig {
    /// Address to listen on (port 0 picks a free port).
    pub listen: SocketAddr,
    /// Shared secret; required when `listen` is not a loopback address.
    pub token: Option<Token>,
    /// Relaxation threads (0 = one per core; more than the cores count as the cores).
    pub threads: usize,
    /// Limits.
    pub limits: Limits,
    /// Serve TLS with this identity (needs the `tls` feature); the token is still checked.
    pub tls: Option<TlsIdentity>,
}

impl Default for WorkerConfig {
    fn default() -> Self {
        Self {
            listen: SocketAddr::from(([127, 0, 0, 1], 0)),
            token: None,
            threads: 0,
            limits: Limits::default(),
            tls: None,
        }
    }
}

impl WorkerConfig {
    /// Refuses a public listener without a token.
    pub fn validate(&self) -> Result<()> {
        if self.token.is_none() && !self.listen.ip().is_loopback() {
            return Err(ServiceError::Config(format!(
                "refusing to listen on non-loopback address {} without a token \
                 (set COSDEM_TOKEN or --token-file)",
                self.listen
            )));
        }
        if self.tls.is_some() && !cfg!(feature = "tls") {
            return Err(ServiceError::Config(
                "TLS asked for, but built without the `tls` feature".into(),
            ));
        }
        if self.limits.max_message_bytes == 0 {
            return Err(ServiceError::Config("max message size must be > 0".into()));
        }
        Ok(())
    }

    /// Relaxation threads actually used: `threads`, at most the machine's cores (more would
    /// only contend for them, and results do not depend on the thread count), or one per
    /// core for 0.
    pub fn thread_count(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        match self.threads {
            0 => cores,
            n => n.min(cores),
        }
    }
}

#[cfg(test)]
mod thread_tests {
    use super::WorkerConfig;

    /// `--threads 100000` made a pool of 100 000 threads: the count is capped at the cores.
    #[test]
    fn thread_counts_are_capped_at_the_cores() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let with = |threads| WorkerConfig { threads, ..WorkerConfig::default() }.thread_count();
        assert_eq!(with(0), cores);
        assert_eq!(with(100_000), cores);
        assert_eq!(with(1), 1);
    }
}
