//! The pieces cosdem writes, built from the FE and DEM data on top of the format of
//! [`super::vtk`]: the mesh with the nodal solution, the Gauss points with their state and
//! micro descriptors, and a DEM snapshot's discs and contacts.

use super::vtk::{CellType, DataArray, VtuPiece};
use super::{Result, invalid};
use cosdem_fem::solve::GaussPointState;
use std::path::Path;

/// The mesh with the nodal solution: one cell per element (8 nodes: `VTK_QUADRATIC_QUAD`,
/// 9 nodes: `VTK_BIQUADRATIC_QUAD`, 6 nodes: `VTK_QUADRATIC_TRIANGLE`, 4 nodes: `VTK_QUAD`,
/// 3 nodes: `VTK_TRIANGLE`; VTK's node order for these is Gmsh's), point arrays
/// `displacement` (u_x, u_y, 0) and `rotation` (w) from `dofs[node] = [u_x, u_y, w]`.
///
/// Errors name the first element whose node count is not 3, 4, 6, 8 or 9; `path` only names
/// the file in errors. Array lengths are checked when the piece is written.
pub fn nodal_piece(
    path: &Path,
    nodes: &[[f64; 2]],
    elements: &[Vec<usize>],
    dofs: &[[f64; 3]],
) -> Result<VtuPiece> {
    let mut piece = VtuPiece::from_points_2d(nodes);
    for (i, e) in elements.iter().enumerate() {
        let cell_type = CellType::element_with_nodes(e.len()).ok_or_else(|| {
            invalid(path, format!("element {i} has {} nodes; expected 3, 4, 6, 8 or 9", e.len()))
        })?;
        piece.push_cell(cell_type, e.clone());
    }
    let u: Vec<[f64; 2]> = dofs.iter().map(|d| [d[0], d[1]]).collect();
    piece.add_point_data(DataArray::vectors_2d("displacement", &u));
    piece.add_point_data(DataArray::scalars("rotation", dofs.iter().map(|d| d[2]).collect()));
    Ok(piece)
}

/// The Gauss points as a point cloud (`VTK_VERTEX` cells) with their state, from
/// `strain = [e_xx, e_yy, e_xy, e_yx, k_x, k_y]` and `stress = [s_xx, s_yy, s_xy, s_yx, m_x,
/// m_y]` (THEORY section 1) and the internal length `lc` of Eq. 34. Point arrays: `strain`
/// (xx, yy, xy, yx), `curvature` (k_x, k_y), `stress` (xx, yy, xy, yx), `couple_stress`
/// (m_x, m_y), `equivalent_strain` (Eq. 34, [`super::equivalent_strain`]).
pub fn gauss_point_piece(
    positions: &[[f64; 2]],
    strain: &[[f64; 6]],
    stress: &[[f64; 6]],
    lc: f64,
) -> VtuPiece {
    let mut piece = VtuPiece::point_cloud_2d(positions);
    let four = |v: &[[f64; 6]]| v.iter().flat_map(|x| [x[0], x[1], x[2], x[3]]).collect();
    let two = |v: &[[f64; 6]]| v.iter().flat_map(|x| [x[4], x[5]]).collect();
    let tensor = ["xx", "yy", "xy", "yx"];
    piece.add_point_data(DataArray::new("strain", 4, four(strain)).with_component_names(&tensor));
    piece.add_point_data(
        DataArray::new("curvature", 2, two(strain)).with_component_names(&["x", "y"]),
    );
    piece.add_point_data(DataArray::new("stress", 4, four(stress)).with_component_names(&tensor));
    piece.add_point_data(
        DataArray::new("couple_stress", 2, two(stress)).with_component_names(&["x", "y"]),
    );
    piece.add_point_data(DataArray::scalars(
        "equivalent_strain",
        strain.iter().map(|e| super::equivalent_strain(e, lc)).collect(),
    ));
    piece
}

/// A DEM snapshot: one `VTK_VERTEX` per disc (cells `0..n`), then one `VTK_LINE` per contact
/// `(i, j, normal_force)` (cells `n..`). Point arrays `radius`, `rotation` and `fluctuation`
/// (the displacement fluctuation, 3 components with z = 0); the cell array `normal_force` is
/// 0 on the vertex cells. In ParaView, show the points as "Point Gaussian" scaled by `radius`
/// and threshold `normal_force` for force chains.
pub fn particle_piece(
    centres: &[[f64; 2]],
    radius: &[f64],
    rotation: &[f64],
    fluctuation: &[[f64; 2]],
    contacts: &[(usize, usize, f64)],
) -> VtuPiece {
    let mut piece = VtuPiece::point_cloud_2d(centres);
    piece.add_point_data(DataArray::scalars("radius", radius.to_vec()));
    piece.add_point_data(DataArray::scalars("rotation", rotation.to_vec()));
    piece.add_point_data(DataArray::vectors_2d("fluctuation", fluctuation));
    let mut force = vec![0.0; centres.len()];
    for &(i, j, f) in contacts {
        piece.push_cell(CellType::Line, vec![i, j]);
        force.push(f);
    }
    piece.add_cell_data(DataArray::scalars("normal_force", force));
    piece
}

/// The Gauss points of a converged state as `vtk/gauss_NNNNN.vtu` holds them (its timestep
/// aside): [`gauss_point_piece`] of their positions, strains and stresses, their micro
/// descriptors ([`add_micro_descriptors`]), and the scalars `element_id` and `gauss_point_id`.
pub fn gauss_state_piece(gauss_points: &[GaussPointState], lc: f64) -> VtuPiece {
    let positions: Vec<[f64; 2]> = gauss_points.iter().map(|g| g.position).collect();
    let strain: Vec<[f64; 6]> = gauss_points.iter().map(|g| g.strain).collect();
    let stress: Vec<[f64; 6]> = gauss_points.iter().map(|g| g.stress).collect();
    let mut piece = gauss_point_piece(&positions, &strain, &stress, lc);
    add_micro_descriptors(&mut piece, gauss_points.iter().map(|g| g.diagnostics.descriptors));
    let elements: Vec<u32> = gauss_points.iter().map(|g| g.id.element).collect();
    let points: Vec<u32> = gauss_points.iter().map(|g| g.id.point).collect();
    piece.add_point_data(DataArray::ids("element_id", &elements));
    piece.add_point_data(DataArray::ids("gauss_point_id", &points));
    piece
}

/// Adds the micro descriptors of the Gauss points of `piece` ([`gauss_point_piece`], one
/// entry per point, in its order) as point arrays: `porosity`, `void_ratio`, `coordination`,
/// `mechanical_coordination`, `fabric` (xx, yy, xy: `F = (1/N_c) sum n n`),
/// `fabric_anisotropy` (`2 (f_1 - f_2) / (f_1 + f_2)`), `fabric_direction` (rad from x),
/// `sliding_fraction` and `mean_rotation` (rad). Added only when every point carries
/// descriptors (a DEM material): analytical materials have none, and a `.vtu` holds no NaN.
pub fn add_micro_descriptors(
    piece: &mut VtuPiece,
    descriptors: impl IntoIterator<Item = Option<cosdem_common::MicroDescriptors>>,
) {
    let Some(d) = descriptors.into_iter().collect::<Option<Vec<_>>>() else { return };
    if d.is_empty() {
        return;
    }
    let scalar = |name: &str, f: fn(&cosdem_common::MicroDescriptors) -> f64| {
        DataArray::scalars(name, d.iter().map(f).collect())
    };
    piece.add_point_data(scalar("porosity", |d| d.porosity));
    piece.add_point_data(scalar("void_ratio", |d| d.void_ratio));
    piece.add_point_data(scalar("coordination", |d| d.coordination));
    piece.add_point_data(scalar("mechanical_coordination", |d| d.mechanical_coordination));
    let fabric: Vec<[f64; 3]> = d.iter().map(|d| [d.fabric_xx, d.fabric_yy, d.fabric_xy]).collect();
    piece.add_point_data(
        DataArray::from_tuples("fabric", &fabric).with_component_names(&["xx", "yy", "xy"]),
    );
    piece.add_point_data(scalar("fabric_anisotropy", |d| d.anisotropy));
    piece.add_point_data(scalar("fabric_direction", |d| d.fabric_direction));
    piece.add_point_data(scalar("sliding_fraction", |d| d.sliding_fraction));
    piece.add_point_data(scalar("mean_rotation", |d| d.mean_rotation));
}
