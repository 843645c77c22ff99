//! The nonlinear solve: loading, sparse linear solves, Newton-Raphson with line search and
//! load-step cutting, and the per-step observer.

mod control;
mod follower;
mod linear;
mod loading;
mod newton;
mod observer;
pub mod secant;
mod settings;
mod solver;
mod stage;
mod system;

pub use linear::LinearSolver;
pub use loading::{
    BodyLoad, ControlTerm, Dirichlet, EdgeLoad, EdgeLoadKind, LoadVectors, Loading, PathControl,
    Platens, Ramp,
};
pub use observer::{GaussPointState, SolutionView, StepControl, StepObserver, StepReport};
pub use settings::{MAX_LOAD_STEPS, MIN_INCREMENT_FRACTION, SolverSettings};
pub use solver::{Model, RunSummary, Solver, SolverState};
pub use system::IterationTiming;
