//! The shared test jobs: the TOML files of `fixtures/jobs/` at the top of the repository, one
//! file per job instead of inline copies in every test.
//!
//! Compiled for this crate's own tests and, elsewhere, with the feature `fixtures`, meant for
//! dev-dependencies only: `cosdem-job = { workspace = true, features = ["fixtures"] }`. The
//! files are read from the source tree at run time, so they are not part of the package.
//!
//! The fixtures, by name:
//! - `elastic-panel`: 1 x 1 m, 2 x 2 Q8, elastic, 1 cm in 4 steps, every other key defaulted;
//! - `elastic-panel-confined`: 1 x 2 m, 4 x 4 Q8, elastic, 100 kPa on both sides, 1 cm in
//!   3 steps (symmetric: usable on half and quarter meshes);
//! - `dem-one-element`: one Q8 element of four hexagonal DEM assemblies, 100 kPa on both
//!   sides, 4 mm in 2 steps, Newton tolerances 5e-3;
//! - `gmsh-square`: the 2 x 2 Q8 Gmsh square of `master/fem/tests/data`, elastic.
//! - `packing-file`: `dem-one-element` with its assemblies read from the YADE packing
//!   `examples/packings/random-270.txt` (`kind = "file"`).

use crate::Job;
use std::path::{Path, PathBuf};

/// The directory of the fixtures, `fixtures/jobs/` at the top of the repository.
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/jobs")
}

/// The file of fixture `name` (given without `.toml`).
pub fn path(name: &str) -> PathBuf {
    dir().join(format!("{name}.toml"))
}

/// The text of fixture `name`, for a test that varies it before parsing
/// (`Job::from_toml(&text("elastic-panel").replace("nx = 2", "nx = 0"), ..)`).
///
/// # Panics
/// When the fixture does not exist (a test bug).
pub fn text(name: &str) -> String {
    let path = path(name);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("fixture {name} ({}): {e}", path.display()))
}

/// Fixture `name` read and validated as a job file ([`Job::load`]: a relative mesh file is
/// found beside the fixture).
///
/// # Panics
/// When the fixture does not exist or is not a valid job (a test bug).
pub fn load(name: &str) -> Job {
    Job::load(&path(name)).unwrap_or_else(|e| panic!("fixture {name}: {e}"))
}
