//! Every job file under `examples/` loads, validates and builds its model and solver: an
//! example the README names cannot rot unnoticed (a renamed key, a removed option). A
//! failure names the file and the error, which names the key.

use cosdem_fem::solve::Solver;
use cosdem_job::Job;

#[test]
fn every_example_builds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let job = Job::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let model = job.model().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let settings = job.solver_settings().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        Solver::new(model, settings).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        names.push(path.file_name().unwrap().to_string_lossy().into_owned());
    }
    names.sort();
    // The examples the README and the committed tables name.
    for want in ["biaxial.toml", "quick.toml", "rve-size.toml", "scene-a-post-peak.toml"] {
        assert!(names.iter().any(|n| n == want), "{want} missing from {names:?}");
    }
}
