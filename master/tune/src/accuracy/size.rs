//! The size law of Eqs. 30-32, `ln(F / F^cr) = a exp(b* V^k)`: the committed RVE-size study
//! fits ([`SIZE_FITS`], `cosdem study rve-size`) and the size error `|F(V) / F^cr - 1|` they
//! predict for a job's assembly. Reported beside a plan, never part of its promise: the
//! assembly size is the user's choice.

use super::choice::reset_knobs;
use super::report::pct;
use super::{AccuracyError, PropertyErrors};
use cosdem_dem::AssemblySpec;
use serde::{Deserialize, Serialize};

/// Committed RVE-size study fits (`cosdem study rve-size`), each `(name, JSON)` in the format
/// of [`SizeFit`]. A fit applies to a job whose assembly equals the study's but for the side
/// and the speed knobs.
///
/// The one committed fit is scene A's RVE-size study on its quarter mesh past the peak
/// (`docs/notes/paper/rve-size-study.json`, written by the study as `size-fit.json`): E reaches its
/// plateau (b* = -43 [-84, -2.9]), F_u and F_res do not (their b* intervals reach above 0),
/// so only E's size error is predicted. (The earlier pre-peak fit to 0.02 m established no
/// plateau at all and is gone.)
pub const SIZE_FITS: &[(&str, &str)] = &[(
    "master/tune/data/rve-size-scene-a-quarter.json",
    include_str!("../../data/rve-size-scene-a-quarter.json"),
)];

/// Parameters of the size law `ln(F / F^cr) = a exp(b* V^k)` for one property.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LawParams {
    /// Exponent of V (2 for F_u, 3 for F_res, 1 for E).
    pub k: i32,
    /// `a`.
    pub a: f64,
    /// `b*` (1/m^(2k)).
    pub b_star: f64,
    /// Upper end of the 95 % interval of `b*` (`None` without an interval).
    pub b_star_high: Option<f64>,
}

impl LawParams {
    /// True when the fit establishes a plateau: `b* < 0` with its whole 95 % interval below
    /// 0. Otherwise the sizes have not reached the plateau and `F^cr` is no representative
    /// value (the study reports huge intervals then).
    pub fn has_plateau(&self) -> bool {
        self.b_star < 0.0 && self.b_star_high.is_some_and(|h| h < 0.0)
    }

    /// `|F(V) / F^cr - 1| = |exp(a exp(b* V^k)) - 1|`; `None` without an established plateau
    /// ([`LawParams::has_plateau`]) or when the value is not finite.
    pub fn size_error(&self, v: f64) -> Option<f64> {
        let e = ((self.a * (self.b_star * v.powi(self.k)).exp()).exp() - 1.0).abs();
        (self.has_plateau() && e.is_finite()).then_some(e)
    }
}

/// A committed RVE-size study fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeFit {
    /// What was run (command, job, date).
    pub source: String,
    /// The assembly the study ran (its side is ignored).
    pub assembly: AssemblySpec,
    /// The sizes V the fit is based on (m^2).
    pub sizes: Vec<f64>,
    /// Eq. 30, if fitted.
    pub peak_load: Option<LawParams>,
    /// Eq. 31, if fitted.
    pub residual_load: Option<LawParams>,
    /// Eq. 32 (E), if fitted.
    pub stiffness: Option<LawParams>,
}

/// The committed fits ([`SIZE_FITS`]).
pub fn size_fits() -> Result<Vec<SizeFit>, AccuracyError> {
    SIZE_FITS
        .iter()
        .map(|(name, text)| {
            serde_json::from_str(text).map_err(|e| AccuracyError::SizeFit {
                name: (*name).to_string(),
                message: e.to_string(),
            })
        })
        .collect()
}

/// The assembly with its side and speed knobs normalised: two assemblies that are equal so
/// have the same size law.
pub(crate) fn size_key(a: &AssemblySpec) -> AssemblySpec {
    let mut a = a.clone();
    if let Some(side) = a.packing.side_mut() {
        *side = 0.0;
    }
    reset_knobs(&mut a, None);
    a
}

/// The predicted size error of the job's assembly (Eqs. 30-32).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SizeReport {
    /// Assembly size V = side^2 (m^2).
    pub volume: f64,
    /// The committed fit used, `None` when none matches the job's assembly.
    pub fit: Option<String>,
    /// `|F(V) / F^cr - 1|` per property where the fit has the property.
    pub predicted: Option<PropertyErrors>,
    /// What the numbers mean (or why there are none).
    pub note: String,
}

/// The size law's report for the job's assembly (and a warning when the size error alone
/// exceeds `target`).
pub(crate) fn size_report(
    assembly: &AssemblySpec,
    target: f64,
    fits: &[SizeFit],
) -> (SizeReport, Option<String>) {
    let side = assembly.packing.region_side();
    let volume = side * side;
    let key = size_key(assembly);
    let Some(fit) = fits.iter().find(|f| size_key(&f.assembly) == key) else {
        let note = format!(
            "V = {volume:.4e} m^2; no committed RVE-size study fit (Eqs. 30-32) for this \
             assembly, so its size error is not predicted (run `cosdem study rve-size` to \
             measure it); the assembly size is kept as written"
        );
        return (SizeReport { volume, fit: None, predicted: None, note }, None);
    };
    let e = |p: Option<LawParams>| p.and_then(|p| p.size_error(volume));
    let predicted = PropertyErrors {
        peak: e(fit.peak_load),
        residual: e(fit.residual_load),
        stiffness: e(fit.stiffness),
    };
    let (lo, hi) =
        fit.sizes.iter().fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    let range = if volume < lo || volume > hi {
        format!(" (V outside the fitted sizes {lo:.4e}-{hi:.4e} m^2: extrapolated)")
    } else {
        String::new()
    };
    let mut unusable = Vec::new();
    for (name, p) in [("F_u", fit.peak_load), ("F_res", fit.residual_load), ("E", fit.stiffness)] {
        match p {
            None => unusable.push(format!("{name}: not fitted")),
            Some(p) if !p.has_plateau() => unusable.push(format!(
                "{name}: no plateau established (b* = {:.3e}, 95 % interval up to {})",
                p.b_star,
                p.b_star_high.map_or("unknown".into(), |h| format!("{h:.3e}"))
            )),
            Some(_) => {}
        }
    }
    let unusable = if unusable.is_empty() {
        String::new()
    } else {
        format!(" (not predicted: {})", unusable.join("; "))
    };
    let note = format!(
        "V = {volume:.4e} m^2; size law of {} predicts |F(V)/F^cr - 1| = {}{unusable}{range}; \
         the assembly size is kept as written (not part of the promise, which is against a \
         tight run of the same V)",
        fit.source,
        predicted.describe("not predicted")
    );
    let warning = (predicted.worst() > target).then(|| {
        format!(
            "the assembly size alone is predicted to be {:.2} % from the representative value \
             (F_u {}, E {}), more than the target; a larger packing.side reduces it",
            100.0 * predicted.worst(),
            pct(predicted.peak),
            pct(predicted.stiffness)
        )
    });
    (
        SizeReport { volume, fit: Some(fit.source.clone()), predicted: Some(predicted), note },
        warning,
    )
}
