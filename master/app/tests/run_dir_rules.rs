//! The run directory is a transaction log: a new run never destroys a previous run's results
//! (refused, or kept as `RUN.old-N` with `overwrite` once the setup has succeeded), one writer
//! at a time, and a resume after a kill that went past the checkpoint ends with the directory
//! of the uninterrupted run, every file byte for byte (curve, VTK and snapshot series, field
//! data, checkpoint).

use cosdem_app::output::claim::{ClaimError, RunLock};
use cosdem_app::output::run_dir::Summary;
use cosdem_app::run::{Ending, Run, RunError};
use cosdem_job::Job;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn example(name: &str) -> Job {
    Job::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
}

fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("run_dir_rules").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(dir.with_file_name(format!("{name}.old-1")));
    dir
}

/// The run directory's files less lock, summary and log.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    cosdem_app::output::run_dir::comparable_files(dir).unwrap()
}

/// A new run into a finished run's directory is refused (nothing touched); with `overwrite`
/// a setup that fails leaves it as it was, and one that succeeds keeps it as `RUN.old-1`.
#[test]
fn a_rerun_is_refused_and_an_overwrite_keeps_the_old_run_once_its_setup_succeeded() {
    let dir = fresh("rerun");
    let job = example("elastic.toml");
    Run::new(&job, &dir).execute().unwrap();
    let before = files(&dir);
    let summary = std::fs::read(dir.join("summary.json")).unwrap();

    let err = Run::new(&job, &dir).execute().expect_err("the directory holds a run");
    assert!(
        matches!(&err, RunError::Claim(ClaimError::NotEmpty { what, .. }) if what.contains("finished")),
        "{err}"
    );
    let mut bad = job.clone();
    bad.loading.load_set = "nosuch".into();
    let err = Run::new(&bad, &dir).overwrite(true).execute().expect_err("unknown set");
    assert!(err.to_string().contains("loading.load_set"), "{err}");
    assert_eq!(files(&dir), before, "a refused or failed run changed the previous run");
    assert_eq!(std::fs::read(dir.join("summary.json")).unwrap(), summary);
    let old = dir.with_file_name("rerun.old-1");
    assert!(!old.exists(), "a failed setup moved the previous run");

    let outcome = Run::new(&job, &dir).overwrite(true).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    assert_eq!(files(&old), before, "the previous run is kept whole");
    assert_eq!(std::fs::read(old.join("summary.json")).unwrap(), summary);
    assert_eq!(files(&dir), before, "the same job gives the same files");
}

/// A failed setup into a directory that did not exist leaves no directory behind.
#[test]
fn a_failed_setup_into_a_new_directory_leaves_nothing() {
    let dir = fresh("failed-new");
    let mut bad = example("elastic.toml");
    bad.loading.load_set = "nosuch".into();
    Run::new(&bad, &dir).execute().expect_err("unknown set");
    assert!(!dir.exists());
}

/// While a run holds the directory, a second writer (a resume, an overwrite) is refused
/// naming the first; a `running` summary whose writer is gone reads as interrupted.
#[test]
fn a_second_writer_is_refused_and_a_dead_writers_run_reads_as_interrupted() {
    let dir = fresh("second-writer");
    let job = example("elastic.toml");
    Run::new(&job, &dir).max_steps(Some(3)).execute().unwrap();
    let before = files(&dir);
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path).unwrap().replace("\"stopped\"", "\"running\"");
    std::fs::write(&path, text).unwrap();
    {
        let _first = RunLock::acquire(&dir).unwrap();
        assert_eq!(Summary::read(&dir).unwrap().status, "running");
        for run in [Run::new(&job, &dir).resume(false), Run::new(&job, &dir).overwrite(true)] {
            let err = run.execute().expect_err("a second writer");
            let me = format!("pid {}", std::process::id());
            assert!(
                matches!(&err, RunError::Claim(ClaimError::Locked { holder, .. }) if holder.contains(&me)),
                "{err}"
            );
        }
        assert_eq!(files(&dir), before);
    }
    let status = Summary::read(&dir).unwrap().status;
    assert!(status.starts_with("interrupted: "), "{status}");
    let outcome = Run::new(&job, &dir).resume(false).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
}

/// `examples/quick.toml` cut to 4 steps with snapshots and a field plot at 4 mm.
fn tiny_dem() -> Job {
    let mut job = example("quick.toml");
    job.loading.compression.as_mut().unwrap().displacement = 0.008;
    job.output.field_plots_at = vec![0.004];
    job.validate().unwrap();
    job
}

/// A session killed after step 3 with its checkpoint at step 2: step 3's row, VTK files,
/// snapshots and field data are on disk, and a temporary file of a write cut short. The resume
/// removes them, rebuilds the series and ends with the uninterrupted run's files.
#[test]
fn a_resume_after_a_kill_past_the_checkpoint_ends_as_the_uninterrupted_run() {
    let job = tiny_dem();
    let cli_like = |dir| Run::new(&job, dir).checkpoints(true).snapshots(true);
    let whole = fresh("whole");
    cli_like(&whole).execute().unwrap();
    let reference = files(&whole);
    assert!(reference.keys().any(|k| k.starts_with("snapshots/") && k.ends_with(".pvd")));
    assert!(reference.keys().any(|k| k.starts_with("fields/")));

    let split = fresh("split");
    cli_like(&split).max_steps(Some(2)).execute().unwrap();
    // What the killed session wrote after its checkpoint (step 3 and, in the snapshot and
    // field data, step 4's), copied from the uninterrupted run, and a write cut short.
    let csv: String = std::fs::read_to_string(whole.join("curve.csv"))
        .unwrap()
        .lines()
        .take(4)
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(split.join("curve.csv"), csv).unwrap();
    for (rel, bytes) in &reference {
        let late = rel.contains("_00003.") || rel.contains("_00004.");
        if late && !rel.ends_with(".pvd") {
            std::fs::write(split.join(rel), bytes).unwrap();
        }
    }
    std::fs::write(split.join("fields").join(".field_00003.json.77-0.tmp"), "half").unwrap();
    std::fs::write(split.join(".summary.json.77-1.tmp"), "half").unwrap();

    let outcome = cli_like(&split).resume(false).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    let resumed = files(&split);
    assert_eq!(resumed.keys().collect::<Vec<_>>(), reference.keys().collect::<Vec<_>>());
    let differ: Vec<&String> =
        reference.iter().filter(|(r, b)| &resumed[*r] != *b).map(|(r, _)| r).collect();
    assert!(differ.is_empty(), "differ from the uninterrupted run's: {differ:?}");
}
