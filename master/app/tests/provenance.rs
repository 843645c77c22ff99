//! The run directory says where its results come from: `provenance.json` with one session per
//! `cosdem run` and `--resume` (command line, version, commit, the job's digest, the resumed
//! step) and `job.toml`, the job as it ran, which reads back as the same job.

use cosdem_app::output::provenance::{self, JOB_COPY, Origin, Provenance};
use cosdem_app::run::Run;
use cosdem_job::Job;
use std::path::{Path, PathBuf};

fn elastic() -> Job {
    Job::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/elastic.toml")).unwrap()
}

fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("provenance").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn each_session_is_recorded_with_the_job_it_ran() {
    let dir = fresh("sessions");
    let job = elastic();
    let origin =
        |cmd: &str| Origin { command: cmd.split(' ').map(String::from).collect(), job_text: None };
    Run::new(&job, &dir).max_steps(Some(3)).origin(origin("cosdem run a")).execute().unwrap();
    let p = Provenance::read(&dir).unwrap();
    assert_eq!(p.sessions.len(), 1);
    let first = &p.sessions[0];
    assert_eq!(first.command, ["cosdem", "run", "a"]);
    assert_eq!(first.cosdem_version, env!("CARGO_PKG_VERSION"));
    assert!(first.commit == "unknown" || first.commit.len() == 40, "{}", first.commit);
    assert_eq!(first.job_digest, provenance::job_digest(&job));
    assert_eq!((first.job_file.as_str(), first.resumed_at_step), (JOB_COPY, None));
    let copy = std::fs::read_to_string(dir.join(JOB_COPY)).unwrap();
    assert_eq!(Job::from_toml(&copy, "job.toml").unwrap(), job, "the copy is the job");

    // A resume with the same job: the same copy; with another [output], a copy of its own.
    Run::new(&job, &dir).resume(false).max_steps(Some(5)).origin(origin("b")).execute().unwrap();
    let mut changed = job.clone();
    changed.output.vtk_every = 2;
    Run::new(&changed, &dir).resume(false).origin(origin("c")).execute().unwrap();
    let p = Provenance::read(&dir).unwrap();
    let files: Vec<(&str, Option<u64>)> =
        p.sessions.iter().map(|s| (s.job_file.as_str(), s.resumed_at_step)).collect();
    assert_eq!(files, [(JOB_COPY, None), (JOB_COPY, Some(3)), ("job.session-3.toml", Some(5))]);
    let copy = std::fs::read_to_string(dir.join("job.session-3.toml")).unwrap();
    assert_eq!(Job::from_toml(&copy, "j").unwrap(), changed);
    assert_ne!(p.sessions[2].job_digest, p.sessions[1].job_digest);
}

/// The job file's own text is kept as the user wrote it (comments included).
#[test]
fn the_job_files_text_is_kept_as_written() {
    let dir = fresh("text");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/elastic.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let origin = Origin { command: vec!["cosdem".into()], job_text: Some(text.clone()) };
    Run::new(&elastic(), &dir).origin(origin).execute().unwrap();
    assert_eq!(std::fs::read_to_string(dir.join(JOB_COPY)).unwrap(), text);
}
