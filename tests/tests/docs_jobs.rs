//! The job files the docs give (`docs/**/*.toml`: the reduced jobs of
//! `docs/problems/accuracy/`, the study jobs of dated notes) are jobs of today's schema: each
//! one loads and validates, and builds its model (the mesh read, every set, region and stage
//! checked against it: `Job::model`, what `cosdem run` does before anything runs). The examples'
//! jobs are checked by running their first steps (`master/cli/tests/examples.rs`); these are
//! run only by the commands their pages give, so without this a renamed key or a moved mesh
//! would break them unseen.

use cosdem_job::Job;
use std::path::{Path, PathBuf};

/// Every `.toml` file under `dir`, in a fixed order.
fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            out.extend(toml_files(&p));
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
    out
}

#[test]
fn every_job_file_in_the_docs_loads_and_builds_its_model() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let files = toml_files(&docs);
    // The accuracy page's two reduced jobs at least: an empty walk would pass vacuously.
    assert!(files.len() >= 2, "found only {files:?}");
    let mut failures = Vec::new();
    for file in &files {
        let checked = Job::load(file).and_then(|job| job.model().map(|_| ()));
        if let Err(e) = checked {
            failures.push(format!("{}: {e}", file.display()));
        }
    }
    assert!(
        failures.is_empty(),
        "job files in docs/ that no longer load:\n{}",
        failures.join("\n")
    );
}
