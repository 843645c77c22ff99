//! The trade table: one row per speed setting of a sweep, its errors against the reference
//! (F_u, F_res, E and the whole curve, relative), the Pareto front, and the CSV and Markdown
//! forms that `cosdem bench tradeoff` writes and the accuracy planner reads back.

use cosdem_fem::post::CurveMetrics;
use serde::Serialize;

/// The result of one variant, compared with the reference.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Knob name.
    pub knob: String,
    /// Knob setting.
    pub setting: String,
    /// `finished` or the reason the run stopped.
    pub status: String,
    /// Displacement reached (m).
    pub displacement: f64,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// DEM steps of the converged evaluations.
    pub dem_steps: u64,
    /// Step cuts.
    pub cuts: u64,
    /// F_u, F_res, E, E50 of this run.
    pub metrics: CurveMetrics,
    /// Relative errors against the reference: F_u, F_res, E, curve (relative L2).
    pub errors: Errors,
    /// Reference wall time / this wall time.
    pub speedup: f64,
}

/// Relative errors of one run against the reference (`None` when either run lacks the value,
/// e.g. a run that stopped before the peak has no F_res).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Errors {
    /// |F_u - F_u,ref| / F_u,ref.
    pub peak: Option<f64>,
    /// |F_res - F_res,ref| / F_res,ref.
    pub residual: Option<f64>,
    /// |E - E_ref| / E_ref.
    pub stiffness: Option<f64>,
    /// Relative L2 distance of the curves (see [`curve_error`]).
    pub curve: Option<f64>,
}

impl Errors {
    /// The largest of the four, `None` if any is missing (an unknown error is not small).
    pub fn worst(&self) -> Option<f64> {
        let all = [self.peak, self.residual, self.stiffness, self.curve];
        all.iter().try_fold(0.0f64, |m, e| e.map(|e| m.max(e)))
    }

    /// The largest of F_u, F_res and E (the accuracy promise), `None` if any is missing.
    pub fn worst_property(&self) -> Option<f64> {
        let all = [self.peak, self.residual, self.stiffness];
        all.iter().try_fold(0.0f64, |m, e| e.map(|e| m.max(e)))
    }

    /// The largest of the errors that exist, `None` only when none does. This is what the
    /// Pareto front and plot rank by: a sweep whose reference never passes a peak has no F_res
    /// in any row, and [`Errors::worst`] would then leave every row off the front. A value is
    /// missing for every row alike when the reference lacks it; a finished row that lacks a
    /// value the reference has (no peak passed where the reference passed one) is ranked on
    /// the rest, so read its F_res column before trusting its place on the front.
    pub fn worst_present(&self) -> Option<f64> {
        [self.peak, self.residual, self.stiffness, self.curve]
            .into_iter()
            .flatten()
            .reduce(f64::max)
    }
}

fn relative(value: Option<f64>, reference: Option<f64>) -> Option<f64> {
    match (value, reference) {
        (Some(v), Some(r)) if r != 0.0 && v.is_finite() && r.is_finite() => {
            Some((v - r).abs() / r.abs())
        }
        _ => None,
    }
}

/// Linear interpolation of a curve sorted by displacement; `None` outside its range.
pub fn interpolate(curve: &[(f64, f64)], d: f64) -> Option<f64> {
    let first = curve.first()?;
    if d < first.0 {
        // Every curve starts at (0, 0) before its first step.
        return (d >= 0.0).then(|| first.1 * d / first.0.max(f64::MIN_POSITIVE));
    }
    let i = curve.partition_point(|p| p.0 < d);
    if i == curve.len() {
        return None;
    }
    let (d1, f1) = curve[i];
    if i == 0 || d1 == d {
        return Some(f1);
    }
    let (d0, f0) = curve[i - 1];
    Some(f0 + (f1 - f0) * (d - d0) / (d1 - d0))
}

/// Relative L2 distance of `curve` from `reference` over the reference's points that both
/// reached: `sqrt(sum (F - F_ref)^2 / sum F_ref^2)`, with `F` linearly interpolated at the
/// reference's displacements (the two runs need not take the same steps). `None` if they
/// share no point.
pub fn curve_error(reference: &[(f64, f64)], curve: &[(f64, f64)]) -> Option<f64> {
    let (mut num, mut den, mut n) = (0.0, 0.0, 0usize);
    for &(d, fr) in reference {
        if let Some(f) = interpolate(curve, d) {
            num += (f - fr) * (f - fr);
            den += fr * fr;
            n += 1;
        }
    }
    (n > 0 && den > 0.0).then(|| (num / den).sqrt())
}

/// The errors of a run's metrics and curve against the reference's.
///
/// Where the reference stopped before the run did (a reference that failed past the peak),
/// F_u and F_res are the run's over the reference's range: F_res is a minimum over the path,
/// and the minimum of a longer path is not the same statistic (a biaxial run's plateau
/// minimum at 8.95 mm against a reference that stopped at 7.575 mm: 3.86 %, where the two
/// over the same range differ by 0.41 %, docs/notes/load-step-biaxial.md). E and the curve error
/// are over the reference's range already.
pub fn compare(
    reference: (&CurveMetrics, &[(f64, f64)]),
    run: (&CurveMetrics, &[(f64, f64)]),
) -> Errors {
    let (rm, rc) = reference;
    let (m, c) = run;
    let within = match (rc.last(), c.last()) {
        (Some(&(end, _)), Some(&(last, _))) if end < last => {
            // The reference's last point counts whatever the round-off of the summed increments.
            let n = c.partition_point(|p| p.0 <= end * (1.0 + cosdem_fem::post::RANGE_SLACK));
            // The linear range does not matter here: only F_u and F_res are taken.
            Some(CurveMetrics::from_curve(&c[..n], 0.0))
        }
        _ => None,
    };
    let m_peak = within.map_or(m.peak_load, |w| w.peak_load);
    let m_residual = within.map_or(m.residual_load, |w| w.residual_load);
    Errors {
        peak: relative(Some(m_peak), Some(rm.peak_load)),
        residual: relative(m_residual, rm.residual_load),
        stiffness: relative(m.stiffness, rm.stiffness),
        curve: curve_error(rc, c),
    }
}

/// True when the row's run reached its end (`status == "finished"`).
pub fn finished(row: &Row) -> bool {
    row.status == "finished"
}

/// Indices of the rows on the Pareto front of (wall time, worst error): no other row is both
/// faster and more accurate. See [`pareto_front_by`].
pub fn pareto_front(rows: &[Row]) -> Vec<usize> {
    pareto_front_by(rows, |r| r.wall_seconds)
}

/// Indices of the rows on the Pareto front of (`cost`, worst error): no other row is both
/// cheaper and more accurate. The error is [`Errors::worst_present`] (the largest of the
/// errors the row has). Only finished rows take part: a run that stopped early is neither a
/// choice nor a yardstick, however fast it failed.
pub fn pareto_front_by(rows: &[Row], cost: impl Fn(&Row) -> f64) -> Vec<usize> {
    let key = |r: &Row| {
        let c = cost(r);
        r.errors.worst_present().filter(|_| finished(r) && c.is_finite()).map(|e| (c, e))
    };
    let mut front = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let Some((t, e)) = key(r) else { continue };
        let dominated = rows.iter().enumerate().any(|(j, o)| {
            j != i && key(o).is_some_and(|(to, eo)| to <= t && eo <= e && (to < t || eo < e))
        });
        if !dominated {
            front.push(i);
        }
    }
    front
}

fn pct(e: Option<f64>) -> String {
    e.map_or("-".into(), |e| format!("{:.2} %", 100.0 * e))
}

/// The Markdown table of a sweep (rows in sweep order; Pareto-front rows marked with `*`).
pub fn markdown(title: &str, rows: &[Row]) -> String {
    let front = pareto_front(rows);
    let mut s = format!(
        "# {title}\n\n| knob | setting | status | wall (s) | speedup | DEM steps | F_u err | \
         F_res err | E err | curve L2 | Pareto |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|:-:|\n"
    );
    for (i, r) in rows.iter().enumerate() {
        s.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.2}x | {} | {} | {} | {} | {} | {} |\n",
            r.knob,
            r.setting,
            r.status,
            r.wall_seconds,
            r.speedup,
            r.dem_steps,
            pct(r.errors.peak),
            pct(r.errors.residual),
            pct(r.errors.stiffness),
            pct(r.errors.curve),
            if front.contains(&i) { "*" } else { "" }
        ));
    }
    s
}

/// The CSV of a sweep (one header, one line per row).
pub fn csv(rows: &[Row]) -> String {
    let f = |e: Option<f64>| e.map_or(String::new(), |e| format!("{e:.6e}"));
    let g = |e: Option<f64>| e.map_or(String::new(), |e| format!("{e:.6e}"));
    let mut s = String::from(
        "knob,setting,status,displacement,wall_seconds,speedup,dem_steps,cuts,peak_load,\
         residual_load,stiffness,err_peak,err_residual,err_stiffness,err_curve\n",
    );
    for r in rows {
        s.push_str(&format!(
            "{},{},{},{:.6e},{:.3},{:.3},{},{},{:.6e},{},{},{},{},{},{}\n",
            r.knob,
            r.setting,
            r.status.replace(',', ";"),
            r.displacement,
            r.wall_seconds,
            r.speedup,
            r.dem_steps,
            r.cuts,
            r.metrics.peak_load,
            g(r.metrics.residual_load),
            g(r.metrics.stiffness),
            f(r.errors.peak),
            f(r.errors.residual),
            f(r.errors.stiffness),
            f(r.errors.curve),
        ));
    }
    s
}

/// Why a sweep table could not be read, or a setting not applied.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// The CSV is malformed (missing column, unreadable number).
    #[error("{origin}: {message}")]
    Csv {
        /// The file (or a name for embedded text).
        origin: String,
        /// What is wrong, naming the line and the column.
        message: String,
    },
    /// A name that is no speed knob (see [`crate::knob::Knob::ALL`]).
    #[error("unknown knob {knob}")]
    UnknownKnob {
        /// The name.
        knob: String,
    },
    /// A setting that [`crate::knob::Knob::apply`] does not know for its knob.
    #[error("unknown setting {knob} = {setting}")]
    UnknownSetting {
        /// The knob.
        knob: String,
        /// The setting.
        setting: String,
    },
}

/// Reads back a `tradeoff.csv` written by [`csv`] (columns found by name). The metrics
/// keep what the CSV has (F_u, F_res, E; not the peak's displacement nor E50).
pub fn read_csv(text: &str, origin: &str) -> Result<Vec<Row>, TableError> {
    let err = |message: String| TableError::Csv { origin: origin.to_string(), message };
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let header: Vec<&str> =
        lines.next().map(|(_, l)| l.split(',').map(str::trim).collect()).unwrap_or_default();
    let col = |name: &str| {
        header.iter().position(|h| *h == name).ok_or_else(|| err(format!("no column {name:?}")))
    };
    let c = [
        "knob",
        "setting",
        "status",
        "displacement",
        "wall_seconds",
        "speedup",
        "dem_steps",
        "cuts",
        "peak_load",
        "residual_load",
        "stiffness",
        "err_peak",
        "err_residual",
        "err_stiffness",
        "err_curve",
    ]
    .map(col);
    let [knob, setting, status, disp, wall, speedup, dem, cuts, pk, res, stiff, ep, er, es, ec] = c;
    let (knob, setting, status, disp, wall, speedup, dem, cuts) =
        (knob?, setting?, status?, disp?, wall?, speedup?, dem?, cuts?);
    let (pk, res, stiff, ep, er, es, ec) = (pk?, res?, stiff?, ep?, er?, es?, ec?);
    let mut rows = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let cell = |c: usize| {
            cells.get(c).copied().ok_or_else(|| {
                err(format!("line {}: {} cells, column {} missing", i + 1, cells.len(), c + 1))
            })
        };
        let num = |c: usize| -> Result<f64, TableError> {
            let v = cell(c)?;
            v.parse::<f64>().map_err(|_| {
                err(format!("line {}: column {:?} is not a number: {v:?}", i + 1, header[c]))
            })
        };
        let opt = |c: usize| -> Result<Option<f64>, TableError> {
            if cell(c)?.is_empty() { Ok(None) } else { num(c).map(Some) }
        };
        rows.push(Row {
            knob: cell(knob)?.to_string(),
            setting: cell(setting)?.to_string(),
            status: cell(status)?.to_string(),
            displacement: num(disp)?,
            wall_seconds: num(wall)?,
            dem_steps: num(dem)? as u64,
            cuts: num(cuts)? as u64,
            metrics: CurveMetrics {
                peak_load: num(pk)?,
                residual_load: opt(res)?,
                stiffness: opt(stiff)?,
                ..CurveMetrics::default()
            },
            errors: Errors {
                peak: opt(ep)?,
                residual: opt(er)?,
                stiffness: opt(es)?,
                curve: opt(ec)?,
            },
            speedup: num(speedup)?,
        });
    }
    Ok(rows)
}
