//! SIGTERM (what Slurm, Kubernetes and `docker stop` send first) stops `cosdem run` like
//! Ctrl-C: after the current step, with the checkpoint written, `summary.json` status
//! `interrupted` and exit code 1, and `--resume` finishes the run.

#![cfg(unix)]

use std::process::Command;
use std::time::{Duration, Instant};

const JOB: &str = r#"
title = "sigterm"
[mesh]
kind = "rectangle"
lx = 1.0
ly = 1.0
nx = 2
ny = 2
[loading]
steps = 400
[loading.compression]
displacement = 0.02
[[loading.pressure]]
set = "left"
value = 1.0e5
[[loading.pressure]]
set = "right"
value = 1.0e5
[newton]
force_tolerance = 1.0e-2
displacement_tolerance = 1.0e-2
[material]
kind = "dem"
[material.assembly]
packing = { kind = "hexagonal", radius = 0.005, side = 0.06 }
"#;

fn rows(dir: &std::path::Path) -> usize {
    std::fs::read_to_string(dir.join("curve.csv"))
        .map_or(0, |t| t.lines().count().saturating_sub(1))
}

#[test]
fn sigterm_stops_after_the_step_and_resume_finishes() {
    let dir = std::env::temp_dir().join(format!("cosdem-sigterm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let job = dir.join("job.toml");
    std::fs::write(&job, JOB).unwrap();
    let out = dir.join("run");
    let bin = env!("CARGO_BIN_EXE_cosdem");
    let mut child = Command::new(bin)
        .args(["run", job.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()])
        .spawn()
        .unwrap();
    // Wait for a few finished steps: the handler is installed before the first one.
    let t = Instant::now();
    while rows(&out) < 3 {
        assert!(t.elapsed() < Duration::from_secs(120), "no steps written");
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was signalled");
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "interrupted runs exit with 1: {status:?}");
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(summary.contains("\"interrupted\""), "{summary}");
    assert!(out.join("checkpoint.bin").is_file());
    let done = rows(&out);
    assert!((3..400).contains(&done), "{done} steps");
    let resumed = Command::new(bin)
        .args(["run", job.to_str().unwrap(), "--quiet", "--resume", "--out", out.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(resumed.success());
    assert_eq!(rows(&out), 400);
    std::fs::remove_dir_all(&dir).unwrap();
}
