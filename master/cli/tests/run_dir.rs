//! `cosdem run` into a directory that holds a previous run: refused with a message naming
//! `--overwrite` and `--resume`, the previous run's files (its log included) untouched; with
//! `--overwrite` the previous run is kept as `RUN.old-1`. The run keeps the job file as written
//! and the command line (`job.toml`, `provenance.json`).

use std::path::Path;
use std::process::Command;

fn cosdem(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cosdem")).args(args).output().unwrap()
}

#[test]
fn a_rerun_is_refused_without_touching_the_log_and_overwrite_keeps_the_old_run() {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli-run-dir");
    let _ = std::fs::remove_dir_all(&root);
    let out = root.join("elastic");
    let job = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/elastic.toml");
    let args = ["run", job.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()];
    assert!(cosdem(&args).status.success());
    let log = std::fs::read(out.join("cosdem.log")).unwrap();
    let curve = std::fs::read(out.join("curve.csv")).unwrap();
    assert!(!log.is_empty());
    // Provenance: the job file as written and the command line.
    let text = std::fs::read_to_string(&job).unwrap();
    assert_eq!(std::fs::read_to_string(out.join("job.toml")).unwrap(), text);
    let provenance = std::fs::read_to_string(out.join("provenance.json")).unwrap();
    assert!(provenance.contains("\"--out\"") && provenance.contains("\"commit\""), "{provenance}");

    let refused = cosdem(&args);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("--overwrite") && stderr.contains("--resume"), "{stderr}");
    assert_eq!(std::fs::read(out.join("cosdem.log")).unwrap(), log, "the log was touched");
    assert_eq!(std::fs::read(out.join("curve.csv")).unwrap(), curve);

    let again = cosdem(&[&args[..], &["--overwrite"]].concat());
    assert!(again.status.success(), "{}", String::from_utf8_lossy(&again.stderr));
    let old = root.join("elastic.old-1");
    assert_eq!(std::fs::read(old.join("cosdem.log")).unwrap(), log);
    assert_eq!(std::fs::read(out.join("curve.csv")).unwrap(), curve);
    std::fs::remove_dir_all(&root).unwrap();
}
