//! A worker's limits are checked before it builds, through the service: RESOURCE_EXHAUSTED
//! naming the limit and the value, and nothing held afterwards. A hint of 0 (what masters
//! sent) does not get a DEM spec past `max_discs`: the worker reads the disc count from the
//! spec. A request of more ids than a request may carry is refused by name.

use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::MicroSolver;
use cosdem_worker::{Dem, Limits, StandIn, WorkerConfig, WorkerService};
use tonic::{Code, Request};

fn gp(e: u32) -> pb::GaussPoint {
    pb::GaussPoint { element: e, point: 0 }
}

fn create(ids: Vec<pb::GaussPoint>, json: &str, hint: u64) -> Request<pb::CreateAssembliesRequest> {
    Request::new(pb::CreateAssembliesRequest {
        ids,
        spec: Some(pb::AssemblySpec {
            spec_json: json.as_bytes().to_vec(),
            boundary: 0,
            disc_count_hint: hint,
        }),
    })
}

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap()
}

async fn held<M: cosdem_worker::MicroModel>(svc: &WorkerService<M>) -> (u64, u64) {
    let h = svc.health(Request::new(pb::HealthRequest {})).await.unwrap().into_inner();
    (h.assemblies, h.discs)
}

/// Two assemblies of the default hexagonal packing (105 discs each) with a hint of 0, on a
/// worker limited to 200 discs: refused before building, naming `max_discs` and 210 discs.
#[test]
fn a_dem_spec_is_checked_against_max_discs_before_building() {
    let limits = Limits { max_discs: 200, ..Limits::default() };
    let config = WorkerConfig { threads: 1, limits, ..WorkerConfig::default() };
    let svc = WorkerService::new(Dem, config).unwrap();
    runtime().block_on(async {
        let e = svc.create_assemblies(create(vec![gp(0), gp(1)], "{}", 0)).await.unwrap_err();
        assert_eq!(e.code(), Code::ResourceExhausted, "{}", e.message());
        let m = e.message();
        assert!(m.contains("210 discs") && m.contains("hinted") && m.contains("max_discs"), "{m}");
        assert_eq!(held(&svc).await, (0, 0));
        svc.create_assemblies(create(vec![gp(0)], "{}", 0)).await.unwrap();
        assert_eq!(held(&svc).await, (1, 105));
    });
}

/// One request of more than `MAX_IDS_PER_REQUEST` ids is refused by name (one of 100 000
/// ids took 2.1 GB), and one of that many passes.
#[test]
fn a_request_of_too_many_ids_is_refused_by_name() {
    let svc = WorkerService::new(StandIn::new(), WorkerConfig::default()).unwrap();
    let spec = r#"{"discs": 1, "work_per_disc": 1}"#;
    let n = Limits::MAX_IDS_PER_REQUEST as u32;
    runtime().block_on(async {
        let e =
            svc.create_assemblies(create((0..=n).map(gp).collect(), spec, 1)).await.unwrap_err();
        assert_eq!(e.code(), Code::ResourceExhausted, "{}", e.message());
        assert!(e.message().contains("MAX_IDS_PER_REQUEST"), "{}", e.message());
        assert_eq!(held(&svc).await, (0, 0));
        svc.create_assemblies(create((0..n).map(gp).collect(), spec, 1)).await.unwrap();
        assert_eq!(held(&svc).await.0, u64::from(n));
    });
}
