//! A deterministic stand-in for the DEM assembly: an isotropic Cosserat elastic material
//! with scalar damage, path-dependent through its committed damage history, with a fake
//! cost proportional to its "disc count".
//!
//! It exists so that the service, the pool and their tests run before the DEM core lands,
//! and it keeps the same contract (committed/trial state, deterministic solve, bytes).

use super::model::{MicroModel, ModelError};
use cosdem_common::micro::{AssemblyRequest, MicroSnapshot};
use cosdem_common::voigt::N;
use cosdem_common::{GaussPointId, MacroDeformation, MicroDiagnostics, MicroResponse};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Parameters of the stand-in (its "spec JSON"; every field has a default).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StandInSpec {
    /// Pretend disc count: sets the cost and the limits' accounting.
    pub discs: u64,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Cosserat couple modulus `mu_c` (Pa).
    pub couple: f64,
    /// Bending modulus (N).
    pub bending: f64,
    /// Equivalent strain at which damage starts.
    pub kappa0: f64,
    /// Softening scale of the damage law.
    pub kappa_f: f64,
    /// Equivalent strain beyond which the "relaxation" fails (reported in-band).
    pub fail_strain: f64,
    /// Fake work per disc per solve (iterations of a logistic map).
    pub work_per_disc: u64,
}

impl Default for StandInSpec {
    fn default() -> Self {
        Self {
            discs: 100,
            young: 1.0e8,
            poisson: 0.25,
            couple: 2.0e7,
            bending: 1.0e3,
            kappa0: 1.0e-3,
            kappa_f: 1.0e-2,
            fail_strain: 0.5,
            work_per_disc: 20,
        }
    }
}

/// Test hooks of a stand-in worker.
#[derive(Clone, Debug, Default)]
pub struct StandInOptions {
    /// After this many solves, every further solve sleeps for `hang_for` first (a worker
    /// that stops answering).
    pub hang_after_solves: Option<u64>,
    /// How long a hanging solve sleeps.
    pub hang_for: Duration,
}

/// The stand-in model.
#[derive(Clone, Debug, Default)]
pub struct StandIn {
    options: StandInOptions,
    solves: Arc<AtomicU64>,
}

impl StandIn {
    /// A well-behaved stand-in.
    pub fn new() -> Self {
        Self::default()
    }

    /// A stand-in with test hooks.
    pub fn with_options(options: StandInOptions) -> Self {
        Self { options, solves: Arc::default() }
    }
}

/// One stand-in assembly: spec, committed damage history, trial damage history.
#[derive(Clone, Debug)]
pub struct StandInAssembly {
    spec: StandInSpec,
    committed_kappa: f64,
    trial_kappa: Option<f64>,
}

fn equivalent(e: &[f64; N]) -> (f64, [f64; N]) {
    let eq2 = e[0] * e[0] + e[1] * e[1] + 0.5 * (e[2] * e[2] + e[3] * e[3]);
    let eq = eq2.sqrt();
    let mut d = [0.0; N];
    if eq > 0.0 {
        d = [e[0] / eq, e[1] / eq, 0.5 * e[2] / eq, 0.5 * e[3] / eq, 0.0, 0.0];
    }
    (eq, d)
}

impl StandInSpec {
    fn stiffness(&self) -> [[f64; N]; N] {
        let (e, nu) = (self.young, self.poisson);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        let mc = self.couple;
        let mut c = [[0.0; N]; N];
        c[0][0] = lambda + 2.0 * mu;
        c[0][1] = lambda;
        c[1][0] = lambda;
        c[1][1] = lambda + 2.0 * mu;
        c[2][2] = mu + mc;
        c[2][3] = mu - mc;
        c[3][2] = mu - mc;
        c[3][3] = mu + mc;
        c[4][4] = self.bending;
        c[5][5] = self.bending;
        c
    }

    /// Damage and its derivative at history `k`.
    fn damage(&self, k: f64) -> (f64, f64) {
        if k <= self.kappa0 {
            (0.0, 0.0)
        } else {
            let x = (-(k - self.kappa0) / self.kappa_f).exp();
            (1.0 - x, x / self.kappa_f)
        }
    }
}

/// The stand-in response from a committed history: (response, trial history).
fn respond(
    spec: &StandInSpec,
    committed_kappa: f64,
    target: &MacroDeformation,
) -> Result<(MicroResponse, f64), ModelError> {
    let e = target.strain();
    let (eq, deq) = equivalent(&e);
    if eq > spec.fail_strain {
        return Err(ModelError::Failed(format!(
            "stand-in relaxation did not converge: equivalent strain {eq} > {}",
            spec.fail_strain
        )));
    }
    let loading = eq > committed_kappa;
    let kappa = committed_kappa.max(eq);
    let (d, dd) = spec.damage(kappa);
    let c = spec.stiffness();
    let mut ce = [0.0; N];
    for i in 0..N {
        for j in 0..N {
            ce[i] += c[i][j] * e[j];
        }
    }
    let mut stress = [0.0; N];
    let mut tangent = [[0.0; N]; N];
    for i in 0..N {
        stress[i] = (1.0 - d) * ce[i];
        for j in 0..N {
            tangent[i][j] = (1.0 - d) * c[i][j];
            if loading {
                tangent[i][j] -= dd * ce[i] * deq[j];
            }
        }
    }
    // Fake work, deterministic: the DEM's cost stands in as a logistic map.
    let mut x = 0.3f64;
    for _ in 0..spec.discs * spec.work_per_disc {
        x = 3.7 * x * (1.0 - x);
    }
    std::hint::black_box(x);
    let diagnostics = MicroDiagnostics {
        steps: spec.discs * spec.work_per_disc,
        residual_ratio: 1e-6 * (1.0 + d),
        converged: true,
        contacts: (2 * spec.discs) as u32,
        sliding_fraction: d,
        rolling_fraction: 0.0,
        wall_seconds: 0.0,
        ..Default::default()
    };
    Ok((MicroResponse { stress, tangent, diagnostics }, kappa))
}

impl MicroModel for StandIn {
    type Assembly = StandInAssembly;

    fn create(
        &self,
        _id: GaussPointId,
        req: &AssemblyRequest,
    ) -> Result<StandInAssembly, ModelError> {
        let spec: StandInSpec = if req.spec_json.is_empty() {
            StandInSpec::default()
        } else {
            serde_json::from_slice(&req.spec_json)
                .map_err(|e| ModelError::InvalidSpec(e.to_string()))?
        };
        if !(spec.young > 0.0 && spec.kappa_f > 0.0 && spec.poisson < 0.5) {
            return Err(ModelError::InvalidSpec(
                "young and kappa_f must be > 0, poisson < 0.5".into(),
            ));
        }
        Ok(StandInAssembly { spec, committed_kappa: 0.0, trial_kappa: None })
    }

    fn solve(
        &self,
        a: &mut StandInAssembly,
        target: &MacroDeformation,
    ) -> Result<MicroResponse, ModelError> {
        let n = self.solves.fetch_add(1, Ordering::SeqCst);
        if self.options.hang_after_solves.is_some_and(|after| n >= after) {
            let until = Instant::now() + self.options.hang_for;
            while Instant::now() < until {
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        let start = Instant::now();
        a.trial_kappa = None;
        let (mut r, kappa) = respond(&a.spec, a.committed_kappa, target)?;
        a.trial_kappa = Some(kappa);
        r.diagnostics.wall_seconds = start.elapsed().as_secs_f64();
        Ok(r)
    }

    fn commit(&self, a: &mut StandInAssembly) {
        if let Some(k) = a.trial_kappa.take() {
            a.committed_kappa = k;
        }
    }

    fn rollback(&self, a: &mut StandInAssembly) {
        a.trial_kappa = None;
    }

    fn export(&self, a: &StandInAssembly) -> Vec<u8> {
        // Exact: the history as its bit pattern, then the spec as JSON.
        let mut out = a.committed_kappa.to_bits().to_le_bytes().to_vec();
        out.extend(serde_json::to_vec(&a.spec).expect("spec serializes"));
        out
    }

    fn import(&self, bytes: &[u8]) -> Result<StandInAssembly, ModelError> {
        if bytes.len() < 8 {
            return Err(ModelError::InvalidState(format!(
                "{} bytes, need at least 8",
                bytes.len()
            )));
        }
        let (k, spec) = bytes.split_at(8);
        let committed_kappa = f64::from_bits(u64::from_le_bytes(k.try_into().expect("8 bytes")));
        let spec =
            serde_json::from_slice(spec).map_err(|e| ModelError::InvalidState(e.to_string()))?;
        Ok(StandInAssembly { spec, committed_kappa, trial_kappa: None })
    }

    fn snapshot(&self, a: &StandInAssembly) -> MicroSnapshot {
        // No particles: the committed history stands in as the one "fluctuation".
        MicroSnapshot { fluctuations: vec![a.committed_kappa], ..Default::default() }
    }

    fn disc_count(&self, a: &StandInAssembly) -> u64 {
        a.spec.discs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_matches_finite_differences_when_loading() {
        let spec = StandInSpec::default();
        let e = [0.004, -0.001, 0.002, 0.001, 0.01, -0.02];
        let m = MacroDeformation::from_strain(&e, 0.0);
        let (r, _) = respond(&spec, 0.0, &m).unwrap();
        for j in 0..N {
            let h = 1e-9;
            let mut ep = e;
            ep[j] += h;
            let (rp, _) = respond(&spec, 0.0, &MacroDeformation::from_strain(&ep, 0.0)).unwrap();
            for i in 0..N {
                let fd = (rp.stress[i] - r.stress[i]) / h;
                let scale = spec.young;
                assert!(
                    (fd - r.tangent[i][j]).abs() < 1e-3 * scale,
                    "({i},{j}): {fd} vs {}",
                    r.tangent[i][j]
                );
            }
        }
    }

    #[test]
    fn export_import_is_exact_and_commit_is_path_dependent() {
        let m = StandIn::new();
        let mut a = m.create(GaussPointId::new(0, 0), &AssemblyRequest::default()).unwrap();
        let big = MacroDeformation::from_strain(&[0.01, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0);
        let small = MacroDeformation::from_strain(&[0.001, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0);
        let fresh = m.solve(&mut a, &small).unwrap();
        m.solve(&mut a, &big).unwrap();
        m.commit(&mut a);
        let mut b = m.import(&m.export(&a)).unwrap();
        let after = m.solve(&mut b, &small).unwrap();
        assert!(after.stress[0] < fresh.stress[0]);
        assert_eq!(m.solve(&mut a, &small).unwrap().stress, after.stress);
    }
}
