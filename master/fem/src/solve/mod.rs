//! The nonlinear solve: loading, sparse linear solves, Newton-Raphson with line search and
//! load-step cutting, and the per-step observer.

mod linear;
mod loading;
mod newton;
mod observer;
pub mod secant;

pub use linear::LinearSolver;
pub use loading::{
    BodyLoad, Dirichlet, EdgeLoad, EdgeLoadKind, LoadVectors, Loading, Platens, Ramp,
};
pub use newton::{
    IterationTiming, MAX_LOAD_STEPS, MIN_INCREMENT_FRACTION, Model, RunSummary, Solver,
    SolverSettings, SolverState,
};
pub use observer::{GaussPointState, SolutionView, StepControl, StepObserver, StepReport};
