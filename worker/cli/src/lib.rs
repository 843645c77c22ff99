//! The command line of the `cosdem-worker` binary, for the binaries that serve a worker: the
//! `listen` arguments and their conversion into the service's [`WorkerConfig`] (the service
//! library knows no clap). The test worker of `cosdem-tests` takes the same arguments.

use cosdem_worker::{Limits, ServiceError, TlsIdentity, Token, WorkerConfig};
use std::net::SocketAddr;
use std::path::PathBuf;

/// `cosdem-worker listen` arguments. The binary parses them and converts with `try_into()`.
#[derive(Clone, Debug, clap::Args)]
pub struct ListenArgs {
    /// Address to listen on, e.g. 127.0.0.1:7700 or 0.0.0.0:7700 (the latter needs a token).
    /// Port 7700 is the one `health --addr`, the docs and the deploy files use.
    #[arg(long, default_value = "127.0.0.1:7700")]
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
    fn try_from(a: ListenArgs) -> Result<Self, ServiceError> {
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
