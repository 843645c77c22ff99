//! The command line of the `cosdem-worker` binary, for the binaries that serve a worker: the
//! `listen` arguments and their conversion into the service's [`WorkerConfig`] (the service
//! library knows no clap). The test worker of `cosdem-tests` takes the same arguments.

use cosdem_worker::{Limits, ServeOptions, ServiceError, TlsIdentity, Token, WorkerConfig};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

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
    /// Most discs held at once, over all assemblies (0 = as many as this machine's memory
    /// holds, at 1 KiB a disc).
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
    /// Seconds a worker asked to stop (SIGTERM, Ctrl-C) lets its calls in flight finish,
    /// answering new ones UNAVAILABLE, before it exits anyway. Keep it below the engine's
    /// own (10 s for `docker stop`, 30 s for Kubernetes' terminationGracePeriodSeconds).
    #[arg(long, default_value_t = 8.0, value_name = "SECS")]
    pub grace_period: f64,
}

impl ListenArgs {
    /// How the worker stops: [`ServeOptions`] with `--grace-period` (no hook). A grace period
    /// that is negative, not a number or over a day is refused, naming the option and value.
    pub fn serve_options(&self) -> Result<ServeOptions, ServiceError> {
        let g = self.grace_period;
        let grace_period = Duration::try_from_secs_f64(g)
            .ok()
            .filter(|d| *d <= Duration::from_secs(86_400))
            .ok_or_else(|| {
                ServiceError::Config(format!(
                    "--grace-period {g:?}: must be a number of seconds from 0 to 86400"
                ))
            })?;
        Ok(ServeOptions { grace_period, ..ServeOptions::default() })
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        listen: ListenArgs,
    }

    fn options(args: &[&str]) -> Result<ServeOptions, ServiceError> {
        let cli = Cli::try_parse_from(std::iter::once("test").chain(args.iter().copied())).unwrap();
        cli.listen.serve_options()
    }

    #[test]
    fn the_grace_period_defaults_to_8_s_below_docker_s_10_and_is_checked_by_name() {
        assert_eq!(options(&[]).unwrap().grace_period, Duration::from_secs(8));
        assert_eq!(options(&[]).unwrap().grace_period, cosdem_worker::DEFAULT_GRACE_PERIOD);
        let half = options(&["--grace-period", "0.5"]).unwrap();
        assert_eq!(half.grace_period, Duration::from_millis(500));
        assert!(half.hook.is_none());
        for bad in ["-1", "NaN", "1e308"] {
            let e = options(&[&format!("--grace-period={bad}")]).unwrap_err().to_string();
            assert!(e.contains("--grace-period") && e.contains(bad), "{bad}: {e}");
        }
    }
}
