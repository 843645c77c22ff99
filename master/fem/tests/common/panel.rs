//! The paper's panel and the test materials of the Newton tests (`newton_convergence.rs`,
//! `line_search.rs`, `step_cutting.rs`, `tolerated_and_forced.rs`, `stall.rs`, `dem_steps.rs`).

use cosdem_common::MicroResponse;
use cosdem_fem::assembly::Field;
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{
    ElasticCosserat, Material, MaterialError, MaterialInput, SofteningElastic, TrialId,
};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Loading, Model, Platens, SolverSettings};

/// Scene A with rough platens: u_x = 0 on top and bottom, u_y = 0 at the bottom and
/// `top_uy` at the top; w free.
pub fn panel(top_uy: f64) -> Model {
    let mesh = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, 2, 2, [0.0, 0.0]).unwrap();
    let loading = Loading::compression(top_uy, 0.0, Platens::Rough);
    Model {
        mesh,
        field: Field::Cosserat,
        rule: QuadratureRule::Gauss2x2,
        loading,
        kinematics: Default::default(),
    }
}

/// The elastic test material of the Newton tests (shear modulus 1e7 Pa, Poisson's ratio 0.3,
/// coupling modulus 5e6 Pa, length 0.05 m).
pub fn elastic() -> ElasticCosserat {
    ElasticCosserat::new(1e7, 0.3, 5e6, 0.05)
}

/// Numbers in short scientific notation, for printed residuals.
pub fn sci(v: &[f64]) -> Vec<String> {
    v.iter().map(|x| format!("{x:.2e}")).collect()
}

/// The answers of material `.0`, changed by `.1` (tangent, diagnostics), reported
/// non-symmetric (the LU path): the test materials of the Newton tests.
pub struct Adjusted<M, F>(pub M, pub F);

impl<M, F> Material for Adjusted<M, F>
where
    M: Material,
    F: FnMut(TrialId, &[MaterialInput], &mut [MicroResponse]) + Send,
{
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut r = self.0.evaluate(trial, inputs)?;
        (self.1)(trial, inputs, &mut r);
        Ok(r)
    }
    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        self.0.commit(step)
    }
    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.0.rollback()
    }
}

/// The elastic material as a non-symmetric one: forces the LU path.
pub fn as_unsymmetric(m: ElasticCosserat) -> impl Material {
    Adjusted(m, |_: TrialId, _: &[MaterialInput], _: &mut [MicroResponse]| {})
}

/// Elastic stresses, the tangent scaled by 0.4, and 7 DEM steps reported per Gauss point
/// per evaluation (summed into `count`: what the solver was asked to relax).
pub fn soft_tangent(count: &mut u64) -> impl Material + '_ {
    scaled_tangent(0.4, count)
}

/// Elastic stresses with the tangent scaled by `factor`; 7 DEM steps per answer, counted.
pub fn scaled_tangent(factor: f64, count: &mut u64) -> impl Material + '_ {
    Adjusted(elastic(), move |_: TrialId, _: &[MaterialInput], r: &mut [MicroResponse]| {
        for x in r.iter_mut() {
            x.tangent = x.tangent.map(|row| row.map(|v| factor * v));
            x.diagnostics.steps = 7;
        }
        *count += 7 * r.len() as u64;
    })
}

/// The panel held at the bottom under a 1e5 Pa pressure on its top.
pub fn top_pressure_panel() -> Model {
    let mut model = panel(0.0);
    model.loading.dirichlet.retain(|d| d.set == "bottom");
    model.loading.edge_loads.push(cosdem_fem::solve::EdgeLoad {
        set: "top".into(),
        kind: cosdem_fem::solve::EdgeLoadKind::Pressure(1e5),
        ramp: cosdem_fem::solve::Ramp::Linear,
    });
    model
}

/// Two steps of the softening panel with one Newton iteration per attempt and an
/// unreachable force tolerance: every attempt fails, so the first step is cut to 1/4 and
/// ends the run (unless `tolerated_residual` accepts it).
pub fn one_iteration_per_attempt() -> SolverSettings {
    SolverSettings {
        steps: 2,
        max_iterations: 1,
        force_tolerance: 1e-14,
        min_increment_fraction: 0.25,
        ..Default::default()
    }
}

/// The softening law's stresses with the elastic tangent: the DEM situation in miniature (a
/// relaxed assembly is softer than its contact-stiffness tangent), so Newton with the
/// material's tangent contracts only by `1 - K_true / K_elastic` per iteration.
pub fn elastic_tangent(beta: f64) -> impl Material {
    let mut initial = elastic();
    let softening = SofteningElastic { elastic: elastic(), beta };
    Adjusted(softening, move |trial: TrialId, inputs: &[MaterialInput], r: &mut [MicroResponse]| {
        let tangents = initial.evaluate(trial, inputs).expect("the elastic law always answers");
        for (x, e) in r.iter_mut().zip(tangents) {
            x.tangent = e.tangent;
        }
    })
}
