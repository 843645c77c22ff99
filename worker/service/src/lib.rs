//! The worker's gRPC service (`cosdem.v1.MicroSolver`) around a [`MicroModel`].
//!
//! - [`serve`] listens on TCP until a shutdown future resolves (use [`shutdown_signal`] for
//!   SIGTERM / Ctrl-C), then drains within a grace period ([`drain`]: new calls answered
//!   UNAVAILABLE, the calls in flight finished, 8 s at most by default);
//!   [`serve_listener`] takes a bound listener (tests bind port 0), [`serve_listener_with`]
//!   a grace period and a hook on every call (the tests' fault injection);
//!   [`serve_duplex`] serves in-memory `tokio::io::duplex` connections; [`direct`] is the
//!   service with no transport at all, called in the caller's task (in-process workers).
//! - The shared secret is checked on every MicroSolver call by [`CheckToken`]; the standard
//!   `grpc.health.v1.Health` service (tonic-health) answers readiness probes without one.
//! - Status codes (mapped in one place, `error.rs`): unknown id NOT_FOUND, NaN or
//!   det(F) <= 0 INVALID_ARGUMENT naming field and value, protocol version mismatch
//!   FAILED_PRECONDITION naming both, over the assembly or disc limits RESOURCE_EXHAUSTED,
//!   an oversized message OUT_OF_RANGE (tonic's code, raised before the service runs),
//!   missing or wrong token UNAUTHENTICATED. A failed relaxation is not a status: it comes
//!   back in-band in its `SolveResult`.
//! - TLS (feature `tls`, rustls with ring): [`WorkerConfig::tls`] / `--tls-cert --tls-key`.
//!
//! The `cosdem-worker` binary and its command line are the `cosdem-worker-cli` package: this
//! library depends on no clap, anyhow or tracing-subscriber.

mod auth;
mod config;
/// The real micro model: DEM assemblies.
pub mod dem;
/// How a served worker stops: the gate of its calls and the drain within a grace period.
pub mod drain;
mod error;
mod model;
mod registry;
mod server;
mod standin;

pub use auth::{AttachToken, CheckToken, TOKEN_ENV, Token};
pub use config::{Limits, TlsIdentity, WorkerConfig};
pub use dem::Dem;
pub use drain::{CallHook, CallVerdict, DEFAULT_GRACE_PERIOD, SHUTTING_DOWN, ServeOptions};
pub use error::{Result, ServiceError};
pub use model::{MicroModel, ModelError};
pub use server::WorkerService;
pub use standin::{StandIn, StandInAssembly, StandInOptions, StandInSpec};

use cosdem_proto::v1::micro_solver_server::MicroSolverServer;
use drain::{Door, Gate};
use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use tokio::net::TcpListener;
use tonic::service::interceptor::InterceptedService;
use tonic::transport::Server;
use tonic::transport::server::Router;

/// What a worker reports as its build at handshake.
pub const BUILD_ID: &str = concat!("cosdem-worker ", env!("CARGO_PKG_VERSION"));

/// Interval of HTTP/2 keepalive pings (so a master notices a dead peer between calls).
const KEEPALIVE: std::time::Duration = std::time::Duration::from_secs(10);

/// The MicroSolver service with its token check, as a plain tower service of HTTP requests:
/// what [`direct`] returns.
pub type DirectService<M> = InterceptedService<MicroSolverServer<WorkerService<M>>, CheckToken>;

/// An in-process worker with no transport: the generated server (request decoding, the token
/// interceptor, the message-size limits, response encoding) called directly by a client in
/// the caller's task, so a call costs no connection task and no thread hand-off but the
/// relaxations' own (the rayon pool and back). No TLS, no HTTP/2 keepalive, no grpc-timeout
/// enforcement on this side (the caller bounds its calls itself).
pub fn direct<M: MicroModel>(model: M, config: &WorkerConfig) -> Result<DirectService<M>> {
    let max = config.limits.max_message_bytes;
    let service = MicroSolverServer::new(WorkerService::new(model, config.clone())?)
        .max_decoding_message_size(max)
        .max_encoding_message_size(max);
    Ok(InterceptedService::new(service, CheckToken(config.token.clone())))
}

/// A server's routes, and what its drain needs of them.
struct Served {
    router: Router,
    /// The gate of the MicroSolver calls.
    door: Arc<Door>,
    /// Relaxations running (they outlive the SolveBatch call that started them).
    relaxing: Box<dyn Fn() -> u64 + Send + Sync>,
    /// The health service's reporter (NOT_SERVING once draining).
    reporter: tonic_health::server::HealthReporter,
}

async fn router<M: MicroModel>(
    model: M,
    config: &WorkerConfig,
    hook: Option<CallHook>,
) -> Result<Served> {
    let (reporter, health) = tonic_health::server::health_reporter();
    let max = config.limits.max_message_bytes;
    let worker = WorkerService::new(model, config.clone())?;
    let relaxing = Box::new(worker.relaxing());
    let service = MicroSolverServer::new(worker)
        .max_decoding_message_size(max)
        .max_encoding_message_size(max);
    reporter.set_serving::<MicroSolverServer<WorkerService<M>>>().await;
    #[allow(unused_mut)]
    let mut builder = Server::builder();
    #[cfg(feature = "tls")]
    if let Some(tls) = &config.tls {
        use tonic::transport::{Identity, ServerTlsConfig};
        let identity = Identity::from_pem(&tls.cert_pem, &tls.key_pem);
        builder = builder
            .tls_config(ServerTlsConfig::new().identity(identity))
            .map_err(|e| ServiceError::Config(format!("TLS: {e}")))?;
    }
    let door = Arc::new(Door::default());
    let gated = Gate::new(
        InterceptedService::new(service, CheckToken(config.token.clone())),
        door.clone(),
        hook,
    );
    let router =
        builder.http2_keepalive_interval(Some(KEEPALIVE)).add_service(health).add_service(gated);
    Ok(Served { router, door, relaxing, reporter })
}

/// Binds `config.listen`, after refusing a public address without a token.
pub async fn bind(config: &WorkerConfig) -> Result<TcpListener> {
    config.validate()?;
    TcpListener::bind(config.listen)
        .await
        .map_err(|e| ServiceError::Transport(format!("bind {}: {e}", config.listen)))
}

/// Serves `model` on `config.listen` until `shutdown` resolves, then drains within the
/// default grace period ([`serve_listener_with`]).
pub async fn serve<M: MicroModel>(
    config: WorkerConfig,
    model: M,
    shutdown: impl Future<Output = ()>,
) -> Result<()> {
    let listener = bind(&config).await?;
    serve_listener(listener, config, model, shutdown).await
}

/// Serves on an already bound listener (tests bind port 0 and read the address first), with
/// the default [`ServeOptions`].
pub async fn serve_listener<M: MicroModel>(
    listener: TcpListener,
    config: WorkerConfig,
    model: M,
    shutdown: impl Future<Output = ()>,
) -> Result<()> {
    serve_listener_with(listener, config, model, shutdown, ServeOptions::default()).await
}

/// Serves on an already bound listener until `shutdown` resolves, then drains
/// ([`drain`]): new calls are answered UNAVAILABLE [`SHUTTING_DOWN`], the calls
/// in flight finish, and the server stops, within `options.grace_period` (past it, it returns
/// with calls still running: the caller exits). `options.hook` sees every MicroSolver call
/// first (fault injection in tests).
pub async fn serve_listener_with<M: MicroModel>(
    listener: TcpListener,
    config: WorkerConfig,
    model: M,
    shutdown: impl Future<Output = ()>,
    options: ServeOptions,
) -> Result<()> {
    config.validate()?;
    let addr: Option<SocketAddr> = listener.local_addr().ok();
    tracing::info!(?addr, auth = config.token.is_some(), grace = ?options.grace_period, "cosdem worker listening");
    use tokio_stream::StreamExt;
    // Replies are several small HTTP/2 frames (a SolveBatch streams one message per Gauss
    // point): with Nagle's algorithm each waits for the master's delayed ACK (~40 ms on Linux).
    // `Server::tcp_nodelay` only applies to listeners tonic binds itself, so set it here.
    let incoming = tokio_stream::wrappers::TcpListenerStream::new(listener).map(|s| {
        if let Ok(s) = &s
            && let Err(e) = s.set_nodelay(true)
        {
            tracing::warn!("TCP_NODELAY: {e}");
        }
        s
    });
    let Served { router, door, relaxing, reporter } = router(model, &config, options.hook).await?;
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let server = router.serve_with_incoming_shutdown(incoming, async {
        let _ = stopped.await;
    });
    let not_serving = async move {
        use tonic_health::ServingStatus::NotServing;
        let name = <MicroSolverServer<WorkerService<M>> as tonic::server::NamedService>::NAME;
        reporter.set_service_status("", NotServing).await;
        reporter.set_service_status(name, NotServing).await;
    };
    drain::run_until_drained(
        server,
        stop,
        shutdown,
        door,
        relaxing,
        not_serving,
        options.grace_period,
    )
    .await
    .map_err(|e| ServiceError::Transport(e.to_string()))
}

/// Serves in-memory connections: each `DuplexStream` received is one client connection.
/// No address, no port: what in-process workers and tests use.
pub async fn serve_duplex<M: MicroModel>(
    connections: tokio::sync::mpsc::UnboundedReceiver<tokio::io::DuplexStream>,
    config: WorkerConfig,
    model: M,
    shutdown: impl Future<Output = ()>,
) -> Result<()> {
    use tokio_stream::StreamExt;
    // In memory, in one process: no TLS.
    let config = WorkerConfig { tls: None, ..config };
    let incoming = tokio_stream::wrappers::UnboundedReceiverStream::new(connections)
        .map(Ok::<_, std::io::Error>);
    router(model, &config, None)
        .await?
        .router
        .serve_with_incoming_shutdown(incoming, shutdown)
        .await
        .map_err(|e| ServiceError::Transport(e.to_string()))
}

/// Registers the SIGTERM and SIGINT (Ctrl-C) handlers now and returns the future that
/// resolves on either: the shutdown future a worker binary passes to [`serve`] (which then
/// drains, [`drain`]). Registering
/// eagerly, before the listener is bound, matters: a handler installed only when the future is
/// first polled leaves a window after the port accepts connections in which SIGTERM kills the
/// worker (the default action) instead of draining it. Call it inside a Tokio runtime.
#[cfg(unix)]
pub fn shutdown_signal() -> impl Future<Output = ()> + Send + 'static {
    use tokio::signal::unix::{Signal, SignalKind, signal};
    let term = signal(SignalKind::terminate()).ok();
    let int = signal(SignalKind::interrupt()).ok();
    let wait = |s: Option<Signal>| async move {
        match s {
            Some(mut s) => {
                s.recv().await;
            }
            None => std::future::pending::<()>().await,
        }
    };
    async move {
        tokio::select! {
            _ = wait(term) => {},
            _ = wait(int) => {},
        }
        tracing::info!("SIGTERM or SIGINT received");
    }
}

/// Resolves on Ctrl-C (no SIGTERM off Unix).
#[cfg(not(unix))]
pub fn shutdown_signal() -> impl Future<Output = ()> + Send + 'static {
    async {
        let _ = tokio::signal::ctrl_c().await;
        tracing::info!("Ctrl-C received");
    }
}
