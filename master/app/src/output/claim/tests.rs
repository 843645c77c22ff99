//! The claim rules on temporary directories: one writer, nothing destroyed, nothing left by
//! a claim that was not committed.

use super::*;

fn fresh(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cosdem-claim-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for n in 1..4 {
        let _ = std::fs::remove_dir_all(
            dir.with_file_name(format!("{}.old-{n}", dir.file_name().unwrap().to_string_lossy())),
        );
    }
    dir
}

fn old(dir: &Path, n: u32) -> PathBuf {
    dir.with_file_name(format!("{}.old-{n}", dir.file_name().unwrap().to_string_lossy()))
}

#[test]
fn a_second_writer_is_refused_naming_the_first_and_the_lock_dies_with_it() {
    let dir = fresh("two-writers");
    let claim = Claim::take(&dir, Mode::Fresh).unwrap();
    let lock = claim.commit().unwrap();
    assert!(is_locked(&dir));
    for mode in [Mode::Fresh, Mode::Overwrite, Mode::Resume] {
        let err = Claim::take(&dir, mode).expect_err("a second writer");
        let me = format!("pid {}", std::process::id());
        assert!(matches!(&err, ClaimError::Locked { holder, .. } if holder.contains(&me)), "{err}");
    }
    drop(lock);
    assert!(!is_locked(&dir), "the lock is released with its holder");
    Claim::take(&dir, Mode::Resume).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_new_run_into_a_directory_holding_files_is_refused_and_nothing_is_touched() {
    let dir = fresh("not-empty");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("curve.csv"), "step\n1\n").unwrap();
    let err = Claim::take(&dir, Mode::Fresh).expect_err("not empty");
    assert!(
        matches!(&err, ClaimError::NotEmpty { what, .. } if what.contains("curve.csv")),
        "{err}"
    );
    assert!(err.to_string().contains("--overwrite"), "{err}");
    assert_eq!(std::fs::read_to_string(dir.join("curve.csv")).unwrap(), "step\n1\n");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_uncommitted_claim_removes_only_the_directory_it_created() {
    let dir = fresh("uncommitted");
    drop(Claim::take(&dir, Mode::Fresh).unwrap());
    assert!(!dir.exists(), "a created directory is removed");
    std::fs::create_dir_all(&dir).unwrap();
    drop(Claim::take(&dir, Mode::Fresh).unwrap());
    assert!(dir.is_dir(), "an existing (empty) directory stays");
    std::fs::write(dir.join("curve.csv"), "x").unwrap();
    drop(Claim::take(&dir, Mode::Overwrite).unwrap());
    assert_eq!(std::fs::read_to_string(dir.join("curve.csv")).unwrap(), "x");
    assert!(!old(&dir, 1).exists(), "nothing is moved before the commit");
    let err = Claim::take(&fresh("missing"), Mode::Resume).expect_err("nothing to resume");
    assert!(matches!(err, ClaimError::Missing { .. }), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_overwrite_keeps_each_previous_run_as_old_n() {
    let dir = fresh("overwrite");
    for n in 1..=2u32 {
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("curve.csv"), format!("run {n}")).unwrap();
        let lock = Claim::take(&dir, Mode::Overwrite).unwrap().commit().unwrap();
        assert!(is_locked(&dir), "the fresh directory is locked");
        assert!(!dir.join("curve.csv").exists(), "the run starts in a fresh directory");
        assert_eq!(
            std::fs::read_to_string(old(&dir, n).join("curve.csv")).unwrap(),
            format!("run {n}")
        );
        drop(lock);
    }
    for n in 1..=2 {
        std::fs::remove_dir_all(old(&dir, n)).unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn temporary_files_left_by_a_kill_are_removed_on_commit() {
    let dir = fresh("temporaries");
    let tmp = [
        ".curve.csv.1-0.tmp",
        "fields/.field_00002.json.1-3.tmp",
        "snapshots/e0_p0/.snap_00002.vtu.1-4.tmp",
    ];
    for t in tmp {
        let path = dir.join(t);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, "half").unwrap();
    }
    std::fs::write(dir.join("curve.csv"), "kept").unwrap();
    drop(Claim::take(&dir, Mode::Resume).unwrap().commit().unwrap());
    for t in tmp {
        assert!(!dir.join(t).exists(), "{t} is left");
    }
    assert!(dir.join("curve.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
