//! The cosdem finite-element core: the Cosserat macro solver (no discs, no network).
//!
//! Data path: [`mesh::Mesh`] -> [`assembly::GaussData`] (Gauss points) -> [`material::Material`]
//! (one batched evaluation per Newton iteration) -> [`assembly::CosseratOperator`] (residual,
//! sparse tangent) -> [`solve::Solver`] (faer solve, Newton, step cutting, commit) ->
//! [`solve::StepObserver`] (output).
//!
//! ```
//! use cosdem_fem::assembly::{Component, Field};
//! use cosdem_fem::element::{ElementKind, QuadratureRule};
//! use cosdem_fem::material::ElasticCosserat;
//! use cosdem_fem::mesh::Mesh;
//! use cosdem_fem::solve::{Dirichlet, Loading, Model, Solver, SolverSettings, StepReport};
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
//! let model = Model { mesh, field: Field::Cosserat, rule: QuadratureRule::Gauss2x2, loading, kinematics: Default::default() };
//! let mut solver = Solver::new(model, SolverSettings { steps: 5, ..Default::default() })?;
//! let mut material = ElasticCosserat::new(1e7, 0.3, 5e6, 0.01);
//! let mut curve: Vec<StepReport> = Vec::new(); // any StepObserver
//! solver.run(&mut material, &mut curve)?;
//! let load = -curve.last().unwrap().reactions["top"][1]; // compression positive
//! assert!(load > 0.0);
//! # Ok::<(), cosdem_fem::Error>(())
//! ```

/// From nodal fields to Gauss-point kinematics and back to global residual and tangent.
pub mod assembly;
/// Reference elements: Q8/Q9/T6 shape functions, Gauss rules and shape checks.
pub mod element;
/// The crate's error type.
pub mod error;
/// Gmsh meshes (`.msh` 2.2 and 4.1, ASCII and binary) read into plain data.
pub mod gmsh;
/// The constitutive operator at the Gauss points: the trait the FE solver talks to.
pub mod material;
/// The macro mesh: structured rectangles and the generic raw-description constructor.
pub mod mesh;
/// Derived quantities for plots (equivalent strain, Eq. 34) and curve metrics.
pub mod post;
/// Loading, linear solves, Newton-Raphson with step cutting, step observers.
pub mod solve;
/// Symmetric scenes on a half or quarter mesh: the reduced rectangle and its axis conditions.
pub mod symmetry;

pub use error::{Error, Result};
