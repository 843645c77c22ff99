//! Checkpoints of a run, resume, and a clean stop on Ctrl-C.
//!
//! `RUN/checkpoint.bin` holds, at a committed step, the solver's evolving state
//! ([`SolverState`]: dofs, load factor, step, next increment, the responses of the converged
//! state, Gauss-point states, reactions) and every assembly's committed state (the bytes the
//! workers export). It is written atomically (temporary file, sync, rename) every
//! `[output] checkpoint_every` steps and when the run is stopped. A run resumed from it
//! (`cosdem run JOB --resume`) goes on bit for bit as the uninterrupted run would have: a
//! solve is deterministic given (committed state, target), and everything else is restored
//! exactly (postcard writes each `f64` as its 8 little-endian bytes).
//!
//! Format `CDEMCKP8`: the 8-byte header `CDEMCKP8`, one postcard [`Checkpoint`] (serde with a
//! specified wire format), and a CRC-32 (IEEE, little-endian) of every byte before it. A
//! damaged file (a flipped bit anywhere) is refused by its checksum, naming the file; so is a
//! checkpoint of the older formats of an earlier cosdem (`CDEMCKP1`, `CDEMCKP2`: bincode;
//! `CDEMCKP4`: postcard without the solver's stage and the answers' micro descriptors;
//! `CDEMCKP7`: without the path control's progress), by name: that run must be restarted.
//!
//! A checkpoint of a [`crate::stepper::Stepper`] also holds the caller's stages so far
//! (`Checkpoint::stages`), so that a resume goes on with the same loading: they follow the
//! postcard checkpoint (inside the checksum) as one postcard string, the `[[stage]]` tables
//! of a job file (TOML, whose numbers read back bit for bit). A run's checkpoint has nothing
//! there: its bytes are those of a checkpoint before stepper checkpoints existed, and those
//! read as ever. A run refuses to resume from a stepper's checkpoint and a stepper from a run's,
//! naming the file.
//!
//! The checksum is a CRC-32 (`crc32fast`) rather than a 64-bit hash: it is guaranteed to catch
//! every single-bit error and every burst of up to 32 bits (a damaged disk block, a bad copy),
//! it is the standard polynomial any zlib recomputes, and it runs at memory speed; a damaged
//! file that matches by chance (2^-32) is no concern for a check against damage. The version
//! is 8: `'8'` is two bits from each of the older `'1'`, `'2'` and `'4'` and four from `'7'`,
//! so a single flipped bit in a header cannot pass for another format. The assembly states
//! inside (`cosdem_dem::Assembly::to_bytes`) carry a checksum of their own, made the same way.
//!
//! The checkpoint also stores a digest of the job's physics (mesh, loading, material; a Gmsh
//! mesh by its content, so that a job moved with its mesh resumes) and one of its Newton
//! settings: resuming with a job whose physics changed is refused, and so is one
//! whose Newton settings changed unless the resume says so (`--newton-changed`): the steps
//! already done stay as they were and only the steps to come are solved with the new settings
//! (a run that stalls past a peak can go on with more iterations or another tolerance instead
//! of starting again), so that run is no longer the uninterrupted run of either job.

use crate::output::write_atomic;
use cosdem_common::GaussPointId;
use cosdem_common::micro::AssemblyState;
use cosdem_fem::error::{Error, Result};
use cosdem_fem::material::Material;
use cosdem_fem::solve::{SolutionView, Solver, SolverState, StepControl, StepObserver, StepReport};
use cosdem_job::{Job, StageSection};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The header of the format written (postcard and a CRC-32).
const MAGIC: &[u8; 8] = b"CDEMCKP8";

/// The headers of the formats of earlier cosdems: `CDEMCKP1` (bincode, before the Newton
/// settings had a digest of their own), `CDEMCKP2` (bincode), `CDEMCKP4` (postcard, before
/// stages and micro descriptors) and `CDEMCKP7` (before the path control's progress).
/// Refused by name.
const OLD_MAGICS: [&[u8; 8]; 4] = [b"CDEMCKP1", b"CDEMCKP2", b"CDEMCKP4", b"CDEMCKP7"];

/// Bytes of the trailing CRC-32.
const CRC_LEN: usize = 4;

/// The checkpoint file's name in the run directory.
pub const FILE: &str = "checkpoint.bin";

/// One assembly's committed state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SavedAssembly {
    /// The Gauss point.
    pub id: GaussPointId,
    /// Its committed step.
    pub committed_step: u64,
    /// Discs.
    pub disc_count: u64,
    /// Model bytes (`Assembly::to_bytes`).
    pub state: Vec<u8>,
}

/// Everything needed to continue a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Digests of the job's physics and of its Newton settings.
    pub digests: Digests,
    /// The solver's state.
    pub solver: SolverState,
    /// The material's committed states (empty for stateless materials).
    pub assemblies: Vec<SavedAssembly>,
    /// A stepper's checkpoint: the caller's stages so far, in order (`None` for a run's).
    /// Encoded after the rest (see the [module](self) doc), not by serde.
    #[serde(skip)]
    pub stages: Option<Vec<StageSection>>,
    /// A stepper's checkpoint: the job it runs (the given job with its accuracy settings,
    /// without its loads) as TOML text, so that a resume needs nothing but the checkpoint
    /// ([`crate::stepper::Stepper::job_of`]). Encoded with the stages, not by serde.
    #[serde(skip)]
    pub job: Option<String>,
}

/// The `[[stage]]` tables of a job file, as a stepper's checkpoint stores the caller's stages.
#[derive(Serialize, Deserialize)]
struct StageTables {
    /// The job the stepper runs, as TOML text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    job: Option<String>,
    #[serde(default)]
    stage: Vec<StageSection>,
}

fn bad(path: &Path, message: String) -> Error {
    Error::Checkpoint { file: path.display().to_string(), message }
}

impl Checkpoint {
    /// Captures the solver and the material at the last committed step.
    pub fn capture(solver: &Solver, material: &mut dyn Material, digests: Digests) -> Result<Self> {
        let states = material.committed_states()?.unwrap_or_default();
        let step = solver.step();
        if let Some(s) = states.iter().find(|s| s.committed_step != step) {
            return Err(Error::Observer(format!(
                "checkpoint: {} is committed at step {}, the solver at step {step}",
                s.id, s.committed_step
            )));
        }
        let assemblies = states
            .into_iter()
            .map(|s| SavedAssembly {
                id: s.id,
                committed_step: s.committed_step,
                disc_count: s.disc_count,
                state: s.state,
            })
            .collect();
        let mut solver = solver.state();
        // The solves' wall times are the one thing in the state that is not a function of the
        // job: zeroed, so that the checkpoint of a resumed or failed-over run is byte for byte
        // the uninterrupted run's.
        for r in solver.committed.iter_mut().flatten() {
            r.diagnostics.wall_seconds = 0.0;
        }
        for g in &mut solver.gauss_points {
            g.diagnostics.wall_seconds = 0.0;
        }
        Ok(Self { digests, solver, assemblies, stages: None, job: None })
    }

    /// The material's committed states, for [`Material::restore_states`].
    pub fn assembly_states(&self) -> Vec<AssemblyState> {
        self.assemblies
            .iter()
            .map(|a| AssemblyState {
                id: a.id,
                committed_step: a.committed_step,
                state: a.state.clone(),
                disc_count: a.disc_count,
            })
            .collect()
    }

    /// Writes the checkpoint atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut bytes = MAGIC.to_vec();
        let body = postcard::to_allocvec(self)
            .map_err(|e| bad(path, format!("encoding the checkpoint: {e}")))?;
        bytes.extend_from_slice(&body);
        if let Some(stages) = &self.stages {
            let tables = StageTables { job: self.job.clone(), stage: stages.clone() };
            let text = toml::to_string(&tables)
                .map_err(|e| bad(path, format!("encoding the stages as TOML: {e}")))?;
            let trailer = postcard::to_allocvec(&text)
                .map_err(|e| bad(path, format!("encoding the stages: {e}")))?;
            bytes.extend_from_slice(&trailer);
        }
        let crc = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&crc.to_le_bytes());
        write_atomic(path, &bytes).map_err(|e| Error::Observer(e.to_string()))
    }

    /// Reads a checkpoint written by [`Checkpoint::write`]. Refuses, naming the file, one of
    /// an older format (by name), one that is not a checkpoint, and one whose checksum does
    /// not match (damaged).
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => bad(
                path,
                "not found: the run stopped before its first checkpoint, or this is not its \
                 directory; start again with --overwrite"
                    .into(),
            ),
            _ => bad(path, e.to_string()),
        })?;
        let head = &bytes[..MAGIC.len().min(bytes.len())];
        if let Some(old) = OLD_MAGICS.iter().find(|o| head == o.as_slice()) {
            return Err(bad(
                path,
                format!(
                    "the checkpoint is in {}, an older format of an earlier cosdem, \
                     which this cosdem no longer reads: the run must be restarted (or resumed \
                     with the cosdem that wrote it)",
                    String::from_utf8_lossy(&old[..])
                ),
            ));
        }
        if head != MAGIC {
            return Err(bad(
                path,
                "not a cosdem checkpoint (no CDEMCKP8 header), or its header is damaged".into(),
            ));
        }
        if bytes.len() < MAGIC.len() + CRC_LEN {
            return Err(bad(path, format!("the checkpoint is truncated ({} bytes)", bytes.len())));
        }
        let (covered, crc) = bytes.split_at(bytes.len() - CRC_LEN);
        let stored = u32::from_le_bytes(crc.try_into().expect("4 bytes"));
        let computed = crc32fast::hash(covered);
        if stored != computed {
            return Err(bad(
                path,
                format!(
                    "the checkpoint is damaged: the CRC-32 of its {} bytes is {computed:08x}, \
                     the stored one {stored:08x}",
                    covered.len()
                ),
            ));
        }
        let (mut c, trailing): (Self, &[u8]) =
            postcard::take_from_bytes(&covered[MAGIC.len()..])
                .map_err(|e| bad(path, format!("cannot decode the checkpoint: {e}")))?;
        if !trailing.is_empty() {
            // A stepper's checkpoint: the caller's stages.
            let (text, rest): (String, &[u8]) = postcard::take_from_bytes(trailing)
                .map_err(|e| bad(path, format!("cannot decode the stepper's stages: {e}")))?;
            if !rest.is_empty() {
                return Err(bad(path, "trailing bytes after the checkpoint".into()));
            }
            let tables: StageTables = toml::from_str(&text)
                .map_err(|e| bad(path, format!("cannot read the stepper's stages: {e}")))?;
            c.stages = Some(tables.stage);
            c.job = tables.job;
        }
        Ok(c)
    }

    /// Refuses a stepper's checkpoint to a run (`stepper = false`) and a run's to a stepper,
    /// naming the file: each goes on with its own loading.
    pub fn check_kind(&self, path: &Path, stepper: bool) -> Result<()> {
        match (&self.stages, stepper) {
            (Some(s), false) => Err(bad(
                path,
                format!(
                    "the checkpoint was written by a stepper (cosdem_app::stepper, {} stage(s) \
                     given by its caller), not by a run of the job: resume it with \
                     Stepper::resume",
                    s.len()
                ),
            )),
            (None, true) => Err(bad(
                path,
                "the checkpoint was written by a run of the job (its own loading), not by a \
                 stepper: resume it with `cosdem run --resume`"
                    .into(),
            )),
            _ => Ok(()),
        }
    }

    /// Refuses a checkpoint of another job's physics.
    ///
    /// `newton_changed`: the job's `[newton]` settings may differ from the checkpoint's (the
    /// steps to come are solved with the job's; a warning is logged).
    pub fn check_job(&self, job: &Job, path: &Path, newton_changed: bool) -> Result<()> {
        let Digests { job: d, newton: n } = Digests::of(job);
        // A checkpoint written before the mesh entered by its content holds the path digest.
        if d != self.digests.job && path_job_digest(job) != self.digests.job {
            return Err(bad(
                path,
                format!(
                    "the checkpoint was written for another job (digest {:016x}, this job {d:016x}): \
                     mesh, loading or material changed, or a cosdem whose job format has other \
                     fields or defaults wrote it",
                    self.digests.job
                ),
            ));
        }
        if n != self.digests.newton {
            if !newton_changed {
                return Err(bad(
                    path,
                    format!(
                        "the checkpoint was written with other [newton] settings (digest \
                         {:016x}, this job {n:016x}): the job's [newton] changed, or a cosdem \
                         whose [newton] has other fields or defaults wrote it; resume with \
                         --newton-changed to solve the steps to come with this job's",
                        self.digests.newton
                    ),
                ));
            }
            tracing::warn!(
                step = self.solver.step,
                "[newton] settings changed at the resume: the steps from here on are solved with \
                 the job's"
            );
        }
        Ok(())
    }
}

/// The digests a checkpoint stores.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Digests {
    /// [`job_digest`].
    pub job: u64,
    /// [`newton_digest`].
    pub newton: u64,
}

impl Digests {
    /// The job's.
    pub fn of(job: &Job) -> Self {
        Self { job: job_digest(job), newton: newton_digest(job) }
    }
}

/// FNV-1a digest of the job's physics: `[mesh]`, `[loading]`, `[material]` and, in a job
/// that has them, its `[[stage]]`s, `[[region]]`s and `[specimens]`, as JSON (a job without stages keeps the digest it had
/// before stages existed). Output and worker settings may change between a run and its
/// resume.
///
/// A Gmsh mesh enters by its content, not its path: `mesh.file` is replaced by the FNV-1a
/// digest of the file's bytes, so a job moved or copied with its mesh resumes, and a mesh
/// edited in place is refused. A mesh file that cannot be read enters by its path (reading it
/// for the run then fails, naming it). A job with a generated mesh has the digest it had
/// before.
pub fn job_digest(job: &Job) -> u64 {
    let content = job.mesh.file.as_deref().and_then(|f| std::fs::read(f).ok());
    match content {
        Some(bytes) => {
            let mut mesh = job.mesh.clone();
            mesh.file = Some(PathBuf::from(format!("fnv1a:{:016x}", fnv1a_bytes(&bytes))));
            physics_digest(job, &mesh)
        }
        None => path_job_digest(job),
    }
}

/// The digest of earlier cosdems, [`job_digest`] with a Gmsh mesh entering by its path: their
/// checkpoints still resume where the job and its mesh stayed.
fn path_job_digest(job: &Job) -> u64 {
    physics_digest(job, &job.mesh)
}

/// [`job_digest`] with `mesh` for the job's `[mesh]`.
fn physics_digest(job: &Job, mesh: &cosdem_job::MeshSection) -> u64 {
    let json = if job.stage.is_empty() {
        serde_json::to_string(&(mesh, &job.loading, &job.material))
    } else {
        serde_json::to_string(&(mesh, &job.loading, &job.material, &job.stage))
    };
    let mut json = json.unwrap_or_default();
    // Regions and specimens, in a job that has them.
    if !job.region.is_empty() || job.specimens != Default::default() {
        json.push_str(&serde_json::to_string(&(&job.region, &job.specimens)).unwrap_or_default());
    }
    fnv1a(&json)
}

/// FNV-1a digest of the job's `[newton]` settings as JSON.
pub fn newton_digest(job: &Job) -> u64 {
    fnv1a(&serde_json::to_string(&job.newton).unwrap_or_default())
}

/// FNV-1a, 64 bits: the digests of a job (here and in the run directory's provenance).
pub(crate) fn fnv1a(text: &str) -> u64 {
    fnv1a_bytes(text.as_bytes())
}

/// [`fnv1a`] of bytes.
fn fnv1a_bytes(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Wraps a [`StepObserver`]: writes the checkpoint every `every` steps (0: only when
/// stopping) and stops the run cleanly once `stop` is set (checkpoint written first).
pub struct Checkpointer<O> {
    /// The wrapped observer (sees every step first).
    pub inner: O,
    path: PathBuf,
    every: u64,
    digests: Digests,
    stop: Arc<AtomicBool>,
    max_steps: Option<u64>,
}

impl<O: StepObserver> Checkpointer<O> {
    /// Checkpoints into `dir/checkpoint.bin`.
    pub fn new(inner: O, dir: &Path, every: usize, job: &Job, stop: Arc<AtomicBool>) -> Self {
        Self {
            inner,
            path: dir.join(FILE),
            every: every as u64,
            digests: Digests::of(job),
            stop,
            max_steps: None,
        }
    }

    /// Also stops the run cleanly (checkpoint written) once `max_steps` steps are committed
    /// (`cosdem run --max-steps`): the run can go on later with `--resume`.
    pub fn stop_at(mut self, max_steps: Option<u64>) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// Whether the run reached its `max_steps` at `step`.
    pub fn reached(&self, step: u64) -> bool {
        self.max_steps.is_some_and(|k| step >= k)
    }
}

impl<O: StepObserver> StepObserver for Checkpointer<O> {
    fn on_step(&mut self, report: &StepReport, state: &SolutionView<'_>) -> Result<()> {
        self.inner.on_step(report, state)
    }

    fn after_step(&mut self, solver: &Solver, material: &mut dyn Material) -> Result<StepControl> {
        let inner = self.inner.after_step(solver, material)?;
        let stop = inner == StepControl::Stop
            || self.stop.load(Ordering::SeqCst)
            || self.reached(solver.step());
        if stop || (self.every > 0 && solver.step().is_multiple_of(self.every)) {
            let _s = tracing::info_span!("checkpoint", step = solver.step()).entered();
            Checkpoint::capture(solver, material, self.digests)?.write(&self.path)?;
        }
        Ok(if stop { StepControl::Stop } else { StepControl::Continue })
    }
}

/// A flag set by the first Ctrl-C (SIGINT) or SIGTERM (what Slurm, Kubernetes and
/// `docker stop` send before they kill); a second one exits at once with status 130. Listens on
/// a thread of its own (a one-thread tokio runtime), so the solver is never interrupted
/// mid-step: the run stops after the current step with its checkpoint written.
pub fn ctrl_c_flag() -> std::io::Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    // Registered here, before the run starts, not when the thread first polls.
    #[cfg(unix)]
    let mut term = {
        let _guard = rt.enter();
        tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?
    };
    let f = flag.clone();
    std::thread::Builder::new().name("cosdem-ctrl-c".into()).spawn(move || {
        rt.block_on(async move {
            loop {
                #[cfg(unix)]
                let received = tokio::select! {
                    r = tokio::signal::ctrl_c() => r.is_ok().then_some("Ctrl-C"),
                    r = term.recv() => r.map(|()| "SIGTERM"),
                };
                #[cfg(not(unix))]
                let received = tokio::signal::ctrl_c().await.is_ok().then_some("Ctrl-C");
                let Some(what) = received else { return };
                if f.swap(true, Ordering::SeqCst) {
                    eprintln!("\nsecond {what}: exiting without waiting for the step");
                    std::process::exit(130);
                }
                eprintln!("\n{what}: stopping after the current step (again to quit now)");
            }
        });
    })?;
    Ok(flag)
}

#[cfg(test)]
mod tests;
