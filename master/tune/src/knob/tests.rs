use super::*;

fn quick() -> Job {
    Job::from_toml(include_str!("../../../../examples/quick.toml"), "examples/quick.toml").unwrap()
}

/// Every knob's name reads back as the knob (`Display` and `FromStr` agree), names are
/// unique, and a row label that is no knob (`reference`, `default`, a combination) is none,
/// with the error naming it.
#[test]
fn names_round_trip() {
    let mut names = std::collections::BTreeSet::new();
    for k in Knob::ALL {
        assert_eq!(k.to_string(), k.name());
        assert_eq!(k.name().parse::<Knob>().unwrap(), k);
        assert_eq!(Knob::from_name(k.name()), Some(k));
        assert!(names.insert(k.name()), "{k} twice");
    }
    for label in ["reference", "default", "accuracy", "cheapest", "relaxation", ""] {
        assert_eq!(Knob::from_name(label), None);
        let e = label.parse::<Knob>().unwrap_err();
        assert!(matches!(&e, TableError::UnknownKnob { knob } if knob == label), "{e:?}");
    }
}

/// The knobs a plan sets are the catalogue's planned ones, in the catalogue's order (the
/// report's order, unchanged since the planner listed them by name), and the knobs that set
/// the time step are all planned.
#[test]
fn planned_knobs_in_report_order() {
    let names: Vec<&str> = Knob::PLANNED.iter().map(|k| k.name()).collect();
    assert_eq!(
        names,
        [
            "load_step",
            "relaxation.tolerance",
            "relaxation.safety",
            "relaxation.density_scale",
            "relaxation.driver",
            "tangent",
            "warm_start",
            "relaxation.skip_below",
            "relaxation.elastic_shortcut",
        ]
    );
    let timed: Vec<Knob> = Knob::ALL.into_iter().filter(|k| k.sets_time_step()).collect();
    assert_eq!(
        timed,
        [Knob::RelaxationSafety, Knob::RelaxationDensityScale, Knob::RelaxationDriver]
    );
    assert!(timed.iter().all(|k| k.planned()));
}

/// `apply_setting` makes the same job as the sweep's variant of that setting; a setting or a
/// knob it does not know is refused with the error that names it.
#[test]
fn apply_setting_agrees_with_the_variants() {
    let job = quick();
    let side =
        |j: &mut Job| std::mem::replace(assembly_mut(j).unwrap().packing.side_mut().unwrap(), 0.0);
    for v in &variants(&job)[2..] {
        let mut j = job.clone();
        apply_setting(&mut j, v.knob, &v.setting).unwrap();
        let mut expect = v.job.clone();
        // The side is printed to 3 decimals in the setting (0.1 * 0.75 = 0.07500000000000001).
        let (a, b) = (side(&mut j), side(&mut expect));
        assert!((a - b).abs() <= 5e-4, "{}: side {a} vs {b}", v.slug());
        assert_eq!(j, expect, "{}", v.slug());
    }
    let refused = |knob: &str, setting: &str| {
        let mut j = job.clone();
        let e = apply_setting(&mut j, knob, setting).unwrap_err();
        assert_eq!(j, job, "a refused setting leaves the job as it was");
        e
    };
    for (knob, setting) in [
        ("tangent", "magic"),
        ("load_step", "x0"),
        ("load_step", "4"),
        ("relaxation.tolerance", "-1"),
        ("relaxation.safety", "inf"),
        ("warm_start", "yes"),
        ("newton.stall_iterations", "-1"),
    ] {
        let e = refused(knob, setting);
        let named = |k: &str, s: &str| k == knob && s == setting;
        assert!(
            matches!(&e, TableError::UnknownSetting { knob: k, setting: s } if named(k, s)),
            "{knob} = {setting}: {e:?}"
        );
    }
    assert!(matches!(refused("relaxation.magic", "1"), TableError::UnknownKnob { .. }));
    // An analytical material has no assembly knobs.
    let elastic =
        Job::from_toml(include_str!("../../../../examples/elastic.toml"), "elastic").unwrap();
    let mut j = elastic.clone();
    let e = Knob::WarmStart.apply(&mut j, "true").unwrap_err();
    assert!(matches!(e, TableError::UnknownSetting { .. }), "{e:?}");
    Knob::LoadStep.apply(&mut j, "x2").unwrap();
    assert_ne!(j, elastic);
}

/// A knob's value reads what `apply` set, and `reset` puts back the value of the assembly it
/// is given (the planned knobs: the table's default settings).
#[test]
fn value_apply_and_reset_agree() {
    let job = quick();
    let mut j = job.clone();
    Knob::RelaxationTolerance.apply(&mut j, "1e-3").unwrap();
    Knob::RelaxationDriver.apply(&mut j, "fire").unwrap();
    Knob::Tangent.apply(&mut j, "sliding_aware").unwrap();
    Knob::WarmStart.apply(&mut j, "true").unwrap();
    assert_eq!(Knob::RelaxationTolerance.value(&j), "1e-3");
    assert_eq!(Knob::RelaxationDriver.value(&j), "fire");
    assert_eq!(Knob::Tangent.value(&j), "sliding_aware");
    assert_eq!(Knob::WarmStart.value(&j), "true");
    let original = assembly_of(&job).unwrap().clone();
    let a = assembly_mut(&mut j).unwrap();
    for k in Knob::PLANNED {
        k.reset(a, &original);
    }
    assert_eq!(j, job);
}

/// `--skip` names a variant by knob or by knob=setting, nothing else.
#[test]
fn skip_by_knob_or_setting() {
    let job = quick();
    let v = variants(&job);
    let fire = v.iter().find(|v| v.setting == "fire").unwrap();
    let x2 = v.iter().find(|v| v.knob == "load_step" && v.setting == "x2").unwrap();
    let by_knob = ["relaxation.driver".to_string()];
    assert!(skipped(fire, &by_knob) && !skipped(x2, &by_knob));
    let by_setting = ["load_step=x4".to_string()];
    assert!(!skipped(x2, &by_setting));
    assert!(v.iter().any(|v| skipped(v, &by_setting)));
    assert!(!skipped(fire, &[]));
}

/// The sweep of a DEM job moves every knob of the catalogue, one at a time, and keeps the
/// scene.
#[test]
fn variants_move_one_knob() {
    let job = quick();
    let v = variants(&job);
    assert_eq!(v[0].knob, "reference");
    assert_eq!(v[1].job, job);
    let knobs: std::collections::BTreeSet<_> = v.iter().map(|v| v.knob).collect();
    for k in Knob::ALL {
        assert!(knobs.contains(k.name()), "{k} missing");
    }
    for x in &v[2..] {
        assert_eq!(x.job.mesh, job.mesh, "{}", x.slug());
        assert_ne!(x.job, job, "{} changes nothing", x.slug());
    }
    let slugs: std::collections::BTreeSet<_> = v.iter().map(Variant::slug).collect();
    assert_eq!(slugs.len(), v.len(), "slugs must be unique (run directories)");
    // The load-path row takes the reference's step with the job's relaxation.
    let half = v.iter().find(|v| v.knob == "load_step" && v.setting == "x0.5").unwrap();
    assert_eq!(half.job.loading.increment, Some(0.001));
    assert_eq!(half.job.loading.increment, v[0].job.loading.increment);
    assert_eq!(half.job.material, job.material);
}

/// A job that already sets a sweep's setting (tolerance 1e-3, mass scaling 4, FIRE, warm
/// start) gets no row for it: the row would be the default run again, at its full cost.
#[test]
fn a_setting_the_job_has_is_not_swept_again() {
    let mut job = quick();
    let a = assembly_mut(&mut job).unwrap();
    a.relaxation.tolerance = 1e-3;
    a.relaxation.density_scale = 4.0;
    a.relaxation.driver = Driver::fire();
    a.warm_start = true;
    let v = variants(&job);
    for x in &v[2..] {
        assert_ne!(x.job, job, "{} repeats the default", x.slug());
    }
    let settings: Vec<_> = v.iter().map(Variant::slug).collect();
    for kept in ["relaxation.tolerance_3e-4", "relaxation.density_scale_16"] {
        assert!(settings.iter().any(|s| s == kept), "{kept} missing: {settings:?}");
    }
    for gone in ["relaxation.driver", "warm_start"] {
        assert!(!settings.iter().any(|s| s.starts_with(gone)), "{gone}: {settings:?}");
    }
}

/// An analytical material is swept on the load step and Newton's knobs only.
#[test]
fn an_analytical_material_has_no_assembly_knobs() {
    let job = Job::from_toml(include_str!("../../../../examples/elastic.toml"), "elastic").unwrap();
    let knobs: std::collections::BTreeSet<_> = variants(&job)[2..].iter().map(|v| v.knob).collect();
    for k in knobs {
        let k = Knob::from_name(k).unwrap();
        assert!(
            matches!(k, Knob::LoadStep | Knob::NewtonSecantUpdates | Knob::NewtonStallIterations),
            "{k}"
        );
    }
}

/// A job in stages: the load-step knob scales each stage's step count (the stage's loads are
/// totals), at least one step, rounded; the reference doubles each stage's steps, and the
/// report names them. The retaining wall's first stage (the surcharge in 1 step) keeps 1
/// under `x2`, its push of 30 steps takes 15; the reference runs 2 and 60.
#[test]
fn the_load_step_of_a_job_in_stages_is_each_stages_steps() {
    let path = "examples/retaining-smooth-active.toml";
    let text = include_str!("../../../../examples/retaining-smooth-active.toml");
    let job = Job::from_toml(text, path).unwrap();
    let steps = |j: &Job| j.stage.iter().map(|s| s.steps).collect::<Vec<_>>();
    let given = steps(&job);
    assert_eq!(given.len(), 2, "{given:?}");
    let mut coarse = job.clone();
    Knob::LoadStep.apply(&mut coarse, "x2").unwrap();
    let expect = |f: f64| {
        given.iter().map(|&n| ((n as f64 / f).round() as usize).max(1)).collect::<Vec<_>>()
    };
    assert_eq!(steps(&coarse), expect(2.0));
    assert_eq!(steps(&coarse), [1, 15]);
    assert_eq!(coarse.loading, job.loading);
    let fine = reference(&job).job;
    assert_eq!(steps(&fine), given.iter().map(|n| 2 * n).collect::<Vec<_>>());
    assert_eq!(Knob::LoadStep.value(&job), format!("stage steps [{}, {}]", given[0], given[1]));
}
