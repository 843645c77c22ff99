//! SIGTERM (what Slurm, Kubernetes and `docker stop` send first) stops `cosdem run` like
//! Ctrl-C: after the current step, with the checkpoint written, `summary.json` status
//! `interrupted` and exit code 1, and `--resume` finishes the run.

#![cfg(unix)]

use cosdem_job::{Job, MaterialSection, NewtonSection};
use std::process::Command;
use std::time::{Duration, Instant};

/// A DEM job long enough to be signalled mid-run: the `dem-one-element` fixture on a 2 x 2
/// mesh with smaller assemblies (side 0.06 m), 2 cm in 400 steps, Newton tolerances 1e-2 and
/// the default iteration limit. Written as a job file for the binary.
fn long_job() -> Job {
    let mut job = cosdem_job::fixtures::load("dem-one-element");
    job.title = "sigterm".into();
    (job.mesh.nx, job.mesh.ny) = (Some(2), Some(2));
    job.loading.steps = 400;
    job.loading.compression.as_mut().unwrap().displacement = 0.02;
    job.newton.force_tolerance = 1.0e-2;
    job.newton.displacement_tolerance = 1.0e-2;
    job.newton.max_iterations = NewtonSection::default().max_iterations;
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.06;
    job.validate().unwrap();
    job
}

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
    let text = toml::to_string(&long_job()).unwrap();
    assert_eq!(Job::from_toml(&text, "job.toml").unwrap(), long_job(), "the file is the job");
    std::fs::write(&job, text).unwrap();
    let out = dir.join("run");
    let bin = env!("CARGO_BIN_EXE_cosdem");
    let mut child = Command::new(bin)
        .args(["run", job.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()])
        // A deliberate stop is no error: no backtrace even where backtraces are asked for.
        .env("RUST_BACKTRACE", "1")
        .stderr(std::process::Stdio::piped())
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
    let ended = child.wait_with_output().unwrap();
    let status = ended.status;
    assert_eq!(status.code(), Some(1), "interrupted runs exit with 1: {status:?}");
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"interrupted: stopped by Ctrl-C or SIGTERM after step"),
        "{summary}"
    );
    // The hint gives the command that goes on: the same job and --out.
    let stderr = String::from_utf8_lossy(&ended.stderr);
    let hint = format!("cosdem run {} --out {} --resume", job.display(), out.display());
    assert!(stderr.contains(&hint), "{stderr}");
    assert!(!stderr.to_lowercase().contains("backtrace"), "{stderr}");
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
