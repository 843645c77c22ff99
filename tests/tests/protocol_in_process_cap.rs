//! `[workers] in_process = 100000` was accepted and exhausted the threads: a job's in-process
//! workers are capped at the machine's cores (results do not depend on the worker count).
//! The test asks for a few more than the cores (not 100 000: without the cap that would
//! exhaust the threads of the machine running the tests).

mod common;
use common::quick;
use cosdem_app::run::{WorkerChoice, material_for};
use cosdem_common::GaussPointId;
use cosdem_pool::PoolConfig;

#[test]
fn a_jobs_in_process_workers_are_capped_at_the_cores() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut job = quick(0.02);
    job.workers.in_process = cores + 3;
    let choice = WorkerChoice {
        addresses: Vec::new(),
        config: PoolConfig { in_process_threads: 1, ..PoolConfig::default() },
    };
    let ids: Vec<_> = (0..3).map(|e| GaussPointId::new(e, 0)).collect();
    let mesh = job.build_mesh().unwrap();
    let workers = material_for(&job, &choice, &mesh, &ids, None).unwrap().workers;
    assert_eq!(workers, cores);
}
