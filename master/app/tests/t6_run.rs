//! A job of 6-node triangles (`[mesh] element = "t6"`) runs end to end through
//! [`Run`], and every output knows its elements are triangles: the curve agrees with the same
//! job on Q8, the mesh `.vtu` holds `VTK_QUADRATIC_TRIANGLE` cells (type 22) with the mesh's
//! own connectivity and a nodal stress, the Gauss-point `.vtu` holds 3 points per triangle
//! (as many as the admission estimate counted), the `.pvd` series list them, the field data
//! and the strain-field figure are written, and a snapshot request is checked against the
//! triangles' 3 points.

use cosdem_app::output::field_data::FieldData;
use cosdem_app::output::plot::plot_run;
use cosdem_app::output::read_pvd;
use cosdem_app::output::vtk::CellType;
use cosdem_app::output::vtu_read::read_vtu;
use cosdem_app::run::{Ending, Run};
use cosdem_job::admission::{MeshCounts, estimate};
use cosdem_job::{Job, fixtures};
use std::path::{Path, PathBuf};

/// The elastic panel (1 x 1 m, G = 10 MPa, nu = 0.3, 1 cm in 4 steps) on 4 x 4 cells of
/// `element`, between `platens` platens, with `extra` appended to the job file.
fn panel(element: &str, platens: &str, extra: &str) -> Job {
    panel_of(4, element, platens, extra)
}

/// [`panel`] on `n` x `n` cells.
fn panel_of(n: usize, element: &str, platens: &str, extra: &str) -> Job {
    let text = fixtures::text("elastic-panel")
        .replace("nx = 2\nny = 2\n", &format!("nx = {n}\nny = {n}\nelement = \"{element}\"\n"))
        .replace(
            "displacement = 0.01\n",
            &format!("displacement = 0.01\nplatens = \"{platens}\"\n"),
        );
    assert!(text.contains("element = ") && text.contains("platens = "), "the fixture changed");
    Job::from_toml(&format!("{text}\n{extra}"), "t6.toml").unwrap()
}

fn run(job: &Job, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("t6_run").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let outcome = Run::new(job, &dir).snapshots(true).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    dir
}

/// The load of every row of `curve.csv`.
fn loads(dir: &Path) -> Vec<f64> {
    let csv = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    csv.lines().skip(1).map(|l| l.split(',').nth(3).unwrap().parse().unwrap()).collect()
}

/// The load at the last step of T6 against Q8 on the same cells (relative difference).
///
/// Smooth platens compress the panel homogeneously: both elements represent the uniform
/// strain exactly (the patch test), so the loads agree to the linear solver's rounding
/// (tolerance 1e-9 relative; measured 8e-16).
///
/// Rough platens hold the loaded edges, and the corners where they meet the free sides are
/// stress singularities that each discretisation resolves its own way. Both converge to the
/// same continuum: on 4 x 4 cells the loads must differ by less than the Q8 load's own
/// discretisation error, estimated by its change from 4 x 4 to 8 x 8 cells (and less than
/// 2 %), and on 8 x 8 cells by less than on 4 x 4. Measured (last-step loads, N): Q8
/// 3.01993e5, 3.01151e5, 3.00811e5 and T6 3.02202e5, 3.01213e5, 3.00836e5 on 4, 8 and 16
/// cells a side: T6 - Q8 = 6.9e-4, 2.1e-4, 8.4e-5 relative, against the Q8 change of 2.8e-3
/// from 4 to 8 cells.
#[test]
fn a_t6_compression_agrees_with_q8() {
    let last = |n: usize, element: &str, platens: &str| {
        let job = panel_of(n, element, platens, "[output]\nvtk_every = 0\n");
        let l = loads(&run(&job, &format!("{element}-{platens}-{n}")));
        assert_eq!(l.len(), 4);
        l[3]
    };
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    let (t6, q8) = (last(4, "t6", "smooth"), last(4, "q8", "smooth"));
    assert!(t6 > 0.0 && rel(t6, q8) <= 1e-9, "smooth: T6 {t6} N, Q8 {q8} N");

    let (t6, q8) = (last(4, "t6", "rough"), last(4, "q8", "rough"));
    let (t6_fine, q8_fine) = (last(8, "t6", "rough"), last(8, "q8", "rough"));
    let (coarse, fine, q8_error) = (rel(t6, q8), rel(t6_fine, q8_fine), rel(q8, q8_fine));
    eprintln!("rough: T6 - Q8 {coarse:.2e} (4 x 4), {fine:.2e} (8 x 8); Q8 4 -> 8: {q8_error:.2e}");
    assert!(
        coarse < q8_error && coarse < 0.02,
        "4 x 4: T6 {t6} N, Q8 {q8} N, Q8 8 x 8 {q8_fine} N"
    );
    assert!(fine < coarse, "8 x 8: T6 {t6_fine} N, Q8 {q8_fine} N: no closer than on 4 x 4");
}

/// The outputs of the T6 run: cells of type 22 with the mesh's connectivity (Gmsh's node
/// order is VTK's for this type), a nodal stress on every node, 3 Gauss points per triangle
/// numbered 0..3 in every element (the count the admission estimate made from the job's keys),
/// the field data of 3 points per triangle and the strain-field figure (PNG and SVG) drawn
/// from it. Exact comparisons: integers and copied coordinates.
#[test]
fn a_t6_run_writes_triangles_everywhere() {
    let job = panel("t6", "rough", "[output]\nfield_plots_at = [0.005]\n");
    let dir = run(&job, "outputs");
    let mesh = job.build_mesh().unwrap();
    assert_eq!(mesh.n_elements(), 32);

    let piece = read_vtu(&dir.join("vtk/mesh_00004.vtu")).unwrap();
    assert_eq!(piece.cells.len(), 32);
    assert!(piece.cells.iter().all(|c| c.cell_type == CellType::QuadraticTriangle));
    assert_eq!(CellType::QuadraticTriangle.vtk_id(), 22);
    let conn: Vec<usize> = piece.cells.iter().flat_map(|c| c.nodes.clone()).collect();
    assert_eq!(conn, mesh.connectivity);
    let points: Vec<[f64; 2]> = piece.points.iter().map(|p| [p[0], p[1]]).collect();
    assert_eq!(points, mesh.nodes);
    let stress = piece.point_array("stress").expect("nodal stress");
    assert_eq!(stress.values.len(), 4 * mesh.n_nodes());
    // Compression: every node's mean s_yy is negative.
    assert!(stress.values.chunks(4).all(|s| s[1] < 0.0), "a node is not compressed");

    let gauss = read_vtu(&dir.join("vtk/gauss_00004.vtu")).unwrap();
    let counted = estimate(&job, MeshCounts::of_job(&job).unwrap()).gauss_points;
    assert_eq!(gauss.points.len(), 96);
    assert_eq!(counted, 96.0, "the admission estimate");
    let ids = |name: &str| -> Vec<u32> {
        gauss.point_array(name).unwrap().values.iter().map(|&v| v as u32).collect()
    };
    let expected: Vec<u32> = (0..32).flat_map(|e| [e; 3]).collect();
    assert_eq!(ids("element_id"), expected);
    assert_eq!(ids("gauss_point_id"), [0, 1, 2].repeat(32));

    // The series list every step's files, at the displacements 2.5, 5, 7.5 and 10 mm.
    for (pvd, stem) in [("fields.pvd", "mesh"), ("gauss.pvd", "gauss")] {
        let listed: Vec<(f64, String)> =
            read_pvd(&dir.join(pvd)).unwrap().into_iter().map(|d| (d.timestep, d.file)).collect();
        let expected: Vec<(f64, String)> =
            (1..=4).map(|s| (0.0025 * s as f64, format!("vtk/{stem}_{s:05}.vtu"))).collect();
        assert_eq!(listed, expected, "{pvd}");
    }

    let field = FieldData::read(&dir.join("fields/field_00002.json")).unwrap();
    assert_eq!((field.gauss_points.clone(), field.elements.len()), (vec![3; 32], 32));
    assert!(field.elements.iter().all(|e| e.len() == 6));
    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for name in ["equivalent_strain_00002.png", "equivalent_strain_00002.svg"] {
        assert!(dir.join("plots").join(name).is_file(), "{name} missing");
    }
}

/// A snapshot request names a Gauss point of the triangles' 3: point 2 of the last triangle
/// is taken, point 3 is refused naming the key and the mesh's points (0..3).
#[test]
fn snapshot_points_are_checked_against_three_per_triangle() {
    let job = panel("t6", "rough", "[output]\nsnapshots = [[31, 2]]\nvtk_every = 0\n");
    run(&job, "snapshot-ok");
    let job = panel("t6", "rough", "[output]\nsnapshots = [[31, 3]]\n");
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("t6_run/snapshot-refused");
    let _ = std::fs::remove_dir_all(&dir);
    let e = Run::new(&job, &dir).snapshots(true).execute().expect_err("point 3").to_string();
    assert!(e.contains("output.snapshots") && e.contains("[31, 3]"), "{e}");
    assert!(e.contains("points 0..3"), "{e}");
}

/// The smallest two-scale job on triangles: the `dem-one-element` fixture's cell as two T6
/// (6 Gauss points, each a hexagonal DEM assembly of side 0.05 m), with the particle snapshots
/// of point 2 of triangle 1 at both steps: the series lists both, the snapshots hold the
/// same discs, the Gauss-point file carries the micro descriptors of the 6 assemblies, and
/// every figure is drawn (the force chains of the last snapshot among them).
#[test]
fn a_two_scale_t6_job_writes_its_snapshots() {
    let text = fixtures::text("dem-one-element")
        .replace("ny = 1\n", "ny = 1\nelement = \"t6\"\n")
        .replace("side = 0.1", "side = 0.05");
    let text = format!("{text}\n[output]\nsnapshots = [[1, 2]]\n");
    let job = Job::from_toml(&text, "t6-dem.toml").unwrap();
    let dir = run(&job, "dem");
    let listed: Vec<String> =
        read_pvd(&dir.join("snapshots/e1_p2.pvd")).unwrap().into_iter().map(|d| d.file).collect();
    assert_eq!(listed, ["e1_p2/snap_00001.vtu", "e1_p2/snap_00002.vtu"]);
    let discs = |step: u32| {
        let path = dir.join(format!("snapshots/e1_p2/snap_{step:05}.vtu"));
        read_vtu(&path).unwrap().points.len()
    };
    assert!(discs(1) > 0 && discs(1) == discs(2), "{} and {} discs", discs(1), discs(2));
    let gauss = read_vtu(&dir.join("vtk/gauss_00002.vtu")).unwrap();
    assert_eq!(gauss.points.len(), 6);
    assert_eq!(gauss.point_array("porosity").map(|a| a.values.len()), Some(6));
    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    assert!(dir.join("plots/force_chains_e1_p2_00002.png").is_file());
}
