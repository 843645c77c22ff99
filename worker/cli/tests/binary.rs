//! The `cosdem-worker` binary itself: its commands, a bad address refused by name, and a
//! worker started with `listen` answering `health` as SERVING (what the container health
//! checks of `deploy/` rely on). These tests also make `cargo test --workspace` build the
//! binary, with the test build's features, so that CI's Python tests and container tests
//! use it without a build of their own (`.ci/run`).

use std::net::TcpListener;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn worker() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cosdem-worker"))
}

/// `--help` names the three commands.
#[test]
fn help_names_the_commands() {
    let out = worker().arg("--help").output().expect("cosdem-worker runs");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for command in ["listen", "health", "bench"] {
        assert!(text.contains(command), "{command} missing from:\n{text}");
    }
}

/// An address that is not `host:port` is refused, naming it; nothing listens.
#[test]
fn a_bad_listen_address_is_refused_by_name() {
    let out = worker().args(["listen", "--listen", "nowhere"]).output().expect("runs");
    assert!(!out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("nowhere") && text.contains("--listen"), "{text}");
}

/// `bench dem --candidates` runs the relaxation yardstick alone: the default relaxation first,
/// then only the named candidates (a smoke run at the two smallest sizes), and no kernel rate.
#[test]
fn bench_dem_runs_the_named_candidates_only() {
    let out = worker()
        .args(["bench", "dem", "--quick", "--candidates", "extrapolated predictor"])
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    let candidates: Vec<&str> = text.lines().filter(|l| l.starts_with("candidate ")).collect();
    assert_eq!(candidates.len(), 2, "{text}");
    assert!(candidates[0].starts_with("candidate default (Cundall 0.7)"), "{text}");
    assert!(candidates[1].starts_with("candidate extrapolated predictor, one"), "{text}");
    assert!(candidates.iter().all(|l| l.contains("20 of 20 solves converged")), "{text}");
    assert!(!text.contains("particle-steps/s"), "{text}");
}

/// Kills the worker when the test ends, passed or not.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A worker started on a free port answers `health` (exit 0) within a few seconds of its
/// start; `health` against a port where nothing listens fails (exit non-zero).
#[test]
fn a_listening_worker_reports_serving() {
    // A port free a moment ago (the worker binds it right after).
    let port = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let addr = format!("127.0.0.1:{port}");
    let health = |addr: &str| {
        worker()
            .args(["health", "--addr", addr, "--timeout", "2"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .expect("runs")
            .success()
    };
    assert!(!health(&addr), "nothing listens yet on {addr}");
    let _worker = Running(
        worker()
            .args(["listen", "--listen", &addr, "--threads", "1"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("the worker starts"),
    );
    let start = Instant::now();
    while !health(&addr) {
        assert!(start.elapsed() < Duration::from_secs(30), "no SERVING from {addr} in 30 s");
        std::thread::sleep(Duration::from_millis(100));
    }
}
