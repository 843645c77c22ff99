//! A job on a Gmsh mesh mixing quadrilaterals and triangles (the FE core's
//! `plate_hole_mixed_v41.msh`: a 1 x 1 m plate with a hole, 14 Q8 and 10 T6 elements) runs end
//! to end through [`Run`], and every output takes each element as what it is: the mesh `.vtu`
//! holds type-23 and type-22 cells with the mesh's connectivity and a nodal stress, the
//! Gauss-point `.vtu` 4 points per quadrilateral and 3 per triangle (as many as the admission
//! estimate counted), the field data those counts and the strain-field figure is drawn; a
//! snapshot request is checked against the element's own points.

use cosdem_app::output::field_data::FieldData;
use cosdem_app::output::plot::plot_run;
use cosdem_app::output::vtk::CellType;
use cosdem_app::output::vtu_read::read_vtu;
use cosdem_app::run::{Ending, Run};
use cosdem_fem::element::ElementKind;
use cosdem_job::admission::{MeshCounts, estimate};
use cosdem_job::{Job, fixtures};
use std::path::{Path, PathBuf};

/// The `gmsh-square` fixture (elastic, rough platens, 2 mm in 2 steps, 50 kPa on the left
/// edge) on the mixed plate, with `extra` appended.
fn plate(extra: &str) -> Job {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fem/tests/data/plate_hole_mixed_v41.msh")
        .canonicalize()
        .unwrap();
    let text = fixtures::text("gmsh-square").replace(
        "file = \"../../master/fem/tests/data/square_q8_v22.msh\"",
        &format!("file = {:?}", file.display().to_string()),
    );
    assert!(text.contains("plate_hole_mixed"), "the fixture changed");
    Job::from_toml(&format!("{text}\n{extra}"), "mixed.toml").unwrap()
}

fn run(job: &Job, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mixed_run").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let outcome = Run::new(job, &dir).snapshots(true).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    dir
}

/// The outputs of the mixed run. Exact comparisons: integers and copied coordinates.
#[test]
fn a_mixed_run_writes_each_element_as_its_kind() {
    let job = plate("[output]\nfield_plots_at = [0.001]\n");
    let dir = run(&job, "outputs");
    let mesh = job.build_mesh().unwrap();
    let kinds = &mesh.kinds;
    let triangles = kinds.iter().filter(|k| k.is_triangle()).count();
    assert_eq!((kinds.len(), triangles), (24, 10));

    let piece = read_vtu(&dir.join("vtk/mesh_00002.vtu")).unwrap();
    let cell_types: Vec<CellType> = piece.cells.iter().map(|c| c.cell_type).collect();
    let expected: Vec<CellType> = kinds
        .iter()
        .map(|k| match k {
            ElementKind::T6 => CellType::QuadraticTriangle,
            _ => CellType::QuadraticQuad,
        })
        .collect();
    assert_eq!(cell_types, expected);
    let conn: Vec<usize> = piece.cells.iter().flat_map(|c| c.nodes.clone()).collect();
    assert_eq!(conn, mesh.connectivity);
    let stress = piece.point_array("stress").expect("nodal stress");
    assert_eq!(stress.values.len(), 4 * mesh.n_nodes());
    assert!(stress.values.iter().all(|v| v.is_finite()));

    let gauss = read_vtu(&dir.join("vtk/gauss_00002.vtu")).unwrap();
    let counts: Vec<usize> = kinds.iter().map(|k| if k.is_triangle() { 3 } else { 4 }).collect();
    let total: usize = counts.iter().sum();
    assert_eq!(gauss.points.len(), total);
    assert_eq!(total, 14 * 4 + 10 * 3);
    let counted = estimate(&job, MeshCounts::of_mesh(&mesh)).gauss_points;
    assert_eq!(counted, total as f64, "the admission estimate");
    let ids = |name: &str| -> Vec<u32> {
        gauss.point_array(name).unwrap().values.iter().map(|&v| v as u32).collect()
    };
    let elements: Vec<u32> =
        counts.iter().enumerate().flat_map(|(e, &n)| vec![e as u32; n]).collect();
    let points: Vec<u32> = counts.iter().flat_map(|&n| 0..n as u32).collect();
    assert_eq!(ids("element_id"), elements);
    assert_eq!(ids("gauss_point_id"), points);

    let field = FieldData::read(&dir.join("fields/field_00001.json")).unwrap();
    assert_eq!(field.gauss_points, counts);
    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for name in ["equivalent_strain_00001.png", "equivalent_strain_00001.svg"] {
        assert!(dir.join("plots").join(name).is_file(), "{name} missing");
    }
}

/// A snapshot request is checked against the element it names: point 3 of a quadrilateral is
/// taken, point 3 of a triangle refused naming the key and that element's points (0..3).
#[test]
fn snapshot_points_are_checked_per_element() {
    let mesh = plate("").build_mesh().unwrap();
    let quad = mesh.kinds.iter().position(|k| !k.is_triangle()).unwrap();
    let tri = mesh.kinds.iter().position(|k| k.is_triangle()).unwrap();
    let job = plate(&format!("[output]\nsnapshots = [[{quad}, 3]]\nvtk_every = 0\n"));
    run(&job, "snapshot-ok");
    let job = plate(&format!("[output]\nsnapshots = [[{tri}, 3]]\n"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mixed_run/snapshot-refused");
    let _ = std::fs::remove_dir_all(&dir);
    let e = Run::new(&job, &dir).snapshots(true).execute().expect_err("point 3").to_string();
    assert!(e.contains("output.snapshots") && e.contains(&format!("[{tri}, 3]")), "{e}");
    assert!(e.contains(&format!("element {tri} has points 0..3")), "{e}");
}
