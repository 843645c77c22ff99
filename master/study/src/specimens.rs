//! Speed against accuracy averaged over specimens: `cosdem bench tradeoff-specimens DIR...`.
//!
//! Past a peak a single run's residual capacity is one sample of a chaotic response: on the
//! biaxial example two runs whose displacements differ by one ulp end 11 % apart on F_res
//! (docs/notes/substep-biaxial.md), so a one-specimen table cannot tell a knob's error from that
//! scatter. A laboratory repeats the test on several specimens and reports the mean; this
//! module does the same with sweeps of the same scene on different specimens (packing seeds,
//! one `cosdem bench tradeoff` each). Every row of the averaged table compares the
//! specimen-mean of F_u, F_res and E with the mean of the references, and the paired
//! differences give each comparison its standard error.
//!
//! The pure part ([`average`], [`markdown`]) is separate from reading the sweeps
//! ([`read_sweep`]) so it is tested without running anything.

use crate::tradeoff::{self, Row};
use cosdem_app::output::plot::curve::read_curve;
use cosdem_fem::post::CurveMetrics;
use std::path::{Path, PathBuf};

/// One specimen's sweep: its rows (the reference first) and each row's curve.
#[derive(Clone, Debug)]
pub struct Specimen {
    /// The specimen's name in the tables (the sweep directory's name).
    pub label: String,
    /// The sweep's rows as `tradeoff.csv` has them; the first is the reference.
    pub rows: Vec<Row>,
    /// The `(displacement, load)` curve of each row (empty when its run left none; a row
    /// past the end of this list has none either).
    pub curves: Vec<Vec<(f64, f64)>>,
}

/// Why sweeps could not be averaged.
#[derive(Debug, thiserror::Error)]
pub enum SpecimensError {
    /// Fewer than two specimens: there is nothing to average and no scatter to measure.
    #[error("averaging over specimens needs at least 2 sweeps, got {0}")]
    TooFew(usize),
    /// The same specimen twice: its scatter would count as zero.
    #[error("specimen {0} is given twice")]
    Repeated(String),
    /// A sweep whose first row is not its reference.
    #[error("specimen {specimen}: the first row is {knob:?}, not the reference")]
    NoReference {
        /// The specimen.
        specimen: String,
        /// The knob of its first row.
        knob: String,
    },
    /// A sweep's files could not be read.
    #[error("specimen {specimen}: {message}")]
    Read {
        /// The specimen.
        specimen: String,
        /// What failed, naming the file.
        message: String,
    },
}

/// The spread of one property over the specimens: the mean of the paired differences
/// `(x_i - r_i) / mean(r)` (signed: the averaged row's error with its sign) and its standard
/// error `sd / sqrt(n)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Difference {
    /// Mean of the paired relative differences.
    pub mean: f64,
    /// Standard error of that mean (sample standard deviation over sqrt(n)).
    pub standard_error: f64,
}

/// One averaged row with what each specimen said.
#[derive(Clone, Debug)]
pub struct Spread {
    /// Each specimen's row, in the specimens' order.
    pub per_specimen: Vec<Row>,
    /// F_u, F_res and E: paired differences from the references (`None` where a specimen
    /// lacks the value).
    pub peak: Option<Difference>,
    /// See [`Spread::peak`].
    pub residual: Option<Difference>,
    /// See [`Spread::peak`].
    pub stiffness: Option<Difference>,
}

/// The sweeps averaged: one row per setting every specimen ran.
#[derive(Clone, Debug)]
pub struct Averaged {
    /// Specimen labels, in order.
    pub labels: Vec<String>,
    /// The averaged rows (the reference first): metrics are specimen means, wall time, DEM
    /// steps and cuts are totals over the specimens, errors compare the means.
    pub rows: Vec<Row>,
    /// Per row (same order): each specimen's row and the paired differences.
    pub spread: Vec<Spread>,
    /// Settings left out because not every specimen ran them (`knob = setting`): the
    /// combination rows are planned from each sweep's own rows and can differ.
    pub dropped: Vec<String>,
}

fn mean(v: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = v.len() as f64;
    v.sum::<f64>() / n
}

/// The mean of every specimen's value, `None` if any specimen lacks it.
fn mean_of(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Option<Vec<f64>> = values.collect();
    v.filter(|v| !v.is_empty()).map(|v| mean(v.into_iter()))
}

/// Paired relative differences `(x_i - r_i) / mean(r)`, their mean and standard error.
fn difference(x: &[Option<f64>], r: &[Option<f64>]) -> Option<Difference> {
    let pairs: Option<Vec<(f64, f64)>> =
        x.iter().zip(r).map(|(x, r)| Some(((*x)?, (*r)?))).collect();
    let pairs = pairs.filter(|p| p.len() >= 2)?;
    let rm = mean(pairs.iter().map(|p| p.1));
    if rm == 0.0 || !rm.is_finite() {
        return None;
    }
    let d: Vec<f64> = pairs.iter().map(|(x, r)| (x - r) / rm.abs()).collect();
    let m = mean(d.iter().copied());
    let n = d.len() as f64;
    let var = d.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
    Some(Difference { mean: m, standard_error: (var / n).sqrt() })
}

/// The specimen-mean curve on `grid`'s displacements: at each, the mean of every curve's
/// load (linear interpolation), kept only where every curve reaches.
pub fn mean_curve(curves: &[&[(f64, f64)]], grid: &[(f64, f64)]) -> Vec<(f64, f64)> {
    grid.iter()
        .map_while(|&(d, _)| {
            let loads: Option<Vec<f64>> =
                curves.iter().map(|c| tradeoff::interpolate(c, d)).collect();
            loads.map(|l| (d, mean(l.into_iter())))
        })
        .collect()
}

/// Row `i`'s curve of a specimen (empty when it has none).
fn curve_of(s: &Specimen, i: usize) -> &[(f64, f64)] {
    s.curves.get(i).map_or(&[], Vec::as_slice)
}

/// What a row ran: the knob settings it moves from the job as given, sorted
/// (`knob=setting`; a combination row, [`cosdem_tune::accuracy::COMBINATIONS`], lists its own
/// after the target: `accuracy` `0.2: a=1+b=2` moves `a=1` and `b=2`).
fn moves(r: &Row) -> Vec<String> {
    if !cosdem_tune::accuracy::COMBINATIONS.contains(&r.knob.as_str()) {
        return vec![format!("{}={}", r.knob, r.setting)];
    }
    let list = r.setting.split_once(": ").map_or(r.setting.as_str(), |(_, l)| l);
    let mut v: Vec<String> = list.split('+').map(str::to_string).collect();
    v.sort();
    v
}

/// The averaged row's knob and setting: the specimens' own when they agree; otherwise
/// (one sweep's `cheapest` is another's `accuracy 0.2` pick: [`tradeoff::combinations`]
/// runs the same settings once) every name it has, and the settings it moves.
fn label(per: &[&Row], key: &[String]) -> (String, String) {
    if per.iter().all(|r| (&r.knob, &r.setting) == (&per[0].knob, &per[0].setting)) {
        return (per[0].knob.clone(), per[0].setting.clone());
    }
    let mut names: Vec<String> = Vec::new();
    for r in per {
        let name = match r.setting.split_once(": ") {
            Some((target, _)) if r.knob == "accuracy" => format!("accuracy {target}"),
            _ => r.knob.clone(),
        };
        if !names.contains(&name) {
            names.push(name);
        }
    }
    (names.join(" / "), key.join("+"))
}

/// Averages the sweeps of several specimens (see the module's docs). Rows are matched by
/// what they ran ([`moves`]), whatever each sweep called them; the first specimen's order
/// is kept, and a row that repeats an earlier one's settings there is left out (the same
/// run again); a row some specimen lacks is dropped (and named in [`Averaged::dropped`]).
pub fn average(specimens: &[Specimen]) -> Result<Averaged, SpecimensError> {
    if specimens.len() < 2 {
        return Err(SpecimensError::TooFew(specimens.len()));
    }
    for (i, s) in specimens.iter().enumerate() {
        if specimens[..i].iter().any(|o| o.label == s.label) {
            return Err(SpecimensError::Repeated(s.label.clone()));
        }
        let knob = s.rows.first().map_or("(none)", |r| r.knob.as_str());
        if knob != "reference" {
            return Err(SpecimensError::NoReference {
                specimen: s.label.clone(),
                knob: knob.to_string(),
            });
        }
    }
    // What each row of each specimen ran, worked out once.
    let keys: Vec<Vec<Vec<String>>> =
        specimens.iter().map(|s| s.rows.iter().map(moves).collect()).collect();
    let find = |k: &[Vec<String>], key: &[String]| k.iter().position(|o| o.as_slice() == key);
    // The references' mean curve on the first reference's grid is every row's grid.
    let grid = curve_of(&specimens[0], 0);
    let mut reference: Option<tradeoff::Reference> = None;
    // Each property of the given rows, in the specimens' order, and the references' rows.
    let pick = |rows: &[&Row], f: fn(&CurveMetrics) -> Option<f64>| -> Vec<Option<f64>> {
        rows.iter().map(|r| f(&r.metrics)).collect()
    };
    let fu: fn(&CurveMetrics) -> Option<f64> = |m| Some(m.peak_load);
    let fres: fn(&CurveMetrics) -> Option<f64> = |m| m.residual_load;
    let e: fn(&CurveMetrics) -> Option<f64> = |m| m.stiffness;
    let refs: Vec<&Row> = specimens.iter().map(|s| &s.rows[0]).collect();
    let (mut rows, mut spread, mut dropped) = (Vec::new(), Vec::new(), Vec::new());
    for (j, (r, key)) in specimens[0].rows.iter().zip(&keys[0]).enumerate() {
        // A combination that repeats an earlier row's settings is that row run again.
        if keys[0][..j].contains(key) {
            continue;
        }
        let Some(at) = keys.iter().map(|k| find(k, key)).collect::<Option<Vec<usize>>>() else {
            dropped.push(format!("{} = {}", r.knob, r.setting));
            continue;
        };
        let per: Vec<&Row> = specimens.iter().zip(&at).map(|(s, &i)| &s.rows[i]).collect();
        let (knob, setting) = label(&per, key);
        let curves: Vec<&[(f64, f64)]> =
            specimens.iter().zip(&at).map(|(s, &i)| curve_of(s, i)).collect();
        let metrics = CurveMetrics {
            peak_load: mean(per.iter().map(|r| r.metrics.peak_load)),
            peak_displacement: mean(per.iter().map(|r| r.metrics.peak_displacement)),
            residual_load: mean_of(per.iter().map(|r| r.metrics.residual_load)),
            stiffness: mean_of(per.iter().map(|r| r.metrics.stiffness)),
            stiffness_50: mean_of(per.iter().map(|r| r.metrics.stiffness_50)),
        };
        let curve = mean_curve(&curves, grid);
        let wall: f64 = per.iter().map(|r| r.wall_seconds).sum();
        let (rm, rc, rt) = reference.get_or_insert_with(|| (metrics, curve.clone(), wall));
        let status = match per.iter().zip(specimens).find(|(r, _)| !tradeoff::finished(r)) {
            None => "finished".to_string(),
            Some((r, s)) => format!("specimen {}: {}", s.label, r.status),
        };
        let errors = tradeoff::compare((rm, rc), (&metrics, &curve));
        rows.push(Row {
            knob,
            setting,
            status,
            displacement: per.iter().map(|r| r.displacement).fold(f64::INFINITY, f64::min),
            wall_seconds: wall,
            dem_steps: per.iter().map(|r| r.dem_steps).sum(),
            cuts: per.iter().map(|r| r.cuts).sum(),
            metrics,
            errors,
            speedup: *rt / wall.max(1e-9),
        });
        spread.push(Spread {
            per_specimen: per.iter().map(|r| (*r).clone()).collect(),
            peak: difference(&pick(&per, fu), &pick(&refs, fu)),
            residual: difference(&pick(&per, fres), &pick(&refs, fres)),
            stiffness: difference(&pick(&per, e), &pick(&refs, e)),
        });
    }
    let labels = specimens.iter().map(|s| s.label.clone()).collect();
    Ok(Averaged { labels, rows, spread, dropped })
}

fn signed(d: Option<Difference>) -> String {
    d.map_or("-".into(), |d| {
        format!("{:+.2} % ± {:.2} %", 100.0 * d.mean, 100.0 * d.standard_error)
    })
}

fn load(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.0}"))
}

/// The averaged table ([`tradeoff::markdown`] of the averaged rows), then the paired
/// differences with their standard errors, then every specimen's figures.
pub fn markdown(title: &str, a: &Averaged) -> String {
    let mut s = tradeoff::markdown(title, &a.rows);
    s.push_str(&format!(
        "\nAveraged over {} specimens ({}): F_u, F_res and E are specimen means, wall time \
         and DEM steps totals.\n",
        a.labels.len(),
        a.labels.join(", ")
    ));
    if !a.dropped.is_empty() {
        s.push_str(&format!("Not run on every specimen: {}.\n", a.dropped.join("; ")));
    }
    s.push_str(
        "\n## Paired differences from the reference (mean ± standard error over specimens)\n\n\
         | knob | setting | F_u | F_res | E |\n|---|---|---:|---:|---:|\n",
    );
    for (r, d) in a.rows.iter().zip(&a.spread) {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            r.knob,
            r.setting,
            signed(d.peak),
            signed(d.residual),
            signed(d.stiffness)
        ));
    }
    s.push_str(
        "\n## Each specimen\n\n| knob | setting | specimen | status | wall (s) | F_u (N) | \
         F_res (N) | E (N/m) | F_u err | F_res err | E err |\n\
         |---|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let pct = |e: Option<f64>| e.map_or("-".into(), |e| format!("{:.2} %", 100.0 * e));
    for d in &a.spread {
        for (label, p) in a.labels.iter().zip(&d.per_specimen) {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {:.1} | {:.0} | {} | {} | {} | {} | {} |\n",
                p.knob,
                p.setting,
                label,
                p.status,
                p.wall_seconds,
                p.metrics.peak_load,
                load(p.metrics.residual_load),
                p.metrics.stiffness.map_or("-".into(), |v| format!("{v:.4e}")),
                pct(p.errors.peak),
                pct(p.errors.residual),
                pct(p.errors.stiffness),
            ));
        }
    }
    s
}

/// Reads one specimen's sweep from its directory: `DIR/tradeoff.csv` and each row's
/// `DIR/runs/<slug>/curve.csv` (a row without one gets an empty curve).
pub fn read_sweep(dir: &Path) -> Result<Specimen, SpecimensError> {
    let label = dir.file_name().map_or(dir.display().to_string(), |n| n.to_string_lossy().into());
    let err = |message: String| SpecimensError::Read { specimen: label.clone(), message };
    let csv: PathBuf = dir.join("tradeoff.csv");
    let text = std::fs::read_to_string(&csv)
        .map_err(|e| err(format!("reading {}: {e}", csv.display())))?;
    let rows =
        tradeoff::read_csv(&text, &csv.display().to_string()).map_err(|e| err(e.to_string()))?;
    let mut curves = Vec::new();
    for r in &rows {
        let path = dir.join("runs").join(tradeoff::slug(&r.knob, &r.setting)).join("curve.csv");
        curves.push(if path.exists() {
            read_curve(&path).map_err(|e| err(e.to_string()))?
        } else {
            Vec::new()
        });
    }
    // The CSV keeps F_u, F_res and E; the peak's displacement and E50 come from the curve
    // (neither depends on the linear range).
    let mut rows = rows;
    for (r, c) in rows.iter_mut().zip(&curves).filter(|(_, c)| !c.is_empty()) {
        let m = CurveMetrics::from_curve(c, 0.0);
        r.metrics.peak_displacement = m.peak_displacement;
        r.metrics.stiffness_50 = m.stiffness_50;
    }
    Ok(Specimen { label, rows, curves })
}

#[cfg(test)]
mod tests;
