//! Admission control through the run driver: a job whose estimated memory exceeds the limit
//! is refused before anything is built or written, naming the keys that drive it; the
//! repository's own example fits its machine.

use cosdem_app::run::{Run, RunError};
use cosdem_job::Job;
use std::path::{Path, PathBuf};

/// The pool's default message limit.
const MESSAGE: usize = 256 << 20;

fn quick() -> Job {
    Job::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/quick.toml")).unwrap()
}

fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("admission").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The 300 x 300 mesh of DEM assemblies (360 000 Gauss points) against a 24 GiB
/// machine's default limit (80 %): refused at once, nothing written, the mesh keys named.
#[test]
fn a_job_too_large_for_the_limit_is_refused_before_anything_is_built() {
    let mut job = quick();
    (job.mesh.nx, job.mesh.ny) = (Some(300), Some(300));
    let dir = fresh("too-large");
    let t = std::time::Instant::now();
    let limit = (0.8 * 24.0 * 1024f64.powi(3)) as u64;
    let err = Run::new(&job, &dir).max_memory(Some(limit)).execute().expect_err("too large");
    assert!(t.elapsed().as_secs_f64() < 5.0, "the refusal built something: {:?}", t.elapsed());
    assert!(matches!(err, RunError::Admission(_)), "{err}");
    let text = err.to_string();
    for key in ["mesh.nx = 300", "mesh.ny = 300", "--max-memory"] {
        assert!(text.contains(key), "{key} not named: {text}");
    }
    assert!(!dir.exists(), "a refused job created its directory");
}

/// The quick scene on a 40 x 40 mesh (6400 assemblies of 105 discs) under a limit between
/// its estimates with in-process and with remote workers: refused with in-process workers,
/// naming the assembly's keys; admitted with remote workers, whose assemblies are not in this
/// process. The quick example itself fits in 1 GiB.
#[test]
fn the_limit_is_the_callers_and_counts_only_this_process() {
    use cosdem_job::admission::{MeshCounts, estimate};
    let mut job = quick();
    (job.mesh.nx, job.mesh.ny) = (Some(40), Some(40));
    let e = estimate(&job, MeshCounts::of_job(&job).unwrap());
    let (local, remote) = (e.in_process_share(true), e.in_process_share(false));
    assert!(local > 1.2 * remote, "{local} vs {remote}");
    let limit = (0.5 * (local + remote)) as u64;
    let dir = fresh("limit");
    let err = Run::new(&job, &dir).max_memory(Some(limit)).execute().expect_err("over the limit");
    assert!(err.to_string().contains("material.assembly"), "{err}");
    assert!(cosdem_app::run::admit(&job, Some(limit), false, MESSAGE).is_ok());
    let warnings = cosdem_app::run::admit(&quick(), Some(1 << 30), true, MESSAGE).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
}

/// A million steps with VTK at every step: admitted, with a warning naming the size, the file
/// count and the keys.
#[test]
fn a_run_that_would_fill_a_disk_is_warned_about() {
    let mut job = quick();
    job.loading.increment = None;
    job.loading.steps = 1_000_000;
    let warnings = cosdem_app::run::admit(&job, None, true, MESSAGE).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("output.vtk_every"), "{}", warnings[0]);
}

/// The 16 points x 935k discs: one assembly's state (about 520 MB) cannot travel in a
/// 256 MiB message, so the job is refused at once naming the packing and the limit (it failed
/// after building, naming no key).
#[test]
fn an_assembly_whose_state_exceeds_the_message_limit_is_refused() {
    let mut job = quick();
    let cosdem_job::MaterialSection::Dem { assembly } = &mut job.material else { panic!() };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else { panic!() };
    *side = 9.5; // radius 5 mm: about 900k discs
    let err = cosdem_app::run::admit(&job, None, false, MESSAGE).expect_err("too large a state");
    let text = err.to_string();
    assert!(matches!(err, RunError::StateTooLarge { discs, .. } if discs > 800_000), "{text}");
    assert!(
        text.contains("material.assembly.packing") && text.contains("max_message_bytes"),
        "{text}"
    );
}
