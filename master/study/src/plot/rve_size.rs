//! Figures of the RVE-size study (`cosdem study rve-size`): the load-displacement curves of
//! every size (the paper's Fig. 3) and each property against the assembly size with its
//! fitted size law (Figs. 4-5).

use crate::rve_size::fit::SizeLawFit;
use cosdem_app::output::plot::curve::LoadScales;
use cosdem_app::output::plot::{
    Draw, DrawResult, Figure, LineAxes, PlotError, Result, draw_legend, si_prefix, sig4, viridis,
    write_figure,
};
use plotters::prelude::*;
use std::path::Path;

/// Fig. 3 of a study: one load-displacement curve per assembly size `V` (m^2), coloured from
/// the smallest (dark) to the largest (light) size. Loads per metre of thickness. Written as
/// the PNG `path` and the SVG beside it.
pub fn plot_study_curves(
    curves: &[(f64, Vec<(f64, f64)>)],
    title: &str,
    path: &Path,
) -> Result<()> {
    if curves.iter().all(|(_, c)| c.is_empty()) {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "no curve".into() });
    }
    write_figure(&StudyCurves { curves, title }, path)
}

/// Fig. 3 of a study: the curves `(V, points)` and the title.
struct StudyCurves<'c> {
    curves: &'c [(f64, Vec<(f64, f64)>)],
    title: &'c str,
}

impl Draw for StudyCurves<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let StudyCurves { curves, title } = *self;
        let all = || curves.iter().flat_map(|(_, c)| c.iter());
        let scales = LoadScales::of(all().copied());
        let LoadScales { fmax, fmin, div, dd, .. } = scales;
        let y1 = if fmax > 0.0 { fmax / div * 1.08 } else { 1.0 };
        let y0 = (fmin / div).min(0.0) * 1.08;
        let caption = format!("Load-displacement per assembly size: {title}");
        let mut chart = scales.axes(caption, 22, y0..y1).draw(root, path)?;
        let n = curves.len().max(2) - 1;
        for (i, (v, c)) in curves.iter().enumerate() {
            // Light yellow is unreadable on white: stop the map at 0.85.
            let colour = viridis(0.85 * i as f64 / n as f64);
            let pts = std::iter::once((0.0, 0.0))
                .chain(c.iter().copied())
                .map(|(d, f)| (d / dd, f / div))
                .collect::<Vec<_>>();
            chart
                .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                .at(path)?
                .label(format!("V = {} m^2", sig4(*v)))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                });
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight, 18, path)
    }
}

/// Figs. 4-5 of a study: one property (`name`, `unit` such as `N/m`) against the assembly size
/// `V`: the measured `points` `(V, value)`, the fitted law `F^cr exp(a exp(b* V^k))` over the
/// measured range, its representative value `F^cr` and `V^cr` when the fit has them. Written
/// as the PNG `path` and the SVG beside it.
pub fn plot_size_law(
    points: &[(f64, f64)],
    fit: Option<&SizeLawFit>,
    name: &str,
    unit: &str,
    path: &Path,
) -> Result<()> {
    if points.is_empty() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: format!("no {name}") });
    }
    write_figure(&SizeLaw { points, fit, name, unit }, path)
}

/// Figs. 4-5 of a study: the measured points, the fit, the property's name and unit.
struct SizeLaw<'p> {
    points: &'p [(f64, f64)],
    fit: Option<&'p SizeLawFit>,
    name: &'p str,
    unit: &'p str,
}

impl Draw for SizeLaw<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let SizeLaw { points, fit, name, unit } = *self;
        let vmax = points.iter().map(|p| p.0).fold(0.0, f64::max);
        let vmax =
            fit.and_then(|f| f.v_cr.as_ref()).map_or(vmax, |c| vmax.max(c.value.min(2.0 * vmax)));
        let mut values: Vec<f64> = points.iter().map(|p| p.1).collect();
        if let Some(f) = fit {
            values.push(f.representative.value);
        }
        let hi = values.iter().copied().fold(f64::MIN, f64::max);
        let lo = values.iter().copied().fold(f64::MAX, f64::min);
        let (div, prefix) = si_prefix(hi.abs().max(lo.abs()));
        let pad = 0.1 * (hi - lo).abs().max(0.05 * hi.abs()).max(f64::MIN_POSITIVE);
        let (y0, y1) = ((lo - pad) / div, (hi + pad) / div);
        let axes = LineAxes {
            caption: format!("{name} against the assembly size"),
            caption_size: 24,
            y_label_area: 100,
            x: 0.0..vmax * 1.08,
            y: y0..y1,
            x_desc: "Assembly size V (m^2)".into(),
            y_desc: format!("{name} ({prefix}{unit})"),
        };
        let mut chart = axes.draw(root, path)?;
        let blue = RGBColor(31, 88, 160);
        chart
            .draw_series(points.iter().map(|&(v, f)| Circle::new((v, f / div), 6, blue.filled())))
            .at(path)?
            .label("measured (one two-scale run per size)")
            .legend(move |(x, y)| Circle::new((x + 12, y), 6, blue.filled()));
        if let Some(f) = fit {
            let red = RGBColor(200, 30, 30);
            let v0 = points.iter().map(|p| p.0).fold(f64::MAX, f64::min);
            let law: Vec<(f64, f64)> = (0..=200)
                .map(|i| v0 + (vmax * 1.08 - v0) * f64::from(i) / 200.0)
                .map(|v| (v, f.predict(v) / div))
                .filter(|p| p.1.is_finite() && p.1 >= y0 && p.1 <= y1)
                .collect();
            chart
                .draw_series(LineSeries::new(law, red.stroke_width(2)))
                .at(path)?
                .label(format!(
                    "ln(F/F^cr) = a exp(b* V^{}): a = {}, b* = {}",
                    f.k,
                    sig4(f.a.value),
                    sig4(f.b_star.value)
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(2))
                });
            let rep = f.representative.value / div;
            let grey = RGBColor(90, 90, 90);
            chart
                .draw_series(DashedLineSeries::new(
                    [(0.0, rep), (vmax * 1.08, rep)],
                    8,
                    6,
                    grey.stroke_width(2),
                ))
                .at(path)?
                .label(format!("F^cr = {} {prefix}{unit}", sig4(rep)))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2))
                });
            if let Some(c) = &f.v_cr
                && c.value.is_finite()
                && c.value <= vmax * 1.08
            {
                let green = RGBColor(46, 139, 87);
                chart
                    .draw_series(DashedLineSeries::new(
                        [(c.value, y0), (c.value, y1)],
                        8,
                        6,
                        green.stroke_width(2),
                    ))
                    .at(path)?
                    .label(format!(
                        "V^cr = {} m^2 (within {} %)",
                        sig4(c.value),
                        sig4(100.0 * f.tolerance)
                    ))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], green.stroke_width(2))
                    });
            }
        }
        // The legend goes where the points are not: top right over a property that falls with V,
        // bottom right under one that rises.
        let by_v = |a: &&(f64, f64), b: &&(f64, f64)| a.0.total_cmp(&b.0);
        let falls = match (points.iter().min_by(by_v), points.iter().max_by(by_v)) {
            (Some(first), Some(last)) => first.1 > last.1,
            _ => false,
        };
        let position =
            if falls { SeriesLabelPosition::UpperRight } else { SeriesLabelPosition::LowerRight };
        draw_legend(&mut chart, position, 17, path)
    }
}
