//! Two outputs of a run, end to end, from one tiny two-scale run (the `dem-one-element`
//! fixture with smaller assemblies, as in `visual_outputs.rs`):
//!
//! - every figure `plot_run` writes as a PNG has its SVG beside it (same name), a whole
//!   document whose load-displacement curve is one polyline through every point of the curve;
//! - `[output] packing_formats = ["yade", "lammps", "vtu"]` writes, beside every particle
//!   snapshot, its discs as `packing_NNNNN.{txt,data,vtu}`, and the YADE and LAMMPS readers
//!   of `cosdem_dem::packing::formats` read the discs back to the bit (the writers print the
//!   shortest decimals that read back as the same `f64`; LAMMPS's diameter `2 r` halves back
//!   exactly).

use cosdem_app::output::plot::{plot_run, svg_path};
use cosdem_app::output::read_pvd;
use cosdem_app::output::snapshots::{read_snapshot, snapshot_packing};
use cosdem_app::output::vtu_read::read_vtu;
use cosdem_app::run::{Ending, Run};
use cosdem_dem::packing::formats::{OutputFormat, PackingFormat, ReadOptions, read};
use cosdem_job::{Job, MaterialSection, fixtures};
use std::path::Path;

/// The `dem-one-element` fixture (one Q8 element, 4 hexagonal assemblies, 2 steps of 2 mm)
/// with assemblies of side 0.05 m, a snapshot series of point 3, no VTK fields, field data
/// at 2 mm and the three packing formats.
fn dem_job() -> Job {
    let mut job = fixtures::load("dem-one-element");
    job.title = "tiny two-scale panel".into();
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.05;
    job.output.vtk_every = 0;
    job.output.snapshots = vec![[0, 3]];
    job.output.field_plots_at = vec![0.002];
    job.output.packing_formats = vec![OutputFormat::Yade, OutputFormat::Lammps, OutputFormat::Vtu];
    job.validate().unwrap();
    job
}

/// The SVG beside `png`, checked to be a whole document (starts with `<svg`, ends with
/// `</svg>`, every `<text>` closed).
fn svg_beside(png: &Path) -> String {
    let svg = svg_path(png);
    assert_eq!(svg, png.with_extension("svg"));
    let text = std::fs::read_to_string(&svg).unwrap_or_else(|e| panic!("{svg:?}: {e}"));
    assert!(text.starts_with("<svg"), "{svg:?}");
    assert!(text.trim_end().ends_with("</svg>"), "{svg:?} is not closed");
    assert_eq!(text.matches("<text").count(), text.matches("</text>").count(), "{svg:?}");
    assert!(text.contains("font-family=\"sans-serif\""), "{svg:?}: no text in the font family");
    text
}

/// The point counts of the `<polyline>`s of `svg` stroked in `colour` (`#RRGGBB`).
fn polylines(svg: &str, colour: &str) -> Vec<usize> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&format!("stroke=\"{colour}\"")))
        .filter_map(|l| l.split("points=\"").nth(1)?.split('"').next())
        .map(|p| p.split_whitespace().count())
        .collect()
}

#[test]
fn figures_have_svgs_and_snapshots_have_packings() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("figures_svg_and_packings");
    let _ = std::fs::remove_dir_all(&dir);
    let job = dem_job();
    let outcome = Run::new(&job, &dir).snapshots(true).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);

    // Figures: every PNG has its SVG.
    let report = plot_run(&dir).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    assert_eq!(report.written.len(), 7);
    for png in &report.written {
        assert!(png.extension().is_some_and(|e| e == "png"), "{png:?}");
        svg_beside(png);
    }
    // The curve: one polyline in the curve's blue through the origin and every step, then
    // the legend's two-point stroke.
    let svg = svg_beside(&dir.join("plots/load_displacement.png"));
    let rows = std::fs::read_to_string(dir.join("curve.csv")).unwrap().lines().count() - 1;
    assert_eq!(rows, 2);
    assert_eq!(polylines(&svg, "#1F58A0"), vec![rows + 1, 2]);

    // Packings: beside each snapshot of the series, in the three formats.
    let series = dir.join("snapshots/e0_p3");
    let pvd = read_pvd(&dir.join("snapshots/e0_p3.pvd")).unwrap();
    assert_eq!(pvd.len(), 2);
    let density = match &job.material {
        MaterialSection::Dem { assembly } => assembly.density,
        MaterialSection::Elastic { .. } => unreachable!(),
    };
    let opt = ReadOptions { density, periodic: false };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for step in [1u64, 2] {
        let snap = read_snapshot(&series.join(format!("snap_{step:05}.vtu"))).unwrap();
        let p = snapshot_packing(&snap);
        // The region is the discs' bounding box, from the origin.
        let lo = |k: usize| snap.centres.iter().zip(&snap.radius).map(move |(c, r)| c[k] - r);
        let (x0, y0) = (lo(0).fold(f64::MAX, f64::min), lo(1).fold(f64::MAX, f64::min));
        for (k, c) in snap.centres.iter().enumerate() {
            assert_eq!((p.x[k], p.y[k]), (c[0] - x0, c[1] - y0));
        }
        for (format, read_as) in [
            (OutputFormat::Yade, PackingFormat::Yade),
            (OutputFormat::Lammps, PackingFormat::Lammps),
        ] {
            let file = series.join(format!("packing_{step:05}.{}", format.extension()));
            let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file:?}: {e}"));
            let q = read(&text, read_as, &file.display().to_string(), &opt).unwrap();
            assert_eq!(bits(&q.x), bits(&p.x), "{file:?}");
            assert_eq!(bits(&q.y), bits(&p.y), "{file:?}");
            assert_eq!(bits(&q.r), bits(&snap.radius), "{file:?}");
            assert_eq!((q.lx.to_bits(), q.ly.to_bits()), (p.lx.to_bits(), p.ly.to_bits()));
        }
        let vtu = read_vtu(&series.join(format!("packing_{step:05}.vtu"))).unwrap();
        let xy: Vec<(f64, f64)> = vtu.points.iter().map(|c| (c[0], c[1])).collect();
        assert_eq!(xy, p.x.iter().copied().zip(p.y.iter().copied()).collect::<Vec<_>>());
        assert_eq!(vtu.point_array("radius").unwrap().values, snap.radius);
    }
    // Nothing else in the series directory: two snapshots, three packing files each.
    assert_eq!(std::fs::read_dir(&series).unwrap().count(), 2 * 4);
}

/// An unknown format and a format named twice are refused naming the key and the value.
#[test]
fn unknown_packing_formats_are_refused_naming_the_key() {
    let base = fixtures::text("dem-one-element");
    let with = |list: &str| format!("{base}\n[output]\npacking_formats = {list}\n");
    let job = Job::from_toml(&with("[\"lammps\", \"yade\"]"), "j.toml").unwrap();
    assert_eq!(job.output.packing_formats, [OutputFormat::Lammps, OutputFormat::Yade]);
    assert!(Job::from_toml(&base, "j.toml").unwrap().output.packing_formats.is_empty());
    let e = Job::from_toml(&with("[\"yade\", \"xyz\"]"), "j.toml").unwrap_err().to_string();
    assert!(e.contains("`output.packing_formats[1]`") && e.contains("\"xyz\""), "{e}");
    assert!(e.contains("yade, lammps or vtu"), "{e}");
    let e = Job::from_toml(&with("[\"vtu\", \"vtu\"]"), "j.toml").unwrap_err().to_string();
    assert!(e.contains("`output.packing_formats[1]`") && e.contains("twice"), "{e}");
}
