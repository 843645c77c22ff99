//! Figures of the RVE-size study (`cosdem study rve-size`): the load-displacement curves of
//! every size (the paper's Fig. 3) and each property against the assembly size with its
//! fitted size law (Figs. 4-5).

use crate::rve_size::fit::SizeLawFit;
use cosdem_app::output::plot::{
    DrawResult, FONT, PlotError, Result, SIZE, register_font, si_prefix, sig4, viridis,
};
use plotters::prelude::*;
use std::path::Path;

/// Fig. 3 of a study: one load-displacement curve per assembly size `V` (m^2), coloured from
/// the smallest (dark) to the largest (light) size. Loads per metre of thickness.
pub fn plot_study_curves(
    curves: &[(f64, Vec<(f64, f64)>)],
    title: &str,
    path: &Path,
) -> Result<()> {
    register_font();
    let all = || curves.iter().flat_map(|(_, c)| c.iter());
    if all().next().is_none() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "no curve".into() });
    }
    let dmax = all().map(|p| p.0).fold(0.0, f64::max).max(1e-12);
    let fmax = all().map(|p| p.1).fold(0.0, f64::max);
    let fmin = all().map(|p| p.1).fold(0.0, f64::min);
    let (div, prefix) = si_prefix(fmax.abs().max(fmin.abs()));
    let (dd, dprefix) = if dmax < 0.1 { (1e-3, "m") } else { (1.0, "") };
    let y1 = if fmax > 0.0 { fmax / div * 1.08 } else { 1.0 };
    let y0 = (fmin / div).min(0.0) * 1.08;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).at(path)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .caption(format!("Load-displacement per assembly size: {title}"), (FONT, 22))
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..dmax / dd * 1.04, y0..y1)
        .at(path)?;
    chart
        .configure_mesh()
        .x_desc(format!("Displacement d ({dprefix}m)"))
        .y_desc(format!("Load F ({prefix}N/m)"))
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.1))
        .draw()
        .at(path)?;
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 18))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .at(path)?;
    root.present().at(path)?;
    Ok(())
}

/// Figs. 4-5 of a study: one property (`name`, `unit` such as `N/m`) against the assembly size
/// `V`: the measured `points` `(V, value)`, the fitted law `F^cr exp(a exp(b* V^k))` over the
/// measured range, its representative value `F^cr` and `V^cr` when the fit has them.
pub fn plot_size_law(
    points: &[(f64, f64)],
    fit: Option<&SizeLawFit>,
    name: &str,
    unit: &str,
    path: &Path,
) -> Result<()> {
    register_font();
    if points.is_empty() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: format!("no {name}") });
    }
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
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).at(path)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .caption(format!("{name} against the assembly size"), (FONT, 24))
        .x_label_area_size(60)
        .y_label_area_size(100)
        .build_cartesian_2d(0.0..vmax * 1.08, y0..y1)
        .at(path)?;
    chart
        .configure_mesh()
        .x_desc("Assembly size V (m^2)")
        .y_desc(format!("{name} ({prefix}{unit})"))
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.1))
        .draw()
        .at(path)?;
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
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(2)));
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
    chart
        .configure_series_labels()
        .position(if falls {
            SeriesLabelPosition::UpperRight
        } else {
            SeriesLabelPosition::LowerRight
        })
        .label_font((FONT, 17))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .at(path)?;
    root.present().at(path)?;
    Ok(())
}
