//! What answers at the Gauss points: the job's materials per region, and the DEM specimens
//! per point.
//!
//! Each element takes `[material]` or the material of the `[[region]]` it is in
//! ([`Job::element_materials`]). The elastic materials answer on the master; every DEM point,
//! whatever its region, is held by one pool of workers, which gets one creation request per
//! distinct specimen ([`plan_specimens`]): a region's packing, with the seed of the point's
//! specimen (`[specimens] count`) and the confining stress of its consolidation level
//! (`[specimens] consolidation`). A worker builds one specimen per request and copies it to
//! the request's points, so the generation cost grows with the number of distinct specimens,
//! not of points. A job of one material is exactly what it was before regions existed: the
//! material itself, no composite.

use super::{RunError, WorkerChoice};
use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, AssemblyState, BoundaryKind};
use cosdem_dem::spec::TangentFrame;
use cosdem_fem::assembly::Kinematics;
use cosdem_fem::material::{BiotCosserat, Material, Regions};
use cosdem_fem::mesh::Mesh;
use cosdem_job::{Consolidation, Job, MaterialSection};
use cosdem_pool::Pool;
use cosdem_worker::Dem;
use serde::{Deserialize, Serialize};

/// The points of one distinct specimen: one creation request.
#[derive(Clone, Debug, PartialEq)]
pub struct SpecimenGroup {
    /// The material (0: `[material]`, i + 1: `region[i]`).
    pub material: usize,
    /// The specimen number (its packing seed is the material's plus this, wrapping).
    pub specimen: u64,
    /// The confining stress it is consolidated at (Pa); `None`: the packing's own.
    pub confining_stress: Option<f64>,
    /// Its Gauss points, in the order of the mesh's points.
    pub ids: Vec<GaussPointId>,
}

/// What the assemblies of a run cost to build (the summary's `specimens`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpecimenReport {
    /// Distinct specimens generated (creation requests): one per material, consolidation
    /// level and specimen number that some point uses.
    pub distinct: usize,
    /// Gauss points they back.
    pub points: usize,
    /// Wall time of the generation (s): the in-situ stress solve and every creation request.
    pub seconds: f64,
}

/// A run's material and what it took.
pub struct Built {
    /// What answers at the Gauss points.
    pub material: Box<dyn Material>,
    /// Workers serving the DEM points (0 without DEM points).
    pub workers: usize,
    /// The specimens generated (`None` without DEM points, or on a resume: the assemblies
    /// came from the checkpoint).
    pub specimens: Option<SpecimenReport>,
}

/// The distinct specimens of the DEM points, in the order their first point appears.
///
/// `element_materials` is [`Job::element_materials`]; `ids` every Gauss point, element-major;
/// `mean_stress` the in-situ mean stress per point (same order), needed when
/// `[specimens] consolidation = "in_situ"`. Points of elastic materials are in no group.
pub fn plan_specimens(
    job: &Job,
    element_materials: &[usize],
    ids: &[GaussPointId],
    mean_stress: Option<&[f64]>,
) -> Vec<SpecimenGroup> {
    let materials = job.materials();
    let s = &job.specimens;
    let mut groups: Vec<SpecimenGroup> = Vec::new();
    // (material, specimen, level bits) -> group index; levels are exact ladder values.
    let mut index = std::collections::HashMap::new();
    for (flat, &id) in ids.iter().enumerate() {
        let m = element_materials[id.element as usize];
        if !matches!(materials[m], MaterialSection::Dem { .. }) {
            continue;
        }
        let specimen = s.specimen_of(ids.len(), id.element, id.point, flat);
        let level = match (s.consolidation, mean_stress) {
            (Consolidation::InSitu, Some(p)) => Some(s.level_of(p[flat])),
            _ => None,
        };
        let key = (m, specimen, level.map(f64::to_bits));
        let g = *index.entry(key).or_insert_with(|| {
            groups.push(SpecimenGroup {
                material: m,
                specimen,
                confining_stress: level,
                ids: Vec::new(),
            });
            groups.len() - 1
        });
        groups[g].ids.push(id);
    }
    groups
}

/// What answers at the Gauss points `ids` (element-major) of `mesh`, and how many workers
/// serve it. The DEM points are held by one pool (remote workers when `workers.addresses` is
/// non-empty, else the job's `[workers] in_process` in-process workers); the elastic points
/// by their materials; a job with both gets a [`Regions`] composite.
///
/// `saved` (a resume) places those committed states instead of building new assemblies.
pub fn material_for(
    job: &Job,
    workers: &WorkerChoice,
    mesh: &Mesh,
    ids: &[GaussPointId],
    saved: Option<Vec<AssemblyState>>,
) -> Result<Built, RunError> {
    let element_materials = job.element_materials(mesh)?;
    let materials = job.materials();
    let is_dem = |id: &GaussPointId| {
        matches!(materials[element_materials[id.element as usize]], MaterialSection::Dem { .. })
    };
    let dem_ids: Vec<GaussPointId> = ids.iter().copied().filter(is_dem).collect();
    // One part per elastic material that has points, in material order.
    let mut parts: Vec<(Box<dyn Material>, Vec<GaussPointId>)> = Vec::new();
    for (m, section) in materials.iter().enumerate() {
        if let Some(e) = section.elastic() {
            // Under the updated-Lagrangian option the objective (Biot-type) law with the same
            // constants: it is Eq. 8 at small strain.
            let e: Box<dyn Material> = match job.mesh.kinematics {
                Kinematics::Small => Box::new(e),
                Kinematics::UpdatedLagrangian => Box::new(BiotCosserat { elastic: e }),
            };
            let own: Vec<GaussPointId> = ids
                .iter()
                .copied()
                .filter(|id| element_materials[id.element as usize] == m)
                .collect();
            if !own.is_empty() {
                parts.push((e, own));
            }
        }
    }
    let mut n_workers = 0;
    let mut specimens = None;
    if !dem_ids.is_empty() {
        let (pool, report) = dem_pool(job, workers, &element_materials, ids, saved)?;
        n_workers = pool.live_workers();
        specimens = report;
        parts.push((Box::new(pool), dem_ids));
    }
    let material: Box<dyn Material> = if parts.len() == 1 {
        parts.pop().expect("one part").0
    } else {
        Box::new(Regions::new(parts)?)
    };
    Ok(Built { material, workers: n_workers, specimens })
}

/// The pool holding every DEM point: new assemblies, one creation request per distinct
/// specimen, or the checkpoint's `saved` states.
fn dem_pool(
    job: &Job,
    workers: &WorkerChoice,
    element_materials: &[usize],
    ids: &[GaussPointId],
    saved: Option<Vec<AssemblyState>>,
) -> Result<(Pool, Option<SpecimenReport>), RunError> {
    // `dns:NAME:PORT` (a headless service) is the same as `NAME:PORT`: every address the
    // name resolves to becomes a worker.
    let addresses: Vec<String> =
        workers.addresses.iter().map(|a| a.strip_prefix("dns:").unwrap_or(a).to_string()).collect();
    let mut pool = if addresses.is_empty() {
        let n = Pool::in_process_workers(job.workers.in_process);
        Pool::in_process(n, workers.config.clone(), |_| Dem)?
    } else {
        Pool::connect(&addresses, workers.config.clone())?
    };
    if let Some(states) = saved {
        // Resume: the assemblies as committed at the checkpoint.
        pool.restore_states(states).map_err(cosdem_fem::Error::from)?;
        return Ok((pool, None));
    }
    let start = std::time::Instant::now();
    let mean_stress = match job.specimens.consolidation {
        Consolidation::InSitu => {
            Some(super::in_situ::in_situ_mean_stress(job, job.specimens.poisson)?)
        }
        Consolidation::Uniform => None,
    };
    let groups = plan_specimens(job, element_materials, ids, mean_stress.as_deref());
    let materials = job.materials();
    let span = tracing::info_span!("specimens", distinct = groups.len());
    let _enter = span.enter();
    for g in &groups {
        let MaterialSection::Dem { assembly } = materials[g.material] else {
            unreachable!("plan_specimens groups DEM points only")
        };
        let mut spec = job.specimens.assembly_of(assembly, g.specimen, g.confining_stress);
        if job.mesh.kinematics == Kinematics::UpdatedLagrangian {
            // The tangent the FE needs on the current configuration: convected, with the
            // polar sub-step path and the objective shortcut.
            spec.frame = TangentFrame::Current;
        }
        // The disc count from the spec, so that a worker checks its limits before building
        // and the pool splits and times its requests by it.
        let request = AssemblyRequest {
            spec_json: serde_json::to_vec(&spec)?,
            boundary: BoundaryKind::Unspecified,
            disc_count_hint: spec.disc_count_hint(),
        };
        tracing::debug!(
            material = %job.material_label(g.material),
            specimen = g.specimen,
            confining_stress = g.confining_stress,
            points = g.ids.len(),
            "creating a specimen"
        );
        pool.create_assemblies(&g.ids, &request)?;
    }
    let report = SpecimenReport {
        distinct: groups.len(),
        points: groups.iter().map(|g| g.ids.len()).sum(),
        seconds: start.elapsed().as_secs_f64(),
    };
    tracing::info!(
        distinct = report.distinct,
        points = report.points,
        seconds = report.seconds,
        "specimens generated"
    );
    Ok((pool, Some(report)))
}
