//! Property tests: assembly spec JSON (what a job's `[material.assembly]` table and a
//! CreateAssemblies request carry), mutated with hostile values, through deserialization,
//! validation, packing generation and one solve. Nothing may panic; a refused spec names
//! the field; a built assembly answers with finite numbers or an error.
//!
//! Sizes are capped so the file stays fast: packings estimated above 300 discs (hexagonal)
//! or 12 discs (random) are only validated, and relaxations get at most 3 000 steps.
//! Deterministic: a fixed-seed ChaCha runner, no failure persistence.

use cosdem_common::MacroDeformation;
use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::{Value, json};

fn runner(cases: u32) -> TestRunner {
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

/// The bases: the default spec (hexagonal, penalty), a small periodic FIRE one with the
/// perturbation tangent, and a random packing of six given radii.
fn bases() -> Vec<Value> {
    let hex = serde_json::to_value(AssemblySpec::default()).unwrap();
    let periodic = json!({
        "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.05},
        "boundary": {"kind": "periodic"},
        "relaxation": {"driver": {"kind": "fire", "alpha_start": 0.1, "f_inc": 1.1,
                       "f_dec": 0.5, "f_alpha": 0.99, "n_min": 5, "dt_max": 1.8},
                       "criterion": "kinetic_energy", "max_steps": 2000},
        "tangent": {"kind": "perturbation", "strain": 1e-5},
        "warm_start": true
    });
    let random = json!({
        "packing": {"kind": "random", "r_min": 0.0, "r_max": 0.0,
                    "radii": [0.005, 0.004, 0.006, 0.005, 0.0045, 0.0055],
                    "side": 0.05, "seed": 9, "confining_stress": 1e5},
        "contact": {"normal": {"model": "linear_dashpot", "k_n": 6.7e7, "c_n": 1.0},
                    "tangential": {"model": "none"}, "rolling": {"model": "none"}}
    });
    vec![hex, periodic, random]
}

fn hostile_json() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(json!(0)),
        Just(json!(-1)),
        Just(json!(0.0)),
        Just(json!(-0.0)),
        Just(json!(1e308)),
        Just(json!(-1e308)),
        Just(json!(5e-324)),
        Just(json!(1e-300)),
        Just(json!(u64::MAX)),
        Just(json!(i64::MIN)),
        Just(json!(1e10)),
        Just(json!(1e-10)),
        Just(json!(10.0)),
        Just(json!(null)),
        Just(json!(true)),
        Just(json!("")),
        Just(json!("periodic")),
        Just(json!([])),
        Just(json!([1e308, -1.0, 0.0, 5e-324])),
        Just(json!({})),
        Just(json!({"kind": "nope"})),
        (-1e3f64..1e3).prop_map(|v| json!(v)),
        any::<f64>()
            .prop_filter("JSON has no NaN or inf", |v| v.is_finite())
            .prop_map(|v| json!(v)),
        any::<i64>().prop_map(|v| json!(v)),
        Just(deep(300)),
    ]
}

fn deep(depth: usize) -> Value {
    (0..depth).fold(json!(1), |v, _| json!([v]))
}

/// Every path to a value inside objects (array elements by index).
fn paths(v: &Value, prefix: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match v {
        Value::Object(m) => {
            for (k, sub) in m {
                prefix.push(json!(k));
                out.push(prefix.clone());
                paths(sub, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, sub) in a.iter().enumerate() {
                prefix.push(json!(i));
                out.push(prefix.clone());
                paths(sub, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn slot<'a>(v: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
    let mut cur = v;
    for k in path {
        cur = match k {
            Value::String(s) => cur.get_mut(s.as_str())?,
            Value::Number(n) => cur.get_mut(n.as_u64()? as usize)?,
            _ => return None,
        };
    }
    Some(cur)
}

fn mutate(mut v: Value, muts: &[(usize, u8, Value)]) -> Value {
    for (i, how, new) in muts {
        let mut all = Vec::new();
        paths(&v, &mut Vec::new(), &mut all);
        let p = all[i % all.len()].clone();
        match how % 4 {
            // Replace the value.
            0 | 1 => {
                if let Some(s) = slot(&mut v, &p) {
                    *s = new.clone();
                }
            }
            // Remove the key (the default then applies, or a required field is missing).
            2 => {
                if let Some(Value::Object(m)) = slot(&mut v, &p[..p.len() - 1])
                    && let Some(Value::String(k)) = p.last()
                {
                    m.remove(k);
                }
            }
            // Add an unknown key next to it.
            _ => {
                if let Some(Value::Object(m)) = slot(&mut v, &p[..p.len() - 1]) {
                    m.insert("unknown_key".into(), new.clone());
                }
            }
        }
    }
    v
}

/// Small enough to build and solve inside the budget.
fn small(spec: &AssemblySpec) -> bool {
    let n = spec.packing.estimated_discs();
    match &spec.packing {
        PackingSpec::Hexagonal { .. } => n <= 300.0,
        PackingSpec::Random { confining_stress, .. } => {
            n <= 12.0 && (1e3..=1e7).contains(confining_stress)
        }
        PackingSpec::Explicit { .. } | PackingSpec::File { .. } => n <= 300.0,
    }
}

/// Parse, validate, build, solve one compression: the outcome as text (for the assertions).
fn exercise(bytes: &[u8]) -> Result<(), String> {
    let mut spec: AssemblySpec = serde_json::from_slice(bytes).map_err(|e| format!("json: {e}"))?;
    spec.validate().map_err(|e| e.to_string())?;
    if !small(&spec) {
        return Ok(());
    }
    spec.relaxation.max_steps = spec.relaxation.max_steps.min(3_000);
    let mut a = Assembly::new(&spec).map_err(|e| format!("build: {e}"))?;
    let t = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2]);
    let r = a.solve(&t).map_err(|e| format!("solve: {e}"))?;
    assert!(r.is_finite(), "non-finite response {r:?}");
    a.commit();
    let back = Assembly::from_bytes(&a.to_bytes()).map_err(|e| format!("bytes: {e}"))?;
    assert_eq!(back.to_bytes(), a.to_bytes());
    Ok(())
}

/// Mutated specs: never a panic; a validation error names a field in backquotes.
#[test]
fn mutated_specs_never_panic_and_name_the_field() {
    let strat =
        (0usize..3, prop::collection::vec((any::<usize>(), any::<u8>(), hostile_json()), 1..4));
    let bases = bases();
    for b in &bases {
        exercise(&serde_json::to_vec(b).unwrap()).expect("every base spec builds");
    }
    runner(128)
        .run(&strat, |(b, muts)| {
            let v = mutate(bases[b].clone(), &muts);
            let bytes = serde_json::to_vec(&v).unwrap();
            match exercise(&bytes) {
                Ok(()) => {}
                Err(e) if e.starts_with("json: ") => prop_assert!(e.len() > 6),
                Err(e) if e.starts_with("build: ") || e.starts_with("solve: ") => {
                    prop_assert!(e.len() > 7)
                }
                Err(e) => prop_assert!(e.contains('`'), "no field named: {e}\n{v}"),
            }
            Ok(())
        })
        .unwrap();
}

/// Arbitrary bytes and arbitrary JSON text: never a panic.
#[test]
fn arbitrary_bytes_never_panic() {
    let strat = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..256),
        "[{}\\[\\]\",:0-9a-z.eE+-]{0,200}".prop_map(String::into_bytes),
        Just(b"{\"density\": 1e400}".to_vec()),
        Just(b"{\"density\": NaN}".to_vec()),
        Just(format!("{}{}", "[".repeat(100_000), "]".repeat(100_000)).into_bytes()),
    ];
    runner(256)
        .run(&strat, |bytes| {
            let _ = exercise(&bytes);
            let _ = Assembly::from_bytes(&bytes);
            Ok(())
        })
        .unwrap();
}

/// Exported states with flipped or dropped bytes: refused or decoded, never a panic, and a
/// decoded one still solves to a finite answer or an error.
#[test]
fn corrupted_states_never_panic() {
    let spec: AssemblySpec = serde_json::from_value(json!({
        "packing": {"kind": "hexagonal", "radius": 0.005, "side": 0.04},
        "relaxation": {"max_steps": 2000}
    }))
    .unwrap();
    let mut a = Assembly::new(&spec).unwrap();
    a.solve(&MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2])).unwrap();
    a.commit();
    let good = a.to_bytes();
    let strat = prop::collection::vec((any::<usize>(), any::<u8>(), 0u8..3), 1..6);
    runner(128)
        .run(&strat, |edits| {
            let mut b = good.clone();
            for (pos, byte, how) in edits {
                if b.is_empty() {
                    break;
                }
                let p = pos % b.len();
                match how {
                    0 => b[p] = byte,
                    1 => b[p] ^= 1 << (byte % 8),
                    _ => b.truncate(p),
                }
            }
            if let Ok(mut c) = Assembly::from_bytes(&b) {
                let t = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -2e-3]], 0.0, [0.0; 2]);
                if let Ok(r) = c.solve(&t) {
                    prop_assert!(r.is_finite());
                }
            }
            Ok(())
        })
        .unwrap();
}
