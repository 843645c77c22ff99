use super::{
    Draw, DrawResult, Figure, LineAxes, PlotError, Result, draw_legend, si_prefix, sig4,
    write_figure,
};
use crate::output::io_err;
use cosdem_fem::post::CurveMetrics;
use plotters::prelude::*;
use std::path::Path;

/// The `(displacement, load)` points of a `curve.csv` (columns found by name).
pub fn read_curve(path: &Path) -> Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(path).map_err(io_err(path, "read"))?;
    // A row being written by a running job has no newline yet: leave it out.
    let complete = text.rfind('\n').map_or(text.as_str(), |i| &text[..=i]);
    let mut lines = complete.lines();
    let no = |message: String| PlotError::NoData { path: path.to_path_buf(), message };
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').map(str::trim).collect();
    let col = |name: &str| {
        header.iter().position(|h| *h == name).ok_or_else(|| no(format!("no column {name:?}")))
    };
    let (cd, cl) = (col("displacement")?, col("load")?);
    let mut curve = Vec::new();
    for (i, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |c: usize| -> Result<f64> {
            cells
                .get(c)
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or_else(|| no(format!("row {}: column {c} is not a number: {line:?}", i + 2)))
        };
        curve.push((num(cd)?, num(cl)?));
    }
    Ok(curve)
}

/// The scales of a load-displacement chart: the extremes of its points and the units its axes
/// show them in.
#[derive(Debug, Clone, Copy)]
pub struct LoadScales {
    /// The largest displacement (at least 1e-12).
    pub dmax: f64,
    /// The largest load (at least 0).
    pub fmax: f64,
    /// The smallest load (at most 0).
    pub fmin: f64,
    /// The divisor of the loads on the axis ([`si_prefix`] of the largest magnitude).
    pub div: f64,
    /// The SI prefix of [`Self::div`].
    pub prefix: &'static str,
    /// The divisor of the displacements on the axis: millimetres below 0.1 m, else metres.
    pub dd: f64,
    /// The SI prefix of [`Self::dd`].
    pub dprefix: &'static str,
}

impl LoadScales {
    /// The scales of the `(displacement, load)` points.
    pub fn of(points: impl Iterator<Item = (f64, f64)> + Clone) -> Self {
        let dmax = points.clone().map(|p| p.0).fold(0.0, f64::max).max(1e-12);
        let fmax = points.clone().map(|p| p.1).fold(0.0, f64::max);
        let fmin = points.map(|p| p.1).fold(0.0, f64::min);
        let (div, prefix) = si_prefix(fmax.abs().max(fmin.abs()));
        let (dd, dprefix) = if dmax < 0.1 { (1e-3, "m") } else { (1.0, "") };
        Self { dmax, fmax, fmin, div, prefix, dd, dprefix }
    }

    /// Load-displacement axes with `caption` (of `caption_size`) and the load range `y`
    /// (already divided by [`Self::div`]): displacement from 0 to 4 % past the largest.
    pub fn axes(&self, caption: String, caption_size: u32, y: std::ops::Range<f64>) -> LineAxes {
        LineAxes {
            caption,
            caption_size,
            y_label_area: 90,
            x: 0.0..self.dmax / self.dd * 1.04,
            y,
            x_desc: format!("Displacement d ({}m)", self.dprefix),
            y_desc: format!("Load F ({}N/m)", self.prefix),
        }
    }
}

/// Fig. 3: load against displacement from the origin through every converged step, with the
/// bearing capacity F_u (peak), the residual capacity F_res (minimum after the peak) and the
/// stiffness E (the secant line through the origin) marked. Loads are per metre of thickness.
pub fn plot_curve(
    curve: &[(f64, f64)],
    metrics: &CurveMetrics,
    title: &str,
    path: &Path,
) -> Result<()> {
    plot_curve_with_labels(curve, metrics, None, title, path)
}

/// An axis description from a quantity label `"NAME (UNIT)"` with the axis' SI `prefix`:
/// `"NAME (PREFIXUNIT)"` (`"uy of top (m)"` with `m` gives `"uy of top (mm)"`).
fn axis_label(label: &str, prefix: &str) -> String {
    match label.rsplit_once(" (") {
        Some((name, unit)) => format!("{name} ({prefix}{}", unit),
        None => label.to_string(),
    }
}

/// [`plot_curve`] with the axes of `[output.curve]`: `labels = [abscissa, ordinate]` as
/// `summary.json`'s `curve_labels` (`"-1 × uy of footing (m)"`); `None`: the compression's
/// "Displacement d" and "Load F". Written as the PNG `path` and the SVG beside it.
pub fn plot_curve_with_labels(
    curve: &[(f64, f64)],
    metrics: &CurveMetrics,
    labels: Option<&[String; 2]>,
    title: &str,
    path: &Path,
) -> Result<()> {
    if curve.is_empty() {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "empty curve".into() });
    }
    let points: Vec<(f64, f64)> =
        std::iter::once((0.0, 0.0)).chain(curve.iter().copied()).collect();
    write_figure(&CurveFigure { points, metrics, labels, title }, path)
}

/// Fig. 3's drawing: the curve's points from the origin, its metrics, axis labels and title.
struct CurveFigure<'c> {
    points: Vec<(f64, f64)>,
    metrics: &'c CurveMetrics,
    labels: Option<&'c [String; 2]>,
    title: &'c str,
}

impl Draw for CurveFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let CurveFigure { points, metrics, labels, title } = self;
        draw_curve(root, points, metrics, *labels, title, path)
    }
}

fn draw_curve<DB: DrawingBackend>(
    root: &Figure<DB>,
    points: &[(f64, f64)],
    metrics: &CurveMetrics,
    labels: Option<&[String; 2]>,
    title: &str,
    path: &Path,
) -> Result<()> {
    let scales = LoadScales::of(points.iter().copied());
    let LoadScales { dmax, fmax, fmin, div, prefix, dd, dprefix } = scales;
    let y1 = (fmax / div) * 1.12;
    let y1 = if y1 > 0.0 { y1 } else { 1.0 };
    let y0 = (fmin / div).min(0.0) * 1.12;

    let heading = if title.is_empty() {
        "Load-displacement curve".to_string()
    } else {
        format!("Load-displacement curve: {title}")
    };
    let mut axes = scales.axes(heading, 24, y0..y1);
    if let Some([x, y]) = labels {
        axes.x_desc = axis_label(x, dprefix);
        axes.y_desc = axis_label(y, prefix);
    }
    let mut chart = axes.draw(root, path)?;

    let scaled = |(d, f): (f64, f64)| (d / dd, f / div);
    let blue = RGBColor(31, 88, 160);
    chart
        .draw_series(LineSeries::new(points.iter().map(|&p| scaled(p)), blue.stroke_width(3)))
        .at(path)?
        .label("computed (converged steps)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], blue.stroke_width(3)));
    chart
        .draw_series(points.iter().skip(1).map(|&p| Circle::new(scaled(p), 3, blue.filled())))
        .at(path)?;

    if let Some(e) = metrics.stiffness {
        // The secant through the origin, drawn up to the peak load.
        let d_end = if e > 0.0 { (metrics.peak_load / e).min(dmax) } else { dmax };
        let green = RGBColor(46, 139, 87);
        chart
            .draw_series(DashedLineSeries::new(
                [scaled((0.0, 0.0)), scaled((d_end, e * d_end))],
                10,
                6,
                green.stroke_width(2),
            ))
            .at(path)?
            .label({
                let (ediv, eprefix) = si_prefix(e);
                format!("E = {} {eprefix}N/m per m (linear range)", sig4(e / ediv))
            })
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], green.stroke_width(2))
            });
    }
    let red = RGBColor(200, 30, 30);
    let peak = scaled((metrics.peak_displacement, metrics.peak_load));
    chart
        .draw_series([Cross::new(peak, 9, red.stroke_width(3))])
        .at(path)?
        .label(format!(
            "{} = {} {prefix}N/m at d = {} {dprefix}m",
            // The last point is the highest: the curve has not passed a peak yet.
            if metrics.residual_load.is_some() { "F_u" } else { "max load (no peak yet)" },
            sig4(metrics.peak_load / div),
            sig4(metrics.peak_displacement / dd)
        ))
        .legend(move |(x, y)| Cross::new((x + 12, y), 7, red.stroke_width(3)));
    chart
        .draw_series(DashedLineSeries::new(
            [(0.0, peak.1), (dmax / dd * 1.04, peak.1)],
            4,
            6,
            red.mix(0.6).stroke_width(1),
        ))
        .at(path)?;
    if let Some(fr) = metrics.residual_load {
        let orange = RGBColor(230, 120, 0);
        chart
            .draw_series(DashedLineSeries::new(
                [(peak.0, fr / div), (dmax / dd * 1.04, fr / div)],
                10,
                6,
                orange.stroke_width(2),
            ))
            .at(path)?
            .label(format!("F_res = {} {prefix}N/m (minimum after the peak)", sig4(fr / div)))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], orange.stroke_width(2))
            });
    }
    draw_legend(&mut chart, SeriesLabelPosition::LowerRight, 18, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::SIZE;

    /// The point counts of the polylines in the curve's blue.
    fn svg_check_polylines(svg: &str) -> Vec<usize> {
        crate::output::plot::svg_check::polylines(svg, "#1F58A0")
    }

    /// A known softening curve is drawn at the figure size with many non-white pixels, and
    /// the blue of the curve is among them.
    #[test]
    fn known_curve_is_drawn() {
        let dir = std::env::temp_dir().join(format!("cosdem-plot-curve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut curve = Vec::new();
        for i in 1..=40 {
            let d = 0.001 * f64::from(i);
            let f = if d <= 0.02 { 1e6 * d } else { 2e4 - 4e5 * (d - 0.02) };
            curve.push((d, f));
        }
        let m = CurveMetrics::from_curve(&curve, 0.01);
        let path = dir.join("curve.png");
        plot_curve(&curve, &m, "test", &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let ink = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(ink > 5_000, "only {ink} non-white pixels");
        assert!(img.pixels().any(|p| p.0 == [31, 88, 160]), "no curve colour");
        // The SVG beside it: the same curve as one polyline through the origin and every
        // point (then the legend's two-point stroke), and its text as elements.
        let svg = crate::output::plot::svg_check::read_beside(&path);
        assert_eq!(svg_check_polylines(&svg), vec![curve.len() + 1, 2]);
        assert!(svg.contains(">\nLoad-displacement curve: test\n</text>"), "no caption");
        let e = plot_curve(&[], &m, "", &dir.join("empty.png")).unwrap_err();
        assert!(e.to_string().contains("empty curve"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A quantity label takes the axis' SI prefix before its unit.
    #[test]
    fn axis_labels_take_the_prefix() {
        assert_eq!(axis_label("-1 × uy of footing (m)", "m"), "-1 × uy of footing (mm)");
        assert_eq!(axis_label("R_y of footing (N/m)", "k"), "R_y of footing (kN/m)");
        assert_eq!(axis_label("plain", "k"), "plain");
    }

    #[test]
    fn reads_curve_csv() {
        let dir = std::env::temp_dir().join(format!("cosdem-read-curve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("curve.csv");
        std::fs::write(&p, "step,load_factor,displacement,load\n1,0.5,0.01,100\n2,1,0.02,150.5\n")
            .unwrap();
        assert_eq!(read_curve(&p).unwrap(), vec![(0.01, 100.0), (0.02, 150.5)]);
        std::fs::write(&p, "step,displacement\n").unwrap();
        assert!(read_curve(&p).unwrap_err().to_string().contains("\"load\""));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
