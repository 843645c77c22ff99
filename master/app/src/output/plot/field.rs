use super::{
    Draw, DrawResult, FONT, Figure, PlotError, Result, equal_aspect, sig4, viridis, write_figure,
};
use crate::output::field_data::FieldData;
use cosdem_fem::element::{ElementKind, Quadrature, QuadratureRule, gauss_1d};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Sub-cells per element side when the field is painted.
const SUBDIVISIONS: usize = 24;

/// The element family of a node list: 6 nodes a T6, 9 a Q9, otherwise a Q8 (what
/// [`FieldData::read`] lets through).
fn kind_of(nodes: usize) -> ElementKind {
    match nodes {
        6 => ElementKind::T6,
        9 => ElementKind::Q9,
        _ => ElementKind::Q8,
    }
}

/// Lagrange basis through the 1D Gauss points `g` at `t`.
fn lagrange(g: &[f64], t: f64) -> Vec<f64> {
    (0..g.len())
        .map(|i| (0..g.len()).filter(|&j| j != i).map(|j| (t - g[j]) / (g[i] - g[j])).product())
        .collect()
}

/// The complete polynomials of degree `degree` (1: `1, x, y`; 2: also `x^2, xy, y^2`) at `p`.
fn monomials(degree: usize, p: [f64; 2]) -> Vec<f64> {
    let [x, y] = p;
    let mut m = vec![1.0, x, y];
    if degree >= 2 {
        m.extend([x * x, x * y, y * y]);
    }
    m
}

/// The inverse of the square matrix `a` (Gauss-Jordan with partial pivoting); `None` when it
/// is singular.
fn invert(mut a: Vec<Vec<f64>>) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut inv: Vec<Vec<f64>> =
        (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-12 {
            return None;
        }
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c];
        a[c].iter_mut().chain(inv[c].iter_mut()).for_each(|v| *v /= d);
        for r in (0..n).filter(|&r| r != c) {
            let f = a[r][c];
            for k in 0..n {
                a[r][k] -= f * a[c][k];
                inv[r][k] -= f * inv[c][k];
            }
        }
    }
    Some(inv)
}

/// The extrapolation from the `points` Gauss points of a `kind` element to its nodes:
/// `m[a][g]` is node `a`'s weight of point `g`. On a quadrilateral, the tensor-product Lagrange
/// polynomial through the n x n points; on a triangle, the complete polynomial through the
/// rule's points (linear through 3, quadratic through 6: both rules are unisolvent), so that a
/// mid-side node of a 3-point triangle gets the mean of its corners. `None` for a rule the
/// solver does not have.
fn extrapolation(kind: ElementKind, points: usize) -> Option<Vec<Vec<f64>>> {
    let nodes = kind.reference_nodes();
    if kind.is_triangle() {
        let degree = match points {
            3 => 1,
            6 => 2,
            _ => return None,
        };
        let rule = Quadrature::new(match points {
            3 => QuadratureRule::Triangle3,
            _ => QuadratureRule::Triangle6,
        });
        let v = invert(rule.points.iter().map(|&p| monomials(degree, p)).collect())?;
        let m = nodes
            .iter()
            .map(|&xi| {
                let at = monomials(degree, xi);
                (0..points).map(|g| (0..points).map(|k| at[k] * v[k][g]).sum()).collect()
            })
            .collect();
        return Some(m);
    }
    let n = (points as f64).sqrt().round() as usize;
    if n * n != points || !(2..=4).contains(&n) {
        return None;
    }
    let (g, _) = gauss_1d(n);
    let m = nodes
        .iter()
        .map(|xi| {
            let (lx, ly) = (lagrange(&g, xi[0]), lagrange(&g, xi[1]));
            (0..points).map(|p| lx[p % n] * ly[p / n]).collect()
        })
        .collect();
    Some(m)
}

/// Nodal values of the Gauss-point equivalent strain: in every element, the polynomial through
/// its Gauss values evaluated at the nodes ([`extrapolation`]: the usual extrapolation), then
/// averaged over the elements sharing each node.
pub fn nodal_values(f: &FieldData) -> Vec<f64> {
    let mut sum = vec![0.0; f.nodes.len()];
    let mut count = vec![0u32; f.nodes.len()];
    let mut matrices = std::collections::BTreeMap::new();
    for (nodes, range) in f.elements.iter().zip(f.point_ranges()) {
        let per = range.len();
        let q = &f.equivalent_strain[range];
        let m = matrices
            .entry((nodes.len(), per))
            .or_insert_with(|| extrapolation(kind_of(nodes.len()), per));
        let Some(m) = m else { continue };
        for (a, row) in m.iter().enumerate() {
            sum[nodes[a]] += row.iter().zip(q).map(|(w, v)| w * v).sum::<f64>();
            count[nodes[a]] += 1;
        }
    }
    sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / f64::from(c) } else { 0.0 }).collect()
}

/// The sub-cells an element is painted with, in reference coordinates: `k x k` quadrilaterals
/// of the reference square, or the `k^2` triangles of the reference triangle cut `k` times
/// along each side (`k (k + 1) / 2` upright, `k (k - 1) / 2` upside down).
fn sub_cells(kind: ElementKind, k: usize) -> Vec<Vec<[f64; 2]>> {
    let c = &kind.reference_nodes()[..kind.corners()];
    let s = |i: usize| i as f64 / k as f64;
    let mut cells = Vec::with_capacity(k * k);
    if kind.is_triangle() {
        let at = |i: usize, j: usize| {
            let (a, b) = (s(i), s(j));
            [0, 1].map(|d| c[0][d] + a * (c[1][d] - c[0][d]) + b * (c[2][d] - c[0][d]))
        };
        for j in 0..k {
            for i in 0..k - j {
                cells.push(vec![at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < k {
                    cells.push(vec![at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    } else {
        let at = |i: usize, j: usize| {
            let (a, b) = (s(i), s(j));
            [0, 1].map(|d| {
                (1.0 - a) * (1.0 - b) * c[0][d]
                    + a * (1.0 - b) * c[1][d]
                    + a * b * c[2][d]
                    + (1.0 - a) * b * c[3][d]
            })
        };
        for j in 0..k {
            for i in 0..k {
                cells.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    cells
}

/// Shape-function interpolation of nodal `values` and deformed positions in element `e`.
fn interpolate(f: &FieldData, e: usize, values: &[f64], xi: [f64; 2]) -> ([f64; 2], f64) {
    let nodes = &f.elements[e];
    let kind = kind_of(nodes.len());
    let mut n = [0.0; 9];
    let mut dn = [[0.0; 2]; 9];
    kind.shape(xi, &mut n, &mut dn);
    let (mut x, mut y, mut v) = (0.0, 0.0, 0.0);
    for (a, &k) in nodes.iter().enumerate() {
        x += n[a] * (f.nodes[k][0] + f.displacements[k][0]);
        y += n[a] * (f.nodes[k][1] + f.displacements[k][1]);
        v += n[a] * values[k];
    }
    ([x, y], v)
}

/// Fig. 9: the equivalent strain (Eq. 34) painted over the deformed mesh (true scale), with
/// the element edges, the undeformed outline and a colour bar.
pub fn plot_strain_field(f: &FieldData, title: &str, path: &Path) -> Result<()> {
    if f.elements.is_empty() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "no elements".into() });
    }
    let values = nodal_values(f);
    let all = || values.iter().chain(&f.equivalent_strain).copied();
    let (lo, hi) = (all().fold(f64::INFINITY, f64::min), all().fold(0.0, f64::max));
    // The colours span the values drawn (a uniform field: from 0), so variations show.
    let range = if hi > 0.0 && hi - lo > 1e-6 * hi {
        (lo, hi)
    } else {
        (0.0, if hi > 0.0 { hi } else { 1e-12 })
    };

    let mut heading = format!(
        "Equivalent strain q (Eq. 34) at d = {} mm (step {}), deformed mesh at true scale",
        sig4(f.displacement * 1e3),
        f.step
    );
    if !title.is_empty() {
        heading = format!("{title}\n{heading}");
    }
    write_figure(&FieldFigure { f, values, range, heading }, path)
}

/// Fig. 9's drawing: the field, its nodal values, the colour range and the heading.
struct FieldFigure<'f> {
    f: &'f FieldData,
    values: Vec<f64>,
    range: (f64, f64),
    heading: String,
}

impl Draw for FieldFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let mut area = root.clone();
        for line in self.heading.lines() {
            area = area.titled(line, (FONT, 22)).at(path)?;
        }
        let (w, _) = area.dim_in_pixel();
        let (main, bar) = area.split_horizontally(w - 170);
        draw_mesh(&main, self.f, &self.values, self.range, path)?;
        draw_colour_bar(&bar, self.range, path)
    }
}

fn draw_mesh<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    f: &FieldData,
    values: &[f64],
    (lo, hi): (f64, f64),
    path: &Path,
) -> Result<()> {
    let mut bx = (f64::INFINITY, f64::NEG_INFINITY);
    let mut by = (f64::INFINITY, f64::NEG_INFINITY);
    for (p, u) in f.nodes.iter().zip(&f.displacements) {
        for q in [*p, [p[0] + u[0], p[1] + u[1]]] {
            bx = (bx.0.min(q[0]), bx.1.max(q[0]));
            by = (by.0.min(q[1]), by.1.max(q[1]));
        }
    }
    let build = |xr: (f64, f64), yr: (f64, f64)| {
        ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
    };
    let px = build(bx, by).at(path)?.plotting_area().dim_in_pixel();
    let (xr, yr) = equal_aspect(bx, by, 0.03, px);
    let mut chart = build(xr, yr).at(path)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .label_style((FONT, 17))
        .axis_desc_style((FONT, 19))
        .draw()
        .at(path)?;
    for (e, nodes) in f.elements.iter().enumerate() {
        let cells = sub_cells(kind_of(nodes.len()), SUBDIVISIONS).into_iter().map(|cell| {
            let mut centre = [0.0; 2];
            for p in &cell {
                centre = [centre[0] + p[0], centre[1] + p[1]];
            }
            let centre = centre.map(|c| c / cell.len() as f64);
            let (_, v) = interpolate(f, e, values, centre);
            let colour = viridis((v - lo) / (hi - lo));
            let corners = cell
                .iter()
                .map(|&xi| {
                    let (p, _) = interpolate(f, e, values, xi);
                    (p[0], p[1])
                })
                .collect::<Vec<_>>();
            Polygon::new(corners, colour.filled())
        });
        chart.draw_series(cells).at(path)?;
    }
    // Element edges, deformed (black) and the undeformed outline (grey).
    let m = 8 * SUBDIVISIONS;
    for (e, nodes) in f.elements.iter().enumerate() {
        let kind = kind_of(nodes.len());
        let corners = &kind.reference_nodes()[..kind.corners()];
        let mut deformed = Vec::with_capacity(corners.len() * m + 1);
        let mut reference = Vec::with_capacity(corners.len() * m + 1);
        for (s, from) in corners.iter().enumerate() {
            let to = corners[(s + 1) % corners.len()];
            let last = if s + 1 == corners.len() { m } else { m - 1 };
            for i in 0..=last {
                let a = i as f64 / m as f64;
                let xi = [from[0] + a * (to[0] - from[0]), from[1] + a * (to[1] - from[1])];
                let (p, _) = interpolate(f, e, values, xi);
                deformed.push((p[0], p[1]));
                let mut n = [0.0; 9];
                let mut dn = [[0.0; 2]; 9];
                kind.shape(xi, &mut n, &mut dn);
                let (mut x, mut y) = (0.0, 0.0);
                for (a, &node) in nodes.iter().enumerate() {
                    x += n[a] * f.nodes[node][0];
                    y += n[a] * f.nodes[node][1];
                }
                reference.push((x, y));
            }
        }
        chart
            .draw_series([PathElement::new(reference, RGBColor(150, 150, 150).stroke_width(1))])
            .at(path)?;
        chart.draw_series([PathElement::new(deformed, BLACK.stroke_width(1))]).at(path)?;
    }
    Ok(())
}

fn draw_colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    path: &Path,
) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(15)
        .margin_bottom(70)
        .margin_left(10)
        .margin_right(5)
        .set_label_area_size(LabelAreaPosition::Right, 110)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .at(path)?;
    let n = 256;
    chart
        .draw_series((0..n).map(|i| {
            let a = lo + (hi - lo) * i as f64 / n as f64;
            let b = lo + (hi - lo) * (i + 1) as f64 / n as f64;
            Rectangle::new([(0.0, a), (1.0, b)], viridis((i as f64 + 0.5) / n as f64).filled())
        }))
        .at(path)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .set_tick_mark_size(LabelAreaPosition::Right, 6)
        .y_desc("equivalent strain q (-)")
        .y_label_formatter(&|v| format!(" {v:.3e}"))
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .draw()
        .at(path)?;
    chart.draw_series([Rectangle::new([(0.0, lo), (1.0, hi)], BLACK.stroke_width(1))]).at(path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::SIZE;
    use cosdem_fem::assembly::GaussData;

    /// The unit square meshed 2 x 2 with `kind`, its Gauss points of `rule` holding `q(x)`.
    fn sample(kind: ElementKind, rule: QuadratureRule, q: impl Fn([f64; 2]) -> f64) -> FieldData {
        let mesh = cosdem_fem::mesh::Mesh::rectangle(kind, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
        let gauss = GaussData::new(&mesh, rule).unwrap();
        FieldData {
            step: 3,
            displacement: 0.006,
            internal_length: 0.01,
            displacements: mesh.nodes.iter().map(|p| [0.0, -0.01 * p[1]]).collect(),
            nodes: mesh.nodes.clone(),
            elements: mesh.element_lists(),
            gauss_points: gauss.counts(),
            equivalent_strain: gauss.x.iter().map(|&x| q(x)).collect(),
        }
    }

    /// The largest nodal error of `f`'s extrapolation against the exact `q`.
    fn nodal_error(f: &FieldData, q: impl Fn([f64; 2]) -> f64) -> f64 {
        nodal_values(f).iter().zip(&f.nodes).map(|(v, &p)| (v - q(p)).abs()).fold(0.0, f64::max)
    }

    /// A field linear in x and y is reproduced exactly at the nodes (the extrapolation is exact
    /// for bilinear data, and the averages of equal values are equal).
    #[test]
    fn extrapolation_is_exact_for_bilinear_fields() {
        let q = |x: [f64; 2]| 0.01 + 0.02 * x[0] - 0.005 * x[1];
        let f = sample(ElementKind::Q8, QuadratureRule::Gauss2x2, q);
        assert!(nodal_error(&f, q) < 1e-14, "{}", nodal_error(&f, q));
    }

    /// On triangles the extrapolation is the linear polynomial through the 3 points (so a
    /// mid-side node gets the mean of its corners) and the quadratic one through the 6 points:
    /// a linear field comes back at every node from either rule, a quadratic one from the
    /// 6 points. Tolerance 1e-13: the rules' points are given to 16 digits and the 6 x 6
    /// Vandermonde system of the quadratic fit loses about two more to its conditioning.
    #[test]
    fn triangle_extrapolation_is_exact_for_its_polynomials() {
        fn linear(x: [f64; 2]) -> f64 {
            0.01 + 0.02 * x[0] - 0.005 * x[1]
        }
        fn quadratic(x: [f64; 2]) -> f64 {
            linear(x) + 0.03 * x[0] * x[1] - 0.01 * x[1] * x[1]
        }
        let f = sample(ElementKind::T6, QuadratureRule::Triangle3, linear);
        assert_eq!((f.gauss_points[0], f.elements.len()), (3, 8));
        assert!(nodal_error(&f, linear) < 1e-13, "{}", nodal_error(&f, linear));
        let m = extrapolation(ElementKind::T6, 3).unwrap();
        for (mid, [a, b]) in [(3, [0, 1]), (4, [1, 2]), (5, [2, 0])] {
            for g in 0..3 {
                assert!((m[mid][g] - 0.5 * (m[a][g] + m[b][g])).abs() < 1e-14, "node {mid}");
            }
        }
        for q in [linear as fn([f64; 2]) -> f64, quadratic] {
            let f = sample(ElementKind::T6, QuadratureRule::Triangle6, q);
            assert_eq!(f.gauss_points[0], 6);
            assert!(nodal_error(&f, q) < 1e-13, "{}", nodal_error(&f, q));
        }
    }

    /// The reference triangle is cut into k^2 sub-triangles that tile it: their areas sum to
    /// the triangle's 1/2 (1e-12: sums of 576 small areas).
    #[test]
    fn triangle_sub_cells_tile_the_reference_triangle() {
        let cells = sub_cells(ElementKind::T6, SUBDIVISIONS);
        assert_eq!(cells.len(), SUBDIVISIONS * SUBDIVISIONS);
        let area: f64 = cells
            .iter()
            .map(|c| {
                let (a, b, d) = (c[0], c[1], c[2]);
                0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]))
            })
            .inspect(|&a| assert!(a > 0.0, "a sub-triangle is inverted or flat"))
            .sum();
        assert!((area - 0.5).abs() < 1e-12, "{area}");
    }

    /// The figure is drawn with the peak colour and every element's sub-cells (4 Q8 elements
    /// of 24 x 24 cells, or 8 triangles of 24^2 sub-triangles) and the colour bar.
    #[test]
    fn field_plot_is_drawn() {
        let dir = std::env::temp_dir().join(format!("cosdem-plot-field-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let q = |x: [f64; 2]| (-((x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2)) * 8.0).exp() * 0.02;
        for (kind, elements) in [(ElementKind::Q8, 4), (ElementKind::T6, 8)] {
            let path = dir.join(format!("field-{kind:?}.png"));
            let f = sample(kind, QuadratureRule::for_kind(kind, false), q);
            plot_strain_field(&f, "test", &path).unwrap();
            let img = image::open(&path).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), SIZE);
            // The top of the colour map (the peak in the middle) and the bottom are both painted.
            let has = |c: RGBColor| img.pixels().any(|p| p.0 == [c.0, c.1, c.2]);
            assert!(has(viridis(1.0 - 0.5 / 256.0)), "{kind:?}: no peak colour");
            let ink = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
            assert!(ink > 100_000, "{kind:?}: {ink}");
            let svg = crate::output::plot::svg_check::read_beside(&path);
            assert!(svg.matches("<polygon").count() >= elements * 24 * 24, "too few cells");
            assert!(svg.matches("<rect").count() >= 256, "no colour bar");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
