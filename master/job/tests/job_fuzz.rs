//! Property tests: random and hostile job files fed to parsing, validation and model
//! building (`Job::from_toml`, `Job::model`, `Job::solver_settings`, `Solver::new`).
//! Nothing may panic; an error must name a job-file key (so the user knows what to fix).
//!
//! Three generators: (1) arbitrary text, (2) arbitrary TOML documents (random keys, values of
//! every type, nesting), (3) a valid job with one to three keys replaced, added or removed,
//! using hostile values (huge, negative, NaN, inf, wrong types, deep nesting). Case counts
//! are modest (the whole file runs in seconds) and deterministic: proptest's default
//! `ProptestConfig` seeds from the test name when failure persistence is off, which it is.

mod common;

use cosdem_fem::error::Error;
use cosdem_fem::solve::Solver;
use cosdem_job::{Job, fixtures};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::sync::LazyLock;
use toml::{Table, Value};

/// Every key a job file knows (job tables and the `[material.assembly]` spec, from the schema
/// itself): an error message must contain at least one of them.
static KEYS: LazyLock<Vec<String>> = LazyLock::new(common::keys);

/// The elastic base job: the confined elastic panel fixture with a title, an internal length,
/// `[newton]` and `[output]`, so that mutations reach those keys too.
fn elastic() -> String {
    let panel = fixtures::text("elastic-panel-confined")
        .replace("poisson = 0.25", "poisson = 0.25\nlength = 0.05");
    format!("title = \"fuzz\"\n{panel}\n[newton]\nmax_iterations = 10\n\n[output]\nvtk_every = 1\n")
}

/// The DEM base job: the one-element DEM fixture with the density, the normal contact model
/// and the relaxation spelled out, so that mutations reach those tables too.
fn dem() -> String {
    let job = fixtures::text("dem-one-element")
        .replace("[material.assembly]\n", "[material.assembly]\ndensity = 2650.0\n");
    format!(
        "{job}\n[material.assembly.contact.normal]\nmodel = \"linear\"\nk_n = 6.7e7\n\n\
         [material.assembly.relaxation]\ntolerance = 1e-4\nmax_steps = 1000\n"
    )
}

/// Hostile scalar values: extremes of every numeric kind, special floats, wrong types.
fn hostile_value() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::Float(f64::NAN)),
        Just(Value::Float(f64::INFINITY)),
        Just(Value::Float(f64::NEG_INFINITY)),
        Just(Value::Float(-0.0)),
        Just(Value::Float(1e308)),
        Just(Value::Float(-1e308)),
        Just(Value::Float(5e-324)),
        Just(Value::Float(1e-300)),
        Just(Value::Integer(0)),
        Just(Value::Integer(-1)),
        Just(Value::Integer(i64::MAX)),
        Just(Value::Integer(i64::MIN)),
        Just(Value::Integer(1_000_001)),
        Just(Value::Integer(1 << 40)),
        any::<f64>().prop_map(Value::Float),
        any::<i64>().prop_map(Value::Integer),
        (-3i64..10).prop_map(Value::Integer),
        (-1.0f64..2.0).prop_map(Value::Float),
        Just(Value::Boolean(true)),
        "[a-z_]{0,12}".prop_map(Value::String),
        Just(Value::String("gmsh".into())),
        Just(Value::String("\u{0}\u{feff}é".into())),
        Just(Value::Array(vec![])),
        Just(Value::Array(vec![Value::Float(f64::NAN), Value::Integer(-1)])),
        Just(Value::Table(Table::new())),
        Just(deep_array(200)),
        Just(deep_table(200)),
    ]
}

fn deep_array(depth: usize) -> Value {
    (0..depth).fold(Value::Integer(1), |v, _| Value::Array(vec![v]))
}

fn deep_table(depth: usize) -> Value {
    (0..depth).fold(Value::Integer(1), |v, _| {
        let mut t = Table::new();
        t.insert("kind".into(), v);
        Value::Table(t)
    })
}

/// Arbitrary TOML values, nested a few levels.
fn any_value() -> impl Strategy<Value = Value> {
    let key = prop_oneof![prop::sample::select(KEYS.clone()), "[a-z]{1,6}"];
    hostile_value().prop_recursive(4, 32, 6, move |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::btree_map(key.clone(), inner, 0..6)
                .prop_map(|m| Value::Table(m.into_iter().collect())),
        ]
    })
}

/// Every path to a value in `t` (tables entered, arrays of tables entered by index 0).
fn paths(t: &Table, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    for (k, v) in t {
        prefix.push(k.clone());
        out.push(prefix.clone());
        match v {
            Value::Table(sub) => paths(sub, prefix, out),
            Value::Array(a) => {
                if let Some(Value::Table(sub)) = a.first() {
                    paths(sub, prefix, out);
                }
            }
            _ => {}
        }
        prefix.pop();
    }
}

/// The table that holds the last segment of `path` (descending into arrays of tables).
fn parent<'a>(t: &'a mut Table, path: &[String]) -> Option<&'a mut Table> {
    let mut cur = t;
    for k in &path[..path.len() - 1] {
        cur = match cur.get_mut(k)? {
            Value::Table(sub) => sub,
            Value::Array(a) => match a.first_mut()? {
                Value::Table(sub) => sub,
                _ => return None,
            },
            _ => return None,
        };
    }
    Some(cur)
}

#[derive(Clone, Debug)]
enum Mutation {
    Replace(usize, Value),
    Remove(usize),
    Add(usize, String, Value),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let key = prop_oneof![prop::sample::select(KEYS.clone()), "[a-z]{1,8}"];
    prop_oneof![
        4 => (any::<usize>(), prop_oneof![3 => hostile_value(), 1 => any_value()])
            .prop_map(|(i, v)| Mutation::Replace(i, v)),
        1 => any::<usize>().prop_map(Mutation::Remove),
        1 => (any::<usize>(), key, hostile_value()).prop_map(|(i, k, v)| Mutation::Add(i, k, v)),
    ]
}

fn mutate(base: &str, muts: &[Mutation]) -> String {
    let mut t: Table = toml::from_str(base).expect("base job parses");
    for m in muts {
        let mut all = Vec::new();
        paths(&t, &mut Vec::new(), &mut all);
        let pick = |i: usize| all[i % all.len()].clone();
        match m {
            Mutation::Replace(i, v) => {
                let p = pick(*i);
                if let Some(tab) = parent(&mut t, &p) {
                    tab.insert(p.last().unwrap().clone(), v.clone());
                }
            }
            Mutation::Remove(i) => {
                let p = pick(*i);
                if let Some(tab) = parent(&mut t, &p) {
                    tab.remove(p.last().unwrap());
                }
            }
            Mutation::Add(i, k, v) => {
                let mut p = pick(*i);
                p.push(k.clone());
                if let Some(tab) = parent(&mut t, &p) {
                    tab.insert(k.clone(), v.clone());
                }
            }
        }
    }
    // Serializing can refuse some trees (e.g. NaN inside some arrays): fall back on the
    // Display of the value, which writes every TOML form.
    toml::to_string(&t).unwrap_or_else(|_| Value::Table(t).to_string())
}

/// Parses, validates and builds everything a run builds before it needs workers. Returns
/// the first error's message.
fn exercise(text: &str) -> Result<(), String> {
    let job = Job::from_toml(text, "fuzz.toml").map_err(|e| e.to_string())?;
    let model = job.model().map_err(|e| e.to_string())?;
    let settings = job.solver_settings().map_err(|e| e.to_string())?;
    let _ = job.loading();
    Solver::new(model, settings).map_err(|e| e.to_string())?;
    Ok(())
}

fn names_a_key(msg: &str) -> bool {
    KEYS.iter().any(|k| msg.contains(k.as_str()))
}

fn runner(cases: u32) -> TestRunner {
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    // A fixed seed: the same cases on every run and every machine.
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

/// Arbitrary text (mostly not TOML): never a panic, always a message.
#[test]
fn arbitrary_text_never_panics() {
    let text = prop_oneof![
        ".{0,200}",
        "(\\[[a-z.]{1,12}\\]\n([a-z_]{1,10} = [-0-9.eEinfa\"]{1,12}\n){0,4}){0,5}",
    ];
    runner(256)
        .run(&text, |s| {
            if let Err(e) = exercise(&s) {
                prop_assert!(!e.is_empty());
            }
            Ok(())
        })
        .unwrap();
}

/// Arbitrary TOML documents: an error names a key (unknown or missing or invalid).
#[test]
fn arbitrary_toml_documents_name_a_key() {
    let doc = prop::collection::btree_map(
        prop_oneof![prop::sample::select(KEYS.clone()), "[a-z]{1,6}"],
        any_value(),
        0..6,
    );
    runner(128)
        .run(&doc, |m| {
            let text = Value::Table(m.into_iter().collect()).to_string();
            if let Err(e) = exercise(&text) {
                prop_assert!(names_a_key(&e), "no key named in: {e}\n--- job ---\n{text}");
            }
            Ok(())
        })
        .unwrap();
}

/// A valid job (elastic or DEM) with one to three hostile mutations: no panic; an error
/// names a key.
#[test]
fn mutated_jobs_name_the_key() {
    let (elastic, dem) = (elastic(), dem());
    for base in [&elastic, &dem] {
        exercise(base).expect("the base job is valid");
    }
    let strat = (prop::bool::ANY, prop::collection::vec(mutation(), 1..4));
    runner(256)
        .run(&strat, |(is_dem, muts)| {
            let text = mutate(if is_dem { &dem } else { &elastic }, &muts);
            if let Err(e) = exercise(&text) {
                prop_assert!(names_a_key(&e), "no key named in: {e}\n--- job ---\n{text}");
            }
            Ok(())
        })
        .unwrap();
}

/// Hand-picked hostile documents: nesting far beyond any job, huge counts, NaN and infinite
/// numbers where a count or a length is expected.
#[test]
fn hostile_documents_are_refused_with_the_key() {
    // Nesting 5 000 to 10 000 deep: refused by the TOML reader's depth limit, as a job-file
    // error naming the file and the limit, with the line and column where the parser has them
    // (the dotted key's limit is hit after parsing, where it has none).
    let deep = format!("title = {}{}", "[".repeat(10_000), "]".repeat(10_000));
    let dotted = format!("{} = 1", vec!["a"; 5_000].join("."));
    let inline = format!("mesh = {}1{}", "{a = ".repeat(5_000), "}".repeat(5_000));
    for (text, place) in
        [(deep, Some("line 1, column 89")), (dotted, None), (inline, Some("line 1, column 408"))]
    {
        let err = Job::from_toml(&text, "fuzz.toml").unwrap_err();
        // The message quotes the whole line: only its first and last lines are shown.
        let msg = err.to_string();
        let short = format!("{} ... {}", msg.lines().next().unwrap(), msg.lines().last().unwrap());
        assert!(matches!(&err, Error::JobFile { file, .. } if file == "fuzz.toml"), "{short}");
        assert!(msg.contains("recursion"), "{short}");
        if let Some(place) = place {
            assert!(msg.contains(place), "{place} not in {short}");
        }
    }
    let elastic = elastic();
    for (from, to, key) in [
        ("nx = 4", "nx = 9223372036854775807", "mesh.nx"),
        ("nx = 4\nny = 4", "nx = 1000000\nny = 1000000", "mesh.nx"),
        ("nx = 4\nny = 4", "nx = 1000\nny = 1001", "mesh.nx"),
        ("nx = 4\nny = 4", "nx = 1000\nny = 501\nelement = \"t6\"", "2 * nx * ny triangles"),
        ("steps = 3", "steps = 1000000000", "loading.steps"),
        ("steps = 3", "increment = 1e-300", "loading.increment = 1e-300"),
        ("lx = 1.0", "lx = nan", "mesh.lx"),
        ("lx = 1.0", "lx = inf", "mesh.lx"),
        ("lx = 1.0", "lx = 1.0\norigin = [1e308, 0.0]", "mesh.origin"),
        ("lx = 1.0", "lx = 1e308", "mesh.lx = 1e308"),
        ("ly = 2.0", "ly = 2.0\norigin = [nan, 0.0]", "mesh.origin"),
        ("length = 0.05", "length = -inf", "material.length"),
        ("shear_modulus = 2e7", "shear_modulus = 1e308", "material.shear_modulus"),
        ("length = 0.05", "length = 1e160", "material.length"),
        ("max_iterations = 10", "max_iterations = -1", "max_iterations"),
        ("max_iterations = 10", "min_increment_fraction = 1e-300", "min_increment_fraction"),
        ("value = 1.0e5", "value = nan", "loading.pressure.value"),
        ("set = \"left\"", "set = \"nowhere\"", "nowhere"),
    ] {
        assert!(elastic.contains(from), "the base job has no `{from}`");
        let text = elastic.replace(from, to);
        let e = exercise(&text).expect_err(to);
        assert!(e.contains(key), "`{to}`: error does not name {key}: {e}");
    }
}
