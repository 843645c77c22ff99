//! VTK XML output: every file parses as well-formed XML with the structure ParaView reads,
//! and every number reads back bit for bit.

mod io_support;

use cosdem_app::output::pieces::{gauss_point_piece, nodal_piece, particle_piece};
use cosdem_app::output::vtk::{CellType, DataArray, VtuPiece, write_vtu};
use cosdem_app::output::{OutputError, equivalent_strain};
use cosdem_fem::gmsh::read_msh;
use io_support::{Element, data, parse, scratch};

fn read_vtu(path: &std::path::Path) -> Element {
    let text = std::fs::read_to_string(path).unwrap();
    let root = parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(root.name, "VTKFile");
    assert_eq!(root.attr("type"), Some("UnstructuredGrid"));
    root
}

fn grid_piece(root: &Element) -> &Element {
    root.child("UnstructuredGrid").child("Piece")
}

/// Checks the cell arrays against the piece and returns (connectivity per cell, types).
fn cells(p: &Element) -> (Vec<Vec<usize>>, Vec<u8>) {
    let c = p.child("Cells");
    let conn: Vec<usize> = c.array("connectivity").numbers().iter().map(|&x| x as usize).collect();
    let offsets: Vec<usize> = c.array("offsets").numbers().iter().map(|&x| x as usize).collect();
    let types: Vec<u8> = c.array("types").numbers().iter().map(|&x| x as u8).collect();
    let n_cells: usize = p.attr("NumberOfCells").unwrap().parse().unwrap();
    assert_eq!(offsets.len(), n_cells);
    assert_eq!(types.len(), n_cells);
    assert_eq!(offsets.last().copied().unwrap_or(0), conn.len());
    let mut start = 0;
    let mut out = Vec::new();
    for &end in &offsets {
        out.push(conn[start..end].to_vec());
        start = end;
    }
    (out, types)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn mesh_with_nodal_solution() {
    let mesh = read_msh(&data("square_q8_v22.msh")).unwrap();
    let elements: Vec<Vec<usize>> = mesh.elements.iter().map(|e| e.nodes.clone()).collect();
    // A displacement field with awkward numbers.
    let dofs: Vec<[f64; 3]> = mesh
        .nodes
        .iter()
        .map(|p| [1e-3 * p[0] / 3.0, -2.5e-7 * p[1], (p[0] * p[1]).sin() * 1e-20])
        .collect();
    let dir = scratch("vtk-mesh");
    let path = dir.join("mesh_0001.vtu");
    let mut piece = nodal_piece(&path, &mesh.nodes, &elements, &dofs).unwrap();
    piece.time = Some(0.125);
    write_vtu(&path, &piece).unwrap();

    let root = read_vtu(&path);
    let time = root.child("UnstructuredGrid").child("FieldData").array("TimeValue");
    assert_eq!(time.numbers(), [0.125]);
    let p = grid_piece(&root);
    assert_eq!(p.attr("NumberOfPoints"), Some("21"));
    assert_eq!(p.attr("NumberOfCells"), Some("4"));
    let (conn, types) = cells(p);
    assert_eq!(conn, elements);
    assert_eq!(types, [23; 4]);
    let points = p.child("Points").child("DataArray");
    assert_eq!(points.attr("NumberOfComponents"), Some("3"));
    let expected: Vec<f64> = mesh.nodes.iter().flat_map(|q| [q[0], q[1], 0.0]).collect();
    assert_eq!(bits(&points.numbers()), bits(&expected));
    let pd = p.child("PointData");
    let disp = pd.array("displacement");
    assert_eq!(disp.attr("NumberOfComponents"), Some("3"));
    assert_eq!(disp.attr("type"), Some("Float64"));
    let expected: Vec<f64> = dofs.iter().flat_map(|d| [d[0], d[1], 0.0]).collect();
    assert_eq!(bits(&disp.numbers()), bits(&expected));
    let rot: Vec<f64> = dofs.iter().map(|d| d[2]).collect();
    assert_eq!(bits(&pd.array("rotation").numbers()), bits(&rot));
    // No temporary files are left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

#[test]
fn nine_node_mesh_uses_biquadratic_quads() {
    let mesh = read_msh(&data("square_q9_v41.msh")).unwrap();
    let elements: Vec<Vec<usize>> = mesh.elements.iter().map(|e| e.nodes.clone()).collect();
    let dofs = vec![[0.0; 3]; mesh.nodes.len()];
    let dir = scratch("vtk-q9");
    let path = dir.join("q9.vtu");
    write_vtu(&path, &nodal_piece(&path, &mesh.nodes, &elements, &dofs).unwrap()).unwrap();
    let root = read_vtu(&path);
    let (conn, types) = cells(grid_piece(&root));
    assert_eq!(types, [28; 6]);
    assert_eq!(conn, elements);
    let bad = nodal_piece(&path, &mesh.nodes, &[vec![0, 1, 2, 3, 4]], &dofs).unwrap_err();
    assert!(bad.to_string().contains("element 0 has 5 nodes"), "{bad}");
}

/// Two 6-node triangles of a unit square (corners 0-2-8 and 0-8-6 of a 3 x 3 grid, mid-sides
/// 0-1, 1-2, 2-0 after the corners, Gmsh's order and VTK's): written as
/// `VTK_QUADRATIC_TRIANGLE` (22) with the node lists as given, ASCII and zlib alike, and read
/// back by the crate's own reader with the same cells.
#[test]
fn six_node_triangles_are_quadratic_triangles() {
    use cosdem_app::output::vtk::{Encoding, write_vtu_encoded};
    let nodes: Vec<[f64; 2]> =
        (0..9).map(|i| [0.5 * (i % 3) as f64, 0.5 * (i / 3) as f64]).collect();
    let elements = vec![vec![0, 2, 8, 1, 5, 4], vec![0, 8, 6, 4, 7, 3]];
    let dofs: Vec<[f64; 3]> = nodes.iter().map(|p| [0.0, -1e-3 * p[1], 0.0]).collect();
    let dir = scratch("vtk-t6");
    for (name, encoding) in [("t6.vtu", Encoding::Ascii), ("t6z.vtu", Encoding::Zlib)] {
        let path = dir.join(name);
        let piece = nodal_piece(&path, &nodes, &elements, &dofs).unwrap();
        write_vtu_encoded(&path, &piece, encoding).unwrap();
        let back = cosdem_app::output::vtu_read::read_vtu(&path).unwrap();
        assert_eq!(back.cells, piece.cells, "{name}");
        assert!(back.cells.iter().all(|c| c.cell_type == CellType::QuadraticTriangle));
        if encoding == Encoding::Ascii {
            let (conn, types) = cells(grid_piece(&read_vtu(&path)));
            assert_eq!(types, [22, 22]);
            assert_eq!(conn, elements);
        }
    }
}

#[test]
fn gauss_point_cloud() {
    let positions: Vec<[f64; 2]> =
        (0..16).map(|i| [0.1 * (i % 4) as f64, 0.3 * (i / 4) as f64]).collect();
    let strain: Vec<[f64; 6]> =
        (0..16).map(|i| [1e-3, -2e-3, 3e-4 * i as f64, 1e-4, 0.5, -0.25]).collect();
    let stress: Vec<[f64; 6]> =
        (0..16).map(|i| [-1e5, -2e5 - i as f64, 3e3, 2.9e3, 1.0 / 7.0, 12.0]).collect();
    let lc = 0.01;
    let dir = scratch("vtk-gauss");
    let path = dir.join("gauss_0003.vtu");
    write_vtu(&path, &gauss_point_piece(&positions, &strain, &stress, lc)).unwrap();

    let root = read_vtu(&path);
    let p = grid_piece(&root);
    assert_eq!(p.attr("NumberOfPoints"), Some("16"));
    let (conn, types) = cells(p);
    assert_eq!(types, [1; 16]);
    assert_eq!(conn, (0..16).map(|i| vec![i]).collect::<Vec<_>>());
    let pd = p.child("PointData");
    let s = pd.array("stress");
    assert_eq!(s.attr("NumberOfComponents"), Some("4"));
    assert_eq!(
        [
            s.attr("ComponentName0"),
            s.attr("ComponentName1"),
            s.attr("ComponentName2"),
            s.attr("ComponentName3")
        ],
        [Some("xx"), Some("yy"), Some("xy"), Some("yx")]
    );
    let expected: Vec<f64> = stress.iter().flat_map(|x| [x[0], x[1], x[2], x[3]]).collect();
    assert_eq!(bits(&s.numbers()), bits(&expected));
    let m = pd.array("couple_stress");
    assert_eq!(m.attr("NumberOfComponents"), Some("2"));
    let expected: Vec<f64> = stress.iter().flat_map(|x| [x[4], x[5]]).collect();
    assert_eq!(bits(&m.numbers()), bits(&expected));
    let e = pd.array("strain").numbers();
    assert_eq!(e.len(), 64);
    assert_eq!(pd.array("curvature").numbers()[..2], [0.5, -0.25]);
    let q = pd.array("equivalent_strain").numbers();
    let expected: Vec<f64> = strain.iter().map(|e| equivalent_strain(e, lc)).collect();
    assert_eq!(bits(&q), bits(&expected));
}

#[test]
fn particle_snapshot_with_force_chains() {
    let centres = [[0.0, 0.0], [0.01, 0.0], [0.005, 0.0087], [0.02, 0.02]];
    let radius = [0.005, 0.005, 0.005, 0.006];
    let rotation = [0.0, 1e-3, -2e-3, 0.5];
    let fluct = [[1e-6, 0.0], [0.0, -1e-6], [3e-7, 3e-7], [0.0, 0.0]];
    let contacts = [(0, 1, 12.5), (1, 2, 3.25), (0, 2, 1e-9)];
    let dir = scratch("vtk-particles");
    let path = dir.join("assembly_gp7_0010.vtu");
    write_vtu(&path, &particle_piece(&centres, &radius, &rotation, &fluct, &contacts)).unwrap();

    let root = read_vtu(&path);
    let p = grid_piece(&root);
    assert_eq!(p.attr("NumberOfPoints"), Some("4"));
    assert_eq!(p.attr("NumberOfCells"), Some("7"));
    let (conn, types) = cells(p);
    assert_eq!(types, [1, 1, 1, 1, 3, 3, 3]);
    assert_eq!(conn[4..], [vec![0, 1], vec![1, 2], vec![0, 2]]);
    let pd = p.child("PointData");
    assert_eq!(pd.array("radius").numbers(), radius);
    assert_eq!(pd.array("rotation").numbers(), rotation);
    assert_eq!(pd.array("fluctuation").attr("NumberOfComponents"), Some("3"));
    assert_eq!(pd.array("fluctuation").numbers()[6..9], [3e-7, 3e-7, 0.0]);
    let f = p.child("CellData").array("normal_force").numbers();
    assert_eq!(f, [0.0, 0.0, 0.0, 0.0, 12.5, 3.25, 1e-9]);
}

#[test]
fn generic_piece_escapes_names_and_handles_empty_data() {
    let dir = scratch("vtk-generic");
    let path = dir.join("generic.vtu");
    let mut piece = VtuPiece::from_points_2d(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
    piece.push_cell(CellType::Triangle, vec![0, 1, 2]);
    piece.add_cell_data(DataArray::scalars("a<b & \"c\"", vec![f64::MIN_POSITIVE]));
    piece.add_point_data(
        DataArray::from_tuples("pair", &[[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
            .with_component_names(&["first", "<second>"]),
    );
    write_vtu(&path, &piece).unwrap();
    let root = read_vtu(&path);
    let p = grid_piece(&root);
    let a = p.child("CellData").array("a<b & \"c\"");
    assert_eq!(a.numbers(), [f64::MIN_POSITIVE]);
    assert_eq!(p.child("PointData").array("pair").attr("ComponentName1"), Some("<second>"));

    let empty = dir.join("empty.vtu");
    write_vtu(&empty, &VtuPiece::default()).unwrap();
    let root = read_vtu(&empty);
    assert_eq!(grid_piece(&root).attr("NumberOfPoints"), Some("0"));
}

#[test]
fn invalid_pieces_are_rejected_and_nothing_is_written() {
    let dir = scratch("vtk-invalid");
    let path = dir.join("bad.vtu");
    let base = VtuPiece::point_cloud_2d(&[[0.0, 0.0], [1.0, 0.0]]);

    let mut p = base.clone();
    p.add_point_data(DataArray::scalars("short", vec![1.0]));
    let err = write_vtu(&path, &p).unwrap_err();
    assert!(matches!(err, OutputError::InvalidData { .. }));
    let msg = err.to_string();
    assert!(
        msg.contains("bad.vtu") && msg.contains("\"short\"") && msg.contains("expected 2"),
        "{msg}"
    );

    let mut p = base.clone();
    p.add_cell_data(DataArray::scalars("f", vec![1.0, f64::NAN]));
    let err = write_vtu(&path, &p).unwrap_err();
    assert!(
        matches!(err, OutputError::NonFinite { index: 1, ref array, .. } if array == "f"),
        "{err}"
    );

    let mut p = base.clone();
    p.push_cell(CellType::Line, vec![0, 5]);
    let msg = write_vtu(&path, &p).unwrap_err().to_string();
    assert!(msg.contains("cell 2 refers to point 5"), "{msg}");

    let mut p = base.clone();
    p.push_cell(CellType::QuadraticQuad, vec![0, 1, 0, 1]);
    let msg = write_vtu(&path, &p).unwrap_err().to_string();
    assert!(msg.contains("has 4 nodes, expected 8"), "{msg}");

    let mut p = base.clone();
    p.add_point_data(DataArray::scalars("x", vec![1.0, 2.0]));
    p.add_point_data(DataArray::scalars("x", vec![1.0, 2.0]));
    let msg = write_vtu(&path, &p).unwrap_err().to_string();
    assert!(msg.contains("two point arrays are named \"x\""), "{msg}");

    let mut p = base.clone();
    p.points[1][2] = f64::INFINITY;
    assert!(matches!(write_vtu(&path, &p).unwrap_err(), OutputError::NonFinite { .. }));

    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing may be written");
}

#[test]
fn base64_encoding_reads_back_exactly() {
    use cosdem_app::output::vtk::{Encoding, write_vtu_encoded};
    use io_support::binary_array;
    let mesh = read_msh(&data("plate_hole_q8_v41_bin.msh")).unwrap();
    let elements: Vec<Vec<usize>> = mesh.elements.iter().map(|e| e.nodes.clone()).collect();
    let dofs: Vec<[f64; 3]> =
        mesh.nodes.iter().map(|p| [p[0].sin() * 1e-3, -p[1] / 7.0, f64::MIN_POSITIVE]).collect();
    let dir = scratch("vtk-base64");
    let path = dir.join("plate.vtu");
    let mut piece = nodal_piece(&path, &mesh.nodes, &elements, &dofs).unwrap();
    piece.time = Some(1.0 / 3.0);
    write_vtu_encoded(&path, &piece, Encoding::Base64).unwrap();
    let ascii = piece.to_xml(&path).unwrap();
    let binary = std::fs::read_to_string(&path).unwrap();
    assert!(binary.len() < ascii.len());

    let root = read_vtu(&path);
    let f64s = |a: &Element| -> Vec<f64> {
        binary_array(a, 8).iter().map(|b| f64::from_le_bytes(b[..].try_into().unwrap())).collect()
    };
    let i64s = |a: &Element| -> Vec<i64> {
        binary_array(a, 8).iter().map(|b| i64::from_le_bytes(b[..].try_into().unwrap())).collect()
    };
    let time = root.child("UnstructuredGrid").child("FieldData").array("TimeValue");
    assert_eq!(f64s(time), [1.0 / 3.0]);
    let p = grid_piece(&root);
    let points: Vec<f64> = mesh.nodes.iter().flat_map(|q| [q[0], q[1], 0.0]).collect();
    assert_eq!(bits(&f64s(p.child("Points").child("DataArray"))), bits(&points));
    let disp: Vec<f64> = dofs.iter().flat_map(|d| [d[0], d[1], 0.0]).collect();
    assert_eq!(bits(&f64s(p.child("PointData").array("displacement"))), bits(&disp));
    let conn: Vec<i64> = elements.iter().flatten().map(|&n| n as i64).collect();
    assert_eq!(i64s(p.child("Cells").array("connectivity")), conn);
    let offsets: Vec<i64> = (1..=elements.len() as i64).map(|k| 8 * k).collect();
    assert_eq!(i64s(p.child("Cells").array("offsets")), offsets);
    let types = binary_array(p.child("Cells").array("types"), 1);
    assert!(types.iter().all(|t| t == &[23]));
    assert_eq!(types.len(), elements.len());
}
