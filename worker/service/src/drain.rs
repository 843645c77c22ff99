//! How a served worker stops: the gate every MicroSolver call passes, and the drain.
//!
//! Asked to stop (SIGTERM from Docker, Kubernetes or Slurm, Ctrl-C: the shutdown future of
//! [`serve_listener_with`](crate::serve_listener_with)), a worker closes its gate: every new
//! call is answered UNAVAILABLE [`SHUTTING_DOWN`] at once (the master takes the worker as lost
//! and restores its assemblies on the others from the committed states) and the health
//! service reports NOT_SERVING, while the calls in flight (and the relaxations they started)
//! finish and answer. Then the server stops. All of it within the grace period
//! ([`ServeOptions::grace_period`]): past it the worker exits with calls still running, before
//! the container engine's own deadline (10 s for `docker stop`, 30 s for Kubernetes) kills it.
//!
//! The gate also hands each call to an optional [`CallHook`] before serving it: how the tests
//! inject faults into a real worker process. Production servers have none.

use std::convert::Infallible;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::task::{Context, Poll};
use std::time::Duration;
use tonic::Status;
use tonic::body::Body;
use tonic::codegen::{Bytes, Service, StdError, http};
use tonic::server::NamedService;

/// The message of the UNAVAILABLE status a draining worker answers new calls with.
pub const SHUTTING_DOWN: &str = "worker shutting down";

/// Default of [`ServeOptions::grace_period`]: shorter than the 10 s `docker stop` gives
/// before SIGKILL (Kubernetes gives 30 s, Slurm `KillWait` defaults to 30 s).
pub const DEFAULT_GRACE_PERIOD: Duration = Duration::from_secs(8);

/// What a [`CallHook`] decides for one call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CallVerdict {
    /// Serve it as usual.
    Serve,
    /// Serve it, then answer bytes that are not a gRPC message instead of its reply (a worker
    /// that answers garbage, for tests of the master).
    Garbage,
}

/// Called with the gRPC path of each MicroSolver call (e.g.
/// `/cosdem.v1.MicroSolver/Commit`) as it arrives, before it is served.
pub type CallHook = Arc<dyn Fn(&str) -> CallVerdict + Send + Sync>;

/// How [`serve_listener_with`](crate::serve_listener_with) serves and stops.
#[derive(Clone)]
pub struct ServeOptions {
    /// How long a worker asked to stop lets its calls in flight finish (taking no new one)
    /// before it exits anyway. Default [`DEFAULT_GRACE_PERIOD`].
    pub grace_period: Duration,
    /// Called as each MicroSolver call arrives (fault injection in tests); `None` in
    /// production.
    pub hook: Option<CallHook>,
}

impl Default for ServeOptions {
    fn default() -> Self {
        Self { grace_period: DEFAULT_GRACE_PERIOD, hook: None }
    }
}

impl std::fmt::Debug for ServeOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServeOptions")
            .field("grace_period", &self.grace_period)
            .field("hook", &self.hook.is_some())
            .finish()
    }
}

/// Whether the gate is closed, and how many calls are inside.
#[derive(Debug, Default)]
pub(crate) struct Door {
    closing: AtomicBool,
    calls: AtomicU64,
}

impl Door {
    /// Refuses every call from now on.
    pub(crate) fn close(&self) {
        self.closing.store(true, Ordering::SeqCst);
    }

    /// Calls inside (entered, not yet answered).
    pub(crate) fn calls(&self) -> u64 {
        self.calls.load(Ordering::SeqCst)
    }

    /// Lets a call in, unless the gate is closed. Counted first, then checked: a drain that
    /// closes the gate and then sees no call inside cannot miss one that got in.
    fn enter(self: &Arc<Self>) -> Option<Inside> {
        self.calls.fetch_add(1, Ordering::SeqCst);
        let inside = Inside(self.clone());
        (!self.closing.load(Ordering::SeqCst)).then_some(inside)
    }
}

/// One call inside the gate (counted until dropped).
struct Inside(Arc<Door>);

impl Drop for Inside {
    fn drop(&mut self) {
        self.0.calls.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The MicroSolver service behind the gate.
#[derive(Clone)]
pub(crate) struct Gate<S> {
    inner: S,
    door: Arc<Door>,
    hook: Option<CallHook>,
}

impl<S> Gate<S> {
    pub(crate) fn new(inner: S, door: Arc<Door>, hook: Option<CallHook>) -> Self {
        Self { inner, door, hook }
    }
}

impl<S: NamedService> NamedService for Gate<S> {
    const NAME: &'static str = S::NAME;
}

type Answer = Pin<Box<dyn Future<Output = Result<http::Response<Body>, Infallible>> + Send>>;

/// Not a gRPC message: a length-prefixed frame needs a compression flag of 0 or 1 first.
fn garbage() -> http::Response<Body> {
    let mut r = http::Response::new(Body::new(String::from("garbage, not a gRPC message")));
    r.headers_mut()
        .insert(http::header::CONTENT_TYPE, http::HeaderValue::from_static("application/grpc"));
    r
}

impl<S, B> Service<http::Request<Body>> for Gate<S>
where
    S: Service<http::Request<Body>, Response = http::Response<B>, Error = Infallible>
        + Clone
        + Send
        + 'static,
    S::Future: Send + 'static,
    B: tonic::codegen::Body<Data = Bytes> + Send + 'static,
    B::Error: Into<StdError>,
{
    type Response = http::Response<Body>;
    type Error = Infallible;
    type Future = Answer;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Infallible>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, req: http::Request<Body>) -> Answer {
        let Some(inside) = self.door.enter() else {
            return Box::pin(async { Ok(Status::unavailable(SHUTTING_DOWN).into_http()) });
        };
        let verdict = self.hook.as_ref().map_or(CallVerdict::Serve, |h| h(req.uri().path()));
        // The clone is ready only if polled; the one polled ready is the one to call.
        let clone = self.inner.clone();
        let mut inner = std::mem::replace(&mut self.inner, clone);
        Box::pin(async move {
            let answer = inner.call(req).await?;
            drop(inside);
            Ok(match verdict {
                CallVerdict::Serve => answer.map(Body::new),
                CallVerdict::Garbage => garbage(),
            })
        })
    }
}

/// Runs `server` until `shutdown` resolves, then drains: closes the gate (`door`), tells the
/// health service (`not_serving`), waits until no call is inside and no relaxation runs
/// (`relaxing`), then resolves `stop` (the server's own graceful shutdown: no new connection,
/// the answers in flight sent) and waits for the server to end. Gives up waiting once `grace`
/// has passed since `shutdown` resolved.
pub(crate) async fn run_until_drained<F, N>(
    server: F,
    stop: tokio::sync::oneshot::Sender<()>,
    shutdown: impl Future<Output = ()>,
    door: Arc<Door>,
    relaxing: impl Fn() -> u64,
    not_serving: N,
    grace: Duration,
) -> Result<(), tonic::transport::Error>
where
    F: Future<Output = Result<(), tonic::transport::Error>>,
    N: Future<Output = ()>,
{
    tokio::pin!(server);
    tokio::select! {
        r = &mut server => return r,
        () = shutdown => {}
    }
    let deadline = tokio::time::Instant::now() + grace;
    door.close();
    tracing::info!(
        ?grace,
        calls = door.calls(),
        relaxing = relaxing(),
        "shutdown requested: draining"
    );
    let idle = async {
        not_serving.await;
        while door.calls() > 0 || relaxing() > 0 {
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    };
    tokio::select! {
        r = &mut server => return r,
        () = idle => {}
        () = tokio::time::sleep_until(deadline) => {
            tracing::warn!(?grace, calls = door.calls(), relaxing = relaxing(), "grace period over: exiting with calls in flight");
            return Ok(());
        }
    }
    let _ = stop.send(());
    match tokio::time::timeout_at(deadline, server).await {
        Ok(r) => {
            tracing::info!("drained: stopped");
            r
        }
        Err(_) => {
            tracing::warn!(?grace, "grace period over: exiting with answers unsent");
            Ok(())
        }
    }
}
