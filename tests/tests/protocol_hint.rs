//! The master sends an honest disc-count hint: the disc count of the job's packing, read from
//! its spec (it sent 0, so a worker's `--max-discs` was checked only after building, and an
//! ordinary job crashed a worker started with that limit). A worker on loopback records the
//! hints it receives.

mod common;
use common::quick;
use cosdem_app::run::{WorkerChoice, material_for};
use cosdem_common::GaussPointId;
use cosdem_dem::Assembly;
use cosdem_job::MaterialSection;
use cosdem_pool::PoolConfig;
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::{MicroSolver, MicroSolverServer};
use cosdem_worker::{Dem, WorkerConfig, WorkerService};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tonic::{Request, Response, Status};

/// A DEM worker that records the `disc_count_hint` of every CreateAssemblies.
struct Recording {
    inner: WorkerService<Dem>,
    hints: Arc<Mutex<Vec<u64>>>,
}

#[tonic::async_trait]
impl MicroSolver for Recording {
    async fn handshake(
        &self,
        r: Request<pb::HandshakeRequest>,
    ) -> Result<Response<pb::HandshakeReply>, Status> {
        self.inner.handshake(r).await
    }
    async fn create_assemblies(
        &self,
        r: Request<pb::CreateAssembliesRequest>,
    ) -> Result<Response<pb::CreateAssembliesReply>, Status> {
        let hint = r.get_ref().spec.as_ref().map_or(0, |s| s.disc_count_hint);
        self.hints.lock().unwrap().push(hint);
        self.inner.create_assemblies(r).await
    }
    type SolveBatchStream = <WorkerService<Dem> as MicroSolver>::SolveBatchStream;
    async fn solve_batch(
        &self,
        r: Request<pb::SolveBatchRequest>,
    ) -> Result<Response<Self::SolveBatchStream>, Status> {
        self.inner.solve_batch(r).await
    }
    async fn commit(
        &self,
        r: Request<pb::CommitRequest>,
    ) -> Result<Response<pb::CommitReply>, Status> {
        self.inner.commit(r).await
    }
    async fn rollback(
        &self,
        r: Request<pb::RollbackRequest>,
    ) -> Result<Response<pb::RollbackReply>, Status> {
        self.inner.rollback(r).await
    }
    async fn export_state(
        &self,
        r: Request<pb::ExportStateRequest>,
    ) -> Result<Response<pb::ExportStateReply>, Status> {
        self.inner.export_state(r).await
    }
    async fn import_state(
        &self,
        r: Request<pb::ImportStateRequest>,
    ) -> Result<Response<pb::ImportStateReply>, Status> {
        self.inner.import_state(r).await
    }
    async fn snapshot(
        &self,
        r: Request<pb::SnapshotRequest>,
    ) -> Result<Response<pb::SnapshotReply>, Status> {
        self.inner.snapshot(r).await
    }
    async fn health(
        &self,
        r: Request<pb::HealthRequest>,
    ) -> Result<Response<pb::HealthReply>, Status> {
        self.inner.health(r).await
    }
    async fn drop(&self, r: Request<pb::DropRequest>) -> Result<Response<pb::DropReply>, Status> {
        MicroSolver::drop(&self.inner, r).await
    }
}

#[test]
fn the_master_hints_the_packings_disc_count() {
    let rt =
        tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
    let hints = Arc::new(Mutex::new(Vec::new()));
    let config = WorkerConfig { threads: 1, ..WorkerConfig::default() };
    let worker =
        Recording { inner: WorkerService::new(Dem, config).unwrap(), hints: hints.clone() };
    let addr = rt.block_on(async {
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        let addr = listener.local_addr().unwrap();
        let incoming = tonic::transport::server::TcpIncoming::from(listener);
        tokio::spawn(
            tonic::transport::Server::builder()
                .add_service(MicroSolverServer::new(worker))
                .serve_with_incoming(incoming),
        );
        addr
    });
    let job = quick(0.02);
    let MaterialSection::Dem { assembly } = &job.material else { panic!("quick is a DEM job") };
    let built = Assembly::new(assembly).unwrap().disc_count() as u64;
    let choice = WorkerChoice {
        addresses: vec![addr.to_string()],
        config: PoolConfig {
            connect_timeout: Duration::from_secs(3),
            call_timeout: Duration::from_secs(10),
            ..PoolConfig::default()
        },
    };
    let ids: Vec<_> = (0..3).map(|e| GaussPointId::new(e, 0)).collect();
    let mesh = job.build_mesh().unwrap();
    let workers = material_for(&job, &choice, &mesh, &ids, None).unwrap().workers;
    assert_eq!(workers, 1);
    assert_eq!(*hints.lock().unwrap(), vec![built]);
    assert_eq!(built, 105);
}
