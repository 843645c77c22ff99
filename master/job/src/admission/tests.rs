//! The admission estimate against the issue's jobs, the fixtures and the examples.

use super::*;
use crate::fixtures;

const GIB: u64 = 1 << 30;

fn job(text: &str) -> Job {
    Job::from_toml(text, "j.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn of(job: &Job) -> Estimate {
    let counts = MeshCounts::of_job(job)
        .unwrap_or_else(|| MeshCounts::of_mesh(&job.build_mesh().expect("the mesh builds")));
    estimate(job, counts)
}

/// quick.toml with its mesh and packing replaced.
fn quick(nx: usize, packing: &str) -> Job {
    let text = std::fs::read_to_string(fixtures::dir().join("../../examples/quick.toml")).unwrap();
    let text = text
        .replace("nx = 2", &format!("nx = {nx}"))
        .replace("ny = 2", &format!("ny = {nx}"))
        .replace("packing = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }", packing);
    job(&text)
}

/// A random packing of about `discs` discs of radii 4-6 mm.
fn random(discs: f64) -> String {
    let er2: f64 = (0.004f64 * 0.004 + 0.004 * 0.006 + 0.006 * 0.006) / 3.0;
    let side = (discs * std::f64::consts::PI * er2 / 0.84).sqrt();
    format!(
        "packing = {{ kind = \"random\", r_min = 0.004, r_max = 0.006, side = {side}, seed = 1, \
         confining_stress = 1e5 }}"
    )
}

/// The issue's jobs that allocated until the allocator aborted are refused under the default
/// limit of a 24 GiB machine, naming the keys that make them large with their values, and
/// the figures.
#[test]
fn the_issues_jobs_are_refused_naming_the_keys() {
    let hex = "packing = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }";
    let panel = fixtures::text("elastic-panel");
    let cases = [
        (quick(300, hex), vec!["mesh.nx = 300", "mesh.ny = 300"]),
        (
            job(&panel.replace("nx = 2", "nx = 1000").replace("ny = 2", "ny = 1000")),
            vec!["mesh.nx = 1000", "mesh.ny = 1000"],
        ),
        (quick(2, &random(935e3)), vec!["material.assembly.packing.side", "mesh.nx = 2"]),
        (quick(10, &random(289e3)), vec!["material.assembly.packing.side", "mesh.nx = 10"]),
    ];
    for (job, keys) in cases {
        let e = of(&job);
        let limit = (24.0 * GIB as f64 * DEFAULT_MEMORY_FRACTION) as u64;
        let err = e.check(limit, true).expect_err("refused").to_string();
        for key in keys {
            assert!(err.contains(key), "{key} not in: {err}");
        }
        assert!(err.contains("GiB") && err.contains("limit of 19.2 GiB"), "{err}");
    }
}

/// The disc count follows the packing: 16 points of 935k discs are 15M discs.
#[test]
fn the_estimate_counts_points_and_discs() {
    let e = of(&quick(2, &random(935e3)));
    assert_eq!(e.gauss_points, 16.0);
    assert!((e.discs_per_assembly / 935e3 - 1.0).abs() < 1e-6, "{}", e.discs_per_assembly);
    let dem = e.parts.iter().find(|p| p.name == "DEM assemblies").unwrap();
    assert!(dem.in_process_only && dem.keys.iter().any(|k| k.contains("packing.r_max")), "{dem:?}");
    // With remote workers this process holds less: the assemblies live in the workers.
    assert!(e.in_process_share(false) < 0.7 * e.in_process_share(true));
    assert_eq!(e.in_process_share(true), e.total());
}

/// Every fixture and example is admitted under the default limit of a 24 GiB machine,
/// quick.toml under 1 GiB, and none of them draws a disk warning.
#[test]
fn the_fixtures_and_examples_are_admitted() {
    let examples = fixtures::dir().join("../../examples");
    let mut paths: Vec<_> = std::fs::read_dir(fixtures::dir())
        .unwrap()
        .chain(std::fs::read_dir(&examples).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 10, "{paths:?}");
    for path in paths {
        let job = Job::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let e = of(&job);
        let limit = (24.0 * GIB as f64 * DEFAULT_MEMORY_FRACTION) as u64;
        e.check(limit, true).unwrap_or_else(|err| panic!("{}: {err}", path.display()));
        assert_eq!(e.disk_warning(), None, "{}", path.display());
        if path.ends_with("quick.toml") {
            e.check(GIB, true).unwrap();
            assert!(e.total() < GIB as f64, "{}", size(e.total()));
        }
    }
}

/// 10^6 steps at `vtk_every = 1` (the elastic panel) would write about 16 GB in 2 million
/// files: warned, with the figures and the keys; every 1000th step is not.
#[test]
fn a_million_saved_steps_draw_a_disk_warning() {
    let text = fixtures::text("elastic-panel").replace("steps = 4", "steps = 1000000");
    let e = of(&job(&text));
    assert_eq!(e.saved_steps, 1e6);
    assert!(e.disk_total > 10e9 && e.disk_total < 20e9, "{}", size(e.disk_total));
    assert!(e.files_total > 1.9e6 && e.files_total < 2.1e6, "{}", e.files_total);
    let warning = e.disk_warning().expect("a warning");
    assert!(warning.contains("GiB") && warning.contains("2000010 files"), "{warning}");
    assert!(warning.contains("output.vtk_every = 1"), "{warning}");
    let e = of(&job(&format!("{text}\n[output]\nvtk_every = 1000\n")));
    assert_eq!(e.disk_warning(), None);
}

/// The machine's memory comes from `MemTotal`.
#[test]
fn machine_memory_reads_mem_total() {
    assert_eq!(mem_total("MemTotal:       24683784 kB\nMemFree: 1 kB\n"), Some(24683784 * 1024));
    assert_eq!(mem_total("MemFree: 1 kB\n"), None);
    assert_eq!(mem_total("MemTotal: x kB\n"), None);
    if cfg!(target_os = "linux") {
        assert!(machine_memory().is_some_and(|m| m > 1 << 26));
    }
}

/// Sizes print in binary units.
#[test]
fn sizes_print_in_binary_units() {
    assert_eq!(size(512.0), "512.0 B");
    assert_eq!(size(1.5 * 1024.0 * 1024.0), "1.5 MiB");
    assert_eq!(size(24.0 * GIB as f64), "24.0 GiB");
}

/// A structured T6 rectangle counts two triangles per cell, every node of the
/// (2 nx + 1) x (2 ny + 1) grid (the diagonals' mid-sides are the cells' centres) and 3 Gauss
/// points per triangle (`reduced`) or 6 (`full`); the counts from the keys equal the built
/// mesh's (exact: integers), and the key `mesh.element = "t6"` is named with the points.
#[test]
fn a_t6_rectangle_counts_three_points_per_triangle() {
    let hex = "packing = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }";
    let base = quick(2, hex);
    let text = std::fs::read_to_string(fixtures::dir().join("../../examples/quick.toml"))
        .unwrap()
        .replace("element = \"q8\"", "element = \"t6\"");
    let t6 = job(&text);
    let counts = MeshCounts::of_job(&t6).unwrap();
    assert_eq!((counts.elements(), counts.nodes, counts.by_kind), (8.0, 25.0, [0.0, 0.0, 8.0]));
    assert_eq!(counts, MeshCounts::of_mesh(&t6.build_mesh().unwrap()));
    let e = of(&t6);
    assert_eq!(e.gauss_points, 24.0);
    assert_eq!(of(&base).gauss_points, 16.0);
    let dem = e.parts.iter().find(|p| p.name == "DEM assemblies").unwrap();
    assert!(dem.keys.iter().any(|k| k == "mesh.element = \"t6\""), "{dem:?}");
    let full = job(&text.replace("integration = \"reduced\"", "integration = \"full\""));
    assert_eq!(of(&full).gauss_points, 48.0);
}
