//! Particle snapshots of chosen Gauss points: fetched from the material after every commit
//! ([`SnapshotTap`]), written as VTK ([`snapshot_piece`]) and as packing files
//! ([`snapshot_packing`]), and read back for plots ([`read_snapshot`]).
//!
//! The solver hands its observers the FE solution only, so the snapshots are taken by a thin
//! [`Material`] wrapper: after the wrapped material commits step N it asks it for the particle
//! picture of each chosen Gauss point and leaves the latest one in a shared [`SnapshotInbox`];
//! the run writer, called right after the commit, takes it from there when the step is one it
//! writes. A snapshot that cannot be fetched is logged and skipped: output never stops a run.

use super::pieces::particle_piece;
use super::vtk::{DataArray, VtuPiece};
use super::vtu_read::read_vtu;
use super::{Result, invalid};
use cosdem_common::micro::MicroSnapshot;
use cosdem_common::{GaussPointId, MicroResponse};
use cosdem_dem::packing::Packing;
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The latest committed snapshot of each watched Gauss point, with its step.
#[derive(Clone, Debug, Default)]
pub struct SnapshotInbox(Arc<Mutex<BTreeMap<GaussPointId, (u64, MicroSnapshot)>>>);

impl SnapshotInbox {
    /// The snapshot of `id` taken at the commit of `step`, if there is one.
    pub fn take(&self, id: GaussPointId, step: u64) -> Option<MicroSnapshot> {
        let mut map = self.0.lock().unwrap_or_else(|p| p.into_inner());
        match map.remove(&id) {
            Some((s, snap)) if s == step => Some(snap),
            Some(other) => {
                map.insert(id, other);
                None
            }
            None => None,
        }
    }

    fn put(&self, id: GaussPointId, step: u64, snap: MicroSnapshot) {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).insert(id, (step, snap));
    }
}

/// A [`Material`] that forwards everything to `inner` and, after every successful commit,
/// fetches the snapshots of `ids` into its [`SnapshotInbox`].
pub struct SnapshotTap<'m> {
    inner: &'m mut dyn Material,
    ids: Vec<GaussPointId>,
    inbox: SnapshotInbox,
}

impl<'m> SnapshotTap<'m> {
    /// Watches `ids` of `inner`, delivering into `inbox`.
    pub fn new(inner: &'m mut dyn Material, ids: Vec<GaussPointId>, inbox: SnapshotInbox) -> Self {
        Self { inner, ids, inbox }
    }
}

impl Material for SnapshotTap<'_> {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> std::result::Result<Vec<MicroResponse>, MaterialError> {
        self.inner.evaluate(trial, inputs)
    }

    fn commit(&mut self, step: u64) -> std::result::Result<(), MaterialError> {
        self.inner.commit(step)?;
        for &id in &self.ids {
            match self.inner.snapshot(id) {
                Ok(Some(snap)) => self.inbox.put(id, step, snap),
                Ok(None) => {}
                Err(e) => tracing::warn!(%id, step, error = %e, "snapshot not fetched"),
            }
        }
        Ok(())
    }

    fn rollback(&mut self) -> std::result::Result<(), MaterialError> {
        self.inner.rollback()
    }

    fn committed_states(
        &mut self,
    ) -> std::result::Result<Option<Vec<cosdem_common::micro::AssemblyState>>, MaterialError> {
        self.inner.committed_states()
    }

    fn restore_states(
        &mut self,
        states: Vec<cosdem_common::micro::AssemblyState>,
    ) -> std::result::Result<(), MaterialError> {
        self.inner.restore_states(states)
    }

    fn is_symmetric(&self) -> bool {
        self.inner.is_symmetric()
    }

    fn snapshot(
        &mut self,
        id: GaussPointId,
    ) -> std::result::Result<Option<MicroSnapshot>, MaterialError> {
        self.inner.snapshot(id)
    }
}

/// Checks the requested `[element, point]` pairs (the job's `output.snapshots`) against the
/// Gauss points of the mesh, `points[e]` in element `e`.
pub fn resolve_snapshot_ids(
    requested: &[[u32; 2]],
    points: &[usize],
) -> cosdem_fem::Result<Vec<GaussPointId>> {
    let mut ids = Vec::new();
    for &[e, p] in requested {
        let count = points.get(e as usize).copied();
        if count.is_none_or(|n| p as usize >= n) {
            return Err(cosdem_fem::Error::InvalidSetting {
                field: "output.snapshots",
                value: format!("[{e}, {p}]"),
                reason: match count {
                    None => format!("the mesh has elements 0..{}", points.len()),
                    Some(n) => format!("element {e} has points 0..{n}"),
                },
            });
        }
        let id = GaussPointId::new(e, p);
        if !ids.contains(&id) {
            ids.push(id);
        }
    }
    Ok(ids)
}

/// A snapshot as plain arrays, as written to and read from a snapshot `.vtu`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParticleSnapshot {
    /// Disc centres (m).
    pub centres: Vec<[f64; 2]>,
    /// Radii (m).
    pub radius: Vec<f64>,
    /// Rotations (rad).
    pub rotation: Vec<f64>,
    /// Fluctuation displacement, Eq. 35 (m).
    pub fluctuation: Vec<[f64; 2]>,
    /// Contacts `(i, j, normal force, tangential force)` (N per metre of thickness).
    pub contacts: Vec<(usize, usize, f64, f64)>,
    /// Macro displacement (m) of the step (the `.vtu`'s time value).
    pub displacement: Option<f64>,
}

impl ParticleSnapshot {
    /// Unflattens a service snapshot, checking that its arrays agree (`path` names the file in
    /// errors). A model without particles (an empty snapshot) is an error too.
    pub fn from_micro(s: &MicroSnapshot, path: &Path) -> Result<Self> {
        let n = s.radii.len();
        let bad = |what: &str, len: usize, want: usize| {
            invalid(
                path,
                format!("snapshot {what} has {len} values for {n} discs (expected {want})"),
            )
        };
        if n == 0 {
            return Err(invalid(path, "snapshot has no discs".into()));
        }
        if s.positions.len() != 2 * n {
            return Err(bad("positions", s.positions.len(), 2 * n));
        }
        if s.rotations.len() != n {
            return Err(bad("rotations", s.rotations.len(), n));
        }
        if s.fluctuations.len() != 2 * n {
            return Err(bad("fluctuations", s.fluctuations.len(), 2 * n));
        }
        if !s.contacts.len().is_multiple_of(4) {
            return Err(invalid(
                path,
                format!("{} contact values (not 4 per contact)", s.contacts.len()),
            ));
        }
        let mut contacts = Vec::with_capacity(s.contacts.len() / 4);
        for (k, c) in s.contacts.chunks(4).enumerate() {
            let index =
                |v: f64| (v >= 0.0 && v.fract() == 0.0 && v < n as f64).then_some(v as usize);
            let (Some(i), Some(j)) = (index(c[0]), index(c[1])) else {
                return Err(invalid(
                    path,
                    format!("contact {k} joins discs {} and {}", c[0], c[1]),
                ));
            };
            contacts.push((i, j, c[2], c[3]));
        }
        Ok(Self {
            centres: s.positions.chunks(2).map(|p| [p[0], p[1]]).collect(),
            radius: s.radii.clone(),
            rotation: s.rotations.clone(),
            fluctuation: s.fluctuations.chunks(2).map(|p| [p[0], p[1]]).collect(),
            contacts,
            displacement: None,
        })
    }
}

/// The VTK piece of a snapshot: one vertex per disc with `radius`, `rotation` and
/// `fluctuation` (Eq. 35, z = 0), then one line per contact with the cell arrays
/// `normal_force` and `tangential_force` (0 on the vertex cells). No velocities.
pub fn snapshot_piece(s: &ParticleSnapshot) -> VtuPiece {
    let contacts: Vec<(usize, usize, f64)> = s.contacts.iter().map(|c| (c.0, c.1, c.2)).collect();
    let mut piece = particle_piece(&s.centres, &s.radius, &s.rotation, &s.fluctuation, &contacts);
    let mut ft = vec![0.0; s.centres.len()];
    ft.extend(s.contacts.iter().map(|c| c.3));
    piece.add_cell_data(DataArray::scalars("tangential_force", ft));
    piece.time = s.displacement;
    piece
}

/// The discs of a snapshot as a packing: the region is the discs' bounding box
/// (`min(x - r)` to `max(x + r)`, the region a packing reader gives a file without one) and
/// the centres are shifted by `(-min(x - r), -min(y - r))`, so that the region starts at the
/// origin as the readers' does. Discs keep their order.
pub fn snapshot_packing(s: &ParticleSnapshot) -> Packing {
    let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
    for (c, r) in s.centres.iter().zip(&s.radius) {
        b = [b[0].min(c[0] - r), b[1].max(c[0] + r), b[2].min(c[1] - r), b[3].max(c[1] + r)];
    }
    Packing {
        x: s.centres.iter().map(|c| c[0] - b[0]).collect(),
        y: s.centres.iter().map(|c| c[1] - b[2]).collect(),
        r: s.radius.clone(),
        lx: b[1] - b[0],
        ly: b[3] - b[2],
    }
}

/// Reads a snapshot `.vtu` written from [`snapshot_piece`].
pub fn read_snapshot(path: &Path) -> Result<ParticleSnapshot> {
    let piece = read_vtu(path)?;
    let n = piece.points.len();
    let point = |name: &str, comps: usize| -> Result<&[f64]> {
        match piece.point_array(name) {
            Some(a) if a.components == comps && a.values.len() == comps * n => Ok(&a.values),
            _ => Err(invalid(path, format!("no point array {name:?} of {comps} component(s)"))),
        }
    };
    let radius = point("radius", 1)?.to_vec();
    let rotation = point("rotation", 1)?.to_vec();
    let fluctuation = point("fluctuation", 3)?.chunks(3).map(|v| [v[0], v[1]]).collect();
    let nc = piece.cells.len();
    let cell = |name: &str| -> Result<&[f64]> {
        match piece.cell_array(name) {
            Some(a) if a.components == 1 && a.values.len() == nc => Ok(&a.values),
            _ => Err(invalid(path, format!("no cell array {name:?}"))),
        }
    };
    let fnorm = cell("normal_force")?;
    let ft = cell("tangential_force")?;
    let contacts = piece
        .cells
        .iter()
        .enumerate()
        .filter(|(_, c)| c.nodes.len() == 2)
        .map(|(k, c)| (c.nodes[0], c.nodes[1], fnorm[k], ft[k]))
        .collect();
    Ok(ParticleSnapshot {
        centres: piece.points.iter().map(|p| [p[0], p[1]]).collect(),
        radius,
        rotation,
        fluctuation,
        contacts,
        displacement: piece.time,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::write_vtu;

    fn micro() -> MicroSnapshot {
        MicroSnapshot {
            positions: vec![0.0, 0.0, 0.01, 0.0, 0.005, 0.0087],
            radii: vec![0.005, 0.005, 0.005],
            rotations: vec![0.0, 1e-3, -2e-3],
            contacts: vec![0.0, 1.0, 120.0, 3.5, 1.0, 2.0, 80.0, -1.0],
            fluctuations: vec![1e-6, 0.0, -1e-6, 2e-7, 0.0, 0.0],
        }
    }

    /// Shape: n vertices then one line per contact, the arrays sized accordingly; and the
    /// file read back equals what was written (bit for bit: shortest round-trip decimals).
    #[test]
    fn snapshot_vtu_round_trip() {
        let dir = std::env::temp_dir().join(format!("cosdem-snap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("snap.vtu");
        let mut s = ParticleSnapshot::from_micro(&micro(), &path).unwrap();
        s.displacement = Some(0.004);
        let piece = snapshot_piece(&s);
        assert_eq!(piece.points.len(), 3);
        assert_eq!(piece.cells.len(), 3 + 2);
        assert_eq!(
            piece.cell_array("normal_force").unwrap().values,
            vec![0.0, 0.0, 0.0, 120.0, 80.0]
        );
        assert_eq!(piece.point_array("fluctuation").unwrap().components, 3);
        write_vtu(&path, &piece).unwrap();
        assert_eq!(read_snapshot(&path).unwrap(), s);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The stand-in model's snapshot (no discs, one fluctuation value) is refused by name.
    #[test]
    fn inconsistent_snapshots_are_refused() {
        let p = Path::new("x.vtu");
        let stand_in = MicroSnapshot { fluctuations: vec![0.1], ..Default::default() };
        assert!(
            ParticleSnapshot::from_micro(&stand_in, p)
                .unwrap_err()
                .to_string()
                .contains("no discs")
        );
        let mut m = micro();
        m.contacts[1] = 7.0;
        let e = ParticleSnapshot::from_micro(&m, p).unwrap_err().to_string();
        assert!(e.contains("contact 0") && e.contains('7'), "{e}");
        let mut m = micro();
        m.fluctuations.pop();
        assert!(
            ParticleSnapshot::from_micro(&m, p).unwrap_err().to_string().contains("fluctuations")
        );
    }

    #[test]
    fn snapshot_ids_are_checked() {
        let ids = resolve_snapshot_ids(&[[0, 0], [3, 3], [0, 0]], &[4; 4]).unwrap();
        assert_eq!(ids, vec![GaussPointId::new(0, 0), GaussPointId::new(3, 3)]);
        let e = resolve_snapshot_ids(&[[4, 0]], &[4; 4]).unwrap_err().to_string();
        assert!(e.contains("output.snapshots") && e.contains("[4, 0]"), "{e}");
        assert!(e.contains("elements 0..4"), "{e}");
        // A mixed mesh: element 1 is a triangle of 3 points.
        let e = resolve_snapshot_ids(&[[1, 3]], &[4, 3]).unwrap_err().to_string();
        assert!(e.contains("element 1 has points 0..3"), "{e}");
        assert!(resolve_snapshot_ids(&[[0, 3], [1, 2]], &[4, 3]).is_ok());
    }
}
