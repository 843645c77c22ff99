//! The choice: which settings of a trade are candidates for a job, every combination of
//! them (at most one setting per knob, at most one knob that sets the time step), and the
//! cheapest whose predicted error fits the budget; or, for a job of another packing kind than
//! the table's, the tight reference settings.

use super::report::pct;
use super::size::size_report;
use super::{
    AccuracyError, COMBINATIONS, KnobChoice, MARGIN, MAX_SAFETY, MIN_SAVING, Plan, PropertyErrors,
    Report, SizeFit, Trade, packing_kind,
};
use crate::knob::Knob;
use crate::table::{Row, finished};
use cosdem_dem::AssemblySpec;
use cosdem_job::{Job, MaterialSection};

/// Sets the planned knobs ([`Knob::PLANNED`]) of an assembly to the table's default values:
/// `base`'s, or the worker's defaults (a committed table's default row).
pub(crate) fn reset_knobs(a: &mut AssemblySpec, base: Option<&AssemblySpec>) {
    let defaults = AssemblySpec::default();
    let b = base.unwrap_or(&defaults);
    for knob in Knob::PLANNED {
        knob.reset(a, b);
    }
}

/// The plan for `job` from `trade` and `fits` whose predicted error stays within `budget`
/// (`target` is the job's, for the report; infinite for [`super::cheapest`]): see the
/// module documentation of [`super`]. `None` for a job without a DEM material.
pub(crate) fn plan_within(
    job: &Job,
    trade: &Trade,
    fits: &[SizeFit],
    target: f64,
    budget: f64,
) -> Result<Option<Plan>, AccuracyError> {
    let MaterialSection::Dem { assembly } = &job.material else {
        // Job::validate refuses `accuracy` without a DEM material.
        return Ok(None);
    };
    if packing_kind(&assembly.packing) != trade.packing {
        return Ok(Some(reference_plan(job, target, trade, fits)?));
    }
    let default_error = trade.default_error();
    let measured = |e: &PropertyErrors| {
        // The properties the default has an error for are the ones the table measured.
        let m = |d: Option<f64>, s: Option<f64>| d.is_none() || s.is_some();
        m(default_error.peak, e.peak)
            && m(default_error.residual, e.residual)
            && m(default_error.stiffness, e.stiffness)
    };

    // Candidates per knob (index 0 = the table's default), and the settings left out.
    let knobs = Knob::PLANNED;
    let mut options: Vec<Vec<Option<&Row>>> = knobs.iter().map(|_| vec![None]).collect();
    let mut not_candidates = Vec::new();
    for r in &trade.settings {
        let name = format!("{}={}", r.knob, r.setting);
        if COMBINATIONS.contains(&r.knob.as_str()) {
            not_candidates.push(format!("{name}: moves several knobs (a check of the prediction)"));
            continue;
        }
        let knob = Knob::from_name(&r.knob);
        let Some(k) = knob.and_then(|knob| knobs.iter().position(|k| *k == knob)) else {
            if knob == Some(Knob::AssemblySide) {
                not_candidates.push(format!("{name}: the assembly size is the user's choice"));
            } else {
                not_candidates.push(format!("{name}: not a knob the target sets"));
            }
            continue;
        };
        let ratio = trade.cost_ratio(r);
        let too_close = knobs[k] == Knob::RelaxationSafety
            && r.setting.parse::<f64>().is_ok_and(|s| s > MAX_SAFETY);
        if too_close {
            not_candidates.push(format!(
                "{name}: above the largest safety ever picked ({MAX_SAFETY}): near the \
                 stability limit, stable on some scenes only"
            ));
        } else if !finished(r) {
            not_candidates.push(format!("{name}: its run did not finish ({})", r.status));
        } else if ratio > 1.0 - MIN_SAVING {
            not_candidates.push(format!(
                "{name}: {} DEM steps against {} for the default (saves less than {:.0} %)",
                r.dem_steps,
                trade.default.dem_steps,
                100.0 * MIN_SAVING
            ));
        } else if !measured(&trade.shift(r)) {
            not_candidates.push(format!("{name}: its effect on a measured property is unknown"));
        } else {
            options[k].push(Some(r));
        }
    }

    // Every combination: the cheapest whose prediction fits (ties: the smaller error).
    let predict = |choice: &[usize]| {
        let mut p = default_error;
        let mut cost = 1.0;
        for (k, &i) in choice.iter().enumerate() {
            if let Some(r) = options[k][i] {
                p = p.zip(trade.shift(r), |a, b| a + b);
                cost *= trade.cost_ratio(r);
            }
        }
        (p, cost)
    };
    let mut best: Option<(Vec<usize>, f64, f64)> = None;
    // At most one of the knobs that set the time step is moved.
    let allowed = |choice: &[usize]| {
        knobs.iter().zip(choice).filter(|(k, i)| k.sets_time_step() && **i > 0).count() <= 1
    };
    let mut choice = vec![0usize; knobs.len()];
    loop {
        let (p, cost) = predict(&choice);
        let worst = p.worst();
        let better = best.as_ref().is_none_or(|(_, c, w)| {
            cost < *c * (1.0 - 1e-12) || (cost <= *c * (1.0 + 1e-12) && worst < *w)
        });
        // `allowed` apart from the budget: an infinite budget (`cheapest`) admits any error,
        // never a forbidden combination.
        if allowed(&choice) && worst <= budget && better {
            best = Some((choice.clone(), cost, worst));
        }
        // Next combination (odometer).
        let mut k = 0;
        while k < choice.len() {
            choice[k] += 1;
            if choice[k] < options[k].len() {
                break;
            }
            choice[k] = 0;
            k += 1;
        }
        if k == choice.len() {
            break;
        }
    }
    let mut warnings = Vec::new();
    let chosen = match best {
        Some((c, _, _)) => c,
        None => {
            warnings.push(format!(
                "the table predicts the default settings alone to be {} off, more than the \
                 budget {:.3} %: no speed setting is moved, and the target may not be met",
                pct(Some(default_error.worst())),
                100.0 * budget
            ));
            vec![0; knobs.len()]
        }
    };
    let (predicted, predicted_cost) = predict(&chosen);

    // The tuned job: knobs to the table's default values, then the picked settings.
    let mut tuned = job.clone();
    tuned.accuracy = None;
    if let MaterialSection::Dem { assembly } = &mut tuned.material {
        reset_knobs(assembly, trade.base.as_ref());
    }
    let defaults = tuned.clone();
    let mut choices = Vec::new();
    for (k, &knob) in knobs.iter().enumerate() {
        let was = knob.value(job);
        let row = options[k][chosen[k]];
        let choice = match row {
            Some(r) => {
                knob.apply(&mut tuned, &r.setting)?;
                let s = trade.shift(r);
                KnobChoice {
                    knob: knob.to_string(),
                    was,
                    picked: if knob == Knob::LoadStep {
                        format!("{} ({})", r.setting, knob.value(&tuned))
                    } else {
                        knob.value(&tuned)
                    },
                    row: Some(format!("{}={}", r.knob, r.setting)),
                    shift: s,
                    dem_steps_ratio: trade.cost_ratio(r),
                    why: format!(
                        "row {}={}: {} DEM steps against {} for the default, F_u {}, E {} \
                         from the default",
                        r.knob,
                        r.setting,
                        r.dem_steps,
                        trade.default.dem_steps,
                        pct(s.peak),
                        pct(s.stiffness)
                    ),
                }
            }
            None => {
                let others: Vec<String> =
                    options[k][1..].iter().flatten().map(|r| r.setting.clone()).collect();
                let moved_partner = knob
                    .sets_time_step()
                    .then(|| {
                        (0..knobs.len())
                            .find(|&j| j != k && knobs[j].sets_time_step() && chosen[j] > 0)
                    })
                    .flatten();
                let why = if others.is_empty() {
                    "no measured setting is a candidate (see not_candidates)".to_string()
                } else if let Some(j) = moved_partner {
                    format!(
                        "the table's default: {} was moved, and knobs that set the time step \
                         are not moved together (their one-at-a-time rows do not measure the \
                         product)",
                        knobs[j]
                    )
                } else {
                    format!(
                        "the table's default: with {} the cheapest combination would exceed \
                         the budget",
                        others.join(" or ")
                    )
                };
                KnobChoice {
                    knob: knob.to_string(),
                    was,
                    picked: knob.value(&defaults),
                    row: None,
                    shift: PropertyErrors::default(),
                    dem_steps_ratio: 1.0,
                    why,
                }
            }
        };
        choices.push(choice);
    }
    tuned.validate()?;

    if default_error.residual.is_none() {
        warnings.push(format!(
            "{} measured no F_res (its runs did not pass the peak): F_res is not covered by \
             the prediction, and past the peak the errors are larger (see \
             docs/notes/tradeoff-scene-a-post-peak.md: the collapse is not converged in the load \
             step)",
            trade.table
        ));
    }
    let (size, size_warning) = size_report(assembly, target, fits);
    warnings.extend(size_warning);
    let report = Report {
        target,
        margin: MARGIN,
        budget,
        table: trade.table.clone(),
        default_error,
        predicted,
        predicted_dem_steps_ratio: predicted_cost,
        knobs: choices,
        not_candidates,
        size,
        warnings,
        fallback_to_reference: false,
    };
    Ok(Some(Plan { job: tuned, report }))
}

/// The plan for a job the table does not apply to: the tight reference settings.
pub(crate) fn reference_plan(
    job: &Job,
    target: f64,
    trade: &Trade,
    fits: &[SizeFit],
) -> Result<Plan, AccuracyError> {
    let mut tight = crate::knob::reference(job).job;
    tight.accuracy = None;
    tight.validate()?;
    let kind = match &job.material {
        MaterialSection::Dem { assembly } => packing_kind(&assembly.packing),
        MaterialSection::Elastic { .. } => "none",
    };
    let measured = &trade.packing;
    let knobs = Knob::PLANNED
        .iter()
        .map(|knob| KnobChoice {
            knob: knob.to_string(),
            was: knob.value(job),
            picked: if *knob == Knob::LoadStep {
                format!("x0.5 ({})", knob.value(&tight))
            } else {
                knob.value(&tight)
            },
            row: Some("reference=tight".into()),
            shift: PropertyErrors::default(),
            dem_steps_ratio: trade.cost_ratio(&trade.reference),
            why: format!(
                "the table's reference setting: {} measured {measured} assemblies, not \
                 {kind} ones",
                trade.table
            ),
        })
        .collect();
    let mut warnings = vec![format!(
        "{} was measured on {measured} assemblies and does not carry over to {kind} ones: \
         the run uses the tight reference settings, and its distance from the converged \
         answer is not predicted",
        trade.table
    )];
    let MaterialSection::Dem { assembly } = &job.material else {
        unreachable!("plan() checked the material")
    };
    let (size, size_warning) = size_report(assembly, target, fits);
    warnings.extend(size_warning);
    let zero = PropertyErrors { peak: Some(0.0), residual: None, stiffness: Some(0.0) };
    let report = Report {
        target,
        margin: MARGIN,
        budget: MARGIN * target,
        table: trade.table.clone(),
        default_error: trade.default_error(),
        predicted: zero,
        predicted_dem_steps_ratio: trade.cost_ratio(&trade.reference),
        knobs,
        not_candidates: Vec::new(),
        size,
        warnings,
        fallback_to_reference: true,
    };
    Ok(Plan { job: tight, report })
}
