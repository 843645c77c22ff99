//! A run directory read back through `cosdem_app::results::RunReader` (what the Python
//! binding hands its users as numpy arrays): small runs of the shared fixtures (the elastic
//! `elastic-panel`, milliseconds; the two-scale `dem-one-element` with small assemblies, a
//! fraction of a second) written by the real run driver, then read back and checked against
//! the files' own text, the job's prescribed displacements and the files present.

use cosdem_app::results::{ResultsError, RunReader};
use cosdem_app::run::Run;
use cosdem_dem::packing::formats::OutputFormat;
use cosdem_job::{Job, MaterialSection, VtkFormat, fixtures};
use std::path::{Path, PathBuf};

/// An empty directory `results_NAME` under the target's temporary directory.
fn fresh(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("results_{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The `elastic-panel` fixture (1 x 1 m, 2 x 2 Q8 with 2 x 2 Gauss points each, 1 cm in 4
/// steps, both platens moving, rough) with VTK every `vtk_every` steps in `format`.
fn elastic_job(vtk_every: usize, format: VtkFormat) -> Job {
    let mut job = fixtures::load("elastic-panel");
    job.output.vtk_every = vtk_every;
    job.output.vtk_format = format;
    job.validate().unwrap();
    job
}

/// Runs `job` into `results_NAME` to its end (or `max_steps`) and returns the directory.
fn run(job: &Job, name: &str, max_steps: Option<u64>) -> PathBuf {
    let dir = fresh(name);
    let outcome = Run::new(job, &dir).snapshots(true).max_steps(max_steps).execute().unwrap();
    let expected = if max_steps.is_some() { "stopped" } else { "finished" };
    assert_eq!(outcome.ending.status(), expected, "{:?}", outcome.ending);
    dir
}

/// The values of the ASCII `<DataArray>` named `name` in a `.vtu`'s text, parsed here (not
/// by the crate's reader) so that the reader is checked against the file itself.
/// `Points` names the unnamed array of `<Points>` (the coordinates, 3 per point).
fn ascii_array(text: &str, name: &str) -> Vec<f64> {
    let marker = if name == "Points" { "<Points>".into() } else { format!("Name=\"{name}\"") };
    let at = text.find(&marker).unwrap_or_else(|| panic!("no {name}"));
    let mut body = &text[at..];
    if name == "Points" {
        body = &body[body.find("<DataArray").unwrap()..];
    }
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.split_whitespace().map(|t| t.parse().unwrap()).collect()
}

/// The names and component counts of arrays, in order.
fn shapes(arrays: &[cosdem_app::results::Array]) -> Vec<(&str, usize)> {
    arrays.iter().map(|a| (a.name.as_str(), a.components)).collect()
}

/// The Gauss-point arrays of every run, in file order, with their component counts.
const GAUSS_ARRAYS: [(&str, usize); 5] = [
    ("strain", 4),
    ("curvature", 2),
    ("stress", 4),
    ("couple_stress", 2),
    ("equivalent_strain", 1),
];

/// A finished elastic run read back: the summary is the file's JSON; the curve has
/// curve.csv's header as its columns, one row per converged step (summary `steps`) and the
/// file's numbers; the saved steps are those of the files in `vtk/` (every second step); the
/// Gauss-point and mesh arrays have one row per Gauss point / node, their values are those of
/// the `.vtu` text, the ids name each (element, point) once, the mesh is the job's; and the
/// last step's nodal displacement on the platens is the one the job prescribes (rough
/// platens, each moving by half the 1 cm: u = (0, -/+ 5 mm, 0)).
#[test]
fn elastic_run_reads_back_as_written() {
    let job = elastic_job(2, VtkFormat::Ascii);
    let dir = run(&job, "elastic", None);
    let reader = RunReader::open(&dir).unwrap();
    assert_eq!(reader.dir(), dir);

    let summary = reader.summary().unwrap();
    let raw: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary, raw, "a finished run's summary is the file's");
    assert_eq!(
        (summary["status"].as_str(), summary["steps"].as_u64()),
        (Some("finished"), Some(4))
    );

    let curve = reader.curve().unwrap();
    let csv = std::fs::read_to_string(dir.join("curve.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let names: Vec<&str> = curve.columns.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, header);
    assert_eq!(curve.rows() as u64, summary["steps"].as_u64().unwrap());
    for (r, line) in lines.enumerate() {
        for ((_, column), v) in curve.columns.iter().zip(line.split(',')) {
            assert_eq!(column[r].to_bits(), v.parse::<f64>().unwrap().to_bits(), "row {r}");
        }
    }
    assert_eq!(curve.column("step").unwrap(), [1.0, 2.0, 3.0, 4.0]);

    let mut files: Vec<String> = std::fs::read_dir(dir.join("vtk"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    assert_eq!(files, ["gauss_00002.vtu", "gauss_00004.vtu", "mesh_00002.vtu", "mesh_00004.vtu"]);
    assert_eq!(reader.saved_steps().unwrap(), [2, 4]);

    let gauss = reader.gauss(4).unwrap();
    let text = std::fs::read_to_string(dir.join("vtk/gauss_00004.vtu")).unwrap();
    assert_eq!(gauss.step, 4);
    assert_eq!(gauss.positions.len(), 16, "4 elements of 2 x 2 points");
    let mut pairs: Vec<(i64, i64)> =
        gauss.element.iter().copied().zip(gauss.point.clone()).collect();
    pairs.sort_unstable();
    assert_eq!(pairs, (0..4).flat_map(|e| (0..4).map(move |p| (e, p))).collect::<Vec<_>>());
    assert_eq!(shapes(&gauss.arrays), GAUSS_ARRAYS);
    for a in &gauss.arrays {
        assert_eq!(a.rows(), 16, "{}", a.name);
        assert_eq!(a.values, ascii_array(&text, &a.name), "{}", a.name);
    }
    assert!(gauss.positions.iter().flatten().all(|&x| x > 0.0 && x < 1.0));

    let mesh = reader.mesh(4).unwrap();
    let text = std::fs::read_to_string(dir.join("vtk/mesh_00004.vtu")).unwrap();
    let fem = job.build_mesh().unwrap();
    assert_eq!(mesh.points, fem.nodes);
    let cells: Vec<Vec<i64>> =
        fem.element_lists().iter().map(|e| e.iter().map(|&n| n as i64).collect()).collect();
    assert_eq!(mesh.cells, cells);
    assert_eq!(mesh.cell_types, [23; 4], "VTK_QUADRATIC_QUAD");
    let expected = [("displacement", 3), ("rotation", 1), ("stress", 4), ("couple_stress", 2)];
    assert_eq!(shapes(&mesh.point_arrays), expected);
    assert!(mesh.cell_arrays.is_empty());
    for a in &mesh.point_arrays {
        assert_eq!(a.rows(), fem.nodes.len(), "{}", a.name);
        assert_eq!(a.values, ascii_array(&text, &a.name), "{}", a.name);
    }
    let u = &mesh.point_arrays[0].values;
    let mut on_platens = 0;
    for (n, p) in mesh.points.iter().enumerate() {
        let u = &u[3 * n..3 * n + 3];
        assert_eq!(u[2], 0.0);
        let platen = if p[1] == 1.0 {
            -0.005
        } else if p[1] == 0.0 {
            0.005
        } else {
            continue;
        };
        assert!(u[0] == 0.0 && (u[1] - platen).abs() < 1e-15, "node {n} at {p:?}: u = {u:?}");
        on_platens += 1;
    }
    assert_eq!(on_platens, 10, "5 nodes on each platen");
}

/// The binary (zlib) `.vtu` files of the same job read back to the same fields as the ASCII
/// ones, bit for bit (both encodings carry the exact `f64`s).
#[test]
fn binary_files_read_as_the_ascii_ones() {
    let ascii = RunReader::open(&run(&elastic_job(2, VtkFormat::Ascii), "ascii", None)).unwrap();
    let binary = RunReader::open(&run(&elastic_job(2, VtkFormat::Binary), "binary", None)).unwrap();
    let text = std::fs::read_to_string(binary.dir().join("vtk/mesh_00002.vtu")).unwrap();
    assert!(text.contains("vtkZLibDataCompressor"));
    for step in [2, 4] {
        assert_eq!(binary.gauss(step).unwrap(), ascii.gauss(step).unwrap(), "step {step}");
        assert_eq!(binary.mesh(step).unwrap(), ascii.mesh(step).unwrap(), "step {step}");
    }
}

/// A run stopped by `max_steps` (status `stopped`, checkpoint written) opens and reads: its
/// two steps' curve rows and files, and a later step is refused naming the two saved.
#[test]
fn a_run_stopped_at_max_steps_opens_and_reads() {
    let dir = run(&elastic_job(1, VtkFormat::Ascii), "stopped", Some(2));
    let reader = RunReader::open(&dir).unwrap();
    let summary = reader.summary().unwrap();
    assert_eq!((summary["status"].as_str(), summary["steps"].as_u64()), (Some("stopped"), Some(2)));
    assert_eq!(reader.curve().unwrap().rows(), 2);
    assert_eq!(reader.saved_steps().unwrap(), [1, 2]);
    assert_eq!(reader.gauss(2).unwrap().positions.len(), 16);
    assert_eq!(reader.mesh(1).unwrap().points.len(), 21);
    let e = reader.gauss(3).unwrap_err().to_string();
    let want = format!("step 3 has no Gauss-point fields in {}; saved steps: 1, 2", dir.display());
    assert_eq!(e, want);
}

/// A step or point that was not saved is refused naming what was: the saved steps of that
/// kind of file, the snapshot points (none, and why, for an elastic run); a long list is
/// shortened to its ends with the saved steps nearest to the one asked.
#[test]
fn unsaved_steps_and_points_name_what_was_saved() {
    let dir = run(&elastic_job(2, VtkFormat::Ascii), "unsaved", None);
    let reader = RunReader::open(&dir).unwrap();
    let e = reader.gauss(3).unwrap_err();
    assert!(matches!(&e, ResultsError::StepNotSaved { step: 3, saved, .. } if saved == &[2, 4]));
    let d = dir.display();
    assert_eq!(
        e.to_string(),
        format!("step 3 has no Gauss-point fields in {d}; saved steps: 2, 4")
    );
    let e = reader.mesh(5).unwrap_err().to_string();
    assert_eq!(e, format!("step 5 has no mesh fields in {d}; saved steps: 2, 4"));
    assert_eq!(reader.snapshot_points().unwrap(), []);
    for e in [reader.snapshot_steps(0, 1).unwrap_err(), reader.snapshot(0, 1, 4).unwrap_err()] {
        assert_eq!(
            e.to_string(),
            format!(
                "no snapshots of element 0, Gauss point 1 in {d}; snapshot points: none: the \
                 job's [output] snapshots is empty (or its material has no particles)"
            )
        );
    }
    let long = ResultsError::StepNotSaved {
        dir: "RUN".into(),
        what: "mesh fields".into(),
        step: 47,
        saved: (1..=100).map(|s| 2 * s).collect(),
    };
    assert_eq!(
        long.to_string(),
        "step 47 has no mesh fields in RUN; saved steps: 2, 4, 6, 8, 10, ..., 192, 194, 196, \
         198, 200 (100 in all; nearest to 47: 46, 48)"
    );
    let none = ResultsError::StepNotSaved {
        dir: "RUN".into(),
        what: "Gauss-point fields".into(),
        step: 1,
        saved: vec![],
    };
    assert_eq!(none.to_string(), "step 1 has no Gauss-point fields in RUN; saved steps: none");
}

/// The snapshot reader on a tiny two-scale run (`dem-one-element` with assemblies of side
/// 0.05 m, a snapshot series of point 3, VTK every step, packing files as `.vtu` beside the
/// snapshots): the one point and its two steps are listed (the packing files are not
/// snapshots); the discs, their fluctuation (x, y of the file's 3 components, z = 0) and the
/// contacts (the line cells after the discs' vertex cells, with their forces) are the file's
/// text; the Gauss-point file carries the micro descriptors; a point or step not saved is
/// refused naming the saved ones.
#[test]
fn dem_snapshots_read_back() {
    let mut job = fixtures::load("dem-one-element");
    let MaterialSection::Dem { assembly } = &mut job.material else { panic!("a DEM job") };
    let cosdem_dem::PackingSpec::Hexagonal { side, .. } = &mut assembly.packing else {
        panic!("a hexagonal packing")
    };
    *side = 0.05;
    job.output.snapshots = vec![[0, 3]];
    job.output.packing_formats = vec![OutputFormat::Vtu];
    job.validate().unwrap();
    let dir = run(&job, "dem", None);
    let reader = RunReader::open(&dir).unwrap();
    assert!(dir.join("snapshots/e0_p3/packing_00002.vtu").exists());
    assert_eq!(reader.snapshot_points().unwrap(), [(0, 3)]);
    assert_eq!(reader.snapshot_steps(0, 3).unwrap(), [1, 2]);

    let s = reader.snapshot(0, 3, 2).unwrap();
    let text = std::fs::read_to_string(dir.join("snapshots/e0_p3/snap_00002.vtu")).unwrap();
    assert_eq!((s.element, s.point, s.step), (0, 3, 2));
    let n = s.positions.len();
    let xyz = ascii_array(&text, "Points");
    let (c, fl) = (xyz.chunks(3), ascii_array(&text, "fluctuation"));
    assert_eq!(s.positions, c.map(|p| [p[0], p[1]]).collect::<Vec<_>>());
    assert_eq!(s.radius, ascii_array(&text, "radius"));
    assert_eq!(s.rotation, ascii_array(&text, "rotation"));
    assert_eq!(fl.len(), 3 * n, "fluctuation is written with 3 components");
    assert!(fl.chunks(3).all(|f| f[2] == 0.0));
    assert_eq!(s.fluctuation, fl.chunks(3).map(|f| [f[0], f[1]]).collect::<Vec<_>>());
    let connectivity = ascii_array(&text, "connectivity");
    let lines: Vec<[i64; 2]> =
        connectivity[n..].chunks(2).map(|p| [p[0] as i64, p[1] as i64]).collect();
    assert!(!lines.is_empty(), "a compressed assembly has contacts");
    assert_eq!(s.contacts, lines);
    assert_eq!(s.normal_force, ascii_array(&text, "normal_force")[n..]);
    assert_eq!(s.tangential_force, ascii_array(&text, "tangential_force")[n..]);
    assert!(s.normal_force.iter().any(|&f| f > 0.0));

    let gauss = reader.gauss(2).unwrap();
    let mut expected = GAUSS_ARRAYS.to_vec();
    expected.extend([
        ("porosity", 1),
        ("void_ratio", 1),
        ("coordination", 1),
        ("mechanical_coordination", 1),
        ("fabric", 3),
        ("fabric_anisotropy", 1),
        ("fabric_direction", 1),
        ("sliding_fraction", 1),
        ("mean_rotation", 1),
    ]);
    assert_eq!(shapes(&gauss.arrays), expected);
    assert!(gauss.arrays.iter().all(|a| a.rows() == 4));

    let d = dir.display();
    let e = reader.snapshot(0, 0, 2).unwrap_err().to_string();
    assert_eq!(
        e,
        format!("no snapshots of element 0, Gauss point 0 in {d}; snapshot points: [e0 p3]")
    );
    let e = reader.snapshot(0, 3, 7).unwrap_err().to_string();
    assert_eq!(e, format!("step 7 has no snapshot e0_p3 in {d}; saved steps: 1, 2"));
}

/// A path that holds no run is refused naming it and what it is: missing, a file, an empty
/// directory, a directory of other files.
#[test]
fn a_path_without_a_run_is_refused_naming_it() {
    let dir = fresh("not_a_run");
    let refusal = |p: &Path| RunReader::open(p).unwrap_err().to_string();
    let d = dir.display();
    assert_eq!(refusal(&dir), format!("{d}: not a run directory: it does not exist"));
    std::fs::create_dir_all(&dir).unwrap();
    assert_eq!(
        refusal(&dir),
        format!("{d}: not a run directory: it is empty: no summary.json and no curve.csv")
    );
    std::fs::write(dir.join("notes.txt"), "x").unwrap();
    assert_eq!(
        refusal(&dir),
        format!(
            "{d}: not a run directory: it holds no summary.json and no curve.csv, only notes.txt"
        )
    );
    let file = dir.join("notes.txt");
    let e = refusal(&file);
    assert!(
        e.starts_with(&format!("{}: not a run directory: it is a file", file.display())),
        "{e}"
    );
}

/// A directory as a run being written or killed leaves it (made by hand from a finished
/// run's files): a `running` status with no process holding the lock reads as
/// `interrupted: ...`; a curve row without its line end (being appended) is left out, a
/// header alone is an empty curve, a broken row elsewhere is an error naming the file, line
/// and column, a quoted column name (as the writer quotes a name with a comma) reads back;
/// a step whose Gauss-point file exists without its mesh file is not listed; a
/// truncated `.vtu` is an error naming the file, never a panic.
#[test]
fn a_run_being_written_reads_its_finished_parts() {
    let src = run(&elastic_job(2, VtkFormat::Ascii), "written_source", None);
    let dir = fresh("written");
    std::fs::create_dir_all(dir.join("vtk")).unwrap();
    let summary = std::fs::read_to_string(src.join("summary.json")).unwrap();
    let running = summary.replace("\"status\": \"finished\"", "\"status\": \"running\"");
    assert_ne!(running, summary);
    std::fs::write(dir.join("summary.json"), running).unwrap();
    let csv = std::fs::read_to_string(src.join("curve.csv")).unwrap();
    std::fs::write(dir.join("curve.csv"), format!("{csv}5,1,0.0")).unwrap();
    let reader = RunReader::open(&dir).unwrap();
    let status = reader.summary().unwrap()["status"].as_str().unwrap().to_string();
    assert!(status.starts_with("interrupted: the process writing the run ended"), "{status}");
    assert_eq!(reader.curve().unwrap().rows(), 4, "the partial fifth row is left out");

    let header = &csv[..=csv.find('\n').unwrap()];
    std::fs::write(dir.join("curve.csv"), header).unwrap();
    let curve = reader.curve().unwrap();
    assert_eq!(curve.columns.len(), header.split(',').count());
    assert!(curve.columns.iter().all(|(_, v)| v.is_empty()));

    let first = csv.lines().nth(1).unwrap();
    let mut bad: Vec<&str> = first.split(',').collect();
    bad[1] = "x";
    let bad = bad.join(",");
    std::fs::write(dir.join("curve.csv"), format!("{header}{bad}\n")).unwrap();
    let e = reader.curve().unwrap_err().to_string();
    assert!(e.contains("curve.csv") && e.contains("line 2") && e.contains("load_factor"), "{e}");
    let short = csv.replacen('\n', "\n1,2\n", 1);
    std::fs::write(dir.join("curve.csv"), short).unwrap();
    let e = reader.curve().unwrap_err().to_string();
    assert!(e.contains("line 2: \"1,2\" has 2 values for the 8 columns"), "{e}");

    // Column names are quoted as the writer quotes them (a set name may hold a comma).
    std::fs::write(dir.join("curve.csv"), "step,\"R_y:a,b\",\"q\"\"x\"\n1,2,3\n").unwrap();
    let curve = reader.curve().unwrap();
    let names: Vec<&str> = curve.columns.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["step", "R_y:a,b", "q\"x"]);
    assert_eq!(curve.column("R_y:a,b"), Some(&[2.0][..]));

    let gauss = std::fs::read_to_string(src.join("vtk/gauss_00002.vtu")).unwrap();
    std::fs::write(dir.join("vtk/gauss_00002.vtu"), &gauss[..gauss.len() / 2]).unwrap();
    assert_eq!(reader.saved_steps().unwrap(), [] as [u64; 0], "no mesh file of step 2");
    let e = reader.gauss(2).unwrap_err().to_string();
    assert!(e.contains("gauss_00002.vtu"), "{e}");
}
