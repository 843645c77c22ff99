//! The Pareto plot of a speed/accuracy sweep (`cosdem bench tradeoff`): one panel per cost
//! (wall time, DEM steps), cost on a log x axis, the worst relative error in percent on a log
//! y axis, every row a labelled point and the Pareto front joined by a line.
//!
//! The figure takes plain data ([`ParetoPanel`]); `crate::tradeoff` turns a sweep's rows
//! into panels. Labels are placed by [`place_labels`], a greedy search for a free spot next to
//! each point (sweeps put many points on top of each other: settings that change nothing).

use cosdem_app::output::plot::{Draw, DrawResult, FONT, Figure, PlotError, Result, write_figure};
use plotters::prelude::*;
use std::path::Path;

/// What a point is, for its marker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointRole {
    /// The tight reference run (error 0 by definition).
    Reference,
    /// The job as given.
    Default,
    /// Any other finished setting.
    Other,
    /// A run that stopped before its end (grey; never on the front).
    Failed,
}

/// One row of the sweep in one panel.
#[derive(Clone, Debug, PartialEq)]
pub struct ParetoPoint {
    /// `knob=setting`.
    pub label: String,
    /// The cost (s, or DEM steps); points with a cost <= 0 are left out (log axis).
    pub x: f64,
    /// Worst relative error (fraction); `None`: not drawn.
    pub error: Option<f64>,
    /// Marker.
    pub role: PointRole,
}

/// One panel: a cost axis, the points and which of them form the Pareto front.
#[derive(Clone, Debug, PartialEq)]
pub struct ParetoPanel {
    /// The x-axis title (`Wall time (s)`, `DEM steps`).
    pub x_label: String,
    /// Every row of the sweep.
    pub points: Vec<ParetoPoint>,
    /// Indices into `points` of the front (any order).
    pub front: Vec<usize>,
}

/// Size of one panel in pixels (the figure is panels side by side).
pub const PANEL: (u32, u32) = (1000, 800);

/// An axis-aligned box `(x, y, w, h)` in pixels.
type Rect = (i32, i32, i32, i32);

fn overlap(a: Rect, b: Rect) -> i64 {
    let w = (a.0 + a.2).min(b.0 + b.2) - a.0.max(b.0);
    let h = (a.1 + a.3).min(b.1 + b.3) - a.1.max(b.1);
    if w > 0 && h > 0 { i64::from(w) * i64::from(h) } else { 0 }
}

/// Top-left corners for labels of `sizes` (w, h) next to `anchors` (pixels), inside `bounds`
/// (x0, y0, x1, y1), greedily in the given order: the first of a list of candidate spots
/// (right of the point, left, then stepping up and down on both sides) that overlaps neither
/// an earlier label nor any point's marker (`marker` px around each anchor); failing that, the
/// candidate with the least overlap. Pure, so it is tested without drawing.
pub fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(u32, u32)],
    bounds: (i32, i32, i32, i32),
    marker: i32,
) -> Vec<(i32, i32)> {
    let markers: Vec<Rect> =
        anchors.iter().map(|&(x, y)| (x - marker, y - marker, 2 * marker, 2 * marker)).collect();
    let mut placed: Vec<Rect> = Vec::new();
    let mut out = Vec::new();
    for (&(ax, ay), &(w, h)) in anchors.iter().zip(sizes) {
        let (w, h) = (w as i32, h as i32);
        let gap = marker + 4;
        let mut candidates = Vec::new();
        for k in 0..16 {
            for dy in if k == 0 { vec![0] } else { vec![-k, k] } {
                let y = ay - h / 2 + dy * (h + 2);
                candidates.push((ax + gap, y));
                candidates.push((ax - gap - w, y));
            }
        }
        let inside = |&(x, y): &(i32, i32)| {
            x >= bounds.0 && y >= bounds.1 && x + w <= bounds.2 && y + h <= bounds.3
        };
        let cost = |&(x, y): &(i32, i32)| {
            let r = (x, y, w, h);
            let labels: i64 = placed.iter().map(|&p| overlap(r, p)).sum();
            let points: i64 = markers.iter().map(|&m| overlap(r, m)).sum();
            labels + points
        };
        let inside_candidates: Vec<(i32, i32)> =
            candidates.iter().copied().filter(inside).collect();
        let pool = if inside_candidates.is_empty() { &candidates } else { &inside_candidates };
        let best = pool
            .iter()
            .copied()
            .find(|c| cost(c) == 0)
            .or_else(|| pool.iter().copied().min_by_key(cost))
            .unwrap_or((ax + gap, ay - h / 2));
        placed.push((best.0, best.1, w, h));
        out.push(best);
    }
    out
}

/// Log-axis range around positive values `v` (a factor `pad` beyond both ends); `fallback`
/// when there is none.
fn log_range(v: impl Iterator<Item = f64>, pad: f64, fallback: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    if hi <= 0.0 {
        return fallback;
    }
    let (lo, hi) = if hi / lo < 10.0 { (lo / 2.0, hi * 2.0) } else { (lo, hi) };
    (lo / pad, hi * pad)
}

/// A tick value without trailing noise (`0.1`, `3`, `2e5`).
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A log-axis tick label at 1, 2 and 5 times a power of ten, none elsewhere (plotters puts a
/// tick at every integer multiple, and their labels run into each other).
fn decade_tick(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let m = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|k| (m - k).abs() < 1e-6 * k) {
        tick(v)
    } else {
        String::new()
    }
}

/// Draws the panels side by side into `path` (PNG, and the same as SVG beside it) under
/// `title`. Errors of 0 (the
/// reference) cannot sit on a log axis: they are drawn on the axis floor and say so in the
/// legend.
pub fn plot_pareto(panels: &[ParetoPanel], title: &str, path: &Path) -> Result<()> {
    if panels.iter().all(|p| p.points.is_empty()) {
        return Err(PlotError::NoData { path: path.to_path_buf(), message: "no rows".into() });
    }
    write_figure(&ParetoFigure { panels, title }, path)
}

/// The Pareto figure's drawing: its panels side by side under the title.
struct ParetoFigure<'p> {
    panels: &'p [ParetoPanel],
    title: &'p str,
}

impl Draw for ParetoFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (PANEL.0 * self.panels.len().max(1) as u32, PANEL.1)
    }

    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()> {
        let root = root.titled(self.title, (FONT, 26)).at(path)?;
        let areas = root.split_evenly((1, self.panels.len().max(1)));
        for (panel, area) in self.panels.iter().zip(&areas) {
            draw_panel(panel, area, path)?;
        }
        Ok(())
    }
}

fn draw_panel<DB: DrawingBackend>(
    panel: &ParetoPanel,
    area: &Figure<DB>,
    path: &Path,
) -> Result<()> {
    // Percent; zero errors go to the floor.
    let pct = |p: &ParetoPoint| p.error.map(|e| 100.0 * e);
    let drawable: Vec<usize> = (0..panel.points.len())
        .filter(|&i| {
            let p = &panel.points[i];
            p.x.is_finite() && p.x > 0.0 && pct(p).is_some_and(|e| e.is_finite() && e >= 0.0)
        })
        .collect();
    let (x0, x1) = log_range(drawable.iter().map(|&i| panel.points[i].x), 1.6, (0.1, 10.0));
    let (y0, y1) =
        log_range(drawable.iter().filter_map(|&i| pct(&panel.points[i])), 2.0, (1e-3, 100.0));
    // Room above the highest point for the legend (upper right); the lower ends down to a
    // power of ten, where plotters starts its log-axis ticks.
    let y1 = y1 * 4.0;
    let decade = |v: f64| {
        let d = 10f64.powf(v.log10().floor());
        if v / d < 3.0 { d } else { v }
    };
    let (x0, y0) = (decade(x0), decade(y0));
    let floor = y0 * 1.6;
    let y_of = |p: &ParetoPoint| pct(p).map(|e| if e > 0.0 { e } else { floor });

    let mut chart = ChartBuilder::on(area)
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .at(path)?;
    chart
        .configure_mesh()
        .x_desc(format!("{} (log)", panel.x_label))
        .y_desc("Worst error against the reference (%, log)")
        .x_label_formatter(&|v: &f64| decade_tick(*v))
        .y_label_formatter(&|v: &f64| decade_tick(*v))
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .light_line_style(BLACK.mix(0.04))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .at(path)?;

    let red = RGBColor(200, 30, 30);
    let blue = RGBColor(31, 88, 160);
    let green = RGBColor(46, 139, 87);
    let orange = RGBColor(230, 120, 0);
    let grey = RGBColor(140, 140, 140);

    // The front, joined in order of cost.
    let mut front: Vec<(f64, f64)> = panel
        .front
        .iter()
        .filter(|i| drawable.contains(i))
        .filter_map(|&i| y_of(&panel.points[i]).map(|y| (panel.points[i].x, y)))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(front.iter().copied(), red.stroke_width(2)))
        .at(path)?
        .label("Pareto front (no row both cheaper and more accurate)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(2)));

    let of_role = |role: PointRole| -> Vec<(f64, f64, bool)> {
        drawable
            .iter()
            .filter(|&&i| panel.points[i].role == role)
            .filter_map(|&i| {
                let p = &panel.points[i];
                y_of(p).map(|y| (p.x, y, panel.front.contains(&i)))
            })
            .collect()
    };
    let others = of_role(PointRole::Other);
    chart
        .draw_series(
            others
                .iter()
                .filter(|p| !p.2)
                .map(|&(x, y, _)| Circle::new((x, y), 6, blue.stroke_width(2))),
        )
        .at(path)?
        .label("setting (one knob moved)")
        .legend(move |(x, y)| Circle::new((x + 12, y), 6, blue.stroke_width(2)));
    chart
        .draw_series(
            others.iter().filter(|p| p.2).map(|&(x, y, _)| Circle::new((x, y), 6, red.filled())),
        )
        .at(path)?
        .label("setting on the front")
        .legend(move |(x, y)| Circle::new((x + 12, y), 6, red.filled()));
    chart
        .draw_series(
            of_role(PointRole::Default)
                .into_iter()
                .map(|(x, y, _)| TriangleMarker::new((x, y), 10, orange.filled())),
        )
        .at(path)?
        .label("default: the job as given")
        .legend(move |(x, y)| TriangleMarker::new((x + 12, y), 9, orange.filled()));
    chart
        .draw_series(of_role(PointRole::Reference).into_iter().map(|(x, y, _)| {
            Rectangle::new([(x / 1.06, y / 1.12), (x * 1.06, y * 1.12)], green.filled())
        }))
        .at(path)?
        .label("reference: tight settings (error 0, drawn on the floor)")
        .legend(move |(x, y)| Rectangle::new([(x + 6, y - 6), (x + 18, y + 6)], green.filled()));
    chart
        .draw_series(
            of_role(PointRole::Failed)
                .into_iter()
                .map(|(x, y, _)| Cross::new((x, y), 8, grey.stroke_width(3))),
        )
        .at(path)?
        .label("failed run (errors on what it reached)")
        .legend(move |(x, y)| Cross::new((x + 12, y), 7, grey.stroke_width(3)));

    // Labels: placed in pixels, lowest error first (the front's end of the plot).
    let style = TextStyle::from((FONT, 16).into_font());
    let mut order: Vec<usize> = drawable.clone();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (&panel.points[a], &panel.points[b]);
        (y_of(pa).unwrap_or(0.0), pa.x)
            .partial_cmp(&(y_of(pb).unwrap_or(0.0), pb.x))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let anchors: Vec<(i32, i32)> = order
        .iter()
        .map(|&i| {
            let p = &panel.points[i];
            chart.backend_coord(&(p.x, y_of(p).unwrap_or(floor)))
        })
        .collect();
    let sizes: Vec<(u32, u32)> = order
        .iter()
        .map(|&i| area.estimate_text_size(&panel.points[i].label, &style).unwrap_or((120, 16)))
        .collect();
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let spots = place_labels(&anchors, &sizes, (xr.start, yr.start, xr.end, yr.end), 7);
    let (ox, oy) = area.get_base_pixel();
    for ((&i, &(ax, ay)), (&(lx, ly), &(w, h))) in
        order.iter().zip(&anchors).zip(spots.iter().zip(&sizes))
    {
        let (w, h) = (w as i32, h as i32);
        // A leader line when the label had to move away from its point.
        let (cx, cy) = (if lx > ax { lx } else { lx + w }, ly + h / 2);
        if (cy - ay).abs() > h {
            area.draw(&PathElement::new(
                vec![(ax - ox, ay - oy), (cx - ox, cy - oy)],
                BLACK.mix(0.35).stroke_width(1),
            ))
            .at(path)?;
        }
        area.draw(&Text::new(panel.points[i].label.clone(), (lx - ox, ly - oy), style.clone()))
            .at(path)?;
    }

    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 16))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .at(path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ten labels on one point get ten spots that do not overlap each other.
    #[test]
    fn stacked_points_get_separate_labels() {
        let anchors = vec![(500, 400); 10];
        let sizes = vec![(150, 16); 10];
        let spots = place_labels(&anchors, &sizes, (0, 0, 1000, 800), 7);
        for i in 0..spots.len() {
            for j in 0..i {
                let a = (spots[i].0, spots[i].1, 150, 16);
                let b = (spots[j].0, spots[j].1, 150, 16);
                assert_eq!(overlap(a, b), 0, "labels {i} and {j} overlap: {spots:?}");
            }
            assert!(spots[i].0 >= 0 && spots[i].0 + 150 <= 1000, "{spots:?}");
        }
        // A free point's label goes right beside it, vertically centred.
        assert_eq!(place_labels(&[(100, 100)], &[(50, 10)], (0, 0, 1000, 800), 7), vec![(111, 95)]);
        // At the right edge it goes to the left.
        assert_eq!(place_labels(&[(990, 100)], &[(50, 10)], (0, 0, 1000, 800), 7), vec![(929, 95)]);
    }

    #[test]
    fn ticks_and_ranges() {
        assert_eq!(tick(0.1), "0.1");
        assert_eq!(tick(3.0), "3");
        assert_eq!(tick(2e5), "2e5");
        assert_eq!(tick(2e4), "2e4");
        assert_eq!(decade_tick(2e4), "2e4");
        assert_eq!(decade_tick(3e4), "");
        assert_eq!(decade_tick(0.5), "0.5");
        assert_eq!(decade_tick(100.0), "100");
        let (lo, hi) = log_range([0.5, 2.0].into_iter(), 1.0, (1.0, 2.0));
        assert!((lo - 0.25).abs() < 1e-12 && (hi - 4.0).abs() < 1e-12);
        assert_eq!(log_range([0.0, -1.0].into_iter(), 1.0, (1.0, 2.0)), (1.0, 2.0));
    }

    /// A panel with every role, zero errors and a missing one is drawn.
    #[test]
    fn panel_with_every_role_is_drawn() {
        let p = |label: &str, x: f64, e: Option<f64>, role| ParetoPoint {
            label: label.into(),
            x,
            error: e,
            role,
        };
        let panel = ParetoPanel {
            x_label: "Wall time (s)".into(),
            points: vec![
                p("reference (tight)", 3.6, Some(0.0), PointRole::Reference),
                p("default", 0.5, Some(0.002), PointRole::Default),
                p("load_step=x4", 0.18, Some(0.003), PointRole::Other),
                p("safety=0.95 (failed)", 63.0, Some(0.65), PointRole::Failed),
                p("nothing", 1.0, None, PointRole::Other),
            ],
            front: vec![0, 1, 2],
        };
        let dir = std::env::temp_dir().join(format!("cosdem-pareto-panel-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.png");
        plot_pareto(&[panel.clone(), panel], "test", &path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (2 * PANEL.0, PANEL.1));
        assert!(img.pixels().any(|p| p.0 == [200, 30, 30]), "no front colour");
        assert!(img.pixels().any(|p| p.0 == [46, 139, 87]), "no reference colour");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
