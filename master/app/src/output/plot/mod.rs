//! Figures of a run, drawn from what the run directory holds (so `cosdem plot RUN` can
//! redraw them at any time), each as a PNG and, beside it with the same name, as an SVG:
//!
//! | file in `RUN/plots/` | from | paper |
//! |---|---|---|
//! | `load_displacement.png` | `curve.csv`, `summary.json` | Fig. 3 |
//! | `equivalent_strain_NNNNN.png` | `fields/field_NNNNN.json` | Fig. 9 |
//! | `force_chains_eE_pP_NNNNN.png` | `snapshots/eE_pP/snap_NNNNN.vtu` | Figs. 10-11 |
//! | `fluctuations_eE_pP_NNNNN.png` | the same snapshot | Fig. 12 |
//!
//! The Pareto plot of a speed/accuracy sweep (`cosdem bench tradeoff`, written beside its
//! `tradeoff.csv`) is [`pareto::plot_pareto`].
//!
//! Each figure is a pure function of its input data ([`curve::plot_curve`],
//! [`field::plot_strain_field`], [`particles::plot_force_chains`],
//! [`particles::plot_fluctuations`]); [`plot_run`] finds the inputs in a run directory.
//! The line figures (here and in the RVE-size study's) share their page
//! ([`blank_figure`](crate::output::plot::blank_figure)), axes
//! ([`LineAxes`](crate::output::plot::LineAxes)) and legend box
//! ([`draw_legend`](crate::output::plot::draw_legend)).
//! Every figure is one drawing ([`Draw`], generic over plotters' backends) that
//! [`write_figure`] sends through the bitmap backend (the PNG) and the SVG backend (the
//! `.svg` beside it, [`svg_path`]). The bitmap's text is rendered with a font embedded in the
//! crate (a subset of DejaVu Sans, `assets/fonts`), so no system font library is needed; the
//! SVG holds its text as `<text>` elements of the generic family `sans-serif` (the embedded
//! font only measures them, for the layout), so it needs no font file either.

/// Fig. 3: the load-displacement curve.
pub mod curve;
/// Fig. 9: the equivalent-strain field over the mesh.
pub mod field;
/// Figs. 10-12: force chains and fluctuation arrows of one assembly.
pub mod particles;

use super::OutputError;
use super::field_data::FieldData;
use super::pvd::read_pvd;
use super::snapshots::read_snapshot;
use cosdem_fem::post::CurveMetrics;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Why a figure could not be drawn. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Reading an input file failed (missing, unreadable, malformed).
    #[error(transparent)]
    Input(#[from] OutputError),
    /// An input holds nothing to draw, or something that cannot be drawn.
    #[error("{}: {message}", path.display())]
    NoData {
        /// The input (or figure) concerned.
        path: PathBuf,
        /// What is missing.
        message: String,
    },
    /// plotters failed to draw or encode the PNG.
    #[error("{}: drawing failed: {message}", path.display())]
    Draw {
        /// The figure.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
}

/// Result of the plotting functions.
pub type Result<T> = std::result::Result<T, PlotError>;

/// The font family every figure uses, registered from the embedded font.
pub const FONT: &str = "sans-serif";

static FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");

/// Registers the embedded font with plotters (once per process). Called by every figure;
/// public for other plotting code of the crate's users.
pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is compiled in and parsed by the tests: registration cannot fail.
        let _ =
            plotters::style::register_font(FONT, plotters::style::FontStyle::Normal, FONT_BYTES);
    });
}

/// Turns a drawing failure on `path` into a [`PlotError::Draw`] naming the file.
pub fn draw_err(path: &Path) -> impl Fn(String) -> PlotError + '_ {
    move |message| PlotError::Draw { path: path.to_path_buf(), message }
}

/// Maps plotters' errors (which are generic over the backend) to [`PlotError::Draw`].
pub trait DrawResult<T> {
    /// The error, if any, as a [`PlotError::Draw`] naming `path`.
    fn at(self, path: &Path) -> Result<T>;
}

impl<T, E: std::fmt::Display> DrawResult<T> for std::result::Result<T, E> {
    fn at(self, path: &Path) -> Result<T> {
        self.map_err(|e| draw_err(path)(e.to_string()))
    }
}

/// Figure size in pixels (the SVG's width and height in user units).
pub const SIZE: (u32, u32) = (1000, 750);

/// A whole figure on the backend `DB` (a bitmap for the PNG, an SVG document).
pub type Figure<DB> = DrawingArea<DB, Shift>;

/// A chart with `f64` coordinates on both axes, drawn on a [`Figure`].
pub type XyChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A figure's drawing, written through any plotters backend: the one code behind a figure's
/// PNG and its SVG ([`write_figure`]).
pub trait Draw {
    /// The page size in pixels; [`SIZE`] unless the figure says otherwise.
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    /// Draws the figure on `root`, a white page of [`Draw::size`]; `path` names the file in
    /// errors.
    fn draw<DB: DrawingBackend>(&self, root: &Figure<DB>, path: &Path) -> Result<()>;
}

/// The SVG written beside the PNG `png`: the same name with the extension `svg`.
pub fn svg_path(png: &Path) -> PathBuf {
    png.with_extension("svg")
}

/// Writes `figure` to the PNG `path` and the same drawing to the SVG beside it
/// ([`svg_path`]). A drawing failure names the file it was drawing.
pub fn write_figure(figure: &impl Draw, path: &Path) -> Result<()> {
    register_font();
    let size = figure.size();
    let root = BitMapBackend::new(path, size).into_drawing_area();
    paint(figure, &root, path)?;
    let svg = svg_path(path);
    if svg != path {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        paint(figure, &root, &svg)?;
    }
    Ok(())
}

/// Fills `root` white, draws `figure` on it and writes it out.
fn paint<DB: DrawingBackend>(figure: &impl Draw, root: &Figure<DB>, path: &Path) -> Result<()> {
    root.fill(&WHITE).at(path)?;
    figure.draw(root, path)?;
    root.present().at(path)
}

/// The axes of a line figure (load-displacement curves, a property against a size): a
/// caption, linear `x` and `y` ranges with their descriptions, and a light mesh of the
/// major ticks only.
#[derive(Debug, Clone)]
pub struct LineAxes {
    /// The caption above the chart.
    pub caption: String,
    /// The caption's font size.
    pub caption_size: u32,
    /// The width in pixels of the y labels' area (wide enough for the longest tick label).
    pub y_label_area: u32,
    /// The x range.
    pub x: std::ops::Range<f64>,
    /// The y range.
    pub y: std::ops::Range<f64>,
    /// The x axis' description (quantity and unit).
    pub x_desc: String,
    /// The y axis' description (quantity and unit).
    pub y_desc: String,
}

impl LineAxes {
    /// Draws the caption, the axes and the mesh on `root` (drawn to `path`); returns the chart
    /// to draw the series on.
    pub fn draw<'a, DB: DrawingBackend>(
        &self,
        root: &'a Figure<DB>,
        path: &Path,
    ) -> Result<XyChart<'a, DB>> {
        let mut chart = ChartBuilder::on(root)
            .margin(20)
            .caption(&self.caption, (FONT, self.caption_size))
            .x_label_area_size(60)
            .y_label_area_size(self.y_label_area)
            .build_cartesian_2d(self.x.clone(), self.y.clone())
            .at(path)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_desc)
            .y_desc(&self.y_desc)
            .label_style((FONT, 18))
            .axis_desc_style((FONT, 20))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.1))
            .draw()
            .at(path)?;
        Ok(chart)
    }
}

/// Draws the legend of `chart` (drawn to `path`) at `position` with labels of `font_size`,
/// in a box of translucent white with a grey border.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_size: u32,
    path: &Path,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, font_size))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .at(path)
}

/// What [`plot_run`] did: the figures written and the ones that failed (with why).
#[derive(Debug, Default)]
pub struct PlotReport {
    /// PNG files written (each with its SVG beside it, [`svg_path`]).
    pub written: Vec<PathBuf>,
    /// Figures that could not be drawn, with the reason.
    pub failed: Vec<(String, PlotError)>,
}

/// Draws every figure the run directory `run` has data for into `run/plots/` (PNG and SVG,
/// [`write_figure`]). A figure that fails does not stop the others (see
/// [`PlotReport::failed`]); only a run directory without `curve.csv` or an unwritable
/// `plots/` is an error.
pub fn plot_run(run: &Path) -> Result<PlotReport> {
    let curve_path = run.join("curve.csv");
    if !curve_path.is_file() {
        return Err(PlotError::NoData {
            path: curve_path,
            message: "not a run directory (no curve.csv)".into(),
        });
    }
    let out = run.join("plots");
    std::fs::create_dir_all(&out).map_err(|source| {
        PlotError::Input(OutputError::Io { path: out.clone(), action: "create directory", source })
    })?;
    let mut report = PlotReport::default();
    let mut record = |name: String, r: Result<PathBuf>| match r {
        Ok(p) => report.written.push(p),
        Err(e) => report.failed.push((name, e)),
    };
    let title = read_title(run);

    // Fig. 3.
    let target = out.join("load_displacement.png");
    record(
        "load-displacement curve".into(),
        curve::read_curve(&curve_path).and_then(|c| {
            let m = read_metrics(run).unwrap_or_else(|| CurveMetrics::from_curve(&c, 0.01));
            let labels = read_curve_labels(run);
            curve::plot_curve_with_labels(&c, &m, labels.as_ref(), &title, &target)
                .map(|()| target.clone())
        }),
    );

    // Fig. 9 at every displacement the run kept field data for.
    let fields = sorted_files(&run.join("fields"), "field_", ".json");
    let mut field_steps = Vec::new();
    for f in &fields {
        let step = step_of(f);
        field_steps.push(step);
        let target = out.join(format!("equivalent_strain_{step:05}.png"));
        record(
            format!("equivalent strain, {}", f.display()),
            FieldData::read(f)
                .map_err(PlotError::from)
                .and_then(|d| field::plot_strain_field(&d, &title, &target))
                .map(|()| target.clone()),
        );
    }

    // Figs. 10-12 for every snapshot series: at the field-plot steps, else the last one.
    for pvd in sorted_files(&run.join("snapshots"), "", ".pvd") {
        let series = pvd.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let datasets = match read_pvd(&pvd) {
            Ok(d) => d,
            Err(e) => {
                record(format!("snapshots {}", pvd.display()), Err(e.into()));
                continue;
            }
        };
        let dir = pvd.parent().unwrap_or(Path::new("."));
        let files: Vec<PathBuf> = datasets.iter().map(|d| dir.join(&d.file)).collect();
        let mut chosen: Vec<&PathBuf> =
            files.iter().filter(|f| field_steps.contains(&step_of(f))).collect();
        if chosen.is_empty() {
            chosen.extend(files.last());
        }
        for f in chosen {
            let step = step_of(f);
            let label = gauss_label(&series);
            match read_snapshot(f) {
                Ok(s) => {
                    let target = out.join(format!("force_chains_{series}_{step:05}.png"));
                    record(
                        format!("force chains, {}", f.display()),
                        particles::plot_force_chains(&s, &label, &target).map(|()| target.clone()),
                    );
                    let target = out.join(format!("fluctuations_{series}_{step:05}.png"));
                    record(
                        format!("fluctuations, {}", f.display()),
                        particles::plot_fluctuations(&s, &label, &target).map(|()| target.clone()),
                    );
                }
                Err(e) => record(format!("snapshot {}", f.display()), Err(e.into())),
            }
        }
    }
    Ok(report)
}

/// "Gauss point 3 of element 12" from the series name `e12_p3`.
fn gauss_label(series: &str) -> String {
    let mut parts = series.split('_');
    match (
        parts.next().and_then(|e| e.strip_prefix('e')),
        parts.next().and_then(|p| p.strip_prefix('p')),
    ) {
        (Some(e), Some(p)) => format!("element {e}, Gauss point {p}"),
        _ => series.to_string(),
    }
}

/// The step number in a file name ending in `_NNNNN.ext` (0 if none).
fn step_of(path: &Path) -> u64 {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    stem.rsplit('_').next().and_then(|s| s.parse().ok()).unwrap_or(0)
}

/// Files `prefix*suffix` directly in `dir`, sorted by name (empty if `dir` does not exist).
fn sorted_files(dir: &Path, prefix: &str, suffix: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            p.is_file()
                && name.starts_with(prefix)
                && name.ends_with(suffix)
                && !name.starts_with('.')
        })
        .collect();
    files.sort();
    files
}

fn read_summary(run: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(run.join("summary.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// The job's title from `summary.json` (empty if none).
fn read_title(run: &Path) -> String {
    read_summary(run)
        .and_then(|s| s.get("title").and_then(|t| t.as_str()).map(str::to_string))
        .unwrap_or_default()
}

/// The axis labels of `[output.curve]` (`curve_labels` of `summary.json`), if the run has them.
fn read_curve_labels(run: &Path) -> Option<[String; 2]> {
    serde_json::from_value(read_summary(run)?.get("curve_labels")?.clone()).ok()
}

/// The curve metrics the run itself computed (its linear range), from `summary.json`.
fn read_metrics(run: &Path) -> Option<CurveMetrics> {
    serde_json::from_value(read_summary(run)?.get("metrics")?.clone()).ok()
}

/// A colour map from 0 to 1: viridis (perceptually uniform, readable in grey), by linear
/// interpolation between 9 samples of the reference table.
pub fn viridis(t: f64) -> plotters::style::RGBColor {
    const STOPS: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c = |k: usize| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    plotters::style::RGBColor(c(0), c(1), c(2))
}

/// A value with an SI prefix chosen for `scale` (the largest magnitude to show): returns the
/// divisor and the prefix, e.g. `(1e3, "k")`.
pub fn si_prefix(scale: f64) -> (f64, &'static str) {
    let a = scale.abs();
    if !a.is_finite() || a == 0.0 {
        return (1.0, "");
    }
    for (div, p) in [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ")] {
        if a >= div {
            return (div, p);
        }
    }
    (1e-9, "n")
}

/// `x` with 4 significant digits in plain notation (`227.97` -> `228.0`, `0.0012345` ->
/// `0.001235`); scientific beyond 1e6 or below 1e-4.
pub fn sig4(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 {
        return format!("{x}");
    }
    if !(1e-4..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// Ranges `(x, y)` containing `[x0, x1] x [y0, y1]` with `pad` (fraction) around it and the
/// same scale per pixel on both axes in a plotting area of `px` pixels.
pub fn equal_aspect(
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    pad: f64,
    px: (u32, u32),
) -> ((f64, f64), (f64, f64)) {
    let (w, h) = ((x1 - x0).max(1e-300), (y1 - y0).max(1e-300));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (pw, ph) = (f64::from(px.0.max(1)), f64::from(px.1.max(1)));
    let scale = (w * (1.0 + 2.0 * pad) / pw).max(h * (1.0 + 2.0 * pad) / ph);
    let (hw, hh) = (0.5 * scale * pw, 0.5 * scale * ph);
    ((cx - hw, cx + hw), (cy - hh, cy + hh))
}

/// Checks of the SVG written beside a PNG, for the tests.
#[cfg(test)]
pub(crate) mod svg_check {
    use std::path::Path;

    /// The SVG beside the PNG `png`, checked to be a whole document: it starts with `<svg`,
    /// ends with `</svg>`, and every `<text>` element is closed.
    pub(crate) fn read_beside(png: &Path) -> String {
        let svg = super::svg_path(png);
        let text = std::fs::read_to_string(&svg).unwrap_or_else(|e| panic!("{svg:?}: {e}"));
        assert!(text.starts_with("<svg"), "{svg:?} starts with {:?}", &text[..20.min(text.len())]);
        assert!(text.trim_end().ends_with("</svg>"), "{svg:?} is not closed");
        assert_eq!(text.matches("<svg").count(), 1, "{svg:?}");
        assert_eq!(text.matches("<text").count(), text.matches("</text>").count(), "{svg:?}");
        text
    }

    /// The number of points of each `<polyline>` of `svg` stroked in `colour` (`#RRGGBB`).
    pub(crate) fn polylines(svg: &str, colour: &str) -> Vec<usize> {
        svg.lines()
            .filter(|l| l.starts_with("<polyline") && l.contains(&format!("stroke=\"{colour}\"")))
            .filter_map(|l| l.split("points=\"").nth(1)?.split('"').next())
            .map(|p| p.split_whitespace().count())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_font_parses() {
        assert!(
            plotters::style::register_font(
                "test-font",
                plotters::style::FontStyle::Normal,
                FONT_BYTES
            )
            .is_ok()
        );
    }

    #[test]
    fn helpers() {
        assert_eq!(step_of(Path::new("a/field_00012.json")), 12);
        assert_eq!(step_of(Path::new("snap_00003.vtu")), 3);
        assert_eq!(gauss_label("e12_p3"), "element 12, Gauss point 3");
        assert_eq!(si_prefix(2.5e4), (1e3, "k"));
        assert_eq!(sig4(227.9722), "228.0");
        assert_eq!(sig4(2.53412), "2.534");
        assert_eq!(sig4(-0.00123456), "-0.001235");
        assert_eq!(sig4(5e7), "5.000e7");
        assert_eq!(si_prefix(0.3), (1e-3, "m"));
        assert_eq!(viridis(0.0), plotters::style::RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), plotters::style::RGBColor(253, 231, 37));
        // Equal aspect: a 2 x 1 box in a 400 x 400 area gets a 2-wide, 2-high window.
        let ((a, b), (c, d)) = equal_aspect((0.0, 2.0), (0.0, 1.0), 0.0, (400, 400));
        assert!((b - a - 2.0).abs() < 1e-12 && (d - c - 2.0).abs() < 1e-12);
        assert!((c + 0.5).abs() < 1e-12);
    }
}
