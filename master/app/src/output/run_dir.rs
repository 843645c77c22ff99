//! The run directory, written as the run goes: a run killed halfway leaves every finished step
//! readable.
//!
//! ```text
//! RUN/curve.csv        one row per converged step (full-precision numbers)
//! RUN/fields.pvd       ParaView collection of RUN/vtk/mesh_NNNNN.vtu (u, w per node)
//! RUN/gauss.pvd        ParaView collection of RUN/vtk/gauss_NNNNN.vtu (stress, strain, q)
//! RUN/summary.json     metrics so far (F_u, F_res, E, E50), DEM totals, status, wall time
//! RUN/snapshots/, RUN/fields/   particle snapshots and field data (see `super::visuals`)
//! ```
//! Everything but `summary.json`'s timing and worker fields is a deterministic function of the
//! job, so two runs can be compared byte for byte.

use super::csv::CsvWriter;
use super::curve_axes::CurveAxes;
use super::pieces::{gauss_state_piece, nodal_piece};
use super::pvd::PvdWriter;
use super::snapshots::{SnapshotInbox, SnapshotTap};
use super::visuals::{StepInfo, VisualOutputs, reached as done};
use super::vtk::write_vtu_encoded;
use super::{OutputError, Result, write_atomic};
use cosdem_common::Answer;
use cosdem_common::GaussPointId;
use cosdem_fem::material::Material;
use cosdem_fem::post::{CurveMetrics, CurveNotes};
use cosdem_fem::solve::{SolutionView, StepObserver, StepReport};
pub use cosdem_job::PvdTime;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Columns of `curve.csv`.
pub const CURVE_COLUMNS: [&str; 8] = [
    "step",
    "load_factor",
    "displacement",
    "load",
    "iterations",
    "cuts",
    "dem_steps",
    "unconverged_points",
];

/// Column of `curve.csv` after [`CURVE_COLUMNS`] in every run but a compression without
/// `[output.curve]`: the pseudo-time (stages finished plus the stage's load factor).
pub const TIME_COLUMN: &str = "time";

/// What the run writer needs to know about the job.
#[derive(Clone, Debug)]
pub struct RunSettings {
    /// Free text for the summary.
    pub title: String,
    /// Displacement at load factor 1 (the curve's abscissa is `load_factor * shortening`).
    pub shortening: f64,
    /// Node set whose reaction is the load (compression positive: `-R_y`).
    pub load_set: String,
    /// Factor from that reaction to the reported load (2 on a half or quarter mesh).
    pub load_scale: f64,
    /// Write VTK every this many steps (0: never).
    pub vtk_every: usize,
    /// Internal length for the equivalent strain (m).
    pub internal_length: f64,
    /// Upper end of the linear range for the stiffness E (m).
    pub linear_range: f64,
    /// `[output.curve]`: the curve's axes and extra reaction columns; `None`: the platen
    /// compression's curve (`load_factor * shortening`, `-R_y` of `load_set`).
    pub curve: Option<CurveAxes>,
    /// What the `.pvd` timesteps are ([`cosdem_job::Job::pvd_time`]).
    pub pvd_time: PvdTime,
    /// Encoding of the `.vtu` files.
    pub vtk_encoding: super::Encoding,
    /// `[output] packing_formats`: packing files written with each particle snapshot.
    pub packings: super::packing::PackingOutput,
}

impl RunSettings {
    /// A compression job without `[output.curve]`: `curve.csv`, the `.pvd` series and
    /// `summary.json` are exactly what they were before the table existed.
    fn is_compression_curve(&self) -> bool {
        self.curve.is_none() && self.pvd_time == PvdTime::Displacement
    }

    /// The columns of `curve.csv`: [`CURVE_COLUMNS`], then (but for a compression job
    /// without `[output.curve]`) [`TIME_COLUMN`] and the curve's reaction columns.
    pub fn columns(&self) -> Vec<String> {
        let mut c: Vec<String> = CURVE_COLUMNS.iter().map(|s| s.to_string()).collect();
        if !self.is_compression_curve() {
            c.push(TIME_COLUMN.into());
        }
        if let Some(axes) = &self.curve {
            c.extend(axes.reaction_columns());
        }
        c
    }
}

/// The summary, rewritten atomically after every step. It reads back (a field missing from an
/// older file takes its default) so that a finished run can be reused (`bench tradeoff
/// --resume`).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Summary {
    /// The job's title.
    pub title: String,
    /// `running`, `finished`, `stopped` (at `--max-steps`), `failed: <reason>` or
    /// `interrupted: <reason>`. Read with [`Summary::read`], a `running` left by a process
    /// that ended without writing its status (killed: the directory's lock is free) reads as
    /// `interrupted: ...`.
    pub status: String,
    /// Converged steps so far.
    pub steps: u64,
    /// Displacement reached (m).
    pub displacement: f64,
    /// F_u, F_res, E, E50 of the curve so far.
    pub metrics: CurveMetrics,
    /// DEM steps summed over every Gauss point and every relaxation of the converged steps:
    /// all Newton iterations, line-search trials and cut attempts that answered, the
    /// run's relaxation cost (0 for analytical materials).
    pub dem_steps: u64,
    /// Gauss-point relaxations that hit their step cap in converged steps.
    pub capped_relaxations: u64,
    /// Gauss-point answers of converged steps given without a relaxation because the
    /// increment was below `relaxation.skip_below`.
    pub skipped_relaxations: u64,
    /// Gauss-point answers of converged steps given through the tangent by the elastic
    /// shortcut (`relaxation.elastic_shortcut`).
    pub linear_answers: u64,
    /// Largest reported stress-error bound of those answers (Pa).
    pub max_error_bound: f64,
    /// Step cuts taken.
    pub cuts: u64,
    /// Steps accepted under `newton.tolerated_residual` (ran out of iterations above the
    /// force tolerance): their imbalance is in the log.
    pub tolerated_steps: u64,
    /// Of those, steps forced through at the smallest increment above the tolerated residual
    /// (`newton.forced_residual`).
    pub forced_steps: u64,
    /// Wall time so far (s); not deterministic.
    pub wall_seconds: f64,
    /// Workers used (set by the caller).
    pub workers: usize,
    /// With `[output.curve]`: its axis labels `[abscissa, ordinate]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve_labels: Option<[String; 2]>,
    /// With `[output.curve]`: whether the peak was passed, and why a metric is absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve_notes: Option<CurveNotes>,
    /// What the `.pvd` timesteps are: `displacement` or `pseudo-time`; absent for a
    /// compression job without `[output.curve]` (displacement, as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pvd_time: Option<PvdTime>,
    /// With DEM points: the distinct specimens generated, the points they back and the
    /// generation's wall time (a resume keeps the first session's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub specimens: Option<crate::run::SpecimenReport>,
}

impl Summary {
    /// The summary of the run directory `dir`, with the status it has now: a `running` whose
    /// writer no longer holds the directory's lock ([`super::claim::is_locked`]) is
    /// `interrupted: the process writing the run ended without a status (killed?)`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join("summary.json");
        let text = std::fs::read_to_string(&path).map_err(super::io_err(&path, "read"))?;
        let mut s: Self = serde_json::from_str(&text)
            .map_err(|e| OutputError::InvalidData { path: path.clone(), message: e.to_string() })?;
        if s.status == "running" && !super::claim::is_locked(dir) {
            s.status =
                "interrupted: the process writing the run ended without a status (killed?)".into();
        }
        Ok(s)
    }
}

/// Every file of the run directory `dir` (path relative to it, `/`-separated -> bytes) but the
/// four that are not a function of the job: the lock file (a pid), `summary.json` (its wall
/// time), `provenance.json` (dates, command lines) and `cosdem.log`. Two runs of one job, interrupted and resumed or not, on any number
/// of workers, give equal maps.
pub fn comparable_files(dir: &Path) -> Result<std::collections::BTreeMap<String, Vec<u8>>> {
    fn walk(
        root: &Path,
        dir: &Path,
        out: &mut std::collections::BTreeMap<String, Vec<u8>>,
    ) -> Result<()> {
        for e in std::fs::read_dir(dir).map_err(super::io_err(dir, "list"))? {
            let p = e.map_err(super::io_err(dir, "list"))?.path();
            if p.is_dir() {
                walk(root, &p, out)?;
                continue;
            }
            let rel = p.strip_prefix(root).unwrap_or(&p).to_string_lossy().replace('\\', "/");
            let skipped =
                [super::claim::LOCK_FILE, "summary.json", super::provenance::FILE, "cosdem.log"];
            if !skipped.contains(&rel.as_str()) {
                out.insert(rel, std::fs::read(&p).map_err(super::io_err(&p, "read"))?);
            }
        }
        Ok(())
    }
    let mut out = std::collections::BTreeMap::new();
    walk(dir, dir, &mut out)?;
    Ok(out)
}

/// Writes the run directory; a [`StepObserver`].
pub struct RunWriter {
    dir: PathBuf,
    settings: RunSettings,
    csv: CsvWriter,
    fields: Option<PvdWriter>,
    gauss: Option<PvdWriter>,
    curve: Vec<(f64, f64)>,
    summary: Summary,
    started: Instant,
    visuals: VisualOutputs,
}

impl RunWriter {
    /// Creates the run directory (and `vtk/` in it) and the empty curve.
    pub fn create(dir: &Path, settings: RunSettings) -> Result<Self> {
        let mk = |p: &Path| {
            std::fs::create_dir_all(p).map_err(|source| OutputError::Io {
                path: p.to_path_buf(),
                action: "create directory",
                source,
            })
        };
        mk(dir)?;
        let (fields, gauss) = if settings.vtk_every > 0 {
            mk(&dir.join("vtk"))?;
            (
                Some(PvdWriter::create(&dir.join("fields.pvd"))?),
                Some(PvdWriter::create(&dir.join("gauss.pvd"))?),
            )
        } else {
            (None, None)
        };
        let columns = settings.columns();
        let columns: Vec<&str> = columns.iter().map(String::as_str).collect();
        let csv = CsvWriter::create(&dir.join("curve.csv"), &columns)?;
        let mut summary = Summary {
            title: settings.title.clone(),
            status: "running".into(),
            ..Summary::default()
        };
        fill_curve_fields(&mut summary, &settings, &[]);
        Self::open(dir, settings, csv, (fields, gauss), Vec::new(), summary, Instant::now())
    }

    /// Continues the run directory of a run resumed at committed step `step` (from its
    /// checkpoint): `curve.csv` keeps its rows up to `step` (later rows, written after the
    /// checkpoint, are dropped; new rows are appended), the `.pvd` series keep their datasets
    /// up to that step's displacement, and the summary's totals are rebuilt from the kept rows.
    pub fn resume(dir: &Path, settings: RunSettings, step: u64) -> Result<Self> {
        let path = dir.join("curve.csv");
        let text = std::fs::read_to_string(&path).map_err(super::io_err(&path, "read"))?;
        let columns = settings.columns();
        let mut kept = String::new();
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for (i, line) in text.split_inclusive('\n').enumerate() {
            if i == 0 {
                kept.push_str(line);
                continue;
            }
            if !line.ends_with('\n') {
                break; // a row cut short by a kill
            }
            let values: Vec<f64> =
                line.trim_end().split(',').filter_map(|v| v.parse().ok()).collect();
            if values.len() != columns.len() {
                return Err(super::invalid(
                    &path,
                    format!("line {}: {line:?} is not a curve row", i + 1),
                ));
            }
            if values[0] > step as f64 {
                break;
            }
            kept.push_str(line);
            rows.push(values);
        }
        if rows.len() as u64 != step {
            return Err(super::invalid(
                &path,
                format!(
                    "{} rows up to step {step}: the curve does not match the checkpoint",
                    rows.len()
                ),
            ));
        }
        write_atomic(&path, kept.as_bytes())?;
        let names: Vec<&str> = columns.iter().map(String::as_str).collect();
        let csv = CsvWriter::resume(&path, &names)?;
        let displacement = rows.last().map_or(0.0, |r| r[2]);
        // The `.pvd` timestep of each kept row: the displacement, or the time column.
        let time_at =
            if settings.pvd_time == PvdTime::Displacement { 2 } else { CURVE_COLUMNS.len() };
        let times: Vec<f64> = rows.iter().map(|r| r[time_at]).collect();
        super::restart::cut_back(dir, step, &times, settings.vtk_every > 0)?;
        let (fields, gauss) = if settings.vtk_every > 0 {
            std::fs::create_dir_all(dir.join("vtk"))
                .map_err(super::io_err(dir, "create vtk/ in"))?;
            (
                Some(PvdWriter::resume(&dir.join("fields.pvd"))?),
                Some(PvdWriter::resume(&dir.join("gauss.pvd"))?),
            )
        } else {
            (None, None)
        };
        // Wall time of the sessions before this one, if the old summary says.
        // The counters the curve does not hold come from the old summary (a session stopped
        // after its last checkpoint counts a few answers twice: they are diagnostics).
        let old = std::fs::read_to_string(dir.join("summary.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .unwrap_or_default();
        let before = old["wall_seconds"].as_f64().unwrap_or(0.0);
        let count = |key: &str| old[key].as_u64().unwrap_or(0);
        let curve: Vec<(f64, f64)> = rows.iter().map(|r| (r[2], r[3])).collect();
        let mut summary = Summary {
            title: settings.title.clone(),
            status: "running".into(),
            steps: step,
            displacement,
            metrics: CurveMetrics::from_curve(&curve, settings.linear_range),
            dem_steps: rows.iter().map(|r| r[6] as u64).sum(),
            capped_relaxations: rows.iter().map(|r| r[7] as u64).sum(),
            cuts: rows.iter().map(|r| r[5] as u64).sum(),
            skipped_relaxations: count("skipped_relaxations"),
            linear_answers: count("linear_answers"),
            max_error_bound: old["max_error_bound"].as_f64().unwrap_or(0.0),
            tolerated_steps: count("tolerated_steps"),
            forced_steps: count("forced_steps"),
            wall_seconds: before,
            specimens: serde_json::from_value(old["specimens"].clone()).ok(),
            ..Summary::default()
        };
        fill_curve_fields(&mut summary, &settings, &curve);
        let started = Instant::now()
            .checked_sub(std::time::Duration::from_secs_f64(before.max(0.0)))
            .unwrap_or_else(Instant::now);
        Self::open(dir, settings, csv, (fields, gauss), curve, summary, started)
    }

    /// Counts `setup` (the time spent before the writer was opened: building the solver and
    /// the workers' assemblies) in the run's wall time, as when the writer was opened first.
    pub fn add_setup_time(&mut self, setup: std::time::Duration) {
        self.started = self.started.checked_sub(setup).unwrap_or(self.started);
    }

    /// The writer of the run directory `dir` with its open `curve.csv`, its `.pvd` series
    /// `(fields, gauss)` (if VTK is written), the `curve` and `summary` so far and the time
    /// the run `started`; writes the summary.
    fn open(
        dir: &Path,
        settings: RunSettings,
        csv: CsvWriter,
        (fields, gauss): (Option<PvdWriter>, Option<PvdWriter>),
        curve: Vec<(f64, f64)>,
        summary: Summary,
        started: Instant,
    ) -> Result<Self> {
        let mut w = Self {
            dir: dir.to_path_buf(),
            settings,
            csv,
            fields,
            gauss,
            curve,
            summary,
            started,
            visuals: VisualOutputs::default(),
        };
        w.write_summary()?;
        Ok(w)
    }

    /// Marks the run interrupted (stopped cleanly; resume with `--resume`) for `reason` and
    /// writes the summary.
    pub fn finish_interrupted(&mut self, reason: &str) -> Result<()> {
        self.summary.status = format!("interrupted: {reason}");
        self.write_summary()
    }

    /// Marks the run stopped at `cosdem run --max-steps` (resume with `--resume`) and writes
    /// the summary.
    pub fn finish_stopped(&mut self) -> Result<()> {
        self.summary.status = "stopped".into();
        self.write_summary()
    }

    /// The run directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The curve so far: `(displacement, load)` per converged step.
    pub fn curve(&self) -> &[(f64, f64)] {
        &self.curve
    }

    /// The summary so far.
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    /// Asks for particle snapshots of `snapshots` (written with the VTK cadence, at the
    /// `field_plots_at` displacements and at the last step) and for the field data of
    /// `field_plots_at` and the last step. Returns `material` wrapped so that it hands the
    /// snapshots over at every commit: run the solver with the wrapper.
    pub fn watch<'m>(
        &mut self,
        material: &'m mut dyn Material,
        snapshots: Vec<GaussPointId>,
        field_plots_at: &[f64],
    ) -> SnapshotTap<'m> {
        let inbox = SnapshotInbox::default();
        // On a resume the displacements reached before the checkpoint have had their field
        // data and snapshots.
        let reached = if self.summary.steps > 0 { self.summary.displacement } else { f64::MIN };
        let pending: Vec<f64> =
            field_plots_at.iter().copied().filter(|&d| !done(reached, d)).collect();
        self.visuals = VisualOutputs::new(snapshots.clone(), &pending, inbox.clone())
            .with_packings(self.settings.packings.clone());
        SnapshotTap::new(material, snapshots, inbox)
    }

    /// `material` wrapped as [`Self::watch`] wrapped it, delivering to this writer the
    /// snapshots the last watch asked for: for a caller that runs the solver more than once
    /// under one watch (the stepper runs it once per stage).
    pub fn tap<'m>(&self, material: &'m mut dyn Material) -> SnapshotTap<'m> {
        let (ids, inbox) = self.visuals.watched();
        SnapshotTap::new(material, ids, inbox)
    }

    /// Records the number of workers in the summary.
    pub fn set_workers(&mut self, n: usize) {
        self.summary.workers = n;
    }

    /// Gives each element's packing files its region's density (before [`Self::watch`]).
    pub fn set_regions(&mut self, job: &cosdem_job::Job, element_materials: &[usize]) {
        self.settings.packings.set_regions(job, element_materials);
    }

    /// Records what the specimens cost in the summary.
    pub fn set_specimens(&mut self, report: crate::run::SpecimenReport) {
        self.summary.specimens = Some(report);
    }

    /// Adds DEM steps that no step row carries to the summary's count: the failed attempts
    /// of the step that ended a run ([`cosdem_fem::solve::Solver::uncommitted_dem_steps`]), so
    /// that a failed run's cost is all it spent (`curve.csv` keeps the committed steps').
    pub fn add_uncommitted_dem_steps(&mut self, n: u64) {
        self.summary.dem_steps = self.summary.dem_steps.saturating_add(n);
    }

    /// Marks the run finished (or failed, with the reason) and writes the summary.
    pub fn finish(&mut self, outcome: std::result::Result<(), String>) -> Result<()> {
        self.summary.status = match outcome {
            Ok(()) => "finished".into(),
            Err(why) => format!("failed: {why}"),
        };
        self.write_summary()
    }

    fn write_summary(&mut self) -> Result<()> {
        self.summary.wall_seconds = self.started.elapsed().as_secs_f64();
        let path = self.dir.join("summary.json");
        let mut text = serde_json::to_string_pretty(&self.summary)
            .map_err(|e| OutputError::InvalidData { path: path.clone(), message: e.to_string() })?;
        text.push('\n');
        write_atomic(&path, text.as_bytes())
    }

    fn write_vtk(&mut self, step: u64, time: f64, view: &SolutionView<'_>) -> Result<()> {
        let mesh = view.mesh;
        let elements = mesh.element_lists();
        let dofs: Vec<[f64; 3]> = view
            .displacements()
            .iter()
            .zip(view.rotations())
            .map(|(u, w)| [u[0], u[1], w])
            .collect();
        let path = self.dir.join(format!("vtk/mesh_{step:05}.vtu"));
        let mut piece = nodal_piece(&path, &mesh.nodes, &elements, &dofs)?;
        piece.time = Some(time);
        super::nodal_stress::add_nodal_stress(
            &mut piece,
            mesh.n_nodes(),
            &elements,
            view.gauss_points,
        );
        write_vtu_encoded(&path, &piece, self.settings.vtk_encoding)?;
        if let Some(pvd) = &mut self.fields {
            pvd.add(time, &path)?;
        }
        let mut piece = gauss_state_piece(view.gauss_points, self.settings.internal_length);
        piece.time = Some(time);
        let path = self.dir.join(format!("vtk/gauss_{step:05}.vtu"));
        write_vtu_encoded(&path, &piece, self.settings.vtk_encoding)?;
        if let Some(pvd) = &mut self.gauss {
            pvd.add(time, &path)?;
        }
        Ok(())
    }
}

impl StepObserver for RunWriter {
    fn on_step(&mut self, report: &StepReport, view: &SolutionView<'_>) -> cosdem_fem::Result<()> {
        let (displacement, load) = match &self.settings.curve {
            Some(axes) => (axes.control_displacement(view).unwrap_or(0.0), axes.load(report)),
            None => (
                report.load_factor * self.settings.shortening,
                -self.settings.load_scale
                    * report.reactions.get(&self.settings.load_set).map_or(0.0, |r| r[1]),
            ),
        };
        let time = match self.settings.pvd_time {
            PvdTime::Displacement => displacement,
            PvdTime::PseudoTime => report.time,
        };
        let dem_steps = report.dem_steps;
        let capped = view
            .gauss_points
            .iter()
            .filter(|g| g.diagnostics.steps > 0 && !g.diagnostics.converged);
        let capped = capped.count() as u64;
        self.curve.push((displacement, load));
        self.summary.steps = report.step;
        self.summary.displacement = displacement;
        self.summary.dem_steps += dem_steps;
        self.summary.capped_relaxations += capped;
        for g in view.gauss_points {
            let d = &g.diagnostics;
            match d.answer {
                Answer::Relaxed => {}
                Answer::Skipped => self.summary.skipped_relaxations += 1,
                Answer::Linear => self.summary.linear_answers += 1,
            }
            self.summary.max_error_bound = self.summary.max_error_bound.max(d.error_bound);
        }
        self.summary.cuts += u64::from(report.cuts);
        self.summary.tolerated_steps += u64::from(report.tolerated);
        self.summary.forced_steps += u64::from(report.forced);
        fill_curve_fields(&mut self.summary, &self.settings, &self.curve);
        let mut row = vec![
            report.step as f64,
            report.load_factor,
            displacement,
            load,
            f64::from(report.iterations),
            f64::from(report.cuts),
            dem_steps as f64,
            capped as f64,
        ];
        if !self.settings.is_compression_curve() {
            row.push(report.time);
        }
        if let Some(axes) = &self.settings.curve {
            row.extend(axes.reaction_values(report));
        }
        let io = |e: OutputError| cosdem_fem::Error::Observer(e.to_string());
        self.csv.write_row(&row).map_err(io)?;
        let every = self.settings.vtk_every;
        let on_cadence = every > 0 && report.step.is_multiple_of(every as u64);
        if on_cadence {
            self.write_vtk(report.step, time, view).map_err(io)?;
        }
        let info = StepInfo {
            step: report.step,
            displacement,
            time,
            // The stage's end: its load factor at 1, or a path control's progress (the
            // pseudo-time's fraction of the stage).
            last: report.time - f64::from(report.stage) >= 1.0 - 1e-12,
            on_cadence,
            internal_length: self.settings.internal_length,
        };
        self.visuals.on_step(&self.dir, info, view).map_err(io)?;
        self.write_summary().map_err(io)
    }
}

/// The summary's curve fields for `curve` so far: the metrics, and with `[output.curve]` its
/// labels and notes (what is absent and why: [`CurveMetrics::assess`]); the `.pvd` time but
/// for a compression job without `[output.curve]` (whose summary stays as it was).
fn fill_curve_fields(summary: &mut Summary, settings: &RunSettings, curve: &[(f64, f64)]) {
    match &settings.curve {
        Some(axes) => {
            let (metrics, notes) = CurveMetrics::assess(curve, settings.linear_range);
            summary.metrics = metrics;
            summary.curve_notes = Some(notes);
            summary.curve_labels = Some(axes.labels());
        }
        None => summary.metrics = CurveMetrics::from_curve(curve, settings.linear_range),
    }
    summary.pvd_time = (!settings.is_compression_curve()).then_some(settings.pvd_time);
}
