//! The job schema as serde reads it, for the tests: every table, its keys, and the values of
//! every choice, found by asking the schema itself.
//!
//! Every table is `deny_unknown_fields`, so a table holding an unknown key `zz_probe` is refused
//! with the list of the keys it accepts; a tagged table (`kind = ...` or `model = ...`) without
//! its tag is refused naming the tag, with an unknown tag value it lists its variants, and each
//! variant then lists its own keys; a string-valued choice (`element`, `criterion`, ...) with
//! an unknown value lists the values it accepts. The walk descends from the top level into
//! every table, array of tables and variant, so a new key, table or variant anywhere
//! (including the DEM assembly spec of `cosdem_dem::spec`) is found without touching a test.

use cosdem_job::Job;
use std::collections::{BTreeMap, BTreeSet};
use toml::{Table, Value};

/// A key no table accepts.
const PROBE: &str = "zz_probe";

/// What the schema accepts: per table (dotted path, "" for the top level), per key, the
/// values of a choice (empty for a free value).
pub type Schema = BTreeMap<String, BTreeMap<String, BTreeSet<String>>>;

/// One step of the path from the top level to a table.
#[derive(Clone, Debug)]
struct Seg {
    /// The key of the table in its parent.
    key: String,
    /// `(tag, variant)`: the variant a tagged table is given.
    tag: Option<(String, String)>,
    /// The table is an element of an array of tables (`[[loading.pressure]]`).
    array: bool,
}

fn dotted(path: &[Seg]) -> String {
    path.iter().map(|s| s.key.as_str()).collect::<Vec<_>>().join(".")
}

fn child(path: &[Seg], key: &str, array: bool) -> Vec<Seg> {
    let mut p = path.to_vec();
    p.push(Seg { key: key.into(), tag: None, array });
    p
}

/// A document holding `inner` as the table at `path` (with the tags of the path's tables).
fn document(path: &[Seg], inner: Table) -> Table {
    let Some((last, outer)) = path.split_last() else { return inner };
    let mut t = inner;
    if let Some((tag, variant)) = &last.tag {
        t.insert(tag.clone(), Value::String(variant.clone()));
    }
    let value = if last.array { Value::Array(vec![Value::Table(t)]) } else { Value::Table(t) };
    document(outer, Table::from_iter([(last.key.clone(), value)]))
}

/// The error of reading the document as a job ("" if it reads).
fn probe(path: &[Seg], inner: Table) -> String {
    match Value::Table(document(path, inner)).try_into::<Job>() {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

/// The names serde lists after `unknown {what} `zz_probe``, if that is the error.
fn listed(message: &str, what: &str) -> Option<BTreeSet<String>> {
    let head = format!("unknown {what} `{PROBE}`");
    let rest = &message[message.find(&head)? + head.len()..];
    let line = rest.lines().next().unwrap_or("");
    Some(line.split('`').skip(1).step_by(2).map(String::from).collect())
}

/// How the table at `path` answers a table holding only the unknown key.
enum Shape {
    /// A table with these keys.
    Fields(BTreeSet<String>),
    /// A tagged table: its tag key.
    Tagged(String),
    /// Not a table.
    Value,
}

/// Asks the table at `path` what it is, with a table holding only the unknown key.
fn shape(path: &[Seg]) -> Shape {
    let message = probe(path, Table::from_iter([(PROBE.to_string(), Value::Integer(0))]));
    if let Some(keys) = listed(&message, "field") {
        return Shape::Fields(keys);
    }
    // An internally tagged enum looks for its tag first, and names its variants when the tag
    // is unknown.
    if let Some(tag) = message.split("missing field `").nth(1).and_then(|r| r.split('`').next()) {
        let unknown = probe(path, Table::from_iter([(tag.to_string(), PROBE.into())]));
        if listed(&unknown, "variant").is_some() {
            return Shape::Tagged(tag.to_string());
        }
    }
    Shape::Value
}

/// Walks the table at `path` and everything below it into `schema`.
fn walk(path: &[Seg], schema: &mut Schema) {
    assert!(path.len() < 10, "runaway walk at {}", dotted(path));
    let name = dotted(path);
    let variants: Vec<(Vec<Seg>, BTreeSet<String>)> = match shape(path) {
        Shape::Fields(keys) => vec![(path.to_vec(), keys)],
        Shape::Tagged(tag) => {
            let message = probe(path, Table::from_iter([(tag.clone(), PROBE.into())]));
            let names = listed(&message, "variant")
                .unwrap_or_else(|| panic!("[{name}]: no variants of `{tag}` in: {message}"));
            schema.entry(name.clone()).or_default().insert(tag.clone(), names.clone());
            names
                .into_iter()
                .map(|v| {
                    let mut p = path.to_vec();
                    p.last_mut().unwrap().tag = Some((tag.clone(), v));
                    let keys = match shape(&p) {
                        Shape::Fields(keys) => keys,
                        // A variant without fields (`periodic`, `paper`, `none`): it has no
                        // keys of its own (and refuses any other, see `cosdem_dem::spec`).
                        _ => BTreeSet::new(),
                    };
                    (p, keys)
                })
                .collect()
        }
        Shape::Value => panic!("[{name}] is not a table"),
    };
    for (p, keys) in variants {
        for key in keys {
            schema.entry(name.clone()).or_default().entry(key.clone()).or_default();
            let (table, array) = (child(&p, &key, false), child(&p, &key, true));
            if !matches!(shape(&table), Shape::Value) {
                walk(&table, schema);
            } else if !matches!(shape(&array), Shape::Value) {
                walk(&array, schema);
            } else {
                let message = probe(&p, Table::from_iter([(key.clone(), PROBE.into())]));
                if let Some(values) = listed(&message, "variant") {
                    schema.get_mut(&name).unwrap().get_mut(&key).unwrap().extend(values);
                }
            }
        }
    }
}

pub fn schema() -> Schema {
    let mut schema = Schema::new();
    walk(&[], &mut schema);
    schema
}

/// Every key of every table, once each, sorted (a table's name is a key of its parent).
pub fn keys() -> Vec<String> {
    let all: BTreeSet<String> = schema().into_values().flat_map(BTreeMap::into_keys).collect();
    all.into_iter().collect()
}
