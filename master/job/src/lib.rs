//! The job file: one TOML document that says what to run.
//!
//! Every table and key is listed in `docs/reference/job-file.md` with its default and unit.
//! Unknown keys are errors (serde's `deny_unknown_fields`, with the line and column), and so
//! are out-of-range values: [`Job::validate`] names the key and the value. The job is turned
//! into the solver's own types by [`Job::model`] and [`Job::solver_settings`]; nothing below
//! this module knows about TOML.

use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::error::{Error, Result};
use cosdem_fem::gmsh;
use cosdem_fem::material::ElasticCosserat;
use cosdem_fem::mesh::{MAX_ELEMENTS, Mesh, MeshDescription};
use cosdem_fem::solve::{
    Dirichlet, EdgeLoad, EdgeLoadKind, Loading, MAX_LOAD_STEPS, MIN_INCREMENT_FRACTION, Platens,
    Ramp, SolverSettings,
};
use cosdem_fem::symmetry::Symmetry;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A whole job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Job {
    /// Free text shown in the summary.
    #[serde(default)]
    pub title: String,
    /// Accuracy target (fraction in (0, 1), e.g. 0.05 for 5 %): when given, the speed knobs
    /// of `[material.assembly]` and the load step are chosen by [`cosdem_tune::accuracy`] from the
    /// measured speed/accuracy trade before the run. Absent (the default): the job runs as
    /// written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<f64>,
    /// The macro mesh.
    pub mesh: MeshSection,
    /// Boundary conditions, loads and load steps.
    #[serde(default)]
    pub loading: LoadingSection,
    /// The material at the Gauss points.
    pub material: MaterialSection,
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
    /// A Gmsh `.msh` file (2.2 or 4.1) of 8- or 9-node quadrilaterals.
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
}

/// Gauss rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// 2x2 points per element (the paper's; one DEM assembly per point).
    Reduced,
    /// 3x3 points per element.
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
    #[serde(default)]
    pub origin: [f64; 2],
    /// `q8` (default) or `q9`, rectangle only (a Gmsh file says its own).
    #[serde(default = "default_element")]
    pub element: ElementChoice,
    /// `reduced` (2x2, default) or `full` (3x3).
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

impl From<ComponentChoice> for Component {
    fn from(c: ComponentChoice) -> Self {
        match c {
            ComponentChoice::Ux => Component::Ux,
            ComponentChoice::Uy => Component::Uy,
            ComponentChoice::W => Component::W,
        }
    }
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
        }
    }
}

/// `[material]`: what answers at the Gauss points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
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
    pub snapshots: Vec<[u32; 2]>,
    /// Displacements (m) at which the equivalent-strain field is plotted.
    pub field_plots_at: Vec<f64>,
    /// Write `checkpoint.bin` every this many steps (0: only when stopped by Ctrl-C).
    pub checkpoint_every: usize,
    /// Upper end (m) of the linear range the stiffness E is fitted over
    /// ([`cosdem_fem::post::CurveMetrics`]); the paper's 0.01 m.
    pub linear_range: f64,
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

fn bad(field: &'static str, value: impl ToString, reason: &str) -> Error {
    Error::InvalidSetting { field, value: value.to_string(), reason: reason.into() }
}

fn positive(field: &'static str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(bad(field, v, "must be finite and > 0")) }
}

impl Job {
    /// Parses a job from TOML text; `origin` names the file in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        let job: Job = toml::from_str(text)
            .map_err(|e| Error::JobFile { file: origin.to_string(), message: e.to_string() })?;
        job.validate()?;
        Ok(job)
    }

    /// Reads and validates a job file; relative paths inside it are resolved against it.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::JobFile {
            file: path.display().to_string(),
            message: e.to_string(),
        })?;
        let mut job = Self::from_toml(&text, &path.display().to_string())?;
        if let Some(file) = &job.mesh.file
            && file.is_relative()
        {
            let base = path.parent().unwrap_or(Path::new("."));
            job.mesh.file = Some(base.join(file));
        }
        Ok(job)
    }

    /// Checks every value that serde cannot: ranges and combinations.
    pub fn validate(&self) -> Result<()> {
        let m = &self.mesh;
        match m.kind {
            MeshKind::Rectangle => {
                positive("mesh.lx", m.lx.ok_or_else(|| bad("mesh.lx", "missing", "required"))?)?;
                positive("mesh.ly", m.ly.ok_or_else(|| bad("mesh.ly", "missing", "required"))?)?;
                for (name, n) in [("mesh.nx", m.nx), ("mesh.ny", m.ny)] {
                    match n {
                        Some(n) if (1..=MAX_ELEMENTS).contains(&n) => {}
                        Some(n) => return Err(bad(name, n, "must be in [1, 1 000 000]")),
                        None => return Err(bad(name, "missing", "required for a rectangle")),
                    }
                }
                let (nx, ny) = (m.nx.unwrap_or(1), m.ny.unwrap_or(1));
                if nx.saturating_mul(ny) > MAX_ELEMENTS {
                    return Err(bad(
                        "mesh.nx",
                        format!("{nx} (with mesh.ny = {ny})"),
                        "nx * ny must be at most MAX_ELEMENTS = 1 000 000 elements",
                    ));
                }
                for v in m.origin {
                    if !v.is_finite() {
                        return Err(bad("mesh.origin", v, "must be finite"));
                    }
                }
                if m.file.is_some() {
                    return Err(bad("mesh.file", "given", "only for kind = \"gmsh\""));
                }
                let even = |name: &'static str, n: Option<usize>| match n {
                    Some(n) if n % 2 == 1 => {
                        Err(bad(name, n, "must be even to cut the mesh on its mid-line"))
                    }
                    _ => Ok(()),
                };
                if m.symmetry != Symmetry::None {
                    even("mesh.nx", m.nx)?;
                }
                if m.symmetry == Symmetry::Quarter {
                    even("mesh.ny", m.ny)?;
                    let both = self.loading.compression.as_ref().map(|c| c.moving);
                    if both != Some(Moving::Both) {
                        return Err(bad(
                            "mesh.symmetry",
                            "quarter",
                            "needs [loading.compression] with moving = \"both\" (symmetric about the horizontal mid-line)",
                        ));
                    }
                }
            }
            MeshKind::Gmsh => {
                if m.symmetry != Symmetry::None {
                    return Err(bad("mesh.symmetry", "given", "only for kind = \"rectangle\""));
                }
                if m.file.is_none() {
                    return Err(bad("mesh.file", "missing", "required for kind = \"gmsh\""));
                }
            }
        }
        let l = &self.loading;
        if l.steps == 0 || l.steps > MAX_LOAD_STEPS {
            return Err(bad("loading.steps", l.steps, "must be in [1, 1 000 000]"));
        }
        if let Some(c) = &l.compression {
            positive("loading.compression.displacement", c.displacement)?;
        }
        if let Some(inc) = l.increment {
            positive("loading.increment", inc)?;
            let Some(c) = &l.compression else {
                return Err(bad("loading.increment", inc, "needs [loading.compression]"));
            };
            if c.displacement / inc > MAX_LOAD_STEPS as f64 {
                return Err(bad(
                    "loading.increment",
                    inc,
                    "too small: more than 1 000 000 load steps for the compression displacement",
                ));
            }
        }
        for p in &l.prescribed {
            if !p.value.is_finite() {
                return Err(bad("loading.prescribed.value", p.value, "must be finite"));
            }
        }
        for p in &l.pressure {
            if !p.value.is_finite() {
                return Err(bad("loading.pressure.value", p.value, "must be finite"));
            }
        }
        match &self.material {
            MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
                positive("material.shear_modulus", *shear_modulus)?;
                if !(*poisson > -1.0 && *poisson < 0.5) {
                    return Err(bad("material.poisson", poisson, "must be in (-1, 0.5)"));
                }
                if let Some(gc) = cosserat_modulus
                    && !(gc.is_finite() && *gc >= 0.0)
                {
                    return Err(bad("material.cosserat_modulus", gc, "must be finite and >= 0"));
                }
                if let Some(lc) = length
                    && !(lc.is_finite() && *lc >= 0.0)
                {
                    return Err(bad("material.length", lc, "must be finite and >= 0"));
                }
                // Each value may be finite and the moduli they make still overflow.
                let m = self.elastic().expect("elastic material");
                let d = m.tangent();
                if !d[..4].iter().flatten().all(|v| v.is_finite()) {
                    return Err(bad(
                        "material.shear_modulus",
                        shear_modulus,
                        "with this Poisson's ratio and Cosserat modulus the elastic moduli overflow",
                    ));
                }
                if !d[4][4].is_finite() {
                    return Err(bad(
                        "material.length",
                        m.length,
                        "the bending modulus 2 G lc^2 overflows",
                    ));
                }
            }
            MaterialSection::Dem { assembly } => assembly.validate().map_err(|e| {
                Error::JobFile { file: "[material.assembly]".into(), message: e.to_string() }
            })?,
        }
        let n = &self.newton;
        if n.max_iterations == 0 {
            return Err(bad("newton.max_iterations", 0, "must be >= 1"));
        }
        for (name, v) in [
            ("newton.force_tolerance", n.force_tolerance),
            ("newton.displacement_tolerance", n.displacement_tolerance),
            ("newton.tolerated_residual", n.tolerated_residual),
            ("newton.forced_residual", n.forced_residual),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, v, "must be finite and >= 0"));
            }
        }
        if !(n.min_increment_fraction >= MIN_INCREMENT_FRACTION && n.min_increment_fraction <= 1.0)
        {
            return Err(bad(
                "newton.min_increment_fraction",
                n.min_increment_fraction,
                "in [1e-12, 1]",
            ));
        }
        if let Some(a) = self.accuracy {
            if !(a > 0.0 && a < 1.0) {
                return Err(bad("accuracy", a, "must be a fraction in (0, 1), e.g. 0.05 for 5 %"));
            }
            if matches!(self.material, MaterialSection::Elastic { .. }) {
                return Err(bad(
                    "accuracy",
                    a,
                    "needs [material] kind = \"dem\": the measured trade is of DEM settings",
                ));
            }
        }
        positive("output.linear_range", self.output.linear_range)?;
        for &d in &self.output.field_plots_at {
            if !(d.is_finite() && d >= 0.0) {
                return Err(bad("output.field_plots_at", d, "must be finite and >= 0 (m)"));
            }
        }
        Ok(())
    }

    /// The linear-elastic Cosserat material of an `elastic` job (its defaults filled in:
    /// Gc = G / 2, lc = 0.01 m); `None` for a DEM job.
    pub fn elastic(&self) -> Option<ElasticCosserat> {
        match &self.material {
            MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
                let g = *shear_modulus;
                Some(ElasticCosserat::new(
                    g,
                    *poisson,
                    cosserat_modulus.unwrap_or(0.5 * g),
                    length.unwrap_or(0.01),
                ))
            }
            MaterialSection::Dem { .. } => None,
        }
    }

    /// The continuum field.
    pub fn field(&self) -> Field {
        match self.mesh.continuum {
            Continuum::Cosserat => Field::Cosserat,
            Continuum::Cauchy => Field::Cauchy,
        }
    }

    /// Builds the mesh (reads the Gmsh file if any).
    pub fn build_mesh(&self) -> Result<Mesh> {
        let m = &self.mesh;
        match m.kind {
            MeshKind::Rectangle => {
                let kind = match m.element {
                    ElementChoice::Q8 => ElementKind::Q8,
                    ElementChoice::Q9 => ElementKind::Q9,
                };
                // validate() made sure these are present.
                let (lx, ly, nx, ny) = m.symmetry.reduce_rectangle(
                    m.lx.unwrap_or(1.0),
                    m.ly.unwrap_or(1.0),
                    m.nx.unwrap_or(1),
                    m.ny.unwrap_or(1),
                );
                Mesh::rectangle(kind, lx, ly, nx, ny, m.origin)
            }
            MeshKind::Gmsh => {
                let file = m.file.as_deref().unwrap_or(Path::new(""));
                let raw = gmsh::read_msh(file).map_err(|e| Error::JobFile {
                    file: file.display().to_string(),
                    message: e.to_string(),
                })?;
                Mesh::from_description(MeshDescription::from(raw))
            }
        }
    }

    /// The loading of the job: compression platens, prescribed dofs and pressures.
    pub fn loading(&self) -> Loading {
        let l = &self.loading;
        let mut loading = match &l.compression {
            Some(c) => {
                let platens = match c.platens {
                    PlatenChoice::Rough => Platens::Rough,
                    PlatenChoice::Smooth => Platens::Smooth,
                };
                let (top, bottom) = match c.moving {
                    Moving::Both => (-0.5 * c.displacement, 0.5 * c.displacement),
                    Moving::Top => (-c.displacement, 0.0),
                };
                Loading::compression(top, bottom, platens)
            }
            None => Loading::default(),
        };
        for p in &l.prescribed {
            loading.dirichlet.push(Dirichlet::new(&p.set, p.component.into(), p.value));
        }
        for p in &l.pressure {
            let ramp = match p.ramp {
                RampChoice::Constant => Ramp::Constant,
                RampChoice::Linear => Ramp::Linear,
            };
            loading.edge_loads.push(EdgeLoad {
                set: p.set.clone(),
                kind: EdgeLoadKind::Pressure(p.value),
                ramp,
            });
        }
        self.mesh.symmetry.reduce_loading(loading, self.field())
    }

    /// Factor from the meshed part's reaction to the whole panel's load (2 on a half or
    /// quarter mesh).
    pub fn load_scale(&self) -> f64 {
        self.mesh.symmetry.load_scale()
    }

    /// Total shortening of the compression (m), 0 without one: the curve's abscissa is
    /// `load_factor * shortening`.
    pub fn shortening(&self) -> f64 {
        self.loading.compression.as_ref().map_or(0.0, |c| c.displacement)
    }

    /// The Gauss rule.
    pub fn rule(&self) -> QuadratureRule {
        match self.mesh.integration {
            Integration::Reduced => QuadratureRule::Gauss2x2,
            Integration::Full => QuadratureRule::Gauss3x3,
        }
    }

    /// The FE model: mesh, field, rule, loading.
    pub fn model(&self) -> Result<cosdem_fem::solve::Model> {
        Ok(cosdem_fem::solve::Model {
            mesh: self.build_mesh()?,
            field: self.field(),
            rule: self.rule(),
            loading: self.loading(),
        })
    }

    /// Newton and step settings.
    pub fn solver_settings(&self) -> Result<SolverSettings> {
        let l = &self.loading;
        let steps = match (l.increment, &l.compression) {
            (Some(inc), Some(c)) => SolverSettings::steps_for_increment(c.displacement, inc)?,
            _ => l.steps,
        };
        let n = &self.newton;
        Ok(SolverSettings {
            steps,
            max_iterations: n.max_iterations,
            force_tolerance: n.force_tolerance,
            displacement_tolerance: n.displacement_tolerance,
            line_search: n.line_search,
            min_increment_fraction: n.min_increment_fraction,
            tolerated_residual: n.tolerated_residual,
            secant_updates: n.secant_updates,
            stall_iterations: n.stall_iterations,
            forced_residual: n.forced_residual,
            ..SolverSettings::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = r#"
        [mesh]
        kind = "rectangle"
        lx = 1.0
        ly = 1.0
        nx = 2
        ny = 2
        [loading]
        steps = 4
        [loading.compression]
        displacement = 0.01
        [material]
        kind = "elastic"
        shear_modulus = 1e7
        poisson = 0.3
    "#;

    #[test]
    fn minimal_job_takes_the_documented_defaults() {
        let job = Job::from_toml(MINIMAL, "minimal").unwrap();
        assert_eq!(job.mesh.element, ElementChoice::Q8);
        assert_eq!(job.mesh.integration, Integration::Reduced);
        assert_eq!(job.mesh.continuum, Continuum::Cosserat);
        assert_eq!(job.output.vtk_every, 1);
        assert_eq!(job.loading.load_set, "top");
        let model = job.model().unwrap();
        assert_eq!(model.mesh.n_elements(), 4);
        assert_eq!(job.solver_settings().unwrap().steps, 4);
    }

    #[test]
    fn unknown_keys_are_errors_naming_the_key() {
        let text = MINIMAL.replace("nx = 2", "nx = 2\nnz = 3");
        let err = Job::from_toml(&text, "job.toml").unwrap_err().to_string();
        assert!(err.contains("nz") && err.contains("job.toml"), "{err}");
    }

    #[test]
    fn out_of_range_values_name_key_and_value() {
        let text = MINIMAL.replace("poisson = 0.3", "poisson = 0.7");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("material.poisson") && err.contains("0.7"), "{err}");
        let text = MINIMAL.replace("displacement = 0.01", "displacement = -0.01");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("loading.compression.displacement") && err.contains("-0.01"), "{err}");
        let text = MINIMAL.replace("nx = 2", "nx = 0");
        let err = Job::from_toml(&text, "j").unwrap_err().to_string();
        assert!(err.contains("mesh.nx"), "{err}");
    }

    /// `accuracy` is optional, a fraction in (0, 1), and only for DEM jobs; errors name the
    /// key and the value.
    #[test]
    fn accuracy_key_is_validated() {
        assert_eq!(Job::from_toml(MINIMAL, "j").unwrap().accuracy, None);
        let quick = include_str!("../../../examples/quick.toml");
        let with = |a: &str| format!("accuracy = {a}\n{quick}");
        assert_eq!(Job::from_toml(&with("0.05"), "j").unwrap().accuracy, Some(0.05));
        for bad in ["0.0", "1.0", "-0.1", "5", "nan"] {
            let err = Job::from_toml(&with(bad), "j").unwrap_err().to_string();
            assert!(err.contains("accuracy") && err.contains("(0, 1)"), "{bad}: {err}");
        }
        let err = Job::from_toml(&format!("accuracy = 0.05\n{MINIMAL}"), "j").unwrap_err();
        assert!(err.to_string().contains("accuracy") && err.to_string().contains("dem"), "{err}");
    }

    /// E's linear range is the paper's 0.01 m unless the job sets its own (the run writer reads it,
    /// `cosdem_app::run::run_settings`); a range that is not a positive length is refused naming the key.
    #[test]
    fn linear_range_defaults_to_the_papers_and_is_validated() {
        let job = Job::from_toml(MINIMAL, "j").unwrap();
        assert_eq!(job.output.linear_range, PAPER_LINEAR_RANGE);
        assert_eq!(job.output.linear_range, 0.01);
        let with = |v: &str| format!("{MINIMAL}\n[output]\nlinear_range = {v}\n");
        let job = Job::from_toml(&with("1e-3"), "j").unwrap();
        assert_eq!(job.output.linear_range, 1e-3);
        for bad in ["0.0", "-1e-3", "nan", "inf"] {
            let err = Job::from_toml(&with(bad), "j").unwrap_err().to_string();
            assert!(err.contains("output.linear_range"), "{bad}: {err}");
        }
    }

    #[test]
    fn increment_gives_the_number_of_steps() {
        let text = MINIMAL.replace("steps = 4", "increment = 0.001");
        let job = Job::from_toml(&text, "j").unwrap();
        assert_eq!(job.solver_settings().unwrap().steps, 10);
    }

    #[test]
    fn symmetric_compression_moves_both_platens_by_half() {
        let job = Job::from_toml(MINIMAL, "j").unwrap();
        let l = job.loading();
        let top = l.dirichlet.iter().find(|d| d.set == "top" && d.component == Component::Uy);
        let bottom = l.dirichlet.iter().find(|d| d.set == "bottom" && d.component == Component::Uy);
        assert_eq!(top.unwrap().value, -0.005);
        assert_eq!(bottom.unwrap().value, 0.005);
    }
}
