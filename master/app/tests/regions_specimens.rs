//! Materials per region and specimens per point, end to end (issue 28 items 2 and 3).
//!
//! The base job is a 2 x 4 biaxial sample of eight-node elements (32 Gauss points) of
//! periodic random 40-disc assemblies, as `examples/cyclic-biaxial.toml` with smaller
//! assemblies, compressed by its top platen in 2 steps. What is checked:
//! - the plan of specimens: one specimen for the whole job by default, whose spec is the
//!   material's bit for bit (so a job without `[specimens]` builds what it built before);
//!   K seeded specimens cover every point, each its own seed; one per point with
//!   `per_point`; elastic points in no specimen;
//! - in-situ consolidation: the levels of a gravity column follow its depth;
//! - runs: a job whose bottom row is an elastic region and the rest DEM with K = 2 runs,
//!   reports its specimens in the summary, and gives the same `curve.csv` bytes on one
//!   and on two in-process workers (determinism whatever the number of workers).

use cosdem_app::run::material::plan_specimens;
use cosdem_app::run::{Ending, Run};
use cosdem_common::GaussPointId;
use cosdem_job::{Job, MaterialSection};
use std::path::{Path, PathBuf};

/// The biaxial sample's stage: 2 steps of the top platen down 0.2 mm under 100 kPa sides.
const COMPRESSION: &str = r#"
[[stage]]
name = "compression"
steps = 2
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "bottom_left", component = "ux", value = 0.0 },
  { set = "top", component = "uy", value = -2.0e-4 },
]
pressure = [ { set = "left", value = 1.0e5 }, { set = "right", value = 1.0e5 } ]
"#;

/// The biaxial sample with `extra` TOML appended.
fn job(extra: &str) -> Job {
    sample(0.1, COMPRESSION, extra)
}

/// A 0.05 m wide sample `ly` tall of 2 x 4 elements with the stages `stages` and `extra`.
fn sample(ly: f64, stages: &str, extra: &str) -> Job {
    let text = format!(
        r#"
title = "regions and specimens"
[mesh]
kind = "rectangle"
lx = 0.05
ly = {ly:?}
nx = 2
ny = 4
{stages}
[newton]
force_tolerance = 5.0e-3
displacement_tolerance = 5.0e-3
max_iterations = 20
tolerated_residual = 0.05

[material]
kind = "dem"

[material.assembly]
packing = {{ kind = "random", r_min = 0.0035, r_max = 0.005, side = 0.045, seed = 7, confining_stress = 1.0e5 }}
boundary = {{ kind = "periodic" }}
tangent = {{ kind = "paper" }}

[output]
vtk_every = 0

[output.curve]
control = {{ set = "top", component = "uy", scale = -1.0 }}
load = {{ set = "top", component = "uy", scale = -1.0 }}
{extra}
"#
    );
    Job::from_toml(&text, "regions.toml").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Every Gauss point of the 8-element mesh, element-major.
fn ids() -> Vec<GaussPointId> {
    (0..8u32).flat_map(|e| (0..4).map(move |p| GaussPointId::new(e, p))).collect()
}

fn assembly(job: &Job) -> &cosdem_dem::AssemblySpec {
    let MaterialSection::Dem { assembly } = &job.material else { panic!("a DEM job") };
    assembly
}

/// Without `[specimens]`: one group of every point, whose spec is the material's (equal as a
/// value and as the JSON the workers get), so the run builds what it built before.
#[test]
fn by_default_one_specimen_is_the_material_itself() {
    let job = job("");
    let mesh = job.build_mesh().unwrap();
    let em = job.element_materials(&mesh).unwrap();
    let groups = plan_specimens(&job, &em, &ids(), None);
    assert_eq!(groups.len(), 1);
    assert_eq!(groups[0].ids, ids());
    let spec =
        job.specimens.assembly_of(assembly(&job), groups[0].specimen, groups[0].confining_stress);
    assert_eq!(&spec, assembly(&job));
    assert_eq!(serde_json::to_vec(&spec).unwrap(), serde_json::to_vec(assembly(&job)).unwrap());
}

/// `count = 3`: three groups that together hold every point once, specimen k with the seed
/// 7 + k; `per_point`: 32 groups of one point; an elastic region's points in none.
#[test]
fn seeded_specimens_cover_every_point_once() {
    let job3 = job("[specimens]\ncount = 3\nseed = 5\n");
    let mesh = job3.build_mesh().unwrap();
    let em = job3.element_materials(&mesh).unwrap();
    let groups = plan_specimens(&job3, &em, &ids(), None);
    assert_eq!(groups.len(), 3, "32 points over 3 specimens: each used");
    let mut all: Vec<GaussPointId> = groups.iter().flat_map(|g| g.ids.clone()).collect();
    all.sort();
    assert_eq!(all, ids());
    for g in &groups {
        let cosdem_dem::PackingSpec::Random { seed, .. } =
            job3.specimens.assembly_of(assembly(&job3), g.specimen, g.confining_stress).packing
        else {
            panic!("random")
        };
        assert_eq!(seed, 7 + g.specimen);
    }
    let per = job("[specimens]\ncount = \"per_point\"\n");
    assert_eq!(plan_specimens(&per, &em, &ids(), None).len(), 32);

    let mixed = job(
        "[[region]]\nname = \"base\"\nelements = [[0, 1]]\n[region.material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3\n",
    );
    let em = mixed.element_materials(&mesh).unwrap();
    assert_eq!(em, [1, 1, 0, 0, 0, 0, 0, 0]);
    let groups = plan_specimens(&mixed, &em, &ids(), None);
    assert_eq!(groups.len(), 1);
    assert!(groups[0].ids.iter().all(|id| id.element >= 2), "{:?}", groups[0].ids);
    assert_eq!(groups[0].ids.len(), 24);
}

/// In-situ consolidation of a column under its weight (the sample, 10 m tall so that the
/// stresses span several levels): the level of a point never decreases with its depth, the
/// deepest points are on a higher level than the shallowest, and each level is a value of
/// the ladder `min_stress * ratio^k`.
#[test]
fn in_situ_levels_follow_depth() {
    let geostatic = r#"
[[stage]]
name = "geostatic"
steps = 1
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "left", component = "ux", value = 0.0 },
  { set = "right", component = "ux", value = 0.0 },
]
gravity = { acceleration = [0.0, -9.81], density = 1600.0 }
"#;
    let job = sample(
        10.0,
        geostatic,
        "[specimens]\nconsolidation = \"in_situ\"\nmin_stress = 1.0e4\nlevel_ratio = 2.0\n",
    );
    let p = cosdem_app::run::in_situ::in_situ_mean_stress(&job, 0.3).unwrap();
    let mesh = job.build_mesh().unwrap();
    let em = job.element_materials(&mesh).unwrap();
    let groups = plan_specimens(&job, &em, &ids(), Some(&p));
    assert!(groups.len() >= 3, "a 10 m column at 16 kN/m^3 spans 1e4..1.6e5 Pa: {groups:?}");
    let solver =
        cosdem_fem::solve::Solver::new(job.model().unwrap(), job.solver_settings().unwrap())
            .unwrap();
    let y: Vec<f64> = (0..32).map(|g| solver.gauss().x[g][1]).collect();
    let level = |id: &GaussPointId| {
        groups.iter().find(|g| g.ids.contains(id)).unwrap().confining_stress.unwrap()
    };
    for a in ids() {
        for b in ids() {
            let (ia, ib) = ((a.element * 4 + a.point) as usize, (b.element * 4 + b.point) as usize);
            if y[ia] < y[ib] - 1e-9 {
                assert!(level(&a) >= level(&b), "{a} at y {} below {b} at {}", y[ia], y[ib]);
            }
        }
        let k = (level(&a) / 1.0e4).log2();
        assert!((k - k.round()).abs() < 1e-12, "{a}: level {} off the ladder", level(&a));
    }
}

fn out(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("regions_{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// An elastic bottom row under a DEM sample of two specimens: it runs its 2 steps, the
/// summary reports 2 distinct specimens for the 24 DEM points, and one or two in-process
/// workers give the same curve bytes.
#[test]
fn an_elastic_region_under_two_dem_specimens_runs_the_same_on_any_workers() {
    let extra = "[specimens]\ncount = 2\n\n[[region]]\nname = \"base\"\nelements = [[0, 1]]\n[region.material]\nkind = \"elastic\"\nshear_modulus = 2e7\npoisson = 0.3\n";
    let mut curves = Vec::new();
    for workers in [1, 2] {
        let mut job = job(extra);
        job.workers.in_process = workers;
        let dir = out(&format!("w{workers}"));
        let outcome = Run::new(&job, &dir).execute().unwrap();
        assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
        let s = outcome.summary.unwrap();
        let specimens = s.specimens.expect("DEM points: specimens reported");
        assert_eq!((specimens.distinct, specimens.points), (2, 24));
        assert!(specimens.seconds > 0.0);
        curves.push(std::fs::read(dir.join("curve.csv")).unwrap());
    }
    assert_eq!(curves[0], curves[1], "the curve depends on the number of workers");
}

/// The LAMMPS packings of a job with regions carry each region's solid density: a DEM region
/// of density 2000 over elements 0-1, `[material]` (2650) elsewhere.
#[test]
fn packing_files_take_the_density_of_their_region() {
    let job = job(
        "[[region]]\nelements = [[0, 1]]\n[region.material]\nkind = \"dem\"\n[region.material.assembly]\npacking = { kind = \"hexagonal\", radius = 0.005, side = 0.1 }\ndensity = 2000.0\n",
    );
    let mesh = job.build_mesh().unwrap();
    let mut out = cosdem_app::output::packing::PackingOutput::of(&job);
    out.set_regions(&job, &job.element_materials(&mesh).unwrap());
    let densities: Vec<f64> = (0..8).map(|e| out.density_of(e)).collect();
    assert_eq!(densities, [2000.0, 2000.0, 2650.0, 2650.0, 2650.0, 2650.0, 2650.0, 2650.0]);
}
