//! The cosdem master: the Cosserat finite-element macro solver.
//!
//! Data path: [`mesh::Mesh`] -> [`assembly::GaussData`] (Gauss points) -> [`material::Material`]
//! (one batched evaluation per Newton iteration) -> [`assembly::CosseratOperator`] (residual,
//! sparse tangent) -> [`solve::Solver`] (faer solve, Newton, step cutting, commit) ->
//! [`solve::StepObserver`] (output).
//!
//! ```
//! use cosdem_master::assembly::{Component, Field};
//! use cosdem_master::element::{ElementKind, QuadratureRule};
//! use cosdem_master::material::ElasticCosserat;
//! use cosdem_master::mesh::Mesh;
//! use cosdem_master::solve::{Dirichlet, Loading, Model, Solver, SolverSettings, StepReport};
//!
//! // Scene A: 1 x 1 m panel, 2 x 2 Q8, rough platens, top moved down by 1 cm.
//! let mesh = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, 2, 2, [0.0, 0.0])?;
//! let loading = Loading {
//!     dirichlet: vec![
//!         Dirichlet::new("bottom", Component::Ux, 0.0),
//!         Dirichlet::new("bottom", Component::Uy, 0.0),
//!         Dirichlet::new("top", Component::Ux, 0.0),
//!         Dirichlet::new("top", Component::Uy, -0.01),
//!     ],
//!     ..Default::default()
//! };
//! let model = Model { mesh, field: Field::Cosserat, rule: QuadratureRule::Gauss2x2, loading };
//! let mut solver = Solver::new(model, SolverSettings { steps: 5, ..Default::default() })?;
//! let mut material = ElasticCosserat::new(1e7, 0.3, 5e6, 0.01);
//! let mut curve: Vec<StepReport> = Vec::new(); // any StepObserver
//! solver.run(&mut material, &mut curve)?;
//! let load = -curve.last().unwrap().reactions["top"][1]; // compression positive
//! assert!(load > 0.0);
//! # Ok::<(), cosdem_master::Error>(())
//! ```

/// Accuracy target: the cheapest speed settings the measured trade predicts to stay within
/// a job's `accuracy` (what was picked and why: `RUN/accuracy.json`).
pub mod accuracy;
/// From nodal fields to Gauss-point kinematics and back to global residual and tangent.
pub mod assembly;
/// Benchmarks of the coupling (RPC overhead, worker scaling, FE versus DEM cost): `cosdem bench`.
pub mod bench;
/// Checkpoints (`RUN/checkpoint.bin`), resume, and the clean stop on Ctrl-C.
pub mod checkpoint;
/// Reference elements: Q8/Q9 shape functions and Gauss rules.
pub mod element;
/// The crate's error type.
pub mod error;
/// Reading input files (Gmsh meshes) into plain data.
pub mod io;
/// The job file: schema, validation, conversion into the solver's types.
pub mod job;
/// The constitutive operator at the Gauss points: the trait the FE solver talks to.
pub mod material;
/// The macro mesh: structured rectangles and the generic raw-description constructor.
pub mod mesh;
/// Writing results: VTK unstructured grids, ParaView collections, CSV curves.
pub mod output;
/// The DEM-backed material: a pool of workers (remote or in-process), with failover and balancing.
pub mod pool;
/// Derived quantities for plots (equivalent strain, Eq. 34).
pub mod post;
/// One job run to its end into a run directory (the library side of `cosdem run`).
pub mod run;
/// One DEM assembly driven through a laboratory path (biaxial, isotropic, simple shear):
/// `cosdem rve`, for calibrating micro parameters.
pub mod rve;
/// Loading, linear solves, Newton-Raphson with step cutting, step observers.
pub mod solve;
/// Speed against accuracy averaged over specimens (packing seeds):
/// `cosdem bench tradeoff-specimens`.
pub mod specimens;
/// Parameter studies over whole runs: the RVE-size study (Eqs. 30-32), `cosdem study`.
pub mod study;
/// Symmetric scenes on a half or quarter mesh: the reduced rectangle and its axis conditions.
pub mod symmetry;
/// Speed against accuracy: the knob sweep of `cosdem bench tradeoff`.
pub mod tradeoff;

pub use error::{Error, Result};
