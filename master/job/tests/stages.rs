//! `[[stage]]` turned into the solver's stages: what an earlier stage set stays in force
//! (held dofs, held loads, gravity), paths and repetitions expand, and every bad stage is
//! refused naming its key and value.

use cosdem_fem::assembly::Component;
use cosdem_fem::solve::{EdgeLoadKind, Ramp};
use cosdem_job::{Job, SolverStage};

/// The elastic panel with `stages` (TOML) instead of a `[loading]`.
fn staged(stages: &str) -> Result<Job, String> {
    let text = format!(
        "[mesh]\nkind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2\n\n\
         [material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3\n\n{stages}"
    );
    Job::from_toml(&text, "staged.toml").map_err(|e| e.to_string())
}

fn stages(text: &str) -> Vec<SolverStage> {
    staged(text).unwrap().stages().unwrap()
}

/// (set, component, value, relative) of a stage's prescribed dofs.
fn dirichlet(s: &SolverStage) -> Vec<(String, Component, f64, bool)> {
    s.loading.dirichlet.iter().map(|d| (d.set.clone(), d.component, d.value, d.relative)).collect()
}

const LOAD_UNLOAD: &str = r#"
[[stage]]
name = "load"
steps = 4
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "top", component = "uy", value = -1e-3 },
]

[[stage]]
name = "unload"
steps = 2
prescribed = [{ set = "top", component = "uy", increment = 5e-4 }]

[[stage]]
name = "release"
prescribed = [{ set = "top", component = "uy", free = true }]
"#;

/// A dof prescribed earlier is held (an increment of 0) until a stage moves or frees it.
#[test]
fn prescribed_dofs_are_held_until_moved_or_freed() {
    let s = stages(LOAD_UNLOAD);
    assert_eq!(s.len(), 3);
    assert_eq!((s[0].steps, s[1].steps, s[2].steps), (4, 2, 10));
    assert_eq!(
        dirichlet(&s[0]),
        [("bottom".into(), Component::Uy, 0.0, false), ("top".into(), Component::Uy, -1e-3, false)]
    );
    assert_eq!(
        dirichlet(&s[1]),
        [("bottom".into(), Component::Uy, 0.0, true), ("top".into(), Component::Uy, 5e-4, true)]
    );
    assert_eq!(dirichlet(&s[2]), [("bottom".into(), Component::Uy, 0.0, true)]);
    // The model is the first stage's.
    let job = staged(LOAD_UNLOAD).unwrap();
    assert_eq!(job.model().unwrap().loading.dirichlet.len(), 2);
    assert_eq!(job.solver_settings().unwrap().steps, 4);
}

/// A pressure stays at its value in later stages (constant), a new value is reached from
/// the old one (the old held, the difference ramped), and a removal ramps it down.
#[test]
fn pressures_are_held_changed_from_their_value_and_removed() {
    let s = stages(
        r#"
[[stage]]
prescribed = [{ set = "bottom", component = "uy", value = 0.0 }]
pressure = [{ set = "left", value = 1e5 }]
[[stage]]
prescribed = [{ set = "top", component = "uy", increment = -1e-3 }]
[[stage]]
pressure = [{ set = "left", value = 3e5, ramp = "linear" }]
[[stage]]
pressure = [{ set = "left", ramp = "remove" }]
"#,
    );
    let edges = |k: usize| -> Vec<(f64, Ramp)> {
        s[k].loading
            .edge_loads
            .iter()
            .map(|e| match e.kind {
                EdgeLoadKind::Pressure(p) => (p, e.ramp),
                EdgeLoadKind::Traction(_) => panic!("no traction here"),
            })
            .collect()
    };
    assert_eq!(edges(0), [(1e5, Ramp::Constant)]);
    assert_eq!(edges(1), [(1e5, Ramp::Constant)]);
    assert_eq!(edges(2), [(1e5, Ramp::Constant), (2e5, Ramp::Linear)]);
    assert_eq!(edges(3), [(3e5, Ramp::Down)]);
}

/// A path of targets becomes one stage per target, `repeat` repeats the stage: a cyclic
/// loading of 2 cycles of (load, unload) is 4 stages with the path's targets in order.
#[test]
fn paths_and_repetitions_expand_in_order() {
    let s = stages(
        r#"
[[stage]]
name = "cycle"
steps = 3
repeat = 2
prescribed = [
  { set = "bottom", component = "uy", value = 0.0 },
  { set = "top", component = "uy", path = [-2e-3, -1e-3] },
]
"#,
    );
    let tops: Vec<f64> = s.iter().map(|x| dirichlet(x)[1].2).collect();
    assert_eq!(tops, [-2e-3, -1e-3, -2e-3, -1e-3]);
    assert_eq!(s[3].name, "cycle 2/2 point 2/2");
    assert!(s.iter().all(|x| x.steps == 3));
}

/// Gravity: the body force is the density times the acceleration, applied over its stage
/// (linear) and held after it.
#[test]
fn gravity_is_applied_then_held() {
    let s = stages(
        r#"
[[stage]]
name = "geostatic"
prescribed = [{ set = "bottom", component = "uy", value = 0.0 }]
gravity = { acceleration = [0.0, -9.81], density = 2000.0, ramp = "linear" }
[[stage]]
prescribed = [{ set = "top", component = "uy", increment = -1e-3 }]
"#,
    );
    for (k, ramp) in [(0, Ramp::Linear), (1, Ramp::Constant)] {
        let body = s[k].loading.body.as_ref().expect("gravity in force");
        assert_eq!((body.0)(0, [0.3, 0.7]), [0.0, -19620.0, 0.0]);
        assert_eq!(s[k].loading.body_ramp, ramp);
    }
}

/// A job without `[[stage]]` is the one stage of its `[loading]`.
#[test]
fn a_loading_job_is_one_stage() {
    let job = cosdem_job::fixtures::load("elastic-panel");
    let s = job.stages().unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(s[0].steps, 4);
    assert_eq!(s[0].loading.dirichlet, job.loading().dirichlet);
}

/// Every bad stage is refused naming the key (stages counted from 0) and the value.
#[test]
fn bad_stages_are_refused_naming_the_key() {
    let cases = [
        ("[[stage]]\nsteps = 0\n", "stage[0].steps", "0"),
        ("[[stage]]\nrepeat = 0\n", "stage[0].repeat", "0"),
        (
            "[[stage]]\nprescribed = [{ set = \"top\", component = \"uy\" }]\n",
            "stage[0].prescribed[0]",
            "exactly one of value, increment, path or free",
        ),
        (
            "[[stage]]\nprescribed = [{ set = \"top\", component = \"uy\", value = 1.0, increment = 1.0 }]\n",
            "stage[0].prescribed[0]",
            "exactly one",
        ),
        (
            "[[stage]]\n[[stage]]\nprescribed = [{ set = \"top\", component = \"uy\", value = nan }]\n",
            "stage[1].prescribed[0]",
            "NaN",
        ),
        (
            "[[stage]]\ngravity = { acceleration = [0.0, -9.81], density = 0.0 }\n",
            "stage[0].gravity.density",
            "bulk density",
        ),
        ("[loading.compression]\ndisplacement = 0.01\n[[stage]]\n", "loading", "[[stage]]"),
    ];
    for (text, key, says) in cases {
        let e = staged(text).unwrap_err();
        assert!(e.contains(key) && e.contains(says), "{text}: {e}");
    }
}

/// A set the mesh lacks, and a removal of a load never applied, are refused when the
/// stages are built, naming the key and the value.
#[test]
fn unknown_sets_and_removals_of_nothing_are_refused() {
    let job = staged(
        "[[stage]]\n[[stage]]\nprescribed = [{ set = \"footing\", component = \"uy\", value = 0.0 }]\n",
    )
    .unwrap();
    let e = job.model().unwrap_err().to_string();
    assert!(e.contains("stage[1].prescribed[0].set") && e.contains("footing"), "{e}");
    let job = staged("[[stage]]\npressure = [{ set = \"nosuch\", value = 1.0 }]\n").unwrap();
    let e = job.model().unwrap_err().to_string();
    assert!(e.contains("stage[0].pressure[0].set") && e.contains("nosuch"), "{e}");
    let job = staged("[[stage]]\npressure = [{ set = \"left\", ramp = \"remove\" }]\n").unwrap();
    let e = job.stages().unwrap_err().to_string();
    assert!(e.contains("stage[0].pressure[0].set") && e.contains("no earlier stage"), "{e}");
}

/// The stages given one at a time (`next_stages`, as the application's stepper gives them)
/// are `stages` (the same loadings, compared through their debug text, every number written
/// out), with regions and gravity too. A bad stage is refused naming its key (its index is the
/// count so far) and leaves what is in force as it was: the next good stage expands as if the
/// bad one had not been given.
#[test]
fn stages_one_at_a_time_are_the_jobs_stages() {
    let text = |s: &[SolverStage]| format!("{s:?}");
    let job = staged(LOAD_UNLOAD).unwrap();
    let mesh = job.build_mesh().unwrap();
    let base = Job { stage: Vec::new(), ..job.clone() };
    let mut so_far = cosdem_job::StagesSoFar::default();
    let mut one_by_one = Vec::new();
    for (i, stage) in job.stage.iter().enumerate() {
        if i == 1 {
            let mut bad = stage.clone();
            bad.steps = 0;
            let e = base.next_stages(&bad, &mut so_far, &mesh).unwrap_err().to_string();
            assert!(e.contains("stage[1].steps"), "{e}");
            let mut bad = stage.clone();
            bad.prescribed[0].set = "lid".into();
            let e = base.next_stages(&bad, &mut so_far, &mesh).unwrap_err().to_string();
            assert!(e.contains("stage[1].prescribed[0].set") && e.contains("lid"), "{e}");
            assert!(e.contains("known: ") && e.contains("top"), "{e}");
        }
        one_by_one.extend(base.next_stages(stage, &mut so_far, &mesh).unwrap());
    }
    assert_eq!(so_far.count(), 3);
    assert_eq!(text(&one_by_one), text(&job.stages().unwrap()));

    let regions = Job::from_toml(
        &cosdem_job::fixtures::text("rectangle-two-regions"),
        "rectangle-two-regions.toml",
    )
    .unwrap();
    let gravity = r#"
[[stage]]
prescribed = [{ set = "bottom", component = "uy", value = 0.0 },
              { set = "bottom", component = "ux", value = 0.0 }]
gravity = { acceleration = [0.0, -9.81], density = 1800.0 }
[[stage]]
prescribed = [{ set = "top", component = "uy", increment = -1e-3 }]
[[stage]]
gravity = { acceleration = [0.0, -9.81], ramp = "remove" }
"#;
    let mut job = regions.clone();
    job.loading = Default::default();
    job.stage = toml::from_str::<StageList>(gravity).unwrap().stage;
    job.validate().unwrap();
    let mesh = job.build_mesh().unwrap();
    let base = Job { stage: Vec::new(), ..job.clone() };
    let mut so_far = cosdem_job::StagesSoFar::default();
    let mut one_by_one = Vec::new();
    for stage in &job.stage {
        one_by_one.extend(base.next_stages(stage, &mut so_far, &mesh).unwrap());
    }
    assert_eq!(text(&one_by_one), text(&job.stages().unwrap()));
}

/// `[[stage]]` tables alone.
#[derive(serde::Deserialize)]
struct StageList {
    stage: Vec<cosdem_job::StageSection>,
}

/// `[loading.control]` and `[stage.control]` reach the solver's loading (the stage's on its
/// own stage only: a path control is not held into the next stage), and a control on a set
/// the mesh lacks is refused naming the key and the value.
#[test]
fn path_controls_reach_the_loading_and_unknown_sets_are_refused() {
    let got = stages(
        "[[stage]]\nprescribed = [{ set = \"top\", component = \"uy\", value = -1e-3 }]\n\
         control = { set = \"left\", component = \"ux\", value = -2e-4 }\n[[stage]]\n",
    );
    let c = got[0].loading.control.as_ref().expect("the first stage's control");
    assert_eq!((c.set.as_str(), c.component, c.value), ("left", Component::Ux, -2e-4));
    assert!(got[1].loading.control.is_none());
    let e = staged("[[stage]]\ncontrol = { set = \"lid\", component = \"uy\", value = 1e-3 }\n")
        .unwrap()
        .model()
        .unwrap_err()
        .to_string();
    assert!(e.contains("stage[0].control.set") && e.contains("lid"), "{e}");

    let plain = |control: &str| {
        let text = format!(
            "[mesh]\nkind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2\n\n\
             [material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3\n\n\
             [loading.compression]\ndisplacement = 0.01\n\n[loading.control]\n{control}"
        );
        Job::from_toml(&text, "control.toml").map_err(|e| e.to_string())
    };
    let model =
        plain("set = \"left\"\ncomponent = \"ux\"\nvalue = -1e-3\n").unwrap().model().unwrap();
    let c = model.loading.control.expect("the job's control");
    assert_eq!((c.set.as_str(), c.component, c.value), ("left", Component::Ux, -1e-3));
    let e =
        plain("set = \"side\"\ncomponent = \"ux\"\nvalue = -1e-3\n").unwrap().model().unwrap_err();
    assert!(e.to_string().contains("loading.control.set") && e.to_string().contains("side"), "{e}");
    let e =
        plain("set = \"left\"\ncomponent = \"ux\"\nvalue = 0.0\n").unwrap().model().unwrap_err();
    assert!(e.to_string().contains("loading.control.value"), "{e}");
    let e = plain("set = \"left\"\ncomponent = \"ux\"\n").unwrap_err();
    assert!(e.contains("value"), "{e}");
    // A combination: the top's mean u_y minus twice the left side's mean u_x.
    let both = "set = \"top\"\ncomponent = \"uy\"\nvalue = -1e-3\n\
                plus = [{ set = \"left\", component = \"ux\", weight = -2.0 }]\n";
    let c = plain(both).unwrap().model().unwrap().loading.control.expect("the job's control");
    assert_eq!(c.plus.len(), 1);
    let term = &c.plus[0];
    assert_eq!((term.set.as_str(), term.component, term.weight), ("left", Component::Ux, -2.0));
    // `increment` counts steps in the compression's displacement: refused with a control.
    let e = Job::from_toml(
        &format!(
            "[mesh]\nkind = \"rectangle\"\nlx = 1.0\nly = 1.0\nnx = 2\nny = 2\n\n\
             [material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3\n\n\
             [loading]\nincrement = 0.002\n\n[loading.compression]\ndisplacement = 0.01\n\n\
             [loading.control]\n{both}"
        ),
        "control.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("loading.increment") && e.contains("steps"), "{e}");
    let flank = both.replace("\"left\"", "\"flank\"");
    let e = plain(&flank).unwrap().model().unwrap_err().to_string();
    assert!(e.contains("loading.control.plus[0].set") && e.contains("flank"), "{e}");
}
