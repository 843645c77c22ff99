//! Gauss-point values carried to the mesh's nodes, for the nodal `stress` of the mesh `.vtu`.

/// The nodal average of Gauss-point values `gauss` (point `g` of element `owner[g]`) over a
/// mesh of `n_nodes` nodes and the node lists `elements`.
///
/// The rule: each element's value is the mean of its Gauss points' values; a node's value is
/// the mean of the values of the elements that contain it (each element counted once, however
/// many times it lists the node). A node in no element, or only in elements without points,
/// gets zeros. The result is exact for a uniform field and bounded by the Gauss-point extremes
/// everywhere (no extrapolation, so no overshoot at the boundary; a gradient is smoothed over
/// one element). It holds for any rule and element family alike, mixed or not: 4 or 9 points
/// of a quadrilateral, 3 or 6 of a triangle.
///
/// # Panics
/// When `owner` and `gauss` differ in length, an owner is `>= elements.len()` or an element
/// lists a node `>= n_nodes` (the solver's own data: a bug, not an input error).
pub fn nodal_average<const N: usize>(
    n_nodes: usize,
    elements: &[Vec<usize>],
    owner: &[u32],
    gauss: &[[f64; N]],
) -> Vec<[f64; N]> {
    assert_eq!(owner.len(), gauss.len());
    let mut means = vec![[0.0; N]; elements.len()];
    let mut points = vec![0u32; elements.len()];
    for (&e, v) in owner.iter().zip(gauss) {
        for (m, x) in means[e as usize].iter_mut().zip(v) {
            *m += x;
        }
        points[e as usize] += 1;
    }
    let mut sum = vec![[0.0; N]; n_nodes];
    let mut count = vec![0u32; n_nodes];
    for ((nodes, mean), &own) in elements.iter().zip(&mut means).zip(&points) {
        if own == 0 {
            continue;
        }
        mean.iter_mut().for_each(|m| *m /= f64::from(own));
        for (i, &n) in nodes.iter().enumerate() {
            if nodes[..i].contains(&n) {
                continue;
            }
            for (s, m) in sum[n].iter_mut().zip(mean.iter()) {
                *s += m;
            }
            count[n] += 1;
        }
    }
    for (s, &c) in sum.iter_mut().zip(&count) {
        if c > 0 {
            s.iter_mut().for_each(|v| *v /= f64::from(c));
        }
    }
    sum
}

use super::vtk::{DataArray, VtuPiece};
use cosdem_fem::solve::GaussPointState;
/// Adds the point arrays `stress` (xx, yy, xy, yx) and `couple_stress` (x, y) to the mesh
/// piece: the Gauss-point stresses of `gp` averaged to the nodes by
/// [`nodal_average`] (element means, then the mean over the elements
/// sharing a node). Nothing is added when a point names an element past `elements`.
pub fn add_nodal_stress(
    piece: &mut VtuPiece,
    n_nodes: usize,
    elements: &[Vec<usize>],
    gp: &[GaussPointState],
) {
    let owner: Vec<u32> = gp.iter().map(|g| g.id.element).collect();
    if owner.iter().any(|&e| e as usize >= elements.len()) {
        return;
    }
    let stress: Vec<[f64; 6]> = gp.iter().map(|g| g.stress).collect();
    let nodal = super::nodal_stress::nodal_average(n_nodes, elements, &owner, &stress);
    let four: Vec<f64> = nodal.iter().flat_map(|s| [s[0], s[1], s[2], s[3]]).collect();
    let two: Vec<f64> = nodal.iter().flat_map(|s| [s[4], s[5]]).collect();
    piece.add_point_data(
        DataArray::new("stress", 4, four).with_component_names(&["xx", "yy", "xy", "yx"]),
    );
    piece.add_point_data(DataArray::new("couple_stress", 2, two).with_component_names(&["x", "y"]));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two Q4 elements side by side (nodes 0-1-4-3 and 1-2-5-4) and a lone node 6.
    fn two_quads() -> Vec<Vec<usize>> {
        vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]]
    }

    /// A uniform stress field comes out exactly at every node of an element (the mean of
    /// equal values is the value: exact in floating point for the powers of two used), and a
    /// node in no element is zero.
    #[test]
    fn a_uniform_field_is_exact_at_every_node() {
        let s = [1.5, -2.25, 0.5, 0.5, 0.125, -4.0];
        let gauss = vec![s; 8];
        let nodal = nodal_average(7, &two_quads(), &[0, 0, 0, 0, 1, 1, 1, 1], &gauss);
        for (n, v) in nodal.iter().enumerate().take(6) {
            assert_eq!(*v, s, "node {n}");
        }
        assert_eq!(nodal[6], [0.0; 6]);
    }

    /// Element means 1 and 3 (from Gauss values 0, 2 and 2, 4): the shared nodes 1 and 4 get
    /// (1 + 3) / 2 = 2, the others their element's mean.
    #[test]
    fn shared_nodes_average_their_elements() {
        let gauss: Vec<[f64; 1]> =
            [0.0, 2.0, 0.0, 2.0, 2.0, 4.0, 2.0, 4.0].iter().map(|&v| [v]).collect();
        let nodal = nodal_average(6, &two_quads(), &[0, 0, 0, 0, 1, 1, 1, 1], &gauss);
        let got: Vec<f64> = nodal.iter().map(|v| v[0]).collect();
        assert_eq!(got, [1.0, 2.0, 3.0, 1.0, 2.0, 3.0]);
    }

    /// The rule does not depend on the element family: two 6-node triangles of a unit square
    /// (corners 0-2-8 and 0-8-6 of a 3 x 3 grid of nodes, mid-sides in Gmsh order) with 3
    /// Gauss points each, of means 1 (values 0, 1, 2) and 3 (values 2, 3, 4): the diagonal's
    /// nodes 0, 4 and 8 get 2, the others their triangle's mean (exact: sums of small
    /// integers and a division by 2 or 3 of a multiple).
    #[test]
    fn triangles_with_three_points_average_the_same_way() {
        let triangles = vec![vec![0, 2, 8, 1, 5, 4], vec![0, 8, 6, 4, 7, 3]];
        let gauss: Vec<[f64; 1]> = [0.0, 1.0, 2.0, 2.0, 3.0, 4.0].iter().map(|&v| [v]).collect();
        let nodal = nodal_average(9, &triangles, &[0, 0, 0, 1, 1, 1], &gauss);
        let got: Vec<f64> = nodal.iter().map(|v| v[0]).collect();
        assert_eq!(got, [2.0, 1.0, 1.0, 3.0, 2.0, 1.0, 3.0, 3.0, 2.0]);
    }

    /// A mixed mesh: a Q4-like quadrilateral with 4 points (mean 1) beside a triangle with 3
    /// (mean 4, values 3, 4, 5) sharing nodes 1 and 2: those get 2.5, the others their
    /// element's mean; the points may come in any order (exact: small integers, halves).
    #[test]
    fn mixed_elements_average_with_their_own_point_counts() {
        let elements = vec![vec![0, 1, 2, 3], vec![1, 4, 2]];
        let owner = [1, 0, 0, 1, 0, 0, 1];
        let gauss: Vec<[f64; 1]> =
            [3.0, 0.0, 2.0, 4.0, 1.0, 1.0, 5.0].iter().map(|&v| [v]).collect();
        let nodal = nodal_average(5, &elements, &owner, &gauss);
        let got: Vec<f64> = nodal.iter().map(|v| v[0]).collect();
        assert_eq!(got, [1.0, 2.5, 2.5, 1.0, 4.0]);
    }
}
