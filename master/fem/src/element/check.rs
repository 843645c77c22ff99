//! Shape checks of one element's geometry: mid-side nodes near their edges and a positive
//! Jacobian determinant across the element.
//!
//! Criterion: each mid-side node lies within a quarter of its edge's length of the midpoint
//! of the straight edge between the edge's corners (a tangential offset of a quarter is
//! where the Jacobian of the quadratic edge vanishes at a corner, the quarter-point element;
//! the same distance off the edge, a bulge of a quarter of the chord, is a moderately curved
//! edge and allowed), and the Jacobian determinant is positive at every node, at the
//! centroid and at the points of the element's reduced and full rules. The determinant of a
//! quadratic triangle is a quadratic polynomial; these 13 points catch inversion at a corner
//! (the usual failure of a misplaced mid-side node) and at the integration points the solver
//! uses.

use super::{ElementKind, Quadrature, QuadratureRule, shape_at};

/// How far (relative to its edge's length) a mid-side node may sit from the midpoint of the
/// straight edge.
pub const MAX_MID_NODE_OFFSET: f64 = 0.25;

/// What is wrong with the shape of an element with node coordinates `coords` (Gmsh order,
/// counter-clockwise), or `None` when it passes the checks of this module. The message names
/// the local node or reference point; the caller names the element.
pub fn shape_defect(kind: ElementKind, coords: &[[f64; 2]]) -> Option<String> {
    debug_assert_eq!(coords.len(), kind.nodes());
    for ed in kind.edges() {
        let (a, b, m) = (coords[ed[0]], coords[ed[1]], coords[ed[2]]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let off = (m[0] - 0.5 * (a[0] + b[0])).hypot(m[1] - 0.5 * (a[1] + b[1]));
        if off.is_nan() || off > MAX_MID_NODE_OFFSET * len {
            return Some(format!(
                "mid-side node {} (local) of edge {}-{} is {off:e} from the edge's midpoint, \
                 more than {MAX_MID_NODE_OFFSET} of the edge length {len:e}",
                ed[2], ed[0], ed[1]
            ));
        }
    }
    let centroid = if kind.is_triangle() { [1.0 / 3.0; 2] } else { [0.0; 2] };
    let rules = [QuadratureRule::for_kind(kind, false), QuadratureRule::for_kind(kind, true)];
    let points = kind
        .reference_nodes()
        .iter()
        .copied()
        .chain(std::iter::once(centroid))
        .chain(rules.iter().flat_map(|&r| Quadrature::new(r).points));
    for xi in points {
        if let Err(crate::error::Error::InvertedElement { det_j, .. }) =
            shape_at(kind, 0, coords, xi)
        {
            return Some(format!(
                "the Jacobian determinant is {det_j:e} <= 0 at reference point {xi:?} \
                 (a mid-side node too far along or off its edge, or a folded element)"
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference triangle scaled by 2 passes; a mid-side node moved along its edge by
    /// 0.3 of the edge length, or off it by 0.3, fails the distance check; a node moved by
    /// 0.2 along passes (det J at the corner is 1 - 4 * 0.2 = 0.2 of the straight value), so
    /// do an outward bulge of 0.25 of the edge and an inward one of 0.1 (an inward bulge of
    /// 0.25 would turn the end tangent by 45 degrees, onto the neighbouring edge at the
    /// 45-degree corner: det J = 0 there, refused).
    #[test]
    fn mid_side_nodes_far_off_are_named() {
        let kind = ElementKind::T6;
        let base: Vec<[f64; 2]> =
            kind.reference_nodes().iter().map(|p| [2.0 * p[0], 2.0 * p[1]]).collect();
        assert_eq!(shape_defect(kind, &base), None);
        let moved = |dx: f64, dy: f64| {
            let mut c = base.clone();
            c[3] = [c[3][0] + dx, c[3][1] + dy];
            shape_defect(kind, &c)
        };
        let along = moved(0.6, 0.0).unwrap();
        assert!(along.contains("mid-side node 3") && along.contains("edge 0-1"), "{along}");
        assert!(moved(0.0, 0.6).unwrap().contains("mid-side node 3"));
        assert_eq!(moved(0.4, 0.0), None);
        assert_eq!(moved(0.0, -0.5), None);
        assert_eq!(moved(0.0, 0.2), None);
        assert!(moved(0.0, 0.5).unwrap().contains("Jacobian determinant"));
    }

    /// A flat triangle (corners (0,0), (1,0), (0.5,0.1)) whose long edge bulges inward by
    /// 0.2, past the opposite corner: within the distance limit (0.2 <= 0.25), but the
    /// element folds (det J = -0.3 at the bulged node, by hand).
    #[test]
    fn folded_element_is_found_by_the_jacobian() {
        let c = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.1], [0.5, 0.2], [0.75, 0.05], [0.25, 0.05]];
        let msg = shape_defect(ElementKind::T6, &c).unwrap();
        assert!(msg.contains("Jacobian determinant"), "{msg}");
        let mut straight = c;
        straight[3] = [0.5, 0.0];
        assert_eq!(shape_defect(ElementKind::T6, &straight), None);
    }
}
