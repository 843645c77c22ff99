//! The assembly specification: what a job file (or the gRPC service) says about one DEM
//! assembly. Every struct is serde-derived with `deny_unknown_fields`, and a variant without
//! settings (`periodic`, `paper`, `none`, ...) refuses any key besides its tag; defaults are the
//! paper's values (Chu et al. 2015, section 3) unless a comment says otherwise.
//!
//! Every field may be omitted (defaults); a full spec in JSON reads:
//! ```json
//! {
//!   "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.1},
//!   "contact": {
//!     "normal": {"model": "linear", "k_n": 6.7e7},
//!     "tangential": {"model": "coulomb", "k_s": 3.4e7, "mu_s": 0.5, "c_s": 0.0},
//!     "rolling": {"model": "coulomb", "k_r": 25.0, "mu_r": 0.2, "c_r": 0.0}
//!   },
//!   "density": 2650.0,
//!   "boundary": {"kind": "penalty", "eps_f": 6.7e6, "eps_c": 1000.0},
//!   "relaxation": {"driver": {"kind": "cundall", "alpha": 0.7}, "criterion": "unbalanced_force",
//!                  "tolerance": 1e-4, "max_steps": 400000, "check_every": 10, "safety": 0.8,
//!                  "density_scale": 1.0, "skin": 0.5},
//!   "tangent": {"kind": "paper"},
//!   "frame": "reference",
//!   "warm_start": false
//! }
//! ```
//! A random packing: `{"kind": "random", "r_min": 0.004, "r_max": 0.006, "side": 0.1,
//! "seed": 1, "confining_stress": 1e5}`; a periodic boundary: `{"kind": "periodic"}`; FIRE:
//! `{"kind": "fire", "alpha_start": 0.1, "f_inc": 1.1, "f_dec": 0.5, "f_alpha": 0.99,
//! "n_min": 5, "dt_max": 1.8}`; the perturbation tangent: `{"kind": "perturbation",
//! "strain": 1e-5}`.
//!
//! One module per part of the spec, each with the checks of its own fields: `packing`,
//! `contact`, `boundary`, `relaxation` and `tangent`; `size` gives the disc count a spec
//! builds ([`AssemblySpec::disc_count_hint`]) and a bound on its exported state's bytes
//! ([`state_bytes`]) before anything is built.

mod boundary;
mod contact;
mod packing;
mod relaxation;
mod size;
mod tangent;

pub use boundary::BoundarySpec;
pub use contact::{ContactParams, NormalModel, RollingModel, TangentialModel};
pub use packing::{Lattice, LatticeOrientation, MAX_DISCS, MAX_LATTICE_OVERLAP, PackingSpec};
pub use relaxation::{
    Criterion, Driver, FIRE_CEILING, MAX_RELAXATION_STEPS, MAX_SUBSTEPS, Predictor, RelaxationSpec,
};
pub use size::{STATE_BYTES_PER_DISC, STATE_ENVELOPE_BYTES, STATE_FIXED_BYTES, state_bytes};
pub use tangent::{MAX_TANGENT_STRAIN, SECANT_RANGE, TangentFrame, TangentKind};

use crate::error::{Result, positive};
use serde::{Deserialize, Deserializer, Serialize};

/// Everything needed to build and drive one assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AssemblySpec {
    /// How the discs are arranged in the reference state.
    pub packing: PackingSpec,
    /// The contact law (normal, tangential and rolling sub-models).
    pub contact: ContactParams,
    /// Solid density in kg/m^3 (default 2650: quartz; the paper does not give one).
    pub density: f64,
    /// Penalty (Miehe, Eq. 24) or periodic boundary.
    pub boundary: BoundarySpec,
    /// Time step, relaxation driver and convergence criterion.
    pub relaxation: RelaxationSpec,
    /// Which tangent operator `solve` returns.
    pub tangent: TangentKind,
    /// The frame of the tangent, the sub-step path and the shortcut: `reference` (default,
    /// not written) or `current` (under the FE's updated-Lagrangian kinematics).
    #[serde(skip_serializing_if = "TangentFrame::is_reference")]
    pub frame: TangentFrame,
    /// Start each trial solve from the last trial state (since the last commit or rollback)
    /// instead of the committed state: fewer steps per Newton iteration, but the answer then
    /// depends on the iteration history. Default false.
    pub warm_start: bool,
}

impl Default for AssemblySpec {
    fn default() -> Self {
        Self {
            packing: PackingSpec::default(),
            contact: ContactParams::default(),
            density: 2650.0,
            boundary: BoundarySpec::default(),
            relaxation: RelaxationSpec::default(),
            tangent: TangentKind::default(),
            frame: TangentFrame::Reference,
            warm_start: false,
        }
    }
}

impl AssemblySpec {
    /// Checks every field; errors name the field and value.
    pub fn validate(&self) -> Result<()> {
        self.packing.validate()?;
        self.contact.validate()?;
        positive("density", self.density)?;
        self.boundary.validate()?;
        self.relaxation.validate()?;
        self.tangent.validate()
    }
}

/// Reads the table of a variant that takes no settings (`{kind = "periodic"}`, `{model =
/// "none"}`, ...), refusing any key besides the tag with serde's "unknown field" error naming
/// it: a plain unit variant of an internally tagged enum would accept the keys and drop them. Used as
/// `#[serde(deserialize_with = "super::no_settings")]` on the variant, which leaves its
/// serialization untouched.
fn no_settings<'de, D: Deserializer<'de>>(deserializer: D) -> std::result::Result<(), D::Error> {
    /// An empty table.
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct NoSettings {}
    NoSettings::deserialize(deserializer).map(|NoSettings {}| ())
}

#[cfg(test)]
mod tests;
