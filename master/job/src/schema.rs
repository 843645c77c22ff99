//! The tables of the job file as serde structs: every key, its meaning and its default.
//! Unknown keys are refused (`deny_unknown_fields`); ranges are checked by [`Job::validate`].

use cosdem_fem::assembly::Kinematics;
use cosdem_fem::solve::SolverSettings;
use cosdem_fem::symmetry::Symmetry;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A whole job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Job {
    /// Free text shown in the summary.
    #[serde(default)]
    pub title: String,
    /// Accuracy target (fraction in (0, 1), e.g. 0.05 for 5 %): when given, the speed knobs
    /// of `[material.assembly]` and the load step are chosen by `cosdem_tune::accuracy` from the
    /// measured speed/accuracy trade before the run. Absent (the default): the job runs as
    /// written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<f64>,
    /// The macro mesh.
    pub mesh: MeshSection,
    /// Boundary conditions, loads and load steps.
    #[serde(default)]
    pub loading: LoadingSection,
    /// The loading in stages (`[[stage]]`), instead of `[loading]`'s loads.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stage: Vec<crate::stage::StageSection>,
    /// The material at the Gauss points (of the elements in no `[[region]]`).
    pub material: MaterialSection,
    /// Parts of the mesh with their own material (`[[region]]`); none: `[material]` everywhere.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub region: Vec<crate::region::RegionSection>,
    /// The DEM specimens and their consolidation (`[specimens]`); default: one specimen, the
    /// packing's own confining stress.
    #[serde(default, skip_serializing_if = "crate::specimens::SpecimensSection::is_default")]
    pub specimens: crate::specimens::SpecimensSection,
    /// Newton-Raphson and step control.
    #[serde(default)]
    pub newton: NewtonSection,
    /// What is written, and how often.
    #[serde(default)]
    pub output: OutputSection,
    /// Where the DEM assemblies are solved.
    #[serde(default)]
    pub workers: WorkersSection,
}

/// How the mesh is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshKind {
    /// A structured rectangle `lx` x `ly` with `nx` x `ny` elements.
    Rectangle,
    /// A Gmsh `.msh` file (2.2 or 4.1) of 8- or 9-node quadrilaterals or 6-node triangles.
    Gmsh,
}

/// Element family of a structured mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementChoice {
    /// 8-node serendipity quadrilateral (the paper's).
    Q8,
    /// 9-node Lagrange quadrilateral.
    Q9,
    /// 6-node quadratic triangle: each cell of the rectangle's grid split into two.
    T6,
}

/// Gauss rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// 2x2 points per quadrilateral (the paper's; one DEM assembly per point), 3 per
    /// triangle.
    Reduced,
    /// 3x3 points per quadrilateral, 6 per triangle.
    Full,
}

/// The continuum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Continuum {
    /// `u_x, u_y, w` per node (the paper's).
    Cosserat,
    /// `u_x, u_y` per node (Guo & Zhao's FEMxDEM is Cauchy).
    Cauchy,
}

/// `[mesh]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSection {
    /// `rectangle` or `gmsh`.
    pub kind: MeshKind,
    /// Width (m), rectangle only.
    pub lx: Option<f64>,
    /// Height (m), rectangle only.
    pub ly: Option<f64>,
    /// Elements along x, rectangle only.
    pub nx: Option<usize>,
    /// Elements along y, rectangle only.
    pub ny: Option<usize>,
    /// Lower-left corner (m), rectangle only; default `[0, 0]`.
    #[serde(default, deserialize_with = "crate::arrays::origin")]
    pub origin: [f64; 2],
    /// `q8` (default), `q9` or `t6`, rectangle only (a Gmsh file says its own).
    #[serde(default = "default_element")]
    pub element: ElementChoice,
    /// `reduced` (2x2 or 3 per triangle, default) or `full` (3x3 or 6 per triangle).
    #[serde(default = "default_integration")]
    pub integration: Integration,
    /// `cosserat` (default) or `cauchy`.
    #[serde(default = "default_continuum")]
    pub continuum: Continuum,
    /// The `.msh` file, gmsh only; relative to the job file.
    pub file: Option<PathBuf>,
    /// `none` (default), `half_x` or `quarter`: mesh only the left half or lower-left quarter
    /// of a symmetric rectangle (see [`cosdem_fem::symmetry`]).
    #[serde(default)]
    pub symmetry: Symmetry,
    /// `small` (default: the paper's small-strain statement) or `updated_lagrangian`
    /// (balance on the deformed configuration, geometric stiffness, follower pressures, an
    /// objective elastic law). Not written when `small`, so jobs without it keep their
    /// digests.
    #[serde(default, skip_serializing_if = "is_small")]
    pub kinematics: Kinematics,
}

fn is_small(k: &Kinematics) -> bool {
    *k == Kinematics::Small
}

fn default_element() -> ElementChoice {
    ElementChoice::Q8
}
fn default_integration() -> Integration {
    Integration::Reduced
}
fn default_continuum() -> Continuum {
    Continuum::Cosserat
}

/// Which platens move in a compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Moving {
    /// Top down and bottom up by half the shortening each (the paper: "applied to the top
    /// and bottom").
    Both,
    /// Top down by the whole shortening, bottom held.
    Top,
}

/// Platen friction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlatenChoice {
    /// `u_x = 0` on top and bottom (default).
    Rough,
    /// `u_x` free on top and bottom (one node pinned).
    Smooth,
}

/// `[loading.compression]`: the paper's platen compression.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Compression {
    /// Total shortening at the end of the run (m, positive).
    pub displacement: f64,
    /// `rough` (default) or `smooth`.
    #[serde(default = "default_platens")]
    pub platens: PlatenChoice,
    /// `both` (default) or `top`.
    #[serde(default = "default_moving")]
    pub moving: Moving,
}

fn default_platens() -> PlatenChoice {
    PlatenChoice::Rough
}
fn default_moving() -> Moving {
    Moving::Both
}

/// Dof component names in the job file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ComponentChoice {
    /// `u_x`.
    Ux,
    /// `u_y`.
    Uy,
    /// `w` (Cosserat only).
    W,
}

/// `[[loading.prescribed]]`: a dof value on a node set, reached at the end of the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prescribed {
    /// Node set (`top`, `bottom`, `left`, `right`, corners, or a Gmsh physical name).
    pub set: String,
    /// `ux`, `uy` or `w`.
    pub component: ComponentChoice,
    /// Final value (m or rad); grows linearly over the load steps.
    pub value: f64,
}

/// `[loading.control]` (or `[stage.control]`): path control. The steps advance the mean of
/// `component` over the node set `set` by `value` in all, from where it is, instead of the
/// load factor; the load factor of the prescribed dofs and loads is solved for at each step,
/// so the load-displacement path may turn back (a snap-back) without the run failing. The
/// run (stage) ends when the control quantity has moved by `value`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlSection {
    /// Node set (a Gmsh physical name or a structured mesh's side or corner).
    pub set: String,
    /// `ux`, `uy` or `w`.
    pub component: ComponentChoice,
    /// The change of the control quantity over the run or stage (m or rad; not 0).
    pub value: f64,
    /// Further terms: the control quantity is the set's mean `component` plus each term's
    /// `weight` times its set's mean `component`.
    #[serde(default)]
    pub plus: Vec<ControlTermSection>,
}

/// One of `[loading.control] plus`: `weight` times the mean of `component` over `set`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlTermSection {
    /// Node set.
    pub set: String,
    /// `ux`, `uy` or `w`.
    pub component: ComponentChoice,
    /// Weight (finite).
    pub weight: f64,
}

impl ControlSection {
    /// The solver's path control.
    pub fn path_control(&self) -> cosdem_fem::solve::PathControl {
        cosdem_fem::solve::PathControl {
            set: self.set.clone(),
            component: self.component.into(),
            value: self.value,
            plus: self
                .plus
                .iter()
                .map(|t| cosdem_fem::solve::ControlTerm {
                    set: t.set.clone(),
                    component: t.component.into(),
                    weight: t.weight,
                })
                .collect(),
        }
    }
}

/// How an edge load follows the loading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RampChoice {
    /// Full from the first step (a confining pressure; default).
    Constant,
    /// Grows with the load factor.
    Linear,
}

/// `[[loading.pressure]]`: a pressure on an edge set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureLoad {
    /// Edge set.
    pub set: String,
    /// Pressure (Pa, positive pushes into the body).
    pub value: f64,
    /// `constant` (default) or `linear`.
    #[serde(default = "default_ramp")]
    pub ramp: RampChoice,
}

fn default_ramp() -> RampChoice {
    RampChoice::Constant
}

/// `[loading]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingSection {
    /// Number of equal load steps (default 10); ignored when `increment` is given.
    #[serde(default = "default_steps")]
    pub steps: usize,
    /// Displacement increment per step (m) of the compression, instead of `steps`.
    pub increment: Option<f64>,
    /// Platen compression (the paper's scenes).
    pub compression: Option<Compression>,
    /// Further prescribed dofs.
    #[serde(default)]
    pub prescribed: Vec<Prescribed>,
    /// Pressures on edge sets.
    #[serde(default)]
    pub pressure: Vec<PressureLoad>,
    /// Node set whose reaction is "the load" of the curve (default `top`).
    #[serde(default = "default_load_set")]
    pub load_set: String,
    /// Path control: the steps advance a set's mean displacement, the load factor follows.
    pub control: Option<ControlSection>,
}

fn default_steps() -> usize {
    10
}
fn default_load_set() -> String {
    "top".into()
}

impl Default for LoadingSection {
    fn default() -> Self {
        Self {
            steps: default_steps(),
            increment: None,
            compression: None,
            prescribed: Vec::new(),
            pressure: Vec::new(),
            load_set: default_load_set(),
            control: None,
        }
    }
}

/// `[material]`: what answers at the Gauss points.
///
/// Read through `material::RawMaterial` (a plain struct with the tag `kind` as a
/// field) rather than as an internally tagged enum: serde reads a tagged enum's table into a
/// buffer first, which loses the TOML positions, so an error anywhere in
/// `[material.assembly]` would point at the `[material]` line instead of the key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields,
    try_from = "crate::material::RawMaterial"
)]
pub enum MaterialSection {
    /// Linear-elastic Cosserat (THEORY.md Eq. 8): cheap, for checks and calibration.
    Elastic {
        /// Shear modulus G (Pa).
        shear_modulus: f64,
        /// Poisson's ratio, in (-1, 0.5).
        poisson: f64,
        /// Cosserat shear modulus Gc (Pa); default G / 2.
        cosserat_modulus: Option<f64>,
        /// Internal length lc (m); default 0.01.
        length: Option<f64>,
    },
    /// A DEM disc assembly at every Gauss point (the paper's two-scale model). The table
    /// `[material.assembly]` is the worker's assembly spec: packing, contact law, density,
    /// micro boundary, relaxation and tangent (see `docs/reference/job-file.md`).
    Dem {
        /// The assembly spec, identical at every Gauss point.
        assembly: Box<cosdem_dem::AssemblySpec>,
    },
}

/// `[newton]`: Newton-Raphson and step control. Defaults are [`SolverSettings::default`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSection {
    /// Iterations per attempt before the step is cut.
    pub max_iterations: u32,
    /// Relative force residual that ends the iteration.
    pub force_tolerance: f64,
    /// Relative displacement increment that ends the iteration.
    pub displacement_tolerance: f64,
    /// Backtracking line search when the residual grows.
    pub line_search: bool,
    /// Smallest step as a fraction of the nominal one.
    pub min_increment_fraction: f64,
    /// Relative force residual at which a step that ran out of iterations is accepted as
    /// "tolerated" instead of cut (0 = never; see `SolverSettings::tolerated_residual`).
    pub tolerated_residual: f64,
    /// Gauss-point secant updates of the iteration matrix within a step (see
    /// `SolverSettings::secant_updates`).
    pub secant_updates: bool,
    /// Iterations without a new smallest residual after which an attempt whose best is
    /// already within `tolerated_residual` is accepted there (0 = off; see
    /// `SolverSettings::stall_iterations`).
    pub stall_iterations: u32,
    /// Relative force residual up to which the attempt at the smallest increment accepts its
    /// best iterate instead of ending the run, as a "forced" step (0 = never; see
    /// `SolverSettings::forced_residual`).
    pub forced_residual: f64,
}

impl Default for NewtonSection {
    fn default() -> Self {
        let s = SolverSettings::default();
        Self {
            max_iterations: s.max_iterations,
            force_tolerance: s.force_tolerance,
            displacement_tolerance: s.displacement_tolerance,
            line_search: s.line_search,
            min_increment_fraction: s.min_increment_fraction,
            tolerated_residual: s.tolerated_residual,
            secant_updates: s.secant_updates,
            stall_iterations: s.stall_iterations,
            forced_residual: s.forced_residual,
        }
    }
}

/// `[output]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSection {
    /// Run directory; the CLI's `--out` wins; default `runs/<job file stem>`.
    pub dir: Option<PathBuf>,
    /// Write the VTK fields every this many steps (0: never).
    pub vtk_every: usize,
    /// Gauss points `[element, point]` whose particle snapshots are written.
    #[serde(deserialize_with = "crate::arrays::snapshots")]
    pub snapshots: Vec<[u32; 2]>,
    /// Displacements (m) at which the equivalent-strain field is plotted.
    pub field_plots_at: Vec<f64>,
    /// Write `checkpoint.bin` every this many steps (0: only when stopped by Ctrl-C).
    pub checkpoint_every: usize,
    /// Upper end (m) of the linear range the stiffness E is fitted over
    /// ([`cosdem_fem::post::CurveMetrics`]); the paper's 0.01 m.
    pub linear_range: f64,
    /// `[output.curve]`: the curve's control displacement, load and extra reaction columns;
    /// absent: the platen compression's curve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curve: Option<crate::curve::CurveSection>,
    /// Encoding of the `.vtu` files: `ascii` (default) or `binary` (zlib-compressed base64).
    pub vtk_format: VtkFormat,
    /// Formats (`yade`, `lammps`, `vtu`) in which each particle snapshot of `snapshots` is also
    /// written as a packing file beside it, `packing_NNNNN.{txt,data,vtu}`; empty: none.
    #[serde(deserialize_with = "packing_formats", skip_serializing_if = "Vec::is_empty")]
    pub packing_formats: Vec<cosdem_dem::packing::formats::OutputFormat>,
}

/// `output.packing_formats`: a list of format names, each known and named once; an error
/// names the key and the value.
fn packing_formats<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Vec<cosdem_dem::packing::formats::OutputFormat>, D::Error> {
    use serde::de::Error;
    let names = Vec::<String>::deserialize(d)?;
    let mut formats = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let f = name
            .parse()
            .map_err(|e: String| D::Error::custom(format!("`output.packing_formats[{i}]`: {e}")))?;
        if formats.contains(&f) {
            return Err(D::Error::custom(format!(
                "`output.packing_formats[{i}]`: {name:?} is named twice"
            )));
        }
        formats.push(f);
    }
    Ok(formats)
}

/// `[output] vtk_format`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VtkFormat {
    /// Readable text (the default).
    #[default]
    Ascii,
    /// Inline base64 of zlib-compressed little-endian data (`vtkZLibDataCompressor`).
    Binary,
}

/// The paper's linear range for the stiffness E: displacements up to 0.01 m.
pub const PAPER_LINEAR_RANGE: f64 = 0.01;

impl Default for OutputSection {
    fn default() -> Self {
        Self {
            dir: None,
            vtk_every: 1,
            snapshots: Vec::new(),
            field_plots_at: Vec::new(),
            checkpoint_every: 1,
            linear_range: PAPER_LINEAR_RANGE,
            curve: None,
            vtk_format: VtkFormat::Ascii,
            packing_formats: Vec::new(),
        }
    }
}

/// `[workers]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WorkersSection {
    /// Remote workers `host:port` or `dns:NAME:PORT`; empty: in-process workers.
    pub addresses: Vec<String>,
    /// Number of in-process workers (0: one per core).
    pub in_process: usize,
}
