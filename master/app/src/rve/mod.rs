//! One DEM assembly driven directly through a laboratory strain or stress path (no FE): how
//! users calibrate the micro parameters (contact stiffnesses, friction, rolling resistance)
//! against biaxial, isotropic and simple-shear tests before running a two-scale job.
//!
//! The assembly is the job's `[material.assembly]`, built and relaxed in this thread by the
//! worker's DEM core ([`Assembly::solve`] / [`Assembly::commit`]): every step starts from the
//! last committed state, exactly as a Gauss point of `cosdem run` does.
//!
//! Paths ([`RvePath`]), with `d` the strain increment per step and `k` the step number:
//! - **biaxial**: isotropic consolidation to the confining pressure `p` (step 0), then axial
//!   compression `e_yy = e_yy0 - k d` with the lateral stress held at `s_xx = -p`: each step
//!   solves for `e_xx` by a Newton iteration on `s_xx + p` with the assembly's tangent
//!   `C_xxxx` for the first correction, then secant updates ([`lateral`]);
//! - **isotropic**: `e_xx = e_yy = -k d` (strain controlled);
//! - **simple shear**: `F = [[1, g], [0, 1]]`, `g = k d`, with the micro-rotation following
//!   the continuum rotation `w = -g/2` (so `e_xy = e_yx = g/2`); with `p > 0` the vertical
//!   stress is held at `s_yy = -p` by the same iteration on `e_yy`;
//! - **table**: prescribed `F`, `w`, `kappa` per step from a CSV file ([`table`]).
//!
//! Sign conventions are THEORY.md's (tension positive); the derived quantities of
//! [`report`] use compression-positive principal stresses, as soil mechanics does.

/// Derived quantities (friction and dilatancy angles) and the output files.
pub mod report;
/// Prescribed deformation tables (the `FILE` path).
pub mod table;

use cosdem_common::voigt::{XX, YY};
use cosdem_common::{MacroDeformation, MicroResponse, StressVector, Tangent};
use cosdem_dem::Assembly;
use cosdem_fem::error::{Error, Result};

/// The loading path of an RVE test.
#[derive(Clone, Debug, PartialEq)]
pub enum RvePath {
    /// Consolidation to the confining pressure, then axial (y) compression at constant
    /// lateral stress.
    Biaxial,
    /// Equal compression in x and y.
    Isotropic,
    /// `F = [[1, g], [0, 1]]`, optionally at constant vertical stress.
    SimpleShear,
    /// One prescribed deformation per step.
    Table(Vec<MacroDeformation>),
}

impl RvePath {
    /// Short name for file and directory names.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Biaxial => "biaxial",
            Self::Isotropic => "isotropic",
            Self::SimpleShear => "simple-shear",
            Self::Table(_) => "table",
        }
    }
}

/// How an RVE test is run.
#[derive(Clone, Debug, PartialEq)]
pub struct RveSettings {
    /// The path.
    pub path: RvePath,
    /// Load steps after the initial state (ignored by tables: one step per row).
    pub steps: usize,
    /// Strain (or shear `g`) increment per step, positive.
    pub increment: f64,
    /// Confining pressure (biaxial) or vertical stress (simple shear), Pa, compression
    /// positive; 0 = none (simple shear only).
    pub pressure: f64,
    /// Stress-control tolerance, relative to `pressure`.
    pub tolerance: f64,
    /// Iterations allowed to reach the controlled stress; past them the step is kept with
    /// its residual reported (column `control_residual`).
    pub max_iterations: u32,
}

impl Default for RveSettings {
    fn default() -> Self {
        Self {
            path: RvePath::Biaxial,
            steps: 100,
            increment: 1e-3,
            pressure: 1e5,
            tolerance: 1e-3,
            max_iterations: 30,
        }
    }
}

impl RveSettings {
    /// Checks the values a user gives.
    pub fn validate(&self) -> Result<()> {
        let bad = |field: &'static str, value: String, reason: &str| {
            Err(Error::InvalidSetting { field, value, reason: reason.into() })
        };
        if !(self.increment.is_finite() && self.increment > 0.0) {
            return bad("increment", self.increment.to_string(), "must be finite and > 0");
        }
        if !(self.pressure.is_finite() && self.pressure >= 0.0) {
            return bad("pressure", self.pressure.to_string(), "must be finite and >= 0");
        }
        if self.path == RvePath::Biaxial && self.pressure <= 0.0 {
            return bad("pressure", self.pressure.to_string(), "a biaxial test needs p > 0");
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad("tolerance", self.tolerance.to_string(), "must be finite and > 0");
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", "0".into(), "must be >= 1");
        }
        if self.steps == 0 && !matches!(self.path, RvePath::Table(_)) {
            return bad("steps", "0".into(), "must be >= 1");
        }
        Ok(())
    }
}

/// One committed state of the test.
#[derive(Clone, Debug, PartialEq)]
pub struct RveRow {
    /// Step (0 = the initial, consolidated or reference, state).
    pub step: u64,
    /// The deformation the assembly was relaxed to.
    pub deformation: MacroDeformation,
    /// Stress and couple stress (THEORY.md order, tension positive).
    pub stress: StressVector,
    /// The assembly's tangent at that state.
    pub tangent: Tangent,
    /// DEM steps of the accepted relaxation.
    pub dem_steps: u64,
    /// Trial relaxations of the step (stress control iterations; 1 when strain controlled).
    pub iterations: u32,
    /// `|s_controlled + p| / p` reached (0 when strain controlled).
    pub control_residual: f64,
    /// Active contacts.
    pub contacts: u32,
    /// Fraction of sliding contacts.
    pub sliding_fraction: f64,
}

/// A stress component held at a target by adjusting one strain component.
#[derive(Clone, Copy, Debug)]
struct Control {
    /// Voigt index of the controlled stress (and of the adjusted strain).
    index: usize,
    /// Target stress (tension positive).
    target: f64,
}

/// Runs the test on `assembly` (in its reference state), handing every committed state to
/// `on_row` (step 0 first). Returns the number of steps after step 0.
pub fn drive(
    assembly: &mut Assembly,
    settings: &RveSettings,
    on_row: &mut dyn FnMut(&RveRow) -> Result<()>,
) -> Result<u64> {
    settings.validate()?;
    let p = settings.pressure;
    let mut step = 0u64;
    // Step 0: the starting state.
    let start = match &settings.path {
        RvePath::Biaxial => consolidate(assembly, settings)?,
        RvePath::SimpleShear if p > 0.0 => consolidate(assembly, settings)?,
        _ => {
            let r = solve(assembly, &MacroDeformation::IDENTITY, 0)?;
            assembly.commit();
            row(0, MacroDeformation::IDENTITY, &r, 1, 0.0)
        }
    };
    on_row(&start)?;
    let base = start.deformation;
    let mut last = start;
    let steps = match &settings.path {
        RvePath::Table(t) => t.len(),
        _ => settings.steps,
    };
    for k in 1..=steps {
        step = k as u64;
        let d = settings.increment * k as f64;
        let next = match &settings.path {
            RvePath::Isotropic => {
                let m = MacroDeformation::from_gradient([[-d, 0.0], [0.0, -d]], 0.0, [0.0; 2]);
                strain_step(assembly, step, m)?
            }
            RvePath::Table(t) => strain_step(assembly, step, t[k - 1])?,
            RvePath::Biaxial => {
                let mut m = last.deformation;
                m.f[1][1] = base.f[1][1] - d;
                let c = Control { index: XX, target: -p };
                controlled_step(assembly, settings, step, m, c, &last)?
            }
            RvePath::SimpleShear => {
                let mut m = last.deformation;
                m.f[0][1] = d;
                m.w = -0.5 * d;
                if p > 0.0 {
                    let c = Control { index: YY, target: -p };
                    controlled_step(assembly, settings, step, m, c, &last)?
                } else {
                    strain_step(assembly, step, m)?
                }
            }
        };
        on_row(&next)?;
        last = next;
    }
    Ok(step)
}

fn solve(assembly: &mut Assembly, m: &MacroDeformation, step: u64) -> Result<MicroResponse> {
    let r = assembly.solve(m).map_err(|e| Error::Rve { step, message: e.to_string() })?;
    if !r.diagnostics.converged {
        return Err(Error::Rve {
            step,
            message: format!(
                "relaxation hit its step cap: residual ratio {:.3e} after {} steps",
                r.diagnostics.residual_ratio, r.diagnostics.steps
            ),
        });
    }
    Ok(r)
}

fn row(step: u64, m: MacroDeformation, r: &MicroResponse, iterations: u32, res: f64) -> RveRow {
    RveRow {
        step,
        deformation: m,
        stress: r.stress,
        tangent: r.tangent,
        dem_steps: r.diagnostics.steps,
        iterations,
        control_residual: res,
        contacts: r.diagnostics.contacts,
        sliding_fraction: r.diagnostics.sliding_fraction,
    }
}

fn strain_step(assembly: &mut Assembly, step: u64, m: MacroDeformation) -> Result<RveRow> {
    let r = solve(assembly, &m, step)?;
    assembly.commit();
    Ok(row(step, m, &r, 1, 0.0))
}

/// The strain component of Voigt index `i` in `m` (`XX` -> `F_xx`, `YY` -> `F_yy`).
fn component(m: &mut MacroDeformation, i: usize) -> &mut f64 {
    if i == XX { &mut m.f[0][0] } else { &mut m.f[1][1] }
}

/// One stress-controlled step: `m` with its controlled component adjusted until the
/// controlled stress reaches its target. The first guess keeps the controlled stress constant
/// to first order with the last tangent (`de_c = -(C_c,o . de_o) / C_c,c`).
fn controlled_step(
    assembly: &mut Assembly,
    settings: &RveSettings,
    step: u64,
    mut m: MacroDeformation,
    c: Control,
    last: &RveRow,
) -> Result<RveRow> {
    let i = c.index;
    let t = &last.tangent;
    let old = last.deformation.strain();
    let new = m.strain();
    let mut cross = 0.0;
    for (j, (a, b)) in new.iter().zip(&old).enumerate() {
        if j != i {
            cross += t[i][j] * (a - b);
        }
    }
    if t[i][i] > 0.0 {
        *component(&mut m, i) -= cross / t[i][i];
    }
    lateral(assembly, settings, step, m, c, t[i][i])
}

/// Largest change of the controlled strain in one correction of [`lateral`], in load-step
/// increments: a specimen dilating at psi widens by (1 + sin psi) / (1 - sin psi)
/// increments a step (2.5 at psi = 25 degrees, the largest of the calibrated specimens), so
/// a correction beyond 4 is a secant gone flat, not the answer.
pub const MAX_MOVE: f64 = 4.0;

/// Isotropic consolidation to `settings.pressure` from the reference state: `s_xx = s_yy =
/// -p`, both normal strains adjusted by Newton iterations with the 2 x 2 normal block of the
/// assembly's tangent (a packing need not be isotropic, so the strains may differ).
fn consolidate(assembly: &mut Assembly, settings: &RveSettings) -> Result<RveRow> {
    let p = settings.pressure;
    let tol = settings.tolerance * p;
    let at =
        |e: [f64; 2]| MacroDeformation::from_gradient([[e[0], 0.0], [0.0, e[1]]], 0.0, [0.0; 2]);
    let mut e = [0.0, 0.0];
    let mut best: Option<(MacroDeformation, MicroResponse, f64, u32)> = None;
    for it in 1..=settings.max_iterations {
        let m = at(e);
        let r = solve(assembly, &m, 0)?;
        let f = [r.stress[XX] + p, r.stress[YY] + p];
        let err = f[0].abs().max(f[1].abs());
        if best.as_ref().is_none_or(|b| err < b.2) {
            best = Some((m, r.clone(), err, it));
        }
        if err <= tol {
            break;
        }
        let t = &r.tangent;
        let (a, b, c, d) = (t[XX][XX], t[XX][YY], t[YY][XX], t[YY][YY]);
        let det = a * d - b * c;
        if !(det.is_finite() && det > 0.0 && a > 0.0) {
            // No usable tangent (a just-touching packing has no contacts in compression
            // yet): a first guess from the contact stiffness scale.
            let k = assembly.law().kn;
            e = [e[0] - f[0] / k, e[1] - f[1] / k];
            continue;
        }
        e = [e[0] - (d * f[0] - b * f[1]) / det, e[1] - (a * f[1] - c * f[0]) / det];
    }
    let (m, r, err, it) = best.expect("at least one iteration");
    // The accepted state must be the assembly's trial state: solve it again if a later
    // iterate was worse (a solve is deterministic given the committed state and target).
    let r =
        if assembly.trial().is_some_and(|s| s.target == m) { r } else { solve(assembly, &m, 0)? };
    if err > tol {
        tracing::warn!(residual = err / p, "consolidation did not reach the pressure");
    }
    assembly.commit();
    Ok(row(0, m, &r, it, err / p))
}

/// Newton-secant iteration on the controlled component: the first correction uses the
/// tangent `c_ii`, later ones the secant through the last two iterates (the paper tangent
/// ignores sliding, so past the elastic range the secant is the better slope). Safeguarded:
/// a correction moves the component by at most [`MAX_MOVE`] increments, and once iterates
/// on both sides of the target are known it stays between them (bisecting when the secant
/// points outside). Past a peak a soft, noisy response gives near-zero secants whose
/// corrections were unbounded: a 147-disc specimen at 20 kPa reached det F < 0 at step 74.
fn lateral(
    assembly: &mut Assembly,
    settings: &RveSettings,
    step: u64,
    mut m: MacroDeformation,
    c: Control,
    c_ii: f64,
) -> Result<RveRow> {
    let p = settings.pressure;
    let tol = settings.tolerance * p;
    let i = c.index;
    let mut prev: Option<(f64, f64)> = None;
    let mut best: Option<(MacroDeformation, MicroResponse, f64, u32)> = None;
    let mut slope0 = c_ii;
    let max_move = MAX_MOVE * settings.increment.abs();
    // The largest iterate below the target and the smallest above it.
    let (mut below, mut above) = (f64::NEG_INFINITY, f64::INFINITY);
    for it in 1..=settings.max_iterations {
        let r = solve(assembly, &m, step)?;
        let f = r.stress[i] - c.target;
        if best.as_ref().is_none_or(|b| f.abs() < b.2.abs()) {
            best = Some((m, r.clone(), f, it));
        }
        if f.abs() <= tol {
            break;
        }
        let e = *component(&mut m, i);
        if f < 0.0 {
            below = below.max(e);
        } else {
            above = above.min(e);
        }
        if slope0 <= 0.0 || !slope0.is_finite() {
            slope0 = r.tangent[i][i];
        }
        let slope = match prev {
            Some((e0, f0)) if e != e0 => {
                let s = (f - f0) / (e - e0);
                if s.is_finite() && s > 0.0 { s } else { slope0 }
            }
            _ => slope0,
        };
        if !(slope.is_finite() && slope > 0.0) {
            break;
        }
        prev = Some((e, f));
        let mut next = e - (f / slope).clamp(-max_move, max_move);
        if below < above
            && above.is_finite()
            && below.is_finite()
            && !(below < next && next < above)
        {
            next = 0.5 * (below + above);
        }
        *component(&mut m, i) = next;
    }
    let (m, r, f, it) = best.expect("at least one iteration");
    let r = if assembly.trial().is_some_and(|s| s.target == m) {
        r
    } else {
        solve(assembly, &m, step)?
    };
    if f.abs() > tol {
        tracing::warn!(step, residual = f.abs() / p, "controlled stress not reached");
    }
    assembly.commit();
    Ok(row(step, m, &r, it, f.abs() / p))
}

#[cfg(test)]
mod tests;
