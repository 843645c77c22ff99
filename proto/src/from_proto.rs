//! Wire -> domain. Every conversion validates: a peer can send anything.

use crate::v1 as pb;
use cosdem_common::micro::{
    AssemblyInfo, AssemblyRequest, AssemblyState, BoundaryKind, MicroSnapshot,
};
use cosdem_common::voigt::N;
use cosdem_common::{
    GaussPointId, KinematicsError, MacroDeformation, MicroDescriptors, MicroDiagnostics,
    MicroResponse,
};

/// Why a wire message does not make a domain value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConvertError {
    /// A required message field is absent.
    #[error("missing field `{0}`")]
    Missing(&'static str),
    /// A repeated field has the wrong length.
    #[error("field `{field}` has {got} values, expected {expected}")]
    Length {
        /// Field name.
        field: &'static str,
        /// Expected count.
        expected: usize,
        /// Count received.
        got: usize,
    },
    /// An enum value this version does not know.
    #[error("field `{field}` has unknown value {value}")]
    UnknownEnum {
        /// Field name.
        field: &'static str,
        /// Value received.
        value: i32,
    },
    /// Kinematics that cannot drive an assembly (NaN, det(F) <= 0).
    #[error("{0}")]
    Kinematics(#[from] KinematicsError),
}

impl From<pb::GaussPoint> for GaussPointId {
    fn from(p: pb::GaussPoint) -> Self {
        GaussPointId::new(p.element, p.point)
    }
}

/// The id of a message that must carry one.
pub fn gauss_point(p: Option<pb::GaussPoint>) -> Result<GaussPointId, ConvertError> {
    p.map(GaussPointId::from).ok_or(ConvertError::Missing("id"))
}

impl TryFrom<pb::MacroDeformation> for MacroDeformation {
    type Error = ConvertError;
    /// Validates: every component finite and det(F) > 0.
    fn try_from(m: pb::MacroDeformation) -> Result<Self, ConvertError> {
        let d = MacroDeformation {
            f: [[m.f_xx, m.f_xy], [m.f_yx, m.f_yy]],
            w: m.w,
            kappa: [m.k_x, m.k_y],
        };
        d.validate()?;
        Ok(d)
    }
}

impl From<pb::MicroDiagnostics> for MicroDiagnostics {
    fn from(d: pb::MicroDiagnostics) -> Self {
        MicroDiagnostics {
            steps: d.steps,
            residual_ratio: d.residual_ratio,
            converged: d.converged,
            contacts: d.contacts,
            sliding_fraction: d.sliding_fraction,
            rolling_fraction: d.rolling_fraction,
            wall_seconds: d.wall_seconds,
            answer: cosdem_common::Answer::from_code(d.answer),
            unrelaxed_increment: d.unrelaxed_increment,
            error_bound: d.error_bound,
            descriptors: d.descriptors.map(MicroDescriptors::from),
        }
    }
}

impl From<pb::MicroDescriptors> for MicroDescriptors {
    fn from(d: pb::MicroDescriptors) -> Self {
        MicroDescriptors {
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

impl TryFrom<pb::MicroResponse> for MicroResponse {
    type Error = ConvertError;
    fn try_from(r: pb::MicroResponse) -> Result<Self, ConvertError> {
        if r.stress.len() != N {
            return Err(ConvertError::Length { field: "stress", expected: N, got: r.stress.len() });
        }
        if r.tangent.len() != N * N {
            return Err(ConvertError::Length {
                field: "tangent",
                expected: N * N,
                got: r.tangent.len(),
            });
        }
        let mut stress = [0.0; N];
        stress.copy_from_slice(&r.stress);
        let mut tangent = [[0.0; N]; N];
        for (row, chunk) in tangent.iter_mut().zip(r.tangent.chunks_exact(N)) {
            row.copy_from_slice(chunk);
        }
        Ok(MicroResponse { stress, tangent, diagnostics: r.diagnostics.unwrap_or_default().into() })
    }
}

/// The boundary type of a spec (an open proto enum: unknown values are refused).
pub fn boundary(v: i32) -> Result<BoundaryKind, ConvertError> {
    {
        match pb::BoundaryType::try_from(v) {
            Ok(pb::BoundaryType::Unspecified) => Ok(BoundaryKind::Unspecified),
            Ok(pb::BoundaryType::Penalty) => Ok(BoundaryKind::Penalty),
            Ok(pb::BoundaryType::Periodic) => Ok(BoundaryKind::Periodic),
            Err(_) => Err(ConvertError::UnknownEnum { field: "boundary", value: v }),
        }
    }
}

impl TryFrom<pb::AssemblySpec> for AssemblyRequest {
    type Error = ConvertError;
    fn try_from(s: pb::AssemblySpec) -> Result<Self, ConvertError> {
        Ok(AssemblyRequest {
            spec_json: s.spec_json,
            boundary: boundary(s.boundary)?,
            disc_count_hint: s.disc_count_hint,
        })
    }
}

impl TryFrom<pb::AssemblyInfo> for AssemblyInfo {
    type Error = ConvertError;
    fn try_from(a: pb::AssemblyInfo) -> Result<Self, ConvertError> {
        Ok(AssemblyInfo {
            id: gauss_point(a.id)?,
            disc_count: a.disc_count,
            cost_hint: a.cost_hint,
        })
    }
}

impl TryFrom<pb::AssemblyState> for AssemblyState {
    type Error = ConvertError;
    fn try_from(a: pb::AssemblyState) -> Result<Self, ConvertError> {
        Ok(AssemblyState {
            id: gauss_point(a.id)?,
            committed_step: a.committed_step,
            state: a.state,
            disc_count: a.disc_count,
        })
    }
}

impl From<pb::SnapshotReply> for MicroSnapshot {
    fn from(s: pb::SnapshotReply) -> Self {
        MicroSnapshot {
            positions: s.positions,
            radii: s.radii,
            rotations: s.rotations,
            contacts: s.contacts,
            fluctuations: s.fluctuations,
        }
    }
}

/// A solve target: the Gauss point and its validated kinematics.
pub fn solve_item(item: pb::SolveItem) -> Result<(GaussPointId, MacroDeformation), ConvertError> {
    let id = gauss_point(item.id)?;
    let target = item.target.ok_or(ConvertError::Missing("target"))?.try_into()?;
    Ok((id, target))
}

/// A streamed result: the Gauss point and its response or in-band failure message.
pub fn solve_result(
    r: pb::SolveResult,
) -> Result<(GaussPointId, Result<MicroResponse, String>), ConvertError> {
    let id = gauss_point(r.id)?;
    let outcome = match r.outcome.ok_or(ConvertError::Missing("outcome"))? {
        pb::solve_result::Outcome::Response(resp) => Ok(resp.try_into()?),
        pb::solve_result::Outcome::Error(e) => Err(e),
    };
    Ok((id, outcome))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_are_exact() {
        let m =
            MacroDeformation::from_gradient([[0.01, -0.02], [0.003, -0.004]], 0.1, [0.5, -0.25]);
        let back: MacroDeformation = pb::MacroDeformation::from(m).try_into().unwrap();
        assert_eq!(back, m);
        let mut r = MicroResponse {
            stress: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            tangent: [[0.0; N]; N],
            diagnostics: Default::default(),
        };
        r.tangent[2][5] = 7.5;
        r.diagnostics.steps = 9;
        let back: MicroResponse = pb::MicroResponse::from(&r).try_into().unwrap();
        assert_eq!(back, r);
    }

    #[test]
    fn nan_and_inversion_name_the_field() {
        let mut m = pb::MacroDeformation::from(MacroDeformation::IDENTITY);
        m.k_x = f64::NAN;
        let e = MacroDeformation::try_from(m).unwrap_err().to_string();
        assert!(e.contains("k_x") && e.contains("NaN"), "{e}");
        let mut m = pb::MacroDeformation::from(MacroDeformation::IDENTITY);
        m.f_xx = -1.0;
        let e = MacroDeformation::try_from(m).unwrap_err().to_string();
        assert!(e.contains("det(F) = -1"), "{e}");
    }

    #[test]
    fn short_tangent_is_refused() {
        let r =
            pb::MicroResponse { stress: vec![0.0; 6], tangent: vec![0.0; 35], diagnostics: None };
        assert!(matches!(
            MicroResponse::try_from(r),
            Err(ConvertError::Length { field: "tangent", .. })
        ));
    }
}
