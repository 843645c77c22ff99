//! Fault injection on the master (`test-master`, the run driver with in-process workers that
//! SIGKILLs itself at a chosen phase): killed during the setup, during a solve, during a
//! commit, after a step's outputs and before its checkpoint, twice in one run; a checkpoint
//! with a flipped bit; a second writer while a run holds the directory. Each case ends either
//! with the resumed run's directory byte for byte the undisturbed run's, or with a clear error
//! and the directory intact and resumable. The table of cases and outcomes is printed
//! (`--nocapture`).
//!
//! The job: `examples/quick.toml` to 8 mm in 4 steps (16 assemblies of 105 discs, snapshots
//! at two Gauss points, a field plot at 4 mm), checkpoint after every step.

#![cfg(unix)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("faults_master")
}

fn job_file() -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/quick.toml"),
    )
    .unwrap()
    .replace("displacement = 0.02", "displacement = 0.008")
    .replace("field_plots_at = [0.01, 0.02]", "field_plots_at = [0.004]");
    let path = root().join("tiny.toml");
    std::fs::create_dir_all(root()).unwrap();
    std::fs::write(&path, text).unwrap();
    path
}

fn master(out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_test-master"))
        .arg(job_file())
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn fresh(name: &str) -> PathBuf {
    let dir = root().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The run directory's files less lock, summary and log.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    cosdem_app::output::run_dir::comparable_files(dir).unwrap()
}

/// The summary's deterministic part: status, steps, DEM steps, the curve's metrics.
fn summary(dir: &Path) -> String {
    let s = cosdem_app::output::run_dir::Summary::read(dir).unwrap();
    format!("{} {} {} {:?}", s.status, s.steps, s.dem_steps, s.metrics)
}

fn killed(o: &Output) -> bool {
    use std::os::unix::process::ExitStatusExt;
    o.status.signal() == Some(9) && String::from_utf8_lossy(&o.stderr).contains("FAULT")
}

fn finished(o: &Output) -> bool {
    o.status.success() && String::from_utf8_lossy(&o.stdout).contains("FINISHED 4")
}

/// The differences between `dir` and the undisturbed run `reference`: none is the outcome
/// every recoverable case must have.
fn differences(dir: &Path, reference: &Path) -> Vec<String> {
    let (a, b) = (files(dir), files(reference));
    let mut d: Vec<String> = b
        .iter()
        .filter(|(k, v)| a.get(*k) != Some(v))
        .map(|(k, _)| k.clone())
        .chain(a.keys().filter(|k| !b.contains_key(*k)).cloned())
        .collect();
    if summary(dir) != summary(reference) {
        d.push(format!("summary: {} vs {}", summary(dir), summary(reference)));
    }
    d
}

#[test]
fn a_killed_master_resumes_to_the_undisturbed_run_and_bad_states_are_refused_intact() {
    let reference = fresh("reference");
    assert!(finished(&master(&reference, &[])));
    let mut table: Vec<(String, String)> = Vec::new();

    // Killed, then resumed (a kill during the setup: run again, the directory it left holds
    // only the lock file).
    let kills: [(&str, &[&str]); 7] = [
        ("setup", &["setup:0:0:kill"]),
        ("solve, step 1, second evaluation (no checkpoint yet)", &["solve:1:2:kill"]),
        ("solve, step 2, first evaluation", &["solve:2:1:kill"]),
        ("commit of step 2", &["commit:2:0:kill"]),
        ("step 2 recorded, before its checkpoint", &["recorded:2:0:kill"]),
        ("last step recorded, before its checkpoint", &["recorded:4:0:kill"]),
        ("twice: step 2 recorded, then step 3's commit", &["recorded:2:0:kill", "commit:3:0:kill"]),
    ];
    for (case, faults) in kills {
        let dir = fresh(&format!("kill-{}", case.split(',').next().unwrap().replace(' ', "-")));
        for (i, f) in faults.iter().enumerate() {
            let resume: &[&str] = if i == 0 { &[] } else { &["--resume"] };
            let o = master(&dir, &[resume, &["--fault", f]].concat());
            assert!(killed(&o), "{case}: {f}: {o:?}");
        }
        let again: &[&str] = if faults[0].starts_with("setup") { &[] } else { &["--resume"] };
        let mut o = master(&dir, again);
        if faults[0].starts_with("solve:1:") {
            // Nothing to resume: refused naming the file; `--overwrite` starts again and
            // keeps the killed run as `.old-1`.
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert!(o.status.code() == Some(2) && stderr.contains("checkpoint.bin"), "{stderr}");
            let _ = std::fs::remove_dir_all(
                dir.with_file_name(format!("{}.old-1", dir.file_name().unwrap().to_string_lossy())),
            );
            o = master(&dir, &["--overwrite"]);
        }
        assert!(finished(&o), "{case}: {o:?}");
        let d = differences(&dir, &reference);
        assert!(d.is_empty(), "{case}: differs from the undisturbed run: {d:?}");
        let how = match faults[0] {
            f if f.starts_with("setup") => {
                "run again (the directory held only its lock): byte-identical"
            }
            f if f.starts_with("solve:1:") => {
                "resume refused naming checkpoint.bin; --overwrite run byte-identical"
            }
            _ => "resumed, byte-identical",
        };
        table.push((format!("master SIGKILL: {case}"), how.into()));
    }

    // A killed run's summary says `running`; read back, its dead lock makes it interrupted.
    let dir = fresh("flips");
    assert!(killed(&master(&dir, &["--fault", "recorded:2:0:kill"])));
    let status = cosdem_app::output::run_dir::Summary::read(&dir).unwrap().status;
    assert!(status.starts_with("interrupted: "), "{status}");
    table.push(("killed run's `running` summary, read back".into(), status));

    // A bit flipped anywhere in the checkpoint: refused naming the file, nothing touched;
    // with the good checkpoint back, the resume finishes byte-identical.
    let path = dir.join("checkpoint.bin");
    let good = std::fs::read(&path).unwrap();
    let before = files(&dir);
    let n = good.len() * 8;
    for bit in [0, 77, n / 3, n / 2, n - 1] {
        let mut bad = good.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        std::fs::write(&path, &bad).unwrap();
        let o = master(&dir, &["--resume"]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "bit {bit}: {o:?}");
        assert!(stderr.contains("checkpoint.bin"), "bit {bit}: {stderr}");
        let mut now = files(&dir);
        now.insert("checkpoint.bin".into(), good.clone());
        assert!(now == before, "bit {bit}: the refused resume changed the directory");
    }
    table.push((
        format!("checkpoint bit flips (5 of {n} bits)"),
        "refused naming checkpoint.bin, directory intact".into(),
    ));
    std::fs::write(&path, &good).unwrap();
    assert!(finished(&master(&dir, &["--resume"])));
    assert!(differences(&dir, &reference).is_empty());
    table.push(("resume with the good checkpoint back".into(), "byte-identical".into()));

    // A second writer while a run holds the directory (paused after step 2).
    let dir = fresh("two-writers");
    let mut first = Command::new(env!("CARGO_BIN_EXE_test-master"))
        .arg(job_file())
        .arg(&dir)
        .args(["--fault", "recorded:2:0:pause"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let t = std::time::Instant::now();
    while !std::fs::read_to_string(dir.join("curve.csv")).is_ok_and(|c| c.lines().count() == 3) {
        assert!(t.elapsed().as_secs() < 60, "the first writer did not reach step 2");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(200));
    let before = files(&dir);
    for extra in [&["--resume"][..], &[]] {
        let o = master(&dir, extra);
        let stderr = String::from_utf8_lossy(&o.stderr);
        let holder = format!("pid {}", first.id());
        assert!(o.status.code() == Some(2) && stderr.contains(&holder), "{extra:?}: {stderr}");
    }
    assert!(files(&dir) == before, "a refused second writer changed the directory");
    first.kill().unwrap();
    first.wait().unwrap();
    assert!(finished(&master(&dir, &["--resume"])));
    assert!(differences(&dir, &reference).is_empty());
    table.push((
        "second writer (resume, new run) while the first runs".into(),
        "refused naming the first's pid, directory intact; resumed byte-identical".into(),
    ));

    println!("\n| master-side case | outcome |\n|---|---|");
    for (case, outcome) in &table {
        println!("| {case} | {outcome} |");
    }
}
