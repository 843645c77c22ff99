//! The run directory of a general boundary-value job (no `[loading.compression]`): an elastic
//! 1 x 1 m panel of 2 x 2 Q8 whose top is pushed down by `[[loading.prescribed]]` u_y on `top`
//! (bottom held), with `[output.curve]` (control: u_y of `top` times -1, load: R_y of `top`
//! times -1, extra reactions of `bottom` and `top`) and binary VTK. Checked: the curve's
//! displacement is the prescribed one (exactly, every top node is prescribed), positive and
//! increasing; the elastic curve is a straight line through the origin, so E equals the secant
//! (1e-9 relative: a least-squares slope of exact multiples) and the summary says there is no
//! peak and why E50 is absent; the `.pvd` timesteps are the displacements, strictly increasing;
//! the bottom's and top's vertical reactions balance (1e-9 relative: equilibrium of a converged
//! linear solve); the binary `.vtu` files read back with the ids and the nodal stress.
//! Without `[output.curve]` the same job's `.pvd` timesteps are the pseudo-time.

use cosdem_app::output::read_pvd;
use cosdem_app::output::vtu_read::read_vtu;
use cosdem_app::run::{Ending, Run};
use cosdem_job::{Job, fixtures};
use std::path::{Path, PathBuf};

/// The elastic panel pushed down by `settlement` on top in 4 steps, bottom held, no
/// compression; `extra` appended to the job file.
fn footing_job(settlement: f64, extra: &str) -> Job {
    let text = fixtures::text("elastic-panel").replace(
        "[loading.compression]\ndisplacement = 0.01\n",
        &format!(
            "[[loading.prescribed]]\nset = \"top\"\ncomponent = \"uy\"\nvalue = {}\n\n\
             [[loading.prescribed]]\nset = \"bottom\"\ncomponent = \"uy\"\nvalue = 0.0\n\n\
             [[loading.prescribed]]\nset = \"bottom\"\ncomponent = \"ux\"\nvalue = 0.0\n",
            -settlement
        ),
    );
    assert!(!text.contains("compression"), "the fixture changed: {text}");
    Job::from_toml(&format!("{text}\n{extra}"), "test").unwrap()
}

fn run(job: &Job, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let outcome = Run::new(job, &dir).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    dir
}

fn rows(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let csv = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    (header, rows)
}

fn timesteps(pvd: &Path) -> Vec<f64> {
    read_pvd(pvd).unwrap().iter().map(|d| d.timestep).collect()
}

#[test]
fn a_prescribed_settlement_gets_its_curve_metrics_and_times() {
    let job = footing_job(
        0.004,
        "[output]\nvtk_format = \"binary\"\n\n[output.curve]\n\
         control = { set = \"top\", component = \"uy\", scale = -1 }\n\
         load = { set = \"top\", component = \"uy\", scale = -1 }\n\
         reactions = [\"bottom\", \"top\"]\n",
    );
    let dir = run(&job, "run_curve_settlement");
    let (header, rows) = rows(&dir);
    assert_eq!(
        header[8..],
        ["time", "R_x:bottom", "R_y:bottom", "R_x:top", "R_y:top"],
        "{header:?}"
    );
    assert_eq!(rows.len(), 4);
    let mut last = 0.0;
    for (i, r) in rows.iter().enumerate() {
        let (d, f) = (r[2], r[3]);
        let expect = 0.001 * (i + 1) as f64;
        assert!((d - expect).abs() < 1e-15, "step {}: displacement {d}, expected {expect}", i + 1);
        assert!(d > last && f > 0.0, "step {}: d = {d}, load = {f}", i + 1);
        last = d;
        assert_eq!(r[8], r[1], "one stage: time = load factor");
        assert_eq!(f, -r[12], "the load is -R_y of top");
        assert!((r[10] + r[12]).abs() <= 1e-9 * f, "R_y bottom {} + top {} != 0", r[10], r[12]);
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let (d, f) = (rows[3][2], rows[3][3]);
    let e = summary["metrics"]["stiffness"].as_f64().unwrap();
    assert!((e - f / d).abs() <= 1e-9 * f / d, "E = {e}, secant {}", f / d);
    assert!(summary["metrics"]["stiffness_50"].is_null(), "{summary}");
    let notes = &summary["curve_notes"];
    assert_eq!(notes["peak_reached"], false, "{summary}");
    assert!(notes["no_peak"].as_str().unwrap().contains("has not fallen"), "{summary}");
    assert!(notes["no_stiffness_50"].as_str().is_some(), "{summary}");
    assert_eq!(summary["pvd_time"], "displacement");
    assert_eq!(summary["curve_labels"][0], "-1 × uy of top (m)");
    for pvd in ["fields.pvd", "gauss.pvd"] {
        let t = timesteps(&dir.join(pvd));
        let d: Vec<f64> = rows.iter().map(|r| r[2]).collect();
        assert_eq!(t, d, "{pvd}");
    }
    let gauss = read_vtu(&dir.join("vtk/gauss_00004.vtu")).unwrap();
    let ids = gauss.point_array("element_id").unwrap();
    let per = ids.values.len() / 4; // 2 x 2 elements, element-major
    assert!(ids.int32 && per > 0 && ids.values.len() == 4 * per, "{ids:?}");
    for (k, &e) in ids.values.iter().enumerate() {
        assert_eq!(e, (k / per) as f64, "point {k}");
    }
    let points = gauss.point_array("gauss_point_id").unwrap();
    assert!(points.values.iter().enumerate().all(|(k, &p)| p == (k % per) as f64));
    let mesh = read_vtu(&dir.join("vtk/mesh_00004.vtu")).unwrap();
    let stress = mesh.point_array("stress").unwrap();
    assert_eq!(stress.values.len(), 4 * mesh.points.len());
    // Pushed down: compressive vertical stress everywhere (nodal averages of negative values).
    assert!(stress.values.chunks(4).all(|s| s[1] < 0.0), "{stress:?}");
    let text = std::fs::read_to_string(dir.join("vtk/mesh_00004.vtu")).unwrap();
    assert!(text.contains("compressor=\"vtkZLibDataCompressor\""));
}

#[test]
fn without_a_curve_the_pvd_times_are_the_pseudo_time() {
    let dir = run(&footing_job(0.004, ""), "run_curve_pseudo_time");
    let (header, rows) = rows(&dir);
    assert_eq!(header.len(), 9, "{header:?}");
    let times = timesteps(&dir.join("fields.pvd"));
    assert_eq!(times, [0.25, 0.5, 0.75, 1.0]);
    assert_eq!(rows.iter().map(|r| r[8]).collect::<Vec<_>>(), times);
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(summary.contains("\"pvd_time\": \"pseudo-time\""), "{summary}");
}
