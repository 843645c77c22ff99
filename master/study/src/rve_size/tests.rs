//! The RVE-size study on three tiny sizes (a one-element confined panel, 4 Gauss points,
//! 2 load steps, 16-36-disc assemblies): every run finishes, the results do not depend on how
//! many runs go side by side, and the files are written.

use super::*;

/// The `dem-one-element` fixture: one Q8 element of four hexagonal assemblies (5 mm discs),
/// 100 kPa on both sides, 4 mm in 2 steps.
fn tiny() -> Job {
    cosdem_job::fixtures::load("dem-one-element")
}

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("cosdem-study-{name}-{}", std::process::id()))
}

/// Peak loads (N) of the three sizes, measured. The third re-measured on 2026-12-06: in the
/// square of side 0.06 m the column count's quotient (0.06 - 0.01) / 0.01 is
/// 4.999999999999999, and the square held one column too few until the lattice count was
/// fixed (221 931.1 N before).
const PEAK_LOADS: [f64; 3] =
    [201_901.493_276_461_32, 227_970.754_682_257_54, 245_392.274_446_038_18];

#[test]
fn three_tiny_sizes_run_deterministically_and_write_files() {
    let job = tiny();
    let sizes = vec![0.0016, 0.0025, 0.0036];
    let one = RveSizeSettings { sizes: sizes.clone(), threads: 1, ..Default::default() };
    let two = RveSizeSettings { threads: 2, ..one.clone() };
    let (d1, d2) = (temp("a"), temp("b"));
    let a = rve_size(&job, &one, &d1).unwrap();
    let b = rve_size(&job, &two, &d2).unwrap();
    assert_eq!(a.runs.len(), 3);
    for (x, y) in a.runs.iter().zip(&b.runs) {
        assert_eq!(x.status, "finished", "{x:?}");
        assert_eq!(x.steps, 2);
        // Bit-identical whatever the number of runs side by side.
        assert_eq!(x.metrics, y.metrics);
        assert_eq!(x.dem_steps, y.dem_steps);
    }
    // The peak loads, measured (N): deterministic runs, so 1e-9 relative covers only a change
    // of summation order.
    for (run, want) in a.runs.iter().zip(PEAK_LOADS) {
        let rel = (run.metrics.peak_load - want).abs() / want;
        assert!(
            rel <= 1e-9,
            "size {}: peak load {} N, measured {want} N",
            run.size,
            run.metrics.peak_load
        );
    }
    assert!(a.runs[0].discs < a.runs[1].discs && a.runs[1].discs < a.runs[2].discs);
    for f in [
        "study.csv",
        "study.json",
        "curves/curve_0.0025.csv",
        "plots/curves.png",
        "plots/size_peak_load.png",
        "plots/size_stiffness.png",
    ] {
        assert!(d1.join(f).is_file(), "{f}");
        if let Some(png) = f.strip_suffix(".png") {
            // The same figure as SVG beside it: a whole document.
            let svg = std::fs::read_to_string(d1.join(format!("{png}.svg"))).unwrap();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{png}.svg");
        }
    }
    // The curves' figure: one polyline per size (plus its legend stroke) through the origin
    // and every step of the size's curve (2 steps).
    let svg = std::fs::read_to_string(d1.join("plots/curves.svg")).unwrap();
    let points: Vec<usize> = svg
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains("stroke-width=\"2\""))
        .filter_map(|l| l.split("points=\"").nth(1)?.split('"').next())
        .map(|p| p.split_whitespace().count())
        .collect();
    assert_eq!(points, vec![3; 3], "{points:?}");
    let csv = std::fs::read_to_string(d1.join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4);
    let curve = std::fs::read_to_string(d1.join("curves/curve_0.0025.csv")).unwrap();
    assert_eq!(curve.lines().count(), 3);
    // Three points: F_u and E fit exactly (no intervals), or say why not.
    let json = std::fs::read_to_string(d1.join("study.json")).unwrap();
    assert!(json.contains("peak_load") && json.contains("stiffness_50"), "{json}");
    // study.json reads back into the same study (what `cosdem plot DIR` redraws from).
    assert_eq!(read_study(&d1).unwrap().runs, a.runs);
    // size-fit.json is the study's fit in the accuracy target's form, for the job's assembly
    // (compared as text: serde_json's float parsing is not bit-exact on the way back).
    let text = std::fs::read_to_string(d1.join(SIZE_FIT_FILE)).unwrap();
    let fit: cosdem_tune::accuracy::SizeFit = serde_json::from_str(&text).unwrap();
    assert_eq!(fit.sizes, one.sizes);
    let made = size_fit(&a, &job, fit.source).unwrap();
    assert_eq!(text, format!("{}\n", serde_json::to_string_pretty(&made).unwrap()));
    // Reusing the curves gives the same runs but for the (unknown) wall time.
    let reuse = RveSizeSettings { reuse: true, ..one.clone() };
    let c = rve_size(&job, &reuse, &d1).unwrap();
    for (x, y) in a.runs.iter().zip(&c.runs) {
        assert_eq!(SizeRun { wall_seconds: 0.0, ..x.clone() }, *y);
    }
    std::fs::remove_dir_all(&d1).unwrap();
    std::fs::remove_dir_all(&d2).unwrap();
}

#[test]
fn bad_sizes_and_materials_are_errors_naming_the_value() {
    let job = tiny();
    let e = job_for_size(&job, -1.0, None).unwrap_err().to_string();
    assert!(e.contains("sizes") && e.contains("-1"), "{e}");
    // side = 0.03 < 8 r = 0.04: the packing's own check names the key.
    let e = job_for_size(&job, 0.0009, None).unwrap_err().to_string();
    assert!(e.contains("packing.side"), "{e}");
    let mut job = tiny();
    job.material = cosdem_job::MaterialSection::Elastic {
        shear_modulus: 1e7,
        poisson: 0.3,
        cosserat_modulus: None,
        length: None,
    };
    job.validate().unwrap();
    assert!(job_for_size(&job, 0.01, None).unwrap_err().to_string().contains("dem"));
}

/// A symmetric mesh reports the whole panel's load: the half mesh (`symmetry = "half_x"`, two
/// elements in x so the axis is a mesh line) gives the full mesh's F_u and E. The half mesh is
/// the full problem restricted to symmetric fields, so the curves agree to the Newton
/// tolerance (5e-3 relative residual here; 1e-7 measured on scene A), not to round-off;
/// without the load scale they would differ by a factor 2.
#[test]
fn symmetric_meshes_report_the_whole_panel_load() {
    let mut full = tiny();
    full.mesh.nx = Some(2);
    let mut half = full.clone();
    half.mesh.symmetry = cosdem_fem::symmetry::Symmetry::HalfX;
    let settings = RveSizeSettings { sizes: vec![0.0025], threads: 1, ..Default::default() };
    let run = |job: &Job| {
        job.validate().unwrap();
        run_size(job, 0.0025, &settings, None).unwrap()
    };
    let (f, h) = (run(&full), run(&half));
    assert_eq!(f.status, "finished");
    assert_eq!(h.status, "finished");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(h.metrics.peak_load, f.metrics.peak_load) < 1e-2, "{h:?} vs {f:?}");
    let (hs, fs) = (h.metrics.stiffness.unwrap(), f.metrics.stiffness.unwrap());
    assert!(rel(hs, fs) < 1e-2, "E {hs} vs {fs}");
}

/// The committed size fit the accuracy target reads is what `size_fit` makes of the
/// committed study (`docs/notes/paper/rve-size-study.json`) and its job (`examples/rve-size.toml`):
/// the same laws to the bit, the same assembly and sizes. A hand edit of either file, or a
/// study whose fits changed without the committed fit, fails here.
#[test]
fn committed_size_fit_is_the_study_s() {
    let study: RveSizeStudy =
        serde_json::from_str(include_str!("../../../../docs/notes/paper/rve-size-study.json"))
            .unwrap();
    let job =
        Job::from_toml(include_str!("../../../../examples/rve-size.toml"), "rve-size").unwrap();
    let committed: cosdem_tune::accuracy::SizeFit =
        serde_json::from_str(include_str!("../../../../docs/notes/rve-size-scene-a-quarter.json"))
            .unwrap();
    let made = size_fit(&study, &job, committed.source.clone()).unwrap();
    assert_eq!(made, committed);
    assert!(committed.stiffness.unwrap().has_plateau());
    assert!(!committed.peak_load.unwrap().has_plateau());
}
