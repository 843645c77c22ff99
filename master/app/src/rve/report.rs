//! What a laboratory test reports: principal stresses, mobilized friction angle, dilatancy
//! angle; and the files `rve.csv`, `tangent.csv`, `rve.json`.
//!
//! Soil-mechanics signs here: principal stresses `sigma_1 >= sigma_3` are compression
//! positive (`sigma = -s`, symmetric part of the in-plane stress), so
//! `sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3)`. The dilatancy angle of a step is
//! `sin(psi) = (de_1 + de_3) / (de_1 - de_3)` with `de_1 >= de_3` the principal increments of
//! the symmetric small-strain increment (tension positive): `psi > 0` when the sample dilates.

use super::RveRow;
use crate::output::{CsvWriter, OutputError, write_atomic};
use cosdem_common::MacroDeformation;
use cosdem_common::voigt::{N, NAMES, XX, XY, YX, YY};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Columns of `rve.csv`.
pub const RVE_COLUMNS: [&str; 24] = [
    "step",
    "e_xx",
    "e_yy",
    "e_xy",
    "e_yx",
    "k_x",
    "k_y",
    "w",
    "s_xx",
    "s_yy",
    "s_xy",
    "s_yx",
    "m_x",
    "m_y",
    "volumetric_strain",
    "mean_stress",
    "deviatoric_stress",
    "friction_angle",
    "dilatancy_angle",
    "iterations",
    "control_residual",
    "dem_steps",
    "contacts",
    "sliding_fraction",
];

/// Principal stresses `(sigma_1, sigma_3)`, compression positive, of the symmetric part of
/// the in-plane stress.
pub fn principal_stresses(s: &[f64; N]) -> (f64, f64) {
    let (a, b, c) = (-s[XX], -s[YY], -0.5 * (s[XY] + s[YX]));
    let mean = 0.5 * (a + b);
    let rad = (0.25 * (a - b) * (a - b) + c * c).sqrt();
    (mean + rad, mean - rad)
}

/// Mobilized friction angle in degrees, `asin((s1 - s3) / (s1 + s3))`; NaN when the mean
/// stress is not compressive.
pub fn friction_angle(s: &[f64; N]) -> f64 {
    let (s1, s3) = principal_stresses(s);
    if s1 + s3 > 0.0 {
        ((s1 - s3) / (s1 + s3)).clamp(-1.0, 1.0).asin().to_degrees()
    } else {
        f64::NAN
    }
}

/// Volumetric strain `det(F) - 1` (area change, tension positive).
pub fn volumetric_strain(m: &MacroDeformation) -> f64 {
    m.det() - 1.0
}

/// Dilatancy angle in degrees of the step from `a` to `b` (NaN for a zero increment), from
/// the strain increment in the current configuration: the symmetric part of
/// `dF F_mid^-1`, `F_mid` the mean of the two gradients (exact for any step of a constant
/// principal stretch rate along fixed axes, e.g. `F = diag(l, 1/l)`: no area change, zero
/// angle however large the strain). The increment of `F` itself (`dF`, what this used
/// before 2026-12-06) reads an isochoric step at 20 % strain as dilating by 12-18 degrees.
pub fn dilatancy_angle(a: &MacroDeformation, b: &MacroDeformation) -> f64 {
    let (fa, fb) = (a.f, b.f);
    let mid = |i: usize, j: usize| 0.5 * (fa[i][j] + fb[i][j]);
    let det = mid(0, 0) * mid(1, 1) - mid(0, 1) * mid(1, 0);
    let inv = [[mid(1, 1) / det, -mid(0, 1) / det], [-mid(1, 0) / det, mid(0, 0) / det]];
    let df = |i: usize, j: usize| fb[i][j] - fa[i][j];
    let d = |i: usize, j: usize| df(i, 0) * inv[0][j] + df(i, 1) * inv[1][j];
    let (exx, eyy, exy) = (d(0, 0), d(1, 1), 0.5 * (d(0, 1) + d(1, 0)));
    let mean = 0.5 * (exx + eyy);
    let rad = (0.25 * (exx - eyy) * (exx - eyy) + exy * exy).sqrt();
    if rad > 0.0 { (mean / rad).clamp(-1.0, 1.0).asin().to_degrees() } else { f64::NAN }
}

/// The summary of a test (also `rve.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RveSummary {
    /// The path's name.
    pub path: String,
    /// Steps after the initial state.
    pub steps: u64,
    /// Discs in the assembly.
    pub discs: usize,
    /// Reference area V (m^2).
    pub area: f64,
    /// Peak mobilized friction angle (degrees).
    pub peak_friction_angle: f64,
    /// Step of the peak.
    pub peak_step: u64,
    /// Axial strain `-e_yy` at the peak (biaxial and isotropic; the shear `g` for simple shear).
    pub peak_strain: f64,
    /// Deviatoric stress `sigma_1 - sigma_3` at the peak (Pa).
    pub peak_deviatoric_stress: f64,
    /// Dilatancy angle of the step that reached the peak (degrees).
    pub dilatancy_at_peak: f64,
    /// Largest dilatancy angle of any step (degrees).
    pub max_dilatancy_angle: f64,
    /// Friction angle of the last step (degrees): the residual value once the curve is flat.
    pub final_friction_angle: f64,
    /// Volumetric strain of the last step.
    pub final_volumetric_strain: f64,
    /// First step of the path's last quarter (at least its last two steps), over which the
    /// critical state is read.
    pub critical_state_from_step: u64,
    /// Mean friction angle over the last quarter (degrees): the critical-state friction
    /// angle once the specimen deforms at constant volume and stress.
    pub critical_state_friction_angle: f64,
    /// Dilatancy angle of the last quarter as one increment (degrees): near zero when the
    /// last quarter is at the critical state (check it before quoting the friction angle).
    pub critical_state_dilatancy_angle: f64,
    /// DEM steps of all accepted relaxations.
    pub dem_steps: u64,
    /// Steps whose controlled stress missed its tolerance.
    pub uncontrolled_steps: u64,
    /// Wall time (s); not deterministic.
    pub wall_seconds: f64,
}

/// Writes `rve.csv` and `tangent.csv` row by row, and `rve.json` at the end.
pub struct RveWriter {
    dir: PathBuf,
    rows: CsvWriter,
    tangent: CsvWriter,
    last: Option<RveRow>,
    /// Every step's friction angle and deformation (the critical state's window).
    history: Vec<(u64, f64, MacroDeformation)>,
    summary: RveSummary,
    tolerance: f64,
}

fn strain_of_interest(path: &str, m: &MacroDeformation) -> f64 {
    if path == "simple-shear" { m.f[0][1] } else { 1.0 - m.f[1][1] }
}

impl RveWriter {
    /// Creates the files in `dir` (created if missing). `tolerance` is the stress-control
    /// tolerance (a row above it counts as uncontrolled).
    pub fn create(dir: &Path, summary: RveSummary, tolerance: f64) -> crate::output::Result<Self> {
        std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
            path: dir.to_path_buf(),
            action: "create directory",
            source,
        })?;
        let rows = CsvWriter::create(&dir.join("rve.csv"), &RVE_COLUMNS)?;
        let names: Vec<String> = std::iter::once("step".to_string())
            .chain((0..N).flat_map(|i| (0..N).map(move |j| format!("C_{}_{}", NAMES[i], NAMES[j]))))
            .collect();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let tangent = CsvWriter::create(&dir.join("tangent.csv"), &refs)?;
        let summary =
            RveSummary { peak_friction_angle: f64::NAN, max_dilatancy_angle: f64::NAN, ..summary };
        let history = Vec::new();
        Ok(Self { dir: dir.to_path_buf(), rows, tangent, last: None, history, summary, tolerance })
    }

    /// Appends one state to both CSV files and updates the summary.
    pub fn write(&mut self, r: &RveRow) -> crate::output::Result<()> {
        let m = &r.deformation;
        let e = m.strain();
        let (s1, s3) = principal_stresses(&r.stress);
        let phi = friction_angle(&r.stress);
        let psi = self.last.as_ref().map_or(f64::NAN, |l| dilatancy_angle(&l.deformation, m));
        let ev = volumetric_strain(m);
        let mut row = vec![r.step as f64];
        row.extend_from_slice(&e);
        row.push(m.w);
        row.extend_from_slice(&r.stress);
        row.extend_from_slice(&[
            ev,
            0.5 * (s1 + s3),
            s1 - s3,
            phi,
            psi,
            f64::from(r.iterations),
            r.control_residual,
            r.dem_steps as f64,
            f64::from(r.contacts),
            r.sliding_fraction,
        ]);
        self.rows.write_row(&row)?;
        let mut t = vec![r.step as f64];
        t.extend(r.tangent.iter().flatten());
        self.tangent.write_row(&t)?;
        let s = &mut self.summary;
        s.steps = r.step;
        s.dem_steps += r.dem_steps;
        if r.control_residual > self.tolerance {
            s.uncontrolled_steps += 1;
        }
        if phi.is_finite() && (s.peak_friction_angle.is_nan() || phi > s.peak_friction_angle) {
            s.peak_friction_angle = phi;
            s.peak_step = r.step;
            s.peak_strain = strain_of_interest(&s.path, m);
            s.peak_deviatoric_stress = s1 - s3;
            s.dilatancy_at_peak = psi;
        }
        if psi.is_finite() && (s.max_dilatancy_angle.is_nan() || psi > s.max_dilatancy_angle) {
            s.max_dilatancy_angle = psi;
        }
        s.final_friction_angle = phi;
        s.final_volumetric_strain = ev;
        self.history.push((r.step, phi, *m));
        self.last = Some(r.clone());
        Ok(())
    }

    /// The summary so far (the critical state once [`Self::finish`] has run).
    pub fn summary(&self) -> &RveSummary {
        &self.summary
    }

    /// Reads the critical state off the steps written and writes `rve.json` with the wall
    /// time.
    pub fn finish(&mut self, wall_seconds: f64) -> crate::output::Result<()> {
        self.summary.wall_seconds = wall_seconds;
        critical_state(&self.history, &mut self.summary);
        let path = self.dir.join("rve.json");
        // serde_json writes NaN (no peak, no dilation yet) as null.
        let json = serde_json::to_string_pretty(&self.summary)
            .map_err(|e| OutputError::InvalidData { path: path.clone(), message: e.to_string() })?;
        write_atomic(&path, format!("{json}\n").as_bytes())
    }
}

/// The critical state read off the last quarter of `history` (the loading steps, not the
/// initial state; at least two steps): the mean friction angle and the dilatancy angle of
/// the quarter as one increment. NaN before there are two loading steps.
fn critical_state(history: &[(u64, f64, MacroDeformation)], s: &mut RveSummary) {
    let loading = history.len().saturating_sub(1);
    s.critical_state_friction_angle = f64::NAN;
    s.critical_state_dilatancy_angle = f64::NAN;
    if loading < 2 {
        return;
    }
    let n = (loading / 4).max(2);
    let window = &history[history.len() - n..];
    let before = &history[history.len() - n - 1];
    s.critical_state_from_step = window[0].0;
    s.critical_state_friction_angle = window.iter().map(|h| h.1).sum::<f64>() / n as f64;
    s.critical_state_dilatancy_angle = dilatancy_angle(&before.2, &window[n - 1].2);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The critical state of a made-up history of 8 loading steps: the last quarter is its
    /// last 2 steps (from step 7), the friction angle their mean, the dilatancy angle that of
    /// steps 6 to 8 as one increment (`F = diag(l, 1/l)`, no area change: 0).
    #[test]
    fn the_critical_state_is_the_last_quarter() {
        let at = |k: u64| {
            let l = 1.0 + 1e-3 * k as f64;
            MacroDeformation::from_gradient([[l - 1.0, 0.0], [0.0, 1.0 / l - 1.0]], 0.0, [0.0; 2])
        };
        let history: Vec<_> = (0..=8).map(|k| (k, 20.0 + k as f64, at(k))).collect();
        let mut s = RveSummary::default();
        critical_state(&history[..2], &mut s);
        assert!(s.critical_state_friction_angle.is_nan());
        critical_state(&history, &mut s);
        assert_eq!(s.critical_state_from_step, 7);
        assert_eq!(s.critical_state_friction_angle, 27.5);
        assert!(s.critical_state_dilatancy_angle.abs() < 1e-9);
    }

    /// Closed forms: a stress state with sigma_1 = 3 sigma_3 gives sin(phi) = 1/2 (30 deg);
    /// a strain increment with no area change gives psi = 0, and de_1 = 2e-3, de_3 = -1e-3 gives
    /// sin(psi) = 1e-3 / 3e-3 (dilation positive). Tolerances: a few ulps of the
    /// trigonometric functions.
    #[test]
    fn angles_of_known_states() {
        let s = [-100.0, -300.0, 0.0, 0.0, 0.0, 0.0];
        assert!((friction_angle(&s) - 30.0).abs() < 1e-12);
        assert_eq!(principal_stresses(&s), (300.0, 100.0));
        // Rotated by 45 degrees: the same principal values.
        let s = [-200.0, -200.0, 100.0, 100.0, 0.0, 0.0];
        let (a, b) = principal_stresses(&s);
        assert!((a - 300.0).abs() < 1e-12 && (b - 100.0).abs() < 1e-12);
        assert!(friction_angle(&[1.0, 1.0, 0.0, 0.0, 0.0, 0.0]).is_nan());
        let id = MacroDeformation::IDENTITY;
        // F = diag(1.001, 1/1.001): no area change, psi = 0 (up to the rounding of F,
        // 1e-16 against 1e-3 strain: 1e-13 rad).
        let b =
            MacroDeformation::from_gradient([[1e-3, 0.0], [0.0, 1.0 / 1.001 - 1.0]], 0.0, [0.0; 2]);
        assert!(dilatancy_angle(&id, &b).abs() < 1e-10);
        // e_yy = -1e-3, e_xx = +2e-3 from the identity: the current-configuration increments
        // are d_xx = 2e-3 / (1 + 1e-3), d_yy = -1e-3 / (1 - 0.5e-3) (F_mid = diag(1.001,
        // 0.9995)), sin(psi) = (d_xx + d_yy) / (d_xx - d_yy), dilation (about 1/3).
        let b = MacroDeformation::from_gradient([[2e-3, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2]);
        let (dxx, dyy): (f64, f64) = (2e-3 / 1.001, -1e-3 / 0.9995);
        let want = ((dxx + dyy) / (dxx - dyy)).asin().to_degrees();
        assert!((dilatancy_angle(&id, &b) - want).abs() < 1e-9);
        // A large isochoric step, diag(1.2, 1/1.2) to diag(1.25, 1/1.25): zero angle (the
        // increment of F itself would give asin(0.0167 / 0.0833) = 11.5 degrees).
        let at = |l: f64| {
            MacroDeformation::from_gradient([[l - 1.0, 0.0], [0.0, 1.0 / l - 1.0]], 0.0, [0.0; 2])
        };
        assert!(dilatancy_angle(&at(1.2), &at(1.25)).abs() < 1e-9);
    }
}
