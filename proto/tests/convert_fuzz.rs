//! Property tests of the wire -> domain conversions: a peer can send anything (NaN, inf,
//! det(F) <= 0, wrong lengths, missing messages, unknown enum values, huge arrays). Every
//! conversion returns a value or a `ConvertError` naming the field; never a panic; and what
//! converts round-trips exactly. Deterministic: fixed-seed runner, 256 cases each.

use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_proto::v1 as pb;
use cosdem_proto::{ConvertError, from_proto};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

fn runner() -> TestRunner {
    let config = Config { cases: 256, failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -2.0f64..2.0,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => Just(1e308),
        1 => Just(-1e-320),
        2 => any::<f64>(),
    ]
}

fn deformation() -> impl Strategy<Value = pb::MacroDeformation> {
    prop::array::uniform7(number()).prop_map(|v| pb::MacroDeformation {
        f_xx: v[0],
        f_xy: v[1],
        f_yx: v[2],
        f_yy: v[3],
        w: v[4],
        k_x: v[5],
        k_y: v[6],
    })
}

fn gauss_point() -> impl Strategy<Value = Option<pb::GaussPoint>> {
    prop::option::weighted(
        0.8,
        any::<(u32, u32)>().prop_map(|(element, point)| pb::GaussPoint { element, point }),
    )
}

fn response() -> impl Strategy<Value = pb::MicroResponse> {
    let len = prop_oneof![Just(6usize), Just(36), 0usize..40, Just(10_000)];
    (len.clone(), len, number(), prop::option::of(any::<(u64, u32, bool)>())).prop_map(
        |(ns, nt, v, d)| pb::MicroResponse {
            stress: vec![v; ns],
            tangent: (0..nt).map(|k| v * k as f64).collect(),
            diagnostics: d.map(|(steps, contacts, converged)| pb::MicroDiagnostics {
                steps,
                contacts,
                converged,
                residual_ratio: v,
                ..Default::default()
            }),
        },
    )
}

/// Kinematics: accepted exactly when every component is finite and det(F) > 0 (then the
/// round trip is exact); refused naming the field or the determinant.
#[test]
fn deformations_are_validated() {
    runner()
        .run(&deformation(), |m| {
            match MacroDeformation::try_from(m) {
                Ok(d) => {
                    prop_assert!(d.det() > 0.0);
                    prop_assert_eq!(pb::MacroDeformation::from(d), m);
                }
                Err(e) => {
                    let msg = e.to_string();
                    let named = ["F_xx", "F_xy", "F_yx", "F_yy", "`w`", "k_x", "k_y", "det(F)"]
                        .iter()
                        .any(|f| msg.contains(f));
                    prop_assert!(named, "{msg}");
                }
            }
            Ok(())
        })
        .unwrap();
}

/// Solve items: a missing id or target is named; otherwise as the kinematics.
#[test]
fn solve_items_are_validated() {
    let item = (gauss_point(), prop::option::weighted(0.8, deformation()));
    runner()
        .run(&item, |(id, target)| {
            let r = from_proto::solve_item(pb::SolveItem { id, target });
            match (id, target, r) {
                (None, _, Err(e)) => prop_assert_eq!(e, ConvertError::Missing("id")),
                (Some(_), None, Err(e)) => prop_assert_eq!(e, ConvertError::Missing("target")),
                (Some(g), Some(_), Ok((got, _))) => prop_assert_eq!(got, GaussPointId::from(g)),
                (Some(_), Some(_), Err(ConvertError::Kinematics(_))) => {}
                (id, t, r) => prop_assert!(false, "{id:?} {t:?} -> {r:?}"),
            }
            Ok(())
        })
        .unwrap();
}

/// Responses: wrong lengths are refused naming the field; right ones round-trip exactly
/// (NaN included: the master's Newton loop, not the wire, turns a non-finite answer into a
/// failed Gauss point).
#[test]
fn responses_check_their_lengths() {
    runner()
        .run(&response(), |r| {
            let (ns, nt) = (r.stress.len(), r.tangent.len());
            match MicroResponse::try_from(r.clone()) {
                Ok(d) => {
                    prop_assert!(ns == 6 && nt == 36);
                    let back = pb::MicroResponse::from(&d);
                    prop_assert_eq!(
                        back.stress.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        r.stress.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                    );
                }
                Err(ConvertError::Length { field, .. }) => {
                    prop_assert!(field == "stress" || field == "tangent");
                    prop_assert!(ns != 6 || nt != 36);
                }
                Err(e) => prop_assert!(false, "{e}"),
            }
            Ok(())
        })
        .unwrap();
}

/// Streamed results, specs, infos and states: missing messages and unknown enum values are
/// refused naming the field; never a panic.
#[test]
fn other_messages_never_panic() {
    let outcome = prop_oneof![
        Just(None),
        response().prop_map(|r| Some(pb::solve_result::Outcome::Response(r))),
        ".{0,40}".prop_map(|e| Some(pb::solve_result::Outcome::Error(e))),
    ];
    let strat = (
        gauss_point(),
        outcome,
        any::<i32>(),
        prop::collection::vec(any::<u8>(), 0..64),
        any::<u64>(),
        number(),
    );
    runner()
        .run(&strat, |(id, outcome, boundary, bytes, n, x)| {
            if let Err(e) = from_proto::solve_result(pb::SolveResult { id, outcome }) {
                prop_assert!(!e.to_string().is_empty());
            }
            let spec = pb::AssemblySpec { spec_json: bytes.clone(), boundary, disc_count_hint: n };
            match cosdem_common::micro::AssemblyRequest::try_from(spec) {
                Ok(_) => prop_assert!((0..=2).contains(&boundary)),
                Err(e) => prop_assert!(e.to_string().contains("boundary"), "{e}"),
            }
            let info = pb::AssemblyInfo { id, disc_count: n, cost_hint: x };
            if let Err(e) = cosdem_common::micro::AssemblyInfo::try_from(info) {
                prop_assert_eq!(e, ConvertError::Missing("id"));
            }
            let state = pb::AssemblyState { id, committed_step: n, state: bytes, disc_count: n };
            if let Err(e) = cosdem_common::micro::AssemblyState::try_from(state) {
                prop_assert_eq!(e, ConvertError::Missing("id"));
            }
            Ok(())
        })
        .unwrap();
}
