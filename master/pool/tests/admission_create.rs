//! Creating assemblies within a worker's means: in-process workers and their threads capped
//! at the machine's cores; a worker's share sent in requests within the per-request caps; the
//! CreateAssemblies deadline scaled with the discs to build (or set), and named when missed.

use cosdem_common::micro::{AssemblyRequest, BoundaryKind, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_pool::{Pool, PoolConfig, PoolError};
use cosdem_worker::{Limits, MicroModel, ModelError, StandIn, StandInAssembly};
use std::time::Duration;

fn config() -> PoolConfig {
    PoolConfig {
        connect_timeout: Duration::from_secs(3),
        call_timeout: Duration::from_secs(5),
        solve_timeout: Duration::from_secs(5),
        in_process_threads: 1,
        ..PoolConfig::default()
    }
}

fn spec(discs: u64) -> AssemblyRequest {
    AssemblyRequest {
        spec_json: format!(r#"{{"discs": {discs}, "work_per_disc": 1}}"#).into_bytes(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: discs,
    }
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `[workers] in_process = 100000` exhausted the threads: a job's in-process workers are
/// capped at the machine's cores, and so are each worker's relaxation threads (results depend
/// on neither).
#[test]
fn in_process_workers_and_threads_are_capped_at_the_cores() {
    assert_eq!(Pool::in_process_workers(100_000), cores());
    assert_eq!(Pool::in_process_workers(0), 1);
    assert_eq!(Pool::in_process_workers(1), 1);
    let config = PoolConfig { in_process_threads: 10_000, ..config() };
    let pool = Pool::in_process(2, config, |_| StandIn::new()).unwrap();
    assert_eq!(pool.live_workers(), 2);
    for (name, info) in pool.workers() {
        assert_eq!(info.cores as usize, cores(), "{name}: {} threads", info.cores);
    }
}

/// More Gauss points on one worker than a request may carry
/// ([`Limits::MAX_IDS_PER_REQUEST`]): the pool sends them in several requests, and every
/// assembly is created and its state stored.
#[test]
fn a_large_share_is_sent_in_requests_within_the_caps() {
    let n = Limits::MAX_IDS_PER_REQUEST as u32 + 5;
    let ids: Vec<_> = (0..n).map(|e| GaussPointId::new(e, 0)).collect();
    let mut pool = Pool::in_process(1, config(), |_| StandIn::new()).unwrap();
    pool.create_assemblies(&ids, &spec(2)).unwrap();
    assert_eq!(pool.assignment().len(), n as usize);
    assert_eq!(pool.committed_states().len(), n as usize);
}

/// A stand-in whose assemblies take `delay` to build (a large random packing).
struct Slow {
    inner: StandIn,
    delay: Duration,
}

impl MicroModel for Slow {
    type Assembly = StandInAssembly;
    fn create(&self, id: GaussPointId, s: &AssemblyRequest) -> Result<StandInAssembly, ModelError> {
        std::thread::sleep(self.delay);
        self.inner.create(id, s)
    }
    fn solve(
        &self,
        a: &mut StandInAssembly,
        t: &MacroDeformation,
    ) -> Result<MicroResponse, ModelError> {
        self.inner.solve(a, t)
    }
    fn commit(&self, a: &mut StandInAssembly) {
        self.inner.commit(a)
    }
    fn rollback(&self, a: &mut StandInAssembly) {
        self.inner.rollback(a)
    }
    fn export(&self, a: &StandInAssembly) -> Vec<u8> {
        self.inner.export(a)
    }
    fn import(&self, b: &[u8]) -> Result<StandInAssembly, ModelError> {
        self.inner.import(b)
    }
    fn snapshot(&self, a: &StandInAssembly) -> MicroSnapshot {
        self.inner.snapshot(a)
    }
    fn disc_count(&self, a: &StandInAssembly) -> u64 {
        self.inner.disc_count(a)
    }
}

fn slow(delay: Duration) -> impl Fn(usize) -> Slow {
    move |_| Slow { inner: StandIn::new(), delay }
}

/// The CreateAssemblies deadline scales with the discs to build: a build of 1.2 s with a
/// call timeout of 0.3 s passes for an assembly of 60 000 discs (it failed on the fixed call
/// timeout, `DeadlineExceeded` naming no setting); a `create_timeout` set too short fails
/// naming the setting and its value.
#[test]
fn the_create_deadline_scales_with_the_discs_or_is_set() {
    let short = PoolConfig { call_timeout: Duration::from_millis(300), ..config() };
    let delay = Duration::from_millis(1200);
    let ids = [GaussPointId::new(0, 0)];
    let mut pool = Pool::in_process(1, short.clone(), slow(delay)).unwrap();
    pool.create_assemblies(&ids, &spec(60_000)).unwrap();
    assert!(
        short.create_deadline(60_000) > Duration::from_secs(60),
        "{:?}",
        short.create_deadline(60_000)
    );
    assert_eq!(short.create_deadline(0), short.call_timeout);

    let set = PoolConfig { create_timeout: Some(Duration::from_millis(400)), ..short };
    let mut pool = Pool::in_process(1, set, slow(delay)).unwrap();
    let e = pool.create_assemblies(&ids, &spec(60_000)).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, PoolError::Refused { .. }), "{m}");
    assert!(m.contains("DeadlineExceeded") && m.contains("create_timeout"), "{m}");
    assert!(m.contains("400ms") && m.contains("60000 discs"), "{m}");
}
