use super::{
    Draw, DrawResult, FONT, Figure, PlotError, Result, equal_aspect, sig4, viridis, write_figure,
};
use crate::output::field_data::FieldData;
use cosdem_fem::element::{ElementKind, gauss_1d};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Sub-cells per element side when the field is painted.
const SUBDIVISIONS: usize = 24;

fn kind_of(nodes: usize) -> ElementKind {
    if nodes == 9 { ElementKind::Q9 } else { ElementKind::Q8 }
}

/// Lagrange basis through the 1D Gauss points `g` at `t`.
fn lagrange(g: &[f64], t: f64) -> Vec<f64> {
    (0..g.len())
        .map(|i| (0..g.len()).filter(|&j| j != i).map(|j| (t - g[j]) / (g[i] - g[j])).product())
        .collect()
}

/// Nodal values of the Gauss-point equivalent strain: in every element, the tensor-product
/// Lagrange polynomial through its n x n Gauss values evaluated at the nodes (the usual
/// extrapolation), then averaged over the elements sharing each node.
pub fn nodal_values(f: &FieldData) -> Vec<f64> {
    let n = (f.gauss_per_element as f64).sqrt().round() as usize;
    let (g, _) = gauss_1d(n);
    let mut sum = vec![0.0; f.nodes.len()];
    let mut count = vec![0u32; f.nodes.len()];
    for (e, nodes) in f.elements.iter().enumerate() {
        let q = &f.equivalent_strain[e * f.gauss_per_element..(e + 1) * f.gauss_per_element];
        for (a, xi) in kind_of(nodes.len()).reference_nodes().iter().enumerate() {
            let (lx, ly) = (lagrange(&g, xi[0]), lagrange(&g, xi[1]));
            let mut v = 0.0;
            for j in 0..n {
                for i in 0..n {
                    v += lx[i] * ly[j] * q[j * n + i];
                }
            }
            sum[nodes[a]] += v;
            count[nodes[a]] += 1;
        }
    }
    sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / f64::from(c) } else { 0.0 }).collect()
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
    let k = SUBDIVISIONS;
    let t = |i: usize| -1.0 + 2.0 * i as f64 / k as f64;
    for e in 0..f.elements.len() {
        let mut cells = Vec::with_capacity(k * k);
        for j in 0..k {
            for i in 0..k {
                let corner = |a: usize, b: usize| {
                    let (p, _) = interpolate(f, e, values, [t(i + a), t(j + b)]);
                    (p[0], p[1])
                };
                let centre = [0.5 * (t(i) + t(i + 1)), 0.5 * (t(j) + t(j + 1))];
                let (_, v) = interpolate(f, e, values, centre);
                let colour = viridis((v - lo) / (hi - lo));
                cells.push(Polygon::new(
                    vec![corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)],
                    colour.filled(),
                ));
            }
        }
        chart.draw_series(cells).at(path)?;
    }
    // Element edges, deformed (black) and the undeformed outline (grey).
    let m = 8 * k;
    for (e, nodes) in f.elements.iter().enumerate() {
        let kind = kind_of(nodes.len());
        let mut deformed = Vec::with_capacity(4 * m + 1);
        let mut reference = Vec::with_capacity(4 * m + 1);
        let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]];
        for s in 0..4 {
            for i in 0..=m {
                let a = i as f64 / m as f64;
                let xi = [
                    corners[s][0] + a * (corners[s + 1][0] - corners[s][0]),
                    corners[s][1] + a * (corners[s + 1][1] - corners[s][1]),
                ];
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

    fn sample(q: impl Fn([f64; 2]) -> f64) -> FieldData {
        let mesh =
            cosdem_fem::mesh::Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
        let (g, _) = gauss_1d(2);
        let mut strain = Vec::new();
        for e in 0..mesh.n_elements() {
            let c = mesh.element_coords(e);
            for j in 0..2 {
                for i in 0..2 {
                    let mut n = [0.0; 8];
                    let mut dn = [[0.0; 2]; 8];
                    ElementKind::Q8.shape([g[i], g[j]], &mut n, &mut dn);
                    let x = [0usize, 1].map(|k| (0..8).map(|a| n[a] * c[a][k]).sum::<f64>());
                    strain.push(q(x));
                }
            }
        }
        FieldData {
            step: 3,
            displacement: 0.006,
            internal_length: 0.01,
            displacements: mesh.nodes.iter().map(|p| [0.0, -0.01 * p[1]]).collect(),
            nodes: mesh.nodes.clone(),
            elements: mesh.connectivity.chunks(8).map(|c| c.to_vec()).collect(),
            gauss_per_element: 4,
            equivalent_strain: strain,
        }
    }

    /// A field linear in x and y is reproduced exactly at the nodes (the extrapolation is exact
    /// for bilinear data, and the averages of equal values are equal).
    #[test]
    fn extrapolation_is_exact_for_bilinear_fields() {
        let f = sample(|x| 0.01 + 0.02 * x[0] - 0.005 * x[1]);
        for (v, p) in nodal_values(&f).iter().zip(&f.nodes) {
            assert!((v - (0.01 + 0.02 * p[0] - 0.005 * p[1])).abs() < 1e-14, "{p:?}: {v}");
        }
    }

    #[test]
    fn field_plot_is_drawn() {
        let dir = std::env::temp_dir().join(format!("cosdem-plot-field-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("field.png");
        let f = sample(|x| (-((x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2)) * 8.0).exp() * 0.02);
        plot_strain_field(&f, "test", &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // The top of the colour map (the peak in the middle) and the bottom are both painted.
        let has = |c: RGBColor| img.pixels().any(|p| p.0 == [c.0, c.1, c.2]);
        assert!(has(viridis(1.0 - 0.5 / 256.0)), "no peak colour");
        let ink = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(ink > 100_000, "{ink}");
        let svg = crate::output::plot::svg_check::read_beside(&path);
        // 4 elements of 24 x 24 painted cells, and the 256 bands of the colour bar.
        assert!(svg.matches("<polygon").count() >= 4 * 24 * 24, "too few cells");
        assert!(svg.matches("<rect").count() >= 256, "no colour bar");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
