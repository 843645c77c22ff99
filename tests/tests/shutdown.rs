//! SIGTERM drains and stops a worker process cleanly; a pool's drop frees its assemblies.

mod common;
use common::*;
use cosdem_common::GaussPointId;
use cosdem_pool::Pool;
use cosdem_proto::v1 as pb;
use std::time::{Duration, Instant};

#[test]
fn sigterm_stops_a_worker_cleanly() {
    let mut w = WorkerProcess::start(&[], &[]);
    let pid = w.child.id().to_string();
    let status = std::process::Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(status.success());
    let t = Instant::now();
    loop {
        if let Some(code) = w.child.try_wait().unwrap() {
            assert!(code.success(), "exit status {code:?}");
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(5), "worker did not stop on SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn snapshot_and_release() {
    let w = WorkerProcess::start(&[], &[]);
    let mut pool = Pool::connect(&[w.addr.to_string()], test_config()).unwrap();
    create(&mut pool, 10, 1);
    let snap = pool.snapshot(GaussPointId::new(0, 0)).unwrap();
    assert_eq!(snap.fluctuations, vec![0.0], "the stand-in's committed history");
    drop(pool);
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let h = rt.block_on(async {
        client(w.addr).await.health(pb::HealthRequest {}).await.unwrap().into_inner()
    });
    assert_eq!(h.assemblies, 0, "a dropped pool frees its assemblies");
}
