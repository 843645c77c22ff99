use super::{
    Draw, DrawResult, FONT, Figure, PlotError, Result, XyChart, equal_aspect, si_prefix, sig4,
    write_figure,
};
use crate::output::snapshots::ParticleSnapshot;
use plotters::prelude::*;
use std::path::Path;

/// Vertices of a disc outline.
const DISC_VERTICES: usize = 28;

fn disc(c: [f64; 2], r: f64) -> Vec<(f64, f64)> {
    (0..DISC_VERTICES)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / DISC_VERTICES as f64;
            (c[0] + r * a.cos(), c[1] + r * a.sin())
        })
        .collect()
}

/// What a particle figure draws over the discs.
enum Overlay {
    /// Force chains: contacts `(i, j, normal force)` by increasing force, the largest `fmax`.
    Chains { contacts: Vec<(usize, usize, f64)>, fmax: f64 },
    /// Fluctuation arrows: their strokes (shaft and head strokes, mm).
    Arrows(Vec<Vec<(f64, f64)>>),
}

/// A particle figure: the title, axes (equal scale, mm) and discs of `s` in `fill`, then the
/// overlay. The axes also take in the `extra` points (m).
struct ParticleFigure<'s> {
    s: &'s ParticleSnapshot,
    heading: String,
    fill: RGBColor,
    extra: Vec<[f64; 2]>,
    overlay: Overlay,
}

/// Writes the particle figure (PNG and SVG) after checking that there are discs.
fn particle_figure(figure: ParticleFigure<'_>, path: &Path) -> Result<()> {
    if figure.s.centres.is_empty() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "no discs".into() });
    }
    write_figure(&figure, path)
}

impl Draw for ParticleFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let mut area = root.clone();
        for line in self.heading.lines() {
            area = area.titled(line, (FONT, 22)).at(path)?;
        }
        let mut chart = self.draw_discs(&area, path)?;
        self.overlay.draw(self.s, &mut chart, path)
    }
}

impl ParticleFigure<'_> {
    /// The axes and the discs on `area` (below the heading).
    fn draw_discs<'a, DB: DrawingBackend>(
        &self,
        area: &'a Figure<DB>,
        path: &Path,
    ) -> Result<XyChart<'a, DB>> {
        let ParticleFigure { s, fill, extra, .. } = self;
        let mut bx = (f64::INFINITY, f64::NEG_INFINITY);
        let mut by = (f64::INFINITY, f64::NEG_INFINITY);
        for (c, r) in s.centres.iter().zip(&s.radius) {
            bx = (bx.0.min(c[0] - r), bx.1.max(c[0] + r));
            by = (by.0.min(c[1] - r), by.1.max(c[1] + r));
        }
        for p in extra {
            bx = (bx.0.min(p[0]), bx.1.max(p[0]));
            by = (by.0.min(p[1]), by.1.max(p[1]));
        }
        // Millimetres on the axes.
        let mm = |r: (f64, f64)| (r.0 * 1e3, r.1 * 1e3);
        let build = |xr: (f64, f64), yr: (f64, f64)| {
            ChartBuilder::on(area)
                .margin(15)
                .x_label_area_size(55)
                .y_label_area_size(75)
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        };
        let px = build(mm(bx), mm(by)).at(path)?.plotting_area().dim_in_pixel();
        let (xr, yr) = equal_aspect(mm(bx), mm(by), 0.02, px);
        let mut chart = build(xr, yr).at(path)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (mm, assembly frame)")
            .y_desc("y (mm)")
            .label_style((FONT, 17))
            .axis_desc_style((FONT, 19))
            .draw()
            .at(path)?;
        let outline = RGBColor(120, 120, 120);
        let discs: Vec<Vec<(f64, f64)>> = s
            .centres
            .iter()
            .zip(&s.radius)
            .map(|(c, r)| disc([c[0] * 1e3, c[1] * 1e3], r * 1e3))
            .collect();
        chart.draw_series(discs.iter().map(|d| Polygon::new(d.clone(), fill.filled()))).at(path)?;
        chart
            .draw_series(discs.into_iter().map(|mut d| {
                d.push(d[0]);
                PathElement::new(d, outline.stroke_width(1))
            }))
            .at(path)?;
        Ok(chart)
    }
}

fn heading(what: &str, s: &ParticleSnapshot, label: &str, detail: &str) -> String {
    let at = s.displacement.map_or(String::new(), |d| format!(" at d = {} mm", sig4(d * 1e3)));
    format!("{what}{at}, {label}\n{} discs; {detail}", s.centres.len())
}

/// True for a contact drawn as a segment: not one across a periodic cell (its two centres
/// farther apart than the sum of the radii, with some slack).
fn drawable(s: &ParticleSnapshot, i: usize, j: usize) -> bool {
    let (a, b) = (s.centres[i], s.centres[j]);
    let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    d <= 1.5 * (s.radius[i] + s.radius[j])
}

/// Figs. 10-11: the discs with the contact force chains, segments between the centres of
/// touching discs with a width proportional to the normal force.
pub fn plot_force_chains(s: &ParticleSnapshot, label: &str, path: &Path) -> Result<()> {
    let mut contacts: Vec<(usize, usize, f64)> = s
        .contacts
        .iter()
        .filter(|c| c.2 > 0.0 && drawable(s, c.0, c.1))
        .map(|c| (c.0, c.1, c.2))
        .collect();
    contacts.sort_by(|a, b| a.2.total_cmp(&b.2));
    let fmax = contacts.last().map_or(0.0, |c| c.2);
    let (div, prefix) = si_prefix(fmax);
    let detail = format!(
        "{} contacts drawn, line width ∝ normal force (max {} {prefix}N/m)",
        contacts.len(),
        sig4(fmax / div)
    );
    let heading = heading("Contact force chains", s, label, &detail);
    let fill = RGBColor(238, 238, 238);
    let overlay = Overlay::Chains { contacts, fmax };
    particle_figure(ParticleFigure { s, heading, fill, extra: Vec::new(), overlay }, path)
}

/// Fig. 12: the fluctuation field of Eq. 35 (each disc's displacement minus the affine part
/// of the macro deformation) as arrows from the disc centres, magnified so that the longest
/// is 2.5 mean radii long.
pub fn plot_fluctuations(s: &ParticleSnapshot, label: &str, path: &Path) -> Result<()> {
    let umax = s.fluctuation.iter().map(|u| u[0].hypot(u[1])).fold(0.0, f64::max);
    let rmean = s.radius.iter().sum::<f64>() / s.radius.len().max(1) as f64;
    let scale = if umax > 0.0 { 2.5 * rmean / umax } else { 0.0 };
    let tips: Vec<[f64; 2]> = s
        .centres
        .iter()
        .zip(&s.fluctuation)
        .map(|(c, u)| [c[0] + scale * u[0], c[1] + scale * u[1]])
        .collect();
    let (div, prefix) = si_prefix(umax);
    let detail =
        format!("arrows magnified {}×, longest {} {prefix}m", sig4(scale), sig4(umax / div));
    let heading = heading("Fluctuations u_R (Eq. 35)", s, label, &detail);
    let mut arrows = Vec::new();
    for (c, t) in s.centres.iter().zip(&tips) {
        let (x0, y0) = (c[0] * 1e3, c[1] * 1e3);
        let (x1, y1) = (t[0] * 1e3, t[1] * 1e3);
        let (dx, dy) = (x1 - x0, y1 - y0);
        let len = dx.hypot(dy);
        if len <= 0.0 {
            continue;
        }
        arrows.push(vec![(x0, y0), (x1, y1)]);
        // Head: two strokes at 25 degrees, 30 % of the arrow but at most a radius long.
        let h = (0.3 * len).min(rmean * 1e3);
        let (ux, uy) = (dx / len, dy / len);
        let (ca, sa) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
        for sgn in [-1.0, 1.0] {
            let (rx, ry) = (ux * ca - sgn * uy * sa, sgn * ux * sa + uy * ca);
            arrows.push(vec![(x1, y1), (x1 - h * rx, y1 - h * ry)]);
        }
    }
    let fill = RGBColor(248, 248, 248);
    let overlay = Overlay::Arrows(arrows);
    particle_figure(ParticleFigure { s, heading, fill, extra: tips, overlay }, path)
}

impl Overlay {
    /// Draws the overlay on the particle chart of `s` (drawn to `path`).
    fn draw<DB: DrawingBackend>(
        &self,
        s: &ParticleSnapshot,
        chart: &mut XyChart<'_, DB>,
        path: &Path,
    ) -> Result<()> {
        match self {
            Overlay::Chains { contacts, fmax } => {
                let chain = RGBColor(170, 20, 20);
                // The widest line is 0.3 mean disc radii (2 to 10 pixels), so chains stay
                // readable over dense packings.
                let rmean = s.radius.iter().sum::<f64>() / s.radius.len() as f64 * 1e3;
                let (a, b) = (chart.backend_coord(&(0.0, 0.0)), chart.backend_coord(&(rmean, 0.0)));
                let wmax = (0.3 * f64::from(b.0 - a.0)).clamp(2.0, 10.0);
                let width = |f: f64| (1.0 + (wmax - 1.0) * f / fmax).round() as u32;
                let segments = contacts.iter().map(|&(i, j, f)| {
                    let (a, b) = (s.centres[i], s.centres[j]);
                    let seg = vec![(a[0] * 1e3, a[1] * 1e3), (b[0] * 1e3, b[1] * 1e3)];
                    PathElement::new(seg, chain.stroke_width(width(f)))
                });
                chart.draw_series(segments).at(path)?;
            }
            Overlay::Arrows(arrows) => {
                let ink = RGBColor(20, 60, 150);
                chart
                    .draw_series(
                        arrows.iter().map(|p| PathElement::new(p.clone(), ink.stroke_width(2))),
                    )
                    .at(path)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::{SIZE, svg_check};

    /// A 6 x 6 square lattice of 5 mm discs with a vertical force column and a swirl of
    /// fluctuations: both figures are drawn at full size with the chain and arrow colours.
    #[test]
    fn particle_figures_are_drawn() {
        let dir = std::env::temp_dir().join(format!("cosdem-plot-part-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut s = ParticleSnapshot { displacement: Some(0.004), ..Default::default() };
        for j in 0..6 {
            for i in 0..6 {
                let (x, y) = (0.01 * f64::from(i) - 0.025, 0.01 * f64::from(j) - 0.025);
                s.centres.push([x, y]);
                s.radius.push(0.005);
                s.rotation.push(0.0);
                s.fluctuation.push([-y * 1e-4, x * 1e-4]);
            }
        }
        for j in 0..5 {
            for i in 0..6 {
                s.contacts.push((j * 6 + i, (j + 1) * 6 + i, 100.0 * (1.0 + i as f64), 0.0));
            }
        }
        // A periodic image contact (far apart) is not drawn.
        s.contacts.push((0, 35, 1e6, 0.0));
        let p = dir.join("chains.png");
        plot_force_chains(&s, "test point", &p).unwrap();
        let img = image::open(&p).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        assert!(img.pixels().filter(|q| q.0 == [170, 20, 20]).count() > 2_000);
        // The SVG: 36 disc outlines and one segment per drawn contact (the periodic one not).
        let svg = crate::output::plot::svg_check::read_beside(&p);
        assert_eq!(svg_check::polylines(&svg, "#787878").len(), 36);
        assert_eq!(svg_check::polylines(&svg, "#AA1414"), vec![2; 30]);
        let p = dir.join("fluct.png");
        plot_fluctuations(&s, "test point", &p).unwrap();
        let img = image::open(&p).unwrap().to_rgb8();
        assert!(img.pixels().filter(|q| q.0 == [20, 60, 150]).count() > 500);
        // Three strokes (shaft and head) per arrow; the centre disc of the swirl has none.
        let svg = svg_check::read_beside(&p);
        let arrows = svg_check::polylines(&svg, "#143C96").len();
        assert_eq!(arrows % 3, 0);
        assert!(arrows >= 3 * 35, "{arrows}");
        let empty = ParticleSnapshot::default();
        let e = plot_force_chains(&empty, "", &dir.join("e.png")).unwrap_err();
        assert!(matches!(&e, PlotError::NoData { message, .. } if message == "no discs"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
