//! `[[region]]` against real meshes: which material every element gets on a structured
//! rectangle (element ranges) and on a Gmsh mesh (physical surfaces), each error of a region
//! the mesh refutes, and the per-region body force of a stage's gravity.

use cosdem_fem::Error;
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::Ramp;
use cosdem_job::{Job, fixtures};

/// `fixtures/jobs/rectangle-two-regions.toml` with `from` replaced by `to` (`from` must occur).
fn rectangle_with(from: &str, to: &str) -> Job {
    let text = fixtures::text("rectangle-two-regions");
    assert!(text.contains(from), "{from}");
    Job::from_toml(&text.replace(from, to), "j").unwrap_or_else(|e| panic!("{e}"))
}

/// The key and the message of an `InvalidSetting` error.
fn key_and_message(e: &Error) -> (&'static str, String) {
    match e {
        Error::InvalidSetting { field, .. } => (field, e.to_string()),
        other => panic!("not an InvalidSetting: {other}"),
    }
}

/// The rectangle's 4 x 2 elements, numbered row by row from the bottom: the lower row is
/// region 0 (material 1), elements 4 and 5 region 1 (material 2), the rest `[material]`.
#[test]
fn element_ranges_give_each_element_its_material() {
    let job = fixtures::load("rectangle-two-regions");
    let mesh = job.build_mesh().unwrap();
    assert_eq!(job.element_materials(&mesh).unwrap(), [1, 1, 1, 1, 2, 2, 0, 0]);
    assert_eq!(job.material_label(2), "region[1] (loose)");
    assert_eq!(job.materials().len(), 3);
    // model() checks the regions and builds.
    assert_eq!(job.model().unwrap().mesh.n_elements(), 8);
}

/// A Gmsh region by physical surface: the left element is "sand" (region 0), the right one
/// takes `[material]`; with a second region "clay" both are in regions. The mesh's element
/// sets come from its physical surfaces (an element in several: "all" holds both).
#[test]
fn a_physical_surface_gives_its_elements_a_material() {
    let job = fixtures::load("gmsh-two-soils");
    let mesh = job.build_mesh().unwrap();
    assert_eq!(mesh.element_sets["all"], [0, 1]);
    assert_eq!(job.element_materials(&mesh).unwrap(), [1, 0]);
    job.model().unwrap();
    let mut two = job.clone();
    let mut clay = two.region[0].clone();
    clay.name = Some("clay".into());
    clay.physical = Some("clay".into());
    two.region.push(clay);
    assert_eq!(two.element_materials(&mesh).unwrap(), [1, 2]);
}

/// Every way a region can contradict the mesh is refused by `element_materials` (and so by
/// `model()`, before anything runs), naming the key and the value: an unknown physical
/// surface (listing the known ones), a range past the last element, an element in two
/// regions (both named, and the element), a region whose set is empty.
#[test]
fn regions_the_mesh_refutes_are_refused_naming_the_key() {
    let gmsh = fixtures::load("gmsh-two-soils");
    let mesh = gmsh.build_mesh().unwrap();

    let mut job = gmsh.clone();
    job.region[0].physical = Some("gravel".into());
    let e = job.model().unwrap_err();
    let (key, msg) = key_and_message(&e);
    assert_eq!(key, "region[0].physical");
    assert!(msg.contains("gravel") && msg.contains("known: all, clay, sand"), "{msg}");

    // "sand" and then "all": element 0 is in both.
    let mut job = gmsh.clone();
    let mut all = job.region[0].clone();
    all.name = Some("everything".into());
    all.physical = Some("all".into());
    job.region.push(all);
    let (key, msg) = key_and_message(&job.element_materials(&mesh).unwrap_err());
    assert_eq!(key, "region[1].physical");
    assert!(msg.contains("element 0") && msg.contains("region[0] (sand)"), "{msg}");

    let mut empty = mesh.clone();
    empty.element_sets.insert("sand".into(), Vec::new());
    let (key, msg) = key_and_message(&gmsh.element_materials(&empty).unwrap_err());
    assert_eq!(key, "region[0].physical");
    assert!(msg.contains("no elements"), "{msg}");

    // The rectangle: a range past element 7, and ranges of two regions that meet at 5.
    let job = rectangle_with("[[4, 4], [5, 5]]", "[[4, 4], [5, 8]]");
    let (key, msg) = key_and_message(&job.model().unwrap_err());
    assert_eq!(key, "region[1].elements[1]");
    assert!(msg.contains("[5, 8]") && msg.contains("0 to 7"), "{msg}");
    let job = rectangle_with("[[0, 3]]", "[[0, 5]]");
    let mesh = job.build_mesh().unwrap();
    let (key, msg) = key_and_message(&job.element_materials(&mesh).unwrap_err());
    assert_eq!(key, "region[1].elements[0]");
    assert!(
        msg.contains("element 4") && msg.contains("region[0] (dense)") && msg.contains("region"),
        "{msg}"
    );
}

/// The checks that need no mesh are refused when the job is read: both or neither of
/// `physical` and `elements`, a reversed range, a physical name on a rectangle.
#[test]
fn malformed_regions_are_refused_when_read() {
    let text = fixtures::text("rectangle-two-regions");
    for (from, to, key) in [
        ("elements = [[0, 3]]", "elements = [[3, 0]]", "region[0].elements[0]"),
        ("elements = [[0, 3]]", "", "region[0]"),
        ("elements = [[0, 3]]", "physical = \"dense\"", "region[0].physical"),
        (
            "elements = [[4, 4], [5, 5]]",
            "elements = [[4, 5]]\nphysical = \"x\"",
            "region[1].physical",
        ),
    ] {
        let e = Job::from_toml(&text.replace(from, to), "j").unwrap_err();
        assert_eq!(key_and_message(&e).0, key, "{e}");
    }
}

/// The body force `[f_x, f_y]` at element `e` of a stage's loading.
fn force(job: &Job, stage: usize, e: usize) -> [f64; 2] {
    let stages = job.stages().unwrap();
    let body = stages[stage].loading.body.as_ref().expect("gravity in force");
    let f = (body.0)(e, [0.0, 0.0]);
    assert_eq!(f[2], 0.0);
    [f[0], f[1]]
}

/// Gravity per region: the lower row weighs its bulk density (2000 x 9.81 = 19620 N/m^3), the
/// loose region (no `bulk_density`) and `[material]` the stage's density (1500 x 9.81 =
/// 14715). The products are the same f64 operations as the test's, so equality is exact.
/// Held in a next stage, and removed, per element.
#[test]
fn gravity_weighs_each_region_with_its_density() {
    let job = fixtures::load("rectangle-two-regions");
    for e in 0..4 {
        assert_eq!(force(&job, 0, e), [2000.0 * 0.0, 2000.0 * -9.81]);
    }
    for e in 4..8 {
        assert_eq!(force(&job, 0, e), [1500.0 * 0.0, 1500.0 * -9.81]);
    }
    assert_eq!(job.stages().unwrap()[0].loading.body_ramp, Ramp::Linear);
    // The model's first loading is the first stage's, with the same forces.
    let model = job.model().unwrap();
    assert_eq!((model.loading.body.as_ref().unwrap().0)(0, [0.0; 2])[1], 2000.0 * -9.81);
    let text = fixtures::text("rectangle-two-regions");
    let more = format!(
        "{text}\n[[stage]]\nname = \"hold\"\n\n[[stage]]\nname = \"dig\"\n\
         gravity = {{ acceleration = [0.0, 0.0], ramp = \"remove\" }}\n"
    );
    let job = Job::from_toml(&more, "j").unwrap();
    let stages = job.stages().unwrap();
    assert_eq!(
        (stages[1].loading.body_ramp, stages[2].loading.body_ramp),
        (Ramp::Constant, Ramp::Down)
    );
    for stage in [1, 2] {
        assert_eq!(force(&job, stage, 0)[1], 2000.0 * -9.81);
        assert_eq!(force(&job, stage, 7)[1], 1500.0 * -9.81);
    }
}

/// `density` left out, a DEM material weighs its assembly: solid density times the solid
/// fraction of the assembly as built ([`cosdem_job::bulk`]), here the default hexagonal
/// lattice in `[material]` (elements 6 and 7) beside the regions' own. The force is that
/// density times g to the bit (the same f64 product).
#[test]
fn a_dem_material_without_density_weighs_its_assembly() {
    let density = "gravity = { acceleration = [0.0, -9.81], density = 1500.0, ramp = \"linear\" }";
    let text = fixtures::text("rectangle-two-regions")
        .replace(density, "gravity = { acceleration = [0.0, -9.81], ramp = \"linear\" }")
        .replace("[[4, 4], [5, 5]]", "[[4, 4], [5, 5]]\nbulk_density = 1200.0")
        .replace(
            "[material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3",
            "[material]\nkind = \"dem\"\n[material.assembly]\npacking = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }",
        );
    let job = Job::from_toml(&text, "j").unwrap_or_else(|e| panic!("{e}\n{text}"));
    let cosdem_job::MaterialSection::Dem { assembly } = &job.material else { panic!() };
    let rho = cosdem_job::bulk::assembly_bulk_density(assembly).unwrap();
    assert!((1500.0..2650.0).contains(&rho), "{rho}");
    assert_eq!(force(&job, 0, 7), [rho * 0.0, rho * -9.81]);
    assert_eq!(force(&job, 0, 4), [1200.0 * 0.0, 1200.0 * -9.81]);
    assert_eq!(force(&job, 0, 0), [2000.0 * 0.0, 2000.0 * -9.81]);
}

/// `density` may be left out only when every region gives `bulk_density`; then an element in
/// no region has no density, refused naming `stage[0].gravity.density` when the stages are
/// built; with the regions covering the mesh it runs. Without regions, a missing density is
/// refused when the job is read.
#[test]
fn a_missing_density_is_refused_unless_the_regions_weigh_everything() {
    let no_density = "gravity = { acceleration = [0.0, -9.81], ramp = \"linear\" }";
    let density = "gravity = { acceleration = [0.0, -9.81], density = 1500.0, ramp = \"linear\" }";
    let text = fixtures::text("rectangle-two-regions").replace(density, no_density);
    let e = Job::from_toml(&text, "j").unwrap_err();
    assert_eq!(key_and_message(&e).0, "stage[0].gravity.density", "{e}");
    let weighed = text.replace("[[4, 4], [5, 5]]", "[[4, 4], [5, 5]]\nbulk_density = 1200.0");
    let job = Job::from_toml(&weighed, "j").unwrap();
    let (key, msg) = key_and_message(&job.stages().unwrap_err());
    assert_eq!(key, "stage[0].gravity.density");
    assert!(msg.contains("material is elastic and has no bulk_density"), "{msg}");
    assert_eq!(key_and_message(&job.model().unwrap_err()).0, "stage[0].gravity.density");
    let covered = weighed.replace("[[4, 4], [5, 5]]", "[[4, 7]]");
    let job = Job::from_toml(&covered, "j").unwrap();
    assert_eq!(force(&job, 0, 7), [1200.0 * 0.0, 1200.0 * -9.81]);
    assert_eq!(force(&job, 0, 0), [2000.0 * 0.0, 2000.0 * -9.81]);
}

/// Without regions every element takes `[material]` (material 0).
#[test]
fn one_material_per_element() {
    let job = fixtures::load("elastic-panel");
    let mesh: Mesh = job.build_mesh().unwrap();
    assert_eq!(job.element_materials(&mesh).unwrap(), vec![0; mesh.n_elements()]);
}
