//! Domain -> wire. Infallible.

use crate::v1 as pb;
use cosdem_common::micro::{
    AssemblyInfo, AssemblyRequest, AssemblyState, BoundaryKind, MicroSnapshot,
};
use cosdem_common::{
    GaussPointId, MacroDeformation, MicroDescriptors, MicroDiagnostics, MicroResponse,
};

impl From<GaussPointId> for pb::GaussPoint {
    fn from(id: GaussPointId) -> Self {
        pb::GaussPoint { element: id.element, point: id.point }
    }
}

impl From<MacroDeformation> for pb::MacroDeformation {
    fn from(m: MacroDeformation) -> Self {
        pb::MacroDeformation {
            f_xx: m.f[0][0],
            f_xy: m.f[0][1],
            f_yx: m.f[1][0],
            f_yy: m.f[1][1],
            w: m.w,
            k_x: m.kappa[0],
            k_y: m.kappa[1],
        }
    }
}

impl From<&MicroDiagnostics> for pb::MicroDiagnostics {
    fn from(d: &MicroDiagnostics) -> Self {
        pb::MicroDiagnostics {
            steps: d.steps,
            residual_ratio: d.residual_ratio,
            converged: d.converged,
            contacts: d.contacts,
            sliding_fraction: d.sliding_fraction,
            rolling_fraction: d.rolling_fraction,
            wall_seconds: d.wall_seconds,
            answer: d.answer.code(),
            unrelaxed_increment: d.unrelaxed_increment,
            error_bound: d.error_bound,
            descriptors: d.descriptors.as_ref().map(pb::MicroDescriptors::from),
        }
    }
}

impl From<&MicroDescriptors> for pb::MicroDescriptors {
    fn from(d: &MicroDescriptors) -> Self {
        pb::MicroDescriptors {
            porosity: d.porosity,
            void_ratio: d.void_ratio,
            coordination: d.coordination,
            mechanical_coordination: d.mechanical_coordination,
            fabric_xx: d.fabric_xx,
            fabric_yy: d.fabric_yy,
            fabric_xy: d.fabric_xy,
            anisotropy: d.anisotropy,
            fabric_direction: d.fabric_direction,
            sliding_fraction: d.sliding_fraction,
            mean_rotation: d.mean_rotation,
        }
    }
}

impl From<&MicroResponse> for pb::MicroResponse {
    fn from(r: &MicroResponse) -> Self {
        pb::MicroResponse {
            stress: r.stress.to_vec(),
            tangent: r.tangent.iter().flatten().copied().collect(),
            diagnostics: Some((&r.diagnostics).into()),
        }
    }
}

impl From<BoundaryKind> for pb::BoundaryType {
    fn from(b: BoundaryKind) -> Self {
        match b {
            BoundaryKind::Unspecified => pb::BoundaryType::Unspecified,
            BoundaryKind::Penalty => pb::BoundaryType::Penalty,
            BoundaryKind::Periodic => pb::BoundaryType::Periodic,
        }
    }
}

impl From<&AssemblyRequest> for pb::AssemblySpec {
    fn from(s: &AssemblyRequest) -> Self {
        pb::AssemblySpec {
            spec_json: s.spec_json.clone(),
            boundary: pb::BoundaryType::from(s.boundary) as i32,
            disc_count_hint: s.disc_count_hint,
        }
    }
}

impl From<&AssemblyInfo> for pb::AssemblyInfo {
    fn from(a: &AssemblyInfo) -> Self {
        pb::AssemblyInfo { id: Some(a.id.into()), disc_count: a.disc_count, cost_hint: a.cost_hint }
    }
}

impl From<AssemblyState> for pb::AssemblyState {
    fn from(a: AssemblyState) -> Self {
        pb::AssemblyState {
            id: Some(a.id.into()),
            committed_step: a.committed_step,
            state: a.state,
            disc_count: a.disc_count,
        }
    }
}

/// The snapshot reply of one assembly.
pub fn snapshot_reply(
    id: GaussPointId,
    committed_step: u64,
    s: MicroSnapshot,
) -> pb::SnapshotReply {
    pb::SnapshotReply {
        id: Some(id.into()),
        committed_step,
        positions: s.positions,
        radii: s.radii,
        rotations: s.rotations,
        contacts: s.contacts,
        fluctuations: s.fluctuations,
    }
}

/// A streamed result: a response, or the in-band failure of one relaxation.
pub fn solve_result(id: GaussPointId, outcome: &Result<MicroResponse, String>) -> pb::SolveResult {
    pb::SolveResult {
        id: Some(id.into()),
        outcome: Some(match outcome {
            Ok(r) => pb::solve_result::Outcome::Response(r.into()),
            Err(e) => pb::solve_result::Outcome::Error(e.clone()),
        }),
    }
}

/// A solve item.
pub fn solve_item(id: GaussPointId, target: MacroDeformation) -> pb::SolveItem {
    pb::SolveItem { id: Some(id.into()), target: Some(target.into()) }
}
