//! The examples stay true: every `examples/*.toml` runs its first load steps through the
//! `cosdem` binary, `cosdem run JOB --max-steps K --quiet --out DIR`, and the run's
//! `curve.csv` must equal the committed prefix `examples/expected/<stem>.csv` byte for byte.
//!
//! Byte equality is the right tolerance: a run is deterministic (the same job gives the same
//! floating-point operations in the same order, and Rust reorders none of them at any
//! optimisation level, so the release build of `scripts/check-examples` must agree too), so
//! any difference in the curve's first K rows (load, iterations, cuts, DEM steps) is a change
//! of what the example computes, which must be deliberate and re-blessed.
//!
//! K per example ([`EXAMPLES`]) keeps the default run of this file under about two minutes in
//! the test profile on two cores; the figures the docs quote for whole runs are checked by
//! `scripts/check-examples` (release, every example to its end), not here. A file in
//! `examples/` without an entry in [`EXAMPLES`], its expected prefix or its claims file
//! (`examples/expected/<stem>.claims.toml`) fails [`every_example_has_a_prefix`].
//!
//! To (re)write the expected prefixes after a deliberate change, run with `COSDEM_BLESS=1`
//! (each test then writes `examples/expected/<stem>.csv` from its run instead of comparing):
//!
//! ```sh
//! COSDEM_BLESS=1 cargo test -p cosdem-cli --test examples -- --include-ignored
//! ```
//!
//! and review the diff before committing it (`scripts/check-examples --bless` does the same).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Every example and the number of load steps its default test runs. The first steps' cost in
/// the test profile on two cores (measured 2026-12-05, step 1 alone, with other builds
/// running) is given beside each K.
const EXAMPLES: &[(&str, u64)] = &[
    // 10 steps, the whole run: well under a second.
    ("elastic", 10),
    // 10 steps, the whole run: under a second.
    ("quick", 10),
    // 1.2 s for step 1 (32 points x 400 discs).
    ("biaxial", 5),
    // 115-210 s for step 1 alone (16 points x 880 discs, perturbation tangent, 19 Newton
    // iterations): the slowest check of the default tests, kept because every example runs
    // its first steps there.
    ("panel-1m", 1),
    // 2.5 s for step 1 (4 points x 880 discs, perturbation tangent).
    ("rve-size", 3),
    // 0.2 s for step 1 (4 points x 105 discs); to step 25, past the first steps that
    // need more than one Newton iteration (23-25).
    ("scene-a-post-peak", 25),
    // The same under the updated-Lagrangian option (issue 29): 25 steps as well.
    ("scene-a-post-peak-ul", 25),
    // 1.7 s for step 1 (400 points x 105 discs), the next four cheaper.
    ("panel-5m", 5),
    // Staged jobs (issue 28), K = 2 each. Steps 1-2 of the footing: the surcharge then the
    // first push, on its mixed mesh (164 points x 147 discs).
    ("footing", 2),
    // 1.0 s for steps 1-2 (32 points x 147 discs, at rest then the first active step).
    ("retaining-wall", 2),
    // 8.1 s for steps 1-2 (108 points x 147 discs, the first two geostatic steps).
    ("slope", 2),
    // 0.7 s for steps 1-2 (32 points x 147 discs, the first two loading steps).
    ("cyclic-biaxial", 2),
    // The geotechnical checks of issue 31 (docs/problems/), FEMxDEM's geometries. Step 1 is
    // the surcharge (2 Newton iterations), step 2 the first move of the wall or the footing
    // (the iteration limit, 21 solves of every point).
    // 53 s for steps 1-2 (800 points x 147 discs; measured 2026-12-07 beside a release run,
    // so about half that on a quiet machine).
    ("retaining-smooth-active", 2),
    // 3.8 s for step 1 (800 points x 147 discs): the passive job differs only in the sign of
    // the wall's move, which step 2 of the active one covers.
    ("retaining-smooth-passive", 1),
    // 62 s for steps 1-2 (1 287 points x 147 discs), measured as the wall's.
    ("footing-femxdem", 2),
    // Step 1 of the 512-point biaxial test with its weak element (400 discs each; the cheap
    // relaxation the job sets).
    ("biaxial-shear-band", 1),
];

/// The workspace root (this crate is `master/cli`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("master/cli").to_path_buf()
}

/// The first `steps` steps of `examples/<stem>.toml` against `examples/expected/<stem>.csv`,
/// or, with `COSDEM_BLESS` set, the run's curve written there. Returns the run directory.
fn check_prefix(stem: &str) -> PathBuf {
    let steps = EXAMPLES
        .iter()
        .find(|(s, _)| *s == stem)
        .map(|(_, k)| *k)
        .unwrap_or_else(|| panic!("examples/{stem}.toml has no entry in EXAMPLES"));
    let root = root();
    let job = root.join("examples").join(format!("{stem}.toml"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("examples").join(stem);
    let _ = std::fs::remove_dir_all(&out);
    let run = Command::new(env!("CARGO_BIN_EXE_cosdem"))
        .current_dir(&root)
        .arg("run")
        .arg(&job)
        .args(["--max-steps", &steps.to_string(), "--quiet", "--out"])
        .arg(&out)
        .output()
        .expect("cosdem runs");
    assert!(
        run.status.success(),
        "cosdem run {} --max-steps {steps} failed ({}):\n{}{}",
        job.display(),
        run.status,
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let curve = std::fs::read(out.join("curve.csv")).expect("the run wrote curve.csv");
    let expected = root.join("examples/expected").join(format!("{stem}.csv"));
    if std::env::var_os("COSDEM_BLESS").is_some() {
        std::fs::write(&expected, &curve).expect("writing the expected prefix");
        return out;
    }
    let want = std::fs::read(&expected).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; write it with COSDEM_BLESS=1 cargo test -p cosdem-cli --test examples",
            expected.display()
        )
    });
    assert!(
        curve == want,
        "examples/{stem}.toml's first {steps} steps differ from {}:\n--- expected\n{}\n--- got\n{}",
        expected.display(),
        String::from_utf8_lossy(&want),
        String::from_utf8_lossy(&curve)
    );
    out
}

/// What a geotechnical check (docs/problems/) reads besides the curve, written from the first
/// step on: the equivalent-strain field data of step 1 (the failure mechanism is read from
/// these fields) and the nodal and Gauss-point VTK series.
fn check_fields(out: &Path) {
    for file in ["fields/field_00001.json", "fields.pvd", "gauss.pvd"] {
        assert!(out.join(file).is_file(), "{} was not written", out.join(file).display());
    }
    let field = std::fs::read_to_string(out.join("fields/field_00001.json")).expect("readable");
    assert!(field.contains("equivalent_strain"), "field data without the equivalent strain");
}

/// Every `examples/*.toml` has an entry in [`EXAMPLES`], a committed prefix and a claims file
/// (`examples/expected/<stem>.claims.toml`, what its docs say of the whole run), and every
/// entry belongs to an example: a new example cannot go unchecked.
#[test]
fn every_example_has_a_prefix() {
    let root = root();
    let mut stems: Vec<String> = std::fs::read_dir(root.join("examples"))
        .expect("examples/ is readable")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_stem().expect("a file name").to_string_lossy().into_owned())
        .collect();
    stems.sort();
    let mut listed: Vec<String> = EXAMPLES.iter().map(|(s, _)| s.to_string()).collect();
    listed.sort();
    assert_eq!(stems, listed, "examples/*.toml and this file's EXAMPLES differ");
    let bless = std::env::var_os("COSDEM_BLESS").is_some();
    for stem in &stems {
        let expected = root.join("examples/expected").join(format!("{stem}.csv"));
        assert!(
            bless || expected.is_file(),
            "{} is missing: write it with COSDEM_BLESS=1 cargo test -p cosdem-cli --test examples",
            expected.display()
        );
        // What the docs claim for the whole run, checked by scripts/check-examples.
        let claims = root.join("examples/expected").join(format!("{stem}.claims.toml"));
        assert!(claims.is_file(), "{} is missing (see scripts/check-examples)", claims.display());
    }
}

#[test]
fn elastic() {
    check_prefix("elastic");
}

#[test]
fn quick() {
    check_prefix("quick");
}

#[test]
fn biaxial() {
    check_prefix("biaxial");
}

#[test]
fn panel_1m() {
    check_prefix("panel-1m");
}

#[test]
fn rve_size() {
    check_prefix("rve-size");
}

#[test]
fn scene_a_post_peak() {
    check_prefix("scene-a-post-peak");
}

#[test]
fn scene_a_post_peak_ul() {
    check_prefix("scene-a-post-peak-ul");
}

#[test]
fn panel_5m() {
    check_prefix("panel-5m");
}

#[test]
fn footing() {
    check_prefix("footing");
}

#[test]
fn retaining_wall() {
    check_prefix("retaining-wall");
}

#[test]
fn slope() {
    check_prefix("slope");
}

#[test]
fn cyclic_biaxial() {
    check_prefix("cyclic-biaxial");
}

#[test]
fn retaining_smooth_active() {
    check_fields(&check_prefix("retaining-smooth-active"));
}

#[test]
fn retaining_smooth_passive() {
    check_fields(&check_prefix("retaining-smooth-passive"));
}

#[test]
fn footing_femxdem() {
    check_fields(&check_prefix("footing-femxdem"));
}

/// The weak element is a second material: its points get their own specimen.
#[test]
fn biaxial_shear_band() {
    let out = check_prefix("biaxial-shear-band");
    check_fields(&out);
    let summary = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let specimens = summary.split("\"specimens\"").nth(1).expect("summary.json's specimens");
    assert!(specimens.contains("\"distinct\": 2,"), "{summary}");
    assert!(specimens.contains("\"points\": 512"), "{summary}");
}
