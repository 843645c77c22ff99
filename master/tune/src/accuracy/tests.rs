//! The planner on made-up tables, whose errors and costs are chosen so that the right pick is
//! known by construction, and one smoke test that the committed tables still parse and plan
//! as documented.
//!
//! Tolerances: a made-up table prints round decimals (F_u 100 + 2 = 102), so a predicted
//! error or cost is the sum or product of a few correctly rounded quotients: 1e-12 covers
//! their round-off and nothing else.

use super::*;
use crate::knob::Knob;
use crate::table::TableError;
use cosdem_dem::AssemblySpec;
use cosdem_dem::spec::Driver;

fn quick(accuracy: Option<f64>) -> Job {
    let text = include_str!("../../../../examples/quick.toml");
    let text = match accuracy {
        Some(a) => format!("accuracy = {a}\n{text}"),
        None => text.to_string(),
    };
    Job::from_toml(&text, "quick").unwrap()
}

/// The quick job with random 4-6 mm assemblies and `accuracy`.
fn random_quick(accuracy: f64) -> Job {
    let text = format!("accuracy = {accuracy}\n{}", include_str!("../../../../examples/quick.toml"))
        .replace(
            r#"packing = { kind = "hexagonal", radius = 0.005, side = 0.1 }"#,
            r#"packing = { kind = "random", r_min = 0.004, r_max = 0.006, side = 0.1, seed = 3, confining_stress = 1e5 }"#,
        );
    Job::from_toml(&text, "random").unwrap()
}

fn assembly(job: &Job) -> &AssemblySpec {
    match &job.material {
        MaterialSection::Dem { assembly } => assembly,
        MaterialSection::Elastic { .. } => panic!("DEM job"),
    }
}

/// One made-up row: knob, setting, status, DEM steps, and its F_u and E shifts from the
/// default in percent of the reference (`None`: the row has no E).
type Made<'a> = (&'a str, &'a str, &'a str, u64, f64, Option<f64>);

/// A made-up sweep (hexagonal assemblies): the reference at F_u = 100, E = 10 and 1000 DEM
/// steps; the default 100 DEM steps, `default_percent` % off on both; each row shifted
/// upwards from the default by its percentages. No F_res anywhere (a pre-peak table).
fn made_up(default_percent: f64, rows: &[Made]) -> Trade {
    let mut csv = String::from(
        "knob,setting,status,displacement,wall_seconds,speedup,dem_steps,cuts,peak_load,\
         residual_load,stiffness,err_peak,err_residual,err_stiffness,err_curve\n\
         reference,tight,finished,1,1,1,1000,0,100,,10,0,,0,0\n",
    );
    let d = default_percent;
    let e = d / 100.0;
    csv.push_str(&format!(
        "default,as given,finished,1,1,1,100,0,{},,{},{e},,{e},0\n",
        100.0 + d,
        10.0 + d / 10.0
    ));
    for &(knob, setting, status, steps, fu, stiffness) in rows {
        let e_stiffness = stiffness.map_or(String::new(), |s| format!("{}", 10.0 + (d + s) / 10.0));
        csv.push_str(&format!(
            "{knob},{setting},{status},1,1,1,{steps},0,{},,{e_stiffness},0,,0,0\n",
            100.0 + d + fu
        ));
    }
    Trade::from_csv(&csv, "made-up").unwrap()
}

/// The rows a plan moved (`knob=setting`), in report order.
fn moved(plan: &Plan) -> Vec<String> {
    plan.report.knobs.iter().filter_map(|c| c.row.clone()).collect()
}

fn knob_choice<'a>(plan: &'a Plan, knob: &str) -> &'a KnobChoice {
    plan.report.knobs.iter().find(|c| c.knob == knob).unwrap()
}

/// A job without `accuracy` has no plan (it runs as written), whatever the table.
#[test]
fn no_target_no_plan() {
    assert!(tune(&quick(None)).unwrap().is_none());
    let trade = made_up(0.1, &[("relaxation.tolerance", "1e-3", "finished", 50, 1.0, Some(0.0))]);
    assert!(plan(&quick(None), &trade, &[]).unwrap().is_none());
}

/// A target of 4 % (budget 2 %) over a default 0.1 % off: the tolerance row (1 % shift, half
/// the DEM steps) fits and is picked; the load-step row is cheaper (0.3) but its 3 % alone
/// exceeds the budget, so it stays at the default and the report says why. The prediction
/// is the default's error plus the picked shift, the cost the picked ratio; the tuned job
/// carries the setting and no `accuracy`.
#[test]
fn a_cheaper_setting_within_the_budget_is_picked_and_one_over_it_is_not() {
    let trade = made_up(
        0.1,
        &[
            ("load_step", "x4", "finished", 30, 3.0, Some(0.0)),
            ("relaxation.tolerance", "1e-3", "finished", 50, 1.0, Some(0.5)),
        ],
    );
    let p = plan(&quick(Some(0.04)), &trade, &[]).unwrap().unwrap();
    assert_eq!(moved(&p), ["relaxation.tolerance=1e-3"]);
    assert_eq!(p.report.budget, 0.02);
    assert!((p.report.predicted.peak.unwrap() - 0.011).abs() < 1e-12);
    assert!((p.report.predicted.stiffness.unwrap() - 0.006).abs() < 1e-12);
    assert_eq!(p.report.predicted.residual, None);
    assert!((p.report.predicted_dem_steps_ratio - 0.5).abs() < 1e-12);
    let step = knob_choice(&p, "load_step");
    assert!(step.why.contains("with x4 the cheapest combination would exceed"), "{}", step.why);
    assert_eq!(p.job.accuracy, None);
    assert_eq!(assembly(&p.job).relaxation.tolerance, 1e-3);
    assert_eq!(p.job.loading.increment, quick(None).loading.increment);
    // Every planned knob is reported once, in the catalogue's order.
    let names: Vec<&str> = p.report.knobs.iter().map(|c| c.knob.as_str()).collect();
    assert_eq!(names, Knob::PLANNED.map(|k| k.name()));
    // The table measured no F_res: the report says it is not covered.
    assert!(p.report.warnings.iter().any(|w| w.contains("measured no F_res")));
}

/// A tight budget between the measured shifts picks the cheapest combination that fits,
/// not the cheapest knob alone: where the cheapest setting of one knob costs the whole
/// budget, two cheaper-together settings of other knobs win.
#[test]
fn the_cheapest_combination_within_the_budget_wins() {
    let trade = made_up(
        0.0,
        &[
            ("load_step", "x4", "finished", 30, 3.0, Some(0.0)),
            ("relaxation.tolerance", "1e-3", "finished", 50, -1.0, Some(0.0)),
            ("warm_start", "true", "finished", 50, 0.5, Some(0.0)),
        ],
    );
    // Budget 2 %: x4 alone (3 %) does not fit; tolerance + warm start (1.5 %, 0.25) do.
    let p = plan(&quick(Some(0.04)), &trade, &[]).unwrap().unwrap();
    assert_eq!(moved(&p), ["relaxation.tolerance=1e-3", "warm_start=true"]);
    assert!((p.report.predicted.peak.unwrap() - 0.015).abs() < 1e-12);
    assert!((p.report.predicted_dem_steps_ratio - 0.25).abs() < 1e-12);
    // Budget 4.25 %: all three (4.5 %) do not fit; x4 with one of the others does (0.15 <
    // 0.25), and on that tie of cost the smaller error wins: warm start (3.5 %) over the
    // tolerance (4 %), though the search meets the tolerance first.
    let p = plan(&quick(Some(0.085)), &trade, &[]).unwrap().unwrap();
    assert_eq!(moved(&p), ["load_step=x4", "warm_start=true"]);
    assert!((p.report.predicted.peak.unwrap() - 0.035).abs() < 1e-12);
    assert!((p.report.predicted_dem_steps_ratio - 0.15).abs() < 1e-12);
}

/// The knobs that set the time step (safety, mass scaling, FIRE) are never moved together,
/// however loose the target and however cheap they would be together (0.6 x 0.5 x 0.7): the
/// cheapest of them alone (FIRE, 0.5) is picked, with the warm start that combines freely,
/// and the other two say why they stay. `cheapest` (no budget at all) keeps the same rule.
#[test]
fn time_step_knobs_are_not_combined() {
    let trade = made_up(
        0.0,
        &[
            ("relaxation.safety", "0.7", "finished", 60, 0.0, Some(0.0)),
            ("relaxation.density_scale", "4", "finished", 70, 0.0, Some(0.0)),
            ("relaxation.driver", "fire", "finished", 50, 0.0, Some(0.0)),
            ("warm_start", "true", "finished", 50, 0.0, Some(0.0)),
        ],
    );
    let p = plan(&quick(Some(0.5)), &trade, &[]).unwrap().unwrap();
    assert_eq!(moved(&p), ["relaxation.driver=fire", "warm_start=true"]);
    assert!((p.report.predicted_dem_steps_ratio - 0.25).abs() < 1e-12);
    for knob in ["relaxation.safety", "relaxation.density_scale"] {
        let why = &knob_choice(&p, knob).why;
        assert!(why.contains("relaxation.driver was moved"), "{knob}: {why}");
    }
    let a = assembly(&p.job);
    assert_eq!(a.relaxation.driver, Driver::fire());
    assert_eq!((a.relaxation.safety, a.relaxation.density_scale), (0.8, 1.0));
    let c = cheapest(&quick(None), &trade).unwrap().unwrap();
    assert_eq!(moved(&c), moved(&p));
}

/// A setting that saves less than [`MIN_SAVING`] of the default's DEM steps (96 of 100) is
/// no candidate, however accurate (no shift at all): with only such rows nothing is picked,
/// and the report names each with its reason. One that saves 10 % is picked.
#[test]
fn no_saving_below_min_saving_picks_nothing() {
    let rows = [
        ("relaxation.density_scale", "4", "finished", 96, 0.0, Some(0.0)),
        ("tangent", "sliding_aware", "finished", 100, 0.0, Some(0.0)),
    ];
    let p = plan(&quick(Some(0.5)), &made_up(0.1, &rows), &[]).unwrap().unwrap();
    assert!(moved(&p).is_empty());
    assert_eq!(p.report.predicted_dem_steps_ratio, 1.0);
    assert_eq!(p.report.not_candidates.len(), 2);
    assert!(
        p.report.not_candidates[0]
            .starts_with("relaxation.density_scale=4: 96 DEM steps against 100 for the default"),
        "{:?}",
        p.report.not_candidates
    );
    assert!(p.report.not_candidates.iter().all(|n| n.contains("saves less than 5 %")));
    let mut rows = rows.to_vec();
    rows.push(("relaxation.skip_below", "1e-3", "finished", 90, 0.0, Some(0.0)));
    let p = plan(&quick(Some(0.5)), &made_up(0.1, &rows), &[]).unwrap().unwrap();
    assert_eq!(moved(&p), ["relaxation.skip_below=1e-3"]);
}

/// Never a candidate, whatever the target: a failed run, a time-step safety above
/// [`MAX_SAFETY`] (however well it did), a row whose effect on a property the default has is
/// unknown (no E), rows that are no knob a target sets (the assembly side, Newton's and the
/// substep's rows, a combination row), each with its reason.
#[test]
fn rows_that_are_never_candidates() {
    let trade = made_up(
        0.1,
        &[
            ("relaxation.tolerance", "1e-3", "failed: step 3", 10, 0.0, Some(0.0)),
            ("relaxation.safety", "0.95", "finished", 20, 0.0, Some(0.0)),
            ("warm_start", "true", "finished", 30, 0.0, None),
            ("assembly.side", "0.050", "finished", 40, 0.0, Some(0.0)),
            ("newton.secant_updates", "true", "finished", 40, 0.0, Some(0.0)),
            ("relaxation.substep", "5e-4", "finished", 40, 0.0, Some(0.0)),
            ("cheapest", "warm_start=true", "finished", 40, 0.0, Some(0.0)),
        ],
    );
    let p = plan(&quick(Some(0.99)), &trade, &[]).unwrap().unwrap();
    assert!(moved(&p).is_empty(), "{:?}", moved(&p));
    let reasons = &p.report.not_candidates;
    let expect = [
        "relaxation.tolerance=1e-3: its run did not finish (failed: step 3)",
        "relaxation.safety=0.95: above the largest safety ever picked (0.8)",
        "warm_start=true: its effect on a measured property is unknown",
        "assembly.side=0.050: the assembly size is the user's choice",
        "newton.secant_updates=true: not a knob the target sets",
        "relaxation.substep=5e-4: not a knob the target sets",
        "cheapest=warm_start=true: moves several knobs",
    ];
    assert_eq!(reasons.len(), expect.len(), "{reasons:?}");
    for (r, e) in reasons.iter().zip(expect) {
        assert!(r.starts_with(e), "{r:?} should start with {e:?}");
    }
    assert!(
        knob_choice(&p, "relaxation.safety").why.contains("no measured setting is a candidate")
    );
}

/// A target below what the default itself reaches (3 % off, budget 2.5 %) moves nothing and
/// warns; the tuned job is the job with its planned knobs reset to the table's default (the
/// worker's defaults). The plan is a pure function of its inputs.
#[test]
fn a_target_below_the_default_error_moves_nothing() {
    let trade = made_up(3.0, &[("relaxation.tolerance", "1e-3", "finished", 50, 0.0, Some(0.0))]);
    let mut job = quick(Some(0.05));
    assembly_mut(&mut job).relaxation.tolerance = 1e-6;
    let p = plan(&job, &trade, &[]).unwrap().unwrap();
    assert!(moved(&p).is_empty());
    assert!(p.report.warnings.iter().any(|w| w.contains("no speed setting is moved")));
    let mut expect = job.clone();
    expect.accuracy = None;
    choice::reset_knobs(assembly_mut(&mut expect), None);
    assert_eq!(p.job, expect);
    assert_eq!(assembly(&p.job).relaxation.tolerance, AssemblySpec::default().relaxation.tolerance);
    let tolerance = knob_choice(&p, "relaxation.tolerance");
    assert_eq!(tolerance.was, "1e-6");
    assert_eq!(plan(&job, &trade, &[]).unwrap().unwrap().job, p.job);
}

fn assembly_mut(job: &mut Job) -> &mut AssemblySpec {
    crate::knob::assembly_mut(job).expect("DEM job")
}

/// A trade made from a sweep of the job itself (`base`: its default row ran the job as
/// given) resets the planned knobs to the job's own values, not the worker's: the tangent
/// the job chose stays.
#[test]
fn a_sweep_of_the_job_keeps_its_own_defaults() {
    let mut job = quick(Some(0.5));
    assembly_mut(&mut job).tangent = cosdem_dem::spec::TangentKind::Secant;
    let committed = made_up(0.0, &[("warm_start", "true", "finished", 50, 0.0, Some(0.0))]);
    let own = Trade { base: Some(assembly(&job).clone()), ..committed.clone() };
    let from_own = plan(&job, &own, &[]).unwrap().unwrap();
    assert_eq!(assembly(&from_own.job).tangent, cosdem_dem::spec::TangentKind::Secant);
    let from_committed = plan(&job, &committed, &[]).unwrap().unwrap();
    assert_eq!(assembly(&from_committed.job).tangent, cosdem_dem::spec::TangentKind::Paper);
}

/// A job of another packing kind than the table's (random against a hexagonal table) is
/// planned with the tight reference settings, with a warning; `cheapest` has no plan for it.
#[test]
fn another_packing_falls_back_to_the_reference() {
    let trade = made_up(0.1, &[("relaxation.tolerance", "1e-3", "finished", 50, 1.0, Some(0.0))]);
    let job = random_quick(0.05);
    let p = plan(&job, &trade, &[]).unwrap().unwrap();
    assert!(p.report.fallback_to_reference);
    assert!(p.report.warnings[0].contains("does not carry over to random"));
    assert!(p.report.knobs.iter().all(|c| c.row.as_deref() == Some("reference=tight")));
    let mut plain = job.clone();
    plain.accuracy = None;
    assert_eq!(p.job, crate::knob::reference(&plain).job);
    assert!(cheapest(&job, &trade).unwrap().is_none());
}

/// What cannot be planned says what is wrong: a table without its reference or whose
/// default failed is no model ([`AccuracyError::Model`]), a malformed CSV a table error, and
/// a candidate row whose setting the knob does not know fails when applied
/// ([`TableError::UnknownSetting`]) rather than being skipped.
#[test]
fn errors_name_what_is_wrong() {
    let header = "knob,setting,status,displacement,wall_seconds,speedup,dem_steps,cuts,\
                  peak_load,residual_load,stiffness,err_peak,err_residual,err_stiffness,\
                  err_curve\n";
    let default = "default,as given,finished,1,1,1,100,0,100,,10,0,,0,0\n";
    let reference = "reference,tight,finished,1,1,1,1000,0,100,,10,0,,0,0\n";
    let model = |text: String| match Trade::from_csv(&text, "t") {
        Err(AccuracyError::Model { message, .. }) => message,
        other => panic!("{other:?}"),
    };
    assert_eq!(model(format!("{header}{default}")), "no reference row");
    assert_eq!(model(format!("{header}{reference}")), "no default row");
    let failed = default.replace("finished", "failed: step 1");
    assert!(model(format!("{header}{reference}{failed}")).contains("did not finish"));
    assert!(matches!(
        Trade::from_csv("knob,setting\nx,y\n", "t"),
        Err(AccuracyError::Table(TableError::Csv { .. }))
    ));
    let trade = made_up(0.0, &[("relaxation.tolerance", "tight", "finished", 50, 0.0, Some(0.0))]);
    match plan(&quick(Some(0.5)), &trade, &[]) {
        Err(AccuracyError::Table(TableError::UnknownSetting { knob, setting })) => {
            assert_eq!((knob.as_str(), setting.as_str()), ("relaxation.tolerance", "tight"));
        }
        other => panic!("{other:?}"),
    }
}

/// The size law on made-up fits: `ln(F/F^cr) = -0.2 exp(-100 V^2)` at V = 0.01 gives
/// `|exp(-0.2 exp(-0.01)) - 1| = 0.1797` (computed the same way here: 1e-15 is round-off),
/// above a 5 % target (a warning); without a plateau (b* >= 0, or an interval reaching above
/// 0) nothing is predicted; a fit of another contact law does not apply; V is never changed.
#[test]
fn size_error_from_a_matching_fit() {
    let job = quick(Some(0.05));
    let trade = made_up(0.1, &[]);
    let none = plan(&job, &trade, &[]).unwrap().unwrap();
    assert!(none.report.size.fit.is_none());
    assert!(none.report.size.note.contains("no committed RVE-size study fit"));
    let fit = SizeFit {
        source: "made up".into(),
        assembly: assembly(&job).clone(),
        sizes: vec![0.005, 0.01, 0.02],
        peak_load: Some(LawParams { k: 2, a: -0.2, b_star: -100.0, b_star_high: Some(-50.0) }),
        residual_load: None,
        stiffness: None,
    };
    let p = plan(&job, &trade, std::slice::from_ref(&fit)).unwrap().unwrap();
    assert_eq!(p.report.size.fit.as_deref(), Some("made up"));
    let e = p.report.size.predicted.unwrap().peak.unwrap();
    let expect = ((-0.2f64 * (-100.0f64 * 1e-4).exp()).exp() - 1.0).abs();
    assert!((e - expect).abs() < 1e-15 && (e - 0.1797).abs() < 1e-4, "{e}");
    assert!(p.report.warnings.iter().any(|w| w.contains("assembly size alone")));
    assert!(p.report.size.note.contains("F_res: not fitted"), "{}", p.report.size.note);
    // No plateau (b* >= 0): no size error.
    assert_eq!(LawParams { k: 1, a: -0.2, b_star: 5.0, b_star_high: None }.size_error(0.01), None);
    // b* < 0 but its interval reaches above 0: not established either.
    let open = LawParams { k: 1, a: -0.2, b_star: -5.0, b_star_high: Some(3.0) };
    assert_eq!(open.size_error(0.01), None);
    assert_eq!(assembly(&p.job).packing, assembly(&job).packing);
    // The side and the speed knobs do not matter; the contact law does.
    let mut other_side = fit.clone();
    if let cosdem_dem::spec::PackingSpec::Hexagonal { side, .. } = &mut other_side.assembly.packing
    {
        *side *= 3.0;
    }
    other_side.assembly.warm_start = true;
    let p = plan(&job, &trade, &[other_side]).unwrap().unwrap();
    assert_eq!(p.report.size.fit.as_deref(), Some("made up"));
    let mut other = fit;
    if let cosdem_dem::spec::TangentialModel::Coulomb { mu_s, .. } =
        &mut other.assembly.contact.tangential
    {
        *mu_s = 0.3;
    }
    let p = plan(&job, &trade, &[other]).unwrap().unwrap();
    assert!(p.report.size.fit.is_none());
}

/// Smoke test of the committed data (`master/tune/data/`): the tables parse, and what they
/// plan for the quick example is what the docs say. Re-measuring a table changes these
/// picks: this test is the one to update then (with `docs/guide` and `data/README.md`).
///
/// - The hexagonal table: 17 settings, its default 0.135 % (F_u) / 0.236 % (E) off; at 5 %
///   every knob that saves DEM steps within the budget is moved (x4, tolerance 1e-3, FIRE),
///   safety 0.95 (failed), mass scaling (no saving) and the assembly side are not
///   candidates; a 0.1 % target moves nothing; the committed size fit predicts E 9.9 % below
///   E^cr for V = 0.01 (more than the target: a warning), F_u no plateau.
/// - The random table (the biaxial sweep to 1 %): its default is 2.1 % (F_u) / 2.9 % (E) from
///   the tight reference, so a 5 % target (budget 2.5 %) moves nothing and says so, while
///   10 % (budget 5 %) moves the relaxation tolerance (0.54 of the default's DEM steps), never
///   the load step (4.8-13 % there), never safety 0.95 (finished, but above MAX_SAFETY).
/// - Planned from the hexagonal table, a random job falls back to the reference.
#[test]
fn committed_tables_parse_and_plan() {
    let t = Trade::measured().unwrap();
    // 16 one-knob rows and the accuracy-0.05 combination (not a candidate).
    assert_eq!(t.settings.len(), 17);
    let e = t.default_error();
    assert_eq!(e.peak, Some(1.352761e-3));
    assert_eq!(e.stiffness, Some(2.361133e-3));
    assert_eq!(e.residual, None);
    // Mass scaling changed no value: no shift.
    let scaled = t.settings.iter().find(|r| r.knob == "relaxation.density_scale").unwrap();
    assert_eq!(t.shift(scaled).peak, Some(0.0));

    let job = quick(Some(0.05));
    let plan5 = tune(&job).unwrap().unwrap();
    let r = &plan5.report;
    assert_eq!(plan5.job.accuracy, None);
    assert!(r.predicted.worst() <= r.budget && r.budget == 0.025);
    let picked = |k: &str| r.knobs.iter().find(|c| c.knob == k).unwrap().row.clone();
    assert_eq!(picked("load_step").as_deref(), Some("load_step=x4"));
    assert_eq!(picked("relaxation.tolerance").as_deref(), Some("relaxation.tolerance=1e-3"));
    // FIRE saves 20 % of the DEM steps; the only larger safety (0.95) failed.
    assert_eq!(picked("relaxation.driver").as_deref(), Some("relaxation.driver=fire"));
    assert_eq!(picked("relaxation.safety"), None);
    let safety = r.knobs.iter().find(|c| c.knob == "relaxation.safety").unwrap();
    assert!(safety.why.contains("no measured setting is a candidate"), "{}", safety.why);
    assert_eq!(picked("relaxation.density_scale"), None);
    assert_eq!(picked("tangent"), None);
    let mut sum = r.default_error.peak.unwrap();
    for c in &r.knobs {
        sum += c.shift.peak.unwrap_or(0.0);
    }
    assert!((r.predicted.peak.unwrap() - sum).abs() < 1e-15);
    let product: f64 = r.knobs.iter().map(|c| c.dem_steps_ratio).product();
    assert!((r.predicted_dem_steps_ratio - product).abs() < 1e-12);
    assert!(r.not_candidates.iter().any(|n| n.starts_with("relaxation.safety=0.95")));
    assert!(r.not_candidates.iter().any(|n| n.starts_with("assembly.side=")));
    assert!(r.not_candidates.iter().any(|n| n.starts_with("relaxation.density_scale=16")));
    let a = assembly(&plan5.job);
    assert_eq!(a.relaxation.tolerance, 1e-3);
    assert_eq!(a.relaxation.safety, 0.8);
    assert_eq!(a.relaxation.driver, Driver::fire());
    assert_eq!(plan5.job.loading.increment, Some(0.008));
    // The size is the user's: unchanged.
    assert_eq!(a.packing, assembly(&job).packing);
    // The report says it in words and as JSON.
    let text = r.lines().join("\n");
    assert!(text.contains("load_step") && text.contains("x4"), "{text}");
    let json = serde_json::to_value(r).unwrap();
    assert_eq!(json["knobs"].as_array().unwrap().len(), Knob::PLANNED.len());
    assert!(r.warnings.iter().any(|w| w.contains("F_res")), "{:?}", r.warnings);
    // Failed settings are never picked, whatever the target; a target below what the default
    // itself reaches moves nothing.
    let loose = tune(&quick(Some(0.99))).unwrap().unwrap();
    assert!(loose.report.knobs.iter().all(|c| c.row.as_deref() != Some("relaxation.safety=0.95")));
    assert_ne!(assembly(&loose.job).relaxation.safety, 0.95);
    let tight = tune(&quick(Some(1e-3))).unwrap().unwrap();
    assert!(tight.report.knobs.iter().all(|c| c.row.is_none()));
    assert!(tight.report.warnings.iter().any(|w| w.contains("no speed setting is moved")));
    let mut expect = quick(None);
    choice::reset_knobs(assembly_mut(&mut expect), None);
    assert_eq!(tight.job, expect);
    let (a, b) = (tune(&quick(Some(0.05))).unwrap(), tune(&quick(Some(0.05))).unwrap());
    assert_eq!(a.unwrap().job, b.unwrap().job);

    // The committed size fit (scene A's study on the quarter mesh) matches the quick job (the
    // same assembly, another side and tangent). E's fit has a plateau: ln(E/E^cr) =
    // -0.1612 exp(-43.24 V) at V = 0.01 gives |E/E^cr - 1| = 0.0993, more than the 5 % target
    // alone (a warning). F_u's and F_res's b* intervals reach above 0: no plateau, nothing
    // predicted, and the note says why.
    let size = &r.size;
    assert_eq!(size.fit.as_deref().map(|f| f.contains("rve-size")), Some(true));
    assert!(size.note.contains("F_u: no plateau established"), "{}", size.note);
    assert!(size.note.contains("F_u not predicted, E 9.9"), "{}", size.note);
    let predicted = size.predicted.unwrap();
    assert_eq!(predicted.peak, None);
    assert_eq!(predicted.residual, None);
    let e = predicted.stiffness.unwrap();
    let expect = ((-0.1611678247445746f64 * (-43.2367682544591f64 * 0.01).exp()).exp() - 1.0).abs();
    assert!((e - expect).abs() < 1e-12 && (e - 0.0993).abs() < 1e-3, "{e}");
    assert!(r.warnings.iter().any(|w| w.contains("assembly size alone")));

    // The random table.
    let tight = tune(&random_quick(0.05)).unwrap().unwrap();
    assert!(!tight.report.fallback_to_reference);
    assert_eq!(tight.report.table, RANDOM_TABLE_NAME);
    assert!(tight.report.knobs.iter().all(|k| k.row.is_none()), "{:?}", tight.report.knobs);
    assert!(tight.report.warnings.iter().any(|w| w.contains("default settings alone")));
    let loose = tune(&random_quick(0.1)).unwrap().unwrap();
    let rows = moved(&loose);
    assert!(!rows.is_empty());
    assert!(rows.iter().all(|r| !r.starts_with("load_step")), "{rows:?}");
    assert!(!rows.contains(&"relaxation.safety=0.95".to_string()), "{rows:?}");
    assert!(loose.report.not_candidates.iter().any(|n| n.contains("largest safety")));
    assert!(loose.report.predicted.worst() <= 0.05);
    assert!(loose.report.predicted_dem_steps_ratio < 0.6);

    // A random job planned from the hexagonal table: the tight reference.
    let random = random_quick(0.05);
    let fallback = plan(&random, &t, &[]).unwrap().unwrap();
    assert!(fallback.report.fallback_to_reference);
    let mut plain = random.clone();
    plain.accuracy = None;
    assert_eq!(fallback.job, crate::knob::reference(&plain).job);
}

/// A job in stages plans like a one-stage job (the load-step knob scales each stage's steps:
/// `crate::knob`'s tests). The retaining wall's random assemblies plan from the committed
/// biaxial table as the guide says: 5 % moves nothing (the table's default is already more
/// than half of it from the reference) and leaves the job as written; 20 % picks the relaxation
/// tolerance 1e-3 and the warm start, and keeps the stages' loads and steps.
#[test]
fn a_job_in_stages_plans() {
    let text = include_str!("../../../../examples/retaining-smooth-active.toml");
    let wall = |a: f64| Job::from_toml(&format!("accuracy = {a}\n{text}"), "wall").unwrap();
    let five = tune(&wall(0.05)).unwrap().unwrap();
    assert!(five.report.knobs.iter().all(|c| c.row.is_none()), "{:?}", five.report.knobs);
    assert_eq!(five.job.stage, wall(0.05).stage);
    let twenty = tune(&wall(0.2)).unwrap().unwrap();
    let moved = moved(&twenty);
    assert!(moved.contains(&"relaxation.tolerance=1e-3".to_string()), "{moved:?}");
    assert!(moved.contains(&"warm_start=true".to_string()), "{moved:?}");
    assert_eq!(twenty.job.stage, wall(0.2).stage);
    assert_eq!(assembly(&twenty.job).relaxation.tolerance, 1e-3);
    let step = knob_choice(&twenty, "load_step");
    assert!(step.was.starts_with("stage steps [1, 30]"), "{}", step.was);
}
