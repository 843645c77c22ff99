//! The accuracy target keeps its promise on a scene the measured table was not made on.
//!
//! The table (`master/tune/data/tradeoff-scene-a.csv`) is scene A: a 1 x 1 m panel, 2 x 2
//! elements, 100 kPa confinement, 105-disc assemblies (V = 0.01 m^2), 2 mm load steps to
//! 0.03 m. The scene here differs in every one of those: a slender 0.5 x 1 m panel (aspect 2)
//! of 1 x 2 elements, 150 kPa confinement, smaller assemblies (side 0.08 m, V = 0.0064 m^2),
//! to 0.012 m (pre-peak, like the table). It runs once with `accuracy = 0.05` (the settings
//! `cosdem run` would pick) and once with the sweep's tight reference settings
//! ([`reference`]: relaxation tolerance 1e-5, safety 0.25, half the load step, cold
//! starts), and checks:
//!
//! - F_u and E of the accuracy run are within 5 % of the reference's (and F_res, if the
//!   reference curve has one). 5 % is the promise itself, not a loosened test tolerance: the
//!   prediction was asked to stay within half of it, and the remaining half is the margin for
//!   a scene the table did not see.
//! - the accuracy run was cheaper: fewer DEM steps (machine-independent; wall time is not
//!   asserted on a shared machine).
//! - the run directory holds `accuracy.json` naming what was picked.

use cosdem_app::run::{WorkerChoice, run_job};
use cosdem_job::Job;
use cosdem_tune::knob::reference;
use cosdem_tune::table::compare;
use std::time::Instant;

const SCENE: &str = r#"
accuracy = 0.05
title = "accuracy test: slender confined panel, 8 DEM assemblies"

[mesh]
kind = "rectangle"
lx = 0.5
ly = 1.0
nx = 1
ny = 2

[loading]
increment = 0.002

[loading.compression]
displacement = 0.012
platens = "rough"

[[loading.pressure]]
set = "left"
value = 1.5e5

[[loading.pressure]]
set = "right"
value = 1.5e5

[newton]
force_tolerance = 5.0e-3
displacement_tolerance = 5.0e-3
max_iterations = 20
tolerated_residual = 0.05

[material]
kind = "dem"

[material.assembly]
packing = { kind = "hexagonal", radius = 0.005, side = 0.08 }

[output]
vtk_every = 0
"#;

#[test]
fn accuracy_target_holds_on_a_scene_the_table_was_not_measured_on() {
    check(SCENE, "hexagonal");
}

/// The same scene with random polydisperse assemblies (radii 4-6 mm, equilibrated at
/// 150 kPa, a penalty boundary): planned from the random table
/// (`master/tune/data/tradeoff-biaxial-1mm.csv`: periodic 2-3 mm assemblies, smooth platens,
/// 100 kPa), which this scene differs from in
/// radii, boundary, platens, confinement and mesh. Its default is 2.9 % from its reference
/// (the half load step), so only a 10 % target moves knobs; the promise is checked at 10 %.
/// (Before the specimen was fixed across the knobs, this scene's default settings alone
/// were 13-15 % from the tight reference: specimen scatter, not accuracy.)
#[test]
fn accuracy_target_holds_on_random_assemblies() {
    let scene = SCENE
        .replace(
            "packing = { kind = \"hexagonal\", radius = 0.005, side = 0.08 }",
            "packing = { kind = \"random\", r_min = 0.004, r_max = 0.006, side = 0.08, seed = 3, \
             confining_stress = 1.5e5 }",
        )
        .replace("accuracy = 0.05", "accuracy = 0.1");
    assert!(scene.contains("kind = \"random\"") && scene.contains("accuracy = 0.1"));
    check(&scene, "random");
}

/// Runs `scene` with its `accuracy` target and with the tight reference settings, and checks
/// the promise (F_u, E and F_res, if any, within the target) and that it was cheaper.
fn check(scene: &str, name: &str) {
    let job = Job::from_toml(scene, "accuracy-scene").unwrap();
    let target = job.accuracy.unwrap();
    let dir =
        std::env::temp_dir().join(format!("cosdem-accuracy-test-{name}-{}", std::process::id()));
    let workers = WorkerChoice::default();

    let t0 = Instant::now();
    let (fast, fast_curve) = run_job(&job, &dir.join("accuracy"), &workers).unwrap();
    let t_fast = t0.elapsed().as_secs_f64();
    let mut plain = job.clone();
    plain.accuracy = None;
    let t0 = Instant::now();
    let (tight, tight_curve) =
        run_job(&reference(&plain).job, &dir.join("reference"), &workers).unwrap();
    let t_tight = t0.elapsed().as_secs_f64();

    let report = std::fs::read_to_string(dir.join("accuracy").join("accuracy.json")).unwrap();
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    let picked: Vec<String> = report["knobs"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|k| k["row"].as_str().map(str::to_string))
        .collect();
    let e = compare((&tight.metrics, &tight_curve), (&fast.metrics, &fast_curve));
    eprintln!(
        "{name}: picked {picked:?}; accuracy run {t_fast:.1} s, {} DEM steps, {} steps; reference \
         {t_tight:.1} s, {} DEM steps, {} steps; errors F_u {:?} F_res {:?} E {:?} curve {:?}",
        fast.dem_steps,
        fast.steps,
        tight.dem_steps,
        tight.steps,
        e.peak,
        e.residual,
        e.stiffness,
        e.curve
    );
    assert_eq!(fast.status, "finished");
    assert_eq!(tight.status, "finished");
    assert!(!picked.is_empty(), "this target on its table moves some knob");
    let peak = e.peak.unwrap();
    let stiffness = e.stiffness.unwrap();
    assert!(peak <= target, "F_u off by {:.2} %", 100.0 * peak);
    assert!(stiffness <= target, "E off by {:.2} %", 100.0 * stiffness);
    if tight.metrics.residual_load.is_some() {
        let r = e.residual.expect("the accuracy run passed the peak too");
        assert!(r <= target, "F_res off by {:.2} %", 100.0 * r);
    }
    assert!(
        fast.dem_steps < tight.dem_steps,
        "not cheaper: {} DEM steps against {}",
        fast.dem_steps,
        tight.dem_steps
    );
    std::fs::remove_dir_all(&dir).ok();
}
