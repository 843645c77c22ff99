//! The micro descriptors of protocol 4 survive the wire bit for bit: domain -> prost message
//! -> encoded bytes -> prost message -> domain gives back every `f64` exactly (protobuf
//! `double` is the IEEE bits) except the sign of a zero (proto3 omits a zero scalar, so a
//! negative zero reads back positive: the DEM kernel never produces one), and an answer
//! without descriptors (an analytical material) stays without them.

use cosdem_common::{MicroDescriptors, MicroDiagnostics, MicroResponse};
use cosdem_proto::PROTOCOL_VERSION;
use cosdem_proto::v1 as pb;
use prost::Message;

fn through_the_wire(r: &MicroResponse) -> MicroResponse {
    let bytes = pb::MicroResponse::from(r).encode_to_vec();
    MicroResponse::try_from(pb::MicroResponse::decode(bytes.as_slice()).unwrap()).unwrap()
}

fn response(descriptors: Option<MicroDescriptors>) -> MicroResponse {
    MicroResponse {
        stress: [1.0, -2.0, 0.5, 0.25, 1e-3, -1e-3],
        tangent: [[3.0; 6]; 6],
        diagnostics: MicroDiagnostics { contacts: 12, descriptors, ..Default::default() },
    }
}

/// Values with full mantissas (no value is a short binary fraction), compared on their bits;
/// a negative zero comes back as +0.0 (documented above).
#[test]
fn descriptors_round_trip_exactly() {
    let d = MicroDescriptors {
        porosity: 1.0 - std::f64::consts::PI / (2.0 * 3f64.sqrt()),
        void_ratio: 2.0 * 3f64.sqrt() / std::f64::consts::PI - 1.0,
        coordination: 4.0 / 3.0,
        mechanical_coordination: 3.1,
        fabric_xx: 0.1f64.sqrt(),
        fabric_yy: 1.0 - 0.1f64.sqrt(),
        fabric_xy: -1.0 / 7.0,
        anisotropy: 0.123_456_789_012_345_67,
        fabric_direction: -std::f64::consts::FRAC_PI_3,
        sliding_fraction: 1.0 / 11.0,
        mean_rotation: -0.0,
    };
    let b = through_the_wire(&response(Some(d))).diagnostics.descriptors.unwrap();
    let bits = |d: &MicroDescriptors| {
        [
            d.porosity,
            d.void_ratio,
            d.coordination,
            d.mechanical_coordination,
            d.fabric_xx,
            d.fabric_yy,
            d.fabric_xy,
            d.anisotropy,
            d.fabric_direction,
            d.sliding_fraction,
            d.mean_rotation,
        ]
        .map(f64::to_bits)
    };
    let mut expected = d;
    expected.mean_rotation = 0.0;
    assert_eq!(bits(&b), bits(&expected));
}

#[test]
fn absent_descriptors_stay_absent() {
    assert_eq!(through_the_wire(&response(None)).diagnostics.descriptors, None);
}

/// Protocol 4 is the first that carries the descriptors (a master or worker of protocol 3
/// would drop them), 5 the first whose assembly spec may name a predictor: the handshake must
/// tell each from the one before.
#[test]
fn protocol_version_is_five() {
    assert_eq!(PROTOCOL_VERSION, 5);
}
