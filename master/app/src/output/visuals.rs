//! The run writer's outputs for people to look at, besides the curve and the VTK fields:
//! particle snapshots of chosen Gauss points and the field data of chosen displacements.
//!
//! ```text
//! RUN/snapshots/e{E}_p{P}.pvd                 ParaView series of one Gauss point's assembly
//! RUN/snapshots/e{E}_p{P}/snap_NNNNN.vtu      discs (radius, rotation, fluctuation) + contacts
//! RUN/snapshots/e{E}_p{P}/packing_NNNNN.txt   the same discs as YADE text      ┐ `[output]
//! RUN/snapshots/e{E}_p{P}/packing_NNNNN.data  ... as a LAMMPS data file        │ packing_
//! RUN/snapshots/e{E}_p{P}/packing_NNNNN.vtu   ... as a VTU point cloud         ┘ formats`
//! RUN/fields/field_NNNNN.json                 mesh, u and equivalent strain (Eq. 34) of a step
//! ```
//! Snapshots are written at the VTK cadence (`vtk_every`), at the first step reaching each
//! `field_plots_at` displacement and at the last step; field data at those displacements and
//! at the last step; the packing files with every snapshot, in the formats asked
//! ([`super::packing`], the same files as `cosdem export`'s, of the snapshot's discs). Every
//! file is written atomically and the `.pvd` lists only written files.

use super::field_data::FieldData;
use super::packing::{PackingOutput, snapshot_packing_path, write_packing};
use super::pvd::PvdWriter;
use super::snapshots::{ParticleSnapshot, SnapshotInbox, snapshot_packing, snapshot_piece};
use super::{Result, io_err, write_vtu};
use cosdem_common::GaussPointId;
use cosdem_fem::solve::SolutionView;
use std::collections::BTreeMap;
use std::path::Path;

/// Which steps get snapshots and field data, and the series written so far.
#[derive(Debug, Default)]
pub struct VisualOutputs {
    snapshot_ids: Vec<GaussPointId>,
    inbox: SnapshotInbox,
    series: BTreeMap<GaussPointId, PvdWriter>,
    /// `field_plots_at` displacements not reached yet, ascending.
    pending: Vec<f64>,
    /// The packing files written with each snapshot.
    packings: PackingOutput,
}

/// What [`VisualOutputs::on_step`] needs to know about the step.
#[derive(Clone, Copy, Debug)]
pub struct StepInfo {
    /// Converged step number.
    pub step: u64,
    /// Macro displacement reached (m): the curve's abscissa.
    pub displacement: f64,
    /// The `.pvd` timestep of the step (the displacement or the pseudo-time, see
    /// [`super::run_dir::RunSettings::pvd_time`]).
    pub time: f64,
    /// True for the last step of the loading.
    pub last: bool,
    /// True when the step is on the VTK cadence.
    pub on_cadence: bool,
    /// Internal length for Eq. 34 (m).
    pub internal_length: f64,
}

/// Whether a step at `displacement` reaches the field-plot displacement `at` (to 1e-9 of it).
pub fn reached(displacement: f64, at: f64) -> bool {
    displacement >= at - (1e-9 * at.abs() + 1e-15)
}

/// File stem of a Gauss point's snapshot series.
pub fn series_name(id: GaussPointId) -> String {
    format!("e{}_p{}", id.element, id.point)
}

impl VisualOutputs {
    /// Snapshots of `snapshot_ids` (delivered into `inbox`) and field data at `field_plots_at`.
    pub fn new(
        snapshot_ids: Vec<GaussPointId>,
        field_plots_at: &[f64],
        inbox: SnapshotInbox,
    ) -> Self {
        let mut pending: Vec<f64> = field_plots_at.to_vec();
        pending.sort_by(f64::total_cmp);
        Self { snapshot_ids, inbox, series: BTreeMap::new(), pending, packings: Default::default() }
    }

    /// The Gauss points watched and the inbox their snapshots are delivered into.
    pub(crate) fn watched(&self) -> (Vec<GaussPointId>, SnapshotInbox) {
        (self.snapshot_ids.clone(), self.inbox.clone())
    }

    /// Also writes each snapshot as packing files in `packings.formats`.
    pub fn with_packings(mut self, packings: PackingOutput) -> Self {
        self.packings = packings;
        self
    }

    /// Writes what the step calls for into `dir`.
    pub fn on_step(&mut self, dir: &Path, s: StepInfo, view: &SolutionView<'_>) -> Result<()> {
        let mut hit = false;
        while let Some(&d) = self.pending.first() {
            if reached(s.displacement, d) {
                hit = true;
                self.pending.remove(0);
            } else {
                break;
            }
        }
        if hit || s.last {
            self.write_field(dir, s, view)?;
        }
        if hit || s.last || s.on_cadence {
            for i in 0..self.snapshot_ids.len() {
                let id = self.snapshot_ids[i];
                if let Some(snap) = self.inbox.take(id, s.step) {
                    self.write_snapshot(dir, id, s, &snap)?;
                }
            }
        }
        Ok(())
    }

    fn write_field(&self, dir: &Path, s: StepInfo, view: &SolutionView<'_>) -> Result<()> {
        let mesh = view.mesh;
        let mut gauss_points = vec![0; mesh.n_elements()];
        for g in view.gauss_points {
            gauss_points[g.id.element as usize] += 1;
        }
        let data = FieldData {
            step: s.step,
            displacement: s.displacement,
            internal_length: s.internal_length,
            nodes: mesh.nodes.clone(),
            displacements: view.displacements(),
            elements: mesh.element_lists(),
            gauss_points,
            equivalent_strain: view
                .gauss_points
                .iter()
                .map(|g| cosdem_fem::post::equivalent_strain(&g.strain, s.internal_length))
                .collect(),
        };
        let fields = dir.join("fields");
        std::fs::create_dir_all(&fields).map_err(io_err(&fields, "create directory"))?;
        data.write(&fields.join(format!("field_{:05}.json", s.step)))
    }

    fn write_snapshot(
        &mut self,
        dir: &Path,
        id: GaussPointId,
        s: StepInfo,
        snap: &cosdem_common::micro::MicroSnapshot,
    ) -> Result<()> {
        let name = series_name(id);
        let sub = dir.join("snapshots").join(&name);
        let path = sub.join(format!("snap_{:05}.vtu", s.step));
        let mut particles = match ParticleSnapshot::from_micro(snap, &path) {
            Ok(p) => p,
            Err(e) => {
                // A model without particles (the stand-in): nothing to draw, not an error.
                tracing::warn!(error = %e, "snapshot skipped");
                return Ok(());
            }
        };
        particles.displacement = Some(s.displacement);
        let pvd = match self.series.entry(id) {
            std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::btree_map::Entry::Vacant(e) => {
                std::fs::create_dir_all(&sub).map_err(io_err(&sub, "create directory"))?;
                // A resumed run goes on with the series its directory holds (rebuilt by
                // `super::restart::cut_back`); a new run's directory has none.
                e.insert(PvdWriter::resume(&dir.join("snapshots").join(format!("{name}.pvd")))?)
            }
        };
        write_vtu(&path, &snapshot_piece(&particles))?;
        if !self.packings.formats.is_empty() {
            let packing = snapshot_packing(&particles);
            for &format in &self.packings.formats {
                let file = snapshot_packing_path(&sub, s.step, format);
                write_packing(&file, &packing, self.packings.density_of(id.element), format)?;
            }
        }
        pvd.add(s.time, &path)
    }
}
