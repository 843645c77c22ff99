//! One DEM assembly: reference geometry, committed and trial states, the trial solve,
//! commit/rollback, and (de)serialization.

/// Building an assembly from its spec (packings, masses, time step).
mod build;
/// The extrapolated predictor: the last committed step's non-affine increment.
pub mod extrapolate;
/// Perturbation columns and shortcut answers in the reference or the current frame.
mod frame;
/// Byte encoding and snapshots.
mod io;
/// The polar sub-step path of the current frame.
mod path;
/// Answers without a relaxation: the skip threshold and the elastic shortcut.
mod shortcut;
/// The trial solve: affine predictor, relaxation, homogenization, tangents.
mod solve;

pub use extrapolate::StepIncrement;
pub use io::{ContactForce, Snapshot};
pub use shortcut::{MARGIN as SHORTCUT_MARGIN, Relaxed};

use crate::boundary::penalty::Penalty;
use crate::boundary::periodic;
use crate::broadphase::{Domain, PairList};
use crate::contact::Law;
use crate::integrate::{Dynamics, System, Work};
use crate::spec::{AssemblySpec, BoundarySpec, Predictor};
use cosdem_common::MacroDeformation;
use serde::{Deserialize, Serialize};

/// Immutable reference data of an assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// Radii (m).
    pub r: Vec<f64>,
    /// Inverse masses used by the relaxation (density scaling included).
    pub inv_m: Vec<f64>,
    /// Inverse moments of inertia used by the relaxation.
    pub inv_i: Vec<f64>,
    /// Reference centres x (`X_q`); for a prestressed penalty reference the boundary
    /// particles' entries are the rest points of their penalty springs.
    pub x0: Vec<f64>,
    /// Reference centres y.
    pub y0: Vec<f64>,
    /// Rest rotations of the penalty moment springs (zero except for prestressed references).
    pub th0: Vec<f64>,
    /// Boundary-layer particles (penalty boundary; empty for periodic).
    pub boundary: Vec<u32>,
    /// Reference region width (m).
    pub lx: f64,
    /// Reference region height (m).
    pub ly: f64,
    /// Reference centre `X_c` (centre of the reference region).
    pub xc: [f64; 2],
    /// Reference area `V` (m^2).
    pub area: f64,
    /// Smallest radius.
    pub r_min: f64,
    /// Largest radius.
    pub r_max: f64,
}

/// A committed or trial state: everything that evolves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// Positions, rotations, velocities.
    pub dynamics: Dynamics,
    /// Verlet list with the contact histories.
    pub pairs: PairList,
    /// The macro deformation this state was relaxed to.
    pub target: MacroDeformation,
    /// What the relaxation to `target` answered (None for a state that was never relaxed by
    /// `solve`, e.g. the initial packing): the base of the shortcuts.
    pub relaxed: Option<Relaxed>,
}

/// A disc assembly backing one Gauss point.
#[derive(Clone, Debug)]
pub struct Assembly {
    spec: AssemblySpec,
    law: Law,
    refc: Reference,
    dt: f64,
    committed: State,
    trial: Option<State>,
    /// The non-affine increment of the step that ended at `committed` (kept only with
    /// `relaxation.predictor = "extrapolated"`).
    last_step: Option<StepIncrement>,
    work: Work,
}

impl Assembly {
    /// Builds the packing of `spec` (equilibrating random ones at their confining stress).
    pub fn new(spec: &AssemblySpec) -> crate::Result<Assembly> {
        // The specimen's own preparation is no load step to extrapolate from.
        build::new(spec).map(|a| Assembly { last_step: None, ..a })
    }

    /// Number of discs.
    pub fn disc_count(&self) -> usize {
        self.refc.r.len()
    }

    /// Reference area `V` (m^2).
    pub fn area(&self) -> f64 {
        self.refc.area
    }

    /// The spec this assembly was built from.
    pub fn spec(&self) -> &AssemblySpec {
        &self.spec
    }

    /// Resolved contact law.
    pub fn law(&self) -> &Law {
        &self.law
    }

    /// Reference data.
    pub fn reference(&self) -> &Reference {
        &self.refc
    }

    /// Base time step (s).
    pub fn time_step(&self) -> f64 {
        self.dt
    }

    /// The committed state.
    pub fn committed(&self) -> &State {
        &self.committed
    }

    /// The non-affine increment of the last committed step, kept for the extrapolated
    /// predictor (None with the affine predictor and before the first commit).
    pub fn last_step(&self) -> Option<&StepIncrement> {
        self.last_step.as_ref()
    }

    /// The last trial state, if a solve happened since the last commit/rollback.
    pub fn trial(&self) -> Option<&State> {
        self.trial.as_ref()
    }

    /// Accepts the last trial state (no-op without one).
    pub fn commit(&mut self) {
        if let Some(t) = self.trial.take() {
            self.last_step = (self.spec.relaxation.predictor == Predictor::Extrapolated)
                .then(|| self.step_increment(&self.committed, &t));
            self.committed = t;
        }
    }

    /// Discards the last trial state.
    pub fn rollback(&mut self) {
        self.trial = None;
    }

    /// Penalty springs for `target` (None for a periodic boundary).
    pub fn penalty(&self, target: &MacroDeformation) -> Option<Penalty> {
        match self.spec.boundary {
            BoundarySpec::Penalty { eps_f, eps_c } => Some(Penalty::new(
                &self.refc.boundary,
                &self.refc.x0,
                &self.refc.y0,
                &self.refc.th0,
                self.refc.xc,
                eps_f / self.refc.area,
                eps_c / self.refc.area,
                target,
            )),
            BoundarySpec::Periodic => None,
        }
    }

    /// Broad-phase domain for `target`.
    pub fn domain(&self, target: &MacroDeformation) -> Domain {
        match self.spec.boundary {
            BoundarySpec::Penalty { .. } => Domain::Open,
            BoundarySpec::Periodic => {
                Domain::Periodic { h: periodic::cell(&target.f, self.refc.lx, self.refc.ly) }
            }
        }
    }

    fn system<'a>(
        &'a self,
        law: &'a Law,
        penalty: Option<&'a Penalty>,
        target: &MacroDeformation,
    ) -> System<'a> {
        System {
            law,
            r: &self.refc.r,
            inv_m: &self.refc.inv_m,
            inv_i: &self.refc.inv_i,
            penalty,
            domain: self.domain(target),
            skin: self.spec.relaxation.skin * self.refc.r_min,
            force_floor: 1e-12 * self.law.kn * self.refc.r_min,
        }
    }

    /// Total energy of a state (kinetic with relaxation masses + contact and penalty springs).
    pub fn energy(&self, st: &State) -> f64 {
        let pen = self.penalty(&st.target);
        let sys = self.system(&self.law, pen.as_ref(), &st.target);
        crate::integrate::kinetic_energy(&sys, &st.dynamics)
            + crate::integrate::elastic_energy(&sys, &st.dynamics, &st.pairs)
    }
}
