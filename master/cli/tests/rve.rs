//! `cosdem rve`: `--seed` gives another specimen of the job's random material (the scatter of
//! a calibration), the job's own seed the job's own specimen byte for byte, a refusal naming
//! the option for a packing without a seed; the biaxial path keeps control past the peak.

use std::path::Path;
use std::process::Command;

fn cosdem(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cosdem")).args(args).output().unwrap()
}

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    p.to_str().unwrap().to_string()
}

/// Two steps of the footing's specimen (random, seed 7 in the job) as given, with `--seed 7`
/// and with `--seed 8`: the first two agree byte for byte, the third is another specimen
/// (another disc count or stress path) and lands in its own default directory name.
#[test]
fn a_seed_replaces_the_random_packing_s_and_only_that() {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli-rve-seed");
    let _ = std::fs::remove_dir_all(&root);
    let job = example("footing.toml");
    let run = |seed: Option<&str>, out: &str| {
        let out = root.join(out);
        let mut args = vec!["rve", &job, "--path", "biaxial", "--steps", "2"];
        args.extend(["--out", out.to_str().unwrap()]);
        if let Some(s) = seed {
            args.extend(["--seed", s]);
        }
        let o = cosdem(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(out.join("rve.csv")).unwrap()
    };
    let given = run(None, "given");
    assert_eq!(run(Some("7"), "seed7"), given, "--seed 7 is the job's own specimen");
    assert_ne!(run(Some("8"), "seed8"), given, "--seed 8 is another specimen");
}

/// A hexagonal packing has no seed: refused before anything runs, naming the option, its
/// value and the packing's kind.
#[test]
fn a_seed_for_a_lattice_is_refused_by_name() {
    let o = cosdem(&["rve", &example("quick.toml"), "--path", "biaxial", "--seed", "3"]);
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("--seed 3") && stderr.contains("`hexagonal`"), "{stderr}");
}

/// The footing's specimen with seed 8 (147 discs at 20 kPa) through 100 steps of the biaxial
/// path, well past its peak (step 9): before the lateral control's corrections were bounded,
/// a near-flat secant sent e_xx to det F = -9.7e6 at step 74 and the test stopped there. Now
/// every step is written, and at most 5 miss the control tolerance of 1e-3 (measured: 5, four
/// of them by under 1.2 %; one by 16 %, at step 78, where the small specimen collapses, its
/// friction angle falling from 33 to 29 degrees within a few steps, and no lateral strain
/// holds the stress: the step is written at its best iterate, flagged in `control_residual`).
#[test]
fn the_biaxial_path_keeps_control_past_the_peak() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli-rve-control");
    let _ = std::fs::remove_dir_all(&out);
    let job = example("footing.toml");
    let args = ["rve", &job, "--path", "biaxial", "--steps", "100", "--seed", "8"];
    let o = cosdem(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(out.join("rve.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (s_xx, residual) = (col("s_xx"), col("control_residual"));
    let rows: Vec<Vec<f64>> =
        lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 101);
    let missed = rows.iter().filter(|r| r[residual] > 1e-3).count();
    assert!(missed <= 5, "{missed} steps missed the control tolerance");
    for r in &rows {
        assert!((r[s_xx] + 2e4).abs() < 0.2 * 2e4, "s_xx {} (row {r:?})", r[s_xx]);
    }
}
