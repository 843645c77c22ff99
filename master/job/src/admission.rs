//! Admission control: what a job will hold in memory and write to disk, estimated from the job
//! alone before anything is allocated, so that a job too large for the machine is refused
//! naming the keys that make it large instead of allocating until the allocator aborts.
//!
//! [`estimate`] is a pure function of the job and its mesh's size ([`MeshCounts`]: from the
//! job for a rectangle, from the mesh for a Gmsh file). The figures per disc, per contact, per
//! element and per saved file were measured once from the real structures:
//! `tests/admission_measure.rs` builds assemblies and panels under a counting allocator (run
//! it with `--nocapture` to see the figures; it fails when a constant below no longer bounds
//! what it measures), and the per-file figures are the sizes of the files of a run directory of
//! `examples/elastic.toml` at 2 x 2 and 8 x 8 elements and of `examples/quick.toml`.
//!
//! The in-process share is what the master's own process holds: always the mesh, the linear
//! system, the outputs and the master's copies of the committed DEM states (failover and
//! checkpoints); with in-process workers also the DEM assemblies themselves and the states
//! they encode when exporting.

use crate::schema::{ElementChoice, Integration, Job, MaterialSection, MeshKind};
use cosdem_dem::PackingSpec;
use cosdem_fem::element::{ElementKind, Quadrature, QuadratureRule};
use cosdem_fem::mesh::Mesh;
use std::fmt::Write;

/// Heap bytes per disc of a live assembly, contacts aside: reference data (6 numbers),
/// committed and trial states (6 numbers and 2 build positions each) and work arrays.
/// Measured: 348-359 bytes per disc with 2.6-2.9 pairs per disc, of which the pairs take
/// about 160.
pub const BYTES_PER_DISC: f64 = 200.0;

/// Heap bytes per contact pair of a live assembly: two indices, the tangential and rolling
/// histories (and periodic offsets), in the committed and the trial state, with the lists'
/// spare capacity.
pub const BYTES_PER_CONTACT: f64 = 56.0;

/// Contact pairs per disc counted: measured 2.9 in a hexagonal packing, 2.6 in a random one
/// at its confining stress.
pub const CONTACTS_PER_DISC: f64 = 3.0;

/// Bytes per disc of an encoded assembly state (what a worker exports and the master keeps
/// for failover and checkpoints): measured 282-294.
pub const STATE_BYTES_PER_DISC: f64 = 300.0;

/// Heap bytes per disc that building a random packing holds on top of the live assembly
/// while it runs (measured: a build peaks at 940-945 bytes per disc against 350 live); a
/// hexagonal build peaks below the live assembly.
pub const RANDOM_BUILD_BYTES_PER_DISC: f64 = 600.0;

/// The share of the machine's memory a job may take by default ([`default_memory_limit`]):
/// the rest is the system's, the page cache's and the allocator's. Measured against the
/// estimate: a run of 16 assemblies of 4 288 discs peaked at 1 330 bytes per disc (maximum
/// resident set), which the estimate puts at 1 570.
pub const DEFAULT_MEMORY_FRACTION: f64 = 0.8;

/// Copies of every committed state the master holds at once: the stored state of the
/// failover history, the export arriving from a worker, and the checkpoint being encoded.
pub const MASTER_STATE_COPIES: f64 = 3.0;

/// Peak heap bytes per element of the finite-element side (mesh, Gauss-point data, sparse
/// matrix and its factorization), a Q8 Cosserat element with 2 x 2 points:
/// `FE_BYTES_PER_ELEMENT + FE_BYTES_PER_ELEMENT_LOG2 * log2(elements)` (the factorization's
/// fill grows like n log n). Measured: 26.9 kB per element at 16 elements, 29.9 k at 64,
/// 36.2 k at 4 096, 41.7 k at 16 384.
pub const FE_BYTES_PER_ELEMENT: f64 = 21_000.0;

/// See [`FE_BYTES_PER_ELEMENT`].
pub const FE_BYTES_PER_ELEMENT_LOG2: f64 = 1_600.0;

/// A fixed workspace of the linear solver: peaks of 100 to 210 MB were measured once at 256
/// and 1 024 elements (the parallel factorization's scratch), none at 64 or 4 096.
pub const FE_WORKSPACE_BYTES: f64 = 256.0 * MIB;

/// Bytes of one saved step's two VTK files beyond the per-node and per-point figures.
pub const VTK_BYTES_FIXED: f64 = 2_500.0;
/// Bytes per node of `vtk/mesh_NNNNN.vtu` (measured 127).
pub const VTK_BYTES_PER_NODE: f64 = 130.0;
/// Bytes per Gauss point of `vtk/gauss_NNNNN.vtu` (measured 407).
pub const VTK_BYTES_PER_POINT: f64 = 410.0;
/// Bytes per disc of one particle snapshot file (measured 400-490, contacts included).
pub const SNAPSHOT_BYTES_PER_DISC: f64 = 500.0;
/// Bytes of the figures and field data written at one `field_plots_at` displacement, per
/// snapshot point on top of the field's own (PNG files of 80-290 kB).
pub const FIELD_PLOT_BYTES: f64 = 100_000.0;
/// See [`FIELD_PLOT_BYTES`]: the force-chain and fluctuation plots of one snapshot point.
pub const FIELD_PLOT_BYTES_PER_SNAPSHOT: f64 = 600_000.0;
/// Bytes of one `curve.csv` row.
pub const CURVE_BYTES_PER_STEP: f64 = 60.0;

/// A disk use above this many bytes draws a warning ([`Estimate::disk_warning`]).
pub const DISK_WARNING_BYTES: f64 = 10.0 * GIB;
/// A file count above this draws a warning ([`Estimate::disk_warning`]).
pub const DISK_WARNING_FILES: f64 = 100_000.0;

const MIB: f64 = (1u64 << 20) as f64;
const GIB: f64 = (1u64 << 30) as f64;

/// The element kinds [`MeshCounts::by_kind`] counts, in its order.
pub const KINDS: [ElementKind; 3] = [ElementKind::Q8, ElementKind::Q9, ElementKind::T6];

/// The size of the mesh: what the estimate needs of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshCounts {
    /// Nodes.
    pub nodes: f64,
    /// Elements of each of [`KINDS`]: the kind sets the element's nodes and Gauss points
    /// ([`MeshCounts::gauss_points`]).
    pub by_kind: [f64; 3],
}

impl MeshCounts {
    /// The counts of a rectangle job (after its symmetry's cut), from its keys alone; `None`
    /// for a Gmsh job (build the mesh and use [`MeshCounts::of_mesh`]).
    pub fn of_job(job: &Job) -> Option<Self> {
        let m = &job.mesh;
        if m.kind != MeshKind::Rectangle {
            return None;
        }
        let (nx, ny) = (m.nx.unwrap_or(1), m.ny.unwrap_or(1));
        let (_, _, nx, ny) = m.symmetry.reduce_rectangle(1.0, 1.0, nx, ny);
        let (nx, ny) = (nx as f64, ny as f64);
        let grid = (2.0 * nx + 1.0) * (2.0 * ny + 1.0);
        // Q8 lacks the cells' centres; Q9 has every node of the (2 nx + 1) x (2 ny + 1) grid;
        // T6 too (a cell's diagonal has its mid-side at the centre), in two triangles a cell.
        let (elements, nodes, kind) = match m.element {
            ElementChoice::Q8 => (nx * ny, grid - nx * ny, ElementKind::Q8),
            ElementChoice::Q9 => (nx * ny, grid, ElementKind::Q9),
            ElementChoice::T6 => (2.0 * nx * ny, grid, ElementKind::T6),
        };
        Some(Self { nodes, by_kind: KINDS.map(|k| if k == kind { elements } else { 0.0 }) })
    }

    /// The counts of a built mesh.
    pub fn of_mesh(mesh: &Mesh) -> Self {
        let by_kind = KINDS.map(|k| mesh.kinds.iter().filter(|&&e| e == k).count() as f64);
        Self { nodes: mesh.n_nodes() as f64, by_kind }
    }

    /// Elements, of every kind.
    pub fn elements(&self) -> f64 {
        self.by_kind.iter().sum()
    }

    /// Gauss points under `integration`: each element has those of the rule the solver gives
    /// its kind ([`QuadratureRule::for_kind`]), 4 (`reduced`, 2 x 2) or 9 (`full`, 3 x 3) per
    /// quadrilateral, 3 or 6 per triangle.
    pub fn gauss_points(&self, integration: Integration) -> f64 {
        self.sum(|k| points_of(k, integration))
    }

    /// `sum over elements of f(kind)`.
    fn sum(&self, f: impl Fn(ElementKind) -> f64) -> f64 {
        KINDS.iter().zip(&self.by_kind).filter(|(_, n)| **n > 0.0).map(|(&k, n)| n * f(k)).sum()
    }
}

/// Gauss points of an element of `kind` under `integration`.
fn points_of(kind: ElementKind, integration: Integration) -> f64 {
    let rule = QuadratureRule::for_kind(kind, integration == Integration::Full);
    Quadrature::new(rule).len() as f64
}

/// One part of the memory estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// What it is (`DEM assemblies`, `mesh and linear system`, ...).
    pub name: &'static str,
    /// Bytes.
    pub bytes: f64,
    /// Held only when the DEM assemblies are solved in this process (in-process workers).
    pub in_process_only: bool,
    /// How the figure comes about (`16 Gauss points x 935 000 discs x 368 B`).
    pub detail: String,
    /// The job-file keys that drive it, with their values (`mesh.nx = 300`).
    pub keys: Vec<String>,
}

/// What a job will hold and write ([`estimate`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The memory parts, largest first.
    pub parts: Vec<Part>,
    /// Gauss points (one DEM assembly each).
    pub gauss_points: f64,
    /// Discs per assembly (0 for an elastic job), from
    /// [`AssemblySpec::disc_count_hint`](cosdem_dem::AssemblySpec::disc_count_hint).
    pub discs_per_assembly: f64,
    /// Nominal load steps.
    pub steps: f64,
    /// Steps whose fields are saved (`steps / vtk_every`; 0 when `vtk_every = 0`).
    pub saved_steps: f64,
    /// Bytes written per saved step (VTK fields and particle snapshots).
    pub disk_per_saved_step: f64,
    /// Files written per saved step.
    pub files_per_saved_step: f64,
    /// Bytes written by the whole run (saved steps, curve, checkpoint, field plots).
    pub disk_total: f64,
    /// Files written by the whole run.
    pub files_total: f64,
    /// The keys that drive the disk use, with their values.
    pub disk_keys: Vec<String>,
}

/// A job refused before it starts.
#[derive(Debug, thiserror::Error)]
pub enum AdmissionError {
    /// The job's in-process share of memory exceeds the limit.
    #[error(
        "the job needs about {} of memory in this process, more than the limit of {}{}: {}",
        size(*needed),
        size(*limit),
        if *in_process { " (DEM assemblies in this process)" } else { "" },
        parts
    )]
    TooLarge {
        /// Bytes the estimate gives.
        needed: f64,
        /// The limit (bytes).
        limit: f64,
        /// Whether the DEM assemblies were counted in this process.
        in_process: bool,
        /// The parts, largest first, with their keys and values.
        parts: String,
    },
}

/// A size for people: `512.0 MiB`, `21.3 GiB`, `1.2e3 TiB`.
pub fn size(bytes: f64) -> String {
    const UNITS: [&str; 5] = ["B", "kiB", "MiB", "GiB", "TiB"];
    let mut v = bytes;
    let mut unit = 0;
    while v >= 1024.0 && unit < UNITS.len() - 1 {
        v /= 1024.0;
        unit += 1;
    }
    if v >= 1e4 { format!("{v:.1e} {}", UNITS[unit]) } else { format!("{v:.1} {}", UNITS[unit]) }
}

/// The keys of the mesh's size, with their values.
fn mesh_keys(job: &Job) -> Vec<String> {
    let m = &job.mesh;
    let mut keys = match m.kind {
        MeshKind::Rectangle => vec![
            format!("mesh.nx = {}", m.nx.unwrap_or(1)),
            format!("mesh.ny = {}", m.ny.unwrap_or(1)),
        ],
        MeshKind::Gmsh => vec![format!(
            "mesh.file = {:?}",
            m.file.as_deref().unwrap_or(std::path::Path::new("")).display().to_string()
        )],
    };
    if m.kind == MeshKind::Rectangle {
        match m.element {
            ElementChoice::Q8 => {}
            ElementChoice::Q9 => keys.push("mesh.element = \"q9\"".into()),
            ElementChoice::T6 => keys.push("mesh.element = \"t6\"".into()),
        }
    }
    keys
}

/// The key of the step count, with its value: `loading.steps = 10`, or
/// `loading.increment = 0.002 (10 steps)`.
fn steps_key(job: &Job, steps: f64) -> String {
    match job.loading.increment {
        Some(inc) => format!("loading.increment = {inc:?} ({steps} steps)"),
        None => format!("loading.steps = {steps}"),
    }
}

/// The keys of the disc count, with their values.
fn packing_keys(p: &PackingSpec) -> Vec<String> {
    let k = |name: &str, v: f64| format!("material.assembly.packing.{name} = {v:?}");
    match p {
        PackingSpec::Hexagonal { radius, side, .. } => vec![k("side", *side), k("radius", *radius)],
        PackingSpec::Random { radii, side, .. } if !radii.is_empty() => {
            vec![
                format!("material.assembly.packing.radii = [{} radii]", radii.len()),
                k("side", *side),
            ]
        }
        PackingSpec::Random { r_min, r_max, side, .. } => {
            vec![k("side", *side), k("r_min", *r_min), k("r_max", *r_max)]
        }
        PackingSpec::Explicit { radii, .. } => {
            vec![format!("material.assembly.packing.file = ({} discs)", radii.len())]
        }
        PackingSpec::File { file, .. } => {
            vec![format!("material.assembly.packing.file = {:?}", file.display().to_string())]
        }
    }
}

/// Estimates the memory and disk of `job` on a mesh of `mesh`'s size, before anything is
/// allocated. No file is read; the one input besides the job is the number of cores when
/// `[workers] in_process = 0` (random packings built at once).
pub fn estimate(job: &Job, mesh: MeshCounts) -> Estimate {
    let gauss_points = mesh.gauss_points(job.mesh.integration);
    let mut point_keys = mesh_keys(job);
    if job.mesh.integration == Integration::Full {
        point_keys.push("mesh.integration = \"full\"".into());
    }
    let mut parts = Vec::new();

    // The finite-element side, scaled from the measured Q8 Cosserat element with 2 x 2 points
    // by the square of its dofs (the matrix) and by its points.
    let dofs = match job.mesh.continuum {
        crate::Continuum::Cosserat => 3.0,
        crate::Continuum::Cauchy => 2.0,
    };
    let scale = |k: ElementKind| {
        ((k.nodes() as f64 * dofs) / 24.0).powi(2).max(points_of(k, job.mesh.integration) / 4.0)
    };
    let elements = mesh.elements();
    let per_element = (FE_BYTES_PER_ELEMENT + FE_BYTES_PER_ELEMENT_LOG2 * elements.max(1.0).log2())
        * mesh.sum(scale)
        / elements.max(1.0);
    parts.push(Part {
        name: "mesh and linear system",
        bytes: FE_WORKSPACE_BYTES + elements * per_element,
        in_process_only: false,
        detail: format!(
            "{elements} elements x {} + {} solver workspace",
            size(per_element),
            size(FE_WORKSPACE_BYTES)
        ),
        keys: point_keys.clone(),
    });

    // With regions, a bound: every point takes the largest DEM assembly of the job.
    let largest = job
        .materials()
        .into_iter()
        .filter_map(|m| match m {
            MaterialSection::Dem { assembly } => Some(assembly),
            MaterialSection::Elastic { .. } => None,
        })
        .max_by_key(|a| a.disc_count_hint());
    let discs = largest.map_or(0.0, |a| a.disc_count_hint() as f64);
    if let Some(assembly) = largest {
        let mut keys = point_keys.clone();
        keys.extend(packing_keys(&assembly.packing));
        let all_discs = gauss_points * discs;
        let live = BYTES_PER_DISC + CONTACTS_PER_DISC * BYTES_PER_CONTACT;
        parts.push(Part {
            name: "DEM assemblies",
            bytes: all_discs * live,
            in_process_only: true,
            detail: format!("{gauss_points} Gauss points x {discs:.0} discs x {live} B"),
            keys: keys.clone(),
        });
        if let PackingSpec::Random { .. } = assembly.packing {
            let builds = gauss_points.min(builds_in_flight(job));
            parts.push(Part {
                name: "random packings being built",
                bytes: builds * discs * RANDOM_BUILD_BYTES_PER_DISC,
                in_process_only: true,
                detail: format!(
                    "{builds} builds at once x {discs:.0} discs x {RANDOM_BUILD_BYTES_PER_DISC} B"
                ),
                keys: packing_keys(&assembly.packing),
            });
        }
        parts.push(Part {
            name: "DEM states encoded by the workers for export",
            bytes: all_discs * STATE_BYTES_PER_DISC,
            in_process_only: true,
            detail: format!("{gauss_points} x {discs:.0} discs x {STATE_BYTES_PER_DISC} B"),
            keys: keys.clone(),
        });
        parts.push(Part {
            name: "committed DEM states held by the master",
            bytes: all_discs * STATE_BYTES_PER_DISC * MASTER_STATE_COPIES,
            in_process_only: false,
            detail: format!(
                "{gauss_points} x {discs:.0} discs x {STATE_BYTES_PER_DISC} B x \
                 {MASTER_STATE_COPIES} copies"
            ),
            keys,
        });
    }

    // Outputs held in memory: the curve, one step's VTK text, the snapshots' particles.
    let steps = job.solver_settings().map_or(job.loading.steps as f64, |s| s.steps as f64);
    let snapshots = job.output.snapshots.len() as f64;
    let vtk =
        VTK_BYTES_FIXED + mesh.nodes * VTK_BYTES_PER_NODE + gauss_points * VTK_BYTES_PER_POINT;
    let snapshot_file = 1_000.0 + discs * SNAPSHOT_BYTES_PER_DISC;
    parts.push(Part {
        name: "outputs held in memory",
        bytes: steps * CURVE_BYTES_PER_STEP + 2.0 * vtk + 2.0 * snapshots * snapshot_file,
        in_process_only: false,
        detail: format!("{steps} curve rows, one step's VTK text, {snapshots} snapshots"),
        keys: vec![steps_key(job, steps), format!("output.snapshots = {snapshots} points")],
    });
    parts.sort_by(|a, b| b.bytes.total_cmp(&a.bytes));

    // Disk.
    let every = job.output.vtk_every;
    let saved_steps = if every == 0 { 0.0 } else { (steps / every as f64).floor() };
    let (disk_per_saved_step, files_per_saved_step) =
        if every == 0 { (0.0, 0.0) } else { (vtk + snapshots * snapshot_file, 2.0 + snapshots) };
    let plots = job.output.field_plots_at.len() as f64;
    let checkpoint = if discs > 0.0 {
        gauss_points * discs * STATE_BYTES_PER_DISC
    } else {
        gauss_points * 600.0
    };
    let disk_total = saved_steps * disk_per_saved_step
        + steps * CURVE_BYTES_PER_STEP
        + checkpoint
        + plots * (FIELD_PLOT_BYTES + snapshots * FIELD_PLOT_BYTES_PER_SNAPSHOT);
    let files_total = saved_steps * files_per_saved_step + plots * (2.0 + 2.0 * snapshots) + 10.0;
    let mut disk_keys = vec![steps_key(job, steps), format!("output.vtk_every = {every}")];
    if snapshots > 0.0 {
        disk_keys.push(format!("output.snapshots = {snapshots} points"));
    }
    disk_keys.extend(mesh_keys(job));
    Estimate {
        parts,
        gauss_points,
        discs_per_assembly: discs,
        steps,
        saved_steps,
        disk_per_saved_step,
        files_per_saved_step,
        disk_total,
        files_total,
        disk_keys,
    }
}

impl Estimate {
    /// All parts, in bytes (the in-process share with in-process workers).
    pub fn total(&self) -> f64 {
        self.parts.iter().map(|p| p.bytes).sum()
    }

    /// The bytes this process holds: with `in_process` (in-process workers) every part, else
    /// the master's parts only.
    pub fn in_process_share(&self, in_process: bool) -> f64 {
        self.parts.iter().filter(|p| in_process || !p.in_process_only).map(|p| p.bytes).sum()
    }

    /// Refuses the job when its in-process share exceeds `limit_bytes` (the machine's memory
    /// by default: [`machine_memory`]), naming the parts, their figures and the keys that
    /// drive them with their values.
    pub fn check(&self, limit_bytes: u64, in_process: bool) -> Result<(), AdmissionError> {
        let needed = self.in_process_share(in_process);
        let limit = limit_bytes as f64;
        if needed <= limit {
            return Ok(());
        }
        let mut parts = String::new();
        let mut keys: Vec<&str> = Vec::new();
        for p in self.parts.iter().filter(|p| in_process || !p.in_process_only) {
            if p.bytes < 0.01 * needed {
                continue;
            }
            let sep = if parts.is_empty() { "" } else { "; " };
            let _ = write!(parts, "{sep}{} {} ({})", p.name, size(p.bytes), p.detail);
            for k in &p.keys {
                if !keys.contains(&k.as_str()) {
                    keys.push(k);
                }
            }
        }
        let _ = write!(parts, "; driven by {}", keys.join(", "));
        if in_process && self.discs_per_assembly > 0.0 {
            let remote = self.in_process_share(false);
            let _ = write!(
                parts,
                "; with remote workers ([workers] addresses) this process would hold {}",
                size(remote)
            );
        }
        Err(AdmissionError::TooLarge { needed, limit, in_process, parts })
    }

    /// A warning when the run would write more than [`DISK_WARNING_BYTES`] or
    /// [`DISK_WARNING_FILES`] files (e.g. 10^6 steps at `vtk_every = 1`), with the figures and
    /// the keys; `None` otherwise.
    pub fn disk_warning(&self) -> Option<String> {
        if self.disk_total <= DISK_WARNING_BYTES && self.files_total <= DISK_WARNING_FILES {
            return None;
        }
        Some(format!(
            "the run would write about {} in {:.0} files ({} in {:.0} files per saved step, \
             {:.0} saved steps): {}; raise output.vtk_every or set it to 0 to write fewer",
            size(self.disk_total),
            self.files_total,
            size(self.disk_per_saved_step),
            self.files_per_saved_step,
            self.saved_steps,
            self.disk_keys.join(", ")
        ))
    }
}

/// Assemblies built at once by in-process workers: `[workers] in_process`, or one per core.
fn builds_in_flight(job: &Job) -> f64 {
    match job.workers.in_process {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()) as f64,
        n => n as f64,
    }
}

/// The default memory limit: [`DEFAULT_MEMORY_FRACTION`] of [`machine_memory`].
pub fn default_memory_limit() -> Option<u64> {
    machine_memory().map(|m| (m as f64 * DEFAULT_MEMORY_FRACTION) as u64)
}

/// This machine's memory in bytes (`MemTotal` of `/proc/meminfo`), `None` where that is not
/// known (not Linux, or unreadable).
pub fn machine_memory() -> Option<u64> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    mem_total(&text)
}

/// `MemTotal` of a `/proc/meminfo` text, in bytes.
fn mem_total(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line["MemTotal:".len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests;
