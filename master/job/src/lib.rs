//! The job file: one TOML document that says what to run.
//!
//! Every table and key is listed in `docs/reference/job-file.md` with its default and unit
//! (`tests/reference.rs` fails when one is missing). Unknown keys are errors (serde's
//! `deny_unknown_fields`, with the line and column), and so are out-of-range values:
//! [`Job::validate`] names the key and the value. The job is turned into the solver's own
//! types by [`Job::model`] and [`Job::solver_settings`]; nothing below this crate knows about
//! TOML.
//!
//! - `schema`: the tables as serde structs ([`Job`], [`MeshSection`], [`MaterialSection`], ...);
//! - `arrays`: the fixed-length arrays (`mesh.origin`, `output.snapshots`), length checked;
//! - `material`: reading `[material]` as a plain struct, so errors keep their TOML position;
//! - `region`: `[[region]]`, parts of the mesh with their own material and bulk density
//!   ([`Job::element_materials`], [`Job::materials`]);
//! - `specimens`: `[specimens]`, the distinct DEM specimens and their consolidation levels
//!   ([`SpecimensSection::specimen_of`], [`SpecimensSection::level_of`]);
//! - `table`: a job given as a TOML table (the Python package's `Job(dict)`), errors by key path;
//! - `load`: reading TOML text or a regular file of at most [`MAX_JOB_FILE_BYTES`]
//!   ([`Job::from_toml`], [`Job::load`]);
//! - `bulk`: the bulk density of a DEM material from its assembly, for gravity;
//! - `packing_file`: a `kind = "file"` packing read on the master into its explicit discs;
//! - `validate`: ranges and combinations ([`Job::validate`]);
//! - `curve`: `[output.curve]`, the curve's axes, and the `.pvd` time rule ([`Job::pvd_time`]);
//! - `convert`: the FE model, the solver settings and the elastic material ([`Job::model`],
//!   [`Job::solver_settings`], [`Job::elastic`]);
//! - `admission`: the memory and disk a job will need, estimated before anything is
//!   allocated, and the refusal of a job too large ([`admission::estimate`]);
//! - `fixtures` (tests only, feature `fixtures`): the shared test jobs of `fixtures/jobs/`.

pub mod admission;
mod arrays;
pub mod bulk;
mod convert;
mod curve;
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
mod load;
mod material;
mod packing_file;
mod region;
mod schema;
mod specimens;
mod stage;
mod table;
mod validate;

pub use curve::{CurveQuantity, CurveSection, PvdTime};
pub use load::MAX_JOB_FILE_BYTES;
pub use packing_file::MAX_PACKING_FILE_BYTES;
pub use region::RegionSection;
pub use schema::{
    ComponentChoice, Compression, Continuum, ControlSection, ControlTermSection, ElementChoice,
    Integration, Job, LoadingSection, MaterialSection, MeshKind, MeshSection, Moving,
    NewtonSection, OutputSection, PAPER_LINEAR_RANGE, PlatenChoice, Prescribed, PressureLoad,
    RampChoice, VtkFormat, WorkersSection,
};
pub use specimens::{Consolidation, SpecimenCount, SpecimensSection};
pub use stage::{
    MAX_STAGES, SolverStage, StageGravity, StagePrescribed, StagePressure, StageRamp, StageSection,
    StageTraction, StagesSoFar,
};
pub use table::from_table;
pub use validate::MAX_TANGENT_STRAIN;
