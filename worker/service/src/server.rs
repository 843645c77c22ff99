//! The tonic service around a [`MicroModel`]: wire in, validate, run off the async runtime,
//! wire out. Relaxations run on a rayon pool (one assembly per task) and stream back as they
//! finish; every other call that touches assemblies runs in `spawn_blocking`. So Handshake
//! and Health answer while the worker computes.

use super::config::WorkerConfig;
use super::error::ServiceError;
use super::model::MicroModel;
use super::registry::Registry;
use cosdem_common::GaussPointId;
use cosdem_common::micro::AssemblyRequest;
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::MicroSolver;
use cosdem_proto::{PROTOCOL_VERSION, from_proto, to_proto};
use std::pin::Pin;
use std::sync::Arc;
use tokio_stream::Stream;
use tonic::{Request, Response, Status};

/// The MicroSolver service of one worker.
pub struct WorkerService<M: MicroModel> {
    registry: Arc<Registry<M>>,
    relax: Arc<rayon::ThreadPool>,
    config: WorkerConfig,
}

impl<M: MicroModel> WorkerService<M> {
    /// A service with its own relaxation thread pool.
    pub fn new(model: M, config: WorkerConfig) -> Result<Self, ServiceError> {
        if config.threads > config.thread_count() {
            let cores = config.thread_count();
            tracing::warn!(asked = config.threads, cores, "relaxation threads capped at the cores");
        }
        let relax = rayon::ThreadPoolBuilder::new()
            .num_threads(config.thread_count())
            .thread_name(|i| format!("cosdem-relax-{i}"))
            .build()
            .map_err(|e| ServiceError::Internal(format!("relaxation pool: {e}")))?;
        Ok(Self {
            registry: Arc::new(Registry::new(model, config.limits)),
            relax: Arc::new(relax),
            config,
        })
    }

    /// How many relaxations run now (a probe that outlives the service): a SolveBatch call
    /// answers with a stream at once, its relaxations go on after it. What a drain waits for.
    pub(crate) fn relaxing(&self) -> impl Fn() -> u64 + Send + Sync + 'static {
        let registry = self.registry.clone();
        move || registry.load().2
    }
}

/// Runs blocking work off the async runtime. Not on the relaxation pool: commit, export and
/// rollback must not queue behind long relaxations (a deadline would declare us dead).
async fn blocking<M: MicroModel, T: Send + 'static>(
    s: &WorkerService<M>,
    f: impl FnOnce(&Registry<M>) -> Result<T, ServiceError> + Send + 'static,
) -> Result<T, Status> {
    let registry = s.registry.clone();
    tokio::task::spawn_blocking(move || f(&registry))
        .await
        .map_err(|e| Status::from(ServiceError::Internal(format!("task lost: {e}"))))?
        .map_err(Status::from)
}

fn ids(list: Vec<pb::GaussPoint>) -> Vec<GaussPointId> {
    list.into_iter().map(GaussPointId::from).collect()
}

fn invalid(context: impl std::fmt::Display, e: impl std::fmt::Display) -> Status {
    Status::from(ServiceError::InvalidArgument(format!("{context}: {e}")))
}

/// Memory of this machine in bytes (0 when unknown).
fn memory_bytes() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kib| kib * 1024)
}

type ResultStream = Pin<Box<dyn Stream<Item = Result<pb::SolveResult, Status>> + Send>>;

#[tonic::async_trait]
impl<M: MicroModel> MicroSolver for WorkerService<M> {
    async fn handshake(
        &self,
        req: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        let req = req.into_inner();
        if req.protocol_version != PROTOCOL_VERSION {
            return Err(ServiceError::VersionMismatch {
                master: req.protocol_version,
                worker: PROTOCOL_VERSION,
            }
            .into());
        }
        tracing::info!(master = %cosdem_proto::printable(&req.master_build_id), "handshake");
        let l = self.config.limits;
        Ok(Response::new(pb::HandshakeReply {
            protocol_version: PROTOCOL_VERSION,
            cores: self.config.thread_count() as u32,
            memory_bytes: memory_bytes(),
            build_id: super::BUILD_ID.to_string(),
            max_assemblies: l.max_assemblies,
            max_discs: l.max_discs,
            max_message_bytes: l.max_message_bytes as u64,
        }))
    }

    async fn create_assemblies(
        &self,
        req: Request<pb::CreateAssembliesRequest>,
    ) -> Result<Response<pb::CreateAssembliesReply>, Status> {
        let req = req.into_inner();
        let spec: AssemblyRequest = req
            .spec
            .ok_or_else(|| invalid("CreateAssemblies", "missing field `spec`"))?
            .try_into()
            .map_err(|e| invalid("spec", e))?;
        let ids = ids(req.ids);
        let relax = self.relax.clone();
        let infos = blocking(self, move |r| {
            let mut seen = std::collections::HashSet::new();
            if let Some(id) = ids.iter().find(|id| !seen.insert(**id)) {
                return Err(ServiceError::InvalidArgument(format!(
                    "{id} appears twice in one request"
                )));
            }
            // Building packings is heavy: use the relaxation threads.
            relax.install(|| r.create(&ids, &spec))
        })
        .await?;
        Ok(Response::new(pb::CreateAssembliesReply {
            assemblies: infos.iter().map(Into::into).collect(),
        }))
    }

    type SolveBatchStream = ResultStream;

    async fn solve_batch(
        &self,
        req: Request<pb::SolveBatchRequest>,
    ) -> Result<Response<ResultStream>, Status> {
        let req = req.into_inner();
        let (step, iteration) = (req.step, req.iteration);
        let mut items = Vec::with_capacity(req.items.len());
        for (k, item) in req.items.into_iter().enumerate() {
            let id = item.id.map(GaussPointId::from);
            let (id, target) = from_proto::solve_item(item).map_err(|e| match id {
                Some(id) => invalid(format!("item {k} ({id})"), e),
                None => invalid(format!("item {k}"), e),
            })?;
            items.push((id, target));
        }
        let list: Vec<_> = items.iter().map(|(id, _)| *id).collect();
        let handles = self.registry.resolve(&list)?;
        if let Some(c) = req.commit {
            // The previous step's commit, carried here to save its round trip: applied in
            // full (every assembly checked before any changes) before a relaxation of this
            // batch starts, since they start from the committed states. A commit moves
            // trial states, it does not compute: done on this thread.
            if c.export_state {
                return Err(invalid("commit", "a commit carried on a SolveBatch cannot export"));
            }
            let ids = ids(c.ids);
            if !ids.is_empty() {
                self.registry.commit(&ids, c.step, c.iteration, false)?;
            }
        }
        let (tx, rx) = tokio::sync::mpsc::unbounded_channel();
        for (h, (_, target)) in handles.into_iter().zip(items) {
            let registry = self.registry.clone();
            let tx = tx.clone();
            registry.begin();
            self.relax.spawn(move || {
                let outcome = registry.solve(&h, step, iteration, target);
                registry.end();
                // The caller may have gone (deadline); the cached trial still serves a retry.
                let _ = tx.send(Ok(to_proto::solve_result(h.id(), &outcome)));
            });
        }
        Ok(Response::new(Box::pin(tokio_stream::wrappers::UnboundedReceiverStream::new(rx))))
    }

    async fn commit(
        &self,
        req: Request<pb::CommitRequest>,
    ) -> Result<Response<pb::CommitReply>, Status> {
        let req = req.into_inner();
        let ids = ids(req.ids);
        let (committed, already, states) =
            blocking(self, move |r| r.commit(&ids, req.step, req.iteration, req.export_state))
                .await?;
        Ok(Response::new(pb::CommitReply {
            committed,
            already_committed: already,
            states: states.into_iter().map(Into::into).collect(),
        }))
    }

    async fn rollback(
        &self,
        req: Request<pb::RollbackRequest>,
    ) -> Result<Response<pb::RollbackReply>, Status> {
        let ids = ids(req.into_inner().ids);
        let n = blocking(self, move |r| r.rollback(&ids)).await?;
        Ok(Response::new(pb::RollbackReply { rolled_back: n }))
    }

    async fn export_state(
        &self,
        req: Request<pb::ExportStateRequest>,
    ) -> Result<Response<pb::ExportStateReply>, Status> {
        let ids = ids(req.into_inner().ids);
        let states = blocking(self, move |r| r.export(&ids)).await?;
        Ok(Response::new(pb::ExportStateReply {
            states: states.into_iter().map(Into::into).collect(),
        }))
    }

    async fn import_state(
        &self,
        req: Request<pb::ImportStateRequest>,
    ) -> Result<Response<pb::ImportStateReply>, Status> {
        let states = req
            .into_inner()
            .states
            .into_iter()
            .enumerate()
            .map(|(k, s)| s.try_into().map_err(|e| invalid(format!("state {k}"), e)))
            .collect::<Result<Vec<_>, _>>()?;
        let infos = blocking(self, move |r| r.import(states)).await?;
        Ok(Response::new(pb::ImportStateReply {
            assemblies: infos.iter().map(Into::into).collect(),
        }))
    }

    async fn snapshot(
        &self,
        req: Request<pb::SnapshotRequest>,
    ) -> Result<Response<pb::SnapshotReply>, Status> {
        let id =
            from_proto::gauss_point(req.into_inner().id).map_err(|e| invalid("Snapshot", e))?;
        let (step, snap) = blocking(self, move |r| r.snapshot(id)).await?;
        Ok(Response::new(to_proto::snapshot_reply(id, step, snap)))
    }

    async fn health(
        &self,
        _req: Request<pb::HealthRequest>,
    ) -> Result<Response<pb::HealthReply>, Status> {
        let (assemblies, discs, in_flight) = self.registry.load();
        Ok(Response::new(pb::HealthReply { assemblies, discs, in_flight }))
    }

    async fn drop(&self, req: Request<pb::DropRequest>) -> Result<Response<pb::DropReply>, Status> {
        let ids = ids(req.into_inner().ids);
        let dropped = blocking(self, move |r| Ok(r.drop_assemblies(&ids))).await?;
        Ok(Response::new(pb::DropReply { dropped }))
    }
}
