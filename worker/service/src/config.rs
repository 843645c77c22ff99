//! Worker configuration and the `listen` command-line arguments that build it.

use super::auth::Token;
use super::error::{Result, ServiceError};
use std::net::SocketAddr;
use std::path::PathBuf;

/// Limits a worker enforces (RESOURCE_EXHAUSTED beyond them; 0 = unlimited).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Assemblies held at once.
    pub max_assemblies: u64,
    /// Discs summed over all assemblies held.
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
    /// Relaxation threads (0 = one per core).
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

    /// Relaxation threads actually used.
    pub fn thread_count(&self) -> usize {
        if self.threads > 0 {
            self.threads
        } else {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        }
    }
}

/// `cosdem-worker listen` arguments. The binary parses them and converts with `try_into()`.
#[derive(Clone, Debug, clap::Args)]
pub struct ListenArgs {
    /// Address to listen on, e.g. 127.0.0.1:50051 or 0.0.0.0:50051 (the latter needs a token).
    #[arg(long, default_value = "127.0.0.1:50051")]
    pub listen: SocketAddr,
    /// File holding the shared secret (else the COSDEM_TOKEN environment variable).
    #[arg(long)]
    pub token_file: Option<PathBuf>,
    /// Relaxation threads (0 = one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Most assemblies held at once (0 = unlimited).
    #[arg(long, default_value_t = 0)]
    pub max_assemblies: u64,
    /// Most discs held at once, over all assemblies (0 = unlimited).
    #[arg(long, default_value_t = 0)]
    pub max_discs: u64,
    /// TLS certificate chain (PEM); with `--tls-key`, serves TLS (needs the `tls` feature).
    #[arg(long, requires = "tls_key")]
    pub tls_cert: Option<PathBuf>,
    /// TLS private key (PEM).
    #[arg(long, requires = "tls_cert")]
    pub tls_key: Option<PathBuf>,
    /// Largest gRPC message, in MiB.
    #[arg(long, default_value_t = 256)]
    pub max_message_mib: usize,
}

impl TryFrom<ListenArgs> for WorkerConfig {
    type Error = ServiceError;
    fn try_from(a: ListenArgs) -> Result<Self> {
        let config = WorkerConfig {
            listen: a.listen,
            token: Token::load(a.token_file.as_deref())?,
            threads: a.threads,
            limits: Limits {
                max_assemblies: a.max_assemblies,
                max_discs: a.max_discs,
                max_message_bytes: a.max_message_mib.saturating_mul(1024 * 1024),
            },
            tls: match (&a.tls_cert, &a.tls_key) {
                (Some(c), Some(k)) => Some(TlsIdentity::load(c, k)?),
                _ => None,
            },
        };
        config.validate()?;
        Ok(config)
    }
}
